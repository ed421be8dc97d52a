"""`gearjax optimize` on the packaged spur studies, their checks, the smooth quantities.

References: the hard model of `gearjax.mesh_efficiency` on a written design file (a
second route through the chain), SciPy's SLSQP on the same study (a second optimiser),
central differences for the sensitivities, the synthesis target of the ISO 10/41
hypoid pinion (TE drop 8 arcsec at half a pitch), and the concrete tooth-form checks of
the involute loader."""

import json
import math
import re

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.cli import main
from gearjax.studies import study_run as sr
from gearjax.studies.quantities import smooth_max, smooth_min, te_ptp_continuous
from gearjax.studies.study_file import read_study
from notebook_run import images, run_notebook


@pytest.fixture(scope="module")
def sliding_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("sliding")
    rc = main(["optimize", "example:spur_sliding", "--out", str(out)])
    rep = json.loads((out / "spur_sliding_history.json").read_text())
    return rc, out, rep


def test_sliding_study_converges_on_the_tooth_form_limit(sliding_run):
    rc, out, rep = sliding_run
    assert rc == 0 and rep["checks"]["accepted"], rep["checks"]["reasons"]
    opt = rep["optimizer"]
    assert opt["converged"] and opt["method"] == "augmented_lagrangian"
    for k in ("stationarity", "feasibility", "complementarity"):
        assert opt[k] <= opt["tolerance"]
    q = rep["quantities"]
    assert q["max_abs_srr"]["end"][0] < 0.95 * q["max_abs_srr"]["start"][0]
    # the optimum lies on the tip/fillet limit the study added (active: multiplier > 0),
    # with x2 on its upper bound; the contact ratio and the mask's margin are inactive
    names = [c["quantity"] for c in rep["constraints"]]
    assert names == ["contact_ratio", "min_margin_mm", "tooth_form_margin_mm"]
    assert abs(q["tooth_form_margin_mm"]["end"][0]) < 1e-6
    assert opt["multipliers"][2] > 1e-3 and max(opt["multipliers"][:2]) == 0.0
    v = {d["field"]: d for d in rep["variables"]}
    assert v["pair.x2"]["end"] == pytest.approx(0.6, abs=1e-9)
    # the written file is the end design, and the loader accepts it (tooth form valid)
    d = gj.load_design(str(out / "spur_sliding_optimised.toml"))
    assert float(d.design.pair.x1) == pytest.approx(v["pair.x1"]["end"], rel=1e-12)
    assert d.data["design"]["name"] == "khk_spur_12x24_optimised"
    assert d.data["design"]["description"].endswith(
        "; the end design of study spur_sliding (gearjax optimize)")
    assert (out / "spur_sliding.png").stat().st_size > 10_000


def test_slsqp_finds_the_same_optimum(sliding_run):
    rep = sliding_run[2]
    import dataclasses
    prob = sr.set_up(dataclasses.replace(read_study("example:spur_sliding"), method="slsqp",
                                         max_iterations=60))
    r = sr.run_study(prob)
    assert r.accepted and r.report["optimizer"]["converged"]
    # the start and the end evaluation ran one traced program (the scales set between
    # them keep their shapes: a retrace costs seconds of tracing per study)
    assert prob.evaluate_program._cache_size() == 1
    end_al = {d["field"]: d["end"] for d in rep["variables"]}
    for d in r.report["variables"]:
        assert d["end"] == pytest.approx(end_al[d["field"]], abs=1e-6)
    assert r.report["objective"]["end"] == pytest.approx(rep["objective"]["end"], abs=1e-9)
    # SLSQP runs on the forward-mode Jacobian of the quantities.  At this point on the
    # tooth-form limit (an SLSQP iterate) the margin's and the contact ratio's tangents
    # were NaN (jnp.min's derivative, see gearjax.tca.path.smallest_margin) and SLSQP
    # stopped ("Singular matrix E").  The point is a kink of both (the pinion's form
    # circle and the gear's tip limit the path together): each derivative is one of the
    # one-sided differences
    u = np.array([0.5161506371832055, 0.6])
    dQ, Q = (np.asarray(a)[0] for a in sr.quantity_jacobian(prob)(u, prob.data))
    h = 1e-7
    for j in range(2):
        e = np.eye(2)[j] * h
        q0 = np.asarray(sr.evaluate(prob, u)[0][0])
        right = (np.asarray(sr.evaluate(prob, u + e)[0][0]) - q0) / h
        left = (q0 - np.asarray(sr.evaluate(prob, u - e)[0][0])) / h
        err = np.minimum(np.abs(dQ[:, j] - right), np.abs(dQ[:, j] - left))
        assert np.all(err <= 1e-4 * np.abs(dQ[:, j]) + 1e-6), (j, dQ[:, j], left, right)


@pytest.fixture(scope="module")
def efficiency_problem():
    prob = sr.set_up(read_study("example:spur_efficiency"))
    sr.start_point(prob)
    return prob


def test_hard_model_recheck_is_gearjax_efficiency(efficiency_problem):
    """The study's hard-model values at a moved design equal `mesh_efficiency` of that
    design written to a file and read back (a fresh TCA): a second route."""
    from gearjax.io import design_from_dict
    from gearjax.tca.result import family_of
    prob = efficiency_problem
    sc = np.asarray(prob.data.scale)
    x = np.array([0.45, 0.55])
    Q, _, _, H = sr.evaluate(prob, (x - prob.x0) / sc)
    pair = gj.with_fields(prob.data.pair0, {"pair.x1": x[0], "pair.x2": x[1]})
    d = design_from_dict(family_of(prob.design).design_data(prob.design, pair, "drive"))
    eff, _ = gj.mesh_efficiency(d, 60.0, 3000.0, gj.tribology.get_oil("mineral_vg100"),
                                gj.tribology.make_surface(0.4))
    i = prob.study.quantities.index("power_loss_W")
    assert float(H[0, i]) == pytest.approx(float(eff.power_in * (1 - eff.mean_efficiency)),
                                           rel=1e-9)
    j = prob.study.quantities.index("peak_pressure_MPa")
    assert float(H[0, j]) >= float(eff.max_p_max) - 1e-6          # smooth max >= max
    assert float(H[0, j]) <= float(eff.max_p_max) + 5.0 * math.log(72)
    # the start's hard value is that of gearjax efficiency on the example (247.300 W)
    H0 = sr.evaluate(prob, np.zeros(2))[3]
    assert float(H0[0, i]) == pytest.approx(247.300, abs=5e-3)


def test_run_study_hands_the_softened_objective_to_the_acceptance(efficiency_problem,
                                                                   monkeypatch):
    """run_study gives ``acceptance_reasons`` the hard model's objective and the softened
    one's, start and end (an infeasible start may cost objective: the hard model may rise
    as far as the softened one).  The optimiser is replaced by a fixed step (the wiring
    is under test, not the optimiser); the programs are those compiled above."""
    from types import SimpleNamespace
    seen = {}
    real = sr.acceptance_reasons

    def spy(*args, **kw):
        seen["args"] = args
        return real(*args, **kw)

    u1 = np.array([-0.2, 0.1])
    fake = SimpleNamespace(x=u1, outer_iterations=1, message="converged", converged=True,
                           evaluations=1, stationarity=0.0, feasibility=0.0,
                           complementarity=0.0, multipliers=np.zeros(4),
                           history_value=[1.0], history_feasibility=[0.0],
                           history_stationarity=[0.0])
    monkeypatch.setattr(sr, "acceptance_reasons", spy)
    monkeypatch.setattr(sr, "_run_al", lambda prob, callback: (fake, {}))
    rep = sr.run_study(efficiency_problem).report
    hard, soft = seen["args"][-2:]
    obj = rep["objective"]
    assert soft == pytest.approx((obj["start"], obj["end"]), rel=1e-12)
    assert hard == pytest.approx((obj["start_hard_model"], obj["end_hard_model"]), rel=1e-12)
    assert soft[1] != soft[0] and hard[1] != hard[0]


def test_soft_active_set_removes_the_hand_over_jump(efficiency_problem):
    """Across x1 = 0.700 .. 0.7025 a second tooth pair leaves contact at the first
    position of the cycle: with the hard model the cycle-mean loss jumps by about 3 W
    (the position's load goes from two pairs to one); with the study's edge softening
    (0.2 mm) the loss and its slope are continuous."""
    prob = efficiency_problem
    sc = np.asarray(prob.data.scale)
    x1s = np.linspace(0.69, 0.71, 21)
    soft, hard = [], []
    for x1 in x1s:
        Q, _, _, H = sr.evaluate(prob, (np.array([x1, 0.6]) - prob.x0) / sc)
        soft.append(float(Q[0, 0]))
        hard.append(float(H[0, 0]))
    dh, ds = np.diff(hard), np.diff(soft)
    assert np.max(np.abs(dh)) > 2.0                    # the jump (W per 0.001 of x1)
    assert np.max(np.abs(ds)) < 0.1                    # continuous
    # the slope: from step to step it changes by less than 1 % of the hard model's
    # apparent slope across the jump (about 2850 W per unit x1; measured 21 W per unit)
    slope_s, slope_h = ds / np.diff(x1s), dh / np.diff(x1s)
    assert np.max(np.abs(np.diff(slope_s))) < 0.01 * np.max(np.abs(slope_h))


def test_worst_case_over_scenarios_is_not_finite_when_a_scenario_is_not():
    """The objective's worst case over scenarios (``over = "max"``) must not leave out a
    scenario whose value is not finite: a VH-CATT study lowered its worst-case power
    loss from 1.00 to 0.18 (scaled) by a step that left one scenario with no valid
    position (power loss NaN), which the smooth maximum had dropped.  Planted bug
    caught: the smooth maximum over scenarios without the finiteness test."""
    from types import SimpleNamespace
    st = read_study("example:preset_bevel_robust_kappa")
    qi = st.quantities.index("te_ptp_arcsec")
    Q = np.ones((4, len(st.quantities)))
    Q[:, qi] = [9.0, 8.0, 7.0, 6.0]
    data = SimpleNamespace(term_scale=jnp.ones(len(st.objective)),
                           con_scale=jnp.ones(len(st.constraints)))
    J, g = sr.combine(st, jnp.asarray(Q), data)
    assert 9.0 <= float(J) <= 9.0 + sr.SCENARIO_TEMPERATURE * math.log(4)
    # one constraint row per bound and scenario: the count the optimiser is given
    assert g.shape == (sr.n_constraint_rows(sr.set_up(st)),) == (8,)
    Q[1, qi] = np.nan
    J, g = sr.combine(st, jnp.asarray(Q), data)
    assert np.isnan(float(J))


def test_valid_share_is_the_share_of_valid_positions():
    """``valid_share``: valid positions over all positions of the cycle (not over the
    loaded ones, not the count)."""
    from types import SimpleNamespace
    from gearjax.studies.quantities import QUANTITIES
    eff = SimpleNamespace(valid=jnp.array([True, False, True, True, False, True, True, True]))
    assert float(QUANTITIES["valid_share"].fn(None, eff, None, None)) == 0.75


def test_forward_mode_for_few_variables_or_several_scenarios():
    """study_run.derivatives: forward mode up to FORWARD_MAX_VARIABLES variables or with
    several scenarios (where reverse mode through the scenarios' vmap gave NaN), reverse
    mode otherwise (the 13-variable hypoid study)."""
    from types import SimpleNamespace
    n = sr.FORWARD_MAX_VARIABLES
    mode = lambda nv, ns: sr.derivatives(SimpleNamespace(fields=["f"] * nv,  # noqa: E731
                                                         scenarios=[{}] * ns))
    assert mode(n, 1) == "forward" and mode(n + 1, 1) == "reverse"
    assert mode(n + 9, 4) == "forward" and mode(1, 1) == "forward"


def test_smooth_extrema_bounds():
    q = jnp.array([1.0, 3.0, 2.0, jnp.nan, 2.9])
    m = jnp.array([True, True, True, True, False])
    T = 0.1
    hi = float(smooth_max(q, m, T))
    assert 3.0 <= hi <= 3.0 + T * math.log(3)           # NaN and masked entries left out
    lo = float(smooth_min(q, m, T))
    assert 1.0 - T * math.log(3) <= lo <= 1.0
    assert float(smooth_max(q, jnp.zeros(5, bool), T)) == -math.inf


def test_smallest_margin_takes_the_derivative_of_the_smallest_part():
    import jax
    from gearjax.tca.path import smallest_margin

    def parts(x):                       # three parts at two points; the smallest differ
        return jnp.stack([jnp.array([x[0], 5.0]), jnp.array([2.0, x[1] ** 2]),
                          jnp.array([3.0, 7.0])])
    x = jnp.array([1.0, 2.0])
    np.testing.assert_array_equal(smallest_margin(parts(x)), jnp.min(parts(x), axis=0))
    for jac in (jax.jacfwd, jax.jacrev):
        np.testing.assert_array_equal(jac(lambda x: smallest_margin(parts(x)))(x),
                                      [[1.0, 0.0], [0.0, 4.0]])


def test_continuous_te_ptp_meets_the_synthesis_target():
    """The ISO 10/41 pinion was synthesised for a TE drop of 8 arcsec at half a pitch
    from the apex: with the hand-overs at their continuous positions and the top at the
    vertex the p-t-p is 8 arcsec (7.9993 / 8.0002) on the default grid, on both sides;
    the grid value misses the coast side's hand-over by 0.8 arcsec."""
    d = gj.load_design("example:hypoid_iso_10x41_synthesised")
    out = {}
    for side in ("drive", "coast"):
        r = gj.run_tca(d, side=side)
        out[side] = (float(r.ptp / gj.ARCSEC), float(te_ptp_continuous(r)))
    for side, (grid, cont) in out.items():
        assert cont == pytest.approx(8.0, abs=0.002), side
    assert abs(out["coast"][0] - 8.0) > 0.5


def test_load_carried_on_crossing_flanks_is_flagged():
    """The ISO 10/41 pinion's edge of regression lies above its fillet boundary (an
    undercut generated flank, docs/tca.md "Crossing flanks"): on the default grid the
    drive path of pair 0 runs past it at its end.  The flag test of ``flanks_cross``
    (indefinite relative curvature) marks exactly the on-flank points that the
    independent route puts on the second sheet of the generated pinion flank (the sign
    of (E_u x E_v) . n, test_tca_hypoid._sheet), and the ellipse route agrees (no
    ellipse there).  Nominal: those points carry no load, no flag.  Under dE = +0.1 mm
    the load-carrying part of the path reaches them: ``crossing_flanks`` is raised
    (and a warning), where before this flag every other flag was clear and the TE
    p-t-p (7.05 arcsec) looked valid.  The study quantity ``handover_definiteness``
    changes sign with the flag.  Planted bugs caught: the determinant's sign or
    tolerance, the carrying mask dropped or inverted, the flag left out of flags()."""
    from gearjax.gears.hypoid.pair import flank_function
    from test_tca_hypoid import _sheet
    d = gj.load_design("example:hypoid_iso_10x41_synthesised")
    zero = dict(dE=0.0, dP=0.0, dG=0.0, dSigma=0.0)
    nom = gj.run_tca(d, side="drive")
    mis = gj.run_tca(d, gj.Misalignment(**{**zero, "dE": 0.1}), side="drive")
    pair = gj.hypoid.pair_flanks(d, "drive")
    surf = flank_function(pair.pinion, pair.pinion_crossing)
    sheet = jax.jit(jax.vmap(lambda uv: _sheet(surf, uv)))
    for res, carried in ((nom, False), (mis, True)):
        on = np.asarray(res.on_flank)
        cross = np.asarray(res.flanks_cross)
        s = np.asarray(sheet(res.path.uv1))
        second = s * s[s.shape[0] // 2] < 0.0        # against the reference contact
        assert np.array_equal(cross[on], second[on]) and second[on].sum() >= 2
        assert np.all(np.isinf(np.asarray(res.path.semi_major)[cross & on]))
        assert np.all(np.isfinite(np.asarray(res.path.semi_major)[on & ~cross]))
        loaded = res._carrying() & on & cross
        f = res.flags()
        assert f.pop("crossing_flanks") is carried is bool(loaded.any())
        assert not any(f[k] for k in ("edge_contact", "tip_contact", "face_end_contact",
                                      "low_contact_ratio", "large_te"))
        assert any("crossing flanks" in w for w in res.warnings()) is carried
    # the study quantity: the definiteness passes through 0 at the edge of regression,
    # linearly in the path position (a principal curvature through infinity), and its
    # smooth minimum over the nominal on-flank points lies within T ln n below the least
    from gearjax.studies.quantities import DEFINITENESS_TEMPERATURE, QUANTITIES
    from gearjax.tca.result import curvature_definiteness
    on = np.asarray(nom.on_flank)
    q = np.asarray(curvature_definiteness(nom.path))[on]
    assert np.array_equal(q < -1e-9, np.asarray(nom.flanks_cross)[on]) and q.min() < 0.0
    step = np.diff(q[-6:])                    # the last on-flank points: through the edge
    assert np.all(step < 0.0) and step.max() / step.min() > 0.9, step
    smin = float(QUANTITIES["min_definiteness"].fn(nom, None, on, None))
    assert q.min() - DEFINITENESS_TEMPERATURE * np.log(on.sum()) <= smin <= q.min()
    # at the hand-overs (the ends of the carrying interval) the definiteness is >= 0
    # exactly where the flag is clear: nominal 1.56e-3, under dE = +0.1 mm -6.5e-4
    from gearjax.studies.quantities import handover_definiteness
    for res, carried in ((nom, False), (mis, True)):
        hd = float(handover_definiteness(res))
        assert (hd < 0.0) is carried and abs(hd) > 1e-4, hd


def test_sweep_rows_and_acceptance_refuse_crossing_flanks():
    """A sweep row whose scenario carries load where the flanks cross is not ``ok``
    (each of the three flags alone, and a non-finite quantity); an end design that
    gains ``crossing_flanks`` is not accepted, one whose start had it already is."""
    from gearjax.studies.end_checks import acceptance_reasons
    from gearjax.studies.sweep import FLAG_KEYS, rows_ok
    flags = {k: np.zeros((5, 2), bool) for k in FLAG_KEYS}
    flags["converged"][:] = True
    flags["converged"][1, 1] = False
    flags["edge_contact"][2, 0] = True
    flags["crossing_flanks"][3, 1] = True
    values = np.ones((5, 2, 3))
    values[4, 0, 2] = np.nan
    assert rows_ok(flags, values).tolist() == [True, False, False, False, False]
    opt = {"converged": True, "message": "converged"}
    fl = {"converged": True, "edge_contact": False, "crossing_flanks": False}
    gained = {**fl, "crossing_flanks": True}

    def reasons(f0, f1):
        return acceptance_reasons(opt, 0.0, 1e-6, None, 0.0, np.zeros(2), [f0], [f1])

    assert reasons(fl, fl) == []
    assert reasons(fl, gained) == ["scenario 1: the end design carries load where the flanks cross"]
    assert reasons(gained, gained) == []


def test_tooth_form_margins_agree_with_the_loader():
    """The traced margins say "valid" exactly where the loader's concrete checks accept
    the pair (undercut, pointed tip, involute and tip/fillet interference)."""
    import jax
    from gearjax.gears.involute.geometry import InvolutePair, tooth_form_margins
    x1s, x2s = np.meshgrid(np.linspace(-0.5, 1.2, 9), np.linspace(-0.6, 1.0, 9))
    n = 0
    for z1, z2 in ((12, 24), (17, 40), (9, 30)):
        def smallest(x1, x2, z1=z1, z2=z2):
            p = InvolutePair(jnp.asarray(3.0), jnp.asarray(math.radians(20.0)),
                             jnp.asarray(0.0), x1, x2, z1, z2)
            return jnp.min(jnp.stack(list(tooth_form_margins(p).values())))
        m = np.asarray(jax.jit(jax.vmap(smallest))(x1s.ravel(), x2s.ravel()))
        for x1, x2, mi in zip(x1s.ravel(), x2s.ravel(), m):
            try:
                InvolutePair.create(z1, z2, 3.0, 20.0, 0.0, float(x1), float(x2))
                ok = True
            except ValueError:
                ok = False
            assert ok == (mi >= 0.0), (z1, z2, x1, x2, mi)
            n += ok
    assert 0 < n < 243          # both kinds of design were tried


def test_sensitivity_command_against_central_differences(capsys):
    """The outputs are the sliding study's quantities on its design and fields, so the
    command runs the Jacobian program SLSQP compiled above (one program)."""
    outs = ("max_abs_srr", "contact_ratio", "min_margin_mm", "tooth_form_margin_mm")
    rc = main(["sensitivity", "example:khk_spur_12x24", "--outputs", ",".join(outs),
               "--params", "pair.x1,pair.x2", "--json"])
    assert rc == 0
    rep = json.loads(capsys.readouterr().out)
    d = gj.load_design("example:khk_spur_12x24")
    f = gj.tca_function(d)
    from gearjax.studies.quantities import QUANTITIES
    mask = np.asarray(f(f.pair).on_flank)

    def outputs(x1, x2):
        p = gj.with_fields(f.pair, {"pair.x1": x1, "pair.x2": x2})
        r = f(p)
        return np.array([float(QUANTITIES[q].fn(r, None, mask, p)) for q in outs])

    h = 1e-5
    for j, name in enumerate(("pair.x1", "pair.x2")):
        e = np.array([h, 0.0]) if j == 0 else np.array([0.0, h])
        cd = (outputs(0.6 + e[0], 0.36 + e[1]) - outputs(0.6 - e[0], 0.36 - e[1])) / (2 * h)
        for i, q in enumerate(outs):
            o = next(o for o in rep["outputs"] if o["name"] == q)
            pu = next(p["per_unit"] for p in o["params"] if p["field"] == name)
            assert pu == pytest.approx(cd[i], rel=1e-5, abs=1e-8), (q, name)
            el = next(p["elasticity"] for p in o["params"] if p["field"] == name)
            x = 0.6 if j == 0 else 0.36
            assert el == pytest.approx(pu * x / o["value"], rel=1e-12)


@pytest.mark.parametrize("args, match", [
    (["optimize"], "STUDY is required"),
    (["optimize", "example:nope"], "unknown example study 'nope'"),
    (["optimize", "example:spur_efficiency", "--max-iterations", "0"], "--max-iterations"),
    (["sweep", "example:spur_sliding", "--points", "1"],
     "--points = 1 is outside the allowed range [2, inf)"),
    (["sweep", "example:spur_sliding", "--samples", "0"], "--samples = 0"),
    (["sweep", "example:spur_sliding", "--chunk", "0"], "--chunk = 0"),
    (["sweep", "example:spur_sliding", "--seed", "-1"], "--seed = -1"),
    (["sweep", "example:nope"], "unknown example study 'nope'"),
    (["sensitivity", "example:khk_spur_12x24", "--outputs", "power_loss_W", "--params",
      "pair.x1"], "'power_loss_W' needs the operating point: torque_Nm"),
    (["sensitivity", "example:khk_spur_12x24", "--outputs", "contact_ratio", "--params",
      "pair.x1,pair.x1"], "'pair.x1' is given more than once"),
    (["sensitivity", "example:khk_spur_12x24", "--outputs", "contact_ratio", "--params",
      "pair.y"], "field 'pair.y' is not a field"),
])
def test_bad_command_lines_are_refused(capsys, args, match):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1


@pytest.fixture(scope="module")
def sweep_four(tmp_path_factory):
    """``gearjax sweep`` of the sliding study in a process whose CPU is split into 4
    devices: 4 Latin-hypercube designs and the design itself, chunks of 3 rounded up to
    4 (one chunk per device row), so the second chunk is 1 row padded by 3."""
    import os
    import subprocess
    import sys
    out = tmp_path_factory.mktemp("sweep4")
    env = dict(os.environ)
    env["XLA_FLAGS"] = env.get("XLA_FLAGS", "") + " --xla_force_host_platform_device_count=4"
    code = ("import sys; from gearjax.cli import main, _fast_compile_flags; "
            "_fast_compile_flags(); sys.exit(main(sys.argv[1:]))")
    run = subprocess.run([sys.executable, "-c", code, "sweep", "example:spur_sliding",
                          "--samples", "4", "--chunk", "3", "--seed", "1", "--out", str(out)],
                         env=env, capture_output=True, text=True, timeout=900)
    return run, out, (dict(np.load(out / "spur_sliding_sweep.npz"))
                      if run.returncode == 0 else None)


def test_sweep_on_four_devices_is_each_designs_own_tca_on_one(sweep_four):
    """The rows, computed on 4 host devices in sharded chunks, against a second route on
    this process's one device: the TCA of each row's design by ``gj.tca_function`` (the
    program of the sensitivity test above), its quantities over its own on-flank points,
    its flags (the same numbers within 1e-9 relative); ``ok``, ``feasible`` and ``J``
    against the study's constraints and objective written out by hand."""
    from gearjax.studies.quantities import QUANTITIES
    from gearjax.studies.sweep import FLAG_KEYS
    run, out, d = sweep_four
    assert run.returncode == 0, run.stderr[-3000:]
    assert "5 designs (random), 4 device(s), chunk 4" in run.stdout
    assert (out / "spur_sliding_sweep.png").stat().st_size > 10_000
    names = list(d["quantities"])
    assert names == ["max_abs_srr", "contact_ratio", "min_margin_mm", "tooth_form_margin_mm"]
    x = d["x"]
    assert x.shape == (5, 2) and np.allclose(x[0], [0.6, 0.36])
    assert np.array_equal(d["x:pair.x2"], x[:, 1])
    assert np.all((x[1:, 0] >= 0.3) & (x[1:, 0] <= 0.9) & (x[1:, 1] >= -0.2) & (x[1:, 1] <= 0.6))
    f = gj.tca_function(gj.load_design("example:khk_spur_12x24"))
    for k in range(5):
        p = gj.with_fields(f.pair, {"pair.x1": jnp.asarray(x[k, 0]),
                                    "pair.x2": jnp.asarray(x[k, 1])})
        r = f(p)
        want = [float(QUANTITIES[q].fn(r, None, r.on_flank, p)) for q in names]
        np.testing.assert_allclose(d["values"][k, 0], want, rtol=1e-9, atol=1e-12)
        np.testing.assert_array_equal(d[f"q:{names[1]}"][k], d["values"][k, :, 1])
        fl = r.flags()
        for key in FLAG_KEYS:
            assert bool(d[f"flag:{key}"][k, 0]) == fl[key], (k, key)
    v = d["values"][:, 0]
    ok = (np.isfinite(v).all(axis=1) & d["flag:converged"][:, 0] & ~d["flag:edge_contact"][:, 0]
          & ~d["flag:crossing_flanks"][:, 0])
    assert np.array_equal(d["ok"], ok)
    # the study's constraints: contact ratio >= 1.25 and the tooth form (the fixed mask's
    # margin, which the study adds, is left out of a sweep)
    assert np.array_equal(d["feasible"], ok & (v[:, 1] >= 1.25) & (v[:, 3] >= 0.0))
    np.testing.assert_allclose(d["J"], v[:, 0] / v[0, 0], rtol=1e-12)
    meta = json.loads(str(d["meta"]))
    assert (meta["devices"], meta["chunk"], meta["designs"], meta["samples"]) == (4, 4, 5, 4)
    # the summary's best design is the feasible row of the smallest J
    best = int(re.search(r"best feasible design: row (\d+)", run.stdout).group(1))
    rows = np.flatnonzero(d["feasible"])
    assert best == rows[np.argmin(d["J"][rows])] and d["feasible"][best]


# -- the notebook of this subject (tests/notebook_run.py: after this file's tests,
# whose compiled programs it reuses)


def test_design_study_notebook_runs_and_converges(tmp_path):
    nb, text = run_notebook("02_design_study", tmp_path)
    assert images(nb) == 1         # the study figure, in the kernel's inline backend
    assert "converged:" in text and "accepted: True []" in text, text[-2000:]
    kkt = re.search(r"stationarity ([0-9.e+-]+), feasibility ([0-9.e+-]+)", text)
    assert float(kkt.group(1)) <= 1e-4 and float(kkt.group(2)) <= 1e-4
