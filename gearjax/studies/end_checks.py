"""The checks of a study's end design and its report tables (``gearjax optimize``):
per-scenario quality flags of every route, the acceptance test, the design-file round
trip, and the start/end quantity tables.

``prob`` is a :class:`gearjax.studies.study_run.Problem` (duck-typed here: ``route``,
``scenarios``, ``study``, ``design``, ``fields``, ``soft``).  An end design is accepted
only when :func:`acceptance_reasons` finds nothing: the optimiser met its stopping test,
the constraints hold, the written design file reads back to the optimiser's fields, no
scenario lost convergence or gained edge contact or a load carried where the flanks
cross, no fewer positions are valid than at
the start, and (edge softening) the hard model's objective did not rise beyond the
softened one's.  Units: those of the quantities (docs/optimize.md).
"""

from __future__ import annotations

import math

import jax
import numpy as np

from gearjax.fields import get_fields
from gearjax.studies.quantities import QUANTITIES

__all__ = ["scenario_of", "scenario_flags", "acceptance_reasons", "end_round_trip",
           "q_table", "quantities_report"]


def scenario_of(tree, k):
    return jax.tree_util.tree_map(lambda a: a[k], tree)


def scenario_flags(prob, res, eff) -> list:
    """Per scenario: the TCA's quality flags and (loaded) the number of valid positions."""
    if prob.route == "line":
        from gearjax.studies.line_route import line_flags
        return [line_flags(res, eff, k) for k in range(len(prob.scenarios))]
    if prob.route == "kinematics":
        from gearjax.studies.kinematics_route import kinematics_flags
        return [kinematics_flags(res, k) for k in range(len(prob.scenarios))]
    out = []
    for k in range(len(prob.scenarios)):
        fl = scenario_of(res, k).flags()
        if eff is not None:
            fl["n_valid"] = int(np.asarray(eff.n_valid)[k])
        out.append(fl)
    return out


def acceptance_reasons(opt: dict, feasibility: float, tol: float, file_error, difference,
                       x, flags0: list, flags1: list, hard=None, soft=None) -> list:
    """Why an end design is not accepted (empty: accepted; module docstring): the
    optimiser's stopping test (``opt["converged"]``), the scaled constraint violation
    against ``tol``, the design file (``file_error`` of the loader; ``difference`` of its
    fields from the optimiser's ``x``, relative 1e-9), per scenario the TCA flags and
    valid positions (``flags0``/``flags1`` at start/end), and ``hard = (J0, J1)``, the
    objective with the hard model when the study softens the edges: it may not rise by
    more than ``tol`` beyond the rise of the softened objective ``soft = (J0, J1)`` (none
    given: beyond 0).  A start that violates a constraint may cost objective to reach
    feasibility; the hard model must then agree with that cost, not exceed it."""
    reasons = []
    if not opt["converged"]:
        reasons.append(f"the optimiser did not meet its stopping test ({opt['message']})")
    if feasibility > tol:
        reasons.append(f"constraints violated by {feasibility:.3g} (scaled; tolerance {tol:g})")
    if file_error is not None:
        reasons.append(f"the end design is refused by its design-file checks: {file_error}")
    elif difference > 1e-9 * (1.0 + float(np.max(np.abs(x)))):
        reasons.append(f"the design file does not reproduce the end design (field difference "
                       f"{difference:.3g})")
    allowed = 0.0 if soft is None else max(0.0, soft[1] - soft[0])
    if hard is not None and hard[1] > hard[0] + allowed + tol:
        reasons.append(f"with the hard model (no edge softening, as gearjax efficiency) the "
                       f"objective rose {hard[0]:.6g} -> {hard[1]:.6g}"
                       + ("" if soft is None else
                          f" (softened: {soft[0]:.6g} -> {soft[1]:.6g})"))
    for k, (a, b) in enumerate(zip(flags0, flags1)):
        where = f"scenario {k + 1}"
        if not b["converged"]:
            reasons.append(f"{where}: the end design's TCA did not converge")
        if b.get("edge_contact") and not a.get("edge_contact"):
            reasons.append(f"{where}: the end design has edge contact")
        if b.get("crossing_flanks") and not a.get("crossing_flanks"):
            reasons.append(f"{where}: the end design carries load where the flanks cross")
        if "n_valid" in b and b["n_valid"] < a["n_valid"]:
            reasons.append(f"{where}: fewer valid positions of the cycle at the end "
                           f"({b['n_valid']} < {a['n_valid']})")
    return reasons


def end_round_trip(prob, end_pair):
    """The end design written to a design file and read back through the family's
    validating loader; ``(data, error or None, max |field difference|)``."""
    from gearjax.io import design_from_dict
    from gearjax.tca.result import family_of
    if prob.route == "line":
        from gearjax.studies.line_route import line_round_trip
        return line_round_trip(prob, end_pair)
    if prob.route == "kinematics":
        from gearjax.studies.kinematics_route import kinematics_round_trip
        return kinematics_round_trip(prob, end_pair)
    ad = family_of(prob.design)
    try:
        data = ad.design_data(prob.design, end_pair, prob.study.side)
        d2 = design_from_dict(data)
    except ValueError as exc:
        return None, str(exc), math.inf
    back = ad.fam.user_pair(ad.fam.setup(d2, prob.study.side)[0])
    a, b = get_fields(end_pair, prob.fields), get_fields(back, prob.fields)
    diff = max(abs(float(np.asarray(a[n])) - float(np.asarray(b[n]))) for n in prob.fields)
    return data, None, diff


def q_table(prob, Q):
    """quantity -> its values per scenario (rows of ``Q``), as lists."""
    return {q: np.asarray(Q)[:, i].tolist() for i, q in enumerate(prob.study.quantities)}


def quantities_report(prob, Q0, Q1, H0, H1) -> dict:
    """Per quantity: unit, start and end per scenario; for the loaded quantities of a
    study with edge softening also the hard model's (``start_hard_model``, ...)."""
    out = {}
    t0, t1, h0, h1 = (q_table(prob, a) for a in (Q0, Q1, H0, H1))
    for q in prob.study.quantities:
        d = {"unit": QUANTITIES[q].unit, "start": t0[q], "end": t1[q]}
        if prob.soft > 0.0 and QUANTITIES[q].loaded:
            d.update(start_hard_model=h0[q], end_hard_model=h1[q])
        out[q] = d
    return out
