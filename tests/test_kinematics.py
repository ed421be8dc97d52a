"""Eigenfunction kinematics (seed 000 §1) against independent routes.

Sigma_1 is an explicit curved patch on member 1; Sigma_2 is generated from it as
the envelope in member 2's frame (GeneratedSurface), for crossed, parallel and
intersecting axes.  Checked: K_II = kappa1 - kappa2 from the two surfaces' own
autodiff curvatures; the contact-line direction carries zero induced curvature;
u1, u2 and v12 from the time derivative of the contact point on each surface; the
alternative forms of q and p given in the seed.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax import frames as F
from gearjax.kinematics import crossed_axes, eigen_kinematics, relative_velocity
from gearjax.newton import newton_solve
from gearjax.surfaces import GeneratedSurface, curvature_in_direction, local_geometry, meshing_function

CASES = {
    "crossed": dict(shaft_angle=1.2, offset=20.0, ratio=2.5),
    "parallel": dict(shaft_angle=0.0, offset=90.0, ratio=2.0),
    "intersecting": dict(shaft_angle=np.pi / 2, offset=0.0, ratio=3.0),
}


def setup(case):
    c = CASES[case]
    mesh = crossed_axes(c["shaft_angle"], c["offset"], c["ratio"])
    k2 = -mesh.omega2 / jnp.linalg.norm(mesh.omega2)
    P0 = jnp.array([30.0, 4.0, 12.0])
    v0 = relative_velocity(mesh, P0)
    n0 = jnp.cross(v0, jnp.array([0.2, -0.5, 1.0]))
    n0 = n0 / jnp.linalg.norm(n0)
    t1 = jnp.cross(n0, jnp.array([0.3, 0.9, 0.1]))
    t1 = t1 / jnp.linalg.norm(t1)
    t2 = jnp.cross(n0, t1)

    def sigma1(uv):  # curved patch through P0 with normal n0; a contact point at psi = 0
        u, v = uv
        return P0 + u * t1 + v * t2 + 0.5 * (0.02 * u * u + 0.012 * u * v - 0.008 * v * v) * n0

    def family2(uv, psi):  # Sigma_1 seen in member 2's frame after member 1 turned psi
        x = F.apply_point(F.rot_z(psi), sigma1(uv))
        return F.apply_point(F.rot_axis(k2, psi / c["ratio"]), x - mesh.a)

    sigma2_body = GeneratedSurface(family2, 0.0)

    def sigma2(uv):  # at psi = 0 member 2's frame is the fixed frame shifted by a
        return sigma2_body(uv) + mesh.a

    return mesh, sigma1, family2, sigma2_body, sigma2, k2


def contact_u(family2, psi, v=0.0):
    """Contact point on the line v = const of Sigma_1 at member-1 angle psi."""
    return newton_solve(lambda u, th: meshing_function(family2, jnp.stack([u, th[1]]), th[0]),
                        0.0, jnp.stack([psi, v])).x


def quantities(case):
    """Everything the test compares, computed in one jitted call per case."""
    mesh, sigma1, family2, sigma2_body, sigma2, k2 = setup(case)
    uv0 = jnp.zeros(2)
    g1 = local_geometry(sigma1, uv0)
    g2 = local_geometry(sigma2, uv0)
    kin = eigen_kinematics(mesh, g1.r, g1.n, g1.W)
    # velocities of the contact point over each surface, from the motion (omega1 = 1);
    # over Sigma_2 the member-2 frame derivative is rotated back (identity at psi = 0)
    du = jax.jacfwd(lambda psi: contact_u(family2, psi))(0.0)
    vr1 = jax.jacfwd(sigma1)(uv0)[:, 0] * du
    vr2 = jax.jacfwd(lambda psi: sigma2_body(jnp.stack([contact_u(family2, psi), 0.0])))(0.0)
    return dict(mesh=mesh, g1=g1, g2=g2, kin=kin, vr1=vr1, vr2=vr2,
                u_at_0=contact_u(family2, 0.0))


@pytest.mark.parametrize("case", list(CASES))
def test_eigenfunctions_against_independent_routes(case):
    d = jax.jit(quantities, static_argnums=0)(case)
    mesh, g1, g2, kin, vr1, vr2 = d["mesh"], d["g1"], d["g2"], d["kin"], d["vr1"], d["vr2"]
    assert abs(float(d["u_at_0"])) < 1e-12
    np.testing.assert_allclose(g2.r, g1.r, atol=1e-12)          # same point
    s = np.sign(float(g1.n @ g2.n))
    np.testing.assert_allclose(s * g2.n, g1.n, atol=1e-12)       # common normal
    assert abs(float(g1.n @ kin.v12)) < 1e-12                    # meshing equation

    # K_II = kappa1 - kappa2 in the direction of p (common normal, independent surfaces)
    ph = kin.p / jnp.linalg.norm(kin.p)
    W2 = s * g2.W
    k1p = curvature_in_direction(g1.n, g1.W, ph)[0]
    k2p = curvature_in_direction(g1.n, W2, ph)[0]
    np.testing.assert_allclose(kin.k_II, k1p - k2p, rtol=1e-9)
    np.testing.assert_allclose(kin.r_eff * kin.k_II, 1.0, rtol=1e-14)
    # no induced curvature along the contact line, and no torsion between the directions
    cl = kin.contact_dir
    assert abs(float(curvature_in_direction(g1.n, g1.W - W2, cl)[0])) < 1e-10 * abs(float(kin.k_II))
    assert abs(float(ph @ (g1.W - W2) @ cl)) < 1e-10 * abs(float(kin.k_II))

    np.testing.assert_allclose(vr2 - vr1, kin.v12, rtol=1e-9, atol=1e-9)   # v_r2 = v_r1 + v12
    np.testing.assert_allclose(vr1 @ kin.p, kin.phi_I, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(vr2 @ kin.p, kin.phi_II, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(-vr1 @ ph, kin.u1, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(-vr2 @ ph, kin.u2, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(kin.u_s, kin.v12 @ ph, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(kin.srr, kin.u_s / kin.u_e, rtol=1e-14)

    # seed's alternative forms
    w1, w2 = mesh.omega1, mesh.omega2
    q_alt = jnp.cross(jnp.cross(w1, w2), g1.r) + (w1 @ w2) * mesh.a - (w1 @ mesh.a) * w2
    np.testing.assert_allclose(kin.q, q_alt, atol=1e-11)
    v = kin.v12
    p_alt = jnp.cross(w1 - w2, g1.n) + kin.k_v * v + kin.tau_v * jnp.cross(g1.n, v)
    np.testing.assert_allclose(kin.p, p_alt, atol=1e-12)
    k1, k2_, e, f = g1.k1, g1.k2, g1.e1, g1.e2
    phv = jnp.arctan2(v @ f, v @ e)
    p_pr = jnp.cross(w1 - w2, g1.n) - jnp.linalg.norm(v) * (
        -k1 * jnp.cos(phv) * e - k2_ * jnp.sin(phv) * f)
    np.testing.assert_allclose(kin.p, p_pr, atol=1e-12)
    # p is tangent; limit normal is orthogonal to q and v12
    assert abs(float(kin.p @ g1.n)) < 1e-13
    assert abs(float(kin.n0 @ kin.q)) < 1e-12 and abs(float(kin.n0 @ kin.v12)) < 1e-12


def test_signs_flip_with_normal_but_srr_does_not():
    mesh, sigma1, *_ = setup("crossed")
    g = local_geometry(sigma1, jnp.zeros(2))
    a = eigen_kinematics(mesh, g.r, g.n, g.W)
    b = eigen_kinematics(mesh, g.r, -g.n, -g.W)
    np.testing.assert_allclose(b.srr, a.srr, rtol=1e-14)
    np.testing.assert_allclose(b.r_eff, -a.r_eff, rtol=1e-14)
    np.testing.assert_allclose(b.u_e, -a.u_e, rtol=1e-14)
