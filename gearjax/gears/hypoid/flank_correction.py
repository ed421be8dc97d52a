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

**Fit** (the family-neutral one of :mod:`gearjax.correction`, which this module feeds
with :func:`flank_deviations` as its deviation model).  The unknowns ``u`` (the chosen
settings, :data:`SETTINGS`, of each measured flank, or one value for both flanks where
the member's two machine tables are the same set-up -- identical tables -- and the
rotation :data:`ROTATION`) are scaled so that every Jacobian column has an rms of 1 um
over the grid: ``u_k = c_k x_k`` with ``c_k = 1 / rms_i(dd_i/du_k)`` (the change of
setting ``k`` that moves the flank by 1 um rms).  Levenberg-Marquardt
(:func:`gearjax.optimize.least_squares_lm`) minimises

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
import sys
from dataclasses import replace

import jax
import jax.numpy as jnp
import numpy as np

from gearjax import frames
from gearjax.correction import (DEFAULT_REGULARISATION, INDISTINCT, ROTATION,
                                CorrectionProblem, CorrectionResult, checked_settings,
                                correct_flanks, flank_increments, measured_reference_grids,
                                model_deviations, register_correction, unknown_columns)
from gearjax.gears.hypoid.design_file import (HypoidDesign, design_from_dict,
                                             flank_settings_table)
from gearjax.gears.hypoid.flank import machine_chain, point_and_first_equation
from gearjax.gears.hypoid.pair import program_pair
from gearjax.newton import newton_solve

__all__ = ["SETTINGS", "ROTATION", "DEFAULT_GENERATED", "DEFAULT_FORMATE", "INDISTINCT",
           "DEFAULT_REGULARISATION", "CorrectionProblem", "CorrectionResult",
           "line_deviations", "correction_problem", "model_deviations", "correct_flanks",
           "corrected_design", "apply_settings", "problem_on_lines", "with_setting_errors",
           "flank_deviations", "UNITS"]

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
#: default settings of a generated member (the first-order set the synthesis varies)
DEFAULT_GENERATED = ("point_radius", "blade_angle", "ratio_of_roll", "modified_roll_2c",
                     "modified_roll_6d")
#: default settings of a formate member (no roll)
DEFAULT_FORMATE = ("point_radius", "blade_angle", "cradle_angle")
_LINE_TOL = 1e-10               # mm, residual tolerance of the line intersections
#: boundary unit of each field and of the rotation
UNITS = {**{n: u for n, (_, u) in SETTINGS.items()}, ROTATION: "deg"}


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



def flank_deviations(fl, delta, points, normals, params, rotation):
    """The family's deviation model of :mod:`gearjax.correction`: :func:`line_deviations`
    of the flank ``fl`` with the increments ``delta`` (13,) of :data:`SETTINGS`
    (:func:`apply_settings`) added."""
    return line_deviations(apply_settings(fl, delta), points, normals, params, rotation)


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
    kind = "generated" if generated else "formate (no roll)"
    names = checked_settings(
        (DEFAULT_GENERATED if generated else DEFAULT_FORMATE) if settings is None else settings,
        allowed, f"the {kind} {member}")
    grids = measured_reference_grids(design, measured, flanks)
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
    data = design.data[member]
    one_setup = len(flanks) == 2 and data[flanks[0]]["machine"] == data[flanks[1]]["machine"]
    shared = set(_MACHINE_FIELDS) if one_setup else set()
    unknowns, index, M, rot = unknown_columns(flanks, FIELDS, names, shared)
    stacked = jax.tree_util.tree_map(lambda *a: jnp.stack(a), *[program_pair(s) for s in specs])
    return CorrectionProblem(design, member, flanks, measured, lines, unknowns, index, M, rot,
                             stacked, jax.tree_util.Partial(flank_deviations), FIELDS, UNITS,
                             generated, float(sign),
                             None if weight is None else np.asarray(weight, float))


def corrected_design(result: CorrectionResult, *, description: str | None = None):
    """The design with the corrections ``sign * delta`` (``-delta`` for a measurement,
    :attr:`CorrectionProblem.sign`) applied to the measured flanks' cutter
    and machine tables (file units; a flank's No. 116 dials become the geometric
    settings), validated by the family's loader.  Refused (``ValueError``) for a
    non-converged result."""
    incs = flank_increments(result)
    p = result.problem
    data = p.design.to_dict()
    for a, f in enumerate(p.flanks):
        fl = p.design.flank(p.member, f)
        table = flank_settings_table(apply_settings(fl, jnp.asarray(incs[a])))
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


register_correction(HypoidDesign, sys.modules[__name__])
