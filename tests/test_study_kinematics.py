"""Kinematics studies (gearjax.studies.kinematics_route): the [Eigenfunctions]
cutter-radius study as a study file -- the cutter settings as variables, the smooth
flank-grid extrema as quantities, the refusals, the written design.

References: :func:`gearjax.studies.cutter_radius.flank_statistics` (the study's plain
grid statistics, a second route to the same flank fields) at the start and the end;
central differences of the study's own program; the hypoid design-file reader for the
written ``[blank]`` table.  The packaged study runs once (module fixture)."""

import math
import re

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.cli import main
from gearjax.io import design_from_dict
from gearjax.studies import cutter_radius as hk
from gearjax.studies import study_run as sr
from gearjax.studies.quantities import KIN_PHI_T, KIN_R_EFF_T_MM, KIN_SRR_T
from gearjax.studies.study_file import read_study

PLAIN = {"kin_max_abs_srr": ("max_abs_srr", KIN_SRR_T, 2),
         "kin_min_r_eff_mm": ("min_r_eff", KIN_R_EFF_T_MM, -1),
         "kin_min_phi_I": ("min_phi_I", KIN_PHI_T, -1),
         "kin_min_phi_II": ("min_phi_II", KIN_PHI_T, -1)}
MEANS = {"kin_mean_abs_srr": "mean_abs_srr", "kin_mean_r_eff_mm": "mean_r_eff",
         "kin_mean_abs_u_e": "mean_abs_u_e"}

STUDY = """
[study]
name = "kin"
design = "example:hypoid_6x39_7p5in"
[kinematics]
grid = [9, 7]
[[variables]]
field = "cutter_radius"
lower = 60.0
upper = 130.0
[[variables]]
field = "blade_angle_delta"
unit = "deg"
lower = -3.0
upper = 3.0
[[variables]]
field = "cutter_shift"
lower = -5.0
upper = 5.0
[[objective]]
quantity = "kin_max_abs_srr"
[[constraints]]
quantity = "kin_min_phi_II"
lower = 1.0
[[constraints]]
quantity = "kin_min_r_eff_mm"
lower = 3.5
[[constraints]]
quantity = "kin_mean_abs_srr"
upper = 5.0
[[constraints]]
quantity = "kin_mean_r_eff_mm"
lower = 1.0
[[constraints]]
quantity = "kin_mean_abs_u_e"
lower = 0.1
[[constraints]]
quantity = "kin_min_phi_I"
lower = 1.0
"""


def _write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    st = read_study(_write(tmp_path_factory.mktemp("kin"), STUDY))
    prob = sr.set_up(st)
    return prob, sr.run_study(prob)


def _settings(x):
    return hk.StudySettings(jnp.asarray(x[0]), jnp.asarray(x[1]), jnp.asarray(x[2]))


def _check_against_plain(prob, Q, x):
    """Every quantity against flank_statistics at the settings x (mm, rad, mm)."""
    inp = prob.design.blank_input()
    plain = hk.flank_statistics(inp, _settings(x), "convex", (9, 7))
    n = 9 * 7
    qi = {q: i for i, q in enumerate(prob.study.quantities)}
    for q, (name, t, sense) in PLAIN.items():
        v, ref = float(Q[0, qi[q]]), float(plain[name])
        bias = t * math.log((2 if sense == 2 else 1) * n)
        if sense == 2:        # smooth max: above the maximum by at most T ln 2n
            assert ref - 1e-12 <= v <= ref + bias, (q, v, ref)
        else:                 # smooth min: below the minimum by at most T ln n
            assert ref - bias <= v <= ref + 1e-12, (q, v, ref)
    for q, name in MEANS.items():
        assert float(Q[0, qi[q]]) == pytest.approx(float(plain[name]), rel=1e-10), q


def test_quantities_agree_with_flank_statistics(run):
    prob, res = run
    assert list(prob.fields) == ["cutter_radius", "blade_angle_delta", "cutter_shift"]
    assert prob.x0 == pytest.approx([95.25, 0.0, 0.0])
    _check_against_plain(prob, np.asarray(res.start[0]), prob.x0)
    _check_against_plain(prob, np.asarray(res.end[0]), res.x)


def test_objective_gradient_matches_central_differences(run):
    prob = run[0]
    u = jnp.array([0.1, -0.2, 0.3])
    grad = jax.jit(jax.jacfwd(lambda v: prob.fun(v, prob.data)[0]))(u)

    def J(v):
        return float(sr.combine(prob.study, sr.evaluate(prob, v)[0], prob.data)[0])

    h = 1e-4
    for i in range(3):
        e = np.zeros(3)
        e[i] = h
        fd = (J(np.asarray(u) + e) - J(np.asarray(u) - e)) / (2 * h)
        assert float(grad[i]) == pytest.approx(fd, rel=1e-5, abs=1e-8), i
    assert np.all(np.isfinite(np.asarray(grad))) and np.any(np.abs(np.asarray(grad)) > 1e-3)


def test_study_lowers_objective_within_constraints(run):
    prob, res = run
    rep = res.report
    assert res.accepted, res.reasons
    assert rep["route"] == "kinematics" and rep["optimizer"]["converged"]
    assert rep["objective"]["end"] < rep["objective"]["start"] - 1e-3
    assert rep["max_violation"]["end"] <= prob.study.tolerance
    q = rep["quantities"]
    assert q["kin_min_phi_I"]["end"][0] >= 1.0 - 1e-6
    assert q["kin_min_phi_II"]["end"][0] >= 1.0 - 1e-6
    assert q["kin_min_r_eff_mm"]["end"][0] >= 3.5 - 1e-6
    for flags in (rep["checks"]["flags_start"], rep["checks"]["flags_end"]):
        assert flags[0]["converged"] and flags[0]["blank_converged"]
        assert flags[0]["n_valid"] == 9 * 7


def test_written_design_round_trips(run):
    prob, res = run
    back = design_from_dict(res.end_data)
    inp = back.blank_input()
    assert float(inp.cutter_radius) == pytest.approx(res.x[0], rel=1e-12)
    assert res.end_data["blank"]["cutter_radius_mm"] != prob.design.data["blank"][
        "cutter_radius_mm"]
    assert set(res.end_data["blank"]) == set(prob.design.data["blank"])   # no new keys
    # the file's blank with the study's other settings gives the end quantities again
    plain = hk.flank_statistics(inp, _settings(res.x), "convex", (9, 7))
    qi = {q: i for i, q in enumerate(prob.study.quantities)}
    assert float(plain["mean_r_eff"]) == pytest.approx(
        float(np.asarray(res.end[0])[0, qi["kin_mean_r_eff_mm"]]), rel=1e-10)


def test_round_trip_at_an_interior_radius(run):
    from gearjax.studies.kinematics_route import kinematics_round_trip
    prob = run[0]
    r0 = 101.23456789012
    data, err, diff = kinematics_round_trip(prob, {"cutter_radius": jnp.asarray(r0),
                                                   "blade_angle_delta": jnp.asarray(0.01),
                                                   "cutter_shift": jnp.asarray(1.5)})
    assert err is None and diff < 1e-12
    assert float(design_from_dict(data).blank_input().cutter_radius) == pytest.approx(
        r0, rel=1e-14)
    assert prob.design.data["blank"]["cutter_radius_mm"] == 95.25      # start untouched
    data, err, diff = kinematics_round_trip(prob, {"cutter_radius": jnp.asarray(-5.0)})
    assert data is None and "cutter_radius" in err and diff == math.inf


def test_quantities_on_synthetic_fields_match_the_plain_statistics():
    """Each kin_* quantity against cutter_radius._stats on fields whose eigenfunctions
    are negative at the grid centre (the pitch-point sign normalisation) and whose SRR
    has its largest magnitude at a negative value."""
    from types import SimpleNamespace

    from gearjax.studies.kinematics_route import KinematicsResult
    from gearjax.studies.quantities import KIN_QUANTITIES
    rng = np.random.default_rng(3)
    shape = (9, 7)
    f = SimpleNamespace(**{k: jnp.asarray(rng.normal(size=shape)) for k in
                           ("srr", "u_e", "phi_I", "phi_II")},
                        r_eff=jnp.asarray(rng.uniform(2.0, 30.0, size=shape)))
    f.phi_I = -jnp.abs(f.phi_I) - 0.5
    f.phi_II = f.phi_II.at[4, 3].set(-2.0)
    f.srr = f.srr.at[0, 0].set(-5.0)
    plain = hk._stats(f)
    res = KinematicsResult(f, jnp.asarray(1.0), jnp.asarray(0.0))
    n = 63
    for q, (name, t, sense) in PLAIN.items():
        v, ref = float(KIN_QUANTITIES[q].fn(res, None, None, None)), float(plain[name])
        if sense == 2:
            assert ref - 1e-12 <= v <= ref + t * math.log(2 * n), q
        else:
            assert ref - t * math.log(n) <= v <= ref + 1e-12, q
    assert float(plain["min_phi_I"]) > 0.0 and float(plain["max_abs_srr"]) == 5.0
    for q, name in MEANS.items():
        assert float(KIN_QUANTITIES[q].fn(res, None, None, None)) == pytest.approx(
            float(plain[name]), rel=1e-12), q


BASE = STUDY.split("[[objective]]")[0] + '[[objective]]\nquantity = "kin_max_abs_srr"\n'


@pytest.mark.parametrize("text, match", [
    (BASE + '[[constraints]]\nquantity = "max_abs_srr"\nupper = 1.0\n',
     r"\[\[constraints\]\] 1: quantity 'max_abs_srr' is of the TCA route"),
    (BASE.replace('field = "cutter_shift"', 'field = "pair.x1"'),
     r"\[\[variables\]\] 3: field 'pair.x1': a kinematics study varies"),
    (BASE + '[scenarios]\ntorque_Nm = 10.0\n', r"^\[scenarios\]: a kinematics study"),
    (BASE + '[operating]\ntorque_Nm = 10.0\n', r"^\[operating\]: a kinematics study"),
    (BASE + '[[constraints]]\nquantity = "line_p_max_MPa"\nupper = 1.0\n',
     r"\[\[constraints\]\] 1: quantity 'line_p_max_MPa' is of the loaded line-contact"),
    (BASE.replace('field = "cutter_radius"', 'field = "cutter_radius"\nunit = "deg"'),
     r"\[\[variables\]\] 1: field 'cutter_radius': unit = 'deg'"),
    (BASE.replace("[kinematics]\ngrid = [9, 7]", '[kinematics]\nflank = "left"'),
     r"\[kinematics\] flank"),
])
def test_refusals_when_read(tmp_path, text, match):
    with pytest.raises(ValueError, match=match):
        read_study(_write(tmp_path, text))


def test_kin_field_in_tca_study_refused(tmp_path):
    text = ('[study]\nname = "t"\ndesign = "example:khk_spur_12x24"\n[[variables]]\n'
            'field = "cutter_radius"\nlower = 60.0\nupper = 130.0\n[[objective]]\n'
            'quantity = "max_abs_srr"\n')
    with pytest.raises(ValueError, match=r"\[\[variables\]\] 1: field 'cutter_radius' is a "
                                         "cutter setting"):
        read_study(_write(tmp_path, text))


@pytest.mark.parametrize("old, new, match", [
    ("upper = 130.0", "upper = 500.0",
     r"\[\[variables\]\] 1 \(cutter_radius\): bounds \[60, 500\] mm outside the setting's "
     r"range \[20, 400\]"),
    ("lower = -3.0", "lower = -12.0",
     r"\[\[variables\]\] 2 \(blade_angle_delta\): bounds \[-12, 3\] deg outside"),
    ('"example:hypoid_6x39_7p5in"', '"example:khk_spur_12x24"',
     r"\[\[variables\]\] 1 \(cutter_radius\): .*for hypoid pairs, not involute pairs"),
])
def test_refusals_at_set_up(tmp_path, old, new, match):
    st = read_study(_write(tmp_path, BASE.replace(old, new, 1)))
    with pytest.raises(ValueError, match=match):
        sr.set_up(st)


def test_sweep_runs_the_kinematics_study(run):
    from gearjax.studies.sweep import run_sweep, set_up_sweep
    prob, res = run
    sp = set_up_sweep(prob.study)
    U = np.array([np.zeros(3), prob.upper, [-0.5, 0.2, 0.1]])
    r = run_sweep(sp, U, chunk=4)
    assert r.ok.all() and r.flags["converged"].all() and not r.flags["edge_contact"].any()
    idx = [sp.study.quantities.index(q) for q in prob.study.quantities]
    # row 0 is the start, row 1 the corner where the optimiser ended (the upper bounds)
    np.testing.assert_allclose(r.values[0][:, idx], np.asarray(res.start[0]), rtol=1e-10)
    assert np.allclose(res.u, prob.upper)
    np.testing.assert_allclose(r.values[1][:, idx], np.asarray(res.end[0]), rtol=1e-10)


def test_packaged_study_and_quantity_list(capsys):
    st = read_study("example:hypoid_cutter_radius")
    assert st.route == "kinematics" and st.kinematics == {"flank": "convex", "grid": (9, 7)}
    assert [v.field for v in st.variables] == ["cutter_radius", "blade_angle_delta",
                                               "cutter_shift"]
    assert gj.load_design(st.design).blank_input().cutter_radius == pytest.approx(95.25)
    assert main(["optimize", "--quantities"]) == 0
    out = capsys.readouterr().out
    for q in list(PLAIN) + list(MEANS):
        assert q in out


def test_concave_flank_is_the_concave_flanks_statistics(tmp_path):
    """``[kinematics] flank = "concave"``: the study's quantities are those of the concave
    gear flank (flank_statistics of that flank), which differ from the convex one's."""
    text = STUDY.replace("grid = [9, 7]", 'grid = [5, 3]\nflank = "concave"')
    prob = sr.set_up(read_study(_write(tmp_path, text)))
    Q = np.asarray(sr.start_point(prob)[0])
    inp = prob.design.blank_input()
    st = _settings(prob.x0)
    plain = {f: hk.flank_statistics(inp, st, f, (5, 3)) for f in ("concave", "convex")}
    qi = {q: i for i, q in enumerate(prob.study.quantities)}
    for q, name in MEANS.items():
        assert float(Q[0, qi[q]]) == pytest.approx(float(plain["concave"][name]), rel=1e-10)
    a, b = float(plain["concave"]["mean_abs_srr"]), float(plain["convex"]["mean_abs_srr"])
    assert abs(a - b) > 1e-3 * abs(b), (a, b)


def test_blank_failure_fails_the_acceptance_flags(monkeypatch):
    """A design whose blank Newton solve did not converge is not "converged", even when
    every grid point's solve did; and a blank without offset is refused (the model is for
    hypoid pairs)."""
    import dataclasses

    from gearjax.studies.kinematics_route import (KinematicsResult, kinematics_chain,
                                                  kinematics_flags)
    conv = np.ones((1, 3, 2), bool)
    f = hk.FlankFields(*([np.zeros((1, 3, 2))] * len(hk.FlankFields._fields)))
    f = f._replace(converged=conv)
    good = KinematicsResult(f, np.array([1.0]), np.array([0.0]))
    assert kinematics_flags(good, 0)["converged"]
    bad = kinematics_flags(good._replace(blank_converged=np.array([0.0])), 0)
    assert not bad["converged"] and not bad["blank_converged"] and bad["n_valid"] == 6
    d = gj.load_design("example:hypoid_6x39_7p5in")
    inp0 = d.blank_input()
    flat = dataclasses.replace(inp0, offset=jnp.asarray(0.0))

    monkeypatch.setattr(type(d), "blank_input", lambda self: flat)
    with pytest.raises(ValueError, match="blank.offset_mm must be > 0"):
        kinematics_chain(d, read_study("example:hypoid_cutter_radius"))


def _numbers(text, label):
    """The floats printed on the line that starts with ``label``."""
    line = next(ln for ln in text.splitlines() if ln.startswith(label))
    return [float(x) for x in re.findall(r"[-+]?\d+\.\d+(?:e[-+]?\d+)?", line[len(label):])]


def test_hypoid_design_notebook_synthesis_and_packaged_study(tmp_path):
    """notebooks/09_hypoid_design.ipynb: the local synthesis of the spiral-bevel pinion
    meets its six targets and the independent TCA agrees (the tolerances of
    tests/test_synthesis.py); the packaged study ``hypoid_cutter_radius`` (run end to end
    only here) converges on the KKT test, is accepted, ends on the corner of its box with
    every constraint inactive and a lower max |SRR|, and SLSQP on the same gradients
    reaches the same point (docs/optimize.md)."""
    from notebook_run import images, run_notebook
    nb, text = run_notebook("09_hypoid_design", tmp_path)
    assert images(nb) == 2, text[-2000:]
    m = re.search(r"converged: (\d+) iterations", text)
    assert m and int(m.group(1)) <= 15, text[:2000]
    assert _numbers(text, "largest scaled residual per step:")[-1] <= 1e-3
    tol = {"xi1 (face)": 1e-4, "h1 (mm)": 1e-3, "TE level (arcsec)": 1e-2,
           "TE apex (arcsec)": 1e-2, "path angle (deg)": 1e-2, "semi-major (mm)": 1e-3}
    for label, t in tol.items():
        want, got = _numbers(text, label)
        assert abs(got - want) <= t, (label, want, got)
    xi, h, h_t = _numbers(text, "bearing xi1")
    assert abs(xi) < 0.01 and abs(h - h_t) < 0.05
    for drop in _numbers(text, "TE drop half a pitch from the apex:"):
        assert abs(drop - 8.0) < 0.5
    # the packaged cutter-settings study
    kkt = re.search(r"KKT: stationarity ([0-9.e+-]+), feasibility ([0-9.e+-]+)", text)
    assert float(kkt.group(1)) <= 1e-4 and float(kkt.group(2)) <= 1e-4
    assert "accepted: True []" in text and "SLSQP accepted: True" in text
    for field, end in (("cutter_radius", 130.0), ("blade_angle_delta", 3.0),
                       ("cutter_shift", 5.0)):
        assert _numbers(text, field)[1] == pytest.approx(end, abs=1e-6), field
    start, end = _numbers(text, "kin_max_abs_srr")
    assert end < 0.95 * start
    assert _numbers(text, "multipliers of the constraints:") == [0.0, 0.0, 0.0]
    assert _numbers(text, "largest difference of the end settings")[0] <= 1e-6
    al, sq = _numbers(text, "objective: augmented Lagrangian")
    assert al == pytest.approx(sq, abs=1e-9)
