"""Gradient of the mesh efficiency of the hypoid example against central differences.

d eta_bar / d(every pinion and gear machine setting and cutter parameter, the four
misalignments, pinion torque, speed, base viscosity eta0 and roughness sigma) by one
reverse-mode pass through the whole chain (TCA, kinematics, load sharing, friction,
losses), each entry checked by a central difference of the jitted forward model with
the relative step ``H`` (1e-6: the efficiency of a discretised mesh cycle is smooth
on that scale; at 1e-4 steps the difference quotients already see the curvature of
the bearing moving across the grid).  Also the cost of the gradient against one
forward evaluation (same process).

Run: ``python experiments/efficiency_gradients.py`` (the gradient program compiles for
several minutes on 2 CPU cores).  Writes ``experiments/results/efficiency_gradients.json``
and ``.md``.
"""

from __future__ import annotations

import dataclasses
import json
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
import gearjax as gj  # noqa: E402
from gearjax.io import atomic_write  # noqa: E402
sys.path.insert(0, str(ROOT / "experiments"))
from efficiency_hypoid import DESIGN, RPM, TORQUE, chain  # noqa: E402
H = 1e-6


def log(msg):
    print(f"[efficiency_gradients] {msg}", file=sys.stderr, flush=True)


def main():
    design, f, oil, surf, names, x0 = chain()
    mis0 = gj.Misalignment.zero()

    def eta(x, mis, T, w, eta0, sigma):
        pair = gj.with_fields(f.pair, {n: x[i] for i, n in enumerate(names)})
        eff, _ = f(pair, T, w, dataclasses.replace(oil, eta0=eta0),
                   dataclasses.replace(surf, sigma=sigma), mis)
        return eff.mean_efficiency

    args = (x0, mis0, jnp.asarray(TORQUE), jnp.asarray(float(RPM)),
            jnp.asarray(oil.eta0), jnp.asarray(surf.sigma))
    jf = jax.jit(eta)
    log("compiling the forward model")
    t = time.perf_counter(); v = float(jf(*args)); tcf = time.perf_counter() - t
    t = time.perf_counter(); jax.block_until_ready(jf(*args)); tf = time.perf_counter() - t
    log("compiling the gradient")
    jg = jax.jit(jax.grad(eta, argnums=(0, 1, 2, 3, 4, 5)))
    t = time.perf_counter(); g = jax.block_until_ready(jg(*args)); tcg = time.perf_counter() - t
    t = time.perf_counter(); jax.block_until_ready(jg(*args)); tg = time.perf_counter() - t
    rows = []

    def cd(fun, x, h):
        return float((fun(x + h) - fun(x - h)) / (2.0 * h))

    for i, n in enumerate(names):
        h = H * max(abs(float(x0[i])), 1e-2)
        rows.append((n, float(g[0][i]), cd(lambda xi: jf(x0.at[i].set(xi), *args[1:]), x0[i], h)))
    for m in ("dE", "dP", "dG", "dSigma"):
        rows.append((m, float(getattr(g[1], m)),
                     cd(lambda v: jf(x0, dataclasses.replace(mis0, **{m: v}), *args[2:]),
                        getattr(mis0, m), 1e-6)))
    for j, n in enumerate(("torque_Nm", "pinion_rpm", "eta0_Pas", "sigma_mm")):
        a = args[2 + j]

        def fs(v, j=j):
            aa = list(args)
            aa[2 + j] = v
            return jf(*aa)

        rows.append((n, float(g[2 + j]), cd(fs, a, H * float(a))))
    table = []
    for n, ad, fd in rows:
        scale = max(abs(ad), abs(fd))
        rel = abs(ad - fd) / scale if scale > 0 else 0.0
        table.append({"input": n, "autodiff": ad, "central_difference": fd, "rel_diff": rel})
    out = {"design": DESIGN, "eta_bar": v, "step": H,
           "timing_s": {"compile_forward": tcf, "forward": tf, "compile_gradient": tcg,
                        "gradient": tg, "gradient_over_forward": tg / tf},
           "n_inputs": len(rows), "rows": table}
    RESULTS = ROOT / "experiments" / "results"
    atomic_write(RESULTS / "efficiency_gradients.json", json.dumps(out, indent=1))
    lines = ["| input | d eta_bar (autodiff) | central difference | rel. diff. |", "|---|---:|---:|---:|"]
    lines += [f"| {r['input']} | {r['autodiff']:.6e} | {r['central_difference']:.6e} | {r['rel_diff']:.1e} |"
              for r in table]
    atomic_write(RESULTS / "efficiency_gradients.md", "\n".join(lines) + "\n")
    log(f"eta_bar = {v:.6f}; forward {tf:.3f} s, gradient {tg:.3f} s ({tg / tf:.2f}x); "
        f"max rel diff {max(r['rel_diff'] for r in table if abs(r['central_difference']) > 1e-9):.2e}")


if __name__ == "__main__":
    main()
