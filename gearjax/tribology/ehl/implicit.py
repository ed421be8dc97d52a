"""Implicit differentiation of the converged EHL solution.

At a converged state ``R(x*, θ) = 0`` (``R`` =
:func:`gearjax.tribology.ehl.model.residual`, θ the :class:`EHLCase`), the
implicit function theorem gives ``dx*/dθ = -J⁻¹ ∂R/∂θ`` with ``J = ∂R/∂x``.  For a
scalar output ``y(x*, θ)`` reverse mode needs one adjoint solve

    Jᵀ λ = ∂y/∂x,        dy/dθ = ∂y/∂θ - λᵀ ∂R/∂θ,

done here matrix-free: ``Jᵀ v`` is a VJP of the residual (``jax.vjp``), the
system is solved by restarted GMRES (:mod:`.krylov`) preconditioned with the transpose of the
line-block preconditioner of the forward solve
(:mod:`gearjax.tribology.ehl.precondition`).  The Newton iterations themselves
are never differentiated (the solution enters through ``stop_gradient``).

Reference: Blondel et al., "Efficient and modular implicit differentiation",
NeurIPS 2022; for the Fischer–Burmeister rows at the free (cavitation) boundary
the Jacobian is an element of the generalised (Clarke) Jacobian, which is the
derivative wherever the active set does not change.

An adjoint solve that does not reach ``ADJOINT_ACCEPT`` (1e-8 relative) gives NaN
derivatives instead of inaccurate ones.
"""

from __future__ import annotations

from functools import partial

import jax
import jax.numpy as jnp

from gearjax.tribology.ehl.grid import EHLGrid
from gearjax.tribology.ehl.krylov import gmres
from gearjax.tribology.ehl.model import EHLCase, kernel_hat, residual, residual_core, scales

__all__ = ["attach_implicit_gradient", "ADJOINT_TOL", "ADJOINT_ACCEPT", "adjoint_restart"]

ADJOINT_TOL = 1e-10
#: relative adjoint residual above which the gradient is returned as NaN (not silently
#: inaccurate): the adjoint GMRES stops at ADJOINT_TOL when it converges
ADJOINT_ACCEPT = 1e-8


def adjoint_restart(grid: EHLGrid) -> int:
    """Krylov dimension of the adjoint GMRES: 60 up to 128² nodes, 150 above.  On 256²
    GMRES(60)×20 stagnates at 5e-7 … 3e-6 relative (h_c, h_min, μ of the M = 168 case),
    GMRES(150) reaches 1e-10 … 2.3e-10 (measured; docs/ehl.md, "Gradients")."""
    return 60 if grid.nx * grid.ny <= 128 * 128 else 150


@partial(jax.custom_vjp, nondiff_argnums=(2, 3, 4))
def attach_implicit_gradient(x_star, case: EHLCase, grid: EHLGrid, angle_deg: float,
                             mixed: bool):
    """Identity on the converged state ``x_star`` whose VJP w.r.t. ``case`` is implicit.

    ``x_star`` must be a converged solution (pass it through ``stop_gradient``);
    the cotangent returned for ``x_star`` itself is zero.
    """
    return x_star


def _fwd(x_star, case, grid, angle_deg, mixed):
    return x_star, (x_star, case)


def _bwd(grid, angle_deg, mixed, res, g):
    from gearjax.tribology.ehl.solver import precondition_operator   # circular import guard

    x, case = res
    sc = scales(case)
    khat = kernel_hat(grid, sc)
    f_x = lambda v: residual_core(v, case, sc, khat, grid, angle_deg, mixed)
    R, vjp_x = jax.vjp(f_x, x)
    JT = lambda v: vjp_x(v)[0]
    _, M_T = precondition_operator(x, case, grid, angle_deg, mixed, R, sc)
    lam, rel = gmres(JT, g, M=M_T, tol=ADJOINT_TOL, restart=adjoint_restart(grid),
                     maxiter=20)
    _, vjp_c = jax.vjp(lambda c: residual(x, c, grid, angle_deg, mixed), case)
    (case_bar,) = vjp_c(-lam)
    ok = rel <= ADJOINT_ACCEPT
    case_bar = jax.tree_util.tree_map(lambda a: jnp.where(ok, a, jnp.nan), case_bar)
    return jnp.zeros_like(x), case_bar


attach_implicit_gradient.defvjp(_fwd, _bwd)
