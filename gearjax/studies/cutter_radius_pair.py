"""The gear set of [Eigenfunctions] as a machine-cut pair: the formate gear whose flank is the
study's cutter cone, the pinion it generates, and the link between the two models.

[Eigenfunctions] §2 (see docs/references.md) models the gear flank as the face-mill
cutter cone placed at the pitch point (:func:`gearjax.studies.cutter_radius.pitch_setup`)
and reads the meshing characteristics off the eigenfunctions, with the pinion only
implied as the conjugate surface.  Here the same cone becomes a formate gear on the cradle machine
of :mod:`gearjax.gears.hypoid.machine` (:func:`gearjax.gears.hypoid.formate.formate_from_placement`:
classical formate set-up, no tilt), the pinion is generated from it by the machine
chain (:func:`gearjax.gears.hypoid.formate.generating_gear_pinion`: the gear as generating
gear, a tilted cutter), and tooth contact analysis
(:mod:`gearjax.gears.hypoid.tca`) finds the actual contact points; the kinematics there
(:mod:`gearjax.gears.hypoid.contact_kinematics`) are compared with the fields of that model.

Frames: the fixed frame ``S_f`` of [Eigenfunctions] (:mod:`gearjax.gears.hypoid.pitch_cones`: gear axis
``u2 = e_z`` through the origin, which is the gear's crossing point; pinion axis
``u1`` through ``C1 = (E, 0, 0)``) and the gear work frame of :mod:`gearjax.gears.hypoid.machine`
(origin at the pitch apex ``A2 = P - R_m2 g2``, ``z`` apex to heel):
``p_f = A2 + Q p_w``, ``Q = [x_w, y_w, z_w]``.  The cutter frame of
:mod:`gearjax.gears.hypoid.cutter` (blade tips in ``z_t = 0``, ``s`` along the blade from the
tip) is the paper's cone frame ``(x_c, y_c, z_c = k)`` shifted to the gear root:
the paper's slant length ``u`` (from the pitch plane, positive towards the gear
root) is ``u = u_root - s``, ``u_root = h_fm2/cos(a)``; point radius
``R_p = r0 + shift - sb u_root sin(a)``, blade sign ``-sb``.

Units: mm, rad.  Reference: [Eigenfunctions] §2.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.gears.hypoid.cutter import FaceMillCutter
from gearjax.gears.hypoid.formate import formate_from_placement, generating_gear_pinion
from gearjax.gears.hypoid import pitch_cones
from gearjax.gears.hypoid.flank import FlankSpec, MemberBlank
from gearjax.gears.hypoid.blank import BlankInput
from gearjax.studies.cutter_radius import StudySettings, pitch_setup
from gearjax.gears.hypoid.tca import HypoidPair

__all__ = ["StudyPair", "study_pair", "study_uv"]


class StudyPair(NamedTuple):
    """The machine-cut pair of [Eigenfunctions] and the frame data linking it to the cone model.

    pair : :class:`~gearjax.gears.hypoid.tca.HypoidPair` (formate gear, generated pinion).
    setup : the cone model's :class:`~gearjax.studies.cutter_radius.PitchSetup`.
    info : :func:`~gearjax.gears.hypoid.formate.generating_gear_pinion`'s info.
    A2 : (3,) gear pitch apex in ``S_f``; Q : (3, 3) gear work axes in ``S_f``.
    phi0 : work phase of the formate settings (rad; flank of the settings = placed
        cone turned by ``phi0`` about the gear axis).
    u_root : slant length ``u`` (cone model) of the blade tips (gear root), mm.
    All arrays are ``jax.Array`` (traced under ``jax.grad``).
    """

    pair: HypoidPair
    setup: object
    info: dict
    A2: jax.Array
    Q: jax.Array
    phi0: jax.Array
    u_root: jax.Array


#: reflection y -> -y (homogeneous): the mirror image of the cone model's set (left hand)
_MIRROR = np.diag([1.0, -1.0, 1.0, 1.0])


def _member_blank(bd, k: int, teeth: int, hand: str) -> MemberBlank:
    f = lambda name: jnp.asarray(bd[f"{name}{k}"], float)
    return MemberBlank(f("Re"), f("b"), f("delta"), f("delta_a"), f("delta_f"), f("hae"), f("hfe"),
                       f("beta_m"), teeth, hand)


def study_pair(inp: BlankInput, settings: StudySettings, flank: str = "convex",
               edge_radius=0.0) -> StudyPair:
    """The [Eigenfunctions] set of ``inp`` with the cutter of ``settings`` as a machine-cut pair
    (module docstring).  ``flank`` is the gear flank ("convex": drive side, mating the
    pinion concave flank).  ``edge_radius`` of the blades (mm; the paper's cone has none).

    Placement of the cone (cutter -> gear work, ``p_w = Q^T (p_f - A2)``):
    ``G = [Q^T [x_c y_c z_c], Q^T (C + u_root cos(a) z_c - A2)]`` with the cone's
    centre ``C`` and axes from :func:`~gearjax.studies.cutter_radius.pitch_setup`;
    point radius ``R_p = r0 + shift - sb u_root sin(a)``; crossing points
    ``t1 = (C1 - A1) . z_w1``, ``t2 = -A2 . z_w2`` (``A_k = P - R_k g_k`` the pitch apexes,
    ``z_wk = sgn(g_k . u_k) u_k`` apex to heel).  Hand of spiral: the cone model (pinion
    axis through ``(+E, 0, 0)``) is the right-hand pinion set (pinion blank offset ``+E``
    on its machine, hand measured on the generated flanks); ``inp.hand == "left"``
    places the mirror image ``M G M``, ``M = diag(1, -1, 1, 1)`` (the cone reflected in
    the gear work frame's x-z plane), and the pinion it generates is the mirror image
    too.  A spiral-bevel set (offset 0) lays the cutter along the tooth trace at the mean
    spiral angle (:func:`~gearjax.studies.cutter_radius.pitch_setup`).
    Differentiable with respect to
    ``settings`` (and ``edge_radius``); under ``jax.jit`` the mean-contact search of
    :func:`~gearjax.gears.hypoid.formate.generating_gear_pinion` is refused.
    """
    s = pitch_setup(inp, settings, flank)
    bd = s.blank
    _check_gear_spiral(bd["beta_m2"])
    geo = pitch_cones.cone_tangency(bd["delta1"], bd["delta2"], inp.shaft_angle, inp.offset,
                                    bd["Rm2"])
    P, g1, g2, u1, u2 = s.P, geo["g1"], geo["g2"], s.u1, s.u2
    A2 = P - bd["Rm2"] * g2
    A1 = P - geo["R1"] * g1
    zw2 = jax.lax.stop_gradient(jnp.sign(g2 @ u2)) * u2   # a side (+-1): no derivative
    zw1 = jax.lax.stop_gradient(jnp.sign(g1 @ u1)) * u1
    xw = jnp.array([1.0, 0.0, 0.0]) - zw2[0] * zw2
    xw = xw / jnp.linalg.norm(xw)
    Q = jnp.stack([xw, jnp.cross(zw2, xw), zw2], axis=1)
    off = jnp.asarray(inp.offset, float)
    C1 = jnp.stack([off, 0.0 * off, 0.0 * off])
    t1 = (C1 - A1) @ zw1
    t2 = -A2 @ zw2
    a = s.blade
    sb = -1.0 if flank == "convex" else 1.0              # pitch_setup's blade side
    u_root = bd["hfm2"] / jnp.cos(a)
    r0 = jnp.linalg.norm(s.centre - P)
    cutter = FaceMillCutter(r0 - sb * u_root * jnp.sin(a), a, jnp.asarray(edge_radius, float),
                            int(-sb))
    G = (jnp.eye(4).at[:3, :3].set(Q.T @ jnp.stack([s.xc, s.yc, s.zc], axis=1))
         .at[:3, 3].set(Q.T @ (s.centre + u_root * jnp.cos(a) * s.zc - A2)))
    if inp.hand == "left":
        # the cone model (pinion axis through (+E, 0, 0)) is the right-hand pinion set;
        # its mirror image in the gear work frame's x-z plane: M G M with M = diag(1, -1,
        # 1, 1) (work side: the reflection; cutter side: the cone reflected in its own
        # x-z plane, the same cone; M G M is a proper rigid motion)
        G = _MIRROR @ G @ _MIRROR
    hands = ("left", "right") if inp.hand == "left" else ("right", "left")
    gear_blank = _member_blank(bd, 2, inp.z2, hands[1])
    gear, phi0 = formate_from_placement(cutter, G, gear_blank)
    placeholder = FlankSpec(cutter, gear.machine, _member_blank(bd, 1, inp.z1, hands[0]))
    pair = HypoidPair(placeholder, gear, jnp.asarray(inp.shaft_angle, float), off, t1, t2,
                      inp.z1, inp.z2, 1)
    # mounting hand: the cone model is the right-hand set (+1), its mirror image the
    # left-hand one (-1); searching both (the closer mean contact wins) picked the mirror
    # mounting for a gear spiral angle near 0 (8/43, E = 47 mm, beta_m2 = 0.26 deg: a
    # right-hand design's pinion cut left-handed; the bevel sweep).  At E = 0 both
    # mountings are the same set (mirror images through the plane of the axes): searched
    pair, info = generating_gear_pinion(pair, hand=_mount_hand(inp))
    return StudyPair(pair, s, info, A2, Q, phi0, u_root)


def _mount_hand(inp) -> int | None:
    """+1 (right-hand design) / -1 (left-hand) for an offset pair, None (search) at E = 0
    or for a traced offset."""
    from gearjax.errors import is_traced
    if is_traced(inp.offset) or not float(inp.offset) > 0.0:
        return None
    return 1 if inp.hand == "right" else -1


def _check_gear_spiral(beta_m2) -> None:
    """Refuse a blank whose gear mean spiral angle is not positive (concrete values; a
    traced one passes).  With ``beta_m2 <= 0`` (a large offset with a small pinion spiral
    angle: ``beta_m2 = beta_m1 - eps'``) the gear's trace turns the other way and the
    route's mirror rule for the hand no longer holds: it cut a right-hand design's
    pinion left-handed (measured on the generated flanks; the bevel sweep, docs/hypoid.md)."""
    from gearjax.errors import is_traced
    if is_traced(beta_m2):
        return
    b = float(beta_m2)
    if not b > 0.0:
        raise ValueError(f"beta_m2 = {math.degrees(b):.4g} deg (the blank's gear mean spiral "
                         "angle): the cone-model flank route needs beta_m2 > 0 deg (gear and "
                         "pinion of opposite hands); raise the pinion spiral angle or reduce "
                         "the offset")


def study_uv(sp: StudyPair, p2_body):
    """Cone-model flank parameters ``(u, theta)`` (mm, rad) of gear body-frame points
    ``(..., 3)`` (the TCA's ``path.p2_body``): into ``S_f`` (undoing the work phase
    ``phi0``: ``p_f = A2 + Q Rz(-phi0) (p + t2 e_z)``), then into the paper's cone frame,
    ``u = (p_f - C) . z_c / cos(a)``, ``theta = atan2((p_f - C) . y_c, (p_f - C) . x_c)``."""
    p = jnp.asarray(p2_body, float) + jnp.stack([0.0, 0.0, jnp.asarray(sp.pair.gear_crossing, float)])
    c, s_ = jnp.cos(-sp.phi0), jnp.sin(-sp.phi0)
    Rz = jnp.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])
    pw = p @ Rz.T
    if sp.pair.gear.blank.hand == "right":       # left-hand pinion: the mirrored cone
        pw = pw * jnp.array([1.0, -1.0, 1.0])
    pf = sp.A2 + pw @ sp.Q.T
    st = sp.setup
    d = pf - st.centre
    u = (d @ st.zc) / jnp.cos(st.blade)
    th = jnp.arctan2(d @ st.yc, d @ st.xc)
    return jnp.stack([u, th], axis=-1)
