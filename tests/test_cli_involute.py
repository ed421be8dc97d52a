"""The ``gearjax involute`` command (run in-process)."""

import json

import numpy as np
import pytest

from gearjax.cli import main
from gearjax.gears.involute.geometry import InvolutePair, closed_form_path

ARGS = ["involute", "--z1", "20", "--z2", "40", "--module", "4", "--pressure-angle", "20",
        "--helix", "15", "--x1", "0.2", "--x2", "0", "--points", "5", "--rpm", "1500"]


def test_table_and_json(capsys):
    assert main(ARGS) == 0
    out = capsys.readouterr().out
    lines = out.strip().splitlines()
    assert "[m/s]" in lines[3] and "[mm]" in lines[3]
    assert len(lines) == 4 + 5
    assert main(ARGS + ["--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    for key in ("roll_angle_rad", "u_e", "u_s", "srr", "r_eff_mm", "k_ii_per_mm", "u1", "u2"):
        assert len(data[key]) == 5
    # the table shows the JSON numbers
    first = [float(x) for x in lines[4].split()]
    np.testing.assert_allclose(first[0], data["roll_angle_rad"][0], atol=1e-5)
    np.testing.assert_allclose(first[6], data["srr"][0], atol=1e-5)
    # independent check of the reported numbers (m/s at 1500 rpm)
    pair = InvolutePair.create(20, 40, 4.0, 20.0, 15.0, 0.2, 0.0)
    w1 = 1500 * 2 * np.pi / 60
    cf = closed_form_path(pair, np.array(data["rho1_mm"]), omega1=w1)
    np.testing.assert_allclose(data["u_e"], np.asarray(cf["u_e"]) * 1e-3, rtol=1e-9)
    np.testing.assert_allclose(data["srr"], cf["srr"], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(data["r_eff_mm"], cf["r_eff"], rtol=1e-9)
    assert min(data["u_e"]) > 0
    # every key the command prints is documented in the README
    import os
    readme = open(os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                               "README.md"), encoding="utf-8").read()
    assert [k for k in data if f"`{k}`" not in readme] == []


@pytest.mark.parametrize("change, word", [
    (("--module", "0"), "module"),
    (("--module", "-2"), "module"),
    (("--pressure-angle", "45"), "pressure_angle"),
    (("--helix", "70"), "helix"),
    (("--z1", "5"), "z1"),
    (("--z2", "40.5"), "z2"),
    (("--x1", "2.0"), "x1"),
    (("--points", "1"), "points"),
])
def test_bad_input_exits_nonzero_with_one_line(capsys, change, word):
    args = list(ARGS)
    i = args.index(change[0])
    args[i + 1] = change[1]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and word in err[0]
    assert "allowed range" in err[0] or "integer" in err[0]


def test_undercut_is_refused(capsys):
    args = ["involute", "--z1", "12", "--z2", "40", "--module", "3", "--pressure-angle", "20"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "x1" in err and "undercut" in err
