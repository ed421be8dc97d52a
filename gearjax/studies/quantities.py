"""The named quantities a design study optimises or constrains (``gearjax optimize``).

Each quantity is a traceable scalar of one evaluation of the chain at one scenario
(operating point and misalignment): of the unloaded TCA (:class:`~gearjax.TCAResult`
with its kinematics) or, for the loaded ones, of the mesh-efficiency result
(:class:`~gearjax.MeshEfficiency`).  A study's objective and constraints are written
with their names (:data:`QUANTITIES`; ``gearjax optimize --quantities`` lists them).

**Smoothness.**  An optimiser needs values whose gradient does not jump where the
design moves a grid point on or off the flank.  So

* maxima and minima over the positions of a cycle are smooth (log-sum-exp)::

      smax_T(q) = T log sum_i exp(q_i / T)  >=  max_i q_i >= smax_T(q) - T log n

  with a stated temperature ``T`` per quantity (:data:`QUANTITIES`, column
  ``temperature``): the bias is at most ``T log n`` (n positions), a known amount far
  below the accuracy an engineer reads these values to;
* quantities over the contact path use the positions selected by a **fixed mask**,
  the start design's on-flank points (``mask``), so that no point enters or leaves the
  sum while the design moves; ``min_margin_mm`` (the smallest boundary margin over the
  same mask) is then the constraint that keeps those points on the flank -- a study
  that uses a path quantity gets ``min_margin_mm >= 0`` added (``gearjax.studies.
  study_file``), so the fixed mask never describes points off the flank at its end;
* the loaded cycle summaries are means over the *valid* positions, so a design whose
  contact runs off the flank under load (positions lost) can look better; the
  piecewise constant ``valid_share`` constrains that;
* ``te_ptp_arcsec`` and the loaded cycle summaries (mean loss, efficiency, loaded TE)
  are those of the chain: piecewise smooth in the design, with kinks where the TE
  envelope hands over between pairs or a position changes validity.  The end design is
  therefore re-checked with the full forward model (``study_run``), and a study that
  fails there says so.

Units: those in the names (arcsec, mm, W, MPa; ``srr`` and efficiencies are
fractions).  References: Litvin & Fuentes, "Gear Geometry and Applied Theory" (2nd
ed., 2004) for TE and the contact path; Boyd & Vandenberghe, "Convex Optimization"
(2004, ex. 3.1.5) for the log-sum-exp bound.
"""

from __future__ import annotations

from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.tca.multi_pair import interp_uniform, transfer_gaps
from gearjax.tca.path import ARCSEC

__all__ = ["Quantity", "QUANTITIES", "smooth_max", "smooth_min", "te_ptp_continuous",
           "handovers", "handover_definiteness", "quantity_values",
           "needs_loaded", "uses_mask", "start_mask", "route_of", "LINE_QUANTITIES",
           "KIN_QUANTITIES", "KIN_SRR_T", "KIN_R_EFF_T_MM", "KIN_PHI_T"]


def smooth_max(q, mask, temperature):
    """``T log sum_{mask} exp(q / T)`` (module docstring; traceable; masked entries
    and non-finite values are left out; ``-inf`` when the mask is empty)."""
    ok = mask & jnp.isfinite(q)
    qs = jnp.where(ok, q, 0.0)                     # finite everywhere: safe gradients
    m = jax.lax.stop_gradient(jnp.max(jnp.where(ok, qs, -jnp.inf)))
    m0 = jnp.where(jnp.isfinite(m), m, 0.0)
    s = jnp.sum(jnp.where(ok, jnp.exp((qs - m0) / temperature), 0.0))
    return jnp.where(jnp.any(ok), m0 + temperature * jnp.log(jnp.maximum(s, 1e-300)), -jnp.inf)


def smooth_min(q, mask, temperature):
    """``-smooth_max(-q)``: at most the minimum, by no more than ``T log n``."""
    return -smooth_max(-q, mask, temperature)


class Quantity(NamedTuple):
    """A named study quantity: ``unit``, ``loaded`` (needs the loaded chain: an
    operating point), ``path`` (computed over the fixed on-flank mask), ``temperature``
    of its smooth extremum (None: no extremum taken here), a one-line ``description``
    and ``fn(res, eff, mask, pair) -> scalar`` (``eff`` None for unloaded studies;
    ``pair`` the differentiable pair); ``families``: the families that have it (empty:
    every family); ``route``: the chain it is a quantity of, ``"tca"`` (the unloaded
    TCA and the point-contact loaded chain) or ``"line"`` (the loaded line contact of
    involute pairs with micro-geometry, :mod:`gearjax.studies.line_route`: ``res`` a
    :class:`~gearjax.gears.involute.line_load.LineLoad`, ``eff`` a
    :class:`~gearjax.gears.involute.line_efficiency.LineEfficiency` or None) or
    ``"kinematics"`` (the eigenfunction kinematics of a hypoid flank,
    :mod:`gearjax.studies.kinematics_route`: ``res`` a ``KinematicsResult``); a study
    uses one route."""

    unit: str
    loaded: bool
    path: bool
    temperature: float | None
    description: str
    fn: Callable
    families: tuple = ()
    route: str = "tca"


def _mid(res):
    return res.path.phi1.shape[0] // 2


def _path_interpolant(path, values):
    """``x -> values(x)``: quadratic interpolation of per-point ``values`` on the path's
    uniform pinion-angle grid (:func:`gearjax.tca.multi_pair.interp_uniform`)."""
    phi = path.phi1
    h = phi[1] - phi[0]
    return lambda x: interp_uniform(phi[0], h, values, x)


def handovers(res):
    """``(t, found)``: the pinion angles (rad, (2,)) where tooth pair 0 takes the load over
    from pair -1 and hands it on to pair +1, at their continuous positions (traceable).

    ``t`` solves ``TE_0(x) = TE_0(x + p)`` (entering) and ``TE_0(x) = TE_0(x - p)``
    (leaving), pair +-1 being pair 0 shifted by a pitch ``p``: three Newton steps from
    the grid's transfer angles on the quadratic interpolant of the path's TE, which
    continues past the flank boundaries.  ``found`` (no derivative): both transfers are
    on the grid, both continuous transfer gaps (:func:`gearjax.tca.multi_pair.
    transfer_gaps`) are below 0 -- the curves cross inside the flanks -- and the contact
    ratio is at least 1; otherwise (an edge hand-over, where the envelope jumps) ``t`` is
    the grid's transfer angles (0 where none is found: no NaN enters a derivative)."""
    m = res.multi
    te0 = _path_interpolant(res.path, res.path.te)

    def crossing(x, shift):
        for _ in range(3):
            d, dd = jax.jvp(lambda y: te0(y) - te0(y + shift), (x,), (jnp.ones_like(x),))
            x = x - jnp.where(dd != 0.0, d / jnp.where(dd != 0.0, dd, 1.0), 0.0)
        return x

    t_grid = jnp.nan_to_num(m.transfer_phi1)
    p = jnp.nan_to_num(m.pitch)
    t = jnp.stack([crossing(t_grid[0], p), crossing(t_grid[1], -p)])
    gaps = jnp.stack(transfer_gaps(res.path, res.margin, m))
    found = jax.lax.stop_gradient(
        jnp.all(jnp.isfinite(m.transfer_phi1)) & jnp.all(jnp.isfinite(t))
        & jnp.all(gaps < 0.0) & (m.contact_ratio >= 1.0))
    return jnp.where(found, t, t_grid), found          # no NaN in the branch not taken


def te_ptp_continuous(res):
    """Peak-to-peak of the unloaded TE envelope (arcsec) with the hand-overs at their
    continuous positions (traceable).

    The grid value ``res.ptp`` takes the envelope's extremes at grid points: its bottom
    -- where two tooth pairs hand over, between grid points -- snaps from point to point
    as the design moves, so its gradient jumps whenever the hand-over crosses one.  Here
    the bottom is pair 0's TE at the two crossings of its TE curve with those of the
    neighbouring pairs, ``TE_0(x) = TE_0(x + p)`` entering and ``TE_0(x) = TE_0(x - p)``
    leaving (pair +-1 is pair 0 shifted by a pitch ``p``; three Newton steps from the
    grid's transfer angles on the quadratic interpolant of the path's TE, which
    continues past the flank boundaries), and the top is the vertex of the parabola
    through the envelope's largest sample between the two crossings and its neighbours
    (:func:`_vertex_top`: exact for a parabolic TE, where the sample maximum errs by up
    to ``kappa h^2/8`` and its gradient jumps).  For the coast side (the envelope is the
    minimum over the pairs) top and bottom change roles.  It is the grid value where a
    transfer is not found (conjugate or touching pairs) or is not a crossing inside the
    flanks: a continuous transfer gap (:func:`gearjax.tca.multi_pair.transfer_gaps`) not
    below 0 or a contact ratio below 1 (an edge hand-over, where the envelope jumps).
    The test does not depend on where the grid falls (the crossing may lie between the
    last grid point on the flank and the flank boundary).
    """
    m = res.multi
    phi = res.path.phi1
    env = m.envelope
    ok = jnp.isfinite(env)
    sgn = m.sign          # +1 when the envelope is the maximum over the pairs
    t, found = handovers(res)
    te0 = _path_interpolant(res.path, res.path.te)
    at = jax.vmap(te0)(t)
    # min(x, y) = (x + y - |x - y|) / 2: one sign decides both weights of the derivative.
    # The two values always tie in exact arithmetic (the hand-over out of pair 0 is the
    # one into it a pitch later); jnp.minimum's tie rule compares each operand with the
    # result, and where XLA evaluated the two with different round-off (a jitted
    # reverse-mode program on an AMD EPYC CPU) the weights summed to 1/2 or 3/2.
    bottom = 0.5 * (sgn * (at[0] + at[1]) - jnp.abs(at[0] - at[1]))
    lo, up = jnp.minimum(t[0], t[1]), jnp.maximum(t[0], t[1])
    window = ok & (phi >= lo) & (phi <= up)         # pair 0 carries the load
    top = _vertex_top(sgn * env, window)
    return jnp.where(found, (top - bottom) / ARCSEC, m.ptp / ARCSEC)


def _vertex_top(f, window):
    """The top of the envelope ``f`` (rad) inside ``window``: the vertex of the parabola
    through the largest sample ``f_k`` and its neighbours,

        top = f_k + (f_{k+1} - f_{k-1})^2 / (8 (2 f_k - f_{k-1} - f_{k+1})),

    exact for a parabolic TE wherever the grid falls, so that it moves continuously
    (value and gradient) when the largest sample passes from one grid point to the next
    (the sample maximum, or a log-sum-exp of the samples at a small temperature, has a
    gradient that jumps there).  The sample maximum where a neighbour is outside the
    window or the samples do not curve downwards."""
    g = jnp.where(window, f, -jnp.inf)
    k = jnp.clip(jnp.argmax(g), 1, f.shape[0] - 2)
    a, b, c = f[k - 1], f[k], f[k + 1]
    curv = 2.0 * b - a - c
    inner = window[k - 1] & window[k] & window[k + 1] & (curv > 0.0)
    vertex = b + (c - a) ** 2 / (8.0 * jnp.where(inner, curv, 1.0))
    return jnp.where(inner & (vertex >= jnp.max(g)), vertex, jnp.max(g))


#: temperature of the smooth largest transfer gap (arcsec)
GAP_TEMPERATURE = 0.01


def _transfer_gap(res, eff, mask, pair):
    """Smooth maximum (:data:`GAP_TEMPERATURE`) of the TE gaps where tooth pair 0 enters
    and leaves the flanks (arcsec; :func:`gearjax.tca.multi_pair.transfer_gaps`): > 0
    the envelope jumps there, < 0 the curves cross inside the overlap.  NaN when either
    transfer is not found on the grid (pair 0 does not enter or leave the flanks there):
    ``smooth_max`` alone would leave that gap out (and give -inf without both), so that a
    constraint ``transfer_gap <= 0`` would read "no transfer" as satisfied; a NaN makes
    the start refuse the study and the line search refuse the step."""
    gaps = jnp.stack(transfer_gaps(res.path, res.margin, res.multi)) / ARCSEC
    return jnp.where(jnp.all(jnp.isfinite(gaps)),
                     smooth_max(gaps, jnp.ones(2, bool), GAP_TEMPERATURE), jnp.nan)


def _srr(res, mask):
    return jnp.abs(jnp.where(mask, res.kinematics.srr, 0.0))


def _mean_abs_srr(res, eff, mask, pair):
    return jnp.sum(_srr(res, mask)) / jnp.maximum(jnp.sum(mask), 1)


#: temperature of the smooth peak pressure (MPa)
P_MAX_TEMPERATURE = 5.0


def _peak_pressure(res, eff, mask, pair):
    loaded = (eff.loaded.load > 0.0) & eff.valid[None, :]
    return smooth_max(eff.loaded.p_max, loaded, P_MAX_TEMPERATURE)


QUANTITIES: dict = {
    "te_ptp_arcsec": Quantity(
        "arcsec", False, False, None,
        "peak-to-peak of the unloaded TE envelope over one pitch, hand-overs at their "
        "continuous positions (te_ptp_continuous)",
        lambda res, eff, mask, pair: te_ptp_continuous(res)),
    "te_ptp_grid_arcsec": Quantity(
        "arcsec", False, False, None,
        "peak-to-peak of the unloaded TE envelope at the grid points (as gearjax tca)",
        lambda res, eff, mask, pair: res.ptp / ARCSEC),
    "transfer_gap_arcsec": Quantity(
        "arcsec", False, False, GAP_TEMPERATURE,
        "largest TE gap where tooth pair 0 enters or leaves the flanks: > 0 a jump of the "
        "TE envelope at the transfer, < 0 the TE curves cross inside the overlap",
        _transfer_gap),
    "contact_ratio": Quantity(
        "", False, False, None, "contact ratio of the unloaded TE envelope",
        lambda res, eff, mask, pair: res.contact_ratio),
    "bearing_position": Quantity(
        "", False, False, None,
        "contact position at the reference (the family's path coordinate: face-width "
        "position xi1 of a bevel/hypoid pinion, -1 toe .. +1 heel; radius on the pinion in "
        "mm otherwise)",
        lambda res, eff, mask, pair: res.coords["path_position"][_mid(res)]),
    "margin_ref_mm": Quantity(
        "mm", False, False, None, "boundary margin of the reference contact (>= 0 on the flank)",
        lambda res, eff, mask, pair: res.margin[_mid(res)]),
    "min_margin_mm": Quantity(
        "mm", False, True, 0.05,
        "smallest boundary margin over the start design's on-flank points (smooth min)",
        lambda res, eff, mask, pair: smooth_min(res.margin, mask & res.path.converged, 0.05)),
    "mean_abs_srr": Quantity(
        "", False, True, None, "mean |slide-to-roll ratio| over the on-flank points",
        _mean_abs_srr),
    "max_abs_srr": Quantity(
        "", False, True, 0.01, "largest |slide-to-roll ratio| over the on-flank points (smooth)",
        lambda res, eff, mask, pair: smooth_max(_srr(res, mask), mask, 0.01)),
    "min_r_eff_mm": Quantity(
        "mm", False, True, 0.05,
        "smallest effective radius R_x over the on-flank points (smooth min)",
        lambda res, eff, mask, pair: smooth_min(res.kinematics.r_x, mask, 0.05)),
    "power_loss_W": Quantity(
        "W", True, False, None, "mean sliding power loss over the valid positions of a cycle",
        lambda res, eff, mask, pair: eff.power_in * (1.0 - eff.mean_efficiency)),
    "mesh_efficiency": Quantity(
        "", True, False, None, "mean mesh efficiency over the valid positions (fraction)",
        lambda res, eff, mask, pair: eff.mean_efficiency),
    "mean_mu": Quantity(
        "", True, False, None, "load- and sliding-weighted mean friction coefficient",
        lambda res, eff, mask, pair: eff.mean_mu),
    "peak_pressure_MPa": Quantity(
        "MPa", True, False, P_MAX_TEMPERATURE,
        "highest Hertz pressure over the loaded contacts (smooth max)",
        _peak_pressure),
    "edge_load_share": Quantity(
        "", True, False, None,
        "mean over the valid positions of the part of the mesh stiffness the soft active "
        "set takes away (contacts within edge_softening_mm of a flank boundary; 0 without)",
        lambda res, eff, mask, pair: jnp.sum(jnp.where(eff.valid, eff.edge_share, 0.0))
        / jnp.maximum(jnp.sum(eff.valid), 1)),
    "valid_share": Quantity(
        "", True, False, None,
        "share of the cycle's positions whose loaded result is valid (piecewise constant: "
        "a constraint >= its start value makes a step that loses positions rise the merit "
        "function, and the line search refuses it)",
        lambda res, eff, mask, pair: jnp.sum(eff.valid) / eff.valid.shape[0]),
    "loaded_te_ptp_arcsec": Quantity(
        "arcsec", True, False, None, "peak-to-peak of the loaded TE over the valid positions",
        lambda res, eff, mask, pair: eff.te_loaded_ptp / ARCSEC),
}


#: temperature of the smooth minima of the involute tooth-form margins (mm)
FORM_TEMPERATURE = 0.005
_FORM_KEYS = ("undercut1", "undercut2", "interference1", "interference2", "fillet1",
              "fillet2", "overlap")


def _form(pair, keys):
    from gearjax.gears.involute.geometry import tooth_form_margins
    m = tooth_form_margins(pair.pair)
    v = jnp.stack([m[k] for k in keys])
    return smooth_min(v, jnp.ones(v.shape, bool), FORM_TEMPERATURE)


QUANTITIES["tooth_form_margin_mm"] = Quantity(
    "mm", False, False, FORM_TEMPERATURE,
    "involute pairs: smallest margin of the tooth-form limits (undercut, involute "
    "interference, tip/fillet interference d_Nf >= d_Ff, tip overlap; smooth min; >= 0 valid)",
    lambda res, eff, mask, pair: _form(pair, _FORM_KEYS), ("involute",))
QUANTITIES["tip_thickness_mm"] = Quantity(
    "mm", False, False, FORM_TEMPERATURE,
    "involute pairs: smaller transverse tip thickness of pinion and wheel (smooth min)",
    lambda res, eff, mask, pair: _form(pair, ("tip_thickness1", "tip_thickness2")),
    ("involute",))


#: temperature of the smooth minimum of the curvature definiteness (dimensionless; the
#: minimum lies below the true one by at most T ln n)
DEFINITENESS_TEMPERATURE = 1e-4


def _min_definiteness(res, eff, mask, pair):
    from gearjax.tca.result import curvature_definiteness
    return smooth_min(curvature_definiteness(res.path), mask & res.path.converged,
                      DEFINITENESS_TEMPERATURE)


QUANTITIES["min_definiteness"] = Quantity(
    "", False, True, DEFINITENESS_TEMPERATURE,
    "smallest definiteness det B/(B_xx^2 + B_yy^2 + 2 B_xy^2) of the flanks' relative "
    "curvature over the start design's on-flank points (smooth min): about R_x/R_y where "
    "small, 0 in line contact, < 0 where the flanks cross (past an edge of regression)",
    _min_definiteness)


def handover_definiteness(res):
    """Smooth minimum (:data:`DEFINITENESS_TEMPERATURE`) of the curvature definiteness
    (:func:`gearjax.tca.result.curvature_definiteness`) at the two hand-overs of tooth
    pair 0 (:func:`handovers`: continuous positions), by quadratic interpolation of the
    per-point values (traceable; dimensionless).  Pair 0 carries the load between its
    hand-overs; on a generated flank whose path runs towards an edge of regression the
    definiteness falls along the path and passes through 0 there (docs/tca.md, "Crossing
    flanks"), so ``>= 0`` at the hand-overs keeps the load-carrying part of the path
    ahead of the crossing flanks while the path itself may run past them -- where
    ``min_definiteness`` over every on-flank point would forbid that too.  It does not see
    a minimum inside the carrying interval (the end checks' ``crossing_flanks`` flag
    does).  NaN where a transfer is not found on the grid or the path carries no
    curvatures (the step or the start is refused)."""
    from gearjax.tca.result import curvature_definiteness
    t, _ = handovers(res)
    at = jax.vmap(_path_interpolant(res.path, curvature_definiteness(res.path)))(t)
    ok = jnp.all(jnp.isfinite(res.multi.transfer_phi1)) & jnp.all(jnp.isfinite(at))
    at = jnp.where(ok, at, 0.0)
    return jnp.where(ok, smooth_min(at, jnp.ones(2, bool), DEFINITENESS_TEMPERATURE), jnp.nan)


QUANTITIES["handover_definiteness"] = Quantity(
    "", False, False, DEFINITENESS_TEMPERATURE,
    "definiteness of the flanks' relative curvature (as min_definiteness) at tooth pair "
    "0's two hand-overs (continuous positions; smooth min): >= 0 keeps the load-carrying "
    "part of the path ahead of an edge of regression",
    lambda res, eff, mask, pair: handover_definiteness(res))


QUANTITIES["bearing_reach_mm"] = Quantity(
    "mm", False, False, None,
    "VH-CATT pairs: how far the contact ellipse reaches from the face middle at the "
    "reference, |z| + semi-major (unloaded ellipse at the TCA's approach); <= b/2 keeps "
    "the bearing on the face (docs/vh_catt.md, section 6)",
    lambda res, eff, mask, pair: jnp.abs(res.path.axial1[_mid(res)])
    + res.path.semi_major[_mid(res)], ("vh_catt",))


#: temperatures of the line route's smooth extrema: loaded TE p-t-p (um), peak pressure
#: (MPa), face-load ratios (dimensionless)
LINE_TE_TEMPERATURE_UM = 0.02
LINE_P_TEMPERATURE_MPA = 3.0
LINE_RATIO_TEMPERATURE = 0.005


def _line_te_ptp(res, eff, mask, pair):
    from gearjax.gears.involute.line_load import smooth_ptp
    return smooth_ptp(res.te_loaded_um, LINE_TE_TEMPERATURE_UM)


def _cycle_face_ratio(res):
    """Load per unit face width of the cycle-mean distribution over its mean (N,): the
    ratios whose maximum is K_Hbeta ([ISO6336-1])."""
    cyc = jnp.mean(res.face_load, axis=0)
    return cyc / jnp.mean(cyc)


def _line_end_load(res, eff, mask, pair):
    r = _cycle_face_ratio(res)
    return smooth_max(jnp.stack([r[0], r[-1]]), jnp.ones(2, bool), LINE_RATIO_TEMPERATURE)


def _line_k_hbeta(res, eff, mask, pair):
    r = _cycle_face_ratio(res)
    return smooth_max(r, jnp.ones(r.shape, bool), LINE_RATIO_TEMPERATURE)


def _line_eff(eff):
    if eff is None:          # set-up refuses this: the efficiency needs rpm, oil, sigma
        raise ValueError("the line-route efficiency needs [operating] pinion_rpm, oil and "
                         "sigma_um")
    return eff


#: the quantities of the loaded line contact (route "line"): one scenario is a torque, a
#: mesh misalignment f_ma (and, for the efficiency, a speed)
LINE_QUANTITIES = {
    "line_te_ptp_um": Quantity(
        "um", False, False, LINE_TE_TEMPERATURE_UM,
        "line contact: smooth peak-to-peak of the loaded TE over the mesh cycle "
        "(T logsumexp(te/T) + T logsumexp(-te/T), above the hard p-t-p by <= 2 T ln M)",
        _line_te_ptp, route="line"),
    "line_te_ptp_hard_um": Quantity(
        "um", False, False, None,
        "line contact: peak-to-peak of the loaded TE over the mesh cycle (max - min; "
        "a kink where the extreme position changes: report or constrain, do not minimise)",
        lambda res, eff, mask, pair: jnp.max(res.te_loaded_um) - jnp.min(res.te_loaded_um),
        route="line"),
    "line_te_mean_um": Quantity(
        "um", False, False, None, "line contact: mean loaded TE over the mesh cycle (the "
        "mean approach along the line of action)",
        lambda res, eff, mask, pair: jnp.mean(res.te_loaded_um), route="line"),
    "line_p_max_MPa": Quantity(
        "MPa", False, False, LINE_P_TEMPERATURE_MPA,
        "line contact: highest Hertz pressure over the loaded slice points and positions "
        "(smooth max)",
        lambda res, eff, mask, pair: smooth_max(res.p_max, res.load > 0.0,
                                                LINE_P_TEMPERATURE_MPA), route="line"),
    "line_k_hbeta": Quantity(
        "", False, False, LINE_RATIO_TEMPERATURE,
        "line contact: face load factor K_Hbeta of the cycle-mean face-load distribution "
        "(largest load per unit face width over the mean; smooth max)",
        _line_k_hbeta, route="line"),
    "line_end_load": Quantity(
        "", False, False, LINE_RATIO_TEMPERATURE,
        "line contact: load per unit face width in the end slices over the mean, of the "
        "cycle-mean distribution (the larger end, smooth max; > 1 edge loading)",
        _line_end_load, route="line"),
    "line_power_loss_W": Quantity(
        "W", True, False, None,
        "line contact: mean sliding power loss over the mesh cycle (needs pinion_rpm, oil, "
        "sigma_um)",
        lambda res, eff, mask, pair: jnp.mean(_line_eff(eff).power_loss), route="line"),
    "line_mesh_efficiency": Quantity(
        "", True, False, None,
        "line contact: mesh efficiency over the mesh cycle (fraction; needs pinion_rpm, "
        "oil, sigma_um)",
        lambda res, eff, mask, pair: _line_eff(eff).mean_efficiency, route="line"),
}
QUANTITIES.update(LINE_QUANTITIES)

#: temperatures of the eigenfunction kinematics' smooth extrema: SRR (-), effective radius
#: (mm), eigenfunctions (-)
KIN_SRR_T = 0.002
KIN_R_EFF_T_MM = 0.02
KIN_PHI_T = 0.01


def _kin_abs_srr(res):
    """``[SRR, -SRR]`` over the grid: the smooth maximum of both is that of |SRR|."""
    s = jnp.ravel(res.f.srr)
    return jnp.concatenate([s, -s])


def _kin_normed(res, name):
    """The eigenfunction ``name`` times its sign at the grid centre (the pitch point)."""
    a = getattr(res.f, name)
    c = tuple(n // 2 for n in a.shape)
    return jnp.ravel(jax.lax.stop_gradient(jnp.sign(a[c])) * a)


def _kin_smax(x, t):
    return smooth_max(x, jnp.ones(x.shape, bool), t)


def _kin_smin(x, t):
    return smooth_min(x, jnp.ones(x.shape, bool), t)


def _kin(unit, t, text, fn):
    return Quantity(unit, False, False, t, text, lambda res, eff, mask, pair: fn(res),
                    route="kinematics")


#: the quantities of the eigenfunction kinematics of a hypoid flank (route "kinematics",
#: :mod:`gearjax.studies.kinematics_route`: ``res`` a ``KinematicsResult`` whose ``f`` are
#: the flank fields of :mod:`gearjax.studies.cutter_radius` over the grid)
KIN_QUANTITIES = {
    "kin_max_abs_srr": _kin(
        "", KIN_SRR_T, "hypoid eigenfunction kinematics: largest |SRR| over the working "
        "gear flank grid (smooth max, <= max + T ln 2n)",
        lambda r: _kin_smax(_kin_abs_srr(r), KIN_SRR_T)),
    "kin_mean_abs_srr": _kin(
        "", None, "hypoid eigenfunction kinematics: mean |SRR| over the flank grid",
        lambda r: jnp.mean(jnp.abs(r.f.srr))),
    "kin_min_r_eff_mm": _kin(
        "mm", KIN_R_EFF_T_MM, "hypoid eigenfunction kinematics: smallest effective "
        "radius R_eff over the flank grid (smooth min, >= min - T ln n)",
        lambda r: _kin_smin(jnp.ravel(r.f.r_eff), KIN_R_EFF_T_MM)),
    "kin_mean_r_eff_mm": _kin(
        "mm", None, "hypoid eigenfunction kinematics: mean effective radius over the grid",
        lambda r: jnp.mean(r.f.r_eff)),
    "kin_mean_abs_u_e": _kin(
        "mm/rad", None, "hypoid eigenfunction kinematics: mean |entrainment velocity| "
        "(per rad of pinion roll) over the grid",
        lambda r: jnp.mean(jnp.abs(r.f.u_e))),
    "kin_min_phi_I": _kin(
        "", KIN_PHI_T, "hypoid eigenfunction kinematics: smallest Phi_I (meshing limit) "
        "over the grid, times its pitch-point sign (> 0: limit off the flank; smooth min)",
        lambda r: _kin_smin(_kin_normed(r, "phi_I"), KIN_PHI_T)),
    "kin_min_phi_II": _kin(
        "", KIN_PHI_T, "hypoid eigenfunction kinematics: smallest Phi_II (curvature "
        "interference) over the grid, times its pitch-point sign (smooth min)",
        lambda r: _kin_smin(_kin_normed(r, "phi_II"), KIN_PHI_T)),
}
QUANTITIES.update(KIN_QUANTITIES)


def route_of(names) -> str:
    """The route of the quantities ``names`` (``"tca"``, ``"line"`` or ``"kinematics"``;
    all of one route, which :func:`gearjax.studies.study_file.read_study` has checked)."""
    routes = {QUANTITIES[n].route for n in names}
    return next((r for r in ("line", "kinematics") if r in routes), "tca")


def needs_loaded(names) -> bool:
    """Whether any of the quantities ``names`` needs the loaded chain."""
    return any(QUANTITIES[n].loaded for n in names)


def uses_mask(names) -> bool:
    """Whether any of ``names`` is a path quantity over the fixed on-flank mask."""
    return any(QUANTITIES[n].path for n in names)


def start_mask(res) -> np.ndarray:
    """The fixed mask of the path quantities: the on-flank points of a concrete result
    (the start design at the nominal scenario)."""
    return np.asarray(res.on_flank)


def quantity_values(names, res, eff, mask, pair):
    """``(len(names),)`` array of the quantities ``names`` (traceable)."""
    return jnp.stack([jnp.asarray(QUANTITIES[n].fn(res, eff, mask, pair), float)
                      for n in names])
