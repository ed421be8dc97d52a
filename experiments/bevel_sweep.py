"""Seeded sweep of spiral-bevel and hypoid designs: ISO 23509 blank -> flanks -> local
synthesis -> TCA, drive and coast (issue 27, item 4).

Each design is drawn from the sampler :func:`sample`:

* ratio ``u`` uniform in [1, 8], pinion teeth ``z1`` an integer in
  ``[max(6, round(16 - 1.5 u)), max(that, min(30, round(45/u)))]`` (small pinions at
  high ratios, as built), ``z2 = round(u z1)``.  Tooth numbers, hands and flank sides
  are data of the pair pytree (``gearjax.gears.hypoid.pair.program_pair``), so the
  whole sweep runs on a handful of compiled programs (counted in the report);
* hypoid offset ``E = f * d_e2/2`` with ``f`` uniform in [0, 0.4] (the gear outer
  pitch radius), 15 % of the designs at ``E = 0`` (spiral bevel);
* ISO 23509 Method 0 for ``E = 0`` (Method 0 is defined for zero offset only),
  Method 1 otherwise; mean spiral angle of the pinion uniform in 20-45 deg;
  pinion hand left or right (gear the opposite hand);
* gear outer pitch diameter ``d_e2`` 150-300 mm, gear face width 0.13-0.17 ``d_e2``,
  cutter radius 0.35-0.5 ``d_e2``, nominal pressure angles 20 deg.

Pipeline (one design):

1. **blank**: :class:`gearjax.gears.hypoid.blank.BlankInput` ``from_dict`` (validation:
   ``ValueError`` naming the field) and :func:`~gearjax.gears.hypoid.blank.blank_geometry`
   (``throw=True``: ``ValueError`` / ``ConvergenceError`` on an undefined blank).
2. **flanks**: :func:`gearjax.studies.cutter_radius_pair.study_pair`: the gear flank is
   the face-mill cone of radius ``r_c0`` tangent to the lengthwise direction at the
   pitch point, with the blank's generated pressure angle as blade angle, placed as a
   formate gear; the pinion is the one that gear generates
   (:func:`gearjax.gears.hypoid.formate.generating_gear_pinion`: conjugate, line
   contact).  Gear convex flank = drive side, gear concave = coast side.
   :func:`gearjax.gears.hypoid.tca.prepare` then finds the mounting hand and reference.
3. **synthesis**: :func:`gearjax.gears.hypoid.synthesis.synthesise` to the targets of
   the shipped hypoid examples (experiments/synthesis_hypoid.py): bearing at mid face
   (xi1 = 0) and mid working depth, 8 arcsec TE drop to +-p/2, apex at the mean
   contact, no cubic term, semi-major F/6, path angle -45 deg (drive) / +45 deg
   (coast); start ``d_radius = +-2 mm, 2C = 0.02``, then the other sign of ``d_radius``
   when the starting pinion makes no contact near the mean point (which sign localises
   the bearing depends on the mounting hand and sense of rotation).  Direct solve
   first; if it does not converge, continuation from +-65 deg in 5-deg steps (as the
   example script).
4. **TCA**: :func:`gearjax.gears.hypoid.synthesis.verify` (independent full TCA, 16
   steps per pitch, +-2 pitches, 5 pairs) and the contact-quality flags of
   :meth:`gearjax.tca.result.TCAResult.flags` of that TCA.

Outcome of each side: ``blank refused`` (the parameter and message), ``flanks
refused`` (exception), ``synthesis not converged`` (status), ``TCA failed``
(exception), ``TCA flagged`` (the flags raised), ``targets missed`` (no flag, but a
target check below fails -- a *silent wrong number*), ``wrong hand`` (the pinion flank's
hand of spiral, measured on its grid, is not the design's -- a silent wrong result) or
``ok``.

Target checks of an unflagged TCA (tolerances of tests/test_synthesis.py's
independent-TCA test; ``T`` = targets):

* bearing: |xi1 - 0| < 0.01, |h1 - T_h| < 0.05 mm (where the path crosses the
  target line);
* TE: drop from the apex to +-p/2 within 0.5 arcsec of 8; apex within 0.03 pitch of
  the mean contact; TE at both transfer points within 0.5 arcsec of 8 (two equal
  parabolas one pitch apart cross half a pitch from either apex) and the transfers
  within 0.05 pitch of +-1/2;
* envelope peak-to-peak on the 16-step grid between its closed-form bounds
  ``T (1 - 2/16)`` (``T`` the smaller measured transfer drop: apex and transfer both
  half a grid step off a node -- they are half a pitch, 8 steps, apart) less 0.05 arcsec
  for the TE's departure from two parabolas (measured: 0.006), and 8.5 arcsec;
* path angle within 0.5 deg, semi-major axis within 0.05 mm of the target;
* contact on both flanks between the transfers (min margin > 0) and contact ratio
  along the path > 1.

Run: ``python experiments/bevel_sweep.py --n 100 --seed 2027 --out
experiments/results/bevel_sweep`` (writes OUT.json after every design and OUT.md at the
end; ``--from-json`` rebuilds the table).  Cost: see docs/hypoid.md ("The bevel and
hypoid sweep").
"""

from __future__ import annotations

import argparse
import json
import math
import time
import traceback
from collections import Counter
from pathlib import Path

import jax
import numpy as np

jax.config.update("jax_enable_x64", True)

from gearjax.errors import ConvergenceError  # noqa: E402
from gearjax.gears.hypoid import synthesis as sy  # noqa: E402
from gearjax.gears.hypoid import tca as th  # noqa: E402
from gearjax.gears.hypoid.blank import BlankInput, blank_geometry  # noqa: E402
from gearjax.gears.hypoid.flank import flank_surface  # noqa: E402
from gearjax.studies.cutter_radius import StudySettings  # noqa: E402
from gearjax.studies.cutter_radius_pair import study_pair  # noqa: E402
from gearjax.tca.path import ARCSEC  # noqa: E402
from gearjax.tca.result import TCAResult  # noqa: E402

#: tooth-number pool: ratios 1, 2.5, 4.44, 8 (static fields: one structure each)
#: side -> (gear flank of study_pair, path-angle target (deg), start d_radius (mm))
SIDES = {"drive": ("convex", -45.0, 2.0), "coast": ("concave", 45.0, -2.0)}
TE_TARGET = 8.0
VERIFY_STEPS = 16
PTP_SHAPE_ARCSEC = 0.05

# ---------------------------------------------------------------- compile counter
COMPILES = {"n": 0, "seconds": 0.0}


def _on_duration(event, duration, **_):
    if event == "/jax/core/compile/backend_compile_duration":
        COMPILES["n"] += 1
        COMPILES["seconds"] += float(duration)


jax.monitoring.register_event_duration_secs_listener(_on_duration)


# ---------------------------------------------------------------- sampler
def sample(rng) -> dict:
    """One design in file units (module docstring)."""
    u = float(rng.uniform(1.0, 8.0))
    lo = max(6, round(16 - 1.5 * u))
    z1 = int(rng.integers(lo, max(lo, min(30, round(45 / u))) + 1))
    z2 = max(z1, round(u * z1))
    de2 = float(rng.uniform(150.0, 300.0))
    frac = 0.0 if rng.uniform() < 0.15 else float(rng.uniform(0.0, 0.4))
    return dict(
        method="iso23509-method0" if frac == 0.0 else "iso23509-method1",
        z1=int(z1), z2=int(z2), offset_mm=frac * de2 / 2.0,
        gear_outer_pitch_diameter_mm=de2,
        gear_face_width_mm=float(rng.uniform(0.13, 0.17)) * de2,
        spiral_angle_deg=float(rng.uniform(20.0, 45.0)),
        cutter_radius_mm=float(rng.uniform(0.35, 0.5)) * de2,
        hand="left" if rng.uniform() < 0.5 else "right")


class WrongHand(Exception):
    """The generated pinion flank has the other hand of spiral than the design (a silent
    wrong result of the flank route: it is labelled with the design's hand)."""


def _msg(exc) -> str:
    return f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}"[:300]


def _refused_field(msg: str) -> str:
    """The parameter a one-line ValueError names (first word before ' = ' or ' must')."""
    head = msg.split(": ", 1)[-1]
    for sep in (" = ", " must", " is "):
        if sep in head:
            return head.split(sep, 1)[0].strip().split(" ")[-1]
    return "?"


# ---------------------------------------------------------------- one side
def target_checks(ver: dict, tgt) -> list[str]:
    """Names of the failed target checks of an unflagged verification TCA."""
    xi_t, h_t, _, b_t, a_t = (float(x) for x in tgt)
    fails = []
    if not abs(ver["xi1"] - xi_t) < 0.01:
        fails.append("bearing_xi1")
    if not abs(ver["h1_mm"] - h_t) < 0.05:
        fails.append("bearing_h1")
    if not all(abs(t - TE_TARGET) < 0.5 for t in ver["te_half_pitch_arcsec"]):
        fails.append("te_half_pitch")
    if not abs(ver["apex_offset_pitch"]) < 0.03:
        fails.append("te_apex")
    if not all(abs(t - TE_TARGET) < 0.5 for t in ver["te_transfer_arcsec"]):
        fails.append("te_transfer")
    lo, hi = ver["transfer_offset_pitch"]
    if not (abs(lo + 0.5) < 0.05 and abs(hi - 0.5) < 0.05):
        fails.append("transfer_points")
    # grid sampling of two parabolas of drop T (apex to transfer) m steps per pitch apart:
    # apex and transfer share their offset from the nearest nodes (half a pitch apart), at
    # most half a step; the sampled top is at most T/m^2 below the apex, the sampled
    # bottom at most T (1 - (1 - 1/m)^2) above the transfer: ptp >= T (1 - 2/m)
    # (less PTP_SHAPE_ARCSEC: the TE curves are parabolas only to the order synthesis
    # controls; quartic and higher terms move the sampled values by a few milliarcsec)
    ptp_lo = min(ver["te_transfer_arcsec"]) * (1.0 - 2.0 / VERIFY_STEPS) - PTP_SHAPE_ARCSEC
    if not ptp_lo - 1e-9 <= ver["ptp_arcsec"] <= TE_TARGET + 0.5:
        fails.append("te_ptp")
    if not abs(ver["path_angle_deg"] - math.degrees(b_t)) < 0.5:
        fails.append("path_angle")
    if not abs(ver["semi_major_mm"] - a_t) < 0.05:
        fails.append("semi_major")
    if not ver["min_margin_between_transfers_mm"] > 0.0:
        fails.append("bearing_off_flank")
    if not ver["contact_ratio"] > 1.0:
        fails.append("contact_ratio")
    return fails


def measured_hand(fl) -> str:
    """Hand of spiral measured on a flank grid (the definition of
    tests/test_hypoid_surface.py): right hand when, going toe -> heel at mid height,
    the tooth turns positively about the work axis (apex -> heel)."""
    g = flank_surface(fl, 9, 5, throw=False)
    P = np.asarray(g.points)
    j = P.shape[1] // 2
    # the mid-height row is what is measured (a generated pinion's root row may not
    # converge at every face position: the envelope does not reach the root cone there)
    if not bool(np.all(np.asarray(g.converged)[:, j])):
        raise ConvergenceError("the generated flank's grid did not converge at mid height "
                               "(no hand to measure)")
    t, r = P[-1, j] - P[0, j], P[P.shape[0] // 2, j]
    e_phi = np.array([-r[1], r[0], 0.0]) / math.hypot(r[0], r[1])
    return "right" if t @ e_phi > 0 else "left"


def flank_pair(inp: BlankInput, side: str):
    """(Start, info) of one side: study_pair + prepare (concrete)."""
    gear_flank = SIDES[side][0]
    sp = study_pair(inp, StudySettings.make(float(inp.cutter_radius)), gear_flank)
    got = measured_hand(sp.pair.pinion)
    if got != inp.hand:
        raise WrongHand(f"pinion flank measured {got}-hand, design {inp.hand}-hand")
    prep = th.prepare(sp.pair)
    y0 = np.concatenate([np.asarray(prep.x_ref, float), [prep.phi1_ref]])
    st = sy.Start(prep.pair, float(prep.x_ref[0]), y0, bool(prep.drive), side)
    return st, dict(chain_error=float(sp.info["chain_error"]), mount_hand=int(prep.pair.hand),
                    sense_drive=bool(prep.drive))


def synthesise_side(st, side: str):
    """Direct solve from ``d_radius = +-2 mm`` (the side's sign first, then the other: the
    sign that localises the bearing depends on the mounting hand and the sense of
    rotation, not on the side alone), then continuation from +-65 deg from the first
    start whose TCA ran; returns (result, route).  Raises the ConvergenceError of the
    last start when no start gives a TCA."""
    _, angle, dr = SIDES[side]
    tg = sy.Targets(path_angle_deg=angle)
    first, err = None, None
    for sign in (1.0, -1.0):
        v0 = np.array([sign * dr, 0.02, 0, 0, 0, 0, 0], float)
        try:
            res = sy.synthesise(st, tg, v0=v0, throw=False)
        except ConvergenceError as exc:         # the start's TCA failed: the other sign
            err = exc
            continue
        route = "direct" if sign > 0 else "direct, other start sign"
        if res.converged:
            return res, route
        first = first or (res, v0, route)
    if first is None:
        raise err
    res, v, route = first
    for a in np.arange(65.0, abs(angle) - 1e-9, -5.0):
        r = sy.synthesise(st, sy.Targets(path_angle_deg=float(np.sign(angle) * a)), v0=v,
                          throw=False)
        if not r.converged:
            return res, f"continuation stopped at {np.sign(angle) * a:+.0f} deg"
        v = r.v
    res2 = sy.synthesise(st, tg, v0=v, throw=False)
    return (res2, "continuation") if res2.converged else (res, "continuation failed at target")


def run_side(inp: BlankInput, side: str) -> dict:
    row = dict(side=side)
    t0 = time.perf_counter()
    try:
        st, info = flank_pair(inp, side)
        row.update(info)
    except WrongHand as exc:
        row.update(stage="flanks", outcome="wrong hand", error=_msg(exc))
        row["seconds"] = time.perf_counter() - t0
        return row
    except Exception as exc:                       # noqa: BLE001 -- classified, reported
        row.update(stage="flanks", outcome="flanks refused", error=_msg(exc))
        row["seconds"] = time.perf_counter() - t0
        return row
    try:
        res, route = synthesise_side(st, side)
    except Exception as exc:                       # noqa: BLE001
        row.update(stage="synthesis", outcome="synthesis error", error=_msg(exc))
        row["seconds"] = time.perf_counter() - t0
        return row
    row.update(route=route, iterations=res.iterations, status=res.message,
               residuals=dict(zip(sy.RESIDUAL_NAMES, res.residuals.tolist())),
               max_scaled_residual=float(np.max(np.abs(res.residuals / sy.SCALES))),
               targets=dict(xi1=res.targets[0], h1_mm=res.targets[1],
                            te_arcsec=res.targets[2] / ARCSEC,
                            path_angle_deg=math.degrees(res.targets[3]),
                            semi_major_mm=res.targets[4]))
    if not res.converged:
        row.update(stage="synthesis", outcome="synthesis not converged")
        row["seconds"] = time.perf_counter() - t0
        return row
    try:
        ver = sy.verify(res.pair, res.targets, steps_per_pitch=VERIFY_STEPS)
    except Exception as exc:                       # noqa: BLE001
        row.update(stage="tca", outcome="TCA failed", error=_msg(exc))
        row["seconds"] = time.perf_counter() - t0
        return row
    out = ver["result"]
    flags = TCAResult(out.path, out.margin, out.multi, out.coords, None, side, "hypoid").flags()
    raised = [k for k, v in flags.items() if (not v if k in ("converged", "reference_on_flank") else v)]
    row["verify"] = {k: v for k, v in ver.items() if k not in ("result", "prepared")}
    row["flags"] = raised
    fails = target_checks(ver, res.targets)
    row["fails"] = fails
    if raised:
        row.update(stage="tca", outcome="TCA flagged")
    elif fails:
        row.update(stage="tca", outcome="targets missed")
    else:
        row.update(stage="done", outcome="ok")
    row["seconds"] = time.perf_counter() - t0
    return row


def run_design(d: dict) -> dict:
    row = dict(design=d)
    t0 = time.perf_counter()
    try:
        inp = BlankInput.from_dict(d)
        geo = blank_geometry(inp)
        row["blank"] = {k: float(geo.to_dict()[k]) for k in
                        ("delta1", "delta2", "beta_m1", "beta_m2", "Rm1", "Rm2", "b1", "b2")}
    except Exception as exc:                       # noqa: BLE001
        msg = _msg(exc)
        row.update(outcome="blank refused", error=msg, refused_field=_refused_field(msg),
                   seconds=time.perf_counter() - t0)
        return row
    row["sides"] = {s: run_side(inp, s) for s in SIDES}
    oc = [row["sides"][s]["outcome"] for s in SIDES]
    row["outcome"] = "ok" if all(o == "ok" for o in oc) else "/".join(oc)
    row["seconds"] = time.perf_counter() - t0
    return row


# ---------------------------------------------------------------- report
def summarise(rows: list, meta: dict) -> dict:
    n = len(rows)
    blank_ok = [r for r in rows if r["outcome"] != "blank refused"]
    sides = [(r, r["sides"][s]) for r in blank_ok for s in SIDES]
    stage = Counter()
    classes = {}
    for r in rows:
        if r["outcome"] == "blank refused":
            key = f"blank refused: {r['refused_field']}"
            classes.setdefault(key, dict(count=0, example=r["design"], message=r["error"]))
            classes[key]["count"] += 1
    for r, s in sides:
        stage[s["outcome"]] += 1
        if s["outcome"] == "ok":
            continue
        detail = (s.get("error") or s.get("status") or ",".join(s.get("flags", []))
                  or ",".join(s.get("fails", [])))
        if s["outcome"] == "TCA flagged":
            key = f"{s['side']}: TCA flagged: {','.join(s['flags'])}"
        elif s["outcome"] == "targets missed":
            key = f"{s['side']}: targets missed: {','.join(s['fails'])}"
        elif s["outcome"] == "synthesis not converged":
            key = f"{s['side']}: synthesis not converged ({s.get('route')})"
        else:
            key = f"{s['side']}: {s['outcome']}: {(s.get('error') or '')[:60]}"
        c = classes.setdefault(key, dict(count=0, example=r["design"], message=detail))
        c["count"] += 1
    ok_sides = [s for _, s in sides if s["outcome"] == "ok"]
    worst = {}
    if ok_sides:
        def w(name, f):
            worst[name] = max(f(s) for s in ok_sides)
        w("xi1", lambda s: abs(s["verify"]["xi1"] - s["targets"]["xi1"]))
        w("h1_mm", lambda s: abs(s["verify"]["h1_mm"] - s["targets"]["h1_mm"]))
        w("te_half_pitch_arcsec", lambda s: max(abs(t - TE_TARGET) for t in s["verify"]["te_half_pitch_arcsec"]))
        w("te_transfer_arcsec", lambda s: max(abs(t - TE_TARGET) for t in s["verify"]["te_transfer_arcsec"]))
        w("apex_offset_pitch", lambda s: abs(s["verify"]["apex_offset_pitch"]))
        w("path_angle_deg", lambda s: abs(s["verify"]["path_angle_deg"] - s["targets"]["path_angle_deg"]))
        w("semi_major_mm", lambda s: abs(s["verify"]["semi_major_mm"] - s["targets"]["semi_major_mm"]))
        worst["min_contact_ratio"] = min(s["verify"]["contact_ratio"] for s in ok_sides)
        worst["min_margin_mm"] = min(s["verify"]["min_margin_between_transfers_mm"] for s in ok_sides)
        worst["ptp_range_arcsec"] = [min(s["verify"]["ptp_arcsec"] for s in ok_sides),
                                     max(s["verify"]["ptp_arcsec"] for s in ok_sides)]
    synth_conv = sum(1 for _, s in sides if s.get("outcome") not in
                     ("flanks refused", "synthesis error", "synthesis not converged"))
    flanks_ok = sum(1 for _, s in sides if s.get("outcome") not in ("flanks refused", "wrong hand"))
    return dict(meta, designs=n, blanks_ok=len(blank_ok), sides=len(sides),
                flanks_ok=flanks_ok, synthesis_converged=synth_conv,
                tca_unflagged=sum(1 for _, s in sides if s["outcome"] in ("ok", "targets missed")),
                ok_sides=len(ok_sides), ok_designs=sum(1 for r in rows if r["outcome"] == "ok"),
                silent_wrong=stage.get("targets missed", 0) + stage.get("wrong hand", 0),
                side_outcomes=dict(stage), classes=classes, worst_ok=worst)


def markdown(summary: dict) -> str:
    s = summary
    pct = lambda a, b: f"{a}/{b} ({100.0 * a / b:.0f} %)" if b else f"{a}/{b}"
    lines = [
        "# Bevel and hypoid sweep (experiments/bevel_sweep.py)", "",
        f"Seed {s['seed']}, {s['designs']} designs, {s['sides']} sides (drive + coast of every "
        f"blank that was accepted); wall time {s['wall_s']:.0f} s on the shared 2-core CPU; "
        f"{s['compiles']} XLA compilations ({s['compile_s']:.0f} s of backend compile time).", "",
        "| stage | passed |", "|---|---|",
        f"| blank accepted (ISO 23509 Method 0 / 1) | {pct(s['blanks_ok'], s['designs'])} |",
        f"| flanks + prepare (sides) | {pct(s['flanks_ok'], s['sides'])} |",
        f"| synthesis converged (sides) | {pct(s['synthesis_converged'], s['sides'])} |",
        f"| TCA unflagged (sides) | {pct(s['tca_unflagged'], s['sides'])} |",
        f"| targets met by the TCA (sides) | {pct(s['ok_sides'], s['sides'])} |",
        f"| designs ok on both sides | {pct(s['ok_designs'], s['designs'])} |",
        f"| silent wrong results (wrong hand; unflagged but targets missed) | {s['silent_wrong']} |", "",
        "## Failure classes", "", "| class | count | example (design) | message |", "|---|---|---|---|"]
    for k, c in sorted(s["classes"].items(), key=lambda kv: -kv[1]["count"]):
        ex = c["example"]
        exs = (f"{ex['method'][-7:]} z {ex['z1']}/{ex['z2']}, E {ex['offset_mm']:.2f}, "
               f"d_e2 {ex['gear_outer_pitch_diameter_mm']:.1f}, b2 {ex['gear_face_width_mm']:.1f}, "
               f"beta {ex['spiral_angle_deg']:.2f}, r_c0 {ex['cutter_radius_mm']:.1f}, {ex['hand']}")
        lines.append(f"| {k} | {c['count']} | {exs} | {str(c['message'])[:160].replace('|', '/')} |")
    if s["worst_ok"]:
        lines += ["", "## Worst deviations over the ok sides (verification TCA vs targets)", "",
                  "| quantity | worst |", "|---|---|"]
        for k, v in s["worst_ok"].items():
            lines.append(f"| {k} | {v if isinstance(v, list) else f'{v:.4g}'} |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=100)
    ap.add_argument("--seed", type=int, default=2027)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "bevel_sweep"))
    ap.add_argument("--skip", type=int, default=0,
                    help="skip the first SKIP sampled designs (resume a killed run; merge by hand)")
    ap.add_argument("--resume", action="store_true",
                    help="continue OUT.json: keep its rows and run the designs after them "
                         "(a long run in several processes: one XLA process accumulating "
                         "thousands of programs ran out of LLVM memory after ~700 compilations)")
    ap.add_argument("--chunk", type=int, default=0,
                    help="stop after CHUNK designs (0: all); with --resume, a shell loop "
                         "runs the sweep in fresh processes")
    ap.add_argument("--from-json", action="store_true", help="rebuild OUT.md from OUT.json")
    a = ap.parse_args(argv)
    out = Path(a.out)
    if a.from_json:
        data = json.loads(out.with_suffix(".json").read_text())
        out.with_suffix(".md").write_text(markdown(data["summary"]))
        return
    rng = np.random.default_rng(a.seed)
    rows, prior = [], dict(wall_s=0.0, compiles=0, compile_s=0.0)
    if a.resume and out.with_suffix(".json").exists():
        old = json.loads(out.with_suffix(".json").read_text())
        rows = old["rows"]
        prior = {k: old["summary"].get(k, 0) for k in prior}
    skip = a.skip + len(rows)
    designs = [sample(rng) for _ in range(a.n)][skip:]
    if a.chunk:
        designs = designs[:a.chunk]
    t0 = time.perf_counter()
    for i, d in enumerate(designs, start=skip):
        try:
            rows.append(run_design(d))
        except Exception as exc:                   # noqa: BLE001 -- a crash is a finding
            rows.append(dict(design=d, outcome="crash", error=_msg(exc),
                             traceback=traceback.format_exc()))
        meta = dict(seed=a.seed, n_requested=a.n,
                    wall_s=prior["wall_s"] + time.perf_counter() - t0,
                    compiles=prior["compiles"] + COMPILES["n"],
                    compile_s=prior["compile_s"] + COMPILES["seconds"])
        summary = summarise([r for r in rows if r["outcome"] != "crash"], meta)
        summary["crashes"] = [r for r in rows if r["outcome"] == "crash"]
        out.with_suffix(".json").write_text(json.dumps(dict(summary=summary, rows=rows), indent=1,
                                                       default=float))
        print(f"[{i + 1}/{a.n}] {meta['wall_s']:.0f} s  {meta['compiles']} compiles  "
              f"{rows[-1]['outcome']}  "
              f"{d['z1']}/{d['z2']} E={d['offset_mm']:.1f} b={d['spiral_angle_deg']:.1f} {d['hand']}",
              flush=True)
    out.with_suffix(".md").write_text(markdown(summary))


if __name__ == "__main__":
    main()
