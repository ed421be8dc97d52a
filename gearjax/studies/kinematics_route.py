"""The eigenfunction-kinematics route of a design study: the cutter-radius study of
[Eigenfunctions] (:mod:`gearjax.studies.cutter_radius`) as a study file.

**Model.**  The gear flank of a hypoid pair is the face-mill cutter cone placed at the
pitch point; the eigenfunctions of [Eigenfunctions] §1 give, at every point of a
``depth x face`` grid of the working gear flank, the entrainment velocity ``u_e``, the
slide-to-roll ratio ``SRR = u_s / u_e``, the effective radius ``R_eff`` (mm) and the
eigenfunctions ``Phi_I`` (meshing limit on the gear flank) and ``Phi_II`` (curvature
interference on the pinion) -- :func:`gearjax.studies.cutter_radius.flank_fields` on the
blank of the design's ``[blank]`` table (as ``gearjax kinematics`` reads it; the blank
is re-designed for every cutter radius, so ``r0`` acts through the blank and the flank).

**Variables** (:data:`KIN_FIELDS`): the fields of
:class:`~gearjax.studies.cutter_radius.StudySettings` by name -- ``cutter_radius`` (mm,
r0; start: the design's ``[blank] cutter_radius_mm``), ``blade_angle_delta`` (rad, added
to the blank's generated pressure angle; ``unit = "deg"`` gives the bounds in degrees;
start 0) and ``cutter_shift`` (mm, the cutter centre moved along ``e``; start 0).
Bounds must lie in the ranges of :meth:`StudySettings.make` (20..400 mm, +-10 deg,
+-20 mm).

**Options** (``[kinematics]``, :data:`KIN_DEFAULTS`): ``flank`` ("convex": inside
blade, drive side; "concave") and ``grid = [depth, face]`` points (each 3..201).
A kinematics study has one implicit scenario: it takes no ``[scenarios]``,
``[operating]``, ``[tca]`` or ``[line]`` table.

**Quantities** (route ``"kinematics"``, :data:`gearjax.studies.quantities.KIN_QUANTITIES`;
``n`` = grid points):
the extrema are smooth, ``smooth_max(q) = T log sum exp(q/T)`` (above the grid maximum by
at most ``T ln n``) and ``smooth_min = -smooth_max(-q)``:

    kin_max_abs_srr   = smooth_max([SRR, -SRR]), T = KIN_SRR_T    (<= max|SRR| + T ln 2n)
    kin_mean_abs_srr  = mean |SRR|
    kin_min_r_eff_mm  = smooth_min(R_eff), T = KIN_R_EFF_T_MM      (>= min R_eff - T ln n)
    kin_mean_r_eff_mm = mean R_eff
    kin_mean_abs_u_e  = mean |u_e|   (mm/rad of pinion roll)
    kin_min_phi_I     = smooth_min(s_I Phi_I),  T = KIN_PHI_T       s_I, s_II the signs
    kin_min_phi_II    = smooth_min(s_II Phi_II), T = KIN_PHI_T      at the pitch point

(the plain extrema and the pitch-point normalisation of
:func:`gearjax.studies.cutter_radius.flank_statistics`; the means of absolute values have
kinks only where a grid point's SRR or u_e crosses zero).

**Acceptance** (:func:`kinematics_flags`): the blank's Newton solve and every grid
point's meshing-equation Newton solve converged (``FlankFields.converged``) at the start
and the end.  **Design file**: the end cutter radius is written to ``[blank]
cutter_radius_mm`` and read back through the hypoid loader (:func:`kinematics_round_trip`);
``blade_angle_delta`` and ``cutter_shift`` are machine settings of the study, not
design-file fields: they are reported in the history JSON and the table (and a comment
line of the written design), not written as keys.

Units: mm, rad (deg in the file with ``unit = "deg"``), mm/rad.  References
(docs/references.md): [Eigenfunctions] §1-§3; [ISO23509] (blank).
"""

from __future__ import annotations

import copy
import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

__all__ = ["KIN_FIELDS", "KIN_DEFAULTS", "REPORTED", "KinematicsResult", "KinematicsChain", "kinematics_chain",
           "kinematics_evaluator", "kinematics_flags", "kinematics_round_trip", "check_field"]

_DEG = math.pi / 180.0
#: variable -> (lower, upper) in the field's unit (mm, rad, mm): StudySettings.make's ranges
KIN_FIELDS = {"cutter_radius": (20.0, 400.0, "mm"),
              "blade_angle_delta": (-10.0 * _DEG, 10.0 * _DEG, "rad"),
              "cutter_shift": (-20.0, 20.0, "mm")}
#: the ``[kinematics]`` table's keys and defaults (gear flank, grid depth x face points)
KIN_DEFAULTS = {"flank": "convex", "grid": (9, 7)}
#: quantities every kinematics study reports (the plain grid extremes' smooth versions)
REPORTED = ("kin_max_abs_srr", "kin_min_r_eff_mm", "kin_min_phi_I", "kin_min_phi_II")


class KinematicsResult(NamedTuple):
    """The model's output at one design: the grid's
    :class:`~gearjax.studies.cutter_radius.FlankFields` and the blank's Newton flag and
    residual."""

    f: object
    blank_converged: jax.Array
    blank_residual: jax.Array


def check_field(name: str, unit: str = "") -> None:
    """``name`` one of :data:`KIN_FIELDS` and ``unit = "deg"`` only for the blade angle;
    one-line ValueError otherwise (the caller adds the entry)."""
    if name not in KIN_FIELDS:
        raise ValueError(f"field {name!r}: a kinematics study varies the cutter settings "
                         f"({', '.join(KIN_FIELDS)})")
    if unit and name != "blade_angle_delta":
        raise ValueError(f"field {name!r}: unit = {unit!r}: only blade_angle_delta (rad) may "
                         "be given in deg")


class KinematicsChain:
    """The eigenfunction model of one hypoid design (concrete set-up): ``pair`` the
    variables' pytree ``{cutter_radius (mm), blade_angle_delta (rad), cutter_shift (mm)}``
    at the design's cutter and zero changes; ``__call__(tree) -> KinematicsResult``
    (traceable)."""

    def __init__(self, design, flank: str, grid):
        self.design, self.flank, self.grid = design, flank, tuple(int(g) for g in grid)
        self.inp = design.blank_input()
        self.pair = {"cutter_radius": jnp.asarray(float(self.inp.cutter_radius), jnp.float64),
                     "blade_angle_delta": jnp.asarray(0.0, jnp.float64),
                     "cutter_shift": jnp.asarray(0.0, jnp.float64)}
        self.options = {"flank": flank, "grid": list(self.grid)}

    @staticmethod
    def canonical(name: str) -> str:
        return name

    def __call__(self, tree) -> KinematicsResult:
        from gearjax.studies.cutter_radius import StudySettings, grid_fields
        st = StudySettings(tree["cutter_radius"], tree["blade_angle_delta"],
                           tree["cutter_shift"])
        s, f = grid_fields(self.inp, st, self.flank, self.grid, 1.0)
        return KinematicsResult(f, jnp.asarray(s.blank["converged"], jnp.float64),
                                jnp.asarray(s.blank["residual"], jnp.float64))


def kinematics_chain(design, study) -> KinematicsChain:
    """The :class:`KinematicsChain` of ``design`` for ``study``, its variables' bounds
    checked against :data:`KIN_FIELDS` (one-line ValueError naming the entry)."""
    from gearjax.gears.hypoid.design_file import HypoidDesign
    from gearjax.tca.result import family_of
    if not isinstance(design, HypoidDesign):
        fam = family_of(design).family
        raise ValueError(f"[[variables]] 1 ({study.variables[0].field}): the eigenfunction "
                         f"kinematics quantities (kin_*) are for hypoid pairs, not {fam} "
                         f"pairs ([study] design = {study.design!r})")
    inp = design.blank_input()
    if inp.method == "iso23509-method0" or float(inp.offset) <= 0.0:
        raise ValueError(f"[study] design = {study.design!r}: blank.offset_mm must be > 0: the "
                         "eigenfunction model is for hypoid pairs (offset > 0)")
    chain = KinematicsChain(design, study.kinematics["flank"], study.kinematics["grid"])
    for i, v in enumerate(study.variables):
        lo, hi, unit = KIN_FIELDS[v.field]
        a, b = v.bounds(float(chain.pair[v.field]))
        if a < lo - 1e-12 or b > hi + 1e-12:
            f = v.factor
            u = "deg" if v.unit == "deg" else unit
            raise ValueError(f"[[variables]] {i + 1} ({v.field}): bounds [{a / f:.6g}, "
                             f"{b / f:.6g}] {u} outside the setting's range [{lo / f:.6g}, "
                             f"{hi / f:.6g}] {u}")
    return chain


def kinematics_evaluator(prob):
    """``(u, data) -> (Q (1, nq), res, None, Q)``: the study's quantities at its one
    scenario (the form of the other routes' evaluators; ``res`` a
    :class:`KinematicsResult` with a leading scenario axis of length 1)."""
    from gearjax.fields import with_scaled_fields
    from gearjax.studies.quantities import quantity_values
    chain, qnames, names = prob.chain, prob.study.quantities, list(prob.fields)

    def ev(u, data):
        tree = with_scaled_fields(data.pair0, names, data.x0, data.scale, u)
        res = chain(tree)
        q = quantity_values(qnames, res, None, None, tree)[None]
        return q, jax.tree_util.tree_map(lambda a: a[None], res), None, q

    return ev


def kinematics_flags(res, k: int) -> dict:
    """Scenario ``k``'s flags: the blank and every grid point's Newton solve converged;
    ``n_valid`` the converged grid points."""
    ok = np.asarray(res.f.converged)[k]
    blank = bool(np.asarray(res.blank_converged)[k] > 0.5)
    return {"converged": bool(np.all(ok)) and blank, "blank_converged": blank,
            "n_valid": int(np.sum(ok)),
            "max_residual": float(np.max(np.abs(np.asarray(res.f.residual)[k])))}


def kinematics_round_trip(prob, end_tree):
    """The end design as a design file (the start's with ``[blank] cutter_radius_mm`` the
    end cutter radius) read back through the hypoid loader; ``(data, error or None,
    |cutter radius difference|)`` as :func:`gearjax.studies.study_run.run_study`'s
    check.  The other settings are not design-file fields (module docstring)."""
    from gearjax.io import design_from_dict
    r0 = float(np.asarray(end_tree["cutter_radius"]))
    try:
        data = copy.deepcopy(prob.design.data)
        data["blank"]["cutter_radius_mm"] = r0
        back = design_from_dict(data)
        got = float(back.blank_input().cutter_radius)
    except ValueError as exc:
        return None, str(exc), math.inf
    return data, None, abs(got - r0)
