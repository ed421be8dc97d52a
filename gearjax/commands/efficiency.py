"""``gearjax efficiency``: loaded contact, friction along the path of contact and mesh
efficiency of a gear pair at one operating point (see :mod:`gearjax.loading.mesh_efficiency`).

DESIGN as for ``gearjax tca`` (:mod:`gearjax.commands.designs`): an inline involute
pair or a hypoid/spiral-bevel design file / ``example:NAME``.  The oil, surface and
film options are those of ``gearjax friction`` (:func:`gearjax.commands.friction.
add_lubricant_options`, same ranges).  The pinion torque (N m) and speed (rpm) are
checked against :data:`gearjax.loading.TORQUE_RANGE_NM` and :data:`gearjax.loading.RPM_RANGE`.  The
material (:mod:`gearjax.loading.materials`): ``--E-prime-MPa`` if given, else the design's own
``[material]`` (VH-CATT), else steel; it sets E' and the tooth compliance, and the
output names its source (``input.material_source``).  ``--compliance`` has the default
of :func:`gearjax.loading.mesh_efficiency` (:data:`gearjax.loading.DEFAULT_COMPLIANCE`).

Exit status as ``gearjax tca``: 0 with a result (problems of the result -- TCA
quality flags, positions whose load balance or friction solve did not converge, a
loaded edge contact, a grid too short, implausible results (``plausibility`` of
:mod:`gearjax.loading.mesh_efficiency`), a partial cycle (summaries over the valid positions
only) -- are ``gearjax: warning:`` lines on stderr
and ``valid``/``warnings`` in the output); 2 bad input, refused before any work; 3
no position of the cycle is valid (the result is printed, with one error line).

A pair in line contact that this chain does not load -- an involute design file with
``[microgeometry]`` tables, or a helical pair without lead or profile crown -- goes to
the thin-slice line contact (:mod:`gearjax.commands.line_efficiency`; ``--torque-Nm``
then also takes a list or a range).  A design without ``[microgeometry]`` otherwise runs
exactly the chain above, with one torque.
"""

from __future__ import annotations

import argparse
import math
import sys
import warnings

import numpy as np

from gearjax.commands.designs import involute_design, is_involute, parse_misalign
from gearjax.commands.ehl_check import (EHL_CHECK_KEYS_DOC, add_ehl_check_options,
                                        check_ehl_options, ehl_check, print_ehl_check)
from gearjax.commands.friction import PLOT_SUFFIXES, add_lubricant_options, lubricant_from_args
from gearjax.commands.line_efficiency import (LINE_EFFICIENCY_KEYS_DOC, line_contact_design,
                                              refuse_line_options, run_line_efficiency)
from gearjax.commands.line_tca import (CYCLE_WHY, MIS_WHY, add_coupling_option,
                                       check_line_values)
from gearjax.commands.loaded import parse_torques

EFFICIENCY_KEYS_DOC = """JSON keys (K tooth pairs, M positions over one mesh cycle = one pinion pitch):
  input                 the options as given (design, side, misalign, torque_Nm, rpm,
                        oil, sigma_um, asperity options, fc, film, viscosity,
                        compliance, positions, pitches, pairs) plus the oil's
                        eta0_Pas, alpha_per_GPa, tau0_MPa and the material used:
                        E_prime_MPa (reduced modulus E' = E/(1-nu^2)),
                        youngs_modulus_MPa and poisson (E, nu of the tooth
                        compliance), material_source ("--E-prime-MPa" when the flag
                        is given, "design [material]" from the design file, else
                        "default steel (...)": the design has no material)
  phi1_deg              (M,) pinion angle of each position (deg; reference in the middle)
  pairs                 (K,) tooth-pair index k of the rows below (pair k = pair 0
                        shifted by k pinion pitches)
  n_loaded              (M,) number of tooth pairs carrying load
  load_N                (K, M) normal load of each pair (N; 0 where it carries none)
  load_share            (K, M) torque share l1 F / T1 of each pair (sums to 1 over k)
  p_max_MPa             (K, M) maximum Hertz pressure (MPa; null where unloaded)
  lambda                (K, M) film parameter h_c / sigma (null where unloaded)
  mu                    (K, M) friction coefficient (null where unloaded)
  u_e_m_s               (K, M) entrainment speed |u_e| (m/s; null where unloaded)
  u_s_m_s               (K, M) sliding speed |u_s| (m/s; null where unloaded)
  regime                (K, M) "boundary" | "mixed" | "full film" (null where unloaded)
  mu_position           (M,) load-weighted friction coefficient sum mu F / sum F
  lambda_min            (M,) smallest lambda of the loaded pairs
  p_max_position_MPa    (M,) highest p_max of the loaded pairs
  power_loss_W          (M,) sliding power loss P_f = sum mu F |u_s| (W)
  efficiency            (M,) eta_m = 1 - P_f / P_in
  te_loaded_arcsec      (M,) loaded transmission error (arcsec)
  valid                 (M,) every loaded contact converged (load balance, Hertz,
                        friction), no loaded edge contact, grid not truncated, some
                        pair loaded, and the result plausible: 0 < eta_m <= 1,
                        mu <= 0.3, p_max <= 5000 MPa, fall-back <= 0.02 pitch, Hertz
                        half-width <= 0.5 R_x (docs/efficiency.md; a warning line per
                        failed check)
  edge_loaded           (M,) an edge contact would carry load (not modelled)
  n_valid               number of valid positions; the five summaries below are over
                        the valid positions only (null when none; a partial cycle,
                        n_valid < M, is also a warning line)
  mean_efficiency       eta_bar = 1 - mean(P_f) / P_in over the valid positions (-)
  mean_mu               sum mu F |u_s| / sum F |u_s| over the valid positions (-)
  max_p_max_MPa         highest Hertz pressure over the valid positions (MPa)
  power_in_W            P_in = T1 omega1 (W)
  mean_power_loss_W     mean P_f over the valid positions (W)
  te_loaded_ptp_arcsec  peak-to-peak of the loaded TE over the valid positions (arcsec)
  truncated             the TCA grid or the number of pairs misses a pair in contact
  quality               contact-quality flags of the unloaded TCA (as gearjax tca)
  warnings              the warning lines (also on stderr)
  plot                  the figure's path or null
""" + EHL_CHECK_KEYS_DOC

#: positions per mesh cycle and the grid/pair options (ranges of the TCA options)
POSITIONS_RANGE = (4, 400)
PITCHES_RANGE = (0.75, 4.0)
PAIRS_RANGE = (3, 9)

#: exit status when no position of the cycle gives a valid result
NO_VALID_STATUS = 3


def register(sub):
    import gearjax as gj

    p = sub.add_parser(
        "efficiency", help="loaded contact, friction and mesh efficiency at a torque and speed",
        description="Load sharing between the tooth pairs, Hertz pressure, film parameter, "
                    "friction coefficient and sliding power loss at each position of one "
                    "mesh cycle, and the mean mesh efficiency, of an involute pair or a "
                    "hypoid/spiral-bevel design at a pinion torque and speed.",
        epilog=EFFICIENCY_KEYS_DOC + "\n" + LINE_EFFICIENCY_KEYS_DOC,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("design", help="involute:z1=..,z2=..,m=..,alpha=..,b=..[,...], or a "
                                  "hypoid/spiral-bevel design file or example:NAME")
    lo, hi = gj.loading.TORQUE_RANGE_NM
    p.add_argument("--torque-Nm", required=True,
                   help=f"pinion torque (N m, in [{lo:g}, {hi:g}]); a pair in line contact "
                        "(a design with [microgeometry], or an unmodified helical pair) also "
                        "takes a comma list 50,100,200 or a range START:STOP:COUNT")
    lo, hi = gj.loading.RPM_RANGE
    p.add_argument("--rpm", type=float, required=True,
                   help=f"pinion speed (rpm, in [{lo:g}, {hi:g}])")
    add_lubricant_options(p, e_prime_help=(
        "reduced modulus E' = 2/((1-v1^2)/E1+(1-v2^2)/E2) (MPa, in (0, 1e7]): overrides the "
        "design's material for the Hertz contact, film and tooth compliance (E = E'(1-nu^2), "
        "nu of the design or 0.3); default: the design's [material] table (VH-CATT), else "
        "steel E' = 226374 (E 206000, nu 0.3); the JSON's input.material_source says which"))
    p.add_argument("--side", choices=["drive", "coast"], default="drive")
    p.add_argument("--misalign", default="",
                   help="dE=mm,dP=mm,dG=mm,dSigma=deg (any subset; default all 0)")
    p.add_argument("--compliance", choices=list(gj.loading.COMPLIANCE_MODELS),
                   default=gj.loading.DEFAULT_COMPLIANCE,
                   help=f"tooth compliance model of the load sharing, as "
                        f"gearjax.loading.mesh_efficiency: {gj.loading.COMPLIANCE_HELP}")
    p.add_argument("--positions", type=float, default=None,
                   help=f"positions per mesh cycle (one pinion pitch), integer "
                        f"{POSITIONS_RANGE[0]}..{POSITIONS_RANGE[1]} (default 24 involute, "
                        "16 hypoid; a pair in line contact: per base pitch, default 32)")
    p.add_argument("--pitches", type=float, default=None,
                   help=f"half-range of the TCA grid in pitches ({PITCHES_RANGE[0]:g} ... "
                        f"{PITCHES_RANGE[1]:g}; default 1.25 involute, 2 hypoid)")
    p.add_argument("--pairs", type=float, default=None,
                   help=f"tooth pairs considered, odd {PAIRS_RANGE[0]}..{PAIRS_RANGE[1]} "
                        "(default 3 involute, 5 hypoid)")
    mlo, mhi = gj.involute.MISALIGNMENT_RANGE_UM
    p.add_argument("--slices", type=float, default=None,
                   help="pairs in line contact only: face-width slices, integer 1..400 "
                        "(default 20)")
    p.add_argument("--misalignment-um", type=float, default=None,
                   help=f"pairs in line contact only: mesh misalignment f_ma (um over the "
                        f"face width, in [{mlo:g}, {mhi:g}]; default 0)")
    add_coupling_option(p, "pairs in line contact only: ")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--plot", default=None,
                   help="write load share, mu and P_f along the mesh (.png, .pdf or .svg); a "
                        "pair in line contact: efficiency, power loss and loaded TE against "
                        "torque and the pinion flank's modification map")
    add_ehl_check_options(p)
    p.set_defaults(func=run)


def _grid_options(args) -> dict:
    """The TCA options given on the command line (validated; absent = family default)."""
    from gearjax.errors import check_int, check_range

    opts = {}
    if args.positions is not None:
        opts["steps_per_pitch"] = check_int("--positions", args.positions, *POSITIONS_RANGE)
    if args.pitches is not None:
        opts["half_pitches"] = check_range("--pitches", args.pitches, *PITCHES_RANGE)
    if args.pairs is not None:
        k = check_int("--pairs", args.pairs, *PAIRS_RANGE)
        if k % 2 == 0:
            raise ValueError(f"--pairs = {k} must be odd (pairs -k..k)")
        opts["n_pairs"] = k
    return opts


def _lists(a, mask=None, scale=1.0):
    """Nested lists of ``a * scale``; ``None`` where ``mask`` is False (an intentional
    gap: the pair carries no load).  Other non-finite values stay NaN, so that
    :func:`gearjax.commands.print_json` writes them as null *and* warns."""
    a = np.asarray(a, float) * scale
    keep = np.ones(a.shape, bool) if mask is None else np.asarray(mask, bool)
    if a.ndim == 0:
        return float(a) if keep else None
    return [_lists(x, m) for x, m in zip(a, keep)]


def _position_stats(eff):
    """Per position: load-weighted mu, smallest lambda, highest p_max (loaded pairs)."""
    F = np.asarray(eff.loaded.load, float)
    on = F > 0.0
    mu = np.asarray(eff.friction.mu, float)
    with np.errstate(invalid="ignore", divide="ignore"):
        mu_pos = np.sum(np.where(on, mu * F, 0.0), axis=0) / np.sum(np.where(on, F, 0.0), axis=0)
    lam = np.where(on, np.asarray(eff.friction.lam, float), np.inf).min(axis=0)
    pmax = np.where(on, np.asarray(eff.loaded.p_max, float), -np.inf).max(axis=0)
    any_on = on.any(axis=0)
    return (np.where(any_on, mu_pos, np.nan), np.where(any_on, lam, np.nan),
            np.where(any_on, pmax, np.nan))


def _output(eff, res, inp, warn_lines, plot):
    """The JSON object of the result (throw JSON: NaN -> null by print_json)."""
    from gearjax import ARCSEC
    from gearjax.tribology import REGIMES

    F = np.asarray(eff.loaded.load, float)
    on = F > 0.0
    K = F.shape[0]
    mu_pos, lam_min, pmax_pos = _position_stats(eff)
    te = np.asarray(eff.loaded.te_loaded, float) / ARCSEC
    pf = np.asarray(eff.power_loss, float)
    fr = eff.friction
    regime = np.asarray(fr.regime)
    return {
        "input": inp,
        "phi1_deg": _lists(np.degrees(np.asarray(eff.phi1, float))),
        "pairs": [int(k) for k in np.arange(K) - K // 2],
        "n_loaded": [int(n) for n in np.asarray(eff.loaded.n_loaded)],
        "load_N": _lists(F),
        "load_share": _lists(eff.loaded.share),
        "p_max_MPa": _lists(eff.loaded.p_max, on),
        "lambda": _lists(fr.lam, on),
        "mu": _lists(fr.mu, on),
        "u_e_m_s": _lists(eff.u_e, on, 1e-3),
        "u_s_m_s": _lists(eff.u_s, on, 1e-3),
        "regime": [[REGIMES[int(g)] if o else None for g, o in zip(rg, ro)]
                   for rg, ro in zip(regime, on)],
        "mu_position": _lists(mu_pos),
        "lambda_min": _lists(lam_min),
        "p_max_position_MPa": _lists(pmax_pos),
        "power_loss_W": _lists(pf),
        "efficiency": _lists(eff.efficiency),
        "te_loaded_arcsec": _lists(te),
        "valid": [bool(v) for v in np.asarray(eff.valid)],
        "edge_loaded": [bool(v) for v in np.asarray(eff.edge_loaded)],
        "n_valid": int(np.asarray(eff.n_valid)),
        "mean_efficiency": float(eff.mean_efficiency),
        "mean_mu": float(eff.mean_mu),
        "max_p_max_MPa": float(eff.max_p_max),
        "power_in_W": float(eff.power_in),
        # eta_bar = 1 - mean P_f / P_in over the valid positions (NaN when none)
        "mean_power_loss_W": float((1.0 - eff.mean_efficiency) * eff.power_in),
        "te_loaded_ptp_arcsec": float(eff.te_loaded_ptp) / ARCSEC,
        "truncated": bool(np.asarray(eff.truncated)),
        "quality": res.flags(),
        "warnings": list(warn_lines),
        "plot": plot,
    }


def _cell(v, width, fmt):
    """A table cell, ``-`` where there is no value (no pair loaded)."""
    if v is None or not np.isfinite(v):
        return f"{'-':>{width}s}"
    return f"{v:{width}{fmt}}"


def _print_table(out, args):
    phi = out["phi1_deg"]
    pairs = out["pairs"]
    share = np.asarray(out["load_share"], float)
    print(f"# mesh efficiency {args.design} ({args.side}); T1 = {out['input']['torque_Nm']:g} N m, "
          f"n1 = {args.rpm:g} rpm, oil {args.oil or 'custom'}, sigma = {args.sigma_um:g} um; "
          f"misalign {out['input']['misalign'] or 'none'}")
    inp = out["input"]
    print(f"# material: E' = {inp['E_prime_MPa']:.0f} MPa (E = {inp['youngs_modulus_MPa']:.0f} "
          f"MPa, nu = {inp['poisson']:g}; {inp['material_source']}); compliance "
          f"{inp['compliance']}")
    head = " ".join(f"{f's[{k:+d}]':>7s}" for k in pairs)
    print(f"{'phi1[deg]':>10s} {'n':>2s} {head} {'pmax[MPa]':>9s} {'lam_min':>8s} {'mu':>8s} "
          f"{'P_f[W]':>10s} {'eta_m':>8s} flag")
    for i in range(len(phi)):
        flag = ("ok" if out["valid"][i] else "edge" if out["edge_loaded"][i] else "invalid")
        shares = " ".join(_cell(s, 7, ".4f") for s in share[:, i])
        print(f"{_cell(phi[i], 10, '.4f')} {out['n_loaded'][i]:2d} {shares} "
              f"{_cell(out['p_max_position_MPa'][i], 9, '.1f')} "
              f"{_cell(out['lambda_min'][i], 8, '.3f')} {_cell(out['mu_position'][i], 8, '.5f')} "
              f"{_cell(out['power_loss_W'][i], 10, '.3f')} {_cell(out['efficiency'][i], 8, '.5f')} "
              f"{flag}")
    nv, M = out["n_valid"], len(phi)
    part = "" if nv == M else f"  -- over {nv} of {M} valid positions only (partial cycle)"
    print(f"# eta_bar = {100.0 * out['mean_efficiency']:.4f} %  (mean P_f "
          f"{out['mean_power_loss_W']:.3f} W){part}")
    print(f"# mean mu = {out['mean_mu']:.5f}")
    print(f"# max p_max = {out['max_p_max_MPa']:.1f} MPa")
    print(f"# P_in = {out['power_in_W']:.2f} W")
    print(f"# loaded TE p-t-p = {out['te_loaded_ptp_arcsec']:.4f} arcsec")
    if out["plot"]:
        print(f"# plot written to {out['plot']}")


def run(args) -> int:
    import gearjax as gj
    from gearjax.commands import print_json, warn_nonfinite
    from gearjax.errors import check_range
    from gearjax.io import check_output_path
    from gearjax.progress import Progress

    # every input is checked before any work (one line naming it, status 2)
    torques = parse_torques(args.torque_Nm, *gj.loading.TORQUE_RANGE_NM)
    n = check_range("--rpm", args.rpm, *gj.loading.RPM_RANGE, unit="rpm")
    for T in torques:
        gj.check_operating_point(T, n)
    T = torques[0]
    mis_kv, mis = parse_misalign(args.misalign)
    opts = _grid_options(args)
    ehl_opts = check_ehl_options(args)
    check_line_values(args)
    if args.plot is not None:
        check_output_path(args.plot, "--plot", PLOT_SUFFIXES)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        oil, surf, _ = lubricant_from_args(args)   # E': the material below
    design = (involute_design(args.design)[1] if is_involute(args.design)
              else gj.load_design(args.design))
    if line_contact_design(design):
        # [microgeometry] or an unmodified helical pair: the thin-slice line contact
        return run_line_efficiency(args, design, torques, n, oil, surf, caught, (
            ("--misalign", bool(mis_kv), MIS_WHY),
            ("--pitches", args.pitches is not None, CYCLE_WHY),
            ("--pairs", args.pairs is not None, "it takes every tooth pair on the path"),
            ("--E-prime-MPa", args.E_prime_MPa is not None,
             "the material is the design's [material], else steel"),
            ("--ehl-check", ehl_opts is not None, "the EHL check is of the point-contact "
                                                  "chain's ellipses")))
    refuse_line_options(args, torques)
    opts_all = {**gj.tca.family_of(design).defaults, **opts}
    # the material: --E-prime-MPa (validated above) > the design's [material] > steel;
    # mesh_efficiency resolves it the same way from the same E_prime argument
    mat = gj.pair_material(design, args.E_prime_MPa, override_source="--E-prime-MPa")
    Ep = float(mat.e_prime_MPa)

    with Progress(1, "efficiency") as bar, bar.phase(
            f"{args.side} side: TCA, load sharing, friction ({opts_all['steps_per_pitch']} "
            "positions)"):
        eff, res = gj.mesh_efficiency(design, T, n, oil, surf, misalignment=mis, side=args.side,
                                      compliance=args.compliance, E_prime=args.E_prime_MPa,
                                      viscosity_model=args.viscosity, film_method=args.film,
                                      **opts)
        bar.update()
    for w in caught:
        sys.stderr.write(f"gearjax: warning: {w.message}\n")
    warn_lines = gj.efficiency_warnings(eff, res, film_method=args.film,
                                        viscosity_model=args.viscosity)
    for w in warn_lines:
        sys.stderr.write(f"gearjax: warning: {args.side} side: {w}\n")

    if args.plot is not None:
        from gearjax.plot.efficiency import efficiency_figure
        from gearjax.plot.tribology import save_figure_atomic
        save_figure_atomic(efficiency_figure(eff, title=f"{args.design} ({args.side})"),
                           args.plot)
    inp = {"design": args.design, "side": args.side, "misalign": mis_kv, "torque_Nm": T,
           "rpm": n, "oil": args.oil, "eta0_Pas": float(oil.eta0),
           "alpha_per_GPa": float(oil.alpha) * 1e3, "tau0_MPa": float(oil.tau0),
           "sigma_um": args.sigma_um, "asperity_density_per_mm2": args.asperity_density_per_mm2,
           "asperity_radius_um": args.asperity_radius_um, "fc": args.fc,
           "E_prime_MPa": Ep, "youngs_modulus_MPa": float(mat.youngs_modulus_MPa),
           "poisson": float(mat.poisson), "material_source": mat.source, "film": args.film,
           "viscosity": args.viscosity,
           "compliance": args.compliance, "positions": int(opts_all["steps_per_pitch"]),
           "pitches": float(opts_all["half_pitches"]), "pairs": int(opts_all["n_pairs"])}
    out = _output(eff, res, inp, warn_lines, args.plot)
    out["ehl_check"] = None
    if ehl_opts is not None:
        out["ehl_check"] = ehl_check(eff, oil, surf, Ep, *ehl_opts)
        for r in out["ehl_check"]:
            if not r["skipped"] and not r["converged"]:
                sys.stderr.write(f"gearjax: warning: --ehl-check: the numerical EHL solve at "
                                 f"phi1 = {r['phi1_deg']:.4f} deg did not converge (residual "
                                 f"{r['residual']:.2g})\n")
    status = 0
    if not any(out["valid"]) or not math.isfinite(out["mean_efficiency"]):
        sys.stderr.write(f"gearjax: error: {args.side} side: no position of the mesh cycle gives "
                         "a valid loaded contact (see the warnings); try another --side, "
                         "smaller --misalign values, a wider grid (--pitches 2) or check the "
                         "design\n")
        status = NO_VALID_STATUS
    if args.json:
        print_json(out)
        return status
    warn_nonfinite(k for k in ("mean_efficiency", "mean_mu", "max_p_max_MPa", "power_in_W")
                   if not math.isfinite(out[k]))
    _print_table(out, args)
    if out["ehl_check"] is not None:
        print_ehl_check(out["ehl_check"])
    return status
