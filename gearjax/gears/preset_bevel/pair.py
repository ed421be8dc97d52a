"""The preset-TE bevel pair mounted for tooth contact analysis: assembly, sides, flank
boundaries, reference contact ([Preset-TE-bevel]).

**Mounting** (:class:`gearjax.tca.assembly.Assembly`): fixed frame = pinion frame at phi1 = 0
(apex at the origin, pinion axis z); gear body -> fixed ``R0 = Rx(-Sigma)``, crossing
point ``c0 = 0`` (the apex), common perpendicular ``d = x`` (the direction of an offset
``dE``; ``dSigma`` turns the gear axis about it), nominal ratio ``-z1/z2``
(``phi2 = -(z1/z2) phi1``, :mod:`gearjax.gears.preset_bevel.geometry`).

**Sides.**  ``"drive"``: pinion concave flank on gear convex flank (the seed's
driving side), pinion curve at phase 0.  ``"coast"``: pinion convex flank of the next
tooth (phase ``+pi/z1``) on gear concave flank.  The concave flank faces the seed's
+theta direction, so it pushes the gear when the pinion turns by *decreasing*
``phi1``: its unloaded TE envelope (gearjax's TE, defined for increasing phi1) is the
*minimum* over the tooth pairs; the coast side pushes for increasing phi1 (maximum).

**Flank boundaries** (both members in their body frames, apex at the origin): the
face ends are the spheres of cone distance ``|q| = A_i`` (toe) and ``A_o`` (heel), the
tip and root lines the heights ``h = r cos delta - z sin delta`` (signed distance from
the pitch cone, r the distance from the member's axis) ``h = +addendum`` and
``h = -dedendum``; margin = the smallest distance to them (mm, >= 0 inside).

**Edge contact** (:func:`preset_face_ends`, for :func:`gearjax.tca.edge_contact.face_end_contact`):
the face-end functions ``g(q, e) = |q| - A_m - e b/2`` (mm; zero on the toe sphere
``|q| = A_i`` for ``e = -1`` and on the heel sphere ``|q| = A_o`` for ``e = +1``) and the
tip functions ``t(q) = addendum - h(q)`` (mm; zero on the face cone, > 0 below it).

Units: mm, rad.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.gears.preset_bevel.geometry import (PresetBevelDesign, cone_distances, curve_range,
                                                 gear_assembly_rotation, gear_flank,
                                                 pinion_flank, pitch_angles)
from gearjax.tca.assembly import Assembly
from gearjax.tca.path import smallest_margin

__all__ = ["SIDE_FLANKS", "preset_assembly", "side_flanks", "side_phase", "drives_forward", "side_code",
           "flank_coordinates", "preset_margin", "reference_contact",
           "preset_face_ends"]

#: side -> (pinion flank, gear flank)
SIDE_FLANKS = {"drive": ("concave", "convex"), "coast": ("convex", "concave")}


def preset_assembly(des: PresetBevelDesign) -> Assembly:
    """The nominal mounting (module docstring)."""
    R0 = gear_assembly_rotation(des.shaft_angle)
    z = jnp.zeros(3)
    return Assembly(R0, z, jnp.array([1.0, 0.0, 0.0]), des.z1, des.z2, -1)


def side_code(side: str) -> float:
    """The flank sign of the pinion flank of ``side``: +1 drive (concave), -1 coast
    (convex).  A number, so that it can be a traced argument: both sides share one
    compiled program."""
    return 1.0 if side == "drive" else -1.0


def side_phase(des: PresetBevelDesign, side):
    """Phase (rad) of the pinion contact curve of the flank pair of ``side`` (a name or
    its :func:`side_code`): 0 drive, ``pi/z1`` coast."""
    code = side_code(side) if isinstance(side, str) else side
    return 0.5 * (1.0 - code) * (np.pi / des.z1)


def drives_forward(side):
    """Whether the pinion flank of ``side`` (name or code) pushes the gear for increasing
    phi1 (the TE envelope is then the maximum over the pairs): the coast side."""
    code = side_code(side) if isinstance(side, str) else side
    return code < 0.0


def side_flanks(des: PresetBevelDesign, side):
    """``(r1, r2)``: pinion and gear flank functions ``uv -> (3,)`` of ``side`` (a name
    or its code, which may be traced)."""
    code = side_code(side) if isinstance(side, str) else side
    ph = side_phase(des, code)
    return pinion_flank(des, code, ph), gear_flank(des, code, ph)


def flank_coordinates(des: PresetBevelDesign, q, member: int):
    """``(L, h)``: cone distance and height above the pitch cone (mm) of body points q."""
    d1, d2 = pitch_angles(des)
    d = d1 if member == 1 else d2
    r = jnp.linalg.norm(q[..., :2], axis=-1)
    return jnp.linalg.norm(q, axis=-1), r * jnp.cos(d) - q[..., 2] * jnp.sin(d)


def preset_margin(des: PresetBevelDesign, p1_body, p2_body):
    """``(margin, coords)``: boundary margin of the contact (mm, >= 0 inside both
    flanks; module docstring) and ``coords`` ``{"L1", "h1", "L2", "h2"}`` (mm)."""
    Ai, _, Ao = cone_distances(des)
    L1, h1 = flank_coordinates(des, p1_body, 1)
    L2, h2 = flank_coordinates(des, p2_body, 2)
    parts = jnp.stack([Ao - L1, L1 - Ai, des.addendum - h1, h1 + des.dedendum,
                       Ao - L2, L2 - Ai, des.addendum - h2, h2 + des.dedendum])
    return smallest_margin(parts), {"L1": L1, "h1": h1, "L2": L2, "h2": h2}


def preset_face_ends(des: PresetBevelDesign):
    """``(margin_parts, g1, g2, (t1, t2))`` of :func:`gearjax.tca.edge_contact.face_end_contact`
    (module docstring): each member's margins (mm, >= 0 inside) to its face ends (the
    nearer of toe and heel), tip (face cone) and root at body points (N, 3), the face-end
    functions ``g_k(q, e)`` and the tip-edge functions ``t_k(q)`` of pinion and gear."""
    Ai, Am, Ao = cone_distances(des)

    def parts(q, member):
        L, h = flank_coordinates(des, q, member)
        return jnp.minimum(Ao - L, L - Ai), des.addendum - h, h + des.dedendum

    def margin_parts(q1, q2, uv1=None, uv2=None):
        return parts(q1, 1) + parts(q2, 2)

    def end(q, e):
        return jnp.linalg.norm(q) - Am - 0.5 * e * des.face_width

    def tip(member):
        return lambda q: des.addendum - flank_coordinates(des, q, member)[1]

    return margin_parts, end, end, (tip(1), tip(2))


def reference_contact(des: PresetBevelDesign, side: str):
    """``(x_ref, phi1_ref)``: the contact of the unmodified pair at mid-face
    (``u = v = 0``, ``t = t_m``, ``phi1 = t_m + phase``, ``phi2 = -(z1/z2) phi1``) -- exact
    for kappa = 0 and a starting point otherwise (no derivative flows into it)."""
    _, tm, _ = curve_range(des)
    phi1 = tm + side_phase(des, side)
    x = jnp.stack([0.0 * tm, tm, 0.0 * tm, tm, -(des.z1 / des.z2) * phi1])
    return jax.lax.stop_gradient(x), jax.lax.stop_gradient(phi1)
