"""Public entry points of the loaded line contact (:mod:`gearjax.gears.involute.line_load`):
one operating point, and the map over a torque range and a misalignment set in one
vmapped program.

``design`` is an :class:`~gearjax.gears.involute.tca.InvoluteTCA` (no micro-geometry
unless ``mods`` is given) or an involute design file (its ``[microgeometry]`` tables
and ``[material]``).  The rack mismatches of the TCA route (``dalpha``,
``profile_crown``, ``lead_crown``) are not flank modifications of this model and are
refused; their flank-side equivalents are the micro-geometry fields.

Every input is checked before any work (one-line ``ValueError`` naming the parameter,
its value and the allowed range); the programs are jitted once per option set.
Units: N m for torques, µm for misalignments and TEs, mm, MPa.
"""

from __future__ import annotations

import dataclasses
from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.compile_ahead import call
from gearjax.errors import check_int, check_range
from gearjax.gears.involute.geometry import pair_geometry
from gearjax.gears.involute.line_efficiency import line_efficiency_traced
from gearjax.gears.involute.line_load import (LineLoad, LineLoadOptions, line_load_traced,
                                              pair_range, path_points_bound, smooth_ptp)
from gearjax.gears.involute.microgeometry import (MicroGeometry, PairModification,
                                                  check_modification)
from gearjax.loading.loaded_contact import COMPLIANCE_MODELS
from gearjax.loading.materials import pair_material

__all__ = ["line_contact", "loaded_te_map", "LoadedTEMap", "line_design", "resolution_warnings",
           "line_options", "module_coupling_length",
           "TORQUE_RANGE_NM", "MISALIGNMENT_RANGE_UM", "COUPLING_LENGTH_RANGE_MM",
           "COUPLING_LENGTH_PER_MODULE"]

#: accepted pinion torques (N m)
TORQUE_RANGE_NM = (1e-3, 1e7)
#: accepted mesh misalignments (µm)
MISALIGNMENT_RANGE_UM = (-1000.0, 1000.0)
#: accepted coupling lengths of the foundation along the face (mm; 0: Winkler)
COUPLING_LENGTH_RANGE_MM = (0.0, 1000.0)
#: recommended coupling length over the normal module (docs/microgeometry.md)
COUPLING_LENGTH_PER_MODULE = 1.0


def line_design(design, mods=None, side: str = "drive"):
    """``(pair, face_width, mods, material)`` of ``design`` for the line-contact model
    (module docstring); ``mods`` (a :class:`PairModification`) replaces the design's."""
    from gearjax.gears.involute.design_file import InvoluteFile
    from gearjax.gears.involute.tca import InvoluteTCA
    if side not in ("drive", "coast"):
        raise ValueError(f"side = {side!r} must be 'drive' or 'coast'")
    micro = None
    des = design
    if isinstance(design, InvoluteFile):
        des, micro = design.design, design.micro
    if not isinstance(des, InvoluteTCA):
        raise TypeError(f"the loaded line contact is for involute pairs, not a "
                        f"{type(design).__name__}")
    for k in ("dalpha", "profile_crown", "lead_crown"):
        v = float(getattr(des, k))
        if v != 0.0:
            raise ValueError(f"{k} = {v:g}: the line-contact model takes flank modifications "
                             "([microgeometry] / PairModification), not the rack mismatches of "
                             "the TCA route")
    if mods is None:
        mods = (micro if micro is not None else MicroGeometry.none()).flanks(side)
    if not isinstance(mods, PairModification):
        raise TypeError(f"mods must be a PairModification, not a {type(mods).__name__}")
    check_modification(mods.pinion, "pinion.")
    check_modification(mods.gear, "gear.")
    return des.pair, des.face_width, mods, pair_material(design)


#: largest part of the path of contact one slice's contact-line piece may span before
#: :func:`resolution_warnings` calls the face coarse
COARSE_SLICE_SHARE = 0.25


def resolution_warnings(design, slices, coupling_length_mm=0.0) -> list:
    """Warning lines (no output) when the face is cut too coarsely for the helix: a
    slice's contact-line piece spans ``dy tan(beta_b)`` of the path of contact, and
    beyond :data:`COARSE_SLICE_SHARE` of it the load along a line is resolved by a few
    pieces only (the results converge with more slices; docs/microgeometry.md).  With
    the slices coupled along the face (``coupling_length_mm`` > 0) also the line that
    p_max and K_Hbeta depend on the slice count: the Pasternak foundation's concentrated
    forces at the compressed ends of a line and at the start of a linear relief sit in
    single slices (:mod:`gearjax.gears.involute.face_coupling`)."""
    pair, b, _, _ = line_design(design)
    geo = pair_geometry(pair)
    out = []
    if float(coupling_length_mm) > 0.0:
        out.append(f"with the slices coupled along the face (coupling length "
                   f"{float(coupling_length_mm):g} mm) p_max and K_Hbeta hold the "
                   "foundation's concentrated end and relief-start forces in single slices "
                   f"and grow with the slice count ({int(slices)} here): compare them at the "
                   "same --slices; the loaded TE and the loads converge")
    span = float(b) / int(slices) * float(np.tan(float(geo["beta_b"])))
    path = float(geo["rho_E"] - geo["rho_A"])
    if span <= COARSE_SLICE_SHARE * path:
        return out
    need = int(np.ceil(float(b) * float(np.tan(float(geo["beta_b"])))
                       / (COARSE_SLICE_SHARE * path)))
    return out + [f"a face slice's contact line spans {span:.3g} mm of the {path:.3g} mm "
                  f"path of contact (more than {COARSE_SLICE_SHARE:g} of it): the load along "
                  f"the contact lines is coarsely resolved; use at least {need} slices"]


def line_options(pair, b, positions, slices, compliance,
                 coupling_length_mm=0.0) -> LineLoadOptions:
    """The static :class:`~gearjax.gears.involute.line_load.LineLoadOptions` of ``pair``
    (concrete; face width ``b`` mm): the checked resolution, compliance model and
    coupling length along the face (mm; 0: Winkler), the tooth pairs of
    :func:`~gearjax.gears.involute.line_load.pair_range` and the bound of the points on
    the path."""
    check_int("positions", positions, lo=4, hi=1024)
    check_int("slices", slices, lo=1, hi=400)
    if compliance not in COMPLIANCE_MODELS:
        raise ValueError(f"compliance = {compliance!r} must be one of {COMPLIANCE_MODELS}")
    lam = check_range("coupling_length_mm", coupling_length_mm, *COUPLING_LENGTH_RANGE_MM,
                      unit="mm")
    k_lo, k_hi = pair_range(pair, b)
    return LineLoadOptions(int(positions), int(slices), k_lo, k_hi, compliance,
                           path_points_bound(pair, b, int(slices)), float(lam))


def module_coupling_length(design) -> float:
    """The recommended coupling length of ``design`` (mm): :data:`COUPLING_LENGTH_PER_MODULE`
    times its normal module (the decay length of a local load along the face is of the
    order of the tooth's height; docs/microgeometry.md)."""
    pair, _, _, _ = line_design(design)
    return COUPLING_LENGTH_PER_MODULE * float(pair.module)


def _split(pair):
    """``(blank, teeth)``: the pair with tooth numbers 0 and the tooth numbers as a (2,)
    float array, so that one compiled program serves every pair of the same options
    (the tooth numbers only enter arithmetic inside the model)."""
    return (dataclasses.replace(pair, z1=0, z2=0),
            jnp.asarray(np.array([pair.z1, pair.z2], dtype=float)))


def _join(blank, teeth):
    return dataclasses.replace(blank, z1=teeth[0], z2=teeth[1])


@partial(jax.jit, static_argnames=("opts", "drive"))
def _one(blank, teeth, b, mods, T, f_ma, E, nu, opts, drive):
    return line_load_traced(_join(blank, teeth), b, mods, T, f_ma, opts, E, nu, drive)


def line_contact(design, torque_Nm, *, mods=None, misalignment_um=0.0, side="drive",
                 positions=32, slices=20, compliance="weber",
                 coupling_length_mm=0.0) -> LineLoad:
    """The loaded line contact of ``design`` at ``torque_Nm`` (pinion, N m) and mesh
    misalignment ``misalignment_um`` (µm over the face width): a
    :class:`~gearjax.gears.involute.line_load.LineLoad` over one mesh cycle
    (``positions`` per base pitch, ``slices`` across the face; ``coupling_length_mm``
    > 0: the slices of a tooth pair coupled along the face,
    :mod:`gearjax.gears.involute.face_coupling`)."""
    T = check_range("torque_Nm", torque_Nm, *TORQUE_RANGE_NM, unit="N m")
    f = check_range("misalignment_um", misalignment_um, *MISALIGNMENT_RANGE_UM, unit="um")
    pair, b, mods, mat = line_design(design, mods, side)
    opts = line_options(pair, b, positions, slices, compliance, coupling_length_mm)
    return _one(*_split(pair), b, mods, 1e3 * T, f, mat.youngs_modulus_MPa, mat.poisson,
                opts, side == "drive")


class LoadedTEMap(NamedTuple):
    """Loaded-TE summaries over torques x misalignments (shapes (T, A)).

    torque_Nm : (T,).  misalignment_um : (A,).
    te_ptp_um : peak-to-peak of the loaded TE over the cycle (µm).
    te_ptp_smooth_um : its smooth form (:func:`~gearjax.gears.involute.line_load.smooth_ptp`
        at ``temperature_um``), the one to differentiate.
    te_mean_um : mean loaded TE (µm).
    te_unloaded_ptp_um : peak-to-peak of the unloaded TE (the separation closed first,
        the approach at zero load; µm): the TCA of the modified line contact.
    p_max : highest Hertz pressure (MPa).
    k_hbeta : face load factor of the cycle-mean distribution.  end_load : end-slice
        load per unit face width over the mean, of the cycle-mean distribution.
    converged : every position of the cycle converged (and, with efficiency, every
        loaded point's friction).
    power_loss_W : mean sliding power loss over the cycle (W; NaN without ``pinion_rpm``).
    efficiency : mesh efficiency over the cycle (NaN without ``pinion_rpm``).
    """

    torque_Nm: jax.Array
    misalignment_um: jax.Array
    te_ptp_um: jax.Array
    te_ptp_smooth_um: jax.Array
    te_mean_um: jax.Array
    te_unloaded_ptp_um: jax.Array
    p_max: jax.Array
    k_hbeta: jax.Array
    end_load: jax.Array
    converged: jax.Array
    power_loss_W: jax.Array
    efficiency: jax.Array


def te_map_traced(pair, b, mods, torques_Nmm, f_ma, E, nu, opts, drive, temperature_um,
                  lube=None):
    """:class:`LoadedTEMap` fields (all but the two axes) over ``torques_Nmm`` (T,) x
    ``f_ma`` (A,) (traceable).  ``lube``: ``(pinion_rpm, oil, surface, viscosity_model,
    film_method)`` for the efficiency columns, or None."""
    def one(T, f):
        if lube is None:
            r = line_load_traced(pair, b, mods, T, f, opts, E, nu, drive)
            loss = eff = jnp.nan
            ok = jnp.all(r.converged)
        else:
            rpm, oil, surface, vm, fm = lube
            le = line_efficiency_traced(pair, b, mods, T, f, rpm, oil, surface, opts, E, nu,
                                        drive, vm, fm)
            r, loss, eff = le.loads, jnp.mean(le.power_loss), le.mean_efficiency
            ok = jnp.all(le.valid)
        te = r.te_loaded_um
        te0 = r.te_unloaded_um
        return (jnp.max(te) - jnp.min(te), smooth_ptp(te, temperature_um), jnp.mean(te),
                jnp.max(te0) - jnp.min(te0), jnp.max(r.p_max), r.k_hbeta_mean, r.end_load_mean,
                ok, loss, eff)

    return jax.vmap(lambda T: jax.vmap(lambda f: one(T, f))(f_ma))(torques_Nmm)


@partial(jax.jit, static_argnames=("opts", "drive", "vm", "fm"))
def _map(blank, teeth, b, mods, T, f_ma, E, nu, temperature_um, rpm, oil, surface, opts,
         drive, vm, fm):
    lube = None if rpm is None else (rpm, oil, surface, vm, fm)
    return te_map_traced(_join(blank, teeth), b, mods, T, f_ma, E, nu, opts, drive,
                         temperature_um, lube)


def loaded_te_map(design, torques_Nm, misalignments_um=(0.0,), *, mods=None, side="drive",
                  positions=32, slices=20, compliance="weber", temperature_um=0.01,
                  pinion_rpm=None, oil=None, surface=None, viscosity_model="roelands",
                  film_method="auto", coupling_length_mm=0.0) -> LoadedTEMap:
    """Loaded TE, peak pressure and face load factor of ``design`` over every torque
    (N m) and misalignment (µm) in one vmapped, jitted program (:class:`LoadedTEMap`);
    with ``pinion_rpm``, ``oil`` and ``surface`` also the sliding power loss and the
    mesh efficiency (:mod:`gearjax.gears.involute.line_efficiency`);
    ``coupling_length_mm`` > 0 couples the slices along the face (:func:`line_contact`)."""
    T = np.atleast_1d(np.asarray(torques_Nm, float))
    A = np.atleast_1d(np.asarray(misalignments_um, float))
    if T.ndim != 1 or T.size == 0 or A.ndim != 1 or A.size == 0:
        raise ValueError("torques_Nm and misalignments_um must be non-empty 1-D lists")
    for t in T:
        check_range("torques_Nm", t, *TORQUE_RANGE_NM, unit="N m")
    for a in A:
        check_range("misalignments_um", a, *MISALIGNMENT_RANGE_UM, unit="um")
    check_range("temperature_um", temperature_um, 0.0, 10.0, lo_open=True, unit="um")
    pair, b, mods, mat = line_design(design, mods, side)
    rpm = None
    if pinion_rpm is not None:
        from gearjax.loading.efficiency_inputs import check_efficiency_inputs
        if oil is None or surface is None:
            raise ValueError("pinion_rpm needs an oil and a surface for the efficiency")
        check_efficiency_inputs(min(float(T[0]), 1e6), pinion_rpm, oil, surface,
                                mat.e_prime_MPa, mat.poisson, compliance, viscosity_model,
                                film_method)
        rpm = float(pinion_rpm)
        oil = dataclasses.replace(oil, name="")     # the label is not part of the program
    opts = line_options(pair, b, positions, slices, compliance, coupling_length_mm)
    out = call(_map, *_split(pair), b, mods, jnp.asarray(1e3 * T), jnp.asarray(A),
               mat.youngs_modulus_MPa, mat.poisson, float(temperature_um), rpm, oil, surface,
               opts=opts, drive=side == "drive", vm=viscosity_model, fm=film_method)
    return LoadedTEMap(jnp.asarray(T), jnp.asarray(A), *out)
