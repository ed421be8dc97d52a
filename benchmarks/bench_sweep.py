"""Benchmark: design sweeps (``gearjax sweep``) over 1, 2, 4, ... devices.

Each run is a fresh process that runs the console command ``gearjax sweep STUDY
--samples N --chunk C --no-plot`` with ``GEARJAX_CACHE_DIR=off`` (no persistent
compilation cache) and, on a CPU, the host split into ``D`` devices by
``XLA_FLAGS=--xla_force_host_platform_device_count=D``; on a GPU machine
(``--gpu``) the devices are the GPUs, and ``D`` is their number.  The table gives, from
the command's own ``meta``: the first chunk's time (tracing, compilation, the first
rows), the rate after it (designs per second: the steady state a long sweep sees),
the whole evaluation, and the process's wall time.  The numbers of every run must
agree (``values`` within 1e-11 relative of the one-device run); a disagreement is
printed.

Usage::

    python benchmarks/bench_sweep.py                                  # 1, 2, 4 host devices
    python benchmarks/bench_sweep.py --devices 1,2 --samples 127 --chunk 32
    python benchmarks/bench_sweep.py --study example:spur_efficiency  # the loaded chain
    python benchmarks/bench_sweep.py --gpu                             # the GPUs as they are
    python benchmarks/bench_sweep.py --memory 8,16,64     # the program's memory by chunk

Results of past runs: ``benchmarks/results/sweep.md``.  Benchmarks are never tests.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

RUN = ("import sys; from gearjax.cli import main, _fast_compile_flags; "
       "_fast_compile_flags(); sys.exit(main(sys.argv[1:]))")


def one(study, samples, chunk, devices, gpu) -> dict:
    env = dict(os.environ, GEARJAX_CACHE_DIR="off", GEARJAX_PROGRESS="0")
    if not gpu:
        env["XLA_FLAGS"] = (env.get("XLA_FLAGS", "")
                            + f" --xla_force_host_platform_device_count={devices}")
        env["JAX_PLATFORMS"] = "cpu"
    with tempfile.TemporaryDirectory() as out:
        t = time.time()
        run = subprocess.run([sys.executable, "-c", RUN, "sweep", study, "--samples",
                              str(samples), "--chunk", str(chunk), "--no-plot", "--out", out],
                             env=env, capture_output=True, text=True)
        wall = time.time() - t
        if run.returncode != 0:
            raise SystemExit(f"sweep failed:\n{run.stderr[-3000:]}")
        name = next(p for p in os.listdir(out) if p.endswith("_sweep.npz"))
        d = np.load(Path(out) / name)
        meta = json.loads(str(d["meta"]))
        return dict(meta, wall_s=wall, values=d["values"])


def memory_by_chunk(study, chunks) -> list:
    """``[(chunk, program_memory)]``: XLA's memory account of the sweep's program
    (one device, this process) at each chunk size -- what a sweep holds at once, which
    must not depend on how many designs it evaluates."""
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import jax
    from program_memory import program_memory

    from gearjax.studies.study_file import read_study
    from gearjax.studies.sweep import set_up_sweep, sweep_program

    prob = set_up_sweep(read_study(study))
    prog, _, _ = sweep_program(prob, jax.devices()[:1])
    n = len(prob.x0)
    out = []
    for c in chunks:
        U = jax.ShapeDtypeStruct((c, n), np.float64)
        out.append((c, program_memory(prog.trace(U, prob.data).lower().compile())))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--study", default="example:spur_sliding")
    ap.add_argument("--devices", default="1,2,4", help="host device counts (CPU)")
    ap.add_argument("--samples", type=int, default=63)
    ap.add_argument("--chunk", type=int, default=16)
    ap.add_argument("--gpu", action="store_true", help="use the GPUs as they are")
    ap.add_argument("--memory", default=None,
                    help="chunk sizes (e.g. 8,16,64): XLA's memory account of the sweep "
                         "program at each, instead of the timings")
    args = ap.parse_args(argv)
    if args.memory:
        print(f"{args.study}: the sweep program's memory (MB) by chunk, one device")
        print("| chunk | arguments | outputs | temporaries | peak |")
        print("|---:|---:|---:|---:|---:|")
        for c, m in memory_by_chunk(args.study, [int(c) for c in args.memory.split(",")]):
            print(f"| {c} | {m['args']:.3f} | {m['out']:.3f} | {m['temp']:.2f} | {m['peak']:.2f} |")
        return
    counts = [0] if args.gpu else [int(c) for c in args.devices.split(",")]
    rows, ref = [], None
    for d in counts:
        r = one(args.study, args.samples, args.chunk, d, args.gpu)
        if ref is None:
            ref = r["values"]
        elif not np.allclose(r["values"], ref, rtol=1e-11, atol=1e-13, equal_nan=True):
            print(f"DISAGREEMENT with {r['devices']} devices: largest difference "
                  f"{np.nanmax(np.abs(r['values'] - ref)):.3g}")
        rows.append(r)
        print(f"{r['devices']} device(s): first chunk {r['first_chunk_seconds']:.2f} s, then "
              f"{r['designs_per_s'] or float('nan'):.3g} designs/s; evaluation "
              f"{r['seconds']:.2f} s; process {r['wall_s']:.2f} s", flush=True)
    print(f"\n{args.study}, {rows[0]['designs']} designs, chunk {args.chunk}; "
          f"{platform.machine()}, {os.cpu_count()} cores")
    print("| devices | chunk | first chunk (s) | designs/s after it | evaluation (s) | process (s) |")
    print("|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        rate = r["designs_per_s"]
        print(f"| {r['devices']} | {r['chunk']} | {r['first_chunk_seconds']:.2f} | "
              f"{'-' if rate is None else f'{rate:.3g}'} | {r['seconds']:.2f} | "
              f"{r['wall_s']:.2f} |")


if __name__ == "__main__":
    main()
