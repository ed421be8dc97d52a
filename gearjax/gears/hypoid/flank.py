"""Face-milled hypoid and spiral-bevel tooth flanks by the algorithm of [HFT-hypoid].

A flank is the envelope of a straight-blade face-mill cutter cone
(:mod:`gearjax.gears.hypoid.cutter`) carried by a cradle-type generator
(:mod:`gearjax.gears.hypoid.machine`), or for a formate (non-generated) member the cutter cone
itself placed by the settings.  With ``r_w(s, theta, psi)`` the cutter surface in
the work frame and ``n_w`` its unit normal:

* meshing equation (generated members)      f1 = n_w . dr_w/dpsi = 0   (mm/rad)
  The relative velocity is the autodiff derivative ``dr_w/dpsi`` of the carried
  cutter point (the project's design rule), not a hand-derived velocity formula; it equals
  the ``(omega_c - omega_w) x r + omega_w x R`` of [HFT-hypoid] per unit cradle roll.
* face-width condition                      f2 = l_p(r_w) - l_p(xi0) = 0   (mm)
  with the distance along the pitch generatrix ``l_p = cos(gp) x_A + sin(gp) R_A``
  ([HFT-hypoid]) and ``xi = 1 - 2 (A_o - l_p)/F`` so that ``xi = -1`` at the toe, 0 at
  mid face and +1 at the heel.  ([HFT-hypoid] prints ``xi = 1 - A_o/F + l_p/F``, which
  runs from 0 to 1 and contradicts its own "-1 at the toe, +1 at the heel"; gearjax
  uses the form that matches the stated range.)
* face-cone (tip) condition                 f3 = sin(gF)(x_A + x_pf) - cos(gF) R_A = 0  (mm)
  (the ``tan(gF)(x_A + x_pf) - R_A`` of [HFT-hypoid] times ``cos(gF)``: the signed normal
  distance to the face cone, better scaled near gF = 90 deg).

For a formate member ``psi`` is fixed at 0 and the first equation reads
``f1 = psi``, so both kinds share one code path.

Algorithm ([HFT-hypoid]): (1) start values at mid face from the cutter/blank geometry
at ``psi = 0`` -- gearjax takes the blank's mean pitch point on the side facing the
cutter and reads ``theta*`` and ``s*`` off it in the cutter frame (the geometric
content of the closed-form ``theta* = pi/2 - beta + q0``,
``s* = A_m sin(Delta)/cos(alpha)``, ``psi* = 0`` of [HFT-hypoid], whose signs depend on the paper's
frame conventions); (2) Newton on (f1, f2, f3) at ``xi = 0`` gives the tip point
([HFT-hypoid] uses simulated annealing here; Newton from the geometric estimate
converges and nothing random is used); (3) continuation of the tip point along the
face width (``lax.scan`` from mid face to heel and to toe, previous solution as
the start); (4) for every face-width position a scan down the blade from
``s_max`` to the fillet start ``s_min = rho_f (1 - sin a)/cos a`` solving (f1, f2) at
fixed ``s``.  All solves use :func:`gearjax.newton.newton_solve`, so flank points
are differentiable (forward and reverse) with respect to every machine setting,
the cutter and the blank by the implicit function theorem.

Work frame: origin at the pitch-cone apex, ``z_w`` the work axis pointing from the
apex towards the heel; ``x_A = z_w``, ``R_A = sqrt(x_w^2 + y_w^2)``.
Normals point out of the tooth material into the tooth space.

Units: mm, rad.  References (docs/references.md): [HFT-hypoid];
[Litvin2004] ch. 6 (envelopes) and ch. 21-22.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, replace

import jax
import jax.numpy as jnp
import numpy as np

from gearjax import frames
from gearjax.fields import float64_array, floats_for_ints
from gearjax.gears.hypoid.cutter import (FaceMillCutter, blade_data, cone_normal, cone_point,
                                         cone_surface_normal, cutter_normal, cutter_point,
                                         fillet_start)
from gearjax.errors import check_int, check_positive, check_range, require_converged
from gearjax.gears.hypoid.machine import (MachineSettings, cutter_to_cradle, cutter_to_work,
                                          work_to_machine)
from gearjax.io import FlankGrid  # noqa: F401  (the shared export grid; exported here)
from gearjax.newton import newton_solve

__all__ = ["MemberBlank", "FlankSpec", "FlankGrid", "program_pair", "make_member_blank",
           "mean_cone_distance", "face_apex_offset", "root_apex_offset", "axial_coords",
           "pitch_distance", "xi_of",
           "face_cone_gap", "root_cone_gap", "work_point", "meshing_function", "mid_estimate",
           "solve_tip", "solve_point", "flank_points", "flank_surface", "spiral_angle_at",
           "MachineChain", "machine_chain", "chain_point", "chain_normal", "body_family",
           "body_point",
           "BLANK_FIELDS"]

TOL = 1e-10   # mm, residual tolerance of every solve

BLANK_FIELDS = ["outer_cone_distance", "face_width", "pitch_angle", "face_angle", "root_angle",
                "outer_addendum", "outer_dedendum", "mean_spiral_angle"]


@functools.partial(jax.tree_util.register_dataclass, data_fields=BLANK_FIELDS + ["teeth"],
                   meta_fields=["hand"])
@dataclass(frozen=True)
class MemberBlank:
    """Cone data of one member's blank (mm, rad), as in [HFT-hypoid] Table 1.

    outer_cone_distance A_o, face_width F (mm), pitch/face/root cone angles,
    outer addendum and dedendum (mm, at the heel, Gleason convention), mean spiral
    angle; number of teeth (a data field: it only enters arithmetic, so blanks of
    every tooth number share a compiled program); hand of spiral ("left"/"right",
    static, a label: no computation reads it -- the hand of a flank is the geometry of
    its machine settings -- and :func:`gearjax.gears.hypoid.pair.program_pair` drops it
    at the family's jit boundaries).
    """

    outer_cone_distance: jax.Array
    face_width: jax.Array
    pitch_angle: jax.Array
    face_angle: jax.Array
    root_angle: jax.Array
    outer_addendum: jax.Array
    outer_dedendum: jax.Array
    mean_spiral_angle: jax.Array
    teeth: jax.Array = 1
    hand: str = "right"

    def __post_init__(self):
        floats_for_ints(self, ("teeth",))


def make_member_blank(*, outer_cone_distance, face_width, pitch_angle, face_angle, root_angle,
                      outer_addendum, outer_dedendum, mean_spiral_angle, teeth, hand) -> MemberBlank:
    """Validated constructor; angles in degrees (file units), lengths in mm."""
    Ao = check_positive("outer_cone_distance", outer_cone_distance, "mm")
    F = check_range("face_width", face_width, 0.0, Ao, lo_open=True, hi_open=True, unit="mm")
    gp = check_range("pitch_angle", pitch_angle, 0.0, 90.0, lo_open=True, hi_open=True, unit="deg")
    gf = check_range("face_angle", face_angle, gp, 90.0, hi_open=True, unit="deg")
    gr = check_range("root_angle", root_angle, 0.0, gp, lo_open=True, unit="deg")
    a = check_range("outer_addendum", outer_addendum, 0.0, None, unit="mm")
    d = check_positive("outer_dedendum", outer_dedendum, "mm")
    b = check_range("mean_spiral_angle", mean_spiral_angle, 0.0, 90.0, hi_open=True, unit="deg")
    z = check_int("teeth", teeth, 1)
    if hand not in ("left", "right"):
        raise ValueError(f"hand = {hand!r} must be 'left' or 'right'")
    r = lambda x: x * (np.pi / 180.0)             # traced values pass (inside jax.grad)
    f = lambda v: jnp.asarray(v, float)
    return MemberBlank(f(Ao), f(F), f(r(gp)), f(r(gf)), f(r(gr)), f(a), f(d), f(r(b)), z, hand)


def mean_cone_distance(b: MemberBlank):
    """A_m = A_o - F/2 (mm)."""
    return b.outer_cone_distance - 0.5 * b.face_width


def face_apex_offset(b: MemberBlank):
    """x_pf: distance from the face-cone apex to the pitch apex along the axis (mm).

    The face cone passes through the heel addendum point
    ``(x, R) = (A_o cos gp - a sin gp, A_o sin gp + a cos gp)``, so
    ``x_pf = R / tan(gF) - x``.
    """
    Ao, gp, a = b.outer_cone_distance, b.pitch_angle, b.outer_addendum
    x = Ao * jnp.cos(gp) - a * jnp.sin(gp)
    R = Ao * jnp.sin(gp) + a * jnp.cos(gp)
    return R / jnp.tan(b.face_angle) - x


def root_apex_offset(b: MemberBlank):
    """x_pr: root-cone apex to pitch apex (mm); root cone through the heel dedendum point."""
    Ao, gp, d = b.outer_cone_distance, b.pitch_angle, b.outer_dedendum
    x = Ao * jnp.cos(gp) + d * jnp.sin(gp)
    R = Ao * jnp.sin(gp) - d * jnp.cos(gp)
    return R / jnp.tan(b.root_angle) - x


def axial_coords(r):
    """(x_A, R_A): axial coordinate from the pitch apex and radius of work-frame point(s)."""
    r = jnp.asarray(r)
    return r[..., 2], jnp.sqrt(jnp.sum(r[..., :2] ** 2, axis=-1))


def pitch_distance(b: MemberBlank, r):
    """l_p = cos(gp) x_A + sin(gp) R_A (mm), [HFT-hypoid]."""
    x, R = axial_coords(r)
    return jnp.cos(b.pitch_angle) * x + jnp.sin(b.pitch_angle) * R


def xi_of(b: MemberBlank, r):
    """Face-width coordinate xi = 1 - 2 (A_o - l_p)/F: -1 toe, 0 mid face, +1 heel."""
    return 1.0 - 2.0 * (b.outer_cone_distance - pitch_distance(b, r)) / b.face_width


def face_cone_gap(b: MemberBlank, r):
    """Signed normal distance below the face cone (mm): > 0 inside the blank."""
    x, R = axial_coords(r)
    g = b.face_angle
    return jnp.sin(g) * (x + face_apex_offset(b)) - jnp.cos(g) * R


def root_cone_gap(b: MemberBlank, r):
    """Signed normal distance above the root cone (mm): > 0 above the root."""
    x, R = axial_coords(r)
    g = b.root_angle
    return jnp.cos(g) * R - jnp.sin(g) * (x + root_apex_offset(b))


@functools.partial(jax.tree_util.register_dataclass,
                   data_fields=["cutter", "machine", "blank"], meta_fields=[])
@dataclass(frozen=True)
class FlankSpec:
    """Everything one flank needs: the blade, the machine settings and the blank."""

    cutter: FaceMillCutter
    machine: MachineSettings
    blank: MemberBlank


def work_point(fl: FlankSpec, s, theta, psi=0.0):
    """Cutter point and unit normal carried into the work frame at cradle roll psi."""
    M = cutter_to_work(fl.machine, psi)
    r = frames.apply_point(M, cutter_point(fl.cutter, s, theta))
    n = frames.apply_vector(M, cutter_normal(fl.cutter, s, theta))
    return r, n


@functools.partial(jax.tree_util.register_dataclass,
                   data_fields=["R_ct", "t_ct", "R_f", "t_f", "roll", "blade"],
                   meta_fields=["generated"])
@dataclass(frozen=True)
class MachineChain:
    """The roll-independent factors of :func:`work_point`'s machine chain (a pytree).

    With ``M_mw(phi) = F Rz(phi)`` (``F = T(0, E_m, X_B) Ry(pi/2 - gamma_m) T(0, 0,
    dX_D)``, :func:`gearjax.gears.hypoid.machine.work_to_machine`) the cutter point
    and normal in the work frame are

        r_w(s, theta, psi) = Rz(-phi(psi)) [R_f Rz(psi) (R_ct r_t + t_ct) + t_f]
        n_w(s, theta, psi) = Rz(-phi(psi)) R_f Rz(psi) R_ct n_t

    (``R_ct, t_ct``: the cutter in the cradle, ``M_ct``; ``R_f, t_f``: ``F^-1``;
    ``roll = (R_a, 2C, 6D)``; ``r_t``, ``n_t`` the blade cone and its normal from
    ``blade``, :func:`gearjax.gears.hypoid.cutter.blade_data`; formate members have no
    ``Rz(psi)`` and ``phi = 0``).  Computed once per flank from the
    settings, outside the solves, so that each evaluation of the tool inside the
    solves and their derivatives costs two plane rotations and two 3x3 products
    instead of the seven 4x4 transforms of the full chain -- the same mapping
    (:func:`chain_point` is tested against :func:`work_point`).  Static:
    ``generated`` (cradle roll or formate).
    """

    R_ct: jax.Array
    t_ct: jax.Array
    R_f: jax.Array
    t_f: jax.Array
    roll: jax.Array
    blade: jax.Array
    generated: bool = True


def machine_chain(fl: FlankSpec) -> MachineChain:
    """:class:`MachineChain` of a flank (traceable)."""
    ms, c = fl.machine, fl.cutter
    M_ct = cutter_to_cradle(ms)
    F_inv = frames.inverse(work_to_machine(ms, 0.0))
    roll = jnp.stack([ms.ratio_of_roll, ms.modified_roll_2c, ms.modified_roll_6d])
    return MachineChain(M_ct[:3, :3], M_ct[:3, 3], F_inv[:3, :3], F_inv[:3, 3], roll,
                        blade_data(c), bool(ms.generated))


def _plane_rotation(angle, v):
    """``Rz(angle) v`` for one vector (3,), as the row sums of ``Rz * v``: the solves
    differentiate this to third order inside ``vmap``, where each element written out
    (``c v_x - s v_y``, ...) would become its own chain of slices, broadcasts and
    products in the compiled program (same values; a smaller program).  Not ``Rz @ v``:
    that product, smaller still, lost every coast contact of the synthesised spiral
    bevel under :data:`gearjax.FAST_COMPILE_OPTIONS` (XLA's CPU backend at
    optimisation level 0), while the default options solved them."""
    return jnp.sum(frames.matrix_z(angle) * v, axis=1)


def _chain(k: MachineChain, v, psi, translate: bool):
    """The chain of :class:`MachineChain` applied to a cutter-frame point
    (``translate``) or vector."""
    q = k.R_ct @ v + (k.t_ct if translate else 0.0)
    if k.generated:
        q = _plane_rotation(psi, q)
    q = k.R_f @ q + (k.t_f if translate else 0.0)
    if not k.generated:
        return q
    ra, c2, d6 = k.roll[0], k.roll[1], k.roll[2]
    phi = ra * (psi - 0.5 * c2 * psi ** 2 - d6 / 6.0 * psi ** 3)   # roll_angle
    return _plane_rotation(-phi, q)


def chain_point(k: MachineChain, uv, psi):
    """Cutter point at ``uv = (theta, s)`` in the work frame at cradle roll ``psi``
    (mm), by the factored chain (:class:`MachineChain`; formate: ``psi`` ignored).
    Equals ``work_point(fl, s, theta, psi)[0]``."""
    return _chain(k, cone_point(k.blade, uv[1], uv[0]), psi, True)


def chain_normal(k: MachineChain, uv, psi):
    """Unit cutter normal at ``uv`` in the work frame (``work_point(...)[1]``)."""
    return _chain(k, cone_normal(k.blade, uv[0]), psi, False)


def body_family(k: MachineChain, shift, uv, psi):
    """Tool family of a generated flank in the member's body frame: the cutter point
    at ``uv = (theta, s)`` carried to cradle roll ``psi`` (:func:`chain_point`), minus
    ``shift`` (3,) (the crossing point).  Module-level so that
    ``jax.tree_util.Partial(body_family, machine_chain(fl), shift)`` is a pytree whose
    jit caches are shared by every flank function built from it
    (:func:`gearjax.gears.hypoid.pair.flank_function`)."""
    return chain_point(k, uv, psi) - shift


def body_normal(k: MachineChain, uv, psi):
    """Unit normal of :func:`body_family` at fixed ``psi`` in closed form: the cone's
    parametric normal (:func:`~gearjax.gears.hypoid.cutter.cone_surface_normal`) carried
    by the chain's rotations, equal to ``r_u x r_v/|r_u x r_v|`` of the family (the
    ``normal`` of its :class:`~gearjax.surfaces.GeneratedSurface`)."""
    return _chain(k, cone_surface_normal(k.blade, uv[1], uv[0]), psi, False)


def body_point(k: MachineChain, shift, uv):
    """Formate flank (the cutter cone placed by the settings) in the body frame."""
    return chain_point(k, uv, 0.0) - shift


def _carried(k: MachineChain, s, theta, psi):
    """``(r_w, n_w, dr_w/dpsi)`` from one forward-mode pass through the machine chain
    (the point and the relative velocity share one trace)."""
    psi = jnp.asarray(psi, float)
    uv = jnp.stack([theta, s])
    r, v = jax.jvp(lambda p: chain_point(k, uv, p), (psi,), (jnp.ones_like(psi),))
    return r, chain_normal(k, uv, psi), v


def meshing_function(fl: FlankSpec, s, theta, psi):
    """f1 = n_w . dr_w/dpsi (mm/rad): zero on the generated flank (0 for formate)."""
    if not fl.machine.generated:
        return jnp.zeros_like(jnp.asarray(psi, float))
    _, n, v = _carried(machine_chain(fl), s, theta, psi)
    return jnp.dot(n, v)


def _target(b: MemberBlank, xi0):
    return b.outer_cone_distance - 0.5 * b.face_width * (1.0 - xi0)


def point_and_first_equation(k: MachineChain, s, th, psi):
    """Work point and the first equation of every solve on the flank: the meshing
    equation of a generated flank, ``psi`` itself for a formate one (one pass)."""
    if k.generated:
        r, n, v = _carried(k, s, th, psi)
        return r, jnp.dot(n, v)
    return chain_point(k, jnp.stack([th, s]), psi), psi


def _F_tip(x, p):
    k, b, xi0 = p
    s, th, psi = x[0], x[1], x[2]
    r, f1 = point_and_first_equation(k, s, th, psi)
    return jnp.stack([f1, pitch_distance(b, r) - _target(b, xi0), face_cone_gap(b, r)])


def _F_point(x, p):
    k, b, s, xi0 = p
    th, psi = x[0], x[1]
    r, f1 = point_and_first_equation(k, s, th, psi)
    return jnp.stack([f1, pitch_distance(b, r) - _target(b, xi0)])


def mid_estimate(fl: FlankSpec):
    """Start values (s*, theta*, psi* = 0) at mid face (see module docstring).

    The blank's mean pitch point is taken in the axial plane facing the cutter
    (the work-frame direction of ``-z_m``) and expressed in the cutter frame at
    ``psi = 0``: ``theta* = atan2(y_t, x_t)``, ``s* = max(-z_t / cos(alpha), s_min)``.
    """
    b, ms = fl.blank, fl.machine
    d = frames.apply_vector(frames.inverse(work_to_machine(ms, 0.0)), jnp.array([0.0, 0.0, -1.0]))
    az = jnp.arctan2(d[1], d[0])
    Am = mean_cone_distance(b)
    x, R = Am * jnp.cos(b.pitch_angle), Am * jnp.sin(b.pitch_angle)
    P = jnp.stack([R * jnp.cos(az), R * jnp.sin(az), x])
    Pt = frames.apply_point(frames.inverse(cutter_to_work(ms, 0.0)), P)
    th = jnp.arctan2(Pt[1], Pt[0])
    s = jnp.maximum(-Pt[2] / jnp.cos(fl.cutter.blade_angle), fillet_start(fl.cutter))
    return jnp.stack([s, th, 0.0 * th])


def solve_tip(fl: FlankSpec, xi0, x0):
    """Tip point (on the face cone) at face-width position xi0: x = (s, theta, psi)."""
    return newton_solve(_F_tip, x0, (machine_chain(fl), fl.blank, jnp.asarray(xi0, float)),
                        tol=TOL, noise_floor=True)


def solve_point(fl: FlankSpec, s, xi0, x0):
    """Flank point at blade distance s and face-width position xi0: x = (theta, psi)."""
    return newton_solve(_F_point, x0, (machine_chain(fl), fl.blank, jnp.asarray(s, float),
                                       jnp.asarray(xi0, float)), tol=TOL, noise_floor=True)


def _tip_scan(fl, xs, x_start):
    def step(carry, xi0):
        x1, x2 = carry                    # the last two solutions (equal at the start)
        res = solve_tip(fl, xi0, 2.0 * x1 - x2)   # secant predictor (equal steps in xi)
        nxt = jnp.where(res.converged, res.x, x1)
        return (nxt, x1), res
    _, out = jax.lax.scan(step, (x_start, x_start), xs)
    return out


def _tips(fl: FlankSpec, xis):
    """Tip points at the face-width positions ``xis`` (ascending; NumPy), by two scans
    from mid face outwards: ``(NewtonResult batched over xis, converged with the mid
    point)``."""
    mid = solve_tip(fl, 0.0, mid_estimate(fl))
    up = xis[xis >= 0.0]
    down = xis[xis < 0.0][::-1]
    tips = _tip_scan(fl, jnp.asarray(up), mid.x)
    if down.size:
        tips_dn = _tip_scan(fl, jnp.asarray(down), mid.x)
        tips = jax.tree_util.tree_map(lambda a, b: jnp.concatenate([a[::-1], b]), tips_dn, tips)
    return tips, tips.converged & mid.converged


def _row(fl: FlankSpec, s_min, ts, tip_x, xi0):
    """One row of the grid at ``xi0``, from its tip solution ``tip_x = (s_max, theta,
    psi)`` down to ``s_min`` at the fractions ``ts`` (1 -> 0): ``(points, normals,
    params, residual, converged, Newton steps)``, one entry per fraction."""
    k = machine_chain(fl)
    s_max = tip_x[0]

    def step(carry, t):
        x1, x2 = carry                # the last two solutions (equal at the tip)
        s = s_min + (s_max - s_min) * t
        # secant predictor along the row (equal steps in s): fewer Newton steps
        res = solve_point(fl, s, xi0, 2.0 * x1 - x2)
        nxt = jnp.where(res.converged, res.x, x1)
        uv = jnp.stack([res.x[0], s])
        r, n = chain_point(k, uv, res.x[1]), chain_normal(k, uv, res.x[1])
        return (nxt, x1), (r, n, jnp.stack([s, res.x[0], res.x[1]]), res.residual,
                           res.converged, res.steps)

    return jax.lax.scan(step, (tip_x[1:], tip_x[1:]), ts)[1]


def flank_points(fl: FlankSpec, n_xi: int = 21, n_s: int = 11, face_margin: float = 0.0,
                 height_margin: float = 0.0) -> FlankGrid:
    """Flank grid by the algorithm of [HFT-hypoid] (pure and jit-friendly; no validation).

    ``n_xi`` face-width positions ``xi`` in [-1, 1] (toe to heel), ``n_s`` blade
    positions from the fillet start ``s_min`` to the tip ``s_max(xi)``, uniformly
    spaced in ``s``.  Use :func:`flank_surface` for a validated, convergence-checked
    result.  Differentiable w.r.t. ``fl`` (jacfwd/jacrev) through the implicit solves.

    ``face_margin`` and ``height_margin`` (static fractions, default 0) keep the grid
    inside a border, as a measuring machine's grid is: ``xi`` in ``[-1 + 2 m_f, 1 -
    2 m_f]`` (a margin ``m_f`` of the face width at the toe and at the heel) and the
    blade fraction ``(s - s_min)/(s_max - s_min)`` in ``[m_h, 1 - m_h]`` (a margin
    ``m_h`` of the active blade length at the root and at the tip; docs/correct.md).

    Returns a :class:`gearjax.io.FlankGrid`, shape (n_xi, n_s) per field, index j
    from root (fillet start) to tip: points (n_xi, n_s, 3) mm and normals (n_xi,
    n_s, 3) in the work frame; params (n_xi, n_s, 3) = (s, theta, psi) surface
    parameters (mm, rad, rad); xi (n_xi,) face-width positions; residual (n_xi, n_s)
    max |F| of the solve (mm); converged (n_xi, n_s) bool (point solve and its row's
    tip solve both converged).
    """
    fm, hm = float(face_margin), float(height_margin)
    xis = np.linspace(-1.0 + 2.0 * fm, 1.0 - 2.0 * fm, int(n_xi))
    ts = jnp.asarray(np.linspace(1.0 - hm, hm, int(n_s)))          # tip -> root
    tips, tip_ok = _tips(fl, xis)
    s_min = fillet_start(fl.cutter)
    r, n, prm, res, conv, _ = jax.vmap(lambda x, xi: _row(fl, s_min, ts, x, xi))(
        tips.x, jnp.asarray(xis))
    flip = lambda a: a[:, ::-1]
    res = jnp.maximum(flip(res), tips.residual[:, None])
    conv = flip(conv) & tip_ok[:, None]
    return FlankGrid(flip(r), flip(n), flip(prm), jnp.asarray(xis), res, conv)


@functools.partial(jax.jit, static_argnums=(1, 2, 3, 4))
def _flank_points_jit(fl, n_xi, n_s, face_margin, height_margin):
    return flank_points(fl, n_xi, n_s, face_margin, height_margin)


def flank_surface(fl: FlankSpec, n_xi: int = 21, n_s: int = 11, *, face_margin: float = 0.0,
                  height_margin: float = 0.0, throw: bool = True) -> FlankGrid:
    """Validated, jitted :func:`flank_points`; raises ConvergenceError unless every point
    converged (``throw=False`` returns the grid with its ``converged`` mask).  The
    margins (fractions in [0, 0.4]) as in :func:`flank_points`."""
    n_xi = check_int("n_xi", n_xi, 2, 2001)
    n_s = check_int("n_s", n_s, 2, 2001)
    fm = check_range("face_margin", face_margin, 0.0, 0.4)
    hm = check_range("height_margin", height_margin, 0.0, 0.4)
    g = _flank_points_jit(program_pair(fl), n_xi, n_s, fm, hm)
    if throw:
        require_converged(g.converged, "hypoid flank grid", g.residual)
    return g


def spiral_angle_at(fl: FlankSpec, s, xi0, x0):
    """Spiral angle (rad) of the flank line s = const at (s, xi0), measured in the
    plane tangent to the pitch cone between the flank line and the cone generatrix.

    The flank line tangent dr/dxi comes from the implicit solve (autodiff); it is
    projected onto the tangent plane of the pitch cone at the point's axial
    position (normal ``(cos gp e_R - sin gp e_z)`` in the axial plane).
    """
    b = fl.blank

    def pt(xi):
        res = solve_point(fl, s, xi, x0)
        return work_point(fl, s, res.x[0], res.x[1])[0]

    r = pt(xi0)
    t = jax.jacfwd(pt)(jnp.asarray(xi0, float))
    e_R = jnp.stack([r[0], r[1], 0.0]) / jnp.hypot(r[0], r[1])
    e_z = jnp.array([0.0, 0.0, 1.0])
    g = jnp.cos(b.pitch_angle) * e_z + jnp.sin(b.pitch_angle) * e_R       # generatrix
    nrm = jnp.cos(b.pitch_angle) * e_R - jnp.sin(b.pitch_angle) * e_z     # cone normal
    t = t - jnp.dot(t, nrm) * nrm
    return jnp.arctan2(jnp.linalg.norm(jnp.cross(g, t)), jnp.abs(jnp.dot(g, t)))


def program_pair(tree):
    """``tree`` (a :class:`HypoidPair`, a :class:`FlankSpec` or any pytree holding them)
    as the argument of a compiled program of this family: every number a strongly
    typed float64 array -- tooth numbers, the mounting hand and the blade signs
    included (Python ints and weakly typed floats would each key their own program) --
    and each blank's hand-of-spiral label set to None (a label no computation reads;
    :class:`~gearjax.gears.hypoid.flank.MemberBlank`).  One compiled TCA, synthesis
    or kinematics program then serves every tooth number, hand of spiral, mounting
    hand and flank side; what stays static is the structure: which members are
    generated (a generated flank is an envelope, a formate one a cone) and the grid
    options.  Tracers pass through unchanged; booleans are kept."""
    def strip(x):
        return replace(x, hand=None) if isinstance(x, MemberBlank) else x

    def leaf(v):
        if isinstance(v, jax.core.Tracer) or isinstance(v, (bool, np.bool_)):
            return v
        dt = getattr(v, "dtype", None)
        if isinstance(v, (int, float, np.integer, np.floating)) or (
                dt is not None and np.issubdtype(dt, np.number)):
            return float64_array(v)
        return v

    tree = jax.tree_util.tree_map(strip, tree, is_leaf=lambda x: isinstance(x, MemberBlank))
    return jax.tree_util.tree_map(leaf, tree)
