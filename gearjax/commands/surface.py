"""``gearjax surface DESIGN``: a flank grid of a member of any family with a surface
export (hypoid / spiral bevel, preset-TE bevel, VH-CATT), written to CSV, XYZ (points and
normals) or STL (the hypoid grid by the algorithm of [HFT-hypoid], docs/references.md;
see :mod:`gearjax.gears.hypoid.flank`).

Every exported point is a converged solve: a grid with any point whose solve did not
converge (or whose point or normal is not finite) is refused in every format, CSV, XYZ
and STL, with one ``gearjax: error:`` line naming the flank, the number of such points
and the largest residual, status 3, and nothing is written
(:func:`gearjax.io.check_grid_converged`; an existing file is left unchanged).

``--reference-grid`` writes the measuring grid of a hypoid / spiral-bevel or VH-CATT member
instead:
the nominal points and normals (both flanks unless ``--flank`` is given) inside a border
(``--face-margin``, ``--height-margin``), as the measured-grid CSV that ``gearjax correct``
reads back with the deviations filled in (docs/correct.md)."""

from __future__ import annotations

import re
import sys


def _grid(text: str):
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not m:
        raise ValueError(f"--grid = {text!r} must look like 41x21 (face-width x height points)")
    n_xi, n_s = int(m.group(1)), int(m.group(2))
    for name, v in (("--grid face-width points", n_xi), ("--grid height points", n_s)):
        if not 2 <= v <= 2001:
            raise ValueError(f"{name} = {v} is outside the allowed range [2, 2001]")
    return n_xi, n_s


def register(sub):
    p = sub.add_parser("surface", help="flank point grid of a hypoid/bevel member",
                       description="Tooth-flank grid (toe to heel x fillet start to tip) by "
                                   "the generation of the flank by its machine settings (meshing equation with the "
                                   "face-width and face-cone conditions); every point is a converged solve.")
    p.add_argument("design", help="design file path or example:NAME")
    p.add_argument("--member", choices=["pinion", "gear"], required=True)
    p.add_argument("--flank", choices=["convex", "concave"], default=None,
                   help="the flank (required, except with --reference-grid, where the "
                        "default is both flanks)")
    p.add_argument("--grid", default=None,
                   help="face-width x height points (default 41x21; 9x5 with --reference-grid)")
    p.add_argument("--out", required=True, help="output file: .csv, .xyz or .stl "
                                                "(.csv with --reference-grid)")
    p.add_argument("--reference-grid", action="store_true",
                   help="write the measuring grid instead (hypoid / spiral bevel, VH-CATT): "
                        "nominal "
                        "points and normals to measure at, inside the margins, in the "
                        "measured-grid CSV format of `gearjax correct` (docs/correct.md)")
    p.add_argument("--face-margin", type=float, default=None,
                   help="with --reference-grid: border at the toe and at the heel as a "
                        "fraction of the face width, in [0, 0.4] (default 0.1)")
    p.add_argument("--height-margin", type=float, default=None,
                   help="with --reference-grid: border at the root and at the tip as a "
                        "fraction of the active blade length, in [0, 0.4] (default 0.1)")
    p.add_argument("--tooth", action="store_true",
                   help="with .stl: write the whole tooth (both flanks, top land, root)")
    p.add_argument("--plot", default=None,
                   help="also save the axial-plane figure of the flank (.png, .pdf, .svg)")
    p.set_defaults(func=run)


def run(args) -> int:
    from gearjax import load_design
    from gearjax.io import check_output_path, write_flank, write_stl_tooth
    from gearjax.progress import Progress
    if args.reference_grid:
        return _reference_grid(args)
    for flag, v in (("--face-margin", args.face_margin), ("--height-margin", args.height_margin)):
        if v is not None:
            raise ValueError(f"{flag} applies only with --reference-grid")
    if args.flank is None:
        raise ValueError("--flank is required (convex or concave) unless --reference-grid "
                         "is given")
    n_xi, n_s = _grid("41x21" if args.grid is None else args.grid)
    out = check_output_path(args.out, "--out", (".csv", ".xyz", ".stl"))
    if args.tooth and out.suffix.lower() != ".stl":
        raise ValueError("--tooth needs an .stl output file")
    if args.plot is not None:
        plot = check_output_path(args.plot, "--plot", (".png", ".pdf", ".svg"))
        if plot.resolve() == out.resolve():
            raise ValueError(f"--plot = {args.plot!r} is the same file as --out")
    design = load_design(args.design)
    # the axial-plane figure needs the member's blank (cone distances, cone angles)
    if args.plot is not None and not hasattr(design, "member_blank"):
        raise ValueError(f"--plot: the axial-plane figure is drawn for hypoid and spiral-bevel "
                         f"designs only, not for [design] kind = {design.data['design']['kind']!r}")
    from gearjax.io import check_grid_converged
    flanks = ["convex", "concave"] if args.tooth else [args.flank]
    grids = {}
    with Progress(len(flanks), f"surface {args.member}") as bar:
        for f in flanks:
            with bar.phase(f"{f}: {n_xi}x{n_s} points"):
                grids[f] = design.surface_grid(args.member, f, n_xi, n_s)
            bar.update()
    for f, g in grids.items():      # before any file is written (plot included)
        check_grid_converged(g, f"{design.name} {args.member} {f} flank")
    if args.tooth:
        teeth = int(design.teeth(args.member))
        write_stl_tooth(out, grids["convex"], grids["concave"], teeth,
                        name=f"{design.name}_{args.member}_tooth")
    else:
        write_flank(out, grids[args.flank], name=f"{design.name}_{args.member}_{args.flank}")
    g = grids[args.flank]
    if args.plot is not None:
        from gearjax.plot.flank import save_flank_plot
        save_flank_plot(args.plot, g, design.member_blank(args.member),
                        title=f"{design.name}: {args.member} {args.flank} flank (axial plane)",
                        label=f"{args.member} {args.flank}")
    import numpy as np
    sys.stdout.write(f"{args.member} {'tooth' if args.tooth else args.flank + ' flank'}: "
                     f"{n_xi}x{n_s} points, max residual {float(np.max(g.residual)):.2e} mm, "
                     f"written to {out}\n")
    return 0


#: default measuring grid (face-width x profile points) and margins of --reference-grid
REFERENCE_GRID = "9x5"
REFERENCE_MARGIN = 0.1


def _reference_grid(args) -> int:
    """``--reference-grid``: the nominal points and normals to measure at (the
    measured-grid CSV of :mod:`gearjax.io.measured_grid`, deviations left empty)."""
    from gearjax import load_design
    from gearjax.errors import check_range
    from gearjax.io import check_grid_converged, check_output_path, write_reference_grid
    if args.tooth or args.plot is not None:
        raise ValueError(f"{'--tooth' if args.tooth else '--plot'} does not apply with "
                         f"--reference-grid")
    n_xi, n_s = _grid(REFERENCE_GRID if args.grid is None else args.grid)
    if n_xi > 101 or n_s > 101:
        raise ValueError(f"--grid = {args.grid!r}: a measuring grid has at most 101 x 101 "
                         f"points")
    fm = check_range("--face-margin", REFERENCE_MARGIN if args.face_margin is None
                     else args.face_margin, 0.0, 0.4)
    hm = check_range("--height-margin", REFERENCE_MARGIN if args.height_margin is None
                     else args.height_margin, 0.0, 0.4)
    out = check_output_path(args.out, "--out", (".csv",))
    design = load_design(args.design)
    if not hasattr(design, "reference_grid"):
        raise ValueError(f"--reference-grid: measuring grids are defined for hypoid, "
                         f"spiral-bevel and VH-CATT designs only, not for [design] kind = "
                         f"{design.data['design']['kind']!r}")
    flanks = [args.flank] if args.flank else [f for m, f in design.flanks()
                                              if m == args.member]
    if not flanks:
        raise ValueError(f"--member = {args.member!r}: the design has no {args.member} flanks")
    grids = {f: design.reference_grid(args.member, f, n_xi, n_s, fm, hm) for f in flanks}
    for f, g in grids.items():
        check_grid_converged(g, f"{design.name} {args.member} {f} flank")
    write_reference_grid(out, design=design.name, member=args.member, grids=grids,
                         face_margin=fm, height_margin=hm,
                         frame=getattr(design, "reference_frame", None))
    sys.stdout.write(f"{args.member} reference grid ({', '.join(flanks)}): {n_xi}x{n_s} points "
                     f"per flank, margins {fm:g} of the face width and {hm:g} of the blade, "
                     f"written to {out}\n")
    return 0
