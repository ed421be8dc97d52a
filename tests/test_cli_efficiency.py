"""``gearjax efficiency`` in-process: one run of the command on a small spur pair (JSON
and a figure; the compile dominates, so it is shared by the tests of the result), and
refusals of bad input that must come before any JAX work."""

import contextlib
import io
import os
import re

import numpy as np
import pytest

import gearjax
from gearjax.cli import main
from gearjax.commands.efficiency import EFFICIENCY_KEYS_DOC
from strict_json import strict_json

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DESIGN = "involute:z1=20,z2=40,m=4,alpha=20,b=30"
BASE = [DESIGN, "--torque-Nm", "200", "--rpm", "1500", "--oil", "mineral_vg100",
        "--sigma-um", "0.4"]


_strict = strict_json


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The one real run: 8 positions per mesh cycle, JSON on stdout, a PNG."""
    d = tmp_path_factory.mktemp("eff")
    png = d / "eff.png"
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(["efficiency", *BASE, "--positions", "8", "--json", "--plot", str(png)])
    return rc, out.getvalue(), err.getvalue(), d, png


def _documented_keys():
    keys = []
    for line in EFFICIENCY_KEYS_DOC.splitlines()[1:]:
        m = re.match(r"  (\w+)\s", line)
        if m:
            keys.append(m.group(1))
    return keys


def test_json_keys_documented_strict_and_plot(run):
    rc, text, err, d, png = run
    assert rc == 0, err
    out = _strict(text)
    assert sorted(out) == sorted(_documented_keys())
    readme = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    section = readme.split("### `gearjax efficiency`", 1)[1].split("\n### ", 1)[0]
    missing = [k for k in out if f"`{k}`" not in section]
    assert not missing, f"JSON keys not documented in the README's efficiency section: {missing}"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out["plot"] == str(png)
    assert [p.name for p in d.iterdir()] == ["eff.png"]          # no temporary file left
    assert "Traceback" not in err


def test_load_shares_efficiency_and_summary(run):
    out = _strict(run[1])
    M = len(out["phi1_deg"])
    assert M == 8 and out["pairs"] == [-1, 0, 1] and out["input"]["positions"] == 8
    share = np.asarray(out["load_share"], float)
    load = np.asarray(out["load_N"], float)
    assert share.shape == (3, M)
    assert np.allclose(share.sum(axis=0), 1.0, atol=1e-9)
    # a spur pair of contact ratio ~1.6: one or two pairs in contact over the cycle
    assert set(out["n_loaded"]) == {1, 2}
    assert np.array_equal((load > 0).sum(axis=0), out["n_loaded"])
    # unloaded pairs are null, loaded ones are numbers
    mu = out["mu"]
    assert all((mu[k][i] is None) == (load[k, i] == 0.0) for k in range(3) for i in range(M))
    assert all(out["valid"]) and not out["truncated"]
    assert 0.0 < out["mean_efficiency"] < 1.0
    eta = np.asarray(out["efficiency"], float)
    assert np.all((eta > 0.0) & (eta <= 1.0))
    # eta_bar = 1 - mean(P_f)/P_in; P_in = T omega
    assert out["power_in_W"] == pytest.approx(200.0 * 1500.0 * np.pi / 30.0, rel=1e-12)
    assert out["mean_efficiency"] == pytest.approx(
        1.0 - np.mean(out["power_loss_W"]) / out["power_in_W"], rel=1e-12)
    assert 0.0 < out["mean_mu"] < 0.2 and out["max_p_max_MPa"] > 0.0
    assert out["max_p_max_MPa"] == pytest.approx(max(out["p_max_position_MPa"]), rel=1e-12)


def _no_work(monkeypatch):
    def forbidden(*a, **k):
        raise AssertionError("mesh_efficiency called for bad input")
    monkeypatch.setattr(gearjax, "mesh_efficiency", forbidden)


@pytest.mark.parametrize("flag,value,names", [
    ("--torque-Nm", "-5", ["--torque-Nm", "-5", "0.001"]),
    ("--torque-Nm", "0", ["--torque-Nm", "0.001"]),
    ("--rpm", "0", ["--rpm", "0.001"]),
    ("--rpm", "-100", ["--rpm", "-100"]),
    ("--oil", "castor", ["castor", "mineral_vg100", "pao_vg100"]),
    ("--sigma-um", "20", ["--sigma-um", "20", "10"]),
    ("--positions", "2", ["--positions", "4"]),
    ("--pairs", "4", ["--pairs", "odd"]),
    ("--misalign", "dX=1", ["dX"]),
])
def test_bad_operating_point_refused_in_one_line(capsys, monkeypatch, flag, value, names):
    _no_work(monkeypatch)
    argv = ["efficiency", *BASE]
    if flag in argv:
        argv[argv.index(flag) + 1] = value
    else:
        argv += [flag, value]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("gearjax: error:")
    assert all(n in err[0] for n in names), err[0]


def test_bad_plot_path_refused_before_work(capsys, monkeypatch, tmp_path):
    _no_work(monkeypatch)
    assert main(["efficiency", *BASE, "--plot", str(tmp_path / "no" / "e.png")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--plot" in err[0] and "does not exist" in err[0]
    assert main(["efficiency", *BASE, "--plot", str(tmp_path / "e.txt")]) == 2
    assert "--plot" in capsys.readouterr().err
    assert main(["efficiency", "example:no_such_design", *BASE[1:]]) == 2
    assert "no_such_design" in capsys.readouterr().err


def test_helical_pair_in_line_contact_refuses_point_contact_options(capsys):
    """An unmodified helical pair in line contact goes to the line contact
    (tests/test_cli_microgeometry.py); the point-contact grid options are refused there
    in one line, before anything is traced."""
    argv = ["efficiency", DESIGN + ",helix=15", *BASE[1:], "--pairs", "3"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--pairs" in err[0] and "line contact" in err[0]


def test_table_from_the_same_result(run, capsys):
    """The table printer on the run's result (a second run would compile again)."""
    import argparse

    from gearjax.commands.efficiency import _print_table
    out = _strict(run[1])
    args = argparse.Namespace(design=DESIGN, side="drive", torque_Nm=200.0, rpm=1500.0,
                              oil="mineral_vg100", sigma_um=0.4)
    _print_table(out, args)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("# mesh efficiency involute:")
    # the material and compliance used, and where the material came from (an involute
    # pair has no material: the documented steel default, said so)
    assert lines[1].startswith("# material: E' = 226374 MPa (E = 206000 MPa, nu = 0.3; "
                               "default steel") and lines[1].endswith("compliance weber")
    assert lines[2].split()[:5] == ["phi1[deg]", "n", "s[-1]", "s[+0]", "s[+1]"]
    rows = lines[3:3 + 8]
    assert all(r.split()[-1] == "ok" for r in rows)
    assert float(rows[0].split()[0]) == pytest.approx(out["phi1_deg"][0], abs=1e-4)
    summary = "\n".join(lines[11:])
    for label in ("eta_bar", "mean mu", "max p_max", "P_in", "loaded TE p-t-p"):
        assert label in summary
    assert f"{100 * out['mean_efficiency']:.4f} %" in summary


def test_ehl_check_skips_line_contacts_with_the_reason(run):
    # the spur pair is in line contact: its equivalent ellipse (Ry/Rx ≫ 50) is outside
    # the numerical EHL point-contact model, so every checked position is reported as
    # skipped with the reason, with the fast model's values of the main result
    rc, text, err, d, png = run
    base = _strict(text)
    assert base["ehl_check"] is None
    out, errs = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(errs):
        rc = main(["efficiency", *BASE, "--positions", "8", "--json", "--ehl-check", "3"])
    assert rc == 0, errs.getvalue()
    rows = _strict(out.getvalue())["ehl_check"]
    assert len(rows) == 3
    for r in rows:
        assert "Ry/Rx" in r["skipped"] and r["mu_ehl"] is None and not r["converged"]
        j = base["phi1_deg"].index(r["phi1_deg"])
        k = base["pairs"].index(r["pair"])
        assert r["mu_fast"] == pytest.approx(base["mu"][k][j], rel=1e-12)
        assert r["load_N"] == pytest.approx(max(row[j] for row in base["load_N"]), rel=1e-12)


@pytest.mark.parametrize("flags, name", [(["--ehl-check", "0"], "--ehl-check"),
                                         (["--ehl-check", "2", "--ehl-grid", "8"], "--ehl-grid")])
def test_bad_ehl_check_options_refused(capsys, monkeypatch, flags, name):
    _no_work(monkeypatch)
    rc = main(["efficiency", *BASE, *flags])
    err = capsys.readouterr().err
    assert rc == 2 and name in err and len(err.strip().splitlines()) == 1, err


def test_implausible_result_exits_3_with_warnings(run):
    """Issue 28's finding: --E-prime-MPa 1e-3 printed eta_bar = -18.9 % and mean mu 7.2
    with every row "ok" (exit 0).  Same static options as the module's run (8
    positions; E' is traced): no new program.  Planted bugs caught: the plausibility
    not part of ``valid`` (exit 0, rows "ok"), summaries over all positions (a
    number instead of null), the warning lines not reaching stderr."""
    out, errs = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(errs):
        rc = main(["efficiency", *BASE, "--positions", "8", "--json", "--E-prime-MPa", "1e-3"])
    err = errs.getvalue()
    assert rc == 3, err
    d = _strict(out.getvalue())
    assert d["n_valid"] == 0 and not any(d["valid"])
    assert d["mean_efficiency"] is None and d["mean_mu"] is None
    assert "gearjax: warning: drive side: implausible result" in err
    assert "mu above 0.3" in err and "Hertz half-width above 0.5 R_x" in err
    assert "no position of the mesh cycle gives a valid" in err
    # the module's run at steel E' is whole and plausible
    base = _strict(run[1])
    assert base["n_valid"] == len(base["valid"]) and "implausible" not in run[2]


def test_a_packaged_involute_design_file_runs_the_loaded_chain(capsys):
    """``gearjax efficiency example:khk_spur_12x24`` (an involute *design file*, not a
    ``involute:`` spec): the file adapter hands the loaded chain the pair's arrays (before
    this test: TypeError, the adapter's static split/join functions bound as methods).
    Same program as the spur run above (tooth numbers are data); checked: exit 0, a
    summary line and an efficiency in (0.95, 1)."""
    rc = main(["efficiency", "example:khk_spur_12x24", "--torque-Nm", "100", "--rpm", "1000",
               "--oil", "mineral_vg100", "--sigma-um", "0.4", "--positions", "8", "--json"])
    out = _strict(capsys.readouterr().out)
    assert rc == 0
    assert 0.95 < out["mean_efficiency"] < 1.0
