"""``gearjax loaded`` and the ``[microgeometry]`` tables of involute design files.

One real run of the command on the packaged ``helical_microgeometry`` example (8
positions x 6 slices, 2 torques x 2 misalignments: one compiled program, shared by the
tests through a module fixture; the table run below has the same shapes and reuses it),
the design-file parsing (member and flank tables, shapes, refusals), the refusal of the
point-contact TCA of a design with micro-geometry, and refusals of bad input
before any JAX work.  Each test's docstring names the planted bug it catches."""

import copy
import os
import re

import numpy as np
import pytest

import gearjax as gj
from gearjax.cli import build_parser
from gearjax.commands.loaded import JSON_KEYS_DOC, parse_torques
from gearjax.gears.involute.design_file import read_involute
from cli_call import cli_call
from strict_json import strict_json

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLE = "example:helical_microgeometry"
SMALL = ["--positions", "8", "--slices", "6"]
OPS = ["--torque-Nm", "50,200", "--misalignment-um", "0,10"]


_call = cli_call


_strict = strict_json


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """The one real run: JSON on stdout and a PNG."""
    d = tmp_path_factory.mktemp("loaded")
    png = d / "loaded.png"
    rc, out, err = _call(["loaded", EXAMPLE, *OPS, *SMALL, "--json", "--plot", str(png)])
    return rc, out, err, d, png


def _documented_keys():
    return [m.group(1) for line in JSON_KEYS_DOC.splitlines()[1:]
            if (m := re.match(r"  (\w+)\s", line))]


def _section(text, heading):
    return text.split(heading, 1)[1].split("\n### ", 1)[0]


def test_json_keys_documented_strict_and_plot(run):
    """Catches: a JSON key added or renamed without the help epilog, the README's
    ``gearjax loaded`` section or docs/microgeometry.md listing it; a flag missing from
    the README; a non-strict NaN in the JSON; a figure written in place (a temporary
    file left) or not at all."""
    rc, text, err, d, png = run
    assert rc == 0, err
    assert err == ""
    out = _strict(text)
    assert sorted(out) == sorted(_documented_keys())
    readme = _section(open(os.path.join(ROOT, "README.md"), encoding="utf-8").read(),
                      "### `gearjax loaded`")
    doc = open(os.path.join(ROOT, "docs", "microgeometry.md"), encoding="utf-8").read()
    assert [k for k in out if f"`{k}`" not in readme] == []
    assert [k for k in out if f"`{k}`" not in doc] == []
    sub = build_parser()._subparsers._group_actions[0].choices["loaded"]
    flags = [s for a in sub._actions for s in a.option_strings if s.startswith("--")
             and s != "--help"]
    assert [f for f in flags if f"`{f}" not in readme] == []
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out["plot"] == str(png)
    assert [p.name for p in d.iterdir()] == ["loaded.png"]


def test_json_values_are_the_library_map(run):
    """Catches: the command transposing torques x misalignments, reporting the smooth
    p-t-p or another field under a key, or converting N m / um wrongly."""
    out = _strict(run[1])
    m = gj.involute.loaded_te_map(gj.load_design(EXAMPLE), [50.0, 200.0], [0.0, 10.0],
                                  positions=8, slices=6)
    assert out["torque_Nm"] == [50.0, 200.0] and out["misalignment_um"] == [0.0, 10.0]
    for key, field in (("te_ptp_um", "te_ptp_um"), ("te_mean_um", "te_mean_um"),
                       ("te_unloaded_ptp_um", "te_unloaded_ptp_um"),
                       ("p_max_MPa", "p_max"), ("k_hbeta", "k_hbeta"),
                       ("end_load_ratio", "end_load")):
        np.testing.assert_allclose(out[key], np.asarray(getattr(m, field)), rtol=1e-12,
                                   err_msg=key)
    assert np.asarray(out["converged"]).shape == (2, 2) and all(map(all, out["converged"]))
    # physics sanity: more torque, more mean approach; misalignment loads an end harder
    te = np.asarray(out["te_mean_um"])
    assert (te[1] > te[0]).all()
    assert out["end_load_ratio"][0][1] > out["end_load_ratio"][0][0]


def test_modifications_reported_from_the_file(run):
    """Catches: the [microgeometry] tables not read (an unmodified pair analysed), the
    member tables given to the wrong member, or the shape not mapped to the exponent."""
    mods = _strict(run[1])["modifications"]
    p, g = mods["pinion"], mods["gear"]
    assert (p["tip_relief"], p["tip_relief_length"], p["tip_relief_exponent"]) == (8.0, 2.5, 1.0)
    assert p["lead_crowning"] == 6.0 and g["lead_crowning"] == 0.0
    assert (g["tip_relief"], g["tip_relief_length"]) == (8.0, 2.5)


def test_table_from_a_torque_range_matches_the_json(run):
    """Catches: ``START:STOP:COUNT`` read as a step or as COUNT + 1 values; table rows
    out of order against the JSON; the converged column missing."""
    rc, text, err = _call(["loaded", EXAMPLE, "--torque-Nm", "50:200:2", "--misalignment-um",
                           "0,10", *SMALL])
    assert rc == 0 and err == "", err
    rows = [ln.split() for ln in text.splitlines() if not ln.startswith("#")][1:]
    assert len(rows) == 4 and all(r[-1] == "yes" for r in rows)
    ptp = np.asarray(_strict(run[1])["te_ptp_um"]).ravel()
    np.testing.assert_allclose([float(r[2]) for r in rows], ptp, atol=6e-5)
    assert [float(r[0]) for r in rows] == [50.0, 50.0, 200.0, 200.0]


def test_not_converged_point_warns_and_exits_3(run, monkeypatch):
    """Catches: a non-converged operating point printed as a valid result with exit 0
    and no warning."""
    real = gj.involute.loaded_te_map

    def fake(*a, **k):
        m = real(*a, **k)
        conv = np.asarray(m.converged).copy()
        conv[1, 0] = False
        return m._replace(converged=conv)

    monkeypatch.setattr(gj.involute, "loaded_te_map", fake)
    rc, text, err = _call(["loaded", EXAMPLE, *OPS, *SMALL])
    assert rc == 3
    lines = err.splitlines()
    assert len(lines) == 2 and lines[0].startswith("gearjax: warning:") and "200 N m" in lines[0]
    assert lines[1].startswith("gearjax: error: 1 of 4 operating points")
    assert text.splitlines()[4].split()[-1] == "no"


def test_parse_torques_list_and_range():
    """Catches: a range whose ends are not included or whose COUNT is ignored."""
    assert parse_torques("50, 100,200", 1e-3, 1e7) == [50.0, 100.0, 200.0]
    assert parse_torques("50:400:8", 1e-3, 1e7) == pytest.approx(np.linspace(50, 400, 8))
    assert parse_torques("70:70:1", 1e-3, 1e7) == [70.0]


@pytest.mark.parametrize("argv, needle", [
    (["--torque-Nm", "0"], "--torque-Nm"),
    (["--torque-Nm", "abc"], "--torque-Nm"),
    (["--torque-Nm", "50:100"], "START:STOP:COUNT"),
    (["--torque-Nm", "50:100:0"], "COUNT"),
    (["--torque-Nm", "50,,100"], "--torque-Nm"),
    (["--torque-Nm", "100", "--misalignment-um", "-2000"], "--misalignment-um"),
    (["--torque-Nm", "100", "--compliance", "steel"], "compliance"),
    (["--torque-Nm", "100", "--positions", "2"], "--positions"),
    (["--torque-Nm", "100", "--slices", "4.5"], "--slices"),
])
def test_bad_input_one_line_before_any_work(argv, needle, monkeypatch):
    """Catches: bad input reaching the compiled program (the compute entry point is
    replaced by one that fails), a traceback, or a message that does not name the flag."""
    monkeypatch.setattr(gj.involute, "loaded_te_map",
                        lambda *a, **k: pytest.fail("computed on bad input"))
    rc, text, err = _call(["loaded", EXAMPLE, *argv])
    assert rc == 2 and text == ""
    assert len(err.splitlines()) == 1 and err.startswith("gearjax: error:") and needle in err


def test_non_involute_design_refused(monkeypatch):
    """Catches: a hypoid design handed to the involute line contact (a TypeError
    traceback instead of one line)."""
    rc, text, err = _call(["loaded", "example:hft_8x43", "--torque-Nm", "100"])
    assert rc == 2 and len(err.splitlines()) == 1 and "involute" in err


def test_run_tca_refuses_microgeometry():
    """Catches: run_tca (the point-contact TCA) silently ignoring the [microgeometry]
    tables (an unmodified pair analysed as if it were the design); the commands `gearjax
    tca` / `gearjax efficiency` take such a design to the line contact
    (tests/test_cli_microgeometry.py)."""
    with pytest.raises(ValueError, match="microgeometry"):
        gj.run_tca(gj.load_design(EXAMPLE))


# ----------------------------------------------------------------------- the design file

@pytest.fixture(scope="module")
def raw():
    data = gj.io.read_toml(EXAMPLE)
    del data["microgeometry"]
    return data


def _with(raw, micro):
    d = copy.deepcopy(raw)
    d["microgeometry"] = micro
    return read_involute(d)


def test_member_and_flank_tables(raw):
    """Catches: a member table setting only one flank, a flank table leaking to the other
    flank or member, a shape not mapped (parabolic -> exponent 2)."""
    f = _with(raw, {"pinion": {"tip_relief_um": 5.0, "tip_relief_length_mm": 1.5,
                               "tip_relief_shape": "parabolic"},
                    "gear_coast": {"bias_um": 3.0, "end_relief_II_um": 4.0,
                                   "end_relief_II_length_mm": 5.0}})
    m = f.micro
    for side in ("drive", "coast"):
        p = m.flanks(side).pinion
        assert float(p.tip_relief) == 5.0 and float(p.tip_relief_exponent) == 2.0
    assert float(m.coast.gear.bias) == 3.0 and float(m.coast.gear.end_relief_II) == 4.0
    assert float(m.drive.gear.bias) == 0.0 and float(m.drive.gear.end_relief_II) == 0.0
    assert float(m.coast.pinion.bias) == 0.0
    assert _with(raw, {"pinion": {"lead_crowning_um": 2.0}}).micro.drive.gear == \
        gj.involute.FlankModification.none()
    assert read_involute(raw).micro is None
    f = _with(raw, {"pinion_drive": {"tip_relief_um": 7.0, "tip_relief_length_mm": 2.0},
                    "pinion_coast": {"lead_crowning_um": 3.0}})
    assert float(f.micro.drive.pinion.tip_relief) == 7.0
    assert float(f.micro.drive.pinion.lead_crowning) == 0.0
    assert float(f.micro.coast.pinion.lead_crowning) == 3.0
    assert float(f.micro.coast.pinion.tip_relief) == 0.0


def test_coast_side_reports_and_analyses_the_coast_flanks(raw, tmp_path):
    """``--side coast`` on a design whose coast flanks differ from its drive flanks: the
    JSON's ``modifications`` are the coast flanks' and the numbers those of
    ``loaded_te_map(side="coast")`` (not the drive side's).  Planted bugs caught: the
    reported modifications always the drive side's, the side not passed to the map, a
    pinion_coast table read into the drive flank."""
    d = copy.deepcopy(raw)
    d["microgeometry"] = {"pinion_drive": {"tip_relief_um": 7.0, "tip_relief_length_mm": 2.0},
                          "pinion_coast": {"lead_crowning_um": 9.0}}
    path = tmp_path / "coast.toml"
    from gearjax.io.toml import dumps_toml
    path.write_text(dumps_toml(d))
    rc, text, err = _call(["loaded", str(path), "--torque-Nm", "150", *SMALL, "--side",
                           "coast", "--json"])
    assert rc == 0, err
    out = _strict(text)
    assert out["modifications"]["pinion"]["lead_crowning"] == 9.0
    assert out["modifications"]["pinion"]["tip_relief"] == 0.0
    f = gj.load_design(str(path))
    for side in ("coast", "drive"):
        m = gj.involute.loaded_te_map(f, [150.0], [0.0], side=side, positions=8, slices=6)
        same = out["te_ptp_um"][0][0] == pytest.approx(float(m.te_ptp_um[0, 0]), rel=1e-12)
        assert same == (side == "coast")


@pytest.mark.parametrize("micro, needles", [
    ({"pinion": {"tip_relief_um": 8.0}}, ("[microgeometry.pinion]", "tip_relief_um = 8",
                                           "tip_relief_length_mm")),
    ({"gear_drive": {"end_relief_I_um": 8.0, "end_relief_I_length_mm": 0.0}},
     ("[microgeometry.gear_drive]", "end_relief_I_length_mm = 0")),
    ({"pinion": {}, "pinion_drive": {}}, ("[microgeometry.pinion]",
                                          "[microgeometry.pinion_drive]")),
    ({"pinion": {"tip_relief_shape": "cubic"}}, ("tip_relief_shape", "'cubic'", "linear")),
    ({"pinion": {"tip_relief_um": 600.0, "tip_relief_length_mm": 1.0}},
     ("[microgeometry.pinion]", "tip_relief_um = 600", "[0, 500]")),
    ({"pinion": {"tip_relif_um": 1.0}}, ("microgeometry.pinion.tip_relif_um",)),
    ({"wheel": {}}, ("microgeometry.wheel",)),
    ({"gear": {"bias_um": "x"}}, ("[microgeometry.gear]", "bias_um", "number")),
    ({"gear": {"bias_um": float("nan")}}, ("[microgeometry.gear]", "bias_um", "finite")),
    (3.0, ("[microgeometry]", "table")),
])
def test_bad_tables_refused_in_one_line(raw, micro, needles):
    """Catches: a relief without its length taking a silent 1 mm, a member and a flank
    table both applied, an unknown shape, key or sub-table accepted, an out-of-range or
    non-number value passed on, a message that does not name the table and key."""
    with pytest.raises(ValueError) as exc:
        _with(raw, micro)
    msg = str(exc.value)
    assert "\n" not in msg
    for n in needles:
        assert n in msg, (n, msg)


def test_example_show_loads_back():
    """Catches: the packaged example listing a defaults line that does not load as TOML
    comments, or the example failing its tooth-form checks."""
    rc, text, err = _call(["example", "show", "helical_microgeometry"])
    assert rc == 0 and err == ""
    import tomllib
    d = tomllib.loads(text)
    assert d["microgeometry"]["pinion"]["lead_crowning_um"] == 6.0


def test_efficiency_columns_are_the_library_map():
    """``--rpm`` with the lubrication adds power loss and efficiency equal to
    ``loaded_te_map`` with the same oil and surface (1e-12); without --rpm they are null
    (the fixture's run).  Planted bugs caught: the oil or roughness not passed, the
    columns from another torque, the efficiency printed as a loss."""
    rc, text, err = _call(["loaded", EXAMPLE, "--torque-Nm", "200", *SMALL, "--rpm", "1500",
                           "--oil", "mineral_vg100", "--sigma-um", "0.4", "--json"])
    assert rc == 0, err
    out = _strict(text)
    oil = gj.tribology.get_oil("mineral_vg100")
    surf = gj.tribology.make_surface(0.4)
    ref = gj.involute.loaded_te_map(gj.load_design(EXAMPLE), [200.0], [0.0], positions=8,
                                    slices=6, pinion_rpm=1500.0, oil=oil, surface=surf)
    assert out["efficiency"][0][0] == pytest.approx(float(ref.efficiency[0, 0]), rel=1e-12)
    assert out["power_loss_W"][0][0] == pytest.approx(float(ref.power_loss_W[0, 0]),
                                                      rel=1e-12)
    assert 0.98 < out["efficiency"][0][0] < 1.0
    assert out["input"]["rpm"] == 1500.0 and out["input"]["oil"] == "mineral_vg100"


@pytest.mark.parametrize("extra, msg", [
    (["--rpm", "1500"], "--rpm needs the lubrication"),
    (["--rpm", "1500", "--oil", "mineral_vg100"], "--rpm needs the lubrication"),
    (["--oil", "mineral_vg100", "--sigma-um", "0.4"], "apply with --rpm only"),
    (["--sigma-um", "0.4"], "apply with --rpm only"),
    (["--rpm", "-5", "--oil", "mineral_vg100", "--sigma-um", "0.4"], "--rpm = -5"),
    (["--rpm", "1500", "--oil", "mineral_vg100", "--sigma-um", "50"], "--sigma-um"),
])
def test_lubrication_flags_refused_before_work(extra, msg, monkeypatch):
    """The efficiency needs --rpm, an oil and a roughness together; each bad combination
    or value is one line and exit 2 before any JAX work.  Planted bug caught: the
    lubrication silently ignored without --rpm, or a default oil assumed."""
    monkeypatch.setattr(gj.involute, "loaded_te_map",
                        lambda *a, **k: pytest.fail("work started before the refusal"))
    rc, out, err = _call(["loaded", EXAMPLE, "--torque-Nm", "200", *extra])
    assert rc == 2, (rc, err)
    assert msg in err and len(err.strip().splitlines()) == 1, err


def test_coarse_slices_warned():
    """A helical face cut into one slice (its piece spans more than a quarter of the path
    of contact) gets a warning line naming the slices to use; the default cut of the
    example and any spur pair none.  Planted bug caught: the helix angle left out of
    the check (spur pairs warned, helical ones not)."""
    design = gj.load_design(EXAMPLE)
    w = gj.involute.resolution_warnings(design, 1)
    assert len(w) == 1 and "use at least" in w[0]
    n = int(w[0].rsplit("at least ", 1)[1].split()[0])
    assert gj.involute.resolution_warnings(design, n) == []
    assert gj.involute.resolution_warnings(design, n - 1) != []
    assert gj.involute.resolution_warnings(design, 20) == []
    spur = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(20, 40, 4, 20), 80.0)
    assert gj.involute.resolution_warnings(spur, 1) == []
