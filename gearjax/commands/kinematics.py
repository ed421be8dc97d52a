"""``gearjax kinematics DESIGN``: [Eigenfunctions] eigenfunction kinematics of a hypoid design.

DESIGN is a path or ``example:NAME`` (e.g. ``example:hypoid_6x39_7p5in``).  The
model needs only the design's ``[blank]`` table (any hypoid route; the cutter radius
of the table is the face-mill radius r0; see :mod:`gearjax.studies.cutter_radius`):
the gear flank is the cutter cone at the pitch point, the pinion its conjugate.
Prints the field statistics (mean/min/max of u_e, u_s, SRR, R_eff, K_II, Phi_I,
Phi_II over the working flank) and the limit checks (meshing limit Phi_I = 0,
curvature interference Phi_II = 0, entrainment reversal u_e = 0)."""

from __future__ import annotations

import math
import re
import sys

_FIELDS = ("u_e", "u_s", "srr", "r_eff", "k_II", "phi_I", "phi_II")
_UNITS = {"u_e": "mm/rad", "u_s": "mm/rad", "srr": "-", "r_eff": "mm", "k_II": "1/mm",
          "phi_I": "", "phi_II": ""}


def _grid(text: str):
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m:
        raise ValueError(f"--grid = {text!r} must look like 31x15 (depth x face points)")
    a, b = int(m.group(1)), int(m.group(2))
    for name, v in (("--grid depth points", a), ("--grid face points", b)):
        if not 3 <= v <= 201:
            raise ValueError(f"{name} = {v} is outside the allowed range [3, 201]")
    return a, b


def register(sub):
    p = sub.add_parser("kinematics", help="eigenfunction kinematics of a hypoid design (SRR, sliding, effective radius)",
                       description="Entrainment velocity, SRR, effective radius and limit "
                                   "checks over the working gear flank.")
    p.add_argument("design", help="design file path or example:NAME")
    p.add_argument("--grid", default="31x15", help="depth x face points (default 31x15)")
    p.add_argument("--flank", choices=["convex", "concave"], default="convex",
                   help="gear flank (convex = drive side, default)")
    p.add_argument("--blade-angle-delta", type=float, default=0.0,
                   help="blade angle change from the blank's pressure angle (deg, in [-10, 10])")
    p.add_argument("--cutter-shift", type=float, default=0.0,
                   help="cutter centre shift normal to the tooth trace (mm, in [-20, 20])")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--plot", default=None, help="save field maps to this .png")
    p.set_defaults(func=run)


def run(args) -> int:
    from gearjax.commands import print_json, warn_nonfinite
    from gearjax.errors import check_range
    from gearjax.io import check_output_path
    from gearjax.studies import cutter_radius as hk
    from gearjax import load_design
    from gearjax.progress import Progress
    shape = _grid(args.grid)
    # the ranges of StudySettings.make, checked before the design is read
    check_range("--blade-angle-delta (blade_angle_delta_deg)", args.blade_angle_delta,
                -10.0, 10.0, unit="deg")
    check_range("--cutter-shift (cutter_shift_mm)", args.cutter_shift, -20.0, 20.0, unit="mm")
    if args.plot is not None:
        check_output_path(args.plot, "--plot", (".png",))
    from gearjax.hypoid import KINDS as HYPOID_KINDS
    design = load_design(args.design, kinds=HYPOID_KINDS)
    inp = design.blank_input()
    if inp.method == "iso23509-method0" or float(inp.offset) <= 0.0:
        raise ValueError("blank.offset_mm must be > 0: the eigenfunction model is for hypoid pairs (offset > 0)")
    st = hk.StudySettings.make(float(inp.cutter_radius), args.blade_angle_delta, args.cutter_shift)
    with Progress(1, "kinematics") as bar, bar.phase(f"{shape[0]}x{shape[1]} grid"):
        s, f = hk.flank_fields(inp, st, args.flank, shape)
    stats = hk.field_stats(f, _FIELDS)
    lim = hk.limit_report(f)
    out = {"design": design.name or args.design, "flank": args.flank, "grid": list(shape),
           "cutter_radius_mm": float(inp.cutter_radius),
           "blade_angle_deg": math.degrees(float(s.blade)),
           "stats": stats, "units": _UNITS,
           "limits": {k: {kk: v[kk] for kk in ("inside", "fraction", "margin",
                                               "zero_curve_axial")} for k, v in lim.items()}}
    if args.plot is not None:
        from gearjax.io import atomic_write_figure
        from gearjax.plot.kinematics import field_maps
        atomic_write_figure(field_maps({f"{out['design']} {args.flank}": f}), args.plot, dpi=90)
    if args.json:
        print_json(out)
        return 0
    warn_nonfinite(f"stats.{k}.{kk}" for k in _FIELDS for kk, v in stats[k].items()
                   if isinstance(v, float) and not math.isfinite(v))
    w = sys.stdout.write
    w(f"hypoid kinematics of {out['design']}: gear {args.flank} flank, {shape[0]}x{shape[1]} "
      f"grid, r0 = {out['cutter_radius_mm']:g} mm, blade angle {out['blade_angle_deg']:.3f} deg\n")
    w(f"  {'field':<8s} {'mean':>12s} {'min':>12s} {'max':>12s}  unit\n")
    for k in _FIELDS:
        v = stats[k]
        w(f"  {k:<8s} {v['mean']:12.5g} {v['min']:12.5g} {v['max']:12.5g}  {_UNITS[k]}\n")
    for k, v in lim.items():
        where = ""
        if v["inside"] and v["zero_curve_axial"]:
            zs = [p[0] for p in v["zero_curve_axial"]]
            rs = [p[1] for p in v["zero_curve_axial"]]
            where = (f" at z {min(zs):.2f}..{max(zs):.2f} mm, radius {min(rs):.2f}.."
                     f"{max(rs):.2f} mm ({100 * v['fraction']:.1f}% of the flank beyond it)")
        w(f"  {k:<22s} {'INSIDE the working flank' + where if v['inside'] else 'clear'}"
          f"  (margin {v['margin']:.3f})\n")
    return 0
