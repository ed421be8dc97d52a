"""Hostile input to the ``gearjax`` command and its library entry points.

Every refusal is checked the same way: exit status 2, exactly one line on stderr
that starts with ``gearjax: error:`` and names the parameter, nothing on stdout,
and no computation started (the compute entry points are replaced by a function
that fails the test if called).  Then: strict JSON output, output paths checked
before any work, atomic writes that leave the old file intact, a corrupt
persistent compilation-cache entry, and a failed TCA side.
"""

from __future__ import annotations

import errno
import json
import math
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax
import gearjax.tribology as trib
from gearjax.cli import main
from gearjax.commands import print_json
from gearjax.errors import ConvergenceError

ROOT = Path(__file__).resolve().parents[1]

INVOLUTE = ["involute", "--z1", "20", "--z2", "40", "--module", "4", "--pressure-angle", "20"]
CONTACT = ["--load-N", "500", "--rx-mm", "10", "--ry-mm", "100", "--oil", "mineral_vg100",
           "--sigma-um", "0.4"]
FRICTION = ["friction", *CONTACT, "--ue", "5", "--us", "1"]
STRIBECK = ["stribeck", *CONTACT]
TCA = ["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=30"]
KINEMATICS = ["kinematics", "example:hypoid_6x39_7p5in"]
SURFACE = ["surface", "example:hft_8x43", "--member", "pinion", "--flank", "convex"]


def _strict_json(text):
    """json.loads that refuses the NaN / Infinity tokens Python's json would accept."""
    def refuse(token):
        raise AssertionError(f"non-JSON token {token} in the output")
    return json.loads(text, parse_constant=refuse)


@pytest.fixture
def no_work(monkeypatch):
    """Replace every compute entry point the commands call by a test failure."""
    def forbidden(*a, **k):
        raise AssertionError("the command started computing before refusing its input")
    for mod, name in [(gearjax.involute, "path_kinematics"), (gearjax, "load_design"),
                      (gearjax, "run_tca"), (gearjax.hypoid, "flank_surface"),
                      (trib, "friction_coefficient"), (trib, "stribeck_curve")]:
        monkeypatch.setattr(mod, name, forbidden)


def _refused(capsys, argv, name):
    rc = main(argv)
    cap = capsys.readouterr()
    lines = cap.err.splitlines()
    assert rc == 2, (rc, cap.err)
    assert len(lines) == 1 and lines[0].startswith("gearjax: error:"), cap.err
    assert name in lines[0], (name, lines[0])
    assert cap.out == ""
    return lines[0]


# ------------------------------------------------------------ out-of-range numbers

HOSTILE = [
    # involute: speed, grid size, geometry
    (INVOLUTE + ["--rpm", "1e300"], "rpm"),
    (INVOLUTE + ["--rpm", "nan"], "rpm"),
    (INVOLUTE + ["--rpm=-inf"], "rpm"),
    (INVOLUTE + ["--rpm", "0"], "rpm"),
    (INVOLUTE + ["--rpm", "2e5"], "rpm"),
    (INVOLUTE + ["--points", "1e9"], "points"),
    (["involute", "--z1", "1e6", "--z2", "40", "--module", "4", "--pressure-angle", "20"], "z1"),
    (["involute", "--z1", "20", "--z2", "40", "--module", "1e-300", "--pressure-angle", "20"],
     "module"),
    (["involute", "--z1", "20", "--z2", "40", "--module", "1e6", "--pressure-angle", "20"],
     "module"),
    (INVOLUTE + ["--helix", "inf"], "helix"),
    # friction: speeds, load, roughness, oil, modulus, radii
    (FRICTION[:-4] + ["--ue", "5", "--us", "1e6"], "--us"),
    (FRICTION[:-4] + ["--ue", "1e3", "--us", "1"], "--ue"),
    (FRICTION[:-4] + ["--ue", "nan", "--us", "1"], "--ue"),
    (FRICTION[:-4] + ["--ue", "5", "--us=-1"], "--us"),
    (FRICTION + ["--load-N", "1e9"], "--load-N"),
    (FRICTION + ["--sigma-um", "50"], "--sigma-um"),
    (FRICTION + ["--rx-mm", "1e300"], "--rx-mm"),
    (FRICTION + ["--asperity-density-per-mm2", "1e12"], "--asperity-density-per-mm2"),
    (FRICTION + ["--asperity-radius-um", "inf"], "--asperity-radius-um"),
    (FRICTION + ["--E-prime-MPa", "1e12"], "--E-prime-MPa"),
    (["friction", *CONTACT[:6], "--eta0", "1e6", "--sigma-um", "0.4", "--ue", "5", "--us", "1"],
     "--eta0"),
    (["friction", *CONTACT[:6], "--eta0", "0.1", "--tau0-MPa", "1e9", "--sigma-um", "0.4",
      "--ue", "5", "--us", "1"], "--tau0-MPa"),
    (["friction", *CONTACT[:6], "--eta0", "0.1", "--alpha-per-GPa", "inf", "--sigma-um", "0.4",
      "--ue", "5", "--us", "1"], "--alpha-per-GPa"),
    (STRIBECK + ["--ue-max", "1e4"], "--ue-max"),
    (STRIBECK + ["--points", "1e6"], "--points"),
    (STRIBECK + ["--srr", "nan"], "--srr"),
    # kinematics: blade angle, cutter shift, grid (all refused before the design is read)
    (KINEMATICS + ["--blade-angle-delta", "90"], "--blade-angle-delta"),
    (KINEMATICS + ["--cutter-shift", "1e9"], "--cutter-shift"),
    (KINEMATICS + ["--grid", "1000x3"], "--grid"),
    # surface: grid
    (SURFACE + ["--grid", "1x1", "--out", "x.csv"], "--grid"),
    # tca: misalignments, grid, inline geometry
    (TCA + ["--misalign", "dE=1e9"], "dE"),
    (TCA + ["--misalign", "dSigma=nan"], "dSigma"),
    (TCA + ["--pitches", "100"], "pitches"),
    (TCA + ["--positions", "1e9"], "positions"),
    (["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=1e9"], "face width"),
    (["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=30,crown=inf"], "profile_crown"),
]


@pytest.mark.parametrize("argv,name", HOSTILE, ids=[" ".join(a[-2:]) for a, _ in HOSTILE])
def test_out_of_range_input_refused_before_work(capsys, no_work, argv, name):
    line = _refused(capsys, argv, name)
    assert "allowed range" in line or "must" in line or "extension" in line


def test_refusal_states_the_range(capsys, no_work):
    line = _refused(capsys, FRICTION[:-4] + ["--ue", "5", "--us", "1e6"], "--us")
    assert "[0, 500] m/s" in line          # the physical range, with its unit


# ------------------------------------------------------------ library entry points


def test_library_entry_points_validate_concrete_values():
    from gearjax.contact import hertz_point
    from gearjax.gears.involute.geometry import InvolutePair, pair_geometry, path_kinematics

    with pytest.raises(ValueError, match="z2"):
        InvolutePair.create(20, 10 ** 6, 4.0, 20.0)
    with pytest.raises(ValueError, match="module"):
        InvolutePair.create(20, 40, 1e6, 20.0)
    good = InvolutePair.create(20, 40, 4.0, 20.0)
    bad = InvolutePair(jnp.asarray(1e-300), good.pressure_angle, good.helix, good.x1, good.x2,
                       20, 40)                           # built directly, bypassing create
    with pytest.raises(ValueError, match="module"):
        pair_geometry(bad)
    with pytest.raises(ValueError, match="omega1"):
        path_kinematics(good, 3, omega1=1e300)
    with pytest.raises(ValueError, match="eta0"):
        trib.make_oil(1e6, 20.0)
    with pytest.raises(ValueError, match="tau0"):
        trib.make_oil(0.1, 20.0, tau0_MPa=1e9)
    with pytest.raises(ValueError, match="sigma"):
        trib.make_surface(50.0)
    with pytest.raises(ValueError, match="F"):
        hertz_point(1e9, 10.0, 20.0, 226374.0)
    with pytest.raises(ValueError, match="E_prime"):
        hertz_point(1e3, 10.0, 20.0, 1e12)
    oil, surf = trib.get_oil("mineral_vg100"), trib.make_surface(0.4)
    with pytest.raises(ValueError, match=r"u_s = 1e\+09 mm/s is outside the allowed range"):
        trib.friction_coefficient(500.0, 5e3, 1e9, 10.0, 100.0, oil, surf)
    with pytest.raises(ValueError, match="u_e"):
        trib.friction_coefficient(500.0, 1e6, 1e3, 10.0, 100.0, oil, surf)
    with pytest.raises(ValueError, match="load"):
        trib.friction_coefficient(1e9, 5e3, 1e3, 10.0, 100.0, oil, surf)


def test_validation_lets_traced_values_through():
    """The constructors and pair_geometry stay usable under jit and grad."""
    from gearjax.gears.involute.geometry import InvolutePair, pair_geometry

    def centre_distance(m):
        return pair_geometry(InvolutePair.create(20, 40, m, 20.0))["a_w"]

    # a_w = (z1 + z2) m / 2 for unshifted spur gears: d a_w / d m = 30
    assert float(jax.jit(centre_distance)(4.0)) == pytest.approx(120.0, rel=1e-12)
    assert float(jax.grad(centre_distance)(4.0)) == pytest.approx(30.0, rel=1e-12)


# ------------------------------------------------------------ non-finite results, JSON


def test_print_json_writes_null_and_flags_nonfinite(capsys):
    bad = print_json({"a": 1.0, "b": [2.0, float("nan")], "c": {"d": np.float64(np.inf)},
                      "e": np.array([1.0, -np.inf])})
    cap = capsys.readouterr()
    data = _strict_json(cap.out)
    assert data == {"a": 1.0, "b": [2.0, None], "c": {"d": None}, "e": [1.0, None]}
    assert bad == ["b[1]", "c.d", "e[1]"]
    lines = cap.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("gearjax: warning:")
    assert "b[1]" in lines[0] and "c.d" in lines[0] and "e[1]" in lines[0]


def test_involute_json_is_strict_and_nonfinite_results_are_flagged(capsys, monkeypatch):
    real = gearjax.involute.path_table

    def with_nan(res):
        t = dict(real(res))
        t["u_s"] = np.array(t["u_s"], float)
        t["u_s"][1] = np.nan
        return t

    assert main(INVOLUTE + ["--points", "3", "--json"]) == 0
    clean = _strict_json(capsys.readouterr().out)
    monkeypatch.setattr(gearjax.involute, "path_table", with_nan)
    assert main(INVOLUTE + ["--points", "3", "--json"]) == 0
    cap = capsys.readouterr()
    data = _strict_json(cap.out)
    assert data["u_s"][1] is None and data["u_s"][0] == clean["u_s"][0]
    err = cap.err.splitlines()
    assert len(err) == 1 and "warning" in err[0] and "u_s[1]" in err[0]
    # the table says so too
    assert main(INVOLUTE + ["--points", "3"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "u_s[1]" in err[0]


# ------------------------------------------------------------ output paths


@pytest.mark.parametrize("make,flag_name", [
    (lambda d: d / "fig.txt", "extension"),
    (lambda d: d / "missing" / "fig.png", "does not exist"),
    (lambda d: (d / "isdir.png").mkdir() or d / "isdir.png", "is a directory"),
    (lambda d: (d / "file").write_text("x") and d / "file" / "fig.png", "not a directory"),
])
def test_bad_plot_path_refused_before_work(capsys, no_work, tmp_path, make, flag_name):
    line = _refused(capsys, STRIBECK + ["--plot", str(make(tmp_path))], "--plot")
    assert flag_name in line


def test_bad_out_path_refused_before_the_design_is_read(capsys, no_work, tmp_path):
    (tmp_path / "d.csv").mkdir()
    assert "is a directory" in _refused(capsys, SURFACE + ["--out", str(tmp_path / "d.csv")],
                                        "--out")
    assert "extension" in _refused(capsys, SURFACE + ["--out", str(tmp_path / "f.obj")], "--out")
    line = _refused(capsys, SURFACE + ["--out", str(tmp_path / "f.csv"), "--plot",
                                       str(tmp_path / "no" / "f.png")], "--plot")
    assert "does not exist" in line


def test_unwritable_directory_refused(capsys, no_work, tmp_path, monkeypatch):
    """check_output_path asks the OS for write access to the directory (simulated, as
    the tests may run as root, for whom every directory is writable)."""
    real = os.access
    target = tmp_path / "locked"
    target.mkdir()
    monkeypatch.setattr(os, "access", lambda p, m, **k: False if Path(p) == target
                        else real(p, m, **k))
    for argv, flag in [(STRIBECK + ["--plot", str(target / "s.png")], "--plot"),
                       (TCA + ["--plot", str(target / "t.png")], "--plot"),
                       (KINEMATICS + ["--plot", str(target / "k.png")], "--plot"),
                       (SURFACE + ["--out", str(target / "f.stl")], "--out")]:
        assert "not writable" in _refused(capsys, argv, flag)


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0,
                    reason="root can write into a read-only directory")
def test_read_only_directory_refused(capsys, no_work, tmp_path):
    d = tmp_path / "ro"
    d.mkdir()
    d.chmod(0o555)
    try:
        _refused(capsys, STRIBECK + ["--plot", str(d / "s.png")], "--plot")
    finally:
        d.chmod(0o755)


# ------------------------------------------------------------ atomic writes


@pytest.mark.parametrize("fail", ["replace", "fsync", "write"])
def test_atomic_write_failure_keeps_old_file_and_leaves_no_temp(tmp_path, monkeypatch, fail):
    from gearjax.io import WriteError, atomic_write

    target = tmp_path / "out.csv"
    target.write_text("old content\n")

    def enospc(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    if fail == "write":
        real_fdopen = os.fdopen

        class Full:
            def __init__(self, f):
                self.f = f

            def __enter__(self):
                return self

            def __exit__(self, *exc):
                self.f.close()

            def write(self, data):
                self.f.write(data[: len(data) // 2])   # half the data, then the disk is full
                enospc()

        monkeypatch.setattr(os, "fdopen", lambda *a, **k: Full(real_fdopen(*a, **k)))
    else:
        monkeypatch.setattr(os, fail, enospc)
    with pytest.raises(WriteError) as info:
        atomic_write(target, "new content that does not fit\n")
    assert info.value.filename == str(target)
    assert target.read_text() == "old content\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv"]


def test_cli_write_failure_one_line_old_plot_intact(capsys, tmp_path, monkeypatch):
    png = tmp_path / "s.png"
    png.write_bytes(b"old plot")

    def eperm(*a, **k):
        raise PermissionError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "replace", eperm)
    rc = main(STRIBECK + ["--points", "2", "--plot", str(png)])
    cap = capsys.readouterr()
    lines = cap.err.splitlines()
    assert rc == 1
    assert len(lines) == 1 and lines[0].startswith("gearjax: error: cannot write")
    assert str(png) in lines[0] and "Traceback" not in cap.err
    assert png.read_bytes() == b"old plot"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.png"]


def test_atomic_write_figure_writes_complete_image(tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from gearjax.io import atomic_write_figure

    fig, ax = plt.subplots()
    ax.plot([0, 1], [1, 0])
    path = atomic_write_figure(fig, tmp_path / "f.svg")
    text = path.read_text()
    assert text.lstrip().startswith("<?xml") and text.rstrip().endswith("</svg>")
    assert not plt.fignum_exists(fig.number)            # closed
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.svg"]


# ------------------------------------------------------------ compilation cache

_CACHE_SCRIPT = textwrap.dedent("""
    import os, sys
    os.environ["GEARJAX_CACHE_DIR"] = sys.argv[1]
    from gearjax import cli
    cli._enable_compilation_cache()
    import jax, jax.numpy as jnp
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    f = jax.jit(lambda x: jnp.sin(x) * 2.0 + x ** 3 - jnp.cosh(x))
    print(float(f(0.5)))
""")


def test_corrupt_cache_entry_is_dropped_once(tmp_path):
    cache = tmp_path / "cache"
    env = {k: v for k, v in os.environ.items()   # not the suite's own cache (conftest.py)
           if k not in ("JAX_COMPILATION_CACHE_DIR", "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS")}
    env.update(PYTHONPATH=str(ROOT), JAX_PLATFORMS="cpu")

    def run():
        r = subprocess.run([sys.executable, "-c", _CACHE_SCRIPT, str(cache)], env=env,
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
        return r

    first = run()
    entries = list(cache.glob("*-cache"))
    assert entries, "the first run stored no cache entry"
    for e in entries:                     # a run killed while JAX wrote the entry
        e.write_bytes(e.read_bytes()[:40])
    for _ in range(2):                    # the second run repairs, the third finds it clean
        r = run()
        assert r.stdout == first.stdout
        assert "Error reading persistent compilation cache" not in r.stderr, r.stderr
        assert "error" not in r.stderr.lower(), r.stderr
    assert all(e.stat().st_size > 40 for e in entries)   # recompiled and stored again


def test_cache_switched_off(tmp_path, monkeypatch):
    from gearjax import cli

    monkeypatch.setenv("GEARJAX_CACHE_DIR", "off")
    assert cli._cache_dir() is None
    monkeypatch.setenv("GEARJAX_CACHE_DIR", str(tmp_path))
    assert cli._cache_dir() == str(tmp_path)


@pytest.mark.parametrize("switch", [None, "0", "off"])
def test_program_store_beside_the_cache(tmp_path, monkeypatch, switch):
    """The command line keeps its traced programs in ``programs/`` of its cache
    directory (gearjax/program_store.py) unless ``GEARJAX_PROGRAM_STORE`` is off; no
    store without the cache."""
    import jax
    from gearjax import cli, program_store

    monkeypatch.setattr(jax.config, "update", lambda *a: None)   # not this process's cache
    monkeypatch.setattr(cli, "_install_cache_repair", lambda path: None)
    monkeypatch.setattr(program_store, "_DIR", None)
    if switch is None:
        monkeypatch.delenv("GEARJAX_PROGRAM_STORE", raising=False)
    else:
        monkeypatch.setenv("GEARJAX_PROGRAM_STORE", switch)
    monkeypatch.setenv("GEARJAX_CACHE_DIR", str(tmp_path / "c"))
    cli._enable_compilation_cache()
    want = None if switch else tmp_path / "c" / "programs"
    assert program_store.directory() == want
    if want is not None:
        assert want.is_dir()
    monkeypatch.setattr(program_store, "_DIR", None)
    monkeypatch.setenv("GEARJAX_CACHE_DIR", "off")
    cli._enable_compilation_cache()
    assert program_store.directory() is None


# ------------------------------------------------------------ failed TCA side


def _fail_side(monkeypatch, bad_side, exc):
    import gearjax.commands.tca as cmd
    real = cmd._family_side

    def side(design, mis, m, side_name, *grid):
        if side_name == bad_side:
            raise exc
        return real(design, mis, m, side_name, *grid)

    monkeypatch.setattr(cmd, "_family_side", side)


def test_failed_side_alone_gives_one_actionable_line(capsys, monkeypatch):
    from gearjax import NoContactError

    _fail_side(monkeypatch, "drive", NoContactError(
        "no contact inside the flank boundaries at any grid position (the flanks do not "
        "touch); pass throw=False to get the masks"))
    assert main(TCA + ["--misalign", "dE=1"]) == 3
    cap = capsys.readouterr()
    lines = cap.err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("gearjax: error: drive side:")
    assert "do not touch" in lines[0] and "--misalign" in lines[0] and "--pitches 2" in lines[0]
    assert "throw" not in lines[0]
    assert cap.out == ""


def test_both_sides_keep_the_good_side(capsys, monkeypatch):
    _fail_side(monkeypatch, "coast", ConvergenceError(
        "tooth contact analysis on the flank: 3 of 61 solves did not converge (worst residual "
        "0.1); pass throw=False to get masks instead"))
    assert main(TCA + ["--side", "both", "--json"]) == 3
    cap = capsys.readouterr()
    data = _strict_json(cap.out)
    assert set(data) == {"input", "drive", "coast"}
    assert set(data["coast"]) == {"error"} and "did not converge" in data["coast"]["error"]
    assert "throw" not in data["coast"]["error"]
    drive = data["drive"]
    assert drive["quality"]["converged"] and math.isfinite(drive["ptp_arcsec"])
    assert any(v is not None for v in drive["te_arcsec"])
    err = [ln for ln in cap.err.splitlines() if "error" in ln]
    assert len(err) == 1 and "coast side" in err[0] and "--positions" in err[0]
    # the table of the good side is printed as well, with a line about the failed one
    assert main(TCA + ["--side", "both"]) == 3
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("# TCA involute:") and "(drive)" in out[0]
    assert out[-1].startswith("# TCA") and "(coast): FAILED" in out[-1]


@pytest.mark.parametrize("argv, key", [
    (["tca", "involute:z1=20,z1=21,z2=40,m=4,alpha=20,b=30"], "z1"),
    (["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=30", "--misalign", "dE=0.05,dE=0.1"], "dE"),
])
def test_tca_spec_key_given_twice_is_refused(capsys, argv, key):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"{key} is given twice" in err[0]


def test_a_failed_solve_on_valid_input_is_one_line_and_status_3(capsys, monkeypatch):
    import gearjax.commands.involute as inv

    def boom(args):
        raise ConvergenceError("involute path of contact: 3 of 21 solves did not converge; "
                               "pass throw=False to get masks instead")
    monkeypatch.setattr(inv, "run", boom)
    assert main(["involute", "--z1", "20", "--z2", "40", "--module", "4",
                 "--pressure-angle", "20"]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "did not converge" in err[0] and "throw" not in err[0]


def test_blank_without_a_solution_prints_none_and_warns(capsys):
    """[HFT-hypoid]'s seed formula for the cutter tilt has no solution for the 8/43 set:
    no `nan` in the table (a `none` and a warning line), strict JSON (null)."""
    assert main(["blank", "example:hft_8x43"]) == 0
    out = capsys.readouterr()
    assert "nan" not in out.out.lower().replace("none", "")
    line = [ln for ln in out.out.splitlines() if ln.strip().startswith("machine_tilt ")][0]
    assert "none" in line and "no solution" in line
    assert "machine_tilt" in out.err and "warning" in out.err
    assert main(["blank", "example:hft_8x43", "--json"]) == 0
    data = json.loads(capsys.readouterr().out, parse_constant=lambda c: 1 / 0)
    assert data["machine_tilt"] is None


@pytest.mark.parametrize("argv, name", [
    (["involute", "--z1", "20", "--z2", "40", "--module", "4", "--pressure-angle", "20",
      "--rpm", "1e-300"], "rpm"),
    (["friction", "--load-N", "1e-300", "--rx-mm", "10", "--ry-mm", "300", "--ue", "5",
      "--us", "1", "--oil", "mineral_vg100", "--sigma-um", "0.4"], "--load-N"),
    (["friction", "--load-N", "1000", "--rx-mm", "10", "--ry-mm", "300", "--ue", "1e-300",
      "--us", "1", "--oil", "mineral_vg100", "--sigma-um", "0.4"], "--ue"),
    (["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=0.001"], "face_width"),
])
def test_vanishing_operating_values_are_refused(capsys, argv, name):
    """Tiny positive values that made the solves fail (a traceback before): refused."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and name in err[0]


def test_output_directory_that_refuses_a_file_is_caught_before_work(capsys, monkeypatch,
                                                                      tmp_path):
    """Permission bits can say 'writable' (a superuser, a read-only mount): the check
    creates a probe file; when that fails the command stops before any work."""
    import tempfile as tf

    def refuse(*a, **k):
        raise PermissionError(13, "Permission denied")
    monkeypatch.setattr(tf, "mkstemp", refuse)
    argv = ["stribeck", "--load-N", "1000", "--rx-mm", "10", "--ry-mm", "300", "--oil",
            "mineral_vg100", "--sigma-um", "0.4", "--plot", str(tmp_path / "s.png")]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--plot" in err[0] and "not writable" in err[0]
    assert not (tmp_path / "s.png").exists()
