"""Property fuzzing of valid designs: random small perturbations of every packaged
example and random involute pairs give either a valid TCA result or a flagged one
(or a clear ``ValueError``), never a result that looks valid but is not; where the
result is valid, the gradient of the TE peak-to-peak is free of NaN.

Spiral-bevel / hypoid: every packaged example with flank tables
(``gearjax.list_examples()``; ``hypoid_6x39_7p5in`` has only a ``[blank]`` table and
must be refused with a ``ValueError`` naming the missing flank), drive side,
``gearjax.tca_function(design, side="drive", steps_per_pitch=6, half_pitches=1.5,
n_pairs=3)``: one compiled program per example serves all its perturbations (the
pair pytree is an argument).  Perturbations, uniform within (all leaves of
``f.pair``, both members):

* machine settings: radial distance, blank offset, sliding base, centre-to-back
  +-0.05 mm; cradle angle, tilt, swivel, machine root angle +-0.05 deg; ratio of
  roll of a generated member +-1e-4 relative;
* cutter: point radius +-0.1 mm, blade angle +-0.05 deg;
* misalignment: dE, dP, dG in [-0.05, 0.05] mm, dSigma in [-0.01, 0.01] deg.

Involute: tooth numbers drawn too, z1 in 12..40 and z2 in z1..4 z1 (they are traced:
every pair runs the one compiled program of these options; until 2026-11-26 they were
static and the property ran on (19, 47) only); module 2..6 mm, normal pressure angle 17.5..25 deg, helix 0..30
deg, x1, x2 in [-0.2, 0.4] (a combination the constructor refuses -- undercut,
pointed teeth, interference -- counts as "refused": a ``ValueError``), face width
6..12 modules, pressure-angle modification +-0.05 deg, profile crown 0..5e-4 1/mm,
lead crown 1e-5..2e-3 1/mm (always crowned: one program per tooth pair), dE, dP, dG
in [-0.05, 0.05] mm and dSigma in [-0.2, 0.2] deg; ``gearjax.run_tca(...,
throw=False, steps_per_pitch=8, kinematics=False)``.

Property of every result (``touching`` = ``on_flank | edge_points``, pair 0 touches):
at every touching grid point the solve converged with ``residual < 1e-9`` and finite
TE; ``flags()["converged"]`` is False exactly when the strict check of ``run_tca``
(``gearjax.tca.path.check_on_flank_converged``) raises; a result with no flag raised
(converged, reference on the flanks, no edge / face-end contact, contact ratio >= 1,
TE peak-to-peak <= 60 arcsec, no load carried where the flanks cross) has finite TE over
its whole touching span, a finite peak-to-peak and a contact ellipse (a definite relative
curvature, by the ellipse's own route) wherever pair 0 carries the load at a surface
contact.  Involute: the flag ``face_end_contact`` is raised exactly when
the load-carrying pair 0 touches at a face end, checked from the contact point's own
axial coordinate (|axial| = b/2 on pinion or gear, to 1e-6 mm), not from the
library's edge classification.  Gradients: ``jax.grad`` of the TE peak-to-peak
w.r.t. the whole pair pytree on two perturbations (half the ranges above; numpy
``default_rng`` seeds 0 and 1) of ``spiral_bevel_10x30_synthesised`` and two involute
designs (z1, z2 = 19, 47; seeds 0 and 1): the results are converged with the
reference on the flanks and a finite peak-to-peak (asserted), and every leaf of the
gradient is finite.

Hypothesis: ``derandomize=True`` (the same cases on every run), ``max_examples`` 8
per hypoid example, 30 on the involute pair; the environment variable
``GEARJAX_FUZZ_EXAMPLES`` multiplies the hypoid count and gives 15 times it on each of
the two involute pairs (10 for the figures of docs/reliability.md (property fuzzing)).  ``GEARJAX_FUZZ_REPORT=path`` writes the
outcome counts (valid / flagged / refused) there as JSON.  Cost: four TCA programs
and two gradient programs compiled, about 90 s on two idle cores; a case after the
compile is ~0.1 s.
"""

from __future__ import annotations

import collections
import json
import math
import os
import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import gearjax as gj
from gearjax.errors import ConvergenceError
from gearjax.tca.path import check_on_flank_converged

SCALE = int(os.environ.get("GEARJAX_FUZZ_EXAMPLES", "1"))
HYPOID_EXAMPLES = 8 * SCALE
# Tooth numbers are static: each pair is one compiled TCA program (~12 s of the
# suite's compile time).  The suite's run (SCALE 1) puts its 30 involute cases on one
# pair; the wide run of docs/reliability.md (SCALE > 1) spreads 15 * SCALE cases over
# each of two pairs, as the figures there were produced.
TOOTH_PAIRS = [(19, 47), (31, 62)] if SCALE > 1 else [(19, 47)]
INVOLUTE_EXAMPLES = (15 if SCALE > 1 else 30) * SCALE
GRADIENT_SEEDS = (0, 1)      # numpy default_rng seeds of the gradient cases

RESIDUAL_TOL = 1e-9          # contact solve residual at a touching point (mm / -)
DEG = math.pi / 180.0
HYPOID_OPTIONS = dict(side="drive", steps_per_pitch=6, half_pitches=1.5, n_pairs=3)
# the grid is given explicitly (the family's default grid widens for long paths of
# contact: another program); a grid too short for a pair is a flagged result
INVOLUTE_OPTIONS = dict(side="drive", steps_per_pitch=8, half_pitches=1.25, n_pairs=3,
                        kinematics=False)

# the hypoid/spiral-bevel examples (other families' kinds have their own tests)
ALL_EXAMPLES = [n for n in gj.list_examples()
                if gj.io.read_toml(f"example:{n}")["design"]["kind"] in gj.hypoid.KINDS]
TCA_EXAMPLES = [n for n in ALL_EXAMPLES if gj.load_design(f"example:{n}").flanks()]
NO_FLANK_EXAMPLES = [n for n in ALL_EXAMPLES if n not in TCA_EXAMPLES]

OUTCOMES = collections.Counter()

_SETTINGS = dict(deadline=None, derandomize=True,
                 suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@pytest.fixture(scope="module", autouse=True)
def _report():
    yield
    path = os.environ.get("GEARJAX_FUZZ_REPORT")
    if path:
        with open(path, "w") as fh:
            json.dump(dict(sorted(OUTCOMES.items())), fh, indent=1)


# ----------------------------------------------------------------------------- the property

def _check_result(res, tag):
    """Assert the property on a concrete result; return "valid" or "flagged"."""
    path = res.path
    conv = np.asarray(path.converged)
    resid = np.asarray(path.residual)
    te = np.asarray(path.te)
    touching = np.asarray(res.on_flank | res.edge_points)
    # at every touching point: a converged solve with a small residual and a finite TE
    assert np.all(conv[touching]), tag
    assert np.all(resid[touching] < RESIDUAL_TOL), (tag, resid[touching].max())
    assert np.all(np.isfinite(te[touching])), tag
    flags = res.flags()
    # the flag and the strict mode of run_tca agree
    try:
        check_on_flank_converged(path, res.margin)
        strict_ok = True
    except ConvergenceError:           # NoContactError is a ConvergenceError
        strict_ok = False
    assert flags["converged"] == strict_ok, (tag, flags)
    clean = (flags["converged"] and flags["reference_on_flank"] and not flags["edge_contact"]
             and not flags["face_end_contact"] and not flags["low_contact_ratio"]
             and not flags["large_te"] and not flags["crossing_flanks"])
    if not clean:
        return "flagged"
    # looks valid: nothing may be silently wrong over the touching span
    idx = np.nonzero(touching)[0]
    assert idx.size > 0, tag
    span = slice(idx[0], idx[-1] + 1)
    assert np.all(conv[span]) and np.all(resid[span] < RESIDUAL_TOL), tag
    assert np.all(np.isfinite(te[span])), tag
    # where pair 0 carries the load at a surface contact the flanks do not cross: the
    # contact ellipse (its own route from the relative curvature) exists there (every
    # fuzzed pair is in point contact: crowned involute pairs, bevel/hypoid)
    carrying = np.asarray(res.on_flank) & res._carrying()
    assert np.all(np.isfinite(np.asarray(path.semi_major)[carrying])), tag
    ptp = float(res.ptp)
    assert math.isfinite(ptp) and ptp >= 0.0, (tag, ptp)
    assert math.isfinite(float(res.contact_ratio)), tag
    return "valid"


# ----------------------------------------------------------------------------- hypoid family

_FUNCTIONS = {}


def _tca_fn(name):
    if name not in _FUNCTIONS:
        design = gj.load_design(f"example:{name}")
        _FUNCTIONS[name] = gj.tca_function(design, **HYPOID_OPTIONS)
    return _FUNCTIONS[name]


_LENGTHS = ("radial_distance", "blank_offset", "sliding_base", "center_to_back")
_ANGLES = ("cradle_angle", "tilt", "swivel", "machine_root_angle")
_FIELDS = ([(f"{m}.machine.{k}", "mm", 0.05) for m in ("pinion", "gear") for k in _LENGTHS]
           + [(f"{m}.machine.{k}", "rad", 0.05 * DEG) for m in ("pinion", "gear") for k in _ANGLES]
           + [(f"{m}.machine.ratio_of_roll", "rel", 1e-4) for m in ("pinion", "gear")]
           + [(f"{m}.cutter.point_radius", "mm", 0.1) for m in ("pinion", "gear")]
           + [(f"{m}.cutter.blade_angle", "rad", 0.05 * DEG) for m in ("pinion", "gear")])

_unit = st.floats(-1.0, 1.0, allow_nan=False)


@st.composite
def _hypoid_perturbation(draw):
    """Relative positions in [-1, 1] of each field within its range (0 for about a
    third of them: a perturbation of a few settings as well as of all)."""
    keep = draw(st.lists(st.booleans(), min_size=len(_FIELDS), max_size=len(_FIELDS)))
    xs = draw(st.lists(_unit, min_size=len(_FIELDS) + 4, max_size=len(_FIELDS) + 4))
    return [x if k or i >= len(_FIELDS) else 0.0 for i, (x, k) in
            enumerate(zip(xs, keep + [True] * 4))]


def _perturbed(f, xs):
    pair = f.pair
    values = {}
    for (name, kind, scale), x in zip(_FIELDS, xs):
        v = gj.get_fields(pair, [name])[name]
        if kind == "rel":
            if not getattr(pair, name.split(".")[0]).machine.generated:
                continue                               # a formate member has no roll
            values[name] = v * (1.0 + scale * x)
        else:
            values[name] = v + scale * x
    dE, dP, dG, dS = xs[len(_FIELDS):]
    mis = gj.Misalignment.create(0.05 * dE, 0.05 * dP, 0.05 * dG, 0.01 * dS)
    return gj.with_fields(pair, values), mis


@pytest.mark.parametrize("name", TCA_EXAMPLES)
@settings(max_examples=HYPOID_EXAMPLES, **_SETTINGS)
@given(xs=_hypoid_perturbation())
def test_hypoid_example_perturbations_are_valid_or_flagged(name, xs):
    f = _tca_fn(name)
    pair, mis = _perturbed(f, xs)
    res = f(pair, mis)
    OUTCOMES[f"hypoid {name}: " + _check_result(res, (name, xs))] += 1
    fl = res.flags()
    OUTCOMES[f"hypoid {name}: crossing_flanks raised"] += fl["crossing_flanks"]
    # raised alone: a result that passed as valid before the flag existed
    OUTCOMES[f"hypoid {name}: crossing_flanks alone"] += (
        fl["crossing_flanks"] and fl["converged"] and fl["reference_on_flank"]
        and not any(v for k, v in fl.items()
                    if k not in ("converged", "reference_on_flank", "crossing_flanks")))


@pytest.mark.parametrize("name", NO_FLANK_EXAMPLES)
def test_example_without_flanks_is_refused(name):
    design = gj.load_design(f"example:{name}")
    with pytest.raises(ValueError, match=r"no \[pinion\.concave\] flank"):
        gj.run_tca(design, side="drive")


# ----------------------------------------------------------------------------- involute

@st.composite
def _involute_case(draw, z1, z2):
    u = lambda lo, hi: draw(st.floats(lo, hi, allow_nan=False))   # noqa: E731
    m = u(2.0, 6.0)
    design = dict(module=m, alpha=u(17.5, 25.0), helix=u(0.0, 30.0) * draw(st.sampled_from([0, 1])),
                  x1=u(-0.2, 0.4), x2=u(-0.2, 0.4), b=m * u(6.0, 12.0), dalpha=u(-0.05, 0.05),
                  profile_crown=u(0.0, 5e-4), lead_crown=math.exp(u(math.log(1e-5), math.log(2e-3))))
    mis = dict(dE=u(-0.05, 0.05), dP=u(-0.05, 0.05), dG=u(-0.05, 0.05),
               dSigma_deg=u(-0.2, 0.2) * draw(st.sampled_from([0, 1, 1])))
    return design, mis


def _involute(z1, z2, d, mis):
    pair = gj.involute.InvolutePair.create(z1, z2, d["module"], d["alpha"], d["helix"], d["x1"], d["x2"])
    des = gj.involute.InvoluteTCA.create(pair, d["b"], d["dalpha"], d["profile_crown"], d["lead_crown"])
    return des, gj.Misalignment.create(**mis)


def _face_end_carrying(res, face_width):
    """Pair 0 carries the load (active in the envelope, inside its flanks) at a grid
    point whose contact lies on a face end of pinion or gear (|axial| = b/2)."""
    k0 = np.asarray(res.multi.inside).shape[0] // 2
    carrying = np.asarray(res.multi.inside)[k0] & (np.asarray(res.multi.active) == k0)
    carrying &= np.asarray(res.path.converged)
    hb = 0.5 * face_width
    at_end = ((np.abs(np.abs(np.asarray(res.path.axial1)) - hb) < 1e-6)
              | (np.abs(np.abs(np.asarray(res.path.axial2)) - hb) < 1e-6))
    return bool(np.any(carrying & at_end))


@pytest.mark.parametrize("run", range(len(TOOTH_PAIRS)))
@settings(max_examples=INVOLUTE_EXAMPLES, **_SETTINGS)
@given(data=st.data())
def test_involute_designs_are_valid_flagged_or_refused(run, data):
    z1 = data.draw(st.integers(12, 40))
    z2 = data.draw(st.integers(z1, 4 * z1))
    d, m = data.draw(_involute_case(z1, z2))
    try:
        des, mis = _involute(z1, z2, d, m)
    except ValueError as exc:            # undercut, pointed teeth, interference
        msg = str(exc)
        assert "\n" not in msg and any(k in msg for k in ("x1", "x2", "module", "helix")), msg
        OUTCOMES["involute: refused"] += 1
        return
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        res = gj.run_tca(des, mis, throw=False, **INVOLUTE_OPTIONS)
    outcome = _check_result(res, (z1, z2, d, m))
    # face-end contact from the contact points' own coordinates
    face_end = res.flags()["face_end_contact"]
    assert face_end == _face_end_carrying(res, d["b"]), (d, m)
    OUTCOMES[f"involute: {outcome}"] += 1
    OUTCOMES["involute: face_end_contact raised"] += face_end


# ----------------------------------------------------------------------------- gradients

_GRADS = {}


def _grad_fn(key, f):
    if key not in _GRADS:
        _GRADS[key] = jax.jit(jax.value_and_grad(lambda p, mis: f(p, mis).ptp))
    return _GRADS[key]


def _converged(res):
    """A valid result for the gradient: every touching solve converged, the reference
    on the flanks and a finite peak-to-peak (quality flags such as edge contact at a
    hand-over or a grid too short for the contact ratio may be raised)."""
    f = res.flags()
    return f["converged"] and f["reference_on_flank"] and math.isfinite(float(res.ptp))


def _all_finite(tree):
    return all(bool(np.all(np.isfinite(np.asarray(x)))) for x in jax.tree_util.tree_leaves(tree))


GRADIENT_EXAMPLE = "spiral_bevel_10x30_synthesised"


@pytest.mark.parametrize("seed", GRADIENT_SEEDS)
def test_hypoid_ptp_gradient_is_finite_where_valid(seed):
    f = _tca_fn(GRADIENT_EXAMPLE)
    rng = np.random.default_rng(seed)
    xs = list(0.5 * rng.uniform(-1.0, 1.0, len(_FIELDS) + 4))    # half the fuzzed ranges
    pair, mis = _perturbed(f, xs)
    _check_result(res := f(pair, mis), (GRADIENT_EXAMPLE, seed))
    assert _converged(res), (seed, res.flags())
    value, grad = _grad_fn(GRADIENT_EXAMPLE, f)(pair, mis)
    assert math.isfinite(float(value))
    assert _all_finite(grad), (seed, grad)
    # the TE peak-to-peak moves with the pinion's settings (a gradient that is not all 0)
    assert float(jnp.abs(grad.pinion.machine.ratio_of_roll)) > 0.0
    OUTCOMES["gradient hypoid: finite"] += 1


@pytest.mark.parametrize("seed", GRADIENT_SEEDS)
def test_involute_ptp_gradient_is_finite_where_valid(seed):
    z1, z2 = TOOTH_PAIRS[0]
    rng = np.random.default_rng(seed)
    u = lambda lo, hi: float(rng.uniform(lo, hi))     # noqa: E731
    d = dict(module=u(2.0, 6.0), alpha=u(19.0, 23.0), helix=u(0.0, 30.0), x1=u(0.1, 0.4),
             x2=u(-0.1, 0.2), b=0.0, dalpha=u(-0.05, 0.05), profile_crown=u(1e-4, 5e-4),
             lead_crown=u(5e-4, 2e-3))
    d["b"] = d["module"] * 8.0
    m = dict(dE=u(-0.05, 0.05), dP=u(-0.05, 0.05), dG=u(-0.05, 0.05), dSigma_deg=u(-0.02, 0.02))
    des, mis = _involute(z1, z2, d, m)
    f = gj.tca_function(des, **INVOLUTE_OPTIONS)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        _check_result(res := f(des, mis), (d, m))
    assert _converged(res), (d, m, res.flags())
    value, grad = _grad_fn("involute", f)(des, mis)
    assert math.isfinite(float(value))
    assert _all_finite(grad), (d, m, grad)
    assert float(jnp.abs(grad.lead_crown)) + float(jnp.abs(grad.profile_crown)) > 0.0
    OUTCOMES["gradient involute: finite"] += 1
