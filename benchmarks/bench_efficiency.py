"""Cost of a full mesh-efficiency evaluation and of its gradient (not a test).

One evaluation = the TCA of the design (every contact solve along the grid),
kinematics at the contact points, load sharing at every position, friction at every
(position, pair) and the losses.  The gradient = ``jax.grad`` of the mean efficiency
with respect to every pinion and gear machine setting and cutter parameter, the four
misalignments, torque, speed, viscosity and roughness (reverse mode, one backward
pass).  Prints a table: compile time (trace, lower and compile) and run time of
each, XLA's memory account of each compiled program (peak = arguments + outputs +
temporaries, benchmarks/program_memory.py), and the ratio gradient / forward measured
in the same process.

    python benchmarks/bench_efficiency.py [--design hypoid_iso_10x41_synthesised] [--repeats 5]
                                          [--fast-compile]

``--fast-compile`` adds both routes jitted with ``compiler_options =
gearjax.FAST_COMPILE_OPTIONS`` (the command line's XLA options for one program).

Every route starts cold: ``jax.clear_caches()`` first, so that its first call traces,
lowers and compiles everything it runs (a route does not reuse the trace of the
nested programs, or of the whole function, that an earlier route made).
"""

from __future__ import annotations

import argparse
import dataclasses
import time

import jax
import jax.numpy as jnp
import numpy as np

import gearjax as gj
from gearjax.loading.mesh_efficiency import efficiency_function
from program_memory import memory_cell, peak_rss_mb, program_memory


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--design", default="hypoid_iso_10x41_synthesised")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--fast-compile", action="store_true",
                    help="also compile both with gearjax.FAST_COMPILE_OPTIONS")
    args = ap.parse_args()
    design = gj.load_design(f"example:{args.design}")
    f = efficiency_function(design)
    oil = dataclasses.replace(gj.tribology.get_oil(gj.tribology.OILS[0]), name="")
    surf = gj.tribology.make_surface(0.4)
    names = [n for n in gj.field_names(f.pair) if ".machine." in n or ".cutter." in n]
    d0 = gj.get_fields(f.pair, names)
    x0 = jnp.stack([jnp.asarray(d0[n], float) for n in names])

    def eta(x, mis, T, w, eta0, sigma):
        pair = gj.with_fields(f.pair, {n: x[i] for i, n in enumerate(names)})
        eff, _ = f(pair, T, w, dataclasses.replace(oil, eta0=eta0),
                   dataclasses.replace(surf, sigma=sigma), mis)
        return eff.mean_efficiency

    a = (x0, gj.Misalignment.zero(), jnp.asarray(200.0), jnp.asarray(1000.0),
         jnp.asarray(oil.eta0), jnp.asarray(surf.sigma))
    rows = []
    grad = jax.grad(eta, argnums=(0, 1, 2, 3, 4, 5))
    fast = dict(compiler_options=gj.FAST_COMPILE_OPTIONS)
    routes = [("forward eta_bar", jax.jit(eta)),
              ("gradient (reverse, %d inputs)" % (len(names) + 8), jax.jit(grad))]
    if args.fast_compile:
        routes += [("forward, FAST_COMPILE_OPTIONS", jax.jit(eta, **fast)),
                   ("gradient, FAST_COMPILE_OPTIONS", jax.jit(grad, **fast))]
    for label, fn in routes:
        jax.clear_caches()
        t = time.perf_counter()
        compiled = fn.trace(*a).lower().compile()      # trace, lower, compile
        tc = time.perf_counter() - t
        jax.block_until_ready(compiled(*a))
        ts = []
        for _ in range(args.repeats):
            t = time.perf_counter()
            jax.block_until_ready(compiled(*a))
            ts.append(time.perf_counter() - t)
        rows.append((label, tc, min(ts), program_memory(compiled)))
    eff, res = f(f.pair, *a[2:4], oil, surf)
    K, M = eff.loaded.load.shape
    n_loaded = int(np.sum(np.asarray(eff.loaded.load) > 0))
    print(f"gearjax mesh-efficiency benchmark ({jax.default_backend()}, {args.design}: "
          f"{res.path.phi1.shape[0]} TCA grid points, {M} positions x {K} pairs, "
          f"{n_loaded} loaded contacts)")
    print(f"{'route':40s} {'compile (s)':>12s} {'call (s)':>10s} {'peak MB (temp)':>16s}")
    for label, tc, t, mem in rows:
        print(f"{label:40s} {tc:12.1f} {t:10.4f} {memory_cell(mem):>16s}")
    print(f"process peak RSS {peak_rss_mb():.0f} MB (compilers included)")
    print(f"gradient / forward cost: {rows[1][2] / rows[0][2]:.2f}")
    if args.fast_compile:
        print(f"with FAST_COMPILE_OPTIONS: gradient compile {rows[1][1] / rows[3][1]:.2f}x "
              f"faster, its call {rows[3][2] / rows[1][2]:.2f}x slower")


if __name__ == "__main__":
    main()
