"""Seed 000's gear set as a machine-cut pair: the formate gear whose flank is the
study's cutter cone, the pinion it generates, and the link between the two models.

Seed 000 (§2) models the gear flank as the face-mill cutter cone placed at the pitch
point (:func:`gearjax.studies.cutter_radius.pitch_setup`) and reads the meshing
characteristics off the eigenfunctions, with the pinion only implied as the
conjugate surface.  Here the same cone becomes a formate gear on the cradle machine
of :mod:`gearjax.gears.hypoid.machine` (:func:`gearjax.gears.hypoid.formate.formate_from_placement`:
classical formate set-up, no tilt), the pinion is generated from it by the machine
chain (:func:`gearjax.gears.hypoid.formate.generating_gear_pinion`: the gear as generating
gear, a tilted cutter), and tooth contact analysis
(:mod:`gearjax.gears.hypoid.tca`) finds the actual contact points; the kinematics there
(:mod:`gearjax.gears.hypoid.contact_kinematics`) are compared with the seed's fields.

Frames: the seed's fixed frame ``S_f`` (:mod:`gearjax.gears.hypoid.pitch_cones`: gear axis
``u2 = e_z`` through the origin, which is the gear's crossing point; pinion axis
``u1`` through ``C1 = (E, 0, 0)``) and the gear work frame of :mod:`gearjax.gears.hypoid.machine`
(origin at the pitch apex ``A2 = P - R_m2 g2``, ``z`` apex to heel):
``p_f = A2 + Q p_w``, ``Q = [x_w, y_w, z_w]``.  The cutter frame of
:mod:`gearjax.gears.hypoid.cutter` (blade tips in ``z_t = 0``, ``s`` along the blade from the
tip) is the seed's cone frame ``(x_c, y_c, z_c = k)`` shifted to the gear root:
the seed's slant length ``u`` (from the pitch plane, positive towards the gear
root) is ``u = u_root - s``, ``u_root = h_fm2/cos(a)``; point radius
``R_p = r0 + shift - sb u_root sin(a)``, blade sign ``-sb``.

Units: mm, rad.  Reference: seed 000 (the eigenfunction paper on conjugate surfaces) §2.
"""

from __future__ import annotations

import math
from typing import NamedTuple

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
    """The machine-cut seed-000 pair and the frame data linking it to the seed's model.

    pair : :class:`~gearjax.gears.hypoid.tca.HypoidPair` (formate gear, generated pinion).
    setup : the seed model's :class:`~gearjax.studies.cutter_radius.PitchSetup`.
    info : :func:`~gearjax.gears.hypoid.formate.generating_gear_pinion`'s info.
    A2 : (3,) gear pitch apex in ``S_f``; Q : (3, 3) gear work axes in ``S_f``.
    phi0 : work phase of the formate settings (flank of the settings = placed cone
        turned by ``phi0`` about the gear axis).
    u_root : seed slant length of the blade tips (gear root), mm.
    """

    pair: HypoidPair
    setup: object
    info: dict
    A2: np.ndarray
    Q: np.ndarray
    phi0: float
    u_root: float


def _member_blank(bd, k: int, teeth: int, hand: str) -> MemberBlank:
    f = lambda name: jnp.asarray(float(bd[f"{name}{k}"]))
    return MemberBlank(f("Re"), f("b"), f("delta"), f("delta_a"), f("delta_f"), f("hae"), f("hfe"),
                       f("beta_m"), teeth, hand)


def study_pair(inp: BlankInput, settings: StudySettings, flank: str = "convex",
                 edge_radius: float = 0.0) -> StudyPair:
    """The seed-000 set of ``inp`` with the cutter of ``settings`` as a machine-cut pair
    (module docstring; concrete).  ``flank`` is the gear flank ("convex": drive side,
    mating the pinion concave flank).  ``edge_radius`` of the blades (mm; the seed's
    cone has none)."""
    s = pitch_setup(inp, settings, flank)
    bd = {k: np.asarray(v) for k, v in s.blank.items()}
    geo = pitch_cones.cone_tangency(bd["delta1"], bd["delta2"], inp.shaft_angle, inp.offset,
                                    bd["Rm2"])
    P = np.asarray(s.P)
    g1, g2 = np.asarray(geo["g1"]), np.asarray(geo["g2"])
    u1, u2 = np.asarray(s.u1), np.asarray(s.u2)
    A2 = P - float(bd["Rm2"]) * g2
    A1 = P - float(geo["R1"]) * g1
    zw2 = np.sign(g2 @ u2) * u2
    zw1 = np.sign(g1 @ u1) * u1
    xw = np.array([1.0, 0.0, 0.0]) - zw2[0] * zw2
    xw /= np.linalg.norm(xw)
    Q = np.stack([xw, np.cross(zw2, xw), zw2], axis=1)
    C1 = np.array([float(inp.offset), 0.0, 0.0])
    t1 = float((C1 - A1) @ zw1)
    t2 = float((np.zeros(3) - A2) @ zw2)
    a = float(s.blade)
    sb = float(s.sb)
    u_root = float(bd["hfm2"]) / math.cos(a)
    r0 = float(np.linalg.norm(np.asarray(s.centre) - P))
    cutter = FaceMillCutter(jnp.asarray(r0 - sb * u_root * math.sin(a)), jnp.asarray(a),
                            jnp.asarray(float(edge_radius)), int(-sb))
    xc, yc, zc = (np.asarray(v) for v in (s.xc, s.yc, s.zc))
    G = np.eye(4)
    G[:3, :3] = Q.T @ np.stack([xc, yc, zc], axis=1)
    G[:3, 3] = Q.T @ (np.asarray(s.centre) + u_root * math.cos(a) * zc - A2)
    hands = ("left", "right") if inp.hand == "left" else ("right", "left")
    gear_blank = _member_blank(bd, 2, inp.z2, hands[1])
    gear, phi0 = formate_from_placement(cutter, G, gear_blank)
    placeholder = FlankSpec(cutter, gear.machine, _member_blank(bd, 1, inp.z1, hands[0]))
    f = lambda v: jnp.asarray(float(v))
    pair = HypoidPair(placeholder, gear, f(inp.shaft_angle), f(inp.offset), f(t1), f(t2),
                      inp.z1, inp.z2, 1)
    pair, info = generating_gear_pinion(pair)
    return StudyPair(pair, s, info, A2, Q, float(phi0), u_root)


def study_uv(sp: StudyPair, p2_body) -> np.ndarray:
    """Seed-000 flank parameters ``(u, theta)`` of gear body-frame points ``(..., 3)``
    (the TCA's ``path.p2_body``): into ``S_f`` (undoing the work phase ``phi0``), then
    into the seed's cone frame."""
    p = np.asarray(p2_body, float) + np.array([0.0, 0.0, float(sp.pair.gear_crossing)])
    c, s_ = math.cos(-sp.phi0), math.sin(-sp.phi0)
    Rz = np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])
    pf = sp.A2 + (p @ Rz.T) @ sp.Q.T
    st = sp.setup
    d = pf - np.asarray(st.centre)
    u = (d @ np.asarray(st.zc)) / math.cos(float(st.blade))
    th = np.arctan2(d @ np.asarray(st.yc), d @ np.asarray(st.xc))
    return np.stack([u, th], axis=-1)
