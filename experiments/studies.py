"""Run packaged design studies with both optimisers and record the results.

For each study named on the command line (default: every packaged study), the
augmented Lagrangian of ``gearjax optimize`` and SciPy's SLSQP fed the same exact
gradients run from the design's own point; the table records the objective and
the hard-model values before/after, the KKT measures, iterations, evaluations,
wall time (compile included: a fresh process per method keeps the compile in the
figure) and whether the end design was accepted.

Run: ``python experiments/studies.py [NAME ...] [--methods augmented_lagrangian slsqp]``
(each study in its own process so that timings include compilation).  Writes
``experiments/results/studies.json`` and ``studies.md`` (merged with earlier runs of
other studies).
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "experiments" / "results"

ONE = r"""
import dataclasses, json, sys, time
t0 = time.time()
from gearjax.studies.study_file import read_study
from gearjax.studies import study_run as sr
st = read_study("example:" + sys.argv[1])
st = dataclasses.replace(st, method=sys.argv[2], starts=1)
prob = sr.set_up(st)
r = sr.run_study(prob)
rep = r.report
rep["wall_s"] = time.time() - t0
print(json.dumps(rep, default=float))
"""


def run(name: str, method: str) -> dict:
    t = time.time()
    out = subprocess.run([sys.executable, "-c", ONE, name, method], capture_output=True,
                         text=True, cwd=ROOT, timeout=3600)
    if out.returncode != 0:
        return {"error": out.stderr.strip().splitlines()[-1] if out.stderr else "failed",
                "wall_s": time.time() - t}
    return json.loads(out.stdout.strip().splitlines()[-1])


def _mean(v):
    return sum(v) / len(v)


def row(name, method, rep) -> dict:
    if "error" in rep:
        return {"study": name, "method": method, "error": rep["error"]}
    q = rep["quantities"]
    obj = rep["objective"]["terms"][0]["quantity"]
    d = q[obj]
    out = {"study": name, "method": method, "objective_quantity": obj,
           "start": _mean(d["start"]), "end": _mean(d["end"]),
           "J_start": rep["objective"]["start"], "J_end": rep["objective"]["end"],
           "status": rep["optimizer"]["message"], "iterations": rep["optimizer"]["iterations"],
           "evaluations": rep["optimizer"]["evaluations"],
           "optimizer_s": rep["optimizer"]["seconds"], "wall_s": rep["wall_s"],
           "accepted": rep["checks"]["accepted"], "reasons": rep["checks"]["reasons"],
           "variables_end": {v["field"]: v["end"] for v in rep["variables"]},
           "max_violation_end": rep["max_violation"]["end"]}
    if "start_hard_model" in d:
        out.update(start_hard=_mean(d["start_hard_model"]), end_hard=_mean(d["end_hard_model"]))
    for k in ("stationarity", "feasibility", "complementarity"):
        if k in rep["optimizer"]:
            out[k] = rep["optimizer"][k]
    return out


def markdown(rows) -> str:
    lines = ["| study | method | objective | start | end | change | hard model start -> end "
             "| iterations | evaluations | optimiser s | wall s | accepted |",
             "|---|---|---|---:|---:|---:|---|---:|---:|---:|---:|---|"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['study']} | {r['method']} | error: {r['error']} |"
                         + " |" * 9)
            continue
        ch = 100.0 * (r["end"] - r["start"]) / abs(r["start"])
        hard = (f"{r['start_hard']:.6g} -> {r['end_hard']:.6g} "
                f"({100 * (r['end_hard'] - r['start_hard']) / abs(r['start_hard']):+.2f} %)"
                if "start_hard" in r else "-")
        lines.append(f"| {r['study']} | {r['method']} | {r['objective_quantity']} | "
                     f"{r['start']:.6g} | {r['end']:.6g} | {ch:+.2f} % | {hard} | "
                     f"{r['iterations']} | {r['evaluations']} | {r['optimizer_s']:.1f} | "
                     f"{r['wall_s']:.1f} | "
                     f"{'yes' if r['accepted'] else 'no: ' + '; '.join(r['reasons'])} |")
    return "\n".join(lines)


def main(argv=None):
    from gearjax.studies.study_file import list_studies
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*")
    ap.add_argument("--methods", nargs="+", default=["augmented_lagrangian", "slsqp"])
    args = ap.parse_args(argv)
    names = args.names or list_studies()
    path = RESULTS / "studies.json"
    old = json.loads(path.read_text()) if path.exists() else {"rows": []}
    rows = [r for r in old["rows"] if r["study"] not in names]
    for name in names:
        for method in args.methods:
            print(f"[studies] {name} {method}", file=sys.stderr, flush=True)
            rows.append(row(name, method, run(name, method)))
    from gearjax.io import atomic_write
    data = {"machine": f"{platform.machine()}, {platform.processor() or 'cpu'}, "
                       f"{__import__('os').cpu_count()} cores",
            "date": time.strftime("%Y-%m-%d"), "rows": rows}
    atomic_write(path, json.dumps(data, indent=1, default=float) + "\n")
    atomic_write(RESULTS / "studies.md", "# Packaged studies: augmented Lagrangian and SLSQP\n\n"
                 f"Machine: {data['machine']}; {data['date']}; wall time includes compilation "
                 "(a fresh process per run, no persistent cache).\n\n" + markdown(rows) + "\n")
    print(markdown(rows))


if __name__ == "__main__":
    main()
