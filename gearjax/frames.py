"""Coordinate frames: 4x4 homogeneous transforms built from elementary motions.

A transform ``M`` maps homogeneous coordinates in a frame S_a to a frame S_b,
``[r_b; 1] = M_ba [r_a; 1]``.  Rotations follow the right-hand rule and are
*active*: ``rot_z(phi)`` turns a point by ``+phi`` about z.  (A frame rotated by
``phi`` relative to another is reached with ``rot_z(-phi)``.)  Vectors (normals,
velocities) transform with the upper-left 3x3 block only.

Reference: Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed., ch. 1
(coordinate transformation in matrix form).
"""

from __future__ import annotations

from functools import reduce

import jax.numpy as jnp

__all__ = ["matrix_x", "matrix_y", "matrix_z", "matrix_axis", "rotate_about", "rot_x", "rot_y", "rot_z", "rot_axis", "translate", "compose",
           "apply_point", "apply_vector", "rotation_part", "translation_part", "inverse"]


def _hom(R, t=None):
    dtype = jnp.result_type(R, float)
    top = jnp.concatenate([R, jnp.zeros((3, 1), dtype) if t is None else jnp.reshape(t, (3, 1))], axis=1)
    return jnp.concatenate([top, jnp.array([[0.0, 0.0, 0.0, 1.0]], dtype)], axis=0)


def matrix_x(angle):
    """3x3 active rotation by ``angle`` (rad) about the x axis."""
    c, s = jnp.cos(angle), jnp.sin(angle)
    o, z = jnp.ones_like(c), jnp.zeros_like(c)
    return jnp.stack([jnp.stack([o, z, z]), jnp.stack([z, c, -s]), jnp.stack([z, s, c])])


def matrix_y(angle):
    """3x3 active rotation by ``angle`` (rad) about the y axis."""
    c, s = jnp.cos(angle), jnp.sin(angle)
    o, z = jnp.ones_like(c), jnp.zeros_like(c)
    return jnp.stack([jnp.stack([c, z, s]), jnp.stack([z, o, z]), jnp.stack([-s, z, c])])


def matrix_z(angle):
    """3x3 active rotation by ``angle`` (rad) about the z axis."""
    c, s = jnp.cos(angle), jnp.sin(angle)
    o, z = jnp.ones_like(c), jnp.zeros_like(c)
    return jnp.stack([jnp.stack([c, -s, z]), jnp.stack([s, c, z]), jnp.stack([z, z, o])])


def matrix_axis(axis, angle):
    """3x3 active rotation by ``angle`` about ``axis`` (normalised here), Rodrigues'
    formula ``R = I + sin(a) K + (1 - cos(a)) K^2`` with ``K = [k]_x``."""
    k = jnp.asarray(axis, float)
    k = k / jnp.linalg.norm(k)
    K = jnp.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return jnp.eye(3) + jnp.sin(angle) * K + (1.0 - jnp.cos(angle)) * (K @ K)


def rotate_about(axis, angle, x):
    """Rotate the vector ``x`` by ``angle`` about the *unit* ``axis`` through the origin
    (Rodrigues: ``x cos a + (k x x) sin a + k (k.x)(1 - cos a)``)."""
    c, s = jnp.cos(angle), jnp.sin(angle)
    return c * x + s * jnp.cross(axis, x) + (1.0 - c) * jnp.dot(axis, x) * axis


def rot_x(angle):
    """Active rotation by ``angle`` (rad) about the x axis, as a 4x4 transform."""
    return _hom(matrix_x(angle))


def rot_y(angle):
    """Active rotation by ``angle`` (rad) about the y axis, as a 4x4 transform."""
    return _hom(matrix_y(angle))


def rot_z(angle):
    """Active rotation by ``angle`` (rad) about the z axis, as a 4x4 transform."""
    return _hom(matrix_z(angle))


def rot_axis(axis, angle):
    """Active rotation by ``angle`` about the unit vector ``axis`` (Rodrigues' formula)."""
    return _hom(matrix_axis(axis, angle))


def translate(dx=0.0, dy=0.0, dz=0.0):
    """Translation by (dx, dy, dz) (mm) as a 4x4 transform."""
    t = jnp.stack([jnp.asarray(dx, float), jnp.asarray(dy, float), jnp.asarray(dz, float)])
    return _hom(jnp.eye(3), t)


def compose(*transforms):
    """Matrix product ``T1 @ T2 @ ... @ Tn`` (Tn acts first)."""
    return reduce(jnp.matmul, transforms)


def apply_point(M, r):
    """Transform point(s) ``r`` (..., 3) by the 4x4 ``M``."""
    r = jnp.asarray(r)
    return r @ M[:3, :3].T + M[:3, 3]


def apply_vector(M, v):
    """Transform free vector(s) ``v`` (..., 3) by the rotation part of ``M``."""
    return jnp.asarray(v) @ M[:3, :3].T


def rotation_part(M):
    """The 3x3 rotation block of a homogeneous transform."""
    return M[:3, :3]


def translation_part(M):
    """The translation column of a homogeneous transform."""
    return M[:3, 3]


def inverse(M):
    """Inverse of a rigid transform (rotation + translation)."""
    R = M[:3, :3]
    return _hom(R.T, -R.T @ M[:3, 3])
