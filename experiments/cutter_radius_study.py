"""[Eigenfunctions]: influence of the cutter-head radius on hypoid meshing characteristics.

Reproduces [Eigenfunctions] (docs/references.md) §2-§3 with
:mod:`gearjax.studies.cutter_radius`: the 6/39, 230 mm, E = 35 mm gear set
designed with 6-, 7.5- and 9-inch cutters (blank by the [Tangent-cones] tangency route,
r0 as input; assumptions in docs/kinematics_study.md), Table 1 side by side with
the paper's, fields over the working gear flank (drive = convex side; the coast side
as statistics), the trend with the cutter radius as numbers, a continuous vmap
sweep with derivatives, gradient checks against central differences, and an
optax optimisation re-checked by the full forward model.

Writes ``experiments/results/cutter_radius_study.json`` and the figures
``cutter_radius_fields.png`` (field maps), ``cutter_radius_trends.png`` (sweep and
derivatives), ``cutter_radius_optimisation.png`` (history and optimised fields).

Run: ``python experiments/cutter_radius_study.py [--quick]`` (about 3-5 min on 2
CPU cores; ``--quick`` uses coarse grids).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from gearjax.studies import cutter_radius as hk
from gearjax.studies import cutter_radius_optimize as hko
from gearjax.gears.hypoid.blank import blank_geometry
from gearjax.io import atomic_write
from gearjax.plot.kinematics import field_maps, save_figure, trend_plot

OUT = Path(__file__).resolve().parent / "results"

SEED_TABLE1 = {  # [Eigenfunctions] Table 1 (deg, mm)
    "6in": dict(b1=47.365, alpha_D=15.940, alpha_C=-22.060, delta1=12.493, beta1=76.650,
                beta2=8.774, delta2=70.906),
    "7.5in": dict(b1=47.403, alpha_D=14.841, alpha_C=-23.159, delta1=10.441, beta1=78.833,
                  beta2=8.76, delta2=72.901),
    "9in": dict(b1=47.423, alpha_D=14.106, alpha_C=-23.894, delta1=9.075, beta1=80.289,
                beta2=8.754, delta2=74.333),
}
STAT_FIELDS = ("u_e", "srr", "r_eff", "u_s", "phi_I", "phi_II", "k_II")


def _stats(f):
    out = hk.field_stats(f, STAT_FIELDS)
    a = np.abs(np.asarray(f.u_e))
    out["abs_u_e"] = {"mean": float(a.mean()), "min": float(a.min()), "max": float(a.max())}
    a = np.abs(np.asarray(f.srr))
    out["abs_srr"] = {"mean": float(a.mean()), "min": float(a.min()), "max": float(a.max())}
    return out


def _limits(f):
    rep = hk.limit_report(f)
    return {k: {kk: v[kk] for kk in ("inside", "fraction", "margin")}
            | {"zero_curve_axial_mm": [[round(c, 4) for c in p] for p in v["zero_curve_axial"]]}
            for k, v in rep.items()}


def table1(log):
    rows = {}
    for name, r0 in hk.STUDY_CUTTERS.items():
        out = {}
        for method in ("tangent-cones", "iso23509-method1"):
            b = blank_geometry(hk.study_blank_input(r0, method=method))
            out[method] = dict(b1=float(b.b1), alpha_D=math.degrees(float(b.alpha_nD)),
                               alpha_C=math.degrees(float(b.alpha_nC)),
                               delta1=math.degrees(float(b.delta1)),
                               beta1=math.degrees(float(b.beta_m1)),
                               beta2=math.degrees(float(b.beta_m2)),
                               delta2=math.degrees(float(b.delta2)))
        out["seed"] = SEED_TABLE1[name]
        out["r0_mm"] = r0
        rows[name] = out
    log("table 1 done")
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="coarse grids (smoke run)")
    args = ap.parse_args(argv)
    shape = (9, 5) if args.quick else (31, 15)
    sshape = (7, 5) if args.quick else (15, 9)
    nsweep = 5 if args.quick else 23
    steps = 10 if args.quick else 100
    t0 = time.time()

    def log(msg):
        sys.stderr.write(f"[{time.time() - t0:6.1f} s] {msg}\n")

    OUT.mkdir(parents=True, exist_ok=True)
    res = {"reference": "Eigenfunctions", "blank_input": hk.STUDY_BLANK,
           "grid": list(shape), "units": {"u_e, u_s": "mm per rad of pinion roll",
                                          "r_eff": "mm", "k_II": "1/mm", "srr": "-",
                                          "phi": "eigenfunction units (mm/rad^2 scale)"}}
    res["table1"] = table1(log)

    # fields for the three cutters, both flanks
    fields, cases = {}, {}
    for name, r0 in hk.STUDY_CUTTERS.items():
        inp = hk.study_blank_input(r0)
        for flank in ("convex", "concave"):
            s, f = hk.flank_fields(inp, hk.StudySettings.make(r0), flank, shape)
            cases[f"{name}/{flank}"] = {"r0_mm": r0, "flank": flank,
                                        "blade_angle_deg": math.degrees(float(s.blade)),
                                        "stats": _stats(f), "limits": _limits(f)}
            if flank == "convex":
                fields[f"{name} (r0 = {r0:g} mm)"] = f
        log(f"fields {name}")
    res["cases"] = cases

    # trend with decreasing cutter radius ([Eigenfunctions]: u_e up, SRR down, R_eff up)
    trend = {}
    for flank in ("convex", "concave"):
        t = {}
        for q in ("abs_u_e", "abs_srr", "r_eff"):
            t[q] = {stat: [cases[f"{n}/{flank}"]["stats"][q][stat] for n in hk.STUDY_CUTTERS]
                    for stat in ("mean", "min", "max")}
        t["order"] = list(hk.STUDY_CUTTERS)
        trend[flank] = t
    res["trend"] = trend

    # continuous sweep by vmap with derivatives
    inp = hk.study_blank_input(95.25)
    r0s = np.linspace(70.0, 125.0, nsweep)
    vals, ders = hk.cutter_radius_sweep(inp, r0s, shape=sshape)
    res["sweep"] = {"grid": list(sshape), "r0_mm": r0s.tolist(),
                    "values": {k: np.asarray(v).tolist() for k, v in vals.items()},
                    "d_dr0": {k: np.asarray(v).tolist() for k, v in ders.items()}}
    log("sweep")

    # gradients vs central differences at the 7.5-inch design
    st = hk.StudySettings.make(95.25)
    g = hk.statistics_gradient(inp, st, shape=sshape)
    gc = {}
    for var, h in (("cutter_radius", 1e-2), ("blade_angle_delta", 1e-5), ("cutter_shift", 1e-3)):
        def at(d, var=var):
            kw = {"cutter_radius": st.cutter_radius, "blade_angle_delta": st.blade_angle_delta,
                  "cutter_shift": st.cutter_shift}
            kw[var] = kw[var] + d
            return hk.flank_statistics(inp, hk.StudySettings(**kw), shape=sshape)
        fp, fm = at(h), at(-h)
        for nm in ("mean_abs_srr", "max_abs_srr", "mean_r_eff", "min_r_eff", "mean_abs_u_e"):
            ad = float(getattr(g[nm], var))
            fd = (float(fp[nm]) - float(fm[nm])) / (2 * h)
            gc[f"d {nm} / d {var}"] = {"autodiff": ad, "central_difference": fd, "step": h,
                                       "rel_error": abs(ad - fd) / max(abs(ad), 1e-300)}
    res["gradient_check"] = gc
    log("gradients")

    # optimisation and full re-check
    opt, best = hko.optimise_design(inp, st, steps=steps)
    final = {"cutter_radius_mm": float(best.cutter_radius),
             "blade_angle_delta_deg": math.degrees(float(best.blade_angle_delta)),
             "cutter_shift_mm": float(best.cutter_shift)}
    inp_best = hk.study_blank_input(final["cutter_radius_mm"])
    s0, f0 = hk.flank_fields(inp, st, "convex", shape)
    s1, f1 = hk.flank_fields(inp_best, best, "convex", shape)
    res["optimisation"] = {
        "objective": "J = max|SRR| - min R_eff / 20 mm + 10 (relu(1 - min Phi_I)^2 + "
                     "relu(1 - min Phi_II)^2), optimisation grid 9x7, Adam lr 0.05",
        "bounds": hko.OPT_BOUNDS, "steps": steps,
        "history": np.asarray(opt.history).tolist(), "final_value": float(opt.value),
        "projected_grad_norm": float(opt.grad_norm), "start": {"cutter_radius_mm": 95.25,
                                                              "blade_angle_delta_deg": 0.0,
                                                              "cutter_shift_mm": 0.0},
        "final": final,
        "recheck_full_grid": {"start": {"stats": _stats(f0), "limits": _limits(f0)},
                              "final": {"stats": _stats(f1), "limits": _limits(f1),
                                        "converged": bool(np.all(np.asarray(f1.converged)))}},
    }
    log("optimisation")

    atomic_write(OUT / "cutter_radius_study.json", json.dumps(res, indent=1) + "\n")
    save_figure(field_maps(fields), OUT / "cutter_radius_fields.png", dpi=70)
    keys = ["mean_abs_u_e", "mean_abs_srr", "max_abs_srr", "mean_r_eff", "min_r_eff"]
    save_figure(trend_plot(r0s, {k: np.asarray(vals[k]) for k in keys},
                           {k: np.asarray(ders[k]) for k in keys},
                           marks=list(hk.STUDY_CUTTERS.values())),
                OUT / "cutter_radius_trends.png", dpi=70)
    import matplotlib.pyplot as plt
    fig = field_maps({"start 7.5in": f0, "optimised": f1})
    ax = fig.add_axes([0.07, 0.02, 0.2, 0.12])
    ax.plot(np.asarray(opt.history), "k-")
    ax.set_title("objective J", fontsize=6)
    ax.tick_params(labelsize=5)
    fig.subplots_adjust(bottom=0.25)
    save_figure(fig, OUT / "cutter_radius_optimisation.png", dpi=70)
    plt.close("all")
    log("written")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
