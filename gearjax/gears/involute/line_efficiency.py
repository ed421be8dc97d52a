"""Mesh efficiency of spur and helical pairs in line contact: the mixed-lubrication
friction of :mod:`gearjax.tribology` along the sliced contact lines of
:mod:`gearjax.gears.involute.line_load`.

**Kinematics** ([ISO21771]; [Litvin2004] ch. 10).  A point of the plane of action at
path coordinate ``s`` moves, on each flank, along the transverse profile -- the
normal of the plane of action, perpendicular to every contact line -- with the
surface speeds ``u1 = omega1 xi1`` and ``u2 = omega2 xi2`` (roll lengths ``xi``, mm;
``omega2 = omega1 z1/z2``).  So the entrainment crosses the contact line at right
angles in spur and helical pairs alike, with

    u_e = (u1 + u2)/2,      u_s = u1 - u2 = (omega1 + omega2) s        (mm/s),

and the radius across the line is the normal-section reduced radius
``R_x = xi1 xi2 / ((xi1 + xi2) cos(beta_b))``.

**Friction along a line.**  The friction model is that of an elliptical contact (film
thickness, Greenwood-Williamson asperities, Ree-Eyring shear;
:func:`gearjax.tribology.friction.friction_traced`).  A slice is a piece of a longer
contact line, so each slice is given the line it belongs to: the contact of line
load ``w`` (the slice's) over the whole line length ``L_k`` of its tooth pair at that
position, i.e. the load ``w L_k`` on the ellipse whose major semi-axis is ``L_k/2``
(the equivalent ellipse of the spur chain, :mod:`gearjax.loading.mesh_efficiency`).
The slice's friction force is ``mu F``.  For a spur pair (uniform line load) this is
exactly the spur chain's contact.

**Losses** ([Ohlendorf1958] for the check):

    P_f = sum mu F |u_s| (W after the unit factor),   P_in = T1 omega1,
    eta = 1 - sum_positions P_f / sum_positions P_in.

``sliding_power_per_mu`` = ``sum F |u_s|`` is the loss of a constant mu = 1: its cycle
mean over ``P_in`` is Ohlendorf's tooth loss factor ``H_V`` when the line load is
uniform (a check in the tests).

Units: N, mm, mm/s, W, rpm.  References (docs/references.md): [ISO21771];
[Litvin2004]; [Ohlendorf1958]; [VH-CATT] (the friction model).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import jax
import jax.numpy as jnp

from gearjax.gears.involute.geometry import pair_geometry
from gearjax.gears.involute.line_load import LineLoad, LineLoadOptions, line_load_traced
from gearjax.loading.mesh_efficiency import equivalent_ry
from gearjax.loading.tooth_compliance import E_STEEL, NU_STEEL
from gearjax.tribology.friction import FrictionResult, friction_traced

__all__ = ["LineEfficiency", "line_efficiency_traced"]


class LineEfficiency(NamedTuple):
    """Efficiency of a line-contact pair over one mesh cycle (module docstring).

    loads : the :class:`~gearjax.gears.involute.line_load.LineLoad`.
    u_e, u_s : (K, M, N) entrainment and (signed) sliding speeds (mm/s).
    r_x, r_y : (K, M, N) radii given to the friction model (mm; r_y of the equivalent
        ellipse).
    friction : :class:`~gearjax.tribology.friction.FrictionResult` per point.
    mu : (K, M, N) friction coefficient (0 where unloaded).
    power_loss : (M,) P_f (W).  power_in : P_in (W).  efficiency : (M,).
    mean_efficiency : eta over the cycle.  mean_mu : ``sum mu F|u_s| / sum F|u_s|``.
    sliding_power_per_mu : (M,) ``sum F |u_s|`` (W per unit mu).
    valid : (M,) the loads converged and every loaded point's friction converged.
    """

    loads: LineLoad
    u_e: jax.Array
    u_s: jax.Array
    r_x: jax.Array
    r_y: jax.Array
    friction: FrictionResult
    mu: jax.Array
    power_loss: jax.Array
    power_in: jax.Array
    efficiency: jax.Array
    mean_efficiency: jax.Array
    mean_mu: jax.Array
    sliding_power_per_mu: jax.Array
    valid: jax.Array


def line_efficiency_traced(pair, face_width, mods, torque_Nmm, misalignment_um_, pinion_rpm,
                           oil, surface, opts: LineLoadOptions, E=E_STEEL, nu=NU_STEEL,
                           drive=True, viscosity_model="roelands", film_method="auto",
                           s0=None) -> LineEfficiency:
    """:class:`LineEfficiency` of the pair at the operating point (traceable)."""
    r = line_load_traced(pair, face_width, mods, torque_Nmm, misalignment_um_, opts, E, nu,
                         drive, s0)
    geo = pair_geometry(pair)
    g = geo["a_w"] * jnp.sin(geo["alpha_wt"])
    xi1 = geo["rho_P"] + r.contact_s             # where each slice's load acts
    xi2 = g - xi1
    w1 = jnp.asarray(pinion_rpm, float) * (math.pi / 30.0)
    w2 = w1 * pair.z1 / pair.z2
    u_e = 0.5 * (w1 * xi1 + w2 * xi2)
    u_s = w1 * xi1 - w2 * xi2
    r_x = r.r_x
    loaded = r.load > 0.0
    L_line = jnp.sum(r.length, axis=2, keepdims=True)             # (K, M, 1)
    F_eq = jnp.where(loaded, r.line_load * L_line, 1.0)
    E_prime = E / (1.0 - nu ** 2)
    r_y = equivalent_ry(F_eq, r_x, jnp.broadcast_to(L_line, F_eq.shape), E_prime)
    ue_in = jnp.where(loaded, u_e, 1.0)

    def friction(F_, ue_, us_, rx_, ry_):
        return friction_traced(F_, ue_, us_, rx_, ry_, oil, surface, E_prime,
                               viscosity_model=viscosity_model, film_method=film_method)

    K, M, N = r.load.shape
    P = opts.path_points
    if 0 < P < K * N:
        # only the points on the path can carry load: at most P per position
        # (:func:`~gearjax.gears.involute.line_load.path_points_bound`); the friction
        # of those, put back in place (the rest carry no load: mu 0)
        def pos(a):
            return jnp.moveaxis(a, 1, 0).reshape(M, K * N)

        on = pos(r.length > 0.0)
        idx = jax.lax.top_k(on.astype(r.load.dtype), P)[1]          # (M, P)
        take = lambda a: jnp.take_along_axis(pos(a), idx, axis=1)  # noqa: E731
        fr_p = friction(*(take(a) for a in (F_eq, ue_in, jnp.abs(u_s), r_x, r_y)))
        rows = jnp.arange(M)[:, None]

        def back(a):
            full = jnp.zeros((M, K * N), a.dtype).at[rows, idx].set(a)
            return jnp.moveaxis(full.reshape(M, K, N), 0, 1)

        fr = jax.tree.map(back, fr_p)
        fr = fr._replace(converged=fr.converged | ~loaded)
        overflow = jnp.sum(on, axis=1) > P
    else:
        fr = friction(F_eq, ue_in, jnp.abs(u_s), r_x, r_y)
        overflow = jnp.zeros(M, bool)
    mu = jnp.where(loaded, fr.mu, 0.0)
    slide = jnp.sum(r.load * jnp.abs(u_s), axis=(0, 2))          # N mm/s
    loss = 1e-3 * jnp.sum(mu * r.load * jnp.abs(u_s), axis=(0, 2))
    p_in = 1e-3 * jnp.asarray(torque_Nmm, float) * w1
    fr_ok = jnp.all(jnp.where(loaded, fr.converged, True), axis=(0, 2)) & ~overflow
    return LineEfficiency(r, u_e, u_s, r_x, r_y, fr, mu, loss, p_in, 1.0 - loss / p_in,
                          1.0 - jnp.sum(loss) / (p_in * loss.shape[0]),
                          1e3 * jnp.sum(loss) / jnp.sum(slide), 1e-3 * slide,
                          r.converged & fr_ok)
