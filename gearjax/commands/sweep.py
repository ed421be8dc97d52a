"""``gearjax sweep STUDY``: a study's quantities over many designs (docs/optimize.md, "Sweeps").

STUDY is a study file or ``example:NAME`` (as for ``gearjax optimize``); its ``[sweep]``
table (or the flags) chooses the designs: a Latin hypercube of ``--samples`` points
or a grid of ``--points`` values per variable inside the variables' bounds, plus the
design's own point as row 0.  The designs run in chunks through one compiled program
sharded across every local device (:mod:`gearjax.studies.sweep`).  Progress per
chunk on stderr; a summary on stdout; ``--out`` (default ``./NAME_sweep``) receives
``NAME_sweep.npz`` (the columns below) and ``NAME_sweep.png`` (the objective against
each variable; ``--no-plot``: none).

Exit status: 0 (the sweep ran; rows whose TCA did not converge, touch at an edge or give
a quantity that is not finite are written with ``ok`` false and counted in a warning
line), 2 bad input.
"""

from __future__ import annotations

import argparse
import io
import os
import sys

NPZ_KEYS_DOC = """Arrays of NAME_sweep.npz (numpy.load; one row per design, row 0 the design
itself):
  x                 (n, nv) the variables in the study file's units (order: variables)
  u                 (n, nv) the same, scaled as the optimiser sees them
  x:FIELD           (n,) one variable's column
  values            (n, S, nq) the quantities at the S scenarios (order: quantities)
  q:QUANTITY        (n, S) one quantity's values
  flag:NAME         (n, S) the TCA's quality flags: converged, edge_contact, tip_contact,
                    face_end_contact, low_contact_ratio, large_te, crossing_flanks
  n_valid           (n, S) valid positions of the cycle (loaded studies only)
  ok                (n,) every scenario converged without edge contact and without a load
                    carried where the flanks cross, every quantity finite
  feasible          (n,) ok and every constraint of the study holds
  J                 (n,) the study's objective (scaled by row 0's values; lower is better)
  variables, units, quantities   names (units: "field" the field's own mm/rad/-, or "deg")
  scenario:KEY      (S,) torque_Nm, pinion_rpm, dE_mm, dP_mm, dG_mm, dSigma_deg
  meta              JSON text: study, design, method, samples or points, seed, chunk,
                    devices, designs, seconds (evaluation, compilation included),
                    first_chunk_seconds, designs_per_s (after the first chunk; null with
                    one chunk)
"""


def register(sub):
    p = sub.add_parser(
        "sweep", help="evaluate a study's quantities over a sample or grid of designs",
        description="Evaluate the quantities of a study file at a Latin-hypercube sample or a "
                    "grid of designs inside its variables' bounds, in batches (vmap) sharded "
                    "across every device.",
        epilog=NPZ_KEYS_DOC, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("study", help="study file (.toml) or example:NAME")
    p.add_argument("--method", choices=["random", "grid"], default=None,
                   help="override [sweep] method (default random)")
    p.add_argument("--samples", type=int, default=None,
                   help="override [sweep] samples: designs of a random sweep (>= 1)")
    p.add_argument("--points", type=int, default=None,
                   help="override [sweep] points: values per variable of a grid (>= 2)")
    p.add_argument("--seed", type=int, default=None, help="override [sweep] seed (>= 0)")
    p.add_argument("--chunk", type=int, default=None,
                   help="override [sweep] chunk: designs per batch (>= 1; rounded up to a "
                        "multiple of the device count)")
    p.add_argument("--out", default=None,
                   help="output directory (created if missing; default ./NAME_sweep)")
    p.add_argument("--no-plot", action="store_true", help="do not write the figure")
    p.set_defaults(func=run)


def _settings(study, args) -> dict:
    sw = dict(study.sweep)
    for key, lo in (("samples", 1), ("points", 2), ("seed", 0), ("chunk", 1)):
        v = getattr(args, key)
        if v is not None:
            if v < lo:
                raise ValueError(f"--{key} = {v} is outside the allowed range [{lo}, inf)")
            sw[key] = v
    if args.method is not None:
        sw["method"] = args.method
    return sw


def run(args) -> int:
    from gearjax.commands import output_dir
    from gearjax.studies.study_file import read_study
    from gearjax.studies.sweep import check_design_count
    study = read_study(args.study)
    sw = _settings(study, args)
    check_design_count(sw["method"], sw["samples"], sw["points"], len(study.variables))
    out = output_dir(args.out or f"{study.name}_sweep", study.name,
                     ("_sweep.npz", "_sweep.png"))
    return _run(study, sw, out, args)


def _run(study, sw, out, args) -> int:
    import numpy as np

    from gearjax.io import atomic_write, atomic_write_figure
    from gearjax.progress import Progress
    from gearjax.studies.sweep import (npz_columns, run_sweep, sample_points, set_up_sweep,
                                       steady_rate)

    with Progress(1, f"sweep {study.name}") as bar:
        with bar.phase("setting up the design"):
            prob = set_up_sweep(study)
            U = sample_points(prob.lower, prob.upper, sw["method"], samples=sw["samples"],
                              points=sw["points"], seed=sw["seed"])
    n = U.shape[0]
    with Progress(n, f"sweep {study.name}: designs") as bar:
        done = [0]

        def progress(k, total):
            bar.update(k - done[0])
            done[0] = k

        with bar.phase("evaluating"):
            r = run_sweep(prob, U, chunk=sw["chunk"], progress=progress)
    rate = steady_rate(n, r.chunk, r.seconds, r.first_chunk_seconds)
    meta = {"study": study.name, "design": study.design, "method": sw["method"],
            "seed": sw["seed"], "chunk": r.chunk, "devices": r.devices, "designs": n,
            "seconds": r.seconds, "first_chunk_seconds": r.first_chunk_seconds,
            "designs_per_s": rate}
    meta["samples" if sw["method"] == "random" else "points"] = sw[
        "samples" if sw["method"] == "random" else "points"]
    cols = npz_columns(prob, r, meta)
    buf = io.BytesIO()
    np.savez(buf, **cols)
    files = [os.path.join(out, f"{study.name}_sweep.npz")]
    atomic_write(files[0], buf.getvalue())
    if not args.no_plot:
        from gearjax.plot.study import sweep_figure
        names = [v.field + ("" if not v.unit else f" ({v.unit})") for v in study.variables]
        fig = sweep_figure(names, r.x, r.J, r.ok, r.feasible,
                           f"{study.name}: {n} designs ({sw['method']})")
        files.append(os.path.join(out, f"{study.name}_sweep.png"))
        atomic_write_figure(fig, files[-1])
    print(_summary(prob.study, r, meta))
    print(f"files: {', '.join(files)}")
    bad = int(np.sum(~r.ok))
    if bad:
        sys.stderr.write(f"gearjax: warning: {bad} of {n} designs are flagged (TCA not "
                         "converged, edge contact or a quantity not finite): ok = false in "
                         "the file\n")
    return 0


def _summary(study, r, meta) -> str:
    import numpy as np

    from gearjax.studies.sweep import best_row
    rate = meta["designs_per_s"]
    lines = [f"sweep {study.name}: {meta['designs']} designs ({meta['method']}), "
             f"{r.devices} device(s), chunk {r.chunk}, {r.seconds:.1f} s (first chunk, with "
             f"compilation: {r.first_chunk_seconds:.1f} s"
             + ("" if rate is None else f"; then {rate:.3g} designs/s") + ")",
             f"ok {int(np.sum(r.ok))}, feasible {int(np.sum(r.feasible))}", "",
             f"{'quantity (mean over scenarios)':34s} {'the design':>12s} {'min':>12s} "
             f"{'median':>12s} {'max':>12s}  (ok designs)"]
    mean = np.mean(r.values, axis=1)
    for j, q in enumerate(study.quantities):
        v = mean[r.ok, j]
        stats = (np.min(v), np.median(v), np.max(v)) if v.size else (np.nan,) * 3
        lines.append(f"{q:34s} {mean[0, j]:12.6g} " + " ".join(f"{s:12.6g}" for s in stats))
    b = best_row(r.J, r.feasible)
    if b is not None:
        lines += ["", f"best feasible design: row {b}, J {r.J[b]:.6g} (the design: "
                  f"{r.J[0]:.6g})"]
        for i, v in enumerate(study.variables):
            lines.append(f"  {v.field:40s} {r.x[0, i]:14.8g} -> {r.x[b, i]:14.8g}")
    else:
        lines += ["", "no feasible design in the sweep"]
    return "\n".join(lines)
