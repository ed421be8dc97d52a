"""Damped Newton–Krylov solver of the discrete EHL point-contact problem.

Unknowns x = [P, (P_a), H0]; equations :func:`gearjax.tribology.ehl.model.residual`.
Each Newton step solves ``J δ = -R`` by restarted GMRES (:mod:`.krylov`) with matrix-free
Jacobian–vector products (``jax.jvp``) and the line-block preconditioner of
:mod:`gearjax.tribology.ehl.precondition`, then backtracks (step halving) on
``‖R‖₂`` (semismooth Newton for the Fischer–Burmeister cavitation condition).
Start: the Hertz pressure ``P = sqrt(1 - X² - Y²)`` and H0 set so that the
central film equals the Hamrock–Dowson estimate.  Heavy cases are reached by
continuation in the Reynolds coefficient λ (a sequence of solves from
``λ·m_0`` down to λ, each started from the previous solution), which is the
"continuation in viscosity" of the classical EHL literature.

Converged means ``max|R| <= tol`` (default 1e-9: the Fischer–Burmeister residual
in units of p_h and the relative load error) and a film above the floor
(1e-8 in units of b²/Rx) at every node.  Everything is jit-compiled
(``lax.while_loop``) and runs unchanged on a GPU.
"""

from __future__ import annotations

from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.tribology.ehl.grid import EHLGrid, deformation, influence_kernel
from gearjax.tribology.ehl.model import (EHLCase, asperity_P, fields, fluid_props,
                                         kernel_hat, reynolds_operator, residual_core,
                                         row_scale, scales, unpack, H_FLOOR)
from gearjax.tribology.ehl.krylov import gmres
from gearjax.tribology.ehl.precondition import build_preconditioner
from gearjax.tribology.film import hamrock_dowson

__all__ = ["SolverState", "newton_krylov", "initial_guess", "solve_state"]


class SolverState(NamedTuple):
    """Raw outcome of the Newton–Krylov loop.

    x : unknown vector.  residual : max|R|.  load_error : relative load error.
    steps : Newton steps.  converged : residual <= tol, finite, film above the floor.
    """

    x: jax.Array
    residual: jax.Array
    load_error: jax.Array
    steps: jax.Array
    converged: jax.Array


@partial(jax.jit, static_argnames=("grid", "mixed"))
def initial_guess(case: EHLCase, grid: EHLGrid, mixed: bool):
    """Hertz pressure and H0 matching the Hamrock–Dowson central film."""
    sc = scales(case)
    X, Y = (jnp.asarray(v) for v in grid.nodes())
    P0 = jnp.sqrt(jnp.maximum(1.0 - X * X - Y * Y, 0.0))
    P0 = P0 * (2.0 * jnp.pi / 3.0) / (grid.dx * grid.dy * jnp.sum(P0))
    khat = jnp.fft.rfft2(influence_kernel(grid, sc.k))
    W = sc.c_w * deformation(P0, khat, grid)
    Xc = jnp.argmin(jnp.abs(X[0])); Yc = jnp.argmin(jnp.abs(Y[:, 0]))
    hc, _ = hamrock_dowson(case.F, case.Rx, jnp.maximum(sc.k, 1.0), case.u_e, case.eta0,
                           case.alpha, case.E_prime)
    H0 = hc / sc.h_unit - W[Yc, Xc]
    parts = [P0.ravel()] + ([jnp.zeros(P0.size)] if mixed else []) + [jnp.reshape(H0, (1,))]
    return jnp.concatenate(parts)


def precondition_operator(x, case, grid, angle_deg, mixed, R, sc=None):
    sc = scales(case) if sc is None else sc
    kernel = influence_kernel(grid, sc.k)
    khat = jnp.fft.rfft2(kernel)
    P, P_a, H0 = unpack(x, grid, mixed)
    fl = fields(P, H0, P_a, case, sc, grid, khat)
    w = row_scale(fl, sc, grid)
    L = reynolds_operator(P, fl, sc, grid, angle_deg)
    drho = jax.grad(lambda p: jnp.sum(fluid_props(p, sc)[1]))(P)
    dG = jax.grad(lambda h: jnp.sum(asperity_P(h, case, sc, mixed)))(fl.H) if mixed \
        else jnp.zeros_like(P)
    f = partial(residual_core, case=case, sc=sc, khat=khat, grid=grid, angle_deg=angle_deg,
                mixed=mixed)
    e = jnp.zeros_like(x).at[-1].set(1.0)
    col = jax.jvp(f, (x,), (e,))[1]
    n = P.size
    row = jnp.full(x.size - 1, grid.dx * grid.dy / (2.0 * jnp.pi / 3.0))
    return build_preconditioner(P, L, w, fl, drho, dG, kernel, sc, grid, angle_deg, mixed, col, row)


@partial(jax.jit, static_argnames=("grid", "angle_deg", "mixed", "max_steps", "restart",
                                   "maxiter"))
def newton_krylov(x0, case: EHLCase, grid: EHLGrid, angle_deg: float = 0.0, mixed: bool = False,
                  tol=1e-9, max_steps: int = 60, restart: int = 40, maxiter: int = 6,
                  lin_tol=1e-3, ptc=0.0):
    """Damped Newton–Krylov from ``x0``; returns :class:`SolverState`.

    ``ptc`` > 0 switches on pseudo-transient continuation (Kelley & Keyes, SIAM J.
    Numer. Anal. 35 (1998) 508–523): each step solves ``(J + s D) δ = -R`` with D the
    identity on the nodal rows (not on the load row) and the shift s starting at
    ``ptc`` and following the residual, ``s ← s ‖R_new‖/‖R_old‖`` (doubled after a
    step the line search had to shorten), so that it vanishes as the iteration
    converges (Newton's rate is kept).  It damps the nodes where the Newton model is
    poor; used for the fine-grid solve of the nested iteration, where the exit
    spike of the interpolated start is far from the fine-grid one.  ``ptc = 0``
    (default): plain damped Newton.
    """
    sc = scales(case)
    khat = kernel_hat(grid, sc)
    f = partial(residual_core, case=case, sc=sc, khat=khat, grid=grid, angle_deg=angle_deg,
                mixed=mixed)

    def merit(R):
        return jnp.sqrt(jnp.sum(R * R))

    d_rows = jnp.ones(x0.shape[0]).at[-1].set(0.0)

    def cond(st):
        x, R, k, done, shift = st
        return (k < max_steps) & ~done

    def body(st):
        x, R, k, _, shift = st
        M, _ = precondition_operator(x, case, grid, angle_deg, mixed, R, sc)
        Jv = lambda v: jax.jvp(f, (x,), (v,))[1] + shift * d_rows * v
        dx, _ = gmres(Jv, -R, M=M, tol=lin_tol, restart=restart, maxiter=maxiter)
        m0 = merit(R)

        def ls_cond(s):
            t, Rn, j = s
            bad = ~jnp.isfinite(merit(Rn)) | (merit(Rn) > (1.0 - 1e-4 * t) * m0)
            return bad & (j < 12)

        def ls_body(s):
            t, _, j = s
            t = 0.5 * t
            return t, f(x + t * dx), j + 1

        t, Rn, _ = jax.lax.while_loop(ls_cond, ls_body, (1.0, f(x + dx), 0))
        ok = jnp.isfinite(merit(Rn))
        xn = jnp.where(ok, x + t * dx, x)
        Rn = jnp.where(ok, Rn, R)
        done = jnp.max(jnp.abs(Rn)) <= tol
        stall = ~ok | (t < 2.0 ** -11)
        shift = shift * merit(Rn) / m0 * jnp.where(t < 1.0, 2.0, 1.0)
        return xn, Rn, k + 1, done | stall, shift

    R0 = f(x0)
    x, R, k, _, _ = jax.lax.while_loop(cond, body, (x0, R0, 0, jnp.max(jnp.abs(R0)) <= tol,
                                                    jnp.asarray(ptc, R0.dtype)))
    res = jnp.max(jnp.abs(R))
    # a film at the floor everywhere makes ε and ρ̄H vanish, so the Reynolds residual
    # is trivially zero: such a degenerate "root" (seen on a 256² grid after a failed
    # continuation) is not a solution
    P, P_a, H0 = unpack(x, grid, mixed)
    H = fields(P, H0, P_a, case, sc, grid, khat).H
    film_ok = jnp.min(H) > 10.0 * H_FLOOR
    conv = jnp.isfinite(res) & (res <= tol) & film_ok
    return SolverState(x, res, jnp.abs(R[-1]), k, conv)


def solve_state(case: EHLCase, grid: EHLGrid, angle_deg: float = 0.0, mixed: bool = False,
                tol=1e-9, max_steps: int = 60, continuation=(), x0=None, ptc=0.0):
    """Solve with optional continuation in λ (``continuation`` = multipliers m > 1, descending).

    Each stage solves the problem with the Reynolds coefficient multiplied by m
    (i.e. η0 u_e scaled by m at fixed α, load and geometry; m < 1 gives a heavier
    start for light loads) starting from the previous stage (the first from the
    Hertz start of its own case, or ``x0``); the last stage is the case itself.
    ``ptc`` : initial pseudo-transient shift of every stage (see :func:`newton_krylov`).
    """
    import dataclasses

    stages = tuple(float(m) for m in continuation)
    if x0 is not None:
        x = x0
    elif stages:
        x = initial_guess(dataclasses.replace(case, u_e=case.u_e * stages[0]), grid, mixed)
    else:
        x = initial_guess(case, grid, mixed)
    for m in stages:
        cm = dataclasses.replace(case, u_e=case.u_e * m)
        st = newton_krylov(x, cm, grid, angle_deg, mixed, tol=max(tol, 1e-6),
                           max_steps=max_steps, ptc=ptc)
        x = st.x
    return newton_krylov(x, case, grid, angle_deg, mixed, tol=tol, max_steps=max_steps, ptc=ptc)
