"""Tooth contact analysis of face-milled hypoid and spiral-bevel pairs: the family for the
one driver (:mod:`gearjax.tca.family`).

Builds, for a pinion flank and a gear flank of :mod:`gearjax.gears.hypoid.flank`
(:class:`~gearjax.gears.hypoid.flank.FlankSpec`: cutter blade, machine settings, blank),
everything the generic core :mod:`gearjax.tca.path` needs:

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

import math
from dataclasses import dataclass, replace
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.tca.family import DriverAdapter, GearFamily
from gearjax.gears.hypoid.design_file import HypoidDesign
from gearjax.gears.hypoid.flank import face_apex_offset, root_apex_offset
from gearjax.gears.hypoid.pair import (SIDES, HypoidPair, complementary_pinion, flank_coordinates,
                                       flank_function, hypoid_assembly, hypoid_face_ends,
                                       hypoid_margin, mean_dedendum, mean_points,
                                       mean_points_ahead, pair_flanks, program_pair,
                                       with_point_radius)
from gearjax.loading.loaded_contact import TeethOf
from gearjax.newton import newton_solve
from gearjax.surfaces import GeneratedSurface
from gearjax.tca.path import NoContactError, contact_system
from gearjax.tca.assembly import Misalignment
from gearjax.tca.result import register_family

__all__ = ["mean_dedendum", "HypoidPair", "pair_flanks", "complementary_pinion",
           "hypoid_assembly", "flank_function", "reference_guess", "hypoid_margin",
           "flank_coordinates", "SIDES", "Prepared", "prepare", "with_point_radius",
           "pinion_outline", "reference_contact", "tca_summary", "SUMMARY_KEYS",
           "HypoidFamily", "SensedPair", "FAMILY", "ADAPTER"]


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
    (uv1, q1, n1), (uv2, q2, n2) = mean_points(pair)
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
    them (:func:`~gearjax.tca.path.contact_system`).  Returns the Newton result (``x[0]``
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
    its material.  Raises :class:`~gearjax.tca.path.NoContactError` when no hand and no
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


SUMMARY_KEYS = ("ptp_rad", "phi2_ref_rad", "xi1", "h1_mm", "xi2", "h2_mm", "semi_major_mm",
                "path_angle_rad")


def tca_summary(pair: HypoidPair, res):
    """Scalar summary (traceable), in :data:`SUMMARY_KEYS` order.

    ptp_rad : peak-to-peak of the unloaded TE envelope over one pitch;
    phi2_ref_rad : gear angle at the reference pinion angle (its change is the TE
    shift at the mean contact); xi*, h*_mm : bearing position at the reference on
    pinion and gear flank (face-width position, height above the root cone);
    semi_major_mm : contact-ellipse semi-major axis at the reference;
    path_angle_rad : direction of the path of contact on the pinion flank at the
    reference, ``atan2(dh1, (F1/2) dxi1)`` by central differences of the grid (0 =
    lengthwise, pi/2 = along the profile).  ``res`` a :class:`~gearjax.TCAResult` of
    ``pair`` (its path and face-width coordinates).
    """
    p, c = res.path, res.coords
    mid = p.phi1.shape[0] // 2
    dxi = c["xi1"][mid + 1] - c["xi1"][mid - 1]
    dh = c["h1"][mid + 1] - c["h1"][mid - 1]
    ang = jnp.arctan2(dh, dxi * 0.5 * pair.pinion.blank.face_width)
    return jnp.stack([res.multi.ptp, p.phi2[mid], c["xi1"][mid], c["h1"][mid], c["xi2"][mid],
                      c["h2"][mid], p.semi_major[mid], ang])


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


# -- the family for the one driver (gearjax.tca.family) -------------------------------------

@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class SensedPair:
    """The driver's pair of this family: the flank pair and the sense of rotation its
    pinion flank pushes the gear for (``forward``, a boolean array: True for increasing
    ``phi1``, found by :func:`prepare`; traced, so that both senses share a program)."""

    pair: HypoidPair
    forward: jax.Array


def _prepared(design, side):
    """``(Prepared, side)`` of a design file (``side`` picks the flanks: drive = pinion
    concave on gear convex; None: drive), a :class:`HypoidPair` or a :class:`Prepared`
    (their flanks fix the side; a ``side`` that contradicts them is a ValueError)."""
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
    side = side or "drive"
    mean_points_ahead(design, side)       # compiles while pair_flanks computes the blank
    return prepare(pair_flanks(design, side)), side


class HypoidFamily(GearFamily):
    """Face-milled spiral-bevel and hypoid pairs for the driver.  Designs: a loaded
    design file (:class:`~gearjax.gears.hypoid.design_file.HypoidDesign`, ``side``
    picks the flanks), a :class:`HypoidPair` or a :class:`Prepared` pair (its flanks
    fix the side).  Set-up: :func:`prepare` (reference search, hand of the mounting,
    sense of rotation), concrete; inside the program the reference is refined to the
    contact of the pinion's mean point under the misalignment (point contact,
    :meth:`refine_reference`), so the grid moves with the settings.  Point contact by
    default; line contact for conjugate pairs (the 5x5 point-contact system is
    singular there).  Pairs pass :func:`~gearjax.gears.hypoid.pair.program_pair`
    (tooth numbers, hands and blade signs traced: one program for every pair)."""

    name = "hypoid"
    defaults = dict(steps_per_pitch=16, half_pitches=2.0, n_pairs=5)
    line_contact_modes = (False, True)
    summary_keys = SUMMARY_KEYS

    def check(self, design):
        """A hand-built :class:`HypoidPair` (or a prepared one) in the ranges of the
        cutter and machine constructors, in mm and rad
        (:func:`~gearjax.gears.hypoid.pair.check_pair_fields`); a design file is
        validated by its loader."""
        from gearjax.gears.hypoid.pair import check_pair_fields
        if isinstance(design, (Prepared, HypoidPair)):
            check_pair_fields(design.pair if isinstance(design, Prepared) else design)

    def setup(self, design, side):
        return _prepared(design, side)

    def early_setup(self, design, side):
        # a design file: its pair with placeholder crossing points, reference, hand and
        # sense (the program's structure; the blank and the search come later)
        if isinstance(design, (Prepared, HypoidPair)) or (side or "drive") not in SIDES:
            return None
        pair = pair_flanks(design, side or "drive", crossings=(0.0, 0.0))
        return Prepared(pair, np.zeros(5), 0.0, True, (0.0, 0.0))

    def user_pair(self, prep):
        return prep.pair

    def design_data(self, design, pair, side):
        """The design file with the pinion flank and the (complementary) gear flank of
        ``side`` taken from ``pair``'s machine settings and cutters
        (:func:`~gearjax.gears.hypoid.design_file.flank_settings_table`, file units)."""
        from gearjax.gears.hypoid.design_file import flank_settings_table
        data = design.to_dict()
        f1, f2 = SIDES[side]
        data["pinion"][f1] = flank_settings_table(pair.pinion)
        data["gear"][f2] = flank_settings_table(pair.gear)
        return data

    def program_pair(self, pair, prep):
        # the hand of the mounting found by the set-up
        return SensedPair(replace(pair, hand=prep.pair.hand), jnp.asarray(bool(prep.drive)))

    def split(self, tree):
        return program_pair(tree), None

    def reference(self, prep, side):
        return jnp.asarray(prep.x_ref), jnp.asarray(prep.phi1_ref)

    def refine_reference(self, sp, mis, r1, r2, x_ref, phi1_ref, line_contact):
        """Point contact: step 1 of :func:`reference_contact`, where the pinion's mean
        point meets the gear flank; its step 2 (the 5x5 point contact at that pinion
        angle) is exactly the path's first solve (the middle grid point is that angle).
        Where step 1 fails the reference stays at the guess; the path's own solves
        carry the convergence flags.  Line contact: the grid stays on ``phi1_ref`` and
        the blade position ``s`` at ``x_ref[1]``."""
        if line_contact:
            return x_ref, phi1_ref
        x_guess = jax.lax.stop_gradient(jnp.asarray(x_ref, float))
        s1, _, x1 = _mean_point_contact(r1, r2, sp.pair, mis, x_guess, phi1_ref)
        x_ref = jnp.where(s1.converged, jax.lax.stop_gradient(x1), x_guess)
        phi1_ref = jnp.where(s1.converged, s1.x[0],
                             jax.lax.stop_gradient(jnp.asarray(phi1_ref, float)))
        return x_ref, phi1_ref

    def flanks(self, sp, drive, line_contact=False):
        p = sp.pair
        return (flank_function(p.pinion, p.pinion_crossing),
                flank_function(p.gear, p.gear_crossing))

    def forward(self, sp, drive):
        return sp.forward

    def assembly(self, sp):
        return hypoid_assembly(sp.pair)

    def pinion_teeth(self, sp):
        return sp.pair.z1

    def boundaries(self, sp, path):
        return hypoid_margin(sp.pair, path)

    def path_position(self, sp, path, coords):
        # the face-width position on the pinion (-1 toe .. +1 heel)
        return coords["xi1"]

    def edges(self, sp):
        return hypoid_face_ends(sp.pair)

    def summary(self, sp, res):
        return tca_summary(sp.pair, res)

    def teeth(self, prep, side, line_contact=False):
        """The loaded-contact teeth (:mod:`gearjax.gears.hypoid.mesh`)."""
        from gearjax.gears.hypoid.mesh import hypoid_mesh_teeth
        return TeethOf(hypoid_mesh_teeth, (("drive", bool(prep.drive)),)), prep.pair

    def outline(self, design, side="drive"):
        pair = design.pair if isinstance(design, Prepared) else design
        if not isinstance(pair, HypoidPair):
            pair = pair_flanks(design, side)
        return pinion_outline(pair)


FAMILY = HypoidFamily()
ADAPTER = DriverAdapter(FAMILY)
for _t in (HypoidDesign, HypoidPair, Prepared):
    register_family(_t, ADAPTER)
