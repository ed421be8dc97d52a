"""Objective -> gradient -> optimiser: the shared optimisation layer.

Every design study in gearjax writes a scalar objective ``fun(x) -> J`` of a flat
float64 parameter vector ``x`` (scaled by the caller to O(1)), or a residual vector
``r(x)`` for least squares, and hands it here:

* :func:`minimize_optax` -- a first-order optax optimiser (Adam by default) run as
  one jitted ``lax.scan`` over ``steps`` iterations; box bounds by projection
  (``x <- clip(x, lower, upper)`` after each update: projected gradient).  The
  gradient is ``jax.grad`` (reverse mode) or ``jax.jacfwd`` (forward mode, cheaper
  for a handful of parameters with implicit Newton solves inside).
* :func:`minimize_lbfgsb` -- bounded L-BFGS-B from jaxopt.  jaxopt is archived
  upstream; it is imported only here (lazily), with its import-time
  ``DeprecationWarning`` filtered, so that it can be replaced in one place.
* :func:`least_squares_lm` -- Levenberg-Marquardt for ``min 1/2 |r(x)|^2`` with
  exact Jacobians (user-supplied or ``jax.jacfwd``), all iterations in one jitted
  ``lax.while_loop``; optional box bounds and an auxiliary state carried from one
  accepted iterate to the next (e.g. the starting guess of an inner Newton solve).

**Status.**  Every result carries an integer ``status`` (a traced-friendly array,
so results stay pytrees and work under ``jit``/``vmap``) and a ``message`` property
that turns it into text with :func:`status_message` (concrete results only):

========  =======================  ==============================================
code      name                     meaning
========  =======================  ==============================================
0         :data:`CONVERGED`        the solver's convergence test was met
1         :data:`MAX_ITERATIONS`   the step / iteration limit was reached first
2         :data:`FAILED`           non-finite values, or no step could reduce the
                                   objective (damping exhausted)
========  =======================  ==============================================

**Compilation.**  The solvers are module-level ``jax.jit`` functions whose static
arguments are the *callables* (objective / residual function, optax optimiser) and
shape-like options (number of steps, ``maxiter``); everything else (starting point,
bounds, tolerances, the extra ``args`` of the residual function) is traced.  A
second call with the same callable objects and the same shapes therefore reuses
the compiled program; a new ``lambda`` or ``functools.partial`` per call (or a new
``optax.adam(...)`` object) is a new static argument and compiles again -- pass
data through ``args`` and keep the callables at module level.

Neither prints.  References: Kingma & Ba, "Adam: a method for stochastic
optimization" (2015); Byrd, Lu, Nocedal & Zhu, "A limited memory algorithm for
bound constrained optimization" (1995); Moré, "The Levenberg-Marquardt algorithm:
implementation and theory" (1978); Madsen, Nielsen & Tingleff, "Methods for
non-linear least squares problems" (2nd ed., 2004); Nielsen, "Damping parameter in
Marquardt's method" (1999); Marquardt, "An algorithm for least-squares estimation of
nonlinear parameters" (1963); Bertsekas, "Projected Newton methods for optimization
problems with simple constraints" (1982).
"""

from __future__ import annotations

import functools
import warnings
from typing import Any, Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import optax

__all__ = ["CONVERGED", "MAX_ITERATIONS", "FAILED", "STATUS_MESSAGES", "status_message",
           "OptResult", "LMResult", "value_and_grad", "minimize_optax", "minimize_lbfgsb",
           "least_squares_lm"]

CONVERGED = 0
MAX_ITERATIONS = 1
FAILED = 2
STATUS_MESSAGES = {
    CONVERGED: "converged",
    MAX_ITERATIONS: "step limit reached before the convergence test was met",
    FAILED: "failed: non-finite values or no step reduced the objective",
}


def status_message(status) -> str:
    """Text for a status code (:data:`CONVERGED` 0, :data:`MAX_ITERATIONS` 1,
    :data:`FAILED` 2); ``status`` must be concrete (a Python int or a 0-d array)."""
    code = int(status)
    if code not in STATUS_MESSAGES:
        raise ValueError(f"status = {code} is not a gearjax.optimize status code")
    return STATUS_MESSAGES[code]


def status_properties():
    """``(message, converged)``: the two properties every result with an integer
    ``status`` field has (``message``: :func:`status_message`; ``converged``: status
    :data:`CONVERGED`; concrete results only)."""
    return (property(lambda self: status_message(self.status),
                     doc="the text of ``status``"),
            property(lambda self: int(self.status) == CONVERGED,
                     doc="``status`` is CONVERGED"))


class OptResult(NamedTuple):
    """x: final parameters; value: objective there; history: objective before each
    step (``steps`` values) ; x_history: parameters before each step
    (``steps, n``); grad_norm: ``|grad|`` at ``x`` (of the projected problem: the
    components pushing against an active bound are dropped); steps: iterations;
    status: 0 converged, 1 step limit, 2 failed (module docstring); ``message``:
    its text."""

    x: jnp.ndarray
    value: jnp.ndarray
    history: jnp.ndarray
    x_history: jnp.ndarray
    grad_norm: jnp.ndarray
    steps: int
    status: jnp.ndarray = np.asarray(MAX_ITERATIONS)

    message, converged = status_properties()


def value_and_grad(fun: Callable, mode: str = "rev") -> Callable:
    """``x -> (fun(x), grad)`` by reverse (``"rev"``) or forward (``"fwd"``) mode."""
    if mode == "rev":
        return jax.value_and_grad(fun)
    if mode == "fwd":
        def twice(x):
            y = fun(x)
            return y, y

        def vg(x):
            # the value as the primal of the same forward-mode pass (one evaluation of
            # ``fun``, not two)
            g, y = jax.jacfwd(twice, has_aux=True)(x)
            return y, g
        return vg
    raise ValueError(f"mode = {mode!r} must be 'rev' or 'fwd'")


def _projected_grad(x, g, lower, upper):
    at_lo = (x <= lower) & (g > 0)
    at_hi = (x >= upper) & (g < 0)
    return jnp.where(at_lo | at_hi, 0.0, g)


def _projected_grad_norm(x, g, lower, upper):
    return jnp.linalg.norm(_projected_grad(x, g, lower, upper))


def _bounds(x0, lower, upper):
    lo = jnp.full_like(x0, -jnp.inf) if lower is None else jnp.broadcast_to(
        jnp.asarray(lower, float), x0.shape)
    hi = jnp.full_like(x0, jnp.inf) if upper is None else jnp.broadcast_to(
        jnp.asarray(upper, float), x0.shape)
    return lo, hi


_DEFAULT_ADAM = optax.adam(1e-2)


@functools.partial(jax.jit, static_argnames=("fun", "opt", "steps", "mode"))
def _optax_run(fun, opt, steps, mode, x0, lo, hi, gtol, args):
    vg = value_and_grad(lambda x: fun(x, *args), mode)
    x0 = jnp.clip(x0, lo, hi)

    def step(carry, _):
        x, state = carry
        v, g = vg(x)
        upd, state = opt.update(g, state, x)
        xn = jnp.clip(optax.apply_updates(x, upd), lo, hi)
        return (xn, state), (v, x)

    (x, _), (hist, xs) = jax.lax.scan(step, (x0, opt.init(x0)), None, length=steps)
    v, g = vg(x)
    gn = _projected_grad_norm(x, g, lo, hi)
    finite = jnp.isfinite(v) & jnp.all(jnp.isfinite(x)) & jnp.isfinite(gn)
    status = jnp.where(~finite, FAILED, jnp.where(gn <= gtol, CONVERGED, MAX_ITERATIONS))
    return x, v, hist, xs, gn, status


def minimize_optax(fun: Callable, x0, *, optimizer=None, steps: int = 100, lower=None,
                   upper=None, mode: str = "rev", gtol: float | None = None,
                   args: tuple = ()) -> OptResult:
    """Minimise ``fun`` from ``x0`` with an optax optimiser in a jitted ``lax.scan``.

    ``optimizer``: an ``optax.GradientTransformation`` (default ``optax.adam(1e-2)``);
    ``lower``/``upper``: box bounds (scalars or arrays; projection after each step);
    ``mode``: gradient by ``"rev"`` or ``"fwd"`` mode; ``args``: extra (traced)
    arguments, ``fun(x, *args)``.  ``x0`` is projected first.  The run always takes
    ``steps`` updates; ``status`` is :data:`FAILED` when the final point, value or
    gradient is non-finite, :data:`CONVERGED` when ``gtol`` is given and the
    projected gradient norm at the end is ``<= gtol``, else :data:`MAX_ITERATIONS`
    (a fixed-step run has no convergence test of its own).  Compiled once per
    (``fun``, ``optimizer``, ``steps``, ``mode``, shape of ``x0`` and ``args``).
    """
    steps = int(steps)
    if steps < 1:
        raise ValueError(f"steps = {steps} must be >= 1")
    if mode not in ("rev", "fwd"):
        raise ValueError(f"mode = {mode!r} must be 'rev' or 'fwd'")
    x0 = jnp.asarray(x0, float)
    lo, hi = _bounds(x0, lower, upper)
    opt = _DEFAULT_ADAM if optimizer is None else optimizer
    gt = -1.0 if gtol is None else float(gtol)
    x, v, hist, xs, gn, status = _optax_run(fun, opt, steps, mode, x0, lo, hi, gt, tuple(args))
    return OptResult(x, v, hist, xs, gn, steps, status)


def _jaxopt():
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=DeprecationWarning)
        import jaxopt
    return jaxopt


@functools.partial(jax.jit, static_argnames=("fun", "maxiter", "tol"))
def _lbfgsb_run(fun, maxiter, tol, x0, lo, hi, args):
    solver = _jaxopt().LBFGSB(fun=fun, maxiter=maxiter, tol=tol)
    x0 = jnp.clip(x0, lo, hi)
    state = solver.init_state(x0, (lo, hi), *args)

    def step(carry, _):
        x, st = carry
        v = fun(x, *args)
        done = st.error <= tol
        xn, stn = solver.update(x, st, (lo, hi), *args)
        x = jnp.where(done, x, xn)
        st = jax.tree_util.tree_map(lambda a, b: jnp.where(done, a, b), st, stn)
        return (x, st), (v, x)

    (x, st), (hist, xs) = jax.lax.scan(step, (x0, state), None, length=maxiter)
    v, g = jax.value_and_grad(fun)(x, *args)
    gn = _projected_grad_norm(x, g, lo, hi)
    finite = jnp.isfinite(v) & jnp.all(jnp.isfinite(x)) & jnp.isfinite(st.error)
    status = jnp.where(~finite, FAILED, jnp.where(st.error <= tol, CONVERGED, MAX_ITERATIONS))
    return x, v, hist, xs, gn, st.iter_num, status


def minimize_lbfgsb(fun: Callable, x0, lower, upper, *, maxiter: int = 200,
                    tol: float = 1e-10, args: tuple = ()) -> OptResult:
    """Bounded L-BFGS-B (jaxopt) on ``fun`` from ``x0`` within ``[lower, upper]``.

    History: the objective at each accepted iterate (as many as iterations; jaxopt
    runs in a jitted while loop, so the history is recorded by a scan over
    ``maxiter`` single updates, padded with the final value after convergence).
    ``args``: extra (traced) arguments, ``fun(x, *args)``.  ``status``:
    :data:`CONVERGED` when jaxopt's projected-gradient error is ``<= tol``,
    :data:`FAILED` for non-finite values, else :data:`MAX_ITERATIONS`.
    Compiled once per (``fun``, ``maxiter``, ``tol``, shape of ``x0``).
    """
    x0 = jnp.asarray(x0, float)
    lo, hi = _bounds(x0, lower, upper)
    x, v, hist, xs, gn, it, status = _lbfgsb_run(fun, int(maxiter), float(tol), x0, lo, hi,
                                                 tuple(args))
    return OptResult(x, v, hist, xs, gn, int(it), status)


# --------------------------------------------------------------------------------------
# Levenberg-Marquardt
# --------------------------------------------------------------------------------------


class LMResult(NamedTuple):
    """Outcome of :func:`least_squares_lm` (a pytree; arrays).

    x : (n,) final (last accepted) parameters; residual : (m,) ``r(x)``;
    jacobian : (m, n) ``dr/dx`` at ``x``; aux : the auxiliary state of the last
    accepted evaluation (``None`` for a stateless residual); cost : ``1/2 |r|^2``;
    grad_norm : infinity norm of the projected gradient ``J^T r``;
    iterations : accepted steps; evaluations : residual (+ Jacobian) evaluations,
    the start included; status : 0 converged, 1 step limit, 2 failed;
    damping : final Marquardt parameter ``mu``; history : (history_size,) cost at
    the start and after each accepted step, NaN-padded; residual_history :
    (history_size,) ``max |r_i|`` likewise.  ``message``: text of the status.  After
    a failed start, ``residual``/``jacobian``/``aux`` are those of ``x0``.
    """

    x: jnp.ndarray
    residual: jnp.ndarray
    jacobian: jnp.ndarray
    aux: Any
    cost: jnp.ndarray
    grad_norm: jnp.ndarray
    iterations: jnp.ndarray
    evaluations: jnp.ndarray
    status: jnp.ndarray
    damping: jnp.ndarray
    history: jnp.ndarray
    residual_history: jnp.ndarray

    message, converged = status_properties()


_RUNNING = -1


def _normalised(fun, jacobian, stateful):
    """``(x, aux, args) -> (r, J, aux_new, ok)`` from the four calling conventions."""
    def f(x, aux, args):
        if stateful and jacobian:
            r, J, aux_n, ok = fun(x, aux, *args)
        elif stateful:
            def rfun(z):
                out = fun(z, aux, *args)          # (r, aux_new, ok)
                return out[0], out
            J, (r, aux_n, ok) = jax.jacfwd(rfun, has_aux=True)(x)
        else:
            if jacobian:
                r, J = fun(x, *args)
            else:
                def rfun(z):
                    out = fun(z, *args)
                    return out, out
                J, r = jax.jacfwd(rfun, has_aux=True)(x)
            aux_n, ok = aux, jnp.asarray(True)
        r = jnp.asarray(r, float)
        J = jnp.asarray(J, float)
        ok = jnp.asarray(ok, bool) & jnp.all(jnp.isfinite(r)) & jnp.all(jnp.isfinite(J))
        return r, J, aux_n, ok
    return f


@functools.partial(jax.jit, static_argnames=("fun", "jacobian", "stateful", "history_size"))
def _lm_run(fun, jacobian, stateful, history_size, x0, aux0, args, lo, hi, maxiter, atol, ftol,
            gtol, xtol, damping0, max_rejections, diag_floor, nielsen, down, up, damping_min):
    f = jax.jit(_normalised(fun, jacobian, stateful))
    x0 = jnp.clip(x0, lo, hi)
    # one trace of the residual function: its shapes here, the same (cached) trace in the loop
    r_s, J_s, aux_s, _ = jax.eval_shape(f, x0, aux0, args)
    zeros = lambda s: jnp.zeros(s.shape, s.dtype)
    nan_hist = jnp.full((history_size,), jnp.nan, dtype=jnp.float64)

    def converged_at(x, r, J, step, accepted):
        g = _projected_grad(x, J.T @ r, lo, hi)
        small_r = jnp.max(jnp.abs(r), initial=0.0) <= atol
        small_g = jnp.max(jnp.abs(g), initial=0.0) <= gtol
        small_x = accepted & (jnp.linalg.norm(step) <= xtol * (jnp.linalg.norm(x) + xtol))
        return small_r | small_g | small_x

    # carry: (x, r, J, aux, cost, mu, nu, k, evals, rejections, status, hist, rhist, started)
    init = (x0, zeros(r_s), zeros(J_s), aux0, jnp.asarray(jnp.inf), jnp.asarray(damping0, float),
            jnp.asarray(2.0, jnp.float64),
            *(jnp.asarray(i, dtype=int) for i in (0, 0, 0, _RUNNING)),
            nan_hist, nan_hist, jnp.asarray(False))

    def cond(c):
        return c[10] == _RUNNING

    def body(c):
        x, r, J, aux, cost, mu, nu, k, nev, nrej, status, hist, rhist, started = c
        # Marquardt-scaled damped normal equations (Moré 1978, with D^2 = diag(J^T J))
        A = J.T @ J
        g = J.T @ r
        D = jnp.diag(A) + diag_floor
        # variables on a bound with the gradient pushing outwards are held fixed (the
        # reduced system of the free ones is solved; projected Newton, Bertsekas 1982)
        fixed = ((x <= lo) & (g > 0)) | ((x >= hi) & (g < 0)) | (lo >= hi)
        both = fixed[:, None] | fixed[None, :]
        M = jnp.where(both, 0.0, A) + jnp.diag(jnp.where(fixed, 1.0, mu * D))
        h = -jnp.linalg.solve(M, jnp.where(fixed, 0.0, g))
        x_t = jnp.where(started, jnp.clip(x + h, lo, hi), x)
        h = x_t - x
        r_t, J_t, aux_t, ok_t = f(x_t, aux, args)
        cost_t = 0.5 * jnp.dot(r_t, r_t)
        ok_t = ok_t & jnp.isfinite(cost_t)
        nev = nev + 1
        # gain ratio rho = actual / predicted reduction of the cost (Madsen et al. 2004)
        # (actual reduction as 1/2 (r - r_t).(r + r_t): resolved below the rounding of F)
        pred = -(jnp.dot(g, h) + 0.5 * jnp.dot(h, A @ h))
        actred = 0.5 * jnp.dot(r - r_t, r + r_t)
        rho = actred / jnp.where(pred > 0, pred, 1.0)
        # below the rounding of the cost the actual reduction is noise of either sign;
        # there a step that lowers the projected gradient is taken (near a minimum the
        # gradient, not the cost, still resolves the distance to it)
        in_noise = jnp.abs(actred) <= 64.0 * jnp.finfo(jnp.float64).eps * (cost + cost_t)
        g_now = jnp.max(jnp.abs(_projected_grad(x, g, lo, hi)), initial=0.0)
        g_t = jnp.max(jnp.abs(_projected_grad(x_t, J_t.T @ r_t, lo, hi)), initial=0.0)
        decrease = (actred > 0) | (in_noise & (g_t < g_now))
        accept_step = started & ok_t & (pred > 0) & decrease
        accept = jnp.where(started, accept_step, ok_t)
        # damping update of Nielsen (1999): mu *= max(1/3, 1 - (2 rho - 1)^3), nu = 2 on
        # acceptance; mu *= nu, nu *= 2 on rejection.  Or Marquardt's (1963) fixed
        # factors: mu /= down on acceptance, mu *= up on rejection
        mu_acc = jnp.where(nielsen, mu * jnp.maximum(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3),
                           mu / down)
        mu_rej = jnp.where(nielsen, mu * nu, mu * up)
        mu_n = jnp.where(started, jnp.where(accept, jnp.maximum(mu_acc, damping_min), mu_rej), mu)
        nu_n = jnp.where(accept, 2.0, 2.0 * nu)
        # the start evaluation is kept even when invalid (the result then reports it)
        take = accept | ~started
        sel = lambda a, b: jax.tree_util.tree_map(lambda p, q: jnp.where(take, p, q), a, b)
        x, r, J, aux = sel((x_t, r_t, J_t, aux_t), (x, r, J, aux))
        cost = jnp.where(take, cost_t, cost)
        k_n = k + jnp.where(started & accept, 1, 0)
        hist = jnp.where(take, hist.at[k_n].set(cost, mode="drop"), hist)
        rhist = jnp.where(take, rhist.at[k_n].set(jnp.max(jnp.abs(r), initial=0.0), mode="drop"),
                          rhist)
        nrej = jnp.where(accept, 0, nrej + 1)
        # a valid trial rejected with actual and predicted reductions of the cost both
        # <= ftol F (MINPACK's relative-reduction test, Moré 1978): nothing is left to
        # gain at this floating-point precision
        small_f = (started & ~accept & ok_t & (jnp.abs(actred) <= ftol * cost)
                   & (pred <= ftol * cost))
        conv = (accept & converged_at(x, r, J, h, started & accept)) | small_f
        failed = (~started & ~ok_t) | (nrej >= max_rejections) | ~jnp.isfinite(mu_n)
        status = jnp.where(conv, CONVERGED,
                           jnp.where(failed, FAILED,
                                     jnp.where(k_n >= maxiter, MAX_ITERATIONS, _RUNNING)))
        return (x, r, J, aux, cost, mu_n, nu_n, k_n, nev, nrej, status, hist, rhist,
                jnp.asarray(True))

    x, r, J, aux, cost, mu, _, k, nev, _, status, hist, rhist, _ = jax.lax.while_loop(
        cond, body, init)
    gn = jnp.max(jnp.abs(_projected_grad(x, J.T @ r, lo, hi)), initial=0.0)
    return LMResult(x, r, J, aux, cost, gn, k, nev, status, mu, hist, rhist)


def least_squares_lm(fun: Callable, x0, args: tuple = (), *, aux0=None, jacobian: bool = False,
                     lower=None, upper=None, atol: float = 0.0, ftol: float = 1e-12,
                     gtol: float = 1e-10, xtol: float = 1e-12, maxiter: int = 100,
                     max_rejections: int = 12, damping0: float = 1e-3,
                     damping_factors: tuple[float, float] | None = None,
                     damping_min: float = 1e-15, diag_floor: float = 1e-12,
                     history_size: int | None = None) -> LMResult:
    """Levenberg-Marquardt for ``min_x 1/2 |r(x)|^2`` (``lower <= x <= upper``), jitted.

    **Calling conventions** (``args``: a tuple of arrays / pytrees passed on
    unchanged and traced, so new values do not recompile):

    * stateless (``aux0=None``): ``fun(x, *args) -> r``, or ``-> (r, J)`` with
      ``jacobian=True``;
    * stateful (``aux0`` given): ``fun(x, aux, *args) -> (r, aux_new, ok)``, or
      ``-> (r, J, aux_new, ok)`` with ``jacobian=True``.  ``aux`` is an auxiliary
      state with a fixed pytree structure and shapes (``aux_new`` must match
      ``aux0``): the ``aux_new`` of the last *accepted* evaluation is passed to the
      next one (e.g. the starting guess of an inner Newton solve) and returned as
      ``LMResult.aux``.  ``ok`` (bool) False marks an evaluation as invalid.

    Without ``jacobian=True`` the Jacobian is ``jax.jacfwd`` of ``r`` (exact; forward
    mode suits the few-parameter problems here).  An evaluation with non-finite
    ``r`` or ``J`` or ``ok`` False is never accepted; at the start it ends the run
    with :data:`FAILED`.

    **Iteration** (Moré 1978; Madsen, Nielsen & Tingleff 2004, Algorithm 3.16): at
    ``x`` with ``A = J^T J``, ``g = J^T r`` and Marquardt's diagonal scaling
    ``D = diag(A) + diag_floor``, the step solves ``(A + mu D) h = -g``, reduced to
    the free variables (a variable on a bound with ``g`` pushing outwards keeps
    ``h_i = 0``; projected Newton, Bertsekas 1982); the trial point is
    ``clip(x + h, lower, upper)`` (projection).  With the predicted
    reduction ``L(0) - L(h) = -(g.h + 1/2 h.A h)`` and the gain ratio
    ``rho = (F(x) - F(x + h)) / (L(0) - L(h))`` (``F = 1/2 |r|^2``) the step is
    accepted when it is valid and reduces ``F`` (``rho > 0``); then
    ``mu <- mu max(1/3, 1 - (2 rho - 1)^3)``, ``nu <- 2``, else ``mu <- nu mu``,
    ``nu <- 2 nu`` (Nielsen 1999); with ``damping_factors=(down, up)`` Marquardt's
    (1963) fixed factors instead: ``mu <- mu / down`` on acceptance, ``mu <- up mu``
    on rejection.  ``damping0`` is the initial (relative) ``mu``, ``damping_min``
    its floor after an acceptance.

    **Stopping** (``status``): :data:`CONVERGED` when, at an accepted point,
    ``max |r_i| <= atol``, or ``max |P(J^T r)|_i <= gtol`` (``P``: the components
    pushing against an active bound dropped), or the accepted step satisfies
    ``|h| <= xtol (|x| + xtol)``, or when a valid trial is rejected with both the
    actual and the predicted change of ``F`` ``<= ftol F`` (MINPACK's relative
    reduction test, Moré 1978: no step can reduce the cost at this floating-point
    precision) -- set a tolerance to 0 to switch its test off;
    :data:`MAX_ITERATIONS` after ``maxiter`` accepted steps; :data:`FAILED` after
    ``max_rejections`` consecutive rejected trials (no step reduces ``F``) or an
    invalid start.  At most ``1 + maxiter * max_rejections`` evaluations.

    **Bounds** ``lower``/``upper`` (scalars or arrays, default unbounded): ``x0`` is
    projected first; a variable with ``lower == upper`` is held fixed.

    **History**: ``history_size`` entries (default ``maxiter + 1``); steps beyond
    it are not recorded.

    **Compilation**: one compiled program per (``fun``, ``jacobian``, stateful or
    not, ``history_size``) and shapes / pytree structure of ``x0``, ``aux0``,
    ``args`` (module docstring; ``maxiter`` and the tolerances are traced);
    ``fun`` is traced once per compile.
    """
    maxiter = int(maxiter)
    if maxiter < 1:
        raise ValueError(f"maxiter = {maxiter} must be >= 1")
    history_size = maxiter + 1 if history_size is None else int(history_size)
    if history_size < 1:
        raise ValueError(f"history_size = {history_size} must be >= 1")
    if int(max_rejections) < 1:
        raise ValueError(f"max_rejections = {max_rejections} must be >= 1")
    x0 = jnp.asarray(x0, float)
    if x0.ndim != 1:
        raise ValueError(f"x0 must be a 1-d parameter vector, got shape {x0.shape}")
    lo, hi = _bounds(x0, lower, upper)
    stateful = aux0 is not None
    if damping_factors is None:
        down, up = 1.0, 1.0
    else:
        down, up = (float(a) for a in damping_factors)
        if not (down > 1.0 and up > 1.0):
            raise ValueError(f"damping_factors = {damping_factors} must both be > 1")
    f64 = lambda v: jnp.asarray(v, float)
    return _lm_run(fun, bool(jacobian), stateful, history_size, x0, aux0, tuple(args), lo, hi,
                   jnp.asarray(maxiter), f64(atol), f64(ftol), f64(gtol), f64(xtol),
                   f64(damping0), jnp.asarray(int(max_rejections)), f64(diag_floor),
                   jnp.asarray(damping_factors is None), f64(down), f64(up), f64(damping_min))
