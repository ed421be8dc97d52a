"""Newton throughput on envelope points, and the cost of gradients.

Workload: 10^4 points of a rack-generated helical involute flank
(:func:`gearjax.gears.involute.geometry.generated_flank`): each point solves the meshing
equation n.dr/dpsi = 0 for psi by the implicit-differentiated Newton.

Baseline in the same process: a per-point ``scipy.optimize.fsolve`` loop on the
same meshing equation written in NumPy (analytic derivatives of the rack family),
with xtol = 1e-12, timed on a subset and scaled per point.

Gradient cost: Jacobian of all 10^4 points w.r.t. the four pair parameters
(module, pressure angle, helix, profile shift) by ``jax.jacfwd`` through the
implicit solve, and by reverse mode (``jax.vjp`` of a scalar), relative to the
forward solve.  Run: ``python benchmarks/bench_newton.py [--n 10000]``.
"""

from __future__ import annotations

import argparse
import time

import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import fsolve

import gearjax  # noqa: F401  (x64)
from gearjax.gears.involute.geometry import generated_flank, rack_flank


def timeit(f, repeat=5):
    f()  # compile / warm up
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        ts.append(time.perf_counter() - t0)
    return min(ts)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=10_000)
    ap.add_argument("--baseline-points", type=int, default=300)
    args = ap.parse_args()

    params = jnp.array([3.0, np.radians(20.0), np.radians(15.0), 0.3])  # m_n, alpha_n, beta, x
    z, side = 23, -1
    side_n = int(np.sqrt(args.n))
    uu, vv = np.meshgrid(np.linspace(-3.0, 3.5, side_n), np.linspace(-12.0, 12.0, args.n // side_n))
    uv = jnp.asarray(np.stack([uu.ravel(), vv.ravel()], 1))
    n = uv.shape[0]

    def points(p, uv):
        flank = generated_flank(p[0], p[1], p[2], p[3], z, side)
        res = jax.vmap(flank.solve)(uv)
        return jax.vmap(flank)(uv), res

    fwd = jax.jit(points)
    out, res = fwd(params, uv)
    assert bool(jnp.all(res.converged)), "benchmark solves must converge"
    t_fwd = timeit(lambda: jax.block_until_ready(fwd(params, uv)[0]))

    jac = jax.jit(jax.jacfwd(lambda p: points(p, uv)[0]))
    t_jac = timeit(lambda: jax.block_until_ready(jac(params)), repeat=3)
    w = jnp.asarray(np.random.default_rng(0).normal(size=(n, 3)))
    vjp = jax.jit(jax.grad(lambda p: jnp.sum(points(p, uv)[0] * w)))
    t_vjp = timeit(lambda: jax.block_until_ready(vjp(params)), repeat=3)

    # SciPy baseline: same meshing equation in NumPy, one fsolve per point
    rack, m_t, alpha_t, r = rack_flank(*params, z, side)
    rack_n = np.cross(*np.asarray(jax.jacfwd(rack)(jnp.zeros(2))).T)
    rack_n /= np.linalg.norm(rack_n)
    r = float(r)
    at = float(alpha_t)

    def rack_np(q):
        return np.asarray(rack(jnp.asarray(q)))

    def f_np(psi, pr):
        psi = psi[0]
        X = pr[0] - r * psi
        c, s = np.cos(psi), np.sin(psi)
        # r_w = Rz(-psi)[X, y, z];  d r_w/dpsi
        dr = np.array([-s * X + c * pr[1] - c * r, -c * X - s * pr[1] + s * r, 0.0])
        nw = np.array([c * rack_n[0] + s * rack_n[1], -s * rack_n[0] + c * rack_n[1], rack_n[2]])
        return [nw @ dr]

    sub = np.asarray(uv[:: max(1, n // args.baseline_points)])
    prs = [rack_np(q) for q in sub]
    psi_ref = np.asarray(jax.vmap(lambda q: generated_flank(*params, z, side).solve(q).x)(jnp.asarray(sub)))

    def baseline():
        out = []
        for pr in prs:
            g = (pr[0] - side * (pr[1] - r) / np.tan(at)) / r
            out.append(fsolve(f_np, [g], args=(pr,), xtol=1e-12)[0])
        return np.array(out)

    psi_sp = baseline()
    agree = float(np.max(np.abs(psi_sp - psi_ref)))
    t_sp = timeit(baseline, repeat=3) / len(prs) * n

    rows = [
        ("gearjax forward (jit+vmap)", t_fwd, n / t_fwd, 1.0),
        ("SciPy fsolve loop (scaled)", t_sp, n / t_sp, t_sp / t_fwd),
        ("gearjax jacfwd, 4 params", t_jac, n / t_jac, t_jac / t_fwd),
        ("gearjax reverse (grad)", t_vjp, n / t_vjp, t_vjp / t_fwd),
    ]
    print(f"envelope points: {n}; devices: {jax.devices()}; SciPy subset {len(prs)} points, "
          f"max |psi_scipy - psi_gearjax| = {agree:.2e} rad")
    print(f"{'route':32s} {'time [s]':>10s} {'points/s':>12s} {'x forward':>10s}")
    for name, t, rate, ratio in rows:
        print(f"{name:32s} {t:10.4f} {rate:12.0f} {ratio:10.2f}")
    print(f"gearjax speed-up over the SciPy loop: {t_sp / t_fwd:.1f}x")


if __name__ == "__main__":
    main()
