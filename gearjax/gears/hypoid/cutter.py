"""Straight-blade face-mill cutter surfaces (inside and outside blades, edge fillet).

A face-mill cutter head carries blades whose straight cutting edges sweep cones
about the cutter axis ``z_t``.  In the cutter frame S_t (origin on the cutter axis in
the plane of the blade tips, ``z_t`` pointing from the cutter head towards the
workpiece) the generating cone of [HFT-hypoid] (see docs/references.md) is

    r_t(s, theta) = [ (R_p - sgn * s * sin(alpha)) cos(theta),
                      (R_p - sgn * s * sin(alpha)) sin(theta),
                      -s * cos(alpha) ]                                   [HFT-hypoid]

with ``s`` the distance along the blade from its tip (mm, arc length), ``theta``
the angular position about the cutter axis (rad), ``R_p`` the point radius (mm,
radius of the blade tip corner), ``alpha`` the blade (pressure) angle, and
``sgn = +1`` for the blade that cuts a *convex* flank (inside blade: its radius
shrinks towards the tooth tip) and ``sgn = -1`` for the blade that cuts a
*concave* flank (outside blade).  This is the sign convention of [HFT-hypoid].

Unit normal (gearjax's orientation, not stated in [HFT-hypoid]): the normal points from
the workpiece material into the tooth space, i.e. into the blade,

    n_t(theta) = [ sgn cos(alpha) cos(theta), sgn cos(alpha) sin(theta), -sin(alpha) ],

which is ``sgn * (dr/ds x dr/dtheta)/|.|`` (checked in tests).

Edge radius (root fillet): the blade tip corner is rounded with radius ``rho_f``.
The straight part starts at ``s_min = rho_f (1 - sin(alpha)) / cos(alpha)`` ([HFT-hypoid],
"fillet start"); the fillet is a torus segment whose normal turns from the blade
normal (angle ``alpha``) to ``-z_t`` (angle ``pi/2``):

    centre (radial, axial) = (R_p + sgn*s_min, -rho_f),
    point  = centre - rho_f * (sgn cos(phi), -sin(phi)),  phi in [alpha, pi/2].

Units: mm, rad.  References (docs/references.md): [HFT-hypoid];
[Litvin2004] ch. 21 (head-cutters for spiral bevel
gears).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import check_range, is_traced
from gearjax.fields import floats_for_ints

__all__ = ["FaceMillCutter", "make_cutter", "cutter_point", "cutter_normal",
           "cutter_tangents", "fillet_start", "fillet_point", "fillet_normal",
           "blade_radius", "blade_data", "cone_radius", "cone_point", "cone_normal",
           "cone_surface_normal"]


@functools.partial(jax.tree_util.register_dataclass,
                   data_fields=["point_radius", "blade_angle", "edge_radius", "sign"],
                   meta_fields=[])
@dataclass(frozen=True)
class FaceMillCutter:
    """One blade of a straight-blade face-mill cutter (a pytree).

    Attributes
    ----------
    point_radius : R_p, radius of the blade tip corner (mm).
    blade_angle : alpha, blade (pressure) angle, in (0, pi/4) (rad).
    edge_radius : rho_f, radius of the blade tip fillet (mm), >= 0.
    sign : +1 inside blade (cuts a convex flank), -1 outside blade (concave flank);
        a data field (it only multiplies: the drive and coast flanks share a compiled
        program).
    """

    point_radius: jax.Array
    blade_angle: jax.Array
    edge_radius: jax.Array
    sign: jax.Array = 1

    def __post_init__(self):
        floats_for_ints(self, ("sign",))

    @property
    def side(self) -> str:
        return "convex" if self.sign > 0 else "concave"


def _reject_non_number(name, v):
    """ValueError for a bool, string, bytes, None, list, tuple or dict where a number
    is expected (``float()`` would accept some of them); numbers, arrays and JAX
    tracers pass (tracers unchecked)."""
    if v is None or isinstance(v, (bool, np.bool_, str, bytes, list, tuple, dict, set)):
        raise ValueError(f"{name} = {v!r} must be a number, got {type(v).__name__}")


def make_cutter(point_radius, blade_angle_deg, edge_radius, flank: str) -> FaceMillCutter:
    """Validated constructor (file units: mm and degrees).

    ``flank`` is "convex" (inside blade, sgn = +1) or "concave" (outside blade,
    sgn = -1).  Allowed: point_radius in (0, 1e4] mm, blade_angle in (0, 45) deg,
    edge_radius >= 0 mm and small enough for the blade tip (the fillet ends inside
    the point radius), all finite numbers (not bool or str).  Raises ValueError
    naming the parameter, the value and the allowed range; traced values (inside
    ``jax.grad``) pass unchecked.
    """
    if not isinstance(flank, str) or flank not in ("convex", "concave"):
        raise ValueError(f"flank = {flank!r} must be 'convex' or 'concave'")
    for name, v in (("point_radius", point_radius), ("blade_angle", blade_angle_deg),
                    ("edge_radius", edge_radius)):
        _reject_non_number(name, v)
    R = check_range("point_radius", point_radius, 0.0, 1e4, lo_open=True, unit="mm")
    a = check_range("blade_angle", blade_angle_deg, 0.0, 45.0, lo_open=True, hi_open=True,
                    unit="deg")
    rho = check_range("edge_radius", edge_radius, 0.0, None, unit="mm")
    a_rad = a * (math.pi / 180.0)
    if not any(is_traced(v) for v in (R, a, rho)):      # traced values pass unchecked
        s_min = rho * (1.0 - math.sin(a_rad)) / math.cos(a_rad)
        if s_min * math.sin(a_rad) + rho >= R:
            raise ValueError(f"edge_radius = {rho:g} mm is too large for point_radius = {R:g} mm")
    return FaceMillCutter(jnp.asarray(R, float), jnp.asarray(a_rad, float), jnp.asarray(rho, float),
                          1 if flank == "convex" else -1)


def blade_data(c: FaceMillCutter):
    """The blade's constants ``(R_p, sgn sin(alpha), cos(alpha), sgn cos(alpha),
    sin(alpha))`` (5,): the cone and its normal below need nothing else, so a flank
    solve can take them once instead of the cutter (whose sign is static)."""
    sa, ca = jnp.sin(c.blade_angle), jnp.cos(c.blade_angle)
    return jnp.stack([c.point_radius, c.sign * sa, ca, c.sign * ca, sa])


def cone_radius(blade, s):
    """Radius of the blade cone at distance ``s`` (mm) from the tip: R_p - sgn s sin(alpha)
    (``blade`` from :func:`blade_data`)."""
    return blade[0] - s * blade[1]


def cone_point(blade, s, theta):
    """Point r_t(s, theta) of the straight-blade cone in the cutter frame (mm),
    [HFT-hypoid] (``blade`` from :func:`blade_data`)."""
    rho = cone_radius(blade, s)
    return jnp.stack([rho * jnp.cos(theta), rho * jnp.sin(theta), -s * blade[2]])


def cone_normal(blade, theta):
    """Unit normal of the blade cone (out of the workpiece material into the slot),
    ``(sgn cos(alpha) cos(theta), sgn cos(alpha) sin(theta), -sin(alpha))``."""
    return jnp.stack([blade[3] * jnp.cos(theta), blade[3] * jnp.sin(theta),
                      -blade[4] * jnp.ones_like(theta)])


def cone_surface_normal(blade, s, theta):
    """Unit normal ``r_theta x r_s/|r_theta x r_s|`` of :func:`cone_point` in the
    order of its parameters ``uv = (theta, s)``, in closed form:

        r_theta x r_s = -rho (b2 cos(theta), b2 sin(theta), -b1),   rho = R_p - b1 s,

    with ``b1 = sgn sin(alpha)``, ``b2 = cos(alpha)`` (``blade`` from :func:`blade_data`;
    any values of ``b1``, ``b2``, so that its derivatives by them are those of the
    autodiff normal).  ``-sgn`` times :func:`cone_normal` for a real blade."""
    b1, b2 = blade[1], blade[2]
    m = -jnp.sign(cone_radius(blade, s)) / jnp.sqrt(b1 * b1 + b2 * b2)
    return jnp.stack([m * b2 * jnp.cos(theta), m * b2 * jnp.sin(theta), -m * b1])


def blade_radius(c: FaceMillCutter, s):
    """Radius of the blade cone at distance ``s`` (mm) from the tip: R_p - sgn s sin(alpha)."""
    return cone_radius(blade_data(c), s)


def cutter_point(c: FaceMillCutter, s, theta):
    """Point r_t(s, theta) of the straight-blade cone in the cutter frame (mm), [HFT-hypoid]."""
    return cone_point(blade_data(c), s, theta)


def cutter_normal(c: FaceMillCutter, s, theta):
    """Unit normal of the blade cone (points out of the workpiece material into the slot)."""
    del s
    return cone_normal(blade_data(c), theta)


def cutter_tangents(c: FaceMillCutter, s, theta):
    """(dr/ds, dr/dtheta) of the blade cone by forward-mode autodiff (mm, mm/rad)."""
    f = lambda a, b: cutter_point(c, a, b)
    return jax.jacfwd(f, 0)(s, theta), jax.jacfwd(f, 1)(s, theta)


def fillet_start(c: FaceMillCutter):
    """s_min = rho_f (1 - sin alpha) / cos alpha: where the straight blade meets the fillet (mm)."""
    a = c.blade_angle
    return c.edge_radius * (1.0 - jnp.sin(a)) / jnp.cos(a)


def fillet_point(c: FaceMillCutter, phi, theta):
    """Point on the tip-fillet torus, ``phi`` in [alpha, pi/2] the normal's angle (mm)."""
    sg = c.sign
    rc = c.point_radius + sg * fillet_start(c)
    zc = -c.edge_radius
    r = rc - c.edge_radius * sg * jnp.cos(phi)
    z = zc + c.edge_radius * jnp.sin(phi)
    return jnp.stack([r * jnp.cos(theta), r * jnp.sin(theta), z])


def fillet_normal(c: FaceMillCutter, phi, theta):
    """Unit normal of the fillet torus (same orientation as :func:`cutter_normal`)."""
    sg = c.sign
    return jnp.stack([sg * jnp.cos(phi) * jnp.cos(theta), sg * jnp.cos(phi) * jnp.sin(theta),
                      -jnp.sin(phi) * jnp.ones_like(theta)])
