"""``gearjax optimize STUDY``: run a design study (docs/optimize.md).

STUDY is a study file (TOML, :mod:`gearjax.studies.study_file`) or ``example:NAME`` for
a packaged study (``--list``).  The study is read and checked against its design
before any compilation (a bad entry: one line naming it, exit 2).  The optimiser's
progress goes to stderr; at the end a before/after table goes to stdout and three
files to ``--out`` (default ``./NAME_results``):

* ``NAME_optimised.toml`` -- the end design as a design file (read back through the
  family's loader, so it passed the same checks as any design file); not written when
  the loader refuses it;
* ``NAME_history.json`` -- the report (keys below);
* ``NAME.png`` -- objective and constraint history, TE before/after, loss per position
  (loaded studies) or |SRR| along the path, and the variables; a line-contact study:
  history, loaded TE p-t-p against torque before/after (a sweep of both designs by the
  map of ``gearjax loaded``), the optimised pinion flank's modification map and the
  variables (``--no-plot``: none).

Exit status: 0 the end design is accepted (optimiser converged, constraints hold, the
design file round-trips, no new edge contact or non-converged TCA, no fewer valid
positions); 3 it is not (the files are written and every reason is a warning line);
2 bad input.
"""

from __future__ import annotations

import argparse
import os
import sys

from gearjax.commands import output_dir, warn_nonfinite

HISTORY_KEYS_DOC = """JSON keys of NAME_history.json:
  study, description, design, family, side   the study's [study] table (design as given)
  variables         per variable: field, unit ("field": the field's own mm/rad/-, or
                    "deg"), lower, upper, start, end (in that unit)
  route             "tca", "line" (the loaded line contact, micro-geometry variables) or
                    "kinematics" (hypoid eigenfunction kinematics, cutter settings)
  scenarios         per scenario: torque_Nm, pinion_rpm, dE_mm, dP_mm, dG_mm, dSigma_deg
                    (a line-contact study: torque_Nm, pinion_rpm, f_ma_um; a kinematics
                    study: one empty scenario)
  edge_softening_mm the soft active set of the loaded chain (mm; 0: none)
  quantities        per quantity: unit, start and end (one value per scenario); loaded
                    quantities of a study with edge softening also start_hard_model and
                    end_hard_model (the hard model of gearjax efficiency, same TCA)
  objective         start, end (scaled J), start_hard_model, end_hard_model (J with the
                    hard model), terms (quantity, weight, sense, over, scale, scale_used)
  constraints       quantity, lower, upper, scale, added (true: added by the study, the
                    fixed mask's min_margin_mm >= 0), scale_used
  max_violation     start, end: largest scaled constraint violation (0 when feasible)
  optimizer         method, status, converged, message, iterations, evaluations,
                    tolerance, seconds; augmented_lagrangian also stationarity,
                    feasibility, complementarity (the KKT measures) and multipliers;
                    starts (and best_start, per_start with several), derivatives
                    ("reverse" or "forward": how its gradient was taken)
  history           objective, feasibility (and stationarity) per iteration
  checks            accepted, reasons (why not), round_trip_difference (largest
                    |field| difference of the design file read back), flags_start and
                    flags_end (TCA quality flags per scenario; n_valid for loaded studies;
                    a line-contact study: converged, n_valid of the mesh positions; a
                    kinematics study: converged, blank_converged, n_valid of the grid
                    points, max_residual of the meshing equation)
  seconds           wall time of the run
  files             design, history, figure: the paths written (null: not written)
"""


def register(sub):
    p = sub.add_parser(
        "optimize", help="run a design study: optimise design fields for named quantities",
        description="Gradient-based design optimisation of a study file: variables (design "
                    "fields with bounds), an objective and constraints of named quantities "
                    "over scenarios, an augmented Lagrangian (or SciPy SLSQP) with exact "
                    "gradients through the chain.",
        epilog=HISTORY_KEYS_DOC, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("study", nargs="?", help="study file (.toml) or example:NAME")
    p.add_argument("--out", default=None,
                   help="output directory (created if missing; default ./NAME_results)")
    p.add_argument("--max-iterations", type=int, default=None,
                   help="override [optimizer] max_iterations (>= 1)")
    p.add_argument("--method", choices=["augmented_lagrangian", "slsqp"], default=None,
                   help="override [optimizer] method")
    p.add_argument("--no-plot", action="store_true", help="do not write the figure")
    p.add_argument("--list", action="store_true", help="list the packaged studies and exit")
    p.add_argument("--quantities", action="store_true",
                   help="list the quantities a study can use and exit")
    p.add_argument("--fields", action="store_true",
                   help="list the design fields of STUDY's design (names, values) and exit")
    p.set_defaults(func=run)


def _list(args) -> int:
    from gearjax.studies.quantities import QUANTITIES
    from gearjax.studies.study_file import list_studies, read_study
    if args.list:
        for name in list_studies():
            st = read_study(f"example:{name}")
            print(f"{name:34s} {st.description}")
    if args.quantities:
        for q, d in QUANTITIES.items():
            kind = {"line": "line", "kinematics": "kin"}.get(
                d.route, "loaded" if d.loaded else "TCA")
            t = "" if d.temperature is None else f" [smooth, T = {d.temperature:g}]"
            print(f"{q:22s} {d.unit or '-':7s} {kind:6s} {d.description}{t}")
    return 0


def _fields(study) -> int:
    import numpy as np

    import gearjax as gj
    design = gj.load_design(study.design)
    if study.route == "line":
        from gearjax.studies.line_route import line_chain
        pair = line_chain(design, study).pair
    elif study.route == "kinematics":
        from gearjax.studies.kinematics_route import kinematics_chain
        pair = kinematics_chain(design, study).pair
    else:
        pair = gj.tca_function(design, side=study.side).pair
    for name, v in gj.get_fields(pair).items():
        a = np.asarray(v)
        if a.ndim == 0:
            print(f"{name:44s} {float(a):.10g}")
    return 0


def _fmt(v):
    return "-" if v is None else f"{v:.6g}"


def _table(rep) -> str:
    lines = [f"study {rep['study']}: {rep['description']}", "",
             f"{'variable':42s} {'start':>14s} {'end':>14s}  bounds"]
    for v in rep["variables"]:
        u = "" if v["unit"] == "field" else f" ({v['unit']})"
        lines.append(f"{v['field'] + u:42s} {v['start']:14.8g} {v['end']:14.8g}  "
                     f"[{v['lower']:.6g}, {v['upper']:.6g}]")
    lines += ["", f"{'quantity (mean over scenarios)':42s} {'start':>14s} {'end':>14s}  change"]
    for q, d in rep["quantities"].items():
        a = sum(d["start"]) / len(d["start"])
        b = sum(d["end"]) / len(d["end"])
        ch = f"{100 * (b - a) / abs(a):+.2f} %" if a else ""
        u = f" ({d['unit']})" if d["unit"] else ""
        lines.append(f"{q + u:42s} {a:14.6g} {b:14.6g}  {ch}")
        if "start_hard_model" in d:
            a = sum(d["start_hard_model"]) / len(d["start_hard_model"])
            b = sum(d["end_hard_model"]) / len(d["end_hard_model"])
            ch = f"{100 * (b - a) / abs(a):+.2f} %" if a else ""
            lines.append(f"{'  hard model (as gearjax efficiency)':42s} {a:14.6g} {b:14.6g}  {ch}")
    opt = rep["optimizer"]
    lines += ["", f"objective J {rep['objective']['start']:.6g} -> {rep['objective']['end']:.6g}"
              f"; largest constraint violation {rep['max_violation']['start']:.3g} -> "
              f"{rep['max_violation']['end']:.3g} (scaled)",
              f"optimizer {opt['method']}: {opt['message']}; {opt['iterations']} iterations, "
              f"{opt['evaluations']} evaluations, {opt['seconds']:.1f} s"]
    if "stationarity" in opt:
        lines.append(f"KKT: stationarity {opt['stationarity']:.2e}, feasibility "
                     f"{opt['feasibility']:.2e}, complementarity {opt['complementarity']:.2e}"
                     f" (tolerance {opt['tolerance']:g})")
    ok = rep["checks"]["accepted"]
    lines.append("end design: " + ("accepted" if ok else "NOT accepted (see the warnings)"))
    return "\n".join(lines)


def _figure(prob, rep, result):
    """The study's figure (:mod:`gearjax.plot.study`): that of the TCA route, or for a
    line-contact study the loaded TE against torque and the end pinion flank's
    modification map; for a kinematics study the history, quantities and variables."""
    from gearjax.plot import study as plot
    if prob.route == "kinematics":
        return plot.kinematics_study_figure(rep)
    if prob.route != "line":
        return plot.study_figure(rep, result.start, result.end, prob.data.mask[0])
    flank = sweep = None
    if result.end_data is not None:
        from gearjax.io import design_from_dict
        from gearjax.plot.microgeometry import removal_map
        end = design_from_dict(result.end_data)
        flank = removal_map(end, "pinion", prob.study.side)
        sweep = _torque_sweep(prob, end)
    return plot.line_study_figure(rep, flank, f"pinion {prob.study.side} flank", sweep)


#: torque sweep of a line-contact study's figure: points, and the range as factors of
#: the smallest and the largest scenario torque
SWEEP_POINTS, SWEEP_RANGE = 25, (0.25, 1.3)


def _torque_sweep(prob, end):
    """``(T, A, ptp_start, ptp_end)``: the loaded TE p-t-p (µm) of the start and the end
    design over :data:`SWEEP_POINTS` torques (the scenarios' range widened by
    :data:`SWEEP_RANGE`) at each misalignment of the scenarios, by the map of
    ``gearjax loaded`` (one compiled program for both designs)."""
    import numpy as np

    from gearjax.involute import loaded_te_map
    T = [s["torque_Nm"] for s in prob.scenarios]
    A = sorted({s["f_ma_um"] for s in prob.scenarios})
    Ts = np.linspace(SWEEP_RANGE[0] * min(T), SWEEP_RANGE[1] * max(T), SWEEP_POINTS)
    kw = dict(side=prob.study.side, **prob.chain.options)
    p0, p1 = (np.asarray(loaded_te_map(d, Ts, A, **kw).te_ptp_um) for d in (prob.design, end))
    return Ts, np.asarray(A), p0, p1


def run(args) -> int:
    from gearjax.studies.study_file import read_study
    if args.list or args.quantities:
        return _list(args)
    if not args.study:
        raise ValueError("STUDY is required (a study file or example:NAME; --list shows the "
                         "packaged studies)")
    if args.max_iterations is not None and args.max_iterations < 1:
        raise ValueError(f"--max-iterations = {args.max_iterations} must be >= 1")
    import dataclasses
    study = read_study(args.study)
    over = {k: v for k, v in (("max_iterations", args.max_iterations),
                              ("method", args.method)) if v is not None}
    if over.get("method") == "slsqp" and study.starts > 1:
        over["starts"] = 1
    study = dataclasses.replace(study, **over)
    if args.fields:
        return _fields(study)
    out = output_dir(args.out or f"{study.name}_results", study.name,
                     ("_optimised.toml", "_history.json", ".png"))
    return _run(study, out, args)


def _run(study, out, args) -> int:
    from gearjax.io import atomic_write, atomic_write_figure, dumps_json, dumps_toml
    from gearjax.progress import Progress
    from gearjax.studies.study_run import run_study, set_up

    # no per-iteration callback inside the optimiser's program: a host callback would
    # keep the program out of the persistent compilation cache (a repeated run would
    # compile it again); the phases show the elapsed time, the history comes at the end
    with Progress(1, f"optimize {study.name}") as bar:
        with bar.phase("setting up the design"):
            prob = set_up(study)
        result = run_study(prob, phase=bar.phase)
    rep = result.report
    name = study.name
    files = {"design": None, "history": os.path.join(out, f"{name}_history.json"),
             "figure": None}
    if result.end_data is not None:
        path = os.path.join(out, f"{name}_optimised.toml")
        head = (f"# written by gearjax optimize {study.source}: the end design of study "
                f"{name} ({'accepted' if result.accepted else 'NOT accepted'})\n")
        if prob.route == "kinematics":
            # the machine settings are no design-file fields: a comment, as in the history
            from gearjax.studies.kinematics_route import KIN_FIELDS
            unit = {v["field"]: "deg" if v["unit"] == "deg" else KIN_FIELDS[v["field"]][2]
                    for v in rep["variables"]}
            head += "".join(f"# study setting (not a design field): {v['field']} = "
                            f"{v['end']:.10g} {unit[v['field']]}\n" for v in rep["variables"]
                            if v["field"] != "cutter_radius")
        data = dict(result.end_data)
        des = dict(data.get("design", {}))
        # the start's description no longer describes the file ("unmodified", ...)
        desc = des.get("description", des.get("name", name))
        data["design"] = dict(des, name=f"{des.get('name', name)}_optimised",
                              description=f"{desc}; the end design of study {name} "
                                          f"(gearjax optimize)")
        atomic_write(path, head + dumps_toml(data))
        files["design"] = path
    if not args.no_plot:
        fig = _figure(prob, rep, result)
        files["figure"] = os.path.join(out, f"{name}.png")
        atomic_write_figure(fig, files["figure"])
    rep["files"] = files
    text, bad = dumps_json(rep, indent=1)
    atomic_write(files["history"], text + "\n")
    warn_nonfinite(bad)
    hist = rep["history"]
    for k, (J, feas) in enumerate(zip(hist.get("objective", []), hist.get("feasibility", []))):
        sys.stderr.write(f"  iteration {k + 1:3d}: J = {J:.6g}, largest violation {feas:.2e}\n")
    print(_table(rep))
    print(f"files: {', '.join(p for p in files.values() if p)}")
    for why in result.reasons:
        sys.stderr.write(f"gearjax: warning: {why}\n")
    return 0 if result.accepted else 3
