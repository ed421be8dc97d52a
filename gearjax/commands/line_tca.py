"""``gearjax tca`` of an involute design file with ``[microgeometry]`` tables: the
unloaded TCA of the modified flanks by the thin-slice line contact
(:func:`gearjax.involute.line_tca`, docs/microgeometry.md), and with ``--torque-Nm`` the
loaded TE at those torques.

The unloaded TE at a mesh position is the smallest separation of the slice points of
all tooth pairs on the path of contact, ``TE0 = min_j e_j`` (µm along the line of
action; ``TE0 / r_b2`` of the gear in arcsec).  Options of the point-contact TCA that
have no meaning here (``--misalign``, ``--pitches``, ``--kinematics``) are refused in
one line, and the line-contact options (``--slices``, ``--torque-Nm``,
``--misalignment-um``) are refused for designs without ``[microgeometry]``, both before
any work (exit 2).  Exit 3 when the loaded contact at a torque did not converge.
"""

from __future__ import annotations

import math
import sys

import numpy as np

LINE_TCA_KEYS_DOC = """JSON keys of a design with [microgeometry] (line contact; M positions per
base pitch, T torques; with --side both the side keys are under "drive" and "coast"):
  input            the options as given (design, side, positions, slices,
                   misalignment_um, torque_Nm, coupling_length_mm: the value used,
                   'module' resolved, compliance)
  model            "line contact": the thin-slice line contact of docs/microgeometry.md
  phi1_rad         (M,) pinion angle of each mesh position, s0 / r_b1 (rad; 0: pair 0
                   at the pitch point)
  s0_mm            (M,) path coordinate of pair 0 at the face centre (mm)
  te_um            (M,) unloaded TE, the smallest separation min_j e_j of the modified
                   flanks (um along the line of action, > 0: the gear lags)
  te_arcsec        (M,) the same as an angle of the gear, te / r_b2 (arcsec)
  ptp_um           unloaded TE peak-to-peak over the cycle (um)
  ptp_arcsec       the same (arcsec of the gear)
  pairs_in_contact (M,) tooth pairs touching at zero load (a point within 1e-6 um of
                   the smallest separation)
  contact_ratio_zero_load  mean of pairs_in_contact over the cycle
  contact_ratio    eps_alpha of the pair (geometry of the path of contact)
  overlap_ratio    eps_beta = b tan(beta_b) / p_bt
  first_contact    {pair, xi1_mm, r1_mm, y_mm}, (M,) each: the tooth pair, pinion roll
                   length (mm), pinion radius (mm) and face position (mm from the face
                   centre, end I negative) of the point that touches first
  modifications    {pinion, gear}: the flank modifications of the side, by field (um
                   amounts, mm lengths, exponents)
  loaded           null without --torque-Nm, else {torque_Nm (T,), te_loaded_um (T, M)
                   loaded TE over the cycle (um), te_ptp_um (T,), te_mean_um (T,),
                   p_max_MPa (T,) highest Hertz pressure, k_hbeta (T,) face load factor
                   of the cycle-mean load, converged (T,)}
  warnings         the warning lines (also on stderr)
  plot             the figure's path or null"""

#: why the point-contact options have no meaning in the line contact
MIS_WHY = "it takes the mesh misalignment f_ma as --misalignment-um"
CYCLE_WHY = "it analyses one mesh cycle, set by --positions"

#: figure suffixes of the line-contact figure
PLOT_SUFFIXES = (".png", ".pdf", ".svg")


def add_line_options(p) -> None:
    """The options of the line-contact route (designs with ``[microgeometry]``)."""
    import gearjax as gj

    lo, hi = gj.involute.TORQUE_RANGE_NM
    mlo, mhi = gj.involute.MISALIGNMENT_RANGE_UM
    p.add_argument("--slices", type=float, default=None,
                   help="[microgeometry] designs only: face-width slices, integer 1..400 "
                        "(default 20)")
    p.add_argument("--torque-Nm", default=None,
                   help=f"[microgeometry] designs only: add the loaded TE at these pinion "
                        f"torques (N m, each in [{lo:g}, {hi:g}]): a comma list 50,100 or a "
                        "range START:STOP:COUNT")
    p.add_argument("--misalignment-um", type=float, default=None,
                   help=f"[microgeometry] designs only: mesh misalignment f_ma (um over the "
                        f"face width, in [{mlo:g}, {mhi:g}]; default 0)")
    add_coupling_option(p, "[microgeometry] designs only, the loaded TE: ")
    p.add_argument("--compliance", choices=list(gj.loading.COMPLIANCE_MODELS), default=None,
                   help="[microgeometry] designs only, the loaded TE: tooth compliance per "
                        "unit length of contact line, weber (default) or iso6336, as "
                        "gearjax loaded")


def add_coupling_option(p, lead: str) -> None:
    """``--coupling-length-mm`` of a command's line-contact route (``lead``: to whom it
    applies), as in ``gearjax loaded``."""
    import gearjax as gj
    clo, chi = gj.involute.COUPLING_LENGTH_RANGE_MM
    p.add_argument("--coupling-length-mm", default=None,
                   help=f"{lead}coupling length of the slices along the face (mm, in "
                        f"[{clo:g}, {chi:g}]) or 'module' (the normal module): a Pasternak "
                        "foundation along each tooth pair's face; default 0, independent "
                        "slices (Winkler)")


def line_route(text: str) -> bool:
    """Whether DESIGN ``text`` names an involute design file with ``[microgeometry]``
    tables (its raw TOML, read without building the design, so that the options are
    checked first); a file that cannot be read is left to the design loader's refusal."""
    import gearjax as gj
    if text.startswith("involute:"):
        return False
    try:
        data = gj.io.read_toml(text)
    except (OSError, ValueError):
        return False
    head = data.get("design")
    return isinstance(head, dict) and head.get("kind") == "involute" and "microgeometry" in data


def refuse_line_options(args) -> None:
    """The line-contact options given for a design without ``[microgeometry]``: one line."""
    for flag, v in (("--slices", args.slices), ("--torque-Nm", args.torque_Nm),
                    ("--misalignment-um", args.misalignment_um),
                    ("--coupling-length-mm", args.coupling_length_mm),
                    ("--compliance", args.compliance)):
        if v is not None:
            raise ValueError(f"{flag} = {v}: applies to involute designs with "
                             "[microgeometry] tables (the line contact) only; this design "
                             "runs the point-contact TCA (use --misalign, or `gearjax "
                             "efficiency` for a loaded result)")


def modifications(design, side) -> dict:
    """``{pinion, gear}``: the modification fields of ``side`` (floats; µm, mm, -)."""
    import gearjax as gj
    from dataclasses import fields
    pm = (getattr(design, "micro", None) or gj.involute.MicroGeometry.none()).flanks(side)
    return {m: {f.name: float(getattr(getattr(pm, m), f.name))
                for f in fields(gj.involute.FlankModification)} for m in ("pinion", "gear")}


def check_line_values(args) -> None:
    """The values of ``--slices``, ``--misalignment-um`` and ``--coupling-length-mm`` when
    given (one line each), for a command that learns its route only from the design."""
    import gearjax as gj
    from gearjax.commands.loaded import parse_coupling
    from gearjax.errors import check_int, check_range
    if args.coupling_length_mm is not None:
        parse_coupling(args.coupling_length_mm)
    if args.slices is not None:
        check_int("--slices", args.slices, lo=1, hi=400)
    if args.misalignment_um is not None:
        check_range("--misalignment-um", args.misalignment_um,
                    *gj.involute.MISALIGNMENT_RANGE_UM, unit="um")


def check_line_options(args, point_only) -> tuple:
    """``(positions, slices, torques, f_ma, coupling)`` of the line route, checked (one
    line each; ``coupling`` None for ``module``, :func:`gearjax.commands.loaded.
    resolve_coupling`); ``point_only``: ``(flag, given, why)`` of options the line
    contact does not take."""
    import gearjax as gj
    from gearjax.commands.loaded import parse_coupling, parse_torques
    from gearjax.errors import check_int, check_range
    from gearjax.io import check_output_path

    for flag, given, why in point_only:
        if given:
            raise ValueError(f"{flag}: not an option of the thin-slice line contact ({why}) "
                             "that analyses this design; leave it out")
    positions = check_int("--positions", 32 if args.positions is None else args.positions,
                          lo=4, hi=1024)
    slices = check_int("--slices", 20 if args.slices is None else args.slices, lo=1, hi=400)
    torques = ([] if args.torque_Nm is None
               else parse_torques(args.torque_Nm, *gj.involute.TORQUE_RANGE_NM))
    f_ma = 0.0 if args.misalignment_um is None else check_range(
        "--misalignment-um", args.misalignment_um, *gj.involute.MISALIGNMENT_RANGE_UM,
        unit="um")
    coupling = parse_coupling("0" if args.coupling_length_mm is None
                              else args.coupling_length_mm)
    if args.plot:
        check_output_path(args.plot, "--plot", PLOT_SUFFIXES)
    return positions, slices, torques, f_ma, coupling


def _side_json(r, design, side) -> dict:
    arr = lambda a: np.asarray(a, float).tolist()  # noqa: E731
    out = {
        "model": "line contact",
        "phi1_rad": arr(r.phi1_rad), "s0_mm": arr(r.s0_mm),
        "te_um": arr(r.te_um), "te_arcsec": arr(r.te_arcsec),
        "ptp_um": float(r.ptp_um), "ptp_arcsec": float(r.ptp_arcsec),
        "pairs_in_contact": [int(v) for v in np.asarray(r.pairs_in_contact)],
        "contact_ratio_zero_load": float(r.contact_ratio_zero_load),
        "contact_ratio": float(r.contact_ratio), "overlap_ratio": float(r.overlap_ratio),
        "first_contact": {"pair": [int(v) for v in np.asarray(r.first_pair)],
                          "xi1_mm": arr(r.first_xi1_mm), "r1_mm": arr(r.first_r1_mm),
                          "y_mm": arr(r.first_y_mm)},
        "modifications": modifications(design, side),
        "loaded": None,
    }
    if np.size(r.torque_Nm):
        out["loaded"] = {"torque_Nm": arr(r.torque_Nm), "te_loaded_um": arr(r.te_loaded_um),
                         "te_ptp_um": arr(r.te_loaded_ptp_um),
                         "te_mean_um": arr(r.te_loaded_mean_um),
                         "p_max_MPa": arr(r.p_max_MPa), "k_hbeta": arr(r.k_hbeta),
                         "converged": [bool(v) for v in np.asarray(r.converged)]}
    return out


def run_line_tca(args) -> int:
    """``gearjax tca`` of a design with ``[microgeometry]`` (module docstring): the
    options checked, then the design read, then the work."""
    import gearjax as gj
    from gearjax.commands import print_json, warn_nonfinite
    from gearjax.commands.loaded import resolve_coupling
    from gearjax.progress import Progress

    positions, slices, torques, f_ma, coupling = check_line_options(args, (
        ("--misalign", bool(args.misalign.strip()), MIS_WHY),
        ("--pitches", args.pitches is not None, CYCLE_WHY),
        ("--kinematics", args.kinematics, "the velocities along the contact lines are "
                                          "those of `gearjax efficiency`")))
    design = gj.load_design(args.design)
    coupling = resolve_coupling(coupling, design)
    compliance = args.compliance or "weber"
    sides = ["drive", "coast"] if args.side == "both" else [args.side]
    results = {}
    with Progress(len(sides), "tca") as bar:
        for side in sides:
            with bar.phase(f"{side} side: line-contact TCA, {positions} positions x {slices} "
                           f"slices" + (f", {len(torques)} torque(s)" if torques else "")):
                results[side] = gj.involute.line_tca(
                    design, torques_Nm=torques, side=side, misalignment_um=f_ma,
                    positions=positions, slices=slices, coupling_length_mm=coupling,
                    compliance=compliance)
            bar.update()
    outs = {sd: _side_json(r, design, sd) for sd, r in results.items()}
    warns = list(gj.involute.resolution_warnings(design, slices,
                                                  coupling if torques else 0.0))
    bad = []
    for sd, o in outs.items():
        if o["loaded"] is not None:
            for T, ok in zip(o["loaded"]["torque_Nm"], o["loaded"]["converged"]):
                if not ok:
                    bad.append(T)
                    warns.append(f"{sd} side: the loaded contact at {T:g} N m did not "
                                 "converge (torque balance or no contact)")
    for w in warns:
        sys.stderr.write(f"gearjax: warning: {w}\n")
    if args.plot:
        from gearjax.plot.microgeometry import removal_map, save_line_tca_plot
        first = sides[0]
        maps = [(f"{m} {first} flank", removal_map(design, m, first)) for m in ("pinion", "gear")]
        save_line_tca_plot(args.plot, maps, results, title=f"gearjax tca {args.design}")
    status = 0
    if bad:
        sys.stderr.write(f"gearjax: error: {len(bad)} loaded operating point(s) did not "
                         "converge (see the warnings); try more --positions or --slices, or "
                         "check the design\n")
        status = 3
    inp = {"design": args.design, "side": args.side, "positions": positions, "slices": slices,
           "misalignment_um": f_ma, "torque_Nm": torques, "coupling_length_mm": coupling,
           "compliance": compliance}
    tail = {"warnings": warns, "plot": args.plot}
    if args.json:
        body = outs[sides[0]] if len(sides) == 1 else outs
        print_json({"input": inp, **body, **tail})
        return status
    warn_nonfinite(f"{sd}.te_um" for sd, o in outs.items()
                   if not all(math.isfinite(v) for v in o["te_um"]))
    for sd, o in outs.items():
        _print_side(o, sd, args, inp)
    if args.plot:
        print(f"# plot written to {args.plot}")
    return status


def _print_side(o, side, args, inp) -> None:
    print(f"# line-contact TCA {args.design} ({side}); {inp['positions']} positions per base "
          f"pitch x {inp['slices']} slices, f_ma {inp['misalignment_um']:g} um")
    print(f"# unloaded TE p-t-p {o['ptp_um']:.4f} um = {o['ptp_arcsec']:.4f} arcsec; contact "
          f"ratio {o['contact_ratio']:.4f}, overlap ratio {o['overlap_ratio']:.4f}; pairs in "
          f"contact at zero load {o['contact_ratio_zero_load']:.4f} (mean)")
    print(f"{'phi1[deg]':>10s} {'TE[um]':>9s} {'TE[arcsec]':>11s} {'pairs':>5s} "
          f"{'first:pair':>10s} {'xi1[mm]':>9s} {'r1[mm]':>9s} {'y[mm]':>8s}")
    fc = o["first_contact"]
    for i, phi in enumerate(o["phi1_rad"]):
        print(f"{math.degrees(phi):10.4f} {o['te_um'][i]:9.4f} {o['te_arcsec'][i]:11.4f} "
              f"{o['pairs_in_contact'][i]:5d} {fc['pair'][i]:10d} {fc['xi1_mm'][i]:9.4f} "
              f"{fc['r1_mm'][i]:9.4f} {fc['y_mm'][i]:8.3f}")
    ld = o["loaded"]
    if ld is None:
        return
    print(f"# loaded TE against torque ({side})")
    print(f"{'torque[Nm]':>11s} {'LTE_ptp[um]':>12s} {'LTE_mean[um]':>13s} {'p_max[MPa]':>11s} "
          f"{'K_Hbeta':>8s} converged")
    for i, T in enumerate(ld["torque_Nm"]):
        print(f"{T:11.4g} {ld['te_ptp_um'][i]:12.4f} {ld['te_mean_um'][i]:13.4f} "
              f"{ld['p_max_MPa'][i]:11.1f} {ld['k_hbeta'][i]:8.4f} "
              f"{'yes' if ld['converged'][i] else 'no'}")
