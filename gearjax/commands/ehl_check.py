"""``gearjax efficiency --ehl-check N``: the numerical EHL model at a few mesh positions.

For N positions of the mesh cycle (evenly spread over the positions with a loaded
contact) the most heavily loaded tooth pair is solved again with the numerical
mixed-EHL point-contact model (:func:`gearjax.tribology.ehl.solve_ehl`, grid
``--ehl-grid``² nodes, default 64) with exactly the inputs the fast friction model
got there: load, |u_e|, |u_s|, the radii R_x along and R_y across the entrainment
(entrainment along the X axis of the EHL grid), the oil's η0, α, τ0, E', and the
Greenwood–Tripp surface (σ, asperity density and radius, f_c, v_slip).  Fast and
numerical μ, h_c, h_min and asperity load share φ are printed side by side.

The numerical model is a point-contact model on a square grid: contacts with
R_y/R_x outside [0.05, 50] (line contacts of involute pairs, whose equivalent
ellipse is far more elongated) or a Hertz pressure outside its range are reported
as skipped, with the reason.  It always uses the Roelands viscosity (a
``--viscosity barus`` run compares different laws), and it is isothermal and
Newtonian in the flow, as the fast model.  A non-converged solve is reported with
``converged: false`` and its residual, not hidden.
"""

from __future__ import annotations

import math

import numpy as np

EHL_CHECK_RANGE = (1, 20)
EHL_GRID_RANGE = (32, 256)

EHL_CHECK_KEYS_DOC = """  ehl_check             null without --ehl-check; with --ehl-check N a list of N objects, one per checked
                        position: phi1_deg, pair, load_N, p_max_MPa, Rx_mm, Ry_mm,
                        u_e_m_s, u_s_m_s, mu_fast, mu_ehl, h_c_fast_um, h_c_ehl_um,
                        h_min_fast_um, h_min_ehl_um, phi_fast, phi_ehl (asperity load
                        share), converged, residual, grid (nodes per side),
                        time_s, skipped (null, or why the contact was not solved)"""


def add_ehl_check_options(p) -> None:
    p.add_argument("--ehl-check", type=float, default=None, metavar="N",
                   help="also solve the most loaded contact at N positions "
                        f"({EHL_CHECK_RANGE[0]}..{EHL_CHECK_RANGE[1]}) with the numerical "
                        "mixed-EHL model and print fast vs numerical mu, h_c, h_min, phi")
    p.add_argument("--ehl-grid", type=float, default=64.0,
                   help=f"nodes per side of the numerical EHL grid ({EHL_GRID_RANGE[0]}.."
                        f"{EHL_GRID_RANGE[1]}, default 64)")


def check_ehl_options(args) -> tuple[int, int] | None:
    """(N, grid) or None; ValueError naming the option (before any work)."""
    from gearjax.errors import check_int

    if args.ehl_check is None:
        return None
    n = check_int("--ehl-check", args.ehl_check, *EHL_CHECK_RANGE)
    g = check_int("--ehl-grid", args.ehl_grid, *EHL_GRID_RANGE)
    return n, g


def pick_positions(load, n_check: int) -> list[tuple[int, int]]:
    """(pair row, position) of the most loaded pair at ``n_check`` positions spread
    evenly over the positions with a loaded pair."""
    F = np.asarray(load, float)
    cols = np.flatnonzero((F > 0.0).any(axis=0))
    if cols.size == 0:
        return []
    idx = np.unique(np.round(np.linspace(0, cols.size - 1, min(n_check, cols.size))).astype(int))
    return [(int(np.argmax(F[:, cols[i]])), int(cols[i])) for i in idx]


def ehl_check(eff, oil, surf, E_prime, n_check: int, grid_n: int) -> list[dict]:
    """Fast vs numerical EHL at ``n_check`` positions of ``eff`` (a MeshEfficiency)."""
    import time

    from gearjax.tribology.ehl import solve_ehl

    F = np.asarray(eff.loaded.load, float)
    K = F.shape[0]
    fr = eff.friction
    rows = []
    for k, j in pick_positions(F, n_check):
        g = lambda a: float(np.asarray(a, float)[k, j])
        row = {"phi1_deg": math.degrees(float(np.asarray(eff.phi1)[j])), "pair": k - K // 2,
               "load_N": g(F), "p_max_MPa": g(eff.loaded.p_max), "Rx_mm": g(eff.r_x),
               "Ry_mm": g(eff.r_y), "u_e_m_s": g(eff.u_e) * 1e-3, "u_s_m_s": g(eff.u_s) * 1e-3,
               "mu_fast": g(fr.mu), "h_c_fast_um": g(fr.h_c) * 1e3,
               "h_min_fast_um": g(fr.h_min) * 1e3, "phi_fast": g(fr.phi),
               "mu_ehl": None, "h_c_ehl_um": None, "h_min_ehl_um": None, "phi_ehl": None,
               "converged": False, "residual": None, "grid": grid_n, "time_s": None,
               "skipped": None}
        t0 = time.perf_counter()
        try:
            res, _, _ = solve_ehl(row["load_N"], g(eff.u_e), g(eff.u_s), row["Rx_mm"],
                                  row["Ry_mm"], float(oil.eta0), float(oil.alpha) * 1e3,
                                  float(E_prime), float(oil.tau0), float(surf.sigma) * 1e3,
                                  float(surf.density), float(surf.beta) * 1e3, float(surf.f_c),
                                  float(surf.v_slip), n=grid_n, throw=False)
        except ValueError as e:           # outside the numerical model's range
            row["skipped"] = str(e)
            rows.append(row)
            continue
        row.update(mu_ehl=float(res.mu), h_c_ehl_um=float(res.h_c) * 1e3,
                   h_min_ehl_um=float(res.h_min) * 1e3,
                   phi_ehl=float(res.F_asperity) / row["load_N"],
                   converged=bool(res.converged), residual=float(res.residual),
                   time_s=time.perf_counter() - t0)
        rows.append(row)
    return rows


def print_ehl_check(rows) -> None:
    """The comparison table (text output of ``gearjax efficiency``)."""
    def c(v, f):
        return f"{'-':>9s}" if v is None else f"{v:9{f}}"

    print(f"# numerical EHL check ({rows[0]['grid'] if rows else '-'}² grid): most loaded pair "
          "at each checked position")
    print(f"{'phi1[deg]':>10s} {'pair':>4s} {'F[N]':>9s} {'Ry/Rx':>7s} {'mu_fast':>9s} "
          f"{'mu_ehl':>9s} {'hc_fast':>9s} {'hc_ehl':>9s} {'hmin_fst':>9s} {'hmin_ehl':>9s} "
          f"{'phi_fast':>9s} {'phi_ehl':>9s} status")
    for r in rows:
        status = ("skipped: " + r["skipped"]) if r["skipped"] else (
            "ok" if r["converged"] else f"NOT converged (residual {r['residual']:.2g})")
        print(f"{r['phi1_deg']:10.4f} {r['pair']:+4d} {r['load_N']:9.1f} "
              f"{r['Ry_mm'] / r['Rx_mm']:7.2f} {c(r['mu_fast'], '.5f')} {c(r['mu_ehl'], '.5f')} "
              f"{c(r['h_c_fast_um'], '.4f')} {c(r['h_c_ehl_um'], '.4f')} "
              f"{c(r['h_min_fast_um'], '.4f')} {c(r['h_min_ehl_um'], '.4f')} "
              f"{c(r['phi_fast'], '.4f')} {c(r['phi_ehl'], '.4f')} {status}")
    print("# films in um; phi = asperity load share")
