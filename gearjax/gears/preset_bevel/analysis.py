"""What the seed claims, measured on a TCA result of the preset-TE bevel pair:
pure rolling, the preset TE, the transfer between tooth pairs, the contact ends
([Preset-TE-bevel]).  Every function is traceable (``jax.grad`` passes) unless it
says "concrete".

**Preset TE.**  The pinion point ``t`` of the modified curve reaches the pitch line at
``phi1 = t + phase - s kappa (t - t_m)^2`` while the gear point conjugate to the
unmodified curve is there at ``phi2 = -(z1/z2)(t + phase)``; in gearjax's TE (gear
angle, :mod:`gearjax.tca.path`) the preset is therefore

    TE_preset(phi1) = s (z1/z2) kappa x^2,   x - s kappa x^2 = phi1 - phi1_ref,
    x = 2 y / (1 + sqrt(1 - 4 s kappa y)),   y = phi1 - phi1_ref,

(``s`` = +1 drive/concave, -1 coast/convex; ``x = t - t_m``).  The seed's "36
arc-seconds" is the pinion rotation ``kappa (t_min - t_m)^2``; as gear angle it is
``(z1/z2)`` of that (12 arc-seconds for 10/30 teeth).

**Transfer gaps.**  Tooth pair 0 is on both flanks between ``phi_in`` and ``phi_out``
(zero crossings of the boundary margin: bracketed on the grid, then two Newton steps on
its quadratic interpolant).  Where it enters,
pair -1 (pair 0 one pitch later, ``TE_{-1}(phi) = TE_0(phi + p)``, ``p = 2 pi/z1``)
carries the motion; where it leaves, pair +1 (``TE_0(phi - p)``).  With ``sgn = +1``
for the maximum envelope and -1 for the minimum::

    gap_in  = sgn (TE_0(phi_in)  - TE_0(phi_in + p)),
    gap_out = sgn (TE_0(phi_out) - TE_0(phi_out - p)).

A positive gap is a jump of the TE envelope at the transfer (the new pair takes
over ahead of the old one, or the old one runs off the face while still leading); a
negative gap means the curves cross inside the overlap (a smooth transfer).  TE of
pair 0 between grid points: quadratic interpolation of the TE curve (the contact
solve continues beyond the face ends, so the curve is smooth across them).

**Pure rolling.**  The sliding speed at the contact, ``|v12| = |omega1 x r - omega2 x
(r - c)|`` (tangential), relative to the pitch-line speed ``omega1 |r x e_z|``.  From
the kinematics of the result (``u_s``, ``u_s_side``) when present.

Units: mm, rad (arc-seconds only in names ending ``_arcsec``).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.gears.preset_bevel.geometry import PresetBevelDesign, cone_distances
from gearjax.tca.multi_pair import flank_crossings, interp_uniform
from gearjax.tca.multi_pair import transfer_gaps as transfer_gaps_of
from gearjax.tca.path import ARCSEC
from gearjax.tca.result import TCAResult

__all__ = ["preset_te", "preset_deviation", "interp_uniform", "margin_crossings",
           "transfer_gaps", "transfer_jump", "sliding_ratio", "contact_ends", "smooth_max"]


def _sign(res: TCAResult):
    return 1.0 if res.side == "drive" else -1.0


def preset_te(des: PresetBevelDesign, res: TCAResult):
    """(N,) the preset TE (gear angle, rad) on the grid of ``res`` (module docstring)."""
    s = _sign(res)
    phi = res.path.phi1
    y = phi - phi[phi.shape[0] // 2]
    k = des.kappa
    x = 2.0 * y / (1.0 + jnp.sqrt(jnp.maximum(1.0 - 4.0 * s * k * y, 0.0)))
    return s * (des.z1 / des.z2) * k * x ** 2


def preset_deviation(des: PresetBevelDesign, res: TCAResult, on=None):
    """Largest ``|TE - TE_preset|`` (rad) over the grid points ``on`` (default: pair 0
    on both flanks, concrete mask)."""
    on = np.asarray(res.on_flank) if on is None else np.asarray(on)
    d = jnp.abs(res.path.te - preset_te(des, res))
    return jnp.max(jnp.where(on, d, 0.0))


def margin_crossings(res: TCAResult):
    """``(phi_in, phi_out)``: pinion angles where pair 0's margin crosses zero entering
    and leaving the flanks (bracketed on the grid, refined on the quadratic interpolant
    of the margin; NaN if none)."""
    return flank_crossings(res.path, res.margin)


def transfer_gaps(res: TCAResult, z1: int, steps_per_pitch: int):
    """``(gap_in, gap_out)`` (rad, module docstring): > 0 is a TE jump at the transfer
    (:func:`gearjax.tca.multi_pair.transfer_gaps`; ``z1`` and ``steps_per_pitch`` are
    those of the result's grid, kept for the callers)."""
    return transfer_gaps_of(res.path, res.margin, res.multi)


def transfer_jump(res: TCAResult, z1: int, steps_per_pitch: int):
    """Largest TE jump at the transfers into and out of pair 0 (rad, >= 0)."""
    g_in, g_out = transfer_gaps(res, z1, steps_per_pitch)
    return jnp.maximum(jnp.maximum(g_in, g_out), 0.0)


def smooth_max(x, tau):
    """``tau log sum exp(x/tau)``: a smooth upper bound of ``max(x)`` (within ``tau log
    n``)."""
    x = jnp.asarray(x)
    m = jax.lax.stop_gradient(jnp.max(x))
    return m + tau * jnp.log(jnp.sum(jnp.exp((x - m) / tau)))


def sliding_ratio(res: TCAResult):
    """(N,) sliding speed over pitch-line speed at every contact (needs kinematics):
    ``sqrt(u_s^2 + u_s_side^2) / |r x e_z|`` (both per rad/s of pinion speed)."""
    k = res.kinematics
    us = jnp.sqrt(k.u_s ** 2 + k.u_s_side ** 2)
    r = res.path.point
    return us / jnp.sqrt(r[:, 0] ** 2 + r[:, 1] ** 2)


def contact_ends(des: PresetBevelDesign, res: TCAResult):
    """Where pair 0 takes over and hands over the load (concrete dict, mm): at each
    transfer point of the unloaded envelope (``multi.transfer_phi1``; for a pair whose
    TE curves coincide with its neighbours' -- the unmodified pair -- the margin
    crossings instead) the contact's cone distance on the pinion, its distance from
    the toe (``A_i``) and the heel (``A_o``) and its height above the pitch cone."""
    phi = res.path.phi1
    h = float(phi[1] - phi[0])
    Ai, _, Ao = (float(v) for v in cone_distances(des))
    tr = np.asarray(res.multi.transfer_phi1, float)
    cross = [float(v) for v in margin_crossings(res)]
    if float(res.multi.ptp) < 1e-6 * ARCSEC:        # coincident TE curves: load shared
        tr = np.array(cross)
    out = {}
    for name, x, xc in (("first", tr[0], cross[0]), ("last", tr[1], cross[1])):
        x = x if np.isfinite(x) else xc
        if not np.isfinite(x):
            out[name] = None
            continue
        L = float(interp_uniform(phi[0], h, res.coords["L1"], x))
        hh = float(interp_uniform(phi[0], h, res.coords["h1"], x))
        out[name] = {"phi1_rad": float(x), "cone_distance_mm": L, "from_toe_mm": L - Ai,
                     "from_heel_mm": Ao - L, "height_mm": hh}
    return out

