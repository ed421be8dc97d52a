"""Study files (gearjax.studies.study_file) and design write-back (GearFamily.design_data):
every bad entry refused with one line naming it, before any compilation; every family's
design round-trips through its file with a changed field."""

import dataclasses
import math

import numpy as np
import pytest

import gearjax as gj
from gearjax.io import design_from_dict
from gearjax.studies.study_file import list_studies, read_study
from gearjax.tca.result import family_of
from gearjax.studies.study_run import set_up

GOOD = """
[study]
name = "s1"
design = "example:khk_spur_12x24"

[operating]
torque_Nm = 60.0
pinion_rpm = 3000.0
oil = "mineral_vg100"
sigma_um = 0.4

[[variables]]
field = "pair.x1"
lower = 0.3
upper = 0.75

[[objective]]
quantity = "power_loss_W"

[[constraints]]
quantity = "contact_ratio"
lower = 1.25
"""


def _write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return str(p)


def test_good_file_and_defaults(tmp_path):
    st = read_study(_write(tmp_path, GOOD))
    assert st.name == "s1" and st.side == "drive" and st.method == "augmented_lagrangian"
    assert st.quantities == ["power_loss_W", "contact_ratio"]
    v = st.variables[0]
    assert v.bounds(0.6) == (0.3, 0.75)
    # a change relative to the design's value, in degrees for a field in rad
    st2 = read_study(_write(tmp_path, GOOD.replace(
        'field = "pair.x1"\nlower = 0.3\nupper = 0.75',
        'field = "pair.pressure_angle"\nchange = [-1.0, 2.0]\nunit = "deg"')))
    lo, hi = st2.variables[0].bounds(0.35)
    assert lo == pytest.approx(0.35 - math.radians(1.0)) and hi == pytest.approx(
        0.35 + math.radians(2.0))


def test_path_quantity_adds_the_mask_margin_constraint(tmp_path):
    st = read_study(_write(tmp_path, GOOD.replace('quantity = "power_loss_W"',
                                                  'quantity = "max_abs_srr"')))
    added = [c for c in st.constraints if c.added]
    assert len(added) == 1 and added[0].quantity == "min_margin_mm" and added[0].lower == 0.0


@pytest.mark.parametrize("old, new, match", [
    ('quantity = "power_loss_W"', 'quantity = "power_los_W"', r"\[\[objective\]\] 1: unknown "
                                                               r"quantity 'power_los_W'"),
    ("lower = 0.3\nupper = 0.75", "lower = 0.75\nupper = 0.3", r"\[\[variables\]\] 1 "
                                                                r"\(pair.x1\): empty"),
    ("lower = 0.3\nupper = 0.75", "change = [0.1, 0.2]", r"must contain 0"),
    ("lower = 0.3\nupper = 0.75", "lower = 0.3", r"missing the required key 'upper'"),
    ("lower = 0.3\nupper = 0.75", "", r"either lower and upper"),
    ('sigma_um = 0.4\n', "", r"'power_loss_W' needs the operating point: sigma_um"),
    ('[[objective]]\nquantity = "power_loss_W"\n', "", r"no \[\[objective\]\]"),
    ('lower = 1.25', 'lower = 1.25\nupper = 1.0', r"empty range \[1.25, 1\]"),
    ('lower = 1.25', 'bound = 1.25', r"unknown key 'bound' in \[\[constraints\]\] 1 \(allowed"),
    ("lower = 0.3\nupper = 0.75", "lower = nan\nupper = 0.75",
     r"^\[\[variables\]\] 1: lower = nan must be a finite number$"),
    ('name = "s1"', 'name = "s 1"', r"\[study\] name = 's 1'"),
    ('[[objective]]\nquantity = "power_loss_W"',
     '[[objective]]\nquantity = "power_loss_W"\nweight = 0', r"weight = 0 must be > 0"),
    ('sigma_um = 0.4\n', 'sigma_um = 0.4\n[optimizer]\nmethod = "bfgs"\n',
     r"method = 'bfgs' must be one of"),
    ('sigma_um = 0.4\n', 'sigma_um = 0.4\n[optimizer]\nmethod = "slsqp"\nstarts = 3\n',
     r"starts = 3: the slsqp method runs one start"),
    ('sigma_um = 0.4\n', 'sigma_um = 0.4\n[scenarios]\ndE_mm = []\n', r"dE_mm = \[\] is empty"),
    ('sigma_um = 0.4\n', 'sigma_um = 0.4\n[scenarios]\ndQ_mm = 1\n',
     r"unknown key 'scenarios.dQ_mm'"),
    ('oil = "mineral_vg100"', 'oil = "olive"', r"\[operating\] oil = 'olive' must be one of"),
    ('torque_Nm = 60.0', 'torque_Nm = "60"', r"\[operating\] torque_Nm = '60' must be a number"),
    ('sigma_um = 0.4', 'sigma_um = 0.4\nedge_softening_mm = -1',
     r"\[operating\] edge_softening_mm = -1"),
    ('sigma_um = 0.4\n', 'sigma_um = 0.4\n[sweep]\nmethod = "lhs"\n',
     r"\[sweep\] method = 'lhs' must be one of"),
    ('sigma_um = 0.4\n', 'sigma_um = 0.4\n[sweep]\npoints = 1\n',
     r"\[sweep\] points = 1 is outside the allowed range \[2, inf\)"),
    ('sigma_um = 0.4\n', 'sigma_um = 0.4\n[sweep]\nchunk = 0\n', r"\[sweep\] chunk = 0"),
    ('sigma_um = 0.4\n', 'sigma_um = 0.4\n[sweep]\nsize = 3\n', r"unknown key 'sweep.size'"),
])
def test_bad_entries_are_refused_with_one_line(tmp_path, old, new, match):
    assert old in GOOD
    with pytest.raises(ValueError, match=match) as exc:
        read_study(_write(tmp_path, GOOD.replace(old, new, 1)))
    assert "\n" not in str(exc.value)


def test_duplicate_variable_and_unknown_field(tmp_path):
    dup = GOOD.replace("[[objective]]", '[[variables]]\nfield = "pair.x1"\nchange = [-0.1, '
                       '0.1]\n\n[[objective]]')
    with pytest.raises(ValueError, match="'pair.x1' is given more than once"):
        read_study(_write(tmp_path, dup))
    st = read_study(_write(tmp_path, GOOD.replace('"pair.x1"', '"pair.x3"')))
    with pytest.raises(ValueError, match=r"\[\[variables\]\] 1: field 'pair.x3' is not a field "
                                         r"of the design's pair \(fields: pair.module"):
        set_up(st)
    # the design's own value outside absolute bounds
    st = read_study(_write(tmp_path, GOOD.replace("lower = 0.3", "lower = 0.65")))
    with pytest.raises(ValueError, match=r"design's value 0.6 is outside \[0.65, 0.75\]"):
        set_up(st)
    # a scenario out of range, before any work
    st = read_study(_write(tmp_path, GOOD.replace("sigma_um = 0.4\n", "sigma_um = 0.4\n"
                                                  "[scenarios]\ntorque_Nm = [60, -5]\n")))
    with pytest.raises(ValueError, match=r"scenario 2: torque_Nm = -5"):
        set_up(st)


def test_packaged_studies_read():
    names = list_studies()
    assert {"spur_efficiency", "hypoid_efficiency_te", "preset_bevel_robust_kappa",
            "vh_catt_cutter_radius", "hypoid_cutter_radius"} <= set(names)
    scenarios = {"preset_bevel_robust_kappa": 4, "vh_catt_cutter_radius": 2,
                 "helical_microgeometry_robust": 12}
    for n in names:
        st = read_study(f"example:{n}")
        assert st.name == n and st.variables and st.objective
        prob = set_up(st)          # fields, bounds and scenarios checked (no compilation)
        assert len(prob.scenarios) == scenarios.get(n, 1)


@pytest.mark.parametrize("example, field, delta, key", [
    ("khk_spur_12x24", "pair.x1", 0.05, ("pair", "profile_shift1", 0.65)),
    ("khk_helical_12x60", "lead_crown", 1e-4, ("modification", "lead_crown_per_mm", 1e-4)),
    ("khk_spur_12x24", "pair.pressure_angle", math.radians(0.5),
     ("pair", "normal_pressure_angle_deg", 20.5)),
    ("vh_catt_17x23", "cutter_radius1", 5.0, ("pair", "cutter_radius1_mm", 405.0)),
    ("preset_te_bevel_10x30", "rho1", 1.0, ("flanks", "profile_radius_pinion_mm", 17.0)),
])
def test_design_write_back_round_trips(example, field, delta, key):
    d = gj.load_design(f"example:{example}")
    ad = family_of(d)
    p = ad.fam.user_pair(ad.fam.setup(d, "drive")[0])
    v = float(np.asarray(gj.get_fields(p, [field])[field]))
    data = ad.design_data(d, gj.with_fields(p, {field: v + delta}), "drive")
    table, k, expect = key
    assert data[table][k] == pytest.approx(expect, rel=1e-12)
    back = ad.fam.pair(design_from_dict(data))
    assert float(np.asarray(gj.get_fields(back, [field])[field])) == pytest.approx(
        v + delta, rel=1e-12, abs=1e-15)
    # the unchanged fields are not written
    assert data == {**d.to_dict(), table: {**d.to_dict().get(table, {}), k: data[table][k]}}


def test_preset_kappa_is_written_as_the_preset_te():
    d = gj.load_design("example:preset_te_bevel_10x30")
    ad = family_of(d)
    p = ad.fam.pair(d)
    k = float(p.kappa)
    data = ad.design_data(d, gj.with_fields(p, {"kappa": 1.25 * k}), "drive")
    # te = kappa (t_min - t_m)^2 is linear in kappa at fixed geometry
    assert data["preset"]["te_arcsec"] == pytest.approx(1.25 * d.data["preset"]["te_arcsec"],
                                                        rel=1e-10)
    back = ad.fam.pair(design_from_dict(data))
    assert float(back.kappa) == pytest.approx(1.25 * k, rel=1e-10)


def test_hypoid_write_back_and_refusal_of_an_unwritable_field():
    d = gj.load_design("example:hypoid_iso_10x41_synthesised")
    ad = family_of(d)
    p = ad.fam.user_pair(ad.fam.setup(d, "drive")[0])
    name = "pinion.machine.tilt"
    v = float(gj.get_fields(p, [name])[name])
    data = ad.design_data(d, gj.with_fields(p, {name: v + 0.01}), "drive")
    assert data["pinion"]["concave"]["machine"]["tilt"] == pytest.approx(
        math.degrees(v + 0.01), rel=1e-12)
    back = ad.fam.user_pair(ad.fam.setup(design_from_dict(data), "drive")[0])
    assert float(gj.get_fields(back, [name])[name]) == pytest.approx(v + 0.01, rel=1e-12)
    # a field without a design-file key (an involute pair's tooth numbers are static; its
    # tip, a traced array here, has none) is refused by name
    s = gj.load_design("example:khk_spur_12x24")
    sp = family_of(s).fam.pair(s)
    fam = family_of(s).fam
    saved = dict(fam.file_fields)
    try:
        fam.file_fields = {k: v for k, v in saved.items() if k != "face_width"}
        with pytest.raises(ValueError, match="field 'face_width' of a involute pair has no "
                                             "design-file key"):
            family_of(s).design_data(s, gj.with_fields(sp, {"face_width": 25.0}), "drive")
    finally:
        fam.file_fields = saved


def test_scale_and_bounds_in_degrees_and_scenario_combinations(tmp_path):
    from gearjax.studies.study_run import set_up
    text = GOOD.replace('field = "pair.x1"\nlower = 0.3\nupper = 0.75',
                        'field = "pair.pressure_angle"\nchange = [-1.0, 2.0]\nunit = "deg"\n'
                        'scale = 0.5')
    text = text.replace("sigma_um = 0.4\n", "sigma_um = 0.4\n[scenarios]\ntorque_Nm = [40, 60]\n"
                        "dE_mm = [0.0, 0.02, -0.03]\n")
    prob = set_up(read_study(_write(tmp_path, text)))
    deg = math.pi / 180.0
    assert float(prob.data.scale[0]) == pytest.approx(0.5 * deg, rel=1e-14)
    # u bounds: change / scale, both in degrees
    assert prob.lower[0] == pytest.approx(-2.0) and prob.upper[0] == pytest.approx(4.0)
    # every combination of the lists, in order
    combos = [(s["torque_Nm"], s["dE_mm"]) for s in prob.scenarios]
    assert combos == [(40, 0.0), (40, 0.02), (40, -0.03), (60, 0.0), (60, 0.02), (60, -0.03)]
    assert np.asarray(prob.data.mis.dE).tolist() == [0.0, 0.02, -0.03] * 2
    assert all(s["pinion_rpm"] == 3000.0 for s in prob.scenarios)


def test_a_margin_bound_from_above_still_gets_the_mask_constraint(tmp_path):
    text = GOOD.replace('quantity = "power_loss_W"', 'quantity = "max_abs_srr"')
    text += '\n[[constraints]]\nquantity = "min_margin_mm"\nupper = 5.0\n'
    st = read_study(_write(tmp_path, text))
    added = [c for c in st.constraints if c.added]
    assert [(c.quantity, c.lower, c.upper) for c in added] == [("min_margin_mm", 0.0, None)]


def test_acceptance_reasons_each_check():
    from gearjax.studies.study_run import acceptance_reasons
    ok = dict(converged=True, edge_contact=False, n_valid=13)
    good = dict(opt={"converged": True, "message": "converged"}, feasibility=0.0, tol=1e-4,
                file_error=None, difference=0.0, x=np.array([1.0, 2.0]), flags0=[ok],
                flags1=[dict(ok)], hard=(1.0, 0.9))
    assert acceptance_reasons(**good) == []
    cases = [
        (dict(opt={"converged": False, "message": "step limit"}), "stopping test"),
        (dict(feasibility=2e-4), "constraints violated by 0.0002"),
        (dict(file_error="x1 undercuts"), "refused by its design-file checks: x1 undercuts"),
        (dict(difference=1e-6), "does not reproduce"),
        (dict(hard=(1.0, 1.01)), "hard model"),
        (dict(flags1=[dict(ok, converged=False)]), "scenario 1: the end design's TCA"),
        (dict(flags1=[dict(ok, edge_contact=True)]), "scenario 1: the end design has edge"),
        (dict(flags1=[dict(ok, n_valid=12)]), "fewer valid positions of the cycle at the end "
                                              "(12 < 13)"),
    ]
    for change, text in cases:
        r = acceptance_reasons(**{**good, **change})
        assert len(r) == 1 and text in r[0], (change, r)
    # an edge contact present at the start is not a new one; no hard model: not checked
    assert acceptance_reasons(**{**good, "flags0": [dict(ok, edge_contact=True)],
                                 "flags1": [dict(ok, edge_contact=True)], "hard": None}) == []
    # an infeasible start may cost objective: the hard model may rise as much as the
    # softened one (plus tol), not more
    assert acceptance_reasons(**{**good, "hard": (1.07, 1.08), "soft": (1.0, 1.01)}) == []
    assert acceptance_reasons(**{**good, "hard": (1.07, 1.08), "soft": (1.0, 1.00995)}) == []
    r = acceptance_reasons(**{**good, "hard": (1.07, 1.08), "soft": (1.0, 1.0098)})
    assert len(r) == 1 and "(softened: 1 -> 1.0098)" in r[0]
    r = acceptance_reasons(**{**good, "hard": (1.07, 1.08), "soft": (1.0, 0.99)})
    assert len(r) == 1 and "hard model" in r[0]
    # a softened objective that fell asks only that the hard one did not rise, not that
    # it fell as much
    assert acceptance_reasons(**{**good, "hard": (1.0, 0.95), "soft": (1.0, 0.8)}) == []


def test_soften_edges():
    import jax.numpy as jnp
    from gearjax.loading.mesh_efficiency import soften_edges
    q, c = jnp.array([1e-5, 2e-5, 3e-5]), jnp.array([1e-4, 0.0, 2e-4])
    m = jnp.array([0.05, 0.1, 0.5])
    q2, c2, s = soften_edges(q, c, m, 0.2)
    t = np.array([0.25, 0.5, 1.0])
    np.testing.assert_allclose(np.asarray(s), 3 * t ** 2 - 2 * t ** 3, rtol=1e-14)
    # the whole pair compliance (linear and Hertz) grows as 1/s
    np.testing.assert_allclose(np.asarray(q2), np.asarray(q) / np.asarray(s), rtol=1e-14)
    np.testing.assert_allclose(np.asarray(c2), np.asarray(c) / np.asarray(s), rtol=1e-14)
    q3, c3, s3 = soften_edges(q, c, m, 0.0)
    assert q3 is q and c3 is c and np.all(np.asarray(s3) == 1.0)


def test_sweep_table_defaults(tmp_path):
    from gearjax.studies.study_file import SWEEP_DEFAULTS
    assert read_study(_write(tmp_path, GOOD)).sweep == SWEEP_DEFAULTS
    st = read_study(_write(tmp_path, GOOD + '\n[sweep]\nmethod = "grid"\npoints = 3\n'))
    assert st.sweep == dict(SWEEP_DEFAULTS, method="grid", points=3)


def test_sweep_points_grid_and_latin_hypercube():
    """Row 0 the design's own point; a grid: every combination, the bounds included, the
    last variable fastest; a Latin hypercube: one point in each of the n equal strata of
    every variable's range, seeded (same seed, same points)."""
    from gearjax.studies.sweep import MAX_DESIGNS, sample_points
    lo, hi = np.array([-1.0, -0.5, 0.0]), np.array([2.0, 0.5, 3.0])
    g = sample_points(lo, hi, "grid", points=3)
    assert g.shape == (1 + 27, 3) and np.all(g[0] == 0.0)
    assert {tuple(r) for r in g[1:]} == {(a, b, c) for a in (-1.0, 0.5, 2.0)
                                         for b in (-0.5, 0.0, 0.5) for c in (0.0, 1.5, 3.0)}
    assert list(g[1:4, 2]) == [0.0, 1.5, 3.0] and g[1, 0] == g[9, 0] == -1.0
    n = 40
    r = sample_points(lo, hi, "random", samples=n, seed=3)
    assert r.shape == (n + 1, 3) and np.all(r[0] == 0.0)
    strata = np.floor((r[1:] - lo) / (hi - lo) * n).astype(int)
    for i in range(3):
        assert sorted(strata[:, i]) == list(range(n)), i
    # the strata of the variables are paired at random, not in the same order (a shared
    # permutation would put every point on the box's diagonal)
    for i, j in ((0, 1), (0, 2), (1, 2)):
        assert abs(np.corrcoef(strata[:, i], strata[:, j])[0, 1]) < 0.6, (i, j)
    assert np.array_equal(r, sample_points(lo, hi, "random", samples=n, seed=3))
    assert not np.array_equal(r, sample_points(lo, hi, "random", samples=n, seed=4))
    with pytest.raises(ValueError, match=r"\[sweep\] points = 101: 1030301 designs"):
        sample_points(lo, hi, "grid", points=101)
    with pytest.raises(ValueError, match=rf"samples = {MAX_DESIGNS + 1} is more"):
        sample_points(lo, hi, "random", samples=MAX_DESIGNS + 1)


def test_a_sweep_uses_the_hard_loaded_model():
    """``gearjax sweep`` reports the loaded quantities of ``gearjax efficiency`` (no edge
    softening); the study itself keeps its soft active set (set up, no compilation)."""
    from gearjax.studies.sweep import set_up_sweep
    st = read_study("example:spur_efficiency")
    assert set_up(st).soft == 0.2
    prob = set_up_sweep(st)
    assert prob.soft == 0.0 and prob.chain.options["edge_softening_mm"] == 0.0
    assert "edge_load_share" not in prob.study.quantities
    # also where the study file sets its own softening
    own = dataclasses.replace(st, operating={**st.operating, "edge_softening_mm": 0.3})
    assert set_up(own).soft == 0.3 and set_up_sweep(own).soft == 0.0


def test_sweep_chunks_units_and_constraints(tmp_path):
    """The pieces of a sweep that need no compilation: the chunk rounded up to a
    multiple of the devices (and only then), the points in the file's units (degrees
    for a ``unit = "deg"`` variable), the constraints checked (the study's own margin
    constraint kept, the one it adds for its fixed mask left out)."""
    import math
    from gearjax.studies.sweep import chunk_size, file_units, steady_rate, sweep_constraints
    assert [chunk_size(c, d) for c, d in ((3, 4), (4, 4), (5, 4), (1, 1), (16, 1), (0, 2))] \
        == [4, 4, 8, 1, 16, 2]
    # the rate after the first chunk (it carries the compilation); none with one chunk
    assert steady_rate(10, 4, 5.0, 3.0) == 3.0 and steady_rate(4, 4, 5.0, 5.0) is None
    assert steady_rate(3, 4, 2.0, 2.0) is None
    # the best design: the feasible row of the smallest J, counted among all rows
    from gearjax.studies.sweep import best_row
    assert best_row([0.5, 0.9, 0.7, 0.8], [False, True, False, True]) == 3
    assert best_row([1.0, 2.0], [False, False]) is None
    st = read_study(_write(tmp_path, GOOD.replace(
        'field = "pair.x1"\nlower = 0.3\nupper = 0.75',
        'field = "pair.pressure_angle"\nunit = "deg"\nlower = 18.0\nupper = 22.0')))
    prob = set_up(st)
    x = file_units(prob, np.array([[0.0], [prob.lower[0]], [prob.upper[0]]]))
    np.testing.assert_allclose(x[:, 0], [20.0, 18.0, 22.0], rtol=1e-12)
    assert math.isclose(float(prob.x0[0]), math.radians(20.0), rel_tol=1e-12)
    srr = GOOD.replace('quantity = "power_loss_W"', 'quantity = "max_abs_srr"')
    added = read_study(_write(tmp_path, srr))
    assert [c.quantity for c in sweep_constraints(added)] == [
        c.quantity for c in added.constraints if not c.added]
    own = read_study(_write(tmp_path, srr + '\n[[constraints]]\nquantity = "min_margin_mm"\n'
                                              'lower = 0.1\n'))
    assert [(c.quantity, c.lower) for c in sweep_constraints(own)][-1] == ("min_margin_mm", 0.1)
