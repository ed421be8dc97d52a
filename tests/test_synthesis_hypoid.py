"""Local synthesis on an offset hypoid pair (formate gear; gearjax.gears.hypoid.synthesis with the
start of gearjax.gears.hypoid.formate) and the shipped example it produced."""

import math
from dataclasses import replace

import jax
import numpy as np
import pytest

from gearjax import optimize
from gearjax.gears.hypoid import synthesis as sy
from gearjax.gears.hypoid import tca as th
from gearjax.gears.hypoid.design_file import load_design
from gearjax.tca.path import ARCSEC


def test_generated_hypoid_gear_is_refused_as_start():
    pair = th.pair_flanks(load_design("example:hypoid_iso_10x41"), "drive")
    gear = replace(pair.gear, machine=replace(pair.gear.machine, generated=True))
    with pytest.raises(ValueError, match="offset"):
        sy.conjugate_start(replace(pair, gear=gear))


def test_shipped_hypoid_example_has_the_synthesised_bearing():
    d = load_design("example:hypoid_iso_10x41_synthesised")
    base = load_design("example:hypoid_iso_10x41")
    for flank in ("convex", "concave"):          # the gear is the original formate gear
        a, b = d.flank("gear", flank), base.flank("gear", flank)
        for x, y in zip(jax.tree_util.tree_leaves(a), jax.tree_util.tree_leaves(b)):
            assert float(x) == pytest.approx(float(y), abs=1e-12)
        assert a.machine.generated is False and b.machine.generated is False
    # drive side only: the coast flank (other blade sign, a static field) would compile the
    # (residual, Jacobian) function again; experiments/synthesis_hypoid.py re-checks both
    for side, angle in (("drive", -45.0),):
        st = sy.start(d, side, complementary=False)
        assert st.pair.offset == pytest.approx(25.0)
        tgt = sy.Targets(path_angle_deg=angle).resolved(st.pair)
        _, _, aux = sy.residuals_and_jacobian(st, np.zeros(len(sy.VARIABLES)), tgt)
        assert bool(aux["ok"]), side
        assert abs(float(aux["xi1"]) - tgt[0]) < 1e-4
        assert abs(float(aux["h1"]) - tgt[1]) < 1e-3
        assert abs(float(aux["te_level_arcsec"]) - tgt[2] / ARCSEC) < 0.01
        assert abs(float(aux["te_apex_arcsec"])) < 0.01
        assert abs(float(aux["path_angle_deg"]) - math.degrees(tgt[3])) < 0.01
        assert abs(float(aux["semi_major_mm"]) - tgt[4]) < 1e-3
        # the saved pinion is a solution: the solve from it (same compiled program)
        # stops at the start with status converged
        res = sy.synthesise(st, sy.Targets(path_angle_deg=angle), v0=np.zeros(len(sy.VARIABLES)))
        assert res.status == optimize.CONVERGED and res.message == "converged"
        assert res.iterations == 0 and res.evaluations == 1 and res.converged


def test_shipped_hft_example_meshes_with_the_synthesised_te():
    """The 8/43 set of [HFT-hypoid] with its synthesised pinion, through the one TCA
    entry point (the path solver, not the synthesis' own residuals): every point of the
    working flank converges (near line contact: the reference solve from the mean
    point needs the full Newton step that raises one residual, see
    newton.natural_monotonicity), and the TE parabola has the synthesis' 8 arcsec drop
    over half a pitch (cubic fit over the 7 on-flank points; measured 8.003).

    The grid options are those of test_fuzz_designs.py (6 steps per pitch, 1.5 pitches
    each side, 3 pairs, with kinematics), which runs this example with them: one
    compiled program for both files through the persistent compile cache (the test
    compiled a program of its own before, 8 steps over 1 pitch, measured 8.006 with 9
    on-flank points).  The fit and its tolerances do not depend on the grid step."""
    import gearjax as gj
    d = load_design("example:hft_8x43_synthesised")
    r = gj.run_tca(d, side="drive", steps_per_pitch=6, half_pitches=1.5, n_pairs=3,
                   throw=False)
    conv, on = np.asarray(r.path.converged), np.asarray(r.on_flank)
    mid = len(conv) // 2
    assert conv[mid] and on.sum() >= 7 and conv[on].all()
    t = np.asarray(r.path.phi1 - r.path.phi1[mid])[on]
    c = np.polyfit(t, np.asarray(r.path.te)[on] / ARCSEC, 3)
    half = math.pi / 8
    assert abs(c[1] * half ** 2 - 8.0) < 0.1
    assert abs(c[0]) * half ** 3 < 0.1
