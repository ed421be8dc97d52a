"""TCA of pure-rolling bevel pairs with a preset TE: the family as data for the one
TCA driver (:mod:`gearjax.tca.family`).

The flanks are explicit functions ``S_C1(u, t)``, ``S_C2(v, t)``
(:mod:`gearjax.gears.preset_bevel.geometry`; not envelopes), mounted as in
:mod:`gearjax.gears.preset_bevel.pair`.  The contact is a point contact (profile arcs
of radii rho1, rho2 convex against each other): the 5x5 system of
:func:`gearjax.tca.path.contact_path` in ``(u1, t1, v2, t2, phi2)``, continued over a
uniform grid of pinion angles ``phi1_ref + k 2 pi/(z1 steps_per_pitch)``, centred on
the mid-face contact of the unmodified pair.  For ``kappa = 0`` and no misalignment
the solution is known in closed form (``u = v = 0``, ``t = phi1 - phase``, ``phi2 =
-(z1/z2) phi1``: contact along the pitch line, TE = 0); the tests compare with it.

The result is the common :class:`gearjax.tca.result.TCAResult` (``family =
"preset_bevel"``), ``coords`` = cone distance and height above the pitch cone of the
contact on both members (``L1, h1, L2, h2``, mm) and the flank parameters ``t1``,
``t2``.  Edge contact is solved (:func:`gearjax.tca.edge_contact.face_end_contact`
with :func:`gearjax.gears.preset_bevel.pair.preset_face_ends`): where the toe or heel
edge (sphere ``|q| = A_i, A_o``) or the tip edge (face cone) of a member touches the
mating flank ahead of the surface contact, or carries the load where the surface
contact has left the flanks, the path holds that edge contact (``path.edge_kind``;
no Hertz ellipse there, the semi-axes and kinematics are NaN) and the TE envelope
includes it.

Units: mm, rad.  Reference: [Preset-TE-bevel]; [Litvin2004] ch. 9 (contact equations).
"""

from __future__ import annotations

import math

import jax.numpy as jnp
import numpy as np

from gearjax.tca.family import DriverAdapter, GearFamily
from gearjax.gears.preset_bevel.geometry import PresetBevelDesign, cone_distances, pitch_angles
from gearjax.gears.preset_bevel.pair import (drives_forward, preset_assembly, preset_face_ends,
                                             preset_margin, reference_contact, side_flanks)
from gearjax.loading.loaded_contact import TeethOf
from gearjax.tca.result import TCAResult, register_family

__all__ = ["PresetBevelFamily", "preset_outline", "SUMMARY_KEYS", "preset_summary", "DEFAULTS",
           "ADAPTER"]

#: default TCA grid of the family
DEFAULTS = dict(steps_per_pitch=24, half_pitches=1.0, n_pairs=3)

SUMMARY_KEYS = ("ptp_rad", "phi2_ref_rad", "L1_mm", "h1_mm", "L2_mm", "h2_mm", "semi_major_mm")


def preset_summary(res: TCAResult):
    """Scalars of a result (traceable), :data:`SUMMARY_KEYS` order: TE peak-to-peak,
    gear angle at the reference (its change is the TE shift), bearing position
    (cone distance, height) on both members at the reference, ellipse semi-major axis."""
    p, c = res.path, res.coords
    mid = p.phi1.shape[0] // 2
    return jnp.stack([res.multi.ptp, p.phi2[mid], c["L1"][mid], c["h1"][mid], c["L2"][mid],
                      c["h2"][mid], p.semi_major[mid]])


def preset_outline(des: PresetBevelDesign, side: str = "drive") -> dict:
    """Axial projection of the pinion's working flank for plots (concrete): corners
    toe-root, heel-root, heel-tip, toe-tip in (body z, radius) mm."""
    d1 = float(pitch_angles(des)[0])
    Ai, _, Ao = (float(v) for v in cone_distances(des))
    ha, hf = float(des.addendum), float(des.dedendum)

    def corner(L, h):
        # point at cone distance L and height h above the pitch cone (meridian plane)
        s = np.sqrt(max(L * L - h * h, 0.0))
        return [s * np.cos(d1) - h * np.sin(d1), s * np.sin(d1) + h * np.cos(d1)]

    pts = [corner(Ai, -hf), corner(Ao, -hf), corner(Ao, ha), corner(Ai, ha)]
    return {"outline": np.array(pts + [pts[0]])}


class PresetBevelFamily(GearFamily):
    """The preset-TE bevel pair for the driver.  Sides: "drive" = pinion concave on gear
    convex (phase 0), "coast" = pinion convex on gear concave (phase pi/z1); the
    concave flank pushes the gear for *decreasing* phi1, so :meth:`forward` is the coast
    side (:mod:`gearjax.gears.preset_bevel.pair`).  Point contact only."""

    name = "preset_bevel"
    defaults = DEFAULTS
    line_contact_modes = (False,)
    contact_mode_reason = "the profile arcs of radii rho1, rho2 touch at a point"
    summary_keys = SUMMARY_KEYS

    _DEG = math.pi / 180.0
    file_fields = {"beta": ("pair", "spiral_angle_deg", _DEG),
                   "alpha_n": ("pair", "normal_pressure_angle_deg", _DEG),
                   "shaft_angle": ("pair", "shaft_angle_deg", _DEG),
                   "module_t": ("pair", "outer_transverse_module_mm", 1.0),
                   "face_width": ("pair", "face_width_mm", 1.0),
                   "R0": ("flanks", "spiral_R0_mm", 1.0),
                   "rho1": ("flanks", "profile_radius_pinion_mm", 1.0),
                   "rho2": ("flanks", "profile_radius_gear_mm", 1.0),
                   "addendum": ("flanks", "addendum_mm", 1.0),
                   "dedendum": ("flanks", "dedendum_mm", 1.0),
                   "kappa": ("preset", "kappa", 1.0)}

    def pair(self, design):
        # a design-file object carries the pytree as ``.design``
        return getattr(design, "design", design)

    def design_data(self, design, pair, side):
        """As :meth:`GearFamily.design_data`; the file gives the preset as the TE at the
        ends of the contact curve, ``te = kappa (t_min - t_m)^2`` (the inverse of
        :func:`~gearjax.gears.preset_bevel.geometry.preset_kappa`), so ``kappa`` is
        written as ``[preset] te_arcsec`` of the new pair."""
        from gearjax.gears.preset_bevel.geometry import curve_range
        from gearjax.tca.path import ARCSEC
        data = super().design_data(design, pair, side)
        kappa = data.get("preset", {}).pop("kappa", None)
        if kappa is not None:
            t0, tm, _ = curve_range(pair)
            data["preset"]["te_arcsec"] = float(kappa * (t0 - tm) ** 2 / ARCSEC)
        return data

    def check(self, design):
        """The fields in the ranges of the design file, in mm and rad (one-line
        ValueError naming the field); traced or batched fields skip it."""
        from gearjax.gears.preset_bevel.geometry import check_design_fields
        check_design_fields(design)

    def reference(self, pair, side):
        return reference_contact(pair, side)

    def flanks(self, pair, drive, line_contact=False):
        # the side code of the family's flank functions: +1 drive (concave), -1 coast
        return side_flanks(pair, jnp.where(drive, 1.0, -1.0))

    def forward(self, pair, drive):
        return jnp.logical_not(drive)

    def assembly(self, pair):
        return preset_assembly(pair)

    def boundaries(self, pair, path):
        margin, coords = preset_margin(pair, path.p1_body, path.p2_body)
        return margin, dict(coords, t1=path.uv1[:, 1], t2=path.uv2[:, 1])

    def edges(self, pair):
        return preset_face_ends(pair)

    def summary(self, pair, res):
        return preset_summary(res)

    def teeth(self, pair, side, line_contact=False):
        """ISO 10300 virtual cylindrical teeth (:mod:`gearjax.gears.preset_bevel.mesh`)."""
        from gearjax.gears.preset_bevel.mesh import preset_mesh_teeth
        return TeethOf(preset_mesh_teeth, (("drive", drives_forward(side)),)), pair

    def outline(self, pair, side="drive"):
        return preset_outline(pair, side)


FAMILY = PresetBevelFamily()
ADAPTER = DriverAdapter(FAMILY)
register_family(PresetBevelDesign, ADAPTER)
