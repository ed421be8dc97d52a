"""Time per numerical EHL solve and per implicit gradient (gearjax.tribology.ehl).

Case: steel ball-on-disc-like point contact, F = 100 N, u_e = 1 m/s, SRR 0.2,
Rx = Ry = 10 mm, η0 = 0.088 Pa·s, α = 22 GPa⁻¹ (M = 168, L = 14.8,
p_h = 1.35 GPa), started from the Hertz pressure.  For each grid: compile time
(first call), solve time (second call, a 1 % different load so nothing is cached
but the executable), Newton steps, and the time of the implicit gradient of
(h_c, h_min, μ) w.r.t. all case fields (one adjoint GMRES solve per output).
Prints a table; not a test.

    python benchmarks/bench_ehl.py [--grids 64 128]   (256²: nested start from 128², solved
    to the fine-grid default tol 1e-6; 512² stops at max|R| ~ 3e-6 and fails that
    tolerance: docs/ehl.md)
"""

from __future__ import annotations

import argparse
import time

import jax

jax.config.update("jax_enable_x64", True)

from gearjax.tribology.ehl import ehl_gradients, solve_ehl  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grids", type=int, nargs="+", default=[64, 128])
    args = ap.parse_args()
    rows = []
    for n in args.grids:
        t0 = time.perf_counter()
        res, case, grid = solve_ehl(100.0, 1000.0, 200.0, 10.0, 10.0, 0.088, 22.0, n=n)
        t_first = time.perf_counter() - t0
        t0 = time.perf_counter()
        res, case, grid = solve_ehl(101.0, 1000.0, 200.0, 10.0, 10.0, 0.088, 22.0, n=n)
        jax.block_until_ready(res.x)
        t_solve = time.perf_counter() - t0
        t0 = time.perf_counter()
        g = ehl_gradients(res, case, grid)
        jax.block_until_ready(g["mu"].F)
        t_gfirst = time.perf_counter() - t0
        t0 = time.perf_counter()
        g = ehl_gradients(res, case, grid)
        jax.block_until_ready(g["mu"].F)
        t_grad = time.perf_counter() - t0
        rows.append((n, t_first, t_solve, int(res.steps), t_gfirst, t_grad,
                     float(res.residual), float(res.h_c) * 1e3))
        print(f"{n}² done", flush=True)
    print(f"device: {jax.devices()[0].device_kind}, {jax.device_count()} device(s)")
    print("| grid | first solve (incl. compile) s | solve s | Newton steps | first gradient s |"
          " gradient (3 outputs) s | residual | h_c µm |")
    print("|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r[0]}² | {r[1]:.1f} | {r[2]:.2f} | {r[3]} | {r[4]:.1f} | {r[5]:.2f} | "
              f"{r[6]:.1e} | {r[7]:.4f} |")


if __name__ == "__main__":
    main()
