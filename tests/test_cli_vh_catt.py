"""``gearjax surface`` and ``gearjax example`` on the VH-CATT design file (in-process).

The exported points are checked against the closed-form involute of the middle section
(an independent reference), the tooth STL for being a closed mesh of both flanks.
"""

import math

import numpy as np
import pytest

from gearjax.cli import main


def test_surface_xyz_middle_section_is_the_involute(tmp_path, capsys):
    out = tmp_path / "pinion_concave.xyz"
    assert main(["surface", "example:vh_catt_17x23", "--member", "pinion", "--flank", "concave",
                 "--grid", "5x9", "--out", str(out)]) == 0
    assert "max residual" in capsys.readouterr().out
    data = np.loadtxt(out)
    assert data.shape == (45, 6)
    P = data[:, :3].reshape(5, 9, 3)
    N = data[:, 3:].reshape(5, 9, 3)
    assert np.allclose(P[:, :, 2].min(axis=1), np.linspace(-14, 14, 5), atol=1e-9)
    mid = P[2]
    r, rb, a = 34.0, 34.0 * math.cos(math.radians(20)), math.radians(20)
    R = np.hypot(mid[:, 0], mid[:, 1])
    inv = lambda t: math.tan(t) - t  # noqa: E731
    # the 17-tooth pinion is undercut up to its base circle: the grid's lowest row (the
    # straight blade's end) lies on the folded envelope, below the active profile
    ok = R > rb + 0.05
    ref = np.array([math.pi / 2 + (math.pi * 2 / (2 * r) + inv(a) - inv(math.acos(rb / x)))
                    for x in R[ok]])
    assert ok.sum() >= 7 and R[0] < 32.0
    assert np.max(np.abs(R[ok] * (np.arctan2(mid[ok, 1], mid[ok, 0]) - ref))) < 1e-9
    # tip of the grid on the tip circle (middle section), normals out of the tooth
    # (the concave flank of the pinion is at x < 0 of tooth 0: normals towards -x)
    assert abs(R[-1] - 38.0) < 1e-9
    assert np.all(N[..., 0] < 0)


def test_surface_tooth_stl_and_refusals(tmp_path, capsys):
    out = tmp_path / "gear_tooth.stl"
    assert main(["surface", "example:vh_catt_17x23", "--member", "gear", "--flank", "convex",
                 "--grid", "5x9", "--out", str(out), "--tooth"]) == 0
    text = out.read_text()
    assert text.startswith("solid vh_catt_17x23_gear_tooth")
    # 2 flanks x 2 (4x8) triangles + 4 caps
    assert text.count("facet normal") == 2 * 2 * 4 * 8 + 2 * 2 * 8 + 2 * 2 * 4
    with pytest.raises(SystemExit):
        main(["surface", "example:vh_catt_17x23", "--member", "gear", "--flank", "side",
              "--out", str(tmp_path / "x.csv")])


def test_example_list_reads_design_tables_without_loading(capsys, monkeypatch):
    """``gearjax example list`` prints each example's ``[design] description`` from the
    TOML alone: it builds no design (a load would run the tooth-form check and, for
    other families, their geometry), and reports a file whose kind is unknown."""
    import gearjax.io as io

    def no_load(*a, **k):
        raise AssertionError("example list must not load the designs")

    monkeypatch.setattr(io, "load_design", no_load)
    monkeypatch.setattr(io, "design_from_dict", no_load)
    assert main(["example", "list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    desc = io.read_toml("example:vh_catt_17x23")["design"]["description"]
    assert any(ln.startswith("vh_catt_17x23") and ln.endswith(desc) for ln in lines)
    assert len(lines) == len(io.list_examples()) and "(invalid" not in "".join(lines)
    real = io.read_toml
    monkeypatch.setattr(io, "read_toml", lambda src: {"design": {"kind": "helical"}}
                        if src == "example:vh_catt_17x23" else real(src))
    assert main(["example", "list"]) == 0
    line = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("vh_catt")]
    assert "(invalid: [design] kind = 'helical'" in line[0]


def test_example_show_prints_the_file_that_loads(capsys):
    """``gearjax example show`` prints the file text (still TOML that loads to the same
    pair) and no defaults (every VH-CATT key is required)."""
    import tomllib

    import gearjax as gj
    assert main(["example", "show", "vh_catt_17x23"]) == 0
    out = capsys.readouterr().out
    assert "defaults applied (keys not in this file; gearjax uses these values): none" in out
    data = tomllib.loads(out)
    assert data["pair"]["z1"] == 17 and data["pair"]["blade_offset_mm"] == 3.0
    assert gj.design_from_dict(data).pair.z2 == 23
