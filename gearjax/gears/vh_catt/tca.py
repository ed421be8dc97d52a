"""TCA of VH-CATT pairs (adapter to :mod:`gearjax.tca` and :mod:`gearjax.tca_result`).

Mounting (as the involute family): pinion (member 1) about +z through the origin,
gear (member 2) about +z through ``(0, a + dE, 0)``, ``a = r1 + r2`` (standard
centre distance), common perpendicular ``d = +y``, nominal ratio ``-z1/z2``.
Flank ``sigma = -1`` of both members is the drive side (pinion turning about +z):
the pinion's concave flank (outside blade, trace radius ``R_T1 + w/2``) against the
gear's convex flank (inside blade, ``R_T2 - w/2``); ``sigma = +1`` the coast side
(pinion convex ``R_T1 - w/2`` against gear concave ``R_T2 + w/2``).  The traces
differ, so the flanks touch at a point (point-contact TCA, 5 contact equations and
the two meshing equations, :func:`gearjax.tca.contact_system`).

Reference contact: the pitch point of the middle section (blade coordinates
u = v = 0 on both members, which generate the pitch-radius point of z = 0); each
member is turned so that its point lies at ``(0, r1, 0)``.  By the symmetry of both
members about z = 0 the aligned pair touches in the middle section all along the
path, where both flanks are involutes of the same base pitch: TE = 0 and the path
is the middle-section line of action (closed forms of the tests).  Misalignments
move the contact off the middle section, where the sections are not involutes.

Flank boundaries: tip circles ``r + m``, form circles of the straight blades
(:func:`gearjax.gears.vh_catt.geometry.pair_geometry`; those of the middle section,
which the other sections follow to within the trace's small tangential extent) and
the face ends ``|z| <= b/2`` (with edge contact, :mod:`gearjax.edge_contact`).

Units: mm, rad.  References: [VH-CATT]; [Litvin2004] ch. 9.
"""

from __future__ import annotations

from functools import partial

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.edge_contact import face_end_contact
from gearjax.gears.vh_catt.geometry import VHCattPair, generated_flank, pair_geometry
from gearjax.loaded_contact import TeethOf
from gearjax.tca import (DEFAULT_APPROACH, Assembly, ContactPath, Misalignment,
                         check_on_flank_converged, check_tca_options, contact_path, multi_pair,
                         pinion_angle_grid)
from gearjax.tca_result import (TCAResult, check_side, contact_kinematics, register_family,
                                strong_float64)

__all__ = ["vh_assembly", "vh_flanks", "reference_guess", "vh_margin", "vh_tca_traced",
           "vh_result_traced", "SUMMARY_KEYS", "tca_summary", "pair_of", "side_code", "ADAPTER"]


def pair_of(design) -> VHCattPair:
    """The :class:`VHCattPair` of a design-file object (``.pair``) or the pair itself."""
    return design if isinstance(design, VHCattPair) else design.pair


def side_code(side: str) -> float:
    """-1.0 (drive) or +1.0 (coast): the flank sign sigma of both members."""
    return -1.0 if side == "drive" else 1.0


def vh_assembly(pair: VHCattPair) -> Assembly:
    geo = pair_geometry(pair)
    z = jnp.zeros_like(geo["a"])
    return Assembly(jnp.eye(3), jnp.stack([z, geo["a"], z]), jnp.array([0.0, 1.0, 0.0]),
                    pair.z1, pair.z2, -1)


def vh_flanks(pair: VHCattPair, code):
    """Pinion and gear flanks of side ``code`` (-1 drive, +1 coast; may be traced)."""
    return generated_flank(pair, "pinion", code), generated_flank(pair, "gear", code)


def reference_guess(pair: VHCattPair, code):
    """``(x_ref, phi1_ref)``: guess ``(u1, v1, u2, v2, phi2)`` at the middle-section pitch
    point and the pinion angle that puts the pinion's point there (module docstring).
    ``phi1_ref`` carries its derivative (the grid moves with the design)."""
    r1, r2 = vh_flanks(pair, code)
    zero = jnp.zeros(2)
    q1, q2 = r1(zero), r2(zero)
    phi1 = jnp.pi / 2 - jnp.arctan2(q1[1], q1[0])
    phi2 = -jnp.pi / 2 - jnp.arctan2(q2[1], q2[0])
    x = jnp.concatenate([zero, zero, jnp.stack([phi2])])
    return jax.lax.stop_gradient(x), phi1


def _limits(pair: VHCattPair):
    geo = pair_geometry(pair)
    return geo["ra1"], geo["rf1"], geo["ra2"], geo["rf2"], 0.5 * pair.face_width


def vh_margin(pair: VHCattPair, path: ContactPath):
    """Boundary margin (mm, >= 0 inside both flanks) along the path, and its parts
    (tip, form circle, face width of pinion; the same of the gear)."""
    ra1, rf1, ra2, rf2, hb = _limits(pair)
    parts = jnp.stack([ra1 - path.radial1, path.radial1 - rf1, hb - jnp.abs(path.axial1),
                       ra2 - path.radial2, path.radial2 - rf2, hb - jnp.abs(path.axial2)])
    return jnp.min(parts, axis=0), parts


def _face_ends(pair: VHCattPair):
    ra1, rf1, ra2, rf2, hb = _limits(pair)

    def margin_parts(q1, q2, uv1=None, uv2=None):
        r1 = jnp.linalg.norm(q1[..., :2], axis=-1)
        r2 = jnp.linalg.norm(q2[..., :2], axis=-1)
        return (hb - jnp.abs(q1[..., 2]), jnp.minimum(ra1 - r1, r1 - rf1),
                hb - jnp.abs(q2[..., 2]), jnp.minimum(ra2 - r2, r2 - rf2))

    def g(q, e):
        return q[2] - e * hb

    return margin_parts, g, g


def vh_tca_traced(pair: VHCattPair, mis: Misalignment, code, *, steps_per_pitch: int = 24,
                  half_pitches: float = 1.25, n_pairs: int = 3, approach=DEFAULT_APPROACH,
                  face_ends: bool = True):
    """Traceable point-contact TCA: ``(path, margin, multi)`` on the uniform grid of
    pinion angles ``phi1_ref + k 2 pi/(z1 steps_per_pitch)``, ``|k| <=
    round(half_pitches steps_per_pitch)``; with ``face_ends`` the edge contacts at the
    face ends are solved too (:func:`gearjax.edge_contact.face_end_contact`)."""
    x_ref, phi1_ref = reference_guess(pair, code)
    grid = pinion_angle_grid(phi1_ref, pair.z1, steps_per_pitch, half_pitches)
    r1, r2 = vh_flanks(pair, code)
    asm = vh_assembly(pair)
    path = contact_path(r1, r2, asm, mis, grid, x_ref, line_contact=False, approach=approach)
    margin, _ = vh_margin(pair, path)
    if face_ends:
        parts, g1, g2 = _face_ends(pair)
        path, margin, _ = face_end_contact(r1, r2, asm, mis, path, margin, parts, g1, g2,
                                           drive=code < 0, line_contact=False,
                                           steps_per_pitch=steps_per_pitch)
    multi = multi_pair(path, margin, steps_per_pitch, pair.z1, drive=(code < 0),
                       n_pairs=n_pairs)
    return path, margin, multi


def _parts(pair, mis, code, *, steps_per_pitch, half_pitches, n_pairs, approach, kinematics,
           face_ends):
    path, margin, multi = vh_tca_traced(pair, mis, code, steps_per_pitch=steps_per_pitch,
                                        half_pitches=half_pitches, n_pairs=n_pairs,
                                        approach=approach, face_ends=face_ends)
    _, parts = vh_margin(pair, path)
    kin = None
    if kinematics:
        r1, r2 = vh_flanks(pair, code)
        kin = contact_kinematics(r1, r2, vh_assembly(pair), mis, path, line_contact=False)
    return path, margin, multi, {"margin_parts": parts}, kin


def vh_result_traced(pair: VHCattPair, mis: Misalignment, *, side: str = "drive",
                     steps_per_pitch: int = 24, half_pitches: float = 1.25, n_pairs: int = 3,
                     approach=DEFAULT_APPROACH, kinematics: bool = True,
                     face_ends: bool = True) -> TCAResult:
    """:func:`vh_tca_traced` as a :class:`~gearjax.tca_result.TCAResult` (traceable)."""
    parts = _parts(pair, mis, side_code(side), steps_per_pitch=steps_per_pitch,
                   half_pitches=half_pitches, n_pairs=n_pairs, approach=approach,
                   kinematics=kinematics, face_ends=face_ends)
    return TCAResult(*parts, side, "vh_catt")


# the side code enters only as a number: drive and coast share one compiled program
@partial(jax.jit, static_argnames=("steps_per_pitch", "half_pitches", "n_pairs", "kinematics",
                                   "face_ends"))
def _result_jit(pair, mis, approach, code, *, steps_per_pitch, half_pitches, n_pairs,
                kinematics, face_ends):
    return _parts(pair, mis, code, steps_per_pitch=steps_per_pitch, half_pitches=half_pitches,
                  n_pairs=n_pairs, approach=approach, kinematics=kinematics,
                  face_ends=face_ends)


def _result(pair, mis, approach, side, **static) -> TCAResult:
    parts = _result_jit(strong_float64(pair), strong_float64(mis), approach,
                        side_code(side), **static)
    return TCAResult(*parts, side, "vh_catt")


SUMMARY_KEYS = ("ptp_rad", "phi2_ref_rad", "axial1_mm", "radial1_mm", "axial2_mm",
                "radial2_mm", "semi_major_mm")


def tca_summary(path: ContactPath, multi):
    """Scalar summary in :data:`SUMMARY_KEYS` order (as the involute family's): TE
    peak-to-peak, gear angle at the reference, bearing position on both flanks at the
    reference (axial z, radius) and the ellipse semi-major axis there."""
    mid = path.phi1.shape[0] // 2
    return jnp.stack([multi.ptp, path.phi2[mid], path.axial1[mid], path.radial1[mid],
                      path.axial2[mid], path.radial2[mid], path.semi_major[mid]])


@partial(jax.jit, static_argnames=("steps_per_pitch", "half_pitches"))
def _sensitivity_jit(pair, mis, code, steps_per_pitch, half_pitches):
    def f(m):
        path, _, multi = vh_tca_traced(pair, m, code, steps_per_pitch=steps_per_pitch,
                                       half_pitches=half_pitches, face_ends=False)
        return tca_summary(path, multi)
    return f(mis), jax.jacfwd(f)(mis)


class _Adapter:
    """The VH-CATT family behind :func:`gearjax.run_tca` (designs: :class:`VHCattPair` or
    the design-file object of :mod:`gearjax.gears.vh_catt.design_file`)."""

    family = "vh_catt"
    defaults = dict(steps_per_pitch=24, half_pitches=1.25, n_pairs=3)

    def run(self, des, mis=None, *, side="drive", steps_per_pitch=24, half_pitches=1.25,
            n_pairs=3, approach=DEFAULT_APPROACH, kinematics=True, strict=True,
            face_ends=True, line_contact=None):
        side = check_side(side)
        _no_line_contact(line_contact)
        check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach)
        mis = Misalignment.zero() if mis is None else mis
        res = _result(pair_of(des), mis, float(approach), side,
                      steps_per_pitch=int(steps_per_pitch), half_pitches=float(half_pitches),
                      n_pairs=int(n_pairs), kinematics=bool(kinematics),
                      face_ends=bool(face_ends))
        if strict:
            check_on_flank_converged(res.path, res.margin)
        return res

    def traced(self, des, *, side="drive", steps_per_pitch=24, half_pitches=1.25, n_pairs=3,
               approach=DEFAULT_APPROACH, kinematics=True, face_ends=True, line_contact=None):
        side = check_side(side)
        _no_line_contact(line_contact)
        check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach)

        def f(pair, mis=None):
            mis = Misalignment.zero() if mis is None else mis
            return _result(pair_of(pair), mis, approach, side,
                           steps_per_pitch=int(steps_per_pitch),
                           half_pitches=float(half_pitches), n_pairs=int(n_pairs),
                           kinematics=bool(kinematics), face_ends=bool(face_ends))
        f.pair = pair_of(des)
        return f

    def outline(self, des, side="drive"):
        """Pinion flank limits for the TCA figure (concrete floats, mm): face_half,
        root_radius (form circle of the straight blade), tip_radius."""
        ra1, rf1, _, _, hb = _limits(pair_of(des))
        return dict(face_half=float(hb), root_radius=float(rf1), tip_radius=float(ra1))

    def mesh(self, des, *, side="drive", **_):
        """``(teeth_of, pair, pair)`` for the loaded contact (:mod:`gearjax.gears.vh_catt.mesh`)."""
        from gearjax.gears.vh_catt.mesh import vh_mesh_teeth
        drive = check_side(side) == "drive"
        pair = pair_of(des)
        return TeethOf(vh_mesh_teeth, (("drive", drive),)), pair, pair

    def sensitivity(self, des, mis=None, *, side="drive", steps_per_pitch=24,
                    half_pitches=1.25, **_):
        """``(values, table)``: the summary (:data:`SUMMARY_KEYS`) and its derivatives with
        respect to dE, dP, dG (per mm) and dSigma (per rad) by ``jax.jacfwd``."""
        side = check_side(side)
        mis = Misalignment.zero() if mis is None else mis
        vals, jac = _sensitivity_jit(strong_float64(pair_of(des)), strong_float64(mis),
                                     side_code(side), int(steps_per_pitch), float(half_pitches))
        values = {k: float(v) for k, v in zip(SUMMARY_KEYS, np.asarray(vals))}
        table = {k: {n: float(np.asarray(getattr(jac, n))[i])
                     for n in ("dE", "dP", "dG", "dSigma")} for i, k in enumerate(SUMMARY_KEYS)}
        return values, table


def _no_line_contact(line_contact):
    if line_contact:
        raise ValueError("line_contact = True: a VH-CATT pair touches at a point (its traces "
                         "differ by the blade offset); allowed: None or False")


ADAPTER = _Adapter()
register_family(VHCattPair, ADAPTER)
