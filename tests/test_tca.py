"""Tooth contact analysis: conjugacy, mismatch TE against closed forms, multiple pairs,
contact ellipse against a second route, gradients against central differences.

Three compiled configurations only (line contact, point contact, point-contact
jacfwd), shared through module-scoped fixtures: all designs below have the same
static structure (z1 = 25, z2 = 41), so each configuration compiles once.
"""

import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.errors import ConvergenceError
from gearjax.gears.involute import InvolutePair, generated_flank, pair_geometry
from gearjax.tca import (ARCSEC, Misalignment, NoContactError, contact_path,
                         ellipse_from_weingarten)
from gearjax.tca_involute import (InvoluteTCA, crowned_pinion_flank, involute_tca,
                                  misalignment_sensitivity, tca_summary, SUMMARY_KEYS)

Z1, Z2, M, ALPHA = 25, 41, 2.0, 20.0
MID = 30            # 61 positions, 24 per pitch, reference in the middle


@pytest.fixture(scope="module")
def pair():
    return InvolutePair.create(Z1, Z2, M, ALPHA)


@pytest.fixture(scope="module")
def conjugate(pair):
    return involute_tca(InvoluteTCA.create(pair, 20.0))


def test_involute_pair_is_conjugate(conjugate):
    path, margin, multi = conjugate
    assert path.phi1.shape == (61,)
    assert bool(np.all(path.converged))
    assert float(np.max(path.residual)) < 1e-11
    # TE == 0 over the whole computed range (more than the mesh cycle)
    assert float(np.max(np.abs(path.te))) / ARCSEC < 1e-6
    assert float(multi.ptp) / ARCSEC < 1e-6


def test_conjugate_contact_lies_on_the_line_of_action(pair, conjugate):
    path, _, _ = conjugate
    geo = pair_geometry(pair)
    aw, rw1 = float(geo["alpha_wt"]), float(geo["a_w"]) * Z1 / (Z1 + Z2)
    # drive flank (side -1): line of action through the pitch point (0, rw1) along
    # d = (-cos aw, sin aw); the distance of every contact point from it is zero
    d = np.array([-np.cos(aw), np.sin(aw)])
    rel = np.asarray(path.point)[:, :2] - np.array([0.0, rw1])
    np.testing.assert_allclose(rel[:, 0] * d[1] - rel[:, 1] * d[0], 0.0, atol=1e-9)
    # the contact moves along it at the base-circle speed rb1 * dphi1
    s = rel @ d
    np.testing.assert_allclose(np.diff(s), float(geo["rb1"]) * np.diff(path.phi1), rtol=1e-9)


def test_contact_ratio_matches_path_of_contact(pair, conjugate):
    _, _, multi = conjugate
    ref = float(pair_geometry(pair)["contact_ratio"])
    # boundary crossings are interpolated linearly on a grid of 24 steps per pitch
    assert abs(float(multi.contact_ratio) - ref) < 2e-4 * ref


def test_base_pitch_mismatch_gives_exact_linear_te(pair):
    dal = 0.05
    des = InvoluteTCA.create(pair, 20.0, dalpha_deg=dal)
    path, margin, multi = involute_tca(des)
    a1 = float(pair.pressure_angle) + np.radians(dal)
    a2 = float(pair.pressure_angle)
    # involutes transmit rb1/rb2 exactly: TE = (rb1/rb2 - z1/z2)(phi1 - phi1_0)
    slope = Z1 / Z2 * (np.cos(a1) / np.cos(a2) - 1.0)
    theory = slope * (np.asarray(path.phi1) - float(path.phi1[MID]))
    assert np.max(np.abs(theory)) / ARCSEC > 10.0            # a real, visible error
    np.testing.assert_allclose(np.asarray(path.te) / ARCSEC, theory / ARCSEC, atol=1e-6)
    # linear TE: the envelope is a saw-tooth of height |slope| * pitch; sampled on the
    # grid (24 steps per pitch) its peak-to-peak is |slope| * (pitch - step)
    pitch = 2 * np.pi / Z1
    assert abs(float(multi.ptp) - abs(slope) * pitch * 23 / 24) < 1e-6 * float(multi.ptp)


def _crown_te(pair, a):
    des = InvoluteTCA.create(pair, 20.0, profile_crown=a)
    path, margin, multi = involute_tca(des)
    geo = pair_geometry(pair)
    al, rb1, rb2 = float(pair.pressure_angle), float(geo["rb1"]), float(geo["rb2"])
    s = rb1 * (np.asarray(path.phi1) - float(path.phi1[MID]))
    theory = -a * (s * np.tan(al)) ** 2 / rb2
    inside = np.asarray(margin) >= 0.0
    return np.asarray(path.te)[inside], theory[inside], path, multi


def test_profile_crown_gives_parabolic_te_first_order_theory(pair):
    """First-order theory TE = -a (s tan alpha)^2/rb2: error must vanish as a^2."""
    a = 1e-4
    te1, th1, path, multi = _crown_te(pair, a)
    te2, th2, _, _ = _crown_te(pair, a / 2)
    assert bool(np.all(path.converged))
    e1 = np.max(np.abs(te1 - th1))
    e2 = np.max(np.abs(te2 - th2))
    assert e1 < 5e-3 * np.max(np.abs(th1))
    assert 3.6 < e1 / e2 < 4.4                                # second-order remainder
    # reference at the pitch point (u1 = 0): the parabola's vertex
    assert abs(float(path.uv1[MID, 0])) < 1e-9
    # transfer points at +-half a pitch from the vertex, envelope p-t-p at them
    pitch = 2 * np.pi / Z1
    tr = np.asarray(multi.transfer_phi1) - float(path.phi1[MID])
    np.testing.assert_allclose(tr, [-pitch / 2, pitch / 2], atol=1e-3 * pitch)
    geo = pair_geometry(pair)
    ptp_theory = a * (float(geo["rb1"]) * pitch / 2 * np.tan(float(pair.pressure_angle))) ** 2 \
        / float(geo["rb2"])
    assert abs(float(multi.ptp) - ptp_theory) < 5e-3 * ptp_theory


# ---------------------------------------------------------------- point contact

@pytest.fixture(scope="module")
def crowned(pair):
    des = InvoluteTCA.create(pair, 20.0, profile_crown=0.002, lead_crown=0.001)
    return des, involute_tca(des)


def test_point_contact_converges_and_is_localised(crowned):
    des, (path, margin, multi) = crowned
    assert bool(np.all(path.converged)) and float(np.max(path.residual)) < 1e-11
    assert bool(np.all(np.isfinite(np.asarray(path.semi_major))))
    # symmetric lead crown, no misalignment: the path stays at mid face
    np.testing.assert_allclose(path.axial1, 0.0, atol=1e-9)
    # envelope: max over pairs (drive), pair 0 carries between its transfer points
    env = np.asarray(multi.envelope)
    te = np.asarray(multi.te_pairs)
    assert np.all(env >= np.nanmax(np.where(np.asarray(multi.inside), te, -np.inf), 0) - 1e-15)
    assert np.asarray(multi.active)[MID] == 1


def test_contact_ellipse_matches_gap_second_route(pair, crowned):
    """Relative curvature from the flanks' Weingarten maps vs the measured gap
    (t.B.t = gap(t) + gap(-t) over t^2, from point solves on both flanks)."""
    des, (path, _, _) = crowned
    side = -1
    r1 = crowned_pinion_flank(des, side)
    r2 = generated_flank(pair.module, pair.pressure_angle, -pair.helix, pair.x2, pair.z2, side)
    geo = pair_geometry(pair)
    phi1, phi2 = float(path.phi1[MID]), float(path.phi2[MID])
    c1, s1 = np.cos(phi1), np.sin(phi1)
    c2, s2 = np.cos(phi2), np.sin(phi2)
    R1 = jnp.array([[c1, -s1, 0], [s1, c1, 0], [0, 0, 1.0]])
    R2 = jnp.array([[c2, -s2, 0], [s2, c2, 0], [0, 0, 1.0]])
    cen = jnp.array([0.0, float(geo["a_w"]), 0.0])
    P = path.point[MID]
    n = path.normal[MID]
    e = path.major_dir[MID]
    f = jnp.cross(n, e)

    def gap_of(surf, Rm, c, uv0, t, dirn):
        from gearjax.newton import newton_solve

        def F(uv, tt):
            q = c + Rm @ surf(uv) - P
            return jnp.stack([jnp.dot(q, dirn) - tt, jnp.dot(q, jnp.cross(n, dirn))])
        sol = newton_solve(F, uv0, t)
        assert bool(sol.converged)
        return jnp.dot(c + Rm @ surf(sol.x) - P, n)

    def lam(dirn, t):
        g = []
        for tt in (t, -t):
            g1 = gap_of(r1, R1, jnp.zeros(3), path.uv1[MID], tt, dirn)
            g2 = gap_of(r2, R2, cen, path.uv2[MID], tt, dirn)
            g.append(abs(float(g1 - g2)))
        return (g[0] + g[1]) / t ** 2

    lam_major = lam(e, 0.02)
    lam_minor = lam(f, 0.002)
    delta = 0.00632
    np.testing.assert_allclose(np.sqrt(2 * delta / lam_major), path.semi_major[MID], rtol=1e-4)
    np.testing.assert_allclose(np.sqrt(2 * delta / lam_minor), path.semi_minor[MID], rtol=1e-4)


def test_ellipse_of_known_curvatures():
    """Two spheres (radii 10 and -40 with common normal): a = b = sqrt(2 delta/(1/10 - 1/40))."""
    n = jnp.array([0.0, 0.0, 1.0])
    P = jnp.diag(jnp.array([1.0, 1.0, 0.0]))
    a, b, _ = ellipse_from_weingarten(n, -P / 10.0, P / 40.0, jnp.array([1.0, 0, 0]), 0.01)
    np.testing.assert_allclose([a, b], np.sqrt(2 * 0.01 / (0.1 + 0.025)), rtol=1e-12)
    # cylinder on plane: line contact -> infinite major axis
    W1 = -jnp.diag(jnp.array([0.1, 0.0, 0.0]))
    a, b, d = ellipse_from_weingarten(n, W1, jnp.zeros((3, 3)), jnp.array([1.0, 0, 0]), 0.01)
    assert np.isinf(float(a)) and abs(float(b) - np.sqrt(0.2)) < 1e-12
    np.testing.assert_allclose(jnp.abs(d), [0.0, 1.0, 0.0], atol=1e-12)


def test_misalignment_moves_bearing_and_gradients_match_central_differences(pair, crowned):
    des, _ = crowned
    mis0 = Misalignment(jnp.asarray(0.0), jnp.asarray(0.0), jnp.asarray(0.0), jnp.asarray(1e-4))
    values, table, jdes = misalignment_sensitivity(des, mis0)

    def summary(d, m):
        path, _, multi = involute_tca(d, m)
        return np.asarray(tca_summary(path, multi))

    base = summary(des, mis0)
    np.testing.assert_allclose([values[k] for k in SUMMARY_KEYS], base, rtol=1e-12, atol=1e-14)

    def richardson(f, h):
        # 4th-order central difference
        return (8 * (f(h) - f(-h)) - (f(2 * h) - f(-2 * h))) / (12 * h)

    def check(ad, fd, h, what):
        # 1e-5 relative, plus the resolution floor of a difference quotient: the
        # summary values are reproducible to ~1e-12 relative (Newton residual 1e-14)
        floor = 1e-12 * (np.abs(base) + 1e-3) / h
        assert np.all(np.isfinite(ad)), what
        assert np.all(np.abs(ad - fd) <= 1e-5 * np.abs(fd) + floor), (what, ad, fd)

    # steps balance truncation against solve noise
    steps = dict(dE=1e-4, dP=1e-4, dG=1e-4, dSigma=2e-5)
    for name, h in steps.items():
        fd = richardson(lambda e: summary(
            des, Misalignment(**{**mis0.__dict__, name: getattr(mis0, name) + e})), h)
        check(np.array([table[k][name] for k in SUMMARY_KEYS]), fd, h, name)
    # pinion settings: profile and lead crown
    for name, h in (("profile_crown", 1e-5), ("lead_crown", 1e-5)):
        def f(e):
            kw = dict(dalpha=des.dalpha, profile_crown=des.profile_crown,
                      lead_crown=des.lead_crown, face_width=des.face_width)
            kw[name] = kw[name] + e
            return summary(InvoluteTCA(des.pair, **kw), mis0)
        check(np.asarray(getattr(jdes, name)), richardson(f, h), h, name)
    # the derivatives that matter are far above the floor
    assert abs(float(jdes.profile_crown[0])) > 1e-2          # d ptp / d crown
    assert abs(float(jdes.lead_crown[6])) > 1e2              # d ellipse / d lead crown
    # a shaft-angle error moves the bearing across the face (V-H check direction)
    assert abs(table["axial1_mm"]["dSigma"]) > 100.0


def test_strict_mode_raises_when_the_flanks_do_not_touch(pair):
    # a gear 40 mm further away: the (analytically extended) surfaces may still have
    # solutions, but none inside the flank boundaries
    des = InvoluteTCA.create(pair, 20.0)
    mis = Misalignment.create(dE=40.0)
    with pytest.raises(NoContactError):
        involute_tca(des, mis)
    path, margin, multi = involute_tca(des, mis, strict=False)
    assert not np.any((np.asarray(margin) >= 0.0) & np.asarray(path.converged))
    assert issubclass(NoContactError, ConvergenceError)


def test_validation_names_parameters(pair):
    with pytest.raises(ValueError, match="face_width"):
        InvoluteTCA.create(pair, -1.0)
    with pytest.raises(ValueError, match="dSigma"):
        Misalignment.create(dSigma_deg=10.0)
    with pytest.raises(ValueError, match="side"):
        involute_tca(InvoluteTCA.create(pair, 20.0), side=0)
    with pytest.raises(ValueError, match="odd"):
        contact_path(lambda uv: uv, lambda uv: uv, None, None, jnp.zeros(4), jnp.zeros(5),
                     line_contact=True)


def test_plot_written_atomically(tmp_path, pair, crowned):
    from gearjax.plot_tca import ellipse_outline_axial, save_tca_plot
    des, (path, margin, multi) = crowned
    out = save_tca_plot(tmp_path / "tca.png", [("drive", path, margin, multi)],
                        limits=dict(face_half=10.0, root_radius=22.0, tip_radius=27.0))
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tca.png"]
    # the ellipse outline spans the semi-axes about the contact point: at mid face the
    # major axis (lead-crown direction) is axial, so its axial extent is +-semi_major
    o = ellipse_outline_axial(path, MID, points=65)   # samples t = 0, pi exactly
    np.testing.assert_allclose([o[:, 0].min(), o[:, 0].max()],
                               [-float(path.semi_major[MID]), float(path.semi_major[MID])],
                               rtol=1e-3)
