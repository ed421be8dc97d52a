"""Edge contact at the face ends (gearjax.edge_contact) against closed forms.

Reference: a spur pair whose gear axis is turned by a small angle dg about the
centre line (``dSigma``, crossed axes).  A gear point at axial position z moves by
``dg (z, 0, -x)`` (rotation about the y axis through the gear axis); along the
transverse profile normal ``n = (+-cos aw, sin aw, 0)`` (the line of action) that is
``dg z cos aw``.  The profile section at z therefore touches at
``TE(z) = TE(0) +- dg z cos aw / r_b2`` to first order in dg: linear across the face,
so the uncrowned pair touches at the face end that leads, ahead of the mid-face
section by ``(b/2) dg cos aw / r_b2`` (Litvin & Fuentes, Gear Geometry and Applied
Theory, ch. 15: a crossing of the axes of unmodified gears gives edge contact).
"""

import json

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax import ARCSEC
from gearjax.cli import main
from gearjax.edge_contact import EDGE_NAMES
from gearjax.gears.involute import tca as itca

B = 30.0
PAIR = gj.InvolutePair.create(20, 40, 4.0, 20.0, 0.0, 0.0, 0.0)
SPUR = gj.InvoluteTCA.create(PAIR, B)
DG = np.radians(0.05)
RB2 = 0.5 * 40 * 4.0 * np.cos(np.radians(20.0))
LEAD = 0.5 * B * DG * np.cos(np.radians(20.0)) / RB2      # rad, edge ahead of mid-face


@pytest.fixture(scope="module")
def traced():
    """The involute TCA (drive side, line contact) with and without face ends: one
    compiled program each."""
    run = {fe: jax.jit(lambda d, m, fe=fe: itca.involute_tca_traced(d, m, side=-1,
                                                                  face_ends=fe))
           for fe in (True, False)}
    return run


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


def test_the_other_crossing_sense_loads_the_other_end(traced):
    ends = {}
    for sign in (1.0, -1.0):
        path, margin, _ = traced[True](SPUR, _mis(sign * DG))
        kind = np.asarray(path.edge_kind)
        carried = (np.asarray(margin) >= 0.0) & (kind >= 0)
        ends[sign] = {EDGE_NAMES[k].split()[1] for k in kind[carried]}
    assert ends[1.0] == {"heel"} and ends[-1.0] == {"toe"} or \
        ends[1.0] == {"toe"} and ends[-1.0] == {"heel"}, ends


HELICAL = gj.InvoluteTCA.create(gj.InvolutePair.create(20, 40, 4.0, 20.0, 15.0, 0.2, 0.0), B)


@pytest.mark.parametrize("des", [SPUR, HELICAL], ids=["spur", "helical"])
def test_aligned_conjugate_pair_has_no_edge_contact_and_is_unchanged(traced, des):
    """A conjugate pair touches along lines across the whole face: no edge contact.  For
    the helical pair the face ends stay on the flanks after the solved mid-face section
    has left them -- those face-end points lie on its contact line (same TE)."""
    mis = _mis(0.0)
    path, margin, multi = traced[True](des, mis)
    ref, ref_margin, ref_multi = traced[False](des, mis)
    assert np.all(np.asarray(path.edge_kind) == -1)
    np.testing.assert_array_equal(np.asarray(path.te), np.asarray(ref.te))
    np.testing.assert_array_equal(np.asarray(margin), np.asarray(ref_margin))
    assert float(multi.contact_ratio) == float(ref_multi.contact_ratio)


def test_edge_te_derivative_matches_closed_form_and_differences(traced):
    """d(TE at an edge contact)/d(crossing angle) by the implicit derivative of the
    edge-contact solve, against central differences and the closed form."""
    def te_mid(dg):
        path, _, _ = traced[True](SPUR, _mis(dg))
        sec, _, _ = traced[False](SPUR, _mis(dg))
        mid = path.te.shape[0] // 2
        return path.te[mid] - sec.te[mid], path.edge_kind[mid]

    val, kind = te_mid(DG)
    assert int(kind) >= 0
    d_ad = jax.jacfwd(lambda g: te_mid(g)[0])(jnp.asarray(DG))
    h = 1e-6
    d_fd = (te_mid(DG + h)[0] - te_mid(DG - h)[0]) / (2 * h)
    assert np.isfinite(float(d_ad))
    np.testing.assert_allclose(float(d_ad), float(d_fd), rtol=1e-5)
    np.testing.assert_allclose(float(d_ad), LEAD / DG, rtol=2e-3)


def test_crowned_pinion_keeps_its_bearing_inside_and_a_large_crossing_is_flagged():
    helical = gj.InvolutePair.create(20, 40, 4.0, 20.0, 15.0, 0.2, 0.0)
    crowned = gj.InvoluteTCA.create(helical, B, 0.0, 0.0, 2e-4)
    small = gj.run_tca(crowned, gj.Misalignment.create(dSigma_deg=0.05), strict=False)
    assert not small.flags()["face_end_contact"]
    assert small.face_ends_loaded() == []
    big = gj.run_tca(crowned, gj.Misalignment.create(dSigma_deg=0.5), strict=False)
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
