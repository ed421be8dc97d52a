"""Local synthesis of the spiral-bevel pinion (gearjax.gears.hypoid.synthesis).

Two XLA compiles shared through module-scoped fixtures: the jitted Levenberg-Marquardt
solve of the drive side (reused by every solve, the gradient check and the re-check of
the shipped example: ``residuals_and_jacobian`` is the same program stopped after its
first evaluation) and the independent full TCA of the verification.
"""

import math
from dataclasses import replace

import numpy as np
import pytest

from gearjax import optimize
from gearjax.gears.hypoid import synthesis as sy
from gearjax.gears.hypoid import tca as th
from gearjax.errors import ConvergenceError
from gearjax.gears.hypoid.design_file import load_design
from gearjax.tca.path import ARCSEC


@pytest.fixture(scope="module")
def st():
    return sy.start(load_design("example:spiral_bevel_10x30"), "drive")


@pytest.fixture(scope="module")
def res(st):
    return sy.synthesise(st)


def test_synthesis_converges(res):
    assert res.converged
    assert res.status == optimize.CONVERGED and res.message == "converged"
    assert res.iterations <= 15
    assert res.evaluations >= res.iterations + 1
    # history: max scaled residual at the start and after each accepted step, decreasing
    h = np.asarray(res.history)
    assert len(h) == res.iterations + 1 and np.all(np.diff(h) < 0)
    assert h[-1] == pytest.approx(np.max(np.abs(res.residuals / sy.SCALES)))
    assert h[0] > 1.0 and h[-1] <= 1e-3
    assert np.all(np.abs(res.residuals / sy.SCALES) <= 1e-3)
    assert res.singular_values[-1] > 1e-3 * res.singular_values[0]   # well-posed (scaled)
    a = res.achieved
    t = res.targets
    assert abs(a["xi1"] - t[0]) < 1e-4 and abs(a["h1"] - t[1]) < 1e-3
    assert abs(a["te_level_arcsec"] - 8.0) < 1e-2 and abs(a["te_apex_arcsec"]) < 1e-2
    assert abs(a["te_cubic_arcsec"]) < 1e-2
    assert abs(a["path_angle_deg"] - 60.0) < 1e-2 and abs(a["semi_major_mm"] - 5.0) < 1e-3


def test_independent_tca_meets_targets(res):
    """Full TCA (16 steps per pitch, 5 pairs, its own reference contact and grid)."""
    v = sy.verify(res.pair, res.targets)
    t = res.targets
    assert abs(v["xi1"] - t[0]) < 0.01              # 0.15 mm on a 30 mm face
    assert abs(v["h1_mm"] - t[1]) < 0.05            # mm
    for te in v["te_half_pitch_arcsec"]:            # the target's definition
        assert abs(te - 8.0) < 0.5                  # arcsec
    assert abs(v["apex_offset_pitch"]) < 0.03
    assert abs(v["path_angle_deg"] - 60.0) < 0.5
    assert abs(v["semi_major_mm"] - 5.0) < 0.05
    # the bearing between the transfer points is on both flanks; with a 60 deg path
    # the contact ratio along the path is only ~1.0, so the transfers are set by
    # the flank boundary, not by the crossing of the TE parabolas (docs/tca.md)
    assert v["min_margin_between_transfers_mm"] > 0.0
    assert v["contact_ratio"] > 0.95
    lo, hi = v["transfer_offset_pitch"]
    assert -0.7 < lo < -0.3 and 0.3 < hi < 0.7
    for te in v["te_transfer_arcsec"]:
        assert 4.0 < te < 12.0


def test_jacobian_matches_central_differences(st, res):
    tgt = res.targets
    v = res.v.copy()
    _, J, _ = sy.residuals_and_jacobian(st, v, tgt, res.y_ref)
    i, j = sy.RESIDUAL_NAMES.index("te_level_arcsec"), sy.VARIABLES.index("d_ratio_of_roll")
    h = 1e-5
    vp, vm = v.copy(), v.copy()
    vp[j] += h
    vm[j] -= h
    rp, _, _ = sy.residuals_and_jacobian(st, vp, tgt, res.y_ref)
    rm, _, _ = sy.residuals_and_jacobian(st, vm, tgt, res.y_ref)
    fd = (rp[i] - rm[i]) / (2 * h)
    assert J[i, j] == pytest.approx(fd, rel=1e-5)


@pytest.mark.parametrize("kw, name", [(dict(xi1=0.95), "xi1"), (dict(te_arcsec=-3.0), "te_arcsec"),
                                      (dict(path_angle_deg=89.0), "path_angle_deg"),
                                      (dict(semi_major_mm=0.1), "semi_major_mm"),
                                      (dict(h1_mm=0.2), "h1_mm")])
def test_bad_target_raises_value_error(st, kw, name):
    with pytest.raises(ValueError, match=name):
        sy.synthesise(st, sy.Targets(**kw))


def test_bad_free_set_raises(st):
    with pytest.raises(ValueError, match="free"):
        sy.synthesise(st, free=("d_radius", "modified_roll_2c"))
    with pytest.raises(ValueError, match="not one of"):
        sy.synthesise(st, free=("d_radius", "modified_roll_2c", "x", "y", "z"))


def test_residuals_and_jacobian_needs_all_variables(st, res):
    with pytest.raises(ValueError, match="7 entries"):
        sy.residuals_and_jacobian(st, np.zeros(6), res.targets)


def test_not_converged_raises_unless_strict_false(st, res):
    with pytest.raises(ConvergenceError, match="step limit"):
        sy.synthesise(st, max_iter=1)
    r = sy.synthesise(st, max_iter=1, throw=False)
    assert not r.converged
    assert r.status == optimize.MAX_ITERATIONS and "step limit" in r.message
    assert r.iterations == 1 and len(r.history) == 2
    # the first step is the first step of the full solve (same compiled program)
    assert r.history == pytest.approx(res.history[:2], rel=1e-9)


def test_shipped_example_reproduces_the_bearing(res):
    d = load_design("example:spiral_bevel_10x30_synthesised")
    # the saved flanks in the synthesis' mounting (same hand; for a spiral-bevel pair
    # both hands are equivalent and prepare may pick either), so that the compiled
    # (residual, Jacobian) function is reused
    pair = replace(th.pair_flanks(d, "drive"), hand=res.start.pair.hand)
    st_f = replace(res.start, pair=pair)
    r, _, aux = sy.residuals_and_jacobian(st_f, np.zeros(len(sy.VARIABLES)), res.targets,
                                          res.y_ref)
    assert bool(aux["ok"])
    assert abs(float(aux["xi1"]) - res.targets[0]) < 1e-4
    assert abs(float(aux["h1"]) - res.targets[1]) < 1e-3
    assert abs(float(aux["te_level_arcsec"]) - res.targets[2] / ARCSEC) < 0.01
    assert abs(float(aux["path_angle_deg"]) - math.degrees(res.targets[3])) < 0.01
    assert abs(float(aux["semi_major_mm"]) - res.targets[4]) < 1e-3
    # the saved pinion is a solution: the solve from it stops at once, converged
    again = sy.synthesise(st_f, v0=np.zeros(len(sy.VARIABLES)))
    assert again.status == optimize.CONVERGED and again.message == "converged"
    assert again.iterations == 0 and again.evaluations == 1
    # (its own reference guess: the Newton tolerance 1e-11 apart)
    np.testing.assert_allclose(again.residuals, r * sy.SCALES, rtol=0, atol=1e-9)
    # the saved drive pinion is the synthesised one (file precision)
    fl = d.flank("pinion", "concave")
    assert float(fl.cutter.point_radius) == pytest.approx(float(res.pair.pinion.cutter.point_radius),
                                                          abs=1e-9)
