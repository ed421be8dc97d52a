"""Line-contact studies (gearjax.studies.line_route): micro-geometry fields as study
variables, the loaded line contact's quantities over torque x misalignment scenarios,
the refusals, the written design.

References: central differences of the study's own program (the gradient the optimiser
uses is forward mode through the whole program); ``gearjax.involute.loaded_te_map``
(the public map of ``gearjax loaded``, a second entry point into the line contact) on
the design files the study reads and writes; the involute design-file reader for the
written ``[microgeometry]`` tables.  A coarse model (12 positions x 6 slices, 2 x 2
scenarios) keeps the compiled programs small; module fixtures compile each once."""

import json

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.cli import main
from gearjax.gears.involute.design_file import microgeometry_tables, read_microgeometry
from gearjax.gears.involute.loaded_lines import loaded_te_map
from gearjax.gears.involute.microgeometry import (FlankModification, MicroGeometry,
                                                  PairModification)
from gearjax.io import dumps_toml, read_toml
from gearjax.studies import study_run as sr
from gearjax.studies.quantities import QUANTITIES
from gearjax.studies.study_file import read_study

POSITIONS, SLICES = 12, 6
TORQUES, MISALIGNMENTS = (200.0, 400.0), (-10.0, 10.0)

STUDY = f"""
[study]
name = "mg"
description = "small micro-geometry study"
design = "example:helical_microgeometry"

[scenarios]
torque_Nm = {list(TORQUES)}
f_ma_um = {list(MISALIGNMENTS)}

[line]
positions = {POSITIONS}
slices = {SLICES}

[[variables]]
field = "microgeometry.pinion.tip_relief_um"
lower = 0.0
upper = 30.0
scale = 30.0

[[variables]]
field = "microgeometry.pinion.tip_relief_length_mm"
lower = 0.5
upper = 6.0
scale = 5.5

[[variables]]
field = "microgeometry.gear_drive.tip_relief_um"
lower = 0.0
upper = 30.0
scale = 30.0

[[variables]]
field = "microgeometry.pinion.lead_crowning_um"
lower = 0.0
upper = 20.0
scale = 20.0

[[variables]]
field = "microgeometry.pinion.helix_slope_um"
lower = -15.0
upper = 15.0
scale = 30.0

[[objective]]
quantity = "line_te_ptp_um"
scale = 1.0

[[constraints]]
quantity = "line_p_max_MPa"
upper = 1400.0

[[constraints]]
quantity = "line_end_load"
upper = 1.2

[optimizer]
max_iterations = 6
"""


def _write(tmp_path, text, name="mg.toml"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


@pytest.fixture(scope="module")
def problem(tmp_path_factory):
    path = _write(tmp_path_factory.mktemp("mg"), STUDY)
    prob = sr.set_up(read_study(path))
    Q0 = sr.start_point(prob)[0]
    return prob, np.asarray(Q0)


@pytest.fixture(scope="module")
def cli_run(tmp_path_factory):
    d = tmp_path_factory.mktemp("mg_run")
    path = _write(d, STUDY)
    rc = main(["optimize", path, "--out", str(d / "out")])
    rep = json.loads((d / "out" / "mg_history.json").read_text())
    return rc, d / "out", rep


def test_variables_are_the_design_files_fields(problem):
    prob, _ = problem
    design = gj.load_design("example:helical_microgeometry")
    drive = design.micro.flanks("drive")
    # member and flank tables name the drive flank in mesh; the start values are the file's
    assert prob.fields == ["microgeometry.pinion_drive.tip_relief_um",
                           "microgeometry.pinion_drive.tip_relief_length_mm",
                           "microgeometry.gear_drive.tip_relief_um",
                           "microgeometry.pinion_drive.lead_crowning_um",
                           "microgeometry.pinion_drive.helix_slope_um"]
    want = [drive.pinion.tip_relief, drive.pinion.tip_relief_length, drive.gear.tip_relief,
            drive.pinion.lead_crowning, drive.pinion.helix_slope]
    np.testing.assert_array_equal(prob.x0, [float(w) for w in want])
    assert [s["f_ma_um"] for s in prob.scenarios] == list(MISALIGNMENTS) * 2


def test_quantities_agree_with_the_loaded_map(problem):
    """The study's quantities at the start, scenario by scenario, against
    ``loaded_te_map`` of the design file (the ``gearjax loaded`` route)."""
    prob, Q0 = problem
    m = loaded_te_map(prob.design, TORQUES, MISALIGNMENTS, positions=POSITIONS,
                      slices=SLICES, temperature_um=0.02)
    qi = {q: i for i, q in enumerate(prob.study.quantities)}
    ptp = np.asarray(m.te_ptp_um).ravel()          # (T, A) row-major = the scenarios' order
    np.testing.assert_allclose(Q0[:, qi["line_te_ptp_hard_um"]], ptp, rtol=1e-12)
    np.testing.assert_allclose(Q0[:, qi["line_te_ptp_um"]], np.asarray(m.te_ptp_smooth_um)
                               .ravel(), rtol=1e-12)
    # the smooth forms bound the hard values from above (log-sum-exp)
    p = Q0[:, qi["line_p_max_MPa"]]
    assert np.all(p >= np.asarray(m.p_max).ravel())
    assert np.all(p <= np.asarray(m.p_max).ravel() + 3.0 * np.log(POSITIONS * 200))
    end = Q0[:, qi["line_end_load"]]
    assert np.all(end >= np.asarray(m.end_load).ravel() - 1e-12)
    assert np.all(end <= np.asarray(m.end_load).ravel() + 0.005 * np.log(2) + 1e-12)
    kh = Q0[:, qi["line_k_hbeta"]]
    assert np.all((kh >= np.asarray(m.k_hbeta).ravel() - 1e-12) & (kh > 1.0))


def test_objective_gradient_matches_central_differences(problem):
    """d J / d u by forward mode (as the optimiser) against central differences of the
    same jitted program, at an interior point, for every micro-geometry field."""
    prob, _ = problem
    fun = jax.jit(lambda u: prob.fun(u, prob.data))
    grad = jax.jit(jax.jacfwd(lambda u: prob.fun(u, prob.data)))
    u = jnp.array([0.05, 0.1, -0.04, 0.07, 0.03])
    gJ, gg = (np.asarray(a) for a in grad(u))
    h = 1e-5
    for i in range(u.size):
        e = jnp.zeros(u.size).at[i].set(h)
        (Jp, cp), (Jm, cm) = fun(u + e), fun(u - e)
        fd = (float(Jp) - float(Jm)) / (2 * h)
        assert gJ[i] == pytest.approx(fd, rel=1e-5, abs=1e-7), prob.fields[i]
        np.testing.assert_allclose(gg[:, i], (np.asarray(cp) - np.asarray(cm)) / (2 * h),
                                   rtol=1e-5, atol=1e-6)
    assert np.all(np.abs(gJ) > 1e-4)         # every field reaches the model


def test_study_lowers_the_objective_within_the_constraints(cli_run):
    rc, out, rep = cli_run
    opt = rep["optimizer"]
    assert rep["route"] == "line" and rep["family"] == "involute"
    assert rep["objective"]["end"] < 0.95 * rep["objective"]["start"]
    assert rep["max_violation"]["end"] <= opt["tolerance"]
    q = rep["quantities"]
    assert max(q["line_end_load"]["end"]) <= 1.2 * (1 + opt["tolerance"])
    assert max(q["line_p_max_MPa"]["end"]) <= 1400.0 * (1 + opt["tolerance"])
    # accepted exactly when the optimiser met its KKT test (never a stalled point)
    assert (rc == 0) == rep["checks"]["accepted"] == opt["converged"]
    for v in rep["variables"]:
        assert v["lower"] - 1e-12 <= v["end"] <= v["upper"] + 1e-12
    assert (out / "mg.png").stat().st_size > 10_000


def test_written_design_round_trips(cli_run):
    """The optimised design file holds the end fields in its [microgeometry] tables (the
    member table moved both flanks, the flank table one), and the loaded map of the file
    reproduces the study's end values."""
    rc, out, rep = cli_run
    d = gj.load_design(str(out / "mg_optimised.toml"))
    end = {v["field"]: v["end"] for v in rep["variables"]}
    for side in ("drive", "coast"):
        pin = d.micro.flanks(side).pinion
        assert float(pin.tip_relief) == pytest.approx(
            end["microgeometry.pinion.tip_relief_um"], rel=1e-12)
        assert float(pin.lead_crowning) == pytest.approx(
            end["microgeometry.pinion.lead_crowning_um"], rel=1e-12)
    start = gj.load_design("example:helical_microgeometry")
    assert float(d.micro.drive.gear.tip_relief) == pytest.approx(
        end["microgeometry.gear_drive.tip_relief_um"], rel=1e-12)
    assert float(d.micro.coast.gear.tip_relief) == float(start.micro.coast.gear.tip_relief)
    m = loaded_te_map(d, TORQUES, MISALIGNMENTS, positions=POSITIONS, slices=SLICES)
    np.testing.assert_allclose(np.asarray(m.te_ptp_um).ravel(),
                               rep["quantities"]["line_te_ptp_hard_um"]["end"], rtol=1e-9)
    assert rep["checks"]["round_trip_difference"] <= 1e-9
    assert main(["loaded", str(out / "mg_optimised.toml"), "--torque-Nm", "400",
                 "--positions", "8", "--slices", "4"]) == 0


def test_microgeometry_tables_invert_the_reader():
    a = FlankModification.create(tip_relief=12.5, tip_relief_length=2.0,
                                 tip_relief_exponent=2.0, lead_crowning=-3.0, bias=1.5)
    b = FlankModification.create(root_relief=4.0, root_relief_length=1.5, helix_slope=2.0,
                                 end_relief_I=5.0, end_relief_I_length=4.0,
                                 end_relief_exponent=2.0)
    micro = MicroGeometry(PairModification(a, b), PairModification(a, FlankModification.none()))
    tabs = microgeometry_tables(micro)
    assert set(tabs) == {"pinion", "gear_drive"}      # equal pinion flanks: one table
    back = read_microgeometry(tabs)
    for x, y in zip(jax.tree.leaves(micro), jax.tree.leaves(back)):
        assert float(x) == float(y)
    with pytest.raises(ValueError, match="tip_relief_exponent = 3"):
        microgeometry_tables(MicroGeometry(PairModification(
            FlankModification.create(tip_relief_exponent=3.0), a), PairModification.none()))


def test_packaged_study_sets_up_from_the_unmodified_pair():
    st = read_study("example:helical_microgeometry_robust")
    prob = sr.set_up(st)
    assert prob.route == "line" and len(prob.scenarios) == 12
    design = gj.load_design(st.design)
    for name, x in zip(prob.fields, prob.x0):
        key = name.split(".")[-1]
        flank = getattr(design.micro.drive, name.split(".")[1].split("_")[0])
        if key.endswith("_um"):
            assert x == 0.0                    # the unmodified pair
        else:
            assert x == float(flank.tip_relief_length)


def test_quantities_are_listed(capsys):
    assert main(["optimize", "--quantities"]) == 0
    out = capsys.readouterr().out
    for q, d in QUANTITIES.items():
        if d.route == "line":
            assert any(line.startswith(q) and " line " in line for line in out.splitlines())


def _replace(text, old, new):
    assert old in text
    return text.replace(old, new)


@pytest.mark.parametrize("old, new, match", [
    ('quantity = "line_p_max_MPa"', 'quantity = "peak_pressure_MPa"',
     r"\[\[constraints\]\] 1: quantity 'peak_pressure_MPa' is of the TCA route"),
    ("microgeometry.pinion.tip_relief_um", "microgeometry.pinion.tip_relief_shape",
     r"\[\[variables\]\] 1: field .*unknown micro-geometry field 'tip_relief_shape'"),
    ("microgeometry.pinion.tip_relief_um", "microgeometry.wheel.tip_relief_um",
     r"\[\[variables\]\] 1: .*unknown micro-geometry table 'wheel'"),
    ("microgeometry.gear_drive.tip_relief_um", "microgeometry.gear_coast.tip_relief_um",
     r"\[\[variables\]\] 3: .*not in mesh on the study's side \(drive\)"),
    ("microgeometry.pinion.tip_relief_um", "pair.x1",
     r"\[\[variables\]\] 1: field 'pair.x1': a line-contact study varies micro-geometry"),
    ("f_ma_um", "dE_mm", r"\[scenarios\] dE_mm: a scenario key of the TCA route"),
    ("[line]", "[tca]", r"\[tca\]: the TCA grid"),
    ("[scenarios]", "[operating]\nedge_softening_mm = 0.01\n\n[scenarios]",
     r"\[operating\] edge_softening_mm: the soft active set"),
    ('field = "microgeometry.pinion.tip_relief_length_mm"',
     'field = "microgeometry.pinion.tip_relief_length_mm"\nunit = "deg"',
     r"\[\[variables\]\] 2 \(microgeometry.pinion.tip_relief_length_mm\): unit = 'deg'"),
])
def test_bad_study_refused_naming_the_entry(tmp_path, old, new, match):
    with pytest.raises(ValueError, match=match):
        read_study(_write(tmp_path, _replace(STUDY, old, new)))


def test_micro_variables_need_the_line_route(tmp_path):
    text = _replace(_replace(STUDY, 'quantity = "line_te_ptp_um"', 'quantity = "contact_ratio"'),
                    '[[constraints]]\nquantity = "line_p_max_MPa"\nupper = 1400.0\n\n'
                    '[[constraints]]\nquantity = "line_end_load"\nupper = 1.2\n', "")
    text = _replace(text, "[line]\npositions = 12\nslices = 6\n", "")
    text = _replace(text, "f_ma_um", "dE_mm")
    with pytest.raises(ValueError, match=r"\[\[variables\]\] 1: the micro-geometry field "
                                         r"'microgeometry.pinion.tip_relief_um' is analysed"):
        read_study(_write(tmp_path, text))


@pytest.mark.parametrize("old, new, match", [
    ('design = "example:helical_microgeometry"', 'design = "example:hft_8x43"',
     r"\[\[variables\]\] 1 \(microgeometry.pinion.tip_relief_um\): .*for involute pairs, "
     r"not hypoid pairs"),
    ("lower = 0.0\nupper = 30.0\nscale = 30.0", "lower = -5.0\nupper = 30.0\nscale = 30.0",
     r"\[\[variables\]\] 1 \(microgeometry.pinion.tip_relief_um\): bounds \[-5, 30\] um "
     r"outside the field's range"),
    ("lower = 0.5\nupper = 6.0", "lower = 0.0\nupper = 6.0",
     r"\[\[variables\]\] 2 .*outside the field's range \[> 0"),
    ("f_ma_um = [-10.0, 10.0]", "f_ma_um = [-10.0, 2000.0]",
     r"\[scenarios\] scenario 2: f_ma_um = 2000"),
    ("torque_Nm = [200.0, 400.0]", "torque_Nm = [-200.0, 400.0]",
     r"\[scenarios\] scenario 1: torque_Nm = -200"),
    ("lower = -15.0\nupper = 15.0", "lower = -15.0\nupper = 900.0",
     r"\[\[variables\]\] 5 \(microgeometry.pinion.helix_slope_um\): bounds \[-15, 900\] um "
     r"outside the field's range"),
    ("microgeometry.gear_drive.tip_relief_um", "microgeometry.pinion_drive.tip_relief_um",
     r"\[\[variables\]\] 3: field 'microgeometry.pinion_drive.tip_relief_um' is the field "
     r"of \[\[variables\]\] 1 again"),
])
def test_bad_study_refused_at_set_up(tmp_path, old, new, match):
    with pytest.raises(ValueError, match=match):
        sr.set_up(read_study(_write(tmp_path, _replace(STUDY, old, new))))


def test_cli_refusal_is_one_line(tmp_path, capsys):
    path = _write(tmp_path, _replace(STUDY, "microgeometry.pinion.lead_crowning_um",
                                     "microgeometry.pinion.crowning_um"))
    assert main(["optimize", path]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "[[variables]] 4" in err and "crowning_um" in err


def test_efficiency_quantities_agree_with_the_loaded_map(tmp_path):
    """``line_power_loss_W`` and ``line_mesh_efficiency`` of a study against the loaded
    map with ``pinion_rpm`` (the friction along the contact lines, ``gearjax loaded
    --rpm``) at one scenario."""
    text = _replace(STUDY, "[scenarios]", '[operating]\npinion_rpm = 3000.0\noil = '
                    '"mineral_vg100"\nsigma_um = 0.4\ntorque_Nm = 300.0\n\n[scenarios]')
    text = _replace(text, f"torque_Nm = {list(TORQUES)}\nf_ma_um = {list(MISALIGNMENTS)}",
                    "f_ma_um = 5.0")
    text = _replace(text, '[[constraints]]\nquantity = "line_end_load"',
                    '[[constraints]]\nquantity = "line_mesh_efficiency"\nlower = 0.9\n\n'
                    '[[constraints]]\nquantity = "line_power_loss_W"\nupper = 1e4\n\n'
                    '[[constraints]]\nquantity = "line_end_load"')
    prob = sr.set_up(read_study(_write(tmp_path, text)))
    Q = np.asarray(sr.start_point(prob)[0])[0]
    qi = {q: i for i, q in enumerate(prob.study.quantities)}
    m = loaded_te_map(prob.design, [300.0], [5.0], positions=POSITIONS, slices=SLICES,
                      pinion_rpm=3000.0, oil=gj.tribology.get_oil("mineral_vg100"),
                      surface=gj.tribology.make_surface(0.4))
    assert Q[qi["line_power_loss_W"]] == pytest.approx(float(m.power_loss_W[0, 0]), rel=1e-10)
    assert Q[qi["line_mesh_efficiency"]] == pytest.approx(float(m.efficiency[0, 0]), rel=1e-12)
    assert 0.0 < Q[qi["line_power_loss_W"]] and 0.9 < Q[qi["line_mesh_efficiency"]] < 1.0


def test_efficiency_needs_the_operating_point(tmp_path):
    text = _replace(STUDY, 'quantity = "line_end_load"\nupper = 1.2',
                    'quantity = "line_power_loss_W"\nupper = 1e4')
    with pytest.raises(ValueError, match=r"\[operating\]: the loaded quantity "
                                         r"'line_power_loss_W' needs the operating point"):
        read_study(_write(tmp_path, text))


def _design_with(values: dict):
    """``example:helical_microgeometry`` with the member tables' keys set (``values``:
    ``microgeometry.MEMBER[_FLANK].KEY`` -> value; a flank table's key is written to its
    member's table, which the drive-side model reads alike) -- a second route to a
    moved design: the design file's own reader."""
    from gearjax.io import design_from_dict
    data = read_toml("example:helical_microgeometry")
    for name, v in values.items():
        _, table, key = name.split(".")
        data["microgeometry"][table.split("_")[0]][key] = float(v)
    return design_from_dict(data)


def test_sweep_of_a_line_study_is_each_designs_loaded_map(tmp_path, capsys):
    """`gearjax sweep` of a line-contact study: every row's quantities against
    ``loaded_te_map`` of that row's design written as a design file (the `gearjax
    loaded` route), the valid counts, ``ok``, ``feasible`` and ``J`` by hand.  Planted
    bugs caught: rows paired with the wrong designs (a shuffled or padded chunk), the
    flags or counts of another row or scenario, the constraint sense or the objective's
    scaling, a refusal left in place."""
    path = _write(tmp_path, STUDY)
    out = tmp_path / "sw"
    assert main(["sweep", path, "--samples", "3", "--chunk", "2", "--seed", "3",
                 "--out", str(out)]) == 0
    text = capsys.readouterr().out
    d = dict(np.load(out / "mg_sweep.npz"))
    names = [str(q) for q in d["quantities"]]
    fields = [str(v) for v in d["variables"]]
    assert d["x"].shape == (4, 5) and d["values"].shape == (4, 4, len(names))
    qi = {q: i for i, q in enumerate(names)}
    for k in range(4):
        m = loaded_te_map(_design_with(dict(zip(fields, d["x"][k]))), TORQUES, MISALIGNMENTS,
                          positions=POSITIONS, slices=SLICES, temperature_um=0.02)
        v = d["values"][k]
        np.testing.assert_allclose(v[:, qi["line_te_ptp_hard_um"]],
                                   np.asarray(m.te_ptp_um).ravel(), rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(v[:, qi["line_te_ptp_um"]],
                                   np.asarray(m.te_ptp_smooth_um).ravel(), rtol=1e-10)
        assert np.all(v[:, qi["line_p_max_MPa"]] >= np.asarray(m.p_max).ravel())
        conv = np.asarray(m.converged).ravel()
        np.testing.assert_array_equal(d["flag:converged"][k], conv)
        np.testing.assert_array_equal(d["n_valid"][k] == POSITIONS, conv)
    v = d["values"]
    ok = d["flag:converged"].all(axis=1) & np.isfinite(v).all(axis=(1, 2))
    np.testing.assert_array_equal(d["ok"], ok)
    feas = ok & np.all(v[:, :, qi["line_p_max_MPa"]] <= 1400.0, axis=1) & np.all(
        v[:, :, qi["line_end_load"]] <= 1.2, axis=1)
    np.testing.assert_array_equal(d["feasible"], feas)
    np.testing.assert_allclose(d["J"], v[:, :, qi["line_te_ptp_um"]].mean(axis=1), rtol=1e-12)
    assert not d["flag:edge_contact"].any()
    assert "4 designs (random)" in text
    np.testing.assert_array_equal(d["scenario:f_ma_um"], list(MISALIGNMENTS) * 2)


LINE_SENS = ("line_te_ptp_um", "line_te_mean_um")
SENS_FIELDS = ("microgeometry.pinion.tip_relief_um", "microgeometry.pinion.lead_crowning_um",
               "microgeometry.gear.tip_relief_length_mm")


def test_sensitivity_of_line_outputs_against_central_differences(capsys):
    """`gearjax sensitivity` of line-contact outputs with respect to micro-geometry
    fields (forward mode through the exact load solution) against central differences
    of ``loaded_te_map`` on design files with the field moved (a second route), at one
    torque and misalignment; the values equal the map's; elasticities by definition.
    Planted bugs caught: a derivative dropped or of the wrong field, the torque or the
    misalignment of the command not reaching the model (or its sign lost: -5 um here),
    the line options ignored."""
    rc = main(["sensitivity", "example:helical_microgeometry", "--outputs", ",".join(LINE_SENS),
               "--params", ",".join(SENS_FIELDS), "--torque-Nm", "300", "--f-ma-um", "-5",
               "--positions", str(POSITIONS), "--slices", str(SLICES), "--json"])
    assert rc == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["scenario"] == {"torque_Nm": 300.0, "f_ma_um": -5.0, "positions": POSITIONS,
                               "slices": SLICES}
    x0 = {"microgeometry.pinion.tip_relief_um": 8.0, "microgeometry.pinion.lead_crowning_um": 6.0,
          "microgeometry.gear.tip_relief_length_mm": 2.5}

    def outputs(values):
        m = loaded_te_map(_design_with(values), [300.0], [-5.0], positions=POSITIONS,
                          slices=SLICES, temperature_um=0.02)
        return np.array([float(m.te_ptp_smooth_um[0, 0]), float(m.te_mean_um[0, 0])])

    base = outputs(x0)
    for i, o in enumerate(rep["outputs"]):
        assert o["name"] == LINE_SENS[i] and o["value"] == pytest.approx(base[i], rel=1e-11)
    h = 1e-4
    for name in SENS_FIELDS:
        cd = (outputs({**x0, name: x0[name] + h}) - outputs({**x0, name: x0[name] - h})) / (2 * h)
        for i, o in enumerate(rep["outputs"]):
            p = next(p for p in o["params"] if p["field"] == name)
            assert p["value"] == x0[name]
            assert p["per_unit"] == pytest.approx(cd[i], rel=1e-5, abs=1e-8), (o["name"], name)
            assert p["elasticity"] == pytest.approx(p["per_unit"] * x0[name] / o["value"],
                                                    rel=1e-12)
    assert max(abs(p["per_unit"]) for o in rep["outputs"] for p in o["params"]) > 1e-3


@pytest.mark.parametrize("extra, match", [
    ([], "the line-contact quantity 'line_te_ptp_um' needs the operating point: torque_Nm"),
    (["--torque-Nm", "300", "--misalign", "dE=0.01"],
     "scenario key 'dE_mm' is not one of the line outputs' (allowed: f_ma_um)"),
    (["--torque-Nm", "300", "--f-ma-um", "5000"], "--f-ma-um = 5000"),
    (["--torque-Nm", "300", "--slices", "0"], "--slices = 0"),
])
def test_line_sensitivity_refusals(capsys, extra, match):
    assert main(["sensitivity", "example:helical_microgeometry", "--outputs",
                 "line_te_ptp_um", "--params", "microgeometry.pinion.tip_relief_um",
                 *extra]) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1


def test_tca_sensitivity_refuses_a_mesh_misalignment(capsys):
    assert main(["sensitivity", "example:khk_spur_12x24", "--outputs", "contact_ratio",
                 "--params", "pair.x1", "--f-ma-um", "5"]) == 2
    err = capsys.readouterr().err
    assert "scenario key 'f_ma_um' is not one of the tca outputs'" in err


def test_member_variable_of_a_design_whose_flanks_differ_is_refused(tmp_path):
    """``microgeometry.pinion.KEY`` moves both pinion flanks; where the design's two
    flanks differ in KEY the start is ambiguous: refused, naming the flank to give."""
    design = read_toml("example:helical_microgeometry")
    mg = design["microgeometry"]
    mg["pinion_drive"] = dict(mg.pop("pinion"))
    mg["pinion_coast"] = dict(mg["pinion_drive"], tip_relief_um=5.0)
    (tmp_path / "d.toml").write_text(dumps_toml(design))
    text = _replace(STUDY, 'design = "example:helical_microgeometry"', 'design = "d.toml"')
    with pytest.raises(ValueError, match=r"\[\[variables\]\] 1 \(microgeometry.pinion."
                                         r"tip_relief_um\): the design's pinion flanks differ "
                                         r"in tip_relief_um .*microgeometry.pinion_drive"):
        sr.set_up(read_study(_write(tmp_path, text)))


def test_a_scenario_with_one_unconverged_position_is_flagged(problem):
    """The acceptance reads every position of a scenario: one position of one scenario
    not converged flags that scenario (and only it), with the count of valid ones."""
    from gearjax.studies.line_route import line_flags
    prob, _ = problem
    res = sr.start_point(prob)[1]
    conv = np.asarray(res.converged)
    assert conv.ndim == 2 and conv.all()
    bad = conv.copy()
    bad[1, 3] = False
    f = [line_flags(res._replace(converged=bad), None, k) for k in range(bad.shape[0])]
    assert not f[1]["converged"] and f[1]["n_valid"] == bad.shape[1] - 1
    assert all(g["converged"] and g["n_valid"] == bad.shape[1] for k, g in enumerate(f)
               if k != 1)


def test_sweep_flags_are_each_rows_own():
    """The per-row flags and valid counts of a chunk (``chunk_flags``), on a line study's
    outputs laid out by hand: row 1 has one unconverged position in scenario 0, row 2 one
    invalid friction point's position in scenario 1.  Catches: a row's flags or counts
    read from another row (row 0's), or from the loads where the efficiency's validity
    decides."""
    from types import SimpleNamespace
    from typing import NamedTuple

    from gearjax.studies.sweep import chunk_flags

    class Res(NamedTuple):
        converged: np.ndarray

    class Eff(NamedTuple):
        valid: np.ndarray

    conv = np.ones((3, 2, 5), bool)
    conv[1, 0, 2] = False
    valid = conv.copy()
    valid[2, 1, 4] = False
    prob = SimpleNamespace(route="line", scenarios=[{}, {}])
    fl, nv = chunk_flags(prob, Res(conv), None)
    assert fl["converged"] == [[True, True], [False, True], [True, True]]
    assert nv == [[5, 5], [4, 5], [5, 5]]
    fl, nv = chunk_flags(prob, Res(conv), Eff(valid))
    assert fl["converged"] == [[True, True], [False, True], [True, False]]
    assert nv == [[5, 5], [4, 5], [5, 4]]
    assert not any(any(r) for r in fl["edge_contact"])
