"""Cost of the loaded line contact of a helical pair with micro-geometry (not a test).

The packaged ``helical_microgeometry`` pair over a torque x misalignment map
(:func:`gearjax.involute.loaded_te_map`'s program: every operating point's loaded
cycle in one vmapped program), with and without the friction along the contact lines,
and the gradient of the robust objective (mean smooth LTE p-t-p over the map) with
respect to the 32 modification fields of both flanks (reverse mode).  Prints compile
and run times, operating points (loaded cycles) per second, slice points per second,
the gradient / forward ratio, and XLA's memory account of each program.

    python benchmarks/bench_line_load.py [--torques 8] [--misalignments 3] [--positions 32]
                                         [--slices 20] [--repeats 5]

Runs unchanged on a CUDA device (``jax[cuda12]``).
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import jax
import jax.numpy as jnp
import numpy as np

import gearjax as gj
from gearjax.gears.involute.line_load import LineLoadOptions, pair_range, path_points_bound
from gearjax.gears.involute.loaded_lines import te_map_traced
from program_memory import memory_cell, peak_rss_mb, program_memory


def _time(fn, args, repeats):
    t = time.perf_counter()
    lowered = jax.jit(fn).lower(*args)
    compiled = lowered.compile()
    t_compile = time.perf_counter() - t
    jax.block_until_ready(compiled(*args))
    runs = []
    for _ in range(repeats):
        t = time.perf_counter()
        jax.block_until_ready(compiled(*args))
        runs.append(time.perf_counter() - t)
    return t_compile, float(np.median(runs)), program_memory(compiled)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--torques", type=int, default=8)
    ap.add_argument("--misalignments", type=int, default=3)
    ap.add_argument("--positions", type=int, default=32)
    ap.add_argument("--slices", type=int, default=20)
    ap.add_argument("--repeats", type=int, default=5)
    a = ap.parse_args()
    f = gj.load_design("example:helical_microgeometry")
    pair, b = f.design.pair, f.design.face_width
    mods = f.micro.flanks("drive")
    opts = LineLoadOptions(a.positions, a.slices, *pair_range(pair, b), "weber",
                           path_points_bound(pair, b, a.slices))
    every = opts._replace(path_points=0)
    T = jnp.linspace(50e3, 400e3, a.torques)
    A = jnp.linspace(-10.0, 10.0, a.misalignments)
    oil = dataclasses.replace(gj.tribology.get_oil(gj.tribology.OILS[0]), name="")
    surf = gj.tribology.make_surface(0.4)
    E, nu = 206000.0, 0.3
    n_ops = a.torques * a.misalignments
    n_pts = n_ops * a.positions * a.slices * (opts.k_hi - opts.k_lo + 1)

    def loads(m):
        return te_map_traced(pair, b, m, T, A, E, nu, opts, True, 0.02)

    def with_friction(m):
        return te_map_traced(pair, b, m, T, A, E, nu, opts, True, 0.02,
                             (1500.0, oil, surf, "roelands", "auto"))

    def friction_everywhere(m):
        return te_map_traced(pair, b, m, T, A, E, nu, every, True, 0.02,
                             (1500.0, oil, surf, "roelands", "auto"))

    def objective(m):
        return jnp.mean(loads(m)[1])

    rows = [("loads", loads), ("loads + friction (on-path points)", with_friction),
            ("loads + friction (every pair's slices)", friction_everywhere),
            ("grad of mean smooth LTE p-t-p (32 fields)", jax.grad(objective))]
    print(f"# helical_microgeometry: {a.torques} torques x {a.misalignments} misalignments, "
          f"{a.positions} positions x {a.slices} slices x {opts.k_hi - opts.k_lo + 1} pairs "
          f"= {n_pts} slice points; backend {jax.default_backend()}")
    print("| program | compile (s) | run (ms) | operating points/s | slice points/s | memory |")
    print("|---|---:|---:|---:|---:|---|")
    times = {}
    for name, fn in rows:
        jax.clear_caches()
        tc, tr, mem = _time(fn, (mods,), a.repeats)
        times[name] = tr
        print(f"| {name} | {tc:.2f} | {1e3 * tr:.1f} | {n_ops / tr:.0f} | {n_pts / tr:.3g} | "
              f"{memory_cell(mem)} |")
    print(f"\ngradient / forward (loads): "
          f"{times[rows[3][0]] / times['loads']:.2f}; friction on the path / everywhere: "
          f"{times[rows[1][0]] / times[rows[2][0]]:.2f}; peak RSS {peak_rss_mb():.0f} MB")


if __name__ == "__main__":
    main()
