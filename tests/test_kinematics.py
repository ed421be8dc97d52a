"""Eigenfunction kinematics ([Eigenfunctions] §1, docs/references.md) against independent routes and closed forms.

Sigma_1 is an explicit curved patch on member 1; Sigma_2 is generated from it as
the envelope in member 2's frame (GeneratedSurface), for crossed, parallel and
intersecting axes.  References that do not share the eigenfunction formulas:

* the instantaneous contact line from the meshing equation alone (zero set of
  f(uv, 0) on Sigma_1), whose in-plane normal must be the direction of p;
* the velocities of the contact point over each surface, v_r1 and v_r2, from the
  time derivative of the contact point (autodiff of the motion through the
  envelope solve); u1, u2, u_e, u_s and SRR follow from them by their definitions;
* K_II and R_eff from the difference of the two surfaces' normal curvatures, each
  surface's curvature computed on its own by autodiff;
* closed forms: involute spur/helical contact on the line of action (rolling speeds
  omega_i rho_i, rho_red/cos beta_b, contact line at beta_b), the pitch point of
  parallel axes, the pitch cone of a bevel pair and the sliding speed of crossed
  helical gears.
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax import frames as F
from gearjax.kinematics import crossed_axes, eigen_kinematics, parallel_axes, relative_velocity
from gearjax.newton import newton_solve
from gearjax.surfaces import GeneratedSurface, curvature_in_direction, local_geometry, meshing_function

CASES = {
    "crossed": dict(shaft_angle=1.2, offset=20.0, ratio=2.5),
    "parallel": dict(shaft_angle=0.0, offset=90.0, ratio=2.0),
    "intersecting": dict(shaft_angle=np.pi / 2, offset=0.0, ratio=3.0),
}


def setup(case):
    """``case``: a name of CASES, or its dict of (possibly traced) values."""
    c = CASES[case] if isinstance(case, str) else case
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


def quantities(params):
    """Everything the test compares, for the case values ``params`` (traced: the three
    cases run one compiled program)."""
    mesh, sigma1, family2, sigma2_body, sigma2, k2 = setup(params)
    uv0 = jnp.zeros(2)
    g1 = local_geometry(sigma1, uv0)
    g2 = local_geometry(sigma2, uv0)
    kin = eigen_kinematics(mesh, g1.r, g1.n, g1.W)
    # velocities of the contact point over each surface, from the motion (omega1 = 1);
    # over Sigma_2 the member-2 frame derivative is rotated back (identity at psi = 0)
    du = jax.jacfwd(lambda psi: contact_u(family2, psi))(0.0)
    vr1 = jax.jacfwd(sigma1)(uv0)[:, 0] * du
    vr2 = jax.jacfwd(lambda psi: sigma2_body(jnp.stack([contact_u(family2, psi), 0.0])))(0.0)
    # the instantaneous contact line on Sigma_1 is the zero set of the meshing function
    # f(uv, psi = 0); its tangent is J1 (uv-direction normal to grad f)
    gf = jax.grad(lambda q: meshing_function(family2, q, 0.0))(uv0)
    line = jax.jacfwd(sigma1)(uv0) @ jnp.stack([-gf[1], gf[0]])
    return dict(mesh=mesh, g1=g1, g2=g2, kin=kin, vr1=vr1, vr2=vr2, line=line,
                u_at_0=contact_u(family2, 0.0))


_quantities = jax.jit(quantities)


@pytest.mark.parametrize("case", list(CASES))
def test_eigenfunctions_against_independent_routes(case):
    d = _quantities({k: jnp.asarray(v, float) for k, v in CASES[case].items()})
    mesh, g1, g2, kin, vr1, vr2 = d["mesh"], d["g1"], d["g2"], d["kin"], d["vr1"], d["vr2"]
    assert abs(float(d["u_at_0"])) < 1e-12
    np.testing.assert_allclose(g2.r, g1.r, atol=1e-12)          # same point
    s = np.sign(float(g1.n @ g2.n))
    np.testing.assert_allclose(s * g2.n, g1.n, atol=1e-12)       # common normal
    assert abs(float(g1.n @ kin.v12)) < 1e-12                    # meshing equation

    # Tolerances below: every route agrees to <= 1e-15 relative (measured); 1e-12
    # leaves room for other platforms.
    # Direction normal to the contact line in the tangent plane, from the meshing
    # equation alone; p must lie along it.  Its sense is eigen_kinematics' convention,
    # so m takes the sense of p.
    line = d["line"] / jnp.linalg.norm(d["line"])
    m = jnp.cross(g1.n, line)
    ph = kin.p / jnp.linalg.norm(kin.p)
    cos_mp = float(m @ ph)
    assert abs(abs(cos_mp) - 1.0) < 1e-12
    m = np.sign(cos_mp) * m
    np.testing.assert_allclose(abs(float(kin.contact_dir @ line)), 1.0, atol=1e-12)

    # K_II = kappa1 - kappa2 in the direction m (common normal, independent surfaces;
    # Sigma_2's curvature differentiates through its envelope solve); R_eff = 1/K_II.
    W2 = s * g2.W
    k_ind = float(curvature_in_direction(g1.n, g1.W, m)[0] - curvature_in_direction(g1.n, W2, m)[0])
    np.testing.assert_allclose(kin.k_II, k_ind, rtol=1e-12)
    np.testing.assert_allclose(kin.r_eff, 1.0 / k_ind, rtol=1e-12)
    # no induced curvature along the contact line, and no torsion between the directions
    assert abs(float(curvature_in_direction(g1.n, g1.W - W2, line)[0])) < 1e-12 * abs(k_ind)
    assert abs(float(m @ (g1.W - W2) @ line)) < 1e-12 * abs(k_ind)

    # velocities: v_r2 = v_r1 + v12 and the eigenfunctions as v_ri . p
    np.testing.assert_allclose(vr2 - vr1, kin.v12, rtol=1e-12, atol=1e-12 * float(jnp.linalg.norm(kin.v12)))
    np.testing.assert_allclose(vr1 @ kin.p, kin.phi_I, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(vr2 @ kin.p, kin.phi_II, rtol=1e-12, atol=1e-12)
    # surface velocities relative to the contact point, normal to the contact line:
    # u_i = -v_ri . m; then u_e, u_s and SRR by their definitions (rolling = mean,
    # sliding = difference, SRR = u_s/u_e), to 1e-12 of the largest speed.
    u1, u2 = -float(vr1 @ m), -float(vr2 @ m)
    scale = max(abs(u1), abs(u2))
    for got, want in ((kin.u1, u1), (kin.u2, u2), (kin.u_e, 0.5 * (u1 + u2)), (kin.u_s, u1 - u2)):
        assert abs(float(got) - want) < 1e-12 * scale, (float(got), want)
    assert abs(0.5 * (u1 + u2)) > 0.05 * scale      # SRR well conditioned here
    np.testing.assert_allclose(kin.srr, 2 * (u1 - u2) / (u1 + u2), rtol=1e-12)

    # alternative forms of [Eigenfunctions]
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
    # Euler/Bertrand for the curvature and torsion of Sigma_1 along v12
    np.testing.assert_allclose(kin.k_v, k1 * jnp.cos(phv) ** 2 + k2_ * jnp.sin(phv) ** 2, rtol=1e-12)
    np.testing.assert_allclose(kin.tau_v, (k2_ - k1) * jnp.sin(phv) * jnp.cos(phv), atol=1e-14)
    # p is tangent; limit normal is orthogonal to q and v12
    assert abs(float(kin.p @ g1.n)) < 1e-13
    assert abs(float(kin.n0 @ kin.q)) < 1e-12 and abs(float(kin.n0 @ kin.v12)) < 1e-12


@pytest.mark.parametrize("beta_b", [0.0, 0.25])
def test_involute_contact_on_the_line_of_action_closed_forms(beta_b):
    """Spur (beta_b = 0) and helical involute contact, built from the closed-form local
    geometry only (no flank is generated).  Parallel axes, a = 90 mm, u = z2/z1 = 2,
    working pressure angle 0.38 rad, omega1 = 10 rad/s.  The line of action touches the
    base circles at T1, T2; at C = T1 + rho1 d the common normal lies in the plane of
    action at beta_b to the transverse plane, the pinion flank (involute helicoid) has
    the principal curvature cos(beta_b)/rho1 normal to the plane of action and 0 along
    the contact line g = sin(beta_b) d + cos(beta_b) z (a generator).  Textbook answers
    (ISO 21771 involute geometry; ISO 6336-2 rho_red): the flanks roll normal to the
    contact line at omega_i rho_i in the same sense, so u_e = (omega1 rho1 + omega2
    rho2)/2, u_s = omega1 rho1 - omega2 rho2, SRR = u_s/u_e, and
    R_eff = rho1 rho2/((rho1 + rho2) cos beta_b).  Tolerance: rounding only (1e-12)."""
    a, u, alpha_w, w1 = 90.0, 2.0, 0.38, 10.0
    mesh = parallel_axes(a, u, omega1=w1)
    rw1, rw2 = a / (1 + u), a * u / (1 + u)
    d = np.array([np.cos(alpha_w), np.sin(alpha_w), 0.0])
    z = np.array([0.0, 0.0, 1.0])
    P = np.array([0.0, rw1, 0.0])
    T1 = P - rw1 * np.sin(alpha_w) * d
    length = a * np.sin(alpha_w)                       # T1 T2
    cb, sb = np.cos(beta_b), np.sin(beta_b)
    n = -(cb * d - sb * z)                             # into the pinion tooth
    et = np.cross(z, d)                                # normal to the plane of action
    g = sb * d + cb * z                                # contact line (generator)
    for rho1 in (0.3 * length, rw1 * np.sin(alpha_w), 0.75 * length):   # the middle one is P
        rho2 = length - rho1
        C = T1 + rho1 * d
        W1 = -(cb / rho1) * np.outer(et, et)
        k = eigen_kinematics(mesh, jnp.asarray(C), jnp.asarray(n), jnp.asarray(W1))
        assert abs(float(k.v12 @ n)) < 1e-12 * w1 * a             # C is a contact point
        sgn = float(k.p @ et) / float(jnp.linalg.norm(k.p))       # p along e_t, either sense
        np.testing.assert_allclose(abs(sgn), 1.0, atol=1e-12)
        np.testing.assert_allclose(abs(float(k.contact_dir @ g)), 1.0, atol=1e-12)
        v1, v2 = w1 * rho1, w1 / u * rho2
        np.testing.assert_allclose(float(k.u1), sgn * v1, rtol=1e-12)
        np.testing.assert_allclose(float(k.u2), sgn * v2, rtol=1e-12)
        np.testing.assert_allclose(float(k.u_e), sgn * 0.5 * (v1 + v2), rtol=1e-12)
        assert abs(float(k.u_s) - sgn * (v1 - v2)) < 1e-12 * v1
        assert abs(float(k.srr) - 2 * (v1 - v2) / (v1 + v2)) < 1e-12
        r_eff = rho1 * rho2 / ((rho1 + rho2) * cb)
        np.testing.assert_allclose(float(k.r_eff), r_eff, rtol=1e-12)
        np.testing.assert_allclose(float(k.k_II), 1.0 / r_eff, rtol=1e-12)


def test_mesh_constructors_closed_forms():
    """Pure rolling where the textbook puts the pitch surfaces, and the sliding speed of
    crossed helical gears; v12 from relative_velocity, references typed in.

    * parallel axes, external: pitch point on the line of centres at a/(1 + u);
      internal: at a/(u - 1) on the far side of the pinion; omega2 = -/+ omega1/u.
    * intersecting axes (bevel): the pitch cones touch along the line at delta1 from
      axis 1 towards axis 2, tan(delta1) = sin(Sigma)/(u + cos(Sigma)) (pitch angle of
      bevel gears, ISO 23509); v12 = 0 along it.
    * crossed axes, crossed helical gears with helix angles beta1 + beta2 = Sigma, pitch
      radii r_i = z_i m_n/(2 cos beta_i), E = r1 + r2: at the pitch point on the common
      perpendicular the sliding speed is v1 sin(Sigma)/cos(beta2), v1 = omega1 r1 (the
      pitch-line velocities are at Sigma and have equal normal components).
    Tolerance: rounding (1e-13 of the speeds)."""
    w1 = 3.0
    m = parallel_axes(90.0, 2.5, omega1=w1)
    np.testing.assert_allclose(m.omega2, [0.0, 0.0, -w1 / 2.5], rtol=1e-15)
    np.testing.assert_allclose(m.a, [0.0, 90.0, 0.0])
    np.testing.assert_allclose(relative_velocity(m, jnp.array([0.0, 90.0 / 3.5, 7.0])), 0.0, atol=1e-13)
    m = parallel_axes(40.0, 3.0, omega1=w1, external=False)
    np.testing.assert_allclose(m.omega2, [0.0, 0.0, w1 / 3.0], rtol=1e-15)
    np.testing.assert_allclose(relative_velocity(m, jnp.array([0.0, -20.0, -2.0])), 0.0, atol=1e-13)
    # the ratio is not symmetric: a point off the pitch point slides
    assert float(jnp.linalg.norm(relative_velocity(m, jnp.array([0.0, -10.0, 0.0])))) > 1.0

    for sigma, u in ((np.pi / 2, 3.0), (1.2, 2.5), (2.0, 1.5)):
        m = crossed_axes(sigma, 0.0, u, omega1=w1)
        np.testing.assert_allclose(jnp.linalg.norm(m.omega2), w1 / u, rtol=1e-15)
        delta1 = math.atan2(math.sin(sigma), u + math.cos(sigma))
        for s in (10.0, 55.0):
            r = s * jnp.array([math.sin(delta1), 0.0, math.cos(delta1)])
            np.testing.assert_allclose(relative_velocity(m, r), 0.0, atol=1e-13 * w1 * s)

    sigma, b1, mn, z1, z2 = 1.2, 0.5, 2.0, 15, 30
    b2 = sigma - b1
    r1, r2 = z1 * mn / (2 * math.cos(b1)), z2 * mn / (2 * math.cos(b2))
    m = crossed_axes(sigma, r1 + r2, z2 / z1, omega1=w1)
    v12 = relative_velocity(m, jnp.array([0.0, -r1, 0.0]))
    np.testing.assert_allclose(float(jnp.linalg.norm(v12)), w1 * r1 * math.sin(sigma) / math.cos(b2),
                               rtol=1e-13)
    assert abs(float(v12[1])) < 1e-13 * w1 * r1      # tangent to both pitch cylinders


def test_signs_flip_with_normal_but_srr_does_not():
    mesh, sigma1, *_ = setup("crossed")
    g = local_geometry(sigma1, jnp.zeros(2))
    a = eigen_kinematics(mesh, g.r, g.n, g.W)
    b = eigen_kinematics(mesh, g.r, -g.n, -g.W)
    np.testing.assert_allclose(b.srr, a.srr, rtol=1e-14)
    np.testing.assert_allclose(b.r_eff, -a.r_eff, rtol=1e-14)
    np.testing.assert_allclose(b.u_e, -a.u_e, rtol=1e-14)
