"""Hypoid pitch cones by the tangency-contact condition ([Tangent-cones]).

[Tangent-cones] (see docs/references.md) states the pitch-cone problem of a hypoid
pair as the tangency of two skew cones: at the pitch point P the two cones have
a common point (3 equations) and parallel normals (2 equations), equations (1)-(5);
the wheel mean point is at mid face, ``r2 = (D - b sin delta2)/2`` (7); the pinion
spiral angle follows from the angle ``zeta`` between the two generatrices through
P, ``beta1 = beta2 + zeta`` (8); and a cutter-radius (limit curvature) condition
(6) closes the system.  With trial pitch angles ``(delta1, delta2)`` everything
else is explicit, so the eight unknowns reduce to a two-variable root finding in
``(delta1, delta2)``.

What gearjax does (and where it differs from the text of [Tangent-cones]):

* **Frames.**  S_f has its origin at the crossing point C2 of the wheel axis and
  the common perpendicular; x_f runs along the common perpendicular towards the
  pinion axis, the wheel axis is ``u2 = (0, 0, 1)`` through C2 = 0, the pinion axis
  is ``u1 = (0, sin Sigma, cos Sigma)`` through ``C1 = (E, 0, 0)``.  ``u_i`` points
  from the apex of member i into its pitch cone.  The paper's cone parametrisation
  ``(r cos t, r sin t sin d, r sin t cos d)`` is a plane, not a cone, and its
  eq. (3) has the offset on the wrong side of its own translation; its normals
  (1)-(2) are those of cones about y_1 and z_2.  gearjax writes the cones as
  ``P = A_i + R_i g_i``, ``g_i = cos d_i u_i + sin d_i m_i(theta_i)``, outward normal
  ``n_i = -sin d_i u_i + cos d_i m_i``, ``m_i`` the unit radial vector at the
  position angle ``theta_i`` (measured from x_f about ``u_i``).
* **Normals (1)-(2)** are solved in closed form: the common normal ``n = n_1 = -n_2``
  satisfies ``n.u1 = -sin d1``, ``n.u2 = sin d2``, ``|n| = 1``, hence
  ``n = alpha u1 + beta u2 + gamma x_f`` with ``gamma = -sqrt(...)`` (the root that
  puts P between the axes for ``E > 0``).  This gives ``theta1, theta2``.
* **Positions (3)-(5)** are linear in the pinion cone distance ``R1`` and the two
  apex positions once ``R2 = r2 / sin d2`` is known: one 3x3 linear solve.  The apex
  positions are reported as ISO 23509's ``t_z1, t_z2`` (pitch apex beyond the
  crossing point, mm) under the names ``a1, a2``.
* **Spiral angles (8).**  ``zeta`` is the signed angle between the generatrices
  in the common tangent plane (= ISO's offset angle in the pitch plane
  ``zeta_mp``), ``beta1 = beta2 + zeta``; either spiral angle may be the input.
* **The missing equation: the ratio.**  [Tangent-cones] never uses the tooth numbers.
  The pitch point must transmit the ratio: the velocity components normal to the
  tooth trace are equal, ``omega1 r1 cos beta1 = omega2 r2 cos beta2`` (Gleason's
  hypoid dimension factor ``r1 = r2 cos beta2 / (u cos beta1)``, ISO 23509 (14),
  (26)).  This is the first residual.
* **Cutter radius (6).**  The paper's eq. (6) mixes undefined radii ``rho_1, rho_2``
  and its limit-angle formula is not dimensionally consistent.  gearjax uses the
  classical limit pressure angle and limit radius of curvature ([Wildhaber1946];
  [ISO23509] formulae (32)-(33)) with the tangency-route cone distances ``R1, R2``:
  second residual ``rho_lim / r_c0 - 1``.

* **Unknowns.**  Newton runs in ``(delta1, gamma)`` with ``gamma = n . x_f``
  instead of ``(delta1, delta2)``: ``Sigma - delta1 - delta2 = O(E^2)`` and
  ``gamma ~ sqrt(Sigma - delta1 - delta2)``, so in the pitch angles themselves the
  Jacobian degenerates and ``delta2``'s last bit limits the residual for small
  offsets; ``sin delta2`` is an explicit smooth function of ``(delta1, gamma)``.

At ``E = 0`` the limit curvature is 0/0 (any cutter works for a spiral bevel
pair), so this route needs ``E > 0``; the zero-offset limit is checked in the
tests by letting ``E -> 0``.

The pinion machine settings of the last table of [Tangent-cones] are in
:func:`pinion_machine_settings`.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from functools import partial

import jax
import jax.numpy as jnp

from gearjax.errors import require_converged
from gearjax.gears.hypoid import iso23509
from gearjax.newton import newton_solve

__all__ = ["cone_tangency", "normal_offset_component", "delta2_from_normal",
           "PitchConeSolution", "solve_pitch_cones",
           "pinion_machine_settings", "axes"]


def axes(Sigma, E):
    """Unit axis vectors and crossing points ``(u1, u2, C1, C2, ex)`` in S_f (mm)."""
    z = 0.0 * (Sigma + E)
    u1 = jnp.stack([z, jnp.sin(Sigma), jnp.cos(Sigma)])
    u2 = jnp.stack([z, z, z + 1.0])
    C1 = jnp.stack([E + z, z, z])
    C2 = jnp.stack([z, z, z])
    ex = jnp.stack([z + 1.0, z, z])
    return u1, u2, C1, C2, ex


def cone_tangency(delta1, delta2, Sigma, E, R2):
    """Closed-form steps 2-3 of [Tangent-cones]: tangency of the cones for trial pitch angles.

    Given pitch angles ``delta1, delta2`` (rad), shaft angle ``Sigma``, offset ``E``
    (mm) and the wheel cone distance ``R2`` (mm) of the pitch point, returns a dict
    with the common normal ``n`` (pinion outward), pitch point ``P``, generatrix
    directions ``g1, g2``, radial directions ``m1, m2``, pinion cone distance
    ``R1``, apex positions ``a1, a2`` (ISO t_z1, t_z2: apex beyond the crossing
    point along the axis, mm), position angles ``theta1, theta2`` and the signed
    angle ``zeta`` from ``g2`` to ``g1`` in the tangent plane.  Equations (1)-(5)
    of [Tangent-cones] in the frames described in the module docstring.
    """
    gamma = normal_offset_component(delta1, delta2, Sigma)
    return _tangency(jnp.sin(delta1), jnp.cos(delta1), jnp.sin(delta2), jnp.cos(delta2),
                     gamma, Sigma, E, R2)


def _tangency(s1, c1, s2, c2, gamma, Sigma, E, R2):
    """:func:`cone_tangency` from sines/cosines of the pitch angles and ``gamma = n.x_f``.

    Working with ``gamma`` directly keeps the O(E) quantities (the x-components
    of the normal and generatrices, ``zeta``) accurate to machine precision; going
    through ``delta2`` would lose them for small offsets (``gamma^2`` is below the
    resolution of ``cos^2 delta1``).
    """
    u1, u2, C1, C2, ex = axes(Sigma, E)
    cS = jnp.cos(Sigma)
    # normal parallelism: n.u1 = -sin d1, n.u2 = +sin d2, |n| = 1
    alpha = (-s1 - cS * s2) / (1.0 - cS ** 2)
    beta = (s2 + cS * s1) / (1.0 - cS ** 2)
    n = alpha * u1 + beta * u2 + gamma * ex
    m1 = (n + s1 * u1) / c1
    m2 = (-n + s2 * u2) / c2
    g1 = c1 * u1 + s1 * m1
    g2 = c2 * u2 + s2 * m2
    # coincident points: R1 g1 + s1' u1 - s2' u2 = C2 - C1 + R2 g2 (linear)
    A = jnp.stack([g1, u1, -u2], axis=1)
    rhs = C2 - C1 + R2 * g2
    # E = 0 (spiral bevel, intersecting axes): g1, u1, u2 are coplanar and the system
    # is singular -- the cones touch along the whole common generatrix g1 = g2 through
    # the common apex at the crossing point: R1 = R2, both apexes at the crossing point
    degenerate = jnp.abs(jnp.linalg.det(A)) < 1e-12
    R1, sp1, sp2 = jnp.where(degenerate, jnp.stack([R2, 0.0 * R2, 0.0 * R2]),
                             jnp.linalg.solve(jnp.where(degenerate, jnp.eye(3), A), rhs))
    P = C2 + sp2 * u2 + R2 * g2
    theta1 = jnp.arctan2(jnp.dot(m1, jnp.cross(u1, ex)), jnp.dot(m1, ex))
    theta2 = jnp.arctan2(jnp.dot(m2, jnp.cross(u2, ex)), jnp.dot(m2, ex))
    zeta = jnp.arctan2(jnp.dot(n, jnp.cross(g2, g1)), jnp.dot(g1, g2))
    return dict(n=n, P=P, g1=g1, g2=g2, m1=m1, m2=m2, R1=R1, R2=R2 + 0.0 * R1,
                a1=-sp1, a2=-sp2, theta1=theta1, theta2=theta2, zeta=zeta)


def normal_offset_component(delta1, delta2, Sigma):
    """``gamma = n . x_f`` of the common normal for pitch angles ``delta1, delta2``.

    From ``n.u1 = -sin d1``, ``n.u2 = sin d2``, ``|n| = 1`` (see :func:`cone_tangency`);
    ``gamma <= 0``, and ``gamma = 0`` exactly when ``delta1 + delta2 = Sigma``.
    """
    s1, s2, cS = jnp.sin(delta1), jnp.sin(delta2), jnp.cos(Sigma)
    alpha = (-s1 - cS * s2) / (1.0 - cS ** 2)
    beta = (s2 + cS * s1) / (1.0 - cS ** 2)
    return -jnp.sqrt(1.0 - (alpha ** 2 + beta ** 2 + 2.0 * alpha * beta * cS))


def _sin_delta2(delta1, gamma, Sigma):
    """``sin delta2 = -sin d1 cos Sigma + sin Sigma sqrt(cos^2 d1 - gamma^2)``."""
    return (-jnp.sin(delta1) * jnp.cos(Sigma)
            + jnp.sin(Sigma) * jnp.sqrt(jnp.cos(delta1) ** 2 - gamma ** 2))


def delta2_from_normal(delta1, gamma, Sigma):
    """Inverse of :func:`normal_offset_component` for ``delta2``.

    Eliminating ``alpha, beta`` from the normal conditions gives
    ``sin delta2 = -sin d1 cos Sigma + sin Sigma sqrt(cos^2 d1 - gamma^2)``; smooth
    at ``gamma = 0``, where ``delta1 + delta2 = Sigma`` (spiral bevel).
    """
    return jnp.arcsin(_sin_delta2(delta1, gamma, Sigma))


@dataclass(frozen=True)
class PitchConeSolution:
    """Solution of the [Tangent-cones] tangency route (mm, rad).

    ``delta1, delta2`` pitch angles; ``R1, R2`` mean cone distances of the pitch
    point; ``r1, r2`` its radii; ``theta1, theta2`` position angles; ``a1, a2`` apex
    positions (ISO t_z1, t_z2); ``zeta`` offset angle in the pitch plane;
    ``beta1, beta2`` mean spiral angles; ``alpha_lim`` limit pressure angle;
    ``rho_lim`` limit radius of curvature; ``residual`` max |F| of the two
    residuals (dimensionless), ``steps``, ``converged``.
    """

    delta1: jax.Array
    delta2: jax.Array
    R1: jax.Array
    R2: jax.Array
    r1: jax.Array
    r2: jax.Array
    theta1: jax.Array
    theta2: jax.Array
    a1: jax.Array
    a2: jax.Array
    zeta: jax.Array
    beta1: jax.Array
    beta2: jax.Array
    alpha_lim: jax.Array
    rho_lim: jax.Array
    residual: jax.Array
    steps: jax.Array
    converged: jax.Array


jax.tree_util.register_dataclass(
    PitchConeSolution,
    data_fields=[f.name for f in fields(PitchConeSolution)],
    meta_fields=[])


def _state(x, th, spiral_member, wheel_radius):
    """All tangency-route quantities for the unknowns ``x = (delta1, gamma)``.

    The Newton unknowns are ``delta1`` and ``gamma = n . x_f`` rather than
    ``(delta1, delta2)``: ``delta2`` follows from :func:`delta2_from_normal`.  The
    change of variables is smooth and one-to-one on the hypoid branch and removes
    the square-root singularity of ``gamma(delta1 + delta2)`` at the spiral-bevel
    limit (``Sigma - delta1 - delta2 = O(E^2)``), which makes the Jacobian in
    ``(delta1, delta2)`` singular as ``E -> 0``.
    """
    u, Sigma, E, de2, b2, beta, rc0, r2_fixed = th
    delta1, gamma = x[0], x[1]
    s2 = _sin_delta2(delta1, gamma, Sigma)
    c2 = jnp.sqrt(1.0 - s2 ** 2)
    delta2 = jnp.arctan2(s2, c2)
    if wheel_radius == "mid-face":
        r2 = 0.5 * (de2 - b2 * s2)                       # seed 003 eq. (7)
    else:
        r2 = r2_fixed + 0.0 * delta2
    geo = _tangency(jnp.sin(delta1), jnp.cos(delta1), s2, c2, gamma, Sigma, E, r2 / s2)
    zeta = geo["zeta"]
    if spiral_member == "pinion":
        beta1, beta2 = beta + 0.0 * zeta, beta - zeta
    else:
        beta1, beta2 = beta + zeta, beta + 0.0 * zeta       # [Tangent-cones] eq. (8)
    R1, R2 = geo["R1"], geo["R2"]
    r1 = R1 * jnp.sin(delta1)
    alim = iso23509.limit_pressure_angle(delta1, delta2, R1, R2, beta1, beta2, zeta)
    rho = iso23509.limit_curvature_radius(delta1, delta2, R1, R2, beta1, beta2, alim)
    F = jnp.stack([u * r1 * jnp.cos(beta1) / (r2 * jnp.cos(beta2)) - 1.0,  # ratio
                   rho / rc0 - 1.0])                                      # cutter radius
    return geo, dict(delta2=delta2, r1=r1, r2=r2, beta1=beta1, beta2=beta2, alpha_lim=alim, rho_lim=rho), F


def solve_pitch_cones(u, Sigma, E, de2, b2, beta, rc0, *, spiral_member="pinion",
                      wheel_radius="mid-face", r2=None, throw=True):
    """[Tangent-cones] pitch cones: two-variable Newton in the pitch angles.

    The Newton unknowns are ``(delta1, gamma)``, ``gamma = n . x_f``, a smooth
    one-to-one change of coordinates of ``(delta1, delta2)`` (see :func:`_state`);
    ``delta2`` follows from :func:`delta2_from_normal`.

    Parameters (mm, rad): ``u = z2/z1`` ratio (float), ``Sigma`` shaft angle, ``E``
    hypoid offset (> 0), ``de2`` wheel outer pitch diameter, ``b2`` wheel face width,
    ``beta`` mean spiral angle of ``spiral_member`` ("pinion" or "gear"), ``rc0``
    cutter radius.  ``wheel_radius`` is ``"mid-face"`` ([Tangent-cones] eq. (7),
    ``r2 = (de2 - b2 sin delta2)/2``) or ``"given"`` (use ``r2``, e.g. ISO 23509's
    ``rmpt2`` for a like-for-like comparison with Method 1).

    Residuals: ``u r1 cos b1 / (r2 cos b2) - 1`` (ratio) and ``rho_lim/rc0 - 1``
    (limit curvature = cutter radius), both dimensionless, solved to their rounding
    floor (converged at 1e-10) by
    :func:`gearjax.newton.newton_solve` (implicit derivatives).  Start: ISO 23509
    Method 1 for the same data (the root does not depend on it).

    ``throw=True`` raises :class:`gearjax.errors.ConvergenceError` on concrete
    non-converged results; under tracing, or with ``throw=False``, check the
    ``converged`` field.
    """
    if spiral_member not in ("pinion", "gear"):
        raise ValueError(f"spiral_member = {spiral_member!r} is not 'pinion' or 'gear'")
    if wheel_radius not in ("mid-face", "given"):
        raise ValueError(f"wheel_radius = {wheel_radius!r} is not 'mid-face' or 'given'")
    if wheel_radius == "given" and r2 is None:
        raise ValueError("wheel_radius = 'given' needs r2")
    r2_fixed = jnp.asarray(0.0 if r2 is None else r2, dtype=float)
    sol = _solve(u, Sigma, E, de2, b2, beta, rc0, r2_fixed, spiral_member, wheel_radius)
    conv = sol.converged
    if throw and not isinstance(conv, jax.core.Tracer):
        require_converged(conv, "pitch-cone tangency solve", sol.residual)
    return sol


@partial(jax.jit, static_argnames=("spiral_member", "wheel_radius"))
def _solve(u, Sigma, E, de2, b2, beta, rc0, r2_fixed, spiral_member, wheel_radius):
    """Jitted body of :func:`solve_pitch_cones` (compiled once per static choice)."""
    x0 = _start(*jax.lax.stop_gradient((u, Sigma, E, de2, b2, beta, rc0, r2_fixed)),
                spiral_member, wheel_radius)
    th = (u, Sigma, E, de2, b2, beta, rc0, r2_fixed)

    def F(x, th_):
        return _state(x, th_, spiral_member, wheel_radius)[2]

    # tol 1e-10: the residuals' rounding floor is ~1e-12 -- rho_lim/rc0 changes by
    # ~2e4 per rad of delta1 (more near zero offset), and one ulp of delta1 is 5.6e-17
    # rad, so 1e-12 is not always reachable; the step test (xtol) still iterates to
    # the floor, the residual test only decides convergence
    res = newton_solve(F, x0, th, tol=1e-10, xtol=1e-14)
    geo, q, _ = _state(res.x, th, spiral_member, wheel_radius)
    delta2 = q["delta2"]
    conv = res.converged & iso23509.physical_branch(res.x[0], delta2, Sigma, geo["R1"],
                                                    q["rho_lim"])
    sol = PitchConeSolution(delta1=res.x[0], delta2=delta2, R1=geo["R1"], R2=geo["R2"],
                            r1=q["r1"], r2=q["r2"], theta1=geo["theta1"], theta2=geo["theta2"],
                            a1=geo["a1"], a2=geo["a2"], zeta=geo["zeta"], beta1=q["beta1"],
                            beta2=q["beta2"], alpha_lim=q["alpha_lim"], rho_lim=q["rho_lim"],
                            residual=res.residual, steps=res.steps, converged=conv)
    return sol


def _start(u, Sigma, E, de2, b2, beta, rc0, r2_fixed, spiral_member, wheel_radius):
    """Start point ``(delta1, gamma)`` of the tangency Newton (inputs are constants
    here; the root, not the start, carries the derivatives)."""
    # Start: ISO 23509 Method 1 made consistent with this route's wheel radius and
    # spiral-angle input by a few fixed-point passes (the residuals are very steep
    # in the direction of delta1 + delta2 for small offsets, so a start with the
    # Method-1 radius rule alone can leave Newton's basin).
    st = iso23509._method1_start(u, Sigma, E, de2, b2, beta)
    r2_start = r2_fixed if wheel_radius == "given" else st["rmpt2"]
    beta_d1 = beta if spiral_member == "pinion" else beta + jnp.arcsin(
        E * jnp.sin(st["delta_int2"]) / st["rmpt2"])

    def fixed_point(_, carry):
        r2s, bd1 = carry
        it = iso23509.method1_pitch_cones(u, Sigma, E, de2, b2, bd1, rc0, rmpt2=r2s)
        if wheel_radius == "mid-face":
            r2s = 0.5 * (de2 - b2 * jnp.sin(it["delta2"]))
        bd1 = bd1 + (beta - (it["beta_m1"] if spiral_member == "pinion" else it["beta_m2"]))
        return r2s, bd1

    r2_start, beta_d1 = jax.lax.fori_loop(
        0, 3, fixed_point, jax.lax.stop_gradient((r2_start + 0.0 * beta, beta_d1 + 0.0 * r2_start)))
    iso = iso23509.method1_pitch_cones(u, Sigma, E, de2, b2, beta_d1, rc0, rmpt2=r2_start)
    return jnp.stack([iso["delta1"], normal_offset_component(iso["delta1"], iso["delta2"], Sigma)])


def pinion_machine_settings(sol: PitchConeSolution, E, hand="left"):
    """Pinion machine settings of the last table of [Tangent-cones], evaluated literally.

    * vertical wheel base   ``dV = E sin theta2 - a1``
    * horizontal wheel base ``dH = E cos theta2 + a2``
    * cradle angle          ``q = theta2 + 90 deg`` (left-hand pinion) or
      ``theta2 - 90 deg`` (right-hand); the paper writes ``theta2 +- 90 deg``
    * cutter tilt           ``sin i = tan beta1 / tan alpha_lim`` (paper) -- for every
      practical hypoid ``|tan beta1 / tan alpha_lim| >> 1`` (e.g. ~30 for ISO 23509
      sample 2), so the paper's relation has no solution; ``tilt`` is NaN then
      and ``tilt_valid`` False.  ``tilt_reciprocal = asin(tan alpha_lim / tan beta1)``
      is the reciprocal reading (zero for spiral bevels, where no tilt is needed);
      it is gearjax's interpretation, not a published formula.
    * gear machine centre to back ``X_G = a2``.

    ``theta2, a1, a2`` are those of :func:`cone_tangency` (position angle from the
    common perpendicular; ISO t_z1, t_z2).  [Tangent-cones] gives these relations as
    approximations ("primary analytical relation"); the exact settings come from
    the machine model.  Returns a dict (mm, rad).
    """
    ratio = jnp.tan(sol.beta1) / jnp.tan(sol.alpha_lim)
    valid = jnp.abs(ratio) <= 1.0
    tilt = jnp.where(valid, jnp.arcsin(jnp.clip(ratio, -1.0, 1.0)), jnp.nan)
    sgn = 1.0 if hand == "left" else -1.0
    return dict(dV=E * jnp.sin(sol.theta2) - sol.a1,
                dH=E * jnp.cos(sol.theta2) + sol.a2,
                cradle=sol.theta2 + sgn * 0.5 * jnp.pi,
                tilt=tilt, tilt_valid=valid,
                tilt_reciprocal=jnp.arcsin(jnp.tan(sol.alpha_lim) / jnp.tan(sol.beta1)),
                X_G=sol.a2)
