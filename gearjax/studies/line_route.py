"""The loaded line-contact route of a design study: micro-geometry fields of an involute
pair as variables, its loaded TE, pressure, face load and efficiency as quantities.

**Variables.**  A micro-geometry field is named as the design file writes it,
``microgeometry.TABLE.KEY`` (``[microgeometry.TABLE] KEY = value``): ``TABLE`` one of
:data:`~gearjax.gears.involute.design_file.MICRO_TABLES` -- ``pinion`` or ``gear`` (both
flanks of that member) or ``pinion_drive``, ``pinion_coast``, ``gear_drive``,
``gear_coast`` (one flank) -- and ``KEY`` one of :data:`~gearjax.gears.involute.
design_file.MICRO_KEYS` (amounts in µm, lengths in mm: ``tip_relief_um``,
``tip_relief_length_mm``, ``lead_crowning_um``, ``helix_slope_um``, ...).  The relief
shapes (linear, parabolic) are the design's, not variables.  The model sees the flank in
mesh on the study's side; a member table moves both flanks of the member (the design
file's meaning, so the written design has one ``[microgeometry.pinion]`` table), a flank
table must name the study's side.  Bounds must lie in the key's range
(:data:`~gearjax.gears.involute.microgeometry.FIELD_UNITS`) and a relief length's lower
bound be > 0 mm.

**Scenarios.**  Every combination of ``torque_Nm`` (pinion, N m), ``f_ma_um`` (the mesh
misalignment across the face width, µm, ISO 6336-1) and ``pinion_rpm`` (only with the
efficiency quantities) is one evaluation of
:func:`~gearjax.gears.involute.line_load.line_load_traced` -- or
:func:`~gearjax.gears.involute.line_efficiency.line_efficiency_traced` when a power loss
or an efficiency is asked for -- all in one ``vmap``: the loaded line contact of
``gearjax loaded`` (:func:`~gearjax.gears.involute.loaded_lines.loaded_te_map` maps the
same functions over a torque x misalignment grid), at ``[line] positions`` mesh
positions per base pitch and ``slices`` face slices.  The quantities are those of
route ``"line"`` in :data:`gearjax.studies.quantities.QUANTITIES`.  The load solution
is exact per active set, so the quantities are piecewise smooth in the fields (kinks
where a slice point enters contact or crosses the start of a linear relief,
docs/microgeometry.md): the optimiser may stop at such a kink without meeting its
stationarity test, and the study then says so.

**Acceptance.**  Every position of every scenario converged (and, with the
efficiency, every loaded point's friction) at the start and the end; the written design
file read back gives the optimiser's fields (relative 1e-9).

Units: N m, rpm, µm, mm, MPa, W.  References (docs/references.md): [ISO21771];
[ISO6336-1]; [ISO1328-1].
"""

from __future__ import annotations

import copy
import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np

__all__ = ["MICRO_PREFIX", "REPORTED", "micro_field", "LineChain", "line_chain", "line_evaluator",
           "line_flags", "line_round_trip", "check_line_scenarios"]

MICRO_PREFIX = "microgeometry."
#: quantities every line-contact study reports (the hard TE p-t-p of the before/after
#: table and figure, the pressure and face-load figures of ``gearjax loaded``)
REPORTED = ("line_te_ptp_hard_um", "line_p_max_MPa", "line_k_hbeta", "line_end_load")


def micro_field(name: str, side: str) -> tuple:
    """``(table, member, key)`` of the variable ``name`` = ``microgeometry.TABLE.KEY``
    (module docstring); one-line ValueError naming the field otherwise."""
    from gearjax.gears.involute.design_file import MICRO_KEYS, MICRO_TABLES
    parts = name.split(".")
    if len(parts) != 3 or parts[0] + "." != MICRO_PREFIX:
        raise ValueError(f"field {name!r} must read {MICRO_PREFIX}TABLE.KEY")
    table, key = parts[1], parts[2]
    if table not in MICRO_TABLES:
        raise ValueError(f"field {name!r}: unknown micro-geometry table {table!r} (tables: "
                         f"{', '.join(MICRO_TABLES)})")
    if key not in MICRO_KEYS:
        raise ValueError(f"field {name!r}: unknown micro-geometry field {key!r} (fields: "
                         f"{', '.join(MICRO_KEYS)}; the relief shapes are not variables)")
    member = table.split("_")[0]
    if (member, side) not in MICRO_TABLES[table]:
        raise ValueError(f"field {name!r}: the {table.replace('_', ' ')} flank is not in mesh "
                         f"on the study's side ({side})")
    return table, member, key


class LineChain:
    """The line-contact model of one design and study (concrete set-up).

    ``pair``: the variables' pytree ``{"microgeometry": {"pinion_SIDE": {KEY: value},
    "gear_SIDE": {...}}}`` of every micro-geometry key of the flanks in mesh (field
    names :func:`gearjax.fields.field_names`); ``canonical(name)`` maps a study's field
    name (a member or a flank table) to its name there; ``__call__(tree, T_Nm, rpm,
    f_ma_um, oil, surface) -> (LineLoad, LineEfficiency or None)`` (traceable)."""

    def __init__(self, design, side, positions, slices, compliance, efficiency,
                 coupling_length_mm=0.0):
        from gearjax.gears.involute.design_file import MICRO_KEYS
        from gearjax.gears.involute.loaded_lines import line_design, line_options
        self.design, self.side, self.efficiency = design, side, efficiency
        self.pair_geo, self.b, self.mods0, self.material = line_design(design, None, side)
        self.opts = line_options(self.pair_geo, self.b, positions, slices, compliance,
                                 coupling_length_mm)
        self.options = {"positions": positions, "slices": slices, "compliance": compliance,
                        "coupling_length_mm": coupling_length_mm}
        self.pair = {"microgeometry": {
            f"{m}_{side}": {k: jnp.asarray(getattr(getattr(self.mods0, m), f), jnp.float64)
                            for k, f in MICRO_KEYS.items()} for m in ("pinion", "gear")}}

    def canonical(self, name: str) -> str:
        _table, member, key = micro_field(name, self.side)
        return f"{MICRO_PREFIX}{member}_{self.side}.{key}"

    def mods(self, tree):
        """The :class:`~gearjax.gears.involute.microgeometry.PairModification` of the
        variables' pytree (traceable)."""
        from gearjax.gears.involute.design_file import MICRO_KEYS
        from gearjax.gears.involute.microgeometry import PairModification
        mg = tree["microgeometry"]
        return PairModification(*(dataclasses.replace(
            getattr(self.mods0, m), **{f: mg[f"{m}_{self.side}"][k] for k, f in
                                       MICRO_KEYS.items()}) for m in ("pinion", "gear")))

    def __call__(self, tree, torque_Nm, rpm, f_ma_um, oil, surface):
        """One scenario: pinion torque ``torque_Nm`` (N m; the model takes N mm), speed
        ``rpm`` and ``oil``/``surface`` (used with the efficiency only), mesh
        misalignment ``f_ma_um`` (µm); traceable in all but the options."""
        from gearjax.gears.involute.line_efficiency import line_efficiency_traced
        from gearjax.gears.involute.line_load import line_load_traced
        mat, drive = self.material, self.side == "drive"
        args = (self.pair_geo, self.b, self.mods(tree), 1e3 * torque_Nm, f_ma_um)
        if not self.efficiency:
            return line_load_traced(*args, self.opts, mat.youngs_modulus_MPa, mat.poisson,
                                    drive), None
        eff = line_efficiency_traced(*args, rpm, oil, surface, self.opts,
                                     mat.youngs_modulus_MPa, mat.poisson, drive)
        return eff.loads, eff


def _check_bounds(i, v, table_key, value):
    """The variable's bounds in the key's range, a relief length's lower bound > 0."""
    from gearjax.gears.involute.design_file import MICRO_KEYS
    from gearjax.gears.involute.microgeometry import FIELD_UNITS
    unit, lo, hi = FIELD_UNITS[MICRO_KEYS[table_key]]
    a, b = v.bounds(value)
    if a < lo or b > hi or (table_key.endswith("_length_mm") and not a > 0.0):
        low = "> 0" if table_key.endswith("_length_mm") else f"{lo:g}"
        raise ValueError(f"[[variables]] {i + 1} ({v.field}): bounds [{a:.6g}, {b:.6g}] "
                         f"{unit} outside the field's range [{low}, {hi:g}] {unit}")


def line_chain(design, study) -> LineChain:
    """The :class:`LineChain` of ``design`` for ``study`` with its variables checked
    against the design (module docstring; one-line ValueError naming the entry)."""
    from gearjax.gears.involute.design_file import MICRO_KEYS, InvoluteFile
    from gearjax.tca.result import family_of
    if not isinstance(design, InvoluteFile):
        fam = family_of(design).family
        raise ValueError(f"[[variables]] 1 ({study.variables[0].field}): micro-geometry "
                         f"fields and the line-contact quantities are for involute pairs, not "
                         f"{fam} pairs ([study] design = {study.design!r})")
    efficiency = any(_needs_lube(q) for q in study.quantities)
    comp = study.operating.get("compliance", "weber")
    try:
        chain = LineChain(design, study.side, study.line["positions"], study.line["slices"],
                          comp, efficiency, study.line.get("coupling_length_mm", 0.0))
    except (ValueError, TypeError) as exc:
        raise ValueError(f"[study] design = {study.design!r}: {exc}") from None
    micro = design.micro
    for i, v in enumerate(study.variables):
        table, member, key = micro_field(v.field, study.side)
        flanks = [getattr((micro.flanks(s) if micro is not None else chain.mods0), member)
                  for s in ("drive", "coast")] if table == member else []
        vals = {float(getattr(f, MICRO_KEYS[key])) for f in flanks}
        if len(vals) > 1:
            raise ValueError(f"[[variables]] {i + 1} ({v.field}): the design's {member} "
                             f"flanks differ in {key} ({sorted(vals)}); name one flank "
                             f"({MICRO_PREFIX}{member}_{study.side}.{key})")
        _check_bounds(i, v, key, float(getattr(getattr(chain.mods0, member), MICRO_KEYS[key])))
    return chain


def _needs_lube(name) -> bool:
    """Whether the line-route quantity ``name`` needs the efficiency (speed, oil)."""
    from gearjax.studies.quantities import QUANTITIES
    return QUANTITIES[name].loaded


def check_line_scenarios(chain: LineChain, study, scen: list):
    """Each scenario's torque and misalignment in the ranges of ``gearjax loaded`` and,
    for the efficiency, the operating inputs; returns ``(oil, surface)`` (None without
    the efficiency)."""
    import gearjax as gj
    from gearjax.errors import check_range
    from gearjax.gears.involute.loaded_lines import MISALIGNMENT_RANGE_UM, TORQUE_RANGE_NM
    from gearjax.loading.efficiency_inputs import check_efficiency_inputs
    oil = surface = None
    if chain.efficiency:
        oil = dataclasses.replace(gj.tribology.get_oil(str(study.operating["oil"])), name="")
        surface = gj.tribology.make_surface(float(study.operating["sigma_um"]))
    mat = chain.material
    for i, s in enumerate(scen):
        try:
            check_range("torque_Nm", s["torque_Nm"], *TORQUE_RANGE_NM, unit="N m")
            check_range("f_ma_um", s["f_ma_um"], *MISALIGNMENT_RANGE_UM, unit="um")
            if chain.efficiency:
                check_efficiency_inputs(s["torque_Nm"], s["pinion_rpm"], oil, surface,
                                        mat.e_prime_MPa, mat.poisson,
                                        chain.options["compliance"], "roelands", "auto")
        except ValueError as exc:
            raise ValueError(f"[scenarios] scenario {i + 1}: {exc}") from None
    return oil, surface


def line_evaluator(prob):
    """``(u, data) -> (Q (S, nq), res, eff, Q)``: the study's quantities at every
    scenario (one ``vmap``; the same form as the TCA route's evaluator, the hard model
    being the model itself)."""
    from gearjax.fields import with_scaled_fields
    from gearjax.studies.quantities import quantity_values
    chain, qnames, names = prob.chain, prob.study.quantities, list(prob.fields)

    def ev(u, data):
        tree = with_scaled_fields(data.pair0, names, data.x0, data.scale, u)

        def one(T, n, f):
            res, eff = chain(tree, T, n, f, data.oil, data.surface)
            q = quantity_values(qnames, res, eff, None, tree)
            return q, res, eff, q

        return jax.vmap(one)(data.torque, data.rpm, data.mis)

    return ev


def line_flags(res, eff, k: int) -> dict:
    """Scenario ``k``'s quality flags: every position converged (and its friction),
    the number of valid positions."""
    ok = np.asarray(res.converged)[k] if eff is None else np.asarray(eff.valid)[k]
    return {"converged": bool(np.all(ok)), "n_valid": int(np.sum(ok))}


def line_round_trip(prob, end_tree):
    """The end design as a design file (the start's with its ``[microgeometry]`` tables
    rewritten) read back through the involute loader; ``(data, error or None, max
    |field difference|)`` as :func:`gearjax.studies.study_run.run_study`'s check."""
    from gearjax.fields import get_fields
    from gearjax.gears.involute.design_file import (MICRO_KEYS, MICRO_TABLES,
                                                    microgeometry_tables)
    from gearjax.gears.involute.microgeometry import MicroGeometry
    from gearjax.io import design_from_dict
    side = prob.study.side
    micro = prob.design.micro or MicroGeometry.none()
    values = get_fields(end_tree, prob.fields)
    for v, name in zip(prob.study.variables, prob.fields):
        table, _member, key = micro_field(v.field, side)
        for member, sd in MICRO_TABLES[table]:
            pm = micro.flanks(sd)
            flank = dataclasses.replace(getattr(pm, member),
                                        **{MICRO_KEYS[key]: jnp.asarray(values[name])})
            pm = dataclasses.replace(pm, **{member: flank})
            micro = dataclasses.replace(micro, **{sd: pm})
    try:
        data = copy.deepcopy(prob.design.data)
        data["microgeometry"] = microgeometry_tables(micro)
        if not data["microgeometry"]:
            del data["microgeometry"]
        back = design_from_dict(data)
    except ValueError as exc:
        return None, str(exc), math.inf
    mods = (back.micro or MicroGeometry.none()).flanks(side)
    diff = 0.0
    for name in prob.fields:
        _t, member, key = micro_field(name, side)
        got = float(getattr(getattr(mods, member), MICRO_KEYS[key]))
        diff = max(diff, abs(got - float(np.asarray(values[name]))))
    return data, None, diff
