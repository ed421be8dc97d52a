"""Homogeneous transforms against hand-written matrices.

Every reference below is typed in from the definition (active right-handed rotation
matrices and the homogeneous translation, Litvin & Fuentes, *Gear Geometry and
Applied Theory*, 2nd ed., ch. 1) and multiplied with NumPy, so no comparison uses a
function of ``gearjax.frames`` on both sides.  Tolerances: a few ulp of the O(1)
entries (1e-15 .. 1e-14).
"""

import math

import jax.numpy as jnp
import numpy as np

from gearjax import frames as F

A = 0.7
C, S = math.cos(A), math.sin(A)
# active rotations by A (right-hand rule), typed in
RX = np.array([[1, 0, 0, 0], [0, C, -S, 0], [0, S, C, 0], [0, 0, 0, 1.0]])
RY = np.array([[C, 0, S, 0], [0, 1, 0, 0], [-S, 0, C, 0], [0, 0, 0, 1.0]])
RZ = np.array([[C, -S, 0, 0], [S, C, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def hand_translate(dx, dy, dz):
    T = np.eye(4)
    T[:3, 3] = [dx, dy, dz]
    return T


def hand_rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def hand_rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def test_elementary_rotations_are_active_right_handed():
    np.testing.assert_allclose(F.apply_point(F.rot_z(np.pi / 2), [1.0, 0, 0]), [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(F.apply_point(F.rot_x(np.pi / 2), [0, 1.0, 0]), [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(F.apply_point(F.rot_y(np.pi / 2), [0, 0, 1.0]), [1, 0, 0], atol=1e-15)
    # the whole 4x4 at a general angle, against the typed-in matrices
    np.testing.assert_allclose(F.rot_x(A), RX, atol=1e-15)
    np.testing.assert_allclose(F.rot_y(A), RY, atol=1e-15)
    np.testing.assert_allclose(F.rot_z(A), RZ, atol=1e-15)
    np.testing.assert_allclose(F.translate(1.5, -2.0, 0.25), hand_translate(1.5, -2.0, 0.25), atol=0)


def test_rot_axis_matches_elementary_and_is_orthonormal():
    for axis, R in (([1, 0, 0], RX), ([0, 1, 0], RY), ([0, 0, 1], RZ)):
        np.testing.assert_allclose(F.rot_axis(axis, A), R, atol=1e-15)
    # known answer: a third of a turn about (1, 1, 1) permutes the axes x -> y -> z -> x
    P = F.rot_axis([2.0, 2.0, 2.0], 2 * np.pi / 3)  # axis length must not matter
    np.testing.assert_allclose(P[:3, :3], [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)
    # general axis: axis fixed, rotation angle from the trace (tr R = 1 + 2 cos),
    # sense by the right-hand rule (k . (e x Re) = sin(angle) for unit e normal to k)
    k = np.array([1.0, 2.0, -0.5])
    M = np.asarray(F.rot_axis(k, 1.3))
    R = M[:3, :3]
    k = k / np.linalg.norm(k)
    np.testing.assert_allclose(R @ k, k, atol=1e-15)
    np.testing.assert_allclose(np.trace(R), 1 + 2 * math.cos(1.3), atol=1e-14)
    e = np.cross(k, [0.0, 0.0, 1.0])
    e /= np.linalg.norm(e)
    np.testing.assert_allclose(k @ np.cross(e, R @ e), math.sin(1.3), atol=1e-15)
    np.testing.assert_allclose(R @ R.T, np.eye(3), atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-14)
    np.testing.assert_allclose(M[3], [0, 0, 0, 1], atol=0)
    np.testing.assert_allclose(M[:3, 3], 0.0, atol=0)


def test_compose_inverse_points_and_vectors():
    M = F.compose(F.translate(1.0, -2.0, 3.0), F.rot_x(0.4), F.rot_z(-1.1), F.translate(0.5, 0, 0))
    # reference: the same chain from typed-in matrices, last factor acting first
    Mh = hand_translate(1.0, -2.0, 3.0) @ hand_rx(0.4) @ hand_rz(-1.1) @ hand_translate(0.5, 0, 0)
    np.testing.assert_allclose(M, Mh, atol=1e-15)
    r = np.array([0.3, 0.2, -0.7])
    np.testing.assert_allclose(F.apply_point(M, r), (Mh @ np.append(r, 1.0))[:3], atol=1e-14)
    np.testing.assert_allclose(F.inverse(M), np.linalg.inv(Mh), atol=1e-14)
    # vectors ignore translation: homogeneous coordinate 0
    np.testing.assert_allclose(F.apply_vector(M, r), (Mh @ np.append(r, 0.0))[:3], atol=1e-15)
    np.testing.assert_allclose(F.rotation_part(M), Mh[:3, :3], atol=1e-15)
    np.testing.assert_allclose(F.translation_part(M), Mh[:3, 3], atol=1e-15)
    # batched points and vectors (..., 3)
    pts = np.stack([r, 2 * r, np.array([-1.0, 0.5, 4.0])])
    hom = np.concatenate([pts, np.ones((3, 1))], axis=1)
    np.testing.assert_allclose(F.apply_point(M, jnp.asarray(pts)), (hom @ Mh.T)[:, :3], atol=1e-14)
    np.testing.assert_allclose(F.apply_vector(M, jnp.asarray(pts)), pts @ Mh[:3, :3].T, atol=1e-14)
