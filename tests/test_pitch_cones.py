"""[Tangent-cones] pitch cones by tangency: independent checks.

References (docs/references.md): [Tangent-cones] (tangency route), [ISO23509] 6.2.2
(Method 1, the same conditions by a different parametrisation), [Eigenfunctions] §1 (limit normal
n0 = v12 x q / |v12 x q|, independent of the ISO limit-pressure-angle formula).
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.errors import ConvergenceError
from gearjax.frames import apply_point, compose, rot_x, translate
from gearjax.gears.hypoid import iso23509 as iso
from gearjax.gears.hypoid import pitch_cones as pc
D = np.deg2rad

# (u, Sigma, E, de2, b2, beta1, rc0): ISO 23509 sample 2 data, [Eigenfunctions] 7.5-inch case,
# and two non-orthogonal shaft angles
CASES = [
    (42 / 13, D(90.0), 15.0, 170.0, 30.0, D(50.0), 63.5),
    (39 / 6, D(90.0), 35.0, 230.0, 35.65, D(51.44), 95.25),
    (3.0, D(80.0), 20.0, 200.0, 30.0, D(45.0), 80.0),
    (3.0, D(105.0), 20.0, 200.0, 30.0, D(45.0), 80.0),
]


def _cone(delta, R, theta, M):
    """Cone of half angle delta about z of its own frame, mapped to S_f by M."""
    p = jnp.array([R * jnp.sin(delta) * jnp.cos(theta), R * jnp.sin(delta) * jnp.sin(theta),
                   R * jnp.cos(delta)])
    return apply_point(M, p)


def _frames(sol, Sigma, E):
    # pinion: axis z1 -> u1 = (0, sin S, cos S) by an active rotation about x by -Sigma,
    # apex at C1 - a1 u1 (a1 = ISO t_z1, apex beyond the crossing point)
    u1 = jnp.array([0.0, jnp.sin(Sigma), jnp.cos(Sigma)])
    M1 = compose(translate(*(jnp.array([E, 0.0, 0.0]) - sol.a1 * u1)), rot_x(-Sigma))
    M2 = translate(0.0, 0.0, -sol.a2)
    return M1, M2


def _surface_normal(f, R, theta):
    dR = jax.jacfwd(f, 0)(R, theta)
    dt = jax.jacfwd(f, 1)(R, theta)
    n = jnp.cross(dR, dt)
    return n / jnp.linalg.norm(n)


@pytest.mark.parametrize("case", CASES)
def test_tangency_residuals_vanish_independently(case):
    """Cones rebuilt with gearjax.frames from (delta, R, theta, a) touch at P with
    antiparallel normals; the ratio and the limit normal hold by kinematics."""
    u, S, E, de2, b2, beta, rc0 = case
    sol = pc.solve_pitch_cones(u, S, E, de2, b2, beta, rc0)
    M1, M2 = _frames(sol, S, E)
    f1 = lambda R, t: _cone(sol.delta1, R, t, M1)  # noqa: E731
    f2 = lambda R, t: _cone(sol.delta2, R, t, M2)  # noqa: E731
    P1, P2 = f1(sol.R1, sol.theta1), f2(sol.R2, sol.theta2)
    np.testing.assert_allclose(P1, P2, atol=1e-11)                     # eqs (3)-(5)
    n1 = _surface_normal(f1, sol.R1, sol.theta1)
    n2 = _surface_normal(f2, sol.R2, sol.theta2)
    # outward orientation: away from the own axis
    n1 = n1 * jnp.sign(jnp.dot(n1, P1 - apply_point(M1, jnp.array([0.0, 0.0, sol.R1 / jnp.cos(sol.delta1)]))))
    n2 = n2 * jnp.sign(jnp.dot(n2, P2 - apply_point(M2, jnp.array([0.0, 0.0, sol.R2 / jnp.cos(sol.delta2)]))))
    np.testing.assert_allclose(n1, -n2, atol=1e-14)                    # eqs (1)-(2)
    # radii from the cones
    np.testing.assert_allclose(sol.r1, sol.R1 * np.sin(sol.delta1), rtol=1e-14)
    # ratio by kinematics: v12 along the tooth trace at beta2 from the gear generatrix
    u1 = jnp.array([0.0, jnp.sin(S), jnp.cos(S)])
    u2 = jnp.array([0.0, 0.0, 1.0])
    C1 = jnp.array([E, 0.0, 0.0])
    w1, w2 = u1, -u2 / u
    v12 = jnp.cross(w1, P1 - C1) - jnp.cross(w2, P1)
    g2 = (P2 - apply_point(M2, jnp.zeros(3))) / sol.R2
    t = jnp.cos(sol.beta2) * g2 - jnp.sin(sol.beta2) * jnp.cross(n1, g2)
    assert abs(float(jnp.dot(v12, n1))) < 1e-14 * float(jnp.linalg.norm(v12))
    assert float(jnp.linalg.norm(jnp.cross(v12, t))) < 1e-12 * float(jnp.linalg.norm(v12))
    # generatrix angle (8): beta1 - beta2 = angle between the generatrices
    g1 = (P1 - apply_point(M1, jnp.zeros(3))) / sol.R1
    np.testing.assert_allclose(sol.beta1 - sol.beta2, jnp.arccos(jnp.dot(g1, g2)), atol=1e-13)
    # limit normal ([Eigenfunctions] §1.2): n0 = v12 x q, q = w12 x (w1 x r1) - w1 x v12;
    # its inclination out of the pitch plane is the limit pressure angle (ISO (117))
    q = jnp.cross(w1 - w2, jnp.cross(w1, P1 - C1)) - jnp.cross(w1, v12)
    n0 = jnp.cross(v12, q)
    b = jnp.cross(v12 / jnp.linalg.norm(v12), n1)
    n0 = n0 * jnp.sign(jnp.dot(n0, b))
    alim_kin = jnp.arctan2(jnp.dot(n0, n1), jnp.dot(n0, b))
    np.testing.assert_allclose(alim_kin, sol.alpha_lim, atol=1e-13)
    # cutter-radius condition
    np.testing.assert_allclose(sol.rho_lim, rc0, rtol=1e-12)


@pytest.mark.parametrize("case", CASES)
def test_same_conditions_as_iso_method1(case):
    """With ISO's wheel mean radius (12) and ISO's resulting pinion spiral angle (26),
    the tangency route reproduces Method 1 (a different parametrisation, 1-D in eta)
    and ISO's apex distances t_z1, t_z2 (formulae (129)-(131))."""
    u, S, E, de2, b2, beta, rc0 = case
    m1 = iso.method1_pitch_cones(u, S, E, de2, b2, beta, rc0)
    st = iso._method1_start(u, S, E, de2, b2, beta)
    sol = pc.solve_pitch_cones(u, S, E, de2, b2, m1["beta_m1"], rc0, wheel_radius="given",
                               r2=st["rmpt2"])
    for a, b in [(sol.delta1, m1["delta1"]), (sol.delta2, m1["delta2"]),
                 (sol.beta2, m1["beta_m2"]), (sol.zeta, m1["zeta_mp"]),
                 (sol.alpha_lim, m1["alpha_lim"])]:
        np.testing.assert_allclose(a, b, atol=1e-11)
    np.testing.assert_allclose([sol.R1, sol.R2], [m1["Rm1"], m1["Rm2"]], rtol=1e-11)
    gd = iso.gear_dimensions(m1, z1=13.0, u=u, Sigma=S, a=E, b2=b2, rc0=rc0, alpha_dD=D(20.0),
                             alpha_dC=D(20.0), f_alim=1.0, khap=1.0, khfp=1.25, xhm1=0.0)
    np.testing.assert_allclose([sol.a1, sol.a2], [gd["tz1"], gd["tz2"]], atol=1e-9)
    # ISO's offset angle in the axial plane (113) is the complement of the position
    # angle of the pitch point on the gear cone
    np.testing.assert_allclose(gd["zeta_m"], np.pi / 2 - sol.theta2, atol=1e-11)
    # ... and ISO's wheel offset angle eta (Method 1's unknown, (16)-(17)) is the
    # position angle of the pitch point on the pinion cone: eta = -pi/2 - theta1
    # (both routes converged to 1e-12; measured 2e-16 rad)
    np.testing.assert_allclose(m1["eta"], -np.pi / 2 - sol.theta1, atol=1e-11)


def test_seed_route_vs_iso_route_documented_difference():
    """Each route with its own rules ([Tangent-cones]: contact at mid face, beta1 exactly the
    input; ISO: rmpt2 from the approximate pitch angle (11)-(12), beta_m1 after one
    linearised correction) -- ISO 23509 sample 2 data.  The values are quoted in
    docs/hypoid_blank.md."""
    u, S, E, de2, b2, beta, rc0 = CASES[0]
    m1 = iso.method1_pitch_cones(u, S, E, de2, b2, beta, rc0)
    sol = pc.solve_pitch_cones(u, S, E, de2, b2, beta, rc0)
    d = np.rad2deg
    diffs = dict(delta1=d(sol.delta1 - m1["delta1"]), delta2=d(sol.delta2 - m1["delta2"]),
                 beta2=d(sol.beta2 - m1["beta_m2"]), alpha_lim=d(sol.alpha_lim - m1["alpha_lim"]))
    np.testing.assert_allclose(
        [diffs["delta1"], diffs["delta2"], diffs["beta2"], diffs["alpha_lim"]],
        [0.014411, -0.013272, 0.021393, 0.018539], atol=2e-6)
    np.testing.assert_allclose(d(sol.beta1), 50.0, atol=1e-12)
    np.testing.assert_allclose(d(m1["beta_m1"]), 49.998, atol=5e-4)   # ISO's own sample value
    np.testing.assert_allclose((de2 / (2 * np.sin(sol.delta2)) - sol.R2) / b2, 0.5, atol=1e-12)


def test_zero_offset_limit_reduces_to_spiral_bevel():
    """E -> 0: delta1 -> atan(sin S/(u + cos S)), delta1 + delta2 -> Sigma (as E^2),
    beta1 - beta2 and alpha_lim -> 0 (as E).  Richardson extrapolation in E."""
    for S in (D(90.0), D(75.0), D(100.0)):
        u, de2, b2, beta, rc0 = 42 / 13, 170.0, 30.0, D(35.0), 63.5
        sols = [pc.solve_pitch_cones(u, S, E, de2, b2, beta, rc0) for E in (0.4, 0.2)]
        bevel = np.arctan2(np.sin(S), u + np.cos(S))
        d1 = [float(s.delta1) for s in sols]
        extrap = 2 * d1[1] - d1[0]
        assert abs(d1[1] - bevel) > 1e-5                 # the offset really matters ...
        # ... and vanishes linearly: the E-linear part removed, < 1 % is left
        assert abs(extrap - bevel) < 0.01 * abs(d1[1] - bevel)
        gap = [float(S - s.delta1 - s.delta2) for s in sols]
        assert 0 < gap[1] < 0.3 * gap[0]                 # O(E^2): ratio ~ 1/4
        z = [float(s.beta1 - s.beta2) for s in sols]
        np.testing.assert_allclose(z[1] / z[0], 0.5, atol=0.01)  # linear (E^2: 0.25)
        a = [float(s.alpha_lim) for s in sols]
        np.testing.assert_allclose(a[1] / a[0], 0.5, atol=0.01)
        np.testing.assert_allclose(sols[1].r1 * u / sols[1].r2, 1.0, atol=2e-3)


def test_gear_spiral_angle_input():
    u, S, E, de2, b2, beta, rc0 = CASES[0]
    s1 = pc.solve_pitch_cones(u, S, E, de2, b2, beta, rc0)
    s2 = pc.solve_pitch_cones(u, S, E, de2, b2, s1.beta2, rc0, spiral_member="gear")
    np.testing.assert_allclose([s2.delta1, s2.delta2, s2.beta1], [s1.delta1, s1.delta2, beta],
                               atol=1e-10)


def test_jacobian_matches_central_differences():
    """d(outputs)/d(E, u, de2, b2, rc0, beta) by jacfwd through the implicit Newton."""
    x0 = np.array([15.0, 42 / 13, 170.0, 30.0, 63.5, D(50.0)])

    @jax.jit
    def f(x):
        s = pc.solve_pitch_cones(x[1], D(90.0), x[0], x[2], x[3], x[5], x[4], throw=False)
        return jnp.stack([s.delta1, s.delta2, s.beta2, s.alpha_lim, s.R1, s.R2, s.a1, s.a2,
                          s.theta1, s.theta2])

    J = np.asarray(jax.jacfwd(f)(x0))
    h = 1e-5 * np.maximum(np.abs(x0), 1.0)
    Jfd = np.stack([(f(x0 + h[i] * np.eye(6)[i]) - f(x0 - h[i] * np.eye(6)[i])) / (2 * h[i])
                    for i in range(6)], axis=1)
    assert np.all(np.isfinite(J))
    scale = np.max(np.abs(J), axis=1, keepdims=True)
    err = np.max(np.abs(J - Jfd) / scale)
    assert err < 1e-6, err
    # reverse mode agrees with forward mode
    g = jax.grad(lambda x: f(x)[0])(x0)
    np.testing.assert_allclose(g, J[0], rtol=1e-10, atol=1e-14)


def test_non_convergence_raises_or_flags():
    """A cutter radius far below the limit curvature of any physical cone pair."""
    u, S, E, de2, b2, beta, rc0 = CASES[0]
    with pytest.raises(ConvergenceError):
        pc.solve_pitch_cones(u, S, E, de2, b2, beta, 2.0)
    sol = pc.solve_pitch_cones(u, S, E, de2, b2, beta, 2.0, throw=False)
    assert not bool(sol.converged)


@pytest.mark.parametrize("case", CASES)
def test_normal_offset_component_by_linear_algebra(case):
    """gamma = n.x_f from the normal conditions n.u1 = -sin d1, n.u2 = sin d2, |n| = 1
    solved with NumPy (minimum-norm solution of the 2x3 system, then the x_f part);
    delta2_from_normal inverts it.  Round-off only: gamma^2 = 1 - |n_par|^2 cancels
    (measured 1.1e-15, a few ulp of 1) -> 4e-15; delta2 to 1e-14 rad (measured 3e-16)."""
    u, S, E, de2, b2, beta, rc0 = case
    u1, u2 = np.array([0.0, np.sin(S), np.cos(S)]), np.array([0.0, 0.0, 1.0])
    for d1, d2 in [(D(17.0), S - D(17.0) - D(0.4)), (D(25.0), S - D(25.0) - D(2.0)),
                   (D(20.0), S - D(20.0))]:
        n_par = np.linalg.lstsq(np.stack([u1, u2]), [-np.sin(d1), np.sin(d2)], rcond=None)[0]
        g2 = 1.0 - n_par @ n_par                 # gamma^2 (sqrt amplifies round-off at 0)
        g = float(pc.normal_offset_component(d1, d2, S))
        assert g <= 0.0
        np.testing.assert_allclose(g ** 2, g2, rtol=0, atol=4e-15)
        # spiral-bevel limit (d1 + d2 = Sigma): gamma = 0 exactly
        gamma = 0.0 if abs(d1 + d2 - S) < 1e-15 else -np.sqrt(g2)
        np.testing.assert_allclose(pc.delta2_from_normal(d1, gamma, S), d2, rtol=0, atol=1e-14)


def test_seed_machine_settings_literal_and_tilt_slip():
    u, S, E, de2, b2, beta, rc0 = CASES[0]
    sol = pc.solve_pitch_cones(u, S, E, de2, b2, beta, rc0)
    ms = pc.pinion_machine_settings(sol, E, "left")
    # the tilt relation of [Tangent-cones] sin i = tan(beta1)/tan(alpha_lim) has no solution here
    assert abs(float(jnp.tan(sol.beta1) / jnp.tan(sol.alpha_lim))) > 20
    assert not bool(ms["tilt_valid"]) and np.isnan(ms["tilt"])
    # the reciprocal reading asin(tan alpha_lim / tan beta1), typed in
    t = float(np.tan(sol.alpha_lim) / np.tan(sol.beta1))
    np.testing.assert_allclose(ms["tilt_reciprocal"], np.arcsin(t), rtol=0, atol=1e-15)
    assert -0.1 < float(ms["tilt_reciprocal"]) < 0          # alpha_lim < 0, beta1 > 0
    # cradle angle theta2 + 90 deg (left hand) / theta2 - 90 deg (right hand), with
    # theta2 = 90 deg - zeta_m and the offset angle in the axial plane zeta_m typed in
    # from ISO 23509 (110), (111), (113) -- a different formula for the same angle
    # (measured 4e-16 rad; 1e-14)
    dm1, dm2 = 2 * sol.R1 * np.sin(sol.delta1), 2 * sol.R2 * np.sin(sol.delta2)
    zeta_m = np.arcsin(2 * E / (dm2 + dm1 * np.cos(sol.delta2) / np.cos(sol.delta1)))
    np.testing.assert_allclose(ms["cradle"], np.pi - zeta_m, rtol=0, atol=1e-14)
    np.testing.assert_allclose(pc.pinion_machine_settings(sol, E, "right")["cradle"], -zeta_m,
                               rtol=0, atol=1e-14)
    # gear machine centre to back X_G = a2 ([Tangent-cones]), a2 = ISO t_z2 for the same cone
    # pair: formulae (129), (131) typed in (measured 1e-14 mm; 1e-10 mm)
    dS = S - np.pi / 2
    tzm2 = (dm1 * np.sin(sol.delta2) / (2 * np.cos(sol.delta1))
            - 0.5 * np.cos(zeta_m) * np.tan(dS) * (dm2 + dm1 * np.cos(sol.delta2) / np.cos(sol.delta1)))
    np.testing.assert_allclose(ms["X_G"], sol.R2 * np.cos(sol.delta2) - tzm2, rtol=0, atol=1e-10)
    # vertical wheel base from the cone geometry: E sin(theta2) - a1, with theta2 the
    # angle of the pitch point seen from the gear axis (P_y / r2 = sin theta2)
    P = pc.cone_tangency(sol.delta1, sol.delta2, S, E, sol.R2)["P"]
    np.testing.assert_allclose(ms["dV"], E * P[1] / sol.r2 - sol.a1, atol=1e-10)
    np.testing.assert_allclose(ms["dH"], E * P[0] / sol.r2 + sol.a2, atol=1e-10)
