"""Preset-TE bevel flanks against closed forms ([Preset-TE-bevel]; docs/preset_te_bevel.md).

Cheap: small jitted geometry functions only (no contact analysis)."""

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.gears.preset_bevel import geometry as G
from gearjax.gears.preset_bevel.design_file import read_preset_bevel
from gearjax.io import read_toml

TS = jnp.linspace(-0.5, 0.5, 7)


@pytest.fixture(scope="module")
def des():
    return gj.load_design("example:preset_te_bevel_10x30").design


@pytest.fixture(scope="module")
def frames(des):
    """(r, alpha, n) of the concave flank's curve, unmodified and modified, on TS."""
    out = {}
    for name, kap in (("plain", 0.0), ("mod", float(des.kappa))):
        d = dataclasses.replace(des, kappa=jnp.asarray(kap))
        c = G.curve_data(d, "pinion", "concave", 0.0)
        out[name] = (c, jax.vmap(lambda t: G.curve_frame(c, t))(TS))
    return out


def test_seed_example_blank(des):
    # delta1 = atan(10/30) at 90 deg; A_o = m_t z1 / (2 sin delta1); kappa from 36 arcsec
    d1, d2 = (float(v) for v in G.pitch_angles(des))
    assert d1 == pytest.approx(math.atan(1 / 3), abs=1e-14)
    assert d1 + d2 == pytest.approx(math.pi / 2, abs=1e-14)
    Ai, Am, Ao = (float(v) for v in G.cone_distances(des))
    assert Ao == pytest.approx(35.0 / math.sin(d1), rel=1e-14)
    assert Ao - Ai == pytest.approx(30.0, abs=1e-12)
    t0, tm, t1 = (float(v) for v in G.curve_range(des))
    m = math.sin(d1) / math.tan(math.radians(35.0))
    assert t1 - t0 == pytest.approx(math.log(Ao / Ai) / m, rel=1e-13)
    assert tm == pytest.approx(0.0, abs=1e-14)      # default R0 = sqrt(Ai Ao) cos delta1
    assert float(des.kappa) * (t0 - tm) ** 2 == pytest.approx(math.pi / 18000, rel=1e-13)


def test_log_spiral_constant_spiral_angle_and_unit_frame(des, frames):
    c, (r, al, n) = frames["plain"]
    d1 = float(G.pitch_angles(des)[0])
    f = float(des.R0) * np.exp(float(c.m) * np.asarray(TS))
    np.testing.assert_allclose(r[:, 2], f, rtol=1e-14)                 # f(t) = R0 e^{mt}
    np.testing.assert_allclose(np.hypot(r[:, 0], r[:, 1]), math.tan(d1) * f, rtol=1e-14)
    g = r / jnp.linalg.norm(r, axis=1, keepdims=True)
    ang = np.degrees(np.arccos(np.sum(np.asarray(g * al), axis=1)))
    np.testing.assert_allclose(ang, 35.0, atol=1e-10)                   # constant beta
    np.testing.assert_allclose(np.linalg.norm(al, axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-14)
    np.testing.assert_allclose(np.sum(np.asarray(n * al), axis=1), 0.0, atol=1e-14)


@pytest.mark.parametrize("which", ["plain", "mod"])
def test_pressure_angle_recovered_and_tangent_is_derivative(des, frames, which):
    c, (r, al, n) = frames[which]
    d1 = float(G.pitch_angles(des)[0])
    th = np.arctan2(r[:, 0], r[:, 1])
    eN = np.stack([math.cos(d1) * np.sin(th), math.cos(d1) * np.cos(th),
                   -math.sin(d1) * np.ones_like(th)], 1)
    # alpha_n = angle between n and the pitch-cone tangent plane
    np.testing.assert_allclose(np.degrees(np.arcsin(np.sum(np.asarray(n) * eN, 1))), 20.0,
                               atol=1e-10)
    # the closed-form tangent is the autodiff derivative of the curve (second route)
    d = jax.vmap(jax.jacfwd(lambda t: G.curve_point(c, t)))(TS)
    np.testing.assert_allclose(d / np.linalg.norm(d, axis=1, keepdims=True), al, atol=1e-14)


def test_modified_curve_is_rotated_by_delta_theta(des, frames):
    (_, (r0, _, _)), (c, (r1, _, _)) = frames["plain"], frames["mod"]
    np.testing.assert_allclose(np.linalg.norm(r1, axis=1), np.linalg.norm(r0, axis=1), rtol=1e-14)
    dth = np.arctan2(r1[:, 0], r1[:, 1]) - np.arctan2(r0[:, 0], r0[:, 1])
    np.testing.assert_allclose(dth, -float(des.kappa) * (np.asarray(TS) - float(c.t_m)) ** 2,
                               atol=1e-15)


def test_concave_side_is_the_side_of_geodesic_curvature(frames):
    c, (r, al, n) = frames["plain"]
    # curvature vector by autodiff: its tangent-plane part points where e_c (and the
    # concave flank's normal component) points
    def kvec(t):
        d1 = jax.jacfwd(lambda x: G.curve_point(c, x))(t)
        d2 = jax.jacfwd(jax.jacfwd(lambda x: G.curve_point(c, x)))(t)
        return (d2 - jnp.dot(d2, d1) / jnp.dot(d1, d1) * d1) / jnp.dot(d1, d1)
    k = jax.vmap(kvec)(TS)
    assert np.all(np.sum(np.asarray(k * n), axis=1) > 0.0)   # n . kappa_vec > 0: concave flank
    c2 = dataclasses.replace(c, s=jnp.asarray(-1.0))
    n2 = jax.vmap(lambda t: G.curve_frame(c2, t)[2])(TS)
    assert np.all(np.sum(np.asarray(k * n2), axis=1) < 0.0)  # convex flank


def test_rolling_kinematics_and_conjugate_curve_has_no_sliding(des):
    # omega1 x r = omega2 x r on the pitch line with omega2 = -(z1/z2) (gear axis)
    d1 = float(G.pitch_angles(des)[0])
    r = 100.0 * np.array([0.0, math.sin(d1), math.cos(d1)])
    g = np.asarray(G.gear_assembly_rotation(des.shaft_angle))[:, 2]
    np.testing.assert_allclose(np.cross([0, 0, 1.0], r), np.cross(-(10 / 30) * g, r), atol=1e-13)
    # the gear curve's tangent (autodiff) is the pinion tangent carried into S2: the
    # relative velocity at the contact along Gamma1 is zero
    c = G.curve_data(des, "gear", "concave", 0.0, modified=False)
    dG = jax.vmap(jax.jacfwd(lambda t: G.gear_curve(c, t)[0]))(TS)
    _, a2, n2 = jax.vmap(lambda t: G.gear_curve(c, t))(TS)
    np.testing.assert_allclose(dG / np.linalg.norm(dG, axis=1, keepdims=True), a2, atol=1e-13)
    # Gamma2 lies on the gear pitch cone (angle delta2 with the gear axis)
    P = jax.vmap(lambda t: G.gear_curve(c, t)[0])(TS)
    ang = np.arctan2(np.hypot(P[:, 0], P[:, 1]), P[:, 2])
    np.testing.assert_allclose(ang, float(G.pitch_angles(des)[1]), atol=1e-13)


@pytest.mark.parametrize("member", ["pinion", "gear"])
def test_flank_contains_curve_with_arc_profile(des, member):
    t = jnp.asarray(0.2)
    us = jnp.linspace(-0.4, 0.4, 5)
    if member == "pinion":
        c = G.curve_data(des, "pinion", "concave", 0.0)
        fn = G.pinion_flank_point
        r, al, n = G.curve_frame(c, t)
        centre, rho = r - c.rho * n, float(des.rho1)
    else:
        c = G.curve_data(des, "gear", "concave", 0.0, modified=False)
        fn = G.gear_flank_point
        r, al, n = G.gear_curve(c, t)
        centre, rho = r + c.rho * n, float(des.rho2)
    P = jax.vmap(lambda u: fn(c, jnp.stack([u, t])))(us)
    np.testing.assert_allclose(P[2], r, atol=1e-13)                       # u = 0 on the curve
    np.testing.assert_allclose(np.linalg.norm(P - centre, axis=1), rho, rtol=1e-13)
    np.testing.assert_allclose(np.asarray(P - r) @ np.asarray(al), 0.0, atol=1e-12)  # normal plane
    nu = gj.surfaces.local_geometry(jax.tree_util.Partial(fn, c), jnp.stack([0.0, t])).n
    assert abs(abs(float(jnp.dot(nu, n))) - 1.0) < 1e-13                # surface normal = n


def test_flank_gradient_wrt_design_fields_matches_central_differences(des):
    def point(x):
        d = dataclasses.replace(des, kappa=x[0], rho1=x[1])
        return G.pinion_flank(d, "concave")(jnp.array([0.3, 0.3]))
    x0 = jnp.stack([des.kappa, des.rho1])
    J = np.asarray(jax.jacfwd(point)(x0))
    for i in range(2):
        h = 1e-3 * float(x0[i])
        e = jnp.zeros(2).at[i].set(h)
        fd = (np.asarray(point(x0 + e)) - np.asarray(point(x0 - e))) / (2 * h)
        np.testing.assert_allclose(J[:, i], fd, rtol=1e-5, atol=1e-9 * np.abs(fd).max())


def test_design_file_validation_names_key():
    data = read_toml("example:preset_te_bevel_10x30")
    bad = dict(data, flanks=dict(data["flanks"], profile_radius_pinion_mm=-3.0))
    with pytest.raises(ValueError, match="rho1"):
        read_preset_bevel(bad)
    bad = dict(data, pair={k: v for k, v in data["pair"].items() if k != "spiral_angle_deg"})
    with pytest.raises(ValueError, match="spiral_angle_deg"):
        read_preset_bevel(bad)
    bad = dict(data, preset={"te_arcsec": 1e4})
    with pytest.raises(ValueError, match="preset_te_arcsec"):
        read_preset_bevel(bad)
    bad = dict(data, pair=dict(data["pair"], face_width_mm=90.0))
    with pytest.raises(ValueError, match="face_width"):
        read_preset_bevel(bad)
    f = gj.design_from_dict(data)
    assert isinstance(f, gj.preset_bevel.PresetBevelFile) and f.teeth("gear") == 30
    assert gj.tca.family_of(f).family == "preset_bevel"


def test_constructor_matches_design_file(des):
    d = gj.preset_bevel.PresetBevelDesign.create(z1=10, z2=30, beta_deg=35, alpha_n_deg=20, shaft_angle_deg=90,
                                    module_t=7, face_width=30, rho1=16, rho2=16, addendum=4.5,
                                    dedendum=4.5, preset_te_arcsec=36)
    for a, b in zip(jax.tree_util.tree_leaves(d), jax.tree_util.tree_leaves(des)):
        assert float(a) == float(b)
    with pytest.raises(ValueError, match="beta"):
        gj.preset_bevel.PresetBevelDesign.create(z1=10, z2=30, beta_deg=70, alpha_n_deg=20,
                                    shaft_angle_deg=90, module_t=7, face_width=30, rho1=16,
                                    rho2=16, addendum=4.5, dedendum=4.5)
