"""The ``friction`` and ``stribeck`` sub-commands, called in-process."""

import json
import os

import numpy as np
import pytest

from gearjax.cli import main
from gearjax.tribology import friction_coefficient, get_oil, make_surface

README = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "README.md")


def _readme_documents(keys):
    text = open(README, encoding="utf-8").read()
    missing = [k for k in keys if f"`{k}`" not in text]
    assert not missing, f"JSON keys not documented in README.md: {missing}"


BASE = ["--load-N", "1000", "--rx-mm", "10", "--ry-mm", "100", "--oil", "mineral_vg100",
        "--sigma-um", "0.6"]


def test_friction_json_keys_and_unit_conversion(capsys):
    assert main(["friction", *BASE, "--ue", "3", "--us", "0.6", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("a_mm", "b_mm", "p_max_MPa", "h_c_um", "h_min_um", "lambda", "asperity_load_ratio",
                "mu", "mu_boundary", "mu_fluid", "regime", "lambda_smooth", "friction_force_N"):
        assert key in out
    # same contact through the library (speeds m/s -> mm/s, sigma um -> mm)
    r = friction_coefficient(1000.0, 3000.0, 600.0, 10.0, 100.0, get_oil("mineral_vg100"), make_surface(0.6))
    assert out["mu"] == pytest.approx(float(r.mu), rel=1e-12)
    assert out["h_c_um"] == pytest.approx(float(r.h_c) * 1e3, rel=1e-12)
    assert out["lambda"] == pytest.approx(float(r.h_c) / 6e-4, rel=1e-12)
    assert out["sliding_power_W"] == pytest.approx(float(r.mu) * 1000.0 * 0.6, rel=1e-12)
    _readme_documents(out)  # every key the command prints is documented in the README


def test_friction_table_and_custom_oil(capsys):
    assert main(["friction", "--load-N", "500", "--rx-mm", "8", "--ry-mm", "80", "--eta0", "0.05",
                 "--alpha-per-GPa", "18", "--sigma-um", "0.3", "--ue", "5", "--us", "1"]) == 0
    text = capsys.readouterr().out
    assert "p_max" in text and "regime" in text


@pytest.mark.parametrize("flag,value,name", [
    ("--load-N", "-3", "--load-N"), ("--rx-mm", "0", "--rx-mm"), ("--ue", "-1", "--ue"),
    ("--us", "-0.5", "--us"), ("--sigma-um", "0", "--sigma-um"), ("--oil", "castor", "oil"),
    ("--fc", "2", "--fc")])
def test_friction_bad_input_one_line(capsys, flag, value, name):
    args = {"--load-N": "1000", "--rx-mm": "10", "--ry-mm": "100", "--oil": "mineral_vg100",
            "--sigma-um": "0.6", "--ue": "3", "--us": "0.6", "--fc": "0.1"}
    args[flag] = value
    argv = ["friction"] + [x for kv in args.items() for x in kv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and name in err


def test_friction_bad_eta(capsys):
    argv = ["friction", "--load-N", "1000", "--rx-mm", "10", "--ry-mm", "100", "--eta0", "-0.1",
            "--sigma-um", "0.6", "--ue", "3", "--us", "0.6"]
    assert main(argv) == 2
    assert "--eta0" in capsys.readouterr().err


def test_stribeck_json_and_atomic_plot(capsys, tmp_path):
    png = tmp_path / "s.png"
    assert main(["stribeck", *BASE, "--points", "8", "--ue-min", "0.05", "--ue-max", "20",
                 "--plot", str(png), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert len(out["mu"]) == 8 and out["plot"] == str(png)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["s.png"]  # no temp file left behind
    x = np.asarray(out["stribeck_number_per_m"])
    assert x[0] == pytest.approx(0.088 * 0.05 / 1000.0, rel=1e-12)
    assert out["regime"][-1] == "full film"
    _readme_documents(out)


def test_stribeck_bad_input(capsys, tmp_path):
    assert main(["stribeck", *BASE, "--ue-min", "5", "--ue-max", "1"]) == 2
    assert "--ue-max" in capsys.readouterr().err
    assert main(["stribeck", *BASE, "--plot", str(tmp_path / "no" / "x.png")]) == 2
    assert "--plot" in capsys.readouterr().err
    assert main(["stribeck", *BASE, "--srr", "-1"]) == 2
    assert "--srr" in capsys.readouterr().err


def test_mesh_friction_figure_written_atomically(tmp_path):
    from gearjax.plot.tribology import mesh_friction_figure, save_figure_atomic
    fig = mesh_friction_figure(np.linspace(0, 1, 5), np.array([[0.05, 0.0], [0.04, 0.03]] * 2 + [[0.0, 0.05]]),
                               power_loss_W=np.arange(5.0))
    path = save_figure_atomic(fig, tmp_path / "m.png")
    assert os.path.getsize(path) > 1000
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.png"]
