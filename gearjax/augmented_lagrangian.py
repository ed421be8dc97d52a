"""Inequality- and bound-constrained minimisation by a PHR augmented Lagrangian.

Problem (all in the caller's scaled variables; no units)::

    minimise f(x)   subject to   g(x) <= 0  (m general constraints, m may be 0),
                                 lower <= x <= upper  (either side may be +-inf).

``fun(x, *args) -> (f, g)`` returns both from one evaluation of the model.

**Outer iteration** (Powell-Hestenes-Rockafellar augmented Lagrangian, safeguarded as in
ALGENCAN).  With multipliers ``lam >= 0`` and penalty ``rho > 0``::

    L_rho(x, lam) = f(x) + 1/(2 rho) * sum_i( max(0, lam_i + rho g_i(x))^2 - lam_i^2 )

is minimised over the box (inner problem) to a tolerance ``eps_k`` that tightens as
``eps_k = max(tol, 0.1^(k+1))`` (``tol`` at once when m = 0); then::

    lam <- min(max(0, lam + rho g(x)), lam_max)          (first-order multiplier update)
    V_k  = max_i |min(-g_i(x), lam_i / rho)|             (infeasibility + complementarity)
    rho <- min(10 rho, rho_max)   if V_k > 0.5 V_{k-1}   (penalty increase)

with lam_max = 1e20 and rho_max = 1e8.  Since ``grad_x L_rho(x, lam) = grad f +
J_g^T max(0, lam + rho g)``, the inner gradient at the end is the gradient of the ordinary
Lagrangian ``f + lam^T g`` at the updated multipliers.

**Convergence** (KKT conditions, infinity norms; all three ``<= tol``)::

    stationarity     || P(x - (grad f + J_g^T lam)) - x ||      P: projection on the box
    feasibility      max(0, max_i g_i)                          (the box holds exactly)
    complementarity  max_i |min(lam_i, -g_i)|

Status: 0 (:data:`~gearjax.optimize.CONVERGED`) when the test is met, 2 (``FAILED``) when
``f``, ``g`` or the gradient turn non-finite or the solve stalls (an inner solve ends out
of steps, or in a failed line search after starting from steepest descent -- the matrix
reset after the previous failure --, having lowered ``L_rho`` by no more than 1e-12
relative, with the multipliers unchanged: every later outer iteration would repeat it
-- a kink of a piecewise-smooth objective, or a decrease below rounding), else 1
(``MAX_ITERATIONS``).
An infeasible problem ends with 1 and ``feasibility > tol``.

**Inner solver**: a projected quasi-Newton method (Bertsekas 1982) on the box.  The
eps-active set ``A`` (variables within ``min(1e-3, |P(x - grad) - x|)`` of a bound whose
gradient pushes outwards) takes a steepest-descent step; the free variables a Newton step
``B_FF d_F = -grad_F`` with a dense Powell-damped BFGS matrix ``B`` (Nocedal & Wright,
Procedure 18.2; initial scaling ``y^T y / s^T y``; carried from one outer iteration to the
next, which about halved the evaluations on the test problems; reset to the scaled identity
when a line search fails).  The step follows the projection arc
``x(a) = P(x + a d)``, ``a = 1`` first, backtracking by safeguarded quadratic interpolation
until the Armijo condition ``L(x(a)) <= L(x) + 1e-4 grad^T (x(a) - x)`` holds.  Each
inner evaluation is one ``jax.value_and_grad`` (forward + reverse) of ``L_rho`` (or, with
``derivatives="forward"``, one ``jax.jacfwd``: n tangents in one batched pass); every
evaluation of ``fun`` is counted in ``evaluations``.

Everything, outer loop included, is one ``jax.jit`` program of nested ``lax.while_loop``;
static: ``fun``, ``max_outer``, ``max_inner``, ``callback``; traced: ``x0``, bounds,
``tol``, ``rho0``, ``args`` -- so it runs under ``jax.vmap`` over ``x0`` (multi-start).

References: Hestenes, "Multiplier and gradient methods" (1969); Powell, "A method for
nonlinear constraints in minimization problems" (1969); Rockafellar, "The multiplier
method of Hestenes and Powell applied to convex programming" (1973); Conn, Gould & Toint,
"LANCELOT: a Fortran package for large-scale nonlinear optimization" (1992); Birgin &
Martinez, "Practical Augmented Lagrangian Methods for Constrained Optimization" (SIAM
2014); Bertsekas, "Projected Newton methods for optimization problems with simple
constraints" (1982); Nocedal & Wright, "Numerical Optimization" (2nd ed., 2006).
"""

from __future__ import annotations

import functools
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

# importing gearjax (here through gearjax.optimize) switches on float64
from gearjax.optimize import CONVERGED, FAILED, MAX_ITERATIONS, status_properties

__all__ = ["ConstrainedResult", "minimize_constrained"]

_RHO_MAX = 1e8
_LAM_MAX = 1e20
_MAX_BACKTRACK = 20
#: relative decrease of L_rho over an inner solve below which a failed one stalls
_STALL = 1e-12
_ARMIJO = 1e-4


class ConstrainedResult(NamedTuple):
    """x, value (f), constraints (g), multipliers (lam >= 0) at the end; the three KKT
    measures (module docstring); outer_iterations; evaluations of ``fun``; status (0
    converged, 1 iteration limit, 2 failed); per outer iteration (``max_outer`` long,
    NaN after the last): history_value, history_feasibility, history_stationarity,
    history_x ``(max_outer, n)``."""

    x: jnp.ndarray
    value: jnp.ndarray
    constraints: jnp.ndarray
    multipliers: jnp.ndarray
    stationarity: jnp.ndarray
    feasibility: jnp.ndarray
    complementarity: jnp.ndarray
    outer_iterations: jnp.ndarray
    evaluations: jnp.ndarray
    status: jnp.ndarray
    history_value: jnp.ndarray
    history_feasibility: jnp.ndarray
    history_stationarity: jnp.ndarray
    history_x: jnp.ndarray

    message, converged = status_properties()


def _pg(x, grad, lo, hi):
    """Projected-gradient measure ||P(x - grad) - x||_inf."""
    return jnp.max(jnp.abs(jnp.clip(x - grad, lo, hi) - x), initial=0.0)


def _measures(g, lam):
    feas = jnp.max(jnp.maximum(g, 0.0), initial=0.0)
    compl = jnp.max(jnp.abs(jnp.minimum(lam, -g)), initial=0.0)
    return feas, compl


def _bfgs_update(B, s, y, fresh):
    """Powell-damped BFGS update of the Hessian approximation (N&W Proc. 18.2)."""
    sy = s @ y
    ok = (sy > 1e-12 * jnp.linalg.norm(s) * jnp.linalg.norm(y)) & (s @ s > 0)
    scale = jnp.where(fresh & ok, (y @ y) / jnp.where(ok, sy, 1.0), 1.0)
    B = B * scale
    Bs = B @ s
    sBs = s @ Bs
    theta = jnp.where(sy >= 0.2 * sBs, 1.0, 0.8 * sBs / jnp.where(sBs - sy > 0, sBs - sy, 1.0))
    r = theta * y + (1.0 - theta) * Bs
    sr = s @ r
    good = (sBs > 0) & (sr > 0) & jnp.isfinite(sr)
    Bn = B - jnp.outer(Bs, Bs) / jnp.where(good, sBs, 1.0) + jnp.outer(r, r) / jnp.where(
        good, sr, 1.0)
    return jnp.where(good & jnp.all(jnp.isfinite(Bn)), Bn, B), fresh & ~good


def _direction(x, grad, B, fresh, lo, hi):
    """The projected quasi-Newton direction (module docstring)."""
    w = _pg(x, grad, lo, hi)
    tol_act = jnp.minimum(1e-3, w)
    act = (((x - lo) <= tol_act) & (grad > 0)) | (((hi - x) <= tol_act) & (grad < 0))
    M = jnp.where(act[:, None] | act[None, :], 0.0, B) + jnp.diag(act.astype(x.dtype))
    dF = jnp.linalg.solve(M, jnp.where(act, 0.0, -grad))
    d = jnp.where(act, -grad, dF)
    bad = ~jnp.all(jnp.isfinite(d)) | (jnp.where(act, 0.0, grad) @ d >= 0) | fresh
    gmax = jnp.max(jnp.abs(grad))
    return jnp.where(bad, -grad / jnp.maximum(1.0, jnp.where(fresh, gmax, 1.0)), d)


#: what the evaluation of one pass of the loop is for
_RESET, _TRIAL = 0, 1


@functools.partial(jax.jit, static_argnames=("fun", "max_outer", "max_inner", "callback",
                                             "derivatives", "m"))
def _run(fun, max_outer, max_inner, callback, x0, lo, hi, tol, rho0, args,
         derivatives="reverse", m=None):
    """One ``lax.while_loop`` with one evaluation of ``fun`` (and its gradient) per pass:
    the model appears once in the program, whatever the iteration logic around it.  A
    pass evaluates either the current point afresh (``_RESET``: at the start and after a
    multiplier update, which changes ``L_rho``) or a trial point of the line search
    (``_TRIAL``); the outer update runs in the pass where an inner solve ends.  ``m``:
    the number of constraints, else found by a trace of ``fun`` (a shape probe)."""
    n = x0.shape[0]
    if m is None:
        m = jax.eval_shape(lambda x: fun(x, *args), x0)[1].shape[0]
    dt = x0.dtype

    def aug(x, lam, rho):
        f, g = fun(x, *args)
        f = jnp.asarray(f, dt)
        g = jnp.asarray(g, dt)
        if g.size != m:
            raise ValueError(f"fun returned {g.size} constraint values; n_constraints = {m}")
        g = jnp.reshape(g, (m,))
        pen = jnp.sum(jnp.maximum(0.0, lam + rho * g) ** 2 - lam ** 2) / (2.0 * rho)
        return f + pen, (f, g)

    if derivatives == "reverse":
        vg = jax.value_and_grad(aug, has_aux=True)
    else:
        # forward mode: n tangents at once (one jvp of the model, batched)
        def vg(x, lam, rho):
            def la(x):
                L, aux = aug(x, lam, rho)
                return L, (L, aux)
            grad, (L, aux) = jax.jacfwd(la, has_aux=True)(x)
            return (L, aux), grad
    nan = jnp.nan * jnp.ones(max_outer, dt)
    z = jnp.zeros((), dt)
    max_evals = max_outer * (max_inner * (_MAX_BACKTRACK + 1) + 1)

    def cond(st):
        return (st["k"] < max_outer) & (st["status"] == MAX_ITERATIONS) & (
            st["nev"] < max_evals)

    def body(st):
        lam, rho = st["lam"], st["rho"]
        (Le, (fe, ge)), gre = vg(st["xe"], lam, rho)
        reset = st["mode"] == _RESET
        # -- the line search's test (a trial) -----------------------------------------
        dd = st["grad"] @ (st["xe"] - st["x"])
        finite_e = jnp.isfinite(Le) & jnp.all(jnp.isfinite(gre))
        ok = reset | (finite_e & (Le <= st["L"] + _ARMIJO * dd))
        moved = jnp.max(jnp.abs(st["xe"] - st["x"])) > 1e-15 * (1.0 + jnp.max(jnp.abs(st["x"])))
        give_up = ~ok & ((st["bt"] >= _MAX_BACKTRACK) | ~moved)
        Bn, fresh_n = _bfgs_update(st["B"], st["xe"] - st["x"], gre - st["grad"], st["fresh"])
        acc = ok & ~reset
        sel = lambda a, b: jax.tree_util.tree_map(lambda u, v: jnp.where(ok, u, v), a, b)  # noqa
        x, L, grad, f, g = sel((st["xe"], Le, gre, fe, ge),
                               (st["x"], st["L"], st["grad"], st["f"], st["g"]))
        # the quasi-Newton matrix is kept from one outer iteration to the next, unless
        # its direction failed the line search: then the next starts from a scaled
        # steepest descent (else every later outer iteration repeats the failed step)
        B = jnp.where(give_up, jnp.eye(n, dtype=dt), jnp.where(acc, Bn, st["B"]))
        fresh = give_up | jnp.where(acc, fresh_n, st["fresh"])
        it = jnp.where(reset, 0, st["it"] + acc.astype(int))
        # -- the inner solve ends: converged to eps, out of steps or stuck -------------
        stat = _pg(x, grad, lo, hi)
        by_eps = ok & (stat <= st["eps"])
        inner_done = by_eps | (ok & (it >= max_inner)) | give_up
        lam_new = jnp.clip(lam + rho * g, 0.0, _LAM_MAX)
        feas, compl = _measures(g, lam_new)
        V = jnp.max(jnp.abs(jnp.minimum(-g, lam / rho)), initial=0.0)
        k = st["k"]
        rho_new = jnp.where((k > 0) & (V > 0.5 * st["V"]), jnp.minimum(10.0 * rho, _RHO_MAX),
                            rho)
        finite = (jnp.isfinite(f) & jnp.all(jnp.isfinite(g)) & jnp.all(jnp.isfinite(grad))
                  & jnp.all(jnp.isfinite(x)))
        done = (stat <= tol) & (feas <= tol) & (compl <= tol)
        # stalled: an inner solve ends out of steps, or in a failed line search after
        # starting from steepest descent (the matrix reset after the last failure),
        # having lowered L by no more than rounding, and the multipliers do not move --
        # every later outer iteration would repeat it (a kink of f or g, or a decrease
        # below rounding): no step can reduce L, the FAILED status
        L0 = jnp.where(reset, Le, st["L0"])           # L where this inner solve started
        fresh0 = jnp.where(reset, st["fresh"], st["fresh0"])
        stalled = (inner_done & ~by_eps & (fresh0 | ~give_up)
                   & (L0 - L <= _STALL * jnp.maximum(1.0, jnp.abs(L)))
                   & jnp.all(lam_new == lam) & ~done)
        status = jnp.where(~finite | stalled, FAILED,
                           jnp.where(done, CONVERGED, MAX_ITERATIONS))
        if callback is not None:
            jax.debug.callback(_report(callback), inner_done, k + 1, f, feas, stat)
        outer = lambda a, b: jax.tree_util.tree_map(  # noqa: E731
            lambda u, v: jnp.where(inner_done, u, v), a, b)
        lam, rho, V, eps, k_new, status = outer(
            (lam_new, rho_new, V, jnp.maximum(tol, 0.1 * st["eps"]), k + 1, status),
            (lam, rho, st["V"], st["eps"], k, jnp.asarray(MAX_ITERATIONS)))
        hv = jnp.where(inner_done, st["hv"].at[k].set(f), st["hv"])
        hf = jnp.where(inner_done, st["hf"].at[k].set(feas), st["hf"])
        hs = jnp.where(inner_done, st["hs"].at[k].set(stat), st["hs"])
        hx = jnp.where(inner_done, st["hx"].at[k].set(x), st["hx"])
        # -- the next point to evaluate -------------------------------------------------
        d = _direction(x, grad, B, fresh, lo, hi)
        t = -dd / (2.0 * (Le - st["L"] - dd))          # safeguarded quadratic interpolation
        a_bt = jnp.where(ok, 1.0, st["a"] * jnp.where(jnp.isfinite(t), jnp.clip(t, 0.1, 0.5),
                                                      0.1))
        d = jnp.where(ok, d, st["d"])
        a = jnp.where(inner_done, 1.0, a_bt)
        xe = jnp.where(inner_done, x, jnp.clip(x + a * d, lo, hi))
        mode = jnp.where(inner_done, _RESET, _TRIAL)
        bt = jnp.where(ok | inner_done, 0, st["bt"] + 1)
        return dict(x=x, L=L, grad=grad, f=f, g=g, B=B, fresh=fresh, it=it, xe=xe, d=d, a=a,
                    bt=bt, mode=mode, lam=lam, rho=rho, V=V, eps=eps, k=k_new,
                    nev=st["nev"] + 1, status=status, L0=L0, fresh0=fresh0,
                    stat=jnp.where(inner_done, stat, st["stat"]),
                    feas=jnp.where(inner_done, feas, st["feas"]),
                    compl=jnp.where(inner_done, compl, st["compl"]),
                    lam_out=jnp.where(inner_done, lam_new, st["lam_out"]),
                    hv=hv, hf=hf, hs=hs, hx=hx)

    st = dict(x=x0, L=jnp.inf + z, grad=jnp.zeros(n, dt), f=jnp.nan + z,
              g=jnp.full(m, jnp.nan, dt), B=jnp.eye(n, dtype=dt), fresh=jnp.asarray(True),
              it=jnp.asarray(0), xe=x0, d=jnp.zeros(n, dt), a=jnp.ones((), dt),
              bt=jnp.asarray(0), mode=jnp.asarray(_RESET), lam=jnp.zeros(m, dt), rho=rho0 + z,
              L0=jnp.inf + z, fresh0=jnp.asarray(True),
              V=jnp.inf + z, eps=(tol if m == 0 else jnp.maximum(tol, 0.1)) + z,
              k=jnp.asarray(0), nev=jnp.asarray(0), status=jnp.asarray(MAX_ITERATIONS),
              stat=jnp.nan + z, feas=jnp.nan + z, compl=jnp.nan + z,
              lam_out=jnp.zeros(m, dt), hv=nan, hf=nan, hs=nan,
              hx=jnp.full((max_outer, n), jnp.nan, dt))
    st = jax.lax.while_loop(cond, body, st)
    return ConstrainedResult(st["x"], st["f"], st["g"], st["lam_out"], st["stat"], st["feas"],
                             st["compl"], st["k"], st["nev"], st["status"], st["hv"],
                             st["hf"], st["hs"], st["hx"])


def _report(callback):
    """The progress callback, called at the passes that end an outer iteration only."""
    def report(end, k, f, feas, stat):
        if bool(end):
            callback(int(k), float(f), float(feas), float(stat))
    return report


def _concrete(v):
    return not isinstance(v, jax.core.Tracer)


def minimize_constrained(fun: Callable, x0, *, lower=None, upper=None, args=(),
                         max_outer: int = 30, max_inner: int = 60, tol=1e-6, rho0=10.0,
                         callback: Callable | None = None,
                         derivatives: str = "reverse",
                         n_constraints: int | None = None) -> ConstrainedResult:
    """Minimise ``f`` subject to ``g(x) <= 0`` and ``lower <= x <= upper`` (module docstring).

    ``fun(x, *args) -> (f, g)``: scalar objective and constraint vector (shape ``(m,)``,
    m >= 0) from one evaluation; ``x0``: flat start (projected into the box first);
    ``lower``/``upper``: scalars or arrays, ``None`` for unbounded; ``max_outer``: outer
    (multiplier) iterations; ``max_inner``: quasi-Newton steps per inner solve; ``tol``:
    KKT tolerance; ``rho0``: initial penalty; ``callback(outer_iteration, value,
    feasibility, stationarity)``: called once per outer iteration (1-based count) through
    ``jax.debug.callback`` (under ``vmap`` also for members already finished);
    ``derivatives``: ``"reverse"`` (one ``jax.value_and_grad``: any number of variables)
    or ``"forward"`` (``jax.jacfwd``, n tangents in one batched pass: for few variables,
    and where reverse mode fails, see docs/optimize.md); ``n_constraints``: m, where the
    caller knows it (else ``fun`` is traced once more for the shape of ``g``: for an
    expensive model seconds of tracing).  Compiled once per (``fun``, ``max_outer``,
    ``max_inner``, ``callback``, ``derivatives``, ``n_constraints``, shapes).
    """
    if derivatives not in ("reverse", "forward"):
        raise ValueError(f"derivatives = {derivatives!r} must be 'reverse' or 'forward'")
    if n_constraints is not None and (int(n_constraints) != n_constraints
                                      or int(n_constraints) < 0):
        raise ValueError(f"n_constraints = {n_constraints!r} must be an integer >= 0")
    for name, val in (("max_outer", max_outer), ("max_inner", max_inner)):
        if int(val) != val or int(val) < 1:
            raise ValueError(f"{name} = {val!r} must be an integer >= 1")
    for name, val in (("tol", tol), ("rho0", rho0)):
        if _concrete(val) and not (np.isfinite(float(val)) and float(val) > 0):
            raise ValueError(f"{name} = {val!r} must be finite and > 0")
    x0 = jnp.asarray(x0, jnp.float64)
    if x0.ndim != 1:
        raise ValueError(f"x0 has shape {x0.shape}; it must be a flat vector (n,)")
    lo = jnp.broadcast_to(jnp.asarray(-jnp.inf if lower is None else lower, x0.dtype), x0.shape)
    hi = jnp.broadcast_to(jnp.asarray(jnp.inf if upper is None else upper, x0.dtype), x0.shape)
    if _concrete(lo) and _concrete(hi):
        bad = np.flatnonzero(~(np.asarray(lo) <= np.asarray(hi)))
        if bad.size:
            i = int(bad[0])
            raise ValueError(f"lower[{i}] = {float(lo[i])} must be <= upper[{i}] = "
                             f"{float(hi[i])} (and neither NaN)")
    if _concrete(x0) and not np.all(np.isfinite(np.asarray(x0))):
        i = int(np.flatnonzero(~np.isfinite(np.asarray(x0)))[0])
        raise ValueError(f"x0[{i}] = {float(x0[i])} must be finite")
    x0 = jnp.clip(x0, lo, hi)
    return _run(fun, int(max_outer), int(max_inner), callback, x0, lo, hi,
                jnp.asarray(tol, x0.dtype), jnp.asarray(rho0, x0.dtype), tuple(args),
                derivatives=derivatives,
                m=None if n_constraints is None else int(n_constraints))
