"""Edge contact at the face ends (gearjax.tca.edge_contact) against closed forms.

Reference: a spur pair whose gear axis is turned by a small angle dg about the
centre line (``dSigma``, crossed axes).  A gear point at axial position z moves by
``dg (z, 0, -x)`` (rotation about the y axis through the gear axis); along the
transverse profile normal ``n = (+-cos aw, sin aw, 0)`` (the line of action) that is
``dg z cos aw``.  The profile section at z therefore touches at
``TE(z) = TE(0) +- dg z cos aw / r_b2`` to first order in dg: linear across the face,
so the uncrowned pair touches at the face end that leads, ahead of the mid-face
section by ``(b/2) dg cos aw / r_b2`` (Litvin & Fuentes, Gear Geometry and Applied
Theory, ch. 15: a crossing of the axes of unmodified gears gives edge contact).

Tip edges: a spur pair with a base-pitch mismatch touches at a tooth tip off the line
of action; reference: the closed form of the plane involutes (below, before the tests).
"""

import functools
import json

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cost_guard import check_cost

import gearjax as gj
from gearjax import ARCSEC
from gearjax.cli import main
from gearjax.tca.edge_contact import EDGE_NAMES
from gearjax.gears.involute import tca as itca
from gearjax.gears.involute.geometry import generated_flank

B = 30.0
PAIR = gj.involute.InvolutePair.create(20, 40, 4.0, 20.0, 0.0, 0.0, 0.0)
SPUR = gj.involute.InvoluteTCA.create(PAIR, B)
DG = np.radians(0.05)
RB2 = 0.5 * 40 * 4.0 * np.cos(np.radians(20.0))
LEAD = 0.5 * B * DG * np.cos(np.radians(20.0)) / RB2      # rad, edge ahead of mid-face


@pytest.fixture(scope="module")
def traced():
    """The involute TCA (line contact, 24 steps per pitch, +-1.25 pitches, 3 pairs, no
    kinematics) with and without face ends by the one entry point,
    ``traced[fe](design, misalignment, side=-1.0)`` (-1 drive, +1 coast) ->
    ``(path, margin, multi)``: one compiled program each (the side is an argument of
    the program, so both sides share it)."""
    def run(d, m, side=-1.0, fe=True):
        f = gj.tca_function(d, side="drive" if side < 0 else "coast", line_contact=True,
                            face_ends=fe, kinematics=False, steps_per_pitch=24,
                            half_pitches=1.25, n_pairs=3)
        res = f(d, m)
        return res.path, res.margin, res.multi
    return {fe: functools.partial(run, fe=fe) for fe in (True, False)}


def _mis(dg):
    return gj.Misalignment(*(jnp.asarray(v, float) for v in (0.0, 0.0, 0.0, dg)))


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_crossed_uncrowned_spur_touches_at_the_leading_face_end(traced, sign):
    path, margin, multi = traced[True](SPUR, _mis(sign * DG))
    section, _, _ = traced[False](SPUR, _mis(sign * DG))
    kind = np.asarray(path.edge_kind)
    on = np.asarray(margin) >= 0.0
    carried = on & (kind >= 0)
    assert carried.sum() > 20, "the crossed uncrowned pair must be in edge contact"
    # the face end: axial position +-b/2 on the member whose edge touches
    ax = np.where(kind[carried] < 2, np.asarray(path.axial1)[carried],
                  np.asarray(path.axial2)[carried])
    np.testing.assert_allclose(np.abs(ax), 0.5 * B, atol=1e-6)
    ends = {EDGE_NAMES[k].split()[1] for k in kind[carried]}
    assert len(ends) == 1, ends            # one end leads over the whole mesh
    # ahead of the mid-face section by (b/2) dg cos aw / r_b2 (drive: larger TE)
    lead = (np.asarray(path.te) - np.asarray(section.te))[carried]
    np.testing.assert_allclose(lead, LEAD, rtol=2e-3)
    # the contact normal is that of the flank the edge touches (the edge has none):
    # a spur flank's normal is transverse in its own body; the gear is turned by dg
    # about the y axis, (nx, ny, 0) -> (nx cos dg, ny, -nx sin dg).  A pinion edge on
    # the gear flank: |n_z| = |n_x| tan dg; a gear edge on the pinion flank: n_z = 0.
    # (Planted bug caught: the normal of the edge's own flank.)
    nrm = np.asarray(path.normal)[carried]
    np.testing.assert_allclose(np.linalg.norm(nrm, axis=1), 1.0, rtol=1e-12)
    pin = kind[carried] < 2
    np.testing.assert_allclose(np.abs(nrm[:, 2]),
                               np.where(pin, np.abs(nrm[:, 0]) * np.tan(DG), 0.0),
                               rtol=1e-6, atol=1e-12)


def test_the_other_crossing_sense_loads_the_other_end(traced):
    ends = {}
    for sign in (1.0, -1.0):
        path, margin, _ = traced[True](SPUR, _mis(sign * DG))
        kind = np.asarray(path.edge_kind)
        carried = (np.asarray(margin) >= 0.0) & (kind >= 0)
        ends[sign] = {EDGE_NAMES[k].split()[1] for k in kind[carried]}
    assert ends[1.0] == {"heel"} and ends[-1.0] == {"toe"} or \
        ends[1.0] == {"toe"} and ends[-1.0] == {"heel"}, ends


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_coast_side_touches_at_the_other_face_end(traced, sign):
    """The crossed uncrowned spur pair on the coast side (the other flanks in contact,
    the load sense reversed).  The crossing moves a gear tooth at axial position z
    sideways by dg z (rotation about the centre line): towards the pinion tooth's drive
    flank at one face end and towards its coast flank at the other.  So the coast
    contact is made at the face end opposite the drive side's, at the same distance
    (b/2) dg cos(aw)/r_b2 from the mid-face section but ahead in the coast sense: a
    smaller TE (the closed form of the module docstring with the load sense reversed).
    Same compiled programs as the drive tests (the side is traced).  Planted bug
    caught: the edge candidate picked by the largest TE whatever the side (the
    trailing end on the coast side)."""
    ends = {}
    for side in (-1.0, 1.0):
        path, margin, _ = traced[True](SPUR, _mis(sign * DG), side)
        section, _, _ = traced[False](SPUR, _mis(sign * DG), side)
        kind = np.asarray(path.edge_kind)
        carried = (np.asarray(margin) >= 0.0) & (kind >= 0)
        assert carried.sum() > 20, side
        ax = np.where(kind[carried] < 2, np.asarray(path.axial1)[carried],
                      np.asarray(path.axial2)[carried])
        np.testing.assert_allclose(np.abs(ax), 0.5 * B, atol=1e-6)
        ends[side] = {EDGE_NAMES[k].split()[1] for k in kind[carried]}
        assert len(ends[side]) == 1, ends
        # ahead of the mid-face section in the sense of the load: larger TE on the drive
        # side, smaller on the coast side
        lead = (np.asarray(path.te) - np.asarray(section.te))[carried]
        np.testing.assert_allclose(-side * lead, LEAD, rtol=2e-3)
    assert ends[-1.0] != ends[1.0], ends


HELICAL = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(20, 40, 4.0, 20.0, 15.0, 0.2, 0.0), B)


@pytest.mark.parametrize("des", [SPUR, HELICAL], ids=["spur", "helical"])
def test_aligned_conjugate_pair_has_no_edge_contact_and_is_unchanged(traced, des):
    """A conjugate pair touches along lines across the whole face: no edge contact (face
    end or tip).  For
    the helical pair the face ends stay on the flanks after the solved mid-face section
    has left them -- those face-end points lie on its contact line (same TE)."""
    mis = _mis(0.0)
    path, margin, multi = traced[True](des, mis)
    ref, ref_margin, ref_multi = traced[False](des, mis)
    assert np.all(np.asarray(path.edge_kind) == -1)
    # the two programs (with and without the edge solves) are compiled separately and
    # may round the common surface solve differently (1e-16 rad seen); an edge that
    # replaced the surface contact would lead it by more than EDGE_LEAD = 1e-9 rad
    np.testing.assert_allclose(np.asarray(path.te), np.asarray(ref.te), rtol=0, atol=1e-14)
    np.testing.assert_allclose(np.asarray(margin), np.asarray(ref_margin), rtol=0, atol=1e-12)
    assert float(multi.contact_ratio) == pytest.approx(float(ref_multi.contact_ratio), abs=1e-12)
    # no spurious tip contact: a tip corner off the line of action has clearance, so
    # the TE envelope is the same (to rounding) with and without the edge solve
    np.testing.assert_allclose(np.asarray(multi.envelope), np.asarray(ref_multi.envelope),
                               rtol=0, atol=1e-14)


def _d_mis(traced, des, mis, direction):
    """The TCA with edges and its derivative along a misalignment ``direction`` (a
    Misalignment of tangents): forward mode through the implicit derivative of every
    solve; one compiled derivative program for every direction and design."""
    t = gj.Misalignment(*(jnp.asarray(v, float) for v in direction))
    return jax.jvp(lambda m: traced[True](des, m), (mis,), (t,))


def test_edge_te_derivative_matches_closed_form_and_differences(traced):
    """d(TE at an edge contact)/d(crossing angle) by the implicit derivative of the
    edge-contact solve, against central differences and the closed form.  (The TE of
    the mid-face section at the reference, subtracted, is 0 by definition.)"""
    def te_mid(dg):
        path, _, _ = traced[True](SPUR, _mis(dg))
        sec, _, _ = traced[False](SPUR, _mis(dg))
        mid = path.te.shape[0] // 2
        return path.te[mid] - sec.te[mid], path.edge_kind[mid]

    val, kind = te_mid(DG)
    assert int(kind) >= 0
    (path, _, _), (d_path, _, _) = _d_mis(traced, SPUR, _mis(DG), (0.0, 0.0, 0.0, 1.0))
    mid = path.te.shape[0] // 2
    d_ad = d_path.te[mid]
    h = 1e-6
    d_fd = (te_mid(DG + h)[0] - te_mid(DG - h)[0]) / (2 * h)
    assert np.isfinite(float(d_ad))
    np.testing.assert_allclose(float(d_ad), float(d_fd), rtol=1e-5)
    np.testing.assert_allclose(float(d_ad), LEAD / DG, rtol=2e-3)


def test_crowned_pinion_keeps_its_bearing_inside_and_a_large_crossing_is_flagged():
    helical = gj.involute.InvolutePair.create(20, 40, 4.0, 20.0, 15.0, 0.2, 0.0)
    crowned = gj.involute.InvoluteTCA.create(helical, B, 0.0, 0.0, 2e-4)
    small = gj.run_tca(crowned, gj.Misalignment.create(dSigma_deg=0.05), throw=False)
    assert not small.flags()["face_end_contact"]
    assert small.face_ends_loaded() == []
    big = gj.run_tca(crowned, gj.Misalignment.create(dSigma_deg=0.5), throw=False)
    f = big.flags()
    assert f["face_end_contact"] and f["edge_contact"]
    assert any("edge contact at the" in w for w in big.warnings())
    # no Hertz ellipse and no rolling/sliding values at an edge contact
    edge = np.asarray(big.path.edge_kind) >= 0
    assert np.all(np.isnan(np.asarray(big.path.semi_minor)[edge]))
    assert np.all(np.isnan(np.asarray(big.kinematics.srr)[edge]))
    assert not np.any(np.asarray(big.on_flank)[edge])


def test_cli_warns_on_edge_contact(capsys):
    """The crowned helical pair of the test above at the large crossing, through the
    CLI (61 positions = 24 steps per pitch, 1.25 pitches, kinematics: the options of
    ``run_tca`` above, so the compiled program is shared): edge contact is warned on
    stderr and flagged in the JSON."""
    code = main(["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=30,helix=15,x1=0.2,lead_crown=2e-4",
                 "--misalign", "dSigma=0.5", "--kinematics", "--json"])
    out = capsys.readouterr()
    assert code == 0
    assert "edge contact at the" in out.err
    q = json.loads(out.out)["quality"]
    assert q["face_end_contact"] and q["edge_contact"]


# -- tip edges: premature and prolonged contact under a base-pitch mismatch ------------
#
# Closed form (plane involute geometry of the rack-generated spur pair, independent of
# the TCA): tooth i (1 pinion, 2 gear; body frame, tooth centred on +y) has pitch radius
# r_i = z_i m/2, generating pressure angle a_i (pinion alpha + dalpha), base radius
# r_bi = r_i cos a_i, tooth thickness s_i = m (pi/2 + 2 x_i tan a_i), tip radius
# r_ai = r_i + m (1 + x_i), form radius of the straight rack flank
# r_Fi = sqrt(r_bi^2 + (r_i sin a_i - m (1 - x_i)/sin a_i)^2); its working flank point
# at radius R lies at the polar angle pi/2 + sig_i psi_i(R) with the half angular
# thickness psi_i(R) = s_i/(2 r_i) + inv a_i - inv(arccos(r_bi/R)).  Mounted (pinion
# turned by phi1 about the origin, gear by phi2 about (0, a)), the gear angle at which
#   * the flanks touch: the pinion point whose normal is the inner common tangent of
#     the base circles, a sin(tau) = r_b1 + r_b2 (explicit);
#   * the gear's tip corner touches the pinion flank: the pinion point at distance r_a2
#     from the gear centre (one scalar root in R), then phi2 explicit;
#   * the pinion's tip corner touches the gear flank: explicit;
# each candidate valid where both points lie on their flanks (r_F <= R <= r_a).  The
# rigid teeth touch at the candidate furthest ahead (drive: max TE over the candidates
# of the pairs k = -1, 0, 1, pair k = pair 0 shifted by k pinion pitches).

def _inv(a):
    return np.tan(a) - a


class _ClosedFormSpur:
    def __init__(self, z1, z2, m, alpha_deg, dalpha_deg, a, sig):
        self.a, self.sig, self.g = a, sig, []
        for z, alp in ((z1, np.radians(alpha_deg + dalpha_deg)), (z2, np.radians(alpha_deg))):
            r = 0.5 * z * m
            rb = r * np.cos(alp)
            self.g.append(dict(r=r, rb=rb, s=0.5 * np.pi * m, ra=r + m, alp=alp,
                               rF=np.hypot(rb, r * np.sin(alp) - m / np.sin(alp))))

    def psi(self, i, R):
        g = self.g[i]
        return g["s"] / (2 * g["r"]) + _inv(g["alp"]) - _inv(np.arccos(g["rb"] / R))

    def pinion_point(self, ph1, R):
        t = ph1 + 0.5 * np.pi + self.sig[0] * self.psi(0, R)
        return R * np.array([np.cos(t), np.sin(t)])

    def gear_angle(self, X):
        """Gear angle that puts its working flank through the fixed point X, and the
        radius of that gear point."""
        d = X - np.array([0.0, self.a])
        R2 = np.hypot(*d)
        return np.arctan2(d[1], d[0]) - 0.5 * np.pi - self.sig[1] * self.psi(1, R2), R2

    def on(self, i, R):
        return self.g[i]["rF"] <= R <= self.g[i]["ra"]

    def candidates(self, ph1):
        """{name: phi2} of the valid contacts of pair 0 at pinion angle ph1."""
        from scipy.optimize import brentq
        g1, g2 = self.g
        out = {}
        thb = ph1 + 0.5 * np.pi + self.sig[0] * (g1["s"] / (2 * g1["r"]) + _inv(g1["alp"]))
        base = np.arcsin((g1["rb"] + g2["rb"]) / self.a)
        for tau in (base, np.pi - base):
            t = self.sig[0] * np.angle(np.exp(1j * (thb - tau)))     # roll angle
            if t > 0:
                R = g1["rb"] * np.hypot(1.0, t)
                ph2, R2 = self.gear_angle(self.pinion_point(ph1, R))
                if self.on(0, R) and self.on(1, R2):
                    out["surface"] = ph2
        f = lambda R: np.hypot(*(self.pinion_point(ph1, R) - [0.0, self.a])) - g2["ra"]
        Rs = np.linspace(g1["rF"], g1["ra"], 41)
        fs = np.array([f(R) for R in Rs])
        for i in np.nonzero(np.sign(fs[:-1]) != np.sign(fs[1:]))[0]:
            R = brentq(f, Rs[i], Rs[i + 1], xtol=1e-14, rtol=1e-15)
            out["gear tip"] = self.gear_angle(self.pinion_point(ph1, R))[0]
        ph2, R2 = self.gear_angle(self.pinion_point(ph1, g1["ra"]))
        if self.on(1, R2):
            out["pinion tip"] = ph2
        return out


@pytest.fixture(scope="module")
def mismatch(traced):
    """The spur pair 20/40 with the pinion's pressure angle changed by +-1 deg (base
    pitch of the pinion smaller / larger than the gear's), the TCA with and without
    edges and the closed form."""
    out = {}
    for da in (1.0, -1.0):
        des = gj.involute.InvoluteTCA.create(PAIR, B, dalpha_deg=da)
        res = traced[True](des, _mis(0.0))
        plain = traced[False](des, _mis(0.0))
        path = res[0]
        mid = path.phi1.shape[0] // 2
        # the working-flank sides in the body frames, from one point of each flank
        r1 = itca.crowned_pinion_flank(des, -1)
        r2 = generated_flank(PAIR.module, PAIR.pressure_angle, 0.0, 0.0, 40, -1)
        cf = _ClosedFormSpur(20, 40, 4.0, 20.0, da, 120.0, (1.0, 1.0))
        sig = []
        for i, (r, uv) in enumerate(((r1, path.uv1[mid]), (r2, path.uv2[mid]))):
            q = np.asarray(r(uv))
            sig.append((np.arctan2(q[1], q[0]) - 0.5 * np.pi) / cf.psi(i, np.hypot(q[0], q[1])))
        np.testing.assert_allclose(np.abs(sig), 1.0, atol=1e-9)   # the closed-form flanks
        cf.sig = tuple(np.sign(sig))
        out[da] = (des, res, plain, cf)
    return out


def _closed_form_te(cf, phi, mid, with_tips=True):
    """Candidates' TE (rad) of pair 0 at the angles ``phi`` (reference: the surface
    contact at phi[mid]), and the envelope over pairs -1, 0, 1 at ``phi``."""
    ph2_ref = cf.candidates(phi[mid])["surface"]
    pitch = 2 * np.pi / 20

    def te(ph1):
        c = cf.candidates(ph1)
        if not with_tips:
            c.pop("gear tip", None), c.pop("pinion tip", None)
        return {k: -np.angle(np.exp(1j * (v - ph2_ref))) - 0.5 * (ph1 - phi[mid])
                for k, v in c.items()}

    pair0 = [te(p) for p in phi]
    env = np.array([max([v for k in (-1, 0, 1) for v in te(p - k * pitch).values()],
                        default=np.nan) for p in phi])
    return pair0, env


@pytest.mark.parametrize("da,tip", [(1.0, "gear tip"), (-1.0, "pinion tip")],
                         ids=["premature", "prolonged"])
def test_tip_contact_under_a_base_pitch_mismatch_matches_the_closed_form(mismatch, da, tip):
    """Pinion base pitch smaller (dalpha > 0): the incoming pair's gear tip hits the
    pinion flank before the line of action (premature contact); larger: the outgoing
    pair's pinion tip stays on the gear flank after it (prolonged contact).  The TCA
    finds that corner contact, at the TE of the closed form, and the envelope over a
    pitch is the closed form's (the sawtooth of the flank contacts alone is not)."""
    des, (path, margin, multi), (_, _, plain), cf = mismatch[da]
    phi = np.asarray(path.phi1)
    n = phi.shape[0]
    mid = n // 2
    pair0, env = _closed_form_te(cf, phi, mid)
    kind = np.asarray(path.edge_kind)
    carried = (np.asarray(margin) >= 0.0) & (kind >= 0)
    assert {EDGE_NAMES[k] for k in kind[carried]} == {tip}
    assert carried.sum() >= 3
    te = np.asarray(path.te)
    for j in np.nonzero(carried)[0]:
        assert abs(te[j] - pair0[j][tip]) / ARCSEC < 1e-6, (j, te[j] / ARCSEC, pair0[j])
    # the corner: the touching point of the tip's member lies on its tip circle
    radial = np.asarray(path.radial2 if tip == "gear tip" else path.radial1)[carried]
    np.testing.assert_allclose(radial, cf.g[1 if tip == "gear tip" else 0]["ra"], atol=1e-9)
    window = np.abs(np.arange(n) - mid) <= 12
    np.testing.assert_allclose(np.asarray(multi.envelope)[window] / ARCSEC,
                               env[window] / ARCSEC, rtol=0, atol=1e-6)
    assert float(multi.ptp) / ARCSEC == pytest.approx(np.ptp(env[window]) / ARCSEC, abs=1e-6)
    # without the tip candidates: the sawtooth of the flank contacts alone
    _, saw = _closed_form_te(cf, phi, mid, with_tips=False)
    np.testing.assert_allclose(np.asarray(plain.envelope)[window] / ARCSEC,
                               saw[window] / ARCSEC, rtol=0, atol=1e-6)
    assert np.max(np.abs(env - saw)[window]) / ARCSEC > 50.0
    res = gj.TCAResult(path, margin, multi, {}, None, "drive", "involute")
    f = res.flags()
    assert f["tip_contact"] and f["edge_contact"] and not f["face_end_contact"]
    assert res.tips_loaded() == [tip]
    assert any(w.startswith(f"tip contact at the {tip}") for w in res.warnings())


def test_tip_contact_te_derivative_matches_central_differences(traced, mismatch):
    """d(TE at a premature gear-tip contact)/d(centre-distance change dE) through the
    implicit derivative of the tip-edge solve, against central differences; the
    derivative of the envelope's peak-to-peak is finite (NaN-free where valid)."""
    des, (path, margin, _), _, _ = mismatch[1.0]
    tip = EDGE_NAMES.index("gear tip")
    j = int(np.nonzero((np.asarray(path.edge_kind) == tip) & (np.asarray(margin) >= 0))[0][1])

    def f(de):
        p, m, mu = traced[True](des, gj.Misalignment(*(jnp.asarray(v, float)
                                                       for v in (de, 0.0, 0.0, 0.0))))
        return p.te[j], p.edge_kind[j], m[j]

    (p0, m0, mu0), (dp, _, dmu) = _d_mis(traced, des, _mis(0.0), (1.0, 0.0, 0.0, 0.0))
    assert int(p0.edge_kind[j]) == tip
    assert np.isfinite(float(dp.te[j])) and np.isfinite(float(dmu.ptp))
    h = 1e-5
    (up, k_up, m_up), (dn, k_dn, m_dn) = f(h), f(-h)
    assert int(k_up) == int(k_dn) == tip and float(m_up) >= 0 and float(m_dn) >= 0
    d_fd = (up - dn) / (2 * h)
    assert abs(float(d_fd)) > 1e-5                       # rad/mm: not a trivial zero
    np.testing.assert_allclose(float(dp.te[j]), float(d_fd), rtol=1e-6)


def test_hypoid_tip_edge_function_is_the_face_cone():
    """The bevel/hypoid tip-edge function is zero on the pinion's face cone (the line
    heel-tip to toe-tip corner of its axial outline, from the blank) and grows into
    the tooth as the normal distance, cos(face angle) per mm of radius; the margins
    give it as the tip part.  (No TCA: the edge system with it is the one above.)"""
    from gearjax.gears.hypoid.pair import hypoid_face_ends
    pair = gj.hypoid.pair_flanks(gj.load_design(gj.example_path("spiral_bevel_10x30_synthesised")),
                          "drive")
    parts, g1, g2, (t1, t2) = hypoid_face_ends(pair)
    corners = gj.hypoid.pinion_outline(pair)["outline"]
    z, r = 0.5 * (corners[2] + corners[3])               # mid face on the face cone
    q = jnp.array([r, 0.0, z])
    assert abs(float(t1(q))) < 1e-9
    d = 0.3
    cos_g = float(np.cos(pair.pinion.blank.face_angle))
    assert float(t1(q - jnp.array([d, 0.0, 0.0]))) == pytest.approx(d * cos_g, rel=1e-12)
    f1, tip1, root1, *_ = parts(q[None] - jnp.array([[d, 0.0, 0.0]]), q[None])
    assert float(tip1[0]) == pytest.approx(d * cos_g, rel=1e-12)
    assert float(f1[0]) > 0 and float(root1[0]) > 0



@pytest.fixture(scope="module")
def bevel_coast():
    d = gj.load_design(gj.example_path("spiral_bevel_10x30_synthesised"))
    return gj.run_tca(d, side="coast", steps_per_pitch=16, half_pitches=1.25, throw=False,
                      kinematics=False)


def test_synthesised_spiral_bevel_coast_edge_contacts_belong_to_pair_0(bevel_coast):
    """The coast side of the shipped synthesised spiral bevel (synthesised for drive:
    its coast bearing runs off the face, the path is face-end contact with hundreds of
    arc-seconds of TE).  The corner and tip-edge solves of tooth pair 0 can converge
    onto the gear turned by whole pitches (a neighbouring gear tooth); those are not
    contacts of pair 0.  Without the half-pitch rule of ``face_end_contact`` this grid
    (16 steps per pitch, under the suite's XLA flags) put a contact 9.45 gear pitches
    (408 400 arcsec) from the reference, and the CLI's 61 positions under the default
    flags read pinion tip/toe and tip/heel corner contacts at TE 37 000 - 44 600
    arcsec, about one pitch (2 pi / z2 = 43 200 arcsec) off (peak-to-peak 6573 arcsec).
    Every contact of the path (a converged point on the flanks or on an edge) lies
    within half a gear pitch of pair 0's reference TE -- independent of the edge
    system: a whole pitch is what such a solve adds --, and the peak-to-peak is that of
    the face-end contacts, a few hundred arc-seconds."""
    r = bevel_coast
    te, kind = np.asarray(r.path.te), np.asarray(r.path.edge_kind)
    used = np.asarray(r.path.converged) & (np.asarray(r.margin) >= 0.0)
    mid = te.size // 2
    half_pitch = np.pi / 30
    assert used[mid] and (kind >= 0).sum() >= 10, kind
    assert np.all(np.abs(te[used] - te[mid]) < half_pitch), te / gj.ARCSEC
    assert float(r.ptp) < 0.1 * half_pitch, float(r.ptp) / gj.ARCSEC


def test_cost_of_the_spiral_bevel_edge_search(bevel_coast):
    """Cost guard (tests/cost_guard.py): the Newton work of this all-edge spiral-bevel
    TCA (surface and the ten edge candidates) against the recorded baseline."""
    check_cost("tca_spiral_bevel_coast_edges", newton_work=int(bevel_coast.path.newton_work))

# -- corners: tip edge x face end under a shaft-angle error ----------------------------
#
# Closed form (independent of the TCA): the pinion is aligned (world = body frame turned
# by phi1 about z, shifted by dP along z), the gear is turned by phi2 about its body z
# and then by dg about the centre line y (right-handed rotation R_y(dg)), its centre at
# (0, a, 0).  A spur tooth's tip edge is the straight line of its flank at radius r_a,
# parallel to its body axis; the transverse flanks are the plane involutes of
# _ClosedFormSpur.  The gear's tip edge touches the pinion flank at a world point W on
# the pinion's involute: one scalar equation in phi2 (brentq), with W at the gear's
# face end (the gear's own corner, body z = e b/2) or at the pinion's face end (world
# z = e b/2 + dP, where the tip edge crosses it); the pinion's tip edge touches the
# gear flank at a gear body point read off directly (explicit in phi2).  Exact in dg
# (no small-angle terms neglected).  The rigid teeth touch at the candidate furthest
# ahead: where the TE of the tip-edge point grows along the face (to first order
# linearly, d TE/dz = +-dg cos(alpha)/r_b2), at one end of the tip edge.

def _rot_y(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _tip_corners(cf, ph1, dg, dP, b, tip):
    """{name: (phi2, valid)} of the tip-edge end candidates of pair 0 at pinion angle
    ``ph1``: the own corners ("gear tip/toe corner", ...), the crossings of the mating
    face ends ("gear tip x pinion toe", ...; EDGE_NAMES calls both the toe/heel corner
    of the tip edge), and the tip edge in the pinion's section z = 0 ("section")."""
    from scipy.optimize import brentq
    g1, g2 = cf.g
    c = np.array([0.0, cf.a, 0.0])
    Ry = _rot_y(dg)
    out = {}
    if tip == "gear tip":
        th = 0.5 * np.pi + cf.sig[1] * cf.psi(1, g2["ra"])
        e2 = np.array([np.cos(th), np.sin(th)]) * g2["ra"]

        def world(ph2, zb):
            cz, sz = np.cos(ph2), np.sin(ph2)
            return c + Ry @ np.array([cz * e2[0] - sz * e2[1], sz * e2[0] + cz * e2[1], zb])

        def on_pinion(W):
            R = np.hypot(W[0], W[1])
            if R <= g1["rb"]:
                return np.nan, R
            return (np.angle(np.exp(1j * (np.arctan2(W[1], W[0]) - ph1 - 0.5 * np.pi
                                          - cf.sig[0] * cf.psi(0, R)))), R)

        def zb_at(ph2, zw):
            # gear body z of the tip-edge point at world z zw: with x' the body x of
            # R_z(phi2) q, W_z = -sin(dg) x' + cos(dg) zb, and W_x = cos(dg) x' at zb = 0
            xp = (world(ph2, 0.0)[0] - c[0]) / np.cos(dg)
            return (zw + np.sin(dg) * xp) / np.cos(dg)

        ph2_0 = cf.candidates(ph1).get("gear tip")
        if ph2_0 is None:
            return out
        cases = {"gear tip/toe corner": ("own", -1), "gear tip/heel corner": ("own", 1),
                 "gear tip x pinion toe": ("cross", -1), "gear tip x pinion heel": ("cross", 1),
                 "section": ("cross", 0)}
        for name, (how, e) in cases.items():
            def zb(ph2):
                return e * 0.5 * b if how == "own" else zb_at(ph2, e * 0.5 * b + dP)

            f = lambda ph2: on_pinion(world(ph2, zb(ph2)))[0]
            lo, hi = ph2_0 - 2e-3, ph2_0 + 2e-3
            if not (np.isfinite(f(lo)) and np.isfinite(f(hi))) or f(lo) * f(hi) > 0:
                continue
            ph2 = brentq(f, lo, hi, xtol=1e-15, rtol=1e-15)
            W = world(ph2, zb(ph2))
            R = on_pinion(W)[1]
            ok = (g1["rF"] <= R <= g1["ra"] and abs(W[2] - dP) <= 0.5 * b + 1e-9
                  and abs(zb(ph2)) <= 0.5 * b + 1e-9)
            out[name] = (ph2, ok)
    else:
        t = ph1 + 0.5 * np.pi + cf.sig[0] * cf.psi(0, g1["ra"])
        xy = g1["ra"] * np.array([np.cos(t), np.sin(t)])
        cases = {"pinion tip/toe corner": ("own", -1), "pinion tip/heel corner": ("own", 1),
                 "pinion tip x gear toe": ("cross", -1), "pinion tip x gear heel": ("cross", 1),
                 "section": ("own", 0)}
        for name, (how, e) in cases.items():
            # gear body point Q = R_z(-phi2) R_y(-dg) (P - c); its z and radius do not
            # depend on phi2
            zp = (e * 0.5 * b + dP if how == "own"
                  else (e * 0.5 * b - np.sin(dg) * xy[0]) / np.cos(dg))   # world z of P
            P = np.array([xy[0], xy[1], zp])
            Q = Ry.T @ (P - c)
            R2 = np.hypot(Q[0], Q[1])
            if R2 <= g2["rb"]:
                continue
            ph2 = np.arctan2(Q[1], Q[0]) - 0.5 * np.pi - cf.sig[1] * cf.psi(1, R2)
            ok = (g2["rF"] <= R2 <= g2["ra"] and abs(Q[2]) <= 0.5 * b + 1e-9
                  and abs(zp - dP) <= 0.5 * b + 1e-9)
            out[name] = (ph2, ok)
    return out


def _corner_name(name):
    """EDGE_NAMES' name of a candidate of _tip_corners (a crossing of the mating face end
    is the tip edge's corner at that end)."""
    if " x " not in name:
        return name
    tip, end = name.split(" x ")
    return f"{tip}/{end.split()[1]} corner"


@pytest.mark.parametrize("da,tip,dg_deg,dP,where", [
    (1.0, "gear tip", 0.1, 0.0, "gear tip/heel corner"),
    (1.0, "gear tip", -0.1, 0.0, "gear tip/toe corner"),
    (1.0, "gear tip", 0.1, -1.0, "gear tip x pinion heel"),
    (-1.0, "pinion tip", 0.1, 0.0, "pinion tip/heel corner"),
    (-1.0, "pinion tip", -0.1, 1.0, "pinion tip/toe corner")],
    ids=["premature+", "premature-", "premature-crossing", "prolonged+", "prolonged-dP"])
def test_tip_corner_under_a_shaft_angle_error_matches_the_closed_form(traced, mismatch, da,
                                                                      tip, dg_deg, dP, where):
    """A base-pitch mismatch (tip contact) and a shaft-angle error dg (the tip edge
    tilted against the mating flank): the tip touches at the leading end of its tip
    edge -- its own corner, or where it crosses the mating face end -- ahead of the
    tip contact in the mid-face section.  The TCA's contact (which candidate, and its
    gear angle) against the closed form above, at every grid point where the tip
    carries the load.  With the pinion shifted axially by dP = -1 mm the gear's
    leading corner lies beyond the pinion's face: the tip edge touches where it crosses
    the pinion's heel (reported as the gear tip's heel corner, at the pinion's heel).  The lead over the tip's point in the mid-face section (the
    contact reported before corners were solved) is close to the line-of-action
    estimate (b/2) dg cos(alpha)/r_b2 = 67.5 arcsec (measured 66.0-69.0: the normal at a
    tip corner is not the line of action), far above the tolerance."""
    des, _, _, cf = mismatch[da]
    dg = np.radians(dg_deg)
    mis = gj.Misalignment(*(jnp.asarray(v, float) for v in (0.0, dP, 0.0, dg)))
    from gearjax.tca.assembly import rotation_about
    np.testing.assert_allclose(np.asarray(rotation_about(jnp.array([0.0, 1.0, 0.0]), dg)),
                               _rot_y(dg), atol=1e-15)         # the closed form's convention
    path, margin, multi = traced[True](des, mis)
    kind = np.asarray(path.edge_kind)
    carried = (np.asarray(margin) >= 0.0) & (kind >= 0)
    names = [EDGE_NAMES[k] for k in kind]
    at_tip = [j for j in np.nonzero(carried)[0] if names[j].startswith(tip)]
    assert len(at_tip) >= 3, [names[j] for j in np.nonzero(carried)[0]]
    assert {names[j] for j in at_tip} == {_corner_name(where)}
    phi1, phi2 = np.asarray(path.phi1), np.asarray(path.phi2)
    lead_first_order = 0.5 * B * dg * np.cos(np.radians(20.0)) / RB2
    errs = []
    for j in at_tip:
        cands = _tip_corners(cf, phi1[j], dg, dP, B, tip)
        valid = {k: v[0] for k, v in cands.items() if v[1] and k != "section"}
        # drive: the gear is turned furthest back (largest TE = smallest phi2 here:
        # TE = -(phi2 - phi2_ref) + ...) by the leading candidate
        lead = min(valid, key=valid.get)
        assert lead == where and names[j] == _corner_name(lead), (j, names[j], valid)
        errs.append(abs(phi2[j] - valid[lead]) / ARCSEC)
        # ahead of the tip edge's point in the mid-face section (the old result)
        ahead = (cands["section"][0] - valid[lead])
        assert 0.9 * abs(lead_first_order) < ahead < 1.1 * abs(lead_first_order)
    assert max(errs) < 1e-6, errs
    # on the face end of the member that bounds it (the tip's own, or the mating one)
    on_pinion = where.startswith("pinion") == (" x " not in where)
    e = 1.0 if where.endswith("heel") or "heel corner" in where else -1.0
    body = np.asarray(path.axial1 if on_pinion else path.axial2)[at_tip]
    np.testing.assert_allclose(body, e * 0.5 * B, atol=1e-9)


# -- VH-CATT tip edges -------------------------------------------------------------------

def _vh_tools(pair):
    """Closed-form cutting data (NumPy) of the drive flanks of the VH-CATT pinion and gear
    of ``pair`` = {"pinion": pair the pinion is cut as, "gear": the seed's pair}
    (NumPy leaves): the blade cones of :func:`~gearjax.gears.vh_catt.geometry.
    envelope_point_np`."""
    from gearjax.gears.vh_catt import geometry as G
    pin, gp = pair["pinion"], pair["gear"]
    k1 = G.tool_data(pin.module, pin.pressure_angle, pin.cutter_radius("pinion"), 17,
                     G.HANDS["pinion"], -1.0, pin.blade_offset, xp=np)   # drive flanks
    k2 = G.tool_data(gp.module, gp.pressure_angle, gp.cutter_radius("gear"), 23,
                     G.HANDS["gear"], -1.0, gp.blade_offset, xp=np)
    return k1, k2


def _vh_u_at_radius(k, R, zz):
    """Blade coordinate u of the closed-form flank point of radius R in section zz
    (SciPy root), bracketed about the middle section's blade coordinate of that radius
    (rack geometry), on the working branch."""
    from scipy.optimize import brentq
    from gearjax.gears.vh_catt import geometry as G
    ca, sa = float(k.cos_a), float(k.sin_a)
    u0 = (np.sqrt(max(R ** 2 - (k.r * ca) ** 2, 0.0)) - k.r * sa) * sa / ca
    f = lambda u: np.hypot(*G.envelope_point_np(k, u, zz)[0][:2]) - R
    return brentq(f, u0 - 1.0, u0 + 1.0, xtol=1e-14, rtol=1e-15)


def _vh_gear_corner(pair, cf, ph1, e):
    """Gear angle (rad) at which the gear's tip corner at face end ``e`` touches the
    pinion flank of the mismatched VH-CATT pair below, and the pinion point's radius
    and section -- from the closed-form envelope of each member
    (:func:`~gearjax.gears.vh_catt.geometry.envelope_point_np`, Willis' condition on
    the rack, NumPy) and scalar root finding (SciPy): the gear corner is the flank
    point of radius r_a2 in the section z = e b/2; turned by phi2 about the gear
    centre, it must lie on the pinion flank in its section: the pinion point of the
    same radius in that section (root in u) has the same polar angle (root in phi2)."""
    from scipy.optimize import brentq
    from gearjax.gears.vh_catt import geometry as G
    k1, k2 = _vh_tools(pair)
    z = e * 0.5 * float(pair["gear"].face_width)
    q2 = G.envelope_point_np(k2, _vh_u_at_radius(k2, cf.g[1]["ra"], z), z)[0]

    def mismatch(ph2):
        c, s_ = np.cos(ph2), np.sin(ph2)
        W = np.array([c * q2[0] - s_ * q2[1], cf.a + s_ * q2[0] + c * q2[1]])
        R = np.hypot(*W)
        q1 = G.envelope_point_np(k1, _vh_u_at_radius(k1, R, z), z)[0]
        return np.angle(np.exp(1j * (np.arctan2(W[1], W[0]) - ph1
                                     - np.arctan2(q1[1], q1[0])))), R

    ph2_0 = cf.candidates(ph1)["gear tip"]
    ph2 = brentq(lambda p: mismatch(p)[0], ph2_0 - 1.5e-3, ph2_0 + 1.5e-3, xtol=1e-15, rtol=1e-15)
    return ph2, mismatch(ph2)[1]


@pytest.fixture(scope="module")
def vh_tip_run():
    """The seed's VH-CATT pair and its TCA with edges (drive side), the pinion cut as the
    pinion of a given pair (e.g. another blade angle: a base-pitch mismatch): one
    compiled program, ``run(pair, pinion_pair, misalignment)``, for every pinion and
    misalignment."""
    from gearjax.gears.vh_catt.tca import MISMATCHED_PINION
    from gearjax.tca.family import tca_parts
    from gearjax.tca.path import DEFAULT_APPROACH
    pair = gj.load_design("example:vh_catt_17x23").pair

    def run(p, q, m):                   # the drive side, edges, tips and corners solved
        return tca_parts(MISMATCHED_PINION, (p, q), m, None, None, jnp.asarray(True),
                         DEFAULT_APPROACH, steps_per_pitch=24, half_pitches=1.25, n_pairs=3,
                         kinematics=False, face_ends=True)[:3]

    return pair, jax.jit(run)


def test_vh_catt_tip_contact_matches_closed_forms(vh_tip_run):
    """VH-CATT: the pinion of the seed's pair (17/23, m = 4 mm, alpha = 20 deg, b = 28 mm,
    R_T = 400 mm, blade offset 3 mm) cut with a blade angle 1 deg larger -- a deliberate
    base-pitch mismatch (the pinion's base pitch is the smaller): premature contact of
    the incoming pair at the gear tip.  Both members are symmetric about the middle
    section, an exact involute pair (the rack-line envelope, tests/test_vh_catt.py), so
    the tip edge's point there is a candidate whose gear angle the plane closed form
    gives (_ClosedFormSpur, x = 0, centre distance r1 + r2); the other sections are not
    involutes, and at the first grid points the gear's tip edge touches first at its
    corners (toe and heel, equal by the symmetry): their gear angle from the closed-form
    envelopes (_vh_gear_corner).  At each grid point where the gear tip carries the
    load, the TCA's contact is the leading one of these candidates, at its gear angle."""
    from dataclasses import replace
    from gearjax.gears.vh_catt.tca import vh_flanks
    pair, run = vh_tip_run
    pin = replace(pair, pressure_angle=pair.pressure_angle + np.radians(1.0))
    path, margin, multi = run(pair, pin, _mis(0.0))
    mid = path.phi1.shape[0] // 2
    cf = _ClosedFormSpur(17, 23, 4.0, 20.0, 1.0, 80.0, (1.0, 1.0))
    sig = []
    r1, r2 = vh_flanks(pair, -1.0, pin)
    for i, (r, uv) in enumerate(((r1, path.uv1[mid]), (r2, path.uv2[mid]))):
        q = np.asarray(r(uv))
        assert abs(q[2]) < 1e-9                              # the middle section
        sig.append((np.arctan2(q[1], q[0]) - 0.5 * np.pi) / cf.psi(i, np.hypot(q[0], q[1])))
    np.testing.assert_allclose(np.abs(sig), 1.0, atol=1e-9)   # the closed-form flanks
    cf.sig = tuple(np.sign(sig))
    kind = np.asarray(path.edge_kind)
    carried = (np.asarray(margin) >= 0.0) & (kind >= 0)
    names = [EDGE_NAMES[k] for k in kind]
    assert {names[j] for j in np.nonzero(carried)[0]} <= {"gear tip", "gear tip/toe corner",
                                                        "gear tip/heel corner"}
    assert carried.sum() >= 3
    phi1, phi2 = np.asarray(path.phi1), np.asarray(path.phi2)
    pn = jax.tree_util.tree_map(np.asarray, {"pinion": pin, "gear": pair})
    errs, seen = [], set()
    for j in np.nonzero(carried)[0]:
        cands = {"gear tip": cf.candidates(phi1[j]).get("gear tip")}
        for e, name in ((-1.0, "gear tip/toe corner"), (1.0, "gear tip/heel corner")):
            ph2, R = _vh_gear_corner(pn, cf, phi1[j], e)
            if cf.g[0]["rF"] <= R <= cf.g[0]["ra"]:          # on the pinion flank
                cands[name] = ph2
        cands = {k: v for k, v in cands.items() if v is not None}
        best = min(cands.values())       # drive: TE = -(phi2 - phi2_ref) + ...: max TE
        lead = {k for k, v in cands.items() if v - best < 1e-6 * ARCSEC}
        assert names[j] in lead, (j, names[j], cands)
        errs.append(abs(phi2[j] - cands[names[j]]) / ARCSEC)
        seen.add(names[j].split("/")[0])
        if names[j] == "gear tip":
            assert abs(float(path.axial2[j])) < 1e-9
    assert max(errs) < 1e-6, errs
    np.testing.assert_allclose(np.asarray(path.radial2)[carried], cf.g[1]["ra"], atol=1e-9)


def _vh_boundaries(z, module, alpha, face_width):
    """Closed-form flank boundaries of a VH-CATT member (rack geometry of the straight
    blade): tip radius ``r + m``; form radius ``sqrt(r_b^2 + rho_F^2)`` of the straight
    blade, ``rho_F = r sin(alpha) - m/sin(alpha)`` the roll distance at which the blade's
    end (depth m below the pitch line) meets the line of action, clipped at the base
    circle where the member is undercut (``rho_F < 0``); half face width."""
    r = 0.5 * z * module
    rb = r * np.cos(alpha)
    rho_f = max(r * np.sin(alpha) - module / np.sin(alpha), 0.0)
    return dict(tip=r + module, root=np.hypot(rb, rho_f), face=0.5 * face_width)


def _rot_z(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@pytest.mark.parametrize("dP,dg_deg", [(0.0, 0.02), (0.0, 0.1), (3.0, 0.0)],
                         ids=["tilt-small", "tilt", "shift"])
def test_vh_catt_edge_contacts_on_both_flanks_and_tangent(vh_tip_run, dP, dg_deg):
    """The seed's VH-CATT pair (17/23: unequal members) with the pinion cut with a blade
    angle 1 deg smaller (base pitch larger: prolonged contact at the pinion tip) under a
    shaft-angle error (the tip contact moves off the middle section; at 0.1 deg the
    bearing also runs onto the heel: face-end edges and corners) or the pinion pushed
    3 mm along its axis (the contact runs along the pinion's toe end, then on its tip
    edge near the toe).  At every grid point where an edge carries the contact, against
    the closed-form boundaries of each member (_vh_boundaries: tip, form circle, face
    width, from the rack; radii and axial positions of the reported body points):

    * both points lie on their flanks (every margin >= 0);
    * the reported margin is the distance to the nearest boundary other than the edge
      itself (a face end's own face end, a tip edge's own tip circle); 0 at a corner,
      which lies on a face end by its equations (face_end_contact's contract) -- with
      unequal members and the bearing off the middle the nearest boundary is now the
      edge point's own form circle or face end, now the mating member's form circle;
    * at a tip-edge contact the two points coincide in the fixed frame and the tip edge
      is tangent to the mating flank: its tangent (central difference along the
      closed-form tip edge, the flank points of radius r_a in neighbouring sections)
      lies in the mating flank's tangent plane (normal from the closed-form envelope's
      partial derivatives) -- where the TE along the tip edge is stationary, the point
      the rigid teeth touch first.

    Same compiled program as test_vh_catt_tip_contact_matches_closed_forms.  Planted
    bugs caught: the edge's own root or face margin taken from the mating member, the
    mating member's root boundary not checked (tip/fillet interference accepted), the
    pinion tip-edge tangency written with the gear's tip gradient."""
    from dataclasses import replace
    from gearjax.gears.vh_catt import geometry as G
    pair, run = vh_tip_run
    pin = replace(pair, pressure_angle=pair.pressure_angle - np.radians(1.0))
    dg = np.radians(dg_deg)
    mis = gj.Misalignment(*(jnp.asarray(v, float) for v in (0.0, dP, 0.0, dg)))
    path, margin, _ = run(pair, pin, mis)
    kind = np.asarray(path.edge_kind)
    mg = np.asarray(margin)
    carried = np.nonzero((mg >= 0.0) & (kind >= 0))[0]
    names = [EDGE_NAMES[k] for k in kind]
    assert len(carried) >= 3 and any(names[j] == "pinion tip" for j in carried)
    b = float(pair.face_width)
    lim = (_vh_boundaries(17, 4.0, float(pin.pressure_angle), b),
           _vh_boundaries(23, 4.0, float(pair.pressure_angle), b))
    radial = (np.asarray(path.radial1), np.asarray(path.radial2))
    axial = (np.asarray(path.axial1), np.asarray(path.axial2))
    pn = jax.tree_util.tree_map(np.asarray, {"pinion": pin, "gear": pair})
    tools = _vh_tools(pn)
    a = 0.5 * (17 + 23) * 4.0
    nearest = set()
    n_tip = 0
    for j in carried:
        own = 0 if names[j].startswith("pinion") else 1
        parts = {}
        for i in (0, 1):
            parts[i, "tip"] = lim[i]["tip"] - radial[i][j]
            parts[i, "root"] = radial[i][j] - lim[i]["root"]
            parts[i, "face"] = lim[i]["face"] - abs(axial[i][j])
        assert min(parts.values()) >= -1e-9, (j, names[j], parts)
        if "corner" in names[j]:
            assert abs(mg[j]) < 2e-8, (j, names[j], mg[j])
            continue
        parts.pop((own, "tip" if names[j].endswith("tip") else "face"))
        key = min(parts, key=parts.get)
        nearest.add(("own " if key[0] == own else "mating ") + key[1])
        assert abs(mg[j] - parts[key]) < 1e-9, (j, names[j], mg[j], parts)
        if not names[j].endswith("tip"):
            continue
        # the tip edge touching the mating flank: a common point, edge tangent in the
        # mating flank's tangent plane (closed-form envelopes, NumPy)
        n_tip += 1
        mate = 1 - own
        k_own, k_mate = tools[own], tools[mate]
        R_tip = lim[own]["tip"]

        def tip_point(zz):
            return G.envelope_point_np(k_own, _vh_u_at_radius(k_own, R_tip, zz), zz)[0]

        def mate_point(u, zz):
            return G.envelope_point_np(k_mate, u, zz)[0]

        q_own = tip_point(axial[own][j])
        u_m = _vh_u_at_radius(k_mate, radial[mate][j], axial[mate][j])
        q_mate = mate_point(u_m, axial[mate][j])
        h = 1e-4
        t = (tip_point(axial[own][j] + h) - tip_point(axial[own][j] - h)) / (2 * h)
        du = (mate_point(u_m + h, axial[mate][j]) - mate_point(u_m - h, axial[mate][j])) / (2 * h)
        dz = (mate_point(u_m, axial[mate][j] + h) - mate_point(u_m, axial[mate][j] - h)) / (2 * h)
        n = np.cross(du, dz)
        # body frames -> fixed frame: pinion turned by phi1 about z (shifted by dP along
        # z), gear turned by phi2 about its axis, then by dg about the centre line y,
        # its centre at (0, a, 0)
        R1 = _rot_z(float(path.phi1[j]))
        R2 = _rot_y(dg) @ _rot_z(float(path.phi2[j]))
        q1, q2 = (q_own, q_mate) if own == 0 else (q_mate, q_own)
        W1 = R1 @ q1 + np.array([0.0, 0.0, dP])
        W2 = np.array([0.0, a, 0.0]) + R2 @ q2
        np.testing.assert_allclose(W1, W2, rtol=0, atol=1e-8)
        Rown, Rmate = (R1, R2) if own == 0 else (R2, R1)
        tw, nw = Rown @ t, Rmate @ n
        cos_tn = np.dot(tw, nw) / (np.linalg.norm(tw) * np.linalg.norm(nw))
        assert abs(cos_tn) < 1e-8, (j, names[j], cos_tn)
    assert n_tip >= 3
    # the cases reach the boundaries the planted bugs confuse
    assert "mating root" in nearest
    if dP:
        assert {"own root", "own face"} <= nearest, nearest


@pytest.mark.parametrize("n, p", [(33, 16), (13, 4), (49, 16), (65, 16), (9, 9), (40, 7)])
def test_neighbour_key_covers_every_whole_pitch_on_the_grid(n, p):
    """The neighbouring pairs' key at grid point i is the largest key at i + k p,
    k = +-1, +-2, ... on the grid (pair 0 shifted by whole pitches), by brute force over
    the grid.  Catches a loop over k that stops a pitch short: with a contact ratio
    above 2 (or at the grid's ends, where only the far neighbour is on the grid) pair
    0's edge contact would be compared with too few neighbours and kept behind a pair
    that carries the load."""
    from gearjax.tca.edge_contact import neighbour_key
    key = np.random.default_rng(n * 100 + p).normal(size=n)
    got = np.asarray(neighbour_key(jnp.asarray(key), p))
    want = np.array([max([key[j] for j in range(n) if j != i and (j - i) % p == 0],
                         default=-np.inf) for i in range(n)])
    np.testing.assert_array_equal(got, want)
    # a key that only the farthest whole pitch reaches is seen at the grid's first point
    far = (n - 1) // p * p
    if far > 0:
        only = np.full(n, -1.0)
        only[far] = 5.0
        assert float(neighbour_key(jnp.asarray(only), p)[0]) == 5.0


@pytest.mark.parametrize("drive", [True, False])
def test_corner_leads_only_where_the_te_falls_both_ways(drive):
    """A corner is the contact only where the TE at the flank points beside it falls
    (in the sense of the load) along the tip edge *and* down the profile; a corner
    with one slope falling and the other rising is not (the rising side's flank point
    would be through the mating flank first).  Rule by cases, both sides (the sense
    of the load flips the signs)."""
    from gearjax.tca.corners import CORNER_SLOPE_TOL, corner_leads
    s = 1.0 if drive else -1.0
    slopes = s * jnp.array([[-1e-3, -2e-3],     # falls both ways: leads
                            [-1e-3, 0.0],       # falls and level: leads
                            [-1e-3, 2e-3],      # mixed: not
                            [3e-3, -1e-3],      # mixed the other way: not
                            [1e-3, 1e-3],       # rises both ways: not
                            [0.5 * CORNER_SLOPE_TOL, -1.0]])   # level within tol: leads
    got = np.asarray(corner_leads(slopes, jnp.asarray(drive)))
    np.testing.assert_array_equal(got, [True, True, False, False, False, True])


# --------------------------------------------------------------------------------------
# the one-lane continuation (both directions in one scan) against two separate scans


def _lane_system(z, th):
    phi, s = th
    return jnp.stack([z[0] + 0.3 * z[0] ** 3 + 0.1 * z[1] - phi - s,
                      z[1] + 0.2 * jnp.sin(z[0]) - 0.5 * phi])


@pytest.mark.parametrize("i0", [0, 3, 8])
def test_one_lane_continuation_equals_two_directions(i0):
    """An edge candidate runs the homotopy at grid point ``i0``, the steps to the grid's
    end, then from the homotopy's end back to the grid's start, in one scan
    (``_continue`` with ``restart``).  Each half must be exactly the continuation of
    that direction alone (the homotopy, then a constant predictor at its first angle
    step, then the linear predictor of its own two previous solutions): solutions,
    Newton step counts, flags and residuals bit-identical, for a start inside the grid
    and at either end."""
    from gearjax.tca.edge_contact import _continue
    n, k = 9, 4
    phis = np.linspace(-1.0, 1.0, n)
    levels = np.linspace(1.0, 0.0, k + 1)[1:]
    z0 = jnp.asarray([0.0, 0.0])          # F(z0, (phi, 1)) != 0: the homotopy works

    def run(cols, turn=None):
        # as face_end_contact lays it out: a constant predictor at the first angle
        # step and at the turn, the restart from the homotopy's end at the turn
        m = len(cols)
        th = (jnp.asarray(np.concatenate([np.full(k, phis[i0]), phis[cols]])),
              jnp.asarray(np.concatenate([levels, np.zeros(m)])))
        steps = np.arange(m)
        fresh = steps == 0
        restart = np.zeros(m, bool)
        if turn is not None:
            fresh = fresh | (steps == turn)
            restart = (steps == turn) & (steps > 0)
        pad = np.zeros(k, bool)
        return _continue(_lane_system, z0, th, jnp.asarray(np.concatenate([pad, fresh])),
                         jnp.asarray(np.concatenate([pad, restart])), k, 1e-11, 30)

    fwd = list(range(i0 + 1, n))
    bwd = list(range(i0 - 1, -1, -1))
    both = run(fwd + bwd, turn=len(fwd))
    alone_f, alone_b = run(fwd), run(bwd)
    nf = k + len(fwd)
    for field in ("x", "steps", "converged", "residual"):
        a = np.asarray(getattr(both, field))
        np.testing.assert_array_equal(a[:nf], np.asarray(getattr(alone_f, field)))
        np.testing.assert_array_equal(a[nf:], np.asarray(getattr(alone_b, field))[k:])
    assert bool(np.all(np.asarray(both.converged)))
