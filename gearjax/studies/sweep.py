"""Design sweeps: a study's quantities over many designs at once (``gearjax sweep``).

A sweep evaluates the quantities of a study file (:mod:`gearjax.studies.study_file`:
its design, ``[[variables]]`` with their bounds, objective, constraints and scenarios)
at a set of designs inside the variables' box:

* ``method = "random"``: a Latin hypercube of ``samples`` points (each variable's range
  cut into ``samples`` equal strata, one point per stratum, the strata paired by seeded
  random permutations; McKay, Beckman & Conover, Technometrics 21 (1979) 239-245);
* ``method = "grid"``: ``points`` equally spaced values per variable, every combination
  (``points ** n_variables`` designs, the last variable fastest).

Row 0 is always the design's own point (the reference the rows are compared with).

**Batches, devices, memory.**  The designs go through one compiled program in chunks of
``chunk`` rows: ``jax.vmap`` of the study's evaluator (every scenario of a row in the
same call) over the rows of a chunk, the rows laid out across every device (those of
this process; with ``jax.distributed``, those of every process)
(``jax.sharding``: a one-axis mesh ``designs``, the rows sharded, the design data
replicated), so that XLA runs each device's share of the rows on that device; the
rows come back to the host (from every process of a ``jax.distributed`` run).  The
chunk is rounded up to a multiple of the device count (the last chunk padded by
repeating its last row; the padding is dropped); only one chunk's results are on the
devices at a time, so memory does not grow with the number of designs.  On a CPU,
``XLA_FLAGS=--xla_force_host_platform_device_count=N`` splits the host into N devices
(each runs on its own thread); several GPUs are used as they are.  Several hosts: start
one process per host with ``jax.distributed.initialize()`` (docs/optimize.md, "Sweeps").

**Quantities and flags.**  Loaded quantities use the hard model (no edge softening,
:func:`set_up_sweep`).  The path quantities (|SRR|, R_x, margins) of a row are taken
over its own on-flank points (no optimiser moves them; contrast the fixed mask of a
study).  Every row carries per scenario the TCA's quality flags
(:meth:`gearjax.tca.result.TCAResult.flags`) and, for a loaded study, the number of
valid positions of the cycle; ``ok`` is: every scenario's TCA converged without edge
contact and every quantity is finite.  ``feasible``: ``ok`` and every constraint holds.
``J``: the study's objective (:func:`gearjax.studies.study_run.combine`) with the
default scales of the reference row (NaN where a row's quantity is not finite).
"""

from __future__ import annotations

import dataclasses
import json
import time
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec

from gearjax.compile_ahead import FAST_COMPILE_OPTIONS
from gearjax.studies.end_checks import scenario_flags, scenario_of
from gearjax.studies.study_run import Problem, combine, evaluator, set_scales

__all__ = ["SweepResult", "set_up_sweep", "check_design_count", "sample_points",
           "sweep_program", "run_sweep", "chunk_flags", "npz_columns", "chunk_size",
           "steady_rate", "best_row", "file_units", "sweep_constraints", "MAX_DESIGNS",
           "FLAG_KEYS", "rows_ok"]

#: most designs one sweep may ask for (a grid's points ** n_variables included)
MAX_DESIGNS = 1_000_000
#: the TCA flags a sweep records per row and scenario
FLAG_KEYS = ("converged", "edge_contact", "tip_contact", "face_end_contact",
             "low_contact_ratio", "large_te", "crossing_flanks")


def set_up_sweep(study) -> Problem:
    """:func:`gearjax.studies.study_run.set_up` for a sweep: the loaded quantities with
    the hard model (``edge_softening_mm = 0``, that of ``gearjax efficiency``) -- the
    soft active set exists for an optimiser's gradients, which a sweep does not take.
    A kinematics study (:mod:`gearjax.studies.kinematics_route`) is swept as it is (one
    scenario, its flags: converged; the TCA's other flags False), and so is a
    line-contact study (:mod:`gearjax.studies.line_route`, whose exact load solution
    has no softened model; flags: every position converged -- with the efficiency,
    every loaded point's friction too --, the TCA's other flags False, ``n_valid`` the
    converged positions)."""
    from gearjax.studies.study_run import set_up
    if study.route != "tca":
        return set_up(study)
    return set_up(dataclasses.replace(study, operating={**study.operating,
                                                        "edge_softening_mm": 0.0}))


def check_design_count(method: str, samples: int, points: int, n_variables: int) -> None:
    """One-line ``ValueError`` when a sweep would ask for more than :data:`MAX_DESIGNS`
    designs (a grid's ``points ** n_variables`` included) or names an unknown method."""
    if method == "grid":
        n = points ** n_variables
        if n > MAX_DESIGNS:
            raise ValueError(f"[sweep] points = {points}: {n} designs for {n_variables} "
                             f"variables is more than {MAX_DESIGNS}")
    elif method == "random":
        if samples > MAX_DESIGNS:
            raise ValueError(f"[sweep] samples = {samples} is more than {MAX_DESIGNS}")
    else:
        raise ValueError(f"[sweep] method = {method!r} must be one of 'random', 'grid'")


def sample_points(lower, upper, method: str, *, samples: int = 64, points: int = 5,
                  seed: int = 0) -> np.ndarray:
    """``(n, nv)`` points in the box ``[lower, upper]`` (module docstring); row 0 is the
    origin (the design's own point; ``lower <= 0 <= upper``), then the sample."""
    lower, upper = np.asarray(lower, float), np.asarray(upper, float)
    nv = lower.size
    check_design_count(method, samples, points, nv)
    if method == "grid":
        axes = [np.linspace(lower[i], upper[i], points) for i in range(nv)]
        pts = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, nv)
    else:                                              # "random"
        rng = np.random.default_rng(seed)
        strata = np.stack([rng.permutation(samples) for _ in range(nv)], axis=1)
        frac = (strata + rng.uniform(size=(samples, nv))) / samples
        pts = lower + frac * (upper - lower)
    return np.vstack([np.zeros((1, nv)), pts])


def sweep_program(prob: Problem, devices=None):
    """``(program, rows, n_devices)``: ``program(U, data)`` the study's evaluator (own
    masks) vmapped over the rows of ``U`` (a chunk, its length a multiple of
    ``n_devices``), the rows sharded over ``devices`` (default ``jax.devices()``: every
    device of every process of a ``jax.distributed`` run; a process's own devices
    otherwise), ``data`` replicated; ``rows`` the sharding of ``U``.  Returns what
    :func:`gearjax.studies.study_run.evaluator` returns, with a leading row axis."""
    devs = list(jax.devices() if devices is None else devices)
    mesh = Mesh(np.array(devs), ("designs",))
    rows = NamedSharding(mesh, PartitionSpec("designs"))
    every = NamedSharding(mesh, PartitionSpec())
    ev = evaluator(prob, own_mask=True)
    prog = jax.jit(jax.vmap(ev, in_axes=(0, None)), in_shardings=(rows, every),
                   out_shardings=rows, compiler_options=FAST_COMPILE_OPTIONS)
    return prog, rows, len(devs)


def _to_host(tree):
    """NumPy copies of a program's outputs: every row, also those on other processes'
    devices (a ``jax.distributed`` run gathers them)."""
    if jax.process_count() == 1:
        return jax.tree_util.tree_map(np.asarray, tree)
    from jax.experimental import multihost_utils
    return multihost_utils.process_allgather(tree, tiled=True)


def chunk_size(chunk: int, n_devices: int) -> int:
    """Rows per batch: ``chunk`` (at least 1) rounded up to a multiple of the device count
    (every device gets the same number of rows)."""
    return -(-max(int(chunk), 1) // n_devices) * n_devices


def steady_rate(n: int, chunk: int, seconds: float, first_chunk_seconds: float):
    """Designs per second after the first chunk (which carries the compilation), the
    rate a long sweep sees; None when there is only one chunk."""
    later = n - min(chunk, n)
    return later / max(seconds - first_chunk_seconds, 1e-9) if later > 0 else None


def best_row(J, feasible):
    """Index of the feasible row of the smallest ``J`` (None when no row is feasible)."""
    rows = np.flatnonzero(np.asarray(feasible, bool))
    return int(rows[np.argmin(np.asarray(J)[rows])]) if rows.size else None


def file_units(prob: Problem, U) -> np.ndarray:
    """``(n, nv)`` the scaled points ``U`` as the study file writes the variables (the
    field's units, or degrees for ``unit = "deg"``)."""
    U = np.asarray(U, float)
    scale = np.asarray(prob.data.scale)
    return np.stack([(prob.x0[i] + scale[i] * U[:, i]) / v.factor
                     for i, v in enumerate(prob.study.variables)], axis=1)


def sweep_constraints(study) -> tuple:
    """The study's constraints a sweep checks: all but the one the study adds for its
    fixed mask (``min_margin_mm >= 0``, ``added``); a file's own margin constraint stays."""
    return tuple(c for c in study.constraints
                 if not (c.added and c.quantity == "min_margin_mm"))


class SweepResult(NamedTuple):
    """What :func:`run_sweep` found; arrays have one row per design (row 0: the design's
    own point), ``S`` scenarios, the study's ``quantities`` in order."""

    u: np.ndarray             # (n, nv) scaled variables
    x: np.ndarray             # (n, nv) variables in the study file's units
    values: np.ndarray        # (n, S, nq)
    flags: dict               # FLAG_KEYS -> (n, S) bool
    n_valid: np.ndarray | None  # (n, S) valid positions of the cycle (loaded studies)
    ok: np.ndarray            # (n,)
    feasible: np.ndarray      # (n,)
    J: np.ndarray             # (n,)
    seconds: float            # wall time of the evaluation (compilation included)
    first_chunk_seconds: float  # of the first chunk (the compilation, when not cached)
    devices: int
    chunk: int


def run_sweep(prob: Problem, U, chunk: int = 16, devices=None, progress=None) -> SweepResult:
    """Evaluate the study ``prob`` (:func:`gearjax.studies.study_run.set_up`) at the
    scaled points ``U`` (:func:`sample_points`) in chunks (module docstring).
    ``progress(done, total)`` after each chunk (or None)."""
    U = np.asarray(U, float)
    n = U.shape[0]
    prog, sharding, nd = sweep_program(prob, devices)
    c = chunk_size(chunk, nd)
    data = prob.data
    vals, flags, nval = [], {k: [] for k in FLAG_KEYS}, []
    t0 = time.time()
    first = None
    for a in range(0, n, c):
        rows = U[a:a + c]
        k = rows.shape[0]
        if k < c:
            rows = np.vstack([rows, np.repeat(rows[-1:], c - k, axis=0)])
        # every process holds U: each gives the rows of its own devices
        chunk_u = jax.make_array_from_callback(rows.shape, sharding, lambda idx: rows[idx])
        Q, res, eff, _ = prog(chunk_u, data)
        # the padding rows dropped from every output at once; of a loaded TCA study's
        # efficiency only the valid counts come back (a line study's flags read its
        # per-position validity)
        if eff is not None and prob.route == "tca":
            eff = eff.n_valid
        Q, res, eff = jax.tree_util.tree_map(lambda v: v[:k], _to_host((Q, res, eff)))
        rows_flags, rows_valid = chunk_flags(prob, res, eff)
        for key in FLAG_KEYS:
            flags[key] += rows_flags[key]
        if rows_valid is not None:
            nval += rows_valid
        vals.append(Q)
        if first is None:
            first = time.time() - t0
        if progress is not None:
            progress(min(a + c, n), n)
    seconds = time.time() - t0
    values = np.concatenate(vals)
    flags = {k: np.asarray(v, bool) for k, v in flags.items()}       # (n, S): row, scenario
    ok = rows_ok(flags, values)
    J, feasible = _objective_and_feasibility(prob, values, ok)
    n_valid = np.asarray(nval, int) if nval else None
    return SweepResult(U, file_units(prob, U), values, flags, n_valid, ok, feasible, J, seconds,
                       first, nd, c)


def chunk_flags(prob: Problem, res, eff):
    """``(flags, n_valid)`` of a chunk's rows on the host: ``flags[key]`` one list per row
    of the scenarios' :data:`FLAG_KEYS` (a flag a route does not have -- the line
    contact and the kinematics have no edge contact -- is False), ``n_valid`` one list
    per row of the scenarios' valid positions (None where the route counts none).
    ``res``, ``eff``: the program's outputs with a leading row axis (a loaded TCA
    study's ``eff``: its ``n_valid`` counts alone)."""
    flags, nval = {key: [] for key in FLAG_KEYS}, []
    n = jax.tree_util.tree_leaves(res)[0].shape[0]
    for i in range(n):
        row_eff = None if eff is None else scenario_of(eff, i)
        if prob.route == "tca" and row_eff is not None:
            row_eff = _Counts(row_eff)
        one = scenario_flags(prob, scenario_of(res, i), row_eff)
        for key in FLAG_KEYS:
            flags[key].append([f.get(key, False) for f in one])
        if "n_valid" in one[0]:
            nval.append([f["n_valid"] for f in one])
    return flags, (nval if nval else None)


def rows_ok(flags: dict, values: np.ndarray) -> np.ndarray:
    """``ok`` per row: at every scenario converged, without edge contact and without a
    load carried where the flanks cross (``flags[key]`` (n, S) bool, :data:`FLAG_KEYS`),
    and every quantity finite (``values`` (n, S, nq))."""
    return (np.all(flags["converged"] & ~flags["edge_contact"] & ~flags["crossing_flanks"],
                   axis=1)
            & np.all(np.isfinite(values), axis=(1, 2)))


class _Counts(NamedTuple):
    """A row's valid-position counts where the flags expect the efficiency result."""

    n_valid: np.ndarray


def _objective_and_feasibility(prob: Problem, values, ok):
    """``J`` per row (the study's objective, scales from row 0 when its quantities are
    finite, else 1) and ``feasible`` (``ok`` and every scaled constraint <= 0).  The
    constraint a study adds for its fixed mask (``min_margin_mm >= 0``) is left out: a
    sweep's own on-flank points are on the flank by definition, and the smooth minimum
    lies below the true one by up to its ``T log n``."""
    st = prob.study
    prob = dataclasses.replace(prob, study=dataclasses.replace(
        st, constraints=sweep_constraints(st)))
    # the reduced study's quantities in its own order (combine reads them by position)
    values = values[:, :, [st.quantities.index(q) for q in prob.study.quantities]]
    try:
        set_scales(prob, values[0])
    except ValueError:
        pass                                           # row 0 not finite: unit scales
    Jg = jax.jit(jax.vmap(lambda Q: combine(prob.study, Q, prob.data)))
    J, g = (np.asarray(a) for a in Jg(jnp.asarray(values)))
    feasible = ok & np.all(g <= 0.0, axis=1) if g.shape[1] else ok.copy()
    return J, feasible


def npz_columns(prob: Problem, r: SweepResult, meta: dict) -> dict:
    """The arrays of ``NAME_sweep.npz`` (keys in ``gearjax sweep --help``)."""
    st = prob.study
    out = {"x": r.x, "u": r.u, "values": r.values, "ok": r.ok, "feasible": r.feasible,
           "J": r.J, "variables": np.array([v.field for v in st.variables]),
           "units": np.array([v.unit or "field" for v in st.variables]),
           "quantities": np.array(st.quantities),
           "meta": np.array(json.dumps(meta))}
    for i, v in enumerate(st.variables):
        out[f"x:{v.field}"] = r.x[:, i]
    for j, q in enumerate(st.quantities):
        out[f"q:{q}"] = r.values[:, :, j]
    for k, v in r.flags.items():
        out[f"flag:{k}"] = v
    if r.n_valid is not None:
        out["n_valid"] = r.n_valid
    for key in prob.scenarios[0]:
        out[f"scenario:{key}"] = np.array([s[key] for s in prob.scenarios], float)
    return out
