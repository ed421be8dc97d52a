"""VH-CATT cylindrical gears ([VH-CATT]): generated flanks against closed forms, the
point-contact TCA of the seed's pair, the seed's Hertz formula, design files.

Independent references: the textbook involute (polar angle of the involute of the
middle section, tip thickness), the circle of the cutter in the pitch plane (the
developed trace), the involute line of action of the middle section (path of the
aligned pair), the transverse contact ratio, Hertz's ellipse by Timoshenko's
coefficients m_a, m_b from SciPy's complete elliptic integrals.
"""

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cost_guard import check_cost
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

import gearjax as gj
from gearjax.gears.vh_catt import geometry as G
from gearjax.gears.vh_catt.design_file import design_from_dict, flank_sigma

M, ALPHA, B, RT, E_OFF = 4.0, math.radians(20.0), 28.0, 400.0, 3.0


def inv(a):
    return math.tan(a) - a


@pytest.fixture(scope="module")
def design():
    return gj.load_design("example:vh_catt_17x23")


@pytest.fixture(scope="module")
def pair(design):
    return design.pair


@pytest.fixture(scope="module")
def sections(pair):
    """Flank points of both members and flanks at blade coordinates u in sections z
    (one compiled program)."""
    us = jnp.linspace(-3.0, 3.5, 9)
    zs = jnp.array([0.0, 7.0, 14.0])
    out = {}
    for mem in ("pinion", "gear"):
        f = jax.jit(jax.vmap(jax.vmap(lambda s, u, z: G.section_point(pair, mem, s, u, z),
                                      (None, 0, None)), (None, None, 0)))
        for s in (1.0, -1.0):
            out[mem, s] = np.asarray(f(s, us, zs))     # (3 sections, 9, 3)
    return out


def test_middle_section_is_the_involute(pair, sections):
    """z = 0: every generated point lies on the involute of base radius r cos(alpha) of
    a tooth of thickness pi m/2 (closed form, 1e-9 mm along the circle)."""
    for (mem, s), P in sections.items():
        z = pair.teeth(mem)
        r = 0.5 * z * M
        rb = r * math.cos(ALPHA)
        Q = P[0]
        assert np.all(np.abs(Q[:, 2]) < 1e-12)
        R = np.hypot(Q[:, 0], Q[:, 1])
        ok = R > rb * (1 + 1e-9)
        phi = np.arctan2(Q[ok, 1], Q[ok, 0])
        ref = np.array([math.pi / 2 - s * (math.pi * M / 2 / (2 * r) + inv(ALPHA)
                                           - inv(math.acos(rb / x))) for x in R[ok]])
        assert ok.sum() >= 6
        assert np.max(np.abs(R[ok] * (phi - ref))) < 1e-9, (mem, s)


def test_other_sections_are_not_involutes(pair, sections):
    """Off the middle the sections are not involutes: after the best rotation about the
    axis (least squares) a shape deviation from the involute is left, growing about as
    z^2 (the numbers of docs/vh_catt.md)."""
    devs = []
    r, rb = 0.5 * 17 * M, 0.5 * 17 * M * math.cos(ALPHA)
    for zi in (1, 2):
        P = sections["pinion", -1.0][zi]
        R = np.hypot(P[:, 0], P[:, 1])
        ok = R > rb + 0.05
        ref = np.array([math.pi / 2 + (math.pi * M / 2 / (2 * r) + inv(ALPHA)
                                       - inv(math.acos(rb / x))) for x in R[ok]])
        dphi = np.arctan2(P[ok, 1], P[ok, 0]) - ref
        delta = np.sum(R[ok] ** 2 * dphi) / np.sum(R[ok] ** 2)
        devs.append(np.max(np.abs(R[ok] * (dphi - delta))))
    assert devs[0] > 1e-5 and 3.0 < devs[1] / devs[0] < 5.0


def test_pitch_trace_is_the_cutter_circle(pair):
    """The flank's trace on the pitch cylinder, developed, is the circle of radius
    R_T -+ (pi m/4 + e) about the head axis (x_c, 0) of the pitch plane (1e-9 mm)."""
    w = math.pi * M / 2
    zs = jnp.linspace(-B / 2, B / 2, 5)
    for mem, h in (("pinion", 1.0), ("gear", -1.0)):
        for s in (1.0, -1.0):
            pts, res = jax.jit(jax.vmap(lambda z: G.pitch_trace_point(pair, mem, s, z)))(zs)
            rho0 = RT - h * s * (w / 2 + E_OFF)
            xc = s * w / 2 - h * rho0
            d = np.hypot(np.asarray(pts[:, 0]) - xc, np.asarray(pts[:, 1])) - rho0
            assert np.max(np.abs(d)) < 1e-9 and np.max(np.asarray(res)) < 1e-9
            # convex flanks bulge away from the tooth: pinion +1 and gear -1
            assert flank_sigma(mem, "convex") == (1 if mem == "pinion" else -1)


def test_tooth_form_checks(pair):
    """Top land of the middle section = the involute tip thickness
    2 r_a (s/(2r) + inv alpha - inv alpha_a); the ends are thinner (variable
    thickness); the 17-tooth pinion is undercut (z < 2/sin^2 alpha = 17.1) up to its
    base circle, below the start of active profile."""
    form = G.tooth_form(pair)
    for mem, z in (("pinion", 17), ("gear", 23)):
        r, ra = 0.5 * z * M, 0.5 * z * M + M
        rb = r * math.cos(ALPHA)
        sa = 2 * ra * (math.pi * M / 2 / (2 * r) + inv(ALPHA) - inv(math.acos(rb / ra)))
        land = form[mem]["top_land_mm"]
        assert abs(land[1] - sa) < 1e-9
        assert land[0] < land[1] and abs(land[0] - land[2]) < 1e-12
    assert form["pinion"]["undercut"] and not form["gear"]["undercut"]
    rb1 = 34.0 * math.cos(ALPHA)
    assert abs(form["pinion"]["undercut_radius_mm"] - rb1) < 1e-6
    assert not form["pinion"]["active_undercut"]


def test_closed_form_envelope_is_the_generated_flank(pair, sections):
    """The closed-form envelope of the tooth-form check (NumPy, Willis' condition on
    the rack) gives the points of the autodiff envelope (``GeneratedSurface`` Newton
    solve of ``n . dr_w/dpsi = 0``) and of the plain-Newton ``envelope_point``,
    1e-9 mm, for both members and flanks, in and off the middle section (undercut
    pinion rows included); its meshing residual is at the rounding level."""
    us, zs = np.linspace(-3.0, 3.5, 9), np.array([0.0, 7.0, 14.0])
    pn = jax.tree_util.tree_map(np.asarray, pair)
    env = jax.jit(jax.vmap(G.envelope_point, (None, 0, 0)))
    for (mem, s), P in sections.items():
        k = G.tool_data(pn.module, pn.pressure_angle, pn.cutter_radius(mem), pn.teeth(mem),
                        G.HANDS[mem], s, pn.blade_offset, xp=np)
        q, res = G.envelope_point_np(k, us[None, :], zs[:, None])
        assert q.shape == (3, 9, 3) and np.max(res) < 1e-11
        assert np.max(np.abs(q - P)) < 1e-9, (mem, s)
        kj = G.tool_data(pair.module, pair.pressure_angle, pair.cutter_radius(mem),
                         pair.teeth(mem), G.HANDS[mem], s, pair.blade_offset)
        qj, rj = env(kj, jnp.asarray(us[::4]), jnp.full(3, 7.0))
        assert np.max(np.abs(np.asarray(qj) - P[1, ::4])) < 1e-9 and np.max(rj) < 1e-9


def test_tooth_form_refusals_name_the_member():
    """The form check runs in ``create`` (and so on every design-file load): teeth
    pointed at the face ends are refused with a ValueError naming z2 (here a small
    cutter narrows the end sections: the middle section's top land is still the
    positive involute tip thickness), ``check_form=False`` skips it."""
    args = (13, 14, 2.0, 14.5, 30.0, 60.0, 45.0)
    p = G.VHCattPair.create(*args, blade_offset=10.0, check_form=False)
    form = G.tooth_form(p)
    r, ra, al = 14.0, 16.0, math.radians(14.5)
    rb = r * math.cos(al)
    sa = 2 * ra * (math.pi * 2.0 / 2 / (2 * r) + inv(al) - inv(math.acos(rb / ra)))
    assert abs(form["gear"]["top_land_mm"][1] - sa) < 1e-9 and sa > 1.0
    assert form["gear"]["min_top_land_mm"] < 0.0 < form["pinion"]["min_top_land_mm"]
    with pytest.raises(ValueError, match="z2: pointed gear teeth"):
        G.VHCattPair.create(*args, blade_offset=10.0)
    with pytest.raises(ValueError, match=r"\[pair\] z2: pointed gear teeth"):
        design_from_dict(_data(z1=13, z2=14, module_mm=2.0, pressure_angle_deg=14.5,
                               face_width_mm=30.0, cutter_radius1_mm=60.0,
                               cutter_radius2_mm=45.0, blade_offset_mm=10.0))
    # undercut flag at the textbook limit of rack generation z < 2/sin^2(alpha) = 17.1
    und = {z: G.tooth_form(G.VHCattPair.create(z, 40, M, 20.0, B, RT, check_form=False))
           ["pinion"]["undercut"] for z in (17, 18)}
    assert und == {17: True, 18: False}


def test_tip_interference_is_refused_at_the_textbook_limit():
    """Involute interference: the mating tip must not pass the interference point T1
    (tangency of the line of action with the pinion base circle), i.e. the path of
    contact must start at rho_A = a sin(alpha) - sqrt(ra2^2 - rb2^2) >= 0 (computed here
    from the textbook formula).  For z2 = 40, m 4, 20 deg: rho_A = -0.54 mm at z1 = 14,
    +0.14 mm at z1 = 15.  The start-of-active-profile radius sqrt(rb^2 + rho_A^2) is
    symmetric in rho_A, so a check on that radius alone accepts z1 = 8 (rho_A = -4.6)."""
    al = math.radians(20.0)
    for z1 in (8, 13, 14, 15, 16):
        rb2, ra2 = 80.0 * math.cos(al), 84.0
        rho_A = (2.0 * z1 + 80.0) * math.sin(al) - math.sqrt(ra2 ** 2 - rb2 ** 2)
        p = G.VHCattPair.create(z1, 40, 4.0, 20.0, B, RT, check_form=False)
        form = G.tooth_form(p)["pinion"]
        assert abs(form["start_active_roll_mm"] - rho_A) < 1e-9
        assert form["tip_interference"] == (rho_A < 0.0)
        if rho_A < 0.0:
            with pytest.raises(ValueError, match=rf"z1 = {z1}: the gear tip passes"):
                G.VHCattPair.create(z1, 40, 4.0, 20.0, B, RT)
        else:
            G.VHCattPair.create(z1, 40, 4.0, 20.0, B, RT)
    # the gear side: a large pinion tip against a small gear (z2 = 14, z1 = 40)
    with pytest.raises(ValueError, match=r"z2 = 14: the pinion tip passes the gear's"):
        G.VHCattPair.create(40, 14, 4.0, 20.0, B, RT)


@pytest.fixture(scope="module")
def tca_runs(pair):
    opts = dict(kinematics=False, face_ends=False)
    return {"drive": gj.run_tca(pair, side="drive", **opts),
            "coast": gj.run_tca(pair, side="coast", **opts),
            "tilt": gj.run_tca(pair, gj.Misalignment.create(dSigma_deg=0.02), **opts)}


def test_summary_is_the_result_at_the_reference(tca_runs):
    """The summary the sensitivity table differentiates (``tca_summary``, keys
    ``SUMMARY_KEYS``) is read off the result by name at the reference grid point (a
    swapped entry would put the wrong quantity into every sensitivity)."""
    from gearjax.gears.vh_catt.tca import SUMMARY_KEYS, tca_summary
    for side in ("drive", "tilt"):
        res = tca_runs[side]
        p = res.path
        mid = np.asarray(p.phi1).size // 2
        got = np.asarray(tca_summary(p, res.multi))
        want = {"ptp_rad": res.multi.ptp, "phi2_ref_rad": p.phi2[mid],
                "axial1_mm": p.axial1[mid], "radial1_mm": p.radial1[mid],
                "axial2_mm": p.axial2[mid], "radial2_mm": p.radial2[mid],
                "semi_major_mm": p.semi_major[mid]}
        for k, v in zip(SUMMARY_KEYS, got):
            assert v == float(want[k]), (side, k)
        assert got[3] != got[5]                       # pinion and gear radii differ


def test_boundary_margins_are_the_form_and_tip_circles(pair, tca_runs):
    """The six boundary margins of the TCA (coords["margin_parts"]) against the blank
    read directly: tip ``r_a - r``, form circle ``r - r_F`` (on the working branch of
    the envelope) and face ``b/2 - |z|`` of each member at its own contact radius.
    (A gear form-circle margin computed with the pinion's radii survived the blind
    review: on the aligned pair the gear root never bounds the path.)"""
    geo = G.pair_geometry(pair)
    for side in ("drive", "tilt"):
        res = tca_runs[side]
        p = res.path
        parts = np.asarray(res.coords["margin_parts"])
        ok = np.asarray(p.converged)
        for k, (radial, axial, uv, ra, rf, rp) in enumerate((
                (p.radial1, p.axial1, p.uv1, geo["ra1"], geo["rf1"], geo["r1"]),
                (p.radial2, p.axial2, p.uv2, geo["ra2"], geo["rf2"], geo["r2"]))):
            R, z, u = np.asarray(radial), np.asarray(axial), np.asarray(uv)[:, 0]
            alpha = float(pair.pressure_angle)
            working = ok & (u >= -float(rp) * np.sin(alpha) ** 2 / np.cos(alpha))
            assert working.sum() >= 10
            np.testing.assert_allclose(parts[3 * k][ok], (float(ra) - R)[ok], atol=1e-12)
            np.testing.assert_allclose(parts[3 * k + 1][working], (R - float(rf))[working],
                                       atol=1e-12)
            np.testing.assert_allclose(parts[3 * k + 2][ok],
                                       (0.5 * float(pair.face_width) - np.abs(z))[ok],
                                       atol=1e-12)


def test_cost_of_the_vh_catt_tca(tca_runs):
    """Cost guard (tests/cost_guard.py): Newton work of the surface-contact VH-CATT TCA
    on both sides against the recorded baseline."""
    for side in ("drive", "coast"):
        check_cost(f"tca_vh_catt_{side}_surface",
                   newton_work=int(tca_runs[side].path.newton_work))


def test_aligned_tca_is_the_middle_section_involute_mesh(pair, tca_runs):
    """Aligned: the pair touches in the middle section along the involute line of
    action, TE = 0, contact ratio = eps_alpha (closed form); both sides."""
    geo = {k: float(v) for k, v in G.pair_geometry(pair).items() if np.ndim(v) == 0}
    rb1 = 34.0 * math.cos(ALPHA)
    p_b = math.pi * M * math.cos(ALPHA)
    g = 80.0 * math.sin(ALPHA)
    eps = (math.sqrt(38 ** 2 - rb1 ** 2) - (g - math.sqrt(50 ** 2 - (46 * math.cos(ALPHA)) ** 2))) / p_b
    assert abs(geo["eps_alpha"] - eps) < 1e-12
    for side in ("drive", "coast"):
        r = tca_runs[side]
        on = np.asarray(r.on_flank)
        assert on.sum() > 20 and all(r.flags()[k] for k in ("converged", "reference_on_flank"))
        assert np.max(np.abs(np.asarray(r.te)[on])) / gj.ARCSEC < 1e-6
        assert np.max(np.abs(np.asarray(r.path.axial1)[on])) < 1e-9
        # involute roll on the line of action: rho1 = rho_P +- rb1 (phi1 - phi1_P) (the
        # drive flank rolls towards the pinion tip as phi1 grows, the coast flank back)
        phi = np.asarray(r.phi1)
        mid = phi.shape[0] // 2
        rho = geo["rho_P"] + (1.0 if side == "drive" else -1.0) * rb1 * (phi - phi[mid])
        rad = np.hypot(rb1, rho)
        assert np.max(np.abs(np.asarray(r.path.radial1)[on] - rad[on])) < 1e-8
        # contact ratio from the boundary crossings (linear interpolation on the grid)
        assert abs(float(r.contact_ratio) - eps) < 2e-4


def test_ellipse_of_the_mismatch(pair, tca_runs):
    """The long axis of the unloaded ellipse follows the trace mismatch: at the pitch
    point it lies along the face width, and its length is of the order of
    sqrt(2 delta / (cos(alpha)(1/rho_convex - 1/rho_concave))) (the normal curvature
    of the trace circles; exact value from the generated flanks)."""
    r = tca_runs["drive"]
    mid = r.phi1.shape[0] // 2
    w = math.pi * M / 2
    lam = math.cos(ALPHA) * (1 / (RT - w / 2 - E_OFF) - 1 / (RT + w / 2 + E_OFF))
    a_est = math.sqrt(2 * 0.00632 / lam)
    a = float(r.path.semi_major[mid])
    assert abs(a - a_est) < 0.02 * a_est
    assert abs(float(np.asarray(r.path.major_dir)[mid, 2])) > 0.999


def test_misaligned_contact_moves_off_the_middle(tca_runs):
    """A shaft-angle error moves the point contact along the face and, off the middle
    section, the sections are not conjugate: TE appears (differences > 0)."""
    r = tca_runs["tilt"]
    on = np.asarray(r.on_flank)
    assert r.flags()["converged"]
    assert np.min(np.abs(np.asarray(r.path.axial1)[on])) > 1.0
    assert float(r.ptp) / gj.ARCSEC > 0.05


def test_bearing_reach_is_the_ellipse_end_on_the_face_axis(tca_runs):
    """The study quantity ``bearing_reach_mm`` (|z| + semi-major at the reference) is
    how far the ellipse's farther end lies from the face middle: the contact point's
    axial coordinate (fixed frame z, the pinion axis of the aligned pair) moved by the
    semi-major along the major axis, which lies along the face (0.02 deg of tilt changes
    the projection by less than 1e-7 relative).  Under the 0.02 deg shaft-angle error
    the packaged pair's bearing reaches past the face end b/2 = 14 mm (17.78 mm,
    docs/vh_catt.md section 6); aligned it stays inside."""
    from gearjax.studies.quantities import QUANTITIES
    reach = {}
    for case in ("drive", "tilt"):
        r = tca_runs[case]
        mid = r.phi1.shape[0] // 2
        a = float(r.path.semi_major[mid])
        z = float(np.asarray(r.path.point)[mid, 2])
        dz = a * float(np.asarray(r.path.major_dir)[mid, 2])
        ends = max(abs(z + dz), abs(z - dz))
        reach[case] = float(QUANTITIES["bearing_reach_mm"].fn(r, None, None, None))
        assert reach[case] == pytest.approx(ends, abs=1e-3), case
    assert reach["tilt"] == pytest.approx(17.78, abs=0.01)
    assert reach["drive"] < 0.5 * B < reach["tilt"]
    # a bearing pushed the other way (toward the other face end) reaches as far
    r = tca_runs["tilt"]
    mirrored = dataclasses.replace(r, path=r.path._replace(axial1=-r.path.axial1))
    assert float(QUANTITIES["bearing_reach_mm"].fn(mirrored, None, None, None)) == reach["tilt"]


def test_bearing_pushed_past_either_face_end_leaves_the_flank(pair, tca_runs):
    """The pair is symmetric about its middle section: a misalignment (dSigma, dP)
    and its mirror (-dSigma, -dP) put the contact at mirror-image axial positions (to
    1e-9 mm).  With dSigma = 0.663 deg and the pinion moved 5 mm along its axis the
    bearing runs from the middle past one face end, the pinion's and the gear's axial
    positions differing by dP: where the pinion point lies beyond its face end and the
    gear point inside the gear's, the contact is off the flank -- a point is on the flank
    only inside both faces, at the heel (+) and at the toe (-).  Same compiled program
    as ``tca_runs`` (the misalignment is traced).  Planted bug caught: a face-width
    margin that checks one end only (the toe side never out of the face)."""
    opts = dict(kinematics=False, face_ends=False, throw=False)
    runs = {s: gj.run_tca(pair, gj.Misalignment.create(dSigma_deg=s * 0.663, dP=s * 5.0),
                          **opts) for s in (1.0, -1.0)}
    conv = np.asarray(runs[1.0].path.converged) & np.asarray(runs[-1.0].path.converged)
    assert conv.sum() > 20
    ax1 = {s: np.asarray(r.path.axial1) for s, r in runs.items()}
    np.testing.assert_allclose(ax1[-1.0][conv], -ax1[1.0][conv], atol=1e-9)
    half = 0.5 * float(pair.face_width)
    for s, r in runs.items():
        a1, a2 = np.abs(ax1[s]), np.abs(np.asarray(r.path.axial2))
        on = np.asarray(r.on_flank)
        assert on.sum() >= 5, s
        assert np.all((a1 <= half + 1e-9) & (a2 <= half + 1e-9) | ~on), s
        only_gear_inside = conv & (a1 > half) & (a2 < half)
        assert only_gear_inside.sum() >= 3 and not np.any(on & only_gear_inside), s


def _timoshenko(F, Rx, Ry, E_prime):
    """Seed's formula a, b = k_a, k_b [3w/(2E'(A+B))]^(1/3), k_a = (2 E(e)/(pi (1 -
    e^2)))^(1/3), k_b = k_a sqrt(1 - e^2), e from B/A = ((E/(1 - e^2)) - K)/(K - E)
    (m = e^2; Timoshenko & Goodier)."""
    A, Bc = 0.5 / Ry, 0.5 / Rx
    ratio = Bc / A

    def g(m):
        K, E = ellipk(m), ellipe(m)
        return (E / (1 - m) - K) / (K - E) - ratio

    m = brentq(g, 1e-12, 1 - 1e-15, xtol=1e-16, rtol=1e-15)
    ka = (2 * ellipe(m) / (math.pi * (1 - m))) ** (1 / 3)
    base = (3 * F / (2 * E_prime * (A + Bc))) ** (1 / 3)
    return ka * base, ka * math.sqrt(1 - m) * base


def test_seed_hertz_formula_matches_exact_hertz():
    """The seed's Hertz formula (semi-axes through k_a, k_b) and gearjax's exact Hertz
    point contact agree (1e-8 relative) for the elongated ellipses of VH-CATT pairs."""
    for F, Rx, Ry in ((2000.0, 6.7, 16000.0), (500.0, 2.5, 9000.0), (1000.0, 10.0, 60.0)):
        Ep = 203e3 / (1 - 0.09)
        hz = gj.tribology.hertz_point(F, Rx, Ry, Ep)
        a, b = _timoshenko(F, Rx, Ry, Ep)
        assert abs(float(hz.a) - a) / a < 1e-8 and abs(float(hz.b) - b) / b < 1e-8


def _data(**pair_over):
    d = {"design": {"kind": "vh_catt", "name": "t"},
         "pair": dict(z1=17, z2=23, module_mm=4.0, pressure_angle_deg=20.0, face_width_mm=28.0,
                      cutter_radius1_mm=400.0, cutter_radius2_mm=400.0, blade_offset_mm=3.0),
         "material": dict(youngs_modulus_GPa=203.0, poisson=0.3)}
    d["pair"].update(pair_over)
    return d


def test_design_file(design):
    assert design.data["pair"]["cutter_radius1_mm"] == 400.0 and design.defaults_lines() == []
    assert abs(design.e_prime_MPa() - 203e3 / 0.91) < 1e-9
    assert gj.tca.family_of(design).family == "vh_catt"
    d = _data()
    del d["pair"]["blade_offset_mm"]
    with pytest.raises(ValueError, match="blade_offset_mm"):
        design_from_dict(d)
    with pytest.raises(ValueError, match=r"\[pair\] z2 = 15 must be >= z1"):
        design_from_dict(_data(z2=15))
    with pytest.raises(ValueError, match="cutter_radius2"):
        design_from_dict(_data(cutter_radius2_mm=5.0))
    with pytest.raises(ValueError, match="unknown|not allowed|helix"):
        design_from_dict(_data(helix_deg=10.0))


def test_second_branch_past_the_edge_of_regression_is_off_the_flank(pair):
    """The envelope of the unbounded blade cone continues past the base circle onto a
    second branch at the same radii (the defect found on involute pairs: a radius-only
    form-circle test took it for flank).  In the middle section the blade point
    ``u = -2 r sin^2(alpha)/cos(alpha)`` generates the roll distance ``-r sin(alpha)``:
    the second-branch point at the pitch radius, between the form and tip circles.
    The working point at ``u = 0`` (same radius) is on the flank, the other is not."""
    from gearjax.gears.vh_catt.tca import margin_parts, vh_flanks
    r1f, _ = vh_flanks(pair, -1.0)
    r = 0.5 * pair.z1 * float(pair.module)
    al = float(pair.pressure_angle)
    u2 = -2.0 * r * math.sin(al) ** 2 / math.cos(al)
    work, second = (np.asarray(r1f(jnp.array([u, 0.0]))) for u in (0.0, u2))
    np.testing.assert_allclose(np.hypot(*second[:2]), np.hypot(*work[:2]), rtol=1e-9)
    parts = margin_parts(pair)
    q2 = jnp.asarray(work)[None]          # any on-flank gear point: only the pinion matters
    uv = jnp.zeros((1, 2))
    _, _, root_work, *_ = parts(jnp.asarray(work)[None], q2, uv, uv)
    _, _, root_second, *_ = parts(jnp.asarray(second)[None], q2, jnp.array([[u2, 0.0]]), uv)
    assert float(root_work[0]) > 0.0
    assert float(root_second[0]) < 0.0


def test_root_margin_is_continuous_across_the_edge_of_regression(pair):
    """Both members (17/23: different base circles), middle section: the blade point
    ``u_b = -r sin^2(alpha)/cos(alpha)`` generates the base-circle point (closed form,
    1e-9 mm), where the working involute and the second branch meet -- one point, so
    one root margin: ``r_b - r_F`` from either side (``r_F`` the form radius of the
    straight blade, clipped at the base circle for the undercut pinion: closed form);
    continuous there to the rounding of a radius that grows as the square of the
    distance.  On the second branch the margin keeps counting the way along the flank
    from the form circle down to the base circle and back up: ``-(r_F - r_b) - (r - r_b)``
    at the radius r of the point, e.g. at the pitch radius (``u = 2 u_b``).  Planted bug
    caught: the gear's second-branch margin with the pinion's base radius (a jump of
    2 (r_b2 - r_b1) = 22.6 mm at the base circle)."""
    from gearjax.gears.vh_catt.tca import margin_parts, vh_flanks
    flanks = vh_flanks(pair, -1.0)
    parts = margin_parts(pair)
    al = float(pair.pressure_angle)
    m = float(pair.module)
    other = jnp.asarray(flanks[0](jnp.zeros(2)))[None]      # an on-flank point (the other slot)
    zero_uv = jnp.zeros((1, 2))
    eps = 1e-3
    for i, z in enumerate((pair.z1, pair.z2)):
        r = 0.5 * z * m
        rb = r * math.cos(al)
        rF = math.hypot(rb, max(r * math.sin(al) - m / math.sin(al), 0.0))
        u_b = -r * math.sin(al) ** 2 / math.cos(al)

        def root(u):
            q = jnp.asarray(flanks[i](jnp.array([u, 0.0])))
            assert abs(float(q[2])) < 1e-9                 # the middle section
            uv = jnp.array([[u, 0.0]])
            args = (q[None], other, uv, zero_uv) if i == 0 else (other, q[None], zero_uv, uv)
            return float(parts(*args)[2 if i == 0 else 5][0]), float(jnp.hypot(q[0], q[1]))

        _, r_b = root(u_b)
        assert abs(r_b - rb) < 1e-9, (i, r_b, rb)
        (m_work, r_work), (m_second, r_second) = root(u_b + eps), root(u_b - eps)
        assert r_work > rb and r_second > rb
        np.testing.assert_allclose([m_work, m_second], rb - rF, atol=1e-5)
        np.testing.assert_allclose(m_work, r_work - rF, rtol=0, atol=1e-12)
        m_pitch, r_pitch = root(2.0 * u_b)
        assert abs(r_pitch - r) < 1e-6
        np.testing.assert_allclose(m_pitch, -(rF - rb) - (r_pitch - rb), rtol=0, atol=1e-12)
        assert m_pitch < 0.0
