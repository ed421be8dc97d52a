"""Hostile-input harness: run the ``gearjax`` command on inputs a careless or curious
user might give it and classify what happens.

Usage (from the repository root; standard library only, plus this checkout's
``gearjax`` for the command itself)::

    python tools/hostile_inputs.py [--jobs 2] [--only REGEX] [--timeout 300]
                                   [--md OUT.md] [--json OUT.json] [--list]
                                   [--cache-dir DIR] [--keep]

Each case of :data:`CASES` is an argument list for ``python -m gearjax.cli`` (run
in a subprocess with this checkout first on ``PYTHONPATH``), an optional setup that
makes files in the case's own temporary directory (a corrupted design file, a
read-only directory, ...), and the class of answer the project's standards call for:

``refuse``  exit status 2 and exactly one stderr line ``gearjax: error: ...`` (bad
            input is refused before any work, naming the parameter, value and range);
``flag``    the run may go on but the user must be told: a ``gearjax: warning:``
            line, or a non-zero exit with one clean ``gearjax: error:`` line (a
            refusal is accepted too);
``ok``      a valid run: exit 0, no warning, output free of NaN/inf (and valid
            strict JSON where ``--json`` is given).

A case may accept further observed classes (``also``; e.g. a tiny but positive
speed may be refused or give a finite answer).  Observed classes:

``refusal``   exit 2 and exactly one stderr line, starting ``gearjax: error:``;
``flagged``   exit 0 with a ``gearjax: warning:`` line, or a non-zero exit whose
              stderr is only ``gearjax:`` lines with exactly one ``gearjax: error:``
              (e.g. exit 3 "the flanks do not touch");
``traceback`` ``Traceback`` in stderr;
``silent``    exit 0 and no warning although the case expects a refusal or a flag;
``nan``       exit 0 and a NaN/inf in stdout (a ``NaN``/``Infinity`` JSON constant,
              or a bare ``nan``/``inf`` token in a table; in a ``gearjax tca`` table,
              rows marked ``edge``/``no-conv`` are exempt -- they print ``nan`` for "no
              value" by design and say so in their flag column -- and so is ``inf``
              on ``ok`` rows: the 2a column of a line contact, ``null`` in the JSON);
``badjson``   exit 0 with ``--json`` but stdout is not one JSON document;
``ok``        exit 0, no warning, clean output;
``unclean``   non-zero exit without a traceback whose stderr is not one clean line
              (argparse usage text, stray library warnings, a signal);
``timeout``   ran past ``--timeout``;
``setup_error`` the case's setup failed (a harness problem, not a gearjax one).

The table is robust to the command set changing: a case whose flag or command no
longer exists is simply classified by what happens (usually a refusal).

All runs share one JAX compilation cache (``GEARJAX_CACHE_DIR``; a temporary
directory unless ``--cache-dir`` is given) so that the TCA programs compile once;
the expensive cases are started first.  Kept out of CI (it takes tens of minutes);
``tests/test_hostile_harness.py`` checks only that the table is well formed and that
the classifier separates the classes.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES_DIR = ROOT / "gearjax" / "examples"

EXPECTED = ("refuse", "flag", "ok")
OBSERVED = ("refusal", "flagged", "traceback", "silent", "nan", "badjson", "ok", "unclean",
            "timeout", "setup_error")
#: observed classes that satisfy each expected class (a case may add more with ``also``)
ACCEPT = {"refuse": {"refusal"}, "flag": {"flagged", "refusal"}, "ok": {"ok"}}

#: the packaged example designs (names of gearjax/examples/*.toml)
EXAMPLES = sorted(p.stem for p in EXAMPLES_DIR.glob("*.toml"))
HYPOID_EXAMPLES = [n for n in EXAMPLES if not n.startswith("spiral_bevel")]


# ======================================================================================
# cases


@dataclass(frozen=True)
class Case:
    """One hostile input.

    ``argv`` may contain the placeholders ``{tmp}`` (the case's own temporary
    directory) and any key returned by ``setup(tmp)`` (e.g. ``{design}``, ``{ro}``).
    """

    id: str
    argv: tuple
    expect: str
    why: str
    setup: Callable | None = None
    also: frozenset = frozenset()
    heavy: bool = False            # compiles/runs a TCA or similar: started first

    @property
    def command(self) -> str:
        """The sub-command the case exercises: the first part of its id ('top': none)."""
        return self.id.split(".", 1)[0]

    @property
    def accepted(self) -> set:
        return ACCEPT[self.expect] | set(self.also)


# --------------------------------------------------------------------------------------
# setups (run in the harness process before the case's subprocess)


def dumps_toml(data: dict) -> str:
    """TOML text of a (corrupted) design: gearjax's own writer (it writes NaN and inf
    as TOML's ``nan``/``inf``, and a table where a number belongs as a sub-table)."""
    from gearjax.io import dumps_toml as gearjax_dumps_toml
    return gearjax_dumps_toml(data)


_DELETE = object()


def design_file(example: str, *edits, name: str = "design.toml"):
    """Setup: the packaged ``example`` with ``edits`` ``(dotted.path, value)`` applied
    (value ``_DELETE`` removes the key), written to ``{tmp}/name`` -> ``{design}``."""

    def setup(tmp: Path) -> dict:
        data = tomllib.loads((EXAMPLES_DIR / f"{example}.toml").read_text(encoding="utf-8"))
        for path, value in edits:
            *parents, last = path.split(".")
            d = data
            for p in parents:
                d = d.setdefault(p, {})
            if value is _DELETE:
                if last not in d:
                    raise KeyError(f"{example}: no key {path!r} to delete")
                del d[last]
            else:
                d[last] = value
        p = tmp / name
        p.write_text(dumps_toml(data), encoding="utf-8")
        return {"design": str(p)}

    return setup


def raw_file(content: bytes, name: str = "design.toml"):
    """Setup: a file with exactly ``content`` -> ``{design}``."""

    def setup(tmp: Path) -> dict:
        p = tmp / name
        p.write_bytes(content)
        return {"design": str(p)}

    return setup


def a_directory(name: str = "design.toml"):
    """Setup: a directory named like a file -> ``{dir}`` (also ``{design}``)."""

    def setup(tmp: Path) -> dict:
        p = tmp / name
        p.mkdir()
        return {"dir": str(p), "design": str(p)}

    return setup


def _cannot_create_in(d: Path) -> bool:
    probe = d / ".gearjax-hostile-probe"
    try:
        fd = os.open(probe, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600)
    except OSError:
        return True
    os.close(fd)
    os.unlink(probe)
    return False


def readonly_dir(tmp: Path) -> dict:
    """Setup: a directory in which no file can be created -> ``{ro}``.

    A mode-0555 directory; when that does not stop this user (root), a system
    directory that refuses new files (``/sys`` on Linux) -- nothing is written there.
    """
    d = tmp / "readonly"
    d.mkdir()
    os.chmod(d, 0o555)
    if _cannot_create_in(d):
        return {"ro": str(d)}
    for cand in (Path("/sys"),):
        if cand.is_dir() and _cannot_create_in(cand):
            return {"ro": str(cand)}
    raise RuntimeError("no read-only directory available to this user")


def study_file(*replacements, name: str = "study.toml"):
    """Setup: the packaged study ``spur_sliding`` with text ``replacements`` ``(old,
    new)`` applied, written to ``{tmp}/name`` -> ``{study}``."""

    def setup(tmp: Path) -> dict:
        text = (EXAMPLES_DIR / "studies" / "spur_sliding.toml").read_text(encoding="utf-8")
        for old, new in replacements:
            if old not in text:
                raise RuntimeError(f"study_file: {old!r} not in spur_sliding.toml")
            text = text.replace(old, new, 1)
        p = tmp / name
        p.write_text(text, encoding="utf-8")
        return {"study": str(p)}

    return setup


def plain_file(name: str = "afile"):
    """Setup: a regular file, to be used as if it were a directory -> ``{file}``."""

    def setup(tmp: Path) -> dict:
        p = tmp / name
        p.write_text("not a directory\n")
        return {"file": str(p)}

    return setup


#: the packaged sample measurement of ``gearjax correct`` (docs/correct.md)
SAMPLE_MEASUREMENT = (EXAMPLES_DIR / "measurements"
                      / "spiral_bevel_10x30_synthesised_pinion.csv")


def measured_file(edit=None, name: str = "measured.csv"):
    """Setup: the packaged sample measurement with ``edit(lines) -> lines`` applied (the
    text lines of the CSV), written to ``{tmp}/name`` -> ``{measured}``."""

    def setup(tmp: Path) -> dict:
        lines = SAMPLE_MEASUREMENT.read_text(encoding="utf-8").splitlines()
        if edit is not None:
            lines = edit(lines)
        p = tmp / name
        p.write_text("\n".join(lines) + "\n", encoding="utf-8")
        return {"measured": str(p)}

    return setup


def _rows_edit(fn):
    """An edit of the data rows (header and comments kept): ``fn(rows) -> rows``."""
    def edit(lines):
        head = [ln for ln in lines if ln.startswith("#") or ln.startswith("flank,")]
        rows = [ln for ln in lines if not (ln.startswith("#") or ln.startswith("flank,"))]
        return head + fn(rows)
    return edit


def _column_edit(row_index: int, column: int, fn):
    """Replace field ``column`` of data row ``row_index`` by ``fn(old text)``."""
    def rows_fn(rows):
        rows = list(rows)
        c = rows[row_index].split(",")
        c[column] = fn(c[column])
        rows[row_index] = ",".join(c)
        return rows
    return _rows_edit(rows_fn)


def _all_deviations(fn):
    """Apply ``fn`` to the deviation (last) field of every data row."""
    return _rows_edit(lambda rows: [",".join(r.split(",")[:-1] + [fn(r.split(",")[-1])])
                                    for r in rows])


# --------------------------------------------------------------------------------------
# the table


def _argv(base: list, over: dict | None = None, extra=()) -> tuple:
    """``base`` = [(flag, value)...]; ``over`` replaces values (None drops the flag)."""
    over = dict(over or {})
    out = []
    for flag, value in base:
        if flag in over:
            value = over.pop(flag)
            if value is None:
                continue
        out += [flag, value]
    for flag, value in over.items():
        if value is not None:
            out += [flag, value]
    return tuple(out) + tuple(extra)


def _slug(v: str) -> str:
    s = re.sub(r"[^A-Za-z0-9.+-]+", "_", v).strip("_") or "empty"
    return s.replace("+", "p")


INV = [("--z1", "20"), ("--z2", "40"), ("--module", "4"), ("--pressure-angle", "20")]
FRI = [("--load-N", "1000"), ("--rx-mm", "10"), ("--ry-mm", "300"), ("--ue", "5"), ("--us", "1"),
       ("--oil", "mineral_vg100"), ("--sigma-um", "0.4")]
STR = [("--load-N", "1000"), ("--rx-mm", "10"), ("--ry-mm", "300"), ("--oil", "mineral_vg100"),
       ("--sigma-um", "0.4")]
TCA_INV = "involute:z1=20,z2=40,m=4,alpha=20,b=30"

# out-of-range and non-numbers for a parameter that must be a finite positive number
_BAD_POSITIVE = ("0", "-1", "nan", "inf", "-inf", "1e300", "abc")


def _example_data(example: str) -> dict:
    return tomllib.loads((EXAMPLES_DIR / f"{example}.toml").read_text(encoding="utf-8"))


def _has_flanks(example: str) -> bool:
    """The example has flanks for the TCA: machine settings of both members (hypoid,
    spiral bevel), an involute pair (rack-generated; with a [microgeometry] table the
    line-contact TCA analyses it), or a family whose flanks follow from the design
    (preset-TE bevel, VH-CATT)."""
    data = _example_data(example)
    kind = data.get("design", {}).get("kind")
    if kind == "involute":
        return True
    if kind in ("hypoid", "spiral_bevel"):
        return "pinion" in data and "gear" in data
    return True                 # the preset-TE bevel and VH-CATT pairs: flanks by design


def _is_bevel(example: str) -> bool:
    """The example is a hypoid or spiral-bevel design file (what `gearjax blank` takes)."""
    return _example_data(example).get("design", {}).get("kind") in ("hypoid", "spiral_bevel")


def build_cases() -> list[Case]:
    cs: list[Case] = []

    def add(id, argv, expect, why, setup=None, also=(), heavy=False):
        cs.append(Case(id, tuple(argv), expect, why, setup, frozenset(also), heavy))

    # ---------------------------------------------------------------- top level
    add("top.no_args", [], "refuse", "no sub-command")
    add("top.unknown_command", ["frobnicate"], "refuse", "unknown sub-command")
    add("top.unknown_option", ["--frobnicate"], "refuse", "unknown global option")
    add("top.help", ["--help"], "ok", "help text, exit 0")

    # ---------------------------------------------------------------- involute
    add("involute.ok.table", ["involute", *_argv(INV)], "ok", "README example, table")
    add("involute.ok.json", ["involute", *_argv(INV), "--json"], "ok", "README example, JSON")
    add("involute.ok.helical_json",
        ["involute", *_argv(INV, {"--helix": "15", "--x1": "0.2", "--x2": "0"}), "--json"],
        "ok", "helical pair with profile shift")
    add("involute.ok.coast_json", ["involute", *_argv(INV, {"--side": "coast"}), "--json"],
        "ok", "coast side")
    add("involute.ok.points2_json", ["involute", *_argv(INV, {"--points": "2"}), "--json"],
        "ok", "smallest allowed number of points")
    numeric = {
        "--z1": ("0", "-20", "5", "20.5", "abc", "0x14", "nan", "inf", "1e300"),
        "--z2": ("0", "5", "nan", "-inf", "1e300"),
        "--module": ("0", "-4", "nan", "inf", "1e300", "4mm"),
        "--pressure-angle": ("0", "45", "90", "-20", "nan", "inf", "20deg"),
        "--helix": ("-15", "61", "90", "nan", "inf"),
        "--x1": ("5", "-3", "nan", "inf"),
        "--x2": ("5", "nan"),
        "--points": ("0", "1", "2.5", "-3", "nan", "1e300", "1e9"),
        "--rpm": ("0", "-1000", "nan", "inf", "1e300"),
    }
    for flag, values in numeric.items():
        for v in values:
            add(f"involute.{flag[2:]}={_slug(v)}", ["involute", *_argv(INV, {flag: v}), "--json"],
                "refuse", f"{flag} {v}: out of range or not a number")
    add("involute.module=1e-300", ["involute", *_argv(INV, {"--module": "1e-300"}), "--json"],
        "refuse", "tiny module: refuse, or a finite valid result", also={"ok"})
    add("involute.rpm=1e-300", ["involute", *_argv(INV, {"--rpm": "1e-300"}), "--json"],
        "refuse", "tiny speed: refuse, or a finite valid result", also={"ok"})
    add("involute.side=left", ["involute", *_argv(INV, {"--side": "left"})], "refuse",
        "unknown choice")
    add("involute.missing_z1", ["involute", *_argv(INV, {"--z1": None})], "refuse",
        "required flag missing")
    add("involute.missing_module", ["involute", *_argv(INV, {"--module": None})], "refuse",
        "required flag missing")
    add("involute.no_flags", ["involute"], "refuse", "every required flag missing")
    add("involute.flag_without_value", ["involute", "--z1", *_argv(INV[1:])], "refuse",
        "--z1 followed by another flag")
    add("involute.unknown_option", ["involute", *_argv(INV), "--colour", "red"], "refuse",
        "unknown option")
    add("involute.positional", ["involute", *_argv(INV), "extra"], "refuse",
        "stray positional argument")

    # ---------------------------------------------------------------- example
    add("example.list", ["example", "list"], "ok", "list the packaged designs")
    add("example.show", ["example", "show", "hft_8x43"], "ok", "print a design")
    add("example.show_alias", ["example", "show", "seed000_6x39_7p5in"], "ok",
        "former name still accepted")
    add("example.no_action", ["example"], "refuse", "missing action")
    add("example.unknown_action", ["example", "frobnicate"], "refuse", "unknown action")
    add("example.show_missing_name", ["example", "show"], "refuse", "missing name")
    add("example.show_unknown", ["example", "show", "nope_3x7"], "refuse", "unknown example")
    add("example.show_empty", ["example", "show", ""], "refuse", "empty name")
    add("example.show_traversal", ["example", "show", "../cli"], "refuse",
        "path traversal out of the examples")
    add("example.show_suffix", ["example", "show", "hft_8x43.toml"], "refuse",
        "name with its file extension")

    # ---------------------------------------------------------------- design-file troubles
    # (setup, why) of files that are no design at all, shared by blank/surface/kinematics/tca
    broken_files = {
        "missing_file": (None, "design file does not exist"),
        "directory": (a_directory(), "design path is a directory"),
        "empty_file": (raw_file(b""), "empty design file"),
        "binary_file": (raw_file(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\x00\xff\xfe"),
                        "binary file"),
        "non_utf8": (raw_file(b"# r\xe9glage\n[design]\nname = \"x\"\n"), "non-UTF-8 text"),
        "invalid_toml": (raw_file(b"[design\nname = 'x'\n"), "not TOML"),
        "only_design_table": (raw_file(b"[design]\nname = \"x\"\nkind = \"hypoid\"\n"),
                              "a design without blank, summaries or flanks"),
    }
    design_arg = lambda key: "{tmp}/missing.toml" if key == "missing_file" else "{design}"

    # corrupted copies of the packaged examples: id -> (example, edits, why)
    H = "hft_8x43"
    corrupt = {
        "missing_sliding_base": (H, [("pinion.concave.machine.sliding_base", _DELETE)],
                                 "pinion concave sliding_base deleted (the convex flank has one)"),
        "missing_ratio_of_roll": (H, [("pinion.convex.machine.ratio_of_roll", _DELETE)],
                                  "generated pinion without ratio of roll"),
        "missing_blank_offset": (H, [("pinion.concave.machine.blank_offset", _DELETE)],
                                 "hypoid pinion flank without blank offset"),
        "missing_point_radius": (H, [("pinion.convex.cutter.point_radius", _DELETE)],
                                 "cutter without point radius"),
        "missing_summary_face_angle": (H, [("blank_summary.gear.face_angle", _DELETE)],
                                       "gear summary without face angle"),
        "missing_gear_concave": (H, [("gear.concave", _DELETE)], "gear concave flank deleted"),
        "missing_summary_gear": (H, [("blank_summary.gear", _DELETE)],
                                 "[blank_summary.gear] deleted"),
        "teeth_gear_41_vs_blank_43": (H, [("blank_summary.gear.teeth", 41)],
                                      "[blank] z2 = 43 but [blank_summary.gear] teeth = 41"),
        "teeth_pinion_9_vs_blank_8": (H, [("blank_summary.pinion.teeth", 9)],
                                      "[blank] z1 = 8 but [blank_summary.pinion] teeth = 9"),
        "teeth_swapped": (H, [("blank_summary.gear.teeth", 8), ("blank_summary.pinion.teeth", 43)],
                          "pinion and gear tooth numbers swapped"),
        "hand_same_both": (H, [("blank_summary.gear.hand", "left")],
                           "pinion and gear both left hand"),
        "hand_blank_vs_summary": (H, [("blank.hand", "right")],
                                  "[blank] hand right, [blank_summary.pinion] left"),
        "hand_invalid": (H, [("blank_summary.pinion.hand", "up")], "hand 'up'"),
        "unknown_top_table": (H, [("extra.key", 1)], "unknown table [extra]"),
        "unknown_machine_key": (H, [("pinion.convex.machine.sliding_bas", 28.8)],
                                "misspelt machine key"),
        "unknown_blank_key": (H, [("blank.z3", 5)], "unknown key in [blank]"),
        "string_point_radius": (H, [("pinion.convex.cutter.point_radius", "117.475")],
                                "number given as a string"),
        "string_sliding_base": (H, [("pinion.concave.machine.sliding_base", "26.07")],
                                "machine setting given as a string"),
        "bool_blank_offset": (H, [("pinion.concave.machine.blank_offset", True)],
                              "machine setting given as a boolean"),
        "list_sliding_base": (H, [("pinion.concave.machine.sliding_base", [26.0, 1.0])],
                              "machine setting given as an array"),
        "table_ratio_of_roll": (H, [("pinion.convex.machine.ratio_of_roll", {"value": 5.36})],
                                "machine setting given as a table"),
        "int_type_machine": (H, [("pinion.convex.machine.type", 5)], "machine type 5"),
        "unknown_machine_type": (H, [("pinion.convex.machine.type", "hobbed")],
                                 "machine type 'hobbed'"),
        "blank_z1_string": (H, [("blank.z1", "8")], "[blank] z1 as a string"),
        "blank_z1_float": (H, [("blank.z1", 8.5)], "[blank] z1 = 8.5"),
        "blank_z1_zero": (H, [("blank.z1", 0)], "[blank] z1 = 0"),
        "blank_missing_z2": (H, [("blank.z2", _DELETE)], "[blank] without z2"),
        "blank_method_unknown": (H, [("blank.method", "iso99")], "unknown blank method"),
        "blank_shaft_angle_0": (H, [("blank.shaft_angle_deg", 0.0)], "shaft angle 0"),
        "blank_shaft_angle_180": (H, [("blank.shaft_angle_deg", 180.0)], "shaft angle 180"),
        "blank_spiral_angle_90": (H, [("blank.spiral_angle_deg", 90.0)], "spiral angle 90"),
        "blank_cutter_radius_neg": (H, [("blank.cutter_radius_mm", -114.3)],
                                    "negative cutter radius"),
        "blank_diameter_1e300": (H, [("blank.gear_outer_pitch_diameter_mm", 1e300)],
                                 "gear diameter 1e300 mm"),
        "blank_offset_huge": (H, [("blank.offset_mm", 1e6)], "offset far beyond the gear"),
        "blank_offset_nan": (H, [("blank.offset_mm", float("nan"))], "NaN offset"),
        "blank_pressure_angle_0": (H, [("blank.pressure_angle_drive_deg", 0.0)],
                                   "drive pressure angle 0"),
        "design_kind_worm": (H, [("design.kind", "worm")], "design kind 'worm'"),
        "nan_ratio_of_roll": (H, [("pinion.convex.machine.ratio_of_roll", float("nan"))],
                              "NaN ratio of roll"),
        "nan_sliding_base": (H, [("pinion.concave.machine.sliding_base", float("nan"))],
                             "NaN sliding base"),
        "inf_blade_angle": (H, [("pinion.concave.cutter.blade_angle", float("inf"))],
                            "infinite blade angle"),
        "nan_radial_distance": (H, [("gear.convex.machine.radial_distance", float("nan"))],
                                "NaN gear radial distance"),
        "nan_summary_face_width": (H, [("blank_summary.gear.face_width", float("nan"))],
                                   "NaN face width"),
        "nan_machine_root_angle": (H, [("pinion.convex.machine.machine_root_angle",
                                        float("nan"))], "NaN machine root angle"),
        "neg_point_radius": (H, [("pinion.convex.cutter.point_radius", -117.475)],
                             "negative cutter radius"),
        "neg_edge_radius": (H, [("pinion.convex.cutter.edge_radius", -1.0)],
                            "negative edge radius"),
        "blade_angle_95": (H, [("pinion.convex.cutter.blade_angle", 95.0)], "blade angle 95"),
        "eccentric_zero": (H, [("pinion.convex.machine.no116.eccentric", 0.0)],
                           "No. 116 eccentric 0"),
        "tilt_200": (H, [("pinion.convex.machine.no116.tilt", 200.0)], "No. 116 tilt 200"),
        "ratio_of_roll_zero": (H, [("pinion.convex.machine.ratio_of_roll", 0.0)],
                               "generated flank with ratio of roll 0"),
        "ratio_of_roll_huge": (H, [("pinion.convex.machine.ratio_of_roll", 1e300)],
                               "ratio of roll 1e300"),
        "summary_face_width_0": (H, [("blank_summary.pinion.face_width", 0.0)], "face width 0"),
        "summary_face_width_huge": (H, [("blank_summary.pinion.face_width", 1e300)],
                                    "face width 1e300"),
        "summary_pitch_angle_95": (H, [("blank_summary.pinion.pitch_angle", 95.0)],
                                   "pitch angle 95"),
        "summary_root_above_face": (H, [("blank_summary.pinion.root_angle", 20.0)],
                                    "root angle above pitch and face angle"),
        "summary_teeth_float": (H, [("blank_summary.gear.teeth", 43.5)], "43.5 teeth"),
        "mean_cone_inconsistent": (H, [("blank_summary.gear.mean_cone_distance", 100.0)],
                                   "mean cone distance not A_o - F/2"),
        "no116_and_geometric": (H, [("pinion.convex.machine.radial_distance", 120.0)],
                                "dials and geometric settings both given"),
        "formate_with_no116": (H, [("gear.convex.machine.no116",
                                    {"cradle": 1.0, "eccentric": 1.0, "swivel": 1.0,
                                     "tilt": 1.0})], "No. 116 dials on a formate gear"),
        "no_blank_table": (H, [("blank", _DELETE)], "no [blank] table"),
    }

    def corrupt_case(cmd, key, extra, expect="refuse", heavy=False, also=()):
        ex, edits, why = corrupt[key]
        add(f"{cmd}.design.{key}", [cmd, "{design}", *extra], expect, why,
            setup=design_file(ex, *edits), heavy=heavy, also=also)

    # ---------------------------------------------------------------- blank
    for name in EXAMPLES:
        if _is_bevel(name):
            add(f"blank.example.{name}", ["blank", f"example:{name}", "--json"], "ok",
                "packaged example")
        else:
            add(f"blank.example.{name}", ["blank", f"example:{name}", "--json"], "refuse",
                "packaged example of another kind: the blank is for hypoid and "
                "spiral-bevel designs")
    add("blank.example_table", ["blank", "example:hft_8x43"], "flag",
        "table output; the seed formula's cutter tilt has no solution for the 8/43 set "
        "('none' and a warning)")
    add("blank.unknown_example", ["blank", "example:nope_3x7"], "refuse", "unknown example")
    add("blank.empty_example", ["blank", "example:"], "refuse", "empty example name")
    add("blank.missing_design_arg", ["blank"], "refuse", "DESIGN missing")
    for key, (setup, why) in broken_files.items():
        add(f"blank.file.{key}", ["blank", design_arg(key), "--json"], "refuse", why,
            setup=setup)
    for key in ("missing_sliding_base", "teeth_gear_41_vs_blank_43", "teeth_pinion_9_vs_blank_8",
                "hand_same_both", "hand_blank_vs_summary", "unknown_top_table",
                "unknown_blank_key", "blank_z1_string", "blank_z1_float", "blank_z1_zero",
                "blank_missing_z2", "blank_method_unknown", "blank_shaft_angle_0",
                "blank_shaft_angle_180", "blank_spiral_angle_90", "blank_cutter_radius_neg",
                "blank_diameter_1e300", "blank_offset_huge", "blank_offset_nan",
                "blank_pressure_angle_0", "design_kind_worm", "no_blank_table",
                "list_sliding_base"):
        corrupt_case("blank", key, ["--json"])

    # ---------------------------------------------------------------- surface
    def srf(member="pinion", flank="convex", grid="11x7", out="{tmp}/flank.csv", extra=()):
        a = ["surface", "example:hft_8x43"]
        for f, v in (("--member", member), ("--flank", flank), ("--grid", grid), ("--out", out)):
            if v is not None:
                a += [f, v]
        return a + list(extra)

    add("surface.ok.csv", srf(), "ok", "flank grid to CSV")
    add("surface.ok.stl_tooth", srf(member="gear", out="{tmp}/tooth.stl", extra=["--tooth"]),
        "ok", "closed gear tooth to STL")
    add("surface.ok.xyz_plot", srf(flank="concave", out="{tmp}/f.xyz",
                                   extra=["--plot", "{tmp}/f.png"]), "ok", "XYZ and a plot")
    for g in ("0x5", "1x5", "5x", "axb", "3000x3", "-5x5", "5.5x5", "41x21x3", ""):
        add(f"surface.grid={_slug(g)}", srf(grid=g), "refuse", f"--grid {g!r}")
    add("surface.out.missing_dir", srf(out="{tmp}/no/such/dir/f.csv"), "refuse",
        "--out in a missing directory")
    add("surface.out.readonly_dir", srf(out="{ro}/f.csv"), "refuse",
        "--out in a read-only directory", setup=readonly_dir)
    add("surface.out.is_directory", srf(out="{dir}"), "refuse", "--out names a directory",
        setup=a_directory("out.csv"))
    add("surface.out.parent_is_file", srf(out="{file}/f.csv"), "refuse",
        "--out below a regular file", setup=plain_file())
    add("surface.out.bad_extension", srf(out="{tmp}/f.txt"), "refuse", "--out .txt")
    add("surface.out.no_extension", srf(out="{tmp}/flank"), "refuse", "--out without extension")
    add("surface.out.tooth_csv", srf(extra=["--tooth"]), "refuse", "--tooth with a CSV file")
    add("surface.plot.bad_extension", srf(extra=["--plot", "{tmp}/f.jpg2"]), "refuse",
        "--plot with an unsupported extension")
    add("surface.plot.missing_dir", srf(extra=["--plot", "{tmp}/no/dir/f.png"]), "refuse",
        "--plot in a missing directory")
    add("surface.plot.readonly_dir", srf(extra=["--plot", "{ro}/f.png"]), "refuse",
        "--plot in a read-only directory", setup=readonly_dir)
    add("surface.plot.is_directory", srf(extra=["--plot", "{dir}"]), "refuse",
        "--plot names a directory", setup=a_directory("p.png"))
    add("surface.member=wheel", srf(member="wheel"), "refuse", "unknown member")
    add("surface.flank=inner", srf(flank="inner"), "refuse", "unknown flank")
    add("surface.missing_member", srf(member=None), "refuse", "--member missing")
    add("surface.missing_out", srf(out=None), "refuse", "--out missing")
    add("surface.unknown_example", ["surface", "example:nope", "--member", "pinion", "--flank",
                                    "convex", "--out", "{tmp}/f.csv"], "refuse",
        "unknown example")
    for key in ("empty_file", "binary_file", "directory"):
        setup, why = broken_files[key]
        add(f"surface.file.{key}", ["surface", "{design}", "--member", "pinion", "--flank",
                                    "convex", "--grid", "11x7", "--out", "{tmp}/f.csv"],
            "refuse", why, setup=setup)
    surface_corrupt = {  # key -> member, flank the corruption affects
        "missing_sliding_base": ("pinion", "concave"),
        "missing_ratio_of_roll": ("pinion", "convex"),
        "missing_blank_offset": ("pinion", "concave"),
        "missing_point_radius": ("pinion", "convex"),
        "missing_summary_face_angle": ("gear", "convex"),
        "missing_gear_concave": ("gear", "concave"),
        "missing_summary_gear": ("gear", "convex"),
        "hand_invalid": ("pinion", "convex"),
        "unknown_machine_key": ("pinion", "convex"),
        "string_point_radius": ("pinion", "convex"),
        "string_sliding_base": ("pinion", "concave"),
        "bool_blank_offset": ("pinion", "concave"),
        "table_ratio_of_roll": ("pinion", "convex"),
        "int_type_machine": ("pinion", "convex"),
        "unknown_machine_type": ("pinion", "convex"),
        "nan_ratio_of_roll": ("pinion", "convex"),
        "nan_summary_face_width": ("gear", "convex"),
        "nan_machine_root_angle": ("pinion", "convex"),
        "neg_point_radius": ("pinion", "convex"),
        "neg_edge_radius": ("pinion", "convex"),
        "blade_angle_95": ("pinion", "convex"),
        "eccentric_zero": ("pinion", "convex"),
        "tilt_200": ("pinion", "convex"),
        "ratio_of_roll_zero": ("pinion", "convex"),
        "ratio_of_roll_huge": ("pinion", "convex"),
        "summary_face_width_0": ("pinion", "convex"),
        "summary_face_width_huge": ("pinion", "convex"),
        "summary_pitch_angle_95": ("pinion", "convex"),
        "summary_root_above_face": ("pinion", "convex"),
        "summary_teeth_float": ("gear", "convex"),
        "mean_cone_inconsistent": ("gear", "convex"),
        "no116_and_geometric": ("pinion", "convex"),
        "formate_with_no116": ("gear", "convex"),
        "teeth_swapped": ("gear", "convex"),
    }
    for key, (member, flank) in surface_corrupt.items():
        corrupt_case("surface", key, ["--member", member, "--flank", flank, "--grid", "11x7",
                                      "--out", "{tmp}/f.csv"])

    # ---------------------------------------------------------------- correct
    SBX = "example:spiral_bevel_10x30_synthesised"

    def cor(measured="{measured}", out="{tmp}/corrected.toml", design=SBX, extra=()):
        a = ["correct", design]
        for f, v in (("--measured", measured), ("--out", out)):
            if v is not None:
                a += [f, v]
        return a + list(extra)

    sample = measured_file()
    add("correct.ok.default", cor(), "ok", "the packaged sample measurement, default settings",
        setup=sample)
    add("correct.ok.json_plot", cor(extra=["--json", "--plot", "{tmp}/d.png"]),
        "ok", "JSON report and deviation maps", setup=sample)
    add("correct.ok.settings", cor(extra=["--settings", "point_radius,blade_angle,ratio_of_roll"]),
        "ok", "a chosen set of settings", setup=sample)
    add("correct.settings.ill_conditioned", cor(extra=["--settings",
                                                       "point_radius,sliding_base"]),
        "flag", "point radius and sliding base act alike: a warning line names them",
        setup=sample)
    add("correct.settings.with_rotation",
        cor(extra=["--settings", "point_radius,blade_angle,ratio_of_roll,axis_rotation"]),
        "flag", "the measurement's rotation ~ equal point radius changes: warned",
        setup=sample, also={"ok"})
    for key, v in (("unknown", "frobnicate"), ("empty", ""), ("comma", ","),
                   ("twice", "point_radius,point_radius"),
                   ("empty_item", "point_radius,,blade_angle"), ("capitals", "Point_Radius")):
        add(f"correct.settings.{key}", cor(extra=["--settings", v]), "refuse",
            f"--settings {v!r}", setup=sample)
    for v in ("nan", "-1", "2", "inf", "abc"):
        add(f"correct.regularisation={_slug(v)}", cor(extra=["--regularisation", v]), "refuse",
            f"--regularisation {v}", setup=sample)
    for v in ("0", "-3", "1e9", "2.5", "abc"):
        add(f"correct.max-iter={_slug(v)}", cor(extra=["--max-iter", v]), "refuse",
            f"--max-iter {v}", setup=sample)
    add("correct.max-iter=1", cor(extra=["--max-iter", "1"]), "flag",
        "one step: not converged (exit 3, one line) or converged", setup=sample, also={"ok"})
    bad_measured = {
        "nan": (_column_edit(5, 11, lambda v: "nan"), "a deviation NaN"),
        "inf": (_column_edit(9, 11, lambda v: "inf"), "a deviation inf"),
        "empty_deviation": (_column_edit(9, 11, lambda v: ""), "a deviation left empty"),
        "text_deviation": (_column_edit(9, 11, lambda v: "12um"), "a deviation with a unit"),
        "missing_point": (_rows_edit(lambda r: r[:17] + r[18:]), "a grid point missing"),
        "duplicate_point": (_rows_edit(lambda r: r + r[:1]), "a grid point twice"),
        "in_mm": (_all_deviations(lambda v: f"{float(v) / 1000.0:.8f}"),
                  "deviations in mm instead of um"),
        "huge": (_column_edit(3, 11, lambda v: "2500"), "a deviation of 2.5 mm"),
        "wrong_grid": (lambda ls: [ln.replace("grid = 9x5", "grid = 7x5") for ln in ls],
                       "header grid 7x5, rows of a 9x5 grid"),
        "off_grid": (_column_edit(7, 5, lambda v: f"{float(v) + 0.05:.10f}"),
                     "a point 0.05 mm off the design's grid"),
        "other_member": (lambda ls: [ln.replace("member = pinion", "member = gear")
                                     for ln in ls], "the pinion's grid declared as the gear's"),
        "no_member": (lambda ls: [ln for ln in ls if not ln.startswith("# member")],
                      "header without member"),
        "bad_margin": (lambda ls: [ln.replace("face_margin = 0.1", "face_margin = 0.7")
                                   for ln in ls], "face margin 0.7"),
        "missing_column": (lambda ls: [",".join(ln.split(",")[:-1]) if not ln.startswith("#")
                                       else ln for ln in ls], "no deviation column"),
        "bad_flank": (_column_edit(0, 0, lambda v: "left"), "flank 'left'"),
        "unnormalised": (_column_edit(4, 8, lambda v: "0.9"), "a normal that is not unit"),
        "header_only": (lambda ls: [ln for ln in ls if ln.startswith("#")
                                    or ln.startswith("flank,")], "no data rows"),
    }
    for key, (edit, why) in bad_measured.items():
        add(f"correct.measured.{key}", cor(), "refuse", why, setup=measured_file(edit))
    add("correct.measured.missing_file", cor(measured="{tmp}/none.csv"), "refuse",
        "--measured does not exist")
    add("correct.measured.directory", cor(measured="{dir}"), "refuse",
        "--measured is a directory", setup=a_directory("m.csv"))
    add("correct.measured.binary", cor(measured="{design}"), "refuse", "--measured binary",
        setup=raw_file(b"\x89PNG\r\n\x1a\n\x00\xff\xfe", name="m.csv"))
    add("correct.measured.empty", cor(measured="{design}"), "refuse", "--measured empty",
        setup=raw_file(b"", name="m.csv"))
    add("correct.missing_measured", cor(measured=None), "refuse", "--measured missing")
    add("correct.missing_out", cor(out=None), "refuse", "--out missing", setup=sample)
    add("correct.out.bad_extension", cor(out="{tmp}/c.txt"), "refuse", "--out .txt",
        setup=sample)
    add("correct.out.missing_dir", cor(out="{tmp}/no/dir/c.toml"), "refuse",
        "--out in a missing directory", setup=sample)
    add("correct.out.same_as_plot", cor(out="{tmp}/c.png", extra=["--plot", "{tmp}/c.png"]),
        "refuse", "--out and --plot the same file (and --out not .toml)", setup=sample)
    add("correct.plot.bad_extension", cor(extra=["--plot", "{tmp}/d.jpg2"]), "refuse",
        "--plot .jpg2", setup=sample)
    add("correct.example.involute", cor(design="example:khk_spur_12x24"), "refuse",
        "a family without machine settings", setup=sample)
    add("correct.example.other_hypoid", cor(design="example:hft_8x43"), "refuse",
        "another design's grid", setup=sample)
    add("correct.example.unknown", cor(design="example:nope"), "refuse",
        "unknown example", setup=sample)
    add("correct.formate_roll", cor(design="example:hypoid_iso_10x41_synthesised", extra=[
        "--settings", "ratio_of_roll"]), "refuse", "roll setting of a formate gear",
        setup=measured_file(lambda ls: [ln.replace("member = pinion", "member = gear")
                                        for ln in ls]))
    # ---------------------------------------------------------------- ease-off
    HYX = "example:hypoid_iso_10x41_synthesised"

    def eo(design=HYX, out="{tmp}/eased.toml", extra=()):
        return ["ease-off", design] + (["--out", out] if out is not None else []) + list(extra)

    add("ease-off.ok.crowning_bias", eo(extra=["--crowning-um", "30", "--bias-um", "10",
                                              "--plot", "{tmp}/e.png"]),
        "flag", "a reachable target: written, TCA before/after; the conjugate's rotation ~ "
        "point radius and the written pair's tip contact are warned", also={"ok"})
    add("ease-off.ok.json_no_tca", eo(extra=["--crowning-um", "30", "--bias-um", "10",
                                            "--json", "--no-tca", "--settings",
                                            "blade_angle,ratio_of_roll,modified_roll_2c,"
                                            "modified_roll_6d,axis_rotation"]),
        "ok", "strict JSON (lines left out are null), no TCA, settings told apart")
    add("ease-off.profile_out_of_reach", eo(extra=["--crowning-um", "30", "--profile-um", "15",
                                                  "--bias-um", "10"]),
        "flag", "profile crowning out of the straight blade's reach: the written pair's "
        "TCA is flagged (large TE) or fails (exit 3)")
    for flag, v in (("--crowning-um", "nan"), ("--profile-um", "1e6"), ("--bias-um", "-inf"),
                    ("--crowning-um", "abc"), ("--grid", "2x5"), ("--grid", "9x5x3"),
                    ("--grid", "100x5"), ("--regularisation", "-1"), ("--max-iter", "0"),
                    ("--settings", "frobnicate"), ("--settings", ","), ("--side", "both")):
        add(f"ease-off.{flag[2:]}={_slug(v)}", eo(extra=[flag, v]), "refuse", f"{flag} {v}")
    for key, content in (("empty", b""), ("binary", b"\x89PNG\r\n\x1a\n\x00\xff"),
                         ("short_rows", b"1,2,3\n" * 9),
                         ("text", b"a,b,c,d,e\n" * 9),
                         ("nan", b"0,0,0,0,0\n" * 4 + b"0,0,nan,0,0\n" + b"0,0,0,0,0\n" * 4),
                         ("huge", b"0,0,0,0,0\n" * 4 + b"0,0,5000,0,0\n" + b"0,0,0,0,0\n" * 4)):
        add(f"ease-off.target.{key}", eo(extra=["--target", "{design}"]), "refuse",
            f"--target file: {key}", setup=raw_file(content, name="t.csv"))
    add("ease-off.target.with_terms", eo(extra=["--target", "{design}", "--bias-um", "3"]),
        "refuse", "--target together with a term", setup=raw_file(b"0,0,0,0,0\n" * 9, "t.csv"))
    add("ease-off.target.missing", eo(extra=["--target", "{tmp}/none.csv"]), "refuse",
        "--target does not exist")
    add("ease-off.missing_out", eo(out=None), "refuse", "--out missing")
    add("ease-off.out.bad_extension", eo(out="{tmp}/e.txt"), "refuse", "--out .txt")
    add("ease-off.plot.bad_extension", eo(extra=["--plot", "{tmp}/e.toml"]), "refuse",
        "--plot .toml")
    add("ease-off.example.involute", eo(design="example:khk_spur_12x24"), "refuse",
        "a family without machine settings")
    add("ease-off.example.vh_catt", eo(design="example:vh_catt_17x23",
                                       extra=["--crowning-um", "10"]), "flag",
        "VH-CATT: a crowning target met by the pinion's trace radius (written, TCA "
        "before/after); cutter radius and blade offset warned as indistinguishable",
        also={"ok"})
    add("ease-off.example.hft_not_converged", eo(design="example:hft_8x43"), "flag",
        "the dial-set pair's conjugate is far from its pinion: the fit stops at its step "
        "limit (exit 3, no design) and the given pair's TCA warnings are shown")
    # reference grids of gearjax surface
    add("surface.ok.reference_grid", ["surface", SBX, "--member", "gear", "--reference-grid",
                                      "--out", "{tmp}/grid.csv"], "ok", "measuring grid")
    add("surface.reference_grid.stl", ["surface", SBX, "--member", "gear", "--reference-grid",
                                       "--out", "{tmp}/grid.stl"], "refuse",
        "--reference-grid to STL")
    add("surface.reference_grid.margin=0.5", ["surface", SBX, "--member", "gear",
                                              "--reference-grid", "--face-margin", "0.5",
                                              "--out", "{tmp}/grid.csv"], "refuse",
        "--face-margin 0.5")
    add("surface.reference_grid.margin_nan", ["surface", SBX, "--member", "gear",
                                              "--reference-grid", "--height-margin", "nan",
                                              "--out", "{tmp}/grid.csv"], "refuse",
        "--height-margin nan")
    add("surface.reference_grid.margin_without", srf(extra=["--face-margin", "0.1"]), "refuse",
        "--face-margin without --reference-grid")
    add("surface.ok.reference_grid_vh_catt", ["surface", "example:vh_catt_17x23", "--member",
                                              "gear", "--reference-grid", "--out",
                                              "{tmp}/grid.csv"], "ok",
        "the VH-CATT gear's measuring grid (issue #33 item 5)")
    add("surface.reference_grid.involute", ["surface", "example:khk_spur_12x24", "--member",
                                            "gear", "--reference-grid", "--out",
                                            "{tmp}/grid.csv"], "refuse",
        "a family without a measuring grid")
    add("correct.vh_catt.spiral_bevel_measurement", cor(design="example:vh_catt_17x23"),
        "refuse", "the spiral-bevel sample measured against a VH-CATT design", setup=sample)
    add("correct.vh_catt.hypoid_setting", cor(design="example:vh_catt_17x23", extra=[
        "--settings", "ratio_of_roll"]), "refuse", "a hypoid setting for a VH-CATT member",
        setup=sample)
    add("surface.missing_flank", srf(flank=None), "refuse", "--flank missing")

    # ---------------------------------------------------------------- friction
    add("friction.ok.table", ["friction", *_argv(FRI)], "ok", "README example")
    add("friction.ok.json", ["friction", *_argv(FRI), "--json"], "ok", "README example, JSON")
    add("friction.ok.eta0_json", ["friction", *_argv(FRI, {"--oil": None, "--eta0": "0.1"}),
                                  "--json"], "ok", "custom oil")
    fnum = {
        "--load-N": _BAD_POSITIVE,
        "--rx-mm": ("0", "-10", "nan", "inf", "1e300"),
        "--ry-mm": ("0", "nan", "-inf"),
        "--ue": ("0", "-5", "nan", "inf", "1e300", "fast"),
        "--us": ("-1", "nan", "inf", "1e300"),
        "--sigma-um": ("0", "-0.4", "nan", "inf", "1e300"),
        "--asperity-density-per-mm2": ("0", "nan", "-1e4"),
        "--asperity-radius-um": ("0", "inf"),
        "--fc": ("-0.1", "1.5", "nan"),
        "--E-prime-MPa": ("0", "nan", "-1"),
    }
    for flag, values in fnum.items():
        for v in values:
            add(f"friction.{flag[2:]}={_slug(v)}", ["friction", *_argv(FRI, {flag: v}), "--json"],
                "refuse", f"{flag} {v}")
    for flag, values in {"--eta0": ("0", "1e-5", "nan", "inf", "-1"),
                         "--alpha-per-GPa": ("0", "nan", "-20"),
                         "--tau0-MPa": ("0", "nan")}.items():
        for v in values:
            over = {"--oil": None, "--eta0": "0.1", flag: v}
            add(f"friction.{flag[2:]}={_slug(v)}", ["friction", *_argv(FRI, over), "--json"],
                "refuse", f"{flag} {v} (custom oil)")
    add("friction.load-N=1e-300", ["friction", *_argv(FRI, {"--load-N": "1e-300"}), "--json"],
        "refuse", "tiny load: refuse, or a finite valid result", also={"ok"})
    add("friction.ue=1e-300", ["friction", *_argv(FRI, {"--ue": "1e-300"}), "--json"],
        "refuse", "tiny entrainment speed: refuse, or a finite valid result", also={"ok"})
    add("friction.oil=olive", ["friction", *_argv(FRI, {"--oil": "olive"})], "refuse",
        "unknown oil")
    add("friction.oil_and_eta0", ["friction", *_argv(FRI, {"--eta0": "0.1"})], "refuse",
        "--oil and --eta0 together")
    add("friction.no_oil", ["friction", *_argv(FRI, {"--oil": None})], "refuse",
        "neither --oil nor --eta0")
    add("friction.film=ellipse", ["friction", *_argv(FRI, {"--film": "ellipse"})], "refuse",
        "unknown film formula")
    add("friction.viscosity=newton", ["friction", *_argv(FRI, {"--viscosity": "newton"})],
        "refuse", "unknown viscosity model")
    add("friction.missing_load", ["friction", *_argv(FRI, {"--load-N": None})], "refuse",
        "required flag missing")

    # ---------------------------------------------------------------- stribeck
    add("stribeck.ok.table", ["stribeck", *_argv(STR)], "ok", "default sweep")
    add("stribeck.ok.json", ["stribeck", *_argv(STR), "--json"], "ok", "default sweep, JSON")
    add("stribeck.ok.plot", ["stribeck", *_argv(STR), "--plot", "{tmp}/s.png"], "ok",
        "with a plot")
    snum = {
        "--srr": ("-0.1", "2.5", "nan", "inf"),
        "--ue-min": ("0", "-1", "nan"),
        "--ue-max": ("0.001", "inf", "1e300", "nan"),
        "--points": ("0", "1", "2.5", "1e6", "nan"),
        "--load-N": ("0", "nan"),
        "--sigma-um": ("inf",),
    }
    for flag, values in snum.items():
        for v in values:
            add(f"stribeck.{flag[2:]}={_slug(v)}", ["stribeck", *_argv(STR, {flag: v}), "--json"],
                "refuse", f"{flag} {v}")
    add("stribeck.plot.missing_dir", ["stribeck", *_argv(STR), "--plot", "{tmp}/no/dir/s.png"],
        "refuse", "--plot in a missing directory")
    add("stribeck.plot.readonly_dir", ["stribeck", *_argv(STR), "--plot", "{ro}/s.png"],
        "refuse", "--plot in a read-only directory", setup=readonly_dir)
    add("stribeck.plot.is_directory", ["stribeck", *_argv(STR), "--plot", "{dir}"], "refuse",
        "--plot names a directory", setup=a_directory("s.png"))
    add("stribeck.plot.bad_extension", ["stribeck", *_argv(STR), "--plot", "{tmp}/s.txt2"],
        "refuse", "--plot with an unsupported extension")

    # ---------------------------------------------------------------- kinematics
    K = "example:hypoid_6x39_7p5in"
    add("kinematics.ok.json", ["kinematics", K, "--json"], "ok", "README example")
    add("kinematics.ok.hft_table", ["kinematics", "example:hft_8x43", "--grid", "11x7"], "ok",
        "another hypoid, small grid")
    add("kinematics.spiral_bevel", ["kinematics", "example:spiral_bevel_10x30"], "refuse",
        "the model needs an offset (hypoid) pair")
    for g in ("0x5", "2x5", "202x5", "5x", "axb"):
        add(f"kinematics.grid={_slug(g)}", ["kinematics", K, "--grid", g], "refuse",
            f"--grid {g!r}")
    add("kinematics.flank=inner", ["kinematics", K, "--flank", "inner"], "refuse",
        "unknown flank")
    for v in ("nan", "inf", "90", "-90", "1e300"):
        add(f"kinematics.blade-angle-delta={_slug(v)}",
            ["kinematics", K, "--blade-angle-delta", v, "--json"], "refuse",
            f"blade angle change {v} deg")
    for v in ("nan", "inf", "1e300", "-1e6"):
        add(f"kinematics.cutter-shift={_slug(v)}", ["kinematics", K, "--cutter-shift", v,
                                                    "--json"], "refuse",
            f"cutter shift {v} mm")
    add("kinematics.plot.pdf", ["kinematics", K, "--plot", "{tmp}/k.pdf"], "refuse",
        "--plot extension not .png")
    add("kinematics.plot.missing_dir", ["kinematics", K, "--plot", "{tmp}/no/dir/k.png"],
        "refuse", "--plot in a missing directory")
    add("kinematics.plot.readonly_dir", ["kinematics", K, "--plot", "{ro}/k.png"], "refuse",
        "--plot in a read-only directory", setup=readonly_dir)
    add("kinematics.plot.is_directory", ["kinematics", K, "--plot", "{dir}"], "refuse",
        "--plot names a directory", setup=a_directory("k.png"))
    for key in ("non_utf8", "missing_file"):
        setup, why = broken_files[key]
        add(f"kinematics.file.{key}", ["kinematics", design_arg(key)], "refuse", why,
            setup=setup)
    for key in ("no_blank_table", "blank_offset_nan", "blank_cutter_radius_neg",
                "blank_offset_huge"):
        corrupt_case("kinematics", key, ["--json"])

    # ---------------------------------------------------------------- tca
    def tca_inv(spec=TCA_INV, *extra, expect="refuse", why="", also=(), heavy=False, id=None):
        add(id or f"tca.inv.{_slug(spec[len('involute:'):])}", ["tca", spec, *extra],
            expect, why, also=also, heavy=heavy)

    tca_inv(TCA_INV, "--json", expect="ok", why="README involute pair", id="tca.ok.involute_json")
    tca_inv(TCA_INV + ",helix=15,crown=0.0005", "--side", "both", "--kinematics", "--json",
            expect="flag", why="profile-crowned helical pair (no lead crown), both sides, "
            "kinematics: its bearing reaches the face ends (edge contact)",
            id="tca.ok.involute_both_kin")
    tca_inv(TCA_INV + ",helix=15,crown=0.0005,lead_crown=0.0005", "--side", "both",
            "--kinematics", "--json", expect="ok",
            why="profile- and lead-crowned helical pair, both sides, kinematics",
            id="tca.ok.involute_crowned_both_kin")
    tca_inv(TCA_INV, "--plot", "{tmp}/t.png", expect="ok", why="table and plot",
            id="tca.ok.involute_plot")
    for spec, why in (
            ("involute:z1=..", "malformed value"), ("involute:", "empty spec"),
            ("involute:z1=20", "missing keys"),
            (TCA_INV + ",q=1", "unknown key"), (TCA_INV + ",z1=21", "duplicate key"),
            ("involute:z1=abc,z2=40,m=4,alpha=20,b=30", "letters"),
            ("involute:z1=20.5,z2=40,m=4,alpha=20,b=30", "fractional teeth"),
            ("involute:z1=nan,z2=40,m=4,alpha=20,b=30", "NaN teeth"),
            ("involute:z1=20,z2=40,m=inf,alpha=20,b=30", "infinite module"),
            ("involute:z1=20,z2=40,m=0,alpha=20,b=30", "zero module"),
            ("involute:z1=20,z2=40,m=4,alpha=0,b=30", "zero pressure angle"),
            ("involute:z1=20,z2=40,m=4,alpha=20,b=0", "zero face width"),
            ("involute:z1=20,z2=40,m=4,alpha=20,b=-30", "negative face width"),
            ("involute:z1=20,z2=40,m=4,alpha=20,b=nan", "NaN face width"),
            ("involute:z1=20,z2=40,m=4,alpha=20,b=1e300", "face width 1e300"),
            (TCA_INV + ",crown=-1", "negative crowning"), (TCA_INV + ",crown=nan", "NaN crown"),
            (TCA_INV + ",lead_crown=inf", "infinite lead crown"),
            (TCA_INV + ",helix=nan", "NaN helix"), (TCA_INV + ",dalpha=nan", "NaN dalpha"),
            (TCA_INV + ",dalpha=90", "pressure angle change 90 deg"),
            (TCA_INV + ",x1=nan", "NaN profile shift"),
            ("involute:z1=3,z2=40,m=4,alpha=20,b=30", "3 teeth")):
        tca_inv(spec, "--json", why=why)
    tca_inv("involute:z1=20;z2=40;m=4;alpha=20;b=30", "--json", why="semicolons",
            id="tca.inv.semicolons")
    tca_inv("involute:z1 20,z2 40,m 4,alpha 20,b 30", "--json", why="no '='",
            id="tca.inv.no_equals")
    tca_inv("involute-z1=20", why="unknown design form (no such file)",
            id="tca.design.not_a_spec")
    for v in ("dE=abc", "dE", "dX=1", "dE=nan", "dSigma=inf", "dE=1e300", "dSigma=90",
              "dE=0.05;dP=0", "dE=0.05,,dP=", "dE=0.05,dE=0.1"):
        add(f"tca.misalign={_slug(v)}", ["tca", TCA_INV, "--misalign", v, "--json"], "refuse",
            f"--misalign {v!r}")
    for v in ("2", "0", "-61", "60", "61.5", "nan", "inf", "1e300", "2001", "abc"):
        add(f"tca.positions={_slug(v)}", ["tca", TCA_INV, "--positions", v, "--json"], "refuse",
            f"--positions {v}")
    for v in ("0", "0.5", "5", "nan", "inf", "-1"):
        add(f"tca.pitches={_slug(v)}", ["tca", TCA_INV, "--pitches", v, "--json"], "refuse",
            f"--pitches {v}")
    add("tca.side=left", ["tca", TCA_INV, "--side", "left"], "refuse", "unknown side")
    add("tca.missing_design", ["tca", "--json"], "refuse", "DESIGN missing")
    add("tca.plot.missing_dir", ["tca", TCA_INV, "--plot", "{tmp}/no/dir/t.png"], "refuse",
        "--plot in a missing directory (must be refused before the solve)")
    add("tca.plot.readonly_dir", ["tca", TCA_INV, "--plot", "{ro}/t.png"], "refuse",
        "--plot in a read-only directory", setup=readonly_dir)
    add("tca.plot.is_directory", ["tca", TCA_INV, "--plot", "{dir}"], "refuse",
        "--plot names a directory", setup=a_directory("t.png"))
    add("tca.plot.bad_extension", ["tca", TCA_INV, "--plot", "{tmp}/t.txt2"], "refuse",
        "--plot with an unsupported extension")
    # physically poor: must be flagged
    add("tca.poor.uncrowned_dSigma", ["tca", TCA_INV + ",crown=0", "--misalign", "dSigma=0.05",
                                      "--json"], "flag",
        "misaligned uncrowned involute pair: edge contact")
    add("tca.poor.uncrowned_dSigma_table", ["tca", TCA_INV + ",crown=0", "--misalign",
                                            "dSigma=0.2"], "flag",
        "misaligned uncrowned involute pair (table output): edge contact")
    add("tca.poor.dalpha_uncrowned", ["tca", TCA_INV + ",dalpha=1", "--json"], "flag",
        "pressure-angle mismatch without crowning: premature contact at the gear tip "
        "(solved, tip_contact) and a saw-tooth TE")
    add("tca.poor.involute_dE_huge", ["tca", TCA_INV, "--misalign", "dE=100", "--json"], "flag",
        "pinion moved 100 mm: the flanks do not touch")
    add("tca.poor.narrow_face", ["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=0.001", "--json"],
        "flag", "1 um face width: not a gear; refuse or flag", also={"ok"})
    add("tca.poor.hypoid_dE", ["tca", "example:hft_8x43_synthesised", "--pitches", "2",
                               "--misalign", "dE=5", "--json"], "flag",
        "hypoid pinion moved 5 mm: bearing off the flank", heavy=True)
    add("tca.poor.hypoid_dSigma", ["tca", "example:spiral_bevel_10x30_synthesised",
                                   "--misalign", "dSigma=3", "--json"], "flag",
        "shaft angle error 3 deg", heavy=True)
    # packaged examples, default options, both sides: a clean run (a warning or a clean
    # refusal is an honest answer too, and is reported as such)
    for name in EXAMPLES:
        if _has_flanks(name):
            add(f"tca.example.{name}", ["tca", f"example:{name}", "--side", "both", "--json"],
                "ok", "packaged example, default options, both sides", also={"flagged"},
                heavy=True)
        else:
            add(f"tca.example.{name}", ["tca", f"example:{name}", "--side", "both", "--json"],
                "refuse", "packaged example without machine settings (a blank only)")
    add("tca.example.spiral_bevel_kinematics",
        ["tca", "example:spiral_bevel_10x30_synthesised", "--kinematics", "--json"], "flag",
        "packaged example with kinematics; its drive TE parabola opens upwards (pair 0 is "
        "ahead at both ends), so each pair hands over at a flank boundary: edge contact",
        heavy=True)
    add("tca.unknown_example", ["tca", "example:nope_3x7"], "refuse", "unknown example")
    for key in ("missing_file", "directory", "empty_file", "binary_file", "non_utf8",
                "only_design_table"):
        setup, why = broken_files[key]
        add(f"tca.file.{key}", ["tca", design_arg(key), "--json"], "refuse", why, setup=setup)
    for key, side in (("missing_sliding_base", "drive"), ("missing_ratio_of_roll", "coast"),
                      ("teeth_gear_41_vs_blank_43", "drive"), ("teeth_pinion_9_vs_blank_8",
                                                               "drive"),
                      ("hand_same_both", "drive"), ("missing_gear_concave", "both"),
                      ("nan_sliding_base", "drive"), ("inf_blade_angle", "drive"),
                      ("nan_radial_distance", "drive"), ("list_sliding_base", "drive"),
                      ("string_sliding_base", "drive"), ("blank_offset_nan", "drive")):
        corrupt_case("tca", key, ["--side", side, "--json"], heavy=True)

    # ---------------------------------------------------------------- efficiency
    eff = [("--torque-Nm", "200"), ("--rpm", "1500"), ("--oil", "mineral_vg100"),
           ("--sigma-um", "0.4")]
    add("efficiency.ok.spur_json", ["efficiency", TCA_INV, *_argv(eff), "--json"], "ok",
        "README example (spur pair), JSON", heavy=True)
    for flag, values in {"--torque-Nm": ("0", "-200", "nan", "inf", "1e300", "abc"),
                         "--rpm": ("0", "-1500", "nan", "inf", "1e300"),
                         "--sigma-um": ("0", "-0.4", "nan", "1e300"),
                         "--positions": ("0", "2", "1e6", "nan"),
                         "--pairs": ("2", "0", "11")}.items():
        for v in values:
            add(f"efficiency.{flag[2:]}={_slug(v)}",
                ["efficiency", TCA_INV, *_argv(eff, {flag: v}), "--json"], "refuse", f"{flag} {v}")
    add("efficiency.oil=olive", ["efficiency", TCA_INV, *_argv(eff, {"--oil": "olive"})],
        "refuse", "unknown oil")
    add("efficiency.no_torque", ["efficiency", TCA_INV, *_argv(eff, {"--torque-Nm": None})],
        "refuse", "missing --torque-Nm")
    add("efficiency.ok.helical_line_contact",
        ["efficiency", "involute:z1=20,z2=40,m=4,alpha=20,b=30,helix=15", *_argv(eff),
         "--positions", "8", "--slices", "6", "--json"],
        "ok", "unmodified helical pair in line contact: the thin-slice line contact")
    add("efficiency.helical_line_contact.pairs",
        ["efficiency", "involute:z1=20,z2=40,m=4,alpha=20,b=30,helix=15", *_argv(eff),
         "--pairs", "3"], "refuse", "a point-contact grid option in line contact")
    add("efficiency.spur.torque_list",
        ["efficiency", TCA_INV, *_argv(eff, {"--torque-Nm": "100,200"})], "refuse",
        "a torque list for a point-contact pair: one torque")
    add("efficiency.spur.slices", ["efficiency", TCA_INV, *_argv(eff), "--slices", "6"],
        "refuse", "--slices is of the line contact only")
    add("efficiency.plot_dir_missing",
        ["efficiency", TCA_INV, *_argv(eff), "--plot", "{tmp}/no/such/dir/e.png"], "refuse",
        "--plot into a missing directory: refused before any work")
    add("efficiency.compliance=steel", ["efficiency", TCA_INV, *_argv(eff),
                                        "--compliance", "steel"], "refuse",
        "unknown compliance model")

    # ---------------------------------------------------------------- loaded
    ld = ["loaded", "example:helical_microgeometry"]
    small = ["--positions", "8", "--slices", "6"]
    add("loaded.ok.json", [*ld, "--torque-Nm", "50,200", "--misalignment-um", "0,10", *small,
                           "--json"], "ok", "README example (micro-geometry example), JSON",
        heavy=True)
    add("loaded.ok.range_table", [*ld, "--torque-Nm", "50:400:3", *small, "--side", "coast",
                                  "--compliance", "iso6336"], "ok",
        "a torque range, the coast side, the ISO 6336 compliance", heavy=True)
    add("loaded.ok.inline_spur", ["loaded", TCA_INV, "--torque-Nm", "100", *small], "ok",
        "an inline spur pair, unmodified flanks", heavy=True)
    add("loaded.ok.plot", [*ld, "--torque-Nm", "100,200", *small, "--plot", "{tmp}/l.png"],
        "ok", "the modification map and LTE figure", heavy=True)
    for cid, torque, why in (
            ("torque=0", "0", "torque at the lower bound, excluded"),
            ("torque=-100", "-100", "negative torque"),
            ("torque=nan", "nan", "NaN torque"),
            ("torque=inf", "inf", "infinite torque"),
            ("torque=1e300", "1e300", "torque far above the range"),
            ("torque=abc", "abc", "not a number"),
            ("torque=empty_item", "50,,100", "an empty list item"),
            ("torque=empty", "", "no torque"),
            ("torque=twice", "50,50", "a torque twice"),
            ("range=two_parts", "50:100", "a range without COUNT"),
            ("range=four_parts", "50:100:3:1", "a range with four parts"),
            ("range=count_0", "50:100:0", "a range of no torque"),
            ("range=count_float", "50:100:2.5", "a non-integer COUNT"),
            ("range=count_huge", "50:100:100000", "COUNT above the limit"),
            ("range=start_neg", "-50:100:3", "a negative START"),
            ("range=one_unequal", "50:100:1", "COUNT 1 with START != STOP")):
        add(f"loaded.{cid}", [*ld, "--torque-Nm", torque, *small], "refuse", why)
    for cid, mis, why in (("mis=-2000", "-2000", "misalignment beyond the range"),
                          ("mis=nan", "nan", "NaN misalignment"),
                          ("mis=abc", "abc", "not a number"),
                          ("mis=empty", "", "no misalignment")):
        add(f"loaded.{cid}", [*ld, "--torque-Nm", "100", "--misalignment-um", mis, *small],
            "refuse", why)
    for flag, value in (("--positions", "2"), ("--positions", "1e6"), ("--positions", "nan"),
                        ("--slices", "0"), ("--slices", "4.5"), ("--side", "both"),
                        ("--compliance", "steel")):
        add(f"loaded.{flag[2:]}={_slug(value)}",
            [*ld, "--torque-Nm", "100", *_argv([("--positions", "8"), ("--slices", "6")],
                                             {flag: value})], "refuse", f"{flag} {value}")
    add("loaded.no_torque", [*ld], "refuse", "missing --torque-Nm")
    lub = ["--oil", "mineral_vg100", "--sigma-um", "0.4"]
    for cid, extra, why in (
            ("rpm_no_oil", ["--rpm", "1500"], "--rpm without the lubrication"),
            ("rpm_no_sigma", ["--rpm", "1500", "--oil", "mineral_vg100"], "--rpm, no --sigma-um"),
            ("oil_no_rpm", lub, "lubrication without --rpm"),
            ("rpm_negative", ["--rpm", "-1", *lub], "negative speed"),
            ("rpm_nan", ["--rpm", "nan", *lub], "NaN speed"),
            ("rpm_huge", ["--rpm", "1e9", *lub], "speed above the range"),
            ("sigma_huge", ["--rpm", "1500", "--oil", "mineral_vg100", "--sigma-um", "1e4"],
             "roughness in nm typed as um"),
            ("oil_unknown", ["--rpm", "1500", "--oil", "olive", "--sigma-um", "0.4"],
             "unknown oil"),
            ("oil_and_eta0", ["--rpm", "1500", *lub, "--eta0", "0.1"], "two oils")):
        add(f"loaded.{cid}", [*ld, "--torque-Nm", "100", *small, *extra], "refuse", why)
    add("loaded.ok.efficiency", [*ld, "--torque-Nm", "100", *small, "--rpm", "1500", *lub,
                                 "--json"], "ok", "efficiency columns")
    add("loaded.hypoid_design", ["loaded", "example:hft_8x43", "--torque-Nm", "100"], "refuse",
        "not an involute pair")
    add("loaded.inline_crown", ["loaded", TCA_INV + ",crown=0.001", "--torque-Nm", "100"],
        "refuse", "the TCA's rack crown is not a flank modification of the line contact")
    add("loaded.plot_dir_missing", [*ld, "--torque-Nm", "100", "--plot",
                                    "{tmp}/no/such/dir/l.png"], "refuse",
        "--plot into a missing directory: refused before any work")
    mg = "microgeometry.pinion"
    for cid, edits, why in (
            ("unknown_key", ((f"{mg}.tip_relief_mm", 8.0),), "a key of no field"),
            ("string_value", ((f"{mg}.lead_crowning_um", "six"),), "a string amount"),
            ("nan_value", ((f"{mg}.lead_crowning_um", float("nan")),), "a NaN amount"),
            ("amount_too_big", ((f"{mg}.tip_relief_um", 800.0),), "tip relief above 500 um"),
            ("negative_relief", ((f"{mg}.tip_relief_um", -8.0),), "a negative relief"),
            ("bad_shape", ((f"{mg}.tip_relief_shape", "cubic"),), "unknown relief shape"),
            ("relief_without_length", ((f"{mg}.tip_relief_length_mm", _DELETE),),
             "a relief amount without its length"),
            ("relief_zero_length", ((f"{mg}.tip_relief_length_mm", 0.0),),
             "a relief amount over a zero length"),
            ("member_and_flank", (("microgeometry.pinion_drive.bias_um", 2.0),),
             "a member table and its own flank table"),
            ("unknown_table", (("microgeometry.wheel.bias_um", 2.0),), "an unknown sub-table"),
            ("not_a_table", ((f"{mg}", 3.0),), "a number where a table belongs")):
        add(f"loaded.design.{cid}", ["loaded", "{design}", "--torque-Nm", "100", *small],
            "refuse", why, setup=design_file("helical_microgeometry", *edits))
    # tca / efficiency of a design with [microgeometry]: the line contact
    add("tca.ok.microgeometry", ["tca", "example:helical_microgeometry", *small, "--json"],
        "ok", "the line-contact TCA of the modified flanks, JSON")
    add("tca.ok.microgeometry_torques",
        ["tca", "example:helical_microgeometry", *small, "--torque-Nm", "50:200:3",
         "--side", "both", "--plot", "{tmp}/t.png"], "ok",
        "unloaded TCA and loaded TE at a torque range, both sides, table and figure")
    add("tca.ok.microgeometry_unmodified", ["tca", "example:helical_23x67_unmodified",
                                            *small, "--json"], "ok",
        "zero amounts: unloaded TE 0")
    for cid, extra, why in (
            ("misalign", ["--misalign", "dE=0.1"], "point-contact misalignment"),
            ("pitches", ["--pitches", "2"], "point-contact grid"),
            ("kinematics", ["--kinematics"], "point-contact kinematics"),
            ("count0", ["--torque-Nm", "50:200:0"], "a torque range of COUNT 0"),
            ("torque_nan", ["--torque-Nm", "nan"], "a NaN torque"),
            ("torque_big", ["--torque-Nm", "1e9"], "a torque out of range"),
            ("positions", ["--positions", "2"], "too few positions"),
            ("slices", ["--slices", "1e6"], "too many slices"),
            ("misalignment", ["--misalignment-um", "inf"], "an infinite misalignment"),
            ("coupling_negative", ["--coupling-length-mm", "-1"], "a negative coupling length"),
            ("coupling_word", ["--coupling-length-mm", "modulus"], "a coupling length word "
                                                                   "other than 'module'"),
            ("plot_dir", ["--plot", "{tmp}/no/such/dir/t.png"], "a missing plot directory")):
        add(f"tca.microgeometry.{cid}", ["tca", "example:helical_microgeometry", *extra],
            "refuse", why)
    add("tca.inline.torque", ["tca", TCA_INV, "--torque-Nm", "100"], "refuse",
        "--torque-Nm is of the line contact only")
    add("tca.inline.coupling", ["tca", TCA_INV, "--coupling-length-mm", "2"], "refuse",
        "--coupling-length-mm is of the line contact only")
    add("tca.inline.compliance", ["tca", TCA_INV, "--compliance", "iso6336"], "refuse",
        "--compliance is of the line contact's loaded TE only")
    add("tca.microgeometry.compliance=steel", ["tca", "example:helical_microgeometry",
                                               "--compliance", "steel"], "refuse",
        "an unknown compliance model")
    add("tca.microgeometry_coupled",
        ["tca", "example:helical_microgeometry", *small, "--torque-Nm", "200",
         "--coupling-length-mm", "module", "--json"], "flag",
        "the loaded TE with the slices coupled along the face (lambda = m_n): the warning "
        "that p_max and K_Hbeta grow with the slice count")
    add("efficiency.ok.microgeometry",
        ["efficiency", "example:helical_microgeometry", *_argv(eff), *small, "--json"], "ok",
        "the line-contact efficiency of the modified flanks, JSON")
    add("efficiency.ok.microgeometry_range",
        ["efficiency", "example:helical_microgeometry",
         *_argv(eff, {"--torque-Nm": "50:400:4"}), *small, "--plot", "{tmp}/e.png"], "ok",
        "a torque range: a row per torque, and the figure")
    add("efficiency.microgeometry_coupled",
        ["efficiency", "example:helical_microgeometry", *_argv(eff), *small,
         "--coupling-length-mm", "3", "--json"], "flag",
        "the line-contact efficiency with the slices coupled along the face: the warning "
        "that p_max and K_Hbeta grow with the slice count")
    add("efficiency.spur.coupling", ["efficiency", TCA_INV, *_argv(eff),
                                     "--coupling-length-mm", "module"], "refuse",
        "--coupling-length-mm for a pair of the point-contact chain")
    for cid, over, extra, why in (
            ("count0", {"--torque-Nm": "50:200:0"}, [], "a torque range of COUNT 0"),
            ("torque_big", {"--torque-Nm": "1e7"}, [], "a torque out of range"),
            ("torque_twice", {"--torque-Nm": "50,50"}, [], "a torque given twice"),
            ("misalign", {}, ["--misalign", "dE=0.1"], "point-contact misalignment"),
            ("pairs", {}, ["--pairs", "3"], "point-contact pairs"),
            ("E_prime", {}, ["--E-prime-MPa", "2e5"], "the material is the design's"),
            ("ehl_check", {}, ["--ehl-check", "3"], "the point-contact EHL check"),
            ("coupling_nan", {}, ["--coupling-length-mm", "nan"], "a NaN coupling length"),
            ("rpm_missing", {"--rpm": None}, [], "no speed")):
        add(f"efficiency.microgeometry.{cid}",
            ["efficiency", "example:helical_microgeometry", *_argv(eff, over), *extra],
            "refuse", why)

    # ---------------------------------------------------------------- optimize
    add("optimize.ok.list", ["optimize", "--list"], "ok", "packaged studies")
    add("optimize.ok.quantities", ["optimize", "--quantities"], "ok", "the quantity table")
    add("optimize.ok.fields", ["optimize", "example:spur_sliding", "--fields"], "ok",
        "the design fields of a study's design")
    add("optimize.ok.sliding", ["optimize", "example:spur_sliding", "--out", "{tmp}/o",
                                "--no-plot"], "ok", "a packaged study, converged", heavy=True)
    add("optimize.ok.microgeometry", ["optimize", "example:helical_microgeometry_robust",
                                      "--out", "{tmp}/o"], "ok",
        "the packaged line-contact study (micro-geometry), converged, with its figure",
        heavy=True)
    add("optimize.ok.cutter_radius", ["optimize", "example:hypoid_cutter_radius", "--out",
                                      "{tmp}/o", "--no-plot"], "ok",
        "the packaged eigenfunction-kinematics study (seed cutter radius), converged",
        heavy=True)
    add("optimize.no_study", ["optimize"], "refuse", "STUDY missing")
    add("optimize.unknown_example", ["optimize", "example:nope"], "refuse",
        "unknown packaged study")
    add("optimize.missing_file", ["optimize", "{tmp}/no_such_study.toml"], "refuse",
        "study file missing")
    add("optimize.max_iterations=0", ["optimize", "example:spur_sliding",
                                      "--max-iterations", "0"], "refuse", "--max-iterations 0")
    add("optimize.out_is_a_file", ["optimize", "example:spur_sliding", "--out", "{file}"],
        "refuse", "--out names a file", setup=plain_file())
    for cid, old, new, why in (
            ("unknown_quantity", 'quantity = "max_abs_srr"', 'quantity = "max_srr"',
             "unknown quantity"),
            ("empty_bounds", "lower = 0.3\nupper = 0.9", "lower = 0.9\nupper = 0.3",
             "empty bounds"),
            ("unknown_field", 'field = "pair.x1"', 'field = "pair.x9"',
             "a field the design does not have"),
            ("nan_bound", "lower = 0.3", "lower = nan", "NaN bound"),
            ("unknown_key", "[optimizer]", "[optimizer]\nspeed = 3", "unknown key"),
            ("loaded_without_operating", 'quantity = "max_abs_srr"',
             'quantity = "power_loss_W"', "loaded quantity without an operating point")):
        add(f"optimize.study.{cid}", ["optimize", "{study}", "--out", "{tmp}/o"], "refuse", why,
            setup=study_file((old, new)))

    # ---------------------------------------------------------------- sensitivity
    sens = ["sensitivity", "example:khk_spur_12x24"]
    add("sensitivity.ok.json", [*sens, "--outputs", "contact_ratio,mean_abs_srr", "--params",
                                "pair.x1,pair.x2", "--json"], "ok",
        "exact sensitivities of two TCA quantities", heavy=True)
    for cid, outs, params, why in (
            ("unknown_output", "contact_rate", "pair.x1", "unknown quantity"),
            ("unknown_param", "contact_ratio", "pair.x9", "unknown field"),
            ("duplicate_param", "contact_ratio", "pair.x1,pair.x1", "a field twice"),
            ("empty_outputs", ",", "pair.x1", "no output named"),
            ("loaded_without_operating", "power_loss_W", "pair.x1",
             "a loaded quantity without --torque-Nm etc.")):
        add(f"sensitivity.{cid}", [*sens, "--outputs", outs, "--params", params], "refuse", why)
    add("sensitivity.plot_dir_missing", [*sens, "--outputs", "contact_ratio", "--params",
                                         "pair.x1", "--plot", "{tmp}/no/dir/t.png"], "refuse",
        "--plot into a missing directory: refused before any work")
    line = ["sensitivity", "example:helical_microgeometry", "--outputs", "line_te_ptp_um",
            "--params", "microgeometry.pinion.tip_relief_um"]
    add("sensitivity.ok.line", [*line, "--torque-Nm", "300", "--f-ma-um", "5", "--positions",
                                "8", "--slices", "4", "--json"], "ok",
        "a line-contact output w.r.t. a micro-geometry field", heavy=True)
    for cid, extra, why in (
            ("line_without_torque", [], "a line output without --torque-Nm"),
            ("line_with_tca_misalign", ["--torque-Nm", "300", "--misalign", "dE=0.01"],
             "the TCA's misalignment given to a line output"),
            ("line_f_ma_out_of_range", ["--torque-Nm", "300", "--f-ma-um", "5000"],
             "--f-ma-um outside [-1000, 1000] um"),
            ("line_f_ma_nan", ["--torque-Nm", "300", "--f-ma-um", "nan"], "--f-ma-um NaN"),
            ("line_positions=2", ["--torque-Nm", "300", "--positions", "2"],
             "fewer than 4 positions"),
            ("line_slices=1.5", ["--torque-Nm", "300", "--slices", "1.5"],
             "a fractional slice count")):
        add(f"sensitivity.{cid}", [*line, *extra], "refuse", why)
    add("sensitivity.tca_with_f_ma", [*sens, "--outputs", "contact_ratio", "--params",
                                      "pair.x1", "--f-ma-um", "5"], "refuse",
        "a mesh misalignment given to a TCA output")

    # ---------------------------------------------------------------- sweep
    sw = ["sweep", "example:spur_sliding"]
    add("sweep.ok.small", [*sw, "--samples", "3", "--chunk", "2", "--out", "{tmp}/s",
                           "--no-plot"], "ok", "a small random sweep, padded last chunk",
        heavy=True)
    add("sweep.no_study", ["sweep"], "refuse", "STUDY missing")
    add("sweep.unknown_example", ["sweep", "example:nope"], "refuse", "unknown packaged study")
    add("sweep.missing_file", ["sweep", "{tmp}/no_such_study.toml"], "refuse",
        "study file missing")
    for cid, flag, value, why in (
            ("samples=0", "--samples", "0", "no design to sample"),
            ("samples=abc", "--samples", "abc", "not an integer"),
            ("points=1", "--points", "1", "a grid needs two values per variable"),
            ("chunk=0", "--chunk", "0", "an empty batch"),
            ("seed=-1", "--seed", "-1", "a negative seed"),
            ("method=lhs", "--method", "lhs", "unknown method")):
        add(f"sweep.{cid}", [*sw, flag, value], "refuse", why)
    add("sweep.ok.line_study", ["sweep", "example:helical_microgeometry_robust", "--samples",
                                "2", "--out", "{tmp}/s", "--no-plot"], "ok",
        "a line-contact study swept over its micro-geometry fields", heavy=True)
    add("sweep.grid_too_large", [*sw, "--method", "grid", "--points", "1001"], "refuse",
        "a grid of more than 1e6 designs: refused before any compilation")
    add("sweep.out_is_a_file", [*sw, "--out", "{file}"], "refuse", "--out names a file",
        setup=plain_file())
    for cid, old, new, why in (
            ("unknown_method", "[optimizer]", "[sweep]\nmethod = \"lhs\"\n\n[optimizer]",
             "[sweep] method unknown"),
            ("unknown_key", "[optimizer]", "[sweep]\nsize = 3\n\n[optimizer]",
             "[sweep] unknown key")):
        add(f"sweep.study.{cid}", ["sweep", "{study}", "--out", "{tmp}/s"], "refuse", why,
            setup=study_file((old, new)))

    # ---------------------------------------------------------------- warmup
    add("warmup.ok.list", ["warmup", "--list"], "ok", "the jobs listed, nothing run")
    add("warmup.unknown_job", ["warmup", "--jobs", "tca"], "refuse", "unknown job name")
    add("warmup.empty_jobs", ["warmup", "--jobs", ""], "refuse", "no job named")
    add("warmup.ok.one_job", ["warmup", "--jobs", "tca-involute"], "ok",
        "one job: a spur TCA run in the process, its output kept back", heavy=True)
    return cs


CASES = build_cases()


# ======================================================================================
# running and classifying


_NAN_TOKEN = re.compile(r"(?<![A-Za-z0-9_.])[-+]?(nan|inf|infinity)(?![A-Za-z0-9_])", re.I)
_NAN_ONLY = re.compile(r"(?<![A-Za-z0-9_.])[-+]?nan(?![A-Za-z0-9_])|(?<![A-Za-z0-9_.])-inf"
                       r"(?![A-Za-z0-9_])", re.I)
_TCA_NO_VALUE_ROW = re.compile(r"\s(edge|off|no-conv)\s*$")
_TCA_OK_ROW = re.compile(r"\sok\s*$")


class _BareConstant(ValueError):
    pass


def _reject_constant(name):
    raise _BareConstant(name)


def nan_locations(stdout: str, wants_json: bool, limit: int = 5) -> list[str]:
    """Where stdout holds a NaN/inf: JSON key paths (``drive.contact_ratio``) or text
    lines.  Exempt in a ``gearjax tca`` table: rows flagged ``edge``/``no-conv`` (no
    value by design) and ``inf`` on ``ok`` rows (the 2a column of a line contact, an
    infinitely long contact ellipse -- ``null`` in the JSON output)."""
    found: list[str] = []
    if wants_json:
        bad = object()
        try:
            doc = json.loads(stdout, parse_constant=lambda name: bad)
        except ValueError:
            return []

        def walk(x, path):
            if len(found) >= limit:
                return
            if x is bad:
                found.append(path or "(top)")
            elif isinstance(x, dict):
                for k, v in x.items():
                    walk(v, f"{path}.{k}" if path else k)
            elif isinstance(x, list):
                for i, v in enumerate(x):
                    walk(v, f"{path}[{i}]")

        walk(doc, "")
        return found
    for line in stdout.splitlines():
        if _TCA_NO_VALUE_ROW.search(line):
            continue
        pattern = _NAN_ONLY if _TCA_OK_ROW.search(line) else _NAN_TOKEN
        if pattern.search(line):
            found.append(line.strip())
            if len(found) >= limit:
                break
    return found


def _stdout_problem(stdout: str, wants_json: bool) -> str | None:
    """'nan' / 'badjson' / None for the stdout of a run that exited 0."""
    if wants_json:
        try:
            json.loads(stdout, parse_constant=_reject_constant)
        except _BareConstant:
            return "nan"
        except ValueError:
            return "badjson"
        return None
    return "nan" if nan_locations(stdout, False, 1) else None


def _lines(text: str) -> list[str]:
    return [ln for ln in text.splitlines() if ln.strip()]


def classify(rc, stdout: str, stderr: str, wants_json: bool, expect: str) -> str:
    """Observed class of one run (see the module docstring); ``rc`` None = timeout."""
    if rc is None:
        return "timeout"
    if "Traceback (most recent call last)" in stderr:
        return "traceback"
    lines = _lines(stderr)
    warned = any(ln.startswith("gearjax: warning") for ln in lines)
    if rc == 0:
        problem = _stdout_problem(stdout, wants_json)
        if problem:
            return problem
        if warned:
            return "flagged"
        return "ok" if expect == "ok" else "silent"
    errors = [ln for ln in lines if ln.startswith("gearjax: error:")]
    if rc == 2 and len(lines) == 1 and len(errors) == 1:
        return "refusal"
    if len(errors) == 1 and all(ln.startswith("gearjax: ") for ln in lines):
        return "flagged"
    return "unclean"


def key_stderr_line(stderr: str) -> str:
    """The stderr line that tells what happened: the exception line of a traceback,
    else the first ``gearjax:`` line, else the first line."""
    lines = _lines(stderr)
    if not lines:
        return ""
    if "Traceback (most recent call last)" in stderr:
        for ln in reversed(lines):
            if not ln.startswith(" "):
                return ln.strip()
    for ln in lines:
        if ln.startswith("gearjax:"):
            return ln.strip()
    return lines[0].strip()


@dataclass
class Result:
    case: Case
    observed: str
    rc: int | None
    seconds: float
    argv: list = field(default_factory=list)
    stderr: str = ""
    stdout_head: str = ""
    nan_at: list = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return self.observed in self.case.accepted

    def to_dict(self) -> dict:
        lines = _lines(self.stderr)
        return {"id": self.case.id, "command": self.case.command, "argv": self.argv,
                "why": self.case.why, "expected": self.case.expect,
                "also_accepted": sorted(self.case.also), "observed": self.observed,
                "pass": self.passed, "exit": self.rc, "seconds": round(self.seconds, 2),
                "stderr_first": lines[0] if lines else "",
                "stderr_key": key_stderr_line(self.stderr),
                "stderr_lines": len(lines),
                "stderr_tail": "\n".join(lines[-6:])[-1500:],
                "stdout_head": self.stdout_head, "nan_at": self.nan_at}


def _subst(arg: str, mapping: dict) -> str:
    for k, v in mapping.items():
        arg = arg.replace("{" + k + "}", v)
    return arg


def run_case(case: Case, workdir: Path, env: dict, timeout: float) -> Result:
    tmp = workdir / re.sub(r"[^A-Za-z0-9._-]+", "_", case.id)
    tmp.mkdir(parents=True, exist_ok=True)
    mapping = {"tmp": str(tmp)}
    t0 = time.monotonic()
    if case.setup is not None:
        try:
            mapping.update(case.setup(tmp))
        except Exception as exc:  # a harness problem, reported as such
            return Result(case, "setup_error", None, 0.0, list(case.argv),
                          stderr=f"setup failed: {type(exc).__name__}: {exc}")
    argv = [_subst(a, mapping) for a in case.argv]
    cmd = [sys.executable, "-m", "gearjax.cli", *argv]
    proc = subprocess.Popen(cmd, cwd=tmp, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, start_new_session=True)
    try:
        out, err = proc.communicate(timeout=timeout)
        rc = proc.returncode
    except subprocess.TimeoutExpired:
        try:
            os.killpg(proc.pid, 9)       # the case's own process group only
        except ProcessLookupError:
            pass
        out, err = proc.communicate()
        rc = None
    dt = time.monotonic() - t0
    stdout = out.decode("utf-8", "replace")
    stderr = err.decode("utf-8", "replace")
    observed = classify(rc, stdout, stderr, "--json" in argv, case.expect)
    nan_at = nan_locations(stdout, "--json" in argv) if observed == "nan" else []
    return Result(case, observed, rc, dt, argv, stderr, stdout[:400], nan_at)


def _make_writable(root: Path):
    for dirpath, dirnames, _ in os.walk(root):
        for d in dirnames:
            try:
                os.chmod(os.path.join(dirpath, d), 0o755)
            except OSError:
                pass


# ======================================================================================
# reports


def summary(results: list[Result]) -> dict:
    cross = {e: {o: 0 for o in OBSERVED} for e in EXPECTED}
    for r in results:
        cross[r.case.expect][r.observed] += 1
    by_obs = {o: sum(cross[e][o] for e in EXPECTED) for o in OBSERVED}
    return {"cases": len(results), "passed": sum(r.passed for r in results),
            "failed": sum(not r.passed for r in results),
            "observed": {o: n for o, n in by_obs.items() if n},
            "expected_x_observed": {e: {o: n for o, n in row.items() if n}
                                    for e, row in cross.items()}}


def _cell(s: str, n: int = 140) -> str:
    s = s.replace("|", "\\|").replace("\n", " ")
    return s if len(s) <= n else s[: n - 1] + "…"


def _used_observed(results):
    return [o for o in OBSERVED if any(r.observed == o for r in results)]


def markdown(results: list[Result], meta: dict) -> str:
    s = summary(results)
    obs = _used_observed(results)
    out = [f"# Hostile inputs to the `gearjax` command ({meta['label']})", "",
           f"`python tools/hostile_inputs.py` on commit `{meta['commit']}`, {meta['date']}; "
           f"{s['cases']} cases, {meta['jobs']} parallel jobs, per-case timeout "
           f"{meta['timeout_s']:g} s, wall time {meta['wall_s']:.0f} s.  Expected classes and "
           "observed classes are defined in the docstring of `tools/hostile_inputs.py`; "
           "`pass` means the observed class is one the case accepts.", "",
           f"**{s['passed']} of {s['cases']} cases pass; {s['failed']} do not.**", "",
           "## Expected x observed", "",
           "| expected \\ observed | " + " | ".join(obs) + " | total |",
           "|---|" + "---:|" * (len(obs) + 1)]
    for e in EXPECTED:
        row = s["expected_x_observed"][e]
        out.append(f"| {e} | " + " | ".join(str(row.get(o, 0)) for o in obs)
                   + f" | {sum(row.values())} |")
    out.append("| total | " + " | ".join(str(s["observed"].get(o, 0)) for o in obs)
               + f" | {s['cases']} |")
    bad = [r for r in results if not r.passed]
    out += ["", "## Cases that do not pass", "",
            "| case | expected | observed | exit | stderr (first line; traceback: exception) |",
            "|---|---|---|---:|---|"]
    for r in sorted(bad, key=lambda r: (OBSERVED.index(r.observed), r.case.id)):
        extra = f" (NaN/inf at: {', '.join(r.nan_at)})" if r.nan_at else ""
        out.append(f"| `{r.case.id}` | {r.case.expect} | **{r.observed}** | {r.rc} | "
                   f"{_cell(key_stderr_line(r.stderr) + extra, 260)} |")
    out += ["", "## All cases", "",
            "| case | argv | expected | observed | exit | s | stderr (first line; "
            "traceback: exception) |", "|---|---|---|---|---:|---:|---|"]
    for r in results:
        mark = r.observed if r.passed else f"**{r.observed}**"
        out.append(f"| `{r.case.id}` | `{_cell(' '.join(r.argv), 90)}` | {r.case.expect} | "
                   f"{mark} | {r.rc} | {r.seconds:.0f} | {_cell(key_stderr_line(r.stderr))} |")
    return "\n".join(out) + "\n"


def print_table(results: list[Result], file=sys.stdout):
    w = max(len(r.case.id) for r in results)
    print(f"{'case':<{w}s}  {'expected':8s} {'observed':10s} {'exit':>4s}  stderr", file=file)
    for r in results:
        flag = " " if r.passed else "!"
        print(f"{r.case.id:<{w}s}  {r.case.expect:8s} {r.observed:10s} {str(r.rc):>4s} {flag}"
              f"{key_stderr_line(r.stderr)[:120]}", file=file)
    s = summary(results)
    print(f"\n{s['cases']} cases: {s['passed']} pass, {s['failed']} do not", file=file)
    print("observed: " + ", ".join(f"{k} {v}" for k, v in s["observed"].items()), file=file)
    for e, row in s["expected_x_observed"].items():
        if row:
            print(f"  expected {e:7s}: " + ", ".join(f"{k} {v}" for k, v in row.items()),
                  file=file)


def _git_commit() -> str:
    try:
        res = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                             capture_output=True, text=True, timeout=20)
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"],
                               cwd=ROOT, capture_output=True, text=True, timeout=20).stdout
        return res.stdout.strip() + ("+dirty" if dirty.strip() else "")
    except (OSError, subprocess.SubprocessError):
        return "unknown"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jobs", type=int, default=2, help="cases run at once (default 2)")
    ap.add_argument("--only", default=None, help="run only cases whose id matches this regex")
    ap.add_argument("--timeout", type=float, default=300.0, help="seconds per case (default 300)")
    ap.add_argument("--md", default=None, help="write the markdown report here")
    ap.add_argument("--json", default=None, help="write the JSON report here")
    ap.add_argument("--label", default="baseline", help="title of the report (default baseline)")
    ap.add_argument("--cache-dir", default=None,
                    help="JAX compilation cache shared by the runs (default: a temporary one)")
    ap.add_argument("--list", action="store_true", help="list the cases and exit")
    ap.add_argument("--keep", action="store_true", help="keep the temporary directory")
    args = ap.parse_args(argv)
    if args.jobs < 1:
        ap.error("--jobs must be >= 1")

    cases = [c for c in CASES if args.only is None or re.search(args.only, c.id)]
    if not cases:
        print(f"no case matches {args.only!r}", file=sys.stderr)
        return 2
    if args.list:
        for c in cases:
            print(f"{c.id:55s} {c.expect:7s} {' '.join(c.argv)}")
        print(f"{len(cases)} cases")
        return 0

    workdir = Path(tempfile.mkdtemp(prefix="gearjax-hostile-"))
    cache = Path(args.cache_dir) if args.cache_dir else workdir / "jax-cache"
    cache.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH")
                                     else "")
    env["GEARJAX_CACHE_DIR"] = str(cache.resolve())
    order = sorted(range(len(cases)), key=lambda i: (not cases[i].heavy, i))
    results: dict[int, Result] = {}
    t0 = time.monotonic()
    try:
        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            futs = {pool.submit(run_case, cases[i], workdir, env, args.timeout): i
                    for i in order}
            for fut in as_completed(futs):
                i = futs[fut]
                r = results[i] = fut.result()
                print(f"[{len(results):3d}/{len(cases)}] {r.case.id}: {r.observed} "
                      f"(exit {r.rc}, {r.seconds:.0f} s)", file=sys.stderr, flush=True)
    finally:
        if args.keep:
            print(f"kept {workdir}", file=sys.stderr)
        else:
            _make_writable(workdir)
            shutil.rmtree(workdir, ignore_errors=True)
    wall = time.monotonic() - t0
    ordered = [results[i] for i in range(len(cases))]
    print_table(ordered)
    meta = {"label": args.label, "commit": _git_commit(),
            "date": time.strftime("%Y-%m-%d %H:%M %Z"), "jobs": args.jobs,
            "timeout_s": args.timeout, "wall_s": wall, "python": sys.version.split()[0],
            "cpu_count": os.cpu_count(), "only": args.only}
    if args.md:
        Path(args.md).parent.mkdir(parents=True, exist_ok=True)
        Path(args.md).write_text(markdown(ordered, meta), encoding="utf-8")
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        Path(args.json).write_text(json.dumps({"meta": meta, "summary": summary(ordered),
                                               "cases": [r.to_dict() for r in ordered]},
                                              indent=1) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
