"""[Eigenfunctions] repeated on machine-cut pairs: TCA contact points against its model.

[Eigenfunctions]: see docs/references.md.

For the 6/39, 230 mm, E = 35 mm set with the 6-, 7.5- and 9-inch cutters
(:mod:`gearjax.studies.cutter_radius`, assumptions in docs/kinematics_study.md):

1. **Conjugate machine-cut pair** (:func:`gearjax.studies.cutter_radius_pair.study_pair`):
   the paper's cutter cone as a formate gear on the cradle machine, the pinion
   generated from it (tilted cutter, cradle = gear).  Line-contact TCA at several
   pinion blade positions sweeps the working flank; at every contact point on both
   flanks the kinematics of the pair (contact-point velocity from the TCA, both
   flanks' curvatures; :mod:`gearjax.gears.hypoid.contact_kinematics`) are compared with
   the paper's model at the same gear-flank point (:func:`gearjax.studies.cutter_radius` fields
   at the mapped ``(u, theta)``), and field statistics are formed over the contact
   points.
2. **Localised pair**: the same pinion with the blade point radius +2 mm (blade kept
   through the mean point) and modified roll 2C = 0.02 -- point contact along a path;
   the pair's u_e, SRR and R_eff along the path against the paper's conjugate model.
3. **Gradient** of the machine-cut pair with respect to the study's cutter radius:
   ``jax.jacfwd`` of the generated pinion's machine settings (through the blank
   design, the formate placement and the generating-gear chain) against
   Richardson-extrapolated central differences (steps 0.1 and 0.05 mm).

Writes ``experiments/results/seed000_machine_pair.json`` and
``seed000_machine_pair.png``.  Run: ``python experiments/cutter_radius_machine_pair.py``
(about 5-7 min on 2 CPU cores, mostly XLA compiles).
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from dataclasses import replace
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import gearjax as gj
from gearjax.gears.hypoid import tca as th
from gearjax.gears.hypoid.contact_kinematics import path_kinematics
from gearjax.studies import cutter_radius as hk
from gearjax.gears.hypoid.flank import mid_estimate, solve_tip
from gearjax.studies.cutter_radius_pair import study_pair, study_uv
from gearjax.io import atomic_write
from gearjax.plot.kinematics import save_figure
from gearjax.tca.path import ARCSEC

OUT = Path(__file__).resolve().parent / "results"
FIELDS = ("u_e", "u_s", "srr", "r_eff")
BLADE_FRACTIONS = (0.2, 0.35, 0.5, 0.65, 0.8)   # pinion blade positions, fraction of s_tip


def _stats(a):
    a = np.asarray(a)
    return {"mean": float(a.mean()), "min": float(a.min()), "max": float(a.max())}


def _seed_fields(sp, p2_body):
    uv = study_uv(sp, p2_body)
    f = jax.vmap(lambda q: hk.point_fields(sp.setup, q))(jnp.asarray(uv))
    return uv, f


def conjugate_sweep(sp):
    """Line-contact TCA at several pinion blade positions; kinematics on both flanks."""
    prep = th.prepare(sp.pair)
    tip = solve_tip(prep.pair.pinion, 0.0, mid_estimate(prep.pair.pinion))
    s_tip = float(tip.x[0])
    rows = {k: [] for k in ("model", "pair", "seed")}
    te_max, n_pts, uv_all, axial = 0.0, 0, [], []
    for frac in BLADE_FRACTIONS:
        x_ref = np.array(prep.x_ref, float)
        x_ref[1] = frac * s_tip
        p = prep._replace(x_ref=x_ref)
        out = gj.run_tca(p, line_contact=True, steps_per_pitch=8, half_pitches=1.5,
                         n_pairs=3, throw=False, kinematics=False)
        ok = np.asarray(out.path.converged) & (np.asarray(out.margin) >= 0.0)
        te_max = max(te_max, float(np.max(np.abs(np.asarray(out.path.te)[ok]))) / ARCSEC)
        k = path_kinematics(prep.pair, out.path, line_contact=True)
        uv, f = _seed_fields(sp, out.path.p2_body)
        ok &= np.asarray(f.converged)
        n_pts += int(ok.sum())
        for name in FIELDS:
            rows["model"].append((name, np.asarray(getattr(k.model, name))[ok]))
            rows["pair"].append((name, np.asarray(getattr(k, name))[ok]))
            rows["seed"].append((name, np.asarray(getattr(f, name))[ok]))
        uv_all.append(uv[ok])
        axial.append(np.stack([np.asarray(out.path.axial2)[ok], np.asarray(out.path.radial2)[ok],
                               np.asarray(k.srr)[ok], np.asarray(k.r_eff)[ok]], axis=1))
    merged = {src: {name: np.concatenate([v for n, v in rows[src] if n == name])
                    for name in FIELDS} for src in rows}
    diff = {name: float(np.max(np.abs(merged["pair"][name] - merged["seed"][name])
                               / np.maximum(np.abs(merged["seed"][name]), 1e-12)))
            for name in FIELDS}
    diff_model = {name: float(np.max(np.abs(merged["model"][name] - merged["seed"][name])
                                     / np.maximum(np.abs(merged["seed"][name]), 1e-12)))
                  for name in FIELDS}
    stats = {name: _stats(merged["pair"][name]) for name in FIELDS}
    stats["abs_srr"] = _stats(np.abs(merged["pair"]["srr"]))
    stats["abs_u_e"] = _stats(np.abs(merged["pair"]["u_e"]))
    return dict(te_max_arcsec=te_max, contact_points=n_pts,
                max_rel_diff_pair_vs_seed=diff, max_rel_diff_model_vs_seed=diff_model,
                stats_at_contact_points=stats, s_tip_mm=s_tip), np.concatenate(axial)


def localised(sp, d_radius=2.0, c2=0.02):
    """Point contact: pinion point radius +d_radius (blade through the mean point), 2C."""
    prep0 = th.prepare(sp.pair)
    p2 = th.with_point_radius(sp.pair.pinion, d_radius, float(prep0.x_ref[0]))
    pin = replace(p2, machine=replace(p2.machine, modified_roll_2c=jnp.asarray(c2)))
    prep = th.prepare(replace(sp.pair, pinion=pin))
    out = gj.run_tca(prep, steps_per_pitch=16, half_pitches=1.0, n_pairs=3, throw=False,
                     kinematics=False)
    k = path_kinematics(prep.pair, out.path, line_contact=False)
    _, f = _seed_fields(sp, out.path.p2_body)
    ok = (np.asarray(out.path.converged) & (np.asarray(out.margin) >= 0.0)
          & np.asarray(f.converged))
    t = np.asarray(out.path.phi1) - float(out.path.phi1[len(ok) // 2])
    te = np.asarray(out.path.te) / ARCSEC
    c = np.polyfit(t[ok], te[ok], 2)
    res = {"d_radius_mm": d_radius, "modified_roll_2c": c2, "points_on_flank": int(ok.sum()),
           "te_parabola_arcsec_per_rad2": float(c[0]),
           "te_parabola_theory": float((sp.pair.z1 / sp.pair.z2) * 0.5 * c2
                                       / float(sp.pair.pinion.machine.ratio_of_roll) / ARCSEC),
           "semi_major_mm_mid": float(out.path.semi_major[len(ok) // 2]),
           "semi_minor_mm_mid": float(out.path.semi_minor[len(ok) // 2])}
    for name in FIELDS:
        a, b = np.asarray(getattr(k, name))[ok], np.asarray(getattr(f, name))[ok]
        res[name] = {"pair": _stats(a), "seed_model": _stats(b),
                     "max_abs_diff": float(np.max(np.abs(a - b))),
                     "max_rel_diff": float(np.max(np.abs(a - b) / np.abs(b)))}
    curves = dict(t=t[ok], **{f"{n}_pair": np.asarray(getattr(k, n))[ok] for n in FIELDS},
                  **{f"{n}_seed": np.asarray(getattr(f, n))[ok] for n in FIELDS})
    return res, curves


GRAD_SETTINGS = ("radial_distance", "cradle_angle", "tilt", "swivel", "sliding_base",
                 "center_to_back")


def cutter_radius_gradient(r0, h=0.1):
    """d/dr0 of the generated pinion's settings (mm/mm, rad/mm), its point radius and
    the mean-contact gear angle: autodiff against ``(4 D(h/2) - D(h))/3`` (``D`` the
    central difference, error O(h^4))."""
    inp = hk.study_blank_input(r0)

    def f(r):
        sp = study_pair(inp, dataclasses.replace(hk.StudySettings.make(r0), cutter_radius=r), "convex")
        pin = sp.pair.pinion
        v = [getattr(pin.machine, n) for n in GRAD_SETTINGS]
        return jnp.stack(v + [pin.cutter.point_radius, sp.info["phi2m"]])

    ad = np.asarray(jax.jacfwd(f)(jnp.asarray(float(r0))))
    d = {}
    for step in (h, 0.5 * h):
        d[step] = (np.asarray(f(jnp.asarray(r0 + step))) - np.asarray(f(jnp.asarray(r0 - step)))) / (2 * step)
    fd = (4.0 * d[0.5 * h] - d[h]) / 3.0
    names = GRAD_SETTINGS + ("point_radius", "phi2m")
    return {n: {"autodiff": float(a), "central_difference": float(b),
                "rel_error": float(abs(a - b) / abs(a)) if a != 0.0 else float(abs(b))}
            for n, a, b in zip(names, ad, fd)}


def _figure(path, axial, curves):
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.4))
    sc = ax[0].scatter(axial[:, 0], axial[:, 1], c=axial[:, 3], s=14, cmap="viridis")
    fig.colorbar(sc, ax=ax[0], label="R_eff (mm), pair = seed model")
    ax[0].set_xlabel("gear axial position (mm)")
    ax[0].set_ylabel("gear radius (mm)")
    ax[0].set_title("7.5-in conjugate machine-cut pair:\nTCA contact points on the gear flank")
    t = np.degrees(curves["t"])
    for name, a in (("srr", ax[1]), ("r_eff", ax[2])):
        a.plot(t, curves[f"{name}_seed"], "k--", label="seed model (conjugate) at the contact point")
        a.plot(t, curves[f"{name}_pair"], "C1-", label="localised pair (TCA)")
        a.set_xlabel("pinion angle from the mean contact (deg)")
        a.set_ylabel("SRR" if name == "srr" else "R_eff (mm)")
        a.legend(fontsize=8)
    ax[1].set_title("localised pinion (+2 mm point radius, 2C 0.02)")
    ax[2].set_title("effective radius along the path")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)


def main():
    t0 = time.perf_counter()
    out = {"reference": "Eigenfunctions", "flank": "gear convex (drive)",
           "units": {"u_e, u_s": "mm per rad of pinion roll", "r_eff": "mm"}, "cutters": {}}
    axial_75 = curves = None
    for label, r0 in hk.STUDY_CUTTERS.items():
        inp = hk.study_blank_input(r0)
        sp = study_pair(inp, hk.StudySettings.make(r0), "convex")
        ms = sp.pair.pinion.machine
        entry = {"r0_mm": r0, "hand": sp.info["hand"], "chain_error_mm": float(sp.info["chain_error"]),
                 "pinion_settings": {"radial_distance_mm": float(ms.radial_distance),
                                     "cradle_angle_deg": math.degrees(float(ms.cradle_angle)),
                                     "tilt_deg": math.degrees(float(ms.tilt)),
                                     "swivel_deg": math.degrees(float(ms.swivel)),
                                     "blank_offset_mm": float(ms.blank_offset),
                                     "machine_root_angle_deg": math.degrees(float(ms.machine_root_angle)),
                                     "sliding_base_mm": float(ms.sliding_base),
                                     "center_to_back_mm": float(ms.center_to_back),
                                     "ratio_of_roll": float(ms.ratio_of_roll),
                                     "point_radius_mm": float(sp.pair.pinion.cutter.point_radius)}}
        conj, axial = conjugate_sweep(sp)
        entry["conjugate"] = conj
        # the [Eigenfunctions] model's own grid statistics, for the comparison of the trends
        _, f = hk.flank_fields(inp, hk.StudySettings.make(r0), "convex", shape=(31, 15))
        entry["seed_model_grid_stats"] = {n: _stats(np.asarray(getattr(f, n))) for n in FIELDS}
        entry["seed_model_grid_stats"]["abs_srr"] = _stats(np.abs(np.asarray(f.srr)))
        loc, cur = localised(sp)
        entry["localised"] = loc
        out["cutters"][label] = entry
        if label == "7.5in":
            axial_75, curves = axial, cur
            entry["d_dr0_pinion"] = cutter_radius_gradient(r0)
    out["seconds"] = time.perf_counter() - t0
    OUT.mkdir(exist_ok=True)
    atomic_write(OUT / "seed000_machine_pair.json", json.dumps(out, indent=1).encode())
    _figure(OUT / "seed000_machine_pair.png", axial_75, curves)
    for label, e in out["cutters"].items():
        c, lo = e["conjugate"], e["localised"]
        print(f"{label}: conjugate TE {c['te_max_arcsec']:.2e} arcsec, {c['contact_points']} points, "
              f"pair vs seed max rel diff {max(c['max_rel_diff_pair_vs_seed'].values()):.1e}; "
              f"mean|SRR| {c['stats_at_contact_points']['abs_srr']['mean']:.4f}, "
              f"min R_eff {c['stats_at_contact_points']['r_eff']['min']:.3f} mm; localised R_eff "
              f"{lo['r_eff']['pair']['mean']:.3f} vs seed {lo['r_eff']['seed_model']['mean']:.3f} mm")


if __name__ == "__main__":
    main()
