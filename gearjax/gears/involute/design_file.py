"""Involute design files (TOML, ``[design] kind = "involute"``): schema and validation.

The file form of the inline ``involute:z1=..,z2=..,m=..,alpha=..,b=..`` DESIGN of the
contact commands, for pairs worth keeping (the packaged published examples).  File
units: mm and degrees.  Tables and keys:

* ``[design]`` kind = "involute"; name, description, source (optional strings).
* ``[pair]`` (all required but the helix angle and the shifts)
  - ``z1``, ``z2`` (integers, 6..1000): tooth numbers of pinion and gear;
  - ``normal_module_mm`` (0.01..100);
  - ``normal_pressure_angle_deg`` (0..45, open);
  - ``face_width_mm`` (0.1 m_n .. 1000);
  - ``helix_angle_deg`` (0..60, default 0; the pinion's hand is the gear's opposite);
  - ``profile_shift1``, ``profile_shift2`` (-3..3, default 0: x of ISO 21771, the
    rack datum line moved out by x m_n).
  Basic rack: addendum 1.0 m_n, dedendum 1.25 m_n (tip circles r + m_n (1 + x); no tip
  shortening), zero-backlash operating centre distance a_w from
  ``inv α_wt = 2 tan α_n (x1 + x2)/(z1 + z2) + inv α_t`` (ISO 21771).
* ``[material]`` (optional table; both keys required when it is given):
  ``youngs_modulus_GPa`` (50..500), ``poisson`` (0..0.5) of both members -- E′ and the
  tooth compliance of the loaded contact (:mod:`gearjax.loading.materials`); without it steel.
* ``[modification]`` (optional table, every key optional, default 0): the pinion rack's
  ``pressure_angle_change_deg`` (-5..5), ``profile_crown_per_mm`` and
  ``lead_crown_per_mm`` (0..0.1) of :class:`gearjax.gears.involute.tca.InvoluteTCA`.
* ``[microgeometry]`` (optional): the flank modifications of
  :mod:`gearjax.gears.involute.microgeometry` (docs/microgeometry.md), analysed by the
  loaded line contact (``gearjax loaded``, :func:`~gearjax.gears.involute.loaded_lines.
  loaded_te_map`).  Sub-tables ``[microgeometry.pinion]`` and ``[microgeometry.gear]``
  set both flanks (drive and coast) of that member; ``[microgeometry.pinion_drive]``,
  ``pinion_coast``, ``gear_drive``, ``gear_coast`` set one flank (a member table and
  one of its own flank tables together are refused).  Keys, every one optional (default:
  unmodified), units in the name (ranges of :data:`~gearjax.gears.involute.
  microgeometry.FIELD_UNITS`):
  - ``tip_relief_um`` (0..500), ``tip_relief_length_mm`` (roll length from the tip,
    > 0 when there is a relief), ``tip_relief_shape`` ("linear" or "parabolic", default
    "linear"); ``root_relief_um``, ``root_relief_length_mm``, ``root_relief_shape`` (the
    same, from the start of active profile);
  - ``profile_crowning_um``, ``profile_slope_um`` (f_Halpha), ``lead_crowning_um``,
    ``helix_slope_um`` (f_Hbeta), ``bias_um`` (-500..500);
  - ``end_relief_I_um``, ``end_relief_I_length_mm``, ``end_relief_II_um``,
    ``end_relief_II_length_mm`` (axial length from the face end), ``end_relief_shape``
    (both ends).
  A relief amount > 0 without its length is refused.  A design file with these tables
  is refused by the unloaded TCA, its sensitivities and the mesh efficiency
  (``gearjax tca``, ``gearjax efficiency``, :func:`gearjax.run_tca`,
  :func:`gearjax.mesh_efficiency`), which do not take them.

Tooth form (undercut, pointed tip, tip/fillet interference) is checked on loading by
:meth:`InvolutePair.create`, exactly as for the inline form.  Unknown or missing keys
and out-of-range values raise ``ValueError`` naming the table and the key.

:class:`InvoluteFile` carries the validated dict (``data``) and the pytree
(``design``, an :class:`InvoluteTCA`); ``gearjax.run_tca``, ``tca_function`` and
``mesh_efficiency`` take either.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field

from gearjax.errors import check_range
from gearjax.gears.involute.geometry import InvolutePair
from gearjax.gears.involute.microgeometry import (FIELD_UNITS, FlankModification, MicroGeometry,
                                                  PairModification)
from gearjax.gears.involute.tca import ADAPTER, InvoluteTCA
from gearjax.io import (DesignFileMixin, check_integer, check_keys, check_number, check_string,
                        register_design_kind, require_key)
from gearjax.tca.result import register_family

__all__ = ["InvoluteFile", "read_involute", "KIND", "PAIR_KEYS", "MODIFICATION_KEYS",
           "MICRO_KEYS", "MICRO_SHAPES", "MICRO_TABLES", "microgeometry_tables"]

KIND = "involute"
#: [pair] key -> (unit, default or None when required)
PAIR_KEYS = {"z1": ("int", None), "z2": ("int", None), "normal_module_mm": ("mm", None),
             "normal_pressure_angle_deg": ("deg", None), "face_width_mm": ("mm", None),
             "helix_angle_deg": ("deg", 0.0), "profile_shift1": ("", 0.0),
             "profile_shift2": ("", 0.0)}
#: [modification] key -> unit (every key optional, default 0)
MODIFICATION_KEYS = {"pressure_angle_change_deg": "deg", "profile_crown_per_mm": "1/mm",
                     "lead_crown_per_mm": "1/mm"}

#: [microgeometry.*] key -> FlankModification field (amounts um, lengths mm)
MICRO_KEYS = {"tip_relief_um": "tip_relief", "tip_relief_length_mm": "tip_relief_length",
              "root_relief_um": "root_relief", "root_relief_length_mm": "root_relief_length",
              "profile_crowning_um": "profile_crowning", "profile_slope_um": "profile_slope",
              "lead_crowning_um": "lead_crowning", "end_relief_I_um": "end_relief_I",
              "end_relief_I_length_mm": "end_relief_I_length",
              "end_relief_II_um": "end_relief_II",
              "end_relief_II_length_mm": "end_relief_II_length",
              "helix_slope_um": "helix_slope", "bias_um": "bias"}
#: [microgeometry.*] shape key -> FlankModification exponent field
MICRO_SHAPE_KEYS = {"tip_relief_shape": "tip_relief_exponent",
                    "root_relief_shape": "root_relief_exponent",
                    "end_relief_shape": "end_relief_exponent"}
#: relief shape -> exponent
MICRO_SHAPES = {"linear": 1.0, "parabolic": 2.0}
#: relief amount key -> (its length key, its shape key)
MICRO_RELIEFS = {"tip_relief_um": ("tip_relief_length_mm", "tip_relief_shape"),
                 "root_relief_um": ("root_relief_length_mm", "root_relief_shape"),
                 "end_relief_I_um": ("end_relief_I_length_mm", "end_relief_shape"),
                 "end_relief_II_um": ("end_relief_II_length_mm", "end_relief_shape")}
#: [microgeometry] sub-table -> the (member, side) flanks it sets
MICRO_TABLES = {"pinion": (("pinion", "drive"), ("pinion", "coast")),
                "gear": (("gear", "drive"), ("gear", "coast")),
                "pinion_drive": (("pinion", "drive"),), "pinion_coast": (("pinion", "coast"),),
                "gear_drive": (("gear", "drive"),), "gear_coast": (("gear", "coast"),)}


@dataclass(frozen=True)
class InvoluteFile(DesignFileMixin):
    """A validated involute design file: ``data`` (file units) and ``design`` (the
    :class:`InvoluteTCA` pytree the TCA and the loaded chain run)."""

    data: dict = field(compare=True)
    design: InvoluteTCA = field(compare=False)
    #: the ``[microgeometry]`` tables (a
    #: :class:`~gearjax.gears.involute.microgeometry.MicroGeometry`), or None without them
    micro: object = field(default=None, compare=False)

    def defaults_lines(self) -> list:
        """The documented defaults this design relies on (printable lines)."""
        pr = self.data.get("pair", {})
        out = [f"pair.{k} = {d:g}" for k, (_, d) in PAIR_KEYS.items()
               if d is not None and k not in pr]
        mod = self.data.get("modification", {})
        out += [f"modification.{k} = 0" for k in MODIFICATION_KEYS if k not in mod]
        for name, tab in self.data.get("microgeometry", {}).items():
            out += [f'microgeometry.{name}.{shape} = "linear"'
                    for amount, (_, shape) in MICRO_RELIEFS.items()
                    if tab.get(amount, 0.0) > 0.0 and shape not in tab]
        return sorted(set(out), key=out.index)

    def material(self):
        """The file's ``[material]`` (:class:`gearjax.loading.materials.Material`), or None (the
        documented steel default applies)."""
        from gearjax.loading.materials import SOURCE_DESIGN, Material
        m = self.data.get("material")
        if m is None:
            return None
        return Material(float(m["youngs_modulus_GPa"]) * 1e3, float(m["poisson"]), SOURCE_DESIGN)

    def teeth(self, member: str) -> int:
        if member not in ("pinion", "gear"):
            raise ValueError(f"member = {member!r} must be 'pinion' or 'gear'")
        return self.design.pair.z1 if member == "pinion" else self.design.pair.z2

    def surface_grid(self, member, flank, n_u, n_v):
        raise ValueError("gearjax surface: no surface export for [design] kind = 'involute' "
                         "(hypoid, spiral_bevel, vh_catt and preset_te_bevel designs have one)")


def read_involute(data: dict) -> InvoluteFile:
    """Validate a parsed ``involute`` design file (module docstring) and build the pair."""
    data = copy.deepcopy(data)
    check_keys("", data, {"design", "pair", "modification", "material", "microgeometry"})
    des = data["design"]
    check_keys("design", des, {"kind", "name", "description", "source"})
    check_string("design", "kind", require_key("design", des, "kind"), (KIND,))
    for k in ("name", "description", "source"):
        if k in des:
            check_string("design", k, des[k])
    pr = data.get("pair")
    if not isinstance(pr, dict):
        raise ValueError("missing table [pair]")
    check_keys("pair", pr, set(PAIR_KEYS))
    v = {}
    for k, (unit, default) in PAIR_KEYS.items():
        if default is not None and k not in pr:
            v[k] = default
            continue
        raw = require_key("pair", pr, k)
        v[k] = check_integer("pair", k, raw) if unit == "int" else check_number("pair", k, raw,
                                                                               unit)
    mod = data.get("modification", {})
    if not isinstance(mod, dict):
        raise ValueError("[modification] must be a table")
    check_keys("modification", mod, set(MODIFICATION_KEYS))
    m = {k: check_number("modification", k, mod[k], u) if k in mod else 0.0
         for k, u in MODIFICATION_KEYS.items()}
    if "material" in data:
        mat = data["material"]
        if not isinstance(mat, dict):
            raise ValueError("[material] must be a table")
        check_keys("material", mat, {"youngs_modulus_GPa", "poisson"})
        for k, (lo, hi, unit) in (("youngs_modulus_GPa", (50.0, 500.0, "GPa")),
                                  ("poisson", (0.0, 0.5, ""))):
            val = check_number("material", k, require_key("material", mat, k), unit)
            try:
                check_range(k, val, lo, hi, unit=unit)
            except ValueError as exc:
                raise ValueError(f"[material] {exc}") from None
    try:
        pair = InvolutePair.create(v["z1"], v["z2"], v["normal_module_mm"],
                                   v["normal_pressure_angle_deg"], v["helix_angle_deg"],
                                   v["profile_shift1"], v["profile_shift2"])
        check_range("face_width_mm", v["face_width_mm"], 0.0, 1000.0, lo_open=True, unit="mm")
    except ValueError as exc:
        raise ValueError(f"[pair] {exc}") from None
    try:
        tca = InvoluteTCA.create(pair, v["face_width_mm"], m["pressure_angle_change_deg"],
                                 m["profile_crown_per_mm"], m["lead_crown_per_mm"])
    except ValueError as exc:
        raise ValueError(f"[pair]/[modification] {exc}") from None
    micro = read_microgeometry(data["microgeometry"]) if "microgeometry" in data else None
    return InvoluteFile(data, tca, micro)


def _flank_table(where: str, tab) -> FlankModification:
    """The :class:`FlankModification` of one ``[microgeometry.*]`` table (module
    docstring), every value checked with the table and the key in the message."""
    check_keys(where, tab, set(MICRO_KEYS) | set(MICRO_SHAPE_KEYS))
    values = {}
    for key, fld in MICRO_KEYS.items():
        if key not in tab:
            continue
        unit, lo, hi = FIELD_UNITS[fld]
        val = check_number(where, key, tab[key], unit)
        try:
            values[fld] = check_range(key, val, lo, hi, unit=unit)
        except ValueError as exc:
            raise ValueError(f"[{where}] {exc}") from None
    for key, fld in MICRO_SHAPE_KEYS.items():
        if key in tab:
            values[fld] = MICRO_SHAPES[check_string(where, key, tab[key], tuple(MICRO_SHAPES))]
    for amount, (length, _) in MICRO_RELIEFS.items():
        a = values.get(MICRO_KEYS[amount], 0.0)
        if a > 0.0 and values.get(MICRO_KEYS[length], 0.0) <= 0.0:
            given = (f"{length} = {values[MICRO_KEYS[length]]:g}" if length in tab
                     else f"no {length}")
            raise ValueError(f"[{where}] {amount} = {a:g} with {given}: a relief needs its "
                             f"length {length} > 0 mm")
    try:
        return FlankModification.create(**values)
    except ValueError as exc:
        raise ValueError(f"[{where}] {exc}") from None


def read_microgeometry(micro) -> MicroGeometry:
    """The :class:`MicroGeometry` of a ``[microgeometry]`` table (module docstring)."""
    check_keys("microgeometry", micro, set(MICRO_TABLES))
    for member in ("pinion", "gear"):
        for side in ("drive", "coast"):
            if member in micro and f"{member}_{side}" in micro:
                raise ValueError(f"[microgeometry.{member}] and [microgeometry.{member}_{side}] "
                                 f"both set the {member}'s {side} flank: give either the member "
                                 "table (both flanks) or its flank tables")
    flanks = {}
    for name, targets in MICRO_TABLES.items():
        if name in micro:
            mod = _flank_table(f"microgeometry.{name}", micro[name])
            flanks.update({t: mod for t in targets})
    none = FlankModification.none()
    pm = {side: PairModification(flanks.get(("pinion", side), none),
                                 flanks.get(("gear", side), none))
          for side in ("drive", "coast")}
    return MicroGeometry(pm["drive"], pm["coast"])


def _flank_data(mod: FlankModification) -> dict:
    """The ``[microgeometry.*]`` keys of one flank (the inverse of :func:`_flank_table`):
    the values that differ from the unmodified flank, a relief's length and shape with
    its amount; an exponent other than those of :data:`MICRO_SHAPES` is refused."""
    none = FlankModification.none()
    out = {k: float(getattr(mod, f)) for k, f in MICRO_KEYS.items()
           if float(getattr(mod, f)) != float(getattr(none, f))}
    shapes = {v: k for k, v in MICRO_SHAPES.items()}
    for amount, (length, shape) in MICRO_RELIEFS.items():
        e = float(getattr(mod, MICRO_SHAPE_KEYS[shape]))
        if e not in shapes:
            raise ValueError(f"{MICRO_SHAPE_KEYS[shape]} = {e:g}: a design file writes the "
                             f"relief shapes {', '.join(MICRO_SHAPES)} (exponents 1, 2)")
        if amount in out:
            out[length] = float(getattr(mod, MICRO_KEYS[length]))
        if amount in out or e != MICRO_SHAPES["linear"]:
            out[shape] = shapes[e]
    return out


def microgeometry_tables(micro: MicroGeometry) -> dict:
    """The ``[microgeometry]`` table of ``micro`` (read back by :func:`read_microgeometry`
    to the same fields): a member table where its drive and coast flanks are equal, else
    its flank tables; unmodified flanks are left out."""
    out = {}
    for member in ("pinion", "gear"):
        d, c = (_flank_data(getattr(micro.flanks(side), member)) for side in ("drive", "coast"))
        if d == c:
            out.update({member: d} if d else {})
        else:
            out.update({f"{member}_{side}": t for side, t in (("drive", d), ("coast", c)) if t})
    return out


register_design_kind(KIND, read_involute)
register_family(InvoluteFile, ADAPTER)   # the family's pair() takes .design
