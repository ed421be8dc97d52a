"""Meshing characteristics of a hypoid pair by eigenfunctions ([Eigenfunctions] §2-§3).

The model of [Eigenfunctions] (see docs/references.md): the gear flank is the surface
of a face-mill cutter placed at the pitch point and carried about the gear axis;
the eigenfunctions of section 1 (:mod:`gearjax.kinematics`) then give the local
kinematics of the gear and its conjugate pinion at every point of the flank.

Construction (all in the fixed frame ``S_f`` of :mod:`gearjax.gears.hypoid.pitch_cones`:
gear axis ``u2 = (0, 0, 1)`` through the origin, pinion axis ``u1`` through
``C1 = (E, 0, 0)``; mm, rad; pinion speed 1 rad/s so velocities are mm per radian
of pinion roll, as the paper's non-dimensional "pinion speed 1"):

1. Blank: :func:`gearjax.gears.hypoid.blank.blank_geometry`'s core with the cutter
   radius ``r0`` as input (route ``tangent-cones`` by default: the ratio holds
   exactly at the pitch point).  Pitch point ``P``, common normal ``k`` (pinion
   outward, into the gear) from :func:`gearjax.gears.hypoid.pitch_cones.cone_tangency`.
2. Motion: ``omega_p = u1`` (|omega_p| = 1), ``omega_g = s (z1/z2) u2`` with the sign
   ``s`` for which the pitch-point velocities of the two members point the same way
   (rolling cones).  In the paper's pitch-point frame these are its
   ``omega^(1), omega^(2)`` (tested component by component).
3. Pitch-point frame ``i-j-k``: ``j = v21(P)/|v21(P)|`` (v21 = v_gear - v_pinion,
   tangent to the tooth trace because the ratio condition holds), ``k`` the pitch
   plane normal, ``i = j x k``.
4. Cutter ([Eigenfunctions] §2.2): ``r_c = (r_u cos th, r_u sin th, u cos a)``, ``r_u = r0 -+ u sin a``
   (outside blade ``-``: concave gear flank; inside blade ``+``: convex flank), ``u``
   the slant length along the blade from the pitch plane (``u > 0`` towards the gear
   root), ``a`` the blade angle.  Cutter axis ``z_c = k``; centre ``C = P + r0 e``
   with ``e`` the unit vector normal to ``j`` in the pitch plane on the side of
   the gear apex (``e . g2 < 0``: spiral angle growing towards the heel, the
   face-milling rule of ISO 23509 (183)); ``x_c = -e`` so ``r_c(0, 0) = P`` and the
   blade circle is tangent to ``j`` there.
5. Gear flank at gear roll ``phi``: ``r(u, th, phi) = Rot_u2(phi) r_c(u, th)``;
   ``phi`` from the meshing equation ``f = n(phi) . v21(r(phi)) = 0`` (implicit
   Newton :func:`gearjax.newton.newton_solve`, start 0; derivatives by the implicit
   function theorem).
6. Eigen kinematics (:func:`gearjax.kinematics.eigen_kinematics`) with the gear as
   *member 1* of section 1 (the surface whose curvature is known: the cutter cone)
   and the pinion as member 2 (its conjugate): ``Phi_I = 0`` is the meshing limit
   on the gear flank, ``Phi_II = 0`` curvature interference on the pinion.  The
   normal points into the gear tooth (outward normal of the pinion flank), so
   ``R_eff > 0`` for a contact without interference.  Curvatures: autodiff
   (:func:`gearjax.surfaces.local_geometry`); the paper's Euler/Bertrand route
   ``k_v = H + Q cos 2 phi_v``, ``tau_v = -Q sin 2 phi_v`` with ``k_e = cos a / r_u``,
   ``k_f = 0`` is :func:`euler_bertrand` (tested equal).

Slips of [Eigenfunctions] (see docs/kinematics_study.md): the paper's cutter normal
``(-cos a cos th, cos a sin th, sin a)`` is not normal to its own ``r_c`` (the
normal is ``+-(cos a cos th, cos a sin th, sin a)``); gearjax takes the normal from
autodiff.  The paper's "generating angle" is the gear roll angle at which a flank
point is in contact (the gear is cutter-formed, its flank *is* the cutter cone,
as its curvatures ``k_e = cos a / r_u, k_f = 0`` require).

References (docs/references.md): [Eigenfunctions] §1-§3; [Litvin2004] ch. 8-9
(Euler, Bertrand); [ISO23509] (blank).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.frames import rotate_about
from gearjax.errors import check_range, require_converged
from gearjax.gears.hypoid import pitch_cones
from gearjax.gears.hypoid.blank import BlankInput, blank_core
from gearjax.kinematics import Mesh, eigen_kinematics
from gearjax.newton import newton_solve, with_value
from gearjax.surfaces import curvature_in_direction, local_geometry

__all__ = ["STUDY_BLANK", "STUDY_CUTTERS", "study_blank_input", "StudySettings",
           "PitchSetup", "pitch_setup", "FlankFields", "point_fields", "grid_fields",
           "flank_fields", "field_stats",
           "euler_bertrand", "limit_report", "FIELDS", "conjugate_check", "grid_uv", "STAT_NAMES",
           "flank_statistics", "statistics_gradient", "cutter_radius_sweep", "study_statistics"]

_DEG = math.pi / 180.0

#: Gear set of [Eigenfunctions] (ratio 6/39, gear pitch diameter 230 mm, offset 35 mm) with the
#: assumptions of docs/hypoid_blank.md (the paper gives neither face width, spiral
#: angle nor nominal pressure angle): Gleason face width 0.155 d, pinion spiral
#: angle 25 + 5 sqrt(z2/z1) + 90 E/d degrees, nominal pressure angle 19 deg; and
#: profile shift x_hm1 = 0.5 (a 6-tooth pinion needs a long addendum: Gleason's
#: gear addendum 0.21 + 0.29 (z1/z2)^2 of the working depth gives x ~ 0.57; with
#: x_hm1 = 0 the gear tip region shows curvature interference, Phi_II < 0).  Pinion
#: hand right: the hand of the cone model's set (pinion axis through (+E, 0, 0) of
#: ``S_f``, measured on the generated flank; ``study_pair`` builds the mirror image for
#: "left").  The blank itself does not depend on the hand.
STUDY_BLANK = {
    "method": "tangent-cones", "z1": 6, "z2": 39, "offset_mm": 35.0,
    "gear_outer_pitch_diameter_mm": 230.0, "gear_face_width_mm": 0.155 * 230.0,
    "spiral_angle_deg": 25.0 + 5.0 * math.sqrt(39.0 / 6.0) + 90.0 * 35.0 / 230.0,
    "cutter_radius_mm": 95.25, "pressure_angle_drive_deg": 19.0,
    "pressure_angle_coast_deg": 19.0, "profile_shift": 0.5, "hand": "right",
}
#: The three cutters of [Eigenfunctions] (nominal diameter in inches -> radius in mm).
STUDY_CUTTERS = {"6in": 76.2, "7.5in": 95.25, "9in": 114.3}

#: names of the scalar fields of :class:`FlankFields` that :func:`field_stats` reports
FIELDS = ("phi_I", "phi_II", "u1", "u2", "u_e", "u_s", "srr", "k_II", "r_eff")

_FLANKS = ("convex", "concave")


def study_blank_input(cutter_radius_mm=95.25, **overrides) -> BlankInput:
    """Validated :class:`BlankInput` of the [Eigenfunctions] set with cutter radius ``r0`` (mm)."""
    d = dict(STUDY_BLANK)
    d["cutter_radius_mm"] = float(cutter_radius_mm)
    d.update(overrides)
    return BlankInput.from_dict(d)


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class StudySettings:
    """Differentiable inputs of the study (mm, rad).

    cutter_radius : r0, mean point radius of the face mill at the pitch plane (mm);
        enters the blank design (limit curvature condition) *and* the flank.
    blade_angle_delta : added to the blank's generated pressure angle of the flank
        to give the blade angle ``a`` (rad; 0 = the blank's alpha_nD / alpha_nC).
    cutter_shift : moves the cutter centre along ``e`` (mm; 0 = tangent at P), a
        machine setting that changes the lengthwise curvature position.
    """

    cutter_radius: jnp.ndarray
    blade_angle_delta: jnp.ndarray = 0.0
    cutter_shift: jnp.ndarray = 0.0

    @staticmethod
    def make(cutter_radius, blade_angle_delta_deg=0.0, cutter_shift=0.0) -> "StudySettings":
        """Validated settings from display units (mm, degrees)."""
        r0 = check_range("cutter_radius_mm", cutter_radius, 20.0, 400.0, unit="mm")
        da = check_range("blade_angle_delta_deg", blade_angle_delta_deg, -10.0, 10.0, unit="deg")
        sh = check_range("cutter_shift_mm", cutter_shift, -20.0, 20.0, unit="mm")
        return StudySettings(jnp.asarray(r0, float), jnp.asarray(da * _DEG, float),
                        jnp.asarray(sh, float))


class PitchSetup(NamedTuple):
    """Pitch-point frame, motion and cutter placement (mm, rad, rad/s)."""

    P: jnp.ndarray        # pitch point
    i: jnp.ndarray
    j: jnp.ndarray        # along v21(P)
    k: jnp.ndarray        # pitch-plane normal, pinion outward
    mesh: Mesh            # member 1 = gear, member 2 = pinion
    u1: jnp.ndarray       # pinion axis
    u2: jnp.ndarray       # gear axis
    g2: jnp.ndarray       # gear generatrix at P (from apex)
    centre: jnp.ndarray   # cutter centre
    xc: jnp.ndarray
    yc: jnp.ndarray
    zc: jnp.ndarray
    r0: jnp.ndarray
    blade: jnp.ndarray    # blade angle a (rad)
    sb: jnp.ndarray       # +1 outside blade (concave flank), -1 inside blade (convex)
    u_range: jnp.ndarray  # (2,) slant range of the working flank (mm)
    th_range: jnp.ndarray  # (2,) cutter phase range of the working flank (rad)
    blank: dict           # blank outputs (mm, rad)


def pitch_setup(inp: BlankInput, settings: StudySettings, flank: str = "convex") -> PitchSetup:
    """Blank, pitch point frame, motion and cutter for ``settings`` (traceable).

    The blank is designed with ``settings.cutter_radius`` (``inp.cutter_radius`` is
    replaced), so one ``inp`` serves every cutter radius and r0 is differentiable
    through the blank design.

    ``flank``: gear flank, "convex" (inside blade, drive side, blade angle from the
    blank's alpha_nD -- Gleason's drive side is the gear convex side) or "concave"
    (outside blade, coast side, alpha_nC).
    """
    if flank not in _FLANKS:
        raise ValueError(f"flank = {flank!r} must be one of {_FLANKS}")
    r0 = jnp.asarray(settings.cutter_radius, float)
    inp_r = dataclasses.replace(inp, cutter_radius=r0)
    bd = blank_core(inp_r, inp.z2 / inp.z1)
    Sigma, E = inp.shaft_angle, inp.offset
    geo = pitch_cones.cone_tangency(bd["delta1"], bd["delta2"], Sigma, E, bd["Rm2"])
    u1, u2, C1, _, _ = pitch_cones.axes(jnp.asarray(Sigma, float), jnp.asarray(E, float))
    P, k, g2 = geo["P"], geo["n"], geo["g2"]
    wp = u1
    vp = jnp.cross(wp, P - C1)
    sg = jnp.sign(jnp.dot(vp, jnp.cross(u2, P)))
    wg = jax.lax.stop_gradient(sg) * (inp.z1 / inp.z2) * u2
    mesh = Mesh(omega1=wg, omega2=wp, a=C1)
    v21 = jnp.cross(wg, P) - vp
    # lengthwise direction at the pitch point: along the sliding velocity v21 of a
    # hypoid pair; a spiral-bevel pair (E = 0) rolls purely there (v21 = 0), and the
    # tooth trace is the line at the gear's mean spiral angle from its pitch
    # generatrix in the pitch plane, j = -cos(b2) g2' + sin(b2) (k x g2') (g2' the
    # generatrix in the tangent plane) -- the same direction v21 has on every hypoid
    # (tests/test_bevel_sweep.py), so the two agree in the limit E -> 0
    g2t = g2 - jnp.dot(g2, k) * k
    g2t = g2t / jnp.linalg.norm(g2t)
    j_trace = -jnp.cos(bd["beta_m2"]) * g2t + jnp.sin(bd["beta_m2"]) * jnp.cross(k, g2t)
    nv = jnp.linalg.norm(v21)
    hypoid = nv > 1e-9 * jnp.linalg.norm(P) * jnp.linalg.norm(wp)
    j = jnp.where(hypoid, v21 / jnp.where(hypoid, nv, 1.0), j_trace)
    i = jnp.cross(j, k)
    e = -g2 + jnp.dot(g2, j) * j
    e = e / jnp.linalg.norm(e)
    centre = P + (r0 + settings.cutter_shift) * e
    zc = k
    xc = -e
    yc = jnp.cross(zc, xc)
    if flank == "convex":
        sb, alpha = -1.0, bd["alpha_nD"]
    else:
        sb, alpha = 1.0, bd["alpha_nC"]
    alpha = alpha + settings.blade_angle_delta
    ca = jnp.cos(alpha)
    # working flank: from the gear tip (depth -ham2) to the working depth
    # (hfm2 - c, the pinion tip), +-b2/2 of face along the trace (arc b2/cos beta2)
    u_range = jnp.stack([-bd["ham2"], bd["hfm2"] - bd["c"]]) / ca
    th_half = 0.5 * bd["b2"] / (jnp.cos(bd["beta_m2"]) * r0)
    th_range = jnp.stack([-th_half, th_half])
    return PitchSetup(P, i, j, k, mesh, u1, u2, g2, centre, xc, yc, zc, r0, alpha,
                      jnp.asarray(sb), u_range, th_range, bd)


def _cutter_point(s: PitchSetup, uv):
    """Cutter cone point (fixed frame, gear roll 0): ``C + r_u (cos th x_c + sin th y_c)
    + u cos a z_c``, ``r_u = r0 + shift - sb u sin a`` (mm)."""
    u, th = uv[0], uv[1]
    rr = jnp.linalg.norm(s.centre - s.P) - s.sb * u * jnp.sin(s.blade)
    return (s.centre + rr * (jnp.cos(th) * s.xc + jnp.sin(th) * s.yc)
            + u * jnp.cos(s.blade) * s.zc)


class FlankFields(NamedTuple):
    """Fields at one flank point (batched over a grid by :func:`flank_fields`).

    uv (2,) cutter parameters (slant mm, phase rad); phi gear roll angle of contact
    (rad); r, n contact point and normal (fixed frame, at roll phi); axial (2,)
    axial projection (coordinate along the gear axis, radius; mm); eigen
    quantities as :class:`gearjax.kinematics.Kinematics` (mm/rad, 1/mm, mm);
    v_dir unit relative velocity v21; k_v_eb, tau_v_eb the Euler/Bertrand
    values of [Eigenfunctions] §2.3; residual / converged of the meshing equation.
    """

    uv: jnp.ndarray
    phi: jnp.ndarray
    r: jnp.ndarray
    n: jnp.ndarray
    axial: jnp.ndarray
    v12: jnp.ndarray
    v_dir: jnp.ndarray
    q: jnp.ndarray
    p: jnp.ndarray
    phi_I: jnp.ndarray
    phi_II: jnp.ndarray
    u1: jnp.ndarray
    u2: jnp.ndarray
    u_e: jnp.ndarray
    u_s: jnp.ndarray
    srr: jnp.ndarray
    k_II: jnp.ndarray
    r_eff: jnp.ndarray
    n0: jnp.ndarray
    contact_dir: jnp.ndarray
    k_v: jnp.ndarray
    tau_v: jnp.ndarray
    k_v_eb: jnp.ndarray
    tau_v_eb: jnp.ndarray
    residual: jnp.ndarray
    converged: jnp.ndarray


def euler_bertrand(k_e, k_f, e, n, t):
    """[Eigenfunctions] §2.3: ``k_t = H + Q cos 2 phi_t``, ``tau_t = -Q sin 2 phi_t``.

    ``H = (k_e + k_f)/2``, ``Q = (k_e - k_f)/2``, ``phi_t`` the angle from the
    principal direction ``e`` (curvature ``k_e``) to the tangent ``t``, measured
    towards ``f = n x e``.  Sign convention of :func:`gearjax.surfaces.curvature_in_direction`
    (``kappa = -dn.t``, ``tau = -dn.(n x t)``), with which Bertrand's formula
    carries the minus sign as [Eigenfunctions] writes it.
    """
    f = jnp.cross(n, e)
    ph = jnp.arctan2(jnp.dot(t, f), jnp.dot(t, e))
    H, Q = 0.5 * (k_e + k_f), 0.5 * (k_e - k_f)
    return H + Q * jnp.cos(2 * ph), -Q * jnp.sin(2 * ph)


def point_fields(s: PitchSetup, uv, tol=1e-11):
    """All fields at cutter parameters ``uv`` (see :class:`FlankFields`)."""
    mesh = s.mesh
    wg = mesh.omega1
    ax = s.u2 * jnp.sign(jnp.dot(wg, s.u2))       # positive roll = sense of rotation
    g0 = local_geometry(partial(_cutter_point, s), uv)
    radial = g0.r - s.centre
    radial = radial - jnp.dot(radial, s.zc) * s.zc
    radial = radial / jnp.linalg.norm(radial)
    # normal into the gear tooth: tooth outside the blade circle on the concave
    # flank (outside blade), inside it on the convex flank
    sn = jnp.sign(jnp.dot(g0.n, radial)) * s.sb
    n0, r0 = sn * g0.n, g0.r

    def F(phi, th):
        r_, n_ = th
        r = rotate_about(ax, phi, r_)
        return jnp.dot(rotate_about(ax, phi, n_), jnp.cross(mesh.omega1, r)
                       - jnp.cross(mesh.omega2, r - mesh.a))

    sol = newton_solve(F, 0.0, (r0, n0), tol=tol)
    phi = sol.x

    def surf(uv_):
        return rotate_about(ax, phi, _cutter_point(s, uv_))

    g = local_geometry(surf, uv)
    n = sn * g.n
    W = sn * g.W
    kin = eigen_kinematics(mesh, g.r, n, W)
    # Euler/Bertrand route ([Eigenfunctions] §2.3): cone, k_e = cos a / r_u along the circle
    # direction, k_f = 0 along the blade; sign + when n points towards the cutter axis
    rr = jnp.linalg.norm(r0 - s.centre - jnp.dot(r0 - s.centre, s.zc) * s.zc)
    e_dir = rotate_about(ax, phi, jnp.cross(s.zc, radial))
    sig = -jnp.sign(jnp.dot(n0, radial))
    k_e = sig * jnp.cos(s.blade) / rr
    k_v_eb, tau_v_eb = euler_bertrand(k_e, 0.0 * k_e, e_dir, n, kin.v12)
    rho = jnp.linalg.norm(g.r[:2])
    axial = jnp.stack([g.r[2], rho])
    return FlankFields(
        uv=uv, phi=phi, r=g.r, n=n, axial=axial, v12=kin.v12,
        v_dir=kin.v12 / jnp.linalg.norm(kin.v12), q=kin.q, p=kin.p, phi_I=kin.phi_I,
        phi_II=kin.phi_II, u1=kin.u1, u2=kin.u2, u_e=kin.u_e, u_s=kin.u_s, srr=kin.srr,
        k_II=kin.k_II, r_eff=kin.r_eff, n0=kin.n0, contact_dir=kin.contact_dir,
        k_v=kin.k_v, tau_v=kin.tau_v, k_v_eb=k_v_eb, tau_v_eb=tau_v_eb,
        residual=sol.residual, converged=sol.converged)


def conjugate_check(s: PitchSetup, uv):
    """Independent route to ``K_II``: the conjugate pinion flank built explicitly.

    The contact point ``r(uv, phi(uv))`` carried back into the pinion body by its
    roll ``psi = phi |omega_p|/|omega_g|`` and placed at the instant of the contact
    at ``uv`` is a parametrisation of the pinion flank; its normal curvature in
    the direction ``t = p/|p|`` (autodiff through the meshing-equation Newton,
    second order) gives ``kappa_gear(t) - kappa_pinion(t)``, which must equal the
    eigenfunction value ``K_II = |p|^2/Phi_II`` (Litvin & Fuentes ch. 9).  Returns
    ``dict(k_II, k_gear, k_pinion, normal_dot, point_gap)``.
    """
    mesh = s.mesh
    ax_g = s.u2 * jnp.sign(jnp.dot(mesh.omega1, s.u2))
    wp = jnp.linalg.norm(mesh.omega2)
    ax_p = mesh.omega2 / wp
    ratio = wp / jnp.linalg.norm(mesh.omega1)
    f0 = point_fields(s, uv)

    def pinion_body(uv_):
        f = point_fields(s, uv_)
        return rotate_about(ax_p, -ratio * f.phi, f.r - mesh.a)

    psi0 = ratio * f0.phi

    def pinion_now(uv_):
        return rotate_about(ax_p, psi0, pinion_body(uv_)) + mesh.a

    g = local_geometry(pinion_now, uv)
    sn = jnp.sign(jnp.dot(g.n, f0.n))
    t = f0.p / jnp.linalg.norm(f0.p)
    k_pin = curvature_in_direction(f0.n, sn * g.W, t)[0]

    def gear_now(uv_):
        return rotate_about(ax_g, f0.phi, _cutter_point(s, uv_))

    gg = local_geometry(gear_now, uv)
    k_gear = curvature_in_direction(f0.n, jnp.sign(jnp.dot(gg.n, f0.n)) * gg.W, t)[0]
    return dict(k_II=f0.k_II, k_gear=k_gear, k_pinion=k_pin,
                normal_dot=jnp.abs(jnp.dot(sn * g.n, f0.n)),
                point_gap=jnp.linalg.norm(g.r - f0.r))


def grid_uv(s: PitchSetup, shape, extend=1.0):
    """``(nu, nth, 2)`` grid of cutter parameters over the working flank, scaled by
    ``extend`` about its centre (``extend > 1`` looks beyond the working area)."""
    nu, nt = shape
    uc, ud = jnp.mean(s.u_range), 0.5 * (s.u_range[1] - s.u_range[0]) * extend
    tc, td = jnp.mean(s.th_range), 0.5 * (s.th_range[1] - s.th_range[0]) * extend
    a = jnp.linspace(-1.0, 1.0, nu)
    b = jnp.linspace(-1.0, 1.0, nt)
    U, T = jnp.meshgrid(uc + ud * a, tc + td * b, indexing="ij")
    return jnp.stack([U, T], axis=-1)


def grid_fields(inp, settings, flank, shape, extend):
    """``(PitchSetup, FlankFields)`` over a ``shape`` grid of the flank (traceable in
    ``settings``; the un-jitted core of :func:`flank_fields`)."""
    s = pitch_setup(inp, settings, flank)
    uv = grid_uv(s, shape, extend)
    f = jax.vmap(jax.vmap(partial(point_fields, s)))(uv)
    return s, f


_fields_jit = jax.jit(grid_fields, static_argnums=(0, 2, 3, 4))


def flank_fields(inp: BlankInput, settings: StudySettings, flank: str = "convex",
                 shape=(31, 15), extend: float = 1.0, *, throw: bool = True):
    """[Eigenfunctions] fields over a ``shape = (n_depth, n_face)`` grid of the gear flank.

    Returns ``(setup, fields)``: :class:`PitchSetup` and :class:`FlankFields` with
    leading grid axes.  jitted (static: ``inp``, ``flank``, ``shape``, ``extend``);
    differentiable in ``settings``.  ``throw`` (concrete values only): raise
    :class:`gearjax.errors.ConvergenceError` when the blank or any meshing-equation
    solve did not converge; with ``throw=False`` inspect ``fields.converged`` and
    ``setup.blank['converged']``.
    """
    if flank not in _FLANKS:
        raise ValueError(f"flank = {flank!r} must be one of {_FLANKS}")
    shape = tuple(int(x) for x in shape)
    if len(shape) != 2 or min(shape) < 2:
        raise ValueError(f"shape = {shape} must be two integers >= 2")
    s, f = _fields_jit(inp, settings, flank, shape, float(extend))
    if throw and not isinstance(f.phi, jax.core.Tracer):
        require_converged(np.asarray(s.blank["converged"]) > 0.5, "cutter-radius study blank",
                          s.blank["residual"])
        require_converged(np.all(np.asarray(f.converged)), "meshing equation (gear roll)",
                          np.max(np.asarray(f.residual)))
    return s, f


def field_stats(f: FlankFields, names=FIELDS) -> dict:
    """``{name: {"mean", "min", "max"}}`` over the grid (plain floats, display units
    = internal units: mm/rad, 1/mm, mm)."""
    out = {}
    for nm in names:
        a = np.asarray(getattr(f, nm), float)
        out[nm] = {"mean": float(a.mean()), "min": float(a.min()), "max": float(a.max())}
    return out


def _zero_crossings(values, uv, axial):
    """Linear-interpolated zeros of a grid field along grid edges."""
    pts_uv, pts_ax = [], []
    for axis in (0, 1):
        a = np.moveaxis(values, axis, 0)
        U = np.moveaxis(uv, axis, 0)
        A = np.moveaxis(axial, axis, 0)
        s0, s1 = a[:-1], a[1:]
        m = (s0 * s1 < 0) | ((s0 == 0) & (s1 != 0))
        t = np.where(m, s0 / np.where(m, s0 - s1, 1.0), 0.0)
        for idx in zip(*np.nonzero(m)):
            tt = t[idx]
            pts_uv.append((U[idx] * (1 - tt) + U[(idx[0] + 1,) + idx[1:]] * tt).tolist())
            pts_ax.append((A[idx] * (1 - tt) + A[(idx[0] + 1,) + idx[1:]] * tt).tolist())
    return pts_uv, pts_ax


def limit_report(f: FlankFields) -> dict:
    """Meshing limit (Phi_I = 0, on the gear flank) and curvature interference
    (Phi_II = 0, on the pinion) on the grid of ``f``.

    For each limit: ``inside`` (True when the eigenfunction changes sign or
    vanishes on the grid), the fraction of grid points whose sign differs from the
    grid centre's, the smallest ``|Phi|/max|Phi|`` (margin) and the zero curve as
    points in cutter parameters ``(u mm, theta rad)`` and in the axial projection
    ``(z mm, radius mm)``.  Also the lubrication dead points, where the entrainment
    velocity u_e changes sign.
    """
    uv = np.asarray(f.uv)
    ax = np.asarray(f.axial)
    out = {}
    for key, nm in (("meshing_limit", "phi_I"), ("curvature_interference", "phi_II"),
                    ("entrainment_reversal", "u_e")):
        a = np.asarray(getattr(f, nm), float)
        c = a[a.shape[0] // 2, a.shape[1] // 2]
        ref = np.sign(c) if c != 0 else 1.0
        other = np.sign(a) != ref
        zu, za = _zero_crossings(a, uv, ax)
        out[key] = {"field": nm, "inside": bool(other.any() or np.any(a == 0)),
                    "fraction": float(other.mean()),
                    "margin": float(np.min(np.abs(a)) / max(np.max(np.abs(a)), 1e-300)),
                    "zero_curve_uv": zu, "zero_curve_axial": za}
    return out


# --------------------------------------------------------------------------- statistics

#: smooth-statistic temperature: softmax(x) = t log mean exp(x/t) (units of x)
STAT_NAMES = ("mean_abs_srr", "max_abs_srr", "mean_r_eff", "min_r_eff", "mean_abs_u_e",
              "min_phi_I", "min_phi_II")


def _stats(f: FlankFields):
    """Flank statistics as jnp scalars (traceable).  SRR and u_e enter as absolute
    values (their signs are conventions: which member is faster, orientation of
    ``n``); ``min_phi_I``/``min_phi_II`` are normalised by the pitch-point sign
    (> 0: that limit is not on the grid)."""
    c = tuple(n // 2 for n in f.phi_I.shape)
    sI, sII = jnp.sign(f.phi_I[c]), jnp.sign(f.phi_II[c])
    return {"mean_abs_srr": jnp.mean(jnp.abs(f.srr)), "max_abs_srr": jnp.max(jnp.abs(f.srr)),
            "mean_r_eff": jnp.mean(f.r_eff), "min_r_eff": jnp.min(f.r_eff),
            "mean_abs_u_e": jnp.mean(jnp.abs(f.u_e)),
            "min_phi_I": jnp.min(sI * f.phi_I), "min_phi_II": jnp.min(sII * f.phi_II)}


def study_statistics(inp, settings, flank, shape):
    """:data:`STAT_NAMES` of the flank fields on a ``shape`` grid (traceable in
    ``settings``; the un-jitted core of :func:`flank_statistics`)."""
    return _stats(grid_fields(inp, settings, flank, shape, 1.0)[1])


_stats_jit = jax.jit(study_statistics, static_argnums=(0, 2, 3))


def flank_statistics(inp: BlankInput, settings: StudySettings, flank: str = "convex",
                     shape=(15, 9)) -> dict:
    """:data:`STAT_NAMES` over the working flank as jnp scalars (jitted, differentiable
    in ``settings`` by ``jax.jacfwd``/``jax.grad``; ``max``/``min`` are the plain
    grid extremes -- differentiable where the extreme grid point is unique)."""
    return _stats_jit(inp, settings, flank, tuple(int(x) for x in shape))


def _stats_jac(inp, settings, flank, shape):
    return jax.jacfwd(lambda st: study_statistics(inp, st, flank, shape))(settings)


_stats_jac_jit = jax.jit(_stats_jac, static_argnums=(0, 2, 3))


def statistics_gradient(inp: BlankInput, settings: StudySettings, flank: str = "convex",
                        shape=(15, 9)) -> dict:
    """``{stat: StudySettings of derivatives}`` (forward mode through the blank Newton
    and the meshing-equation Newton, implicit function theorem).  Units: per mm for
    ``cutter_radius`` and ``cutter_shift``, per rad for ``blade_angle_delta``."""
    return _stats_jac_jit(inp, settings, flank, tuple(int(x) for x in shape))


def _sweep(inp, r0s, flank, shape):
    def one(r0):
        # the statistics and their derivatives from one forward-mode pass
        der, val = jax.jacfwd(with_value(lambda x: study_statistics(
            inp, StudySettings(x, 0.0 * x, 0.0 * x), flank, shape)), has_aux=True)(r0)
        return val, der
    return jax.vmap(one)(r0s)


_sweep_jit = jax.jit(_sweep, static_argnums=(0, 2, 3))


def cutter_radius_sweep(inp: BlankInput, r0s, flank: str = "convex", shape=(15, 9)):
    """Statistics and their derivatives d/dr0 for a vector of cutter radii (mm),
    computed by ``jax.vmap`` (one compiled program, no Python loop).  The blank is
    re-designed for every r0 (``inp.cutter_radius`` is replaced).  Returns
    ``(values, derivatives)``: dicts of arrays over ``r0s``."""
    r0s = jnp.asarray(r0s, float)
    return _sweep_jit(inp, r0s, flank, tuple(int(x) for x in shape))
