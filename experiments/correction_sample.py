"""The packaged sample measurement (gearjax/examples/measurements/), docs/correct.md.

A synthetic measurement of the pinion of ``example:spiral_bevel_10x30_synthesised`` on
its 9x5 reference grid (margins 0.1): the pinion cut with known setting errors (convex
point radius +0.04 mm, concave ratio of roll +0.002, convex 2C +0.004 1/rad), measured
by the perturbed design's own flank grid met by the nominal normals (tangent planes),
plus seeded Gaussian noise of 1 um.  ``gearjax correct`` should find these errors
within their uncertainties (docs/correct.md; the hostile-input harness uses the file).

Run: ``python experiments/correction_sample.py`` (a few seconds).
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

import gearjax
from gearjax.gears.hypoid import flank_correction as fc
from gearjax.gears.hypoid.design_file import design_from_dict
from gearjax.io import write_reference_grid

OUT = (Path(__file__).resolve().parents[1] / "gearjax" / "examples" / "measurements"
       / "spiral_bevel_10x30_synthesised_pinion.csv")
ERRORS = {"convex.point_radius": 0.04, "concave.ratio_of_roll": 0.002,
          "convex.modified_roll_2c": 0.004}


def main():
    d = gearjax.load_design("example:spiral_bevel_10x30_synthesised")
    data = copy.deepcopy(d.to_dict())
    for key, v in ERRORS.items():
        f, n = key.split(".")
        data["pinion"][f][fc.SETTINGS[n][0]][n] += v
    bad = design_from_dict(data)
    rng = np.random.default_rng(2026)
    grids, dev = {}, {}
    for f in ("convex", "concave"):
        g0 = d.reference_grid("pinion", f, 9, 5, 0.1, 0.1)
        g1 = bad.reference_grid("pinion", f, 9, 5, 0.1, 0.1)
        P, n = np.asarray(g0.points), np.asarray(g0.normals)
        Q, m = np.asarray(g1.points), np.asarray(g1.normals)
        grids[f] = g0
        dev[f] = (np.sum(m * (Q - P), -1) / np.sum(m * n, -1) / 1e-3
                  + rng.normal(0.0, 1.0, P.shape[:2]))
    errs = ", ".join(f"{k} {v:+g}" for k, v in ERRORS.items())
    write_reference_grid(OUT, design=d.name, member="pinion", grids=grids, face_margin=0.1,
                         height_margin=0.1, deviation_um=dev,
                         comments=[f"synthetic measurement (experiments/correction_sample.py): "
                                   f"setting errors {errs} (mm, 1, 1/rad), noise 1 um rms"])
    print(f"written {OUT}")


if __name__ == "__main__":
    main()
