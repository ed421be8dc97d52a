"""Running a study (:mod:`gearjax.studies.study_file`): the scaled problem, the optimiser,
the checks of the end design.

**The problem.**  With ``x0`` the design's values of the study's fields, the optimiser
works on ``u = (x - x0) / s`` (``s`` each variable's scale), inside the bounds.  At
every scenario ``k`` (operating point and misalignment, one ``vmap``) the chain
gives the quantities ``q_k``; then::

    J(u)   = sum_terms  w  r_k( sense * q_k(u) / S )       S: the term's scale
    g(u)   = (q_k(u) - upper) / S_c ,  (lower - q_k(u)) / S_c   <= 0, every k

``r_k`` is the mean over the scenarios or their smooth maximum (log-sum-exp at
temperature 0.01 in units of ``S``: a worst-case objective; ``smooth_max`` of
:mod:`gearjax.studies.quantities`).  The default scale of a term is the magnitude of
its start value (so a weight 1 term starts at 1), of a constraint its bound.

**The optimisers.**  ``augmented_lagrangian``: :func:`gearjax.augmented_lagrangian.
minimize_constrained`, one jitted program, stopping on the KKT conditions
(``tolerance`` on the scaled stationarity, feasibility and complementarity);
``starts > 1`` runs that many starts at once (``vmap``: the design's own point and
seeded uniform points in the bounds) and keeps the best feasible end point.
``slsqp``: SciPy's SLSQP (Kraft, "A software package for sequential quadratic
programming", DFVLR-FB 88-28, 1988) fed the exact value and Jacobian of the same
jitted program -- a second route to the optimum, for comparison.

**The end design** is written back to a design file (:meth:`gearjax.tca.family.
GearFamily.design_data`) and read again through the family's loader, which validates it
(tooth form, ranges), and its fields are compared with the optimiser's.  It is
*accepted* only when the optimiser met its stopping test, the constraints hold, the
file round-trips, and at every scenario the TCA converged without edge contact and (a
loaded study) no fewer positions of the cycle are valid than at the start; with edge
softening, the hard model's objective may not rise by more than the softened one's
(:func:`gearjax.studies.end_checks.acceptance_reasons`).

**The line-contact route** (a study of the ``line_*`` quantities,
:mod:`gearjax.studies.line_route`): the variables are micro-geometry fields, each
scenario one loaded line contact (torque, mesh misalignment f_ma), the same scaled
problem, optimisers and acceptance, with the line contact's own flags (every mesh
position converged) and design-file write-back (the ``[microgeometry]`` tables).

**The kinematics route** (the ``kin_*`` quantities, :mod:`gearjax.studies.
kinematics_route`): the variables are the cutter settings of the [Eigenfunctions]
cutter-radius study, one implicit scenario (the flank grid), the same problem,
optimisers and acceptance with its own flags (the blank's and every grid point's Newton
solve converged) and write-back (``[blank] cutter_radius_mm``).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import time
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.compile_ahead import FAST_COMPILE_OPTIONS
from gearjax.fields import field_names, get_fields, with_fields, with_scaled_fields
from gearjax.studies.end_checks import (acceptance_reasons, end_round_trip, quantities_report,
                                        scenario_flags, scenario_of)
from gearjax.studies.quantities import QUANTITIES, quantity_values, smooth_max
from gearjax.studies.study_file import Constraint, Study
from gearjax.tca.assembly import Misalignment

__all__ = ["Problem", "StudyResult", "set_up", "evaluate", "evaluator", "grid_size", "start_point",
           "run_study", "acceptance_reasons", "combine", "set_scales", "scenario_of",
           "scenario_flags"]

#: smooth maximum over scenarios: temperature in units of the term's scale
SCENARIO_TEMPERATURE = 0.01
#: default soft active set of a loaded study (mm; ``[operating] edge_softening_mm``,
#: :func:`gearjax.loading.mesh_efficiency.mesh_efficiency_traced`)
EDGE_SOFTENING_MM = 0.2


class Data(NamedTuple):
    """The traced inputs of a study's programs."""

    pair0: object
    x0: jax.Array
    scale: jax.Array
    torque: jax.Array
    rpm: jax.Array
    mis: Misalignment
    oil: object
    surface: object
    mask: jax.Array
    term_scale: jax.Array
    con_scale: jax.Array


@dataclasses.dataclass
class Problem:
    """A study set up on its design: the chain, the variables and the scenarios."""

    study: Study
    design: object
    chain: object
    fields: list
    x0: np.ndarray
    lower: np.ndarray          # bounds of u (scaled)
    upper: np.ndarray
    scenarios: list            # one dict per scenario (file units)
    loaded: bool
    soft: float = 0.0          # edge softening of the loaded chain (mm)
    family: str = ""
    route: str = "tca"         # "line": the loaded line contact (gearjax.studies.line_route),
    #                            "kinematics": the eigenfunction kinematics (kinematics_route)
    data: Data = None
    evaluate_program: object = None
    fun: object = None
    jacobian_program: object = None


def _scenario_list(study: Study) -> list:
    op = study.operating
    if study.route == "kinematics":     # one implicit scenario
        return [{}]
    base = {"torque_Nm": float(op.get("torque_Nm", 0.0)),
            "pinion_rpm": float(op.get("pinion_rpm", 0.0))}
    base.update({"f_ma_um": 0.0} if study.route == "line" else
                {"dE_mm": 0.0, "dP_mm": 0.0, "dG_mm": 0.0, "dSigma_deg": 0.0})
    keys = list(study.scenarios)
    out = []
    for combo in itertools.product(*(study.scenarios[k] for k in keys)):
        out.append({**base, **dict(zip(keys, combo))})
    return out


def _check_scenarios(scen: list, loaded: bool) -> None:
    from gearjax.loading.efficiency_inputs import check_operating_point
    for i, s in enumerate(scen):
        try:
            if loaded:
                check_operating_point(s["torque_Nm"], s["pinion_rpm"])
            Misalignment.create(s["dE_mm"], s["dP_mm"], s["dG_mm"], s["dSigma_deg"])
        except ValueError as exc:
            raise ValueError(f"[scenarios] scenario {i + 1}: {exc}") from None


def set_up(study: Study) -> Problem:
    """Load the design, build the chain and check the variables against the design's
    fields and the scenarios against their ranges (before any compilation)."""
    import gearjax as gj
    from gearjax.loading.mesh_efficiency import efficiency_function
    from gearjax.studies.quantities import needs_loaded
    from gearjax.tca.result import family_of

    design = gj.load_design(study.design)
    if study.route == "line":
        return _set_up_line(study, design)
    if study.route == "kinematics":
        return _set_up_kinematics(study, design)
    loaded = needs_loaded(study.quantities)
    tca = {k: (int(v) if k != "half_pitches" else float(v)) for k, v in study.tca.items()}
    if loaded:
        comp = study.operating.get("compliance", "weber")
        chain = efficiency_function(design, side=study.side, compliance=comp,
                                    edge_softening_mm=float(study.operating.get(
                                        "edge_softening_mm", EDGE_SOFTENING_MM)), **tca)
    else:
        chain = gj.tca_function(design, side=study.side, **tca)
    pair0 = chain.pair
    for q in study.quantities:
        fams = QUANTITIES[q].families
        if fams and family_of(design).family not in fams:
            raise ValueError(f"quantity {q!r} is for {', '.join(fams)} pairs, not "
                             f"{family_of(design).family} pairs")
    if (family_of(design).family == "involute" and any(v.field.startswith("pair.")
                                                        for v in study.variables)
            and not any(c.quantity == "tooth_form_margin_mm" for c in study.constraints)):
        # the tooth form stays valid (undercut, interference, tip/fillet): a constraint,
        # since the loader's concrete checks do not run on traced values
        study = dataclasses.replace(study, constraints=study.constraints + (
            Constraint("tooth_form_margin_mm", 0.0, None, 0.1, added=True),))
    soft = float(chain.options["edge_softening_mm"]) if loaded else 0.0
    if soft > 0.0 and "edge_load_share" not in study.quantities:
        # reported: how much of the mesh stiffness the softening takes (docs/optimize.md)
        study = dataclasses.replace(study, reported=study.reported + ("edge_load_share",))
    fields, x0, lo, hi, sc = _variables(study, pair0)
    scen = _scenario_list(study)
    _check_scenarios(scen, loaded)
    prob = Problem(study, design, chain, fields, x0, lo, hi, scen, loaded, soft=soft,
                   family=family_of(design).family)
    oil = surface = None
    if loaded:
        oil = dataclasses.replace(gj.tribology.get_oil(str(study.operating["oil"])), name="")
        surface = gj.tribology.make_surface(float(study.operating["sigma_um"]))
    col = {k: jnp.array([s[k] for s in scen]) for k in scen[0]}
    mis = Misalignment(col["dE_mm"], col["dP_mm"], col["dG_mm"],
                       col["dSigma_deg"] * (math.pi / 180.0))
    return _finish(prob, pair0, sc, col, mis, oil, surface)


def _finish(prob, pair0, sc, col, mis, oil, surface) -> Problem:
    """The traced inputs and the programs of a set-up problem (both routes)."""
    study = prob.study
    prob.data = Data(pair0, jnp.asarray(prob.x0), jnp.asarray(sc), col["torque_Nm"],
                     col["pinion_rpm"], mis, oil, surface, None,
                     jnp.ones(len(study.objective)), jnp.ones(len(study.constraints)))
    prob.evaluate_program = jax.jit(evaluator(prob, hard=True),
                                    compiler_options=FAST_COMPILE_OPTIONS)
    prob.fun = _objective(prob)
    return prob


def _variables(study: Study, pair0, canonical=None):
    """``(fields, x0, lower, upper, scale)`` of the study's variables on the pytree
    ``pair0``: the fields' names there (``canonical(name)``, default the name itself),
    start values, scaled bounds and scales (one-line ValueError naming the entry)."""
    known = field_names(pair0)
    fields, x0, lo, hi, sc = [], [], [], [], []
    for i, v in enumerate(study.variables):
        name = v.field if canonical is None else canonical(v.field)
        if name not in known:
            raise ValueError(f"[[variables]] {i + 1}: field {v.field!r} is not a field of the "
                             f"design's pair (fields: {', '.join(known)})")
        if name in fields:
            raise ValueError(f"[[variables]] {i + 1}: field {v.field!r} is the field of "
                             f"[[variables]] {fields.index(name) + 1} again")
        val = float(np.asarray(get_fields(pair0, [name])[name]))
        a, b = v.bounds(val)
        if not a <= val <= b:
            raise ValueError(f"[[variables]] {i + 1} ({v.field}): the design's value "
                             f"{val / v.factor:.6g} is outside [{a / v.factor:.6g}, "
                             f"{b / v.factor:.6g}]")
        s = (b - a) / 2.0 if v.scale is None else v.scale * v.factor
        fields.append(name), x0.append(val), sc.append(s)
        lo.append((a - val) / s), hi.append((b - val) / s)
    return fields, np.array(x0), np.array(lo), np.array(hi), sc


def _with_reported(study: Study, reported) -> Study:
    """``study`` also reporting the quantities ``reported`` it does not already use."""
    return dataclasses.replace(study, reported=study.reported + tuple(
        q for q in reported if q not in study.quantities))


def _set_up_chain(study: Study, design, chain, scen: list, family: str, mis_key,
                  oil=None, surface=None) -> Problem:
    """The problem of a study on a route's own chain (line contact, kinematics):
    ``chain.pair`` the variables' pytree, ``chain.canonical`` the study's field names
    there; ``mis_key`` the scenario column traced as ``Data.mis`` (None: the route has
    none, the torque column stands in)."""
    fields, x0, lo, hi, sc = _variables(study, chain.pair, chain.canonical)
    prob = Problem(study, design, chain, fields, x0, lo, hi, scen, False, family=family,
                   route=study.route)
    col = {k: jnp.array([s.get(k, 0.0) for s in scen])
           for k in ("torque_Nm", "pinion_rpm", *scen[0])}
    return _finish(prob, chain.pair, sc, col, col[mis_key or "torque_Nm"], oil, surface)


def _set_up_line(study: Study, design) -> Problem:
    """:func:`set_up` of a line-contact study (:mod:`gearjax.studies.line_route`)."""
    from gearjax.studies.line_route import REPORTED, check_line_scenarios, line_chain
    study = _with_reported(study, REPORTED)
    chain = line_chain(design, study)
    scen = _scenario_list(study)
    oil, surface = check_line_scenarios(chain, study, scen)
    return _set_up_chain(study, design, chain, scen, "involute", "f_ma_um", oil, surface)


def _set_up_kinematics(study: Study, design) -> Problem:
    """:func:`set_up` of a kinematics study (:mod:`gearjax.studies.kinematics_route`): one
    implicit scenario."""
    from gearjax.studies.kinematics_route import REPORTED, kinematics_chain
    study = _with_reported(study, REPORTED)
    chain = kinematics_chain(design, study)
    return _set_up_chain(study, design, chain, _scenario_list(study), "hypoid", None)


def evaluator(prob: Problem, hard: bool = False, own_mask: bool = False):
    """``(u, data) -> (Q (S, nq), res, eff, Q_hard)``: the quantities at every scenario;
    with ``hard`` (a loaded study) ``Q_hard`` are the loaded quantities again with the
    hard model (no edge softening: that of ``gearjax efficiency``) on the same TCA, else
    ``Q``.  ``own_mask``: the path quantities over the evaluated design's own on-flank
    points instead of ``data.mask`` (a sweep, where no optimiser moves the points)."""
    if prob.route == "line":
        from gearjax.studies.line_route import line_evaluator
        return line_evaluator(prob)
    if prob.route == "kinematics":
        from gearjax.studies.kinematics_route import kinematics_evaluator
        return kinematics_evaluator(prob)
    chain, names, loaded = prob.chain, list(prob.fields), prob.loaded
    qnames = prob.study.quantities

    def ev(u, data):
        pair = with_scaled_fields(data.pair0, names, data.x0, data.scale, u)

        def one(T, n, mis, mask):
            if loaded:
                eff, res = chain(pair, T, n, data.oil, data.surface, mis)
            else:
                eff, res = None, chain(pair, mis)
            if own_mask:
                mask = res.on_flank
            q = quantity_values(qnames, res, eff, mask, pair)
            if not (hard and loaded):
                return q, res, eff, q
            eff_h = chain.loaded(pair, res, T, n, data.oil, data.surface, 0.0)
            return q, res, eff, quantity_values(qnames, res, eff_h, mask, pair)

        return jax.vmap(one)(data.torque, data.rpm, data.mis, data.mask)

    return ev


def combine(study: Study, Q, data):
    """``(J, g)`` of the module docstring from the quantities ``Q`` (S, nq) (traceable;
    also run eagerly on concrete values for the start and end points)."""
    qi = {q: i for i, q in enumerate(study.quantities)}
    J = 0.0
    for t, term in enumerate(study.objective):
        sign = 1.0 if term.sense == "minimize" else -1.0
        q = sign * Q[:, qi[term.quantity]] / data.term_scale[t]
        # the worst case over the scenarios: a scenario whose value is not finite (e.g. no
        # valid position of the cycle) makes it NaN, so that the line search refuses the
        # step -- smooth_max alone leaves non-finite entries out, and the optimiser then
        # lowered the worst case by emptying a scenario (docs/optimize.md)
        r = jnp.mean(q) if term.over == "mean" else jnp.where(
            jnp.all(jnp.isfinite(q)),
            smooth_max(q, jnp.ones(q.shape, bool), SCENARIO_TEMPERATURE), jnp.nan)
        J = J + term.weight * r
    g = []
    for c, con in enumerate(study.constraints):
        q = Q[:, qi[con.quantity]] / data.con_scale[c]
        if con.upper is not None:
            g.append(q - con.upper / data.con_scale[c])
        if con.lower is not None:
            g.append(con.lower / data.con_scale[c] - q)
    return J, (jnp.concatenate(g) if g else jnp.zeros((0,)))


def n_constraint_rows(prob: Problem) -> int:
    """Length of ``g`` of :func:`combine`: one row per bound of each constraint and
    scenario (given to the optimiser, which would otherwise trace the chain once more
    to find it)."""
    bounds = sum((c.upper is not None) + (c.lower is not None) for c in prob.study.constraints)
    return len(prob.scenarios) * bounds


def _objective(prob: Problem):
    """``fun(u, data) -> (J, g)`` (traceable): the function the optimisers run."""
    ev, study = evaluator(prob), prob.study

    def fun(u, data):
        return combine(study, ev(u, data)[0], data)

    return fun


def evaluate(prob: Problem, u):
    """``(Q, res, eff, Q_hard)`` at the scaled point ``u`` (concrete; the jitted evaluator
    with the hard-model re-check, :func:`evaluator`)."""
    return prob.evaluate_program(jnp.asarray(u, float), prob.data)


def set_scales(prob: Problem, Q0) -> None:
    """The terms' and constraints' default scales from the start values ``Q0``."""
    st = prob.study
    qi = {q: i for i, q in enumerate(st.quantities)}
    bad = [q for q in st.quantities if not np.all(np.isfinite(Q0[:, qi[q]]))]
    if bad:
        k = int(np.nonzero(~np.isfinite(Q0[:, qi[bad[0]]]))[0][0])
        raise ValueError(f"quantity {bad[0]!r} is not finite at the start design (scenario "
                         f"{k + 1}: {prob.scenarios[k]}); the study cannot start there")
    ts = []
    for term in st.objective:
        v = Q0[:, qi[term.quantity]]
        ref = float(np.mean(v)) if term.over == "mean" else float(np.max(np.abs(v)))
        ts.append(term.scale or (abs(ref) if abs(ref) > 1e-12 else 1.0))
    cs = []
    for con in st.constraints:
        b = con.upper if con.upper is not None else con.lower
        cs.append(con.scale or (abs(b) if abs(b) > 0.0 else 1.0))
    prob.data = prob.data._replace(term_scale=jnp.asarray(ts, float),
                                   con_scale=jnp.asarray(cs, float))


class StudyResult(NamedTuple):
    """What a study run found (:func:`run_study`); ``report`` is the JSON-ready dict."""

    u: np.ndarray
    x: np.ndarray
    end_pair: object
    end_data: dict | None
    accepted: bool
    reasons: list
    report: dict
    start: tuple
    end: tuple


def grid_size(prob: Problem) -> int:
    """Number of grid points of the study's TCA (:func:`gearjax.tca.path.pinion_angle_grid`)."""
    from gearjax.tca.result import family_of
    tca = {k: v for k, v in prob.study.tca.items()}
    o = family_of(prob.design).resolve(prob.design, tca)
    return 2 * int(round(o["half_pitches"] * o["steps_per_pitch"])) + 1


def start_point(prob: Problem):
    """The start: the fixed masks of the path quantities (the start design's on-flank
    points at each scenario) from a first evaluation, then the quantities there and
    the default scales.  Both calls run one compiled program (same shapes)."""
    u0 = np.zeros(len(prob.fields))
    if prob.route == "tca":      # the line and kinematics routes have no path mask
        prob.data = prob.data._replace(mask=jnp.ones((len(prob.scenarios), grid_size(prob)),
                                                     bool))
    out = evaluate(prob, u0)
    if any(QUANTITIES[q].path for q in prob.study.quantities):
        prob.data = prob.data._replace(mask=jnp.asarray(np.asarray(out[1].on_flank)))
        out = evaluate(prob, u0)
    set_scales(prob, np.asarray(out[0]))
    return out


def _random_starts(prob: Problem, n: int) -> np.ndarray:
    """``n`` start points: the design's own (0) and ``n - 1`` seeded uniform points in the
    bounds."""
    rng = np.random.default_rng(prob.study.seed)
    pts = rng.uniform(prob.lower, prob.upper, size=(n - 1, prob.lower.size))
    return np.vstack([np.zeros((1, prob.lower.size)), pts])


class _SlsqpResult(NamedTuple):
    x: np.ndarray
    status: int
    message: str
    evaluations: int
    iterations: int
    history_value: list
    history_feasibility: list


def quantity_jacobian(prob: Problem):
    """``(u, data) -> (dQ/du (S, nq, n), Q (S, nq))``: the quantities of the study (soft
    model) and their exact Jacobian by forward mode (``jax.jacfwd``: a study has few
    variables).  One program serves SciPy's SLSQP (which needs the Jacobian of every
    constraint) and ``gearjax sensitivity``; the same study or the same outputs, fields
    and design give the same program, so the persistent compilation cache shares it."""
    if prob.jacobian_program is None:
        ev = evaluator(prob)

        def quantity_jacobian(u, data):
            q = ev(u, data)[0]
            return q, q

        prob.jacobian_program = jax.jit(jax.jacfwd(quantity_jacobian, has_aux=True),
                                        compiler_options=FAST_COMPILE_OPTIONS)
    return prob.jacobian_program


def _run_slsqp(prob: Problem, callback):
    """SciPy's SLSQP on the same scaled problem with exact Jacobians: those of the
    quantities (:func:`quantity_jacobian`) carried through ``[J, g]`` of
    :func:`combine` by the chain rule (a small program of its own)."""
    from scipy.optimize import minimize

    study, prog = prob.study, quantity_jacobian(prob)

    def stacked(Q, data):
        J, g = combine(study, Q, data)
        return jnp.concatenate([jnp.reshape(J, (1,)), g])

    def chain_rule(dQ, Q, data):        # d[J, g]/du = d[J, g]/dQ . dQ/du
        jv = jax.vmap(lambda t: jax.jvp(lambda q: stacked(q, data), (Q,), (t,))[1],
                      in_axes=-1, out_axes=-1)
        return stacked(Q, data), jv(dQ)

    chained = jax.jit(chain_rule)

    def vj(u, data):
        dQ, Q = prog(u, data)
        return chained(dQ, Q, data)

    cache = {}
    hist_v, hist_f, count = [], [], [0]

    def at(u):
        key = np.asarray(u, float).tobytes()
        if key not in cache:
            v, jac = vj(jnp.asarray(u, float), prob.data)
            cache.clear()
            cache[key] = (np.asarray(v), np.asarray(jac))
            count[0] += 1
        return cache[key]

    def cb(u):
        v = at(u)[0]
        hist_v.append(float(v[0]))
        hist_f.append(float(max(0.0, np.max(v[1:], initial=0.0))))
        if callback is not None:
            callback(len(hist_v), v[0], hist_f[-1], np.nan)

    cons = []
    if at(np.zeros(prob.lower.size))[0].size > 1:
        cons = [{"type": "ineq", "fun": lambda u: -at(u)[0][1:],
                 "jac": lambda u: -at(u)[1][1:]}]
    r = minimize(lambda u: at(u)[0][0], np.zeros(prob.lower.size), jac=lambda u: at(u)[1][0],
                 bounds=list(zip(prob.lower, prob.upper)), constraints=cons, method="SLSQP",
                 callback=cb, options=dict(maxiter=prob.study.max_iterations,
                                           ftol=prob.study.tolerance ** 2))
    return _SlsqpResult(np.clip(r.x, prob.lower, prob.upper), int(r.status), str(r.message),
                        count[0], int(r.nit), hist_v, hist_f)


#: up to this many variables the augmented Lagrangian runs in forward mode
FORWARD_MAX_VARIABLES = 4


def derivatives(prob: Problem) -> str:
    """How the augmented Lagrangian differentiates the study: forward mode (``jacfwd``,
    one batched pass of n tangents) for several scenarios or at most
    :data:`FORWARD_MAX_VARIABLES` variables, else reverse mode (one ``value_and_grad``).
    Few variables: the forward program compiles faster and runs as fast (spur_sliding,
    2 variables, cold on 2 cores: 45 s instead of 53 s; spur_efficiency 56 s either way).
    Several scenarios: reverse mode through the scenarios' ``vmap`` returned NaN
    gradients on the preset-TE bevel pair (every quantity, also at a single batched
    scenario; unbatched and in forward mode they are finite and equal central
    differences): an open defect of the batched reverse pass, avoided here
    (docs/optimize.md)."""
    few = len(prob.fields) <= FORWARD_MAX_VARIABLES
    return "forward" if len(prob.scenarios) > 1 or few else "reverse"


def _run_al(prob: Problem, callback):
    """The augmented Lagrangian from the design (one start) or from ``starts`` points at
    once; returns the chosen run and what the starts found."""
    from gearjax.augmented_lagrangian import minimize_constrained
    st = prob.study
    kw = dict(lower=prob.lower, upper=prob.upper, args=(prob.data,),
              max_outer=st.max_iterations, tol=st.tolerance, derivatives=derivatives(prob),
              n_constraints=n_constraint_rows(prob))
    if st.starts == 1:
        return minimize_constrained(prob.fun, np.zeros(prob.lower.size), callback=callback,
                                    **kw), {"starts": 1, "derivatives": kw["derivatives"]}
    X0 = _random_starts(prob, st.starts)
    rs = jax.vmap(lambda x0: minimize_constrained(prob.fun, x0, **kw))(jnp.asarray(X0))
    feas = np.asarray(rs.feasibility) <= st.tolerance
    conv = np.asarray(rs.status) == 0
    vals = np.asarray(rs.value)
    order = np.lexsort((vals, ~feas, ~conv))    # converged, then feasible, then lowest
    best = int(order[0])
    per = [{"start": X0[i].tolist(), "value": float(vals[i]),
            "feasibility": float(np.asarray(rs.feasibility)[i]),
            "status": int(np.asarray(rs.status)[i])} for i in range(st.starts)]
    return scenario_of(rs, best), {"starts": st.starts, "best_start": best, "per_start": per,
                                 "derivatives": kw["derivatives"]}


def run_study(prob: Problem, callback=None, phase=None) -> StudyResult:
    """Run the study set up in ``prob`` (module docstring).  ``callback(k, J, feasibility,
    stationarity)`` per iteration (progress); ``phase(name)`` a context manager around
    each long step (or None)."""
    from contextlib import nullcontext
    phase = phase or (lambda name: nullcontext())
    st, t0 = prob.study, time.time()
    with phase("start design"):
        Q0, res0, eff0, H0 = start_point(prob)
    J0, g0 = combine(st, jnp.asarray(Q0), prob.data)
    with phase(f"optimising ({st.method})"):
        t1 = time.time()
        if st.method == "slsqp":
            r = _run_slsqp(prob, callback)
            u, extra = r.x, {}
            opt = {"status": "converged" if r.status == 0 else r.message,
                   "converged": r.status == 0, "message": r.message,
                   "iterations": r.iterations, "evaluations": r.evaluations}
            hist = {"objective": r.history_value, "feasibility": r.history_feasibility}
        else:
            r, extra = _run_al(prob, callback)
            u = np.asarray(r.x)
            k = int(np.asarray(r.outer_iterations))
            opt = {"status": r.message, "converged": bool(r.converged), "message": r.message,
                   "iterations": k, "evaluations": int(np.asarray(r.evaluations)),
                   "stationarity": float(np.asarray(r.stationarity)),
                   "feasibility": float(np.asarray(r.feasibility)),
                   "complementarity": float(np.asarray(r.complementarity)),
                   "multipliers": np.asarray(r.multipliers).tolist()}
            hist = {"objective": np.asarray(r.history_value)[:k].tolist(),
                    "feasibility": np.asarray(r.history_feasibility)[:k].tolist(),
                    "stationarity": np.asarray(r.history_stationarity)[:k].tolist()}
        opt.update(method=st.method, tolerance=st.tolerance, seconds=time.time() - t1, **extra)
    with phase("checking the end design"):
        Q1, res1, eff1, H1 = evaluate(prob, u)
        J1, g1 = combine(st, jnp.asarray(Q1), prob.data)
        Jh0, Jh1 = (float(combine(st, jnp.asarray(H), prob.data)[0]) for H in (H0, H1))
        x = prob.x0 + np.asarray(prob.data.scale) * u
        end_pair = with_fields(prob.data.pair0, {n: jnp.asarray(x[i])
                                                 for i, n in enumerate(prob.fields)})
        data, err, diff = end_round_trip(prob, end_pair)
        flags0, flags1 = scenario_flags(prob, res0, eff0), scenario_flags(prob, res1, eff1)
    feas = float(np.max(np.asarray(g1), initial=0.0))
    reasons = acceptance_reasons(opt, feas, st.tolerance, err, diff, x, flags0, flags1,
                                 (Jh0, Jh1) if prob.soft > 0.0 else None,
                                 (float(J0), float(J1)))
    scale = np.asarray(prob.data.scale)
    variables = [{"field": v.field, "unit": v.unit or "field",
                  "lower": (prob.x0[i] + scale[i] * prob.lower[i]) / v.factor,
                  "upper": (prob.x0[i] + scale[i] * prob.upper[i]) / v.factor,
                  "start": prob.x0[i] / v.factor, "end": x[i] / v.factor}
                 for i, v in enumerate(st.variables)]
    report = {"study": st.name, "description": st.description, "design": st.design,
              "family": prob.family, "route": prob.route, "side": st.side,
              "variables": variables,
              "scenarios": prob.scenarios,
              "edge_softening_mm": prob.soft,
              "quantities": quantities_report(prob, Q0, Q1, H0, H1),
              "objective": {"start": float(J0), "end": float(J1),
                            "start_hard_model": Jh0, "end_hard_model": Jh1,
                            "terms": [dict(t._asdict() if hasattr(t, "_asdict") else
                                           dataclasses.asdict(t),
                                           scale_used=float(prob.data.term_scale[i]))
                                      for i, t in enumerate(st.objective)]},
              "constraints": [dict(dataclasses.asdict(c),
                                   scale_used=float(prob.data.con_scale[i]))
                              for i, c in enumerate(st.constraints)],
              "max_violation": {"start": float(np.max(np.asarray(g0), initial=0.0)),
                                "end": feas},
              "optimizer": opt, "history": hist,
              "checks": {"accepted": not reasons, "reasons": reasons,
                         "round_trip_difference": diff, "flags_start": flags0,
                         "flags_end": flags1},
              "seconds": time.time() - t0}
    return StudyResult(u, x, end_pair, data, not reasons, reasons, report,
                       (Q0, res0, eff0), (Q1, res1, eff1))
