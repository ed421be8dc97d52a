"""Line-block preconditioner of the EHL Newton–Krylov solver.

The Jacobian of the discrete EHL problem is dense (elastic deformation couples
every node with every other).  Along the dominant entrainment axis the coupling
that matters at high load is the Couette term acting through the film, which
Venner & Lubrecht (2000) resolve with line relaxation.  The preconditioner here
is the block-diagonal part of an approximate Jacobian with one block per grid
line (lines along X, or along Y when the entrainment is closer to the Y axis):
within a line it keeps the Fischer–Burmeister weights, the Poiseuille stencil
with frozen ε, and the *full* in-line elastic coupling of the Couette flux
(ρ̄ dH/dP along the line, plus the neighbour-line term of the cross flux); the
asperity rows (mixed lubrication) enter likewise.  Each block is LU-factorised
(dense, batched over lines).  The load-balance row and the H0 column are
handled exactly by a Schur complement (bordered system).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import jax.scipy.linalg as jsl
import numpy as np

__all__ = ["build_preconditioner", "line_axis"]


def line_axis(angle_deg: float) -> int:
    """1 (lines along X) when |cos θ| >= |sin θ|, else 0 (lines along Y)."""
    c, s = abs(np.cos(np.radians(angle_deg))), abs(np.sin(np.radians(angle_deg)))
    return 1 if c >= s else 0


def _shift(A, d):
    """A shifted along the last axis by d (edge replicated): out[..., i] = A[..., i + d]."""
    n = A.shape[-1]
    idx = np.clip(np.arange(n) + d, 0, n - 1)
    return A[..., idx]


def _line_blocks(P, L, w, fl, dP_rho, dG, K0, K1, cw, d_a, s_a, c_a, d_c, s_c, c_c, mixed,
                 beta=0.0):
    """Blocks (n_lines, m, m) or (n_lines, 2m, 2m); arrays laid out (lines, along)."""
    nl, m = P.shape
    L = w * L
    # the same regularisation as the residual (model.residual_core): with the 1e-300
    # outside the root, P, L ~ 1e-170 (cavitated nodes after a few Newton steps)
    # underflow P², L² and give P/r ~ 1e130, an overflowing block (seen on 256²)
    r = jnp.sqrt(P * P + L * L + 1e-300)
    A = 1.0 - P / r
    B = (-1.0 - L / r) * w
    eps = fl.eps
    ep = jnp.pad(eps, ((1, 1), (1, 1)), mode="edge")
    e_f = 0.5 * (eps + ep[1:-1, 2:])
    e_b = 0.5 * (eps + ep[1:-1, :-2])
    e_n = 0.5 * (eps + ep[2:, 1:-1])
    e_s = 0.5 * (eps + ep[:-2, 1:-1])
    eye = jnp.eye(m)
    sup = jnp.eye(m, k=1)
    sub = jnp.eye(m, k=-1)
    # Poiseuille (frozen ε): dPoi_i/dP_j
    dpoi = (s_a / d_a) ** 2 * (e_f[..., None] * (sup - eye) - e_b[..., None] * (eye - sub)) \
        - ((s_c / d_c) ** 2 * (e_n + e_s))[..., None] * eye
    rho = fl.rho
    rhop = jnp.pad(rho, ((1, 1), (0, 0)), mode="edge")
    # Q[l, mm, j] = d q_mm / d P_j within the line (through the deformation)
    Qk = cw * rho[..., None] * K0[None]                      # (nl, m, m)
    Qp = Qk + (dP_rho * fl.H)[..., None] * eye
    cap, cam = max(c_a, 0.0), min(c_a, 0.0)
    ccp, ccm = max(c_c, 0.0), min(c_c, 0.0)
    idx = np.arange(m)
    prev = np.clip(idx - 1, 0, m - 1)
    nxt = np.clip(idx + 1, 0, m - 1)
    prev2 = np.clip(idx - 2, 0, m - 1)
    nxt2 = np.clip(idx + 2, 0, m - 1)
    h = 0.5 * beta
    nb_prev = cw * rhop[:-2][..., None] * K1[None]
    nb_next = cw * rhop[2:][..., None] * K1[None]

    def dcou(Q):
        # in-line upwind difference with the second-order correction (weight β);
        # the cross-line term stays first order (an approximation is enough here)
        along = cap * ((1.0 + h) * Q - (1.0 + beta) * Q[:, prev, :] + h * Q[:, prev2, :]) \
            + cam * ((1.0 + beta) * Q[:, nxt, :] - h * Q[:, nxt2, :] - (1.0 + h) * Q)
        cross = ccp * (Q - nb_prev) + ccm * (nb_next - Q)
        return s_a / d_a * along + s_c / d_c * cross

    J_pp = A[..., None] * eye + B[..., None] * (dpoi - dcou(Qp))
    if not mixed:
        return J_pp
    J_pa = B[..., None] * (-dcou(Qk))
    gK = dG[..., None] * cw * K0[None]
    top = jnp.concatenate([J_pp, J_pa], axis=-1)
    bot = jnp.concatenate([-gK, eye - gK], axis=-1)
    return jnp.concatenate([top, bot], axis=-2)


def build_preconditioner(P, L, w, fl, dP_rho, dG, kernel, sc, grid, angle_deg, mixed, col_h0, row_load):
    """Return ``apply(v)`` ≈ J⁻¹ v for the (bordered) system, and its transpose."""
    ax = line_axis(angle_deg)
    c, s = float(np.cos(np.radians(angle_deg))), float(np.sin(np.radians(angle_deg)))
    ny, nx = P.shape
    if ax == 1:
        m = nx
        ia = np.arange(m)
        off = (ia[:, None] - ia[None, :]) % (2 * nx)
        K0, K1 = kernel[0][off], kernel[1][off]
        par = (grid.dx, 1.0, c, grid.dy, 1.0 / sc.k, s)
        tr = lambda A: A
    else:
        m = ny
        ia = np.arange(m)
        off = (ia[:, None] - ia[None, :]) % (2 * ny)
        K0, K1 = kernel[:, 0][off], kernel[:, 1][off]
        par = (grid.dy, 1.0 / sc.k, s, grid.dx, 1.0, c)
        tr = lambda A: A.T
    fl_t = type(fl)(*(tr(f) for f in fl))
    blocks = _line_blocks(tr(P), tr(L), tr(w), fl_t, tr(dP_rho), tr(dG), K0, K1, sc.c_w, *par, mixed,
                          grid.upwind)
    lu = jax.vmap(jsl.lu_factor)(blocks)
    nl = blocks.shape[0]
    n = nx * ny
    nf = 2 if mixed else 1

    def to_lines(v):                   # flat (nf*n,) -> (nl, nf*m)
        f = [tr(v[i * n:(i + 1) * n].reshape(ny, nx)) for i in range(nf)]
        return jnp.concatenate(f, axis=-1)

    def from_lines(w):
        parts = [tr(w[:, i * m:(i + 1) * m]).ravel() for i in range(nf)]
        return jnp.concatenate(parts)

    def block_solve(v, trans=0):
        w = jax.vmap(lambda f, b: jsl.lu_solve(f, b, trans=trans))(lu, to_lines(v))
        return from_lines(w)

    b = col_h0[:-1]
    Mb = block_solve(b)
    den = jnp.dot(row_load, Mb)
    Mtc = block_solve(row_load, 1)
    den_t = jnp.dot(b, Mtc)

    def apply(v):
        r, g = v[:-1], v[-1]
        y = block_solve(r)
        t = (jnp.dot(row_load, y) - g) / den
        return jnp.concatenate([y - t * Mb, jnp.reshape(t, (1,))])

    def apply_t(v):
        # transpose of the bordered block: [[M, b], [c^T, 0]]^T = [[M^T, c], [b^T, 0]]
        r, g = v[:-1], v[-1]
        y = block_solve(r, 1)
        t = (jnp.dot(b, y) - g) / den_t
        return jnp.concatenate([y - t * Mtc, jnp.reshape(t, (1,))])

    return apply, apply_t
