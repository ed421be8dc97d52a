"""Corrective machine settings from a measured flank (closed-loop correction).

A member's flanks are measured on a coordinate measuring machine at the nominal
points ``P_i`` of its reference grid (:meth:`HypoidDesign.reference_grid`,
:mod:`gearjax.io.measured_grid`), which reports the normal deviations ``d_i`` (um,
positive = material added, along the nominal unit normal ``n_i`` that points out of
the material).  The flank the machine cut is modelled as the flank of the nominal
settings plus unknown setting errors ``delta`` (the machine's effective settings),
seen in the measurement turned by an unknown angle ``omega`` about the member's axis
(the alignment of the part on the measuring machine: indexing and tooth-thickness
offset, which a measurement does not separate from the settings).

**Deviation model** (exact, no linearisation): the model deviation at grid point
``i`` is the parameter ``t_i`` where the line ``Rz(-omega) (P_i + t n_i)`` meets the
flank of the settings ``p + delta`` -- the point ``r_w(s, theta, psi)`` of the cutter
surface carried by the machine (:func:`gearjax.gears.hypoid.flank.chain_point`) that
satisfies the meshing equation:

    r_w(s, theta, psi; p + delta) - Rz(-omega) (P_i + t n_i) = 0      (3 equations, mm)
    n_w . dr_w/dpsi = 0   (generated)   or   psi = 0   (formate)      (1 equation)

four equations in ``(theta, s, psi, t)``, solved by :func:`gearjax.newton.newton_solve`
from the nominal point's parameters and ``t = 0`` (so that ``t(0) = 0`` exactly); its
implicit-function derivatives make ``dt/d(delta, omega)`` exact (forward mode).  The
first-order form ``t ~ n_i . (X_i(p + delta) - P_i)`` with ``X_i`` the corrected flank's
point at the same grid coordinates differs from it by the in-plane shift of the grid
point times the flank's curvature (docs/correct.md gives the numbers measured).

**Fit.**  The unknowns ``u`` (the chosen settings, :data:`SETTINGS`, of each measured
flank, or one value for both flanks where the member's two machine tables are the same
set-up -- identical tables -- and the rotation :data:`ROTATION`) are scaled so that
every Jacobian column has an rms of 1 um over the grid: ``u_k = c_k x_k`` with ``c_k =
1 / rms_i(dd_i/du_k)`` (the change of setting ``k`` that moves the flank by 1 um rms).
Levenberg-Marquardt (:func:`gearjax.optimize.least_squares_lm`) minimises

    1/2 sum_i (d_i - t_i(u))^2 / (1 um)^2  +  1/2 (alpha sqrt(N))^2 |x|^2

(``N`` grid points): Tikhonov regularisation towards zero correction, which damps the
component of ``x`` along a right singular vector ``v_k`` of the scaled Jacobian by the
filter factor ``s_k^2 / (s_k^2 + alpha^2)`` with the relative singular value ``s_k =
sigma_k / sqrt(N)`` (1 for settings acting independently, 0 for settings acting alike):
an ill-conditioned set gives the minimum-norm correction, not a wild one.  Default
``alpha`` = :data:`DEFAULT_REGULARISATION` (0.003).  Combinations with ``s_k`` below
:data:`INDISTINCT` (0.03) are reported as settings that cannot be told apart; the
condition number is ``sigma_max / sigma_min`` of the scaled Jacobian.

The correction written to the design is ``-delta`` (the next cut with the machine's
errors ``delta`` then produces the nominal flank); ``omega`` is reported, not
corrected.

Units: mm, rad inside; degrees for angles at the boundary (design-file units).
References (docs/references.md): [Artoni2008] (identification of machine settings
from flank deviations by nonlinear least squares), [Fan2008] (closed-loop corrections
of face-milled spiral bevel and hypoid gears from measured flank form errors),
[Litvin2004] ch. 21 (the generating machine); [LevenbergMarquardt] for the damped least
squares, [Hansen1998] for the Tikhonov filter factors.
"""

from __future__ import annotations

import copy

import math
import time
from dataclasses import dataclass, replace

import jax
import jax.numpy as jnp
import numpy as np

from gearjax import frames, optimize
from gearjax.errors import check_int, check_range
from gearjax.gears.hypoid.design_file import design_from_dict, flank_settings_table
from gearjax.gears.hypoid.flank import machine_chain, point_and_first_equation
from gearjax.gears.hypoid.pair import program_pair
from gearjax.io import check_on_reference
from gearjax.newton import newton_solve

__all__ = ["SETTINGS", "ROTATION", "DEFAULT_GENERATED", "DEFAULT_FORMATE", "INDISTINCT",
           "DEFAULT_REGULARISATION", "CorrectionProblem", "CorrectionResult",
           "line_deviations", "correction_problem", "model_deviations", "correct_flanks",
           "corrected_design", "apply_settings", "problem_on_lines", "with_setting_errors"]

#: correctable setting -> (design-file table, unit at the boundary); angles in degrees
SETTINGS = {
    "radial_distance": ("machine", "mm"), "cradle_angle": ("machine", "deg"),
    "tilt": ("machine", "deg"), "swivel": ("machine", "deg"),
    "blank_offset": ("machine", "mm"), "machine_root_angle": ("machine", "deg"),
    "sliding_base": ("machine", "mm"), "center_to_back": ("machine", "mm"),
    "ratio_of_roll": ("machine", "-"), "modified_roll_2c": ("machine", "1/rad"),
    "modified_roll_6d": ("machine", "1/rad^2"),
    "point_radius": ("cutter", "mm"), "blade_angle": ("cutter", "deg"),
}
FIELDS = tuple(SETTINGS)
_MACHINE_FIELDS = FIELDS[:11]
_ROLL = ("ratio_of_roll", "modified_roll_2c", "modified_roll_6d")
#: the rotation of the measured member about its axis (deg at the boundary): an unknown of
#: the measurement's alignment, reported, never written to the design
ROTATION = "axis_rotation"
#: default settings of a generated member (the first-order set the synthesis varies)
DEFAULT_GENERATED = ("point_radius", "blade_angle", "ratio_of_roll", "modified_roll_2c",
                     "modified_roll_6d")
#: default settings of a formate member (no roll)
DEFAULT_FORMATE = ("point_radius", "blade_angle", "cradle_angle")
#: relative singular value below which a combination is reported as indistinguishable
INDISTINCT = 0.03
#: Tikhonov parameter alpha (relative singular value at which a component is halved)
DEFAULT_REGULARISATION = 0.003
UM = 1e-3                       # mm
_LINE_TOL = 1e-10               # mm, residual tolerance of the line intersections
_ZERO_COLUMN = 1e-9             # um per unit: a setting that does not move the flank
_HISTORY = 201


def _to_file(name: str, v):
    """Internal value (rad for angles) -> boundary units (deg)."""
    unit = "deg" if name == ROTATION else SETTINGS[name][1]
    return math.degrees(v) if unit == "deg" else v


def _unit(name: str) -> str:
    return "deg" if name == ROTATION else SETTINGS[name][1]


def apply_settings(fl, delta):
    """FlankSpec ``fl`` with the increments ``delta`` (13,) of :data:`SETTINGS` (order of
    the dict; mm, rad, 1) added (traceable)."""
    ms = fl.machine
    kw = {n: getattr(ms, n) + delta[k] for k, n in enumerate(_MACHINE_FIELDS)}
    cut = replace(fl.cutter, point_radius=fl.cutter.point_radius + delta[11],
                  blade_angle=fl.cutter.blade_angle + delta[12])
    return replace(fl, machine=replace(ms, **kw), cutter=cut)


def _line_system(y, p):
    """Line-flank intersection (module docstring): ``y = (theta, s, psi, t)``."""
    k, P, n = p
    r, f1 = point_and_first_equation(k, y[1], y[0], y[2])
    t = y[3]
    return jnp.concatenate([r - P - t * n, f1[None]])


def line_deviations(fl, points, normals, params, rotation=0.0):
    """Normal deviations of the flank ``fl`` from nominal points (traceable, vmapped).

    ``points``, ``normals`` (..., 3): nominal points (mm) and unit normals in the work
    frame; ``params`` (..., 3): their nominal surface parameters ``(s, theta, psi)``
    (the start of each solve); ``rotation`` (rad): the flank turned by it about the work
    axis.  Returns ``(t, converged)``, ``t`` (...) mm: the signed distance along the
    normal from the nominal point to the flank ``fl`` (module docstring's equations).
    """
    k = machine_chain(fl)
    R = frames.matrix_z(-rotation)
    shape = points.shape[:-1]
    P = (points.reshape(-1, 3) @ R.T)
    n = (normals.reshape(-1, 3) @ R.T)
    prm = params.reshape(-1, 3)
    y0 = jnp.stack([prm[:, 1], prm[:, 0], prm[:, 2], jnp.zeros_like(prm[:, 0])], axis=1)

    def one(P1, n1, y1):
        return newton_solve(_line_system, y1, (k, P1, n1), tol=_LINE_TOL, noise_floor=True)

    res = jax.vmap(one)(P, n, y0)
    return res.x[:, 3].reshape(shape), res.converged.reshape(shape)


def _residual(x, aux, specs, M, rot, P, N, prm, d_mm, w, reg):
    """Scaled residuals of the fit: ``w (d - t(u)) / 1 um`` over every grid point of every
    flank (``w`` 1, or 0 for a line left out: its solve is not required to converge and
    its value does not enter), then ``reg * x``; ``u``: ``delta_f = M_f x``, ``omega =
    rot . x``."""
    delta = jnp.einsum("fkj,j->fk", M, x)
    omega = jnp.dot(rot, x)

    def one(fl, dl, P1, N1, p1):
        return line_deviations(apply_settings(fl, dl), P1, N1, p1, omega)

    t, conv = jax.vmap(one)(specs, delta, P, N, prm)
    keep = w > 0.0
    r = jnp.where(keep, w * (d_mm - t) / UM, 0.0).reshape(-1)
    return jnp.concatenate([r, reg * x]), aux, jnp.all(conv | ~keep)


@dataclass(frozen=True)
class CorrectionProblem:
    """A measured member ready to fit (concrete; :func:`correction_problem`).

    design, member, flanks; measured : the :class:`gearjax.io.MeasuredGrid`; reference
    : flank -> the design's reference :class:`gearjax.io.FlankGrid`; unknowns : names of
    the fitted unknowns (``radial_distance`` for one shared by both flanks,
    ``convex.radial_distance`` for one flank's own, ``axis_rotation``); index : their
    columns in the full unknown vector; M_unit (n_f, 13, K), rot_unit (K,): the maps
    from the full vector (internal units) to each flank's setting increments and the
    rotation; specs : the flanks' FlankSpecs stacked (program pytree); generated : the
    member's structure; sign : the correction written is ``sign * delta``; weight :
    (n_f, n_xi, n_s) 1/0, the points that enter the fit (None: all).
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
    generated: bool
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

    def args(self, scale, deviation_um, reg):
        """Traced arguments of :func:`_residual` for column scales ``scale`` (K,)."""
        g = [self.reference[f] for f in self.flanks]
        st = lambda a: jnp.asarray(np.stack([np.asarray(getattr(x, a), float) for x in g]))
        return (self.specs, jnp.asarray(self.M_unit * scale[None, None, :]),
                jnp.asarray(self.rot_unit * scale), st("points"), st("normals"), st("params"),
                jnp.asarray(np.nan_to_num(np.asarray(deviation_um, float)) * UM),
                jnp.asarray(self.mask.astype(float)), jnp.asarray(float(reg)))


def _choices(generated: bool):
    allowed = [n for n in FIELDS if generated or n not in _ROLL] + [ROTATION]
    return tuple(allowed)


def correction_problem(design, measured, settings=None) -> CorrectionProblem:
    """Check a measured grid against ``design`` and set up the fit (concrete).

    ``measured``: a :class:`gearjax.io.MeasuredGrid` (:func:`gearjax.io.read_measured_grid`);
    ``settings``: names from :data:`SETTINGS` and :data:`ROTATION` (default
    :data:`DEFAULT_GENERATED` or :data:`DEFAULT_FORMATE`).  ``ValueError`` (one line)
    for a member or flank the design lacks, an unknown or duplicated setting, a roll
    setting of a formate member, or a grid that is not the design's reference grid
    (:func:`gearjax.io.check_on_reference`)."""
    member, flanks = measured.member, tuple(measured.flanks)
    have = [f for m, f in design.flanks() if m == member]
    for f in flanks:
        if f not in have:
            raise ValueError(f"--measured {measured.path!r}: the design has no {member} {f} "
                             f"flank (it has: {', '.join(have) or 'none'})")
    specs = [design.flank(member, f) for f in flanks]
    gen = {bool(s.machine.generated) for s in specs}
    if len(gen) != 1:
        raise ValueError(f"the {member}'s flanks are one generated and one formate: measure "
                         f"and correct them one at a time")
    generated = gen.pop()
    allowed = _choices(generated)
    names = list(DEFAULT_GENERATED if generated else DEFAULT_FORMATE) if settings is None \
        else [s.strip() for s in settings]
    for n in names:
        if n not in allowed:
            kind = "generated" if generated else "formate (no roll)"
            raise ValueError(f"--settings: {n!r} is not a correctable setting of the "
                             f"{kind} {member}; allowed: {', '.join(allowed)}")
    if len(set(names)) != len(names) or not names:
        raise ValueError(f"--settings = {','.join(names)!r}: give each setting once, at least one")
    grids = {f: design.reference_grid(member, f, measured.n_xi, measured.n_s,
                                      measured.face_margin, measured.height_margin)
             for f in flanks}
    check_on_reference(measured, np.stack([np.asarray(grids[f].points) for f in flanks]),
                       np.stack([np.asarray(grids[f].normals) for f in flanks]))
    return problem_on_lines(design, measured, grids, names, specs, generated)


def problem_on_lines(design, measured, lines: dict, names, specs, generated: bool,
                     sign: float = -1.0, weight=None) -> CorrectionProblem:
    """:class:`CorrectionProblem` of the flanks ``specs`` (FlankSpecs, in the order of
    ``measured.flanks``) along given lines: ``lines`` flank -> a
    :class:`gearjax.io.FlankGrid` whose ``points``/``normals`` are the lines' origins and
    directions and whose ``params`` start each line solve on the flank (no checks;
    :func:`correction_problem` and the ease-off fit build on it).  ``sign``: the
    correction written to the design is ``sign * delta`` (-1: cancel measured errors;
    +1: produce a target); ``weight`` (n_f, n_xi, n_s) 1/0: the lines that enter."""
    member, flanks = measured.member, tuple(measured.flanks)
    n_f, nk = len(flanks), len(FIELDS)
    K = n_f * nk + 1
    M = np.zeros((n_f, nk, K))
    rot = np.zeros(K)
    rot[K - 1] = 1.0
    data = design.data[member]
    shared = n_f == 2 and data[flanks[0]]["machine"] == data[flanks[1]]["machine"]
    unknowns, index = [], []
    for n in names:
        if n == ROTATION:
            unknowns.append(n)
            index.append(K - 1)
            continue
        k = FIELDS.index(n)
        if shared and SETTINGS[n][0] == "machine":
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
    stacked = jax.tree_util.tree_map(lambda *a: jnp.stack(a), *[program_pair(s) for s in specs])
    return CorrectionProblem(design, member, flanks, measured, lines, tuple(unknowns),
                             tuple(index), M, rot, stacked, generated, float(sign),
                             None if weight is None else np.asarray(weight, float))


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
    from gearjax.errors import ConvergenceError
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
    fitted = {n: _to_file(n.split(".")[-1], delta[i]) for i, n in enumerate(names)}
    units = {n: _unit(n.split(".")[-1]) for n in names}
    correction = {n: problem.sign * v for n, v in fitted.items() if n != ROTATION}
    unc = {n: abs(_to_file(n.split(".")[-1], sd[i])) for i, n in enumerate(names)}
    scales = {n: _to_file(n.split(".")[-1], scale[idx][i]) for i, n in enumerate(names)}
    converged = status == optimize.CONVERGED
    before = np.where(problem.mask, d, np.nan)
    return CorrectionResult(problem, names, units, fitted, correction, unc, before, after, s_rel,
                            cond, combos, noise, alpha, scales, converged, status,
                            optimize.status_message(status), int(out.iterations),
                            int(out.evaluations), seconds, delta)


def corrected_design(result: CorrectionResult, *, description: str | None = None):
    """The design with the corrections ``sign * delta`` (``-delta`` for a measurement,
    :attr:`CorrectionProblem.sign`) applied to the measured flanks' cutter
    and machine tables (file units; a flank's No. 116 dials become the geometric
    settings), validated by the family's loader.  Refused (``ValueError``) for a
    non-converged result."""
    if not result.converged:
        raise ValueError(f"the correction did not converge ({result.message}): no corrected "
                         f"design is written")
    p = result.problem
    data = p.design.to_dict()
    for a, f in enumerate(p.flanks):
        fl = p.design.flank(p.member, f)
        inc = np.zeros(len(FIELDS))
        for i, col in enumerate(p.index):
            if col == len(p.rot_unit) - 1:
                continue
            inc += p.sign * p.M_unit[a, :, col] * result.delta[i]
        table = flank_settings_table(apply_settings(fl, jnp.asarray(inc)))
        data[p.member][f] = {"cutter": table["cutter"], "machine": table["machine"]}
    if description is not None:
        data["design"]["description"] = description
    return design_from_dict(data)


def with_setting_errors(design, member: str, errors: dict):
    """The design cut with setting errors: ``errors`` maps ``"flank.name"`` (one flank of
    ``member``) or ``"name"`` (both flanks) of :data:`SETTINGS` to the error in file
    units (mm, deg, 1, 1/rad, 1/rad^2), added to the member's flank tables; validated by
    the family's loader (a synthetic measurement's "machine": the perturbed design's own
    flanks are what it cut)."""
    data = copy.deepcopy(design.to_dict())
    for key, v in errors.items():
        flank, name = key.split(".", 1) if "." in key else (None, key)
        if name not in SETTINGS:
            raise ValueError(f"errors: {name!r} is not a correctable setting; allowed: "
                             f"{', '.join(SETTINGS)}")
        for f in ([flank] if flank else ["convex", "concave"]):
            table = data.get(member, {}).get(f, {}).get(SETTINGS[name][0], {})
            if name not in table:
                raise ValueError(f"errors: {key!r}: the design's [{member}.{f}."
                                 f"{SETTINGS[name][0]}] table has no {name!r}")
            table[name] += v
    return design_from_dict(data)
