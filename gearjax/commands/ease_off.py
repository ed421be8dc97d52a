"""``gearjax ease-off DESIGN --out NEW.toml``: pinion settings for a target ease-off, and
the TCA of the result (hypoid / spiral bevel: machine settings,
:mod:`gearjax.gears.hypoid.ease_off`; VH-CATT: the pinion's cutter radius, blade offset
and blade angle, :mod:`gearjax.gears.vh_catt.ease_off`; docs/correct.md "Target
ease-off").  One code path: the design's ``ease_off_family()`` (the registry of
:func:`gearjax.correction.ease_off_family`) gives the family's functions.

The ease-off is the difference topography between the pinion flank of a side and the
pinion conjugate to the gear (um, positive = relief), on the pinion's reference grid
(face width ``u`` -1 .. +1 in the grid's ``xi`` order -- toe to heel for a bevel pinion,
-z to +z for a VH-CATT pinion -- by height ``w`` root -1 .. tip +1).  The target is
``e*(u, w) = C_L u^2 + C_P w^2 + B u w`` (``--crowning-um``, ``--profile-um``,
``--bias-um``) or a grid read from ``--target`` (CSV, ``N_XI`` rows along the face of
``N_S`` values root -> tip, um; ``#`` comment lines).  The pinion settings are fitted by
Levenberg-Marquardt with exact Jacobians (the fit of ``gearjax correct`` with the target
as ``-deviation``); the design with the changes is written; its ease-off is then
evaluated anew from the written file (a new conjugate alignment: an independent check
of the fit), and the unloaded TCA of both designs is run on the side (unless
``--no-tca``).  Exit status 0; 2 for bad input (one line, before any work); 3 when the
fit did not converge (no design written) or the TCA of the written design failed (the
design is written; the report says why)."""

from __future__ import annotations

import math
import sys

import numpy as np

EPILOG = """\
JSON report keys (--json):
  design, side, pinion_flank   the design's name, the side, the pinion flank fitted
  grid, face_margin, height_margin  [n_xi, n_s] and the grid's margins (fractions)
  target                       {crowning_um, profile_um, bias_um} or {file}
  lines_used, lines            grid lines that meet the pinion flank (used) / all
  ease_off_design_um           [n_xi][n_s] ease-off of the given design (null: line
                               left out)
  target_um                    [n_xi][n_s] the target
  ease_off_fitted_um           [n_xi][n_s] the fitted ease-off (target + residual)
  ease_off_written_um          [n_xi][n_s] ease-off of the written design, evaluated
                               anew from the file (null without a written design)
  fit_rms_um, fit_max_um       residual of the fit, target - fitted (um)
  written_vs_target_rms_um     rms of (written - target), both taken relative to their
                               value at the grid's middle point (a rotation is not
                               ease-off)
  unknowns, units              fitted settings ('axis_rotation': the conjugate's
                               rotation, not written) and their units
  change                       setting -> change written to the design (+delta)
  uncertainty                  unknown -> one standard deviation of the change
  condition_number             sigma_max / sigma_min of the scaled Jacobian
  indistinguishable            [{combination, relative_singular_value, coefficients}]
  converged, status, message   the fit's convergence test, status code and its text
  iterations, evaluations      accepted steps; residual and Jacobian evaluations
  seconds                      wall time: {fit, check, tca} (first runs compile)
  tca                          {design, written}: each null with --no-tca, else
                               {ptp_arcsec, contact_ratio, xi1_range, h1_range_mm
                               (null for a family without them: VH-CATT),
                               axial1_range_mm (the contact's axial position on the
                               pinion), on_flank_points, points, quality, warnings}
                               or {error} when the TCA failed
  written_design               the design file written (null when not converged)
  files                        every file written (--out, --plot)
VH-CATT: the fitted pinion fields are cutter_radius (mm, [pair] cutter_radius1_mm),
blade_offset (mm, [pinion] blade_offset_mm) and blade_angle (deg, the side's pinion flank:
[pinion] concave_blade_angle_deg on the drive side, convex_ on the coast side); the
conjugate pinion is the pinion cut with the gear flank's trace radius and blade angle.
With straight blades the cutter radius and the blade offset act alike on one flank
(lengthwise crowning only: reported as indistinguishable), and profile crowning and bias
are not reachable: they stay in the fit residual (docs/correct.md)."""


def register(sub):
    import argparse
    p = sub.add_parser(
        "ease-off", help="pinion settings for a target ease-off, and their TCA",
        description="Fit the pinion machine settings of a hypoid / spiral-bevel design (or "
                    "the pinion's cutter radius and blade settings of a VH-CATT design) to "
                    "a target ease-off (difference topography between the pinion flank and "
                    "the pinion conjugate to the gear: lengthwise crowning, profile "
                    "crowning, bias, or a grid), write the design with the changes, and "
                    "show the unloaded TCA before and after.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("design", help="design file path or example:NAME (hypoid / spiral bevel "
                                  "with a generated pinion, or VH-CATT)")
    p.add_argument("--out", required=True, help="the design with the fitted settings (.toml)")
    p.add_argument("--side", choices=("drive", "coast"), default="drive",
                   help="the side whose pinion flank is fitted (default drive)")
    p.add_argument("--crowning-um", type=float, default=0.0,
                   help="lengthwise crowning C_L at the grid's toe and heel, um in "
                        "[-200, 200] (default 0)")
    p.add_argument("--profile-um", type=float, default=0.0,
                   help="profile crowning C_P at the grid's root and tip, um in [-200, 200] "
                        "(default 0)")
    p.add_argument("--bias-um", type=float, default=0.0,
                   help="bias B at the grid's corners (+ toe-root / heel-tip relieved), um "
                        "in [-200, 200] (default 0)")
    p.add_argument("--target", default=None,
                   help="target grid CSV instead of the three terms: N_XI rows (toe -> "
                        "heel; VH-CATT -z -> +z) of N_S values (root -> tip), um, |value| <= 1000")
    p.add_argument("--grid", default="9x5",
                   help="N_XIxN_S points of the reference grid, each 3..41 (default 9x5)")
    p.add_argument("--settings", default=None,
                   help="comma-separated pinion settings to fit (default point_radius, "
                        "blade_angle,ratio_of_roll,modified_roll_2c,modified_roll_6d,"
                        "axis_rotation; any setting `gearjax correct --settings` takes; "
                        "VH-CATT: cutter_radius,blade_offset,blade_angle,axis_rotation)")
    p.add_argument("--regularisation", type=float, default=0.003,
                   help="Tikhonov alpha in [0, 1] (default 0.003)")
    p.add_argument("--max-iter", type=int, default=50,
                   help="Levenberg-Marquardt steps at most, 1..200 (default 50)")
    p.add_argument("--no-tca", action="store_true",
                   help="skip the TCA of the given and the written design")
    p.add_argument("--json", action="store_true",
                   help="print the report as JSON instead of the table (keys below)")
    p.add_argument("--plot", default=None,
                   help="also save the ease-off maps (design, target, written; .png, .pdf, "
                        ".svg)")
    p.set_defaults(func=run)


#: largest |term| of the quadratic target (um) and |value| of a target grid (um)
TERM_LIMIT_UM = 200.0
GRID_LIMIT_UM = 1000.0
FACE_MARGIN, HEIGHT_MARGIN = 0.1, 0.25


def parse_grid(text: str) -> tuple[int, int]:
    """``N_XIxN_S`` with each in 3..41 (``ValueError`` naming ``--grid``)."""
    parts = str(text).lower().split("x")
    try:
        n = tuple(int(v) for v in parts)
    except ValueError:
        n = ()
    if len(n) != 2 or not all(3 <= v <= 41 for v in n):
        raise ValueError(f"--grid = {text!r} must be N_XIxN_S with each in 3..41 (e.g. 9x5)")
    return n


def read_target(path, grid) -> np.ndarray:
    """The target grid (um) of ``path`` (module docstring), checked against ``grid``."""
    from pathlib import Path
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"--target = {str(path)!r} cannot be read ({exc})") from None
    rows = []
    for k, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        try:
            rows.append([float(v) for v in s.split(",")])
        except ValueError:
            raise ValueError(f"--target = {str(path)!r} line {k}: {s[:40]!r} is not a row of "
                             f"comma-separated numbers (um)") from None
    shape = (len(rows), len(rows[0]) if rows else 0)
    if any(len(r) != shape[1] for r in rows) or shape != tuple(grid):
        raise ValueError(f"--target = {str(path)!r} must hold {grid[0]} rows of {grid[1]} "
                         f"values (--grid {grid[0]}x{grid[1]}); it has "
                         f"{[len(r) for r in rows] or 0}")
    a = np.asarray(rows, float)
    bad = ~np.isfinite(a) | (np.abs(a) > GRID_LIMIT_UM)
    if bad.any():
        i, j = (int(v) for v in np.argwhere(bad)[0])
        raise ValueError(f"--target = {str(path)!r}: value {a[i, j]:g} um at row {i}, column "
                         f"{j} must be finite and within [-{GRID_LIMIT_UM:g}, "
                         f"{GRID_LIMIT_UM:g}] um")
    return a


def _centred(e):
    """``e`` less its value at the grid's middle point (a rigid rotation is not ease-off)."""
    i, j = e.shape[0] // 2, e.shape[1] // 2
    return e - e[i, j]


def tca_summary(design, side) -> dict:
    """TE p-t-p, contact ratio, bearing extent and quality flags of the unloaded TCA."""
    import time

    import gearjax
    from gearjax import ARCSEC
    from gearjax.errors import ConvergenceError
    t0 = time.perf_counter()
    try:
        r = gearjax.run_tca(design, side=side, kinematics=False)
    except ConvergenceError as exc:
        return {"error": str(exc), "seconds": time.perf_counter() - t0}
    on = np.asarray(r.on_flank)

    def extent(a):
        a = np.asarray(a)[on]
        return [float(a.min()), float(a.max())] if a.size else None
    # the bearing on the pinion: the family's flank coordinates where it has them
    # (hypoid xi1, h1), and in every family the axial position of the contact (mm)
    return {"ptp_arcsec": float(np.asarray(r.multi.ptp)) / ARCSEC,
            "contact_ratio": float(np.asarray(r.multi.contact_ratio)),
            "xi1_range": extent(r.coords["xi1"]) if "xi1" in r.coords else None,
            "h1_range_mm": extent(r.coords["h1"]) if "h1" in r.coords else None,
            "axial1_range_mm": extent(r.path.axial1),
            "on_flank_points": int(on.sum()), "points": int(on.size),
            "quality": r.flags(), "warnings": r.warnings(),
            "seconds": time.perf_counter() - t0}


def run(args) -> int:
    import time

    from gearjax import load_design
    from gearjax.commands.correct import settings_list, warn_indistinguishable
    from gearjax.errors import check_int, check_range
    from gearjax.io import check_output_path
    from gearjax.progress import Progress

    names = settings_list(args.settings)
    terms = {k: check_range(f"--{k.replace('_um', '')}-um", getattr(args, k), -TERM_LIMIT_UM,
                            TERM_LIMIT_UM, unit="um")
             for k in ("crowning_um", "profile_um", "bias_um")}
    if args.target is not None and any(v != 0.0 for v in terms.values()):
        raise ValueError("--target replaces --crowning-um, --profile-um and --bias-um: give "
                         "either the file or the terms")
    grid = parse_grid(args.grid)
    alpha = check_range("--regularisation", args.regularisation, 0.0, 1.0)
    max_iter = check_int("--max-iter", args.max_iter, 1, 200)
    outs = {"--out": check_output_path(args.out, "--out", (".toml",))}
    if args.plot is not None:
        outs["--plot"] = check_output_path(args.plot, "--plot", (".png", ".pdf", ".svg"))
    if args.target is not None:
        target = read_target(args.target, grid)
        spec = {"file": str(args.target)}
    design = load_design(args.design)
    if not hasattr(design, "ease_off_family"):
        raise ValueError(f"{args.design!r}: the target ease-off is defined for hypoid, "
                         f"spiral-bevel and VH-CATT designs only, not for [design] kind = "
                         f"{design.data['design']['kind']!r}")
    eo = design.ease_off_family()       # the family's module: one code path below
    if args.target is None:
        target = eo.target_ease_off(*grid, terms["crowning_um"], terms["profile_um"],
                                    terms["bias_um"])
        spec = dict(terms)
    kw = dict(settings=names, grid=grid, face_margin=FACE_MARGIN, height_margin=HEIGHT_MARGIN)
    sec = {}
    with Progress(4, "ease-off") as bar:
        with bar.phase("conjugate pinion and fit"):
            t0 = time.perf_counter()
            problem = eo.ease_off_problem(design, args.side, target, **kw)
            e_design = eo.ease_off(problem)
            res = eo.fit_ease_off(problem, regularisation=alpha, max_iter=max_iter)
            sec["fit"] = time.perf_counter() - t0
        bar.update()
        written = None
        e_written = np.full(grid, np.nan)
        if res.converged:
            with bar.phase("written design checked"):
                from gearjax.io import atomic_write, dumps_toml
                t0 = time.perf_counter()
                new = eo.ease_off_design(res, description=(
                    f"{design.data['design'].get('description', design.name)}; {args.side} "
                    f"pinion fitted to a target ease-off by gearjax ease-off"))
                atomic_write(outs["--out"], dumps_toml(new.data))
                written = load_design(str(outs["--out"]))
                e_written = eo.ease_off(eo.ease_off_problem(written, args.side, target, **kw))
                sec["check"] = time.perf_counter() - t0
        bar.update()
        tca = {"design": None, "written": None}
        if not args.no_tca:
            t0 = time.perf_counter()
            with bar.phase(f"TCA of {design.name}"):
                tca["design"] = tca_summary(design, args.side)
            bar.update()
            if written is not None:
                with bar.phase("TCA of the written design"):
                    tca["written"] = tca_summary(written, args.side)
            sec["tca"] = time.perf_counter() - t0
        bar.update()
    mask = problem.mask[0]
    e_design = np.where(mask, e_design, np.nan)
    fitted = target + res.after_um[0]
    diff = (_centred(e_written) - _centred(target))[mask]

    def grid_list(a):             # null for a line left out: documented, not a failure
        return [[float(v) if ok and math.isfinite(v) else None for v, ok in zip(r, m)]
                for r, m in zip(np.asarray(a, float), mask)]
    rep = {
        "design": design.name, "side": args.side, "pinion_flank": problem.flanks[0],
        "grid": list(grid), "face_margin": FACE_MARGIN, "height_margin": HEIGHT_MARGIN,
        "target": spec, "lines_used": int(mask.sum()), "lines": int(mask.size),
        "ease_off_design_um": grid_list(e_design), "target_um": target.tolist(),
        "ease_off_fitted_um": grid_list(fitted), "ease_off_written_um": grid_list(e_written),
        "fit_rms_um": float(np.sqrt(np.nanmean(res.after_um ** 2))),
        "fit_max_um": float(np.nanmax(np.abs(res.after_um))),
        "written_vs_target_rms_um": (float(np.sqrt(np.mean(diff ** 2))) if written is not None
                                     else None),
        "unknowns": list(res.unknowns), "units": res.units, "change": res.correction,
        "uncertainty": res.uncertainty, "condition_number": res.condition_number,
        "indistinguishable": [{"combination": t, "relative_singular_value": s,
                               "coefficients": c} for t, s, c in res.indistinguishable],
        "converged": res.converged, "status": res.status, "message": res.message,
        "iterations": res.iterations, "evaluations": res.evaluations, "seconds": sec,
        "tca": tca, "written_design": str(outs["--out"]) if written is not None else None,
    }
    files = [rep["written_design"]] if written is not None else []
    if args.plot is not None:
        from gearjax.io.measured_grid import grid_heights
        from gearjax.plot.correction import save_map_panels
        xi = problem.reference[problem.flanks[0]].xi
        panels = [("design", e_design), ("target", target)]
        if written is not None:
            panels.append(("written design", np.where(mask, e_written, np.nan)))
        save_map_panels(outs["--plot"], [(problem.flanks[0], panels)], xi,
                        grid_heights(grid[1], HEIGHT_MARGIN), "ease-off (um, + = relief)",
                        title=f"{design.name}: {args.side} pinion ease-off")
        files.append(str(outs["--plot"]))
    rep["files"] = files
    if args.json:
        from gearjax.commands import print_json
        print_json(rep)
    else:
        sys.stdout.write(table(rep) + "\n")
        sys.stdout.write(f"files: {', '.join(files) if files else 'none'}\n")
    warn_indistinguishable(rep)
    for which, t in tca.items():
        for w in (t or {}).get("warnings", []):
            sys.stderr.write(f"gearjax: warning: TCA of the "
                             f"{'given' if which == 'design' else 'written'} design: {w}\n")
    if not res.converged:
        sys.stderr.write(f"gearjax: error: the ease-off fit did not converge ({res.message}) "
                         f"after {res.iterations} steps; no design written\n")
        return 3
    if tca["written"] is not None and "error" in tca["written"]:
        sys.stderr.write(f"gearjax: error: the TCA of the written design failed "
                         f"({tca['written']['error']}); the target is not reachable as a "
                         f"working pair with these settings\n")
        return 3
    return 0


def _grid_lines(a, digits=1) -> list[str]:
    """Rows tip (top) to root, columns toe to heel; ``--`` for a line left out."""
    a = np.asarray(a, float).T[::-1]
    return ["  ".join(f"{v:6.{digits}f}" if math.isfinite(v) else f"{'--':>6}" for v in row)
            for row in a]


def table(rep: dict) -> str:
    """The printed report."""
    t = rep["target"]
    what = (f"file {t['file']}" if "file" in t else
            f"crowning {t['crowning_um']:g}, profile {t['profile_um']:g}, bias "
            f"{t['bias_um']:g} um")
    L = [f"{rep['design']}: {rep['side']} side, pinion {rep['pinion_flank']} flank, grid "
         f"{rep['grid'][0]}x{rep['grid'][1]} ({rep['lines_used']} of {rep['lines']} lines "
         f"used); target {what}",
         "ease-off (um, + = relief; rows tip to root, columns toe to heel):"]
    maps = [("design", rep["ease_off_design_um"]), ("target", rep["target_um"])]
    if rep["written_design"] is not None:
        maps.append(("written design", rep["ease_off_written_um"]))
    for name, a in maps:
        L.append(f"  {name}:")
        L += ["    " + s for s in _grid_lines(a)]
    wv = rep["written_vs_target_rms_um"]
    L.append(f"fit residual rms {rep['fit_rms_um']:.3f} um (max {rep['fit_max_um']:.3f}); "
             f"written design against the target: "
             + (f"{wv:.3f} um rms" if wv is not None else "no design written"))
    L.append(f"{'setting':<28}{'change':>14}{'+- 1 sigma':>13}  unit")
    for n in rep["unknowns"]:
        c = rep["change"].get(n)
        c = f"{c:>14.6g}" if c is not None else f"{'(not written)':>14}"
        L.append(f"{n:<28}{c}{rep['uncertainty'][n]:>13.3g}  {rep['units'][n]}")
    ind = rep["indistinguishable"]
    L.append(f"condition number {rep['condition_number']:.4g}; settings that cannot be told "
             "apart: " + ("none" if not ind else "; ".join(
                 f"{c['combination']} (s = {c['relative_singular_value']:.2g})" for c in ind)))
    L.append(f"fit: {rep['message']} after {rep['iterations']} steps ({rep['evaluations']} "
             f"evaluations), {rep['seconds']['fit']:.2f} s")
    for which in ("design", "written"):
        c = rep["tca"][which]
        if c is None:
            continue
        head = f"TCA of the {'given' if which == 'design' else 'written'} design: "
        if "error" in c:
            L.append(head + f"failed ({c['error']})")
            continue
        xr, zr = c["xi1_range"], c["axial1_range_mm"]
        bearing = (f"xi {xr[0]:+.2f}..{xr[1]:+.2f}" if xr else
                   f"z {zr[0]:+.2f}..{zr[1]:+.2f} mm" if zr else "none")
        L.append(head + f"TE p-t-p {c['ptp_arcsec']:.2f} arcsec, contact ratio "
                 f"{c['contact_ratio']:.3f}, bearing {bearing}"
                 + f" ({c['on_flank_points']} of {c['points']} positions on the flank)")
    return "\n".join(L)
