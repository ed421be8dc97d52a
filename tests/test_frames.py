"""Homogeneous transforms."""

import jax.numpy as jnp
import numpy as np

from gearjax import frames as F


def test_elementary_rotations_are_active_right_handed():
    np.testing.assert_allclose(F.apply_point(F.rot_z(np.pi / 2), [1.0, 0, 0]), [0, 1, 0], atol=1e-15)
    np.testing.assert_allclose(F.apply_point(F.rot_x(np.pi / 2), [0, 1.0, 0]), [0, 0, 1], atol=1e-15)
    np.testing.assert_allclose(F.apply_point(F.rot_y(np.pi / 2), [0, 0, 1.0]), [1, 0, 0], atol=1e-15)


def test_rot_axis_matches_elementary_and_is_orthonormal():
    for axis, R in (([1, 0, 0], F.rot_x), ([0, 1, 0], F.rot_y), ([0, 0, 1], F.rot_z)):
        np.testing.assert_allclose(F.rot_axis(axis, 0.7), R(0.7), atol=1e-15)
    M = F.rot_axis([1.0, 2.0, -0.5], 1.3)
    np.testing.assert_allclose(M[:3, :3] @ M[:3, :3].T, np.eye(3), atol=1e-14)
    np.testing.assert_allclose(np.linalg.det(M[:3, :3]), 1.0, atol=1e-14)


def test_compose_inverse_points_and_vectors():
    M = F.compose(F.translate(1.0, -2.0, 3.0), F.rot_x(0.4), F.rot_z(-1.1), F.translate(0.5, 0, 0))
    r = jnp.array([0.3, 0.2, -0.7])
    # composition: the last transform acts first
    step = F.apply_point(F.translate(0.5, 0, 0), r)
    step = F.apply_point(F.rot_z(-1.1), step)
    step = F.apply_point(F.rot_x(0.4), step)
    step = F.apply_point(F.translate(1.0, -2.0, 3.0), step)
    np.testing.assert_allclose(F.apply_point(M, r), step, atol=1e-14)
    np.testing.assert_allclose(F.inverse(M) @ M, np.eye(4), atol=1e-14)
    # vectors ignore translation
    np.testing.assert_allclose(F.apply_vector(M, r), F.rotation_part(M) @ r, atol=1e-15)
    np.testing.assert_allclose(F.translation_part(F.translate(1, 2, 3)), [1, 2, 3])
    # batched points
    pts = jnp.stack([r, 2 * r])
    np.testing.assert_allclose(F.apply_point(M, pts)[1], F.apply_point(M, 2 * r), atol=1e-14)
