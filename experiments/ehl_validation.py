"""Validation of the numerical EHL point-contact solver (gearjax.tribology.ehl).

Parts (run all, or name some on the command line: moes grid fig rot fast):

* ``moes``: circular contacts over Moes M = 20..1000 at L = 10 (plus L = 5, 20 at
  M = 100 and two elliptical contacts, Ry/Rx = 4), 128 x 128 nodes: central and
  minimum film against Hamrock & Dowson (1977) and the Nijenbanning–Venner–Moes
  (1994) central-film formula, load error, residual.  Fixed: E' = 226.4 GPa,
  Rx = 10 mm, η0 = 0.088 Pa·s, α = 22 GPa⁻¹; u_e and F are chosen to give (M, L).
* ``grid``: grid convergence of one case (F = 100 N, u_e = 1 m/s, M = 168,
  L = 14.8) on 64², 128², 256² nodes (512² with EHL_VAL_512=1; fine-grid tolerance
  EHL_VAL_TOL_FINE; scheme from EHL_VAL_UPWIND and EHL_VAL_LIMITER), each solution
  with a one-Newton-step estimate of its distance to the discrete root.
* ``fig``: pressure spike and horseshoe film (M = 200, L = 10, 128²) ->
  results/ehl_fields.png.
* ``rot``: circular contact, entrainment at 0° and 90° (must agree) and 30°.
* ``fast``: a small subset of the regime grid of the issue, mixed lubrication
  (Greenwood–Tripp, σ set from the target λ = h_c,HD/σ), 64², μ of the fast
  model gearjax.tribology.friction_coefficient against the numerical μ.

Writes results/ehl_validation.json and results/ehl_validation.md (tables).
Usage: python experiments/ehl_validation.py [parts...]   (``md``: merge the part files
written with EHL_VAL_PART_FILE=ehl_validation_partN.json and rewrite the tables)
"""

from __future__ import annotations

import json
import os
import sys
import time

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

from gearjax.tribology.ehl import ehl_fields, solve_ehl  # noqa: E402
from gearjax.tribology.ehl.model import scales  # noqa: E402
from gearjax.tribology.ehl.references import film_from_moes, moes_variables  # noqa: E402
from gearjax.tribology.film import hamrock_dowson  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "results")
E, RX, ETA0, ALPHA = 226373.6, 10.0, 0.088, 22.0


def case_for(M, L, Ry=RX):
    G = ALPHA * 1e-3 * E
    two_u = (L / G) ** 4
    u_e = 0.5 * two_u * E * RX / (ETA0 * 1e-6)
    F = M * two_u ** 0.75 * E * RX * RX
    return F, u_e, Ry


def run_case(F, u_e, Ry, n, angle=0.0, srr=0.2, **kw):
    t = time.time()
    res, case, grid = solve_ehl(F, u_e, srr * u_e, RX, Ry, ETA0, ALPHA, n=n, angle_deg=angle,
                                throw=False, **kw)
    dt = time.time() - t
    sc = scales(case)
    p_max = float(np.max(ehl_fields(res, case, grid, bool(res.x.shape[0] > grid.nx * grid.ny + 1))["p"]))
    hc, hm = (float(v) for v in hamrock_dowson(case.F, case.Rx, sc.k, case.u_e, case.eta0,
                                               case.alpha, case.E_prime))
    M, L, _ = moes_variables(case.F, case.u_e, case.Rx, case.eta0, case.alpha, case.E_prime)
    return dict(F=F, u_e=u_e, Ry=Ry, n=n, angle=angle, M=float(M), L=float(L),
                p_h=float(sc.p_h), k=float(sc.k), h_c=float(res.h_c) * 1e3,
                h_min=float(res.h_min) * 1e3, hc_HD=hc * 1e3, hmin_HD=hm * 1e3,
                hc_NVM=float(film_from_moes(case.F, case.u_e, case.Rx, case.Ry, case.eta0,
                                            case.alpha, case.E_prime)) * 1e3,
                mu=float(res.mu), p_max=p_max, load_error=float(res.load_error),
                residual=float(res.residual), converged=bool(res.converged),
                steps=int(res.steps), time_s=dt), (res, case, grid)


def part_moes(results):
    rows = []
    specs = [(m, 10.0, RX) for m in (20, 50, 100, 200, 500, 1000)] + \
        [(100, 5.0, RX), (100, 20.0, RX), (50, 10.0, 4 * RX), (200, 10.0, 4 * RX)]
    old = {(round(r["M"]), round(r["L"]), round(r["Ry"])): r for r in results.get("moes", [])}
    for M, L, Ry in specs:
        F, u_e, Ry = case_for(M, L, Ry)
        prev = old.get((M, round(L), round(Ry)))
        if prev is not None and prev["converged"]:      # rerun only what did not converge
            rows.append(prev)
            continue
        r, _ = run_case(F, u_e, Ry, 128)
        rows.append(r)
        print(json.dumps(r), flush=True)
    results["moes"] = rows


def newton_error_estimate(x, case, grid, angle=0.0, mixed=False):
    """Distance of the outputs of a state x to the discrete root, estimated by one
    Newton step: solve J δ = -R(x) by GMRES(100) (10 cycles, to 1e-6 relative, the
    solver's own preconditioner) and return the first-order changes of h_c, h_min
    (µm) and μ along δ, with the linear residual reached.  Used for the fine grids,
    whose Newton iteration stops at max|R| ≈ 3e-7 p_h (docs/ehl.md)."""
    from functools import partial

    import jax.numpy as jnp

    from gearjax.tribology.ehl.krylov import gmres
    from gearjax.tribology.ehl.model import kernel_hat, residual_core
    from gearjax.tribology.ehl.outputs import outputs
    from gearjax.tribology.ehl.solver import precondition_operator

    sc = scales(case)
    f = partial(residual_core, case=case, sc=sc, khat=kernel_hat(grid, sc), grid=grid,
                angle_deg=angle, mixed=mixed)

    @jax.jit
    def step(x):
        R = f(x)
        M, _ = precondition_operator(x, case, grid, angle, mixed, R, sc)
        Jv = lambda v: jax.jvp(f, (x,), (v,))[1]
        dx, rel = gmres(Jv, -R, M=M, tol=1e-6, restart=100, maxiter=10)
        out = lambda y: outputs(y, case, grid, mixed)[0]
        d = jax.jvp(lambda y: jnp.stack([out(y).h_c, out(y).h_min, out(y).mu]), (x,), (dx,))[1]
        return d, rel

    d, rel = step(jnp.asarray(x))
    return dict(newton_dh_c=float(d[0]) * 1e3, newton_dh_min=float(d[1]) * 1e3,
                newton_dmu=float(d[2]), newton_lin_res=float(rel))


def part_grid(results):
    """64², 128², 256² (and 512² with EHL_VAL_512=1); ``upwind`` from EHL_VAL_UPWIND,
    ``limiter`` from EHL_VAL_LIMITER; each row with a one-Newton-step error estimate."""
    beta = float(os.environ.get("EHL_VAL_UPWIND", "0"))
    limiter = os.environ.get("EHL_VAL_LIMITER", "none")
    key = "grid" if beta == 0.0 else f"grid_upwind{beta:g}"
    key += "" if limiter == "none" else f"_{limiter}"
    sizes = (64, 128, 256) + ((512,) if os.environ.get("EHL_VAL_512") else ())
    old = {r["n"]: r for r in results.get(key, []) if r.get("converged")}
    rows = []
    for n in sizes:
        if n in old and not os.environ.get("EHL_VAL_RERUN"):
            rows.append(old[n])
            continue
        tol = float(os.environ.get("EHL_VAL_TOL_FINE", "1e-9")) if n > 128 else 1e-9
        r, (res, case, grid) = run_case(100.0, 1000.0, RX, n, upwind=beta, tol=tol,
                                        limiter=limiter)
        r["upwind"] = beta
        r["limiter"] = limiter
        r["tol"] = tol
        if r["converged"]:
            r.update(newton_error_estimate(res.x, case, grid))
        rows.append(r)
        print(json.dumps(r), flush=True)
        results[key] = rows + [old[m] for m in sizes if m > n and m in old]
        with open(os.path.join(OUT, "ehl_validation.json"), "w") as fh:
            json.dump(results, fh, indent=1)
    results[key] = rows


def part_sou(results):
    """First- vs second-order upwind: h_min at high M (128²) and oblique entrainment (64²)."""
    rows = []
    for M, n in ((500, 128), (1000, 128)):
        F, u_e, Ry = case_for(M, 10.0)
        for beta in (0.0, 1.0):
            r, _ = run_case(F, u_e, Ry, n, upwind=beta)
            r.update(upwind=beta, kind="M")
            rows.append(r)
            print(json.dumps(r), flush=True)
    for ang in (0.0, 30.0):
        for beta in (0.0, 1.0):
            r, _ = run_case(100.0, 1000.0, RX, 64, angle=ang, upwind=beta)
            r.update(upwind=beta, kind="angle")
            rows.append(r)
            print(json.dumps(r), flush=True)
    results["sou"] = rows


def part_rot(results):
    rows = []
    for ang in (0.0, 90.0, 30.0):
        r, _ = run_case(100.0, 1000.0, RX, 64, angle=ang)
        rows.append(r)
        print(json.dumps(r), flush=True)
    results["rotation"] = rows


def part_fig(results):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    F, u_e, Ry = case_for(200, 10.0)
    r, (res, case, grid) = run_case(F, u_e, Ry, 128)
    f = ehl_fields(res, case, grid)
    sc = scales(case)
    X, Y, h = f["X"], f["Y"], f["h"] * 1e3
    p = np.maximum(f["p"], 0.0) / float(sc.p_h)     # round-off negatives (~1e-16) of the FB solution
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    c0 = ax[0].contourf(X, Y, p, 30, cmap="viridis")
    fig.colorbar(c0, ax=ax[0], label="p / p_h")
    ax[0].set_title(f"pressure, M = {r['M']:.0f}, L = {r['L']:.0f}, p_h = {r['p_h']:.0f} MPa")
    lv = np.linspace(h.min(), min(h.max(), 3 * r["h_c"]), 30)
    c1 = ax[1].contourf(X, Y, np.minimum(h, lv[-1]), lv, cmap="magma")
    fig.colorbar(c1, ax=ax[1], label="h, µm")
    ax[1].set_title("film (horseshoe); flow +X")
    for a in ax[:2]:
        a.set_xlim(-2.0, 1.5); a.set_ylim(-1.6, 1.6); a.set_aspect("equal")
        a.add_patch(plt.Circle((0, 0), 1.0, fill=False, ls="--", color="w"))
        a.set_xlabel("X = x/b"); a.set_ylabel("Y = y/a")
    j = grid.ny // 2
    ax[2].plot(X[j], p[j], "b-", label="p/p_h (Y≈0)")
    ax[2].plot(X[j], np.sqrt(np.maximum(1 - X[j] ** 2, 0)), "b:", label="Hertz")
    ax2 = ax[2].twinx()
    ax2.plot(X[j], h[j], "r-", label="h (µm)")
    ax2.set_ylim(0, 3 * r["h_c"])
    ax[2].set_xlim(-2.0, 1.5); ax[2].set_xlabel("X")
    ax[2].legend(loc="upper left"); ax2.legend(loc="upper right")
    ax[2].set_title("centre line: pressure spike and exit constriction")
    fig.tight_layout()
    fig.savefig(os.path.join(OUT, "ehl_fields.png"), dpi=110)
    results["figure"] = r
    print(json.dumps(r), flush=True)


def part_fast(results):
    from gearjax.tribology.friction import friction_coefficient, make_surface
    from gearjax.tribology.lubricant import make_oil
    from gearjax.contact import hertz_point
    oil = make_oil(ETA0, alpha_per_GPa=ALPHA, tau0_MPa=5.0)
    rows = []
    # (lambda, SRR, p_max GPa, Ry/Rx, u_e mm/s)
    grid_pts = [(3.0, 0.2, 1.0, 1.0), (1.0, 0.2, 1.0, 1.0), (0.5, 0.2, 1.0, 1.0),
                (3.0, 0.5, 2.0, 1.0), (1.0, 1.0, 1.5, 5.0), (2.0, 0.05, 0.5, 20.0),
                (5.0, 0.0, 1.0, 1.0)]
    u_e = 2000.0
    for lam, srr, pmax, ryrx in grid_pts:
        Ry = RX * ryrx
        # load for the target p_max: p_max ∝ F^(1/3)
        F = 100.0
        for _ in range(3):
            F = F * (pmax * 1e3 / float(hertz_point(F, RX, Ry, E).p_max)) ** 3
        hz = hertz_point(F, RX, Ry, E)
        hc, _ = hamrock_dowson(F, RX, float(hz.k), u_e, ETA0, ALPHA * 1e-3, E)
        sigma_um = float(hc) * 1e3 / lam
        t = time.time()
        res, case, grid = solve_ehl(F, u_e, srr * u_e, RX, Ry, ETA0, ALPHA, sigma_um=sigma_um,
                                    n=64, throw=False)
        dt = time.time() - t
        surf = make_surface(sigma_um)
        fr = friction_coefficient(F, u_e, srr * u_e, RX, Ry, oil, surf, E)
        row = dict(lam=lam, srr=srr, pmax_GPa=pmax, ry_rx=ryrx, F=F, sigma_um=sigma_um,
                   mu_num=float(res.mu), mu_fast=float(fr.mu),
                   mu_b_num=float(res.mu_boundary), mu_b_fast=float(fr.mu_boundary),
                   phi_num=float(res.F_asperity) / F, phi_fast=float(fr.phi),
                   hc_num=float(res.h_c) * 1e3, hc_fast=float(fr.h_c) * 1e3,
                   converged=bool(res.converged), residual=float(res.residual),
                   load_error=float(res.load_error), time_s=dt)
        row["rel_err_mu"] = (row["mu_fast"] - row["mu_num"]) / row["mu_num"] if row["mu_num"] else None
        rows.append(row)
        print(json.dumps(row), flush=True)
    results["fast"] = rows


def main(parts):
    path = os.path.join(OUT, "ehl_validation.json")
    results = json.load(open(path)) if os.path.exists(path) else {}
    if os.environ.get("EHL_VAL_PART_FILE"):       # run parts in parallel processes
        path = os.path.join(OUT, os.environ["EHL_VAL_PART_FILE"])
    if parts == ["md"]:                            # merge part files, write the tables
        import glob
        for fn in sorted(glob.glob(os.path.join(OUT, "ehl_validation_part*.json"))):
            results.update(json.load(open(fn)))
            os.remove(fn)
        with open(path, "w") as fh:
            json.dump(results, fh, indent=1)
        parts = []
    for p in parts:
        {"moes": part_moes, "grid": part_grid, "fig": part_fig, "rot": part_rot,
         "fast": part_fast, "sou": part_sou}[p](results)
        with open(path, "w") as fh:
            json.dump(results, fh, indent=1)
    write_md(results)


def _table(title, header, rows, note=None):
    """Markdown lines of one section: heading, optional note, table of ``rows`` (lists of
    cell strings) under the column names ``header``, blank line."""
    out = [f"## {title}", ""] + ([note, ""] if note else [])
    out += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return out + ["| " + " | ".join(r) + " |" for r in rows] + [""]


def write_md(results):
    lines = ["# EHL validation (generated by experiments/ehl_validation.py)", ""]
    if "moes" in results:
        lines += _table(
            "Film vs Hamrock–Dowson and Nijenbanning–Venner–Moes (128²)",
            ["M", "L", "Ry/Rx", "p_h MPa", "h_c µm", "HD", "NVM", "h_c/HD", "h_c/NVM",
             "h_min µm", "HD", "h_min/HD", "load err", "residual", "conv"],
            [[f"{r['M']:.0f}", f"{r['L']:.0f}", f"{r['Ry']/RX:.0f}", f"{r['p_h']:.0f}",
              f"{r['h_c']:.4f}", f"{r['hc_HD']:.4f}", f"{r['hc_NVM']:.4f}",
              f"{r['h_c']/r['hc_HD']:.3f}", f"{r['h_c']/r['hc_NVM']:.3f}", f"{r['h_min']:.4f}",
              f"{r['hmin_HD']:.4f}", f"{r['h_min']/r['hmin_HD']:.3f}", f"{r['load_error']:.1e}",
              f"{r['residual']:.1e}", f"{r['converged']}"] for r in results["moes"]])
    for key in sorted(k for k in results if k.startswith("grid")):
        lines += _table(
            f"Grid convergence (F = 100 N, u_e = 1 m/s, M = 168, L = 14.8; {key})",
            ["grid", "h_c µm", "h_min µm", "μ", "p_max MPa", "load err", "residual", "steps",
             "time s", "converged", "Newton-step Δh_c µm", "Δh_min µm", "Δμ"],
            [[f"{r['n']}²", f"{r['h_c']:.5f}", f"{r['h_min']:.5f}", f"{r['mu']:.5f}",
              f"{r['p_max']:.1f}" if "p_max" in r else "—", f"{r['load_error']:.1e}",
              f"{r['residual']:.1e}", f"{r['steps']}", f"{r['time_s']:.1f}", f"{r['converged']}"]
             + ([f"{r['newton_dh_c']:+.1e}", f"{r['newton_dh_min']:+.1e}",
                 f"{r['newton_dmu']:+.1e}"] if "newton_dh_c" in r else ["—"] * 3)
             for r in results[key]],
            note="Newton-step estimate: first-order change of h_c, h_min, μ along one Newton "
                 "step from the returned state (distance to the discrete root).")
    if "sou" in results:
        lines += _table(
            "First- (β = 0) vs second-order (β = 1) upwind Couette fluxes",
            ["case", "grid", "angle °", "β", "h_c µm", "h_min µm", "h_min/HD", "μ", "p_max MPa",
             "converged", "time s"],
            [[f"M = {r['M']:.0f}, L = {r['L']:.0f}", f"{r['n']}²", f"{r['angle']:.0f}",
              f"{r['upwind']:g}", f"{r['h_c']:.5f}", f"{r['h_min']:.5f}",
              f"{r['h_min']/r['hmin_HD']:.3f}", f"{r['mu']:.5f}", f"{r['p_max']:.0f}",
              f"{r['converged']}", f"{r['time_s']:.1f}"] for r in results["sou"]])
    if "rotation" in results:
        lines += _table(
            "Entrainment angle (circular contact, 64²)", ["angle °", "h_c µm", "h_min µm", "μ"],
            [[f"{r['angle']:.0f}", f"{r['h_c']:.5f}", f"{r['h_min']:.5f}", f"{r['mu']:.5f}"]
             for r in results["rotation"]])
    if "fast" in results:
        lines += _table(
            "Fast model (friction_coefficient) vs numerical mixed EHL (64²)",
            ["λ", "SRR", "p_max GPa", "Ry/Rx", "σ µm", "μ num", "μ fast", "rel err", "φ num",
             "φ fast", "h_c num", "h_c fast", "conv"],
            [[f"{r['lam']}", f"{r['srr']}", f"{r['pmax_GPa']}", f"{r['ry_rx']:.0f}",
              f"{r['sigma_um']:.3f}", f"{r['mu_num']:.4f}", f"{r['mu_fast']:.4f}",
              "—" if r["rel_err_mu"] is None else f"{r['rel_err_mu']:+.2f}",
              f"{r['phi_num']:.3f}", f"{r['phi_fast']:.3f}", f"{r['hc_num']:.4f}",
              f"{r['hc_fast']:.4f}", f"{r['converged']}"] for r in results["fast"]])
    with open(os.path.join(OUT, "ehl_validation.md"), "w") as fh:
        fh.write("\n".join(lines))


if __name__ == "__main__":
    main(sys.argv[1:] or ["moes", "grid", "fig", "rot", "fast"])
