"""The spiral-bevel/hypoid pair as the loaded-contact models see it
(:class:`~gearjax.loading.loaded_contact.MeshTeeth`).

Each member is the virtual cylindrical gear of its normal section at the mean point
([ISO10300-1]): mean cone distance ``R_m = A_o - F/2``, mean normal module
``m_mn = 2 R_m sin(delta_1) cos(beta_m1) / z1`` (of the pinion; the gear's from its
own data), virtual tooth numbers ``z_v = z / cos(delta)``, ``z_vn = z_v / (cos^2(beta_vb)
cos(beta_m))``, ``sin(beta_vb) = sin(beta_m) cos(alpha_n)`` ([ISO10300-1];
:func:`gearjax.loading.pair_stiffness.virtual_cylindrical_teeth`; each member with its own
mean spiral angle).  Addendum and dedendum at the mean point
``h_am, h_fm`` give the tooth form: ``x = (h_am - h_fm) / (2 m_mn)``,
``h_a* = h_f* = (h_am + h_fm) / (2 m_mn)``.  The contact point maps onto the virtual
gear at its height above the root cone: ``r_v = z_vn m_mn / 2 - h_fm + h``.
Pressure angle: that of the generating blades of the flank pair (pinion and gear).

Load-carrying width: the major axis of the contact ellipse at the elastic approach
of the TCA (0.00632 mm, the bearing length of Gleason practice), at most the face
width: the bevel tooth is treated as a cantilever of that width (a beam model; the
load spreading into the neighbouring tooth length is neglected, which makes the
tooth on the soft side).

Units: mm, rad.  References (docs/references.md): [ISO10300-1].
"""

from __future__ import annotations

import jax.numpy as jnp

from gearjax.gears.hypoid.pair import HypoidPair, mean_dedendum
from gearjax.loading.loaded_contact import MeshTeeth
from gearjax.tca.result import TCAResult
from gearjax.loading.pair_stiffness import virtual_cylindrical_teeth

__all__ = ["hypoid_mesh_teeth"]


def _member(spec, h):
    b = spec.blank
    Rm = b.outer_cone_distance - 0.5 * b.face_width
    beta = b.mean_spiral_angle
    m_mn = 2.0 * Rm * jnp.sin(b.pitch_angle) * jnp.cos(beta) / b.teeth
    z_vn = virtual_cylindrical_teeth(b.teeth, b.pitch_angle, beta, spec.cutter.blade_angle).z_vn
    h_fm = mean_dedendum(b)
    h_am = b.outer_addendum - 0.5 * b.face_width * jnp.tan(b.face_angle - b.pitch_angle)
    x = (h_am - h_fm) / (2.0 * m_mn)
    hstar = (h_am + h_fm) / (2.0 * m_mn)
    r = 0.5 * z_vn * m_mn - h_fm + h
    return z_vn, m_mn, beta, x, hstar, r


def hypoid_mesh_teeth(pair: HypoidPair, res: TCAResult, drive: bool) -> MeshTeeth:
    """:class:`~gearjax.loading.loaded_contact.MeshTeeth` of the pair along the path of ``res``
    (traceable; module docstring)."""
    z1, m1, b1, x1, h1, r1 = _member(pair.pinion, res.coords["h1"])
    z2, m2, b2, x2, h2, r2 = _member(pair.gear, res.coords["h2"])
    alpha = jnp.stack([pair.pinion.cutter.blade_angle, pair.gear.cutter.blade_angle])
    F = jnp.minimum(pair.pinion.blank.face_width, pair.gear.blank.face_width)
    width = jnp.minimum(2.0 * jnp.nan_to_num(res.path.semi_major, nan=0.0, posinf=1e9), F)
    width = jnp.where(width > 0.0, width, F)
    return MeshTeeth(jnp.stack([z1, z2]), 0.5 * (m1 + m2), jnp.abs(alpha), 0.5 * (b1 + b2),
                     jnp.stack([x1, x2]), jnp.stack([h1, h2]), jnp.stack([h1, h2]),
                     jnp.stack([r1, r2]), width, None, jnp.asarray(drive))
