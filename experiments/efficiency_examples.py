"""Mesh efficiency of the examples at stated operating points, with the independent checks.

Spur 20/40 (m 4, b 30 mm) and helical 20/40 (15 deg, lead-crowned pinion
2e-4 1/mm: point contact) at pinion torque 200 N m, 1500 rpm; the spiral-bevel
10/30 and the hypoid 10/41 examples (synthesised pinions) at 200 N m, 1000 rpm.
Oil ``mineral_vg100``, composite roughness 0.4 um; both compliance models for
the cylindrical pairs (Weber/Sainsot and ISO 6336).

Cylindrical pairs: the mean power loss against Ohlendorf's route
``P_V = mu_m H_V P_in`` with gearjax's own load- and sliding-weighted mean mu,
and the mean mesh stiffness of the loaded TE against ISO 6336's
``c_gamma = c' (0.75 eps + 0.25)`` (spur: line contact over the face width).

Run: ``python experiments/efficiency_examples.py`` (several minutes of XLA
compiles on 2 CPU cores).  Writes ``experiments/results/efficiency_examples.json``
and ``.md``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

import gearjax as gj
from gearjax.gears.involute.geometry import pair_geometry
from gearjax.gears.involute.mesh import ohlendorf_loss_factor
from gearjax.io import atomic_write
from gearjax.loading.efficiency_checks import efficiency_warnings
from gearjax.loading.mesh_efficiency import mesh_efficiency
from gearjax.loading.pair_stiffness import iso6336_mesh_stiffness, iso6336_single_stiffness

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "experiments" / "results"
OIL, SIGMA_UM = "mineral_vg100", 0.4
CYLINDRICAL = (("spur 20/40 m4 b30", 0.0, 0.0), ("helical 20/40 m4 b30 15deg, lead crown 2e-4/mm", 15.0, 2e-4))
BEVEL = ("spiral_bevel_10x30_synthesised", "hypoid_iso_10x41_synthesised")


def log(msg):
    print(f"[efficiency_examples] {msg}", file=sys.stderr, flush=True)


def row(eff, res):
    return {"mean_efficiency": float(eff.mean_efficiency),
            "power_loss_mean_W": float(np.mean(np.asarray(eff.power_loss))),
            "power_in_W": float(eff.power_in), "mean_mu": float(eff.mean_mu),
            "max_p_max_MPa": float(eff.max_p_max),
            "lambda_min": float(np.min(np.where(np.asarray(eff.loaded.load) > 0,
                                                np.asarray(eff.friction.lam), np.inf))),
            "loaded_te_ptp_arcsec": float(np.ptp(np.asarray(eff.loaded.te_loaded)) / gj.ARCSEC),
            "unloaded_te_ptp_arcsec": float(res.ptp / gj.ARCSEC),
            "max_balance": float(np.nanmax(np.asarray(eff.loaded.balance))),
            "valid_positions": f"{int(np.sum(np.asarray(eff.valid)))}/{eff.valid.size}",
            "pairs_in_contact": sorted(set(np.asarray(eff.loaded.n_loaded).tolist())),
            "warnings": efficiency_warnings(eff, res)}


def main():
    oil, surf = gj.tribology.get_oil(OIL), gj.tribology.make_surface(SIGMA_UM)
    out = {"oil": OIL, "sigma_um": SIGMA_UM, "cases": {}}
    for name, helix, crown in CYLINDRICAL:
        pair = gj.involute.InvolutePair.create(20, 40, 4.0, 20.0, helix)
        des = gj.involute.InvoluteTCA.create(pair, 30.0, lead_crown=crown)
        geo = pair_geometry(pair)
        for comp in ("weber", "iso6336"):
            log(f"{name}, {comp}")
            eff, res = mesh_efficiency(des, 200.0, 1500.0, oil, surf, compliance=comp)
            r = row(eff, res)
            H = float(ohlendorf_loss_factor(pair))
            P_ohl = float(eff.mean_mu) * H * float(eff.power_in)
            r["ohlendorf"] = {"H_V": H, "P_V_W": P_ohl,
                              "deviation_pct": 100.0 * (r["power_loss_mean_W"] / P_ohl - 1.0)}
            if helix == 0.0:
                F_tot = 1e3 * 200.0 / float(geo["rb1"])
                w_lead = np.nanmax(np.asarray(eff.loaded.approach), axis=0)
                cg = float(np.mean(F_tot / (30.0 * w_lead)) * 1e-3)
                c1 = float(iso6336_single_stiffness(20, 40).c_prime)
                ci = float(iso6336_mesh_stiffness(c1, float(geo["contact_ratio"])))
                r["mesh_stiffness"] = {"c_gamma_N_mm_um": cg, "iso6336_c_gamma": ci,
                                       "deviation_pct": 100.0 * (cg / ci - 1.0)}
            r.update(torque_Nm=200.0, rpm=1500.0, compliance=comp)
            out["cases"][f"{name} [{comp}]"] = r
    for name in BEVEL:
        log(name)
        eff, res = mesh_efficiency(gj.load_design(f"example:{name}"), 200.0, 1000.0, oil, surf,
                                   side="drive", throw=False)
        r = row(eff, res)
        r.update(torque_Nm=200.0, rpm=1000.0, compliance="weber")
        out["cases"][name] = r
    RESULTS.mkdir(parents=True, exist_ok=True)
    atomic_write(RESULTS / "efficiency_examples.json", json.dumps(out, indent=1))
    lines = ["| case | η̄_m (%) | mean P_f (W) | mean μ | max p_max (MPa) | min λ | loaded TE p-t-p (arcsec) | Ohlendorf P_V (W), dev. | valid |",
             "|---|---:|---:|---:|---:|---:|---:|---|---|"]
    for k, r in out["cases"].items():
        ohl = (f"{r['ohlendorf']['P_V_W']:.1f}, {r['ohlendorf']['deviation_pct']:+.2f} %"
               if "ohlendorf" in r else "–")
        lines.append(f"| {k} | {100 * r['mean_efficiency']:.3f} | {r['power_loss_mean_W']:.1f} | "
                     f"{r['mean_mu']:.4f} | {r['max_p_max_MPa']:.0f} | {r['lambda_min']:.2f} | "
                     f"{r['loaded_te_ptp_arcsec']:.1f} | {ohl} | {r['valid_positions']} |")
    atomic_write(RESULTS / "efficiency_examples.md", "\n".join(lines) + "\n")
    log("wrote experiments/results/efficiency_examples.{json,md}")


if __name__ == "__main__":
    main()
