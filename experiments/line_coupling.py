"""The coupling of the slices along the face (Pasternak foundation,
:mod:`gearjax.gears.involute.face_coupling`) on ``example:helical_microgeometry``:
K_Hbeta, p_max and the loaded TE at three torques and two misalignments, Winkler
(lambda = 0) against lambda = 0.5, 1 and 2 normal modules, and the cost of
``gearjax loaded`` with and without coupling (wall time, runs alternated, same machine).

Writes ``experiments/results/line_coupling.json`` and ``.md``::

    python experiments/line_coupling.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

import gearjax as gj

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "results")
TORQUES = (100.0, 200.0, 400.0)
MISALIGN = (0.0, 10.0)
PER_MODULE = (0.0, 0.5, 1.0, 2.0)


def effect(slices_list=(20, 40)):
    des = gj.load_design("example:helical_microgeometry")
    m_n = gj.involute.module_coupling_length(des)
    rows = []
    for slices in slices_list:
        for pm in PER_MODULE:
            lam = pm * m_n
            r = gj.involute.loaded_te_map(des, TORQUES, MISALIGN, positions=32, slices=slices,
                                          coupling_length_mm=lam)
            for i, T in enumerate(TORQUES):
                for j, f in enumerate(MISALIGN):
                    rows.append(dict(slices=slices, lam_mm=lam, per_module=pm, torque_Nm=T,
                                     f_ma_um=f, te_ptp_um=float(r.te_ptp_um[i, j]),
                                     te_mean_um=float(r.te_mean_um[i, j]),
                                     p_max_MPa=float(r.p_max[i, j]),
                                     k_hbeta=float(r.k_hbeta[i, j]),
                                     end_load=float(r.end_load[i, j]),
                                     converged=bool(r.converged[i, j])))
    return m_n, rows


def cost(repeats):
    """Wall time of ``gearjax loaded`` (3 torques x 2 misalignments, 32 x 20), a fresh
    process each, with and without coupling alternated; compilation cache off (cold) and
    on (the second run of each reads its programs back)."""
    exe = os.path.join(os.path.dirname(sys.executable), "gearjax")
    cmd = [exe, "loaded", "example:helical_microgeometry",
           "--torque-Nm", ",".join(f"{t:g}" for t in TORQUES), "--misalignment-um",
           ",".join(f"{f:g}" for f in MISALIGN), "--json"]
    out = {"winkler_cold_s": [], "coupled_cold_s": []}
    env = dict(os.environ, GEARJAX_CACHE_DIR="off")
    for _ in range(repeats):
        for key, extra in (("winkler_cold_s", []),
                           ("coupled_cold_s", ["--coupling-length-mm", "module"])):
            t = time.perf_counter()
            subprocess.run(cmd + extra, env=env, check=True, capture_output=True)
            out[key].append(time.perf_counter() - t)
    return out


def warm_cost(repeats):
    """In-process time of one jitted, compiled map call (3 x 2 operating points)."""
    import jax
    des = gj.load_design("example:helical_microgeometry")
    res = {}
    for key, lam in (("winkler_warm_s", 0.0),
                     ("coupled_warm_s", gj.involute.module_coupling_length(des))):
        run = lambda: jax.block_until_ready(gj.involute.loaded_te_map(  # noqa: E731
            des, TORQUES, MISALIGN, coupling_length_mm=lam))
        run()
        res[key] = []
    for _ in range(repeats):
        for key, lam in (("winkler_warm_s", 0.0),
                         ("coupled_warm_s", gj.involute.module_coupling_length(des))):
            t = time.perf_counter()
            jax.block_until_ready(gj.involute.loaded_te_map(des, TORQUES, MISALIGN,
                                                            coupling_length_mm=lam))
            res[key].append(time.perf_counter() - t)
    return res


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args(argv)
    m_n, rows = effect()
    c = cost(a.repeats)
    c.update(warm_cost(a.repeats))
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "line_coupling.json"), "w") as fh:
        json.dump({"module_mm": m_n, "rows": rows, "cost": c}, fh, indent=1)
    lines = ["| slices | λ (mm) | λ/m_n | T (N m) | f_ma (µm) | LTE p-t-p (µm) | LTE mean (µm) "
             "| p_max (MPa) | K_Hβ | end load | conv. |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['slices']} | {r['lam_mm']:g} | {r['per_module']:g} | "
                     f"{r['torque_Nm']:g} | {r['f_ma_um']:g} | {r['te_ptp_um']:.3f} | "
                     f"{r['te_mean_um']:.3f} | {r['p_max_MPa']:.0f} | {r['k_hbeta']:.3f} | "
                     f"{r['end_load']:.3f} | {'yes' if r['converged'] else 'no'} |")
    cost_lines = [f"| {k} | " + ", ".join(f"{v:.2f}" for v in vals) + f" | {np.median(vals):.2f} |"
                  for k, vals in c.items()]
    with open(os.path.join(OUT, "line_coupling_table.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n\n| run | times (s) | median (s) |\n|---|---|---|\n"
                 + "\n".join(cost_lines) + "\n")


if __name__ == "__main__":
    main()
