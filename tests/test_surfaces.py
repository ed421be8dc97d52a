"""Autodiff differential geometry against closed forms (sphere, cylinder, torus, cone)
and an enveloped surface (a sphere swept on a circle envelopes a torus)."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax import surfaces as S

R_S = 3.0


def sphere(q):  # normal of this parametrisation points inwards -> kappa = +1/R
    return R_S * jnp.array([jnp.cos(q[0]) * jnp.cos(q[1]), jnp.cos(q[0]) * jnp.sin(q[1]), jnp.sin(q[0])])


def cylinder(q, R=2.5):  # axis z; parameters (theta, z)
    return jnp.array([R * jnp.cos(q[0]), R * jnp.sin(q[0]), q[1]])


A_T, C_T = 2.0, 5.0


def torus(q):
    return jnp.array([(C_T + A_T * jnp.cos(q[0])) * jnp.cos(q[1]),
                      (C_T + A_T * jnp.cos(q[0])) * jnp.sin(q[1]), A_T * jnp.sin(q[0])])


ALPHA = 0.4  # cone half angle


def cone(q):  # (s, theta), s = distance from the apex
    return q[0] * jnp.array([jnp.sin(ALPHA) * jnp.cos(q[1]), jnp.sin(ALPHA) * jnp.sin(q[1]), jnp.cos(ALPHA)])


def test_sphere():
    uv = jnp.array([0.3, 0.5])
    g = S.local_geometry(sphere, uv)
    np.testing.assert_allclose(g.n, -g.r / R_S, atol=1e-15)
    np.testing.assert_allclose([g.k1, g.k2], [1 / R_S, 1 / R_S], rtol=1e-13)
    I, II = S.fundamental_forms(sphere, uv)
    np.testing.assert_allclose(I, [[R_S ** 2, 0], [0, (R_S * np.cos(0.3)) ** 2]], rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(II, I / R_S, rtol=1e-13, atol=1e-13)


def test_cylinder_curvatures_and_directions():
    uv = jnp.array([0.8, 1.2])
    g = S.local_geometry(cylinder, uv)
    # normal = r_theta x r_z points outwards -> kappa = -1/R round the axis
    np.testing.assert_allclose([g.k1, g.k2], [0.0, -1 / 2.5], atol=1e-14)
    np.testing.assert_allclose(np.abs(g.e1 @ jnp.array([0, 0, 1.0])), 1.0, atol=1e-14)
    np.testing.assert_allclose(jnp.cross(g.e1, g.e2), g.n, atol=1e-14)


@pytest.mark.parametrize("th", [0.0, 0.7, 2.0, -2.6])
def test_torus(th):
    g = S.local_geometry(torus, jnp.array([th, 0.4]))
    # with the outward normal kappa = -1/a, -cos/(c + a cos); flip for the inward one
    centre = C_T * jnp.array([jnp.cos(0.4), jnp.sin(0.4), 0.0])
    s = np.sign(float(g.n @ (g.r - centre)))
    k_mer, k_par = -s / A_T, -s * np.cos(th) / (C_T + A_T * np.cos(th))
    np.testing.assert_allclose(sorted([float(g.k1), float(g.k2)]), sorted([k_mer, k_par]), rtol=1e-12)
    K = S.fundamental_forms(torus, jnp.array([th, 0.4]))
    I, II = K
    np.testing.assert_allclose(np.linalg.det(II) / np.linalg.det(I), k_mer * k_par, rtol=1e-12)


def test_cone():
    s = 7.0
    g = S.local_geometry(cone, jnp.array([s, 1.1]))
    k_circ = np.cos(ALPHA) / (s * np.sin(ALPHA))
    ks = sorted([float(g.k1), float(g.k2)], key=abs)
    np.testing.assert_allclose(ks[0], 0.0, atol=1e-14)
    np.testing.assert_allclose(abs(ks[1]), k_circ, rtol=1e-12)
    # the zero-curvature direction is the generator
    gen = cone(jnp.array([1.0, 1.1]))
    e0 = g.e1 if abs(float(g.k1)) < abs(float(g.k2)) else g.e2
    np.testing.assert_allclose(abs(float(e0 @ gen)), 1.0, atol=1e-13)


@pytest.mark.parametrize("phi", [0.0, 0.3, 1.0, 2.2])
def test_euler_and_bertrand_formulas(phi):
    uv = jnp.array([0.7, 0.2])
    g = S.local_geometry(torus, uv)
    t = np.cos(phi) * g.e1 + np.sin(phi) * g.e2
    kn = S.normal_curvature(torus, uv, 3.0 * t)  # length of t does not matter
    tg = S.geodesic_torsion(torus, uv, t)
    np.testing.assert_allclose(kn, g.k1 * np.cos(phi) ** 2 + g.k2 * np.sin(phi) ** 2, atol=1e-14)
    np.testing.assert_allclose(tg, (g.k2 - g.k1) * np.sin(phi) * np.cos(phi), atol=1e-14)
    # II(w, w)/I(w, w) route for the normal curvature
    I, II = S.fundamental_forms(torus, uv)
    w = np.linalg.lstsq(np.stack([g.ru, g.rv], 1), t, rcond=None)[0]
    np.testing.assert_allclose(kn, (w @ II @ w) / (w @ I @ w), atol=1e-14)


def test_weingarten_annihilates_normal_and_is_self_adjoint():
    uv = jnp.array([0.7, 0.2])
    W = S.weingarten(torus, uv)
    g = S.local_geometry(torus, uv)
    np.testing.assert_allclose(W @ g.n, 0.0, atol=1e-14)
    np.testing.assert_allclose(g.ru @ W @ g.rv, g.rv @ W @ g.ru, atol=1e-13)


# ----------------------------------------------------------------- enveloped surface

R_C, RHO = 6.0, 1.5


def unit_sphere(uv):
    return jnp.array([jnp.cos(uv[0]) * jnp.cos(uv[1]), jnp.cos(uv[0]) * jnp.sin(uv[1]), jnp.sin(uv[0])])


def swept_sphere(uv, psi):
    """A sphere of radius RHO whose centre runs on the circle of radius R_C (z = 0)."""
    return jnp.array([R_C * jnp.cos(psi), R_C * jnp.sin(psi), 0.0]) + RHO * unit_sphere(uv)


GEN = S.GeneratedSurface(swept_sphere, lambda uv: jnp.arctan2(unit_sphere(uv)[1], unit_sphere(uv)[0]))


@pytest.mark.parametrize("uv", [(0.3, 0.4), (-0.9, 2.0), (1.1, -2.5)])
def test_envelope_of_swept_sphere_is_a_torus(uv):
    uv = jnp.array(uv)
    res = GEN.solve(uv)
    assert bool(res.converged) and float(res.residual) < 1e-12
    r = GEN(uv)
    np.testing.assert_allclose((jnp.hypot(r[0], r[1]) - R_C) ** 2 + r[2] ** 2, RHO ** 2, rtol=1e-13)
    g = S.local_geometry(GEN, uv)
    # envelope normal = tool normal
    np.testing.assert_allclose(g.n, GEN.tool_normal(uv), atol=1e-12)
    # torus curvatures (outward normal): -1/rho and -cos(th)/(R + rho cos th)
    th = np.arctan2(float(r[2]), float(jnp.hypot(r[0], r[1]) - R_C))
    centre = R_C * r.at[2].set(0.0) / jnp.hypot(r[0], r[1])
    s = np.sign(float(g.n @ (r - centre)))
    expect = sorted([-s / RHO, -s * np.cos(th) / (R_C + RHO * np.cos(th))])
    np.testing.assert_allclose(sorted([float(g.k1), float(g.k2)]), expect, rtol=1e-10)


def test_envelope_meshing_residual_and_gradient():
    uv = jnp.array([0.3, 0.4])
    psi = GEN.solve(uv).x
    assert abs(float(S.meshing_function(swept_sphere, uv, psi))) < 1e-14
    # d(point)/d(uv) through the implicit solve vs central differences
    J = jax.jacfwd(GEN)(uv)
    h = 1e-6
    fd = jnp.stack([(GEN(uv + h * e) - GEN(uv - h * e)) / (2 * h) for e in jnp.eye(2)], axis=1)
    np.testing.assert_allclose(J, fd, rtol=1e-7, atol=1e-9)
