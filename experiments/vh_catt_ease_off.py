"""Target ease-off of the VH-CATT example (gearjax/gears/vh_catt/ease_off.py,
docs/correct.md "Target ease-off: VH-CATT").

``gearjax ease-off example:vh_catt_17x23`` (the command's one code path, ``--json``) on
three targets: lengthwise crowning 10 um on the drive side (pinion concave flank),
the same with 5 um of profile crowning and 3 um of bias (out of the straight blades'
reach: the residual shows it), and 10 um on the coast side (pinion convex flank).  Each
run fits the pinion's cutter radius, blade offset, the side's blade angle and the
rotation, writes the design, re-evaluates its ease-off from the file and runs the
unloaded TCA of the shipped and of the written design.

Run: ``python experiments/vh_catt_ease_off.py`` (writes
``experiments/results/vh_catt_ease_off.{json,md}``; about 2 minutes on 2 CPU cores).
"""

from __future__ import annotations

import contextlib
import io
import json
import tempfile
import time
from pathlib import Path

from gearjax.cli import main as cli
from gearjax.io import atomic_write, dumps_json

RESULTS = Path(__file__).resolve().parent / "results"
EX = "example:vh_catt_17x23"
CASES = [("drive", (10.0, 0.0, 0.0)), ("drive", (10.0, 5.0, 3.0)), ("coast", (10.0, 0.0, 0.0))]


def run(side, terms, tmp):
    L, P, B = terms
    out = Path(tmp) / f"vh_{side}_{int(L)}_{int(P)}_{int(B)}.toml"
    buf = io.StringIO()
    t0 = time.perf_counter()
    with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(io.StringIO()):
        rc = cli(["ease-off", EX, "--out", str(out), "--side", side, "--crowning-um", str(L),
                  "--profile-um", str(P), "--bias-um", str(B), "--json"])
    rep = json.loads(buf.getvalue())
    rep["exit_status"], rep["wall_seconds"] = rc, time.perf_counter() - t0
    return rep


def _grid(a):
    rows = [list(r) for r in zip(*a)][::-1]        # rows tip (top) .. root, columns -z .. +z
    return ["| " + " | ".join("--" if v is None else f"{v:.2f}" for v in r) + " |" for r in rows]


def markdown(reps) -> str:
    L = ["# Target ease-off of vh_catt_17x23 (gearjax ease-off)", "",
         "Written by experiments/vh_catt_ease_off.py.  Ease-off in um (positive = relief "
         "from the conjugate pinion), rows tip (top) to root, columns -z to +z.", ""]
    for r in reps:
        t = r["target"]
        L += [f"## {r['side']} (pinion {r['pinion_flank']}): target crowning "
              f"{t['crowning_um']:g}, profile {t['profile_um']:g}, bias {t['bias_um']:g} um", "",
              f"fit residual rms {r['fit_rms_um']:.3f} um (max {r['fit_max_um']:.3f}); written "
              f"design against the target {r['written_vs_target_rms_um']:.3f} um rms; "
              f"condition number {r['condition_number']:.3g}; {r['iterations']} steps; exit "
              f"status {r['exit_status']}; {r['wall_seconds']:.1f} s", "",
              "changes written: " + ", ".join(f"{k} {v:+.5g} {r['units'][k]}"
                                              for k, v in r["change"].items()), ""]
        hdr = "|" + " |" * 9
        sep = "|" + "---:|" * 9
        for what, key in (("shipped pinion", "ease_off_design_um"),
                          ("written design", "ease_off_written_um")):
            L += [f"{what}:", "", hdr, sep, *_grid(r[key]), ""]
        for what, key in (("shipped", "design"), ("written", "written")):
            c = r["tca"][key]
            L.append(f"* TCA of the {what} design: TE p-t-p {c['ptp_arcsec']:.3f} arcsec, "
                     f"contact ratio {c['contact_ratio']:.3f}, contact z "
                     f"{c['axial1_range_mm']} mm, warnings {c['warnings']}")
        L.append("")
    return "\n".join(L) + "\n"


def main():
    with tempfile.TemporaryDirectory() as tmp:
        reps = [run(side, terms, tmp) for side, terms in CASES]
    for r in reps:
        r.pop("files", None)
        r.pop("written_design", None)
        print(r["side"], r["target"], r["fit_rms_um"], r["change"],
              {k: r["tca"][k]["ptp_arcsec"] for k in ("design", "written")}, flush=True)
    RESULTS.mkdir(exist_ok=True)
    atomic_write(RESULTS / "vh_catt_ease_off.json", dumps_json(reps, indent=1)[0] + "\n")
    atomic_write(RESULTS / "vh_catt_ease_off.md", markdown(reps))


if __name__ == "__main__":
    main()
