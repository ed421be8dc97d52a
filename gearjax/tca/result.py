"""The one result type of tooth contact analysis, shared by every gear family, and
the kinematics at its contact points.

:class:`TCAResult` is a pytree (``jax.grad`` and ``jit`` pass through it) holding

* ``path`` -- :class:`~gearjax.tca.path.ContactPath` of tooth pair 0 on the grid of
  pinion angles: TE (rad), the contact point on both flanks (body frames and
  fixed frame), the contact ellipses, residuals and converged flags;
* ``margin`` -- (N,) distance of the contact from the nearest flank boundary of
  either member (mm, >= 0 on both working flanks);
* ``multi`` -- :class:`~gearjax.tca.path.MultiPair`: TE of the neighbouring pairs, the
  unloaded TE envelope, its peak-to-peak, the transfer points, the contact ratio;
* ``coords`` -- family-specific coordinates of the contact on the flanks (hypoid:
  ``xi1, h1, xi2, h2``; involute: the six boundary margins, and the overlap ratio in
  line contact; ...), a dict, and in every family ``path_position`` (the contact's
  position along its path in the family's own coordinate, :mod:`gearjax.tca.family`);
* ``kinematics`` -- :class:`ContactKinematics` at every point of the path, or
  ``None`` when not requested;
* ``side`` (static) -- ``"drive"`` or ``"coast"``, the one side convention of
  every family; ``family`` (static) -- the family's name (``"involute"``,
  ``"hypoid"``, ``"vh_catt"``, ``"preset_bevel"``).

:meth:`TCAResult.flags` gives the contact-quality flags on concrete results
(converged, reference on the flank, edge contact -- at a flank boundary or a
face end --, contact ratio below 1, a large TE, a load carried where the flanks cross).

**Kinematics at the contact points** (:func:`contact_kinematics`).  Pinion =
member 1 turning at 1 rad/s about its body z axis, gear = member 2 turning at the
*actual* speed ``dphi2/dphi1`` about its mounted axis.  The contact point moves
with ``v_c = dr/dphi1``.  At a point contact both come from the flanks' curvatures
at the contact (:func:`contact_velocity`: the equation of meshing gives the gear
speed, Rodrigues' formula on both flanks the velocity), the curvatures the contact
ellipse is computed from; for a line contact, and for a path without curvatures,
from the implicit derivative of the contact equations, ``dx/dphi1 = -F_x^-1 F_phi1``
(:func:`contact_motion`).  The two routes agree to round-off (4e-12 of the largest
value or better on every packaged point-contact example, misaligned too); the first
needs no second derivatives of the flanks under ``grad``.  Surface velocities
relative to the moving contact point, projected on the tangent plane:
``w_i = P (omega_i x (r - a_i) - v_c)``.  The *rolling direction* ``t`` is across the
contact ellipse (``t = +-n x e_major``; for line contact: across the contact line),
the direction of the line-contact EHL theory, oriented along the entrainment
(``u_e >= 0``); along ``t``::

    u1 = w1 . t,   u2 = w2 . t,   u_e = (u1 + u2)/2,   u_s = u1 - u2,   SRR = u_s/u_e

(mm/s per rad/s of pinion speed) plus the side-slip ``u_s_side = (w1 - w2) . e_major``
and the angle of the entrainment vector ``(w1 + w2)/2`` from ``t``.  Curvature:
the relative curvature tensor ``B`` of the two flanks (:func:`~gearjax.tca.path.
relative_curvature`, oriented so that its trace is >= 0), ``R_x = 1/(t.B.t)``
across the ellipse (the effective radius of the EHL theory) and
``R_y = 1/(e_major.B.e_major)`` along it (``inf`` for line contact).  For a line
contact the velocity of the contact point along the contact line is arbitrary; the
components along ``t`` do not depend on it.

References (docs/references.md): [Litvin2004] ch. 8-9 (relative velocity, contact
point velocity, induced curvature); [Eigenfunctions] section 1 (u1, u2, u_e, u_s,
SRR, K_II, R_eff); [HamrockDowson1977] (R_x, R_y of the elliptic EHL contact).
Units: mm, rad, mm/s per rad/s.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.tca.edge_contact import CORNER_KINDS, EDGE_NAMES, FACE_END_KINDS, TIP_KINDS
from gearjax.errors import any_traced
from gearjax.fields import strong_float64
from gearjax.frames import matrix_z
from gearjax.newton import solve_small
from gearjax.surfaces import local_geometry
from gearjax.tca.path import (ARCSEC, ContactPath, MultiPair, contact_equations, contact_system,
                              relative_curvature)
from gearjax.tca.assembly import Assembly, Misalignment, gear_mount
from gearjax.tca.multi_pair import transfer_gaps

__all__ = ["SIDES", "check_side", "check_design",
           "TCAResult", "ContactKinematics", "contact_kinematics",
           "contact_motion", "contact_velocity", "strong_float64",
           "register_family", "family_of"]

#: the side convention of every family: the flank pair that transmits the load in
#: the normal sense of rotation ("drive") or in reverse ("coast")
SIDES = ("drive", "coast")
_SIDE_ALIASES = {-1: "drive", 1: "coast"}   # former involute convention (side = -1/+1)


def check_side(side) -> str:
    """``"drive"``/``"coast"``; the former involute codes -1 (drive) and +1 (coast) are
    accepted.  ValueError naming the allowed values otherwise."""
    if isinstance(side, str) and side in SIDES:
        return side
    if not isinstance(side, (bool, str)) and side in _SIDE_ALIASES:
        return _SIDE_ALIASES[side]
    raise ValueError(f"side = {side!r} must be 'drive' or 'coast'")


_SAME_TE = 1e-9   # rad (2e-4 arc-seconds): TE curves that coincide
#: rad (0.01 arc-seconds): a transfer gap below minus this is a smooth hand-over
#: (the TE curves cross inside the flanks; :func:`gearjax.tca.multi_pair.transfer_gaps`)
_GAP_SMOOTH = 0.01 * ARCSEC

#: arc-seconds: a TE peak-to-peak above this raises the ``large_te`` flag
LARGE_TE_ARCSEC = 60.0


class ContactKinematics(NamedTuple):
    """Rolling, sliding and curvature at every point of a TCA path (module docstring).

    u1, u2 : surface velocities of pinion and gear relative to the contact point
        along the rolling direction ``t`` (mm/s per rad/s of pinion speed).
    u_e, u_s, srr : entrainment ``(u1 + u2)/2``, sliding ``u1 - u2``, slide-to-roll
        ratio ``u_s/u_e`` (pinion = member 1).
    u_s_side : sliding along the major axis of the ellipse (mm/s per rad/s).
    entrainment_angle : angle of the entrainment vector from ``t`` (rad).
    r_x, r_y : effective radii across and along the contact ellipse (mm; ``r_y`` is
        ``inf`` for line contact); ``r_eff = r_x``.
    rolling_dir : (N, 3) unit ``t`` (fixed frame).  v_contact : (N, 3) ``dr/dphi1``.
    gear_ratio : actual ``dphi2/dphi1``.
    """

    u1: jax.Array
    u2: jax.Array
    u_e: jax.Array
    u_s: jax.Array
    srr: jax.Array
    u_s_side: jax.Array
    entrainment_angle: jax.Array
    r_x: jax.Array
    r_y: jax.Array
    rolling_dir: jax.Array
    v_contact: jax.Array
    gear_ratio: jax.Array

    @property
    def r_eff(self):
        return self.r_x


def contact_motion(r1: Callable, r2: Callable, asm: Assembly, mis: Misalignment,
                   line_contact: bool, v1_fixed):
    """``motion(uv1, uv2, phi2, phi1, n, W12=None, psi12=None) -> (r, v_c, dphi2, W1,
    W2)`` at one contact point (traceable): the contact point ``r`` (fixed frame), its
    velocity ``v_c = dr/dphi1`` and the gear speed ``dphi2/dphi1`` from the implicit
    derivative of the contact equations (``dx/dphi1 = -F_x^-1 F_phi1``), and both
    flanks' Weingarten maps in the fixed frame for the common normal ``n`` (computed
    here unless given as ``W12``, e.g. those of the contact path).  With ``psi12``,
    the generating motions of the contact on generated flanks (those of the contact
    path), the derivative is taken of :func:`~gearjax.tca.path.contact_system` (explicit,
    no envelope solve); without, of :func:`~gearjax.tca.path.contact_equations` (the
    nested envelope solves).  Also returns the gear mount ``(R, c)``."""
    R, c = gear_mount(asm, mis)
    ez = jnp.array([0.0, 0.0, 1.0])
    F, unpack, pack = contact_equations(r1, r2, asm, mis, line_contact, v1_fixed)
    cs = contact_system(r1, r2, asm, mis, line_contact, v1_fixed)

    def point(x, ph1):
        uv1, _, _ = unpack(x)
        return matrix_z(ph1) @ r1(uv1) + mis.dP * ez

    def motion(uv1, uv2, ph2, ph1, n, W12=None, psi12=None):
        x = pack(jnp.concatenate([uv1, uv2, jnp.stack([ph2])]))
        # F_x and F_phi1 in one forward-mode pass
        if psi12 is None:
            Fx, Fp = jax.jacfwd(F, (0, 1))(x, ph1)
            dx = -jnp.linalg.solve(Fx, Fp)
            r, v_c = jax.jvp(point, (x, ph1), (dx, jnp.ones_like(ph1)))
        else:
            z = cs.join(x, *psi12)
            Fz, Fp = jax.jacfwd(cs.F, (0, 1))(z, ph1)
            dz = -jnp.linalg.solve(Fz, Fp)
            r, v_c = jax.jvp(cs.point1, (z, ph1), (dz, jnp.ones_like(ph1)))
            dx = cs.split(dz)[0]
        if W12 is None:
            R1, R2 = matrix_z(ph1), R @ matrix_z(ph2)
            g1, g2 = local_geometry(r1, uv1), local_geometry(r2, uv2)
            W1 = jnp.sign(jnp.dot(R1 @ g1.n, n)) * (R1 @ g1.W @ R1.T)
            W2 = jnp.sign(jnp.dot(R2 @ g2.n, n)) * (R2 @ g2.W @ R2.T)
        else:
            W1, W2 = W12
        return r, v_c, dx[-1], W1, W2

    return motion, (R, c)


def contact_velocity(r, n, W1, W2, e, k2, c):
    """``(v_c, dphi2/dphi1)`` at a point contact from the flanks' curvatures (traceable).

    The pinion turns at 1 rad/s about its body z axis (``omega_1 = e_z``), the gear
    at ``m21 = dphi2/dphi1`` about its mounted axis ``k2`` through ``c``.  The contact
    point ``r`` (fixed frame) lies on both flanks, so the relative velocity
    ``v12 = e_z x r - m21 k2 x (r - c)`` is tangent to them (the equation of
    meshing ``n . v12 = 0``), which gives ``m21``.  The common normal ``n`` follows the
    contact on either flank (``dn = W_i dr`` along flank ``i``, Rodrigues)::

        omega_1 x n + W1 v_r1 = omega_2 x n + W2 v_r2,    v_r2 = v_r1 + v12,

    with ``v_r1`` the velocity of the contact point over the pinion flank (tangent):
    ``(W1 - W2) v_r1 = (omega_2 - omega_1) x n + W2 v12``, two equations in the tangent
    plane (basis from ``e``, :func:`~gearjax.tca.path.relative_curvature`), and
    ``v_c = e_z x r + v_r1``.  Litvin & Fuentes, *Gear Geometry and Applied Theory*,
    2nd ed., §8.5-8.6 (relations between curvatures and the contact point's
    velocity).  Equal, up to round-off, to the implicit derivative of the contact
    equations (:func:`contact_motion`), without second derivatives of the flanks:
    their curvatures ``W1, W2`` (for the normal ``n``, 1/mm) are those the contact
    ellipse comes from.  Singular for a line contact (``W1 - W2`` singular along the
    line); use :func:`contact_motion` there.  Units: mm, rad."""
    ez = jnp.array([0.0, 0.0, 1.0])
    w1 = jnp.cross(ez, r)
    w2_unit = jnp.cross(k2, r - c)
    m21 = jnp.dot(n, w1) / jnp.dot(n, w2_unit)
    v12 = w1 - m21 * w2_unit
    rhs = jnp.cross(m21 * k2 - ez, n) + W2 @ v12
    B, A = relative_curvature(n, W1, W2, e)            # B = -A^T (W1 - W2) A
    y = solve_small(-B, A.T @ rhs)
    return w1 + A @ y, m21


def contact_kinematics(r1: Callable, r2: Callable, asm: Assembly, mis: Misalignment,
                       path: ContactPath, *, line_contact: bool) -> ContactKinematics:
    """:class:`ContactKinematics` at every point of ``path`` (traceable; module docstring).

    ``r1, r2, asm, mis, line_contact`` must be those the path was solved with.  Points
    where the path did not converge give meaningless values: mask them with
    ``path.converged``.
    """
    # the fixed face-width parameter of a line contact: that of a surface contact (at
    # an edge contact the pinion point lies on a face end)
    ref = path.phi1.shape[0] // 2 if path.edge_kind is None else jnp.argmax(path.edge_kind < 0)
    motion, (R, c) = contact_motion(r1, r2, asm, mis, line_contact,
                                    jax.lax.stop_gradient(path.uv1[ref, 1]))
    k2 = R[:, 2]
    ez = jnp.array([0.0, 0.0, 1.0])

    def one(uv1, uv2, ph2, ph1, n, major, W12, psi12, point):
        e = major - jnp.dot(major, n) * n
        e = e / jnp.linalg.norm(e)
        if curvature_route:
            W1, W2 = W12
            r = point
            v_c, dph2 = contact_velocity(r, n, W1, W2, e, k2, c)
        else:
            r, v_c, dph2, W1, W2 = motion(uv1, uv2, ph2, ph1, n, W12, psi12)
        t = jnp.cross(n, e)

        def tangential(v):
            return v - jnp.dot(v, n) * n

        w1 = tangential(jnp.cross(ez, r) - v_c)
        w2 = tangential(jnp.cross(dph2 * k2, r - c) - v_c)
        # orient t along the entrainment (u_e >= 0): the rolling direction
        t = jnp.where(jnp.dot(w1 + w2, t) < 0.0, -t, t)
        u1, u2 = jnp.dot(w1, t), jnp.dot(w2, t)
        we = 0.5 * (w1 + w2)
        B, A = relative_curvature(n, W1, W2, t)     # A[:, 0] = t, A[:, 1] = n x t
        B = jnp.where(B[0, 0] + B[1, 1] < 0.0, -B, B)
        kx, ky = B[0, 0], B[1, 1]
        r_y = jnp.where(ky > 1e-12, 1.0 / jnp.where(ky > 1e-12, ky, 1.0), jnp.inf)
        u_e = 0.5 * (u1 + u2)
        return (u1, u2, u_e, u1 - u2, (u1 - u2) / u_e, jnp.dot(w1 - w2, A[:, 1]),
                jnp.arctan2(jnp.dot(we, A[:, 1]), jnp.dot(we, t)), 1.0 / kx, r_y, t, v_c,
                dph2)

    # the flanks' curvatures at the contact points are those of the path (its ellipses)
    W12 = None if path.weingarten1 is None else (path.weingarten1, path.weingarten2)
    # and so are the generating motions of the contact on generated flanks
    psi12 = None if path.psi1 is None else (path.psi1, path.psi2)
    # a point contact with the path's curvatures: the velocities from the curvatures
    # (:func:`contact_velocity`); a line contact (the velocity along the line is
    # fixed by the face-width section of the path), or a path without curvatures:
    # from the contact equations
    curvature_route = W12 is not None and not line_contact
    out = jax.vmap(one)(path.uv1, path.uv2, path.phi2, path.phi1, path.normal, path.major_dir,
                        W12, psi12, path.point)
    if path.edge_kind is not None:
        # at an edge contact one radius of curvature is zero and the surface-contact
        # equations behind the contact velocity do not hold: no rolling/sliding
        # values there (NaN, flagged by ``edge_kind``)
        edge = path.edge_kind >= 0
        out = [jnp.where(edge.reshape(edge.shape + (1,) * (a.ndim - 1)), jnp.nan, a)
               for a in out]
    return ContactKinematics(*out)


def _relative_forms(xp, path):
    """``(B_xx, B_yy, B_xy)`` (N,) of the relative curvature ``B = -A^T (W1 - W2) A`` in
    the basis ``A = [a1, n x a1]``, ``a1`` the major direction projected on the tangent
    plane (:func:`~gearjax.tca.path.relative_curvature`, vectorised over the points),
    with the array module ``xp`` (``jnp`` traced, ``np`` on concrete arrays: no dispatch
    per operation)."""
    n, e = xp.asarray(path.normal), xp.asarray(path.major_dir)
    W = xp.asarray(path.weingarten1) - xp.asarray(path.weingarten2)
    a1 = e - xp.sum(e * n, axis=-1, keepdims=True) * n
    a1 = a1 / xp.linalg.norm(a1, axis=-1, keepdims=True)
    a2 = xp.cross(n, a1)

    def form(u, v):
        return -xp.einsum("ni,nij,nj->n", u, W, v)

    return form(a1, a1), form(a2, a2), 0.5 * (form(a1, a2) + form(a2, a1))


def _definiteness(xp, path):
    """:func:`curvature_definiteness` with the array module ``xp``."""
    if path.weingarten1 is None:
        return xp.full(path.phi1.shape, np.nan)
    bxx, byy, bxy = _relative_forms(xp, path)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (bxx * byy - bxy ** 2) / (bxx ** 2 + byy ** 2 + 2.0 * bxy ** 2)


def _flanks_cross(xp, path):
    """:attr:`TCAResult.flanks_cross` with the array module ``xp`` (False where the
    definiteness is NaN: no curvatures, or B = 0)."""
    with np.errstate(invalid="ignore"):
        return _definiteness(xp, path) < -1e-9


def curvature_definiteness(path):
    """(N,) ``det B / (B_xx^2 + B_yy^2 + 2 B_xy^2)`` of the flanks' relative curvature at
    the path's points (traceable; dimensionless, in [-1/2, 1/2]; NaN where the path
    carries no curvatures).  With principal relative curvatures ``l1, l2`` it is
    ``l1 l2 / (l1^2 + l2^2)``: independent of the sense of the normal and of the tangent
    basis; about ``l_min / l_max = R_x / R_y = (b/a)^2`` of the contact ellipse where
    small; 0 in line contact; negative where the flanks cross (:attr:`TCAResult.
    flanks_cross` is ``< -1e-9``).  Through an edge of regression one principal
    curvature of the generated flank passes through infinity and this ratio passes
    smoothly through 0 (docs/tca.md, "Crossing flanks")."""
    return _definiteness(jnp, path)


class MaskCheck(NamedTuple):
    """:meth:`TCAResult.mask_check`: mask points off the flank and a smooth penalty."""

    n_off: jax.Array
    penalty: jax.Array


@functools.partial(jax.tree_util.register_dataclass,
                   data_fields=["path", "margin", "multi", "coords", "kinematics"],
                   meta_fields=["side", "family"])
@dataclass(frozen=True)
class TCAResult:
    """Result of tooth contact analysis of any family (module docstring; a pytree)."""

    path: ContactPath
    margin: jax.Array
    multi: MultiPair
    coords: dict
    kinematics: ContactKinematics | None = None
    side: str = "drive"
    family: str = ""

    # -- the quantities users ask for first ------------------------------------------
    @property
    def te(self):
        """TE of tooth pair 0 on the grid (rad)."""
        return self.path.te

    @property
    def phi1(self):
        return self.path.phi1

    @property
    def envelope(self):
        return self.multi.envelope

    @property
    def ptp(self):
        """Peak-to-peak of the unloaded TE envelope over one pitch (rad)."""
        return self.multi.ptp

    @property
    def transfer_phi1(self):
        return self.multi.transfer_phi1

    @property
    def contact_ratio(self):
        return self.multi.contact_ratio

    @property
    def on_flank(self):
        """(N,) pair 0 converged and its flanks touch (surface contact) inside both flank
        boundaries -- not at an edge (:attr:`edge_points`)."""
        on = (self.margin >= 0.0) & self.path.converged
        if self.path.edge_kind is None:
            return on
        return on & (self.path.edge_kind < 0)

    @property
    def edge_points(self):
        """(N,) pair 0 touches at an edge: a face end or a tooth tip (edge contact;
        ``path.edge_kind``)."""
        if self.path.edge_kind is None:
            return jnp.zeros(self.path.phi1.shape, bool)
        return (self.margin >= 0.0) & self.path.converged & (self.path.edge_kind >= 0)

    @property
    def flanks_cross(self):
        """(N,) the relative curvature tensor ``B`` of the flanks at pair 0's contact
        point is indefinite, ``det B < -1e-9 (B_xx^2 + B_yy^2 + 2 B_xy^2)`` (the sign
        does not depend on the sense of the normal): the gap between the flanks falls
        below zero in some direction from the point, the flanks cross there and the
        touching point is not a contact of the real flanks.  On a generated flank this
        happens past its edge of regression, where the flank continued by the envelope
        folds back onto a second sheet while the real tooth is undercut ([Litvin2004]
        section 6.3; docs/tca.md, "Crossing flanks").  False where the path carries no
        curvatures; a line contact (``det B = 0``) is not indefinite.  Traceable (a NumPy
        array on a concrete result: no program is compiled for it)."""
        return _flanks_cross(jnp if any_traced(self.path) else np, self.path)

    #: names of :meth:`objectives`, in order
    OBJECTIVES = ("ptp_arcsec", "mean_abs_srr", "max_abs_srr", "min_r_x_mm", "path_position")

    def objectives(self, on):
        """Scalar objectives of the pair (traceable; needs ``kinematics``), over the grid
        points selected by the boolean mask ``on`` (fixed, e.g. the nominal design's
        :attr:`on_flank`, so that every objective is smooth in the design): TE
        peak-to-peak (arcsec), mean and max |SRR|, min R_x (mm), and the contact
        position at the reference (``coords["path_position"]``, the family's own
        coordinate: the face-width position ``xi1`` of a bevel/hypoid pinion, the radius
        on the pinion in mm otherwise).  Order: :attr:`OBJECTIVES`.  A mask point that
        leaves the flank still enters (extrapolated): check :meth:`mask_check` --
        an optimisation is an improvement only with ``n_off == 0`` at its end."""
        on = np.asarray(on)
        mid = on.shape[0] // 2
        k = self.kinematics
        srr = jnp.abs(jnp.where(on, k.srr, 0.0))
        pos = self.coords["path_position"][mid]
        return jnp.stack([self.multi.ptp / ARCSEC, jnp.sum(srr) / on.sum(), jnp.max(srr),
                          jnp.min(jnp.where(on, k.r_x, jnp.inf)), pos])

    def mask_check(self, on) -> "MaskCheck":
        """Whether the fixed mask ``on`` of :meth:`objectives` is still on the flank
        (traceable).  Returns :class:`MaskCheck`:

        n_off : number of mask points that are no longer surface contacts inside both
            flank boundaries (:attr:`on_flank` false: beyond a boundary, at an edge or
            not converged).  There the objectives' values are extrapolations of the
            flank surfaces, not contacts: an optimiser can "improve" :meth:`objectives`
            by moving mask points off the flank, so a run is only a true improvement
            when ``n_off == 0`` at its end -- otherwise it is a flagged failure.
        penalty : ``sum_mask max(0, -margin)^2`` (mm^2) over the converged mask points,
            plus 1 per mask point whose contact solve did not converge: 0 while every
            mask point is inside the boundaries, C^1 in the design (its gradient pushes
            the points back onto the flank).  The recipe: minimise ``objective + w *
            penalty`` (``w`` in objective units per mm^2, e.g. 1e3 for |SRR|) and check
            ``n_off == 0`` at the end (docs/architecture.md, "Public API").
        """
        on = np.asarray(on)
        conv = self.path.converged
        n_off = jnp.sum(on & ~self.on_flank)
        m = jnp.where(conv & jnp.isfinite(self.margin), self.margin, 0.0)
        out = jnp.where(on & conv, jnp.maximum(-m, 0.0) ** 2, 0.0)
        penalty = jnp.sum(out) + jnp.sum(on & ~conv)
        return MaskCheck(n_off, penalty)

    def flags(self) -> dict:
        """Contact-quality flags of a concrete result (Python bools).

        converged : every contact solve between the first and last on-flank grid
            points converged (and the reference did).
        reference_on_flank : the reference (middle) contact lies inside both flanks
            (or on a face end: then ``face_end_contact``).
        edge_contact : the unloaded TE envelope hands over from one tooth pair to the
            next where a pair runs off its flank (its contact reaches a flank boundary
            while it still carries the load) instead of where the TE curves of the
            two pairs cross -- the load is then carried at the edge of a tooth.  Pairs
            whose TE curves coincide (conjugate pairs) touch simultaneously and are
            not flagged, also where their overlap is shorter than a grid step
            (contact ratio just above 1: the curves meet between grid points).  Where
            the grid shows the leaving (entering) pair off its flank at the step after
            (before) the transfer, the curves may still cross between its last grid
            point on the flank and the boundary: then the continuous transfer gap
            (:func:`~gearjax.tca.multi_pair.transfer_gaps`, the TE difference at the
            boundary crossing, interpolated) decides, a gap below -0.01 arc-seconds
            with a contact ratio >= 1 being a smooth hand-over, so the flag does not
            depend on where the grid falls.  Also raised with ``face_end_contact``.
        face_end_contact : pair 0 carries the load (it is the active pair of the
            envelope) at a face end of a flank -- toe or heel of pinion or gear
            (``path.edge_kind``, :mod:`gearjax.tca.edge_contact`): the bearing has run
            off the face, e.g. an uncrowned pair under a shaft-angle error.
        tip_contact : pair 0 carries the load at the tip edge of pinion or gear
            (corner contact off the line of action: premature contact at the start
            of mesh or prolonged contact at its end, e.g. under a base-pitch
            mismatch), or at a corner where the tip edge meets a face end (a tip
            contact under a misalignment that tilts the tip edge against the mating
            flank: ``path.edge_kind`` in :data:`~gearjax.tca.edge_contact.CORNER_KINDS`).
            Also raises ``edge_contact``.
        low_contact_ratio : contact ratio below 1 (or not found): gaps in the
            envelope, the motion is not transmitted continuously.
        large_te : the TE envelope's peak-to-peak exceeds :data:`LARGE_TE_ARCSEC`
            (60 arcsec): far above the 5-15 arcsec of a designed parabolic TE, a
            sign of a mismatched pair or a bearing that is not where it should be.
        crossing_flanks : pair 0 carries the load (it is the active pair of the
            envelope) at a surface contact where the flanks cross (:attr:`flanks_cross`:
            e.g. past the edge of regression of a generated pinion flank, an undercut
            tooth): the TE there is not that of the real flanks.
        """
        conv = np.asarray(self.path.converged)
        on = np.asarray(self.on_flank | self.edge_points)     # pair 0 touches
        idx = np.nonzero(on)[0]
        ok = bool(conv[conv.shape[0] // 2]) and (
            idx.size > 0 and bool(np.all(conv[idx[0]:idx[-1] + 1])))
        inside = np.asarray(self.multi.inside)
        te = np.asarray(self.multi.te_pairs)
        k0 = inside.shape[0] // 2
        phi = np.asarray(self.path.phi1)
        edge = False
        cr = float(self.multi.contact_ratio)
        gaps = None
        for j, (t_phi, (a, b)) in enumerate(zip(np.asarray(self.multi.transfer_phi1),
                                                ((k0 - 1, k0), (k0, k0 + 1)))):
            if not np.isfinite(t_phi):
                edge = True
                continue
            i = int(np.clip(np.searchsorted(phi, t_phi) - 1, 0, phi.shape[0] - 2))
            sl = slice(i, i + 2)
            both = inside[a, sl] & inside[b, sl]
            crossing = bool(both.all())
            # coincident TE curves (a conjugate pair): both pairs touch at once, the
            # hand-over point is arbitrary and no pair carries the load alone
            with np.errstate(invalid="ignore"):
                same = both & (np.abs(te[a, sl] - te[b, sl]) < _SAME_TE)
                # an overlap of the two pairs shorter than a grid step (contact ratio
                # just above 1): one pair on the flank at the step's start, the other at
                # its end, and their TE continuous across it -- coincident
                # curves meeting between grid points, not a pair running off its flank
                handed = cr >= 1.0 and any(
                    inside[p, i] and inside[q, i + 1] and abs(te[p, i] - te[q, i + 1]) < _SAME_TE
                    for p, q in ((a, b), (b, a)))
            if not (crossing or bool(same.any()) or handed):
                # on the grid one pair leaves its flank at the transfer: the curves may
                # still cross between the last grid point on the flank and the boundary
                # (a grid artefact); the continuous gap at the boundary decides
                if gaps is None:
                    gaps = np.asarray(jnp.stack(transfer_gaps(self.path, self.margin,
                                                              self.multi)))
                edge = edge or not (cr >= 1.0 and gaps[j] < -_GAP_SMOOTH)
        face_end = bool(self.face_ends_loaded())
        tip = bool(self.tips_loaded())
        cr = float(self.multi.contact_ratio)
        ptp = float(self.multi.ptp) / ARCSEC
        return dict(converged=ok, reference_on_flank=bool(on[on.shape[0] // 2]),
                    edge_contact=bool(edge) or face_end or tip, face_end_contact=face_end,
                    tip_contact=tip,
                    low_contact_ratio=not (np.isfinite(cr) and cr >= 1.0),
                    large_te=bool(np.isfinite(ptp) and ptp > LARGE_TE_ARCSEC),
                    crossing_flanks=bool(np.any(self._carrying() & np.asarray(self.on_flank)
                                                & self.flanks_cross)))

    def _carrying(self) -> np.ndarray:
        """(N,) tooth pair 0 carries the load: it touches and is the envelope's active
        pair (concrete)."""
        inside = np.asarray(self.multi.inside)
        k0 = inside.shape[0] // 2
        return inside[k0] & (np.asarray(self.multi.active) == k0)

    def edges_loaded(self) -> list[str]:
        """Names (:data:`gearjax.tca.edge_contact.EDGE_NAMES`) of the edges (face ends and
        tips) at which tooth pair 0 carries the load somewhere on the grid (concrete;
        empty if none)."""
        kinds = self.path.edge_kind
        if kinds is None:
            return []
        kinds = np.asarray(kinds)
        carrying = self._carrying()
        return [EDGE_NAMES[k] for k in sorted(set(kinds[carrying & (kinds >= 0)].tolist()))]

    def face_ends_loaded(self) -> list[str]:
        """The face ends (toe/heel) among :meth:`edges_loaded`."""
        return [n for n in self.edges_loaded() if EDGE_NAMES.index(n) in FACE_END_KINDS]

    def tips_loaded(self) -> list[str]:
        """The tip edges and the corners (tip edge x face end) among :meth:`edges_loaded`."""
        return [n for n in self.edges_loaded() if EDGE_NAMES.index(n) in TIP_KINDS + CORNER_KINDS]

    def warnings(self) -> list[str]:
        """Human-readable warnings for the flags that are raised (empty if none)."""
        f = self.flags()
        out = []
        if not f["converged"]:
            out.append("a contact solve did not converge on the working flank")
        if not f["reference_on_flank"]:
            out.append("the reference contact lies outside a flank boundary (off-flank)")
        if f["face_end_contact"]:
            out.append("edge contact at the " + ", ".join(self.face_ends_loaded())
                       + ": the bearing runs off the face (no Hertz ellipse there)")
        if f["tip_contact"]:
            out.append("tip contact at the " + ", ".join(self.tips_loaded())
                       + ": a tooth tip touches the mating flank off the path of contact "
                       "(corner contact, no Hertz ellipse there)")
        if f["edge_contact"] and not (f["face_end_contact"] or f["tip_contact"]):
            out.append("edge contact: a tooth pair carries the load up to a flank boundary")
        if f["low_contact_ratio"]:
            cr = float(self.multi.contact_ratio)
            out.append(f"contact ratio {cr:.3f} below 1" if np.isfinite(cr) else
                       "contact ratio not found: tooth pair 0 does not both enter and leave "
                       "the flanks within the grid (widen it, e.g. --pitches 2)")
        if f["crossing_flanks"]:
            out.append("crossing flanks: tooth pair 0 carries the load where the flanks cross "
                       "(relative curvature indefinite, e.g. past the edge of regression of "
                       "an undercut generated flank); the TE there is not that of real flanks")
        if f["large_te"]:
            out.append(f"TE peak-to-peak {float(self.multi.ptp) / ARCSEC:.1f} arcsec above "
                       f"{LARGE_TE_ARCSEC:.0f} arcsec: a mismatched pair or a misplaced bearing")
        return out


# -- the family registry behind the one TCA entry point ---------------------------------

_FAMILIES: dict[type, object] = {}


def register_family(design_type: type, adapter) -> None:
    """Register the TCA adapter of a gear family for designs of ``design_type``.

    ``adapter`` provides ``family`` (str), ``run(design, mis, *, side, **options) ->
    TCAResult`` (validated, jitted, concrete), ``traced(design, *, side, **options)
    -> f(design, mis) -> TCAResult`` (a pure function for ``jax.grad``/``jit``, the
    concrete set-up -- reference guess, hand, sense of rotation -- done once here)
    and ``sensitivity(design, mis, *, side, **options) -> (values, table)``.
    """
    _FAMILIES[design_type] = adapter


def check_design(design) -> None:
    """Validate a concrete design before any work, as the family's design-file loader
    and validated constructor do (one-line ``ValueError`` naming the field, its value
    and the allowed range, in the internal units mm and rad: e.g. a pressure angle of
    20 typed into the radian field).  The family's adapter provides
    ``check(design)``; traced fields (under ``jit``/``grad``/``vmap``) and batched
    fields are skipped.  A family without ``check`` is not checked here."""
    chk = getattr(family_of(design), "check", None)
    if chk is not None:
        chk(design)


def family_of(design):
    """The registered adapter for ``design`` (TypeError naming the known types)."""
    for typ, ad in _FAMILIES.items():
        if isinstance(design, typ):
            return ad
    known = ", ".join(t.__name__ for t in _FAMILIES) or "none registered"
    raise TypeError(f"no tooth contact analysis for a {type(design).__name__} "
                    f"(known designs: {known}; import gearjax to register the families)")
