"""Eigenfunction kinematics of conjugate surfaces ([Eigenfunctions] §1).

Two members rotate with constant angular velocities: member 1 with ``omega1``
about an axis through the origin, member 2 with ``omega2`` about an axis through
the point ``a`` (all vectors in one fixed frame, mm and rad/s).  Parallel axes
(``omega1 || omega2``), intersecting axes (``a`` on axis 1) and crossed axes with
any shaft angle and offset are special cases of :class:`Mesh`.

At a contact point ``r`` with common unit normal ``n`` and the Weingarten map
``W1`` of surface Sigma_1 (``dn = W1 dr``, see :mod:`gearjax.surfaces`):

    v12   = omega1 x r - omega2 x (r - a)             relative velocity (1 w.r.t. 2)
    w12   = omega1 - omega2
    q     = w12 x (omega1 x r) - omega1 x v12          first-order eigenvector
    p     = w12 x n - W1 v12                           second-order eigenvector
    Phi_I = n . q  = v_r1 . p                          first-order eigenfunction
    Phi_II = Phi_I + p . v12 = v_r2 . p                second-order eigenfunction

(``v_ri`` is the velocity of the contact point over surface i.)  ``p`` lies in the
tangent plane and is normal to the instantaneous contact line, whose direction is
``n x p``.  [Eigenfunctions] writes ``p = w12 x n - v12 d1n/ds``; ``v12 d1n/ds`` is the
directional derivative of n along v12, i.e. ``W1 v12``; with the normal curvature
and geodesic torsion of Sigma_1 in the direction of v12 it is
``p = w12 x n + k_v v12 + tau_v (n x v12)`` — both forms are tested.

Derived quantities (components normal to the contact line, along ``p/|p|``):

    u1 = -Phi_I/|p|,  u2 = -Phi_II/|p|           surface velocities relative to the
                                                 contact point
    u_e = (u1 + u2)/2 = -(Phi_I + Phi_II)/(2|p|) entrainment (rolling) velocity
    u_s = u1 - u2 = (Phi_II - Phi_I)/|p| = v12 . p/|p|   sliding velocity
    SRR = u_s/u_e = 2 (Phi_I - Phi_II)/(Phi_I + Phi_II)
    K_II = |p|^2/Phi_II,  R_eff = 1/K_II = Phi_II/|p|^2
    n0  = (v12 x q)/|v12 x q|                    limit normal (meshing limit)

Slips of [Eigenfunctions] corrected here (documented and tested):

* [Eigenfunctions] states ``SRR = 2 (Phi_II - Phi_I)/(Phi_I + Phi_II)``, which is minus
  its own ``u_s/u_e``.  gearjax uses ``SRR = u_s/u_e`` with its own ``u_s`` and
  ``u_e``; the sign of SRR then tells whether member 1's surface is faster (> 0).
* Its alternative form ``q = (omega1 x omega2) x r - (omega2.omega1) a`` holds
  only for a particular direction of ``a``; from the definition of ``q`` one gets
  ``q = (omega1 x omega2) x r + (omega1.omega2) a - (omega1.a) omega2`` for the
  point ``a`` on axis 2 used here (the last term vanishes when ``a`` is the foot of
  the common perpendicular).

Orientation: every scalar above changes sign with ``n`` except SRR; ``K_II`` and
``R_eff`` are positive for a convex contact when ``n`` points *into member 1*
(the outward normal of Sigma_2).  ``K_II`` equals ``kappa1(t) - kappa2(t)`` with
``t = p/|p|`` and both normal curvatures taken with the common normal ``n``
(induced curvature, Litvin & Fuentes §8); along the contact line it is zero.

References (docs/references.md): [Eigenfunctions] §1; [WuXutang] (eigenfunctions);
[Litvin2004] ch. 8–9.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import jax
import jax.numpy as jnp

from gearjax.surfaces import curvature_in_direction, local_geometry

__all__ = ["Mesh", "parallel_axes", "crossed_axes", "relative_velocity", "Kinematics",
           "eigen_kinematics", "surface_kinematics"]


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class Mesh:
    """Rigid rotation of two members in a fixed frame.

    omega1 : (3,) angular velocity of member 1 (rad/s), axis through the origin.
    omega2 : (3,) angular velocity of member 2 (rad/s), axis through ``a``.
    a : (3,) a point on the axis of member 2 (mm).
    """

    omega1: jnp.ndarray
    omega2: jnp.ndarray
    a: jnp.ndarray


def parallel_axes(center_distance, ratio, omega1=1.0, external=True) -> Mesh:
    """Parallel axes along z: member 1 about the z axis, member 2 about ``(0, a, 0)``.

    ``ratio = z2/z1 = |omega1/omega2|``; external gears turn in opposite senses.
    """
    w1 = jnp.asarray(omega1, float)
    sgn = -1.0 if external else 1.0
    z = jnp.zeros_like(w1)
    return Mesh(jnp.stack([z, z, w1]), jnp.stack([z, z, sgn * w1 / ratio]),
                jnp.stack([z, jnp.asarray(center_distance, float) + z, z]))


def crossed_axes(shaft_angle, offset, ratio, omega1=1.0) -> Mesh:
    """Crossed axes: member 1 about z; member 2 about an axis through ``(0, -E, 0)``.

    The axis of member 2 is perpendicular to the common perpendicular (the y axis)
    and makes the shaft angle ``Sigma`` with axis 1 (direction
    ``(sin Sigma, 0, cos Sigma)``); member 2 turns at ``-omega1/ratio`` about it, so
    that for ``E = 0`` and ``Sigma = pi/2`` this is a bevel pair with apexes at the
    origin.  ``offset = 0`` gives intersecting axes, ``shaft_angle = 0`` parallel.
    """
    w1 = jnp.asarray(omega1, float)
    S = jnp.asarray(shaft_angle, float)
    k2 = jnp.stack([jnp.sin(S), jnp.zeros_like(S), jnp.cos(S)])
    z = jnp.zeros_like(w1)
    return Mesh(jnp.stack([z, z, w1]), -w1 / ratio * k2,
                jnp.stack([z, -jnp.asarray(offset, float) + z, z]))


def relative_velocity(mesh: Mesh, r):
    """``v12 = omega1 x r - omega2 x (r - a)`` (mm/s): velocity of 1 relative to 2 at r."""
    return jnp.cross(mesh.omega1, r) - jnp.cross(mesh.omega2, r - mesh.a)


class Kinematics(NamedTuple):
    """Eigenfunction kinematics at a contact point (see module docstring).

    Velocities in mm/s (mm per rad when omega1 = 1), curvature 1/mm, radius mm.
    """

    v12: jnp.ndarray      # (3,) relative velocity
    q: jnp.ndarray        # (3,) first-order eigenvector
    p: jnp.ndarray        # (3,) second-order eigenvector (tangent, normal to contact line)
    phi_I: jnp.ndarray    # first-order eigenfunction n.q
    phi_II: jnp.ndarray   # second-order eigenfunction
    u1: jnp.ndarray
    u2: jnp.ndarray
    u_e: jnp.ndarray
    u_s: jnp.ndarray
    srr: jnp.ndarray
    k_II: jnp.ndarray     # principal induced curvature
    r_eff: jnp.ndarray    # effective radius of curvature 1/K_II
    n0: jnp.ndarray       # (3,) limit normal
    contact_dir: jnp.ndarray  # (3,) unit tangent of the contact line, n x p/|p|
    k_v: jnp.ndarray      # normal curvature of Sigma_1 in the direction of v12
    tau_v: jnp.ndarray    # geodesic torsion of Sigma_1 in the direction of v12


def eigen_kinematics(mesh: Mesh, r, n, W1) -> Kinematics:
    """Eigenfunctions and derived kinematics at contact point ``r`` (mm).

    ``n``: common unit normal; ``W1``: Weingarten map of Sigma_1 at ``r`` (3x3,
    ``dn = W1 dr``) expressed in the same fixed frame as ``mesh``.
    """
    w1, w2 = mesh.omega1, mesh.omega2
    w12 = w1 - w2
    v12 = relative_velocity(mesh, r)
    q = jnp.cross(w12, jnp.cross(w1, r)) - jnp.cross(w1, v12)
    p = jnp.cross(w12, n) - W1 @ v12
    phi_I = jnp.dot(n, q)
    phi_II = phi_I + jnp.dot(p, v12)
    pn = jnp.linalg.norm(p)
    u1 = -phi_I / pn
    u2 = -phi_II / pn
    u_e = 0.5 * (u1 + u2)
    u_s = u1 - u2
    vq = jnp.cross(v12, q)
    k_v, tau_v = curvature_in_direction(n, W1, v12)
    return Kinematics(
        v12=v12, q=q, p=p, phi_I=phi_I, phi_II=phi_II, u1=u1, u2=u2, u_e=u_e, u_s=u_s,
        srr=u_s / u_e, k_II=pn ** 2 / phi_II, r_eff=phi_II / pn ** 2,
        n0=vq / jnp.linalg.norm(vq), contact_dir=jnp.cross(n, p / pn), k_v=k_v, tau_v=tau_v)


def surface_kinematics(mesh: Mesh, surface, uv, orientation=1.0) -> Kinematics:
    """Eigenfunction kinematics at the point ``surface(uv)`` of Sigma_1.

    ``surface`` is any function ``uv -> r`` (explicit or :class:`GeneratedSurface`)
    already placed in the fixed frame of ``mesh`` at the instant considered;
    ``orientation`` (+1/-1) multiplies the parametrisation's normal.  The point is
    assumed to be a contact point (the meshing equation ``n.v12 = 0`` is not
    imposed here).
    """
    g = local_geometry(surface, uv)
    s = jnp.asarray(orientation, float)
    return eigen_kinematics(mesh, g.r, s * g.n, s * g.W)
