"""``gearjax blank DESIGN``: blank data of a hypoid / spiral-bevel design.

DESIGN is a path or ``example:NAME``; its ``[blank]`` table goes verbatim to
:meth:`gearjax.gears.hypoid.blank.BlankInput.from_dict` and
:func:`~gearjax.gears.hypoid.blank.blank_geometry` computes the blank.  The table is
followed by the documented defaults the design relies on (keys left out of the
file, :meth:`gearjax.hypoid.HypoidDesign.defaults_applied`); ``--json`` prints
the blank data only."""

from __future__ import annotations

import math
import sys

from gearjax.commands import print_json, warn_nonfinite


def register(sub):
    p = sub.add_parser("blank", help="blank data (cones, depths) of a hypoid/bevel design",
                       description="Blank geometry from the [blank] table of a design file.")
    p.add_argument("design", help="design file path or example:NAME")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=run)


def run(args) -> int:
    from gearjax.hypoid import blank_geometry
    from gearjax import load_design
    from gearjax.progress import Progress
    from gearjax.hypoid import KINDS as HYPOID_KINDS
    design = load_design(args.design, kinds=HYPOID_KINDS)
    with Progress(1, "blank") as bar, bar.phase("blank solve"):
        data = blank_geometry(design.blank_input())
    if args.json:
        print_json(data.to_dict(), indent=2)     # strict JSON: a NaN is null + a warning
        return 0
    rows = data.to_table()
    w = max(len(r[0]) for r in rows)
    sys.stdout.write(f"blank of {design.name or args.design}\n")
    bad = []
    for name, value, unit in rows:
        if math.isfinite(value):
            sys.stdout.write(f"  {name:<{w}s}  {value:14.6f}  {unit}\n")
        else:
            bad.append(name)
            sys.stdout.write(f"  {name:<{w}s}  {'none':>14s}  {unit}   (no solution)\n")
    warn_nonfinite(bad)
    lines = design.defaults_lines()
    sys.stdout.write("defaults applied (keys not in the design file):" + ("" if lines else " none")
                     + "\n")
    for ln in lines:
        sys.stdout.write(f"  {ln}\n")
    return 0
