"""Cutter and blade corrections of a VH-CATT member from a measured flank (closed loop).

A member's flanks are measured at the nominal points ``P_i`` (unit normals ``n_i`` out
of the tooth) of its reference grid (:meth:`VHCattDesign.reference_grid`, body frame of
the member); the measuring machine reports the normal deviations ``d_i`` (um, positive =
material added).  The flank the head cut is modelled as the flank of the design's head
with unknown errors ``delta`` of its *correctable fields* (:data:`FIELDS`), turned by an
unknown angle ``omega`` about the member's axis (the part's alignment):

* ``cutter_radius`` (mm): the nominal radius ``R_T`` of the member's head
  (``cutter_radius1`` / ``cutter_radius2``), one value for both flanks;
* ``blade_offset`` (mm): the blade offset ``e`` of the member's head, one value for
  both flanks (the pair's ``blade_offset_mm``, or the member's own ``[pinion]`` /
  ``[gear]`` ``blade_offset_mm``);
* ``blade_angle`` (deg at the boundary): the profile angle of the blade that cuts each
  flank (``convex.blade_angle``, ``concave.blade_angle``: the member's
  ``convex_blade_angle_deg`` / ``concave_blade_angle_deg``).

The other member is never changed: every field is the member's own (per-member keys of
the design file, :mod:`gearjax.gears.vh_catt.design_file`).

**Deviation model** (exact): with the blade cone ``c(u, v)`` of the flank's head
carried by the generating roll, ``r_w(u, v, psi) = Rz(-psi) [c(u, v) - (r psi, 0, 0)]``
(:func:`gearjax.gears.vh_catt.geometry.tool_family`; its trace radius ``rho_0 = R_T - h
sigma (w/2 + e)`` and blade angle ``alpha``), the model deviation at grid point ``i`` is
the ``t`` that solves

    r_w(u, v, psi; p + delta) - Rz(-omega) (P_i + t n_i) = 0      (3 equations, mm)
    n_w . dr_w/dpsi = 0                                          (meshing equation)

four equations in ``(u, v, psi, t)``, solved by :func:`gearjax.newton.newton_solve`
from the nominal point's ``(u, v, psi)`` and ``t = 0`` (so ``t(0) = 0`` exactly); its
implicit-function derivatives make ``dt/d(delta, omega)`` exact, and the fit's
``jax.jacfwd`` forms the Jacobian.  The fit itself (scaling, Tikhonov regularisation,
condition number, indistinguishable combinations, uncertainties) is the family-neutral
one of :mod:`gearjax.correction`.

**What the fields do** (the family's geometry): a flank keeps its middle-section point
whatever ``R_T`` and ``e`` are (the head is re-positioned), so both act on a flank only
through its trace radius ``rho_0``: the lengthwise crowning ``~ z^2 / (2 rho_0)``, about
0.4 um per mm of ``R_T`` at 80 % of the half face of the 17/23 example.  ``R_T`` moves
both flanks' ``rho_0`` alike and ``e`` in opposite senses, so with both flanks measured
they are told apart, with one flank they are the same unknown (reported as
indistinguishable).  The blade angle tilts the profile; the rotation moves both flanks
by ``~ r omega cos(alpha)`` with opposite signs of the normal deviation.

Units: mm, rad inside; degrees for angles at the boundary.  References
(docs/references.md): [VH-CATT], [Fan2008], [Artoni2008].
"""

from __future__ import annotations

import copy
import math
import sys
from typing import NamedTuple

import jax
import jax.numpy as jnp

from gearjax import frames
from gearjax.correction import (ROTATION, CorrectionProblem, checked_settings, flank_increments,
                                measured_reference_grids, register_correction,
                                unknown_columns)
from gearjax.gears.vh_catt.design_file import VHCattDesign, design_from_dict, flank_sigma
from gearjax.gears.vh_catt.geometry import HANDS, MEMBERS, tool_data, tool_family
from gearjax.newton import newton_solve
from gearjax.surfaces import meshing_function

__all__ = ["FIELDS", "UNITS", "SHARED", "DEFAULT_SETTINGS", "FlankSetup", "flank_setup",
           "flank_deviations", "correction_problem", "corrected_design",
           "with_setting_errors", "member_fields", "with_member_fields"]

#: the correctable fields of a member, in the order of a flank's increments ``delta``
FIELDS = ("cutter_radius", "blade_offset", "blade_angle")
#: boundary unit of each field and of the rotation
UNITS = {"cutter_radius": "mm", "blade_offset": "mm", "blade_angle": "deg", ROTATION: "deg"}
#: fields of the member's head: one unknown for both flanks
SHARED = frozenset({"cutter_radius", "blade_offset"})
#: default unknowns: every field and the measurement's rotation (all told apart when both
#: flanks are measured; docs/correct.md)
DEFAULT_SETTINGS = FIELDS + (ROTATION,)
_LINE_TOL = 1e-10               # mm, residual tolerance of the line intersections


class FlankSetup(NamedTuple):
    """The settings of one flank's cut (a pytree of float64 scalars): module (mm),
    blade angle alpha (rad), cutter radius R_T (mm), blade offset e (mm), teeth, hand
    h, side sigma."""

    module: jax.Array
    alpha: jax.Array
    cutter_radius: jax.Array
    blade_offset: jax.Array
    teeth: jax.Array
    hand: jax.Array
    sigma: jax.Array


def flank_setup(pair, member: str, flank: str) -> FlankSetup:
    """:class:`FlankSetup` of ``flank`` of ``member`` with the member's own blade
    settings (:func:`gearjax.gears.vh_catt.geometry.member_tool`)."""
    i = MEMBERS.index(member)
    f = 0 if flank == "convex" else 1
    a = jnp.asarray
    return FlankSetup(a(pair.module, float), a(pair.pressure_angle + pair.blade_angle_delta[i, f]),
                      a(pair.cutter_radius(member), float),
                      a(pair.blade_offset + pair.blade_offset_delta[i]),
                      a(float(pair.teeth(member))), a(HANDS[member]),
                      a(float(flank_sigma(member, flank))))


def _line_system(y, p):
    """Line-flank intersection (module docstring): ``y = (u, v, psi, t)``."""
    k, P, n = p
    uv, psi = y[:2], y[2]
    r = tool_family(k, uv, psi)
    f = meshing_function(jax.tree_util.Partial(tool_family, k), uv, psi)
    return jnp.concatenate([r - P - y[3] * n, f[None]])


def flank_deviations(spec: FlankSetup, delta, points, normals, params, rotation):
    """Normal deviations of the flank ``spec`` with the increments ``delta`` (3,) of
    :data:`FIELDS` (mm, mm, rad) from nominal points (traceable, vmapped): the deviation
    model of :mod:`gearjax.correction`.

    ``points``, ``normals`` (..., 3): nominal points (mm) and unit normals in the body
    frame; ``params`` (..., 3): their nominal ``(u, v, psi)`` (the start of each solve);
    ``rotation`` (rad): the flank turned by it about the member's axis.  Returns ``(t,
    converged)``, ``t`` (...) mm: the signed distance along the normal from the nominal
    point to the flank (module docstring's equations).
    """
    k = tool_data(spec.module, spec.alpha + delta[2], spec.cutter_radius + delta[0],
                  spec.teeth, spec.hand, spec.sigma, spec.blade_offset + delta[1])
    R = frames.matrix_z(-rotation)
    shape = points.shape[:-1]
    P = points.reshape(-1, 3) @ R.T
    n = normals.reshape(-1, 3) @ R.T
    prm = params.reshape(-1, 3)
    y0 = jnp.concatenate([prm, jnp.zeros_like(prm[:, :1])], axis=1)

    def one(P1, n1, y1):
        return newton_solve(_line_system, y1, (k, P1, n1), tol=_LINE_TOL, noise_floor=True)

    res = jax.vmap(one)(P, n, y0)
    return res.x[:, 3].reshape(shape), res.converged.reshape(shape)


def correction_problem(design, measured, settings=None) -> CorrectionProblem:
    """Check a measured grid against the VH-CATT ``design`` and set up the fit (concrete).

    ``measured``: a :class:`gearjax.io.MeasuredGrid`; ``settings``: names from
    :data:`FIELDS` and ``axis_rotation`` (default :data:`DEFAULT_SETTINGS`).
    ``ValueError`` (one line) for an unknown or duplicated setting or a grid that is not
    the design's reference grid (:func:`gearjax.io.check_on_reference`)."""
    member, flanks = measured.member, tuple(measured.flanks)
    names = checked_settings(DEFAULT_SETTINGS if settings is None else settings,
                             FIELDS + (ROTATION,), f"the VH-CATT {member}")
    grids = measured_reference_grids(design, measured, flanks)
    unknowns, index, M, rot = unknown_columns(flanks, FIELDS, names, SHARED)
    specs = [flank_setup(design.pair, member, f) for f in flanks]
    stacked = jax.tree_util.tree_map(lambda *a: jnp.stack(a), *specs)
    return CorrectionProblem(design, member, flanks, measured, grids, unknowns, index, M, rot,
                             stacked, jax.tree_util.Partial(flank_deviations), FIELDS, UNITS)


def member_fields(design, member: str) -> dict:
    """The member's correctable fields in file units: ``cutter_radius`` (mm),
    ``blade_offset`` (mm), ``convex.blade_angle``, ``concave.blade_angle`` (deg)."""
    pair = design.pair
    i = MEMBERS.index(member)
    out = {"cutter_radius": float(pair.cutter_radius(member)),
           "blade_offset": float(pair.blade_offset + pair.blade_offset_delta[i])}
    for f, fl in enumerate(("convex", "concave")):
        out[f"{fl}.blade_angle"] = math.degrees(float(pair.pressure_angle
                                                      + pair.blade_angle_delta[i, f]))
    return out


def with_member_fields(design, member: str, values: dict, description=None):
    """The design with the member's fields ``values`` (keys of :func:`member_fields`,
    file units) written to its file tables, validated by the family's loader."""
    data = copy.deepcopy(design.to_dict())
    for key, v in values.items():
        if key == "cutter_radius":
            data["pair"][f"cutter_radius{1 if member == 'pinion' else 2}_mm"] = float(v)
        elif key == "blade_offset":
            data.setdefault(member, {})["blade_offset_mm"] = float(v)
        else:
            flank = key.split(".")[0]
            data.setdefault(member, {})[f"{flank}_blade_angle_deg"] = float(v)
    if description is not None:
        data["design"]["description"] = description
    return design_from_dict(data)


def corrected_design(result, *, description: str | None = None):
    """The design with the corrections ``sign * delta`` (``-delta`` for a measurement)
    written to the measured member's fields: ``[pair] cutter_radius1_mm`` (pinion) or
    ``cutter_radius2_mm`` (gear), ``[pinion]``/``[gear]`` ``blade_offset_mm``,
    ``convex_blade_angle_deg``, ``concave_blade_angle_deg`` (only the fitted ones; the
    other member untouched), validated by the family's loader.  Refused
    (``ValueError``) for a non-converged result."""
    inc = flank_increments(result)
    p = result.problem
    now = member_fields(p.design, p.member)
    fitted = {n.split(".")[-1] for n in p.unknowns if n != ROTATION}
    values = {}
    for k, name in enumerate(FIELDS):
        if name not in fitted:
            continue
        if name in SHARED:
            values[name] = now[name] + float(inc[0, k])
        else:
            for a, f in enumerate(p.flanks):
                values[f"{f}.{name}"] = now[f"{f}.{name}"] + math.degrees(float(inc[a, k]))
    return with_member_fields(p.design, p.member, values, description)


def with_setting_errors(design, member: str, errors: dict):
    """The design cut with errors of the member's fields: ``errors`` maps
    ``cutter_radius``, ``blade_offset`` (mm), ``blade_angle`` (deg, both flanks) or
    ``convex.blade_angle`` / ``concave.blade_angle`` (one flank) to the error in file
    units, added to the member's fields (a synthetic measurement's "machine");
    validated by the family's loader."""
    now = member_fields(design, member)
    values = {}
    for key, v in errors.items():
        flank, name = key.split(".", 1) if "." in key else (None, key)
        if name not in FIELDS or (flank is not None and (name in SHARED or flank not in
                                                           ("convex", "concave"))):
            raise ValueError(f"errors: {key!r} is not a field of the member; allowed: "
                             f"cutter_radius, blade_offset, blade_angle, convex.blade_angle, "
                             f"concave.blade_angle")
        if name in SHARED:
            values[name] = now[name] + float(v)
        else:
            for f in ([flank] if flank else ["convex", "concave"]):
                k = f"{f}.{name}"
                values[k] = values.get(k, now[k]) + float(v)
    return with_member_fields(design, member, values)


register_correction(VHCattDesign, sys.modules[__name__])
