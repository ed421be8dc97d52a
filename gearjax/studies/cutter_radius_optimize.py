"""Design optimisation of the cutter-radius study ([Eigenfunctions], docs/kinematics_study.md):
the cutter radius, a blade-angle change and a cutter shift that lower the peak
slide-to-roll ratio and raise the smallest effective radius while both eigenfunctions
stay away from zero on the working flank (:func:`design_objective`), by Adam in one
jitted ``lax.scan`` (:func:`optimise_design`).  The model is
:mod:`gearjax.studies.cutter_radius`.  Units: mm, rad inside (degrees in the scaled
variable of the blade-angle change).
"""

from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.gears.hypoid.blank import BlankInput
from gearjax.studies.cutter_radius import StudySettings, study_statistics

__all__ = ["OPT_BOUNDS", "design_objective", "optimise_design"]

_DEG = math.pi / 180.0

#: box of the optimisation variables (mm, deg, mm) and their scales
OPT_BOUNDS = {"cutter_radius": (60.0, 130.0), "blade_angle_delta_deg": (-3.0, 3.0),
              "cutter_shift": (-5.0, 5.0)}
_OPT_SCALE = np.array([10.0, 1.0, 1.0])     # x = (r0/10 mm, d_alpha/deg, shift/mm)


def _x_to_settings(x):
    return StudySettings(x[0] * _OPT_SCALE[0], x[1] * _OPT_SCALE[1] * _DEG, x[2] * _OPT_SCALE[2])


def design_objective(inp, flank="convex", shape=(9, 7), r_ref=20.0, phi_floor=1.0,
                     barrier=10.0):
    """Objective of the optimisation, ``x -> J`` (x scaled: r0/10 mm, blade angle
    change in degrees, cutter shift in mm):

        J = max|SRR| - min(R_eff)/r_ref
            + barrier (relu(1 - min Phi_I/phi_floor)^2 + relu(1 - min Phi_II/phi_floor)^2)

    (lower peak slide-to-roll ratio, larger smallest effective radius, both
    eigenfunctions kept at least ``phi_floor`` away from zero -- with the
    pitch-point sign -- on the working flank).  Plain max/min: differentiable
    wherever the extreme grid point is unique."""
    shape = tuple(int(s) for s in shape)

    def J(x):
        st = study_statistics(inp, _x_to_settings(x), flank, shape)
        pen = (jax.nn.relu(1.0 - st["min_phi_I"] / phi_floor) ** 2
               + jax.nn.relu(1.0 - st["min_phi_II"] / phi_floor) ** 2)
        return st["max_abs_srr"] - st["min_r_eff"] / r_ref + barrier * pen
    return J


def optimise_design(inp: BlankInput, start: StudySettings, *, flank="convex", shape=(9, 7),
                    steps: int = 40, learning_rate: float = 0.05):
    """Adam (optax, jitted ``lax.scan`` via :func:`gearjax.optimize.minimize_optax`)
    on :func:`design_objective` over (r0, blade angle change, cutter shift) within
    :data:`OPT_BOUNDS`; forward-mode gradients.  Returns ``(OptResult, StudySettings)``."""
    import optax

    from gearjax.optimize import minimize_optax
    J = design_objective(inp, flank, shape)
    x0 = jnp.stack([start.cutter_radius / _OPT_SCALE[0],
                    start.blade_angle_delta / _DEG / _OPT_SCALE[1],
                    start.cutter_shift / _OPT_SCALE[2]])
    lo = jnp.array([OPT_BOUNDS[k][0] for k in OPT_BOUNDS]) / _OPT_SCALE
    hi = jnp.array([OPT_BOUNDS[k][1] for k in OPT_BOUNDS]) / _OPT_SCALE
    res = minimize_optax(J, x0, optimizer=optax.adam(learning_rate), steps=steps, lower=lo,
                         upper=hi, mode="fwd")
    return res, _x_to_settings(res.x)
