"""CLI: gearjax kinematics (in-process through gearjax.cli.main)."""

import json

import numpy as np
import pytest

from gearjax.cli import main
from gearjax.studies import cutter_radius as hk
from gearjax.gears.hypoid.design_file import load_design


def test_example_matches_seed000_assumptions():
    inp = load_design("example:hypoid_6x39_7p5in").blank_input()
    assert inp == hk.study_blank_input(95.25)


def test_json_and_table(capsys, tmp_path):
    png = tmp_path / "k.png"
    assert main(["kinematics", "example:hypoid_6x39_7p5in", "--grid", "7x5", "--json",
                 "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    # same numbers as the library on the same grid
    _, f = hk.flank_fields(hk.study_blank_input(95.25), hk.StudySettings.make(95.25), "convex",
                           (7, 5))
    assert out["stats"]["r_eff"]["min"] == pytest.approx(float(np.min(f.r_eff)), rel=1e-12)
    assert out["limits"]["curvature_interference"]["inside"] is False
    assert png.stat().st_size > 1000
    assert main(["kinematics", "example:hypoid_6x39_7p5in", "--grid", "7x5"]) == 0
    txt = capsys.readouterr().out
    assert "r_eff" in txt and "meshing_limit" in txt and "clear" in txt


@pytest.mark.parametrize("argv, word", [
    (["--grid", "7by5"], "--grid"),
    (["--grid", "2x5"], "--grid depth points"),
    (["--blade-angle-delta", "45"], "blade_angle_delta_deg"),
    (["--plot", "x.pdf"], "--plot"),
])
def test_bad_input_one_line(capsys, argv, word):
    assert main(["kinematics", "example:hypoid_6x39_7p5in"] + argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and word in err[0]


def test_spiral_bevel_rejected(capsys):
    assert main(["kinematics", "example:spiral_bevel_10x30", "--grid", "7x5"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "offset" in err[0]
