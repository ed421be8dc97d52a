"""Property fuzzing of invalid input: every numeric flag of the cheap CLI commands and
the user-facing library constructors refuse random out-of-range values naming the
parameter, before any work is done.

CLI (``gearjax.cli.main`` in-process): ``involute``, ``friction``, ``stribeck`` and the
argument stage of ``surface``, ``kinematics`` and ``tca`` (their ranges are checked
before a design is read or a program compiled).  For each numeric flag -- and each
``--misalign`` key and inline ``involute:`` design key of ``tca`` -- one random value
from: NaN, +-inf, a number below or above the documented range (up to +-1e300, the
range typed in here from the command help / README, not read from the code), a
non-integer for integer inputs, a token that is not a number.  Property: exit
status 2, exactly one stderr line starting ``gearjax: error:`` that names the flag,
nothing on stdout, and none of the compute entry points called (they are replaced by
a function that fails the test).

Library: ``InvolutePair.create``, ``InvoluteTCA.create``, ``make_oil``,
``make_surface``, ``Misalignment.create``, ``make_cutter``; one random parameter gets
NaN, +-inf, a value outside its documented range or an object that is not a number
(None, a non-numeric string, a list, a dict, a complex number); property:
``ValueError`` whose one-line message names the parameter.

Hypothesis settings: ``derandomize=True`` (the cases are a fixed function of the test
code: the same on every run), ``max_examples`` = 300 (CLI) and 300 (constructors) by
default; the environment variable ``GEARJAX_FUZZ_EXAMPLES`` multiplies both (e.g. 10
for the figures of docs/reliability.md (property fuzzing)).  Each case is a refusal without
computation: the two properties take about 5 s together.

Gaps the fuzzing found (the library accepted or mis-reported these inputs; fixed
since, see docs/reliability.md) are kept as explicit regression cases at the end.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import warnings
from unittest import mock

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gearjax
import gearjax.tribology as trib
from gearjax.cli import main

SCALE = int(os.environ.get("GEARJAX_FUZZ_EXAMPLES", "1"))
CLI_EXAMPLES = 300 * SCALE
LIB_EXAMPLES = 300 * SCALE

INVOLUTE = ["involute", "--z1", "20", "--z2", "40", "--module", "4", "--pressure-angle", "20"]
CONTACT = ["--load-N", "500", "--rx-mm", "10", "--ry-mm", "100", "--sigma-um", "0.4"]
OIL = ["--oil", "mineral_vg100"]
CUSTOM_OIL = ["--eta0", "0.1"]
FRICTION = ["friction", *CONTACT, *OIL, "--ue", "5", "--us", "1"]
FRICTION_CUSTOM = ["friction", *CONTACT, *CUSTOM_OIL, "--ue", "5", "--us", "1"]
STRIBECK = ["stribeck", *CONTACT, *OIL]
KINEMATICS = ["kinematics", "example:hypoid_6x39_7p5in"]
SURFACE = ["surface", "example:hft_8x43", "--member", "pinion", "--flank", "convex",
           "--out", "fuzz_never_written.csv"]
TCA = ["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=30"]
TCA_HYPOID = ["tca", "example:hft_8x43"]

INF = math.inf
# (base argv, flag, low, high, low excluded, high excluded, integer, needle in the message)
# ranges as documented in the command help and README.md ("CLI ranges")
FLAGS = [
    (INVOLUTE, "--z1", 6, 1000, False, False, True, "z1"),
    (INVOLUTE, "--z2", 6, 1000, False, False, True, "z2"),
    (INVOLUTE, "--module", 0.01, 100.0, False, False, False, "module"),
    (INVOLUTE, "--pressure-angle", 0.0, 45.0, True, True, False, "pressure_angle"),
    (INVOLUTE, "--helix", 0.0, 60.0, False, False, False, "helix"),
    (INVOLUTE, "--x1", -3.0, 3.0, False, False, False, "x1"),
    (INVOLUTE, "--x2", -3.0, 3.0, False, False, False, "x2"),
    (INVOLUTE, "--points", 2, 100000, False, False, True, "points"),
    (INVOLUTE, "--rpm", 1e-3, 1e5, False, False, False, "rpm"),
    (FRICTION, "--load-N", 1e-3, 1e7, False, False, False, "--load-N"),
    (FRICTION, "--rx-mm", 0.0, 1e6, True, False, False, "--rx-mm"),
    (FRICTION, "--ry-mm", 0.0, 1e6, True, False, False, "--ry-mm"),
    (FRICTION, "--sigma-um", 0.0, 10.0, True, False, False, "--sigma-um"),
    (FRICTION, "--asperity-density-per-mm2", 0.0, 1e6, True, False, False,
     "--asperity-density-per-mm2"),
    (FRICTION, "--asperity-radius-um", 0.0, 1000.0, True, False, False, "--asperity-radius-um"),
    (FRICTION, "--fc", 0.0, 1.0, False, False, False, "--fc"),
    (FRICTION, "--E-prime-MPa", 0.0, 1e7, True, False, False, "--E-prime-MPa"),
    (FRICTION, "--ue", 1e-6, 500.0, False, False, False, "--ue"),
    (FRICTION, "--us", 0.0, 500.0, False, False, False, "--us"),
    (FRICTION_CUSTOM, "--eta0", 6.31e-5, 100.0, True, False, False, "--eta0"),
    (FRICTION_CUSTOM, "--alpha-per-GPa", 0.0, 100.0, True, False, False, "--alpha-per-GPa"),
    (FRICTION_CUSTOM, "--tau0-MPa", 0.0, 100.0, True, False, False, "--tau0-MPa"),
    (STRIBECK, "--load-N", 1e-3, 1e7, False, False, False, "--load-N"),
    (STRIBECK, "--sigma-um", 0.0, 10.0, True, False, False, "--sigma-um"),
    (STRIBECK, "--srr", 0.0, 2.0, False, False, False, "--srr"),
    (STRIBECK, "--ue-min", 1e-6, 500.0, False, False, False, "--ue-min"),
    (STRIBECK, "--ue-max", 1e-6, 500.0, False, False, False, "--ue-max"),
    (STRIBECK, "--points", 2, 2000, False, False, True, "--points"),
    (KINEMATICS, "--blade-angle-delta", -10.0, 10.0, False, False, False, "--blade-angle-delta"),
    (KINEMATICS, "--cutter-shift", -20.0, 20.0, False, False, False, "--cutter-shift"),
    (TCA, "--positions", 11, 1001, False, False, True, "positions"),
    (TCA, "--pitches", 0.75, 4.0, False, False, False, "pitches"),
    (TCA_HYPOID, "--positions", 11, 1001, False, False, True, "positions"),
    (TCA_HYPOID, "--pitches", 0.75, 4.0, False, False, False, "pitches"),
]

# keys of ``tca --misalign`` and of an inline ``involute:`` design: (low, high, low
# excluded, high excluded, integer, needle)
MISALIGN = {"dE": (-50.0, 50.0, False, False, False, "dE"),
            "dP": (-50.0, 50.0, False, False, False, "dP"),
            "dG": (-50.0, 50.0, False, False, False, "dG"),
            "dSigma": (-5.0, 5.0, False, False, False, "dSigma")}
INLINE = {"z1": (6, 1000, False, False, True, "z1"),
          "z2": (6, 1000, False, False, True, "z2"),
          "m": (0.01, 100.0, False, False, False, "module"),
          "alpha": (0.0, 45.0, True, True, False, "pressure_angle"),
          "b": (0.0, 1000.0, True, False, False, "face width"),
          "helix": (0.0, 60.0, False, False, False, "helix"),
          "x1": (-3.0, 3.0, False, False, False, "x1"),
          "x2": (-3.0, 3.0, False, False, False, "x2"),
          "dalpha": (-5.0, 5.0, False, False, False, "dalpha"),
          "crown": (0.0, 0.1, False, False, False, "profile_crown"),
          "lead_crown": (0.0, 0.1, False, False, False, "lead_crown")}
INLINE_BASE = {"z1": "20", "z2": "40", "m": "4", "alpha": "20", "b": "30"}

# ("--" as a value is a gap, pinned below: test_gap_double_dash_value)
NOT_A_NUMBER = ["abc", "", "1,5", "0x10", "1e", "five", "2..0", "1 2"]
KV_TOKENS = ["abc", "", "0x10", "1e", "five", "2..0", "1 2"]     # no ',' or '='



def _fmt(x: float) -> str:
    return repr(float(x))


@st.composite
def _bad_number(draw, lo, hi, lo_open, hi_open, integer, tokens=True):
    """A string that is not a number in the range [lo, hi] (open where stated)."""
    kinds = ["nan", "inf", "-inf", "below", "above"]
    if integer:
        kinds.append("fraction")
    if tokens:
        kinds.append("token")
    kind = draw(st.sampled_from(kinds))
    if kind in ("nan", "inf", "-inf"):
        return draw(st.sampled_from({"nan": ["nan", "NaN"], "inf": ["inf", "Infinity", "1e999"],
                                     "-inf": ["-inf", "-Infinity"]}[kind]))
    if kind == "below":
        v = draw(st.floats(min_value=-1e300, max_value=lo, exclude_max=not lo_open,
                           allow_nan=False))
        return _fmt(v)
    if kind == "above":
        v = draw(st.floats(min_value=hi, max_value=1e300, exclude_min=not hi_open,
                           allow_nan=False))
        return _fmt(v)
    if kind == "fraction":
        k = draw(st.integers(min_value=int(lo), max_value=int(hi) - 1))
        return _fmt(k + draw(st.sampled_from([0.5, 0.25, 1e-6])))
    return draw(st.sampled_from(NOT_A_NUMBER))


def _replace(argv, flag, value):
    """``argv`` with ``flag`` set to ``value`` (as ``--flag=value``: a value that starts
    with '-' is not taken for an option)."""
    out, skip = [], False
    for i, a in enumerate(argv):
        if skip:
            skip = False
            continue
        if a == flag:
            skip = True
            continue
        out.append(a)
    return out + [f"{flag}={value}"]


@st.composite
def _cli_case(draw):
    kind = draw(st.sampled_from(["flag"] * 4 + ["misalign", "inline"]))
    if kind == "flag":
        base, flag, lo, hi, lo_open, hi_open, integer, needle = draw(st.sampled_from(FLAGS))
        value = draw(_bad_number(lo, hi, lo_open, hi_open, integer))
        if value in NOT_A_NUMBER:     # refused by argparse: "argument --flag: invalid float"
            needle = flag
        return _replace(base, flag, value), needle
    if kind == "misalign":
        key = draw(st.sampled_from(sorted(MISALIGN)))
        lo, hi, lo_open, hi_open, integer, needle = MISALIGN[key]
        # split at ',' and '=' like the inline design: tokens without them
        value = draw(_bad_number(lo, hi, lo_open, hi_open, integer, tokens=False)
                     | st.sampled_from(KV_TOKENS))
        others = [f"{k}=0.01" for k in draw(st.sets(st.sampled_from(sorted(MISALIGN))))
                  if k != key]
        base = draw(st.sampled_from([TCA, TCA_HYPOID]))
        return base + ["--misalign=" + ",".join(others + [f"{key}={value}"])], needle
    key = draw(st.sampled_from(sorted(INLINE)))
    lo, hi, lo_open, hi_open, integer, needle = INLINE[key]
    # the inline design is split at ',' and '=': tokens with those are another error
    value = draw(_bad_number(lo, hi, lo_open, hi_open, integer, tokens=False)
                 | st.sampled_from(KV_TOKENS))
    if value in KV_TOKENS:
        needle = f"{key} = "      # "design: m = 'abc' must be a number"
    kv = {**INLINE_BASE, key: value}
    return ["tca", "involute:" + ",".join(f"{k}={v}" for k, v in kv.items())], needle


def _forbidden(*a, **k):
    raise AssertionError("the command started computing before refusing its input")


@contextlib.contextmanager
def _no_work():
    with contextlib.ExitStack() as stack:
        for mod, name in [(gearjax.involute, "path_kinematics"), (gearjax, "load_design"),
                          (gearjax, "run_tca"), (gearjax.hypoid, "flank_surface"),
                          (trib, "friction_coefficient"), (trib, "stribeck_curve")]:
            stack.enter_context(mock.patch.object(mod, name, _forbidden))
        yield


def _run(argv):
    """``main(argv)`` in-process: (exit status, stdout, stderr); argparse's own
    refusals (SystemExit) count as their exit status."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), \
            warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            rc = main(argv)
        except SystemExit as exc:
            rc = exc.code
    return rc, out.getvalue(), err.getvalue()


@settings(max_examples=CLI_EXAMPLES, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(_cli_case())
def test_cli_refuses_random_invalid_numbers_naming_the_flag(case):
    argv, needle = case
    with _no_work():
        rc, out, err = _run(argv)
    lines = err.splitlines()
    assert rc == 2, (argv, rc, err)
    assert len(lines) == 1 and lines[0].startswith("gearjax: error:"), (argv, err)
    assert needle in lines[0], (argv, needle, lines[0])
    assert out == "", (argv, out)
    assert "Traceback" not in err


# --grid of surface and kinematics: two integers; ranges [2, 2001] and [3, 201]
@settings(max_examples=max(40, CLI_EXAMPLES // 8), deadline=None, derandomize=True)
@given(st.sampled_from([(SURFACE, 2, 2001), (KINEMATICS, 3, 201)]),
       st.integers(0, 1), st.data())
def test_cli_refuses_random_invalid_grids(cmd, which, data):
    base, lo, hi = cmd
    bad = data.draw(st.integers(-10 ** 6, lo - 1) | st.integers(hi + 1, 10 ** 9)
                    | st.sampled_from(["x", "3", "3x", "ax5", "3.5", "nan", "infxinf"]),
                    label="bad")
    good = data.draw(st.integers(lo, hi), label="good")
    if isinstance(bad, int):
        grid = f"{bad}x{good}" if which == 0 else f"{good}x{bad}"
    else:
        grid = bad                # not of the form AxB
    with _no_work():
        rc, out, err = _run(base + [f"--grid={grid}"])
    lines = err.splitlines()
    assert rc == 2 and len(lines) == 1 and lines[0].startswith("gearjax: error:"), (grid, err)
    assert "--grid" in lines[0] and out == ""


# ------------------------------------------------------------------- library constructors

_PAIR = gearjax.involute.InvolutePair.create(20, 40, 4.0, 20.0)
NOT_NUMBERS = [None, "abc", [1.0], {"a": 1}, 1 + 2j, object()]

# constructor -> (callable taking keyword overrides,
#                 {parameter: (low, high, low excluded, high excluded, integer, needle)})
CONSTRUCTORS = {
    "InvolutePair.create": (
        lambda **k: gearjax.involute.InvolutePair.create(**{**dict(z1=20, z2=40, module=4.0,
                                                          pressure_angle_deg=20.0), **k}),
        {"z1": (6, 1000, False, False, True, "z1"), "z2": (6, 1000, False, False, True, "z2"),
         "module": (0.01, 100.0, False, False, False, "module"),
         "pressure_angle_deg": (0.0, 45.0, True, True, False, "pressure_angle"),
         "helix_deg": (0.0, 60.0, False, False, False, "helix"),
         "x1": (-3.0, 3.0, False, False, False, "x1"),
         "x2": (-3.0, 3.0, False, False, False, "x2")}),
    "InvoluteTCA.create": (
        lambda **k: gearjax.involute.InvoluteTCA.create(**{**dict(pair=_PAIR, face_width=30.0), **k}),
        {"face_width": (0.0, 1000.0, True, False, False, "face_width"),
         "dalpha_deg": (-5.0, 5.0, False, False, False, "dalpha"),
         "profile_crown": (0.0, 0.1, False, False, False, "profile_crown"),
         "lead_crown": (0.0, 0.1, False, False, False, "lead_crown")}),
    "make_oil": (
        lambda **k: gearjax.tribology.make_oil(**{**dict(eta0=0.1, alpha_per_GPa=20.0), **k}),
        {"eta0": (6.31e-5, 100.0, True, False, False, "eta0"),
         "alpha_per_GPa": (0.0, 100.0, True, False, False, "alpha"),
         "tau0_MPa": (0.0, 100.0, True, False, False, "tau0"),
         "rho0": (0.0, 2e4, True, False, False, "rho0")}),
    "make_surface": (
        lambda **k: gearjax.tribology.make_surface(**{**dict(sigma_um=0.4), **k}),
        {"sigma_um": (0.0, 10.0, True, False, False, "sigma"),
         "density_per_mm2": (0.0, 1e6, True, False, False, "asperity density"),
         "beta_um": (0.0, 1000.0, True, False, False, "asperity radius"),
         "f_c": (0.0, 1.0, False, False, False, "f_c"),
         "v_slip_mm_s": (0.0, 1000.0, True, False, False, "v_slip")}),
    "Misalignment.create": (
        lambda **k: gearjax.Misalignment.create(**k),
        {"dE": (-50.0, 50.0, False, False, False, "dE"),
         "dP": (-50.0, 50.0, False, False, False, "dP"),
         "dG": (-50.0, 50.0, False, False, False, "dG"),
         "dSigma_deg": (-5.0, 5.0, False, False, False, "dSigma")}),
    "make_cutter": (
        lambda **k: gearjax.hypoid.make_cutter(**{**dict(point_radius=100.0, blade_angle_deg=20.0,
                                                  edge_radius=1.0, flank="convex"), **k}),
        {"point_radius": (0.0, 1e4, True, False, False, "point_radius"),
         "blade_angle_deg": (0.0, 45.0, True, True, False, "blade_angle"),
         "edge_radius": (0.0, None, False, False, False, "edge_radius")}),
}

# the gaps pinned by the xfail cases below, kept out of the random draws
_INT_PARAMS: set = set()     # (the tooth-number gap is fixed: they join the draws)


@st.composite
def _bad_argument(draw):
    ctor = draw(st.sampled_from(sorted(CONSTRUCTORS)))
    fn, params = CONSTRUCTORS[ctor]
    name = draw(st.sampled_from(sorted(params)))
    lo, hi, lo_open, hi_open, integer, needle = params[name]
    kinds = ["nan", "inf", "-inf", "below"] + (["above"] if hi is not None else [])
    if integer:
        kinds.append("fraction")
    if (ctor, name) not in _INT_PARAMS:
        kinds.append("not a number")
    kind = draw(st.sampled_from(kinds))
    if kind == "nan":
        v = math.nan
    elif kind in ("inf", "-inf"):
        v = math.inf if kind == "inf" else -math.inf
    elif kind == "below":
        v = draw(st.floats(min_value=-1e300, max_value=lo, exclude_max=not lo_open))
    elif kind == "above":
        v = draw(st.floats(min_value=hi, max_value=1e300, exclude_min=not hi_open))
    elif kind == "fraction":
        v = draw(st.integers(int(lo), int(hi) - 1)) + 0.5
    else:
        v = draw(st.sampled_from(NOT_NUMBERS))
    return ctor, fn, name, v, needle


@settings(max_examples=LIB_EXAMPLES, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(_bad_argument())
def test_constructors_refuse_random_invalid_arguments_naming_them(case):
    ctor, fn, name, value, needle = case
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(ValueError) as exc:
            fn(**{name: value})
    msg = str(exc.value)
    assert needle in msg and "\n" not in msg, (ctor, name, value, msg)


# ------------------------------------------------------------------- gaps found, fixed
# Each case below is an invalid input the library accepted or reported without the
# parameter's name when the fuzzing found it (pinned then as strict xfails); kept as
# regression cases.

_STR_BOOL_BYTES = "a numeric string, a bool or bytes passes float() in check_range"


@pytest.mark.parametrize("ctor,name,value", [
    ("InvolutePair.create", "module", "4"),
    ("InvolutePair.create", "helix_deg", True),
    ("InvoluteTCA.create", "face_width", "30"),
    ("InvoluteTCA.create", "lead_crown", b"0"),
    ("make_oil", "eta0", True),
    ("make_oil", "tau0_MPa", "5"),
    ("make_surface", "f_c", True),
    ("make_surface", "density_per_mm2", "1e4"),
])
def test_gap_wrong_type_accepted(ctor, name, value):
    fn, params = CONSTRUCTORS[ctor]
    with pytest.raises(ValueError, match=params[name][-1]):
        fn(**{name: value})


@pytest.mark.parametrize("value", [None, "abc", [20], {"z": 20}, 1 + 2j])
def test_gap_tooth_number_not_a_number(value):
    with pytest.raises(ValueError, match="z1"):
        gearjax.involute.InvolutePair.create(value, 40, 4.0, 20.0)


@pytest.mark.parametrize("ctor,name", [("InvoluteTCA.create", "face_width"),
                                       ("make_cutter", "point_radius")])
def test_gap_huge_length_accepted(ctor, name):
    fn, params = CONSTRUCTORS[ctor]
    with pytest.raises(ValueError, match=params[name][-1]):
        fn(**{name: 1e300})


@pytest.mark.parametrize("flag", ["--alpha-per-GPa", "--tau0-MPa"])
def test_gap_oil_flags_ignored_with_named_oil(flag):
    rc, _, err = _run(FRICTION + [f"{flag}=nan"])
    assert rc == 2 and flag in err


@pytest.mark.parametrize("argv", [_replace(INVOLUTE, "--z1", "--"),
                                  _replace(INVOLUTE, "--points", "--")])
def test_gap_double_dash_value(argv):
    rc, _, err = _run(argv)
    assert rc == 2 and len(err.splitlines()) == 1 and "Traceback" not in err
