"""Tooth contact analysis of face-milled hypoid and spiral-bevel pairs (family adapter).

Builds, for a pinion flank and a gear flank of :mod:`gearjax.gears.hypoid.flank`
(:class:`~gearjax.gears.hypoid.flank.FlankSpec`: cutter blade, machine settings, blank),
everything the generic core :mod:`gearjax.tca` needs:

* Flank functions, mounting and flank boundaries: :mod:`gearjax.gears.hypoid.pair`.

* **Reference contact** (:func:`reference_guess`).  The mean points of the two
  flanks (mid face, mid blade) are brought together by the two body rotations:
  a coarse search over ``(phi1, phi2)`` and both hands ``h`` minimises
  ``|p1 - p2|^2 + L^2 (1 + n1 . n2)`` (the outward normals of touching flanks are
  opposite, ``L`` = 10 mm), then the core's Newton solves the exact contact.  The
  hand is thereby *checked*: a pair whose flanks cannot be brought into contact
  with opposite normals is reported, not forced.

Units: mm, rad inside; arc-seconds at the output boundary.
"""

from __future__ import annotations

import functools
import math
from dataclasses import replace
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.gears.hypoid.design_file import HypoidDesign
from gearjax.gears.hypoid.flank import face_apex_offset, root_apex_offset
from gearjax.gears.hypoid.pair import (SIDES, HypoidPair, complementary_pinion, flank_coordinates,
                                       program_pair,
                                       flank_function, hypoid_assembly, hypoid_face_ends,
                                       hypoid_margin,
                                       mean_dedendum, mean_point, pair_flanks, with_point_radius)
from gearjax.edge_contact import face_end_contact
from gearjax.newton import newton_solve
from gearjax.surfaces import GeneratedSurface
from gearjax.loaded_contact import TeethOf
from gearjax.tca_result import (TCAResult, check_side, contact_kinematics, register_family,
                                strong_float64)
from gearjax.tca import (DEFAULT_APPROACH, ContactPath, Misalignment, MultiPair,
                         NoContactError, check_on_flank_converged, check_tca_options,
                         contact_path, contact_system, multi_pair, pinion_angle_grid)

__all__ = ["mean_dedendum", "HypoidPair", "pair_flanks", "complementary_pinion",
           "hypoid_assembly", "flank_function", "reference_guess", "hypoid_margin",
           "flank_coordinates", "hypoid_tca_traced", "hypoid_tca", "SIDES", "HypoidTCA",
           "Prepared", "prepare", "with_point_radius", "pinion_outline",
           "misalignment_sensitivity", "reference_contact", "tca_summary", "SUMMARY_KEYS",
           "hypoid_result_traced"]























def reference_guess(pair: HypoidPair, n_search: int = 181):
    """Initial guess ``x_ref = (theta1, s1, theta2, s2, phi2)`` and ``phi1_ref`` for the
    reference contact, and the hand of the mounting (concrete; module docstring).

    Returns ``(x_ref, phi1_ref, hand, (gap, angle))``: the distance of the mean points
    (mm) and the angle between the normals (deg, 0 = exactly opposite) at the chosen
    configuration.
    """
    return _search(pair, n_search)[:4]


def _search(pair: HypoidPair, n_search: int):
    """:func:`reference_guess`, plus the pinion's mean point and outward normal (body frame)."""
    (uv1, q1, n1), (uv2, q2, n2) = (mean_point(pair.pinion, pair.pinion_crossing),
                                    mean_point(pair.gear, pair.gear_crossing))
    a = np.linspace(-np.pi, np.pi, n_search, endpoint=False)
    A1, A2 = np.meshgrid(a, a, indexing="ij")
    best = None
    L2 = 100.0
    for h in (1, -1):
        asm = hypoid_assembly(replace(pair, hand=h))
        R0, c0 = np.asarray(asm.R0), np.asarray(asm.c0)
        p1 = _rotz_np(A1, q1)
        m1 = _rotz_np(A1, n1)
        p2 = c0[:, None, None] + np.einsum("ij,jab->iab", R0, _rotz_np(A2, q2))
        m2 = np.einsum("ij,jab->iab", R0, _rotz_np(A2, n2))
        obj = np.sum((p1 - p2) ** 2, axis=0) + L2 * (1.0 + np.sum(m1 * m2, axis=0))
        i, j = np.unravel_index(np.argmin(obj), obj.shape)
        if best is None or obj[i, j] < best[0]:
            gap = float(np.sqrt(np.sum((p1[:, i, j] - p2[:, i, j]) ** 2)))
            ang = float(np.degrees(np.arccos(np.clip(-np.sum(m1[:, i, j] * m2[:, i, j]), -1, 1))))
            best = (obj[i, j], h, a[i], a[j], gap, ang)
    _, h, ph1, ph2, gap, ang = best
    x_ref = np.array([uv1[0], uv1[1], uv2[0], uv2[1], ph2])
    return x_ref, float(ph1), int(h), (gap, ang), q1, n1


def _rotz_np(a, v):
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[0] - s * v[1], s * v[0] + c * v[1], np.broadcast_to(v[2], np.shape(a))])








def _mean_point_contact(r1, r2, pair: HypoidPair, mis: Misalignment, x_guess, phi1_guess):
    """Where the pinion's point ``uv1 = x_guess[:2]`` meets the gear flank: position
    coincidence and one normal equation for ``(phi1, theta2, s2, phi2)``, with the
    motion parameters of the generated flanks and their meshing equations beside
    them (:func:`~gearjax.tca.contact_system`).  Returns the Newton result (``x[0]``
    = phi1, differentiable), the contact system and the 5-vector ``x1``."""
    cs = contact_system(r1, r2, hypoid_assembly(pair), mis, False)
    x_guess = jax.lax.stop_gradient(jnp.asarray(x_guess, float))
    uv1 = x_guess[:2]
    psis = [jax.lax.stop_gradient(r.solve(uv).x) if isinstance(r, GeneratedSurface) else None
            for r, uv in ((r1, uv1), (r2, x_guess[2:4]))]
    n_psi = sum(p is not None for p in psis)

    def G(y, _):
        z = jnp.concatenate([uv1, y[1:4 + n_psi]])
        f = cs.F(z, y[0])
        return jnp.concatenate([f[:4], f[5:]])        # all but the second normal eq.

    y0 = jnp.concatenate([jnp.stack([jnp.asarray(phi1_guess, float)]), x_guess[2:]]
                         + [jnp.reshape(p, (1,)) for p in psis if p is not None])
    sol = newton_solve(G, y0, (), tol=1e-11, max_steps=40, natural_monotonicity=True)
    x1 = jnp.concatenate([uv1, sol.x[1:4]])
    return sol, cs, x1


def reference_contact(pair: HypoidPair, mis: Misalignment, x_guess, phi1_guess):
    """Refine the reference contact near the pinion's mean point (traceable, no derivatives).

    Step 1 keeps the pinion point ``uv1`` of the guess fixed and solves position
    coincidence and one normal equation for ``(phi1, theta2, s2, phi2)`` (4x4, with
    the generating motions as unknowns): where the pinion's mean point meets the
    gear flank.  Step 2 solves the full point contact at that ``phi1``.  Returns
    ``(x_ref, phi1_ref, ok)`` (``phi1_ref`` differentiable with respect to the
    settings); where step 2 fails (a pair in line contact, whose 5x5 system is
    singular) ``x_ref`` is step 1's.
    """
    r1 = flank_function(pair.pinion, pair.pinion_crossing)
    r2 = flank_function(pair.gear, pair.gear_crossing)
    s1, cs, x1 = _mean_point_contact(r1, r2, pair, mis, x_guess, phi1_guess)
    x1 = jax.lax.stop_gradient(x1)
    z1 = jnp.concatenate([x1, jax.lax.stop_gradient(s1.x[4:])])
    s2 = newton_solve(cs.F, z1, s1.x[0], tol=1e-11, max_steps=40,
                      natural_monotonicity=True)
    x_ref = jnp.where(s2.converged, cs.split(s2.x)[0], x1)
    # phi1_ref keeps its (implicit-function) derivatives: the grid moves with the
    # settings, so the reference contact stays the pinion's mean point under
    # differentiation as it does under finite differences
    return jax.lax.stop_gradient(x_ref), s1.x[0], s1.converged


class HypoidTCA(NamedTuple):
    """Result of a hypoid/spiral-bevel TCA.

    path : :class:`~gearjax.tca.ContactPath` of tooth pair 0 (TE in rad).
    margin : (N,) boundary margin (mm, >= 0 on both working flanks).
    multi : :class:`~gearjax.tca.MultiPair` (consecutive pairs, envelope, ptp,
        transfer points, contact ratio).
    coords : ``{xi1, h1, xi2, h2}`` face-width position (-1 toe .. +1 heel) and
        height above the root cone (mm) of the contact on pinion (1) and gear (2).
    """

    path: ContactPath
    margin: jax.Array
    multi: MultiPair
    coords: dict


class Prepared(NamedTuple):
    """Concrete set-up of a pair for TCA (:func:`prepare`)."""

    pair: HypoidPair
    x_ref: np.ndarray
    phi1_ref: float
    drive: bool
    mismatch: tuple


MAX_GAP = 6.0      # mm, mean points of the flanks after the coarse search
MAX_ANGLE = 20.0   # deg, their normals from exactly opposite


def prepare(pair: HypoidPair, n_search: int = 181) -> Prepared:
    """Reference guess, hand of the mounting and sense of rotation (concrete).

    ``drive`` is True when the pinion flank pushes the gear for increasing ``phi1``:
    ``(e_z x p1) . n1 > 0`` at the reference point, ``n1`` the pinion normal out of
    its material.  Raises :class:`~gearjax.tca.NoContactError` when no hand and no
    body rotations bring the mean points of the flanks within ``MAX_GAP`` with
    normals within ``MAX_ANGLE`` of opposite (the flanks cannot mesh).
    """
    x_ref, phi1_ref, hand, (gap, ang), p, n = _search(pair, n_search)
    if not (gap < MAX_GAP and ang < MAX_ANGLE):
        raise NoContactError(
            f"the pinion and gear flanks cannot be brought into contact near their mean "
            f"points (best over both hands of the mounting: gap {gap:.3g} mm, normals "
            f"{ang:.3g} deg from opposite; limits {MAX_GAP:g} mm, {MAX_ANGLE:g} deg): check "
            "the flank sides, hands of spiral and mounting data")
    pair = replace(pair, hand=hand)
    c, s_ = math.cos(phi1_ref), math.sin(phi1_ref)
    p = np.array([c * p[0] - s_ * p[1], s_ * p[0] + c * p[1], p[2]])
    n = np.array([c * n[0] - s_ * n[1], s_ * n[0] + c * n[1], n[2]])
    drive = float(np.dot(np.cross([0.0, 0.0, 1.0], p), n)) > 0.0
    return Prepared(pair, x_ref, phi1_ref, drive, (gap, ang))


def hypoid_tca_traced(pair: HypoidPair, mis: Misalignment, x_ref, phi1_ref, *,
                      steps_per_pitch: int = 16, half_pitches: float = 2.0,
                      line_contact: bool = False, n_pairs: int = 5, drive: bool = True,
                      approach=DEFAULT_APPROACH, face_ends: bool = True,
                      tip_edges: bool = True) -> HypoidTCA:
    """Traceable TCA of a hypoid/spiral-bevel flank pair (see :func:`hypoid_tca`).

    Point contact: the reference contact is refined near the pinion's mean point
    (:func:`reference_contact`) and the grid is centred on its pinion angle.  Line
    contact (conjugate pairs): the grid is centred on ``phi1_ref`` and the pinion
    blade position ``s`` stays at ``x_ref[1]``.  With ``face_ends`` (default) the
    contact at the toe and heel of both members is solved too, with ``tip_edges``
    (default) also the contact of each member's tip edge (on its face cone) with the
    mating flank, and the contact made at each pinion angle is the surface or the edge
    contact
    (:func:`gearjax.edge_contact.face_end_contact`; ``path.edge_kind``).
    """
    r1 = flank_function(pair.pinion, pair.pinion_crossing)
    r2 = flank_function(pair.gear, pair.gear_crossing)
    if not line_contact:
        # step 1 of reference_contact: where the pinion's mean point meets the gear
        # flank.  Its step 2 (the 5x5 point contact at that pinion angle, from step
        # 1's solution) is exactly the path's first solve (the middle grid point is
        # that angle): solving it here too would put a third contact Newton into the
        # program.  Where step 1 fails the reference stays at the guess; the path's
        # own solves carry the convergence flags.
        x_guess = jax.lax.stop_gradient(jnp.asarray(x_ref, float))
        s1, _, x1 = _mean_point_contact(r1, r2, pair, mis, x_guess, phi1_ref)
        x_ref = jnp.where(s1.converged, jax.lax.stop_gradient(x1), x_guess)
        phi1_ref = jnp.where(s1.converged, s1.x[0],
                             jax.lax.stop_gradient(jnp.asarray(phi1_ref, float)))
    grid = pinion_angle_grid(phi1_ref, pair.z1, steps_per_pitch, half_pitches)
    asm = hypoid_assembly(pair)
    path = contact_path(r1, r2, asm, mis, grid, x_ref,
                        line_contact=line_contact, approach=approach)
    margin, coords = hypoid_margin(pair, path)
    if face_ends:
        parts, g1, g2, tips = hypoid_face_ends(pair)
        path, margin, _ = face_end_contact(r1, r2, asm, mis, path, margin, parts, g1, g2,
                                           drive=drive, line_contact=line_contact,
                                           steps_per_pitch=steps_per_pitch,
                                           tips=tips if tip_edges else None)
        _, coords = hypoid_margin(pair, path)
    multi = multi_pair(path, margin, steps_per_pitch, pair.z1, drive=drive, n_pairs=n_pairs)
    return HypoidTCA(path, margin, multi, coords)


# ``drive`` (the sense of rotation) is a traced argument of the programs, ``side`` a label
# put on the result outside them: the drive and coast flanks share one program
_STATIC = ("steps_per_pitch", "half_pitches", "line_contact", "n_pairs")


@functools.partial(jax.jit, static_argnames=_STATIC)
def _tca_jit(pair, mis, x_ref, phi1_ref, approach, drive, *, steps_per_pitch, half_pitches,
             line_contact, n_pairs):
    return hypoid_tca_traced(pair, mis, x_ref, phi1_ref, steps_per_pitch=steps_per_pitch,
                             half_pitches=half_pitches, line_contact=line_contact,
                             n_pairs=n_pairs, drive=drive, approach=approach)


def hypoid_tca(pair: HypoidPair | Prepared, mis: Misalignment | None = None, *,
               steps_per_pitch: int = 16, half_pitches: float = 2.0,
               line_contact: bool = False, n_pairs: int = 5,
               approach: float = DEFAULT_APPROACH, strict: bool = True) -> HypoidTCA:
    """Jitted TCA of a hypoid/spiral-bevel flank pair with validation.

    ``pair`` : a :class:`HypoidPair` (prepared here) or a :class:`Prepared`.
    The grid of pinion angles is uniform with ``steps_per_pitch`` steps per angular
    pitch ``2 pi/z1``, ``half_pitches`` pitches each side of the reference.
    ``line_contact=True`` for conjugate pairs (the 5x5 point-contact system is
    singular there).  ``strict`` raises :class:`~gearjax.errors.ConvergenceError`
    when a contact solve failed between the first and last on-flank grid points
    (or at the reference) and :class:`~gearjax.tca.NoContactError` when no grid
    point is on both flanks; ``strict=False`` returns the masks.
    """
    check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach)
    prep = pair if isinstance(pair, Prepared) else prepare(pair)
    if mis is None:
        mis = Misalignment.zero()
    out = _tca_jit(program_pair(prep.pair), strong_float64(mis), jnp.asarray(prep.x_ref),
                   jnp.asarray(prep.phi1_ref), float(approach), jnp.asarray(bool(prep.drive)),
                   steps_per_pitch=int(steps_per_pitch), half_pitches=float(half_pitches),
                   line_contact=bool(line_contact), n_pairs=int(n_pairs))
    if strict:
        check_on_flank_converged(out.path, out.margin)
    return out


SUMMARY_KEYS = ("ptp_rad", "phi2_ref_rad", "xi1", "h1_mm", "xi2", "h2_mm", "semi_major_mm",
                "path_angle_rad")


def tca_summary(pair: HypoidPair, res: HypoidTCA):
    """Scalar summary (traceable), in :data:`SUMMARY_KEYS` order.

    ptp_rad : peak-to-peak of the unloaded TE envelope over one pitch;
    phi2_ref_rad : gear angle at the reference pinion angle (its change is the TE
    shift at the mean contact); xi*, h*_mm : bearing position at the reference on
    pinion and gear flank (face-width position, height above the root cone);
    semi_major_mm : contact-ellipse semi-major axis at the reference;
    path_angle_rad : direction of the path of contact on the pinion flank at the
    reference, ``atan2(dh1, (F1/2) dxi1)`` by central differences of the grid (0 =
    lengthwise, pi/2 = along the profile).
    """
    p, c = res.path, res.coords
    mid = p.phi1.shape[0] // 2
    dxi = c["xi1"][mid + 1] - c["xi1"][mid - 1]
    dh = c["h1"][mid + 1] - c["h1"][mid - 1]
    ang = jnp.arctan2(dh, dxi * 0.5 * pair.pinion.blank.face_width)
    return jnp.stack([res.multi.ptp, p.phi2[mid], c["xi1"][mid], c["h1"][mid], c["xi2"][mid],
                      c["h2"][mid], p.semi_major[mid], ang])


@functools.partial(jax.jit, static_argnames=_STATIC)
def _sensitivity_jit(pair, mis, x_ref, phi1_ref, approach, drive, *, steps_per_pitch,
                     half_pitches, line_contact, n_pairs):
    def f(m):
        res = hypoid_tca_traced(pair, m, x_ref, phi1_ref, steps_per_pitch=steps_per_pitch,
                                half_pitches=half_pitches, line_contact=line_contact,
                                n_pairs=n_pairs, drive=drive, approach=approach)
        return tca_summary(pair, res)
    return f(mis), jax.jacfwd(f)(mis)


def misalignment_sensitivity(prep: Prepared, mis: Misalignment | None = None, *,
                             steps_per_pitch: int = 16, half_pitches: float = 2.0,
                             n_pairs: int = 5, approach: float = DEFAULT_APPROACH):
    """The V-H check by ``jax.jacfwd``: derivatives of the :func:`tca_summary` values
    (TE peak-to-peak, gear angle at the reference = TE shift, bearing position on
    both flanks, ellipse length, path angle) with respect to dE, dP, dG (per mm) and
    dSigma (per rad), exact through every contact solve (point contact).

    Returns ``(values, table)``: dicts keyed by :data:`SUMMARY_KEYS`; ``table[key]``
    is ``{"dE": .., "dP": .., "dG": .., "dSigma": ..}``.
    """
    check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach)
    if mis is None:
        mis = Misalignment.zero()
    vals, jac = _sensitivity_jit(program_pair(prep.pair), strong_float64(mis),
                                 jnp.asarray(prep.x_ref),
                                 jnp.asarray(prep.phi1_ref), float(approach),
                                 jnp.asarray(bool(prep.drive)),
                                 steps_per_pitch=int(steps_per_pitch),
                                 half_pitches=float(half_pitches), line_contact=False,
                                 n_pairs=int(n_pairs))
    values = {k: float(v) for k, v in zip(SUMMARY_KEYS, np.asarray(vals))}
    table = {k: {name: float(np.asarray(getattr(jac, name))[i])
                 for name in ("dE", "dP", "dG", "dSigma")} for i, k in enumerate(SUMMARY_KEYS)}
    return values, table


def pinion_outline(pair: HypoidPair) -> dict:
    """Axial projection of the pinion's working flank boundary for plots (concrete).

    Corners toe-root, heel-root, heel-tip, toe-tip in (body z from the crossing
    point, radius) mm: the toe and heel lines ``l_p = A_o - F`` and ``l_p = A_o``
    (distance along the pitch generatrix, as in :mod:`gearjax.gears.hypoid.flank`)
    intersected with the root cone and the face cone.
    """
    b = pair.pinion.blank
    gp = float(b.pitch_angle)
    Ao, F = float(b.outer_cone_distance), float(b.face_width)
    cones = [(float(b.root_angle), float(root_apex_offset(b))),
             (float(b.face_angle), float(face_apex_offset(b)))]

    def corner(L, cone):
        g, c = cone
        x = (L - math.sin(gp) * math.tan(g) * c) / (math.cos(gp) + math.sin(gp) * math.tan(g))
        return [x - float(pair.pinion_crossing), math.tan(g) * (x + c)]

    pts = [corner(Ao - F, cones[0]), corner(Ao, cones[0]), corner(Ao, cones[1]),
           corner(Ao - F, cones[1])]
    return {"outline": np.array(pts + [pts[0]])}


# -- the common TCA interface (gearjax.tca_result) --------------------------------------

def hypoid_result_traced(pair: HypoidPair, mis: Misalignment, x_ref, phi1_ref, *,
                         side: str, drive: bool, steps_per_pitch: int = 16, half_pitches: float = 2.0,
                         line_contact: bool = False, n_pairs: int = 5,
                         approach=DEFAULT_APPROACH, kinematics: bool = True) -> TCAResult:
    """:func:`hypoid_tca_traced` as a :class:`~gearjax.tca_result.TCAResult` with the
    kinematics at the contact points (traceable).  ``side`` "drive"/"coast" labels the
    flank pair (drive = pinion concave on gear convex); ``drive`` is the sense of
    rotation found by :func:`prepare` (True: the pinion flank pushes the gear for
    increasing ``phi1``), which picks the max or min TE envelope."""
    res = hypoid_tca_traced(pair, mis, x_ref, phi1_ref, steps_per_pitch=steps_per_pitch,
                            half_pitches=half_pitches, line_contact=line_contact,
                            n_pairs=n_pairs, drive=drive, approach=approach)
    kin = None
    if kinematics:
        kin = contact_kinematics(flank_function(pair.pinion, pair.pinion_crossing),
                                 flank_function(pair.gear, pair.gear_crossing),
                                 hypoid_assembly(pair), mis, res.path, line_contact=line_contact)
    return TCAResult(res.path, res.margin, res.multi, res.coords, kin, side, "hypoid")


_RSTATIC = ("steps_per_pitch", "half_pitches", "line_contact", "n_pairs", "kinematics")


@functools.partial(jax.jit, static_argnames=_RSTATIC)
def _result_program(pair, mis, x_ref, phi1_ref, approach, drive, *, steps_per_pitch,
                    half_pitches, line_contact, n_pairs, kinematics):
    return hypoid_result_traced(pair, mis, x_ref, phi1_ref, side="", drive=drive,
                                steps_per_pitch=steps_per_pitch, half_pitches=half_pitches,
                                line_contact=line_contact, n_pairs=n_pairs, approach=approach,
                                kinematics=kinematics)


def _result_jit(pair, mis, x_ref, phi1_ref, approach, *, side, drive, **static):
    """The compiled TCA-result program (one for both sides and every tooth number and
    hand: ``pair`` through :func:`program_pair`, ``drive`` traced) with ``side`` put
    on the result."""
    res = _result_program(program_pair(pair), mis, x_ref, phi1_ref, approach,
                          jnp.asarray(drive), **static)
    return replace(res, side=side)


def _join_unchanged(pair, _extra):
    """The loaded chain's ``join_pair`` of this family: the pair needs nothing back."""
    return pair


class _Adapter:
    """The spiral-bevel/hypoid family behind :func:`gearjax.run_tca`.  Designs: a
    loaded design file (``side`` picks the flanks: drive = pinion concave on gear
    convex), a :class:`HypoidPair` or a :class:`Prepared` pair (its flanks fix the
    side; a ``side`` that contradicts them raises ValueError)."""

    family = "hypoid"
    defaults = dict(steps_per_pitch=16, half_pitches=2.0, n_pairs=5)
    # the loaded chain's program takes the pair through program_pair (one program for
    # every tooth number and hand)
    split_pair = staticmethod(lambda pair: (program_pair(pair), None))
    join_pair = staticmethod(_join_unchanged)

    @staticmethod
    def _prepared(design, side):
        side = check_side(side) if side is not None else None
        if isinstance(design, (Prepared, HypoidPair)):
            pair = design.pair if isinstance(design, Prepared) else design
            # drive = pinion concave (outside blade, sign -1) on gear convex (SIDES)
            found = "drive" if pair.pinion.cutter.sign == -1 else "coast"
            if side is not None and side != found:
                raise ValueError(f"side = {side!r}: the pinion flank of this pair is "
                                 f"{SIDES[found][0]}, i.e. the {found} side (build the pair "
                                 "of the other side from the design)")
            prep = design if isinstance(design, Prepared) else prepare(design)
            return prep, found
        side = side or "drive"                  # a design file: side picks the flanks
        return prepare(pair_flanks(design, side)), side

    def check(self, design):
        """A hand-built :class:`HypoidPair` (or a prepared one) in the ranges of the
        cutter and machine constructors, in mm and rad
        (:func:`~gearjax.gears.hypoid.pair.check_pair_fields`;
        :func:`gearjax.tca_result.check_design`); a design file is validated by its
        loader."""
        from gearjax.gears.hypoid.pair import check_pair_fields
        if isinstance(design, (Prepared, HypoidPair)):
            check_pair_fields(design.pair if isinstance(design, Prepared) else design)

    def run(self, design, mis=None, *, side=None, steps_per_pitch=16, half_pitches=2.0,
            n_pairs=5, line_contact=False, approach=DEFAULT_APPROACH, kinematics=True,
            strict=True):
        check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach)
        prep, side = self._prepared(design, side)
        mis = Misalignment.zero() if mis is None else mis
        res = _result_jit(prep.pair, strong_float64(mis), jnp.asarray(prep.x_ref),
                          jnp.asarray(prep.phi1_ref),
                          float(approach), side=side, drive=bool(prep.drive),
                          steps_per_pitch=int(steps_per_pitch),
                          half_pitches=float(half_pitches), line_contact=bool(line_contact),
                          n_pairs=int(n_pairs), kinematics=bool(kinematics))
        if strict:
            check_on_flank_converged(res.path, res.margin)
        return res

    def traced(self, design, *, side=None, steps_per_pitch=16, half_pitches=2.0, n_pairs=5,
               line_contact=False, approach=DEFAULT_APPROACH, kinematics=True):
        check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach)
        prep, side = self._prepared(design, side)
        x_ref, phi1_ref = jnp.asarray(prep.x_ref), jnp.asarray(prep.phi1_ref)
        hand, drive = prep.pair.hand, bool(prep.drive)

        def f(pair: HypoidPair, mis=None):
            # the jitted program of ``run`` (composable: inside a user's jit/grad/vmap
            # it is traced once and inlined; called eagerly it runs compiled, not op
            # by op)
            mis = Misalignment.zero() if mis is None else mis
            return _result_jit(replace(pair, hand=hand), strong_float64(mis),
                               x_ref, phi1_ref, approach,
                               side=side, drive=drive, steps_per_pitch=int(steps_per_pitch),
                               half_pitches=float(half_pitches), line_contact=bool(line_contact),
                               n_pairs=int(n_pairs), kinematics=bool(kinematics))
        f.pair = prep.pair
        return f

    def mesh(self, design, *, side=None, **_):
        """``(teeth_of, pair, prepared)`` of the loaded-contact models (concrete
        set-up): ``teeth_of(pair, res) -> MeshTeeth``, the differentiable pair and the
        prepared pair to run the TCA of."""
        from gearjax.gears.hypoid.mesh import hypoid_mesh_teeth
        prep, _ = self._prepared(design, side)
        return TeethOf(hypoid_mesh_teeth, (("drive", bool(prep.drive)),)), prep.pair, prep

    def sensitivity(self, design, mis=None, *, side=None, steps_per_pitch=16, half_pitches=2.0,
                    n_pairs=5, approach=DEFAULT_APPROACH, **_):
        prep, _ = self._prepared(design, side)
        return misalignment_sensitivity(prep, mis, steps_per_pitch=steps_per_pitch,
                                        half_pitches=half_pitches, n_pairs=n_pairs,
                                        approach=approach)


for _t in (HypoidDesign, HypoidPair, Prepared):
    register_family(_t, _Adapter())
