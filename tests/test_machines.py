"""Cradle-type generator (gearjax.gears.hypoid.machine): No. 116 dials, M_ct, roll, relative velocity."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax import frames
from gearjax.gears.hypoid.cutter import cutter_point, make_cutter
from gearjax.gears.hypoid.machine import (MACHINE_LENGTH, WEDGE_ANGLE, MachineSettings, No116Dials,
                              cutter_to_cradle, cutter_to_work, dial_cutter_to_cradle,
                              dials_to_geometric, geometric_to_dials, roll_angle,
                              work_to_machine)

D = math.radians
SEED_DIALS = [(126.27, 63.018609, 261.25, 54.2), (125.92, 65.255185, 256.37, 55.35),
              (10.0, 30.0, -40.0, 120.0), (300.0, 100.0, 15.0, 170.0)]


def _dials(c, e, s, t):
    return No116Dials(jnp.asarray(D(c)), jnp.asarray(D(e)), jnp.asarray(D(s)), jnp.asarray(D(t)))


@pytest.mark.parametrize("dial", SEED_DIALS)
def test_mct_reproduces_seed_a11(dial):
    c, e, s, t = (D(v) for v in dial)
    eps = D(15.0)
    tau = c + e + s
    a11 = math.cos(tau) * (math.cos(eps) ** 2 * math.cos(t) + math.sin(eps) ** 2) \
        - math.sin(tau) * math.cos(eps) * math.sin(t)           # [HFT-hypoid], by hand
    M = np.asarray(dial_cutter_to_cradle(_dials(*dial)))
    assert abs(M[0, 0] - a11) < 1e-14
    # a proper rigid transform
    R = M[:3, :3]
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)
    assert abs(np.linalg.det(R) - 1) < 1e-14
    # the eccentric: cutter centre at radial distance 2 l sin(phi_e/2) (isosceles arms)
    assert abs(np.hypot(M[0, 3], M[1, 3]) - 2 * MACHINE_LENGTH * math.sin(e / 2)) < 1e-12


@pytest.mark.parametrize("dial", SEED_DIALS)
def test_dial_and_geometric_routes_place_the_same_cutter(dial):
    """Independent route: the cutter cone placed by the dial matrix and by the
    converted geometric settings is the same surface of revolution."""
    d = _dials(*dial)
    S, q, i, j = dials_to_geometric(d)
    ms = MachineSettings.create(radial_distance=float(S), cradle_angle=float(q), tilt=float(i),
                                swivel=float(j), machine_root_angle=0.0, ratio_of_roll=1.0)
    Md = np.asarray(dial_cutter_to_cradle(d))
    Mg = np.asarray(cutter_to_cradle(ms))
    np.testing.assert_allclose(Md[:3, 3], Mg[:3, 3], atol=1e-12)        # cutter centre
    np.testing.assert_allclose(Md[:3, 2], Mg[:3, 2], atol=1e-14)        # cutter axis
    c = make_cutter(117.475, 29.0, 1.0, "convex")
    Minv = np.asarray(frames.inverse(jnp.asarray(Mg)))
    for s, th in [(0.0, 0.1), (6.0, 2.0), (11.0, -2.5)]:
        p = Md @ np.append(np.asarray(cutter_point(c, s, th)), 1.0)     # dial route
        pg = Minv @ p                                                   # into the geometric cutter frame
        s_back = -pg[2] / math.cos(D(29.0))
        assert abs(s_back - s) < 1e-11
        assert abs(math.hypot(pg[0], pg[1]) - float(c.point_radius - s_back * math.sin(D(29.0)))) < 1e-11
    # tilt from the wedge construction: cos i = cos^2 eps + sin^2 eps cos phi_t
    eps, t = WEDGE_ANGLE, D(dial[3])
    assert abs(math.cos(float(i)) - (math.cos(eps) ** 2 + math.sin(eps) ** 2 * math.cos(t))) < 1e-14
    q0 = D(dial[0]) + D(dial[1]) / 2 - math.pi / 2                      # q0 of [HFT-hypoid] (mirrored: -q0)
    assert abs(math.sin(float(q) + q0)) < 1e-14 and math.cos(float(q) + q0) > 0


def test_geometric_to_dials_validation():
    """Range checks of the inverse (the inverse itself is checked against the
    hand-typed dial product in test_dial_and_geometric_settings_agree_by_hand)."""
    with pytest.raises(ValueError, match="radial_distance"):
        geometric_to_dials(250.0, 0.0, 0.1, 0.0)          # S_r > 2 l = 222.25 mm
    with pytest.raises(ValueError, match="tilt"):
        geometric_to_dials(100.0, 0.0, D(31.0), 0.0)      # i > 2 eps = 30 deg


def _ms(**kw):
    base = dict(radial_distance=116.0, cradle_angle=1.18, tilt=0.236, swivel=-0.856,
                blank_offset=26.48, machine_root_angle=D(-3.33), sliding_base=28.8,
                center_to_back=-24.04, ratio_of_roll=5.3608, modified_roll_2c=0.08,
                modified_roll_6d=-0.3)
    base.update(kw)
    return MachineSettings.create(**base)


def test_pytree_fields():
    ms = _ms()
    leaves, tree = jax.tree_util.tree_flatten(ms)
    assert len(leaves) == 11
    assert jax.tree_util.tree_unflatten(tree, leaves).generated is True
    formate = _ms(generated=False)
    assert jax.tree_util.tree_structure(formate) != tree      # generated is static


def test_modified_roll_coefficients():
    ms = _ms()
    f = lambda p: roll_angle(ms, p)
    Ra = 5.3608
    assert abs(float(jax.grad(f)(0.0)) - Ra) < 1e-12
    assert abs(float(jax.grad(jax.grad(f))(0.0)) + 0.08 * Ra) < 1e-12      # -2C R_a
    assert abs(float(jax.grad(jax.grad(jax.grad(f)))(0.0)) + (-0.3) * Ra) < 1e-12  # -6D R_a
    assert float(roll_angle(_ms(generated=False), 0.4)) == 0.0


# ----- hand-typed reference matrices (NumPy), from the definitions in the module
# docstring / Litvin & Fuentes ch. 21: active rotations, homogeneous 4x4 transforms


def _Rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1]])


def _Ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s, 0], [0, 1.0, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1]])


def _Rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1.0, 0], [0, 0, 0, 1]])


def _T(x, y, z):
    M = np.eye(4)
    M[:3, 3] = (x, y, z)
    return M


def _Mct_ref(S, q, i, j):
    """M_ct = T(S cos q, S sin q, 0) Rz(q - j) Rx(i)."""
    return _T(S * math.cos(q), S * math.sin(q), 0.0) @ _Rz(q - j) @ _Rx(i)


def _Mmw_ref(E, gamma, XB, dXD, phi):
    """M_mw(phi) = T(0, E_m, X_B) Ry(pi/2 - gamma_m) T(0, 0, dX_D) Rz(phi)."""
    return _T(0.0, E, XB) @ _Ry(math.pi / 2 - gamma) @ _T(0.0, 0.0, dXD) @ _Rz(phi)


def _roll_ref(Ra, c2, d6, psi):
    """Gleason modified roll phi = R_a (psi - C psi^2 - D psi^3) with 2C, 6D given."""
    return Ra * (psi - c2 / 2 * psi ** 2 - d6 / 6 * psi ** 3)


def _dial_ref(c, e, s, t, eps=math.radians(15.0), l=222.25 / 2):
    """The No. 116 product of [HFT-hypoid] typed in with NumPy, mirrored in y (P A P).
    R_k by the vector form of Rodrigues: cos t I + sin t [k]x + (1 - cos t) k k^T."""
    k = np.array([math.sin(eps), 0.0, math.cos(eps)])
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    Rk = np.eye(4)
    Rk[:3, :3] = math.cos(t) * np.eye(3) + math.sin(t) * kx + (1 - math.cos(t)) * np.outer(k, k)
    A = _T(l * (math.cos(c) - math.cos(c + e)), l * (math.sin(c) - math.sin(c + e)), 0.0) \
        @ _Rz(c + e + s) @ Rk
    P = np.diag([1.0, -1.0, 1.0, 1.0])
    return P @ A @ P


MS_KW = dict(radial_distance=116.0, cradle_angle=1.18, tilt=0.236, swivel=-0.856,
             blank_offset=26.48, machine_root_angle=D(-3.33), sliding_base=28.8,
             center_to_back=-24.04, ratio_of_roll=5.3608, modified_roll_2c=0.08,
             modified_roll_6d=-0.3)


def test_transforms_against_hand_typed_matrices():
    """cutter_to_cradle, work_to_machine, roll_angle and cutter_to_work against the
    matrix products of the module docstring typed in with NumPy (Litvin & Fuentes
    ch. 21 cradle model), generated and formate.  Reference and code differ only by
    round-off (measured 4e-14 mm on ~150 mm coordinates, 0 rad in the roll): 1e-12 mm
    in the matrices, 1e-14 rad in the roll."""
    k = MS_KW
    ms = _ms()
    Mct = _Mct_ref(k["radial_distance"], k["cradle_angle"], k["tilt"], k["swivel"])
    np.testing.assert_allclose(np.asarray(cutter_to_cradle(ms)), Mct, rtol=0, atol=1e-12)
    for psi in (0.0, 0.17, -0.31):
        phi = _roll_ref(k["ratio_of_roll"], k["modified_roll_2c"], k["modified_roll_6d"], psi)
        assert abs(float(roll_angle(ms, psi)) - phi) < 1e-14
        Mmw = _Mmw_ref(k["blank_offset"], k["machine_root_angle"], k["sliding_base"],
                       k["center_to_back"], phi)
        np.testing.assert_allclose(np.asarray(work_to_machine(ms, phi)), Mmw, rtol=0, atol=1e-12)
        Mwt = np.linalg.inv(Mmw) @ _Rz(psi) @ Mct
        np.testing.assert_allclose(np.asarray(cutter_to_work(ms, psi)), Mwt, rtol=0, atol=1e-12)
        # formate: no roll of the cradle nor of the work, whatever psi is
        Mf = np.linalg.inv(_Mmw_ref(k["blank_offset"], k["machine_root_angle"],
                                    k["sliding_base"], k["center_to_back"], 0.0)) @ Mct
        np.testing.assert_allclose(np.asarray(cutter_to_work(_ms(generated=False), psi)), Mf,
                                   rtol=0, atol=1e-12)


def test_machine_known_points():
    """Known points/directions from the verbal definitions (no matrix product):
    cutter centre at (S_r cos q, S_r sin q, 0), cutter axis tilted by i from z_c
    about the radial line turned by -j; the work apex at
    (dX_D cos g_m, E_m, X_B + dX_D sin g_m) on a work axis (cos g_m, 0, sin g_m) that
    makes the machine root angle with the machine plane (root line along +x_m); the
    work roll turns about the work axis and the cradle roll carries the cutter centre
    to the cradle angle q + psi (that last check maps back with the hand-typed M_mw).
    Exact up to round-off (measured <= 2e-14 mm, 6e-17): 1e-12 mm, 1e-14."""
    S, q, i, j = 97.0, D(40.0), D(20.0), D(-65.0)
    E, g, XB, dX = 12.5, D(30.0), 7.0, -4.0
    ms = MachineSettings.create(radial_distance=S, cradle_angle=q, tilt=i, swivel=j,
                                blank_offset=E, machine_root_angle=g, sliding_base=XB,
                                center_to_back=dX, ratio_of_roll=3.0)
    Mct = np.asarray(cutter_to_cradle(ms))
    np.testing.assert_allclose(Mct[:3, 3], [S * math.cos(q), S * math.sin(q), 0.0], atol=1e-12)
    # tilt line l = (cos a, sin a, 0), a = q - j (radial line turned by -j); turning
    # z_c by i about l (Rodrigues): z cos i + (l x z) sin i
    a = q - j
    np.testing.assert_allclose(Mct[:3, 2], [math.sin(i) * math.sin(a), -math.sin(i) * math.cos(a),
                                            math.cos(i)], atol=1e-14)
    np.testing.assert_allclose(Mct[:3, 0], [math.cos(a), math.sin(a), 0.0], atol=1e-14)
    Mmw = np.asarray(work_to_machine(ms, 0.0))
    np.testing.assert_allclose(Mmw[:3, 3], [dX * math.cos(g), E, XB + dX * math.sin(g)], atol=1e-12)
    np.testing.assert_allclose(Mmw[:3, 2], [math.cos(g), 0.0, math.sin(g)], atol=1e-14)
    # the work roll turns the work about its own axis: the apex and axis stay put and a
    # work point at radius 10 on x_w moves by phi about the axis
    phi = 0.4
    M = np.asarray(work_to_machine(ms, phi))
    np.testing.assert_allclose(M[:3, 3], Mmw[:3, 3], atol=1e-12)
    p = M[:3, :3] @ np.array([10.0, 0.0, 0.0])
    x0 = Mmw[:3, 0]
    y0 = Mmw[:3, 1]
    np.testing.assert_allclose(p, 10 * (math.cos(phi) * x0 + math.sin(phi) * y0), atol=1e-12)
    # the cradle roll turns cutter centre about z_m: at psi the centre is at angle q + psi
    # (the work turned back by phi(psi) = R_a psi)
    psi = 0.2
    Mwt = np.asarray(cutter_to_work(ms, psi))
    centre_m = _Mmw_ref(E, g, XB, dX, 3.0 * psi) @ Mwt @ np.array([0, 0, 0, 1.0])
    np.testing.assert_allclose(centre_m[:3], [S * math.cos(q + psi), S * math.sin(q + psi), 0.0],
                               atol=1e-12)


@pytest.mark.parametrize("dial", SEED_DIALS)
def test_dial_matrix_against_hand_typed_product(dial):
    """dial_cutter_to_cradle = P A P with the product A of [HFT-hypoid] typed in with NumPy
    (Rodrigues in the vector form, not the code's I + sin K + (1-cos) K^2);
    round-off only (measured 2e-16 in the rotation, 0 mm in the translation):
    1e-14, 1e-12 mm."""
    c, e, s, t = (D(v) for v in dial)
    M = np.asarray(dial_cutter_to_cradle(_dials(*dial)))
    R = _dial_ref(c, e, s, t)
    np.testing.assert_allclose(M[:3, :3], R[:3, :3], rtol=0, atol=1e-14)
    np.testing.assert_allclose(M[:3, 3], R[:3, 3], rtol=0, atol=1e-12)


@pytest.mark.parametrize("dial", SEED_DIALS)
def test_dial_and_geometric_settings_agree_by_hand(dial):
    """dials_to_geometric and geometric_to_dials against the hand-typed matrices:
    the geometric M_ct of the converted settings has the same cutter centre and axis as
    the hand-typed dial product, and converting back gives dials whose hand-typed
    product is the same again (the swivel about the own axis is free).  Round-off
    only (measured 4e-14 mm / 4e-16): 1e-12 mm, 1e-14."""
    c, e, s, t = (D(v) for v in dial)
    S, q, i, j = (float(v) for v in dials_to_geometric(_dials(*dial)))
    R = _dial_ref(c, e, s, t)
    G = _Mct_ref(S, q, i, j)
    np.testing.assert_allclose(G[:3, 3], R[:3, 3], atol=1e-12)
    np.testing.assert_allclose(G[:3, 2], R[:3, 2], atol=1e-14)
    back = geometric_to_dials(S, q, i, j)
    B = _dial_ref(*(float(v) for v in (back.cradle, back.eccentric, back.swivel, back.tilt)))
    np.testing.assert_allclose(B[:3, 3], R[:3, 3], atol=1e-12)
    np.testing.assert_allclose(B[:3, 2], R[:3, 2], atol=1e-14)


def test_relative_velocity_matches_angular_velocity_formula():
    """dr_w/dpsi by autodiff equals the (omega_c - omega_w) x r + omega_w x R form of [HFT-hypoid],
    written in the machine frame and rotated into the work frame.  The machine
    frame, the work axis and the roll rate come from the hand-typed matrices and
    the hand-differentiated roll (R_a (1 - 2C psi - 6D psi^2 / 2)), not from
    gearjax.gears.hypoid.machine.  Round-off only (measured 1.1e-13 mm/rad on ~600 mm/rad): 1e-11."""
    k = MS_KW
    ms = _ms()
    c = make_cutter(117.475, 29.0, 1.0, "convex")
    for s, th, psi in [(3.0, -3.0, 0.1), (8.0, -2.7, -0.2)]:
        rw = lambda p: frames.apply_point(cutter_to_work(ms, p), cutter_point(c, s, th))
        v_ad = np.asarray(jax.jacfwd(rw)(psi))
        phi = _roll_ref(k["ratio_of_roll"], k["modified_roll_2c"], k["modified_roll_6d"], psi)
        Mmw = _Mmw_ref(k["blank_offset"], k["machine_root_angle"], k["sliding_base"],
                       k["center_to_back"], phi)
        r_m = Mmw[:3, :3] @ np.asarray(rw(psi)) + Mmw[:3, 3]
        w_c = np.array([0.0, 0.0, 1.0])                     # cradle, per unit psi
        dphi = k["ratio_of_roll"] * (1 - k["modified_roll_2c"] * psi
                                     - k["modified_roll_6d"] / 2 * psi ** 2)
        w_w = dphi * Mmw[:3, 2]                             # work axis direction, rate dphi/dpsi
        R = Mmw[:3, 3]                                      # a point on the work axis
        v_m = np.cross(w_c - w_w, r_m) + np.cross(w_w, R)
        np.testing.assert_allclose(Mmw[:3, :3].T @ v_m, v_ad, rtol=0, atol=1e-11)


@pytest.mark.parametrize("kw,name", [
    (dict(radial_distance=-1.0), "radial_distance"),
    (dict(tilt=-0.1), "tilt"),
    (dict(ratio_of_roll=0.0), "ratio_of_roll"),
    (dict(sliding_base=float("nan")), "sliding_base"),
])
def test_settings_validation(kw, name):
    with pytest.raises(ValueError, match=name):
        _ms(**kw)
