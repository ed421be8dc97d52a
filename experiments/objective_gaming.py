"""The objective-gaming run of the loaded-chain issue on a hypoid pair, with and without
the guard of ``TCAResult.mask_check``.

Design: ``example:hypoid_iso_10x41_synthesised``, drive side, the TCA options of
tests/test_gradients_end_to_end.py (6 positions per pitch, 1.5 pitches, 3 pairs: the
same compiled program).  Objective: mean |SRR| over the nominal design's on-flank
mask (``TCAResult.objectives(on)[1]``).  Variable: ``pinion.cutter.point_radius`` of
the drive-side pair the TCA runs (mm).  20 Adam steps (learning rate ``--lr`` mm) with
``gj.minimize_optax``:

* plain: the objective alone -- the issue's run, in which mean |SRR| "falls" while
  mask points leave the flank;
* guarded: objective + w * ``mask_check(on).penalty`` (C^1, mm^2), and the end point
  accepted only with ``n_off == 0``.

For each end point: the objective over the nominal mask, the true on-flank mean |SRR|
(over the points on the flank at the end point), ``n_off`` and the penalty.  Results:
experiments/results/objective_gaming.json; docs/architecture.md ("The mask must stay on
the flank").

Usage: python experiments/objective_gaming.py [--lr 0.5] [--steps 20] [--w 1e3]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import jax.numpy as jnp
import numpy as np
import optax

import gearjax as gj

FIELD = "pinion.cutter.point_radius"
OPTIONS = dict(side="drive", steps_per_pitch=6, half_pitches=1.5, n_pairs=3)


def _srr_on(res):
    """Mean |SRR| over the points on the flank of ``res`` (NumPy, the true value)."""
    on = np.asarray(res.on_flank)
    return float(np.mean(np.abs(np.asarray(res.kinematics.srr)[on]))) if on.any() else np.nan


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lr", type=float, default=0.5)
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--w", type=float, default=1e3)
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" /
                                         "objective_gaming.json"))
    args = ap.parse_args(argv)
    d = gj.load_design("example:hypoid_iso_10x41_synthesised")
    f = gj.tca_function(d, **OPTIONS)
    pair0 = f.pair
    nom = f(pair0)
    on = np.asarray(nom.on_flank)
    x0 = float(gj.get_fields(pair0)[FIELD])

    def res_at(x):
        return f(gj.with_fields(pair0, {FIELD: x}))

    def plain(x):
        return res_at(x[0]).objectives(on)[1]

    def guarded(x):
        r = res_at(x[0])
        return r.objectives(on)[1] + args.w * r.mask_check(on).penalty

    out = {"design": "hypoid_iso_10x41_synthesised", "field": FIELD, "options": OPTIONS,
           "mask_points": int(on.sum()), "x0": x0, "lr": args.lr, "steps": args.steps,
           "w": args.w, "nominal": {"objective": float(nom.objectives(on)[1]),
                                    "true_on_flank_mean_srr": _srr_on(nom)}}
    for name, fun in (("plain", plain), ("guarded", guarded)):
        t0 = time.perf_counter()
        r = gj.minimize_optax(fun, jnp.array([x0]), optimizer=optax.adam(args.lr),
                              steps=args.steps)
        x = float(r.x[0])
        end = res_at(x)
        c = end.mask_check(on)
        out[name] = {"x_end": x, "objective": float(end.objectives(on)[1]),
                     "true_on_flank_mean_srr": _srr_on(end), "n_off": int(c.n_off),
                     "penalty_mm2": float(c.penalty), "status": int(r.status),
                     "verdict": "true improvement" if int(c.n_off) == 0 and
                     _srr_on(end) <= out["nominal"]["true_on_flank_mean_srr"]
                     else ("flagged failure" if int(c.n_off) > 0 else "no improvement"),
                     "wall_s": time.perf_counter() - t0}
        print(name, json.dumps(out[name]))
    Path(args.out).write_text(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
