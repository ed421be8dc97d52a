"""``gearjax tca`` and ``gearjax efficiency`` of involute designs with ``[microgeometry]``
tables: the line-contact TCA (:func:`gearjax.involute.line_tca`) and the line-contact
efficiency, against closed forms and second routes through the same model.

Kept cheap: 8 or 16 positions, a few slices, and each compiled program shared by the
tests that need it (module fixtures).  Each test's docstring names the planted bug it
catches."""

import math
import re

import numpy as np
import pytest

import gearjax as gj
from gearjax.commands.line_efficiency import LINE_EFFICIENCY_KEYS_DOC
from gearjax.commands.line_tca import LINE_TCA_KEYS_DOC
from cli_call import cli_call
from strict_json import strict_json

EXAMPLE = "example:helical_microgeometry"
UNMODIFIED = "example:helical_23x67_unmodified"
SMALL = ["--positions", "8", "--slices", "6"]
LUBE = ["--rpm", "1500", "--oil", "mineral_vg100", "--sigma-um", "0.4"]
SPUR = "involute:z1=20,z2=40,m=4,alpha=20,b=30"
#: the spur pair of the closed form: linear pinion tip relief C_a from roll length xi_s
C_A = 8.0


_call = cli_call


def _keys(doc, indent="  "):
    return [m.group(1) for line in doc.splitlines()[1:]
            if (m := re.match(rf"{indent}(\w+)\s", line))]


@pytest.fixture(scope="module")
def tca_run(tmp_path_factory):
    """The one `gearjax tca` run of the micro-geometry example, with two torques."""
    png = tmp_path_factory.mktemp("tca") / "t.png"
    rc, out, err = _call(["tca", EXAMPLE, *SMALL, "--torque-Nm", "50,200", "--json",
                          "--plot", str(png)])
    return rc, out, err, png


@pytest.fixture(scope="module")
def eff_run(tmp_path_factory):
    """The one `gearjax efficiency` run of the micro-geometry example (two torques)."""
    png = tmp_path_factory.mktemp("eff") / "e.png"
    rc, out, err = _call(["efficiency", EXAMPLE, "--torque-Nm", "50,200", *LUBE, *SMALL,
                          "--json", "--plot", str(png)])
    return rc, out, err, png


def test_tca_json_keys_documented_strict_and_plot(tca_run):
    """Catches: a JSON key missing from (or extra to) the epilog, NaN/inf in the JSON, a
    warning on a clean run, a figure not written."""
    rc, out, err, png = tca_run
    assert rc == 0 and err == "", err
    data = strict_json(out)
    assert set(data) == set(_keys(LINE_TCA_KEYS_DOC))
    assert data["model"] == "line contact" and data["plot"] == str(png)
    assert png.exists() and png.stat().st_size > 10_000
    assert set(data["loaded"]) == {"torque_Nm", "te_loaded_um", "te_ptp_um", "te_mean_um",
                                   "p_max_MPa", "k_hbeta", "converged"}


def test_tca_json_is_the_library_result(tca_run):
    """Catches: the command printing another side, resolution or torque than asked, or
    converting the TE to arcsec with the pinion's base radius (the angle is of the gear,
    te / r_b2)."""
    data = strict_json(tca_run[1])
    design = gj.load_design(EXAMPLE)
    r = gj.involute.line_tca(design, torques_Nm=[50.0, 200.0], positions=8, slices=6)
    np.testing.assert_allclose(data["te_um"], np.asarray(r.te_um), rtol=0, atol=1e-12)
    np.testing.assert_allclose(data["loaded"]["te_ptp_um"], np.asarray(r.te_loaded_ptp_um),
                               rtol=1e-12)
    rb2 = float(gj.involute.pair_geometry(design.design.pair)["rb2"])
    np.testing.assert_allclose(np.asarray(data["te_arcsec"]),
                               1e-3 * np.asarray(data["te_um"]) / rb2 / gj.ARCSEC, rtol=1e-12)
    assert len(data["phi1_rad"]) == 8 and data["input"]["slices"] == 6
    assert data["modifications"]["pinion"]["tip_relief"] > 0.0


def test_tca_loaded_te_is_the_efficiency_route(tca_run, eff_run):
    """Catches: the tca command's loaded TE computed at another torque (N m taken as N
    mm) or misalignment than the efficiency route of the same model."""
    t, e = strict_json(tca_run[1]), strict_json(eff_run[1])
    np.testing.assert_allclose(t["loaded"]["te_ptp_um"], e["te_loaded_ptp_um"], rtol=1e-9)
    np.testing.assert_allclose(t["loaded"]["p_max_MPa"], e["p_max_MPa"], rtol=1e-9)
    np.testing.assert_allclose(t["loaded"]["te_mean_um"], e["te_loaded_mean_um"], rtol=1e-9)


def test_tca_table_matches_the_json(tca_run, capsys):
    """Catches: a table printing other numbers than the JSON (a swapped column)."""
    rc, text, err = _call(["tca", EXAMPLE, *SMALL, "--torque-Nm", "50,200"])
    assert rc == 0
    data = strict_json(tca_run[1])
    rows = [ln.split() for ln in text.splitlines() if not ln.startswith("#")]
    body = [r for r in rows if re.match(r"^-?\d", r[0])]
    assert len(body) == 8 + 2
    for i, r in enumerate(body[:8]):
        assert float(r[1]) == pytest.approx(data["te_um"][i], abs=1e-4)
        assert int(r[3]) == data["pairs_in_contact"][i]
    assert float(body[9][1]) == pytest.approx(data["loaded"]["te_ptp_um"][1], abs=1e-4)
    assert f"{data['ptp_um']:.4f} um" in text


def test_tca_both_sides_json(tca_run):
    """Catches: --side both printing one side twice (the coast flanks' tables ignored)
    or its objects not under "drive" and "coast"."""
    rc, out, err = _call(["tca", EXAMPLE, *SMALL, "--side", "both", "--json"])
    assert rc == 0, err
    data = strict_json(out)
    side_keys = set(_keys(LINE_TCA_KEYS_DOC)) - {"input", "warnings", "plot"}
    assert set(data) == {"input", "drive", "coast", "warnings", "plot"}
    assert set(data["drive"]) == side_keys == set(data["coast"])
    assert data["drive"]["te_um"] == strict_json(tca_run[1])["te_um"]
    r = gj.involute.line_tca(gj.load_design(EXAMPLE), side="coast", positions=8, slices=6)
    np.testing.assert_allclose(data["coast"]["te_um"], np.asarray(r.te_um), atol=1e-12)
    assert data["coast"]["modifications"] == data["drive"]["modifications"]


# ------------------------------------------------------- (a) an unmodified pair: conjugate

def test_unmodified_tables_give_zero_te_as_the_point_contact_tca():
    """Catches: a non-zero separation of zero amounts (a relief applied without its
    amount, the misalignment's sign), a wrong count of touching pairs; and the
    point-contact TCA of the same pair without the table disagreeing (TE 0)."""
    rc, out, err = _call(["tca", UNMODIFIED, "--positions", "16", "--slices", "6", "--json"])
    assert rc == 0, err
    data = strict_json(out)
    assert data["ptp_um"] == 0.0 and data["ptp_arcsec"] == 0.0
    assert all(v == 0.0 for v in data["te_um"])
    eps = data["contact_ratio"] + data["overlap_ratio"]
    assert data["contact_ratio_zero_load"] == pytest.approx(eps, abs=4.0 / 16)
    # ISO 21771: eps_beta = b sin(beta) / (pi m_n) (= b tan(beta_b) / p_bt)
    pair = gj.load_design(UNMODIFIED).design.pair
    assert data["overlap_ratio"] == pytest.approx(
        30.0 * math.sin(float(pair.helix)) / (math.pi * float(pair.module)), rel=1e-12)
    res = gj.run_tca(gj.load_design(UNMODIFIED).design)
    assert float(res.multi.ptp) / gj.ARCSEC < 1e-6
    assert float(res.multi.contact_ratio) == pytest.approx(data["contact_ratio"], rel=1e-9)


# ------------------------------------------------------- (b) the closed form of a tip relief

def _spur_design(tmp_path, length):
    path = tmp_path / "spur_relief.toml"
    path.write_text(
        '[design]\nkind = "involute"\nname = "spur_relief"\n\n[pair]\nz1 = 20\nz2 = 40\n'
        'normal_module_mm = 4.0\nnormal_pressure_angle_deg = 20.0\nhelix_angle_deg = 0.0\n'
        'face_width_mm = 30.0\n\n[microgeometry.pinion]\n'
        f'tip_relief_um = {C_A}\ntip_relief_length_mm = {length!r}\n'
        'tip_relief_shape = "linear"\n')
    return str(path)


@pytest.fixture(scope="module")
def spur(tmp_path_factory):
    """The spur design file with the tip relief, its geometry and the relief start."""
    d = tmp_path_factory.mktemp("spur")
    probe = gj.load_design(_spur_design(d, 1.0))
    geo = gj.involute.pair_geometry(probe.design.pair)
    rho_A, rho_E, rho_P = (float(geo[k]) for k in ("rho_A", "rho_E", "rho_P"))
    p_bt = 2.0 * math.pi * float(geo["rb1"]) / 20
    eps = (rho_E - rho_A) / p_bt
    assert 1.2 < eps < 1.9
    # the lower pair is alone on the path for s - s_A in ((eps - 1) p_bt, p_bt)
    xi_s = rho_A + 0.5 * eps * p_bt
    path = _spur_design(d, rho_E - xi_s)
    return path, dict(rho_A=rho_A, rho_E=rho_E, rho_P=rho_P, p_bt=p_bt, xi_s=xi_s,
                      rb1=float(geo["rb1"]), rb2=float(geo["rb2"]), eps=eps)


TIE_MM = 1e-9      # mm: round-off between two routes to s_A, far below a position step


def _closed_form(s0, g):
    """TE0(s0) = C_a max((rho_P + s_low - xi_s) / L_a, 0), s_low = s_A + mod(s0 - s_A,
    p_bt): the lowest pair on the path has the least relief.  The first position is the
    path's start s_A itself (a pair there touches); this s_A and the library's differ by
    round-off (1e-15 mm, by machine), so a position less than TIE_MM short of a whole
    number of pitches from s_A counts as at it."""
    s_A = g["rho_A"] - g["rho_P"]
    s_low = s_A + np.mod(np.asarray(s0) - s_A + TIE_MM, g["p_bt"]) - TIE_MM
    L_a = g["rho_E"] - g["xi_s"]
    return C_A * np.maximum((g["rho_P"] + s_low - g["xi_s"]) / L_a, 0.0)


def test_tip_relief_closed_form_library(spur):
    """Catches: the unloaded TE taken as the largest separation (max instead of min),
    the relief measured from the wrong end of the profile or on the gear, the pinion
    angle of a position (phi1 = s0 / r_b1) and the first contact point misplaced."""
    path, g = spur
    r = gj.involute.line_tca(gj.load_design(path), positions=16, slices=4)
    s0 = np.asarray(r.s0_mm)
    want = _closed_form(s0, g)
    np.testing.assert_allclose(np.asarray(r.te_um), want, rtol=0, atol=1e-9)
    assert want.max() > 1.0 and (want == 0.0).sum() >= 4    # both parts of the cycle
    assert float(r.ptp_um) == pytest.approx(want.max() - want.min(), abs=1e-9)
    # the first contact: the lowest pair (pair 0 at s0 in one base pitch from s_A)
    np.testing.assert_allclose(np.asarray(r.first_xi1_mm), g["rho_P"] + s0, atol=1e-9)
    # its radius on the pinion: the involute's r = sqrt(r_b1^2 + xi1^2)
    np.testing.assert_allclose(np.asarray(r.first_r1_mm), np.hypot(g["rb1"], g["rho_P"] + s0),
                               rtol=1e-12)
    assert set(np.asarray(r.first_pair).tolist()) == {0}
    # where the lower pair is alone, one pair touches; where two are on the path below
    # the relief, only the lower one touches (the upper is relieved)
    assert set(np.asarray(r.pairs_in_contact).tolist()) == {1}


def test_tip_relief_closed_form_through_the_json(spur):
    """Catches: the command dropping the design file's relief (or reading its length in
    other units), and the arcsec column of another radius."""
    path, g = spur
    rc, out, err = _call(["tca", path, "--positions", "16", "--slices", "4", "--json"])
    assert rc == 0, err
    data = strict_json(out)
    want = _closed_form(np.asarray(data["s0_mm"]), g)
    np.testing.assert_allclose(data["te_um"], want, rtol=0, atol=1e-9)
    np.testing.assert_allclose(data["te_arcsec"], 1e-3 * want / g["rb2"] / gj.ARCSEC,
                               rtol=0, atol=1e-8)
    assert data["modifications"]["pinion"]["tip_relief"] == C_A


def test_unmodified_spur_pairs_in_contact_is_eps_alpha(spur, tmp_path):
    """Catches: the count of pairs touching at zero load counting pairs off the path or
    only one pair per position (an unmodified spur pair has 2 in the double zone)."""
    path, g = spur
    d = gj.load_design(path)
    r = gj.involute.line_tca(d, positions=16, slices=4,
                             mods=gj.involute.PairModification.none())
    n = np.asarray(r.pairs_in_contact)
    s = np.asarray(r.s0_mm) - (g["rho_A"] - g["rho_P"])
    np.testing.assert_array_equal(n, np.where(s <= (g["eps"] - 1.0) * g["p_bt"] + 1e-12, 2, 1))
    assert float(r.ptp_um) == 0.0


# ------------------------------------------------------- (c) efficiency: three routes

def test_efficiency_json_keys_documented_and_plot(eff_run):
    """Catches: an undocumented or missing JSON key, NaN in the JSON, no figure."""
    rc, out, err, png = eff_run
    assert rc == 0 and err == "", err
    data = strict_json(out)
    assert set(data) == set(_keys(LINE_EFFICIENCY_KEYS_DOC))
    assert png.exists() and png.stat().st_size > 10_000
    assert data["torque_Nm"] == [50.0, 200.0] and all(data["converged"])


def test_efficiency_equals_loaded_rpm_and_the_library_map(eff_run):
    """Catches: the efficiency route computing at another speed, oil, side or resolution
    than `gearjax loaded --rpm` and loaded_te_map (the same model by two routes), or a
    power input of another unit (P_in = T omega)."""
    e = strict_json(eff_run[1])
    rc, out, err = _call(["loaded", EXAMPLE, "--torque-Nm", "50,200", *LUBE, *SMALL, "--json"])
    assert rc == 0, err
    ld = strict_json(out)
    col = lambda k: [row[0] for row in ld[k]]  # noqa: E731
    for ek, lk in (("power_loss_W", "power_loss_W"), ("efficiency", "efficiency"),
                   ("p_max_MPa", "p_max_MPa"), ("te_loaded_ptp_um", "te_ptp_um"),
                   ("te_loaded_mean_um", "te_mean_um"), ("k_hbeta", "k_hbeta"),
                   ("te_unloaded_ptp_um", "te_unloaded_ptp_um"),
                   ("end_load_ratio", "end_load_ratio")):
        np.testing.assert_allclose(e[ek], col(lk), rtol=1e-12, err_msg=ek)
    surf = gj.tribology.make_surface(0.4, 1e4, 10.0, 0.1)
    m = gj.involute.loaded_te_map(gj.load_design(EXAMPLE), [50.0, 200.0], [0.0],
                                  positions=8, slices=6, pinion_rpm=1500.0,
                                  oil=gj.tribology.get_oil("mineral_vg100"), surface=surf)
    for ek, v in (("efficiency", m.efficiency), ("power_loss_W", m.power_loss_W),
                  ("p_max_MPa", m.p_max), ("te_loaded_ptp_um", m.te_ptp_um)):
        np.testing.assert_allclose(e[ek], np.asarray(v)[:, 0], rtol=1e-12, err_msg=ek)
    np.testing.assert_allclose(e["power_in_W"],
                               np.array([50.0, 200.0]) * 1500.0 * math.pi / 30.0, rtol=1e-12)
    assert 0.9 < min(e["efficiency"]) < 1.0


def test_efficiency_table_prints_the_json_numbers(eff_run):
    """Catches: the table's rows of another torque or column order than the JSON."""
    e = strict_json(eff_run[1])
    rc, text, err = _call(["efficiency", EXAMPLE, "--torque-Nm", "50,200", *LUBE, *SMALL])
    assert rc == 0, err
    rows = [ln.split() for ln in text.splitlines() if not ln.startswith("#")][1:]
    assert len(rows) == 2
    for i, r in enumerate(rows):
        assert float(r[0]) == e["torque_Nm"][i]
        assert float(r[2]) == pytest.approx(e["power_loss_W"][i], abs=1e-3)
        assert float(r[3]) == pytest.approx(100 * e["efficiency"][i], abs=1e-4)
        assert float(r[5]) == pytest.approx(e["te_loaded_ptp_um"][i], abs=1e-4)


def test_unmodified_helical_pair_goes_to_the_line_contact(monkeypatch):
    """Catches: an unmodified helical pair in line contact still refused (or sent to the
    point-contact chain) by `gearjax efficiency`."""
    called = {}

    def fake(design, torques, *a, **k):
        called["torques"] = list(torques)
        raise ValueError("stop here")

    monkeypatch.setattr(gj.involute, "loaded_te_map", fake)
    rc, _, err = _call(["efficiency", SPUR + ",helix=15", "--torque-Nm", "100:300:3", *LUBE])
    assert rc == 2 and "stop here" in err
    assert called["torques"] == [100.0, 200.0, 300.0]


# ------------------------------------------------------- (d) bad input, before any work

def _no_work(monkeypatch):
    for name in ("line_tca", "loaded_te_map"):
        monkeypatch.setattr(gj.involute, name, lambda *a, **k: pytest.fail("work started"))
    monkeypatch.setattr(gj, "run_tca", lambda *a, **k: pytest.fail("work started"))
    monkeypatch.setattr(gj, "mesh_efficiency", lambda *a, **k: pytest.fail("work started"))


EFF = ["efficiency", EXAMPLE, *LUBE]


@pytest.mark.parametrize("argv, needle", [
    (["tca", EXAMPLE, "--misalign", "dE=0.1"], "--misalign"),
    (["tca", EXAMPLE, "--pitches", "2"], "--pitches"),
    (["tca", EXAMPLE, "--kinematics"], "--kinematics"),
    (["tca", EXAMPLE, "--torque-Nm", "50:200:0"], "COUNT"),
    (["tca", EXAMPLE, "--torque-Nm", "0"], "--torque-Nm"),
    (["tca", EXAMPLE, "--torque-Nm", "1e9"], "--torque-Nm"),
    (["tca", EXAMPLE, "--torque-Nm", "50:200"], "--torque-Nm"),
    (["tca", EXAMPLE, "--positions", "2"], "--positions"),
    (["tca", EXAMPLE, "--slices", "0"], "--slices"),
    (["tca", EXAMPLE, "--misalignment-um", "5000"], "--misalignment-um"),
    (["tca", EXAMPLE, "--plot", "t.txt"], "--plot"),
    (["tca", SPUR, "--torque-Nm", "100"], "--torque-Nm"),
    (["tca", SPUR, "--slices", "4"], "--slices"),
    ([*EFF, "--torque-Nm", "50:200:0"], "COUNT"),
    ([*EFF, "--torque-Nm", "2e6"], "--torque-Nm"),
    ([*EFF, "--torque-Nm", "50,50"], "--torque-Nm"),
    ([*EFF, "--torque-Nm", "100", "--misalign", "dE=0.1"], "--misalign"),
    ([*EFF, "--torque-Nm", "100", "--pitches", "2"], "--pitches"),
    ([*EFF, "--torque-Nm", "100", "--pairs", "3"], "--pairs"),
    ([*EFF, "--torque-Nm", "100", "--E-prime-MPa", "2e5"], "--E-prime-MPa"),
    ([*EFF, "--torque-Nm", "100", "--ehl-check", "3"], "--ehl-check"),
    ([*EFF, "--torque-Nm", "100", "--slices", "500"], "--slices"),
    (["efficiency", SPUR, *LUBE, "--torque-Nm", "50,100"], "--torque-Nm"),
    (["efficiency", SPUR, *LUBE, "--torque-Nm", "100", "--slices", "6"], "--slices"),
    (["efficiency", SPUR, *LUBE, "--torque-Nm", "abc"], "--torque-Nm"),
])
def test_bad_input_refused_in_one_line_before_any_work(argv, needle, monkeypatch):
    """Catches: a point-contact option silently ignored by the line contact (or a line
    option by the point-contact chain), a torque range of COUNT 0 or out of range
    reaching the program, a traceback, or a message that does not name the option."""
    _no_work(monkeypatch)
    rc, text, err = _call(argv)
    assert rc == 2 and text == "", (argv, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("gearjax: error:") and needle in err, err


# ------------------------------------------------------- the coupling along the face

def test_coupling_length_reaches_the_tca_and_efficiency_routes():
    """``--coupling-length-mm`` of the two commands' line routes against
    ``loaded_te_map`` with the same coupling (the library route of `gearjax loaded`);
    ``module`` is the design's normal module; the unloaded TE does not depend on it.
    Catches: the option parsed but not passed to the model (the Winkler numbers, which
    differ here), ``module`` resolved to another length, the unloaded TE coupled."""
    design = gj.load_design(EXAMPLE)
    lam = gj.involute.module_coupling_length(design)
    assert lam == pytest.approx(float(design.design.pair.module))
    rc, out, err = _call(["tca", EXAMPLE, *SMALL, "--torque-Nm", "200", "--coupling-length-mm",
                          "module", "--json"])
    assert rc == 0, err
    t = strict_json(out)
    assert t["input"]["coupling_length_mm"] == lam
    assert sum("coupled along the face" in w for w in t["warnings"]) == 1
    m = gj.involute.loaded_te_map(design, [200.0], [0.0], positions=8, slices=6,
                                  coupling_length_mm=lam)
    w = gj.involute.loaded_te_map(design, [200.0], [0.0], positions=8, slices=6)
    np.testing.assert_allclose(t["loaded"]["te_ptp_um"], np.asarray(m.te_ptp_um)[:, 0],
                               rtol=1e-9)
    np.testing.assert_allclose(t["loaded"]["p_max_MPa"], np.asarray(m.p_max)[:, 0], rtol=1e-9)
    assert abs(float(m.p_max[0, 0]) - float(w.p_max[0, 0])) > 1.0     # the coupling acts
    r = gj.involute.line_tca(design, positions=8, slices=6)
    np.testing.assert_allclose(t["te_um"], np.asarray(r.te_um), atol=1e-12)
    # the compliance model of the loaded TE
    rc, out, err = _call(["tca", EXAMPLE, *SMALL, "--torque-Nm", "200", "--compliance",
                          "iso6336", "--json"])
    assert rc == 0, err
    iso = gj.involute.loaded_te_map(design, [200.0], [0.0], positions=8, slices=6,
                                    compliance="iso6336")
    assert strict_json(out)["input"]["compliance"] == "iso6336"
    assert strict_json(out)["loaded"]["te_ptp_um"][0] == pytest.approx(
        float(iso.te_ptp_um[0, 0]), rel=1e-9)
    assert abs(float(iso.te_mean_um[0, 0]) - float(w.te_mean_um[0, 0])) > 1e-3
    rc, out, err = _call(["efficiency", EXAMPLE, "--torque-Nm", "200", *LUBE, *SMALL,
                          "--coupling-length-mm", "2.5", "--json"])
    assert rc == 0, err
    e = strict_json(out)
    assert e["input"]["coupling_length_mm"] == 2.5
    rc, out, err = _call(["loaded", EXAMPLE, "--torque-Nm", "200", *LUBE, *SMALL,
                          "--coupling-length-mm", "2.5", "--json"])
    assert rc == 0, err
    ld = strict_json(out)
    assert e["power_loss_W"][0] == pytest.approx(ld["power_loss_W"][0][0], rel=1e-12)
    assert e["p_max_MPa"][0] == pytest.approx(ld["p_max_MPa"][0][0], rel=1e-12)


@pytest.mark.parametrize("argv, match", [
    (["tca", "example:khk_spur_12x24", "--coupling-length-mm", "2"], "--coupling-length-mm = 2"),
    (["tca", "example:khk_spur_12x24", "--compliance", "iso6336"], "--compliance = iso6336"),
    (["tca", EXAMPLE, "--torque-Nm", "200", "--coupling-length-mm", "-1"],
     "--coupling-length-mm = -1"),
    (["tca", EXAMPLE, "--coupling-length-mm", "modul"], "--coupling-length-mm: 'modul'"),
    (["efficiency", "example:khk_spur_12x24", "--torque-Nm", "200", *LUBE,
      "--coupling-length-mm", "module"], "--coupling-length-mm = module"),
    (["efficiency", EXAMPLE, "--torque-Nm", "200", *LUBE, "--coupling-length-mm", "2000"],
     "--coupling-length-mm = 2000"),
])
def test_coupling_length_refused_in_one_line_before_any_work(monkeypatch, argv, match):
    """Catches: the option accepted (and ignored) for a point-contact design, or a bad
    value found only after the design is read and the model compiled."""
    def forbidden(*a, **k):
        raise AssertionError("work started for bad input")
    monkeypatch.setattr(gj.involute, "loaded_te_map", forbidden)
    monkeypatch.setattr(gj.involute, "line_tca", forbidden)
    rc, out, err = _call(argv)
    assert rc == 2 and match in err and err.count("\n") == 1, err


# ------------------------------------------------------- side, misalignment, arcsec

def _two_sided(tmp_path):
    """A design whose pinion flanks differ: drive tip relief 8 um, coast 2 um over
    other lengths (the side must reach the model)."""
    text = gj.io.read_toml(EXAMPLE)
    mg = text["microgeometry"]
    pin = mg.pop("pinion")
    mg["pinion_drive"] = dict(pin)
    mg["pinion_coast"] = dict(pin, tip_relief_um=2.0, tip_relief_length_mm=1.0)
    path = tmp_path / "two_sided.toml"
    path.write_text(gj.io.dumps_toml(text))
    return str(path)


def test_side_and_misalignment_reach_the_model(tmp_path):
    """``line_tca``, `gearjax tca` and `gearjax efficiency` on the coast side of a design
    whose coast flank differs, at a mesh misalignment, against ``loaded_te_map`` with
    that side and misalignment (the library route of `gearjax loaded`); the arcsec
    columns of the gear's base radius.  Catches: the side or the misalignment dropped
    on the way (the drive side's, or the aligned mesh's, numbers), the loaded TE of
    ``line_tca`` at f_ma = 0, the efficiency's arcsec of r_b1."""
    path = _two_sided(tmp_path)
    design = gj.load_design(path)
    kw = dict(positions=8, slices=6)
    m = gj.involute.loaded_te_map(design, [200.0], [-12.0], side="coast", **kw)
    md = gj.involute.loaded_te_map(design, [200.0], [-12.0], side="drive", **kw)
    assert abs(float(m.te_ptp_um[0, 0]) - float(md.te_ptp_um[0, 0])) > 1e-3
    r = gj.involute.line_tca(design, torques_Nm=[200.0], side="coast", misalignment_um=-12.0,
                             **kw)
    assert float(r.te_loaded_ptp_um[0]) == pytest.approx(float(m.te_ptp_um[0, 0]), rel=1e-10)
    assert float(r.ptp_um) == pytest.approx(float(m.te_unloaded_ptp_um[0, 0]), rel=1e-10)
    rc, out, err = _call(["tca", path, *SMALL, "--side", "coast", "--misalignment-um", "-12",
                          "--torque-Nm", "200", "--json"])
    assert rc == 0, err
    t = strict_json(out)
    assert t["loaded"]["te_ptp_um"][0] == pytest.approx(float(m.te_ptp_um[0, 0]), rel=1e-10)
    assert t["ptp_um"] == pytest.approx(float(m.te_unloaded_ptp_um[0, 0]), rel=1e-10)
    rc, out, err = _call(["efficiency", path, "--torque-Nm", "200", *LUBE, *SMALL, "--side",
                          "coast", "--misalignment-um", "-12", "--json"])
    assert rc == 0, err
    e = strict_json(out)
    assert e["te_loaded_ptp_um"][0] == pytest.approx(float(m.te_ptp_um[0, 0]), rel=1e-10)
    rb2 = float(gj.involute.pair_geometry(design.design.pair)["rb2"])
    assert e["te_loaded_ptp_arcsec"][0] == pytest.approx(
        1e-3 * e["te_loaded_ptp_um"][0] / rb2 / gj.ARCSEC, rel=1e-12)
    assert e["modifications"]["pinion"]["tip_relief"] == 2.0


@pytest.mark.parametrize("argv, match", [
    (["tca", "example:khk_spur_12x24", "--misalignment-um", "5"], "--misalignment-um = 5"),
    (["tca", "example:khk_spur_12x24", "--slices", "6"], "--slices = 6"),
])
def test_line_options_refused_for_a_point_contact_tca(argv, match):
    """Catches: a line-contact option silently ignored by the point-contact TCA."""
    rc, out, err = _call(argv)
    assert rc == 2 and match in err and err.count("\n") == 1, err


def test_tca_plot_without_torques(tmp_path):
    """The figure of the unloaded TCA alone (no loaded TE to draw).  Catches: the figure
    taking every result for a loaded one (an empty torque array is not None)."""
    png = tmp_path / "u.png"
    rc, out, err = _call(["tca", EXAMPLE, *SMALL, "--plot", str(png)])
    assert rc == 0, err
    assert png.stat().st_size > 10_000
