"""``gearjax correct DESIGN --measured FILE``: corrective machine settings from a measured
flank (hypoid / spiral bevel: :mod:`gearjax.gears.hypoid.flank_correction`; VH-CATT:
cutter radius and blade settings, :mod:`gearjax.gears.vh_catt.flank_correction`; the fit
of both: :mod:`gearjax.correction`; docs/correct.md).  The design object supplies
``correction_problem`` and ``corrected_design``: the command does not branch on the
family.

Reads the measured grid (:mod:`gearjax.io.measured_grid`: the nominal points and
normals that ``gearjax surface --reference-grid`` wrote, with the measured normal
deviations in um), checks it against the design's reference grid, fits the errors of the
chosen settings by Levenberg-Marquardt with exact Jacobians, prints the before/after
deviations, the fitted errors and corrections, the condition number and the settings
that cannot be told apart (or, with ``--json``, the report as JSON), and writes the
corrected design (``--out``) and the deviation maps (``--plot``).  Exit status 0; 2 for
bad input (one line, before any work); 3 when the fit did not converge (the report says
``converged: false``; no design is written)."""

from __future__ import annotations

import sys

EPILOG = """\
JSON report keys (--json):
  design, member, measured     the design's name, the member, the measured-grid file
  flanks, grid, points         measured flanks, [n_xi, n_s], grid points in all
  face_margin, height_margin   the grid's margins (fractions)
  unknowns                     fitted unknowns: 'name' (shared by both flanks: one
                               machine set-up; VH-CATT: the head's cutter_radius and
                               blade_offset), 'convex.name' / 'concave.name' (one
                               flank's own), 'axis_rotation' (the measurement's)
  units                        unknown -> unit (mm, deg, -, 1/rad, 1/rad^2)
  fitted_error                 unknown -> fitted setting error delta (what the machine
                               cut, relative to the design), and the rotation
  correction                   setting -> correction written to the design (-delta)
  uncertainty                  unknown -> one standard deviation of delta
  scales                       unknown -> change that moves the flanks by 1 um rms
  condition_number             sigma_max / sigma_min of the scaled Jacobian
  singular_values              relative singular values s_k (descending; 1 = acting
                               independently, 0 = acting alike)
  indistinguishable            [{combination, relative_singular_value, coefficients}]
                               of the combinations with s_k < 0.03
  regularisation               Tikhonov alpha
  noise_um                     residual rms sqrt(|r|^2 / (N - n))
  deviation_summary            flank -> before/after rms and max |deviation| (um)
  deviation_before_um          flank -> [n_xi][n_s] measured deviations (um)
  deviation_after_um           flank -> [n_xi][n_s] residual after the fit (um)
  converged, status, message   the fit's convergence test, status code and its text
  iterations, evaluations      accepted steps; residual and Jacobian evaluations
  seconds                      wall time of the fit (the first run compiles)
  corrected_design             the design file written (null when not converged)
  files                        every file written (--out, --plot)
VH-CATT: the corrected design writes [pair] cutter_radius1_mm / cutter_radius2_mm of the
measured member and its own [pinion] / [gear] blade_offset_mm, convex_blade_angle_deg,
concave_blade_angle_deg (the fitted ones; the other member is not changed).
Sign: deviation > 0 = material added (the measured flank lies outside the nominal one,
along the nominal normal that points out of the tooth).  Format and method:
docs/correct.md."""


def register(sub):
    import argparse
    p = sub.add_parser(
        "correct", help="corrective machine settings from a measured flank",
        description="Corrective machine settings of a hypoid / spiral-bevel member (or the "
                    "cutter radius and blade settings of a VH-CATT member) from the "
                    "normal deviations measured on its reference grid (write the grid with "
                    "`gearjax surface DESIGN --member M --reference-grid --out grid.csv`, "
                    "fill in deviation_um): Levenberg-Marquardt with exact Jacobians, "
                    "Tikhonov-regularised; prints the condition number and the settings "
                    "that cannot be told apart; writes the corrected design.",
        epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("design", help="design file path or example:NAME")
    p.add_argument("--measured", required=True,
                   help="measured-grid CSV (docs/correct.md): one member, one or both flanks")
    p.add_argument("--settings", default=None,
                   help="comma-separated settings to correct (default for a generated "
                        "member: point_radius,blade_angle,ratio_of_roll,modified_roll_2c,"
                        "modified_roll_6d; formate: point_radius,blade_angle,cradle_angle); "
                        "machine settings radial_distance, cradle_angle, tilt, swivel, "
                        "blank_offset, machine_root_angle, sliding_base, center_to_back, "
                        "ratio_of_roll, modified_roll_2c, modified_roll_6d; cutter "
                        "point_radius, blade_angle; axis_rotation (the measurement's "
                        "rotation about the member's axis).  VH-CATT member: "
                        "cutter_radius, blade_offset (the member's head, both flanks), "
                        "blade_angle (per flank), axis_rotation (default: all four)")
    p.add_argument("--regularisation", type=float, default=0.003,
                   help="Tikhonov alpha in [0, 1] (default 0.003): a combination of settings "
                        "whose relative singular value is alpha is halved")
    p.add_argument("--max-iter", type=int, default=50,
                   help="Levenberg-Marquardt steps at most, 1..200 (default 50)")
    p.add_argument("--out", required=True, help="corrected design file (.toml)")
    p.add_argument("--json", action="store_true",
                   help="print the report as JSON instead of the table (keys below)")
    p.add_argument("--plot", default=None,
                   help="also save the deviation maps before/after (.png, .pdf, .svg)")
    p.set_defaults(func=run)


def settings_list(text):
    """The ``--settings`` list (None: the default set; ``ValueError`` for an empty name)."""
    if text is None:
        return None
    names = [s.strip() for s in text.split(",")]
    if not text.strip() or any(not s for s in names):
        raise ValueError(f"--settings = {text!r} must be a comma-separated list of setting "
                         f"names")
    return names


def run(args) -> int:
    from gearjax import load_design
    from gearjax.errors import check_int, check_range
    from gearjax.io import check_output_path, read_measured_grid

    names = settings_list(args.settings)
    alpha = check_range("--regularisation", args.regularisation, 0.0, 1.0)
    max_iter = check_int("--max-iter", args.max_iter, 1, 200)
    out = check_output_path(args.out, "--out", (".toml",))
    outs = {"--out": out}
    if args.plot is not None:
        outs["--plot"] = check_output_path(args.plot, "--plot", (".png", ".pdf", ".svg"))
    seen = {}
    for flag, path in outs.items():
        key = path.resolve()
        if key in seen:
            raise ValueError(f"{flag} = {str(path)!r} is the same file as {seen[key]}")
        seen[key] = flag
    design = load_design(args.design)
    if not hasattr(design, "correction_problem"):
        raise ValueError(f"{args.design!r}: corrections are defined for hypoid, "
                         f"spiral-bevel and VH-CATT designs only, not for [design] kind = "
                         f"{design.data['design']['kind']!r}")
    measured = read_measured_grid(args.measured)
    problem = design.correction_problem(measured, names)
    res = problem.fit(regularisation=alpha, max_iter=max_iter)
    rep = report(res, args.measured)
    files = []
    if res.converged:
        from gearjax.io import atomic_write, dumps_toml
        new = design.corrected_design(res, description=(
            f"{design.data['design'].get('description', design.name)}; {measured.member} "
            f"corrected from {args.measured} by gearjax correct"))
        atomic_write(out, dumps_toml(new.data))
        rep["corrected_design"] = str(out)
        files.append(str(out))
    if args.plot is not None and res.converged:
        from gearjax.io.measured_grid import grid_heights
        from gearjax.plot.correction import save_correction_plot
        xi = problem.reference[problem.flanks[0]].xi
        save_correction_plot(outs["--plot"], problem.flanks, xi,
                             grid_heights(measured.n_s, measured.height_margin),
                             res.before_um, res.after_um,
                             title=f"{design.name}: {measured.member} deviations")
        files.append(str(outs["--plot"]))
    if args.json:
        from gearjax.commands import print_json
        rep["files"] = files
        print_json(rep)
    else:
        sys.stdout.write(table(rep) + "\n")
        sys.stdout.write(f"files: {', '.join(files) if files else 'none'}\n")
    warn_indistinguishable(rep)
    if not res.converged:
        sys.stderr.write(f"gearjax: error: the correction did not converge ({res.message}) "
                         f"after {res.iterations} steps; no corrected design written\n")
        return 3
    return 0


def warn_indistinguishable(rep: dict) -> None:
    """One stderr warning line per combination of settings the fit cannot tell apart."""
    for c in rep["indistinguishable"]:
        sys.stderr.write(f"gearjax: warning: settings that cannot be told apart (relative "
                         f"singular value {c['relative_singular_value']:.2g}): "
                         f"{c['combination']}; the regularised fit keeps their "
                         f"combination small\n")


def report(res, measured_path) -> dict:
    """The JSON report (keys: the command's epilog)."""
    p = res.problem
    m = p.measured
    grid = lambda a: {f: a[k].tolist() for k, f in enumerate(p.flanks)}
    return {
        "design": p.design.name, "member": p.member, "measured": str(measured_path),
        "flanks": list(p.flanks), "grid": [m.n_xi, m.n_s], "points": p.n_points,
        "face_margin": m.face_margin, "height_margin": m.height_margin,
        "unknowns": list(res.unknowns), "units": res.units, "fitted_error": res.fitted,
        "correction": res.correction, "uncertainty": res.uncertainty, "scales": res.scales,
        "condition_number": res.condition_number,
        "singular_values": [float(s) for s in res.singular_values],
        "indistinguishable": [{"combination": t, "relative_singular_value": s,
                               "coefficients": c} for t, s, c in res.indistinguishable],
        "regularisation": res.regularisation, "noise_um": res.noise_um,
        "deviation_summary": res.summary(),
        "deviation_before_um": grid(res.before_um), "deviation_after_um": grid(res.after_um),
        "converged": res.converged, "status": res.status, "message": res.message,
        "iterations": res.iterations, "evaluations": res.evaluations,
        "seconds": res.seconds, "corrected_design": None,
    }


def table(rep: dict) -> str:
    """The printed before/after table."""
    L = [f"{rep['design']}: {rep['member']} ({', '.join(rep['flanks'])}), grid "
         f"{rep['grid'][0]}x{rep['grid'][1]}, {rep['points']} points, {rep['measured']}",
         f"{'deviation (um)':<16}{'before rms':>12}{'max':>9}{'after rms':>12}{'max':>9}"]
    for f, s in rep["deviation_summary"].items():
        L.append(f"{f:<16}{s['before_rms_um']:>12.3f}{s['before_max_um']:>9.3f}"
                 f"{s['after_rms_um']:>12.3f}{s['after_max_um']:>9.3f}")
    L.append(f"{'unknown':<28}{'fitted error':>14}{'correction':>14}{'+- 1 sigma':>13}  unit")
    for n in rep["unknowns"]:
        corr = rep["correction"].get(n)
        c = f"{corr:>14.6g}" if corr is not None else f"{'(none)':>14}"
        L.append(f"{n:<28}{rep['fitted_error'][n]:>14.6g}{c}{rep['uncertainty'][n]:>13.3g}  "
                 f"{rep['units'][n]}")
    sv = rep["singular_values"]
    L.append(f"condition number {rep['condition_number']:.4g} (relative singular values "
             f"{sv[0]:.3g} .. {sv[-1]:.3g}; regularisation alpha {rep['regularisation']:g})")
    ind = rep["indistinguishable"]
    L.append("settings that cannot be told apart: " + ("none" if not ind else "; ".join(
        f"{c['combination']} (s = {c['relative_singular_value']:.2g})" for c in ind)))
    L.append(f"fit: {rep['message']} after {rep['iterations']} steps ({rep['evaluations']} "
             f"evaluations), residual rms {rep['noise_um']:.3f} um, {rep['seconds']:.2f} s")
    return "\n".join(L)
