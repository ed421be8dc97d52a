"""Spiral-bevel / hypoid design files (TOML): schema, validation, load and save.

Design files use mm and degrees; inside gearjax everything is mm and rad.  A
hypoid/spiral-bevel design file has the tables

* ``[design]``  name, kind ("hypoid" | "spiral_bevel"), description, source
* ``[blank]``   the blank-design input, passed verbatim to
  :meth:`gearjax.gears.hypoid.blank.BlankInput.from_dict` (optional)
* ``[blank_summary.pinion]``, ``[blank_summary.gear]``  cone data of each member
  (the layout of [HFT-hypoid] Table 1, docs/references.md): hand, teeth, outer_cone_distance,
  mean_cone_distance (optional, checked against A_o - F/2), face_width,
  outer_addendum, outer_dedendum, pitch_angle, face_angle, root_angle,
  mean_spiral_angle
* ``[<member>.<flank>.cutter]`` point_radius, blade_angle, edge_radius
  (member: pinion | gear, flank: convex | concave; convex = inside blade)
* ``[<member>.<flank>.machine]`` type ("generated" | "formate"), blank_offset,
  machine_root_angle, sliding_base, center_to_back, ratio_of_roll,
  modified_roll_2c, modified_roll_6d, and either the geometric radial_distance,
  cradle_angle, tilt, swivel or a sub-table ``no116`` with the Gleason No. 116
  dials cradle, eccentric, swivel, tilt ([HFT-hypoid])
* ``[machine_summary]`` free-form copy of published settings, kept for comparison.

Unknown keys raise ``ValueError`` naming the key.  :func:`save_design` writes the
same data back (a small TOML writer for this schema; no extra dependency) and
``load_design(save_design(d)) == d`` (tested).

Files are read with :func:`gearjax.io.read_toml` and written atomically with
:func:`gearjax.io.atomic_write`.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path

from gearjax.io import atomic_write, check_keys as _check_keys, dumps_toml, read_toml
from gearjax.io import require_key as _req

__all__ = ["HypoidDesign", "load_design", "save_design", "design_from_dict"]

MEMBERS = ("pinion", "gear")
FLANKS = ("convex", "concave")
_TOP = {"design", "blank", "blank_summary", "pinion", "gear", "machine_summary"}
_DESIGN = {"name", "kind", "description", "source"}
_SUMMARY = {"hand", "teeth", "outer_cone_distance", "mean_cone_distance", "face_width",
            "outer_addendum", "outer_dedendum", "pitch_angle", "face_angle", "root_angle",
            "mean_spiral_angle"}
_CUTTER = {"point_radius", "blade_angle", "edge_radius"}
_MACHINE = {"type", "blank_offset", "machine_root_angle", "sliding_base", "center_to_back",
            "ratio_of_roll", "modified_roll_2c", "modified_roll_6d", "radial_distance",
            "cradle_angle", "tilt", "swivel", "no116"}
_NO116 = {"cradle", "eccentric", "swivel", "tilt"}



@dataclass(frozen=True)
class HypoidDesign:
    """A validated hypoid / spiral-bevel design (file content in file units)."""

    data: dict = field(compare=True)

    @property
    def name(self) -> str:
        return self.data.get("design", {}).get("name", "")

    def to_dict(self) -> dict:
        return copy.deepcopy(self.data)

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
        kw = {k: _req(where, d, k) for k in _SUMMARY if k != "mean_cone_distance"}
        b = make_member_blank(**kw)
        if "mean_cone_distance" in d:
            am = float(d["outer_cone_distance"]) - 0.5 * float(d["face_width"])
            if abs(am - float(d["mean_cone_distance"])) > 1e-6 * max(1.0, am):
                raise ValueError(f"{where}.mean_cone_distance = {d['mean_cone_distance']} mm "
                                 f"must equal outer_cone_distance - face_width/2 = {am:g} mm")
        return b

    def cutter(self, member: str, flank: str):
        from gearjax.gears.hypoid.cutter import make_cutter
        where = f"{member}.{flank}.cutter"
        d = self._flank_table(member, flank)["cutter"]
        return make_cutter(_req(where, d, "point_radius"), _req(where, d, "blade_angle"),
                           _req(where, d, "edge_radius"), flank)

    def machine(self, member: str, flank: str):
        """:class:`~gearjax.gears.hypoid.machine.MachineSettings` (dials converted to geometric settings)."""
        import jax.numpy as jnp
        from gearjax.gears.hypoid.machine import MachineSettings, No116Dials, dials_to_geometric
        where = f"{member}.{flank}.machine"
        d = self._flank_table(member, flank)["machine"]
        typ = _req(where, d, "type")
        if typ not in ("generated", "formate"):
            raise ValueError(f"{where}.type = {typ!r} must be 'generated' or 'formate'")
        gen = typ == "generated"
        r = math.radians
        g = lambda k, default=0.0: float(d.get(k, default))
        if "no116" in d:
            if not gen:
                raise ValueError(f"{where}.no116 dials apply to generated members only")
            dd = d["no116"]
            _check_keys(where + ".no116", dd, _NO116)
            for k in ("radial_distance", "cradle_angle", "tilt", "swivel"):
                if k in d:
                    raise ValueError(f"{where}.{k} conflicts with {where}.no116 (give one of them)")
            from gearjax.errors import check_range
            ecc = check_range(where + ".no116.eccentric", _req(where + ".no116", dd, "eccentric"),
                              0.0, 180.0, lo_open=True, unit="deg")
            tilt = check_range(where + ".no116.tilt", _req(where + ".no116", dd, "tilt"),
                               0.0, 180.0, unit="deg")
            dials = No116Dials(jnp.asarray(r(float(_req(where + ".no116", dd, "cradle")))),
                               jnp.asarray(r(ecc)),
                               jnp.asarray(r(float(_req(where + ".no116", dd, "swivel")))),
                               jnp.asarray(r(tilt)))
            S, q, i, j = (float(v) for v in dials_to_geometric(dials))
        else:
            S = _req(where, d, "radial_distance")
            q = r(float(_req(where, d, "cradle_angle")))
            i, j = r(g("tilt")), r(g("swivel"))
        try:
            return MachineSettings.create(
                radial_distance=S, cradle_angle=q, tilt=i, swivel=j, blank_offset=g("blank_offset"),
                machine_root_angle=r(float(_req(where, d, "machine_root_angle"))),
                sliding_base=g("sliding_base"), center_to_back=g("center_to_back"),
                ratio_of_roll=g("ratio_of_roll") if gen else 0.0,
                modified_roll_2c=g("modified_roll_2c"), modified_roll_6d=g("modified_roll_6d"),
                generated=gen)
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None

    def flank(self, member: str, flank: str):
        """:class:`~gearjax.gears.hypoid.flank.FlankSpec` for one flank."""
        from gearjax.gears.hypoid.flank import FlankSpec
        return FlankSpec(self.cutter(member, flank), self.machine(member, flank),
                         self.member_blank(member))

    def blank_input(self):
        """The ``[blank]`` table as :class:`BlankInput` (blank-design module)."""
        from gearjax.gears.hypoid.blank import BlankInput
        if "blank" not in self.data:
            raise ValueError("the design has no [blank] table")
        return BlankInput.from_dict(self.data["blank"])

    def _flank_table(self, member, flank):
        if member not in MEMBERS:
            raise ValueError(f"member = {member!r} must be 'pinion' or 'gear'")
        if flank not in FLANKS:
            raise ValueError(f"flank = {flank!r} must be 'convex' or 'concave'")
        t = self.data.get(member, {}).get(flank)
        if t is None:
            raise ValueError(f"the design has no [{member}.{flank}] flank")
        return t


def design_from_dict(data: dict) -> HypoidDesign:
    """Validate a design dict (file units) and return a :class:`HypoidDesign`."""
    data = copy.deepcopy(data)
    _check_keys("", data, _TOP)
    _check_keys("design", data.get("design", {}), _DESIGN)
    kind = data.get("design", {}).get("kind", "hypoid")
    if kind not in ("hypoid", "spiral_bevel"):
        raise ValueError(f"design.kind = {kind!r} must be 'hypoid' or 'spiral_bevel'")
    bs = data.get("blank_summary", {})
    _check_keys("blank_summary", bs, set(MEMBERS))
    for m, t in bs.items():
        _check_keys(f"blank_summary.{m}", t, _SUMMARY)
    for m in MEMBERS:
        if m not in data:
            continue
        _check_keys(m, data[m], set(FLANKS))
        for f, t in data[m].items():
            _check_keys(f"{m}.{f}", t, {"cutter", "machine"})
            _check_keys(f"{m}.{f}.cutter", _req(f"{m}.{f}", t, "cutter"), _CUTTER)
            _check_keys(f"{m}.{f}.machine", _req(f"{m}.{f}", t, "machine"), _MACHINE)
    design = HypoidDesign(data)
    teeth = {}
    for m in bs:
        teeth[m] = design.member_blank(m).teeth
    if "pinion" in teeth and "gear" in teeth and teeth["gear"] < teeth["pinion"]:
        raise ValueError(f"ratio = z_gear/z_pinion = {teeth['gear']}/{teeth['pinion']} "
                         f"must be >= 1 (the pinion is the member with fewer teeth)")
    for m, f in design.flanks():
        design.cutter(m, f)
        design.machine(m, f)
        if m not in bs:
            raise ValueError(f"missing table [blank_summary.{m}] for the {m} flanks")
    if "blank" in data:
        design.blank_input()
    return design



def load_design(source) -> HypoidDesign:
    """Load and validate a design: a path or ``example:NAME``."""
    return design_from_dict(read_toml(source))


def save_design(design: HypoidDesign, path) -> Path:
    """Write a design file (atomically); ``load_design`` reads back an equal design."""
    return atomic_write(path, dumps_toml(design.data))
