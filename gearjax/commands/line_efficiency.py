"""``gearjax efficiency`` of a spur or helical pair in line contact with flank
micro-geometry (an involute design file with ``[microgeometry]`` tables) or of an
unmodified helical pair in line contact (no lead or profile crown): the sliding power
loss and mesh efficiency of the thin-slice line contact (:func:`gearjax.involute.
loaded_te_map` with a speed: :mod:`gearjax.gears.involute.line_efficiency`), the peak
Hertz pressure, the loaded and unloaded TE, over one or more torques.

The efficiency of a torque is ``eta = 1 - sum_positions P_f / sum_positions P_in``
with ``P_f = sum mu F |u_s|`` over the loaded slice points of the cycle and ``P_in = T1
omega1`` (W); the numbers are those of ``gearjax loaded --rpm`` (the same program).
``--torque-Nm`` takes a comma list or ``START:STOP:COUNT`` here (a row per torque).
Options of the point-contact chain with no meaning in this model (``--misalign``,
``--pitches``, ``--pairs``, ``--E-prime-MPa``, ``--ehl-check``) are refused in one line
before any work (exit 2).  Exit 3 when the loaded contact or the friction at a torque
did not converge (its row is printed, marked ``no``).
"""

from __future__ import annotations

import math
import sys

import numpy as np

from gearjax.commands.line_tca import modifications

LINE_EFFICIENCY_KEYS_DOC = """JSON keys of a pair in line contact (a design with [microgeometry],
or an unmodified helical pair; T torques):
  input                 the options as given (design, side, torque_Nm, rpm, oil,
                        sigma_um, asperity options, fc, film, viscosity, compliance,
                        positions, slices, misalignment_um, coupling_length_mm: the
                        value used, 'module' resolved) plus the oil's eta0_Pas,
                        alpha_per_GPa, tau0_MPa and the material of the design
                        (E_prime_MPa, youngs_modulus_MPa, poisson, material_source)
  model                 "line contact": the thin-slice line contact of
                        docs/microgeometry.md
  torque_Nm             (T,) pinion torques (N m)
  power_in_W            (T,) P_in = T1 omega1 (W)
  power_loss_W          (T,) mean sliding power loss over the mesh cycle (W)
  efficiency            (T,) mesh efficiency over the cycle, 1 - mean P_f / P_in (-)
  p_max_MPa             (T,) highest Hertz pressure over the cycle and the face (MPa)
  te_loaded_ptp_um      (T,) loaded TE peak-to-peak over the cycle (um along the line
                        of action)
  te_loaded_ptp_arcsec  (T,) the same as an angle of the gear (arcsec)
  te_loaded_mean_um     (T,) mean loaded TE (um)
  te_unloaded_ptp_um    (T,) unloaded TE peak-to-peak (um; the modifications' TCA)
  k_hbeta               (T,) face load factor K_Hbeta of the cycle-mean load
  end_load_ratio        (T,) end-slice load per unit face width over the mean
  converged             (T,) every position's load balance and every loaded point's
                        friction converged
  modifications         {pinion, gear}: the flank modifications of the side, by field
  warnings              the warning lines (also on stderr)
  plot                  the figure's path or null"""

#: exit status when a torque's loaded contact or friction did not converge
NOT_CONVERGED_STATUS = 3


def line_contact_design(design) -> bool:
    """Whether ``gearjax efficiency`` takes ``design`` to the line contact: a design file
    with ``[microgeometry]``, or a helical pair without lead or profile crown (whose
    flanks touch along lines the TCA route does not load)."""
    import gearjax as gj
    if getattr(design, "micro", None) is not None:
        return True
    des = getattr(design, "design", design)
    return (isinstance(des, gj.involute.InvoluteTCA) and float(des.pair.helix) != 0.0
            and float(des.lead_crown) == 0.0 and float(des.profile_crown) == 0.0)


def refuse_line_options(args, torques) -> None:
    """For a design of the point-contact chain: one torque, no line-contact option."""
    for flag, v in (("--slices", args.slices), ("--misalignment-um", args.misalignment_um),
                    ("--coupling-length-mm", args.coupling_length_mm)):
        if v is not None:
            raise ValueError(f"{flag} = {v}: applies to pairs in line contact (a design with "
                             "[microgeometry], or an unmodified helical pair) only; this "
                             "design runs the point-contact chain (use --misalign)")
    if len(torques) != 1 or ":" in args.torque_Nm:
        raise ValueError(f"--torque-Nm = {args.torque_Nm!r}: a list or range of torques is "
                         "for pairs in line contact (a design with [microgeometry]); give "
                         "one torque for this design")


def run_line_efficiency(args, design, torques, rpm, oil, surf, caught, point_only) -> int:
    """``gearjax efficiency`` in line contact (module docstring).  ``caught``: warnings
    of the lubricant set-up; ``point_only``: ``(flag, given, why)`` refused here."""
    import gearjax as gj
    from gearjax.commands import print_json, warn_nonfinite
    from gearjax.commands.line_tca import check_line_options
    from gearjax.commands.loaded import resolve_coupling
    from gearjax.progress import Progress

    positions, slices, _, f_ma, coupling = check_line_options(args, point_only)
    coupling = resolve_coupling(coupling, design)
    with Progress(1, "efficiency") as bar, bar.phase(
            f"{args.side} side: loaded line contact and friction, {len(torques)} torque(s), "
            f"{positions} positions x {slices} slices"):
        res = gj.involute.loaded_te_map(
            design, torques, [f_ma], side=args.side, positions=positions, slices=slices,
            compliance=args.compliance, pinion_rpm=rpm, oil=oil, surface=surf,
            viscosity_model=args.viscosity, film_method=args.film,
            coupling_length_mm=coupling)
        bar.update()
    mat = gj.pair_material(design)
    rb2 = float(gj.involute.pair_geometry(getattr(design, "design", design).pair)["rb2"])
    col = lambda a: np.asarray(a, float)[:, 0].tolist()  # noqa: E731
    ptp = np.asarray(res.te_ptp_um, float)[:, 0]
    T = np.asarray(res.torque_Nm, float)
    inp = {"design": args.design, "side": args.side, "torque_Nm": [float(t) for t in T],
           "rpm": rpm, "oil": args.oil, "eta0_Pas": float(oil.eta0),
           "alpha_per_GPa": float(oil.alpha) * 1e3, "tau0_MPa": float(oil.tau0),
           "sigma_um": args.sigma_um, "asperity_density_per_mm2": args.asperity_density_per_mm2,
           "asperity_radius_um": args.asperity_radius_um, "fc": args.fc, "film": args.film,
           "viscosity": args.viscosity, "compliance": args.compliance, "positions": positions,
           "slices": slices, "misalignment_um": f_ma, "coupling_length_mm": coupling,
           "E_prime_MPa": float(mat.e_prime_MPa),
           "youngs_modulus_MPa": float(mat.youngs_modulus_MPa), "poisson": float(mat.poisson),
           "material_source": mat.source}
    out = {"input": inp, "model": "line contact", "torque_Nm": inp["torque_Nm"],
           "power_in_W": (T * rpm * math.pi / 30.0).tolist(),
           "power_loss_W": col(res.power_loss_W), "efficiency": col(res.efficiency),
           "p_max_MPa": col(res.p_max), "te_loaded_ptp_um": ptp.tolist(),
           "te_loaded_ptp_arcsec": (1e-3 * ptp / rb2 * 180.0 / math.pi * 3600.0).tolist(),
           "te_loaded_mean_um": col(res.te_mean_um),
           "te_unloaded_ptp_um": col(res.te_unloaded_ptp_um), "k_hbeta": col(res.k_hbeta),
           "end_load_ratio": col(res.end_load),
           "converged": np.asarray(res.converged, bool)[:, 0].tolist(),
           "modifications": modifications(design, args.side),
           "warnings": [str(w.message) for w in caught], "plot": args.plot}
    out["warnings"] += gj.involute.resolution_warnings(design, slices, coupling)
    bad = [t for t, ok in zip(out["torque_Nm"], out["converged"]) if not ok]
    for t in bad:
        out["warnings"].append(f"{args.side} side: the loaded line contact or its friction at "
                               f"{t:g} N m did not converge")
    for w in out["warnings"]:
        sys.stderr.write(f"gearjax: warning: {w}\n")
    if args.plot is not None:
        from gearjax.plot.microgeometry import removal_map, save_line_efficiency_plot
        save_line_efficiency_plot(args.plot, removal_map(design, "pinion", args.side), res,
                                  title=f"gearjax efficiency {args.design} ({args.side})")
    status = 0
    if bad:
        sys.stderr.write(f"gearjax: error: {len(bad)} of {len(T)} torques did not converge "
                         "(see the warnings); try more --positions or --slices, or check the "
                         "design\n")
        status = NOT_CONVERGED_STATUS
    if args.json:
        print_json(out)
        return status
    keys = ("power_loss_W", "efficiency", "p_max_MPa", "te_loaded_ptp_um", "k_hbeta")
    warn_nonfinite(f"{k}[{i}]" for k in keys for i in range(len(T))
                   if not math.isfinite(out[k][i]))
    _print_table(out, args)
    return status


def _print_table(out, args) -> None:
    inp = out["input"]
    print(f"# mesh efficiency, line contact {args.design} ({args.side}); n1 = {inp['rpm']:g} "
          f"rpm, oil {args.oil or 'custom'}, sigma = {args.sigma_um:g} um; f_ma "
          f"{inp['misalignment_um']:g} um; {inp['positions']} positions x {inp['slices']} "
          f"slices, compliance {inp['compliance']}, coupling length "
          f"{inp['coupling_length_mm']:g} mm")
    print(f"# material: E' = {inp['E_prime_MPa']:.0f} MPa (E = {inp['youngs_modulus_MPa']:.0f} "
          f"MPa, nu = {inp['poisson']:g}; {inp['material_source']})")
    print(f"{'torque[Nm]':>11s} {'P_in[W]':>10s} {'P_loss[W]':>10s} {'eta[%]':>9s} "
          f"{'p_max[MPa]':>11s} {'LTE_ptp[um]':>12s} {'LTE_ptp[arcsec]':>15s} {'K_Hbeta':>8s} "
          "converged")
    for i, T in enumerate(out["torque_Nm"]):
        print(f"{T:11.4g} {out['power_in_W'][i]:10.2f} {out['power_loss_W'][i]:10.3f} "
              f"{100 * out['efficiency'][i]:9.4f} {out['p_max_MPa'][i]:11.1f} "
              f"{out['te_loaded_ptp_um'][i]:12.4f} {out['te_loaded_ptp_arcsec'][i]:15.4f} "
              f"{out['k_hbeta'][i]:8.4f} {'yes' if out['converged'][i] else 'no'}")
    if out["plot"]:
        print(f"# plot written to {out['plot']}")
