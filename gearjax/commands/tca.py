"""``gearjax tca``: unloaded tooth contact analysis (see :mod:`gearjax.tca.path`).

DESIGN is either an involute pair given inline,
``involute:z1=25,z2=41,m=2,alpha=20,b=20[,helix=0,x1=0,x2=0,dalpha=0,crown=0,lead_crown=0]``
(tooth numbers, normal module mm, normal pressure angle deg, face width mm, helix
deg, profile shifts, pinion pressure-angle change deg, pinion profile and lead
crown 1/mm), or a hypoid/spiral-bevel design file (a path or ``example:NAME``;
:mod:`gearjax.gears.hypoid.tca`; drive side = pinion concave on gear convex).

An involute design file with ``[microgeometry]`` tables goes to the unloaded TCA of the
modified flanks by the thin-slice line contact (:mod:`gearjax.commands.line_tca`).
"""

from __future__ import annotations

import argparse
import math
import re
import sys

import numpy as np

from gearjax.commands.designs import involute_design, parse_misalign
from gearjax.commands.line_tca import (LINE_TCA_KEYS_DOC, add_line_options, line_route,
                                       refuse_line_options, run_line_tca)

JSON_KEYS_DOC = """JSON keys:
  input            the design and options as given
  phi1_rad         pinion angles of the grid (rad); the reference (pitch point) in the middle
  te_arcsec        TE of tooth pair 0 (arcsec, > 0: gear ahead), null off the flank
  te_pairs_arcsec  TE of pairs -1, 0, +1 on the same grid (null where not on the flank)
  envelope_arcsec  unloaded TE envelope (max over pairs on the drive side, min on coast)
  ptp_arcsec       peak-to-peak of the sampled envelope over one pitch
  transfer_phi1_rad  pinion angles of the transfers into and out of pair 0
  contact_ratio    on-flank interval of pair 0 / angular pitch (involute line contact:
                   the transverse section z = 0 is solved, so this is eps_alpha)
  overlap_ratio    involute line contact: b tan(beta)/(r1 2 pi/z1) (null otherwise)
  path             {axial1_mm, radial1_mm, axial2_mm, radial2_mm}: contact point on
                   pinion and gear flank in axial projection (body z, radius; for
                   bevel gears z is measured from the crossing point); bevel gears
                   also {xi1, h1_mm, xi2, h2_mm}: face-width position (-1 toe, +1
                   heel) and height above the root cone; null where pair 0 does
                   not touch
  (with --side both the output is {"drive": {...}, "coast": {...}})
  error            only for a side whose TCA failed: the reason and what to try (that
                   side's object is {"error": "..."}; with one side, the key sits next
                   to "input"); the exit status is then 3
  ellipses         {semi_major_mm, semi_minor_mm}: contact ellipse (elastic approach
                   0.00632 mm; null = infinite, line contact, and where pair 0
                   does not touch or touches at an edge)
  flags            per grid point: converged, on_flank (the flanks touch inside both
                   flank boundaries), edge (pair 0 touches at an edge: a face end or a
                   tooth tip, no ellipse and no kinematics there), edge_end (null, or
                   which edge: "pinion toe", "pinion heel", "gear toe", "gear heel",
                   "pinion tip", "gear tip", or a corner "pinion tip/toe corner" ...),
                   off_flank
                   (converged but outside a flank boundary: no contact of pair 0),
                   crossing_flanks (an on_flank point where the flanks cross: relative
                   curvature indefinite, e.g. past a generated flank's edge of regression)
  quality          {converged, reference_on_flank, edge_contact, face_end_contact,
                   tip_contact, low_contact_ratio, large_te, crossing_flanks}:
                   contact-quality flags of the side (each raised one is also a warning on
                   stderr; large_te: TE p-t-p > 60 arcsec; crossing_flanks: pair 0 carries
                   the load at a crossing_flanks point)
  kinematics       with --kinematics: {u1_mm_s, u2_mm_s, u_e_mm_s, u_s_mm_s, srr, r_x_mm,
                   r_y_mm} per grid point (pinion = 1; per rad/s of pinion speed;
                   rolling direction across the contact ellipse; null off the flank)"""


def register(sub):
    p = sub.add_parser(
        "tca", help="tooth contact analysis: TE, path of contact, contact ellipses",
        description="Unloaded tooth contact analysis of an involute pair (optionally with a "
                    "crowned or mismatched pinion) or of a hypoid/spiral-bevel design, "
                    "with misalignments.",
        epilog=JSON_KEYS_DOC + "\n\n" + LINE_TCA_KEYS_DOC,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("design", help="involute:z1=..,z2=..,m=..,alpha=..,b=..[,...], or a "
                                  "design file of any kind (DESIGN.toml or example:NAME)")
    p.add_argument("--side", choices=["drive", "coast", "both"], default="drive")
    p.add_argument("--misalign", default="",
                   help="dE=mm,dP=mm,dG=mm,dSigma=deg (any subset; default all 0)")
    p.add_argument("--positions", type=float, default=None,
                   help="grid positions, 10k+1 (k >= 1): 4k steps per pitch, "
                        "1.25 pitches each side (with --pitches P: P pitches each side, "
                        "8kP+1 positions); default 61.  A design with [microgeometry] "
                        "(line contact): mesh positions per base pitch, integer 4..1024, "
                        "default 32")
    p.add_argument("--pitches", type=float, default=None,
                   help="half-range of the grid in angular pitches (0.75 ... 4, default 1.25; "
                        "an involute pair whose path of contact reaches further from the pitch "
                        "point gets 2, 3 or 4 and 5, 7 or 9 tooth pairs); widen it when the "
                        "contact of one tooth pair spans more than the grid")
    p.add_argument("--kinematics", action="store_true",
                   help="also compute rolling/sliding velocities, SRR and effective radii at "
                        "the contact points (JSON key 'kinematics')")
    add_line_options(p)
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--plot", default=None,
                   help="write the TE and contact-pattern figure (.png); a design with "
                        "[microgeometry]: the modification maps and the unloaded TE over "
                        "the cycle (and loaded TE against torque) (.png, .pdf or .svg)")
    p.set_defaults(func=run)


def _nan_list(a):
    a = np.asarray(a, float)
    return [None if not np.isfinite(x) else float(x) for x in a.ravel()]


def _family_side(design, mis, m, side_name, half, pairs, kin):
    """The TCA of one side of any registered family's design: its adapter picks the
    flanks of the side (``half``, ``pairs`` None: the family's grid); the pinion flank
    outline for the plot comes from the adapter's ``outline`` method when it has one."""
    import gearjax as gj
    res = gj.run_tca(design, mis, side=side_name, steps_per_pitch=m, half_pitches=half,
                     n_pairs=pairs, kinematics=kin)
    outline = getattr(gj.tca.family_of(design), "outline", None)
    return res, (outline(design, side_name) if outline is not None else None)


def _side_json(res):
    from gearjax import ARCSEC
    path, multi = res.path, res.multi
    from gearjax.tca import EDGE_NAMES
    conv = np.asarray(path.converged)
    on = np.asarray(res.on_flank)
    edge = np.asarray(res.edge_points)
    touch = on | edge
    kinds = (np.full(conv.shape, -1) if path.edge_kind is None
             else np.asarray(path.edge_kind))
    te = np.where(touch, np.asarray(path.te), np.nan) / ARCSEC
    # where pair 0 does not touch (off the flanks, not converged) there is no contact
    # point: null, never a number that reads as a position on the flank
    touched = lambda a: _nan_list(np.where(touch, np.asarray(a, float), np.nan))  # noqa: E731
    pth = {k: touched(getattr(path, k[:-3])) for k in
           ("axial1_mm", "radial1_mm", "axial2_mm", "radial2_mm")}
    if "xi1" in res.coords:                   # face-width positions (bevel/hypoid)
        pth.update({k: touched(res.coords[c]) for k, c in
                    (("xi1", "xi1"), ("h1_mm", "h1"), ("xi2", "xi2"), ("h2_mm", "h2"))})
    out = {
        "phi1_rad": _nan_list(path.phi1),
        "te_arcsec": _nan_list(te),
        "te_pairs_arcsec": [_nan_list(r) for r in np.asarray(multi.te_pairs) / ARCSEC],
        "envelope_arcsec": _nan_list(np.asarray(multi.envelope) / ARCSEC),
        "ptp_arcsec": float(multi.ptp) / ARCSEC,
        "transfer_phi1_rad": _nan_list(multi.transfer_phi1),
        "contact_ratio": float(multi.contact_ratio),
        "overlap_ratio": (float(res.coords["overlap_ratio"]) if "overlap_ratio" in res.coords
                          else None),
        "path": pth,
        "ellipses": {"semi_major_mm": touched(path.semi_major),
                     "semi_minor_mm": touched(path.semi_minor)},
        "flags": {"converged": conv.tolist(), "on_flank": on.tolist(),
                  "edge": edge.tolist(), "off_flank": (conv & ~touch).tolist(),
                  "crossing_flanks": (on & np.asarray(res.flanks_cross)).tolist(),
                  "edge_end": [EDGE_NAMES[k] if e else None for k, e in zip(kinds, edge)]},
        "quality": res.flags(),
    }
    if res.kinematics is not None:
        k = res.kinematics
        mask = lambda a: _nan_list(np.where(on, np.asarray(a), np.nan))
        out["kinematics"] = {"u1_mm_s": mask(k.u1), "u2_mm_s": mask(k.u2),
                             "u_e_mm_s": mask(k.u_e), "u_s_mm_s": mask(k.u_s),
                             "srr": mask(k.srr), "r_x_mm": mask(k.r_x), "r_y_mm": mask(k.r_y)}
    return out


def _cell(v, width, digits):
    """A table cell: the number, ``inf`` (a line contact's length), or ``-`` where there
    is no value (no contact of pair 0 there, or no ellipse at an edge contact)."""
    if np.isnan(v):
        return f"{'-':>{width}s}"
    return f"{v:{width}.{digits}f}"


#: exit status when the TCA of a requested side failed (the other side, if any, is printed)
FAILED_SIDE_STATUS = 3


def _failure(side, exc, args) -> str:
    """One actionable line for a failed side: what failed, on which side, what to try.

    The library's own hint about the ``throw`` keyword is dropped: the command has
    no such option."""
    from gearjax import NoContactError

    detail = re.sub(r"\s*;?\s*pass throw=False[^;]*$", "", str(exc)).strip().rstrip(".;")
    tries = []
    if args.misalign.strip():
        tries.append("smaller or fewer --misalign values")
    if args.pitches is None or args.pitches < 2.0:
        tries.append("a wider grid (--pitches 2)")
    if isinstance(exc, NoContactError):
        what = "the flanks do not touch"
        tries.append("check the design (flank sides, hands, mounting data)")
    else:
        what = "the contact solve did not converge"
        tries += ["a finer grid (more --positions)", "check the design"]
    return f"{side} side: {what} ({detail}); try {', '.join(tries)}"


def run(args) -> int:
    from gearjax import ConvergenceError
    from gearjax.commands import print_json
    from gearjax.errors import check_int, check_range
    from gearjax.io import check_output_path
    from gearjax.progress import Progress

    from gearjax import load_design
    if line_route(args.design):
        # an involute design file with [microgeometry]: the line contact's TCA
        return run_line_tca(args)
    refuse_line_options(args)
    mis_kv, mis = parse_misalign(args.misalign)
    if args.positions is None:
        args.positions = 61
    n = check_int("positions", args.positions, lo=11, hi=1001)
    if (n - 1) % 10:
        raise ValueError(f"positions = {n} must be of the form 10k+1 (11, 21, ..., 61, ...)")
    m = 4 * ((n - 1) // 10)
    if args.pitches is not None:
        check_range("pitches", args.pitches, 0.75, 4.0)
    if args.plot:
        check_output_path(args.plot, "--plot", (".png",))
    sides = ["drive", "coast"] if args.side == "both" else [args.side]
    from gearjax.tca import family_of
    # validated before any tracing
    design = (involute_design(args.design)[1] if args.design.startswith("involute:")
              else load_design(args.design))
    # default: 1.25 pitches and 3 tooth pairs; a family that picks the grid for the
    # design (involute: wider for a path of contact that reaches further) gets its
    # default grid and pairs
    own = family_of(design).grid_from_design
    half = (None if own and args.pitches is None
            else 1.25 if args.pitches is None else float(args.pitches))
    pairs = None if own else 3
    solve = lambda side: _family_side(design, mis, m, side, half, pairs,  # noqa: E731
                                      args.kinematics)
    results, failed = {}, {}
    what = "contact solve" + (" + kinematics" if args.kinematics else "")
    with Progress(len(sides), "tca") as bar:    # stderr, terminals only
        for side in sides:
            try:
                with bar.phase(f"{side} side: {what}"):
                    results[side] = solve(side)
            except ConvergenceError as exc:      # NoContactError is a ConvergenceError
                failed[side] = _failure(side, exc, args)
            bar.update()
    for side, msg in failed.items():
        sys.stderr.write(f"gearjax: error: {msg}\n")
    status = FAILED_SIDE_STATUS if failed else 0
    if not results and not args.json:
        return status
    if args.plot and results:
        from gearjax.plot.tca import save_tca_plot
        save_tca_plot(args.plot, [(sd, r[0].path, r[0].margin, r[0].multi)
                                  for sd, r in results.items()],
                      [r[1] for r in results.values()], title=f"TCA {args.design}")
    for sd, (res, _) in results.items():
        for w in res.warnings():
            sys.stderr.write(f"gearjax: warning: {sd} side: {w}\n")
    outs = {sd: _side_json(r[0]) for sd, r in results.items()}
    if half is None and results:           # the family's default grid: report what ran
        n_grid = len(next(iter(results.values()))[0].path.phi1)
        half = (n_grid - 1) / (2 * m)
        n = n_grid
    inp = {"design": args.design, "side": args.side, "misalign": mis_kv, "positions": n,
           "pitches": half}
    if args.json:
        if len(sides) == 1:
            print_json({"input": inp, **(outs.get(sides[0]) or {"error": failed[sides[0]]})})
        else:
            print_json({"input": inp, **{sd: outs.get(sd) or {"error": failed[sd]}
                                         for sd in sides}})
        return status
    for sd, (res, _) in results.items():
        path = res.path
        out = outs[sd]
        conv = np.asarray(out["flags"]["converged"])
        on = np.asarray(out["flags"]["on_flank"])
        edge = np.asarray(out["flags"]["edge"])
        cross = np.asarray(out["flags"]["crossing_flanks"])
        te = np.array([np.nan if v is None else v for v in out["te_arcsec"]])
        touch = on | edge
        sm = np.where(touch, np.asarray(path.semi_major), np.nan)
        sn = np.where(touch, np.asarray(path.semi_minor), np.nan)
        ax = np.where(touch, np.asarray(path.axial1), np.nan)
        rad = np.where(touch, np.asarray(path.radial1), np.nan)
        print(f"# TCA {args.design} ({sd}); misalign {mis_kv or 'none'}")
        print(f"# TE p-t-p {out['ptp_arcsec']:.4f} arcsec, contact ratio {out['contact_ratio']:.4f}")
        print(f"{'phi1[deg]':>10s} {'TE[arcsec]':>11s} {'axial1':>9s} {'radius1':>9s} "
              f"{'2a[mm]':>8s} {'2b[mm]':>8s} flag")
        phi1 = np.asarray(path.phi1)
        for i in range(len(phi1)):
            flag = ("cross" if cross[i] else "ok" if on[i] else "edge" if edge[i]
                    else "off" if conv[i] else "no-conv")
            print(f"{math.degrees(float(phi1[i])):10.4f} {_cell(te[i], 11, 5)} "
                  f"{_cell(ax[i], 9, 4)} {_cell(rad[i], 9, 4)} "
                  f"{_cell(2 * sm[i], 8, 4)} {_cell(2 * sn[i], 8, 4)} {flag}")
    for sd, msg in failed.items():
        print(f"# TCA {args.design} ({sd}): FAILED, no result: {msg}")
    return status
