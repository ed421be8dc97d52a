"""``gearjax loaded``: loaded transmission error, peak pressure and face load factor of a
spur or helical involute pair with micro-geometry over a torque range and a set of
mesh misalignments (:func:`gearjax.involute.loaded_te_map`, the thin-slice line contact
of :mod:`gearjax.gears.involute.line_load`; docs/microgeometry.md).

DESIGN is an involute design file (a path or ``example:NAME``) whose ``[microgeometry]``
tables give the flank modifications, or an inline ``involute:z1=..,z2=..,m=..,alpha=..,
b=..[,helix=..,x1=..,x2=..]`` pair (unmodified flanks).  ``--torque-Nm`` is a comma list
(``50,100,200``) or a range ``START:STOP:COUNT`` (COUNT torques evenly spaced from START
to STOP); ``--misalignment-um`` a comma list of mesh misalignments f_ma (µm over the face
width, positive opening end II).

Exit status: 0; 2 bad input, refused before any work (one line naming the parameter,
its value and the range); 3 when an operating point did not converge (its row is
printed, marked ``no``; a ``gearjax: warning:`` line per such point and one
``gearjax: error:`` line).
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np

from gearjax.commands.designs import involute_design, is_involute
from gearjax.commands.friction import add_lubricant_options, lubricant_from_args

#: most torques and most misalignments of one run
MAX_TORQUES = 200
MAX_MISALIGNMENTS = 50
#: exit status when an operating point did not converge
NOT_CONVERGED_STATUS = 3

JSON_KEYS_DOC = """JSON keys:
  input            the design and options as given (design, side, torque_Nm,
                   misalignment_um, positions, slices, compliance,
                   coupling_length_mm (the value used, mm), rpm, oil, sigma_um, film,
                   viscosity)
  torque_Nm        the pinion torques (N m), T values
  misalignment_um  the mesh misalignments f_ma (um over the face width), A values
  te_ptp_um        loaded TE peak-to-peak over the mesh cycle (um along the line of
                   action), T lists of A values
  te_mean_um       mean loaded TE (um), T x A
  te_unloaded_ptp_um  unloaded TE peak-to-peak (um; the modifications' TCA: the
                   separation closed first at zero load), T x A
  p_max_MPa        highest Hertz pressure over the cycle and the face (MPa), T x A
  k_hbeta          face load factor K_Hbeta of the cycle-mean load distribution, T x A
  end_load_ratio   load per unit face width in the end slices over the mean, of the
                   cycle-mean distribution (> 1: the face ends carry more than the
                   middle), T x A
  power_loss_W     mean sliding power loss over the cycle (W), T x A; null without --rpm
  efficiency       mesh efficiency over the cycle, T x A; null without --rpm
  converged        every position of the cycle converged (with --rpm: and every
                   loaded point's friction solve), T x A booleans
  modifications    {pinion, gear}: the flank modifications of the analysed side, by
                   field (um amounts, mm lengths, exponents; docs/microgeometry.md)
  warnings         the warning lines (also on stderr)
  plot             the figure's path or null"""


def register(sub):
    import gearjax as gj

    lo, hi = gj.involute.TORQUE_RANGE_NM
    mlo, mhi = gj.involute.MISALIGNMENT_RANGE_UM
    p = sub.add_parser(
        "loaded", help="loaded TE, p_max and K_Hbeta of an involute pair with micro-geometry "
                       "over torques and misalignments",
        description="Loaded line contact of a spur or helical involute pair with the flank "
                    "micro-geometry of its design file ([microgeometry]): loaded "
                    "transmission error, peak Hertz pressure, face load factor and end "
                    "loading over a torque range and a set of mesh misalignments, in one "
                    "vmapped program (docs/microgeometry.md).",
        epilog=JSON_KEYS_DOC, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("design", help="an involute design file (DESIGN.toml or example:NAME, "
                                  "[microgeometry] tables) or involute:z1=..,z2=..,m=..,"
                                  "alpha=..,b=..[,helix=..,x1=..,x2=..]")
    p.add_argument("--torque-Nm", required=True,
                   help=f"pinion torques (N m, each in [{lo:g}, {hi:g}]): a comma list "
                        f"50,100,200 or a range START:STOP:COUNT (COUNT 1..{MAX_TORQUES})")
    p.add_argument("--misalignment-um", default="0",
                   help=f"mesh misalignments f_ma (um over the face width, each in "
                        f"[{mlo:g}, {mhi:g}], at most {MAX_MISALIGNMENTS}): a comma list; "
                        "default 0")
    p.add_argument("--side", choices=["drive", "coast"], default="drive")
    p.add_argument("--positions", type=float, default=32,
                   help="mesh positions per base pitch, integer 4..1024 (default 32)")
    p.add_argument("--slices", type=float, default=20,
                   help="face-width slices, integer 1..400 (default 20)")
    p.add_argument("--compliance", choices=list(gj.loading.COMPLIANCE_MODELS), default="weber",
                   help="tooth compliance per unit length of contact line: weber (Weber/"
                        "Sainsot cantilevers and Weber's contact term) or iso6336 (the "
                        "constant single stiffness of ISO 6336-1); default weber")
    clo, chi = gj.involute.COUPLING_LENGTH_RANGE_MM
    p.add_argument("--coupling-length-mm", default="0",
                   help=f"coupling length of the slices along the face (mm, in [{clo:g}, "
                        f"{chi:g}]), or 'module' (the normal module, the recommended value): "
                        "a Pasternak foundation along each tooth pair's face; 0 (default): "
                        "independent slices (Winkler)")
    rlo, rhi = gj.loading.RPM_RANGE
    p.add_argument("--rpm", type=float, default=None,
                   help=f"pinion speed (rpm, in [{rlo:g}, {rhi:g}]): adds the sliding power "
                        "loss and the mesh efficiency (mixed-lubrication friction along the "
                        "contact lines); needs --oil or --eta0, and --sigma-um")
    add_lubricant_options(p, e_prime_help=None, required=False)
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--plot", default=None,
                   help="write the pinion drive flank's modification map and LTE p-t-p "
                        "against torque (.png, .pdf or .svg)")
    p.set_defaults(func=run)


def _number(flag, text, lo, hi, unit):
    from gearjax.errors import check_range
    try:
        v = float(text)
    except ValueError:
        raise ValueError(f"{flag}: {text!r} must be a number ({unit})") from None
    return check_range(flag, v, lo, hi, unit=unit)


def parse_coupling(text: str):
    """``--coupling-length-mm``: a length in :data:`gearjax.involute.
    COUPLING_LENGTH_RANGE_MM` (mm; 0: the Winkler slices) or ``module`` (returned as
    None: the design's normal module, :func:`resolve_coupling` once it is read)."""
    import gearjax as gj
    if text.strip() == "module":
        return None
    return _number("--coupling-length-mm", text, *gj.involute.COUPLING_LENGTH_RANGE_MM, "mm")


def resolve_coupling(value, design) -> float:
    """The coupling length (mm) of :func:`parse_coupling`'s ``value`` for ``design``."""
    import gearjax as gj
    return gj.involute.module_coupling_length(design) if value is None else value


def parse_torques(text: str, lo: float, hi: float) -> list:
    """``--torque-Nm``: a comma list or ``START:STOP:COUNT`` (module docstring)."""
    text = text.strip()
    if ":" in text:
        parts = [s.strip() for s in text.split(":")]
        if len(parts) != 3:
            raise ValueError(f"--torque-Nm = {text!r}: a range is START:STOP:COUNT "
                             "(e.g. 50:400:8)")
        a = _number("--torque-Nm START", parts[0], lo, hi, "N m")
        b = _number("--torque-Nm STOP", parts[1], lo, hi, "N m")
        try:
            n = int(parts[2])
        except ValueError:
            raise ValueError(f"--torque-Nm COUNT = {parts[2]!r} must be an integer "
                             f"1..{MAX_TORQUES}") from None
        if not 1 <= n <= MAX_TORQUES:
            raise ValueError(f"--torque-Nm COUNT = {n} is outside the allowed range "
                             f"[1, {MAX_TORQUES}]")
        if n == 1 and a != b:
            raise ValueError(f"--torque-Nm = {text!r}: one torque needs START = STOP")
        return [float(v) for v in np.linspace(a, b, n)]
    return _list("--torque-Nm", text, lo, hi, "N m", MAX_TORQUES)


def _list(flag, text, lo, hi, unit, most):
    items = [s.strip() for s in text.split(",")]
    if not text.strip() or any(not s for s in items):
        raise ValueError(f"{flag} = {text!r}: give a comma list of numbers ({unit}) without "
                         "empty items")
    if len(items) > most:
        raise ValueError(f"{flag}: {len(items)} values, at most {most}")
    vals = [_number(flag, s, lo, hi, unit) for s in items]
    if len(set(vals)) != len(vals):
        raise ValueError(f"{flag} = {text!r} gives a value twice")
    return vals


def _modifications(design, side):
    import gearjax as gj
    from dataclasses import fields
    micro = getattr(design, "micro", None) or gj.involute.MicroGeometry.none()
    pm = micro.flanks(side)
    return {m: {f.name: float(getattr(getattr(pm, m), f.name))
                for f in fields(gj.involute.FlankModification)} for m in ("pinion", "gear")}


def _rows(out):
    for i, T in enumerate(out["torque_Nm"]):
        for j, a in enumerate(out["misalignment_um"]):
            yield i, j, T, a


def run(args) -> int:
    import gearjax as gj
    from gearjax.commands import print_json, warn_nonfinite
    from gearjax.errors import check_int, check_range
    from gearjax.io import check_output_path
    from gearjax.progress import Progress

    # every input is checked before any work (one line naming it, status 2)
    torques = parse_torques(args.torque_Nm, *gj.involute.TORQUE_RANGE_NM)
    mis = _list("--misalignment-um", args.misalignment_um, *gj.involute.MISALIGNMENT_RANGE_UM,
                "um", MAX_MISALIGNMENTS)
    positions = check_int("--positions", args.positions, lo=4, hi=1024)
    slices = check_int("--slices", args.slices, lo=1, hi=400)
    if args.plot is not None:
        check_output_path(args.plot, "--plot", (".png", ".pdf", ".svg"))
    lube = {}
    oil_given = args.oil is not None or args.eta0 is not None
    if args.rpm is None:
        if oil_given or args.sigma_um is not None:
            raise ValueError("--oil/--eta0 and --sigma-um apply with --rpm only (the "
                             "efficiency); give --rpm or leave them out")
    else:
        check_range("--rpm", args.rpm, *gj.loading.RPM_RANGE, unit="rpm")
        if not oil_given or args.sigma_um is None:
            raise ValueError("--rpm needs the lubrication: --oil NAME (or --eta0) and "
                             "--sigma-um")
        oil, surf, _ = lubricant_from_args(args)
        lube = dict(pinion_rpm=args.rpm, oil=oil, surface=surf,
                    viscosity_model=args.viscosity, film_method=args.film)
    coupling = parse_coupling(args.coupling_length_mm)
    design = (involute_design(args.design)[1] if is_involute(args.design)
              else gj.load_design(args.design))
    if not isinstance(design, (gj.involute.InvoluteFile, gj.involute.InvoluteTCA)):
        raise ValueError(f"DESIGN {args.design!r} is not an involute pair: `gearjax loaded` "
                         "analyses spur and helical involute pairs ([design] kind = "
                         "'involute' or involute:...)")
    coupling = resolve_coupling(coupling, design)
    with Progress(1, "loaded") as bar, bar.phase(
            f"{args.side} side: loaded line contact, {len(torques)} torque(s) x "
            f"{len(mis)} misalignment(s), {positions} positions x {slices} slices"):
        res = gj.involute.loaded_te_map(design, torques, mis, side=args.side,
                                        positions=positions, slices=slices,
                                        compliance=args.compliance,
                                        coupling_length_mm=coupling, **lube)
        bar.update()
    arr = lambda a: np.asarray(a, float).tolist()  # noqa: E731
    out = {
        "input": {"design": args.design, "side": args.side, "torque_Nm": torques,
                  "misalignment_um": mis, "positions": positions, "slices": slices,
                  "compliance": args.compliance, "coupling_length_mm": coupling,
                  "rpm": args.rpm, "oil": args.oil,
                  "sigma_um": args.sigma_um, "film": args.film, "viscosity": args.viscosity},
        "torque_Nm": arr(res.torque_Nm), "misalignment_um": arr(res.misalignment_um),
        "te_ptp_um": arr(res.te_ptp_um), "te_mean_um": arr(res.te_mean_um),
        "te_unloaded_ptp_um": arr(res.te_unloaded_ptp_um),
        "p_max_MPa": arr(res.p_max), "k_hbeta": arr(res.k_hbeta),
        "end_load_ratio": arr(res.end_load),
        "power_loss_W": arr(res.power_loss_W) if lube else None,
        "efficiency": arr(res.efficiency) if lube else None,
        "converged": np.asarray(res.converged, bool).tolist(),
        "modifications": _modifications(design, args.side),
        "warnings": [], "plot": args.plot,
    }
    out["warnings"] += gj.involute.resolution_warnings(design, slices, coupling)
    bad = [(T, a) for i, j, T, a in _rows(out) if not out["converged"][i][j]]
    for T, a in bad:
        out["warnings"].append(f"{args.side} side: the loaded contact at {T:g} N m, f_ma "
                               f"{a:g} um did not converge (torque balance, no contact, or "
                               "the coupled contact's active set)")
    for w in out["warnings"]:
        sys.stderr.write(f"gearjax: warning: {w}\n")
    if args.plot is not None:
        from gearjax.plot.microgeometry import removal_map, save_loaded_plot
        save_loaded_plot(args.plot, removal_map(design, "pinion", "drive"), res,
                         title=f"gearjax loaded {args.design} ({args.side})")
    status = 0
    if bad:
        sys.stderr.write(f"gearjax: error: {len(bad)} of {len(torques) * len(mis)} operating "
                         "points did not converge (see the warnings); try more --positions or "
                         "--slices, or check the design\n")
        status = NOT_CONVERGED_STATUS
    if args.json:
        print_json(out)
        return status
    keys = ("te_ptp_um", "te_mean_um", "te_unloaded_ptp_um", "p_max_MPa", "k_hbeta",
            "end_load_ratio") + (
        ("power_loss_W", "efficiency") if lube else ())
    warn_nonfinite(f"{k}[{i}][{j}]" for k in keys
                   for i, j, _, _ in _rows(out) if not math.isfinite(out[k][i][j]))
    _print_table(out, args)
    return status


def _print_table(out, args):
    inp = out["input"]
    print(f"# loaded line contact {args.design} ({args.side}); {inp['positions']} positions "
          f"x {inp['slices']} slices, compliance {inp['compliance']}, coupling length "
          f"{inp['coupling_length_mm']:g} mm")
    eff = out["efficiency"] is not None
    print(f"{'torque[Nm]':>11s} {'f_ma[um]':>9s} {'LTE_ptp[um]':>12s} {'LTE_mean[um]':>13s} "
          f"{'p_max[MPa]':>11s} {'K_Hbeta':>8s} {'end_load':>9s} "
          + (f"{'P_loss[W]':>10s} {'eta[%]':>8s} " if eff else "") + "converged")
    for i, j, T, a in _rows(out):
        extra = (f"{out['power_loss_W'][i][j]:10.2f} {100 * out['efficiency'][i][j]:8.3f} "
                 if eff else "")
        print(f"{T:11.4g} {a:9.3g} {out['te_ptp_um'][i][j]:12.4f} "
              f"{out['te_mean_um'][i][j]:13.4f} {out['p_max_MPa'][i][j]:11.1f} "
              f"{out['k_hbeta'][i][j]:8.4f} {out['end_load_ratio'][i][j]:9.4f} " + extra
              + f"{'yes' if out['converged'][i][j] else 'no'}")
    if out["plot"]:
        print(f"# plot written to {out['plot']}")
