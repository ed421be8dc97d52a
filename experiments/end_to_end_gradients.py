"""End-to-end gradients: design field -> flanks -> TCA -> kinematics at the contact
points -> scalar objectives, by autodiff (forward mode through every Newton solve)
against central differences, for the involute, spiral-bevel and hypoid examples.

Objectives (all from one :func:`gearjax.tca_function` evaluation):
  ptp_arcsec     peak-to-peak of the unloaded TE envelope over one pitch
  mean_abs_srr   mean |SRR| over the on-flank points of tooth pair 0
  max_abs_srr    max |SRR| over them
  min_r_x_mm     min effective radius across the contact ellipse over them
  path_position  position of the reference contact on the pinion flank (hypoid: xi1,
                 face-width position; involute: radial1, mm)
The on-flank mask is taken from the nominal design (fixed), so every objective is
a smooth function of the fields near it.

Central differences of fourth order, ``(8 (f(x+h) - f(x-h)) - (f(x+2h) - f(x-2h)))/(12 h)``,
with ``h = 1e-4 |x|`` (``1e-5`` for a field at 0; 1e-6 |x| and 1e-7 on the bevel and
hypoid examples): a step relative to the field, since a
contact position varies like ``1/b`` with a crown coefficient ``b`` (a step fixed in
absolute size would be 5 % of a profile crown of 2e-4/mm); truncation ~h^4 f^(5) and
solve noise ~1e-12 f/h are then both far below 1e-6 relative.

Run:  python experiments/end_to_end_gradients.py [--quick]   -> prints the table and
writes experiments/results/end_to_end_gradients.json.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

import gearjax as gj

OBJECTIVES = gj.TCAResult.OBJECTIVES


def objectives_fn(f, design, mis, family):
    """``g(x) -> (5,)`` objectives as a function of the chosen fields ``x`` (dict)."""
    nominal = f(design, mis)
    on = np.asarray(nominal.on_flank)

    def g(values):
        des = gj.with_fields(design, {k: v for k, v in values.items() if not k.startswith("mis.")})
        m = gj.with_fields(mis, {k[4:]: v for k, v in values.items() if k.startswith("mis.")})
        return f(des, m).objectives(on)
    return g


def fd_noise(base, h):
    """Round-off allowance of the difference quotient for each objective: the solve
    noise of the objective (TE from gear angles of O(1) rad: ~1e-10 arcsec; the others
    ~1e-12 relative), times 10, times the weight sum 18/12 of the formula, over h."""
    noise = 1e-12 * (np.abs(base) + 1.0)
    noise[0] = 1e-9
    return 1.5 * noise / h


def check(name, f, design, mis, fields, family, step=1e-4):
    all_leaves = {**gj.get_fields(design), **{"mis." + k: v for k, v in gj.get_fields(mis).items()}}
    x0 = {k: jnp.asarray(all_leaves[k], float) for k in fields}
    g = jax.jit(objectives_fn(f, design, mis, family))
    t0 = time.perf_counter()
    base = np.asarray(g(x0))
    t_val = time.perf_counter() - t0
    t0 = time.perf_counter()
    jac = jax.jit(jax.jacfwd(g))(x0)
    jac = {k: np.asarray(v) for k, v in jac.items()}
    t_jac = time.perf_counter() - t0
    rows = []
    for k in fields:
        x = abs(float(x0[k]))
        # relative step; a field at 0 (or at round-off from 0, e.g. -6e-17) gets an
        # absolute step of the same order as 0.1 of a unit field's
        h = step * x if x > 1e-12 else 0.1 * step
        ev = {j: np.asarray(g({**x0, k: x0[k] + j * h})) for j in (-2, -1, 1, 2)}
        fd = (8.0 * (ev[1] - ev[-1]) - (ev[2] - ev[-2])) / (12.0 * h)
        allow = fd_noise(base, h)
        for i, obj in enumerate(OBJECTIVES):
            ad = float(jac[k][i])
            rows.append(dict(example=name, field=k, objective=obj, value=float(base[i]),
                             autodiff=ad, central_difference=float(fd[i]),
                             rel_error=abs(ad - fd[i]) / max(abs(fd[i]), 1e-300),
                             fd_noise=float(allow[i]),
                             ok=bool(abs(ad - fd[i]) <= 1e-6 * abs(fd[i]) + allow[i])))
    return rows, dict(example=name, value_s=t_val, jacobian_s=t_jac)


def involute_case(quick):
    pair = gj.involute.InvolutePair.create(25, 41, 2.0, 20.0, helix_deg=15.0)
    des = gj.involute.InvoluteTCA.create(pair, 20.0, dalpha_deg=0.02, profile_crown=2e-4, lead_crown=1e-3)
    f = gj.tca_function(des, side="drive", steps_per_pitch=8 if quick else 24)
    fields = ["dalpha", "profile_crown", "lead_crown", "face_width", "pair.module",
              "pair.pressure_angle", "pair.helix", "pair.x1", "pair.x2", "mis.dE", "mis.dP",
              "mis.dG", "mis.dSigma"]
    return "involute 25/41 helical, crowned", f, des, fields, "involute"


def hypoid_case(example, quick):
    d = gj.load_design(f"example:{example}")
    f = gj.tca_function(d, side="drive", steps_per_pitch=6 if quick else 8, half_pitches=1.5,
                        n_pairs=3)
    names = list(gj.get_fields(f.pair))
    fields = [n for n in names if n.startswith(("pinion.cutter", "pinion.machine",
                                                "gear.cutter", "gear.machine"))]
    fields += ["pinion.blank.face_width", "gear.blank.face_width", "shaft_angle", "offset",
               "mis.dE", "mis.dP", "mis.dG", "mis.dSigma"]
    if quick:
        fields = ["pinion.cutter.point_radius", "pinion.machine.modified_roll_2c",
                  "pinion.machine.ratio_of_roll", "gear.cutter.blade_angle", "mis.dE"]
    # the synthesised designs have the same TE at both transfer points, where TE
    # peak-to-peak (a max over two branches) has a kink and no derivative: check at a
    # design whose ratio of roll is 0.1 % higher (the TE parabola tilts)
    rr = f.pair.pinion.machine.ratio_of_roll
    pair = gj.with_fields(f.pair, {"pinion.machine.ratio_of_roll": rr * (1.0 + 1e-3)})
    return example + " (ratio of roll +0.1 %)", f, pair, fields, "hypoid"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--quick", action="store_true", help="a few fields, coarse grids")
    ap.add_argument("--only", choices=["involute", "spiral_bevel", "hypoid"], default=None)
    args = ap.parse_args(argv)
    cases = {"involute": lambda: involute_case(args.quick),
             "spiral_bevel": lambda: hypoid_case("spiral_bevel_10x30_synthesised", args.quick),
             "hypoid": lambda: hypoid_case("hypoid_iso_10x41_synthesised", args.quick)}
    rows, timing = [], []
    for key, make in cases.items():
        if args.only and key != args.only:
            continue
        name, f, des, fields, fam = make()
        # bevel/hypoid: smaller steps so that no stencil straddles a kink of a sampled
        # max/min (see tests/test_gradients_end_to_end.py)
        r, t = check(name, f, des, gj.Misalignment.zero(), fields, fam,
                     step=1e-4 if fam == "involute" else 1e-6)
        rows += r
        timing.append(t)
        clean = [x["rel_error"] for x in r if x["fd_noise"] < 1e-3 * abs(x["central_difference"])]
        bad = [x for x in r if not x["ok"]]
        print(f"# {name}: {len(fields)} fields x {len(OBJECTIVES)} objectives, worst relative "
              f"error where the difference quotient is not noise-limited {max(clean):.2e}; "
              f"{len(bad)} outside 1e-6 relative + round-off allowance", flush=True)
    print(f"{'example':32s} {'field':34s} {'objective':14s} {'autodiff':>14s} "
          f"{'central diff':>14s} {'rel err':>9s} {'allowance':>9s}")
    for x in rows:
        print(f"{x['example'][:32]:32s} {x['field'][:34]:34s} {x['objective']:14s} "
              f"{x['autodiff']:14.6e} {x['central_difference']:14.6e} {x['rel_error']:9.1e} "
              f"{x['fd_noise']:9.1e}{'' if x['ok'] else '  FAIL'}")
    out = Path(__file__).parent / "results" / "end_to_end_gradients.json"
    if args.only and out.exists():           # keep the other examples' rows
        old = json.loads(out.read_text())
        done = {t["example"] for t in timing}
        rows = [r for r in old["rows"] if r["example"] not in done] + rows
        timing = [t for t in old["timing"] if t["example"] not in done] + timing
    gj.io.atomic_write(out, json.dumps(dict(rows=rows, timing=timing), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
