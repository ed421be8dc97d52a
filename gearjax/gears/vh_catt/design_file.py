"""VH-CATT design files (TOML, ``[design] kind = "vh_catt"``): schema, validation, grids.

File units: mm, degrees, GPa.  Tables and keys (all required unless marked):

* ``[design]`` kind = "vh_catt"; name, description, source (optional strings).
* ``[pair]``
  - ``z1``, ``z2`` (integers, 8..400): tooth numbers of pinion and gear (z2 >= z1);
  - ``module_mm`` (0.1..50): normal module of the middle section;
  - ``pressure_angle_deg`` (10..30): blade profile angle = middle-section pressure angle;
  - ``face_width_mm`` (0 < b <= min(20 m, R_T)): face width, symmetric about the middle;
  - ``cutter_radius1_mm``, ``cutter_radius2_mm`` (10..1e5, and >= 5 pi m): nominal
    radius R_T of the head that cuts the pinion / the gear;
  - ``blade_offset_mm`` (0..5 m): the mismatch e (blades moved apart by e each side,
    trace radii R_T -+ (w/2 + e); 0 = the plain dual-blade head).
* ``[pinion]``, ``[gear]`` (optional tables, every key optional): the member's own blade
  settings, written by ``gearjax correct`` (docs/correct.md) -- ``blade_offset_mm``
  (0..5 m; default the pair's ``blade_offset_mm``): the offset of that member's head;
  ``convex_blade_angle_deg``, ``concave_blade_angle_deg`` (within 2 deg of
  ``pressure_angle_deg`` and in 10..30; default ``pressure_angle_deg``): the profile
  angle of the blade that cuts that flank (pinion convex = inside blade, concave =
  outside blade; the gear mirrored).  The generated flanks honour them; the
  middle-section closed forms (contact path, form circles) keep the pair's values.
* ``[material]`` ``youngs_modulus_GPa`` (50..500), ``poisson`` (0..0.5): both members.
  It sets the loaded contact's reduced modulus E' = E/(1 - nu^2) (Hertz, film,
  asperities) and the tooth compliance (E, nu) of :func:`gearjax.loading.mesh_efficiency`,
  :func:`gearjax.efficiency_function` and ``gearjax efficiency``
  (:meth:`VHCattDesign.material`, :mod:`gearjax.loading.materials`); an explicit E'
  (``E_prime=`` / ``--E-prime-MPa``) overrides it, with the file's nu.

Every number must be a finite TOML number (tooth numbers TOML integers); unknown
keys and missing keys raise ``ValueError`` naming the table and the key.  No
geometry value has a default.  The tooth form is checked on loading (pointed
teeth, an undercut reaching the active profile and involute tip interference are refused,
:func:`gearjax.gears.vh_catt.geometry.tooth_form`).

Reference: [VH-CATT] (Table 1: the packaged example ``vh_catt_17x23``).
"""

from __future__ import annotations

import copy

import numpy as np

from gearjax.errors import check_range
from gearjax.gears.vh_catt.geometry import (MODULE_RANGE_MM, VHCattPair, flank_grid,
                                            member_blade_range)
from gearjax.gears.vh_catt.tca import ADAPTER
from gearjax.io import (DesignFileMixin, FlankGrid, check_integer, check_keys, check_number,
                        check_string, register_design_kind, require_key)
from gearjax.tca.result import register_family

__all__ = ["VHCattDesign", "design_from_dict", "FlankGrid", "KIND", "flank_sigma"]

KIND = "vh_catt"
_TOP = {"design", "pair", "material", "pinion", "gear"}
_DESIGN = {"kind", "name", "description", "source"}
_PAIR = {"z1": "int", "z2": "int", "module_mm": "mm", "pressure_angle_deg": "deg",
         "face_width_mm": "mm", "cutter_radius1_mm": "mm", "cutter_radius2_mm": "mm",
         "blade_offset_mm": "mm"}
#: optional per-member blade keys -> the key of :meth:`VHCattPair.create`'s member_blades
_MEMBER = {"blade_offset_mm": "blade_offset", "convex_blade_angle_deg": "convex_blade_angle",
           "concave_blade_angle_deg": "concave_blade_angle"}
_MATERIAL = {"youngs_modulus_GPa": (50.0, 500.0, "GPa"), "poisson": (0.0, 0.5, "")}


def flank_sigma(member: str, flank: str) -> int:
    """Side sign of the ``flank`` ("convex"/"concave") of ``member``: pinion convex = +1,
    concave = -1; the gear is mirrored (convex = -1)."""
    s = 1 if flank == "convex" else -1
    return s if member == "pinion" else -s


class VHCattDesign(DesignFileMixin):
    """A validated VH-CATT design file (``data`` in file units) and its pair
    (:attr:`pair`, a :class:`~gearjax.gears.vh_catt.geometry.VHCattPair`)."""

    #: the frame of the measuring grid's positions (``gearjax surface --reference-grid``)
    reference_frame = ("body frame of the member: z its axis, tooth 0 centred on +y at z = 0; "
                       "xi = z / (b/2 - face_margin b), height = fraction of the straight "
                       "blade from the form circle to the tip")

    def __init__(self, data: dict, pair: VHCattPair):
        self.data = data
        self.pair = pair

    def defaults_lines(self) -> list:
        """No defaults: every key of the schema is required."""
        return []

    def material(self):
        """The ``[material]`` table as a :class:`gearjax.loading.materials.Material` (E in MPa,
        ν; both members): it sets E′ = E/(1 − ν²) and the tooth compliance of
        :func:`gearjax.loading.mesh_efficiency` and ``gearjax efficiency`` unless E′ is given
        explicitly (:func:`gearjax.loading.materials.pair_material`)."""
        from gearjax.loading.materials import SOURCE_DESIGN, Material
        m = self.data["material"]
        return Material(float(m["youngs_modulus_GPa"]) * 1e3, float(m["poisson"]),
                        SOURCE_DESIGN)

    def e_prime_MPa(self) -> float:
        """E′ = E/(1 − ν²) of the ``[material]`` table (MPa)."""
        return float(self.material().e_prime_MPa)

    def teeth(self, member: str) -> int:
        return self.pair.teeth(member)

    def flanks(self):
        """(member, flank) pairs of the design: both flanks of both members."""
        return [(m, f) for m in ("pinion", "gear") for f in ("convex", "concave")]

    def surface_grid(self, member: str, flank: str, n_u: int, n_v: int) -> FlankGrid:
        """Grid of ``flank`` of tooth 0 of ``member``: ``n_u`` sections across the face
        width (z from -b/2 to b/2) by ``n_v`` points from the form circle to the tip.
        A :class:`gearjax.io.FlankGrid`: points, normals (out of the tooth), params
        (u, v, NaN: blade and trace coordinates, mm), xi (axial z, mm), residual
        (mm/rad of the envelope), converged."""
        g = self._grid(member, flank, n_u, n_v, 0.0, 0.0)
        params = np.concatenate([g.params[..., :2], np.full(g.points.shape[:2] + (1,), np.nan)],
                                axis=-1)
        return g._replace(params=params)

    def reference_grid(self, member: str, flank: str, n_u: int, n_v: int,
                       face_margin: float, height_margin: float) -> FlankGrid:
        """The measuring grid of ``flank`` of ``member`` (docs/correct.md, "VH-CATT"):
        ``n_u`` transverse sections ``z = (b/2 - f_m b) xi`` (``xi`` from -1 at the
        body frame's -z face end to +1 at the +z end) by ``n_v`` points along the
        straight blade at the fractions ``h_m .. 1 - h_m`` of the blade range from the
        form circle to the tip (:func:`~gearjax.gears.vh_catt.geometry.flank_grid`).  A
        :class:`gearjax.io.FlankGrid` in the member's body frame (z the axis, tooth 0
        centred on +y at z = 0): points, normals (out of the tooth), params (u, v, psi:
        blade and trace coordinates, mm, and the roll angle, rad: the start of the
        correction's line solves), xi (n_u,) the normalised positions ``2 z / (b - 2
        f_m b)`` -- the nominal points and normals of ``gearjax surface
        --reference-grid``."""
        g = self._grid(member, flank, n_u, n_v, face_margin, height_margin)
        half = float(self.pair.face_width) * (0.5 - float(face_margin))
        return g._replace(xi=np.asarray(g.xi) / half if half > 0 else np.zeros_like(g.xi))

    def _grid(self, member, flank, n_u, n_v, face_margin, height_margin) -> FlankGrid:
        if member not in ("pinion", "gear"):
            raise ValueError(f"member = {member!r} must be 'pinion' or 'gear'")
        if flank not in ("convex", "concave"):
            raise ValueError(f"flank = {flank!r} must be 'convex' or 'concave'")
        sigma = flank_sigma(member, flank)
        g = {k: np.asarray(v) for k, v in flank_grid(self.pair, member, sigma, n_u, n_v,
                                                     face_margin, height_margin).items()}
        P, N = g["points"], g["normals"]
        # orient the normals out of the tooth: flank sigma of tooth 0 faces sigma x
        # near the +y axis, i.e. along -sigma (e_z x r)
        t = np.stack([P[..., 1], -P[..., 0], np.zeros_like(P[..., 0])], axis=-1)
        sgn = np.sign(np.sum(N * t, axis=-1, keepdims=True)) * sigma
        params = np.concatenate([g["params"], g["psi"][..., None]], axis=-1)
        return FlankGrid(P, N * sgn, params, g["xi"], g["residual"], g["converged"])

    def correction_problem(self, measured, settings=None):
        """The closed-loop correction of the measured member (a
        :class:`gearjax.correction.CorrectionProblem`;
        :func:`gearjax.gears.vh_catt.flank_correction.correction_problem`)."""
        from gearjax.correction import correction_family
        return correction_family(self).correction_problem(self, measured, settings)

    def corrected_design(self, result, *, description: str | None = None):
        """This design with the fitted corrections written
        (:func:`gearjax.gears.vh_catt.flank_correction.corrected_design`)."""
        from gearjax.correction import correction_family
        return correction_family(self).corrected_design(result, description=description)

    def ease_off_family(self):
        """The target ease-off fit of this design's family, which ``gearjax ease-off``
        runs: the module registered in :func:`gearjax.correction.ease_off_family`
        (:mod:`gearjax.gears.vh_catt.ease_off`)."""
        from gearjax.correction import ease_off_family
        return ease_off_family(self)


def _table(data, key):
    t = data.get(key)
    if not isinstance(t, dict):
        raise ValueError(f"missing table [{key}]")
    return t


def design_from_dict(data: dict) -> VHCattDesign:
    """Validate a parsed design file and return a :class:`VHCattDesign` (module docstring)."""
    if not isinstance(data, dict):
        raise ValueError(f"a design must be a table (dict), got {type(data).__name__}")
    data = copy.deepcopy(data)
    check_keys("", data, _TOP)
    des = _table(data, "design")
    check_keys("design", des, _DESIGN)
    check_string("design", "kind", require_key("design", des, "kind"), (KIND,))
    for k in ("name", "description", "source"):
        if k in des:
            check_string("design", k, des[k])
    pr = _table(data, "pair")
    check_keys("pair", pr, set(_PAIR))
    vals = {}
    for k, unit in _PAIR.items():
        v = require_key("pair", pr, k)
        vals[k] = (check_integer("pair", k, v) if unit == "int"
                   else check_number("pair", k, v, unit))
    mat = _table(data, "material")
    check_keys("material", mat, set(_MATERIAL))
    for k, (lo, hi, unit) in _MATERIAL.items():
        v = check_number("material", k, require_key("material", mat, k), unit)
        try:
            check_range(k, v, lo, hi, unit=unit)
        except ValueError as exc:
            raise ValueError(f"[material] {exc}") from None
    blades = {}
    for mem in ("pinion", "gear"):
        if mem in data:
            t = _table(data, mem)
            check_keys(mem, t, set(_MEMBER))
            blades[mem] = {k: check_number(mem, k, v, "mm" if k.endswith("mm") else "deg")
                           for k, v in t.items()}
    if vals["z2"] < vals["z1"]:
        raise ValueError(f"[pair] z2 = {vals['z2']} must be >= z1 = {vals['z1']} (the pinion "
                         "is the member with fewer teeth)")
    try:
        m = check_range("module", vals["module_mm"], *MODULE_RANGE_MM, unit="mm")
        a = check_range("pressure_angle", vals["pressure_angle_deg"], 10.0, 30.0, unit="deg")
    except ValueError as exc:
        raise ValueError(f"[pair] {exc}") from None
    member_blades = {}
    for mem, t in blades.items():
        member_blades[mem] = {}
        for k, x in t.items():
            lo, hi, unit = member_blade_range(_MEMBER[k], m, a)
            try:
                member_blades[mem][_MEMBER[k]] = check_range(k, x, lo, hi, unit=unit)
            except ValueError as exc:
                raise ValueError(f"[{mem}] {exc}") from None
    try:
        pair = VHCattPair.create(vals["z1"], vals["z2"], vals["module_mm"],
                                 vals["pressure_angle_deg"], vals["face_width_mm"],
                                 vals["cutter_radius1_mm"], vals["cutter_radius2_mm"],
                                 blade_offset=vals["blade_offset_mm"],
                                 member_blades=member_blades)
    except ValueError as exc:
        raise ValueError(f"[pair] {exc}") from None
    return VHCattDesign(data, pair)


register_family(VHCattDesign, ADAPTER)
register_design_kind(KIND, design_from_dict)
