"""Pure-rolling bevel gears with a preset parabolic TE ([Preset-TE-bevel]): the numbers
and figures of docs/preset_te_bevel.md.

Parts (``python experiments/preset_te_bevel.py [part ...]``, default all):

* ``rolling``   -- the unmodified pair (kappa = 0): sliding along the contact curve
  over the pitch-line speed (library kinematics and the TCA path), TE, contact along
  Gamma1;
* ``preset``    -- the seed's example (36 arc-seconds): TE against the preset
  parabola, transfer points, contact ends against the unmodified pair, the loaded TE
  at a stated torque (load sharing of gearjax.loading.loaded_contact through
  ``gearjax.loading.mesh_efficiency``);
* ``robust``    -- assembly errors dE, dP, dG, dSigma: TE peak-to-peak and the TE jump
  at the transfer, unmodified and modified (table + figure);
* ``gradients`` -- d(TE p-t-p)/d(kappa, rho1, rho2) and d(largest transfer jump)/d(...)
  by jax.jacfwd against central differences;
* ``optimise``  -- kappa, rho1, rho2 by a jitted optax loop (minimize_optax) minimising
  the nominal TE p-t-p plus a hinge on the smooth maximum of the transfer gaps over a
  set of misalignments, with the bearing kept on the flank; the final design re-run
  by the forward model.

Writes experiments/results/preset_te_bevel.json (merged per part) and
preset_te_bevel_{te,paths,robustness,optimisation}.png.  Several minutes (XLA
compilation); run with ``nice``.
"""

import dataclasses
import json
import math
import sys
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import gearjax as gj
from gearjax.gears.preset_bevel import analysis as A
from gearjax.gears.preset_bevel import geometry as G
from gearjax.gears.preset_bevel.tca import ADAPTER
from gearjax.io import atomic_write, atomic_write_figure

OUT = Path(__file__).parent / "results"
JSON = OUT / "preset_te_bevel.json"
SPP = 24                      # grid steps per pitch
OPTS = dict(steps_per_pitch=SPP, half_pitches=1.0, n_pairs=3)
AS = gj.ARCSEC


def design():
    return gj.load_design("example:preset_te_bevel_10x30").design


def plain(des):
    return dataclasses.replace(des, kappa=jnp.asarray(0.0))


def tca(des, mis=None, side="drive", kinematics=False, throw=False):
    return gj.run_tca(des, mis, side=side, kinematics=kinematics, throw=throw, **OPTS)


def gaps_arcsec(res):
    return [float(g) / AS for g in A.transfer_gaps(res, 10, SPP)]


# -- pure rolling -------------------------------------------------------------------------

def part_rolling():
    des = plain(design())
    out = {}
    for side in ("drive", "coast"):
        t = time.perf_counter()
        res = tca(des, side=side, kinematics=True, throw=True)
        sec = time.perf_counter() - t
        on = np.asarray(res.on_flank)
        p = res.path
        phase = 0.0 if side == "drive" else math.pi / des.z1
        slide = np.asarray(A.sliding_ratio(res))[on]
        # second route: relative velocity from the TCA gear angles (central differences)
        phi, phi2 = np.asarray(p.phi1), np.asarray(p.phi2)
        w2 = np.gradient(phi2, phi)
        r = np.asarray(p.point)
        g = np.asarray(G.gear_assembly_rotation(des.shaft_angle))[:, 2]
        v12 = np.cross([0.0, 0.0, 1.0], r) - w2[:, None] * np.cross(g, r)
        ratio2 = (np.linalg.norm(v12, axis=1) / np.hypot(r[:, 0], r[:, 1]))[1:-1][on[1:-1]]
        out[side] = {
            "max_sliding_over_pitch_speed_kinematics": float(slide.max()),
            "max_sliding_over_pitch_speed_path": float(ratio2.max()),
            "max_abs_te_arcsec": float(np.abs(np.asarray(p.te)[on]).max() / AS),
            "max_abs_u1_rad": float(np.abs(np.asarray(p.uv1[:, 0])[on]).max()),
            "max_abs_t1_minus_phi1_rad": float(np.abs(np.asarray(p.uv1[:, 1] - p.phi1 + phase)[on]).max()),
            "max_abs_height_mm": float(np.abs(np.asarray(res.coords["h1"])[on]).max()),
            "contact_ratio": float(res.multi.contact_ratio),
            "contact_ratio_closed_form": float((G.curve_range(des)[2] - G.curve_range(des)[0])
                                               / (2 * math.pi / des.z1)),
            "r_x_mm_mid": float(res.kinematics.r_x[res.path.phi1.shape[0] // 2]),
            "r_y_mm_mid": float(res.kinematics.r_y[res.path.phi1.shape[0] // 2]),
            "on_flank_points": int(on.sum()), "seconds_incl_compile": sec}
    return {"rolling": out}


# -- preset TE, contact ends, loaded TE ---------------------------------------------------

TORQUES_NM, RPM = (2.0, 10.0, 50.0), 1000.0


def part_preset():
    des = design()
    out = {"kappa_rad": float(des.kappa), "preset_pinion_arcsec": 36.0,
           "preset_gear_arcsec": 36.0 * des.z1 / des.z2}
    res_m = tca(des, kinematics=True, throw=True)
    res_0 = tca(plain(des), kinematics=True, throw=True)
    on = np.asarray(res_m.on_flank)
    pre = np.asarray(A.preset_te(des, res_m))
    dev = np.abs(np.asarray(res_m.path.te) - pre)[on]
    mid = res_m.path.phi1.shape[0] // 2
    out["unloaded"] = {
        "max_deviation_gear_arcsec": float(dev.max() / AS),
        "max_deviation_pinion_arcsec": float(dev.max() / AS * des.z2 / des.z1),
        "te_ptp_arcsec": float(res_m.multi.ptp / AS),
        "transfer_phi1_rel_rad": [float(v) - float(res_m.path.phi1[mid])
                                  for v in np.asarray(res_m.multi.transfer_phi1)],
        "half_pitch_rad": math.pi / des.z1,
        "transfer_gaps_arcsec": gaps_arcsec(res_m),
        "contact_ratio": float(res_m.multi.contact_ratio),
        "flags": res_m.flags(),
        "contact_ends_modified": A.contact_ends(des, res_m),
        "contact_ends_unmodified": A.contact_ends(plain(des), res_0),
        "max_sliding_over_pitch_speed_on_flank": float(np.asarray(A.sliding_ratio(res_m))[on].max()),
    }
    # loaded TE through the loaded-contact models (mesh_efficiency runs the load sharing)
    oil, surf = gj.tribology.get_oil("mineral_vg100"), gj.tribology.make_surface(0.4)
    out["loaded"] = []
    curves = {}
    for T in TORQUES_NM:
        t = time.perf_counter()
        eff, res = gj.mesh_efficiency(des, T, RPM, oil, surf, side="drive", **OPTS)
        sec = time.perf_counter() - t
        lc = eff.loaded
        te_l = np.asarray(lc.te_loaded)
        env = np.asarray(res.multi.envelope)[A_window(res)]
        # envelope of the preset parabolas of the pairs over the cycle (min envelope, drive)
        y = (np.asarray(res.path.phi1)[A_window(res)]
             - float(res.path.phi1[res.path.phi1.shape[0] // 2]))
        pre_env = np.min([preset_curve(des, y - k * 2 * math.pi / des.z1, 1.0)
                          for k in (-1, 0, 1)], axis=0)
        shift = float(np.mean(te_l - pre_env))
        curves[T] = (te_l - shift, pre_env, res)
        out["loaded"].append({
            "torque_Nm": T, "rpm": RPM, "oil": "mineral_vg100", "sigma_um": 0.4,
            "te_loaded_ptp_arcsec": float(np.ptp(te_l) / AS),
            "mean_deflection_arcsec": shift / AS,
            "max_deviation_from_shifted_preset_arcsec": float(np.abs(te_l - pre_env - shift).max()
                                                              / AS),
            "max_deviation_unloaded_envelope_vs_preset_arcsec": float(np.abs(env - pre_env).max()
                                                                      / AS),
            "pairs_loaded_per_position": np.asarray(lc.n_loaded).tolist(),
            "max_p_max_MPa": float(eff.max_p_max), "mean_efficiency": float(eff.mean_efficiency),
            "valid_positions": int(np.sum(np.asarray(eff.valid))), "positions": int(te_l.size),
            "warnings": gj.efficiency_warnings(eff, res), "seconds_incl_compile": sec})
    _figure_te(des, res_m, res_0, curves)
    _figure_paths(des, res_0, res_m)
    return {"preset": out}


def preset_curve(des, y, s):
    """The preset TE (gear angle, rad) at pinion angle y from the reference (closed form
    of gearjax.gears.preset_bevel.analysis.preset_te)."""
    k = float(des.kappa)
    x = 2.0 * y / (1.0 + np.sqrt(np.maximum(1.0 - 4.0 * s * k * y, 0.0)))
    return s * (des.z1 / des.z2) * k * x ** 2


def A_window(res):
    n = res.path.phi1.shape[0]
    mid = n // 2
    return np.arange(mid - SPP // 2, mid - SPP // 2 + SPP)


def _figure_te(des, res_m, res_0, curves):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    phi = np.asarray(res_m.path.phi1)
    mid = phi[phi.shape[0] // 2]
    for k, col in zip((-1, 0, 1), ("C1", "C0", "C2")):
        tp = np.asarray(res_m.multi.te_pairs)[k + 1]
        ax[0].plot(np.degrees(phi - mid), tp / AS, col, label=f"TCA pair {k:+d}")
        sh = preset_curve(des, phi - mid - k * 2 * math.pi / des.z1, 1.0)
        ins = np.asarray(res_m.multi.inside)[k + 1]
        ax[0].plot(np.degrees(phi - mid)[ins], sh[ins] / AS, "k:", lw=1)
    ax[0].plot([], [], "k:", label="preset parabola")
    ax[0].set_xlabel("pinion angle from mid-face contact (deg)")
    ax[0].set_ylabel("TE, gear angle (arcsec)")
    ax[0].set_title("unloaded TE of the modified pair (drive)")
    ax[0].legend(fontsize=8)
    first = True
    for T, (te_l, pre_env, res) in curves.items():
        x = np.degrees(np.asarray(res.path.phi1)[A_window(res)] - mid)
        if first:
            ax[1].plot(x, pre_env / AS, "k-", lw=2, label="preset envelope")
            first = False
        ax[1].plot(x, te_l / AS, "--", label=f"loaded TE, {T:g} N m (mean deflection removed)")
    ax[1].set_xlabel("pinion angle (deg)")
    ax[1].set_ylabel("TE (arcsec)")
    ax[1].set_title("loaded TE against the preset (one mesh cycle)")
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    atomic_write_figure(fig, OUT / "preset_te_bevel_te.png")


def _figure_paths(des, res_0, res_m):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7, 3.5))
    Ai, _, Ao = (float(v) for v in G.cone_distances(des))
    ha, hf = float(des.addendum), float(des.dedendum)
    ax.plot([Ai, Ao, Ao, Ai, Ai], [-hf, -hf, ha, ha, -hf], "k-", lw=1)
    cases = [(res_0, "unmodified", "C0"), (res_m, "preset 36 arcsec", "C3")]
    if JSON.exists() and "optimisation" in json.loads(JSON.read_text()):
        fin = json.loads(JSON.read_text())["optimisation"]["final"]
        best = dataclasses.replace(des, kappa=jnp.asarray(fin["kappa"]),
                                   rho1=jnp.asarray(fin["rho1"]), rho2=jnp.asarray(fin["rho2"]))
        cases.append((tca(best), "optimised (kappa, rho1, rho2)", "C2"))
    for res, lab, col in cases:
        carry = (np.asarray(res.multi.active) == 1) & np.asarray(res.on_flank)
        if res is res_0:
            carry = np.asarray(res.on_flank)
        L, h = np.asarray(res.coords["L1"]), np.asarray(res.coords["h1"])
        ax.plot(L[carry], 10 * h[carry], "o-", color=col, ms=3, label=lab + " (h x10)")
    ax.set_xlabel("cone distance on the pinion (mm): toe -> heel")
    ax.set_ylabel("height above pitch cone (mm; paths x10)")
    ax.set_title("contact path carrying the load (pair 0, unloaded envelope)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    atomic_write_figure(fig, OUT / "preset_te_bevel_paths.png")


# -- robustness ---------------------------------------------------------------------------

ROBUST = [("dE", 0.005), ("dE", -0.005), ("dE", 0.01), ("dE", -0.01),
          ("dP", 0.005), ("dP", -0.005), ("dP", 0.01), ("dP", -0.01),
          ("dG", 0.02), ("dG", -0.02), ("dG", 0.05), ("dG", -0.05),
          ("dSigma", 0.05), ("dSigma", -0.05), ("dSigma", 0.1), ("dSigma", -0.1)]


def mis_of(name, v):
    return (gj.Misalignment.create(dSigma_deg=v) if name == "dSigma"
            else gj.Misalignment.create(**{name: v}))


def part_robust():
    des = design()
    rows = []
    for name, v in ROBUST:
        row = {"error": name, "value": v, "unit": "deg" if name == "dSigma" else "mm"}
        for lab, d in (("unmodified", plain(des)), ("modified", des)):
            res = tca(d, mis_of(name, v))
            g = gaps_arcsec(res)
            row[lab] = {"te_ptp_arcsec": float(res.multi.ptp / AS),
                        "jump_arcsec": max(0.0, max(g)), "gaps_arcsec": g,
                        "warnings": res.warnings()}
        rows.append(row)
    _figure_robust(rows)
    return {"robustness": rows}


def _figure_robust(rows):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(10, 3.8))
    x = np.arange(len(rows))
    for off, lab, col in ((-0.2, "unmodified", "C0"), (0.2, "modified", "C3")):
        ax.bar(x + off, [r[lab]["jump_arcsec"] for r in rows], 0.4, color=col,
               label=f"{lab}: TE jump at transfer")
        ax.plot(x + off, [r[lab]["te_ptp_arcsec"] for r in rows], "k_", ms=10)
    ax.plot([], [], "k_", label="TE peak-to-peak")
    ax.set_xticks(x, [f"{r['error']}\n{r['value']:+g}" for r in rows], fontsize=7)
    ax.set_ylabel("arcsec (gear angle)")
    ax.set_title("assembly errors (mm; dSigma in deg): unmodified vs preset 36 arcsec")
    ax.legend(fontsize=8)
    fig.tight_layout()
    atomic_write_figure(fig, OUT / "preset_te_bevel_robustness.png")


# -- gradients ----------------------------------------------------------------------------

GRAD_MIS = dict(dG=0.05)


def _objectives(des, fn, mis):
    def f(x):
        d = dataclasses.replace(des, kappa=x[0], rho1=x[1], rho2=x[2])
        r = fn(d, mis)
        return jnp.stack([r.multi.ptp, A.transfer_jump(r, 10, SPP)])
    return f


def part_gradients():
    des = design()
    fn = ADAPTER.traced(des, side="drive", kinematics=False, **OPTS)
    mis = gj.Misalignment.create(**GRAD_MIS)
    f = _objectives(des, fn, mis)
    x0 = jnp.stack([des.kappa, des.rho1, des.rho2])
    t = time.perf_counter()
    J = np.asarray(jax.jit(jax.jacfwd(f))(x0))
    sec = time.perf_counter() - t
    out = {"misalignment": GRAD_MIS, "values_rad": np.asarray(f(x0)).tolist(),
           "names": ["te_ptp", "largest_transfer_jump"], "fields": ["kappa", "rho1", "rho2"],
           "jacfwd": J.tolist(), "seconds_jacfwd_incl_compile": sec, "central": [], "rel_err": []}
    for i in range(3):
        h = 1e-4 * float(x0[i])
        e = jnp.zeros(3).at[i].set(h)
        fd = (np.asarray(f(x0 + e)) - np.asarray(f(x0 - e))) / (2 * h)
        out["central"].append(fd.tolist())
        out["rel_err"].append((np.abs(J[:, i] - fd) / np.abs(fd)).tolist())
    out["max_rel_err"] = float(np.max(out["rel_err"]))
    return {"gradients": out}


# -- optimisation -------------------------------------------------------------------------

OPT_SET = [("dE", 0.005), ("dE", -0.005), ("dP", 0.005), ("dP", -0.005),
           ("dG", 0.03), ("dG", -0.03), ("dSigma", 0.05), ("dSigma", -0.05)]
TAU, W_HINGE, W_H = 0.25, 4.0, 10.0      # arcsec, -, 1/mm^2


def stack_mis(items):
    ms = [mis_of(n, v) for n, v in items]
    return jax.tree_util.tree_map(lambda *a: jnp.stack(a), *ms)


def part_optimise():
    des = design()
    fn = ADAPTER.traced(des, side="drive", kinematics=False, **OPTS)
    mset = stack_mis(OPT_SET)
    k0 = float(des.kappa)
    scale = jnp.array([k0, 16.0, 16.0])

    def terms(x):
        d = dataclasses.replace(des, kappa=x[0] * scale[0], rho1=x[1] * scale[1],
                                rho2=x[2] * scale[2])
        r0 = fn(d, gj.Misalignment.zero())
        rs = jax.vmap(lambda m: fn(d, m))(mset)
        gi, go = jax.vmap(lambda r: jnp.stack(A.transfer_gaps(r, 10, SPP)))(rs).T
        gmax = A.smooth_max(jnp.concatenate([gi, go]) / AS, TAU)
        mid = r0.path.phi1.shape[0] // 2
        hpen = jnp.sum(jnp.maximum(jnp.abs(rs.coords["h1"][:, mid]) - 0.5 * d.addendum, 0.0) ** 2)
        return r0.multi.ptp / AS, gmax, hpen

    def fun(x):
        p, g, hp = terms(x)
        return p + W_HINGE * TAU * jax.nn.softplus(g / TAU) + W_H * hp

    x0 = jnp.array([1.0, 1.0, 1.0])
    import optax
    t = time.perf_counter()
    opt = gj.minimize_optax(fun, x0, optimizer=optax.adam(0.05), steps=40, mode="fwd",
                            lower=jnp.array([0.0, 6.0 / 16, 6.0 / 16]),
                            upper=jnp.array([8.0, 4.0, 4.0]))
    sec = time.perf_counter() - t
    x = opt.x
    best = dataclasses.replace(des, kappa=x[0] * scale[0], rho1=x[1] * scale[1],
                               rho2=x[2] * scale[2])
    t0, tm, _ = (float(v) for v in G.curve_range(best))
    check = []
    for name, v in [("none", 0.0)] + OPT_SET:
        for lab, d in (("start", des), ("optimised", best)):
            res = tca(d, None if name == "none" else mis_of(name, v))
            g = gaps_arcsec(res)
            check.append({"error": name, "value": v, "design": lab,
                          "te_ptp_arcsec": float(res.multi.ptp / AS),
                          "jump_arcsec": max(0.0, max(g)), "flags": res.flags()})
    hist = np.asarray(opt.history)
    _figure_opt(hist, np.asarray(opt.x_history) * np.asarray(scale))
    out = {"set": OPT_SET, "tau_arcsec": TAU, "w_hinge": W_HINGE, "w_height": W_H,
           "start": {"kappa": k0, "rho1": 16.0, "rho2": 16.0, "objective": float(hist[0])},
           "final": {"kappa": float(best.kappa), "rho1": float(best.rho1), "rho2": float(best.rho2),
                     "preset_pinion_arcsec": float(best.kappa) * (t0 - tm) ** 2 / AS,
                     "objective": float(opt.value)},
           "status": opt.message, "final_grad_norm": float(opt.grad_norm),
           "steps": int(opt.steps), "history": hist.tolist(), "seconds_incl_compile": sec,
           "forward_check": check}
    return {"optimisation": out}


def _figure_opt(hist, xs):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.5))
    ax[0].plot(hist, "k.-")
    ax[0].set_xlabel("step")
    ax[0].set_ylabel("objective (arcsec)")
    ax[1].plot(xs[:, 0] / xs[0, 0], label="kappa / kappa_36")
    ax[1].plot(xs[:, 1] / 16, label="rho1 / 16 mm")
    ax[1].plot(xs[:, 2] / 16, label="rho2 / 16 mm")
    ax[1].set_xlabel("step")
    ax[1].legend(fontsize=8)
    fig.tight_layout()
    atomic_write_figure(fig, OUT / "preset_te_bevel_optimisation.png")


PARTS = {"rolling": part_rolling, "preset": part_preset, "robust": part_robust,
         "gradients": part_gradients, "optimise": part_optimise}


def main(argv):
    import os
    # keep compiled programs between runs of the parts (several minutes each)
    jax.config.update("jax_compilation_cache_dir",
                      os.environ.get("PRESET_TE_CACHE", "/tmp/preset_te_bevel_jax_cache"))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 5.0)
    names = argv or list(PARTS)
    data = json.loads(JSON.read_text()) if JSON.exists() else {}
    for n in names:
        t = time.perf_counter()
        data.update(PARTS[n]())
        data.setdefault("seconds", {})[n] = time.perf_counter() - t
        data["machine"] = "2 shared CPU cores (helper sandbox), XLA default flags"
        atomic_write(JSON, json.dumps(gj_io_finite(data), indent=1) + "\n")
        print(n, "done", round(time.perf_counter() - t, 1), "s", flush=True)


def gj_io_finite(obj):
    from gearjax.io import finite_json
    return finite_json(obj)[0]


if __name__ == "__main__":
    main(sys.argv[1:])
