"""CLI: gearjax example / blank / surface (in-process through gearjax.cli.main)."""

import json

import numpy as np
import pytest

from gearjax.cli import main
from gearjax.gears.hypoid.design_file import load_design


def test_example_list_and_show(capsys):
    assert main(["example", "list"]) == 0
    out = capsys.readouterr().out
    assert "hft_8x43" in out
    assert main(["example", "show", "hft_8x43"]) == 0
    out = capsys.readouterr().out
    assert "[pinion.convex.machine.no116]" in out and "cradle = 126.27" in out


def test_example_show_unknown(capsys):
    assert main(["example", "show", "nope"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("gearjax: error:") and "nope" in err[0]


def test_blank_table_and_json(capsys):
    assert main(["blank", "example:hft_8x43"]) == 0
    out = capsys.readouterr().out
    assert "blank of hft_8x43" in out and "deg" in out
    assert main(["blank", "example:hft_8x43", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    # the ISO 23509 blank of the [HFT-hypoid] input reproduces its Table 1's cone angles and
    # mean cone distance (given there to 0.01 deg / 0.01 mm) within 0.05 deg / 0.1 mm
    assert abs(data["delta1"] - 12.55) < 0.05 and abs(data["delta2"] - 77.22) < 0.05
    assert abs(data["Rm1"] - 128.32) < 0.1 and abs(data["Rm2"] - 130.75) < 0.1


@pytest.mark.parametrize("ext", ["csv", "xyz", "stl"])
def test_surface_outputs(tmp_path, capsys, ext):
    out = tmp_path / f"g.{ext}"
    rc = main(["surface", "example:hft_8x43", "--member", "gear", "--flank", "concave",
               "--grid", "5x3", "--out", str(out)])
    assert rc == 0
    msg = capsys.readouterr().out
    assert "5x3 points" in msg and "max residual" in msg
    text = out.read_text()
    if ext == "csv":
        assert len(text.splitlines()) == 1 + 15
    elif ext == "xyz":
        assert np.loadtxt(out).shape == (15, 6)
    else:
        assert text.startswith("solid") and text.count("facet normal") == 2 * 4 * 2


def test_surface_tooth_and_plot(tmp_path, capsys):
    out, png = tmp_path / "tooth.stl", tmp_path / "f.png"
    rc = main(["surface", "example:hft_8x43", "--member", "gear", "--flank", "convex",
               "--grid", "4x3", "--out", str(out), "--tooth", "--plot", str(png)])
    assert rc == 0
    assert out.read_text().count("facet normal") == 2 * (2 * 3 * 2) + 2 * (2 * 3 + 2 * 2)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("edit,field", [
    (lambda d: d["gear"]["concave"]["cutter"].__setitem__("point_radius", -5.0), "point_radius"),
    (lambda d: d["pinion"]["convex"]["cutter"].__setitem__("blade_angle", 47.0), "blade_angle"),
    (lambda d: d["blank_summary"]["gear"].__setitem__("face_width", 160.0), "face_width"),
    (lambda d: d["blank_summary"]["gear"].__setitem__("teeth", 7), "ratio"),
    (lambda d: d["gear"]["concave"]["machine"].__setitem__("spin", 1.0), "gear.concave.machine.spin"),
])
def test_invalid_design_refused(tmp_path, capsys, edit, field):
    d = load_design("example:hft_8x43").to_dict()
    edit(d)
    from gearjax.io import atomic_write, dumps_toml
    p = atomic_write(tmp_path / "bad.toml", dumps_toml(d))
    for argv in (["blank", str(p)],
                 ["surface", str(p), "--member", "gear", "--flank", "concave", "--grid", "3x3",
                  "--out", str(tmp_path / "x.csv")]):
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("gearjax: error:") and field in err[0]
    assert not (tmp_path / "x.csv").exists()


@pytest.mark.parametrize("argv,msg", [
    (["--grid", "41by21"], "--grid"),
    (["--grid", "1x5"], "face-width points"),
    (["--out", "OUT.txt"], "extension"),
])
def test_surface_bad_flags(tmp_path, capsys, argv, msg):
    base = ["surface", "example:hft_8x43", "--member", "gear", "--flank", "convex",
            "--out", str(tmp_path / "g.csv")]
    argv = [a.replace("OUT", str(tmp_path / "g")) for a in argv]
    assert main(base + argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and msg in err[0]


def test_missing_design_file(capsys, tmp_path):
    assert main(["blank", str(tmp_path / "none.toml")]) == 2
    assert "does not exist" in capsys.readouterr().err
