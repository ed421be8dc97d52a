"""``gearjax sensitivity DESIGN --outputs Q1,Q2 --params F1,F2``: scaled sensitivities
of study quantities to design fields from the exact Jacobian
(:mod:`gearjax.studies.sensitivity`).

DESIGN is a design file or ``example:NAME``; the outputs are quantity names
(``gearjax optimize --quantities``), the params field names (``gearjax optimize STUDY
--fields``, or ``--params`` with a bad name lists them).  Loaded outputs need
``--torque-Nm``, ``--rpm``, ``--oil`` and ``--sigma-um``; the outputs of the loaded line
contact (``line_*``: an involute design's micro-geometry fields
``microgeometry.TABLE.KEY``) need ``--torque-Nm`` and take the mesh misalignment
``--f-ma-um`` (``--misalign`` is the TCA's).  Prints a table (value,
per-unit derivative, elasticity) or ``--json``; ``--plot F.png`` draws a tornado chart of
the elasticities (one panel per output).  Exit 0, or 2 for bad input.
"""

from __future__ import annotations

import math

SENSITIVITY_KEYS_DOC = """JSON keys (--json):
  design, side, scenario   as given (scenario: torque_Nm, pinion_rpm, oil, sigma_um,
                           dE_mm, dP_mm, dG_mm, dSigma_deg; line-contact outputs:
                           f_ma_um, positions, slices)
  outputs                  per output: name, unit, value, and per param: field (name),
                           value (field units), per_unit (d output / d field, output unit
                           per field unit: mm, rad, -), elasticity (d ln output / d ln
                           field; null where the output or the field is 0)
"""


def register(sub):
    import argparse

    from gearjax.studies.study_file import LINE_DEFAULTS
    from gearjax.tribology import OILS
    p = sub.add_parser(
        "sensitivity", help="exact sensitivities (per unit, elasticities) of quantities to "
                            "design fields, with a tornado chart",
        description="Jacobian of named quantities w.r.t. design fields by forward-mode "
                    "autodiff through the contact solves; elasticities e = (dq/dx) x/q.",
        epilog=SENSITIVITY_KEYS_DOC, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("design", help="design file or example:NAME")
    p.add_argument("--outputs", required=True, help="comma-separated quantity names")
    p.add_argument("--params", required=True, help="comma-separated design field names")
    p.add_argument("--side", choices=["drive", "coast"], default="drive")
    p.add_argument("--torque-Nm", type=float, default=None, help="pinion torque (loaded outputs)")
    p.add_argument("--rpm", type=float, default=None, help="pinion speed (loaded outputs)")
    p.add_argument("--oil", choices=list(OILS), default=None, help="oil (loaded outputs)")
    p.add_argument("--sigma-um", type=float, default=None,
                   help="composite roughness (um, loaded outputs)")
    p.add_argument("--misalign", default="",
                   help="dE=..,dP=..,dG=..,dSigma=.. (mm, mm, mm, deg; default 0)")
    p.add_argument("--f-ma-um", type=float, default=None,
                   help="mesh misalignment f_ma (um over the face width; line-contact "
                        "outputs, default 0)")
    p.add_argument("--positions", type=float, default=None,
                   help=f"mesh positions per base pitch, integer 4..1024 (line-contact "
                        f"outputs, default {LINE_DEFAULTS['positions']})")
    p.add_argument("--slices", type=float, default=None,
                   help=f"face-width slices, integer 1..400 (line-contact outputs, default "
                        f"{LINE_DEFAULTS['slices']})")
    p.add_argument("--plot", default=None, help="write the tornado chart (.png)")
    p.add_argument("--json", action="store_true", help="print JSON instead of the table")
    p.set_defaults(func=run)


def _names(text, flag):
    names = [t.strip() for t in text.split(",") if t.strip()]
    if not names:
        raise ValueError(f"{flag} = {text!r}: give at least one name")
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise ValueError(f"{flag}: {dup[0]!r} is given more than once")
    return names


def _report(args, r, operating, scenario):
    from gearjax.studies.quantities import QUANTITIES

    def num(v):
        return None if not math.isfinite(float(v)) else float(v)

    outs = []
    for i, q in enumerate(r["outputs"]):
        outs.append({"name": q, "unit": QUANTITIES[q].unit, "value": num(r["values"][i]),
                     "params": [{"field": p, "value": float(r["fields"][j]),
                                 "per_unit": num(r["jacobian"][i, j]),
                                 "elasticity": num(r["elasticity"][i, j])}
                                for j, p in enumerate(r["params"])]})
    return {"design": args.design, "side": args.side,
            "scenario": {**operating, **scenario}, "outputs": outs}


def _tornado(rep, path):
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt
    import numpy as np

    from gearjax.io import atomic_write_figure
    from gearjax.plot.style import MIN_WIDTH_IN, report_style

    outs = rep["outputs"]
    with report_style():
        fig, axes = plt.subplots(len(outs), 1, squeeze=False,
                                 figsize=(MIN_WIDTH_IN + 1.0, 1.2 + 0.45 * len(
                                     outs[0]["params"]) * len(outs) + 0.8 * len(outs)))
        for ax, o in zip(axes[:, 0], outs):
            e = np.array([np.nan if p["elasticity"] is None else p["elasticity"]
                          for p in o["params"]])
            order = np.argsort(np.nan_to_num(np.abs(e), nan=-1.0))
            names = [o["params"][k]["field"] for k in order]
            vals = np.nan_to_num(e[order])
            ax.barh(np.arange(len(names)), vals, color=np.where(vals >= 0, "C0", "C3"))
            ax.set_yticks(np.arange(len(names)), names)
            ax.axvline(0.0, color="k", lw=0.8)
            ax.set_xlabel("elasticity (d ln q / d ln x)")
            ax.set_title(f"{o['name']} = {o['value']:.6g} {o['unit']}".strip())
            ax.grid(True, axis="x", lw=0.3, alpha=0.6)
        fig.tight_layout()
    atomic_write_figure(fig, path)


def run(args) -> int:
    import gearjax as gj
    from gearjax.commands import print_json
    from gearjax.commands.designs import parse_misalign
    from gearjax.errors import check_int, check_range
    from gearjax.io import check_output_path
    from gearjax.studies.sensitivity import sensitivities

    outputs, params = _names(args.outputs, "--outputs"), _names(args.params, "--params")
    if args.plot:
        check_output_path(args.plot, "--plot", (".png",))
    kv, _ = parse_misalign(args.misalign)
    scenario = {f"{k}_mm" if k != "dSigma" else "dSigma_deg": float(v) for k, v in kv.items()}
    line = {}
    for flag, key, lo, hi in (("--positions", "positions", 4, 1024),
                              ("--slices", "slices", 1, 400)):
        if getattr(args, key) is not None:
            line[key] = check_int(flag, getattr(args, key), lo=lo, hi=hi)
    if args.f_ma_um is not None:
        scenario["f_ma_um"] = check_range("--f-ma-um", args.f_ma_um,
                                          *gj.involute.MISALIGNMENT_RANGE_UM, unit="um")
    operating = {k: v for k, v in (("torque_Nm", args.torque_Nm), ("pinion_rpm", args.rpm),
                                   ("oil", args.oil), ("sigma_um", args.sigma_um))
                 if v is not None}
    r = sensitivities(args.design, outputs, params, side=args.side, operating=operating,
                      scenario=scenario, line=line)
    rep = _report(args, r, operating, {**scenario, **line})
    if args.plot:
        _tornado(rep, args.plot)
    if args.json:
        print_json(rep)
        return 0
    for o in rep["outputs"]:
        unit = f" {o['unit']}" if o["unit"] else ""
        print(f"{o['name']} = {o['value']:.8g}{unit}")
        print(f"  {'field':44s} {'value':>14s} {'per unit':>14s} {'elasticity':>11s}")
        for p in o["params"]:
            pu = "-" if p["per_unit"] is None else f"{p['per_unit']:.6g}"
            el = "-" if p["elasticity"] is None else f"{p['elasticity']:.4g}"
            print(f"  {p['field']:44s} {p['value']:14.8g} {pu:>14s} {el:>11s}")
    if args.plot:
        print(f"plot: {args.plot}")
    return 0
