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
    # tangents r_theta = R e_theta, r_z = e_z and the normal e_theta x e_z = e_r, by hand
    er, et = np.array([np.cos(0.8), np.sin(0.8), 0.0]), np.array([-np.sin(0.8), np.cos(0.8), 0.0])
    ru, rv = S.tangents(cylinder, uv)
    np.testing.assert_allclose(ru, 2.5 * et, atol=1e-15)
    np.testing.assert_allclose(rv, [0.0, 0.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(S.unit_normal(cylinder, uv), er, atol=1e-15)
    k1, k2, e1, e2 = S.principal_curvatures(cylinder, uv)
    np.testing.assert_allclose([k1, k2], [0.0, -1 / 2.5], atol=1e-15)
    np.testing.assert_allclose(abs(float(e2 @ et)), 1.0, atol=1e-15)
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


def helicoid(q, c=1.5):
    return jnp.array([q[0] * jnp.cos(q[1]), q[0] * jnp.sin(q[1]), c * q[1]])


def test_helicoid_principal_curvatures_and_directions():
    """Helicoid (u cos v, u sin v, c v), a minimal surface: principal curvatures
    +-c/(c^2 + u^2), Gaussian curvature -c^2/(c^2 + u^2)^2 (do Carmo, *Differential
    Geometry of Curves and Surfaces*, §3-3, example of the helicoid).  Its coordinate
    lines are asymptotic (L = N = 0, F = 0), so the principal directions bisect r_u and
    r_v: with n = r_u x r_v/|.| one has M = -c/sqrt(c^2 + u^2) < 0, hence kappa = +k along
    a - b and -k along a + b (a, b unit r_u, r_v; worked out by hand).  Unlike the sphere
    and cylinder, the shape operator is off-diagonal in the (r_u, n x r_u) frame here, so
    the principal angle is exercised.  Tolerance: a few ulp of k."""
    u, v, c = 0.8, 0.3, 1.5
    g = S.local_geometry(helicoid, jnp.array([u, v]))
    k = c / (c ** 2 + u ** 2)
    np.testing.assert_allclose([g.k1, g.k2], [k, -k], rtol=1e-13)
    a = np.array([np.cos(v), np.sin(v), 0.0])
    b = np.array([-u * np.sin(v), u * np.cos(v), c]) / np.hypot(u, c)
    np.testing.assert_allclose(abs(float(g.e1 @ (a - b))) / np.sqrt(2), 1.0, atol=1e-14)
    np.testing.assert_allclose(abs(float(g.e2 @ (a + b))) / np.sqrt(2), 1.0, atol=1e-14)
    I, II = S.fundamental_forms(helicoid, jnp.array([u, v]))
    np.testing.assert_allclose(I, [[1.0, 0.0], [0.0, u ** 2 + c ** 2]], atol=1e-14)
    np.testing.assert_allclose(II, [[0.0, -c / np.hypot(u, c)], [-c / np.hypot(u, c), 0.0]], atol=1e-14)


def test_weingarten_and_direction_curvatures_closed_forms():
    """Weingarten map dn = W dr in closed form: sphere with the inward normal n = -r/R gives
    dn = -dr/R, W = -(I - n n^T)/R; cylinder with the outward normal e_r gives
    dn = (r_theta . dr) e_theta / R^2, W = e_theta e_theta^T / R.  For the cylinder and the
    tangent t = cos(phi) e_z + sin(phi) e_theta, by hand from W:
    kappa_n = -sin^2(phi)/R and tau_g = sin(phi) cos(phi)/R.  The direction is passed with a
    normal component and a length != 1, which the functions must discard.  Tolerance: ulp."""
    uv = jnp.array([0.3, 0.5])
    n = -sphere(uv) / R_S
    np.testing.assert_allclose(S.weingarten(sphere, uv), -(np.eye(3) - np.outer(n, n)) / R_S, atol=1e-15)
    th, R = 0.8, 2.5
    er = np.array([np.cos(th), np.sin(th), 0.0])
    et = np.array([-np.sin(th), np.cos(th), 0.0])
    ez = np.array([0.0, 0.0, 1.0])
    q = jnp.array([th, 1.2])
    np.testing.assert_allclose(S.weingarten(cylinder, q), np.outer(et, et) / R, atol=1e-15)
    for phi in (0.0, 0.6, 2.0):
        t = np.cos(phi) * ez + np.sin(phi) * et
        kn = S.normal_curvature(cylinder, q, 2.0 * t + 0.8 * er)
        tg = S.geodesic_torsion(cylinder, q, 0.5 * t - 0.3 * er)
        np.testing.assert_allclose(kn, -np.sin(phi) ** 2 / R, atol=1e-15)
        np.testing.assert_allclose(tg, np.sin(phi) * np.cos(phi) / R, atol=1e-15)


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
    # the root in closed form: the sphere point at azimuth v is on the envelope when the
    # centre is at psi = v (f below vanishes), whatever the starting guess nearby
    np.testing.assert_allclose(S.solve_envelope(swept_sphere, uv, 0.0).x, 0.4, rtol=1e-14)
    np.testing.assert_allclose(psi, 0.4, rtol=1e-14)
    # away from the root, the closed form: n = -e(uv) (inward normal of this
    # parametrisation), dr/dpsi = R_C (-sin psi, cos psi, 0), so
    # f = n . dr/dpsi = -R_C cos(u) sin(v - psi)   (mm per rad)
    for p in (0.1, 1.3):
        np.testing.assert_allclose(S.meshing_function(swept_sphere, uv, p),
                                   -R_C * np.cos(0.3) * np.sin(0.4 - p), rtol=1e-14)
    # d(point)/d(uv) through the implicit solve vs central differences
    J = jax.jacfwd(GEN)(uv)
    h = 1e-6
    fd = jnp.stack([(GEN(uv + h * e) - GEN(uv - h * e)) / (2 * h) for e in jnp.eye(2)], axis=1)
    np.testing.assert_allclose(J, fd, rtol=1e-7, atol=1e-9)
