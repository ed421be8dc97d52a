"""VH-CATT pair of [VH-CATT] (z 17/23, m 4, alpha 20 deg, b 28 mm, R_T 400 mm): geometry
checks, contact, loaded mesh, friction and efficiency along the mesh, the seed's
trends as numbers, Stribeck curves (docs/vh_catt.md).

Writes ``experiments/results/vh_catt_friction.json``, ``vh_catt_friction.md`` and the
figures ``vh_catt_mu_path.png``, ``vh_catt_stribeck.png``, ``vh_catt_trends.png``.
Run: ``PYTHONPATH=. python experiments/vh_catt_friction.py``.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import gearjax as gj
from gearjax.gears.vh_catt import geometry as G

OUT = Path(__file__).parent / "results"
BASE = dict(torque=100.0, rpm=1000.0, oil="mineral_vg100", sigma=0.4)


def geometry_checks(pair):
    """Deviation of transverse sections from the involute (after the best rotation)."""
    us = jnp.linspace(-2.5, 3.6, 41)
    zs = jnp.array([0.0, 3.5, 7.0, 10.5, 14.0])
    out = []
    for mem in ("pinion", "gear"):
        z = pair.teeth(mem)
        r = 0.5 * z * 4.0
        rb = r * math.cos(math.radians(20))
        for s in (1.0, -1.0):
            P = np.asarray(jax.jit(jax.vmap(jax.vmap(
                lambda u, zz: G.section_point(pair, mem, s, u, zz), (0, None)), (None, 0)))(us, zs))
            for i, zz in enumerate(np.asarray(zs)):
                R = np.hypot(P[i, :, 0], P[i, :, 1])
                ok = R > rb * (1 + 1e-6)
                ref = np.asarray(G.involute_polar_angle(R[ok], rb, r, math.pi * 2.0,
                                                        math.radians(20), s))
                dphi = np.arctan2(P[i, ok, 1], P[i, ok, 0]) - ref
                d = R[ok] * dphi
                # the shape part: what is left after the best rotation about the axis
                # (least squares in R dphi: delta = sum R^2 dphi / sum R^2)
                delta = np.sum(R[ok] ** 2 * dphi) / np.sum(R[ok] ** 2)
                out.append(dict(member=mem, flank=G.SIDE_NAMES[(mem, int(s))], z_mm=float(zz),
                                max_abs_mm=float(np.max(np.abs(d))),
                                shape_dev_mm=float(np.max(np.abs(R[ok] * (dphi - delta)))),
                                radii_mm=[float(R[ok].min()), float(R[ok].max())]))
    return out


def stribeck_param(eff, oil):
    """eta0 u_e / F_n per contact (Pa s * m/s / N = 1/m ... reported in m/N * Pa s * m/s)."""
    F = np.asarray(eff.loaded.load)
    ue = np.asarray(eff.u_e) * 1e-3
    with np.errstate(divide="ignore", invalid="ignore"):
        return float(oil.eta0) * ue / F


def main():
    t_all = time.time()
    design = gj.load_design("example:vh_catt_17x23")
    pair = design.pair
    Ep = design.e_prime_MPa()
    res = {}
    geo = {k: float(v) for k, v in G.pair_geometry(pair).items()}
    res["pair_geometry"] = geo
    res["tooth_form"] = {m: {k: (v.tolist() if isinstance(v, np.ndarray) else v)
                             for k, v in d.items()} for m, d in G.tooth_form(pair).items()}
    res["sections"] = geometry_checks(pair)

    # -- unloaded TCA, aligned and misaligned ------------------------------------------
    tca = []
    for label, mis in (("aligned", gj.Misalignment.zero()),
                       ("dE 0.05 mm", gj.Misalignment.create(dE=0.05)),
                       ("dP 0.1 mm", gj.Misalignment.create(dP=0.1)),
                       ("dG 0.1 mm", gj.Misalignment.create(dG=0.1)),
                       ("dSigma 0.01 deg", gj.Misalignment.create(dSigma_deg=0.01)),
                       ("dSigma 0.02 deg", gj.Misalignment.create(dSigma_deg=0.02))):
        for side in ("drive", "coast"):
            r = gj.run_tca(design, mis, side=side, throw=False)
            mid = r.phi1.shape[0] // 2
            on = np.asarray(r.on_flank)
            tca.append(dict(misalignment=label, side=side,
                            ptp_arcsec=float(r.ptp) / gj.ARCSEC,
                            contact_ratio=float(r.contact_ratio),
                            axial_ref_mm=float(r.path.axial1[mid]),
                            axial_range_mm=[float(np.min(np.asarray(r.path.axial1)[on])),
                                            float(np.max(np.asarray(r.path.axial1)[on]))],
                            semi_major_ref_mm=float(r.path.semi_major[mid]),
                            transfer_phi1_rad=[float(v) for v in np.asarray(r.transfer_phi1)],
                            flags=r.flags()))
    res["tca"] = tca

    # -- loaded mesh at the base point --------------------------------------------------
    def run(torque=BASE["torque"], rpm=BASE["rpm"], oil=None, sigma=BASE["sigma"]):
        oil = gj.tribology.get_oil(BASE["oil"]) if oil is None else oil
        return gj.mesh_efficiency(design, torque, rpm, oil, gj.tribology.make_surface(sigma), E_prime=Ep)

    t0 = time.time()
    eff, r = run()
    t_first = time.time() - t0
    K, Mpos = np.asarray(eff.loaded.load).shape
    spp = 24
    idx = np.asarray(jnp.arange(Mpos)) + (r.phi1.shape[0] // 2 - spp // 2)
    # mu along the path of one tooth pair (pair 0 of the TCA grid): pair k at cycle
    # position j is pair 0 at grid index j - k spp
    rb1 = geo["rb1"]
    path = []
    for k in range(K):
        kk = k - K // 2
        for j in range(Mpos):
            i = idx[j] - kk * spp
            F = float(eff.loaded.load[k, j])
            if F > 0 and 0 <= i < r.phi1.shape[0]:
                R1 = float(r.path.radial1[i])
                path.append(dict(s_mm=math.sqrt(max(R1 ** 2 - rb1 ** 2, 0)) - geo["rho_P"],
                                 load_N=F, share=float(eff.loaded.share[k, j]),
                                 mu=float(eff.friction.mu[k, j]),
                                 lam=float(eff.friction.lam[k, j]),
                                 u_s_mm_s=float(eff.u_s[k, j]), u_e_mm_s=float(eff.u_e[k, j]),
                                 p_max_MPa=float(eff.loaded.p_max[k, j])))
    path.sort(key=lambda d: d["s_mm"])
    res["mu_path"] = path
    res["cycle"] = dict(phi1=np.asarray(eff.phi1).tolist(),
                        share=np.asarray(eff.loaded.share).tolist(),
                        p_max=np.asarray(eff.loaded.p_max).tolist(),
                        mu=np.asarray(eff.friction.mu).tolist(),
                        power_loss_W=np.asarray(eff.power_loss).tolist(),
                        efficiency=np.asarray(eff.efficiency).tolist(),
                        eta_bar=float(eff.mean_efficiency), mean_mu=float(eff.mean_mu),
                        max_p_max=float(eff.max_p_max), valid=bool(np.all(eff.valid)),
                        warnings=gj.efficiency_warnings(eff, r), seconds_first=t_first)

    # -- the seed's Hertz formula at the most loaded contact ---------------------------
    from scipy.optimize import brentq
    from scipy.special import ellipe, ellipk
    kj = np.unravel_index(np.argmax(np.asarray(eff.loaded.load)), (K, Mpos))
    F = float(eff.loaded.load[kj]); Rx = float(eff.r_x[kj]); Ry = float(eff.r_y[kj])
    A, B = 0.5 / Ry, 0.5 / Rx
    m = brentq(lambda m: (ellipe(m) / (1 - m) - ellipk(m)) / (ellipk(m) - ellipe(m)) - B / A,
               1e-12, 1 - 1e-15, xtol=1e-16, rtol=1e-15)
    ka = (2 * ellipe(m) / (math.pi * (1 - m))) ** (1 / 3)
    base = (3 * F / (2 * Ep * (A + B))) ** (1 / 3)
    hz = gj.tribology.hertz_point(F, Rx, Ry, Ep)
    res["hertz"] = dict(F_N=F, r_x_mm=Rx, r_y_mm=Ry, k_a=ka, k_b=ka * math.sqrt(1 - m),
                        seed_a_mm=ka * base, seed_b_mm=ka * math.sqrt(1 - m) * base,
                        gearjax_a_mm=float(hz.a), gearjax_b_mm=float(hz.b),
                        gearjax_p_max_MPa=float(hz.p_max),
                        face_half_width_mm=0.5 * float(pair.face_width))

    # -- trends ------------------------------------------------------------------------
    oil0 = gj.tribology.get_oil(BASE["oil"])

    def oil_eta(f):
        return gj.tribology.make_oil(float(oil0.eta0) * f, alpha_per_GPa=22.0, tau0_MPa=5.0, rho0=880.0,
                           name="scaled")

    def summary(e, rr):
        mu = np.asarray(e.friction.mu)
        F = np.asarray(e.loaded.load)
        lam = np.where(F > 0, np.asarray(e.friction.lam), np.nan)
        return dict(eta_bar=float(e.mean_efficiency), mean_mu=float(e.mean_mu),
                    max_mu=float(np.max(np.where(F > 0, mu, 0))),
                    min_lambda=float(np.nanmin(lam)), max_p_max=float(e.max_p_max),
                    valid=bool(np.all(e.valid)))

    trends = {}
    trends["speed_rpm"] = [dict(value=v, **summary(*run(rpm=v))) for v in
                           (50.0, 200.0, 1000.0, 3000.0, 10000.0)]
    trends["viscosity_factor"] = [dict(value=f, eta0_Pas=float(oil0.eta0) * f,
                                       **summary(*run(oil=oil_eta(f))))
                                  for f in (0.25, 0.5, 1.0, 2.0, 4.0)]
    trends["viscosity_factor_10000rpm"] = [dict(value=f, eta0_Pas=float(oil0.eta0) * f,
                                                **summary(*run(rpm=10000.0, oil=oil_eta(f))))
                                           for f in (0.25, 0.5, 1.0, 2.0, 4.0)]
    trends["sigma_um"] = [dict(value=s, **summary(*run(sigma=s))) for s in
                          (0.1, 0.2, 0.4, 0.8, 1.6)]
    trends["torque_Nm"] = [dict(value=t, **summary(*run(torque=t))) for t in
                           (25.0, 50.0, 100.0, 200.0, 400.0)]
    res["trends"] = trends

    # -- Stribeck curves: mu of the contacts vs eta0 u_e / F_n over a speed sweep -------
    speeds = np.geomspace(5.0, 50000.0, 13)
    variants = {"base": {}, "load x4": dict(torque=400.0), "sigma x2": dict(sigma=0.8),
                "eta0 x2": dict(oil=oil_eta(2.0))}
    strib = {}
    for name, kw in variants.items():
        pts = []
        for n in speeds:
            e, _ = run(rpm=float(n), **kw)
            F = np.asarray(e.loaded.load)
            on = F > 0
            oil = kw.get("oil", oil0)
            par = float(oil.eta0) * np.asarray(e.u_e)[on] * 1e-3 / F[on]
            pts.append(dict(rpm=float(n), param_median=float(np.median(par)),
                            mu_mean=float(e.mean_mu),
                            lam_median=float(np.median(np.asarray(e.friction.lam)[on])),
                            param=par.tolist(), mu=np.asarray(e.friction.mu)[on].tolist(),
                            lam=np.asarray(e.friction.lam)[on].tolist()))
        strib[name] = pts
    res["stribeck"] = strib

    def transition(pts, lam_t):
        """Stribeck parameter at which the median lambda crosses lam_t (log interp)."""
        x = np.log([p["param_median"] for p in pts])
        y = np.log([p["lam_median"] for p in pts])
        if not (y.min() < math.log(lam_t) < y.max()):
            return float("nan")
        return float(np.exp(np.interp(math.log(lam_t), y, x)))

    res["stribeck_transitions"] = {
        name: dict(param_at_lambda_1=transition(p, 1.0), param_at_lambda_3=transition(p, 3.0),
                   mu_min=min(q["mu_mean"] for q in p),
                   param_at_mu_min=min(p, key=lambda q: q["mu_mean"])["param_median"])
        for name, p in strib.items()}
    res["seconds_total"] = time.time() - t_all
    OUT.mkdir(exist_ok=True)
    gj.io.atomic_write(OUT / "vh_catt_friction.json", json.dumps(res, indent=1, default=float))
    write_markdown(res)
    figures(res)


SEED = {"speed_rpm": "mu decreases; eta increases quickly at low speed, levels off",
        "viscosity_factor": "mu increases; eta: better at low speed, optimum medium viscosity",
        "viscosity_factor_10000rpm": "(high speed, full film) mu increases with viscosity; "
                                     "eta: optimum medium viscosity",
        "sigma_um": "mu increases; eta strongly lower at low speed, negligible in full film",
        "torque_Nm": "mu increases (at the pitch point); eta decreases"}


def write_markdown(res):
    g = res["pair_geometry"]
    L = ["# VH-CATT 17x23 ([VH-CATT] Table 1): geometry, contact, friction and efficiency", ""]
    L += ["## Contact ratios", "",
          f"eps_alpha = {g['eps_alpha']:.6f} (middle section), trace extent over the half face "
          f"{g['trace_extent']:.4f} mm, eps_beta = {g['eps_beta']:.5f}, eps_gamma = "
          f"{g['eps_gamma']:.6f}.", ""]
    L += ["## Sections against the involute (deviation along the circle of each radius: max |.| "
          "and max |.| after the best rotation about the axis)", "",
          "| member | flank | z (mm) | max abs (mm) | after best rotation (mm) |", "|---|---|---|---|---|"]
    for s in res["sections"]:
        L.append(f"| {s['member']} | {s['flank']} | {s['z_mm']:.1f} | {s['max_abs_mm']:.3e} | "
                 f"{s['shape_dev_mm']:.3e} |")
    L += ["", "## Unloaded TCA", "",
          "| misalignment | side | TE ptp (arcsec) | contact ratio | z at ref (mm) | z range (mm) "
          "| semi-major at ref (mm) | flags raised |", "|---|---|---|---|---|---|---|---|"]
    for t in res["tca"]:
        fl = ", ".join(k for k, v in t["flags"].items() if (v if k != "converged" and
                                                              k != "reference_on_flank" else not v))
        L.append(f"| {t['misalignment']} | {t['side']} | {t['ptp_arcsec']:.4g} | "
                 f"{t['contact_ratio']:.4f} | {t['axial_ref_mm']:.3f} | "
                 f"{t['axial_range_mm'][0]:.2f} .. {t['axial_range_mm'][1]:.2f} | "
                 f"{t['semi_major_ref_mm']:.3f} | {fl or '-'} |")
    h = res["hertz"]
    L += ["", "## Hertz: the seed's formula against gearjax's exact ellipse (most loaded contact)",
          "", f"F = {h['F_N']:.1f} N, r_x = {h['r_x_mm']:.4f} mm, r_y = {h['r_y_mm']:.1f} mm: "
          f"k_a = {h['k_a']:.4f}, k_b = {h['k_b']:.5f}; seed a = {h['seed_a_mm']:.6f} mm, "
          f"b = {h['seed_b_mm']:.6f} mm; gearjax a = {h['gearjax_a_mm']:.6f} mm, b = "
          f"{h['gearjax_b_mm']:.6f} mm, p_max = {h['gearjax_p_max_MPa']:.1f} MPa "
          f"(half face width {h['face_half_width_mm']} mm)."]
    c = res["cycle"]
    L += ["", f"## Loaded mesh at {BASE['torque']} N m, {BASE['rpm']} rpm, {BASE['oil']}, "
          f"sigma {BASE['sigma']} um", "",
          f"eta_bar = {c['eta_bar']:.6f}, mean mu = {c['mean_mu']:.5f}, max p_max = "
          f"{c['max_p_max']:.1f} MPa, valid = {c['valid']}, warnings: {c['warnings'] or 'none'}.",
          "", "| position | phi1 (rad) | shares (pairs -1, 0, +1) | mu of pair 0 | P_f (W) | eta_m |",
          "|---|---|---|---|---|---|"]
    for j, ph in enumerate(c["phi1"]):
        sh = ", ".join(f"{c['share'][k][j]:.3f}" for k in range(len(c["share"])))
        L.append(f"| {j} | {ph:.5f} | {sh} | {c['mu'][1][j]:.4f} | {c['power_loss_W'][j]:.2f} | "
                 f"{c['efficiency'][j]:.5f} |")
    L += ["", "## mu along the path of one tooth (s from the pitch point, mm)", "",
          "| s (mm) | load (N) | mu | lambda | u_s (mm/s) | p_max (MPa) |", "|---|---|---|---|---|---|"]
    for p in res["mu_path"]:
        L.append(f"| {p['s_mm']:.3f} | {p['load_N']:.1f} | {p['mu']:.4f} | {p['lam']:.3f} | "
                 f"{p['u_s_mm_s']:.1f} | {p['p_max_MPa']:.0f} |")
    L += ["", "## Trends (seed's direction beside gearjax's numbers)", ""]
    for key, rows in res["trends"].items():
        L += [f"### {key} — seed: {SEED[key]}", "",
              "| value | eta_bar | mean mu | max mu | min lambda | max p_max (MPa) | valid |",
              "|---|---|---|---|---|---|---|"]
        for r in rows:
            L.append(f"| {r['value']:g} | {r['eta_bar']:.6f} | {r['mean_mu']:.5f} | "
                     f"{r['max_mu']:.5f} | {r['min_lambda']:.3f} | {r['max_p_max']:.0f} | "
                     f"{r['valid']} |")
        L.append("")
    L += ["## Stribeck curves: transitions (eta0 u_e / F_n, Pa s m/s per N)", "",
          "| variant | at lambda = 1 | at lambda = 3 | min mean mu | at |", "|---|---|---|---|---|"]
    for k, v in res["stribeck_transitions"].items():
        L.append(f"| {k} | {v['param_at_lambda_1']:.3e} | {v['param_at_lambda_3']:.3e} | "
                 f"{v['mu_min']:.5f} | {v['param_at_mu_min']:.3e} |")
    L += ["", f"Total run time {res['seconds_total']:.0f} s (2 shared CPU cores)."]
    gj.io.atomic_write(OUT / "vh_catt_friction.md", "\n".join(L) + "\n")


def figures(res):
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    from gearjax.io import atomic_write_figure
    fig = Figure(figsize=(6, 4))
    ax = fig.add_subplot()
    p = res["mu_path"]
    ax.plot([q["s_mm"] for q in p], [q["mu"] for q in p], "o-")
    ax.set_xlabel("position on the path from the pitch point s (mm)")
    ax.set_ylabel("mu")
    ax.set_title("VH-CATT 17x23: friction along the path of one tooth")
    atomic_write_figure(fig, OUT / "vh_catt_mu_path.png")
    fig = Figure(figsize=(6, 4))
    ax = fig.add_subplot()
    for name, pts in res["stribeck"].items():
        ax.loglog([q["param_median"] for q in pts], [q["mu_mean"] for q in pts], "o-", label=name)
    ax.set_xlabel("eta0 u_e / F_n (median over the loaded contacts)")
    ax.set_ylabel("mean mu")
    ax.legend()
    atomic_write_figure(fig, OUT / "vh_catt_stribeck.png")
    fig = Figure(figsize=(12, 6))
    for i, (key, rows) in enumerate(res["trends"].items()):
        ax = fig.add_subplot(2, 3, i + 1)
        ax.semilogx([r["value"] for r in rows], [r["eta_bar"] for r in rows], "o-")
        ax.set_xlabel(key)
        ax.set_ylabel("eta_bar")
    fig.tight_layout()
    atomic_write_figure(fig, OUT / "vh_catt_trends.png")


if __name__ == "__main__":
    main()
