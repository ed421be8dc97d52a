"""Formate gears and the pinions they generate (gearjax.gears.hypoid.formate): machine settings
from placements, and hypoid (offset) conjugacy through TCA."""

import math
from dataclasses import replace

import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax import frames
from gearjax.gears.hypoid import tca as th
from gearjax.gears.hypoid.formate import formate_from_placement, generating_gear_pinion, settings_from_frames
from gearjax.gears.hypoid.flank import work_point
from gearjax.gears.hypoid.design_file import load_design
from gearjax.gears.hypoid.machine import MachineSettings, cutter_to_cradle, cutter_to_work, work_to_machine
from gearjax.tca.path import ARCSEC

FIELDS = ("radial_distance", "cradle_angle", "tilt", "swivel", "blank_offset",
          "machine_root_angle", "sliding_base", "center_to_back")


def _wrap(a):
    return math.atan2(math.sin(a), math.cos(a))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_settings_from_frames_recovers_settings(seed):
    rng = np.random.default_rng(seed)
    ms = MachineSettings.create(radial_distance=rng.uniform(60, 140), cradle_angle=rng.uniform(-3, 3),
                                tilt=rng.uniform(0.05, 0.5), swivel=rng.uniform(-3, 3),
                                blank_offset=rng.uniform(-30, 30),
                                machine_root_angle=rng.uniform(-0.3, 1.2),
                                sliding_base=rng.uniform(-10, 10), center_to_back=rng.uniform(-20, 20),
                                ratio_of_roll=3.0)
    kappa, phi0 = rng.uniform(-3, 3), rng.uniform(-3, 3)
    # the cutter turned about its own axis and the work turned about its axis: same flank
    Mct = np.asarray(cutter_to_cradle(ms)) @ np.asarray(frames.rot_z(kappa))
    Bw = np.asarray(work_to_machine(ms, phi0))
    got, phi0_got = settings_from_frames(Mct, Bw, generated=True, ratio_of_roll=3.0)
    for f in FIELDS:
        a, b = float(getattr(got, f)), float(getattr(ms, f))
        if f in ("cradle_angle", "swivel"):
            a, b = _wrap(a), _wrap(b)
        assert a == pytest.approx(b, abs=1e-11), f
    assert _wrap(phi0_got - phi0) == pytest.approx(0.0, abs=1e-12)


def test_settings_from_frames_refuses_bad_frames():
    ms = MachineSettings.create(radial_distance=100.0, cradle_angle=0.3, machine_root_angle=0.2,
                                ratio_of_roll=2.0)
    Mct = np.asarray(cutter_to_cradle(ms))
    Bw = np.asarray(work_to_machine(ms, 0.0))
    lifted = Mct.copy()
    lifted[2, 3] = 1.0
    with pytest.raises(ValueError, match="tip-plane centre"):
        settings_from_frames(lifted, Bw, generated=True)
    with pytest.raises(ValueError, match="work axis"):
        settings_from_frames(Mct, np.asarray(frames.rot_z(0.4)) @ Bw, generated=True)


def test_settings_from_frames_is_differentiable():
    """jacfwd of the decomposition of the frames of known settings is the identity on
    the geometric settings (a tilted cutter); the checks still run on the primal values
    under jax.grad and are skipped under jax.jit."""
    import jax
    p = jnp.array([101.0, 0.7, 0.3, -0.4, 12.0, 0.45, -3.0, 4.0])

    def roundtrip(v):
        ms = MachineSettings(*v, jnp.asarray(3.0), jnp.asarray(0.0), jnp.asarray(0.0), True)
        got, _ = settings_from_frames(cutter_to_cradle(ms), work_to_machine(ms, 0.2),
                                      generated=True, ratio_of_roll=3.0)
        return jnp.stack([getattr(got, f) for f in FIELDS])

    J = np.asarray(jax.jacfwd(roundtrip)(p))
    assert np.max(np.abs(J - np.eye(len(FIELDS)))) < 1e-12
    assert np.max(np.abs(np.asarray(jax.jit(roundtrip)(p)) - np.asarray(p))) < 1e-11

    def lifted(z):
        ms = MachineSettings(*p, jnp.asarray(3.0), jnp.asarray(0.0), jnp.asarray(0.0), True)
        Mct = cutter_to_cradle(ms).at[2, 3].set(z)
        return settings_from_frames(Mct, work_to_machine(ms, 0.0), generated=True)[0].radial_distance

    with pytest.raises(ValueError, match="tip-plane centre"):
        jax.grad(lifted)(1.0)


def test_formate_from_placement_gradient_matches_central_differences():
    """d(settings)/d(placement) through formate_from_placement (untilted branch) against
    central differences; the cone is moved along the work axis and turned about the
    work frame's y axis."""
    import jax
    d = load_design("example:hft_8x43")
    g = d.flank("gear", "convex")
    G0 = cutter_to_work(g.machine, 0.0)

    def settings(x):
        G = frames.rot_y(0.1 * x) @ frames.translate(0.0, 0.0, x) @ G0
        ms = formate_from_placement(g.cutter, G, g.blank)[0].machine
        return jnp.stack([getattr(ms, f) for f in FIELDS if f not in ("tilt", "blank_offset")])

    J = np.asarray(jax.jacfwd(settings)(0.0))
    h = 1e-4
    fd = (np.asarray(settings(h)) - np.asarray(settings(-h))) / (2 * h)
    assert np.all(np.isfinite(J))
    assert np.max(np.abs(J - fd)) < 1e-8 * max(1.0, np.max(np.abs(J)))


def test_formate_from_placement_reproduces_the_cone():
    d = load_design("example:hft_8x43")
    g = d.flank("gear", "convex")
    G = np.asarray(cutter_to_work(g.machine, 0.0))
    fl, phi0 = formate_from_placement(g.cutter, G, g.blank)
    assert float(fl.machine.tilt) == pytest.approx(0.0, abs=1e-12)
    assert float(fl.machine.blank_offset) == pytest.approx(0.0, abs=1e-12)
    Rz = np.asarray(frames.rot_z(-phi0))
    for s, t in ((1.0, 0.1), (5.0, -0.05), (9.0, 0.02)):
        a = np.asarray(work_point(g, s, t)[0])
        b = Rz @ np.append(np.asarray(work_point(fl, s, t)[0]), 1.0)
        # same cone, the cutter possibly turned about its own axis: compare radii/heights
        ax, c = G[:3, 2], G[:3, 3]
        for p in (a, b[:3]):
            h = (p - c) @ ax
            r = np.linalg.norm(p - c - h * ax)
            assert r == pytest.approx(float(g.cutter.point_radius) + math.tan(float(g.cutter.blade_angle)) * h
                                      * float(g.cutter.sign), abs=1e-9)


@pytest.fixture(scope="module")
def hypoid_pair():
    d = load_design("example:hypoid_iso_10x41")
    return generating_gear_pinion(th.pair_flanks(d, "drive"))


def test_generating_gear_pinion_settings(hypoid_pair):
    pair, info = hypoid_pair
    ms, gm = pair.pinion.machine, pair.gear.machine
    assert info["chain_error"] < 1e-10
    # cradle = gear: ratio of roll z2/z1, work axis at the shaft angle to the cradle axis
    assert float(ms.ratio_of_roll) == pytest.approx(41 / 10, rel=1e-15)
    assert float(ms.machine_root_angle) == pytest.approx(0.5 * math.pi - float(pair.shaft_angle), abs=1e-12)
    assert abs(float(ms.blank_offset)) == pytest.approx(float(pair.offset), rel=1e-12)
    # the gear's untilted formate cutter, seen from its own axis, is tilted by 90 deg - gamma_m2
    assert float(ms.tilt) == pytest.approx(0.5 * math.pi - float(gm.machine_root_angle), abs=1e-12)
    assert pair.pinion.cutter.sign == -pair.gear.cutter.sign
    # the mean contact falls on the pinion blank near mid face
    assert abs(info["xi"]) < 0.1 and info["h"] > 0.0 and info["tip_gap"] > 0.0


def test_tilted_point_radius_change_keeps_the_mean_blade(hypoid_pair):
    pair, _ = hypoid_pair
    prep = th.prepare(pair)
    th_m = float(prep.x_ref[0])
    p2 = th.with_point_radius(pair.pinion, 2.0, th_m)
    assert float(p2.machine.sliding_base) != pytest.approx(float(pair.pinion.machine.sliding_base), abs=1e-3)
    for s in (0.5, 4.0, 9.0):
        for psi in (-0.1, 0.0, 0.07):
            a = np.asarray(work_point(pair.pinion, s, th_m, psi)[0])
            b = np.asarray(work_point(p2, s, th_m, psi)[0])
            assert np.max(np.abs(a - b)) < 1e-11
    a = np.asarray(work_point(pair.pinion, 4.0, th_m + 0.05, 0.0)[0])
    b = np.asarray(work_point(p2, 4.0, th_m + 0.05, 0.0)[0])
    assert np.max(np.abs(a - b)) > 1e-3


def test_hypoid_offset_pair_is_conjugate(hypoid_pair):
    """Offset 25 mm: the pinion generated by the formate gear meshes with zero TE."""
    pair, _ = hypoid_pair
    out = gj.run_tca(th.prepare(pair), line_contact=True, steps_per_pitch=8, half_pitches=1.0,
                     n_pairs=3, kinematics=False, throw=False)
    te = np.asarray(out.path.te) / ARCSEC
    ok = np.asarray(out.path.converged)
    on = ok & (np.asarray(out.margin) >= 0.0)
    assert ok.all() and on.sum() >= 9          # at least one pitch (8 steps) on both flanks
    assert np.max(np.abs(te)) < 1e-6
    assert float(np.max(np.asarray(out.path.residual))) < 1e-12


@pytest.fixture(scope="module")
def localised(hypoid_pair):
    """Point radius +2 mm (blade through the mean point), 2C = 0.02; one TCA shared by
    the tests below (16 steps per pitch, +-1 pitch)."""
    pair, _ = hypoid_pair
    th_m = float(th.prepare(pair).x_ref[0])
    p2 = th.with_point_radius(pair.pinion, 2.0, th_m)
    ms = replace(p2.machine, modified_roll_2c=jnp.asarray(0.02))
    prep = th.prepare(replace(pair, pinion=replace(p2, machine=ms)))
    out = gj.run_tca(prep, steps_per_pitch=16, half_pitches=1.0, n_pairs=3, kinematics=False,
                     throw=False)
    return prep, out


def test_hypoid_modified_roll_gives_theoretical_parabola(localised):
    """TE parabola ``(z1/z2)(C/R_a) t^2`` (first-order theory, C = 2C/2, R_a = z2/z1)."""
    _, out = localised
    phi, te = np.asarray(out.path.phi1), np.asarray(out.path.te)
    ok = np.asarray(out.path.converged)
    assert ok.all()
    t = phi - phi[len(phi) // 2]
    c3, c2, c1, c0 = np.polyfit(t, te, 3)
    theory = (10 / 41) * 0.01 / (41 / 10)
    assert c2 == pytest.approx(theory, rel=0.01)
    assert abs(c3) * (math.pi / 10) < 0.02 * abs(c2)
    mid = len(phi) // 2
    assert abs(float(out.coords["xi1"][mid])) < 0.2


def test_contact_point_velocity_matches_central_differences(localised):
    """The implicit derivative of the contact (contact-point velocity, actual gear
    speed) against 4th-order central differences of the path."""
    from gearjax.gears.hypoid.contact_kinematics import path_kinematics
    prep, out = localised
    k = path_kinematics(prep.pair, out.path)
    h = float(out.path.phi1[1] - out.path.phi1[0])

    def d4(a):
        a = np.asarray(a)
        return (a[:-4] - 8 * a[1:-3] + 8 * a[3:-1] - a[4:]) / (12 * h)

    # the kinematics are those of the surface contact: stencils of five surface points
    # only (where the path runs onto a tip edge, the contact made there is the edge's,
    # gearjax.tca.edge_contact, and the difference quotient straddles the switch)
    surf = np.asarray(out.path.edge_kind) < 0
    inner = np.convolve(surf.astype(int), np.ones(5, int), "valid") == 5
    assert inner.sum() >= len(surf) // 2
    vc = np.asarray(k.v_contact)[2:-2][inner]
    assert np.max(np.abs(d4(out.path.point)[inner] - vc)) < 1e-5 * np.max(np.abs(vc))
    ratio = np.asarray(k.gear_ratio)[2:-2][inner]
    assert np.max(np.abs(d4(out.path.phi2)[inner] - ratio)) < 1e-9
    # not conjugate: the pair's rolling velocity differs from the conjugate model's
    assert np.max(np.abs(np.asarray(k.u_e) - np.asarray(k.model.u_e))) > 1e-3
