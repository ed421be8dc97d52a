"""Straight-blade face-mill cutter (gearjax.gears.hypoid.cutter): [HFT-hypoid] surface, normals, fillet."""

import math

import jax
import numpy as np
import pytest

from gearjax.gears.hypoid.cutter import (blade_radius, cutter_normal, cutter_point, cutter_tangents,
                             fillet_normal, fillet_point, fillet_start, make_cutter)


@pytest.mark.parametrize("flank,alpha", [("convex", 29.0), ("concave", 16.0)])
def test_seed_formula_and_normal(flank, alpha):
    c = make_cutter(117.475, alpha, 1.0, flank)
    a = math.radians(alpha)
    sg = 1 if flank == "convex" else -1
    for s, th in [(0.0, 0.3), (5.0, -1.2), (12.0, 2.9)]:
        r = np.asarray(cutter_point(c, s, th))
        rho = 117.475 - sg * s * math.sin(a)              # [HFT-hypoid], written out by hand
        np.testing.assert_allclose(r, [rho * math.cos(th), rho * math.sin(th), -s * math.cos(a)],
                                   rtol=0, atol=1e-12)
        # normal = sgn * (dr/ds x dr/dtheta)/|.|, a unit vector
        rs = jax.jacfwd(lambda x: cutter_point(c, x, th))(s)
        rt = jax.jacfwd(lambda x: cutter_point(c, s, x))(th)
        cr = np.cross(rs, rt)
        n_ref = sg * cr / np.linalg.norm(cr)
        np.testing.assert_allclose(np.asarray(cutter_normal(c, s, th)), n_ref, atol=1e-14)
        # s is arc length along the blade
        assert abs(np.linalg.norm(rs) - 1.0) < 1e-14


def test_inside_blade_shrinks_outside_grows():
    cv = make_cutter(100.0, 20.0, 1.0, "convex")
    cc = make_cutter(100.0, 20.0, 1.0, "concave")
    assert float(blade_radius(cv, 5.0)) < 100.0 < float(blade_radius(cc, 5.0))
    # normal points into the tooth space: outward for the inside blade, inward for the outside
    assert float(cutter_normal(cv, 1.0, 0.0)[0]) > 0 > float(cutter_normal(cc, 1.0, 0.0)[0])


@pytest.mark.parametrize("flank", ["convex", "concave"])
def test_fillet_joins_blade_and_tip_plane(flank):
    c = make_cutter(114.3, 25.0, 1.2, flank)
    a = math.radians(25.0)
    s0 = float(fillet_start(c))
    assert abs(s0 - 1.2 * (1 - math.sin(a)) / math.cos(a)) < 1e-14
    th = 0.7
    # tangent continuity with the blade at phi = alpha
    np.testing.assert_allclose(fillet_point(c, a, th), cutter_point(c, s0, th), atol=1e-12)
    np.testing.assert_allclose(fillet_normal(c, a, th), cutter_normal(c, s0, th), atol=1e-14)
    # at phi = pi/2 the fillet touches the tip plane z = 0 with normal -z
    p = np.asarray(fillet_point(c, math.pi / 2, th))
    assert abs(p[2]) < 1e-12
    np.testing.assert_allclose(fillet_normal(c, math.pi / 2, th), [0, 0, -1], atol=1e-15)
    # fillet normal is the torus normal: perpendicular to d/dphi and d/dtheta
    dphi = jax.jacfwd(lambda x: fillet_point(c, x, th))(1.0)
    dth = jax.jacfwd(lambda x: fillet_point(c, 1.0, x))(th)
    n = np.asarray(fillet_normal(c, 1.0, th))
    assert abs(n @ dphi) < 1e-12 and abs(n @ dth) < 1e-12


@pytest.mark.parametrize("flank,sg", [("convex", 1), ("concave", -1)])
def test_tangents_by_hand(flank, sg):
    """cutter_tangents against the derivatives of the [HFT-hypoid] cone differentiated by
    hand: dr/ds = (-sg sin a cos t, -sg sin a sin t, -cos a),
    dr/dt = (-rho sin t, rho cos t, 0), rho = R_p - sg s sin a.  Round-off only
    (measured 0): 1e-14 on the unit tangent, 1e-12 mm on ~114 mm."""
    c = make_cutter(114.3, 22.0, 1.5, flank)
    assert c.side == flank and c.sign == sg
    a = math.radians(22.0)
    for s, t in [(0.0, 0.0), (4.0, 1.3), (9.5, -2.2)]:
        rho = 114.3 - sg * s * math.sin(a)
        assert abs(float(blade_radius(c, s)) - rho) < 1e-12
        rs, rt = (np.asarray(v) for v in cutter_tangents(c, s, t))
        np.testing.assert_allclose(rs, [-sg * math.sin(a) * math.cos(t), -sg * math.sin(a) * math.sin(t),
                                        -math.cos(a)], rtol=0, atol=1e-14)
        np.testing.assert_allclose(rt, [-rho * math.sin(t), rho * math.cos(t), 0.0], rtol=0, atol=1e-12)


@pytest.mark.parametrize("flank,sg", [("convex", 1), ("concave", -1)])
def test_fillet_is_the_inscribed_circle(flank, sg):
    """Plane geometry of the blade tip corner (axial section, (radius, z)): the fillet
    is the circle of radius rho_f tangent to the tip plane z = 0 and to the blade line
    through the tip corner (R_p, 0) with direction (-sg sin a, -cos a), centred inside
    the blade (the side the blade normal points to).  Its centre (found here by NumPy from the two tangency conditions) and every
    fillet point lie where gearjax puts them.  Round-off only (measured 4e-15 mm): 1e-12."""
    Rp, alpha, rf = 110.0, 18.0, 2.0
    c = make_cutter(Rp, alpha, rf, flank)
    a = math.radians(alpha)
    d = np.array([-sg * math.sin(a), -math.cos(a)])          # blade direction from the tip
    nb = np.array([sg * math.cos(a), -math.sin(a)])          # blade normal (into the blade)
    # centre C: z_C = -rf (tangent to z = 0), (C - corner).nb = +rf (inside the blade)
    zc = -rf
    rc = Rp + (rf - zc * nb[1]) / nb[0]
    centre = np.array([rc, zc])
    # tangent point on the blade: foot of the perpendicular from the centre
    s_t = (centre - np.array([Rp, 0.0])) @ d
    assert abs(float(fillet_start(c)) - s_t) < 1e-12
    for phi in np.linspace(a, math.pi / 2, 5):
        p = np.asarray(fillet_point(c, phi, 0.3))
        rz = np.array([math.hypot(p[0], p[1]), p[2]])
        assert abs(np.linalg.norm(rz - centre) - rf) < 1e-12
        assert abs(math.atan2(p[1], p[0]) - 0.3) < 1e-14
        nrm = np.asarray(fillet_normal(c, phi, 0.3))
        # the normal points from the fillet towards its centre (into the blade)
        n_rz = np.array([nrm[0] * math.cos(0.3) + nrm[1] * math.sin(0.3), nrm[2]])
        np.testing.assert_allclose(n_rz, (centre - rz) / rf, atol=1e-14)


@pytest.mark.parametrize("args,name", [
    ((-5.0, 20.0, 1.0, "convex"), "point_radius"),
    ((100.0, 0.0, 1.0, "convex"), "blade_angle"),
    ((100.0, 45.0, 1.0, "convex"), "blade_angle"),
    ((100.0, 50.0, 1.0, "concave"), "blade_angle"),
    ((100.0, 20.0, -1.0, "convex"), "edge_radius"),
    ((100.0, 20.0, 1.0, "middle"), "flank"),
])
def test_validation_names_parameter(args, name):
    with pytest.raises(ValueError, match=name):
        make_cutter(*args)
