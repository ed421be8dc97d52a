"""TCA of pure-rolling bevel pairs with a preset TE (adapter to :mod:`gearjax.tca`).

The flanks are explicit functions ``S_C1(u, t)``, ``S_C2(v, t)``
(:mod:`gearjax.gears.preset_bevel.geometry`; not envelopes), mounted as in
:mod:`gearjax.gears.preset_bevel.pair`.  The contact is a point contact (profile arcs
of radii rho1, rho2 convex against each other): the 5x5 system of
:func:`gearjax.tca.contact_path` in ``(u1, t1, v2, t2, phi2)``, continued over a
uniform grid of pinion angles ``phi1_ref + k 2 pi/(z1 steps_per_pitch)``, centred on
the mid-face contact of the unmodified pair.  For ``kappa = 0`` and no misalignment
the solution is known in closed form (``u = v = 0``, ``t = phi1 - phase``, ``phi2 =
-(z1/z2) phi1``: contact along the pitch line, TE = 0); the tests compare with it.

The result is the common :class:`gearjax.tca_result.TCAResult` (``family =
"preset_bevel"``), ``coords`` = cone distance and height above the pitch cone of the
contact on both members (``L1, h1, L2, h2``, mm) and the flank parameters ``t1``,
``t2``.  Edge contact is solved (:func:`gearjax.edge_contact.face_end_contact`
with :func:`gearjax.gears.preset_bevel.pair.preset_face_ends`): where the toe or heel
edge (sphere ``|q| = A_i, A_o``) or the tip edge (face cone) of a member touches the
mating flank ahead of the surface contact, or carries the load where the surface
contact has left the flanks, the path holds that edge contact (``path.edge_kind``;
no Hertz ellipse there, the semi-axes and kinematics are NaN) and the TE envelope
includes it.

Units: mm, rad.  Reference: [Preset-TE-bevel]; [Litvin2004] ch. 9 (contact equations).
"""

from __future__ import annotations

import functools

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.gears.preset_bevel.geometry import PresetBevelDesign, cone_distances, pitch_angles
from gearjax.edge_contact import face_end_contact
from gearjax.gears.preset_bevel.pair import (drives_forward, preset_assembly, preset_face_ends,
                                             preset_margin, reference_contact, side_code,
                                             side_flanks)
from gearjax.loaded_contact import TeethOf
from gearjax.tca import (DEFAULT_APPROACH, Misalignment, check_on_flank_converged,
                         check_tca_options, contact_path, multi_pair, pinion_angle_grid)
from gearjax.tca_result import (TCAResult, check_side, contact_kinematics, register_family,
                                strong_float64)

__all__ = ["preset_result_traced", "preset_tca", "preset_outline", "SUMMARY_KEYS",
           "preset_summary", "preset_sensitivity", "DEFAULTS"]

#: default TCA grid of the family
DEFAULTS = dict(steps_per_pitch=24, half_pitches=1.0, n_pairs=3)


def preset_result_traced(des: PresetBevelDesign, mis: Misalignment, x_ref, phi1_ref, *,
                         side: str = "drive", steps_per_pitch: int = 24,
                         half_pitches: float = 1.0, n_pairs: int = 3,
                         approach=DEFAULT_APPROACH, kinematics: bool = True,
                         face_ends: bool = True) -> TCAResult:
    """Traceable TCA of ``side`` as a :class:`~gearjax.tca_result.TCAResult` (module
    docstring).  ``x_ref, phi1_ref`` from :func:`~gearjax.gears.preset_bevel.pair.
    reference_contact` (concrete, fixed: the grid does not move with the design).
    ``face_ends``: solve the edge contacts (default; ``False``: surface contact only,
    ``path.edge_kind`` None)."""
    parts = _result_parts(des, mis, x_ref, phi1_ref, side_code(side),
                          steps_per_pitch=steps_per_pitch, half_pitches=half_pitches,
                          n_pairs=n_pairs, approach=approach, kinematics=kinematics,
                          face_ends=face_ends)
    return TCAResult(*parts, side, "preset_bevel")


def _result_parts(des, mis, x_ref, phi1_ref, code, *, steps_per_pitch, half_pitches, n_pairs,
                  approach, kinematics, face_ends=True):
    """``(path, margin, multi, coords, kinematics)``; ``code`` the side code (+1 drive,
    -1 coast; traced: one program for both sides).  With ``face_ends`` the edge
    contacts (toe, heel and tip edge of both members) are solved and the contact made
    at each grid point is the surface or an edge contact
    (:func:`gearjax.edge_contact.face_end_contact`)."""
    grid = pinion_angle_grid(phi1_ref, des.z1, steps_per_pitch, half_pitches)
    r1, r2 = side_flanks(des, code)
    asm = preset_assembly(des)
    path = contact_path(r1, r2, asm, mis, grid, x_ref, line_contact=False, approach=approach)
    margin, _ = preset_margin(des, path.p1_body, path.p2_body)
    if face_ends:
        parts, g1, g2, tips = preset_face_ends(des)
        path, margin, _ = face_end_contact(r1, r2, asm, mis, path, margin, parts, g1, g2,
                                           drive=drives_forward(code), tips=tips,
                                           steps_per_pitch=steps_per_pitch)
    _, coords = preset_margin(des, path.p1_body, path.p2_body)
    coords = dict(coords, t1=path.uv1[:, 1], t2=path.uv2[:, 1])
    multi = multi_pair(path, margin, steps_per_pitch, des.z1, drive=drives_forward(code),
                       n_pairs=n_pairs)
    kin = (contact_kinematics(r1, r2, asm, mis, path, line_contact=False) if kinematics
           else None)
    return path, margin, multi, coords, kin


_STATIC = ("steps_per_pitch", "half_pitches", "n_pairs", "kinematics", "face_ends")


@functools.partial(jax.jit, static_argnames=_STATIC)
def _parts_jit(des, mis, x_ref, phi1_ref, approach, code, *, steps_per_pitch, half_pitches,
               n_pairs, kinematics, face_ends=True):
    return _result_parts(des, mis, x_ref, phi1_ref, code, steps_per_pitch=steps_per_pitch,
                         half_pitches=half_pitches, n_pairs=n_pairs, approach=approach,
                         kinematics=kinematics, face_ends=face_ends)


def _result_jit(des, mis, x_ref, phi1_ref, approach, *, side, **static) -> TCAResult:
    """The jitted TCA (one program for both sides) as a TCAResult."""
    parts = _parts_jit(des, mis, x_ref, phi1_ref, approach, side_code(side), **static)
    return TCAResult(*parts, side, "preset_bevel")


def preset_tca(des: PresetBevelDesign, mis: Misalignment | None = None, *, side="drive",
               steps_per_pitch: int = 24, half_pitches: float = 1.0, n_pairs: int = 3,
               approach: float = DEFAULT_APPROACH, kinematics: bool = True,
               strict: bool = True) -> TCAResult:
    """Validated, jitted TCA of the pair (``gearjax.run_tca`` calls this).  ``strict``
    raises :class:`~gearjax.errors.ConvergenceError` (``NoContactError``) when a solve
    failed on the working flank or no grid point is on both flanks."""
    side = check_side(side)
    check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach)
    mis = Misalignment.zero() if mis is None else mis
    x_ref, phi1_ref = reference_contact(des, side)
    res = _result_jit(strong_float64(des), strong_float64(mis), x_ref, phi1_ref,
                      float(approach), side=side, steps_per_pitch=int(steps_per_pitch),
                      half_pitches=float(half_pitches), n_pairs=int(n_pairs),
                      kinematics=bool(kinematics))
    if strict:
        check_on_flank_converged(res.path, res.margin)
    return res


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


SUMMARY_KEYS = ("ptp_rad", "phi2_ref_rad", "L1_mm", "h1_mm", "L2_mm", "h2_mm", "semi_major_mm")


def preset_summary(res: TCAResult):
    """Scalars of a result (traceable), :data:`SUMMARY_KEYS` order: TE peak-to-peak,
    gear angle at the reference (its change is the TE shift), bearing position
    (cone distance, height) on both members at the reference, ellipse semi-major axis."""
    p, c = res.path, res.coords
    mid = p.phi1.shape[0] // 2
    return jnp.stack([res.multi.ptp, p.phi2[mid], c["L1"][mid], c["h1"][mid], c["L2"][mid],
                      c["h2"][mid], p.semi_major[mid]])


@functools.partial(jax.jit, static_argnames=("side", "steps_per_pitch", "half_pitches", "n_pairs"))
def _sensitivity_jit(des, mis, x_ref, phi1_ref, *, side, steps_per_pitch, half_pitches, n_pairs):
    def f(m):
        return preset_summary(preset_result_traced(des, m, x_ref, phi1_ref, side=side,
                                                   steps_per_pitch=steps_per_pitch,
                                                   half_pitches=half_pitches, n_pairs=n_pairs,
                                                   kinematics=False))
    return f(mis), jax.jacfwd(f)(mis)


def preset_sensitivity(des: PresetBevelDesign, mis: Misalignment | None = None, *,
                       side="drive", steps_per_pitch: int = 24, half_pitches: float = 1.0,
                       n_pairs: int = 3):
    """V-H sensitivity ``(values, table)`` of :data:`SUMMARY_KEYS` to dE, dP, dG (per
    mm) and dSigma (per rad) by ``jax.jacfwd`` (implicit derivatives of every solve)."""
    side = check_side(side)
    check_tca_options(steps_per_pitch, half_pitches, n_pairs, DEFAULT_APPROACH)
    mis = Misalignment.zero() if mis is None else mis
    x_ref, phi1_ref = reference_contact(des, side)
    vals, jac = _sensitivity_jit(strong_float64(des), strong_float64(mis), x_ref, phi1_ref,
                                 side=side, steps_per_pitch=int(steps_per_pitch),
                                 half_pitches=float(half_pitches), n_pairs=int(n_pairs))
    values = {k: float(v) for k, v in zip(SUMMARY_KEYS, np.asarray(vals))}
    table = {k: {n: float(np.asarray(getattr(jac, n))[i]) for n in ("dE", "dP", "dG", "dSigma")}
             for i, k in enumerate(SUMMARY_KEYS)}
    return values, table


class _Adapter:
    """The preset-TE bevel family behind :func:`gearjax.run_tca` (``side`` "drive" =
    pinion concave on gear convex, "coast" = pinion convex on gear concave)."""

    family = "preset_bevel"
    defaults = dict(DEFAULTS)

    @staticmethod
    def _design(design):
        # a design-file object carries the pytree as ``.design``
        return getattr(design, "design", design)

    def check(self, design):
        """The concrete design's fields in the ranges of the design file
        (:func:`~gearjax.gears.preset_bevel.design_file.validate_fields`), in mm and rad:
        one-line ValueError naming the field (:func:`gearjax.tca_result.check_design`);
        traced or batched fields skip it."""
        from gearjax.gears.preset_bevel.geometry import check_design_fields
        check_design_fields(self._design(design))

    def run(self, design, mis=None, *, side=None, steps_per_pitch=24, half_pitches=1.0,
            n_pairs=3, approach=DEFAULT_APPROACH, kinematics=True, strict=True, **_):
        return preset_tca(self._design(design), mis, side=side or "drive",
                          steps_per_pitch=steps_per_pitch, half_pitches=half_pitches,
                          n_pairs=n_pairs, approach=approach, kinematics=kinematics,
                          strict=strict)

    def traced(self, design, *, side=None, steps_per_pitch=24, half_pitches=1.0, n_pairs=3,
               approach=DEFAULT_APPROACH, kinematics=True, **_):
        side = check_side(side or "drive")
        check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach)
        des0 = self._design(design)
        x_ref, phi1_ref = reference_contact(des0, side)

        def f(des, mis=None):
            mis = Misalignment.zero() if mis is None else mis
            return _result_jit(strong_float64(des), strong_float64(mis), x_ref, phi1_ref,
                               approach, side=side, steps_per_pitch=int(steps_per_pitch),
                               half_pitches=float(half_pitches), n_pairs=int(n_pairs),
                               kinematics=bool(kinematics))
        f.pair = des0
        return f

    def mesh(self, design, *, side=None, **_):
        """``(teeth_of, pair, design)`` of the loaded-contact models: ISO 10300 virtual
        cylindrical teeth (:mod:`gearjax.gears.preset_bevel.mesh`)."""
        from gearjax.gears.preset_bevel.mesh import preset_mesh_teeth
        des = self._design(design)
        drive = drives_forward(check_side(side or "drive"))
        return TeethOf(preset_mesh_teeth, (("drive", drive),)), des, des

    def sensitivity(self, design, mis=None, *, side=None, steps_per_pitch=24, half_pitches=1.0,
                    n_pairs=3, **_):
        return preset_sensitivity(self._design(design), mis, side=side or "drive",
                                  steps_per_pitch=steps_per_pitch, half_pitches=half_pitches,
                                  n_pairs=n_pairs)

    def outline(self, design, side="drive"):
        return preset_outline(self._design(design), side)


ADAPTER = _Adapter()
register_family(PresetBevelDesign, ADAPTER)
