"""Results of a converged EHL solve: film, loads, Ree–Eyring friction.

Central film h_c: the film at the contact centre (X, Y) = (0, 0), bilinear
interpolation of the four surrounding nodes; minimum film h_min: the smallest
nodal film.  Friction (isothermal, as the fast model of
:mod:`gearjax.tribology.friction`):

    μ = [ Σ_nodes τ ΔA  +  f_c F_a tanh(u_s/v_slip) ] / F,
    τ = τ0 asinh( η(p) u_s / (h τ0) )          (Ree–Eyring, summed over all nodes),

with η from Roelands at the local fluid pressure and h the local film (as
:func:`gearjax.tribology.lubricant.eyring_shear`).  The whole domain is treated
as flooded: the cavitated zone (p = 0) is not excluded, because a mask
``p > 0`` would make μ jump whenever a node at the free boundary changes state
(seen as 10–100 % errors of central-difference derivatives).  Its contribution
is negligible: there η = η0 and h ≥ h_min, so τ ≤ η0 u_s/h_min, e.g. 2e-5 MPa
against ~30 MPa in the Hertz zone for the test case of docs/ehl.md.  F_a = ∫∫
p_a dA is the asperity load, F_h = ∫∫ p dA the fluid load.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.tribology.ehl.grid import EHLGrid, influence_kernel
from gearjax.tribology.ehl.model import EHLCase, fields, scales, unpack
from gearjax.tribology.lubricant import PA_S_TO_MPA_S

__all__ = ["EHLOutputs", "outputs"]


class EHLOutputs(NamedTuple):
    """Scalar outputs (mm, N, -) of a state."""

    h_c: jax.Array
    h_min: jax.Array
    mu: jax.Array
    mu_fluid: jax.Array
    mu_boundary: jax.Array
    F_fluid: jax.Array
    F_asperity: jax.Array


def _centre_weights(grid: EHLGrid):
    """Indices and bilinear weights of the 4 nodes around (0, 0)."""
    fx = (0.0 - grid.x_lo) / grid.dx - 0.5
    fy = (0.0 - grid.y_lo) / grid.dy - 0.5
    i0, j0 = int(np.floor(fx)), int(np.floor(fy))
    tx, ty = fx - i0, fy - j0
    return i0, j0, tx, ty


def centre_value(A, grid: EHLGrid):
    """Bilinear value of a nodal field A (ny, nx) at X = Y = 0."""
    i0, j0, tx, ty = _centre_weights(grid)
    return ((1 - tx) * (1 - ty) * A[j0, i0] + tx * (1 - ty) * A[j0, i0 + 1]
            + (1 - tx) * ty * A[j0 + 1, i0] + tx * ty * A[j0 + 1, i0 + 1])


def outputs(x, case: EHLCase, grid: EHLGrid, mixed: bool) -> tuple[EHLOutputs, object]:
    """Scalar outputs and the nodal fields of the state x (differentiable in x and case)."""
    sc = scales(case)
    khat = jnp.fft.rfft2(influence_kernel(grid, sc.k))
    P, P_a, H0 = unpack(x, grid, mixed)
    fl = fields(P, H0, P_a, case, sc, grid, khat)
    h = fl.H * sc.h_unit
    dA = grid.dx * grid.dy * sc.a * sc.b
    eta = case.eta0 * fl.eta
    h_pos = jnp.maximum(h, 1e-9)
    tau = case.tau0 * jnp.arcsinh(eta * PA_S_TO_MPA_S * case.u_s / (h_pos * case.tau0))
    F_tau = jnp.sum(tau) * dA
    F_h = jnp.sum(P) * sc.p_h * dA
    F_a = jnp.sum(P_a) * sc.p_h * dA
    mu_f = F_tau / case.F
    mu_b = case.f_c * F_a / case.F * jnp.tanh(case.u_s / case.v_slip)
    out = EHLOutputs(centre_value(h, grid), jnp.min(h), mu_f + mu_b, mu_f, mu_b, F_h, F_a)
    return out, fl
