"""[Eigenfunctions] §2-§3 (docs/references.md): hypoid meshing characteristics by eigenfunctions.

References are independent of the code under test: the paper's own angular-velocity
formulas, the ratio condition at the pitch point, Euler/Bertrand closed forms for
the cutter cone, the conjugate pinion flank built explicitly (K_II = k_gear - k_pinion),
the paper's Table 1 and central differences."""

import re
from collections import namedtuple

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.errors import ConvergenceError
from gearjax.studies import cutter_radius as hk
from gearjax.gears.hypoid.blank import blank_geometry
from notebook_run import images, run_notebook

SHAPE = (7, 5)

# [Eigenfunctions] Table 1: r0 -> (b1 mm, alpha_D, alpha_C, delta1, beta1, beta2, delta2) deg
SEED_TABLE1 = {76.2: (47.365, 15.940, -22.060, 12.493, 76.650, 8.774, 70.906),
               95.25: (47.403, 14.841, -23.159, 10.441, 78.833, 8.76, 72.901),
               114.3: (47.423, 14.106, -23.894, 9.075, 80.289, 8.754, 74.333)}


@pytest.fixture(scope="module")
def base():
    inp = hk.study_blank_input(95.25)
    st = hk.StudySettings.make(95.25)
    s, f = hk.flank_fields(inp, st, "convex", SHAPE)
    return inp, st, s, f


def test_seed_angular_velocities_in_pitch_frame():
    """[Eigenfunctions] §2.3: omega(2) = |w2|(-c d2 s b2, c d2 c b2, -s d2), omega(1) = |w1|(c d1 s b1,
    -c d1 c b1, -s d1) in i-j-k, with the blank's pitch and spiral angles."""
    for r0 in hk.STUDY_CUTTERS.values():
        inp = hk.study_blank_input(r0)
        s = hk.pitch_setup(inp, hk.StudySettings.make(r0))
        M = np.stack([np.asarray(s.i), np.asarray(s.j), np.asarray(s.k)])
        d1, d2, b1, b2 = (float(s.blank[k]) for k in ("delta1", "delta2", "beta_m1", "beta_m2"))
        wg = np.asarray(s.mesh.omega1)
        wp = np.asarray(s.mesh.omega2)
        assert np.linalg.norm(wg) == pytest.approx(6 / 39, rel=1e-14)
        seed_g = np.linalg.norm(wg) * np.array([-np.cos(d2) * np.sin(b2), np.cos(d2) * np.cos(b2),
                                                -np.sin(d2)])
        seed_p = np.array([np.cos(d1) * np.sin(b1), -np.cos(d1) * np.cos(b1), -np.sin(d1)])
        np.testing.assert_allclose(M @ wg, seed_g, atol=1e-13)
        np.testing.assert_allclose(M @ wp, seed_p, atol=1e-13)
        # j is the tooth-trace tangent: angle beta2 from the gear generatrix (ratio condition)
        ang = np.arccos(abs(float(np.dot(s.j, s.g2))))
        assert ang == pytest.approx(b2, abs=1e-10)
        # the cutter circle passes through P tangent to j
        assert float(np.linalg.norm(s.centre - s.P)) == pytest.approx(r0, rel=1e-14)
        assert abs(float(np.dot(s.centre - s.P, s.j))) < 1e-10


def test_meshing_equation_and_convergence(base):
    _, _, s, f = base
    assert np.all(np.asarray(f.converged))
    r, n = np.asarray(f.r), np.asarray(f.n)
    wg, wp, a = (np.asarray(x) for x in (s.mesh.omega1, s.mesh.omega2, s.mesh.a))
    v = np.cross(wg, r) - np.cross(wp, r - a)
    assert np.max(np.abs(np.sum(n * v, -1)) / np.linalg.norm(v, axis=-1)) < 1e-10
    # the cutter point (0, 0) is the pitch point, in contact at roll 0
    f0 = jax.jit(lambda x: hk.point_fields(s, x))(jnp.zeros(2))
    assert abs(float(f0.phi)) < 1e-12
    np.testing.assert_allclose(np.asarray(f0.r), np.asarray(s.P), atol=1e-10)
    # p tangent and normal to the contact line; eigen identities
    p = np.asarray(f.p)
    assert np.max(np.abs(np.sum(p * n, -1))) < 1e-12 * np.max(np.abs(p))
    assert np.max(np.abs(np.sum(p * np.asarray(f.contact_dir), -1))) < 1e-12 * np.max(np.abs(p))
    us = np.sum(np.asarray(f.v12) * p, -1) / np.linalg.norm(p, axis=-1)
    np.testing.assert_allclose(np.asarray(f.u_s), us, rtol=1e-12, atol=1e-12)


def test_euler_bertrand_vs_autodiff(base):
    """[Eigenfunctions] §2.3 closed forms (cone: k_e = cos a/r_u, k_f = 0) vs autodiff curvature,
    and the paper's p = w12 x n + k_v v + tau_v (n x v) vs p = w12 x n - W v."""
    _, _, s, f = base
    kv, tv = np.asarray(f.k_v), np.asarray(f.tau_v)
    scale = np.max(np.abs(kv))
    assert scale > 1e-3
    np.testing.assert_allclose(np.asarray(f.k_v_eb), kv, atol=1e-13 * scale / 1e-3 * 1e-3 + 1e-15)
    np.testing.assert_allclose(np.asarray(f.tau_v_eb), tv, atol=1e-15 + 1e-12 * scale)
    n, v = np.asarray(f.n), np.asarray(f.v12)
    w12 = np.asarray(s.mesh.omega1 - s.mesh.omega2)
    p_eb = (np.cross(np.broadcast_to(w12, n.shape), n) + np.asarray(f.k_v_eb)[..., None] * v
            + np.asarray(f.tau_v_eb)[..., None] * np.cross(n, v))
    np.testing.assert_allclose(p_eb, np.asarray(f.p), atol=1e-12 * np.max(np.abs(f.p)))


def test_k_II_equals_curvature_difference_of_conjugate_flanks(base):
    """Eigenfunction K_II = |p|^2/Phi_II vs kappa_gear(t) - kappa_pinion(t), the
    pinion flank built explicitly as the locus of contact points in its body."""
    _, _, s, _ = base
    uv = jnp.array([[0.0, 0.0], [2.0, 0.1], [-1.5, -0.15], [4.0, 0.2]])
    out = jax.jit(jax.vmap(lambda x: hk.conjugate_check(s, x)))(uv)
    np.testing.assert_allclose(np.asarray(out["k_gear"] - out["k_pinion"]),
                               np.asarray(out["k_II"]), rtol=1e-8)
    np.testing.assert_allclose(np.asarray(out["normal_dot"]), 1.0, atol=1e-12)
    assert np.max(np.asarray(out["point_gap"])) < 1e-10


def test_seed_designs_free_of_limits_and_table1(base):
    """The three [Eigenfunctions] designs (x_hm1 = 0.5): no meshing limit or curvature
    interference on the working convex flank; Table 1 trends and values.  (The
    blank is re-designed from ``StudySettings.cutter_radius``; ``inp.cutter_radius`` is
    not used by the model, so one compiled program serves all three.)"""
    prev = None
    for r0, row in SEED_TABLE1.items():
        inp = hk.study_blank_input(r0)
        _, f = hk.flank_fields(base[0], hk.StudySettings.make(r0), "convex", SHAPE)
        lim = hk.limit_report(f)
        assert not lim["meshing_limit"]["inside"]
        assert not lim["curvature_interference"]["inside"]
        assert np.all(np.asarray(f.r_eff) > 0)
        b = blank_geometry(inp)
        d1 = np.degrees(float(b.delta1))
        aD = np.degrees(float(b.alpha_nD))
        # agreement where the paper's table is self-consistent (docs/kinematics_study.md)
        assert abs(d1 - row[3]) < 0.4
        assert abs(aD - row[1]) < 0.35    # measured: 0.309, 0.133, 0.016 deg
        assert abs(aD + np.degrees(float(b.alpha_nC)) - (row[1] - row[2])) < 1e-9
        if prev is not None:  # trends of [Eigenfunctions]: larger cutter -> smaller delta1, alpha_D; wider b1
            assert d1 < prev[0] and aD < prev[1] and float(b.b1) > prev[2]
        prev = (d1, aD, float(b.b1))


def test_curvature_interference_detected_and_located():
    """x_hm1 = 0 (long gear addendum): Phi_II = 0 crosses the working flank near the
    gear tip; the reported zero curve is where the recomputed Phi_II vanishes."""
    inp = hk.study_blank_input(95.25, profile_shift=0.0)
    s, f = hk.flank_fields(inp, hk.StudySettings.make(95.25), "convex", SHAPE)
    lim = hk.limit_report(f)["curvature_interference"]
    assert lim["inside"] and 0 < lim["fraction"] < 0.5
    pts = np.array(lim["zero_curve_uv"])
    assert len(pts) >= SHAPE[1]
    assert np.all(pts[:, 0] < 0)          # tip side of the gear (u < 0)
    vals = jax.vmap(lambda x: hk.point_fields(s, x).phi_II)(jnp.asarray(pts))
    # linear interpolation on a 7x5 grid: within a few % of the field's range
    assert np.max(np.abs(np.asarray(vals))) < 0.05 * np.ptp(np.asarray(f.phi_II))
    assert not hk.limit_report(f)["meshing_limit"]["inside"]


def test_limit_report_on_a_known_field():
    F = namedtuple("F", "uv axial phi_I phi_II u_e")
    U, T = np.meshgrid(np.linspace(-1, 1, 5), np.linspace(-1, 1, 4), indexing="ij")
    uv = np.stack([U, T], -1)
    f = F(uv, uv * 2.0, 0.25 - U + 0.0 * T, 1.0 + U ** 2, -1.0 - 0 * U)
    rep = hk.limit_report(f)
    ml = rep["meshing_limit"]
    assert ml["inside"] and ml["fraction"] == pytest.approx(8 / 20)  # rows U = 0.5, 1
    np.testing.assert_allclose(np.array(ml["zero_curve_uv"])[:, 0], 0.25, atol=1e-15)
    np.testing.assert_allclose(np.array(ml["zero_curve_axial"])[:, 0], 0.5, atol=1e-15)
    assert not rep["curvature_interference"]["inside"]
    assert not rep["entrainment_reversal"]["inside"]


def test_gradients_vs_central_differences(base):
    """d(stat)/d(r0, blade angle, cutter shift) through both Newton solves vs central
    differences, 1e-6 relative (plain max/min: the extreme grid point does not
    change within +-h here -- verified away from ties)."""
    inp, st, _, _ = base
    g = hk.statistics_gradient(inp, st, shape=SHAPE)
    steps = {"cutter_radius": 1e-2, "blade_angle_delta": 1e-5, "cutter_shift": 1e-3}
    names = ("mean_abs_srr", "max_abs_srr", "mean_r_eff", "min_r_eff", "mean_abs_u_e")
    for field_name, h in steps.items():
        def at(d):
            kw = {"cutter_radius": st.cutter_radius, "blade_angle_delta": st.blade_angle_delta,
                  "cutter_shift": st.cutter_shift}
            kw[field_name] = kw[field_name] + d
            return hk.flank_statistics(inp, hk.StudySettings(**kw), shape=SHAPE)
        fp, fm = at(h), at(-h)
        for nm in names:
            fd = (float(fp[nm]) - float(fm[nm])) / (2 * h)
            ad = float(getattr(g[nm], field_name))
            assert abs(ad) > 1e-6
            assert abs(ad - fd) <= 1e-6 * abs(ad), (nm, field_name, ad, fd)


def test_vmap_sweep_and_its_derivative(base):
    inp, st, _, _ = base
    h = 1e-2
    r = np.array([95.25 - h, 95.25, 95.25 + h, 110.0])
    vals, ders = hk.cutter_radius_sweep(inp, r, shape=SHAPE)
    single = hk.flank_statistics(inp, st, shape=SHAPE)
    for nm in ("mean_abs_srr", "mean_r_eff", "mean_abs_u_e", "min_r_eff"):
        assert float(vals[nm][1]) == pytest.approx(float(single[nm]), rel=1e-9)  # Newton tol
        fd = (float(vals[nm][2]) - float(vals[nm][0])) / (2 * h)
        assert float(ders[nm][1]) == pytest.approx(fd, rel=1e-6)


def test_validation_and_strict():
    with pytest.raises(ValueError, match="cutter_radius_mm"):
        hk.StudySettings.make(5.0)
    with pytest.raises(ValueError, match="blade_angle_delta_deg"):
        hk.StudySettings.make(95.25, blade_angle_delta_deg=30.0)
    inp = hk.study_blank_input(95.25)
    with pytest.raises(ValueError, match="flank"):
        hk.flank_fields(inp, hk.StudySettings.make(95.25), "left")
    with pytest.raises(ValueError, match="shape"):
        hk.flank_fields(inp, hk.StudySettings.make(95.25), "convex", (1, 5))
    # no physical blank for a 2 mm cutter (docs/hypoid_blank.md): raises by default
    bad = hk.StudySettings(jnp.asarray(2.0), 0.0, 0.0)
    with pytest.raises(ConvergenceError):
        hk.flank_fields(inp, bad, "convex", SHAPE)
    s, f = hk.flank_fields(inp, bad, "convex", SHAPE, throw=False)
    assert float(s.blank["converged"]) == 0.0


def test_contact_line_is_level_set_of_the_roll_angle(base):
    """The instantaneous contact line on the gear flank is the set of points in
    contact at the same roll phi: its tangent (from grad phi of the Newton
    solution) must be the eigen direction n x p (p normal to the contact line)."""
    _, _, s, _ = base

    def check(uv):
        f = hk.point_fields(s, uv)
        dphi = jax.grad(lambda x: hk.point_fields(s, x).phi)(uv)
        duv = jnp.array([-dphi[1], dphi[0]])
        # along duv the roll is constant (dphi . duv = 0), so the contact point moves on
        # the flank at one instant: its tangent is the contact-line direction
        J = jax.jacfwd(lambda x: hk.point_fields(s, x).r)(uv)
        t = J @ duv
        t = t / jnp.linalg.norm(t)
        return jnp.linalg.norm(jnp.cross(t, f.contact_dir)), jnp.abs(jnp.dot(t, f.p))
    uv = jnp.array([[0.0, 0.0], [2.0, 0.1], [-1.5, -0.15], [4.0, 0.2]])
    cr, dp = jax.jit(jax.vmap(check))(uv)
    assert np.max(np.asarray(cr)) < 1e-9
    assert np.max(np.asarray(dp)) < 1e-9 * float(np.max(np.linalg.norm(np.asarray(base[3].p), axis=-1)))


# -- the notebook of this subject (tests/notebook_run.py: after this file's tests,
# whose compiled programs it reuses)


def test_cutter_radius_notebook_table_fields_and_derivatives(tmp_path):
    """The cutter-radius notebook (7 x 5: the programs of test_cutter_radius_study.py):
    the seed's Table 1 trends, the curvature-interference case found, the sweep's
    derivatives against central differences, and the field maps displayed (a plot
    module that forced the Agg backend on import hid them)."""
    nb, text = run_notebook("06_cutter_radius_study", tmp_path)
    rows = re.findall(r"^(\S+in)\s+[0-9.]+\s+([0-9.]+)\s+[0-9.]+\s+([0-9.]+)", text, re.M)
    d1 = [float(r[1]) for r in rows]
    assert len(rows) == 3 and d1[0] > d1[1] > d1[2], rows
    assert "curvature interference inside: True" in text
    worst = float(re.search(r"central difference ([0-9.e+-]+)$", text, re.M).group(1))
    assert worst < 1e-6
    assert images(nb) == 2
