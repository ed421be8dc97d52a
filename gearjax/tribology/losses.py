"""Sliding power loss, mesh efficiency and Stribeck curves ([VH-CATT], see docs/references.md).

Mesh cycle input: arrays of shape (n_positions, n_points) — contact points j at
mesh positions i (points of all tooth pairs in contact at position i; a later
issue feeds them from TCA).  Units: load N, speeds mm/s, radii mm, power W.

    P_f(φ_i)  = Σ_j μ_ij F_n,ij |u_s,ij|                      ([VH-CATT]; N·mm/s → W ×1e-3)
    η_m(φ_i)  = 1 - P_f(φ_i) / P_in(φ_i)
    η̄_m       = 1 - Σ_i w_i P_f(φ_i) / Σ_i w_i P_in(φ_i)

with weights ``w_i`` (default: equal, i.e. positions equally spaced in time; pass
trapezoid weights for uneven spacing).  ``η̄_m`` is the ratio of energies over
the cycle, which is what "integrating the instantaneous losses over the path of
contact" ([VH-CATT]) means; it differs from the plain mean of η_m(φ_i) when P_in
varies.  Points with zero load are inactive (masked out; they contribute
nothing and produce no NaN in gradients).  u_s may be signed (direction of
sliding); only |u_s| enters.

Input power: P_in = T_p ω_p (pinion torque N·m × speed rad/s), or given directly.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import any_traced, check_positive, require_converged
from gearjax.tribology.friction import (STEEL_E_PRIME, FrictionResult, Surface, friction_padded,
                                        warn_validity, friction_traced, validate_contact_inputs)
from gearjax.tribology.lubricant import Oil

__all__ = ["MeshLoss", "mesh_losses_traced", "mesh_losses", "input_power",
           "stribeck_traced", "stribeck_curve", "StribeckCurve"]


class MeshLoss(NamedTuple):
    """Mesh-cycle losses.

    power_loss : P_f per mesh position, W (shape (n_positions,)).
    efficiency : instantaneous η_m per position.
    mean_efficiency : cycle-averaged η̄_m (scalar).
    mu : friction coefficient per point (0 where inactive).
    friction : the full :class:`FrictionResult` per point.
    active : load > 0 mask.
    """

    power_loss: jax.Array
    efficiency: jax.Array
    mean_efficiency: jax.Array
    mu: jax.Array
    friction: FrictionResult
    active: jax.Array


def input_power(torque_Nm, speed_rad_s):
    """P_in = T_p ω_p in W (torque N·m, angular speed rad/s)."""
    return jnp.asarray(torque_Nm, float) * jnp.asarray(speed_rad_s, float)


def _assemble(fr, F, u_s, power_in_W, weights):
    F = jnp.asarray(F, float)
    active = F > 0.0
    F_safe = jnp.where(active, F, 1.0)
    us = jnp.abs(jnp.asarray(u_s, float))
    mu = jnp.where(active, fr.mu, 0.0)
    p_loss = 1e-3 * jnp.sum(mu * F_safe * us * active, axis=-1)
    p_in = jnp.broadcast_to(jnp.asarray(power_in_W, float), p_loss.shape)
    eff = 1.0 - p_loss / p_in
    w = jnp.ones_like(p_loss) if weights is None else jnp.asarray(weights, float)
    mean_eff = 1.0 - jnp.sum(w * p_loss) / jnp.sum(w * p_in)
    fr = fr._replace(converged=jnp.where(active, fr.converged, True))
    return MeshLoss(p_loss, eff, mean_eff, mu, fr, active)


def _safe_inputs(F, u_s, u_e):
    F = jnp.asarray(F, float)
    active = F > 0.0
    ue = jnp.broadcast_to(jnp.asarray(u_e, float), F.shape)
    return jnp.where(active, F, 1.0), jnp.abs(jnp.asarray(u_s, float)), jnp.where(active, ue, 1.0)


def mesh_losses_traced(F, u_s, u_e, Rx, Ry, oil: Oil, surface: Surface, power_in_W,
                       E_prime=STEEL_E_PRIME, weights=None, viscosity_model="roelands",
                       film_method="auto") -> MeshLoss:
    """Traceable core of :func:`mesh_losses` (no validation; jit/grad/vmap-friendly)."""
    F_safe, us, ue_safe = _safe_inputs(F, u_s, u_e)
    fr = friction_traced(F_safe, ue_safe, us, Rx, Ry, oil, surface, E_prime,
                         viscosity_model=viscosity_model, film_method=film_method)
    return _assemble(fr, F, u_s, power_in_W, weights)


def mesh_losses(F, u_s, u_e, Rx, Ry, oil: Oil, surface: Surface, power_in_W,
                E_prime=STEEL_E_PRIME, weights=None, *, viscosity_model="roelands",
                film_method="auto", throw=True) -> MeshLoss:
    """Power loss and mesh efficiency over a mesh cycle: the one entry point, concrete or
    traced.

    ``F`` (N, ≥ 0; 0 marks an inactive point), ``u_s`` (mm/s, signed), ``u_e``
    (mm/s, > 0 where active), ``Rx``, ``Ry`` (mm) broadcast to shape
    (n_positions, n_points); ``power_in_W`` scalar or (n_positions,);
    ``weights`` optional (n_positions,) non-negative time weights.  Concrete inputs are
    validated first and a failed solve raises when ``throw``; inside ``jax.jit``,
    ``jax.grad`` or ``jax.vmap`` (any input traced) it runs the traced computation
    without validation or exception (the ``converged`` flags are in the result).
    """
    if any_traced(F, u_s, u_e, Rx, Ry, power_in_W, E_prime, weights, oil, surface):
        return mesh_losses_traced(F, u_s, u_e, Rx, Ry, oil, surface, power_in_W, E_prime,
                                  weights, viscosity_model=viscosity_model,
                                  film_method=film_method)
    F_arr = np.asarray(F, float)
    if F_arr.ndim != 2:
        raise ValueError(f"load must have shape (n_positions, n_points), got {F_arr.shape}")
    if np.any(~np.isfinite(F_arr) | (F_arr < 0)):
        raise ValueError(f"load = {float(F_arr[~np.isfinite(F_arr) | (F_arr < 0)][0]):g} N is "
                         "outside the allowed range [0, inf) N")
    act = F_arr > 0
    if not np.any(act):
        raise ValueError("load: no contact point carries load")
    bc = [np.broadcast_to(np.asarray(v, float), F_arr.shape) for v in (u_e, u_s, Rx, Ry, E_prime)]
    validate_contact_inputs(F_arr[act], bc[0][act], bc[1][act], bc[2][act], bc[3][act], bc[4][act],
                            allow_signed_us=True)
    pin = np.asarray(power_in_W, float)
    if np.any(~np.isfinite(pin) | (pin <= 0)):
        check_positive("power_in", pin.ravel()[0], "W")
    if weights is None:
        weights = np.ones(F_arr.shape[0])
    wt = np.asarray(weights, float)
    if wt.shape != (F_arr.shape[0],) or np.any(wt < 0) or not np.any(wt > 0):
        raise ValueError(f"weights must be {F_arr.shape[0]} non-negative numbers, not all 0")
    F_safe, us, ue_safe = _safe_inputs(F_arr, u_s, u_e)
    fr = friction_padded(F_safe, ue_safe, us, Rx, Ry, oil, surface, E_prime, viscosity_model,
                          film_method)
    out = _assemble(fr, F_arr, u_s, power_in_W, wt)
    if throw:
        require_converged(out.friction.converged, "mesh friction (Hertz / load-sharing solves)")
    warn_validity(out.friction, film_method, viscosity_model)
    eta = np.asarray(out.efficiency, float)
    if not np.all((eta > 0.0) & (eta <= 1.0)):
        # P_f >= P_in: the losses exceed the power transmitted -- an input power far
        # below the operating point of the loads and speeds given
        warnings.warn(f"implausible efficiency: eta_m from {np.nanmin(eta):.6g} to "
                      f"{np.nanmax(eta):.6g}, outside (0, 1] (the sliding loss is not below "
                      f"power_in_W = {float(np.min(pin)):g} W: check power_in_W against the "
                      "loads and speeds)", stacklevel=2)
    return out


class StribeckCurve(NamedTuple):
    """μ along a speed sweep.  ``stribeck_number`` = η0 u_e / F_n in 1/m
    (η0 Pa·s, u_e m/s, F_n N); ``lam`` the smooth-surface λ_s = h_c,smooth/σ;
    ``u_e`` in mm/s; ``friction`` per point."""

    u_e: jax.Array
    stribeck_number: jax.Array
    lam: jax.Array
    mu: jax.Array
    friction: FrictionResult


def stribeck_traced(F, Rx, Ry, srr, u_e, oil, surface, E_prime=STEEL_E_PRIME,
                    viscosity_model="roelands", film_method="auto") -> StribeckCurve:
    """μ against entrainment speed at fixed slide-to-roll ratio SRR = u_s/u_e (no validation)."""
    u_e = jnp.asarray(u_e, float)
    fr = friction_traced(F, u_e, srr * u_e, Rx, Ry, oil, surface, E_prime,
                         viscosity_model=viscosity_model, film_method=film_method)
    st = oil.eta0 * (u_e * 1e-3) / F
    return StribeckCurve(u_e, st, fr.lam_smooth, fr.mu, fr)


def stribeck_curve(F, Rx, Ry, srr, u_e, oil, surface, E_prime=STEEL_E_PRIME, *,
                   viscosity_model="roelands", film_method="auto", throw=True) -> StribeckCurve:
    """Validated Stribeck sweep: ``u_e`` array (mm/s, > 0), SRR ≥ 0, scalar F, Rx, Ry."""
    from gearjax.errors import check_range
    check_range("srr", srr, 0.0, 2.0)
    ue = np.asarray(u_e, float)
    validate_contact_inputs(F, ue, srr * ue, Rx, Ry, E_prime)
    fr = friction_padded(F, ue, srr * ue, Rx, Ry, oil, surface, E_prime, viscosity_model,
                          film_method)
    out = StribeckCurve(jnp.asarray(ue), oil.eta0 * (ue * 1e-3) / F, fr.lam_smooth, fr.mu, fr)
    if throw:
        require_converged(out.friction.converged, "Stribeck sweep")
    warn_validity(out.friction, film_method, viscosity_model)
    return out
