"""``gearjax warmup``: run the main jobs once on the packaged examples, so that a user's
first runs find their programs traced (program store) and compiled (compilation cache).

A program is keyed by its family, grid and shapes, not by the design's numbers
(gearjax/program_store.py): after the hypoid example's ``gearjax tca``, the first
``gearjax tca`` of another hypoid pair with the same structure reads its programs
instead of tracing and compiling them (8/43 example cold 8.2 s, then the 10/41 pair's
first run 3.5 s, 2-core CPU).  For an installation step (a container image, a shared
machine): run it once after ``pip install``.  Needs the cache (``GEARJAX_CACHE_DIR``
not off).
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
import time

#: name -> (what it warms, the gearjax argv)
JOBS = {
    "tca-hypoid": ("gearjax tca, hypoid (generated pinion, formate gear)",
                   ["tca", "example:hypoid_iso_10x41_synthesised"]),
    "tca-spiral-bevel": ("gearjax tca, spiral bevel (no offset)",
                         ["tca", "example:spiral_bevel_10x30_synthesised"]),
    "tca-vh-catt": ("gearjax tca, VH-CATT", ["tca", "example:vh_catt_17x23"]),
    "tca-preset-bevel": ("gearjax tca, preset-TE bevel", ["tca", "example:preset_te_bevel_10x30"]),
    "tca-involute": ("gearjax tca, spur (KHK 12/24)", ["tca", "example:khk_spur_12x24"]),
    "efficiency-hypoid": ("gearjax efficiency, hypoid 10/41",
                          ["efficiency", "example:hypoid_iso_10x41_synthesised",
                           "--torque-Nm", "200", "--rpm", "1000", "--oil", "mineral_vg100",
                           "--sigma-um", "0.4"]),
    "efficiency-involute": ("gearjax efficiency, spur (KHK 12/24)",
                            ["efficiency", "example:khk_spur_12x24", "--torque-Nm", "60",
                             "--rpm", "3000", "--oil", "mineral_vg100", "--sigma-um", "0.4"]),
}


def register(sub):
    p = sub.add_parser(
        "warmup", help="trace and compile the main jobs' programs once (an install step)",
        description=__doc__.splitlines()[0] + "  Jobs: " + "; ".join(
            f"{k}: {v[0]}" for k, v in JOBS.items()) + ".")
    p.add_argument("--jobs", default="all",
                   help="comma-separated job names or 'all' (default; --list shows them)")
    p.add_argument("--list", action="store_true", help="list the jobs and exit")
    p.set_defaults(func=run)


def _jobs(spec: str) -> list:
    names = list(JOBS) if spec.strip() == "all" else [j.strip() for j in spec.split(",")]
    unknown = [j for j in names if j not in JOBS]
    if unknown or not names:
        raise ValueError(f"--jobs = {spec!r}: unknown job {unknown[0] if unknown else ''!r} "
                         f"(allowed: all, {', '.join(JOBS)})")
    return names


def run(args) -> int:
    import gearjax.program_store as program_store
    from gearjax import cli

    if args.list:
        for k, (what, argv) in JOBS.items():
            sys.stdout.write(f"{k:20s} {what}: gearjax {' '.join(argv)}\n")
        return 0
    names = _jobs(args.jobs)
    store = program_store.directory()
    if store is None:
        raise ValueError("gearjax warmup needs the program store and compilation cache: "
                         "GEARJAX_CACHE_DIR is off (or GEARJAX_PROGRAM_STORE=0)")
    before = len(list(store.glob("*.prog")))
    failed = []
    t_all = time.perf_counter()
    for i, name in enumerate(names):
        t = time.perf_counter()
        sys.stderr.write(f"gearjax warmup: [{i + 1}/{len(names)}] {name} ... ")
        sys.stderr.flush()
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            rc = cli.main(JOBS[name][1])
        sys.stderr.write(f"{time.perf_counter() - t:.1f} s" + ("" if rc == 0 else
                                                                f" (exit {rc})") + "\n")
        if rc != 0:
            last = (err.getvalue().strip().splitlines() or ["no message"])[-1]
            failed.append(f"{name}: {last}")
    after = len(list(store.glob("*.prog")))
    sys.stdout.write(f"warmed {len(names) - len(failed)} of {len(names)} jobs in "
                     f"{time.perf_counter() - t_all:.1f} s; programs stored: {after} "
                     f"({after - before} new) in {store}{os.sep}\n")
    for f in failed:
        sys.stderr.write(f"gearjax: warning: warmup job failed: {f}\n")
    return 1 if failed else 0
