"""Spiral-bevel / hypoid design files (TOML): schema, validation, load and save.

Design files use mm and degrees; inside gearjax everything is mm and rad.  A
hypoid/spiral-bevel design file has the tables (R = required, D = default, printed
by ``gearjax example show`` and ``gearjax blank`` when applied, see
:func:`defaults_applied`)

* ``[design]``  kind (R: "hypoid" | "spiral_bevel"), name, description, source
  (optional strings, no geometry)
* ``[blank]``   the blank-design input, passed verbatim to
  :meth:`gearjax.gears.hypoid.blank.BlankInput.from_dict` (its required keys and
  defaults: :data:`gearjax.gears.hypoid.blank.FILE_DEFAULTS`).  Optional for a
  design with flanks of one member only; required when the design has flanks of
  both members (the pair is mounted with its ``shaft_angle_deg`` and ``offset_mm``).
* ``[blank_summary.pinion]``, ``[blank_summary.gear]``  cone data of each member
  (the layout of [HFT-hypoid] Table 1, docs/references.md), all R: hand, teeth,
  outer_cone_distance, face_width, outer_addendum, outer_dedendum, pitch_angle,
  face_angle, root_angle, mean_spiral_angle; mean_cone_distance optional, checked
  against A_o - F/2.  Required for each member that has flanks.
* ``[<member>.<flank>.cutter]`` point_radius, blade_angle, edge_radius (all R)
  (member: pinion | gear, flank: convex | concave; convex = inside blade)
* ``[<member>.<flank>.machine]`` R: type ("generated" | "formate"), blank_offset,
  machine_root_angle, sliding_base, center_to_back, and either the geometric
  radial_distance, cradle_angle, tilt, swivel or a sub-table ``no116`` with the
  Gleason No. 116 dials cradle, eccentric, swivel, tilt ([HFT-hypoid]; generated
  members only); generated members: ratio_of_roll (R, > 0), modified_roll_2c and
  modified_roll_6d (D = 0: no modified roll).  A formate member has no roll:
  ratio_of_roll and the modified-roll keys may be given only as 0.
* ``[machine_summary]`` free-form copy of published settings, kept for comparison
  (not used; any keys).

Every number must be a finite TOML int or float (no bool, string, array, NaN,
inf); tooth numbers TOML integers; sane ranges: angles (degrees) of the machine
tables and dials in [-360, 360], every length in [-1e4, 1e4] mm, ratio_of_roll and
the modified-roll coefficients in [-1e3, 1e3]; the constructors add the finer
ranges (e.g. blade angle in (0, 45) deg, tilt in [0, 90) deg, face width below the
outer cone distance).  Unknown keys raise ``ValueError`` naming the key.

Cross-checks between the tables of one design (:func:`cross_check`), relative
tolerance :data:`CROSS_CHECK_RTOL` = 1e-3 for real numbers (the published tables
print 4-5 significant digits), exact for tooth numbers and hands:

* ``[blank]`` z1, z2 = ``[blank_summary.pinion]`` / ``[blank_summary.gear]`` teeth;
* pinion and gear have opposite hands; ``[blank]`` hand (the pinion's) = the
  pinion's hand in ``[blank_summary.pinion]``;
* ``[blank]`` gear_face_width_mm = ``[blank_summary.gear]`` face_width;
  gear_outer_pitch_diameter_mm = 2 A_o2 sin(delta_2) of ``[blank_summary.gear]``;
  spiral_angle_deg = mean_spiral_angle of ``spiral_member`` in ``[blank_summary]``;
* ``[design]`` kind "hypoid" has ``offset_mm`` > 0, "spiral_bevel" has 0;
* offset 0 (common apex): delta_1 + delta_2 = shaft angle, equal outer cone
  distances, equal mean spiral angles, sin(delta_1)/sin(delta_2) = z1/z2.

Every ``ValueError`` is one line naming the table and the key;
:func:`load_design` prefixes the file name.
:func:`save_design` writes the same data back (a small TOML writer for this
schema; no extra dependency) and ``load_design(save_design(d)) == d`` (tested).

Files are read with :func:`gearjax.io.read_toml` and written atomically with
:func:`gearjax.io.atomic_write`.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path

from gearjax.io import atomic_write, check_integer, check_keys as _check_keys, check_number
from gearjax.io import check_string, dumps_toml, read_toml, register_design_kind
from gearjax.io import require_key as _req

__all__ = ["HypoidDesign", "load_design", "save_design", "design_from_dict", "defaults_applied",
           "format_defaults", "cross_check", "CROSS_CHECK_RTOL", "MACHINE_DEFAULTS",
           "flank_settings_table"]

MEMBERS = ("pinion", "gear")
FLANKS = ("convex", "concave")
KINDS = ("hypoid", "spiral_bevel")
_TOP = {"design", "blank", "blank_summary", "pinion", "gear", "machine_summary"}
_DESIGN = {"name", "kind", "description", "source"}
# key -> unit ("mm", "deg", "int", "str") of [blank_summary.<member>]
_SUMMARY_UNITS = {"hand": "str", "teeth": "int", "outer_cone_distance": "mm",
                  "mean_cone_distance": "mm", "face_width": "mm", "outer_addendum": "mm",
                  "outer_dedendum": "mm", "pitch_angle": "deg", "face_angle": "deg",
                  "root_angle": "deg", "mean_spiral_angle": "deg"}
_SUMMARY = set(_SUMMARY_UNITS)
_CUTTER_UNITS = {"point_radius": "mm", "blade_angle": "deg", "edge_radius": "mm"}
_CUTTER = set(_CUTTER_UNITS)
_MACHINE_UNITS = {"radial_distance": "mm", "cradle_angle": "deg", "tilt": "deg", "swivel": "deg",
                  "blank_offset": "mm", "machine_root_angle": "deg", "sliding_base": "mm",
                  "center_to_back": "mm", "ratio_of_roll": "-", "modified_roll_2c": "1/rad",
                  "modified_roll_6d": "1/rad^2"}
_MACHINE = set(_MACHINE_UNITS) | {"type", "no116"}
_NO116 = {"cradle", "eccentric", "swivel", "tilt"}
#: machine-table keys required for every flank (besides the cutter placement)
_MACHINE_REQUIRED = ("type", "blank_offset", "machine_root_angle", "sliding_base", "center_to_back")
#: cutter placement: the geometric settings, or the sub-table ``no116``
_PLACEMENT = ("radial_distance", "cradle_angle", "tilt", "swivel")
#: defaults of a generated member's machine table (no modified roll); printed when applied
MACHINE_DEFAULTS = {"modified_roll_2c": 0.0, "modified_roll_6d": 0.0}
_ROLL_KEYS = ("ratio_of_roll", "modified_roll_2c", "modified_roll_6d")
_ANGLE_LIMIT = 360.0            # |angle| bound (deg) of machine-table angles and dials
_LENGTH_LIMIT = 1e4             # |length| bound (mm) of every length in a design file (10 m)
_ROLL_LIMIT = 1e3               # |ratio_of_roll|, |2C| (1/rad), |6D| (1/rad^2) bound
#: relative tolerance of the cross-checks between tables (real numbers)
CROSS_CHECK_RTOL = 1e-3


def _u(unit):
    return "" if unit in ("-", "int", "str") else unit


def _num(where, d, key, unit):
    """Required finite number ``d[key]`` (float) within its sane range: angles of the
    machine tables (deg) in [-360, 360], lengths (mm) in [-1e4, 1e4], roll
    coefficients in [-1e3, 1e3] (finer ranges: the constructors)."""
    x = check_number(where, key, _req(where, d, key), _u(unit))
    if unit == "deg" and where.endswith(("machine", "no116")):
        lim = _ANGLE_LIMIT
    else:
        lim = {"mm": _LENGTH_LIMIT}.get(unit, _ROLL_LIMIT if key in _ROLL_KEYS else None)
    if lim is not None and abs(x) > lim:
        u = f" {_u(unit)}" if _u(unit) else ""
        raise ValueError(f"[{where}] {key} = {x:g}{u} is outside the allowed range "
                         f"[-{lim:g}, {lim:g}]{u}")
    return x


def _wrap(where, fn, *a, **kw):
    """Call a validated constructor; prefix its ValueError with the table name."""
    try:
        return fn(*a, **kw)
    except ValueError as exc:
        raise ValueError(f"[{where}] {exc}") from None


@dataclass(frozen=True)
class HypoidDesign:
    """A validated hypoid / spiral-bevel design (file content in file units)."""

    data: dict = field(compare=True)

    @property
    def name(self) -> str:
        return self.data.get("design", {}).get("name", "")

    def to_dict(self) -> dict:
        return copy.deepcopy(self.data)

    def defaults_applied(self) -> list:
        """``[(dotted key, value, unit), ...]`` of the documented defaults this design
        relies on (:func:`defaults_applied`)."""
        return defaults_applied(self)

    def defaults_lines(self) -> list:
        """:meth:`defaults_applied` as printable ``"key = value  # unit"`` lines."""
        return format_defaults(self)

    def flanks(self):
        """(member, flank) pairs present in the design."""
        return [(m, f) for m in MEMBERS for f in FLANKS if f in self.data.get(m, {})]

    def member_blank(self, member: str):
        """:class:`~gearjax.gears.hypoid.flank.MemberBlank` of ``member`` from [blank_summary]."""
        from gearjax.gears.hypoid.flank import make_member_blank
        if member not in MEMBERS:
            raise ValueError(f"member = {member!r} must be 'pinion' or 'gear'")
        where = f"blank_summary.{member}"
        d = self.data.get("blank_summary", {}).get(member)
        if d is None:
            raise ValueError(f"missing table [{where}]")
        _check_keys(where, d, _SUMMARY)
        kw = {}
        for k, unit in _SUMMARY_UNITS.items():
            if k == "mean_cone_distance":
                continue
            if unit == "str":
                kw[k] = check_string(where, k, _req(where, d, k), ("left", "right"))
            elif unit == "int":
                kw[k] = check_integer(where, k, _req(where, d, k), 1)
            else:
                kw[k] = _num(where, d, k, unit)
        b = _wrap(where, make_member_blank, **kw)
        if "mean_cone_distance" in d:
            amd = _num(where, d, "mean_cone_distance", "mm")
            am = kw["outer_cone_distance"] - 0.5 * kw["face_width"]
            if abs(am - amd) > 1e-6 * max(1.0, am):
                raise ValueError(f"[{where}] mean_cone_distance = {amd:g} mm must equal "
                                 f"outer_cone_distance - face_width/2 = {am:g} mm")
        return b

    def cutter(self, member: str, flank: str):
        """:class:`~gearjax.gears.hypoid.cutter.FaceMillCutter` of one flank."""
        from gearjax.gears.hypoid.cutter import make_cutter
        where = f"{member}.{flank}.cutter"
        d = _req(f"{member}.{flank}", self._flank_table(member, flank), "cutter")
        _check_keys(where, d, _CUTTER)
        v = {k: _num(where, d, k, u) for k, u in _CUTTER_UNITS.items()}
        return _wrap(where, make_cutter, v["point_radius"], v["blade_angle"], v["edge_radius"],
                     flank)

    def machine(self, member: str, flank: str):
        """:class:`~gearjax.gears.hypoid.machine.MachineSettings` (dials converted to geometric settings)."""
        import jax.numpy as jnp
        from gearjax.gears.hypoid.machine import MachineSettings, No116Dials, dials_to_geometric
        where = f"{member}.{flank}.machine"
        d = _req(f"{member}.{flank}", self._flank_table(member, flank), "machine")
        _check_keys(where, d, _MACHINE)
        typ = check_string(where, "type", _req(where, d, "type"), ("generated", "formate"))
        gen = typ == "generated"
        r = math.radians
        for k in _MACHINE_REQUIRED[1:]:
            _req(where, d, k)
        if "no116" in d:
            if not gen:
                raise ValueError(f"[{where}] no116: the dials apply to generated members only")
            wd = where + ".no116"
            dd = d["no116"]
            _check_keys(wd, dd, _NO116)
            for k in _PLACEMENT:
                if k in d:
                    raise ValueError(f"[{where}] {k} conflicts with [{wd}] (give one of them)")
            from gearjax.errors import check_range
            ecc = _wrap(wd, check_range, "eccentric", _num(wd, dd, "eccentric", "deg"),
                        0.0, 180.0, lo_open=True, unit="deg")
            tilt = _wrap(wd, check_range, "tilt", _num(wd, dd, "tilt", "deg"), 0.0, 180.0,
                         unit="deg")
            dials = No116Dials(jnp.asarray(r(_num(wd, dd, "cradle", "deg"))), jnp.asarray(r(ecc)),
                               jnp.asarray(r(_num(wd, dd, "swivel", "deg"))), jnp.asarray(r(tilt)))
            S, q, i, j = (float(v) for v in dials_to_geometric(dials))
        else:
            S, q, i, j = (_num(where, d, k, _MACHINE_UNITS[k]) for k in _PLACEMENT)
            q, i, j = r(q), r(i), r(j)
        roll = {}
        for k in _ROLL_KEYS:
            if gen:
                roll[k] = (_num(where, d, k, _MACHINE_UNITS[k]) if k in d or k == "ratio_of_roll"
                           else MACHINE_DEFAULTS[k])
            elif k in d and _num(where, d, k, _MACHINE_UNITS[k]) != 0.0:
                raise ValueError(f"[{where}] {k} = {d[k]!r}: a formate member has no roll "
                                 f"(type = 'formate'); give 0 or leave the key out")
            else:
                roll[k] = 0.0
        if gen and roll["ratio_of_roll"] <= 0.0:
            raise ValueError(f"[{where}] ratio_of_roll = {roll['ratio_of_roll']:g} is outside the "
                             f"allowed range (0, inf) for a generated member")
        return _wrap(where, MachineSettings.create,
                     radial_distance=S, cradle_angle=q, tilt=i, swivel=j,
                     blank_offset=_num(where, d, "blank_offset", "mm"),
                     machine_root_angle=r(_num(where, d, "machine_root_angle", "deg")),
                     sliding_base=_num(where, d, "sliding_base", "mm"),
                     center_to_back=_num(where, d, "center_to_back", "mm"),
                     generated=gen, **roll)

    def flank(self, member: str, flank: str):
        """:class:`~gearjax.gears.hypoid.flank.FlankSpec` for one flank."""
        from gearjax.gears.hypoid.flank import FlankSpec
        return FlankSpec(self.cutter(member, flank), self.machine(member, flank),
                         self.member_blank(member))

    def surface_grid(self, member: str, flank: str, n_u: int, n_v: int):
        """Grid of ``flank`` of tooth 0 of ``member`` (a :class:`gearjax.io.FlankGrid`,
        :func:`~gearjax.gears.hypoid.flank.flank_surface`: ``n_u`` face-width positions
        by ``n_v`` points along the blade) -- the ``gearjax surface`` method of every
        design file."""
        from gearjax.gears.hypoid.flank import flank_surface
        return flank_surface(self.flank(member, flank), n_u, n_v)

    def reference_grid(self, member: str, flank: str, n_u: int, n_v: int,
                       face_margin: float, height_margin: float):
        """The measuring grid of ``flank`` of ``member`` (a :class:`gearjax.io.FlankGrid`):
        ``n_u`` face-width positions by ``n_v`` points along the blade inside a border of
        ``face_margin`` of the face width and ``height_margin`` of the active blade
        length (:func:`~gearjax.gears.hypoid.flank.flank_surface`; docs/correct.md) --
        the nominal points and normals of ``gearjax surface --reference-grid``."""
        from gearjax.gears.hypoid.flank import flank_surface
        return flank_surface(self.flank(member, flank), n_u, n_v, face_margin=face_margin,
                             height_margin=height_margin)

    def correction_problem(self, measured, settings=None):
        """The closed-loop correction of the measured member (a
        :class:`gearjax.correction.CorrectionProblem`;
        :func:`gearjax.gears.hypoid.flank_correction.correction_problem`)."""
        from gearjax.correction import correction_family
        return correction_family(self).correction_problem(self, measured, settings)

    def corrected_design(self, result, *, description: str | None = None):
        """This design with the fitted corrections written
        (:func:`gearjax.gears.hypoid.flank_correction.corrected_design`)."""
        from gearjax.correction import correction_family
        return correction_family(self).corrected_design(result, description=description)

    def ease_off_family(self):
        """The target ease-off fit of this design's family, which ``gearjax ease-off``
        runs: the module registered in :func:`gearjax.correction.ease_off_family`
        (:mod:`gearjax.gears.hypoid.ease_off`)."""
        from gearjax.correction import ease_off_family
        return ease_off_family(self)

    def teeth(self, member: str) -> int:
        """Number of teeth of ``member``."""
        return int(self.member_blank(member).teeth)

    def blank_input(self):
        """The ``[blank]`` table as :class:`BlankInput` (blank-design module)."""
        from gearjax.gears.hypoid.blank import BlankInput
        if "blank" not in self.data:
            raise ValueError("the design has no [blank] table")
        try:
            return BlankInput.from_dict(self.data["blank"])
        except ValueError as exc:
            msg = str(exc)
            raise ValueError(msg if "[blank]" in msg else f"[blank] {msg}") from None

    def _flank_table(self, member, flank):
        if member not in MEMBERS:
            raise ValueError(f"member = {member!r} must be 'pinion' or 'gear'")
        if flank not in FLANKS:
            raise ValueError(f"flank = {flank!r} must be 'convex' or 'concave'")
        t = self.data.get(member, {}).get(flank)
        if t is None:
            raise ValueError(f"the design has no [{member}.{flank}] flank")
        _check_keys(f"{member}.{flank}", t, {"cutter", "machine"})
        return t


def _close(a: float, b: float, rtol: float = CROSS_CHECK_RTOL) -> bool:
    return abs(a - b) <= rtol * max(abs(a), abs(b))


def cross_check(design: HypoidDesign) -> None:
    """Check that the tables of one design agree (module docstring); ``ValueError``
    naming both tables and keys.  Tooth numbers and hands exactly, real numbers to
    the relative tolerance :data:`CROSS_CHECK_RTOL`."""
    data = design.data
    bs = data.get("blank_summary", {})
    kind = data["design"]["kind"]
    blank = data.get("blank")
    inp = design.blank_input() if blank is not None else None
    tol = f"relative tolerance {CROSS_CHECK_RTOL:g}"
    if "pinion" in bs and "gear" in bs and bs["pinion"]["hand"] == bs["gear"]["hand"]:
        raise ValueError(f"[blank_summary.pinion] hand = {bs['pinion']['hand']!r} and "
                         f"[blank_summary.gear] hand = {bs['gear']['hand']!r}: a pinion and its "
                         f"gear have opposite hands of spiral")
    if inp is not None:
        off = float(inp.offset)
        if kind == "hypoid" and not off > 0.0:
            raise ValueError(f"[blank] offset_mm = {off:g} mm: a design of [design] kind = "
                             f"'hypoid' has an offset > 0 (use kind = 'spiral_bevel' for 0)")
        if kind == "spiral_bevel" and off != 0.0:
            raise ValueError(f"[blank] offset_mm = {off:g} mm: a design of [design] kind = "
                             f"'spiral_bevel' has offset 0 (use kind = 'hypoid')")
        for m, zk, z in (("pinion", "z1", inp.z1), ("gear", "z2", inp.z2)):
            if m in bs and bs[m]["teeth"] != z:
                raise ValueError(f"[blank] {zk} = {z} disagrees with [blank_summary.{m}] "
                                 f"teeth = {bs[m]['teeth']} (tooth numbers of one design)")
        if "pinion" in bs and bs["pinion"]["hand"] != inp.hand:
            given = "" if "hand" in blank else " (default)"
            raise ValueError(f"[blank] hand = {inp.hand!r}{given} (the pinion's) disagrees with "
                             f"[blank_summary.pinion] hand = {bs['pinion']['hand']!r}")
        if "gear" in bs:
            g = bs["gear"]
            b2, F2 = float(inp.gear_face_width), float(g["face_width"])
            if not _close(b2, F2):
                raise ValueError(f"[blank] gear_face_width_mm = {b2:g} mm disagrees with "
                                 f"[blank_summary.gear] face_width = {F2:g} mm ({tol})")
            de2 = 2.0 * float(g["outer_cone_distance"]) * math.sin(math.radians(g["pitch_angle"]))
            dei = float(inp.gear_outer_pitch_diameter)
            if not _close(dei, de2):
                raise ValueError(f"[blank] gear_outer_pitch_diameter_mm = {dei:g} mm disagrees "
                                 f"with 2 outer_cone_distance sin(pitch_angle) = {de2:g} mm of "
                                 f"[blank_summary.gear] ({tol})")
        sm = inp.spiral_member
        if sm in bs:
            bi, bm = math.degrees(float(inp.spiral_angle)), float(bs[sm]["mean_spiral_angle"])
            if not _close(bi, bm):
                raise ValueError(f"[blank] spiral_angle_deg = {bi:g} deg (of the {sm}) disagrees "
                                 f"with [blank_summary.{sm}] mean_spiral_angle = {bm:g} deg ({tol})")
    zero_offset = (inp is not None and float(inp.offset) == 0.0) or (inp is None and kind == "spiral_bevel")
    if zero_offset and "pinion" in bs and "gear" in bs:
        p, g = bs["pinion"], bs["gear"]
        d1, d2 = math.radians(p["pitch_angle"]), math.radians(g["pitch_angle"])
        checks = [("outer_cone_distance", p["outer_cone_distance"], g["outer_cone_distance"]),
                  ("mean_spiral_angle", p["mean_spiral_angle"], g["mean_spiral_angle"])]
        for k, a, b in checks:
            if not _close(float(a), float(b)):
                raise ValueError(f"[blank_summary.pinion] {k} = {float(a):g} and "
                                 f"[blank_summary.gear] {k} = {float(b):g} must be equal for "
                                 f"offset 0 (common apex; {tol})")
        r_sin, r_z = math.sin(d1) / math.sin(d2), p["teeth"] / g["teeth"]
        if not _close(r_sin, r_z):
            raise ValueError(f"[blank_summary.pinion] / [blank_summary.gear] pitch_angle: "
                             f"sin(delta1)/sin(delta2) = {r_sin:.6g} disagrees with teeth "
                             f"{p['teeth']}/{g['teeth']} = {r_z:.6g} (offset 0; {tol})")
        if inp is not None:
            sig = math.degrees(float(inp.shaft_angle))
            sdel = float(p["pitch_angle"]) + float(g["pitch_angle"])
            if not _close(sdel, sig):
                raise ValueError(f"[blank_summary.pinion] + [blank_summary.gear] pitch_angle = "
                                 f"{sdel:g} deg disagrees with [blank] shaft_angle_deg = {sig:g} "
                                 f"deg (offset 0; {tol})")


def defaults_applied(design: HypoidDesign) -> list:
    """``[(dotted key, value, unit), ...]``: every documented default the design
    relies on (a key left out of the file), in file units."""
    from gearjax.gears.hypoid.blank import FILE_DEFAULTS
    out = []
    blank = design.data.get("blank")
    if blank is not None:
        for k, (v, unit) in FILE_DEFAULTS.items():
            if k not in blank:
                out.append((f"blank.{k}", v, unit))
    for m, f in design.flanks():
        d = design.data[m][f].get("machine", {})
        if d.get("type") == "generated":
            for k, v in MACHINE_DEFAULTS.items():
                if k not in d:
                    out.append((f"{m}.{f}.machine.{k}", v, _MACHINE_UNITS[k]))
    return out


def format_defaults(design: HypoidDesign) -> list:
    """``["key = value unit", ...]``: :func:`defaults_applied` as printable lines
    (TOML syntax, so that they can be pasted into the design file)."""
    return [f"{k} = {v!r}" + (f"    # {_u(u)}" if _u(u) else "")
            for k, v, u in defaults_applied(design)]


def design_from_dict(data: dict) -> HypoidDesign:
    """Validate a design dict (file units) and return a :class:`HypoidDesign`.

    Checks every table (required keys, types, ranges) and then the agreement of the
    tables (:func:`cross_check`); ``ValueError`` naming the table and the key."""
    if not isinstance(data, dict):
        raise ValueError(f"a design must be a table (dict), got {type(data).__name__}")
    data = copy.deepcopy(data)
    _check_keys("", data, _TOP)
    if "design" not in data:
        raise ValueError("missing table [design] (with kind = 'hypoid' or 'spiral_bevel')")
    des = data["design"]
    _check_keys("design", des, _DESIGN)
    check_string("design", "kind", _req("design", des, "kind"), KINDS)
    for k in ("name", "description", "source"):
        if k in des:
            check_string("design", k, des[k])
    if "machine_summary" in data and not isinstance(data["machine_summary"], dict):
        raise ValueError("[machine_summary] must be a table")
    bs = data.get("blank_summary", {})
    _check_keys("blank_summary", bs, set(MEMBERS))
    for m in MEMBERS:
        if m in data:
            _check_keys(m, data[m], set(FLANKS))
    design = HypoidDesign(data)
    if "blank" in data:
        design.blank_input()
    teeth = {m: design.member_blank(m).teeth for m in MEMBERS if m in bs}
    if "pinion" in teeth and "gear" in teeth and teeth["gear"] < teeth["pinion"]:
        raise ValueError(f"[blank_summary.gear] teeth / [blank_summary.pinion] teeth: ratio = "
                         f"{teeth['gear']}/{teeth['pinion']} must be >= 1 (the pinion is the "
                         f"member with fewer teeth)")
    for m, f in design.flanks():
        design.cutter(m, f)
        design.machine(m, f)
        if m not in bs:
            raise ValueError(f"missing table [blank_summary.{m}] for the {m} flanks")
    members_with_flanks = {m for m, _ in design.flanks()}
    if members_with_flanks == set(MEMBERS) and "blank" not in data:
        raise ValueError("missing table [blank]: a design with flanks of both members needs it "
                         "(the pair is mounted with its shaft_angle_deg and offset_mm)")
    cross_check(design)
    return design


def load_design(source) -> HypoidDesign:
    """Load and validate a design: a path or ``example:NAME``.  ``ValueError`` (one
    line naming the file, the table and the key) for any invalid input."""
    data = read_toml(source)
    try:
        return design_from_dict(data)
    except ValueError as exc:
        raise ValueError(f"design file {str(source)!r}: {exc}") from None


def save_design(design: HypoidDesign, path) -> Path:
    """Write a design file (atomically); ``load_design`` reads back an equal design."""
    return atomic_write(path, dumps_toml(design.data))


for _kind in KINDS:     # gearjax.io.load_design dispatches on [design] kind
    register_design_kind(_kind, design_from_dict)


def flank_settings_table(fl) -> dict:
    """The design-file tables (``cutter``, ``machine``; file units mm and degrees) of a
    member flank's cutter and machine settings (a :class:`~gearjax.gears.hypoid.flank.
    FlankSpec`-like object with ``cutter`` and ``machine``; concrete values)."""
    import numpy as np
    c, m = fl.cutter, fl.machine
    f = lambda a: float(np.asarray(a))
    dg = lambda a: math.degrees(f(a))
    return {"cutter": {"point_radius": f(c.point_radius), "blade_angle": dg(c.blade_angle),
                       "edge_radius": f(c.edge_radius)},
            "machine": {"type": "generated" if m.generated else "formate",
                        "radial_distance": f(m.radial_distance), "cradle_angle": dg(m.cradle_angle),
                        "tilt": dg(m.tilt), "swivel": dg(m.swivel),
                        "blank_offset": f(m.blank_offset),
                        "machine_root_angle": dg(m.machine_root_angle),
                        "sliding_base": f(m.sliding_base), "center_to_back": f(m.center_to_back),
                        "ratio_of_roll": f(m.ratio_of_roll),
                        "modified_roll_2c": f(m.modified_roll_2c),
                        "modified_roll_6d": f(m.modified_roll_6d)}}
