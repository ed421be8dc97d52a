"""Design files and user-facing constructors refuse bad input with one line naming
the file, the table and the key (gearjax.gears.hypoid.design_file, gearjax.io).

Loading and validation only: no flank solve, no TCA compile."""

import copy
import math

import jax
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearjax import io
from gearjax.cli import main
from gearjax.gears.hypoid.blank import BlankInput
from gearjax.gears.hypoid.cutter import make_cutter
from gearjax.gears.hypoid.design_file import (CROSS_CHECK_RTOL, MACHINE_DEFAULTS, cross_check,
                                              defaults_applied, design_from_dict, load_design)
from gearjax.gears.hypoid.machine import MachineSettings
from gearjax.tca.assembly import Misalignment

# the hypoid/spiral-bevel examples (other families' kinds have their own tests)
EXAMPLES = [n for n in io.list_examples()
            if io.read_toml(f"example:{n}")["design"]["kind"] in ("hypoid", "spiral_bevel")]
BASE = "hypoid_iso_10x41"


@pytest.fixture(scope="module")
def raw():
    """The packaged example as parsed TOML (no validation)."""
    return io.read_toml(f"example:{BASE}")


def _edit(data, path, value=None, delete=False):
    d = copy.deepcopy(data)
    node = d
    for k in path[:-1]:
        node = node[k]
    if delete:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return d


def _refused(data, *needles):
    with pytest.raises(ValueError) as exc:
        design_from_dict(data)
    msg = str(exc.value)
    assert "\n" not in msg
    for n in needles:
        assert n in msg, (n, msg)
    return msg


# ----------------------------------------------------------------------------- examples

@pytest.mark.parametrize("name", EXAMPLES)
def test_every_example_loads_and_passes_the_cross_checks(name):
    d = load_design(f"example:{name}")
    cross_check(d)                                    # explicit: no exception
    assert d.name == name
    for m, f in d.flanks():                           # every flank table builds
        d.machine(m, f), d.cutter(m, f)


def test_nine_examples_are_packaged():
    """Six with flanks, three blank-only (hypoid_6x39_7p5in and the ISO 23509 annex F
    samples)."""
    assert len(EXAMPLES) == 9
    assert sum(1 for n in EXAMPLES if not load_design(f"example:{n}").flanks()) == 3


# ----------------------------------------------------------------------------- missing keys

@pytest.mark.parametrize("path", [
    ("pinion", "convex", "machine", "sliding_base"),     # the example
    ("pinion", "concave", "machine", "blank_offset"),
    ("gear", "convex", "machine", "center_to_back"),
    ("gear", "concave", "machine", "tilt"),
    ("gear", "convex", "machine", "swivel"),
    ("pinion", "convex", "machine", "ratio_of_roll"),
    ("pinion", "convex", "machine", "machine_root_angle"),
    ("pinion", "convex", "machine", "radial_distance"),
    ("pinion", "convex", "machine", "type"),
    ("gear", "concave", "cutter", "edge_radius"),
    ("blank_summary", "gear", "face_width"),
    ("blank_summary", "pinion", "teeth"),
    ("blank_summary", "gear", "hand"),
    ("blank", "z1"),
    ("design", "kind"),
])
def test_missing_geometry_key_is_refused(raw, path):
    table = ".".join(path[:-1])
    _refused(_edit(raw, path, delete=True), f"[{table}]", f"'{path[-1]}'")


def test_missing_tables(raw):
    _refused(_edit(raw, ("blank",), delete=True), "[blank]")
    _refused(_edit(raw, ("blank_summary", "gear"), delete=True), "[blank_summary.gear]")
    _refused(_edit(raw, ("design",), delete=True), "[design]")
    _refused(_edit(raw, ("pinion", "convex", "cutter"), delete=True), "[pinion.convex]", "'cutter'")


def test_modified_roll_defaults_are_reported(raw):
    """The one default of the flank tables (no modified roll) is listed by
    defaults_applied when the key is left out, and not when it is given."""
    d = design_from_dict(raw)
    keys = {k for k, _, _ in defaults_applied(d)}
    assert "pinion.convex.machine.modified_roll_2c" in keys
    assert "blank.limit_pressure_angle_factor" in keys
    assert not any(k.startswith("gear.") for k in keys)           # formate gear: no roll
    given_ = _edit(raw, ("pinion", "convex", "machine", "modified_roll_2c"), 0.01)
    keys2 = {k for k, _, _ in defaults_applied(design_from_dict(given_))}
    assert "pinion.convex.machine.modified_roll_2c" not in keys2
    assert float(design_from_dict(given_).machine("pinion", "convex").modified_roll_2c) == 0.01
    assert MACHINE_DEFAULTS == {"modified_roll_2c": 0.0, "modified_roll_6d": 0.0}


# ----------------------------------------------------------------------------- wrong values

@pytest.mark.parametrize("path,value,needle", [
    (("pinion", "convex", "cutter", "point_radius"), "115.8", "must be a number"),
    (("pinion", "convex", "cutter", "point_radius"), True, "must be a number"),
    (("pinion", "convex", "cutter", "point_radius"), [115.8], "must be a number"),
    (("pinion", "convex", "cutter", "point_radius"), float("nan"), "finite"),
    (("gear", "concave", "machine", "sliding_base"), float("inf"), "finite"),
    (("gear", "concave", "machine", "cradle_angle"), -float("inf"), "finite"),
    (("pinion", "convex", "machine", "cradle_angle"), 400.0, "[-360, 360]"),
    (("pinion", "convex", "machine", "ratio_of_roll"), -4.2, "ratio_of_roll"),
    (("pinion", "convex", "machine", "ratio_of_roll"), {"a": 1}, "must be a number"),
    (("gear", "convex", "machine", "ratio_of_roll"), 4.1, "formate member has no roll"),
    (("pinion", "convex", "machine", "type"), 1, "must be a string"),
    (("pinion", "convex", "machine", "type"), "hobbed", "'generated'"),
    (("blank_summary", "pinion", "teeth"), 10.0, "must be an integer"),
    (("blank_summary", "pinion", "teeth"), True, "must be an integer"),
    (("blank_summary", "pinion", "teeth"), 0, "teeth"),
    (("blank_summary", "gear", "hand"), "up", "hand"),
    (("blank_summary", "gear", "pitch_angle"), float("nan"), "finite"),
    (("blank_summary", "gear", "face_width"), 500.0, "face_width"),
    (("blank", "z1"), "10", "must be an integer"),
    (("blank", "offset_mm"), float("nan"), "offset_mm"),
    (("blank", "offset_mm"), True, "must be a number"),
    (("blank", "shaft_angle_deg"), "90", "must be a number"),
    (("blank", "gear_face_width_mm"), 1000.0, "gear_face_width_mm"),
    (("design", "kind"), "worm", "kind"),
    (("design", "name"), 3, "must be a string"),
])
def test_wrong_value_is_refused_naming_table_and_key(raw, path, value, needle):
    table, key = ".".join(path[:-1]), path[-1]
    _refused(_edit(raw, path, value), f"[{table}]", key, needle)


@pytest.mark.parametrize("path", [
    ("pinion", "convex", "machine", "colour"),
    ("blank_summary", "pinion", "shoe_size"),
    ("blank", "wrong_key"),
    ("gear", "concave", "cutter", "radius"),
    ("design", "author"),
    ("pinion", "convex", "extra"),
    ("pinion", "hub"),
    ("blank_summary", "idler"),
])
def test_unknown_key_is_refused(raw, path):
    _refused(_edit(raw, path, 1.0), path[-1], "unknown key")


def test_dials_and_geometric_settings_conflict():
    raw = io.read_toml("example:hft_8x43")
    _refused(_edit(raw, ("pinion", "convex", "machine", "tilt"), 10.0), "conflicts", "no116")
    _refused(_edit(raw, ("pinion", "convex", "machine", "no116", "cradle"), "126"),
             "[pinion.convex.machine.no116]", "cradle", "must be a number")
    _refused(_edit(raw, ("pinion", "convex", "machine", "no116", "tilt"), delete=True),
             "[pinion.convex.machine.no116]", "'tilt'")


# ----------------------------------------------------------------------------- cross-checks

def test_teeth_disagreement_is_refused(raw):
    """The issue's case: gear teeth of [blank_summary.gear] differ from [blank] z2."""
    _refused(_edit(raw, ("blank_summary", "gear", "teeth"), 43), "[blank] z2 = 41",
             "[blank_summary.gear] teeth = 43")
    _refused(_edit(raw, ("blank", "z1"), 11), "[blank] z1 = 11", "[blank_summary.pinion]")


def test_hand_disagreements_are_refused(raw):
    _refused(_edit(raw, ("blank_summary", "gear", "hand"), "left"), "opposite hands")
    both = _edit(_edit(raw, ("blank_summary", "gear", "hand"), "left"),
                 ("blank_summary", "pinion", "hand"), "right")
    _refused(both, "[blank] hand = 'left'", "[blank_summary.pinion] hand = 'right'")


def test_kind_and_offset_must_agree(raw):
    _refused(_edit(raw, ("design", "kind"), "spiral_bevel"), "offset_mm = 25", "spiral_bevel")
    sb = io.read_toml("example:spiral_bevel_10x30")
    _refused(_edit(sb, ("design", "kind"), "hypoid"), "offset_mm = 0", "'hypoid'")


def _rel(a, b):
    return abs(a - b) / max(abs(a), abs(b))


def test_real_valued_cross_checks_at_their_tolerance(raw):
    """Each relation is refused just beyond CROSS_CHECK_RTOL and accepted well inside
    it; the expected values are computed here from the table entries."""
    g = raw["blank_summary"]["gear"]
    de2 = 2 * g["outer_cone_distance"] * math.sin(math.radians(g["pitch_angle"]))
    assert _rel(de2, raw["blank"]["gear_outer_pitch_diameter_mm"]) < 1e-5   # the example agrees
    for key, base in (("gear_outer_pitch_diameter_mm", de2),
                      ("gear_face_width_mm", g["face_width"]),
                      ("spiral_angle_deg", raw["blank_summary"]["pinion"]["mean_spiral_angle"])):
        design_from_dict(_edit(raw, ("blank", key), base * (1 + 0.3 * CROSS_CHECK_RTOL)))
        _refused(_edit(raw, ("blank", key), base * (1 + 3 * CROSS_CHECK_RTOL)), f"[blank] {key}",
                 "disagrees")


def test_common_apex_relations_of_a_spiral_bevel_design():
    sb = io.read_toml("example:spiral_bevel_10x30")
    p, g = sb["blank_summary"]["pinion"], sb["blank_summary"]["gear"]
    # closed forms of the example itself: tan(delta1) = z1/z2 at 90 deg shaft angle
    assert math.degrees(math.atan2(10, 30)) == pytest.approx(p["pitch_angle"], abs=1e-6)
    _refused(_edit(sb, ("blank_summary", "gear", "mean_spiral_angle"), 36.0), "mean_spiral_angle",
             "offset 0")
    bad = _edit(_edit(sb, ("blank_summary", "pinion", "outer_cone_distance"), 112.0),
                ("blank_summary", "pinion", "mean_cone_distance"), 97.0)
    _refused(bad, "outer_cone_distance", "offset 0")
    # both pitch angles shifted by +0.2 deg: the sum no longer equals the shaft angle
    bad = _edit(_edit(sb, ("blank_summary", "gear", "pitch_angle"), g["pitch_angle"] + 0.2),
                ("blank_summary", "pinion", "pitch_angle"), p["pitch_angle"] + 0.2)
    bad = _edit(bad, ("blank", "gear_outer_pitch_diameter_mm"),
                2 * g["outer_cone_distance"] * math.sin(math.radians(g["pitch_angle"] + 0.2)))
    msg = _refused(bad, "pitch_angle")
    assert "shaft_angle_deg" in msg or "sin(delta1)/sin(delta2)" in msg


def test_gear_teeth_fewer_than_pinion_teeth(raw):
    bad = _edit(_edit(raw, ("blank_summary", "gear", "teeth"), 9), ("blank", "z2"), 9)
    _refused(bad, "ratio")


# ----------------------------------------------------------------------------- files

def _write(tmp_path, name, content):
    p = tmp_path / name
    (p.write_bytes if isinstance(content, bytes) else p.write_text)(content)
    return p


@pytest.mark.parametrize("name,content,needle", [
    ("empty.toml", "", "is empty"),
    ("comments.toml", "# nothing\n", "is empty"),
    ("binary.toml", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "binary"),
    ("latin1.toml", "[design]\nname = 'Zahnr\u00e4der'\n".encode("latin-1"), "not UTF-8"),
    ("syntax.toml", "[design]\nkind = = 'hypoid'\n", "invalid TOML"),
    ("dup.toml", "[design]\nkind = 'hypoid'\nkind = 'hypoid'\n", "invalid TOML"),
])
def test_unreadable_files_name_the_file(tmp_path, name, content, needle):
    p = _write(tmp_path, name, content)
    with pytest.raises(ValueError) as exc:
        load_design(p)
    assert name in str(exc.value) and needle in str(exc.value) and "\n" not in str(exc.value)


def test_missing_file_and_directory(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        load_design(tmp_path / "none.toml")
    with pytest.raises(ValueError, match="is a directory"):
        load_design(tmp_path)


def test_load_design_prefixes_the_file_name(tmp_path, raw):
    p = io.atomic_write(tmp_path / "d.toml", io.dumps_toml(
        _edit(raw, ("pinion", "convex", "machine", "sliding_base"), delete=True)))
    with pytest.raises(ValueError) as exc:
        load_design(p)
    msg = str(exc.value)
    assert msg.startswith(f"design file {str(p)!r}: [pinion.convex.machine]") and "sliding_base" in msg


@pytest.mark.parametrize("mutate,needle", [
    (lambda t: t.replace("sliding_base = 0.045523\n", "", 1), "sliding_base"),
    (lambda t: t.replace("teeth = 41", "teeth = 43"), "teeth = 43"),
    (lambda t: t.replace("point_radius = 115.822769", "point_radius = nan", 1), "point_radius"),
    (lambda t: t + "\n[gear.convex.machine.extra]\nx = 1\n", "no116"),
    (lambda t: "\x00" + t, "binary"),
])
def test_cli_refuses_with_one_line(tmp_path, capsys, mutate, needle):
    text = io.example_path(BASE).read_text(encoding="utf-8")
    p = _write(tmp_path, "bad.toml", mutate(text))
    for argv in (["blank", str(p)], ["tca", str(p)]):
        assert main(argv) == 2
        cap = capsys.readouterr()
        err = cap.err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("gearjax: error: design file") and needle in err[0]
        assert "Traceback" not in cap.err and cap.out == ""


def test_cli_prints_the_defaults(capsys):
    assert main(["example", "show", "spiral_bevel_10x30"]) == 0
    out = capsys.readouterr().out
    assert "# defaults applied" in out
    assert "#   pinion.convex.machine.modified_roll_2c = 0.0" in out
    import tomllib
    assert tomllib.loads(out) == io.read_toml("example:spiral_bevel_10x30")   # still TOML
    assert main(["blank", "example:hft_8x43"]) == 0
    out = capsys.readouterr().out
    assert "defaults applied" in out and "blank.dedendum_factor = 1.25" in out
    assert "modified_roll" not in out                  # the 8/43 file gives them


# ----------------------------------------------------------------------------- constructors

@pytest.mark.parametrize("args,name", [
    (("117", 20.0, 1.0, "convex"), "point_radius"),
    ((117.0, True, 1.0, "convex"), "blade_angle"),
    ((117.0, 20.0, None, "convex"), "edge_radius"),
    ((117.0, 20.0, [1.0], "convex"), "edge_radius"),
    ((117.0, 20.0, 1.0, 1), "flank"),
    ((float("nan"), 20.0, 1.0, "convex"), "point_radius"),
])
def test_make_cutter_refuses(args, name):
    with pytest.raises(ValueError, match=name):
        make_cutter(*args)


_MS = dict(radial_distance=110.0, cradle_angle=-1.1, machine_root_angle=0.2, tilt=0.0,
           swivel=0.0, blank_offset=-25.0, sliding_base=0.0, center_to_back=0.0,
           ratio_of_roll=4.2)


@pytest.mark.parametrize("key,value", [
    ("radial_distance", "110"), ("tilt", True), ("sliding_base", None),
    ("blank_offset", [1.0]), ("cradle_angle", 7.0), ("machine_root_angle", -6.5),
    ("swivel", float("inf")), ("ratio_of_roll", 0.0), ("center_to_back", float("nan")),
])
def test_machine_settings_refuse(key, value):
    with pytest.raises(ValueError, match=key):
        MachineSettings.create(**{**_MS, key: value})
    with pytest.raises(ValueError, match="generated"):
        MachineSettings.create(**_MS, generated="yes")


def test_constructors_still_trace():
    """Tracers pass the eager checks (jax.grad through the validated constructors)."""
    g = jax.grad(lambda s: MachineSettings.create(**{**_MS, "sliding_base": s}).sliding_base)(1.0)
    assert float(g) == 1.0
    g = jax.grad(lambda r: make_cutter(r, 20.0, 1.0, "concave").point_radius)(100.0)
    assert float(g) == 1.0
    g = jax.grad(lambda e: Misalignment.create(dG=e).dG)(0.1)
    assert float(g) == 1.0


@pytest.mark.parametrize("kw,name", [
    ({"dE": "0.1"}, "dE"), ({"dP": True}, "dP"), ({"dG": None}, "dG"),
    ({"dSigma_deg": [0.1]}, "dSigma"), ({"dE": float("nan")}, "dE"), ({"dG": 51.0}, "dG"),
    ({"dSigma_deg": -5.5}, "dSigma"),
])
def test_misalignment_create_refuses(kw, name):
    with pytest.raises(ValueError, match=name):
        Misalignment.create(**kw)


def test_blank_input_from_dict_types(raw):
    base = raw["blank"]
    BlankInput.from_dict(base)
    for key, value in (("z1", 10.0), ("z2", True), ("offset_mm", "25"), ("cutter_radius_mm", [1.0]),
                       ("hand", 1), ("spiral_angle_deg", float("inf"))):
        with pytest.raises(ValueError, match=key):
            BlankInput.from_dict({**base, key: value})


# ----------------------------------------------------------------------------- property test

_EXAMPLE_DICTS = {n: io.read_toml(f"example:{n}") for n in EXAMPLES}


def _leaves(d, prefix=()):
    """(path, value) of every scalar key of the geometry tables (not free-form ones)."""
    for k, v in d.items():
        if prefix == () and k == "machine_summary":
            continue
        if isinstance(v, dict):
            yield from _leaves(v, prefix + (k,))
        else:
            yield prefix + (k,), v


_NUMERIC_OK = {"design"}      # [design] holds strings only


@st.composite
def _corruption(draw):
    name = draw(st.sampled_from(EXAMPLES))
    data = _EXAMPLE_DICTS[name]
    leaves = list(_leaves(data))
    kind = draw(st.sampled_from(["drop", "type", "nan", "inf", "range", "unknown", "teeth"]))
    if kind == "drop":
        # a key without a documented default (everything except optional ones)
        optional = {"mean_cone_distance", "modified_roll_2c", "modified_roll_6d", "name",
                    "description", "source"}
        cand = [(p, v) for p, v in leaves if p[-1] not in optional and p[0] != "blank"]
        cand += [(p, v) for p, v in leaves if p[0] == "blank" and p[-1] in
                 ("z1", "z2", "gear_outer_pitch_diameter_mm", "gear_face_width_mm",
                  "spiral_angle_deg", "cutter_radius_mm")]
        # formate machine tables: the roll keys are optional (zero)
        cand = [(p, v) for p, v in cand if not (p[-1] in ("ratio_of_roll",) and
                                                 _table(data, p).get("type") == "formate")]
        path, _ = draw(st.sampled_from(cand))
        return name, _edit(data, path, delete=True), path[-1]
    if kind == "unknown":
        tables = [p[:-1] for p, _ in leaves]
        t = draw(st.sampled_from(tables))
        key = draw(st.sampled_from(["colour", "sliding_bass", "teeth_", "Tilt"]))
        return name, _edit(data, t + (key,), 1.0), key
    if kind == "teeth":
        m = draw(st.sampled_from(["pinion", "gear"]))
        if m not in data.get("blank_summary", {}):
            return name, _edit(data, ("blank", "z1"), "10"), "z1"
        z = data["blank_summary"][m]["teeth"]
        dz = draw(st.sampled_from([-2, -1, 1, 3]))
        return name, _edit(data, ("blank_summary", m, "teeth"), z + dz), "teeth"
    nums = [(p, v) for p, v in leaves if isinstance(v, (int, float)) and not isinstance(v, bool)]
    path, v = draw(st.sampled_from(nums))
    if kind == "type":
        bad = draw(st.sampled_from([str(v), True, [v], {"value": v}]))
    elif kind == "nan":
        bad = float("nan")
    elif kind == "inf":
        bad = draw(st.sampled_from([math.inf, -math.inf]))
    else:  # out of every allowed range: beyond any length or angle bound used
        bad = draw(st.sampled_from([1e9, -1e9]))
    return name, _edit(data, path, bad), path[-1]


def _table(data, path):
    node = data
    for k in path[:-1]:
        node = node[k]
    return node


# max_examples = 60, derandomized (the same 60 corruptions on every run)
@settings(derandomize=True, max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(_corruption())
def test_random_corruption_is_refused_naming_the_key(case):
    name, data, key = case
    with pytest.raises(ValueError) as exc:
        design_from_dict(data)
    msg = str(exc.value)
    assert key in msg and "\n" not in msg, (name, key, msg)
