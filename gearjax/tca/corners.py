"""Corners of the tip edges: where a member's tip edge meets a face end, and whether
such a corner can carry the contact.

A corner candidate of the edge search (:mod:`gearjax.tca.edge_contact`, "Corners")
lies on the tip edge of one member at a face end.  It is the contact only where the
flank points beside it -- along the tip edge into the face and down the profile --
would touch later than the corner itself (first-order slopes of the TE,
:func:`corner_slope`; :func:`corner_leads`).  Units: mm, rad.
"""

from __future__ import annotations

from typing import Callable

import jax
import jax.numpy as jnp

from gearjax.frames import matrix_z
from gearjax.tca.path import flank_at

__all__ = ["pose", "corner_end", "corner_slope", "corner_leads", "CORNER_TOL",
           "CORNER_GIVE_UP", "CORNER_SLOPE_TOL"]


def pose(cs, r1, r2, R, z, ph1):
    """Both flanks' points, normals and flank data at the unknowns ``z`` of the contact
    system ``cs``, and the members' rotations at pinion angle ``ph1`` (gear mount ``R``):
    ``(q1, m1, f1, q2, m2, f2, R1, R2)``."""
    x, psi1, psi2 = cs.split(z)
    uv1, uv2, ph2 = cs.unpack(x)
    q1, m1, f1 = flank_at(r1, uv1, psi1)
    q2, m2, f2 = flank_at(r2, uv2, psi2)
    return q1, m1, f1, q2, m2, f2, matrix_z(ph1), R @ matrix_z(ph2)


def corner_end(g1: Callable, g2: Callable, q1, q2, e):
    """``G_e = e max(e g_1(q_1, e), e g_2(q_2, e))`` (mm): the face-end function of a
    corner at end ``e`` (:mod:`gearjax.tca.edge_contact`, "Corners"); zero where the common point
    (body points ``q1``, ``q2``) lies on the face end ``e`` of one member and inside
    the other's, negative beyond one of them on that end (``g_k`` grows into the face
    from ``e = -1``, out of it at ``e = +1``)."""
    return e * jnp.maximum(e * g1(q1, e), e * g2(q2, e))


#: mm: face-width margin a corner's point may miss by (it lies on a face end by its
#: equations, solved to 1e-11)
CORNER_TOL = 1e-8

#: failed angle steps in a row after which a corner's or tip edge's continuation stops
CORNER_GIVE_UP = 2


#: rad/mm: a corner counts where the TE along its tip edge into the face falls (in
#: the sense of the load) or stays level within this
CORNER_SLOPE_TOL = 1e-12


def corner_slope(cs, r1, r2, R, c, mis, asm, g1, g2, t1, t2, z, ph1, pinion, e):
    """``dTE/d(eps)`` (rad/mm, (2,)) at a corner solution ``z`` of the tip edge of the
    pinion (``pinion`` 1.0) or gear at end ``e``: the TE at which the flank point ``eps``
    mm from the corner along the tip edge into the face, and down the profile from the
    tip (in the flank's tangent plane), would touch the mating flank (first order; the
    mating flank fixed, the gear turned).  With the tip-edge tangent ``u_k = m_k x grad
    t_k`` (body frame, oriented into the face: ``e grad g_k . u_k < 0``), the mating
    normal ``n_j`` and the velocity ``w = a_2 x (p - c)`` of the common point ``p`` per
    unit gear angle: ``dphi2/deps = (n_2 . R_1 u_1)/(n_2 . w)`` for a pinion corner,
    ``-(n_1 . R_2 u_2)/(n_1 . w)`` for a gear corner; ``dTE = ratio_sign dphi2``
    (orientation-free: ``n_j`` enters above and below)."""
    q1, m1, _, q2, m2, _, R1, R2 = pose(cs, r1, r2, R, z, ph1)

    def directions(m, t, g, q):
        # along the tip edge into the face, and down the profile (in the flank's
        # tangent plane, across the tip edge, below the tip: t grows)
        gt = jax.grad(t)(q)
        u = jnp.cross(m, gt)
        u = u / jnp.maximum(jnp.linalg.norm(u), 1e-300)
        u = jnp.where(e * jnp.dot(jax.grad(lambda qq: g(qq, e))(q), u) > 0.0, -u, u)
        v = jnp.cross(m, u)
        v = jnp.where(jnp.dot(gt, v) < 0.0, -v, v)
        return u, v

    p = R1 @ q1 + mis.dP * jnp.array([0.0, 0.0, 1.0])
    w = jnp.cross(R[:, 2], p - c)
    n1, n2 = R1 @ m1, R2 @ m2

    def dte(d1, d2):
        d_pin = jnp.dot(n2, R1 @ d1) / jnp.dot(n2, w)
        d_gear = -jnp.dot(n1, R2 @ d2) / jnp.dot(n1, w)
        return asm.ratio_sign * jnp.where(pinion > 0.5, d_pin, d_gear)

    (u1, v1), (u2, v2) = directions(m1, t1, g1, q1), directions(m2, t2, g2, q2)
    return jnp.stack([dte(u1, u2), dte(v1, v2)])


def corner_leads(slope, drive):
    """True where a corner candidate leads (:mod:`gearjax.tca.edge_contact`, "Corners"): the TE at the
    flank points beside the corner -- along its tip edge into the face and down the
    profile, ``slope = dTE/d(eps)`` (rad/mm, ``(..., 2)``, :func:`corner_slope`) --
    falls in the sense of the load, or stays level within ``CORNER_SLOPE_TOL``, in
    *both* directions: ``max_j(s dTE_j/d eps) <= tol`` with ``s`` +1 on the drive side,
    -1 on the coast side.  Where it rises in either direction that flank point would
    pass through the mating flank before the corner, so the corner cannot be the
    contact."""
    sgn_load = jnp.where(drive, 1.0, -1.0)
    return jnp.max(sgn_load * slope, axis=-1) <= CORNER_SLOPE_TOL
