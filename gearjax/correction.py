"""The family-neutral fit of closed-loop flank correction: setting errors from measured
normal deviations (Levenberg-Marquardt with exact Jacobians, Tikhonov-regularised).

A member's flanks are measured at the nominal points ``P_i`` (unit normals ``n_i``, out
of the material) of its reference grid (:mod:`gearjax.io.measured_grid`); the
measuring machine reports normal deviations ``d_i`` (um, positive = material added).  A
family supplies the *deviation model*: a module-level, traceable function

    deviation(spec, delta, points, normals, params, omega) -> (t, converged)

giving the signed distance ``t`` (mm) along each nominal normal from ``P_i`` to the
flank of the family's settings ``spec`` changed by the increments ``delta``
(``(n_fields,)``, internal units mm, rad, 1), turned by ``omega`` (rad) about the
member's axis -- an exact line-flank intersection solved by
:func:`gearjax.newton.newton_solve` (implicit derivatives, so ``jax.jacfwd`` of ``t``
is exact) -- and a :class:`CorrectionProblem` (its fields, the unknowns and how they map
onto each flank's increments).  The hypoid family's model is
:mod:`gearjax.gears.hypoid.flank_correction`, the VH-CATT family's
:mod:`gearjax.gears.vh_catt.flank_correction`.

**Fit.**  The unknowns ``u`` (each flank's own field, a field shared by the measured
flanks, and the rotation :data:`ROTATION`) are scaled so that every Jacobian column has
an rms of 1 um over the grid: ``u_k = c_k x_k`` with ``c_k = 1 / rms_i(dd_i/du_k)``.
Levenberg-Marquardt (:func:`gearjax.optimize.least_squares_lm`) minimises

    1/2 sum_i (d_i - t_i(u))^2 / (1 um)^2  +  1/2 (alpha sqrt(N))^2 |x|^2

(``N`` grid points): Tikhonov regularisation towards zero correction, which damps the
component of ``x`` along a right singular vector ``v_k`` of the scaled Jacobian by the
filter factor ``s_k^2 / (s_k^2 + alpha^2)`` with the relative singular value ``s_k =
sigma_k / sqrt(N)`` (1 for fields acting independently, 0 for fields acting alike).
Default ``alpha`` = :data:`DEFAULT_REGULARISATION` (0.003).  Combinations with ``s_k``
below :data:`INDISTINCT` (0.03) are reported as settings that cannot be told apart; the
condition number is ``sigma_max / sigma_min`` of the scaled Jacobian.  The correction
written to a design is ``sign * delta`` (``-delta`` for a measurement); ``omega`` is
reported, never written.

Units: mm, rad inside; degrees for angles at the boundary (design-file units).
References (docs/references.md): [Artoni2008], [Fan2008], [LevenbergMarquardt],
[Hansen1998].
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from gearjax import optimize
from gearjax.errors import ConvergenceError, check_int, check_range

__all__ = ["ROTATION", "INDISTINCT", "DEFAULT_REGULARISATION", "UM", "CorrectionProblem",
           "CorrectionResult", "checked_settings", "measured_reference_grids", "unknown_columns",
           "model_deviations", "correct_flanks",
           "flank_increments", "register_correction", "correction_family", "target_ease_off",
           "ease_off_map", "register_ease_off", "ease_off_family"]

#: the rotation of the measured member about its axis (deg at the boundary): an unknown of
#: the measurement's alignment, reported, never written to the design
ROTATION = "axis_rotation"
#: relative singular value below which a combination is reported as indistinguishable
INDISTINCT = 0.03
#: Tikhonov parameter alpha (relative singular value at which a component is halved)
DEFAULT_REGULARISATION = 0.003
UM = 1e-3                       # mm
_ZERO_COLUMN = 1e-9             # um per unit: a setting that does not move the flank
_HISTORY = 201


#: design type -> the family's module (``correction_problem``, ``corrected_design``):
#: filled by the families' correction modules when they are imported
_FAMILIES: dict = {}


def register_correction(design_type, family) -> None:
    """Register ``family`` (a module or object with ``correction_problem(design,
    measured, settings)`` and ``corrected_design(result, description=...)``) as the
    closed-loop correction of the designs of ``design_type``."""
    _FAMILIES[design_type] = family


def correction_family(design):
    """The registered correction family of ``design`` (:func:`register_correction`);
    ``ValueError`` for a design without one."""
    return _registered(_FAMILIES, design, "flank correction")


def _registered(registry: dict, design, what: str):
    """The entry of ``registry`` (design type -> family) for ``design``; ``ValueError``
    naming ``what`` for a design without one."""
    for t, fam in registry.items():
        if isinstance(design, t):
            return fam
    raise ValueError(f"no {what} is defined for {type(design).__name__} designs")


#: design type -> the family's target ease-off module (``target_ease_off``,
#: ``ease_off_problem``, ``ease_off``, ``fit_ease_off``, ``ease_off_design``,
#: ``DEFAULT_EASE_OFF_SETTINGS``): filled by the families' ease-off modules
_EASE_OFF: dict = {}


def register_ease_off(design_type, family) -> None:
    """Register ``family`` (a module with the functions listed at ``_EASE_OFF``) as the
    target ease-off fit of the designs of ``design_type`` (``gearjax ease-off``)."""
    _EASE_OFF[design_type] = family


def ease_off_family(design):
    """The registered ease-off family of ``design`` (:func:`register_ease_off`);
    ``ValueError`` for a design without one."""
    return _registered(_EASE_OFF, design, "target ease-off")


def target_ease_off(n_xi: int, n_s: int, crowning_um: float, profile_um: float,
                    bias_um: float) -> np.ndarray:
    """The quadratic ease-off target (um) on an ``n_xi`` x ``n_s`` reference grid:

        e*(u, w) = C_L u^2 + C_P w^2 + B u w

    ``u`` in [-1, 1] along the face width (the grid's ``xi`` order: toe to heel for a
    bevel pinion, -z to +z for a VH-CATT pinion), ``w`` in [-1, 1] along the height
    (root to tip): lengthwise crowning ``C_L`` at the grid's face ends, profile crowning
    ``C_P`` at its root and tip rows, bias ``B`` at its corners (um; positive = relief).
    Shared by the families' ease-off fits (:mod:`gearjax.gears.hypoid.ease_off`,
    :mod:`gearjax.gears.vh_catt.ease_off`)."""
    u = np.linspace(-1.0, 1.0, int(n_xi))[:, None]
    w = np.linspace(-1.0, 1.0, int(n_s))[None, :]
    return crowning_um * u ** 2 + profile_um * w ** 2 + bias_um * u * w


def ease_off_map(problem, values=None) -> np.ndarray:
    """Ease-off (um, (n_xi, n_s); positive = relief) of the one flank of an ease-off
    problem (a :class:`CorrectionProblem` whose lines are the conjugate flank's grid
    normals) with the changes ``values`` (unknown name -> internal units; default none:
    the design's), the rotation included: ``e_i = -t_i``, ``t_i`` the signed distance
    (mm -> um) along the conjugate's normal (out of the material) to the flank."""
    dev, _ = model_deviations(problem, values or {})
    return -dev[0]


def _to_file(unit: str, v):
    """Internal value (rad for angles) -> boundary units (deg)."""
    return math.degrees(v) if unit == "deg" else v


def _residual(x, aux, deviation, specs, M, rot, P, N, prm, d_mm, w, reg):
    """Scaled residuals of the fit: ``w (d - t(u)) / 1 um`` over every grid point of every
    flank (``w`` 1, or 0 for a line left out: its solve is not required to converge and
    its value does not enter), then ``reg * x``; ``u``: ``delta_f = M_f x``, ``omega =
    rot . x``; ``deviation``: the family's model (module docstring, a
    ``jax.tree_util.Partial``)."""
    delta = jnp.einsum("fkj,j->fk", M, x)
    omega = jnp.dot(rot, x)

    def one(sp, dl, P1, N1, p1):
        return deviation(sp, dl, P1, N1, p1, omega)

    t, conv = jax.vmap(one)(specs, delta, P, N, prm)
    keep = w > 0.0
    r = jnp.where(keep, w * (d_mm - t) / UM, 0.0).reshape(-1)
    return jnp.concatenate([r, reg * x]), aux, jnp.all(conv | ~keep)


@dataclass(frozen=True)
class CorrectionProblem:
    """A measured member ready to fit (concrete; built by a family's
    ``correction_problem``).

    design, member, flanks; measured : the :class:`gearjax.io.MeasuredGrid`; reference
    : flank -> a :class:`gearjax.io.FlankGrid` whose ``points``/``normals`` are the
    lines' origins and directions and whose ``params`` start each line solve; unknowns :
    names of the fitted unknowns (``name`` for one shared by the flanks, ``convex.name``
    for one flank's own, ``axis_rotation``); index : their columns in the full unknown
    vector; M_unit (n_f, n_fields, K), rot_unit (K,): the maps from the full vector
    (internal units) to each flank's increments and the rotation; specs : the flanks'
    settings stacked (a pytree, the ``spec`` of ``deviation``); deviation : the
    family's model (a ``jax.tree_util.Partial`` of a module-level function, module
    docstring); fields : the family's field names (the order of ``delta``); units :
    field (and :data:`ROTATION`) -> unit at the boundary ("deg" converted from rad);
    generated : the member's structure (family information); sign : the correction
    written is ``sign * delta``; weight : (n_f, n_xi, n_s) 1/0, the points that enter
    the fit (None: all).
    """

    design: object
    member: str
    flanks: tuple
    measured: object
    reference: dict
    unknowns: tuple
    index: tuple
    M_unit: np.ndarray
    rot_unit: np.ndarray
    specs: object
    deviation: object
    fields: tuple
    units: dict
    generated: bool = True
    sign: float = -1.0
    weight: object = None

    @property
    def mask(self) -> np.ndarray:
        """(n_f, n_xi, n_s) bool: the grid points that enter the fit (all for a
        measurement)."""
        shape = np.shape(self.measured.deviation_um)
        return np.ones(shape, bool) if self.weight is None else np.asarray(self.weight) > 0

    @property
    def n_points(self) -> int:
        """The number of grid points that enter the fit."""
        return int(np.sum(self.mask))

    @property
    def n_rows(self) -> int:
        return int(np.asarray(self.measured.deviation_um).size)

    def unit(self, name: str) -> str:
        """Boundary unit of an unknown (``convex.name``, ``name`` or the rotation)."""
        return self.units[name.split(".")[-1]]

    def fit(self, *, regularisation: float = DEFAULT_REGULARISATION, max_iter: int = 50):
        """:func:`correct_flanks` of this problem (the command's family-neutral entry)."""
        return correct_flanks(self, regularisation=regularisation, max_iter=max_iter)

    def args(self, scale, deviation_um, reg):
        """Traced arguments of :func:`_residual` for column scales ``scale`` (K,)."""
        g = [self.reference[f] for f in self.flanks]
        st = lambda a: jnp.asarray(np.stack([np.asarray(getattr(x, a), float) for x in g]))
        return (self.deviation, self.specs, jnp.asarray(self.M_unit * scale[None, None, :]),
                jnp.asarray(self.rot_unit * scale), st("points"), st("normals"), st("params"),
                jnp.asarray(np.nan_to_num(np.asarray(deviation_um, float)) * UM),
                jnp.asarray(self.mask.astype(float)), jnp.asarray(float(reg)))


def checked_settings(names, allowed, what: str) -> list:
    """``names`` (the ``--settings`` list) checked against ``allowed``: one-line
    ``ValueError`` naming an unknown setting (of ``what``, e.g. "the generated pinion"),
    a repeated one, or an empty list."""
    names = [s.strip() for s in names]
    for n in names:
        if n not in allowed:
            raise ValueError(f"--settings: {n!r} is not a correctable setting of {what}; "
                             f"allowed: {', '.join(allowed)}")
    if len(set(names)) != len(names) or not names:
        raise ValueError(f"--settings = {','.join(names)!r}: give each setting once, at least one")
    return names


def measured_reference_grids(design, measured, flanks) -> dict:
    """flank -> the design's reference grid of the measured member at the measurement's
    grid and margins, after :func:`gearjax.io.check_on_reference` found the measured
    points and normals on it (one-line ``ValueError`` otherwise)."""
    from gearjax.io import check_on_reference
    grids = {f: design.reference_grid(measured.member, f, measured.n_xi, measured.n_s,
                                      measured.face_margin, measured.height_margin)
             for f in flanks}
    check_on_reference(measured, np.stack([np.asarray(grids[f].points) for f in flanks]),
                       np.stack([np.asarray(grids[f].normals) for f in flanks]))
    return grids


def unknown_columns(flanks, fields, names, shared) -> tuple:
    """``(unknowns, index, M_unit, rot_unit)`` of :class:`CorrectionProblem` for the
    chosen ``names`` (fields and :data:`ROTATION`): a field in ``shared`` is one unknown
    of all measured flanks (one column moving every flank), any other one unknown per
    flank (``convex.name`` where two flanks are measured).  The full vector has one
    column per flank and field, then the rotation."""
    n_f, nk = len(flanks), len(fields)
    K = n_f * nk + 1
    M = np.zeros((n_f, nk, K))
    rot = np.zeros(K)
    rot[K - 1] = 1.0
    unknowns, index = [], []
    for n in names:
        if n == ROTATION:
            unknowns.append(n)
            index.append(K - 1)
            continue
        k = fields.index(n)
        if n in shared:
            col = k
            M[:, k, col] = 1.0
            unknowns.append(n)
            index.append(col)
        else:
            for a, f in enumerate(flanks):
                col = a * nk + k
                M[a, k, col] = 1.0
                unknowns.append(f"{f}.{n}" if n_f == 2 else n)
                index.append(col)
    return tuple(unknowns), tuple(index), M, rot


def _lm(problem: CorrectionProblem, scale, deviation_um, reg, free_x0, fixed: bool,
        max_iter: int):
    """One run of the compiled fit: ``fixed`` holds every unknown at ``free_x0`` (an
    evaluation of residuals and Jacobian)."""
    K = len(problem.rot_unit)
    x0 = np.zeros(K)
    free = np.zeros(K, bool)
    free[list(problem.index)] = True
    x0[list(problem.index)] = free_x0
    if fixed:
        lo = hi = x0
    else:
        lo = np.where(free, -np.inf, 0.0)
        hi = np.where(free, np.inf, 0.0)
    return optimize.least_squares_lm(
        _residual, jnp.asarray(x0), problem.args(scale, deviation_um, reg), aux0=jnp.zeros(()),
        lower=jnp.asarray(lo), upper=jnp.asarray(hi), atol=0.0, ftol=1e-14, gtol=1e-9,
        xtol=1e-12, maxiter=max_iter, history_size=_HISTORY)


def model_deviations(problem: CorrectionProblem, values: dict):
    """Model deviations (um, (n_f, n_xi, n_s)) and Jacobian (um per internal unit,
    (N, n_unknowns)) of the flanks with the setting errors ``values`` (unknown name ->
    internal units: mm, rad, 1) -- the fit's compiled program with every unknown held
    (concrete).  Raises ``ValueError`` for a name that is not an unknown of the problem
    and :class:`~gearjax.errors.ConvergenceError` where a line solve failed."""
    for k in values:
        if k not in problem.unknowns:
            raise ValueError(f"{k!r} is not an unknown of this problem ({problem.unknowns})")
    u = np.array([float(values.get(n, 0.0)) for n in problem.unknowns])
    K = len(problem.rot_unit)
    zero = np.zeros(np.shape(problem.measured.deviation_um))
    out = _lm(problem, np.ones(K), zero, 0.0, u, True, 1)
    if int(out.status) == optimize.FAILED:
        raise ConvergenceError("model deviations: a line-flank intersection did not converge")
    n = problem.n_rows
    dev = -np.asarray(out.residual)[:n].reshape(zero.shape)
    dev = np.where(problem.mask, dev, np.nan)
    J = -np.asarray(out.jacobian)[:n][:, list(problem.index)]
    return dev, J


@dataclass(frozen=True)
class CorrectionResult:
    """Outcome of :func:`correct_flanks` (concrete; boundary units: mm, deg, 1).

    unknowns : names; units : name -> unit; fitted : name -> fitted setting error
    ``delta`` (what the machine cut, relative to the design) and the rotation;
    correction : name -> ``sign * delta`` (``-delta`` for a measurement; settings only);
    uncertainty : name -> one standard
    deviation of ``delta`` from the residual noise (the regularised estimator's
    covariance ``s^2 (A + L)^-1 A (A + L)^-1``, ``A = J^T J``, ``L = (alpha sqrt N)^2 I``,
    ``s`` the residual rms); before_um, after_um : (n_f, n_xi, n_s) the measured
    deviations and the residual after the fit (what the corrected cut is predicted to
    leave); singular_values : relative ``s_k`` (descending); condition_number;
    indistinguishable : list of (text, s_k, {name: coefficient}); noise_um : the residual
    rms ``sqrt(|r|^2 / (N - n))``; regularisation : alpha; scales : name -> ``c_k``
    (internal units per um rms); converged, status, message, iterations, evaluations;
    seconds : wall time of the fit (the first call includes the compilation).
    """

    problem: CorrectionProblem
    unknowns: tuple
    units: dict
    fitted: dict
    correction: dict
    uncertainty: dict
    before_um: np.ndarray
    after_um: np.ndarray
    singular_values: np.ndarray
    condition_number: float
    indistinguishable: list
    noise_um: float
    regularisation: float
    scales: dict
    converged: bool
    status: int
    message: str
    iterations: int
    evaluations: int
    seconds: float
    delta: np.ndarray            # internal units, in ``unknowns`` order

    def summary(self) -> dict:
        """rms and max |deviation| (um) per flank, before and after."""
        out = {}
        for k, f in enumerate(self.problem.flanks):
            b, a = self.before_um[k], self.after_um[k]
            out[f] = {"before_rms_um": float(np.sqrt(np.nanmean(b ** 2))),
                      "before_max_um": float(np.nanmax(np.abs(b))),
                      "after_rms_um": float(np.sqrt(np.nanmean(a ** 2))),
                      "after_max_um": float(np.nanmax(np.abs(a)))}
        return out


def _combination(v, names):
    """'0.71 radial_distance - 0.70 cradle_angle' of a singular vector (terms >= 0.1)."""
    v = np.sign(v[np.argmax(np.abs(v))]) * v / np.linalg.norm(v)    # largest term > 0
    order = [i for i in np.argsort(-np.abs(v)) if abs(v[i]) >= 0.1]
    parts = []
    for m, i in enumerate(order):
        c = v[i]
        sign = ("-" if c < 0 else "") if m == 0 else (" - " if c < 0 else " + ")
        parts.append(f"{sign}{abs(c):.2f} {names[i]}")
    return "".join(parts), {names[i]: float(v[i]) for i in order}


def correct_flanks(problem: CorrectionProblem, *,
                   regularisation: float = DEFAULT_REGULARISATION,
                   max_iter: int = 50) -> CorrectionResult:
    """Fit the setting errors of ``problem`` (module docstring) by Levenberg-Marquardt
    with exact Jacobians (concrete).  ``regularisation``: alpha in [0, 1];
    ``max_iter``: accepted steps at most (1..200).  The result carries ``converged``
    and ``status``; a non-converged fit is returned flagged, never as converged."""
    alpha = check_range("regularisation", regularisation, 0.0, 1.0)
    max_iter = check_int("max_iter", max_iter, 1, _HISTORY - 1)
    d = np.asarray(problem.measured.deviation_um, float)
    if not np.all(np.isfinite(d[problem.mask])):
        raise ValueError(f"--measured {problem.measured.path!r}: deviations missing (a "
                         f"reference grid without measured deviations)")
    t0 = time.perf_counter()
    K = len(problem.rot_unit)
    idx = list(problem.index)
    names = problem.unknowns
    # column scales: the change of each unknown that moves the flanks by 1 um rms
    _, J0 = model_deviations(problem, {})
    N = problem.n_points
    rows = problem.n_rows
    rms = np.sqrt(np.sum(J0 ** 2, axis=0) / N)
    dead = [names[i] for i in range(len(names)) if not rms[i] > _ZERO_COLUMN]
    if dead:
        raise ValueError(f"--settings: {', '.join(dead)} does not change the measured "
                         f"{problem.member} flank(s) (zero Jacobian column, e.g. the swivel "
                         f"at zero tilt); leave it out")
    scale = np.ones(K)
    scale[idx] = 1.0 / rms
    reg = alpha * math.sqrt(N)
    out = _lm(problem, scale, d, reg, np.zeros(len(idx)), False, max_iter)
    jax.block_until_ready(out.x)
    seconds = time.perf_counter() - t0
    status = int(out.status)
    x = np.asarray(out.x)[idx]
    delta = x * scale[idx]
    r = np.asarray(out.residual)[:rows]
    after = np.where(problem.mask, r.reshape(d.shape), np.nan)
    Js = np.asarray(out.jacobian)[:rows][:, idx]       # d r / d x  (= -d t / d x, um)
    sv, V = np.linalg.svd(Js, full_matrices=False)[1:]
    s_rel = sv / math.sqrt(N)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    combos = []
    for k in range(len(s_rel)):
        if s_rel[k] < INDISTINCT:
            text, coef = _combination(V[k], names)
            combos.append((text, float(s_rel[k]), coef))
    dof = max(N - len(idx), 1)
    noise = float(np.sqrt(np.sum(r ** 2) / dof))
    A = Js.T @ Js
    B = np.linalg.pinv(A + reg ** 2 * np.eye(len(idx)))
    cov = noise ** 2 * B @ A @ B
    sd = np.sqrt(np.maximum(np.diag(cov), 0.0)) * scale[idx]
    units = {n: problem.unit(n) for n in names}
    fitted = {n: _to_file(units[n], delta[i]) for i, n in enumerate(names)}
    correction = {n: problem.sign * v for n, v in fitted.items() if n != ROTATION}
    unc = {n: abs(_to_file(units[n], sd[i])) for i, n in enumerate(names)}
    scales = {n: _to_file(units[n], scale[idx][i]) for i, n in enumerate(names)}
    converged = status == optimize.CONVERGED
    before = np.where(problem.mask, d, np.nan)
    return CorrectionResult(problem, names, units, fitted, correction, unc, before, after, s_rel,
                            cond, combos, noise, alpha, scales, converged, status,
                            optimize.status_message(status), int(out.iterations),
                            int(out.evaluations), seconds, delta)


def flank_increments(result: CorrectionResult) -> np.ndarray:
    """(n_f, n_fields) the increments ``sign * delta`` of each measured flank's fields
    (internal units; the rotation left out): what a family's ``corrected_design``
    writes.  Refused (``ValueError``) for a non-converged result."""
    if not result.converged:
        raise ValueError(f"the correction did not converge ({result.message}): no corrected "
                         f"design is written")
    p = result.problem
    inc = np.zeros(p.M_unit.shape[:2])
    for i, col in enumerate(p.index):
        if col == len(p.rot_unit) - 1:
            continue
        inc += p.sign * p.M_unit[:, :, col] * result.delta[i]
    return inc
