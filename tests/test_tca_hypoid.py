"""TCA of face-milled spiral-bevel pairs: conjugacy of a pair cut by one crown gear,
localised contact from a cutter-radius mismatch (TE identically zero), the parabolic
TE of a modified roll against first-order theory, gradients against central
differences, the misalignment table, and the checks of the adapter (bad input, no
contact)."""

from dataclasses import replace
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.gears.hypoid.design_file import load_design
from gearjax.gears.hypoid import tca as th
from gearjax.tca.path import ARCSEC, NoContactError
from gearjax.tca.assembly import Misalignment

STEPS, HALF = 8, 1.5          # 25 grid positions, 1.5 pitches each side
MID = int(round(STEPS * HALF))


def _complementary(side):
    d = load_design("example:spiral_bevel_10x30")
    pair = th.pair_flanks(d, side)
    p_fl, g_fl = th.complementary_pinion(pair.gear, pair.pinion.blank)
    return th.prepare(replace(pair, pinion=p_fl, gear=g_fl))


@pytest.fixture(scope="module")
def conjugate():
    return _complementary("drive")


@pytest.fixture(scope="module")
def coast():
    """Coast side: pinion convex flank on gear concave flank, complementary settings."""
    return _complementary("coast")


def _modified(prep, d_radius, c2):
    pair = prep.pair
    p = th.with_point_radius(pair.pinion, d_radius, prep.x_ref[0])
    p = replace(p, machine=replace(p.machine, modified_roll_2c=jnp.asarray(c2, float)))
    return replace(pair, pinion=p)


@pytest.fixture(scope="module")
def point_tca(conjugate):
    f = gj.tca_function(conjugate, line_contact=False, steps_per_pitch=STEPS, half_pitches=HALF,
                        n_pairs=3, kinematics=False)
    return lambda pair, mis=Misalignment.zero(): f(pair, mis)


def test_crown_gear_complementary_pair_is_conjugate(conjugate):
    res = gj.run_tca(conjugate, line_contact=True, steps_per_pitch=STEPS, half_pitches=HALF,
                     n_pairs=3, kinematics=False, throw=False)
    p = res.path
    assert bool(np.all(np.asarray(p.converged)))
    te = np.abs(np.asarray(p.te)) / ARCSEC
    assert te.max() < 1e-6                                  # issue: below 1e-6 arcsec
    assert float(np.max(np.asarray(p.residual))) < 1e-10
    assert np.all(np.isinf(np.asarray(p.semi_major)))       # line contact
    # the contact line crosses the working flank during the cycle
    assert np.any(np.asarray(res.margin) > 1.0)


def test_cutter_radius_mismatch_localises_with_zero_te(conjugate, point_tca):
    """Blade cones tangent along the blade through the mean point: the pinion equals
    the conjugate one along the curve that blade generates, so the contact runs on
    that curve with TE identically zero and a finite contact ellipse."""
    res = point_tca(_modified(conjugate, 2.0, 0.0))
    p = res.path
    on = np.asarray(res.margin) >= 0
    assert on.sum() >= 6 and bool(np.all(np.asarray(p.converged)[on]))
    assert np.abs(np.asarray(p.te)[on]).max() / ARCSEC < 1e-6
    a, b = np.asarray(p.semi_major)[on], np.asarray(p.semi_minor)[on]
    assert np.all(np.isfinite(a)) and np.all(a > b) and np.all(b > 0.05)
    # bearing at the reference is the pinion's mean point (mid face, half blade height:
    # prepare's x_ref[:2]; measured 3e-13)
    assert abs(float(res.coords["xi1"][MID])) < 0.1
    np.testing.assert_allclose(np.asarray(p.uv1[MID]), conjugate.x_ref[:2], rtol=0, atol=1e-9)
    # the opposite mismatch (hollow pinion) has no such contact: the flanks cross
    bad = point_tca(_modified(conjugate, -2.0, 0.0))
    conv = np.asarray(bad.path.converged)
    assert not np.all(conv) or np.any(~np.isfinite(np.asarray(bad.path.semi_major)))


def test_modified_roll_gives_the_parabola_of_first_order_theory(conjugate, point_tca):
    """Modified roll phi = R_a (psi - C psi^2) turns each generated line of the pinion
    by -R_a C psi^2; in mesh psi = dphi1/R_a, so TE = (z1/z2)(C/R_a)(phi1 - phi1_0)^2
    to first order in C (gear angle)."""
    c2 = 0.02
    pair = _modified(conjugate, 2.0, c2)
    res = point_tca(pair)
    p = res.path
    assert bool(np.all(np.asarray(p.converged)))
    x = np.asarray(p.phi1) - float(p.phi1[MID])
    te = np.asarray(p.te) / ARCSEC
    coef = np.polyfit(x, te, 3)
    theory = (pair.z1 / pair.z2) * (0.5 * c2 / float(pair.pinion.machine.ratio_of_roll)) / ARCSEC
    assert abs(coef[1] / theory - 1.0) < 0.01
    fit = np.polyval(np.polyfit(x, te, 2), x)
    assert np.abs(fit - te).max() < 0.02 * np.ptp(te)        # a parabola over +-1.5 pitches
    _check_envelope(res, conjugate.drive, pair.z1)


def _check_envelope(res, drive, z1):
    """Multi-pair results of a parabolic TE against a second route.

    Pair k is pair 0 shifted by k pitches p = 2 pi/z1.  The least-squares quartic P of
    pair 0's TE (on-flank points) gives the envelope max_k P(phi - k p) (flank pushing
    for increasing phi1, ``drive``) or min_k (the other sense), the transfer points as
    the roots of P(phi) - P(phi + p) and P(phi - p) - P(phi) next to the vertex -+ p/2,
    and the contact ratio lies within one grid step of the number of on-flank grid
    steps.  The parabola must open away from the envelope's side (otherwise the far
    pairs would carry): that is the check of the side's sense of rotation.
    Measured (drive / coast): vertex -0.094 / +0.162 pitch from the reference; transfers
    1.8e-5 / 1.9e-5 pitch from the quartic crossings (tolerance 2e-4 pitch), envelope
    5.5e-7 / 2.6e-7 arcsec and p-t-p (18.89 / 18.26 arcsec) 3e-7 / 1.4e-7 arcsec from the
    shifted quartics (tolerance 1e-5 arcsec, the quartic's fit residual); contact ratio
    1.220 / 1.243 within [1.125, 1.375] (10 on-flank points)."""
    p, m = res.path, res.multi
    pitch = 2 * np.pi / z1
    phi = np.asarray(p.phi1) - float(p.phi1[MID])
    on = np.asarray(m.inside)[1]
    P = np.polynomial.Polynomial.fit(phi[on], np.asarray(p.te)[on], 4).convert()
    vertex = P.deriv().roots()
    vertex = vertex[np.abs(vertex.imag) < 1e-9].real
    vertex = vertex[np.argmin(np.abs(vertex))]
    assert P.deriv(2)(vertex) * (1 if drive else -1) < 0          # opens away

    def cross(shift, near):
        r = (P - P(np.polynomial.Polynomial([shift, 1.0]))).roots()
        r = r[np.abs(r.imag) < 1e-9].real
        return r[np.argmin(np.abs(r - near))]

    quartic = [cross(pitch, vertex - pitch / 2), cross(-pitch, vertex + pitch / 2)]
    tr = np.asarray(m.transfer_phi1) - float(p.phi1[MID])
    np.testing.assert_allclose(tr, quartic, rtol=0, atol=2e-4 * pitch)
    win = np.abs(np.arange(phi.size) - MID) <= STEPS // 2
    pk = np.stack([P(phi[win] - k * pitch) for k in (-1, 0, 1)])
    env = pk.max(axis=0) if drive else pk.min(axis=0)
    np.testing.assert_allclose(np.asarray(m.envelope)[win] / ARCSEC, env / ARCSEC, rtol=0,
                               atol=1e-5)
    assert abs(float(m.ptp) - np.ptp(env)) / ARCSEC < 1e-5
    n_on = int(np.sum(on))
    assert np.all(np.diff(np.nonzero(on)[0]) == 1)                  # one on-flank stretch
    assert (n_on - 1) / STEPS <= float(m.contact_ratio) <= (n_on + 1) / STEPS


def test_a_prepared_pair_is_labelled_by_its_flanks(conjugate, coast):
    """Drive side = pinion concave (blade sign -1) on gear convex: a hand-built or
    prepared pair's own flanks decide its side -- the result is labelled by them, and a
    side that contradicts them is a one-line ValueError before any work -- while a
    design file's ``side`` picks the flanks (drive by default)."""
    for prep, side, other in ((conjugate, "drive", "coast"), (coast, "coast", "drive")):
        with pytest.raises(ValueError, match=f"pinion flank of this pair is .*the {side} side"):
            gj.run_tca(prep, side=other)
        with pytest.raises(ValueError, match=f"the {side} side"):
            gj.run_tca(prep.pair, side=other)
        # the program of the line-contact TCA without kinematics, compiled by the tests above
        res = gj.run_tca(prep, line_contact=True, steps_per_pitch=STEPS, half_pitches=HALF,
                         n_pairs=3, kinematics=False, throw=False)
        assert res.side == side and res.family == "hypoid"
    d = load_design("example:spiral_bevel_10x30")
    fam = gj.tca.family_of(d).fam
    for side in ("drive", "coast"):
        prep, found = fam.setup(d, side)
        assert found == side
        assert int(prep.pair.pinion.cutter.sign) == (-1 if side == "drive" else 1)
    assert fam.setup(d, None)[1] == "drive"


@pytest.fixture(scope="module")
def coast_point_tca(coast):
    f = gj.tca_function(coast, line_contact=False, steps_per_pitch=STEPS, half_pitches=HALF,
                        n_pairs=3, kinematics=False)
    return lambda pair, mis=Misalignment.zero(): f(pair, mis)


def test_coast_complementary_pair_is_conjugate(conjugate, coast):
    """Coast flanks (pinion convex, gear concave) of the pair cut by one crown gear:
    conjugate, TE == 0 wherever the contact line is on both flanks (measured 1.4e-10
    arcsec; beyond the flank the analytic extension of the gear flank switches branch,
    s2 jumps, TE of hundreds of arc-seconds at points flagged off the flank).  The coast
    pinion flank faces the other way, so it pushes the gear for the opposite sense of
    pinion rotation (``drive`` flag of ``prepare`` opposite to the drive side's: the
    envelope is the other extremum) and its cutter blade is the other side."""
    assert coast.drive != conjugate.drive
    assert coast.pair.pinion.cutter.sign == -conjugate.pair.pinion.cutter.sign
    res = gj.run_tca(coast, line_contact=True, steps_per_pitch=STEPS, half_pitches=HALF,
                     n_pairs=3, kinematics=False, throw=False)
    p = res.path
    on = np.asarray(res.margin) >= 0.0
    assert on.sum() >= 6 and bool(np.all(np.asarray(p.converged)))
    assert np.abs(np.asarray(p.te)[on]).max() / ARCSEC < 1e-6
    assert float(np.max(np.asarray(p.residual))) < 1e-10
    assert np.all(np.isinf(np.asarray(p.semi_major)))
    assert np.any(np.asarray(res.margin) > 1.0)


def test_coast_localised_pair_zero_te_and_modified_roll_parabola(coast, coast_point_tca):
    """Coast pinion (convex) with a smaller blade point radius (dR = -2 mm, the convex
    flank made more convex lengthwise; cones tangent along the mean blade): point
    contact with TE identically zero (measured 9e-11 arcsec) and finite ellipses.  With
    modified roll 2C the pinion's generated lines turn by -R_a C psi^2 about its axis;
    a turn of the tooth is seen alike by both of its flanks, so the first-order TE is
    the drive side's (z1/z2)(C/R_a)(phi1 - phi1_0)^2 with the same sign convention.
    The coast flank pushes for the opposite sense of rotation (max envelope here), so it
    is eased off by 2C < 0: with 2C = -0.02 the parabola opens downwards and the pair
    nearest its vertex carries.  Measured: quadratic coefficient -218.15 arcsec/rad^2,
    0.34 % from theory -217.42 (tolerance 1 %, the drive side's 0.27 %); envelope,
    transfers and contact ratio as in _check_envelope."""
    res0 = coast_point_tca(_modified(coast, -2.0, 0.0))
    p0 = res0.path
    on = np.asarray(res0.margin) >= 0
    assert on.sum() >= 6 and bool(np.all(np.asarray(p0.converged)[on]))
    assert np.abs(np.asarray(p0.te)[on]).max() / ARCSEC < 1e-6
    a, b = np.asarray(p0.semi_major)[on], np.asarray(p0.semi_minor)[on]
    assert np.all(np.isfinite(a)) and np.all(a > b) and np.all(b > 0.05)
    assert abs(float(res0.coords["xi1"][MID])) < 0.1
    np.testing.assert_allclose(np.asarray(p0.uv1[MID]), coast.x_ref[:2], rtol=0, atol=1e-9)
    c2 = -0.02
    pair = _modified(coast, -2.0, c2)
    res = coast_point_tca(pair)
    p = res.path
    assert bool(np.all(np.asarray(p.converged)))
    x = np.asarray(p.phi1) - float(p.phi1[MID])
    te = np.asarray(p.te) / ARCSEC
    coef = np.polyfit(x, te, 3)
    theory = (pair.z1 / pair.z2) * (0.5 * c2 / float(pair.pinion.machine.ratio_of_roll)) / ARCSEC
    assert abs(coef[1] / theory - 1.0) < 0.01
    _check_envelope(res, coast.drive, pair.z1)


def _point_and_jacobian(surf, uv):
    return surf(uv), jax.jacfwd(surf)(uv)


def _rx_np(a):
    c, s_ = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s_], [0.0, s_, c]])


def test_misaligned_contact_points_coincide_in_the_fixed_frame(conjugate, point_tca):
    """dE 0.05, dP 0.1, dG -0.1 mm, dSigma 2e-4 rad on the localised drive pair: pinion
    and gear contact points, each from its own flank function and its own placement as
    defined in the tca_hypoid docstring, typed here (pinion Rz(phi1) r1 + dP e_z; gear
    (E + dE) e_x + dG R e_z + R Rz(phi2) r2 with R = Rx(dSigma) Rx(-h Sigma)), coincide
    and the normals (from jacfwd of the flanks) are collinear (measured 3e-14 mm,
    2e-15; tolerance 1e-9); the reported point is that point (3e-14 mm)."""
    pair = _modified(conjugate, 2.0, 0.02)
    vals = (0.05, 0.1, -0.1, 2e-4)
    res = point_tca(pair, Misalignment(*(jnp.asarray(v, float) for v in vals)))
    p = res.path
    r1 = jax.jit(partial(_point_and_jacobian, th.flank_function(pair.pinion, pair.pinion_crossing)))
    r2 = jax.jit(partial(_point_and_jacobian, th.flank_function(pair.gear, pair.gear_crossing)))
    R = _rx_np(vals[3]) @ _rx_np(-pair.hand * float(pair.shaft_angle))
    centre = np.array([float(pair.offset) + vals[0], 0.0, 0.0]) + vals[2] * R[:, 2]

    def rz(a):
        c, s_ = np.cos(a), np.sin(a)
        return np.array([[c, -s_, 0.0], [s_, c, 0.0], [0.0, 0.0, 1.0]])

    def pt_n(surf, uv):
        q, J = surf(jnp.asarray(uv))
        n = np.cross(np.asarray(J)[:, 0], np.asarray(J)[:, 1])
        return np.asarray(q), n / np.linalg.norm(n)

    on = np.nonzero(np.asarray(res.margin) >= 0.0)[0]
    assert on.size >= 6
    for i in (on[0], MID, on[-1]):
        q1, m1 = pt_n(r1, p.uv1[i])
        q2, m2 = pt_n(r2, p.uv2[i])
        R1, R2 = rz(float(p.phi1[i])), R @ rz(float(p.phi2[i]))
        p1 = R1 @ q1 + np.array([0.0, 0.0, vals[1]])
        p2 = centre + R2 @ q2
        np.testing.assert_allclose(p1, p2, rtol=0, atol=1e-9)
        assert np.linalg.norm(np.cross(R1 @ m1, R2 @ m2)) < 1e-9
        np.testing.assert_allclose(np.asarray(p.point[i]), p1, rtol=0, atol=1e-9)
    # the grid is centred where the pinion's mean point meets the gear flank of the
    # *misaligned* pair (th.reference_contact), not of the aligned one
    ref = jax.jit(th.reference_contact)
    mis = Misalignment(*(jnp.asarray(v, float) for v in vals))
    x0, ph0 = jnp.asarray(conjugate.x_ref), jnp.asarray(conjugate.phi1_ref)
    phi_mis = float(ref(pair, mis, x0, ph0)[1])
    phi_aligned = float(ref(pair, Misalignment.zero(), x0, ph0)[1])
    assert abs(phi_mis - phi_aligned) > 1e-5
    assert abs(float(p.phi1[MID]) - phi_mis) < 1e-12


def test_contact_velocity_from_curvatures_equals_the_implicit_derivative(conjugate,
                                                                         point_tca):
    """The TCA's kinematics (contact_kinematics) take the contact point's velocity and
    the gear speed at a point contact from the flanks' curvatures
    (gearjax.tca.result.contact_velocity: the equation of meshing, and Rodrigues'
    formula on both flanks).  Second route: the implicit derivative of the nested
    contact equations ``dx/dphi1 = -F_x^-1 F_phi1`` (path_kinematics), on the
    misaligned localised drive pair (measured 2e-13 of the
    largest velocity, 3e-15 in the gear speed; tolerances 1e-10).  A wrong sign of
    either rotation, of the normal's turn or of ``W2 v12``, or the two flanks' curvatures
    swapped, moves every point.  (The route itself -- curvatures, not the Jacobian -- is
    held by the cost guard: the lowered TCA's flops.)"""
    from gearjax.gears.hypoid.contact_kinematics import path_kinematics
    from gearjax.tca.result import contact_kinematics
    pair = _modified(conjugate, 2.0, 0.02)
    mis = Misalignment(*(jnp.asarray(v, float) for v in (0.05, 0.1, -0.1, 2e-4)))
    p = point_tca(pair, mis).path
    ref = path_kinematics(pair, p, mis)
    r1 = th.flank_function(pair.pinion, pair.pinion_crossing)
    r2 = th.flank_function(pair.gear, pair.gear_crossing)
    # the TCA's own kinematics (what run_tca reports), point contact: the curvature route
    kin = jax.jit(lambda path: contact_kinematics(r1, r2, th.hypoid_assembly(pair), mis, path,
                                                  line_contact=False))(p)
    vc, m21 = kin.v_contact, kin.gear_ratio
    ok = np.asarray(p.converged) & (np.asarray(p.edge_kind) < 0)
    assert ok.sum() >= 10
    v_ref = np.asarray(ref.v_contact)[ok]
    np.testing.assert_allclose(np.asarray(vc)[ok], v_ref, rtol=0,
                               atol=1e-10 * np.max(np.abs(v_ref)))
    np.testing.assert_allclose(np.asarray(m21)[ok], np.asarray(ref.gear_ratio)[ok], rtol=1e-10)
    # the contact moves over both flanks (not a degenerate check)
    assert np.min(np.linalg.norm(v_ref - np.cross([0.0, 0.0, 1.0], np.asarray(p.point)[ok]),
                                 axis=1)) > 1.0


def test_augmented_contact_system_equals_the_nested_solve(conjugate, point_tca):
    """The path is solved as one system in (x, psi1, psi2) with the two meshing
    equations beside the contact equations.  Second route: Newton on the nested
    residual (contact_equations: each flank point from its own envelope solve), started
    0.01 away from the path's solution, reaches the same (u1, v1, u2, v2, phi2) (measured
    1e-13; tolerance 1e-9), and the path's psi are the flanks' envelope solves at the
    contact (measured 1e-15 rad)."""
    from gearjax.newton import newton_solve
    from gearjax.tca.path import contact_equations
    pair = _modified(conjugate, 2.0, 0.02)
    mis = Misalignment(*(jnp.asarray(v, float) for v in (0.05, 0.1, -0.1, 2e-4)))
    p = point_tca(pair, mis).path
    r1 = th.flank_function(pair.pinion, pair.pinion_crossing)
    r2 = th.flank_function(pair.gear, pair.gear_crossing)
    F, _, _ = contact_equations(r1, r2, th.hypoid_assembly(pair), mis, False)
    solve = jax.jit(lambda x0, ph1: newton_solve(F, x0, ph1, tol=1e-12, max_steps=40))
    psi = jax.jit(lambda uv1, uv2: (r1.solve(uv1).x, r2.solve(uv2).x))
    for i in (MID - 6, MID, MID + 6):
        x = np.concatenate([np.asarray(p.uv1[i]), np.asarray(p.uv2[i]), [float(p.phi2[i])]])
        sol = solve(jnp.asarray(x + 0.01), p.phi1[i])
        assert bool(sol.converged)
        np.testing.assert_allclose(np.asarray(sol.x), x, rtol=0, atol=1e-9)
        q1, q2 = psi(p.uv1[i], p.uv2[i])
        np.testing.assert_allclose([float(p.psi1[i]), float(p.psi2[i])],
                                   [float(q1), float(q2)], rtol=0, atol=1e-10)


def test_gradients_match_central_differences(conjugate, point_tca):
    """d(TE ptp, bearing position, ellipse) / d(pinion settings, misalignments)."""
    def summary(v):
        pair = _modified(conjugate, 2.0 + v[0], 0.02 + v[1])
        mis = Misalignment(v[2], v[3], v[4], v[5])
        return th.tca_summary(pair, point_tca(pair, mis))

    idx = np.array([0, 2, 3, 6])          # ptp, xi1, h1, semi_major
    v0 = jnp.zeros(6)
    J = np.asarray(jax.jit(jax.jacfwd(summary))(v0))[idx]
    f = summary                       # eager glue around the compiled TCA
    for k, h in enumerate([1e-3, 1e-4, 1e-3, 1e-3, 1e-3, 1e-5]):
        e = np.zeros(6)
        e[k] = h
        # 4th-order central difference
        fd = (-np.asarray(f(v0 + 2 * e)) + 8 * np.asarray(f(v0 + e)) - 8 * np.asarray(f(v0 - e))
              + np.asarray(f(v0 - 2 * e)))[idx] / (12 * h)
        scale = np.maximum(np.abs(J[:, k]), 1e-3 * np.abs(np.asarray(f(v0))[idx]) + 1e-12)
        err = np.abs(fd - J[:, k]) / scale
        np.testing.assert_array_less(err, 1e-5, err_msg=f"variable {k}")
    assert np.all(np.isfinite(J))


def test_bad_input_and_no_contact(conjugate):
    with pytest.raises(ValueError, match="steps_per_pitch"):
        gj.run_tca(conjugate, kinematics=False, steps_per_pitch=1)
    with pytest.raises(ValueError, match="n_pairs"):
        gj.run_tca(conjugate, kinematics=False, n_pairs=4)
    with pytest.raises(ValueError, match="side"):
        th.pair_flanks(load_design("example:spiral_bevel_10x30"), "reverse")
    # pinion turned inside out (the other blade side): its flank cannot meet the gear's
    pair = conjugate.pair
    wrong = replace(pair, pinion=replace(pair.pinion, cutter=replace(pair.pinion.cutter,
                                                                     sign=-pair.pinion.cutter.sign)))
    with pytest.raises(NoContactError):
        th.prepare(wrong)


@pytest.mark.parametrize("example", ["hft_8x43_synthesised", "hypoid_iso_10x41"])
def test_mean_points_at_mid_face_and_the_gear_at_mid_depth(example):
    """The mean points that seed the reference search (``mean_points``): at mid face
    (``|xi| < 0.1``, the blade point half-way to the tip of the one on the face cone at
    xi = 0) and, for the gear -- whose blade runs from its root cone (the cutter's tips)
    to its face cone -- half-way between the two cones (closed form: equal gaps).  Both
    members of offset pairs, each in its own frame (the crossing points differ by 1.0
    and 5.9 mm here).  Planted bug caught: a member's mean point computed with the other
    member's crossing point (the gear's gaps 4.3/6.3 and 10.8/-0.5 mm)."""
    from gearjax.gears.hypoid.pair import flank_coordinates, mean_points, pair_flanks
    d = gj.load_design(gj.example_path(example))
    for side in ("drive", "coast"):
        p = pair_flanks(d, side)
        (_, q1, _), (_, q2, _) = mean_points(p)
        for fl, crossing, q in ((p.pinion, p.pinion_crossing, q1), (p.gear, p.gear_crossing, q2)):
            xi, above_root, below_tip = (float(v) for v in flank_coordinates(fl, crossing, q))
            assert abs(xi) < 0.1, (side, xi)
        assert abs(above_root - below_tip) < 0.02 * (above_root + below_tip), (
            side, above_root, below_tip)


def _sheet(surf, uv):
    """Independent route to the sheet of a generated flank point: the sign of
    (E_u x E_v) . n, E(uv) = family(uv, psi(uv)) with psi_uv = -f_uv/f_psi from the
    meshing function f (Litvin & Fuentes, 2nd ed., §6.3); it changes sign at the edge
    of regression.  Traceable (``jax.vmap`` over ``uv``)."""
    from gearjax.surfaces import _tool_at, meshing_function
    psi = surf.solve(uv).x
    P_uv, P_psi = jax.jacfwd(surf.family, argnums=(0, 1))(uv, psi)
    f_uv, f_psi = jax.jacfwd(lambda a, b: meshing_function(surf.family, a, b, surf.normal),
                             argnums=(0, 1))(uv, psi)
    E = P_uv - jnp.outer(P_psi, f_uv / f_psi)
    return jnp.dot(jnp.cross(E[:, 0], E[:, 1]), _tool_at(surf.family, uv, psi, surf.normal)[1])


def test_edge_points_beyond_the_blade_tip_are_off_the_flank():
    """The far corner (docs/tca.md, "A far corner branch"): on the kept
    end design of a hypoid study, the pinion's tip/heel corner candidate converged at
    uv = (theta, s) = (-0.7442, -3.9319) -- 3.9 mm beyond the blade tip, on the second
    sheet of the generated flank (the sheet sign opposite to that of the reference
    contact, by the independent Jacobian route above), yet on the tip (tip margin ~0),
    at the heel (face margin ~0) and 11.6 mm above the fillet: every height and
    face-width boundary held, and the TCA took it (TE p-t-p 2852 arcsec on the default
    grid instead of 8.4).  The blade's own extent bounds the root side of an edge point
    (margin s); a real flank point keeps its margins."""
    from gearjax.gears.hypoid.pair import flank_function, hypoid_face_ends
    from pathlib import Path
    d = load_design(str(Path(__file__).resolve().parents[1] / "experiments" / "results"
                        / "hypoid_far_corner" / "hypoid_far_corner.toml"))
    pair = th.pair_flanks(d, "drive")
    surf = flank_function(pair.pinion, pair.pinion_crossing)
    parts = hypoid_face_ends(pair)[0]
    far, ref = jnp.array([-0.7442, -3.9319]), jnp.array([-0.5971, 5.4383])
    assert _sheet(surf, far) * _sheet(surf, ref) < 0
    for uv, s_bounds in ((far, True), (ref, False)):
        q = surf(uv)[None]
        face, tip, root = (float(a[0]) for a in parts(q, q, uv[None], uv[None])[:3])
        face_h, tip_h, root_h = (float(a[0]) for a in parts(q, q)[:3])   # heights only
        assert (face, tip) == (face_h, tip_h)
        if s_bounds:
            assert abs(face) < 0.01 and abs(tip) < 0.01 and root_h > 10.0
            assert root == pytest.approx(float(uv[1]), abs=1e-12)
        else:
            assert min(face, tip, root) > 3.0 and root == root_h
