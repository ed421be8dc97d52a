"""Newton solver: roots, implicit derivatives (forward and reverse), batching, failure flags."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.newton import implicit_solution, newton_solve, solve_small, split_derivative


def cube_root_system(x, th):
    # root: x0 = th0**(1/3), x1 = th1 * x0**2  (closed form)
    return jnp.stack([x[0] ** 3 - th[0], x[1] - th[1] * x[0] ** 2])


def solve(th):
    return newton_solve(cube_root_system, jnp.array([1.0, 1.0]), th).x


def exact(th):
    x0 = th[0] ** (1 / 3)
    return jnp.stack([x0, th[1] * x0 ** 2])


TH = jnp.array([2.7, -0.8])


def test_root_and_diagnostics():
    res = newton_solve(cube_root_system, jnp.array([1.0, 1.0]), TH)
    assert bool(res.converged)
    assert float(res.residual) < 1e-14
    assert 0 < int(res.steps) < 20
    np.testing.assert_allclose(res.x, exact(TH), rtol=1e-14)


@pytest.mark.parametrize("jac", [jax.jacfwd, jax.jacrev])
def test_jacobian_matches_analytic(jac):
    np.testing.assert_allclose(jac(solve)(TH), jax.jacfwd(exact)(TH), rtol=1e-12)


def test_jvp_and_grad_match_central_differences():
    d = jnp.array([0.3, -1.1])
    _, t = jax.jvp(solve, (TH,), (d,))
    h = 1e-6
    fd = (solve(TH + h * d) - solve(TH - h * d)) / (2 * h)
    np.testing.assert_allclose(t, fd, rtol=1e-8)
    g = jax.grad(lambda th: jnp.sum(solve(th) ** 2))(TH)
    e = jnp.eye(2)
    fd = jnp.array([(jnp.sum(solve(TH + h * e[i]) ** 2) - jnp.sum(solve(TH - h * e[i]) ** 2)) / (2 * h)
                    for i in range(2)])
    np.testing.assert_allclose(g, fd, rtol=1e-8)


def test_second_derivative():
    f = lambda a: newton_solve(lambda x, t: x ** 2 - t, 1.0, a).x  # noqa: E731
    np.testing.assert_allclose(jax.grad(jax.grad(f))(2.0), -0.25 * 2.0 ** -1.5, rtol=1e-12)
    np.testing.assert_allclose(jax.hessian(lambda th: solve(th)[1])(TH),
                               jax.hessian(lambda th: exact(th)[1])(TH), rtol=1e-10)


def test_vmap_of_grad_and_jit():
    f = lambda a: newton_solve(lambda x, t: x ** 2 - t, 1.0, a).x  # noqa: E731
    a = jnp.array([1.0, 4.0, 9.0, 0.25])
    np.testing.assert_allclose(jax.jit(jax.vmap(jax.grad(f)))(a), 0.5 / jnp.sqrt(a), rtol=1e-13)
    res = jax.vmap(lambda t: newton_solve(lambda x, s: x ** 2 - s, 1.0, t))(a)
    assert res.converged.shape == (4,) and bool(jnp.all(res.converged))


def test_closure_over_traced_values_is_differentiated():
    def root(a):
        return newton_solve(lambda x, th: jnp.sin(x) - a * th, 0.1, 0.5).x

    a = 0.6
    np.testing.assert_allclose(jax.grad(root)(a), 0.5 / np.sqrt(1 - (0.5 * a) ** 2), rtol=1e-12)


def test_non_convergence_is_flagged_not_returned_as_valid():
    res = newton_solve(lambda x, th: x ** 2 + 1.0, 0.7, ())  # no real root
    assert not bool(res.converged)
    assert float(res.residual) >= 1.0
    res = newton_solve(lambda x, th: jnp.exp(x) - 0.0, 0.0, (), max_steps=5)  # root at -inf
    assert not bool(res.converged)
    # mixed batch: converged mask is per element
    res = jax.vmap(lambda t: newton_solve(lambda x, s: x ** 2 - s, 1.0, t))(jnp.array([4.0, -4.0]))
    assert res.converged.tolist() == [True, False]


def test_affine_system_is_solved_by_one_exact_step():
    """Newton is exact for an affine F: one step lands on the root.  The data are chosen so
    that the step is exact in binary floating point (F = 0 exactly), so the count is 1."""
    res = newton_solve(lambda x, th: 4.0 * x - th, 0.0, 6.0)
    assert float(res.x) == 1.5 and float(res.residual) == 0.0
    assert int(res.steps) == 1 and bool(res.converged)
    res = newton_solve(lambda x, th: jnp.stack([2.0 * x[0] - 3.0, 0.5 * x[1] + 1.0]), jnp.zeros(2), ())
    assert res.x.tolist() == [1.5, -2.0] and int(res.steps) == 1


def test_reported_residual_is_max_abs_F_at_the_returned_x():
    """residual = max|F(x)| evaluated here, independently, at the x the solver returns.  The
    system has no root (x0^2 + 1 > 0) and one affine equation solved at once, so the two
    components differ and a mean or another norm would not match; the solve runs to
    max_steps and is flagged as not converged."""
    F = lambda x, th: jnp.stack([x[0] ** 2 + 1.0, 0.25 * (x[1] - 2.0)])  # noqa: E731
    res = newton_solve(F, jnp.array([0.6, 7.0]), (), max_steps=7)
    fx = np.asarray(F(res.x, ()))
    np.testing.assert_allclose(float(res.residual), np.max(np.abs(fx)), rtol=1e-15)
    assert fx[0] >= 1.0 and abs(fx[1]) < 1e-15
    assert not bool(res.converged) and int(res.steps) == 7


def test_line_search_rescues_overshoot():
    # arctan: undamped Newton diverges from |x0| > 1.39; the backtracking converges
    res = newton_solve(lambda x, th: jnp.arctan(x), 3.0, ())
    assert bool(res.converged) and abs(float(res.x)) < 1e-12
    # one step by hand: dx = -(1 + x0^2) arctan(x0) = -10 arctan(3); the Armijo test
    # |F(x0 + a dx)| <= (1 - 1e-4 a)|F(x0)| fails for a = 1 (|F| = 1.466) and a = 1/2
    # (1.272) and holds for a = 1/4 (0.122) against |F(x0)| = 1.249.  So with at most
    # one halving the step ends at a = 1/2, with two at a = 1/4.
    for halvings, a in ((1, 0.5), (2, 0.25)):
        res = newton_solve(lambda x, th: jnp.arctan(x), 3.0, (), max_steps=1, max_halvings=halvings)
        np.testing.assert_allclose(float(res.x), 3.0 - a * 10.0 * np.arctan(3.0), rtol=1e-14)
        assert int(res.steps) == 1


def _count_primitive(jaxpr, name):
    n = 0
    for eqn in jaxpr.eqns:
        n += eqn.primitive.name == name
        for v in eqn.params.values():
            for sub in (v if isinstance(v, (tuple, list)) else (v,)):
                inner = getattr(sub, "jaxpr", sub)
                if hasattr(inner, "eqns"):
                    n += _count_primitive(inner, name)
    return n


def test_a_solve_evaluates_its_system_in_two_places():
    """The loop body gets F(x) as the primal of the Jacobian's forward-mode pass, so F
    appears twice in a solve's program (that pass and the line search), not a third time
    for a start residual before the loop: in a TCA each appearance is a flank
    evaluation to trace and compile.  ``atan`` marks F's evaluations (its derivative
    has none)."""
    F = lambda x, th: jnp.stack([jnp.arctan(x[0]) - th[0], x[1] - th[1]])  # noqa: E731
    jaxpr = jax.make_jaxpr(lambda th: newton_solve(F, jnp.array([0.1, 0.2]), th).x)(TH)
    assert _count_primitive(jaxpr.jaxpr, "atan") == 2
    sol = newton_solve(F, jnp.array([0.1, 0.2]), jnp.array([0.3, -0.4]))
    np.testing.assert_allclose(sol.x, [np.tan(0.3), -0.4], rtol=1e-14)


def test_zero_steps_reports_the_start_as_it_is():
    """``max_steps=0``: no iteration, the start returned with its own residual -- a start
    that is a root is converged, one that is not is flagged."""
    root = newton_solve(cube_root_system, exact(TH), TH, max_steps=0)
    assert bool(root.converged) and int(root.steps) == 0
    np.testing.assert_array_equal(root.x, exact(TH))
    off = newton_solve(cube_root_system, jnp.array([1.0, 1.0]), TH, max_steps=0)
    assert not bool(off.converged) and int(off.steps) == 0
    np.testing.assert_array_equal(off.x, [1.0, 1.0])
    np.testing.assert_allclose(float(off.residual), np.max(np.abs(
        np.asarray(cube_root_system(jnp.array([1.0, 1.0]), TH)))), rtol=1e-15)


def test_mismatched_system_rejected():
    with pytest.raises(ValueError):
        newton_solve(lambda x, th: jnp.stack([x[0], x[1], x[0]]), jnp.zeros(2), ())


def _badly_scaled(x, K):
    """Root (1, 1); from (0.81, 0.9) the full Newton step lands at (0.99, 1) where the
    first residual is K * 0.01 -- far above the start's 0.1 for K = 1000."""
    return jnp.stack([K * (x[0] - x[1] ** 2), x[1] - 1.0])


def test_natural_monotonicity_accepts_the_full_step_the_residual_test_damps():
    """One step by hand: dx = (0.18, 0.1); at x0 + dx, F = (-10, 0) and the simplified
    correction J(x0)^-1 F = (-0.01, 0) is 0.05 of |dx| (natural test passes, residual
    test fails); the residual test first holds at a = 1/16 (max|F| = 0.09375)."""
    x0, K = jnp.array([0.81, 0.9]), 1000.0
    one = newton_solve(_badly_scaled, x0, K, max_steps=1, natural_monotonicity=True)
    np.testing.assert_allclose(np.asarray(one.x), [0.99, 1.0], rtol=0, atol=1e-14)
    one = newton_solve(_badly_scaled, x0, K, max_steps=1)
    np.testing.assert_allclose(np.asarray(one.x), [0.81 + 0.18 / 16, 0.9 + 0.1 / 16],
                               rtol=0, atol=1e-14)
    # the whole solve: two steps with the natural test; the residual test crawls along
    # the parabola x0 = x1^2 in damped steps and is still 0.07 off after 50 (measured)
    nat = newton_solve(_badly_scaled, x0, K, natural_monotonicity=True)
    assert bool(nat.converged) and int(nat.steps) <= 3
    np.testing.assert_allclose(np.asarray(nat.x), [1.0, 1.0], rtol=0, atol=1e-12)
    res = newton_solve(_badly_scaled, x0, K)
    assert not bool(res.converged) and float(res.residual) > 0.01
    # the implicit derivative does not depend on the globalisation: dx/dK = 0 here
    g = jax.grad(lambda k: newton_solve(_badly_scaled, x0, k, natural_monotonicity=True).x[0])(K)
    assert abs(float(g)) < 1e-12


def test_noise_floor_takes_the_confirming_step_as_it_is():
    """``noise_floor``: the confirming iteration of a converged solve (max|F| <= tol,
    full step below xtol) takes its round-off step without the line search, which would
    halve it up to ``max_halvings`` times (no decrease can show at the noise floor) and,
    under ``vmap``, hold the whole batch that long.  A system with a term that is zero in
    exact arithmetic and round-off noise in floating point, 8 lanes: the same Newton
    steps per lane and the same roots (to the noise), fewer evaluations of F by the
    batch (counted as the program runs; 131 -> 115 measured)."""
    calls = []

    def F(x, th):
        jax.debug.callback(lambda: calls.append(1))
        noise = 1e3 * ((x[0] + 1e-3) ** 2 - x[0] ** 2 - 2e-3 * x[0] - 1e-6)
        return jnp.stack([x[0] ** 2 + x[1] ** 2 - 10.0 * th[0] + noise,
                          jnp.cos(x[0]) - x[1] * th[1]])

    ths = jnp.stack([jnp.linspace(1.0, 1.6, 8), jnp.linspace(0.5, 0.9, 8)], axis=1)
    out = {}
    for floor in (False, True):
        calls.clear()
        r = jax.jit(jax.vmap(lambda t, floor=floor: newton_solve(
            F, jnp.array([1.0, 1.0]), t, tol=1e-10, natural_monotonicity=True,
            noise_floor=floor)))(ths)
        jax.block_until_ready(r.x)
        jax.effects_barrier()
        out[floor] = (r, len(calls))
    (r0, n0), (r1, n1) = out[False], out[True]
    assert bool(jnp.all(r0.converged)) and bool(jnp.all(r1.converged))
    np.testing.assert_array_equal(np.asarray(r1.steps), np.asarray(r0.steps))
    np.testing.assert_allclose(np.asarray(r1.x), np.asarray(r0.x), rtol=1e-10)
    assert n1 < n0, (n1, n0)


def test_implicit_solution_attaches_the_derivative_of_a_root_found_elsewhere():
    # a root found by closed form, the derivative attached: jacfwd, jacrev, second
    # derivatives and a closure over a traced value as for newton_solve
    def attached(th):
        return implicit_solution(cube_root_system, jax.lax.stop_gradient(exact(th)), th)

    np.testing.assert_allclose(attached(TH), exact(TH), rtol=0)
    for jac in (jax.jacfwd, jax.jacrev):
        np.testing.assert_allclose(jac(attached)(TH), jax.jacfwd(exact)(TH), rtol=1e-12)
    np.testing.assert_allclose(jax.hessian(lambda th: attached(th)[1])(TH),
                               jax.hessian(lambda th: exact(th)[1])(TH), rtol=1e-10)

    def root(a):   # sin x = a th: the derivative flows through the closure over a
        x = jax.lax.stop_gradient(jnp.arcsin(a * 0.5))
        return implicit_solution(lambda z, th: jnp.sin(z) - a * th, x, 0.5)

    np.testing.assert_allclose(jax.grad(root)(0.6), 0.5 / np.sqrt(1 - 0.3 ** 2), rtol=1e-12)
    # the rule is evaluated at the x given: d sqrt(t)/dt = 1/(2 x) = 0.25 at x = 2
    np.testing.assert_allclose(jax.grad(lambda th: implicit_solution(
        lambda z, t: z ** 2 - t, jnp.asarray(2.0), th))(4.0), 0.25, rtol=1e-12)
    # and no derivative flows into x itself
    assert float(jax.grad(lambda x: implicit_solution(lambda z, t: z ** 2 - t, x, 4.0))(2.0)) == 0.0


def test_split_derivative_continuation_matches_newton_through_a_scan():
    # a continuation of x^3 + a x = t over t, solved frozen in a scan and attached
    # after it: values, jacfwd and grad (with respect to the traced closure value a and
    # the scanned t) equal those of newton_solve inside the scan
    ts = jnp.linspace(0.5, 3.0, 6)

    def F(x, t, a):
        return x ** 3 + a * x - t

    def by_newton(a, ts):
        def step(x, t):
            s = newton_solve(lambda z, tt: F(z, tt, a), x, t)
            return s.x, s.x
        return jax.lax.scan(step, jnp.asarray(0.5), ts)[1]

    def by_split(a, ts):
        frozen, attach = split_derivative(lambda z, tt: F(z, tt, a), jnp.asarray(0.5), ts[0])

        def step(x, t):
            s = newton_solve(frozen, x, t)
            return s.x, s.x
        xs = jax.lax.scan(step, jnp.asarray(0.5), jax.lax.stop_gradient(ts))[1]
        return jax.vmap(attach)(xs, ts)

    a = 1.3
    np.testing.assert_allclose(by_split(a, ts), by_newton(a, ts), rtol=1e-14)
    for argnums in (0, 1):
        np.testing.assert_allclose(jax.jacfwd(by_split, argnums)(a, ts),
                                   jax.jacfwd(by_newton, argnums)(a, ts), rtol=1e-12)
    g = jax.grad(lambda a, ts: jnp.sum(by_split(a, ts) ** 2), (0, 1))(a, ts)
    h = 1e-6
    fd = (jnp.sum(by_split(a + h, ts) ** 2) - jnp.sum(by_split(a - h, ts) ** 2)) / (2 * h)
    np.testing.assert_allclose(g[0], fd, rtol=1e-8)
    # dx/dt = 1/(3x^2 + a) at each root, closed form
    xs = by_split(a, ts)
    np.testing.assert_allclose(jnp.diag(jax.jacfwd(by_split, 1)(a, ts)), 1 / (3 * xs ** 2 + a),
                               rtol=1e-12)
    # frozen cuts every derivative through the closure
    assert float(jax.grad(lambda b: split_derivative(lambda z, tt: F(z, tt, b), jnp.asarray(0.5),
                                                     1.0)[0](1.0, 1.0))(a)) == 0.0


@pytest.mark.parametrize("n", [1, 2, 3, 4])
def test_small_solve_is_the_factorised_solve(n):
    """solve_small (closed form for n <= 3) against numpy's LU solve on a seeded sweep
    of well-conditioned and badly scaled systems, vector and matrix right-hand sides;
    jitted and vmapped; a singular matrix gives non-finite values (the Newton step's
    failure test relies on it)."""
    rng = np.random.default_rng(n)
    for k in range(20):
        A = rng.normal(size=(n, n)) + 3.0 * np.eye(n)
        A = A * 10.0 ** rng.uniform(-3, 3, size=(n, 1))       # rows of other units
        for b in (rng.normal(size=n), rng.normal(size=(n, 3))):
            ref = np.linalg.solve(A, b)
            got = np.asarray(jax.jit(solve_small)(jnp.asarray(A), jnp.asarray(b)))
            np.testing.assert_allclose(got, ref, rtol=1e-11, atol=1e-13 * np.abs(ref).max())
    As = rng.normal(size=(5, n, n)) + 3.0 * np.eye(n)
    bs = rng.normal(size=(5, n))
    np.testing.assert_allclose(np.asarray(jax.vmap(solve_small)(As, bs)),
                               np.linalg.solve(As, bs[..., None])[..., 0], rtol=1e-11)
    S = np.ones((n, n))
    if n > 1:
        assert not np.all(np.isfinite(np.asarray(solve_small(jnp.asarray(S), jnp.ones(n)))))
