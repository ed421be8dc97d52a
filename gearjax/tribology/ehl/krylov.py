"""Restarted right-preconditioned GMRES (compact, for jit).

Solves ``A x = b`` with the right-preconditioned Krylov space of ``A M``
(Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed., 2003, §9.3.2):
Arnoldi with classical Gram–Schmidt applied twice (CGS2, as accurate as modified
Gram–Schmidt and vectorised), Givens rotations for the small least-squares problem,
exit inside a cycle as soon as the residual estimate ``|g_{j+1}| ≤ tol ‖b‖``.
Written here instead of ``jax.scipy.sparse.linalg.gmres`` because it compiles
about twice as fast in the nested loops of the Newton solver.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

__all__ = ["gmres"]


def _givens(a, b):
    r = jnp.hypot(a, b)
    r_safe = jnp.where(r > 0, r, 1.0)
    return jnp.where(r > 0, a / r_safe, 1.0), jnp.where(r > 0, b / r_safe, 0.0)


def gmres(A, b, M=None, *, tol=1e-6, restart=40, maxiter=6):
    """Approximate solution of ``A x = b`` (x0 = 0) and the number of cycles used.

    A, M : callables on vectors of b's shape (M ≈ A⁻¹, default identity).
    tol : relative residual ``‖b - A x‖/‖b‖`` target.  restart : Krylov dimension per
    cycle.  maxiter : cycles.  Returns ``(x, relative_residual)``.
    """
    M = (lambda v: v) if M is None else M
    m = int(restart)
    n = b.shape[0]
    bnorm = jnp.linalg.norm(b)
    bnorm_safe = jnp.where(bnorm > 0, bnorm, 1.0)
    target = tol * bnorm_safe

    def cycle(x):
        r = b - A(x)
        beta = jnp.linalg.norm(r)
        V = jnp.zeros((m + 1, n), b.dtype).at[0].set(r / jnp.where(beta > 0, beta, 1.0))
        R = jnp.zeros((m + 1, m), b.dtype)     # rotated Hessenberg (upper triangular)
        cs = jnp.zeros(m, b.dtype)
        sn = jnp.zeros(m, b.dtype)
        g = jnp.zeros(m + 1, b.dtype).at[0].set(beta)
        rows = jnp.arange(m + 1)

        def cond(st):
            j, V, R, cs, sn, g = st
            return (j < m) & (jnp.abs(g[j]) > target)

        def body(st):
            j, V, R, cs, sn, g = st
            w = A(M(V[j]))
            mask = rows <= j
            h = jnp.where(mask, V @ w, 0.0)
            w = w - h @ V
            h2 = jnp.where(mask, V @ w, 0.0)
            w = w - h2 @ V
            h = h + h2
            hn = jnp.linalg.norm(w)
            V = V.at[j + 1].set(w / jnp.where(hn > 0, hn, 1.0))
            h = h.at[j + 1].set(hn)

            def rot(i, hh):
                a, bb = hh[i], hh[i + 1]
                ai = cs[i] * a + sn[i] * bb
                bi = -sn[i] * a + cs[i] * bb
                upd = hh.at[i].set(ai).at[i + 1].set(bi)
                return jnp.where(i < j, upd, hh)

            h = jax.lax.fori_loop(0, m, rot, h)
            c, s = _givens(h[j], h[j + 1])
            h = h.at[j].set(c * h[j] + s * h[j + 1]).at[j + 1].set(0.0)
            gj = g[j]
            g = g.at[j].set(c * gj).at[j + 1].set(-s * gj)
            return j + 1, V, R.at[:, j].set(h), cs.at[j].set(c), sn.at[j].set(s), g

        j, V, R, cs, sn, g = jax.lax.while_loop(cond, body, (0, V, R, cs, sn, g))
        # back substitution on the leading j x j block (unused columns -> identity)
        idx = jnp.arange(m)
        act = idx < j
        Rm = jnp.where(act[:, None] & act[None, :], R[:m, :m], 0.0) + jnp.diag(jnp.where(act, 0.0, 1.0))
        y = jax.scipy.linalg.solve_triangular(Rm, jnp.where(act, g[:m], 0.0), lower=False)
        return x + M(y @ V[:m]), jnp.abs(g[j]) / bnorm_safe

    def ocond(st):
        x, res, k = st
        return (k < maxiter) & (res > tol)

    def obody(st):
        x, _, k = st
        x, res = cycle(x)
        return x, res, k + 1

    x0 = jnp.zeros_like(b)
    x, res, _ = jax.lax.while_loop(ocond, obody, (x0, jnp.asarray(jnp.inf, b.dtype), 0))
    return x, res
