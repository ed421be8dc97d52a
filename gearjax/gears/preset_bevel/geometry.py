"""Pure-rolling bevel gears with a preset parabolic transmission error: the design and
the tooth flanks ([Preset-TE-bevel]).

**Frames** (the seed's, with the kinematics corrected): the pinion body frame S1 has
its axis along z, the apex at the origin; the fixed frame S0 is S1 at ``phi1 = 0``.
The gear axis passes through the apex with direction ``(0, sin Sigma, cos Sigma)`` in
S0 (gear body frame S2 = ``Rx(-Sigma)`` of S0 at ``phi2 = 0``).  The pitch line (the
common generatrix of the two pitch cones, the instantaneous axis of the relative
rotation) is ``L (0, sin delta1, cos delta1)``, ``tan delta1 = sin Sigma/(z2/z1 + cos Sigma)``.
A pinion turned by ``phi1`` about +z and a gear turned by ``phi2 = -(z1/z2) phi1``
about its body z roll without sliding along it (``omega2/omega1 = sin delta1/sin
delta2 = z1/z2``).  The seed writes ``i21 = 3`` and ``phi2 = i21 phi1`` for 10/30
teeth: the ratio is ``z1/z2 = 1/3`` and the sign is negative in its own matrices
(``M_2P`` turns the gear the other way); this module uses the correct kinematics.

**Contact curve** (logarithmic spiral on the pinion pitch cone, seed's angle ``theta``
measured from +y towards +x)::

    r1(t) = (p f sin theta, p f cos theta, f),   p = tan delta1,
    f(t) = R0 exp(m t),  m = sin delta1 cot beta,  theta = t + phase + Delta_theta(t).

The pitch-cone point at ``theta`` lies on the pitch line at ``phi1 = theta``: the
unmodified curve (``Delta_theta = 0``) is in contact at ``phi1 = t + phase``.  It makes
the constant angle ``beta`` (spiral angle) with the generatrix.  The preset TE
modification turns each point about the pinion axis by ``Delta_theta(t) = -kappa
(t - t_m)^2`` on the concave flank (the seed's sign) and ``+kappa (t - t_m)^2`` on the
convex flank: in both cases the flank moves *into* the tooth (material removed at
the ends), so that the gear lags at entry and exit.  ``t_min, t_max`` are the curve
parameters at the toe and heel cone distances ``A_i = A_o - b`` and ``A_o = m_t z1/(2
sin delta1)``; ``t_m = (t_min + t_max)/2``.

**Normal from the pure-rolling condition.**  At a point of the pitch line the
relative velocity of the two members is zero, so the equation of meshing ``n . v12 =
0`` holds for *every* normal there; the only conditions on the flank normal along the
curve are that the flank contains the curve (``n . alpha = 0``, alpha the unit
tangent) and the prescribed pressure angle: the angle between ``n`` and the pitch-cone
tangent plane, measured in the normal plane of the curve, is ``alpha_n``.  With the
outward pitch-cone normal ``e_N = (cos delta1 sin theta, cos delta1 cos theta,
-sin delta1)`` and the unit vector ``e_c`` of the tangent plane perpendicular to
alpha pointing to the concave side of the spiral (towards the apex, the side of its
centre of geodesic curvature)::

    e_c = ((g . alpha) alpha - g) / |(g . alpha) alpha - g|,   g = r1/|r1|,
    n   = s cos(alpha_n) e_c + sin(alpha_n) e_N,    s = +1 concave, -1 convex flank.

``n`` is the outward normal of the pinion tooth (it points towards the tip side,
``n . e_N = sin alpha_n > 0``).  The derivation and the components are in
docs/preset_te_bevel.md.

**Flanks.**  Moving frame ``S_F1 = (alpha, n x alpha, n)`` at ``r1(t)``; the circular
arc ``(0, rho1 sin u, rho1 (cos u - 1))`` in it gives the pinion flank
``S_C1(u, t)`` (centre of the arc at ``-rho1 n``, inside the tooth: a convex
profile).  The gear flank is built on the *unmodified* pinion curve: the point
``r1(t)`` and its tangent and normal are carried into S2 at the rolling position
(``phi1 = t + phase``, ``phi2 = -(z1/z2) phi1``), ``Gamma2(t), alpha2, n2``, and the arc
``(0, -rho2 sin v, rho2 (1 - cos v))`` in ``(alpha2, n2 x alpha2, n2)`` (centre at
``+rho2 n2``, inside the gear tooth) gives ``S_C2(v, t)``.  The flank parameters are
``uv = (u, t)`` (profile, face width) for both members.

Units: mm, rad.  Reference: [Preset-TE-bevel] (docs/references.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import check_int, check_range, is_traced
from gearjax.fields import float64_array
from gearjax.tca.path import ARCSEC

__all__ = ["PresetBevelDesign", "validate_fields", "pitch_angles", "spiral_rate", "cone_distances",
           "curve_range", "curve_parameter", "preset_kappa", "CurveData", "curve_data",
           "curve_point", "curve_frame", "pinion_flank_point", "gear_curve", "gear_flank_point",
           "pinion_flank", "gear_flank", "flank_phase", "FLANK_SIGN", "transform_to_gear",
           "gear_assembly_rotation"]

#: flank sign ``s`` of the normal (module docstring): +1 concave, -1 convex (pinion)
FLANK_SIGN = {"concave": 1.0, "convex": -1.0}


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class PresetBevelDesign:
    """A pure-rolling bevel pair with a preset parabolic TE (a pytree; every float field
    is differentiable, the tooth numbers are static).

    beta : spiral angle of the contact curve (rad).  alpha_n : normal pressure angle (rad).
    shaft_angle : Sigma (rad).  module_t : outer transverse module (mm).
    face_width : b (mm).  R0 : scale of ``f(t) = R0 exp(m t)`` (mm; sets where t = 0 is).
    kappa : parabola coefficient of ``Delta_theta = -kappa (t - t_m)^2`` (rad).
    rho1, rho2 : profile arc radii of pinion and gear (mm).
    addendum, dedendum : working heights of the flanks above / below the pitch cone
        (mm, both members; the flank boundaries of the TCA).
    z1, z2 : tooth numbers.
    """

    beta: jnp.ndarray
    alpha_n: jnp.ndarray
    shaft_angle: jnp.ndarray
    module_t: jnp.ndarray
    face_width: jnp.ndarray
    R0: jnp.ndarray
    kappa: jnp.ndarray
    rho1: jnp.ndarray
    rho2: jnp.ndarray
    addendum: jnp.ndarray
    dedendum: jnp.ndarray
    z1: int = field(metadata=dict(static=True), default=10)
    z2: int = field(metadata=dict(static=True), default=30)

    @classmethod
    def create(cls, *, z1, z2, beta_deg, alpha_n_deg, shaft_angle_deg, module_t, face_width,
               rho1, rho2, addendum, dedendum, preset_te_arcsec=None, kappa=None, R0=None):
        """Validated constructor (degrees at the boundary).  Give the preset either as
        ``preset_te_arcsec`` (pinion rotation at ``t_min`` and ``t_max``, the seed's 36
        arc-seconds) or as ``kappa`` (rad).  ``R0`` defaults to ``sqrt(A_i A_o) cos delta1``
        (then ``t_m = 0``).  ValueError naming the parameter and its range."""
        return validate_fields(dict(z1=z1, z2=z2, beta_deg=beta_deg, alpha_n_deg=alpha_n_deg,
                                    shaft_angle_deg=shaft_angle_deg, module_t=module_t,
                                    face_width=face_width, rho1=rho1, rho2=rho2,
                                    addendum=addendum, dedendum=dedendum,
                                    preset_te_arcsec=preset_te_arcsec, kappa=kappa, R0=R0))


def pitch_angles(des: PresetBevelDesign):
    """Pitch angles ``(delta1, delta2)`` (rad): ``tan delta1 = sin S/(z2/z1 + cos S)``."""
    S = des.shaft_angle
    d1 = jnp.arctan2(jnp.sin(S), des.z2 / des.z1 + jnp.cos(S))
    return d1, S - d1


def spiral_rate(des: PresetBevelDesign):
    """``m = sin delta1 cot beta`` of ``f = R0 exp(m t)``."""
    d1, _ = pitch_angles(des)
    return jnp.sin(d1) / jnp.tan(des.beta)


def cone_distances(des: PresetBevelDesign):
    """``(A_i, A_m, A_o)`` toe, mean and heel cone distances (mm): ``A_o = m_t z1/(2 sin
    delta1)``, ``A_i = A_o - b``."""
    d1, _ = pitch_angles(des)
    Ao = des.module_t * des.z1 / (2.0 * jnp.sin(d1))
    return Ao - des.face_width, Ao - 0.5 * des.face_width, Ao


def curve_parameter(des: PresetBevelDesign, L):
    """Curve parameter t of the pitch-cone point at cone distance ``L`` (mm)."""
    d1, _ = pitch_angles(des)
    return jnp.log(L * jnp.cos(d1) / des.R0) / spiral_rate(des)


def curve_range(des: PresetBevelDesign):
    """``(t_min, t_m, t_max)``: curve parameters at the toe, mid-face and heel."""
    Ai, _, Ao = cone_distances(des)
    t0, t1 = curve_parameter(des, Ai), curve_parameter(des, Ao)
    return t0, 0.5 * (t0 + t1), t1


def preset_kappa(des: PresetBevelDesign, preset_rad):
    """``kappa`` giving a pinion rotation ``preset_rad`` at ``t_min`` and ``t_max``:
    ``kappa = preset/(t_min - t_m)^2`` (the seed: ``pi/(18000 (t_min - t_m)^2)`` for 36
    arc-seconds)."""
    t0, tm, _ = curve_range(des)
    return preset_rad / (t0 - tm) ** 2


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class CurveData:
    """The numbers a flank function needs (traced data, so that flanks of the same
    structure share one trace): pitch angle ``delta1``, spiral rate ``m``, ``R0``,
    ``kappa``, ``t_m``, ``phase`` (rad), flank sign ``s`` (+1 concave, -1 convex),
    ``alpha_n``, arc radius ``rho`` (mm), gear ratio ``ratio = z1/z2`` and shaft angle."""

    delta1: jnp.ndarray
    m: jnp.ndarray
    R0: jnp.ndarray
    kappa: jnp.ndarray
    t_m: jnp.ndarray
    phase: jnp.ndarray
    s: jnp.ndarray
    alpha_n: jnp.ndarray
    rho: jnp.ndarray
    ratio: jnp.ndarray
    shaft_angle: jnp.ndarray


def flank_phase(des: PresetBevelDesign, member: str, flank: str):
    """Angular position ``phase`` (rad, seed's theta) of the pinion contact curve a flank
    is built on.  The concave pinion flank is at 0; the convex flank of the same pinion
    tooth is ``pi/z1`` behind it (pitch-cone tooth thickness half the angular pitch).
    The gear flanks of one gear tooth mate with the concave flank of one pinion tooth
    (phase 0: gear convex) and the convex flank of the next (phase ``+pi/z1``: gear
    concave)."""
    half = np.pi / des.z1
    if member == "pinion":
        return 0.0 if flank == "concave" else -half
    return 0.0 if flank == "convex" else half


def curve_data(des: PresetBevelDesign, member: str, pinion_flank, phase, *,
               modified: bool = True) -> CurveData:
    """:class:`CurveData` of the flank built on the pinion curve of ``pinion_flank``
    ("concave"/"convex", or the flank sign s = +1/-1, which may be traced) at ``phase``;
    ``member`` "pinion" or "gear" picks rho.  The gear is built on the unmodified curve
    (``kappa = 0``)."""
    sgn = FLANK_SIGN[pinion_flank] if isinstance(pinion_flank, str) else pinion_flank
    d1, _ = pitch_angles(des)
    _, tm, _ = curve_range(des)
    kap = des.kappa if (modified and member == "pinion") else jnp.zeros_like(des.kappa)
    f = float64_array
    return CurveData(d1, spiral_rate(des), des.R0, kap, tm, jnp.asarray(phase, float), jnp.asarray(sgn, float),
                     des.alpha_n, des.rho1 if member == "pinion" else des.rho2,
                     f(des.z1 / des.z2), des.shaft_angle)


def curve_point(c: CurveData, t):
    """Point of the (modified) contact curve on the pinion pitch cone (body frame, mm)."""
    f = c.R0 * jnp.exp(c.m * t)
    th = t + c.phase - c.s * c.kappa * (t - c.t_m) ** 2
    p = jnp.tan(c.delta1)
    return jnp.stack([p * f * jnp.sin(th), p * f * jnp.cos(th), f])


def curve_frame(c: CurveData, t):
    """``(r, alpha, n)``: point, unit tangent and unit flank normal (pure-rolling
    construction of the module docstring) at t."""
    # closed-form tangent: f' = m f, theta' = 1 - 2 s kappa (t - t_m)
    f = c.R0 * jnp.exp(c.m * t)
    th = t + c.phase - c.s * c.kappa * (t - c.t_m) ** 2
    dth = 1.0 - 2.0 * c.s * c.kappa * (t - c.t_m)
    p = jnp.tan(c.delta1)
    sn, cs = jnp.sin(th), jnp.cos(th)
    r = jnp.stack([p * f * sn, p * f * cs, f])
    dr = f * jnp.stack([p * (c.m * sn + dth * cs), p * (c.m * cs - dth * sn), c.m])
    al = dr / jnp.linalg.norm(dr)
    eN = jnp.stack([jnp.cos(c.delta1) * jnp.sin(th), jnp.cos(c.delta1) * jnp.cos(th),
                    -jnp.sin(c.delta1)])
    g = r / jnp.linalg.norm(r)
    ec = jnp.dot(g, al) * al - g
    ec = ec / jnp.linalg.norm(ec)
    n = c.s * jnp.cos(c.alpha_n) * ec + jnp.sin(c.alpha_n) * eN
    return r, al, n


def pinion_flank_point(c: CurveData, uv):
    """Pinion flank ``S_C1(u, t)`` (body frame, mm); ``uv = (u, t)``."""
    u, t = uv[0], uv[1]
    r, al, n = curve_frame(c, t)
    b = jnp.cross(n, al)
    return r + c.rho * jnp.sin(u) * b + c.rho * (jnp.cos(u) - 1.0) * n


def gear_assembly_rotation(shaft_angle):
    """``R0`` of the gear mounting: gear body frame -> S0 at phi2 = 0 (``Rx(-Sigma)``)."""
    cs, sn = jnp.cos(shaft_angle), jnp.sin(shaft_angle)
    one, zero = jnp.ones_like(cs), jnp.zeros_like(cs)
    return jnp.stack([jnp.stack([one, zero, zero]), jnp.stack([zero, cs, sn]),
                      jnp.stack([zero, -sn, cs])])


def _rz(a):
    c, s = jnp.cos(a), jnp.sin(a)
    z, o = jnp.zeros_like(a), jnp.ones_like(a)
    return jnp.stack([jnp.stack([c, -s, z]), jnp.stack([s, c, z]), jnp.stack([z, z, o])])


def transform_to_gear(c: CurveData, phi1):
    """Rotation carrying pinion body vectors into the gear body frame at the rolling
    position ``phi1`` (``phi2 = -(z1/z2) phi1``): ``Rz(phi2)^T R0^T Rz(phi1)``."""
    R0 = gear_assembly_rotation(c.shaft_angle)
    return _rz(-c.ratio * phi1).T @ R0.T @ _rz(phi1)


def gear_curve(c: CurveData, t):
    """``(Gamma2, alpha2, n2)`` on the gear (body frame): the unmodified pinion curve,
    tangent and normal carried into S2 at ``phi1 = t + phase`` (``c.kappa`` must be 0)."""
    r, al, n = curve_frame(c, t)
    A = transform_to_gear(c, t + c.phase)
    return A @ r, A @ al, A @ n


def gear_flank_point(c: CurveData, uv):
    """Gear flank ``S_C2(v, t)`` (body frame, mm); ``uv = (v, t)``."""
    v, t = uv[0], uv[1]
    g, al, n = gear_curve(c, t)
    b = jnp.cross(n, al)
    return g - c.rho * jnp.sin(v) * b + c.rho * (1.0 - jnp.cos(v)) * n


def pinion_flank(des: PresetBevelDesign, flank="concave", phase=None):
    """The pinion flank ``uv -> (3,)`` (a ``Partial``, traced data); ``flank`` a name or
    the flank sign (+1 concave, -1 convex; ``phase`` must then be given)."""
    ph = flank_phase(des, "pinion", flank) if phase is None else phase
    return jax.tree_util.Partial(pinion_flank_point, curve_data(des, "pinion", flank, ph))


def gear_flank(des: PresetBevelDesign, pinion_flank_name="concave", phase=None):
    """The gear flank conjugate to the unmodified pinion flank ``pinion_flank_name`` at
    ``phase`` (a ``Partial``)."""
    ph = 0.0 if phase is None else phase
    return jax.tree_util.Partial(gear_flank_point,
                                 curve_data(des, "gear", pinion_flank_name, ph, modified=False))


def check_design_fields(des: PresetBevelDesign) -> None:
    """Range check of a concrete design's fields in the internal units (mm, rad), the
    ranges of the design file (``validate_fields`` of the design-file module): one-line
    ValueError naming the field, its value and the range (e.g. a spiral angle of 35
    -- degrees typed into the radian field -- is refused).  Traced or batched fields
    skip it."""
    names = ("beta", "alpha_n", "shaft_angle", "module_t", "face_width", "R0", "kappa",
             "rho1", "rho2", "addendum", "dedendum")
    vals = [getattr(des, n) for n in names]
    if any(is_traced(v) or np.ndim(v) for v in vals):
        return
    check_int("z1", des.z1, 3, 200)
    check_int("z2", des.z2, des.z1, 400)
    check_range("beta", des.beta, math.radians(5.0), math.radians(60.0), unit="rad")
    check_range("alpha_n", des.alpha_n, math.radians(5.0), math.radians(35.0), unit="rad")
    S = check_range("shaft_angle", des.shaft_angle, math.radians(30.0), math.radians(150.0),
                    unit="rad")
    mt = check_range("module_t", des.module_t, 0.1, 100.0, unit="mm")
    d1 = math.atan2(math.sin(S), des.z2 / des.z1 + math.cos(S))
    Ao = mt * des.z1 / (2.0 * math.sin(d1))
    check_range("face_width", des.face_width, 0.0, 0.5 * Ao, lo_open=True, unit="mm")
    check_range("R0", des.R0, 0.0, None, lo_open=True, unit="mm")
    check_range("kappa", des.kappa, 0.0, 1.0, unit="rad")
    for n in ("rho1", "rho2"):
        check_range(n, getattr(des, n), 0.5, 5000.0, unit="mm")
    for n in ("addendum", "dedendum"):
        check_range(n, getattr(des, n), 0.05 * mt, 3.0 * mt, unit="mm")


def validate_fields(v: dict) -> PresetBevelDesign:
    """The design pytree from boundary values (degrees, mm, arc-seconds), validated:
    ValueError naming the parameter, its value and the allowed range."""
    z1 = check_int("z1", v["z1"], 3, 200)
    z2 = check_int("z2", v["z2"], z1, 400)
    beta = check_range("beta", v["beta_deg"], 5.0, 60.0, unit="deg")
    an = check_range("alpha_n", v["alpha_n_deg"], 5.0, 35.0, unit="deg")
    S = check_range("shaft_angle", v["shaft_angle_deg"], 30.0, 150.0, unit="deg")
    mt = check_range("module_t", v["module_t"], 0.1, 100.0, unit="mm")
    d1 = math.atan2(math.sin(math.radians(S)), z2 / z1 + math.cos(math.radians(S)))
    Ao = mt * z1 / (2.0 * math.sin(d1))
    b = check_range("face_width", v["face_width"], 0.0, 0.5 * Ao, lo_open=True, unit="mm")
    rho1 = check_range("rho1", v["rho1"], 0.5, 5000.0, unit="mm")
    rho2 = check_range("rho2", v["rho2"], 0.5, 5000.0, unit="mm")
    ha = check_range("addendum", v["addendum"], 0.05 * mt, 3.0 * mt, unit="mm")
    hf = check_range("dedendum", v["dedendum"], 0.05 * mt, 3.0 * mt, unit="mm")
    Ai = Ao - b
    R0 = v.get("R0")
    R0 = (math.sqrt(Ai * Ao) * math.cos(d1) if R0 is None
          else check_range("R0", R0, 0.0, None, lo_open=True, unit="mm"))
    f = float64_array
    des = PresetBevelDesign(f(math.radians(beta)), f(math.radians(an)), f(math.radians(S)),
                            f(mt), f(b), f(R0), f(0.0), f(rho1), f(rho2), f(ha), f(hf), z1, z2)
    if v.get("kappa") is not None:
        if v.get("preset_te_arcsec") is not None:
            raise ValueError("give the preset as preset_te_arcsec or as kappa, not both")
        k = check_range("kappa", v["kappa"], 0.0, 1.0, unit="rad")
    else:
        te = check_range("preset_te_arcsec", v.get("preset_te_arcsec") or 0.0, 0.0, 600.0,
                         unit="arcsec")
        k = float(preset_kappa(des, te * ARCSEC))
    return PresetBevelDesign(*(getattr(des, n) for n in ("beta", "alpha_n", "shaft_angle",
                                                        "module_t", "face_width", "R0")),
                             f(k), des.rho1, des.rho2, des.addendum, des.dedendum, z1, z2)
