"""Cradle-type generator (gearjax.machines): No. 116 dials, M_ct, roll, relative velocity."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax import frames
from gearjax.cutters import cutter_point, make_cutter
from gearjax.machines import (MACHINE_LENGTH, WEDGE_ANGLE, MachineSettings, No116Dials,
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
        - math.sin(tau) * math.cos(eps) * math.sin(t)           # seed 004, by hand
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
    q0 = D(dial[0]) + D(dial[1]) / 2 - math.pi / 2                      # seed's q0 (mirrored: -q0)
    assert abs(math.sin(float(q) + q0)) < 1e-14 and math.cos(float(q) + q0) > 0


@pytest.mark.parametrize("dial", SEED_DIALS)
def test_geometric_to_dials_inverts(dial):
    d = _dials(*dial)
    g = [float(v) for v in dials_to_geometric(d)]
    back = geometric_to_dials(*g)
    np.testing.assert_allclose(np.asarray(dial_cutter_to_cradle(back))[:3, 2:],
                               np.asarray(dial_cutter_to_cradle(d))[:3, 2:], atol=1e-12)
    with pytest.raises(ValueError, match="radial_distance"):
        geometric_to_dials(250.0, 0.0, 0.1, 0.0)
    with pytest.raises(ValueError, match="tilt"):
        geometric_to_dials(100.0, 0.0, D(31.0), 0.0)


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


def test_relative_velocity_matches_angular_velocity_formula():
    """dr_w/dpsi by autodiff equals seed 004's (omega_c - omega_w) x r + omega_w x R form,
    written in the machine frame and rotated into the work frame."""
    ms = _ms()
    c = make_cutter(117.475, 29.0, 1.0, "convex")
    for s, th, psi in [(3.0, -3.0, 0.1), (8.0, -2.7, -0.2)]:
        rw = lambda p: frames.apply_point(cutter_to_work(ms, p), cutter_point(c, s, th))
        v_ad = np.asarray(jax.jacfwd(rw)(psi))
        Mmw = np.asarray(work_to_machine(ms, roll_angle(ms, psi)))
        r_m = Mmw[:3, :3] @ np.asarray(rw(psi)) + Mmw[:3, 3]
        w_c = np.array([0.0, 0.0, 1.0])                     # cradle, per unit psi
        dphi = float(jax.grad(lambda p: roll_angle(ms, p))(psi))
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
