"""Newton's method for square systems with implicit differentiation.

Solves ``F(x, theta) = 0`` for ``x`` (a scalar or a 1-D array) given parameters
``theta`` (any pytree).  The Jacobian ``dF/dx`` comes from forward-mode autodiff.
Each iteration takes the full Newton step ``dx = -J^{-1} F`` and backtracks
(halving, Armijo condition on ``max|F|``) when the step does not reduce the residual;
with ``natural_monotonicity=True`` a step is also accepted when it passes Deuflhard's
natural monotonicity test (the simplified Newton correction shrinks); with
``noise_floor=True`` the confirming step of a converged iterate is taken without a
line search.

Derivatives of the solution with respect to ``theta`` are **not** obtained by
differentiating through the iterations.  The solution map carries a
``jax.custom_jvp`` rule from the implicit function theorem,

    F(x*(theta), theta) = 0   =>   dx* = -(dF/dx)^{-1} (dF/dtheta) dtheta,

evaluated at the converged root.  Because the rule is linear in ``dtheta`` JAX can
transpose it, so forward mode (``jax.jvp``, ``jax.jacfwd``) and reverse mode
(``jax.grad``, ``jax.jacrev``) both work, as do higher derivatives (the rule is
itself differentiable) and ``vmap``/``jit``.  Functions ``F`` may close over traced
values; they are hoisted into explicit parameters with ``jax.closure_convert`` so
that derivatives flow through them too.

The rule differentiates ``F`` only with respect to the parameters whose tangent is
not a symbolic zero, so a solve nested in another solve's Jacobian does not carry
zero tangents through ``F``.  An eager call (outside any trace, parameters concrete
arrays) runs as one ``jax.jit`` program cached on ``F`` (by identity) and the
options: a module-level ``F`` is traced and compiled once per process.

:func:`implicit_solution` attaches the same rule to a root found by another route, and
:func:`split_derivative` splits it off a continuation: the ``lax.scan`` of solves runs
without derivatives and each root gets its derivative after the scan (one ``vmap``),
so that a gradient does not linearise the scan and its Newton loop.

Every solve returns a :class:`NewtonResult` with the residual norm
``max|F(x)|``, the number of Newton steps and a ``converged`` flag
(finite, residual <= ``tol``).  Nothing here raises on non-convergence — that is
for the public entry points, which check the flags on concrete values.

Reference: Nocedal & Wright, *Numerical Optimization*, 2nd ed., ch. 11 (Newton with
line search); [Deuflhard2004] §3.3 (natural monotonicity); Blondel et al.,
"Efficient and modular implicit differentiation", NeurIPS 2022 (implicit function
theorem for root finding).
"""

from __future__ import annotations

from functools import partial
from typing import Any, Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from jax.custom_derivatives import SymbolicZero

__all__ = ["NewtonResult", "newton_solve", "implicit_solution", "split_derivative",
           "implicit_root", "solve_small"]


class NewtonResult(NamedTuple):
    """Outcome of :func:`newton_solve`.

    Attributes
    ----------
    x : root estimate, same shape as ``x0``.
    residual : ``max|F(x, theta)|`` at ``x`` (same units as ``F``).
    steps : number of Newton steps taken (int).
    converged : True when ``x`` and the residual are finite and residual <= tol.
    """

    x: Any
    residual: Any
    steps: Any
    converged: Any


def with_value(f):
    """``f`` returning its value twice: ``jacfwd(.., has_aux=True)`` then gives the
    Jacobian and the value of one forward-mode pass (the value is not traced, nor
    compiled, a second time; also :mod:`gearjax.surfaces`)."""
    def g(*args):
        y = f(*args)
        return y, y
    return g


def _value_and_jacobian(f, x):
    """``(f(x), df/dx)`` (n, n x n) of ``f: (n,) -> (n,)`` from one forward-mode pass
    (the value is the primal of the same ``jvp``: one trace of ``f``, not two); one
    ``jvp`` for n = 1 (a scalar solve -- the envelope of a generated flank -- is the
    innermost and most often repeated; ``jacfwd`` would wrap it in a batch of one)."""
    if x.shape[0] == 1:
        y, t = jax.jvp(f, (x,), (jnp.ones_like(x),))
        return y, jnp.reshape(t, (1, 1))
    J, y = jax.jacfwd(with_value(f), has_aux=True)(x)
    return y, J


def _jacobian(f, x):
    """``df/dx`` (n x n) of ``f: (n,) -> (n,)`` (:func:`_value_and_jacobian`)."""
    return _value_and_jacobian(f, x)[1]


def solve_small(A, b):
    """``A^-1 b`` for a square ``A`` (n x n) and ``b`` of shape (n,) or (n, k).

    n <= 3 in closed form, ``adj(A) b / det(A)`` (Cramer's rule: for n = 3 the columns
    of ``adj(A)`` are the cross products of A's rows, ``det A = a_0 . (a_1 x a_2)``),
    a few fused multiply-adds instead of an LU factorisation and two triangular solves;
    larger systems by ``jnp.linalg.solve``.  A singular ``A`` gives non-finite values,
    as the factorisation does.  The per-point systems of the flank, blank and edge
    solves are 2 x 2 and 3 x 3, and so are the Weingarten maps' ``J^T J``; measured on
    the 2-core CPU: the 41 x 21 hypoid flank grid 5.8 -> 2.9-3.6 ms, 2e4 Weingarten maps
    6.3 -> 2.1 ms (docs/hypoid.md, Benchmark; the TCA and the efficiency chain, whose
    time is in the 5 x 5 contact system, unchanged within the machine's noise).  Round-off
    differs from the factorisation's; for n = 2 the rule is forward stable
    ([Higham2002]).  (One LU factorisation per Newton step, reused by the line search's
    corrections through ``lax.linalg.triangular_solve``, ran the jitted involute TCA 11 %
    slower on the CPU than solving anew each time.)"""
    n = A.shape[0]
    if n == 1:
        return b / A[0, 0]
    if n == 2:
        adj = (jnp.stack([A[1, 1], -A[1, 0]]), jnp.stack([-A[0, 1], A[0, 0]]))
        det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    elif n == 3:
        adj = (jnp.cross(A[1], A[2]), jnp.cross(A[2], A[0]), jnp.cross(A[0], A[1]))
        det = jnp.dot(A[0], adj[0])
    else:
        return jnp.linalg.solve(A, b)
    # adj[j] is column j of adj(A): x = sum_j adj[:, j] b_j / det
    tail = (1,) * (b.ndim - 1)
    return sum(jnp.reshape(c, (n,) + tail) * b[j] for j, c in enumerate(adj)) / det


def _loop(F, tol, xtol, max_steps, max_halvings, ls, x0, theta):
    """Damped Newton iterations on the flattened unknown; ``ls = (natural, floor)`` the
    line-search options of :func:`newton_solve` (``natural_monotonicity``,
    ``noise_floor``)."""
    natural, floor = ls
    shape = jnp.shape(x0)

    def f(x):
        return jnp.reshape(F(jnp.reshape(x, shape), theta), (-1,))

    x = jnp.reshape(x0, (-1,))

    def residual(fx):
        if fx.shape != x.shape:
            raise ValueError(f"F must return as many equations as unknowns: got "
                             f"{fx.shape[0]} equations for {x.shape[0]} unknowns")
        r = jnp.max(jnp.abs(fx))
        return jnp.where(jnp.isfinite(r), r, jnp.inf)

    if max_steps <= 0:
        res = residual(f(x))
        return jnp.reshape(x, shape), res, jnp.asarray(0), jnp.all(jnp.isfinite(x)) & (
            res <= tol)

    def cond(state):
        x, res, k, done = state
        return (k < max_steps) & jnp.logical_not(done)

    def body(state):
        x, _, k, _ = state
        # the residual at x and the Jacobian from one forward-mode pass: ``F`` is
        # traced here and in the line search, not a third time before the loop
        fx, J = _value_and_jacobian(f, x)
        res = residual(fx)
        dx = solve_small(J, -fx)
        ok = jnp.all(jnp.isfinite(dx))
        dx = jnp.where(ok, dx, 0.0)

        # the full step is the loop's first pass (i = -1 -> 0, alpha = 1), so ``F``
        # appears once in the line search, not twice (half the program to trace and
        # compile for an ``F`` that itself contains solves)
        dx_norm = jnp.linalg.norm(dx)
        # at the noise floor (converged, and the full step below xtol) the step is taken
        # as it is: halving a step of round-off size finds no decrease to test for
        at_floor = floor & (res <= tol) & (
            jnp.max(jnp.abs(dx)) <= xtol * (1.0 + jnp.max(jnp.abs(x))))

        def ls_cond(s):
            alpha, xn, rn, theta_n, i = s
            good = rn <= (1.0 - 1e-4 * alpha) * res
            if natural:
                good = good | (theta_n <= (1.0 - 0.25 * alpha) * dx_norm)
            return (i < 0) | ((i < max_halvings) & jnp.logical_not(good | at_floor))

        def ls_body(s):
            alpha, _, _, _, i = s
            alpha = 0.5 * alpha
            xn = x + alpha * dx
            fn = f(xn)
            rn = residual(fn)
            if natural:
                # Deuflhard's natural monotonicity test: the simplified Newton
                # correction J(x)^-1 F(x_new) is shorter than the step
                theta_n = jnp.linalg.norm(solve_small(J, fn))
                theta_n = jnp.where(jnp.isfinite(theta_n), theta_n, jnp.inf)
            else:
                theta_n = jnp.asarray(jnp.inf, x.dtype)
            return alpha, xn, rn, theta_n, i + 1

        alpha, xn, rn, _, _ = jax.lax.while_loop(
            ls_cond, ls_body, (jnp.asarray(2.0, x.dtype), x, res,
                               jnp.asarray(jnp.inf, x.dtype), -1))
        step = jnp.max(jnp.abs(alpha * dx))
        small = step <= xtol * (1.0 + jnp.max(jnp.abs(xn)))
        done = jnp.logical_not(ok) | ((rn <= tol) & small) | (rn == 0.0)
        # a failed step (singular Jacobian) leaves x where it was
        xn = jnp.where(ok, xn, x)
        rn = jnp.where(ok, rn, res)
        return xn, rn, k + 1, done

    # (the residual of the state is that of its x after each step; max_steps >= 1,
    # so the loop's first pass replaces this initial one)
    init = (x, jnp.asarray(jnp.inf, x.dtype), jnp.asarray(0), jnp.asarray(False))
    x, res, k, _ = jax.lax.while_loop(cond, body, init)
    converged = jnp.all(jnp.isfinite(x)) & jnp.isfinite(res) & (res <= tol)
    return jnp.reshape(x, shape), res, k, converged


@partial(jax.custom_jvp, nondiff_argnums=(0, 1, 2, 3, 4, 5))
def _solve(F, tol, xtol, max_steps, max_halvings, ls, x0, theta):
    return _loop(F, tol, xtol, max_steps, max_halvings, ls, jax.lax.stop_gradient(x0), theta)


def _implicit_tangent(F, xs, theta, theta_dot):
    """``dx* = -(dF/dx)^-1 (dF/dtheta) dtheta`` at the root ``xs`` of ``F(x, theta)``
    (``theta_dot`` may hold symbolic zeros)."""
    shape = jnp.shape(xs)

    def fx(x):
        return jnp.reshape(F(jnp.reshape(x, shape), theta), (-1,))

    # differentiate F only with respect to the parameters whose tangent is not a
    # symbolic zero (typically a few of the many arrays F closes over): the zero
    # tangents of the others would otherwise be carried through F, in every
    # Newton solve nested inside another's Jacobian, and traced and compiled
    leaves, treedef = jax.tree_util.tree_flatten(theta)
    t_leaves = treedef.flatten_up_to(theta_dot)
    nz = [i for i, t in enumerate(t_leaves) if not isinstance(t, SymbolicZero)]
    if not nz:
        return jnp.zeros_like(xs)

    def f_theta(*vals):
        th = list(leaves)
        for i, v in zip(nz, vals):
            th[i] = v
        return jnp.reshape(F(xs, jax.tree_util.tree_unflatten(treedef, th)), (-1,))

    J = _jacobian(fx, jnp.reshape(xs, (-1,)))
    _, f_dot = jax.jvp(f_theta, tuple(leaves[i] for i in nz), tuple(t_leaves[i] for i in nz))
    return jnp.reshape(-solve_small(J, f_dot), shape)


def _solve_jvp(F, tol, xtol, max_steps, max_halvings, ls, primals, tangents):
    x0, theta = primals
    _, theta_dot = tangents
    out = _solve(F, tol, xtol, max_steps, max_halvings, ls, x0, theta)
    x_dot = _implicit_tangent(F, out[0], theta, theta_dot)
    zero_int = np.zeros(jnp.shape(out[2]), dtype=jax.dtypes.float0)
    zero_bool = np.zeros(jnp.shape(out[3]), dtype=jax.dtypes.float0)
    return out, (x_dot, jnp.zeros_like(out[1]), zero_int, zero_bool)


_solve.defjvp(_solve_jvp, symbolic_zeros=True)


def newton_solve(F: Callable, x0, theta=(), *, tol: float = 1e-10, xtol: float = 1e-12,
                 max_steps: int = 50, max_halvings: int = 12,
                 natural_monotonicity: bool = False, noise_floor: bool = False) -> NewtonResult:
    """Solve the square system ``F(x, theta) = 0`` by damped Newton iterations.

    Parameters
    ----------
    F : callable ``F(x, theta) -> array`` with as many equations as unknowns.
        May close over other (traced) arrays; derivatives flow through them too.
    x0 : initial guess, scalar or 1-D array.  The solution does not depend on it
        (no derivative flows into ``x0``).
    theta : pytree of parameters the root is differentiated with respect to.
    tol : residual tolerance on ``max|F|`` for the converged flag (units of F).
    xtol : relative step size below which iterations stop once ``max|F| <= tol``.
    max_steps : maximum number of Newton steps.
    max_halvings : maximum number of step halvings in the backtracking line search.
    natural_monotonicity : also accept a (damped) step that passes Deuflhard's natural
        monotonicity test ``|J(x)^-1 F(x + a dx)| <= (1 - a/4) |dx|`` (the simplified
        Newton correction shrinks) when it does not reduce ``max|F|``.  For nearly
        singular systems with badly scaled equations (a long contact path near line
        contact), where the full Newton step is right but raises the residual of one
        equation and the residual test would damp the iteration to a crawl.
        Reference: [Deuflhard2004] §3.3.
    noise_floor : take the full step without a line search where the iterate has
        converged (``max|F| <= tol``) and the step is below ``xtol`` -- the last,
        confirming iteration.  Its step is of round-off size, so no decrease can be
        tested: the line search would halve it ``max_halvings`` times and, under
        ``vmap``, hold every lane of the batch that long.  The root moves by round-off
        only (the TCA's continuations use it: contacts equal to 4e-13 mm and TE to
        3e-10 arcsec with and without, docs/tca.md "Cost").

    Returns
    -------
    NewtonResult(x, residual, steps, converged).  Under ``vmap`` every field is
    batched.  ``x`` is differentiable with respect to ``theta`` (and anything ``F``
    closes over) in forward and reverse mode by the implicit function theorem.
    """
    x0 = jnp.asarray(x0, dtype=jnp.result_type(float))
    if x0.ndim > 1:
        raise ValueError(f"x0 must be a scalar or a 1-D array, got shape {x0.shape}")
    if _eager(F, x0, theta):
        # an eager call runs as one jitted program cached on ``F`` (by identity) and
        # the options: a module-level ``F`` is traced and compiled once per process
        # instead of at every call (an eager ``while_loop`` compiles its loop anew)
        return _newton_jit(F, float(tol), float(xtol), int(max_steps), int(max_halvings),
                           (bool(natural_monotonicity), bool(noise_floor)), x0, theta)
    converted, consts = jax.closure_convert(lambda x, th: F(x, th), x0, theta)

    def F_all(x, th_all):
        th, cs = th_all
        return converted(x, th, *cs)

    x, res, steps, conv = _solve(F_all, float(tol), float(xtol), int(max_steps),
                                 int(max_halvings), (bool(natural_monotonicity),
                                                     bool(noise_floor)), x0,
                                 (theta, tuple(consts)))
    return NewtonResult(x, res, steps, conv)


def implicit_solution(F: Callable, x, theta=()):
    """``x``, a root of ``F(x, theta) = 0`` found by any route, with the derivative of
    the root attached: ``dx = -(dF/dx)^-1 (dF/dtheta) dtheta`` (the rule of
    :func:`newton_solve`, the implicit function theorem), with respect to ``theta`` and
    anything ``F`` closes over.  No derivative flows into ``x`` itself.  ``x`` a scalar
    or a 1-D array."""
    return split_derivative(F, x, theta)[1](x, theta)


def split_derivative(F: Callable, x, theta):
    """``(F_frozen, attach)`` for solving ``F(x, theta) = 0`` without derivatives and
    attaching them afterwards.  ``F_frozen(x, theta)`` is ``F`` with every value it
    closes over cut from differentiation; ``attach(x, theta)`` is
    :func:`implicit_solution` of ``F`` at ``x`` (same shapes as the examples ``x``,
    ``theta``; ``vmap`` it over many roots).

    For a continuation -- a ``lax.scan`` of solves, each started from the previous
    solutions: run the scan with ``F_frozen`` on ``jax.lax.stop_gradient`` of its
    inputs, then ``vmap(attach)`` over its solutions.  ``grad`` then linearises one
    evaluation of ``F`` per root instead of the scan with its Newton loop (less to
    trace, a smaller program); values are unchanged and the derivatives are those of
    :func:`newton_solve` at the same roots.  One closure conversion serves both."""
    x = jnp.asarray(x, dtype=jnp.result_type(float))
    converted, consts = jax.closure_convert(lambda z, th: F(z, th), x, theta)
    consts = tuple(consts)
    # cut here, once, not inside ``frozen``: a scan or loop that calls ``frozen`` then
    # closes over values without derivatives, and ``grad`` passes it by (cut inside,
    # the values it closes over carry tangents: the whole scan was linearised, each
    # tangent to be zeroed again inside)
    frozen_consts = tuple(jax.lax.stop_gradient(c) for c in consts)

    def frozen(z, th):
        return converted(z, th, *frozen_consts)

    def F_all(z, th_all):
        th, cs = th_all
        return converted(z, th, *cs)

    def attach(z, th):
        return _attach(F_all, jnp.asarray(z, dtype=x.dtype), (th, consts))

    return frozen, attach


@partial(jax.custom_jvp, nondiff_argnums=(0,))
def _attach(F, x, theta):
    del F, theta
    return jax.lax.stop_gradient(x)


@partial(_attach.defjvp, symbolic_zeros=True)
def _attach_jvp(F, primals, tangents):
    x, theta = primals
    xs = _attach(F, x, theta)      # differentiable in theta again: higher derivatives
    return xs, _implicit_tangent(F, xs, theta, tangents[1])


def _eager(F, x0, theta) -> bool:
    """True for a call outside any JAX transformation: nothing is being staged (``x0``,
    made by ``jnp.asarray`` in this call, is concrete, not a tracer of ``jit``) and
    neither ``theta`` nor the arrays ``F`` closes over (its closure cells, and those of
    the functions, partials and bound methods it holds) is a tracer of
    ``grad``/``vmap``.  Public JAX only."""
    if isinstance(x0, jax.core.Tracer):
        return False
    theta_leaves = jax.tree_util.tree_leaves(theta)
    if not all(isinstance(t, jax.Array) for t in theta_leaves):
        return False
    seen, todo, leaves = set(), [F], list(theta_leaves)
    while todo:
        f = todo.pop()
        if id(f) in seen:
            continue
        seen.add(id(f))
        held = []
        for cell in getattr(f, "__closure__", None) or ():
            try:
                held.append(cell.cell_contents)
            except ValueError:       # an empty cell
                continue
        if isinstance(f, partial):
            held += [f.func, *f.args, *f.keywords.values()]
        if hasattr(f, "__self__"):   # a bound method: its object
            held.append(f.__self__)
        for v in held:
            if callable(v) and not isinstance(v, jax.Array):
                todo.append(v)
            else:
                leaves += jax.tree_util.tree_leaves(v)
    return not any(isinstance(t, jax.core.Tracer) for t in leaves)


@partial(jax.jit, static_argnums=(0, 1, 2, 3, 4, 5))
def _newton_jit(F, tol, xtol, max_steps, max_halvings, ls, x0, theta):
    return newton_solve(F, x0, theta, tol=tol, xtol=xtol, max_steps=max_steps,
                        max_halvings=max_halvings, natural_monotonicity=ls[0],
                        noise_floor=ls[1])


# ----------------------------------------------------------------------------
# elementwise roots with a fixed iteration count
# ----------------------------------------------------------------------------

def implicit_root(solve: Callable, residual: Callable, theta):
    """Root ``x(theta)`` of an *elementwise* equation ``residual(x, theta) = 0``.

    ``solve(theta) -> x`` is any forward iteration (typically a fixed number of
    safeguarded Newton or Halley steps from an explicit start, as array code with
    no loops in the trace); it is not differentiated.  ``residual`` must act
    elementwise: entry i of the result depends on entry i of ``x`` only, so its
    Jacobian in ``x`` is diagonal.  Derivatives follow from the implicit function
    theorem at the returned root,

        dx = -(∂R/∂θ · dθ) / (∂R/∂x),

    a ``jax.custom_jvp`` rule that is linear in ``dθ`` (so ``grad``/``jacrev``
    transpose it) and costs one forward-mode pass of ``residual``.  ``theta`` is a
    pytree of arrays broadcasting with ``x``; ``solve`` and ``residual`` must not
    close over traced values (pass them in ``theta``).  Works under ``jit``,
    ``vmap`` and ``grad``.  The caller computes the final residual and its own
    convergence flag (nothing here assumes the iteration converged).
    """
    return _implicit_root(solve, residual, theta)


@partial(jax.custom_jvp, nondiff_argnums=(0, 1))
def _implicit_root(solve, residual, theta):
    return jax.lax.stop_gradient(solve(jax.lax.stop_gradient(theta)))


@_implicit_root.defjvp
def _implicit_root_jvp(solve, residual, primals, tangents):
    (theta,), (theta_dot,) = primals, tangents
    x = _implicit_root(solve, residual, theta)
    r_x = jax.jvp(lambda v: residual(v, theta), (x,), (jnp.ones_like(x),))[1]
    r_t = jax.jvp(lambda th: residual(x, th), (theta,), (theta_dot,))[1]
    return x, -r_t / r_x
