"""The cost guard: the work of the compiled TCA and efficiency programs against a
recorded baseline (tests/cost_baseline.json), without timing anything.

Two kinds of measure, both deterministic on one JAX version and XLA flag set:

* ``newton_work`` -- the Newton iterations a TCA executed
  (:attr:`gearjax.tca.path.ContactPath.newton_work`: every ``vmap``-ed lane counted for as
  long as its batch's slowest lane runs).  The TCA's run time is this count times a
  nearly constant cost per iteration; the edge search that made the involute TCA 30x
  slower (issue [D]) raised it from 179 to 5619 on the crowned 25/41 pair.  Up to
  round-off of the iteration counts (the suite's XLA flags, tests/conftest.py).
* ``flops``, ``transcendentals``, ``bytes accessed`` -- XLA's cost analysis of the
  lowered program (no compilation): the size of the graph, each loop body counted
  once.  A larger graph (more candidates, a solve traced twice) shows here.

A measure more than ``UP`` times its baseline fails (a regression); one below
``DOWN`` times fails too (an improvement: record it, so that the guard stays tight).
The baseline is updated on purpose, never by a normal run:

    GEARJAX_RECORD_COST=1 python -m pytest -n 0 tests/test_cost_guard.py tests/test_tca.py \
        tests/test_edge_contact.py tests/test_vh_catt.py tests/test_preset_bevel_tca.py -k cost

which rewrites the entries those tests measure (and nothing else) and records the
JAX version.  The static measures get a wider band: they move a little with the JAX
version that lowers the program, and a tight one (``SAME_VERSION_BANDS``) on the version
the baseline was recorded with.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import jax

BASELINE = Path(__file__).with_name("cost_baseline.json")
RECORD = os.environ.get("GEARJAX_RECORD_COST") == "1"
#: allowed ratio measured / baseline per measure (regression above UP, re-record below DOWN)
BANDS = {"newton_work": (0.8, 1.25), "flops": (0.67, 1.5), "transcendentals": (0.67, 1.5),
         "bytes accessed": (0.67, 1.5)}
#: the static measures on the JAX version the baseline was recorded with: the lowered
#: program is the same operations, so its cost analysis moves only when the code does
#: (the kinematics' Jacobian route in place of the curvature route is 1.4x the
#: spiral-bevel TCA's flops, inside the wide band)
SAME_VERSION_BANDS = {"flops": (0.85, 1.2), "transcendentals": (0.85, 1.2),
                      "bytes accessed": (0.85, 1.2)}
HOW = ("GEARJAX_RECORD_COST=1 python -m pytest -n 0 <the test files> -k cost "
       "(tests/cost_guard.py)")


def _load() -> dict:
    if not BASELINE.exists():
        return {"jax": None, "programs": {}}
    return json.loads(BASELINE.read_text())


def static_cost(fn, *args) -> dict:
    """XLA's cost analysis of ``jax.jit(fn)`` lowered at ``args`` (no compilation)."""
    ca = jax.jit(fn).lower(*args).cost_analysis()
    if isinstance(ca, (list, tuple)):
        ca = ca[0]
    return {k: float(ca[k]) for k in ("flops", "transcendentals", "bytes accessed")}


def check_cost(name: str, **measures) -> None:
    """Compare ``measures`` (name -> number) of program ``name`` with the baseline (or
    record them with ``GEARJAX_RECORD_COST=1``)."""
    measures = {k.replace("_accessed", " accessed"): float(v) for k, v in measures.items()}
    data = _load()
    if RECORD:
        data["jax"] = jax.__version__
        data.setdefault("programs", {}).setdefault(name, {}).update(measures)
        tmp = BASELINE.with_suffix(".json.tmp")
        tmp.write_text(json.dumps(data, indent=2, sort_keys=True) + "\n")
        os.replace(tmp, BASELINE)
        return
    entry = data["programs"].get(name)
    assert entry is not None, f"no cost baseline for {name!r}: record it with {HOW}"
    for key, value in measures.items():
        assert key in entry, f"no cost baseline for {name!r} {key}: record it with {HOW}"
        same = data.get("jax") == jax.__version__
        lo, hi = (SAME_VERSION_BANDS if same else {}).get(key, BANDS[key])
        ratio = value / entry[key]
        assert ratio <= hi, (f"{name}: {key} {value:.6g} is {ratio:.2f}x its baseline "
                             f"{entry[key]:.6g} (allowed {hi}x): a cost regression")
        assert ratio >= lo, (f"{name}: {key} {value:.6g} is {ratio:.2f}x its baseline "
                             f"{entry[key]:.6g}: cheaper than recorded -- record the new "
                             f"baseline on purpose with {HOW}")
