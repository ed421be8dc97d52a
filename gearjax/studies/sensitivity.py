"""Scaled sensitivities of study quantities to design fields (``gearjax sensitivity``).

For outputs ``q_i`` (named quantities, :data:`gearjax.studies.quantities.QUANTITIES`)
and design fields ``x_j`` of a design at one scenario (operating point and
misalignment), the exact Jacobian ``J_ij = dq_i/dx_j`` (forward mode through every
contact solve, one program: that SciPy's SLSQP runs on a study with the same design,
fields and quantities) and from it::

    per unit      J_ij                      (output unit per field unit: mm, rad, -)
    elasticity    e_ij = J_ij x_j / q_i     (% change of q_i per % change of x_j;
                                             undefined -- null -- where q_i or x_j is 0)

The quantities are those of a study (same masks and smoothing); the fields are named
as in a study file's ``[[variables]]``.  A field whose value is 0 has no elasticity; its
per-unit value is the one to read.

Outputs of the loaded line contact (``line_*``, :mod:`gearjax.studies.line_route`) take
the micro-geometry fields of an involute design (``microgeometry.TABLE.KEY``) at one
pinion torque and mesh misalignment ``f_ma_um`` (the scenario of a line study; the
line options ``positions`` and ``slices`` default to those of a study file's ``[line]``
table); the TCA's misalignments dE, dP, dG, dSigma are for the TCA route.
"""

from __future__ import annotations

import jax.numpy as jnp
import numpy as np

from gearjax.studies.study_file import (LINE_DEFAULTS, SCENARIO_KEYS, Study, Term, Variable,
                                        check_quantities)

__all__ = ["sensitivities"]

def sensitivities(design_source: str, outputs, params, *, side: str = "drive",
                  operating: dict | None = None, scenario: dict | None = None,
                  tca: dict | None = None, line: dict | None = None) -> dict:
    """Values, Jacobian and elasticities of ``outputs`` w.r.t. ``params`` (module
    docstring) for the design ``design_source`` (a path or ``example:NAME``).

    ``operating``: torque_Nm, pinion_rpm, oil, sigma_um (loaded outputs); ``scenario``:
    dE_mm, dP_mm, dG_mm, dSigma_deg (TCA outputs) or f_ma_um (line-contact outputs);
    ``line``: positions, slices (line-contact outputs).  Returns ``{"outputs", "params",
    "values" (n_out,), "fields" (n_par,), "jacobian" (n_out, n_par), "elasticity" (n_out,
    n_par; NaN where undefined)}`` (NumPy arrays)."""
    from gearjax.studies.quantities import QUANTITIES, uses_mask
    from gearjax.studies.study_run import grid_size, quantity_jacobian, set_up, start_point

    outputs, params = list(outputs), list(params)
    if not outputs:
        raise ValueError("--outputs: name at least one quantity")
    if not params:
        raise ValueError("--params: name at least one design field")
    sc = dict(scenario or {})
    op = dict(operating or {})
    study = Study(name="sensitivity", design=design_source, side=side,
                  variables=tuple(Variable(p, change=(-1.0, 1.0), scale=1.0) for p in params),
                  objective=tuple(Term(q) for q in outputs), constraints=(),
                  operating=op, scenarios={k: (float(v),) for k, v in sc.items()},
                  tca=dict(tca or {}), line={**LINE_DEFAULTS, **(line or {})})
    check_quantities(outputs, "--outputs", study.operating)
    route = study.route
    allowed = (("f_ma_um",) if route == "line"
               else tuple(k for k in SCENARIO_KEYS if k.startswith("d")))
    bad = sorted(set(sc) - set(allowed))
    if bad:
        raise ValueError(f"scenario key {bad[0]!r} is not one of the {route} outputs' "
                         f"(allowed: {', '.join(allowed)})")
    if route == "line" and "torque_Nm" not in op:
        q = next(q for q in outputs if QUANTITIES[q].route == "line")
        raise ValueError(f"--outputs: the line-contact quantity {q!r} needs the operating "
                         "point: torque_Nm is missing")
    prob = set_up(study)
    if uses_mask(outputs):      # the fixed on-flank mask needs a first evaluation
        start_point(prob)
    elif route == "tca":
        prob.data = prob.data._replace(mask=jnp.ones((1, grid_size(prob)), bool))
    # the study's quantities are the outputs, then any it adds (the tooth form)
    J, Q0 = (np.asarray(a)[0, :len(outputs)]
             for a in quantity_jacobian(prob)(jnp.zeros(len(params)), prob.data))
    x = np.asarray(prob.x0)
    with np.errstate(divide="ignore", invalid="ignore"):
        el = J * x[None, :] / Q0[:, None]
    el = np.where((Q0[:, None] != 0.0) & (x[None, :] != 0.0), el, np.nan)
    return {"outputs": outputs, "params": params, "values": Q0, "fields": x, "jacobian": J,
            "elasticity": el}
