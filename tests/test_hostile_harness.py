"""The hostile-input harness (tools/hostile_inputs.py, kept out of CI) is well formed:
its case table covers every sub-command with unique ids and resolvable setups, and its
classifier tells the outcome classes apart.  No case is run here (no subprocess)."""

import importlib.util
import json
import re
import sys
import tomllib
from pathlib import Path

import pytest

from gearjax.cli import build_parser

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def harness():
    spec = importlib.util.spec_from_file_location("hostile_inputs",
                                                  ROOT / "tools" / "hostile_inputs.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod               # dataclasses look their module up
    try:
        spec.loader.exec_module(mod)
        yield mod
    finally:
        sys.modules.pop(spec.name, None)


def _subcommands():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    return set(sub.choices)


def test_case_table_is_well_formed(harness):
    cases = harness.CASES
    ids = [c.id for c in cases]
    assert len(cases) >= 160
    assert len(set(ids)) == len(ids), [i for i in ids if ids.count(i) > 1]
    commands = _subcommands()
    assert {"involute", "example", "blank", "surface", "friction", "stribeck", "kinematics",
            "tca"} <= commands
    covered = {c.command for c in cases}
    assert commands <= covered, commands - covered
    for c in cases:
        assert c.expect in harness.EXPECTED, c.id
        assert set(c.also) <= set(harness.OBSERVED), c.id
        assert all(isinstance(a, str) for a in c.argv), c.id
        assert c.command == "top" or (c.argv and c.argv[0] == c.command), c.id
        assert c.why, c.id
    # each expected class is represented, and every sub-command has a valid-run case
    assert {c.expect for c in cases} == set(harness.EXPECTED)
    assert commands <= {c.command for c in cases if c.expect == "ok"}


def test_setups_resolve_every_placeholder(harness, tmp_path):
    for i, c in enumerate(harness.CASES):
        tmp = tmp_path / f"c{i}"
        tmp.mkdir()
        mapping = {"tmp": str(tmp)}
        if c.setup is not None:
            mapping.update(c.setup(tmp))
        argv = [harness._subst(a, mapping) for a in c.argv]
        left = [a for a in argv if re.search(r"\{[a-z]+\}", a)]
        assert not left, (c.id, left)
        if c.setup is not None and c.id.split(".")[1] == "design":
            # corrupted copies of the examples are still TOML (the corruption is the content)
            tomllib.loads(Path(mapping["design"]).read_text(encoding="utf-8"))
    harness._make_writable(tmp_path)


def test_design_edit_applies_and_deletes(harness, tmp_path):
    setup = harness.design_file("hft_8x43", ("pinion.concave.machine.sliding_base",
                                             harness._DELETE),
                                ("blank_summary.gear.teeth", 41),
                                ("blank.offset_mm", float("nan")))
    d = tomllib.loads(Path(setup(tmp_path)["design"]).read_text(encoding="utf-8"))
    assert "sliding_base" not in d["pinion"]["concave"]["machine"]
    assert "sliding_base" in d["pinion"]["convex"]["machine"]
    assert d["blank_summary"]["gear"]["teeth"] == 41
    assert d["blank"]["offset_mm"] != d["blank"]["offset_mm"]          # NaN
    assert d["gear"]["convex"]["machine"]["type"] == "formate"         # the rest is kept
    with pytest.raises(KeyError):
        harness.design_file("hft_8x43", ("blank.no_such_key", harness._DELETE))(tmp_path)


ERR = "gearjax: error: z1 = 0 is outside the allowed range [6, inf)\n"
WARN = "gearjax: warning: drive side: edge contact\n"
TB = ("Traceback (most recent call last):\n  File \"x.py\", line 1, in <module>\n"
      "TypeError: float() argument must be a string or a real number, not 'list'\n")


@pytest.mark.parametrize("rc, out, err, wants_json, expect, observed", [
    (2, "", ERR, False, "refuse", "refusal"),
    (2, "", "usage: gearjax ...\n" + ERR, False, "refuse", "unclean"),
    (2, "", ERR + ERR, False, "refuse", "unclean"),
    (2, "", "some error\n", False, "refuse", "unclean"),
    (1, "", TB, False, "refuse", "traceback"),
    (0, "", TB, False, "refuse", "traceback"),
    (None, "", "", False, "refuse", "timeout"),
    (0, '{"a": 1}', "", True, "refuse", "silent"),
    (0, '{"a": 1}', "", True, "ok", "ok"),
    (0, '{"a": 1}', WARN, True, "flag", "flagged"),
    (0, '{"a": NaN}', "", True, "ok", "nan"),
    (0, '{"a": [1, -Infinity]}', WARN, True, "flag", "nan"),
    (0, '{"a": 1} trailing', "", True, "ok", "badjson"),
    (0, "", "", True, "ok", "badjson"),
    (0, "mu   nan\n", "", False, "ok", "nan"),
    (0, "x = -inf mm\n", "", False, "ok", "nan"),
    (0, "regime mixed, INSIDE the flank, margin 0.1\n", "", False, "ok", "ok"),
    (0, "  1.0000       nan   1.0   2.0   0.0   0.0 edge\n", "", False, "ok", "ok"),
    (0, "  1.0000       nan   1.0   2.0   0.0   0.0 ok\n", "", False, "ok", "nan"),
    (0, "  1.0000   0.12000   1.0   2.0   inf   0.4 ok\n", "", False, "ok", "ok"),
    (0, "  1.0000   0.12000   1.0   2.0  -inf   0.4 ok\n", "", False, "ok", "nan"),
    (0, "  machine_tilt      inf  deg\n", "", False, "ok", "nan"),
    (3, "", "gearjax: error: drive side: the flanks do not touch\n", False, "flag", "flagged"),
    (3, "", WARN + "gearjax: error: drive side: the contact solve failed\n", False, "flag",
     "flagged"),
    (1, "", "", False, "refuse", "unclean"),
    (-9, "", "", False, "refuse", "unclean"),
])
def test_classify(harness, rc, out, err, wants_json, expect, observed):
    assert harness.classify(rc, out, err, wants_json, expect) == observed


def test_acceptance_and_key_line(harness):
    case = harness.Case("x.y", ("x",), "flag", "why")
    assert case.accepted == {"flagged", "refusal"}
    assert harness.Case("x.y", ("x",), "refuse", "w", also=frozenset({"ok"})).accepted == \
        {"refusal", "ok"}
    assert harness.key_stderr_line(TB).startswith("TypeError: float()")
    assert harness.key_stderr_line("W0000 some absl line\n" + ERR) == ERR.strip()
    r = harness.Result(harness.Case("a.b", ("a",), "refuse", "w"), "silent", 0, 1.0, ["a"])
    s = harness.summary([r])
    assert s["failed"] == 1 and s["expected_x_observed"]["refuse"] == {"silent": 1}
    json.dumps(r.to_dict())


def test_nan_locations(harness):
    doc = '{"drive": {"contact_ratio": NaN, "te": [1.0, null, Infinity]}, "ok": 1}'
    assert harness.nan_locations(doc, True) == ["drive.contact_ratio", "drive.te[2]"]
    assert harness.nan_locations('{"a": [1, null]}', True) == []
    text = "blank of x\n  machine_tilt   nan  deg\n  delta1  12.5  deg\n"
    assert harness.nan_locations(text, False) == ["machine_tilt   nan  deg"]
