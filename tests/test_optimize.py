"""gearjax.optimize: known minima of closed-form objectives (independent of the code)."""

import warnings

import jax.numpy as jnp
import numpy as np
import optax
import pytest

from gearjax import optimize


def quad(x):
    # minimum at (1, -2, 0.5), value 3
    c = jnp.array([1.0, -2.0, 0.5])
    w = jnp.array([1.0, 4.0, 0.25])
    return jnp.sum(w * (x - c) ** 2) + 3.0


def test_optax_unbounded_quadratic():
    res = optimize.minimize_optax(quad, jnp.zeros(3), optimizer=optax.adam(0.05), steps=600)
    np.testing.assert_allclose(np.asarray(res.x), [1.0, -2.0, 0.5], atol=1e-4)
    assert float(res.value) == pytest.approx(3.0, abs=1e-7)
    assert res.history.shape == (600,) and res.x_history.shape == (600, 3)
    assert float(res.history[0]) == pytest.approx(float(quad(jnp.zeros(3))))


def test_optax_box_projection_and_forward_mode():
    # box x2 >= -1 is active: constrained minimum (1, -1, 0.5), value 3 + 4
    lo = jnp.array([-5.0, -1.0, -5.0])
    res = optimize.minimize_optax(quad, jnp.zeros(3), optimizer=optax.adam(0.05), steps=600,
                                  lower=lo, upper=5.0, mode="fwd")
    np.testing.assert_allclose(np.asarray(res.x), [1.0, -1.0, 0.5], atol=1e-4)
    assert float(res.value) == pytest.approx(7.0, abs=1e-6)
    assert float(res.grad_norm) < 1e-3
    assert np.all(np.asarray(res.x_history)[:, 1] >= -1.0)


def test_lbfgsb_rosenbrock_bounded():
    def rosen(x):
        return (1 - x[0]) ** 2 + 100 * (x[1] - x[0] ** 2) ** 2
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)   # filtered inside optimize
        res = optimize.minimize_lbfgsb(rosen, jnp.array([-1.2, 1.0]), -2.0, 2.0, maxiter=200)
    np.testing.assert_allclose(np.asarray(res.x), [1.0, 1.0], atol=1e-6)
    # with x1 <= 0.5 the minimum is on the bound: x = (0.5, 0.25), f = 0.25
    res = optimize.minimize_lbfgsb(rosen, jnp.array([-1.2, 1.0]), -2.0,
                                   jnp.array([0.5, 2.0]), maxiter=200)
    np.testing.assert_allclose(np.asarray(res.x), [0.5, 0.25], atol=1e-6)
    assert float(res.value) == pytest.approx(0.25, abs=1e-10)


def test_bad_arguments():
    with pytest.raises(ValueError, match="steps"):
        optimize.minimize_optax(quad, jnp.zeros(3), steps=0)
    with pytest.raises(ValueError, match="mode"):
        optimize.value_and_grad(quad, "sideways")


# --------------------------------------------------------------------------------------
# status codes of the first-order optimisers
# --------------------------------------------------------------------------------------

def rosen_f(x):
    return (1 - x[0]) ** 2 + 100 * (x[1] - x[0] ** 2) ** 2


def test_status_codes_of_optax_and_lbfgsb():
    res = optimize.minimize_lbfgsb(rosen_f, jnp.array([-1.2, 1.0]), -2.0, 2.0, maxiter=200)
    assert int(res.status) == optimize.CONVERGED and res.converged and res.message == "converged"
    res = optimize.minimize_lbfgsb(rosen_f, jnp.array([-1.2, 1.0]), -2.0, 2.0, maxiter=2)
    assert int(res.status) == optimize.MAX_ITERATIONS and "step limit" in res.message
    # a fixed-step run without gtol has no convergence test: step limit
    res = optimize.minimize_optax(quad, jnp.zeros(3), optimizer=optax.adam(0.05), steps=600)
    assert int(res.status) == optimize.MAX_ITERATIONS
    res = optimize.minimize_optax(quad, jnp.zeros(3), optimizer=optax.adam(0.05), steps=600,
                                  gtol=1e-3)
    assert int(res.status) == optimize.CONVERGED
    res = optimize.minimize_optax(quad, jnp.zeros(3), optimizer=optax.adam(0.05), steps=5,
                                  gtol=1e-3)
    assert int(res.status) == optimize.MAX_ITERATIONS
    res = optimize.minimize_optax(lambda x: jnp.sum(jnp.sqrt(x - 1.0)), jnp.zeros(2), steps=3)
    assert int(res.status) == optimize.FAILED and res.message.startswith("failed")
    with pytest.raises(ValueError, match="status"):
        optimize.status_message(7)


_TRACES = {"f": 0, "lm": 0}


def _counted_quad(x, c):
    _TRACES["f"] += 1
    return jnp.sum((x - c) ** 2)


def test_first_order_optimisers_do_not_recompile():
    c1, c2 = jnp.array([1.0, -2.0, 0.5]), jnp.array([0.5, 0.25, -1.0])
    optimize.minimize_optax(_counted_quad, jnp.zeros(3), steps=5, args=(c1,))
    n = _TRACES["f"]
    assert n >= 1
    res = optimize.minimize_optax(_counted_quad, jnp.ones(3), steps=5, lower=-3.0, upper=3.0,
                                  args=(c2,))
    assert _TRACES["f"] == n
    assert float(res.history[0]) == pytest.approx(float(jnp.sum((1.0 - c2) ** 2)))
    optimize.minimize_lbfgsb(_counted_quad, jnp.zeros(3), -5.0, 5.0, maxiter=20, args=(c1,))
    n = _TRACES["f"]
    res = optimize.minimize_lbfgsb(_counted_quad, jnp.ones(3), -4.0, 4.0, maxiter=20, args=(c2,))
    assert _TRACES["f"] == n
    np.testing.assert_allclose(np.asarray(res.x), np.asarray(c2), atol=1e-8)
    assert res.converged


# --------------------------------------------------------------------------------------
# Levenberg-Marquardt
# --------------------------------------------------------------------------------------

def rosen_r(x):
    # 1/2 |r|^2 = 1/2 Rosenbrock: zero residual at (1, 1)
    return jnp.stack([1.0 - x[0], 10.0 * (x[1] - x[0] ** 2)])


def test_lm_rosenbrock():
    res = optimize.least_squares_lm(rosen_r, jnp.array([-1.2, 1.0]))
    np.testing.assert_allclose(np.asarray(res.x), [1.0, 1.0], atol=1e-9)
    assert res.converged and res.message == "converged"
    assert float(res.cost) < 1e-20
    # damping from the gain ratio: 20-30 accepted steps from the classical start (a
    # damping that grows on acceptance, or never shrinks, needs far more)
    assert 5 <= int(res.iterations) <= 30
    assert int(res.evaluations) > int(res.iterations) + 1    # some trials were rejected
    h = np.asarray(res.history)
    assert h[0] == pytest.approx(0.5 * (2.2 ** 2 + 4.4 ** 2))     # cost at x0 = 12.1
    k = int(res.iterations)
    assert np.all(np.diff(h[:k + 1]) < 0) and np.all(np.isnan(h[k + 1:]))
    rh = np.asarray(res.residual_history)
    assert rh[0] == pytest.approx(4.4) and rh[k] == pytest.approx(float(np.max(np.abs(res.residual))))


def test_lm_linear_least_squares_matches_lstsq():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(12, 4))
    b = rng.normal(size=12)
    ref = np.linalg.lstsq(A, b, rcond=None)[0]

    def lin(x, A, b):
        return A @ x - b
    res = optimize.least_squares_lm(lin, jnp.zeros(4), (jnp.asarray(A), jnp.asarray(b)),
                                    ftol=0.0, gtol=1e-13)
    np.testing.assert_allclose(np.asarray(res.x), ref, atol=1e-12)
    assert res.converged and float(res.grad_norm) <= 1e-11
    assert int(res.iterations) <= 8
    # gain ratio 1 on a linear problem: every step accepted, mu / 3 each time (Nielsen)
    res3 = optimize.least_squares_lm(lin, jnp.zeros(4), (jnp.asarray(A), jnp.asarray(b)),
                                     maxiter=3)
    assert int(res3.evaluations) == 4
    assert float(res3.damping) == pytest.approx(1e-3 / 27.0, rel=1e-6)
    # Marquardt's fixed factors: mu / 5 per accepted step, floored at damping_min
    res3 = optimize.least_squares_lm(lin, jnp.zeros(4), (jnp.asarray(A), jnp.asarray(b)),
                                     maxiter=3, damping_factors=(5.0, 8.0))
    assert float(res3.damping) == pytest.approx(1e-3 / 125.0, rel=1e-12)
    res3 = optimize.least_squares_lm(lin, jnp.zeros(4), (jnp.asarray(A), jnp.asarray(b)),
                                     maxiter=3, damping_factors=(5.0, 8.0), damping_min=1e-4)
    assert float(res3.damping) == pytest.approx(1e-4, rel=1e-12)
    np.testing.assert_allclose(np.asarray(res.jacobian), A, atol=1e-14)
    # default tolerances: the relative-reduction test stops at float precision of the cost
    res = optimize.least_squares_lm(lin, jnp.zeros(4), (jnp.asarray(A), jnp.asarray(b)))
    assert res.converged
    np.testing.assert_allclose(np.asarray(res.x), ref, atol=1e-6)
    assert float(res.cost) == pytest.approx(0.5 * np.sum((A @ ref - b) ** 2), rel=1e-12)


T_EXP = np.linspace(0.0, 2.0, 9)
P_EXP = np.array([2.0, -1.3, 0.5])


def exp_r(p, t, y):
    return p[0] * jnp.exp(p[1] * t) + p[2] - y


def exp_rj(p, t, y):
    e = jnp.exp(p[1] * t)
    return p[0] * e + p[2] - y, jnp.stack([e, p[0] * t * e, jnp.ones_like(t)], axis=1)


@pytest.mark.parametrize("fun, jac", [(exp_r, False), (exp_rj, True)])
def test_lm_exponential_fit_exact_data(fun, jac):
    y = P_EXP[0] * np.exp(P_EXP[1] * T_EXP) + P_EXP[2]
    res = optimize.least_squares_lm(fun, jnp.array([1.0, -0.5, 0.0]),
                                    (jnp.asarray(T_EXP), jnp.asarray(y)), jacobian=jac)
    assert res.converged
    np.testing.assert_allclose(np.asarray(res.x), P_EXP, atol=1e-10)
    assert float(np.max(np.abs(res.residual))) < 1e-10
    assert int(res.iterations) <= 20


def test_lm_bounds_and_fixed_variables():
    # x0 <= 0.5: constrained minimum (0.5, 0.25) of Rosenbrock (cost 1/2 * 0.25)
    res = optimize.least_squares_lm(rosen_r, jnp.array([-1.2, 1.0]), upper=jnp.array([0.5, 2.0]))
    assert res.converged
    np.testing.assert_allclose(np.asarray(res.x), [0.5, 0.25], atol=1e-9)
    assert float(res.cost) == pytest.approx(0.125, abs=1e-14)
    # lower == upper holds a variable: x0 = -0.5 fixed, minimum at x1 = 0.25
    res = optimize.least_squares_lm(rosen_r, jnp.array([0.0, 1.0]), lower=jnp.array([-0.5, -5.0]),
                                    upper=jnp.array([-0.5, 5.0]))
    assert res.converged
    np.testing.assert_allclose(np.asarray(res.x), [-0.5, 0.25], atol=1e-9)


def test_lm_status_step_limit_and_failure():
    res = optimize.least_squares_lm(rosen_r, jnp.array([-1.2, 1.0]), maxiter=1)
    assert int(res.status) == optimize.MAX_ITERATIONS and int(res.iterations) == 1
    assert "step limit" in res.message and not res.converged
    assert float(res.cost) < 12.1                     # the one step was a descent step

    def nan_r(x):
        return jnp.stack([x[0] - 1.0, jnp.sqrt(x[1] - 5.0)])   # NaN for x1 < 5
    res = optimize.least_squares_lm(nan_r, jnp.array([0.0, 0.0]))
    assert int(res.status) == optimize.FAILED and res.message.startswith("failed")
    assert int(res.evaluations) == 1 and int(res.iterations) == 0

    # no step can reduce the cost: a residual that is flat in x but marked invalid
    # away from the start -> every trial rejected -> failed after max_rejections
    def stuck(x, aux):
        return jnp.stack([x[0] - 1.0]), aux, x[0] == 0.0
    res = optimize.least_squares_lm(stuck, jnp.array([0.0]), aux0=jnp.zeros(()), max_rejections=5)
    assert int(res.status) == optimize.FAILED
    assert int(res.evaluations) == 6 and float(res.x[0]) == 0.0


def _limited(x, aux):
    # r = x - 3, but evaluations beyond x = 2.5 are invalid (ok False): the solver must
    # never accept them.  aux counts the evaluations it was carried through.
    return jnp.stack([x[0] - 3.0]), aux + 1.0, x[0] < 2.5


def test_lm_rejects_invalid_steps_and_carries_aux_of_accepted_ones():
    res = optimize.least_squares_lm(_limited, jnp.array([0.0]), aux0=jnp.asarray(0.0),
                                    maxiter=60)
    x = float(res.x[0])
    assert 2.4 < x < 2.5
    assert int(res.evaluations) > int(res.iterations) + 1
    # the aux passed on is the one of the last accepted evaluation: one increment per
    # accepted step plus the start, not one per evaluation
    assert float(res.aux) == int(res.iterations) + 1
    # Rosenbrock with a counting aux: rejected trials do not propagate their aux
    def counted(x, aux):
        return rosen_r(x), aux + 1.0, jnp.asarray(True)
    res = optimize.least_squares_lm(counted, jnp.array([-1.2, 1.0]), aux0=jnp.asarray(0.0))
    assert res.converged and float(res.aux) == int(res.iterations) + 1
    assert int(res.evaluations) > int(res.iterations) + 1


def _counted_exp(p, t, y):
    _TRACES["lm"] += 1
    return exp_r(p, t, y)


def test_lm_second_call_does_not_recompile():
    y = P_EXP[0] * np.exp(P_EXP[1] * T_EXP) + P_EXP[2]
    args = (jnp.asarray(T_EXP), jnp.asarray(y))
    r1 = optimize.least_squares_lm(_counted_exp, jnp.array([1.0, -0.5, 0.0]), args)
    n, size = _TRACES["lm"], optimize._lm_run._cache_size()
    assert n >= 1
    # other values (start, data, bounds, tolerances, maxiter): same program
    r2 = optimize.least_squares_lm(_counted_exp, jnp.array([1.5, -1.0, 0.2]),
                                   (args[0], args[1] * 2.0), lower=-10.0, upper=10.0,
                                   gtol=1e-12, maxiter=100)
    assert _TRACES["lm"] == n and optimize._lm_run._cache_size() == size
    assert r1.converged and r2.converged
    np.testing.assert_allclose(np.asarray(r2.x), [4.0, -1.3, 1.0], atol=1e-9)
    # another shape compiles again (the counter shows the trace)
    optimize.least_squares_lm(_counted_exp, jnp.array([1.0, -0.5, 0.0]),
                              (jnp.asarray(T_EXP[:5]), jnp.asarray(y[:5])))
    assert _TRACES["lm"] > n


def test_lm_fixed_damping_factors():
    res = optimize.least_squares_lm(rosen_r, jnp.array([-1.2, 1.0]), damping_factors=(5.0, 8.0))
    assert res.converged
    np.testing.assert_allclose(np.asarray(res.x), [1.0, 1.0], atol=1e-9)
    # a step that fails multiplies mu by 8: after k accepted steps and j rejected trials
    # mu = 1e-3 * 8^j / 5^k (the floor 1e-15 not reached here)
    k, n = int(res.iterations), int(res.evaluations)
    j = n - 1 - k
    assert j > 0
    assert float(res.damping) == pytest.approx(1e-3 * 8.0 ** j / 5.0 ** k, rel=1e-9)


def test_lm_bad_arguments():
    with pytest.raises(ValueError, match="maxiter"):
        optimize.least_squares_lm(rosen_r, jnp.zeros(2), maxiter=0)
    with pytest.raises(ValueError, match="1-d"):
        optimize.least_squares_lm(rosen_r, jnp.zeros((2, 1)))
    with pytest.raises(ValueError, match="damping_factors"):
        optimize.least_squares_lm(rosen_r, jnp.zeros(2), damping_factors=(0.5, 8.0))
