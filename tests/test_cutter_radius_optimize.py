"""[Eigenfunctions] design optimisation (docs/references.md): the jitted optax loop
lowers the documented objective and the final design passes the full forward model's
limit checks."""

import jax.numpy as jnp
import numpy as np

from gearjax.studies import cutter_radius as hk
from gearjax.studies import cutter_radius_optimize as hko
def test_optimise_design_improves_and_rechecks():
    inp = hk.study_blank_input(95.25)
    start = hk.StudySettings.make(95.25)
    res, best = hko.optimise_design(inp, start, shape=(5, 4), steps=6)
    h = np.asarray(res.history)
    assert h.shape == (6,) and np.all(np.isfinite(h))
    assert float(res.value) < h[0]
    # the reported value is the objective at the reported design
    J = hko.design_objective(inp, shape=(5, 4))
    x = jnp.array([float(best.cutter_radius) / 10.0, float(best.blade_angle_delta) * 180 / np.pi,
                   float(best.cutter_shift)])
    assert abs(float(J(x)) - float(res.value)) < 1e-9
    lo, hi = hko.OPT_BOUNDS["cutter_radius"]
    assert lo <= float(best.cutter_radius) <= hi
    # re-check by the full forward model (the blank is re-designed for best.cutter_radius)
    s, f = hk.flank_fields(inp, best, "convex", (7, 5))
    assert float(s.r0) == float(best.cutter_radius)
    rep = hk.limit_report(f)
    assert not rep["meshing_limit"]["inside"] and not rep["curvature_interference"]["inside"]
