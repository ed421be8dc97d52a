"""[Eigenfunctions] (docs/references.md) on a machine-cut pair (gearjax.studies.cutter_radius_pair,
gearjax.gears.hypoid.contact_kinematics): the paper's cutter cone as a formate gear, the pinion
it generates, TCA contact points, and the kinematics there against the paper's eigenfunction
model."""

import dataclasses
import functools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.gears.hypoid import tca as th
from gearjax.gears.hypoid.contact_kinematics import path_kinematics
from gearjax.studies import cutter_radius as hk
from gearjax.studies.cutter_radius_pair import study_pair, study_uv
from gearjax.tca.path import ARCSEC
from gearjax.tca.assembly import Misalignment


@pytest.fixture(scope="module")
def conj():
    inp = hk.study_blank_input(95.25)
    sp = study_pair(inp, hk.StudySettings.make(95.25), "convex")
    prep = th.prepare(sp.pair)
    out = gj.run_tca(prep, line_contact=True, steps_per_pitch=8, half_pitches=1.0, n_pairs=3,
                     kinematics=False, throw=False)
    return sp, prep, out


def test_machine_settings_of_the_seed_cone(conj):
    sp, _, _ = conj
    g, p = sp.pair.gear.machine, sp.pair.pinion.machine
    assert not g.generated and p.generated
    # the cutter axis of [Eigenfunctions] is the pitch-plane normal: untilted formate gear whose
    # machine root angle is the gear pitch angle
    assert float(g.tilt) == pytest.approx(0.0, abs=1e-12)
    assert float(g.machine_root_angle) == pytest.approx(float(sp.setup.blank["delta2"]), abs=1e-12)
    assert float(p.ratio_of_roll) == pytest.approx(39 / 6, rel=1e-15)
    assert abs(float(p.blank_offset)) == pytest.approx(35.0, rel=1e-12)
    assert sp.info["chain_error"] < 1e-10


def test_machine_cut_pair_is_conjugate(conj):
    _, _, out = conj
    ok = np.asarray(out.path.converged)
    on = ok & (np.asarray(out.margin) >= 0.0)
    assert ok.all() and on.sum() >= 9
    assert np.max(np.abs(np.asarray(out.path.te))) / ARCSEC < 1e-6


def _pair_and_seed_fields(sp, prep, out):
    k = path_kinematics(prep.pair, out.path, line_contact=True)
    uv = study_uv(sp, out.path.p2_body)
    f = jax.vmap(lambda q: hk.point_fields(sp.setup, q))(jnp.asarray(uv))
    return k, uv, f


def _rel(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)) / np.abs(np.asarray(b))))


def test_tca_function_starts_the_path_at_the_reference_given(conj):
    """``gearjax.tca_function``'s ``f(pair, reference=(x_ref, phi1_ref))`` starts the
    contact path from that guess instead of the design's: in line contact the pinion
    blade position ``x_ref[1]`` is the contact line followed (it stays fixed), so a
    reference at 60 % of the prepared one, its grid centred a third of a grid step
    later, gives the TCA of the prepared pair whose guess is there, bit-identical (the
    same compiled program), and not the default's."""
    _, prep, out0 = conj
    x_ref = np.array(prep.x_ref, float)
    x_ref[1] *= 0.6
    phi1_ref = float(prep.phi1_ref + (2.0 * np.pi / (prep.pair.z1 * 8)) / 3.0)
    opts = dict(line_contact=True, steps_per_pitch=8, half_pitches=1.0, n_pairs=3,
                kinematics=False)
    ref = gj.run_tca(prep._replace(x_ref=x_ref, phi1_ref=phi1_ref), throw=False, **opts)
    f = gj.tca_function(prep, **opts)
    got = f(f.pair, reference=(jnp.asarray(x_ref), jnp.asarray(phi1_ref)))
    for name in ("phi1", "uv1", "uv2", "phi2", "te", "converged"):
        np.testing.assert_array_equal(np.asarray(getattr(got.path, name)),
                                      np.asarray(getattr(ref.path, name)), err_msg=name)
    assert np.asarray(got.path.converged).all()
    np.testing.assert_array_equal(np.asarray(got.path.uv1)[:, 1], x_ref[1])
    mid = got.path.phi1.shape[0] // 2
    assert float(got.path.phi1[mid]) == pytest.approx(phi1_ref, abs=1e-15)
    np.testing.assert_array_equal(np.asarray(out0.path.uv1)[:, 1], prep.x_ref[1])
    default = f(f.pair)
    np.testing.assert_array_equal(np.asarray(default.path.uv1), np.asarray(out0.path.uv1))

def test_contact_kinematics_equal_the_seed_model(conj):
    """The cone model of [Eigenfunctions] §2 and the machine-cut pair give the same fields.

    At the TCA contact points of three pinion blade positions (30 %, 50 %, 70 % of the
    blade to the tip; 17 pinion angles each, both sides of the mean contact): (i) the
    cone model evaluated by its own module at the mapped flank parameters, (ii) the
    eigenfunctions in the TCA frame, (iii) the pair route (contact-point velocity from
    the TCA, both flanks' curvatures) agree to 1e-9 relative in u1, u2, u_e, u_s, SRR
    and R_eff (and (i)-(ii) in the eigen quantities).  The fields vary over the points
    and are far from zero, so a sign slip (a mirrored flank parameter, a reversed
    velocity) changes them by O(1): checked by planting one of each."""
    sp, prep, out0 = conj
    outs = [out0]
    for frac in (0.3, 0.7):
        x_ref = np.array(prep.x_ref, float)
        x_ref[1] = 2.0 * frac * x_ref[1]          # x_ref[1] is half the blade to the tip
        outs.append(gj.run_tca(prep._replace(x_ref=x_ref), line_contact=True, steps_per_pitch=8,
                               half_pitches=1.0, n_pairs=3, kinematics=False, throw=False))
    uv_all = []
    for out in outs:
        assert np.asarray(out.path.converged).all()
        k, uv, f = _pair_and_seed_fields(sp, prep, out)
        uv_all.append(np.asarray(uv))
        assert np.asarray(f.converged).all()
        for name in ("u1", "u2", "u_e", "u_s", "srr", "r_eff", "phi_I", "phi_II", "k_II"):
            assert _rel(getattr(k.model, name), getattr(f, name)) < 1e-9, name
        for name in ("u1", "u2", "u_e", "u_s", "srr", "r_eff"):
            assert _rel(getattr(k, name), getattr(f, name)) < 1e-9, name
        # line contact: no relative curvature along the contact line; a rank-1 tensor
        assert np.max(np.abs(np.asarray(k.k_along))) < 1e-9 * np.min(np.abs(np.asarray(k.k_rel)))
        assert np.max(np.abs(np.asarray(k.lam_min))) < 1e-9 * np.min(np.asarray(k.lam_max))
        for name in ("u_e", "u_s", "r_eff"):
            v = np.abs(np.asarray(getattr(f, name)))
            assert np.min(v) > 0.05 * np.max(v), name        # far from zero ...
            assert np.ptp(np.asarray(getattr(f, name))) > 1e-3 * np.max(v), name   # ... and varying
    uv_all = np.concatenate(uv_all)
    assert np.ptp(uv_all[:, 0]) > 1.0 and np.ptp(uv_all[:, 1]) > 0.05   # mm, rad: spread over the flank
    # planted sign slips are caught: the cone model at the mirrored phase (u, -theta),
    # and the pair's sliding velocity reversed
    k, uv, f = _pair_and_seed_fields(sp, prep, outs[1])
    bad = jax.vmap(lambda q: hk.point_fields(sp.setup, q))(jnp.asarray(uv) * jnp.array([1.0, -1.0]))
    assert min(_rel(getattr(k, n), getattr(bad, n)) for n in ("u_e", "u_s", "r_eff")) > 1e-3
    assert _rel(-np.asarray(k.u_s), f.u_s) > 1.0


# ---------------------------------------------------------------------------------------
# d/d r0 of the machine-cut pair: settings, TCA contact and its kinematics

R0 = 95.25
SETTING_NAMES = ("radial_distance", "cradle_angle", "tilt", "swivel", "sliding_base",
                 "center_to_back")
CONTACT_NAMES = ("phi2", "axial2", "radial2", "u_e", "u_s", "srr", "r_eff")
GRAD_NAMES = (SETTING_NAMES + ("point_radius", "pinion_crossing", "phi2m")
              + CONTACT_NAMES + ("te",))


@functools.partial(jax.jit, static_argnums=1)
def _contact_scalars(pair, tca, x_ref, phi1_ref):
    """Line-contact TCA on a 5-point grid round ``phi1_ref`` (pinion blade position
    ``x_ref[1]`` fixed) and the pair's kinematics at the middle point (``tca`` the
    pair's :func:`gearjax.tca_function`, started from ``(x_ref, phi1_ref)``).

    Surface contact only (``face_ends=False``): the middle point is a contact inside
    both flanks (its margin is returned and asserted positive), where the face-end /
    tip-edge solves of the full TCA are not taken and change neither the value nor the
    derivative; leaving them out of this jvp program saves ~9 s CPU of compilation."""
    out = tca(pair, Misalignment.zero(), reference=(x_ref, phi1_ref))
    k = path_kinematics(pair, out.path, line_contact=True)
    m = 2
    vals = [out.path.phi2[m], out.path.axial2[m], out.path.radial2[m], k.u_e[m], k.u_s[m],
            k.srr[m], k.r_eff[m], out.path.te[m]]
    return jnp.stack(vals), out.path.converged & (out.margin[m] > 0.0)


def machine_pair_scalars(r0, tca, x_ref, phi1_ref, hand):
    """Scalars of the machine-cut pair of the study with cutter radius ``r0`` (mm): the
    pinion's machine settings (mm, rad), its point radius and crossing point (mm), the
    mean-contact gear angle (rad), and at a fixed pinion angle and blade position the
    TCA contact (gear angle rad, axial/radial position mm), ``u_e, u_s`` (mm/rad),
    SRR, ``R_eff`` (mm) and the TE (rad)."""
    inp = hk.study_blank_input(R0)
    st = dataclasses.replace(hk.StudySettings.make(R0), cutter_radius=r0)
    sp = study_pair(inp, st, "convex")
    assert sp.pair.hand == hand
    pin = sp.pair.pinion
    head = [getattr(pin.machine, n) for n in SETTING_NAMES]
    head += [pin.cutter.point_radius, sp.pair.pinion_crossing, sp.info["phi2m"]]
    contact, conv = _contact_scalars(sp.pair, tca, x_ref, phi1_ref)
    return jnp.concatenate([jnp.stack(head), contact]), conv


def gradient_table(prep, h=0.1):
    """(autodiff d/dr0, Richardson-extrapolated central difference with steps h and
    h/2: ``(4 D(h/2) - D(h)) / 3``, error O(h^4)) for :data:`GRAD_NAMES`."""
    x_ref, phi1_ref = jnp.asarray(prep.x_ref), jnp.asarray(prep.phi1_ref)
    tca = gj.tca_function(prep, steps_per_pitch=4, half_pitches=0.5, line_contact=True,
                          n_pairs=3, face_ends=False, kinematics=False)
    f = lambda r: machine_pair_scalars(r, tca, x_ref, phi1_ref, prep.pair.hand)
    (v0, conv), (dv, _) = jax.jvp(f, (jnp.asarray(R0),), (jnp.asarray(1.0),))
    assert np.asarray(conv).all()

    def value(r):
        # the values at R0 +- step by the same (jvp) programs, whose primal half is the
        # plain evaluation: the TCA is compiled once instead of once more without the
        # tangent (the difference quotient still sees only values, never tangents)
        return jax.jvp(f, (jnp.asarray(r),), (jnp.asarray(0.0),))[0]

    d = {}
    for step in (h, 0.5 * h):
        plus, minus = value(R0 + step), value(R0 - step)
        assert np.asarray(plus[1]).all() and np.asarray(minus[1]).all()
        d[step] = (np.asarray(plus[0]) - np.asarray(minus[0])) / (2.0 * step)
    fd = (4.0 * d[0.5 * h] - d[h]) / 3.0
    return np.asarray(v0), np.asarray(dv), fd


def test_gradient_wrt_cutter_radius_matches_central_differences(conj):
    """End to end: jax.jvp from the study's cutter radius through the blank design, the
    formate placement, the generated pinion's settings, a line-contact TCA and the
    contact kinematics, against central differences (1e-6 relative).  The pair stays
    conjugate for every r0: dTE/dr0 = 0."""
    _, prep, _ = conj
    v0, ad, fd = gradient_table(prep)
    te = GRAD_NAMES.index("te")
    assert abs(ad[te]) < 1e-12 and abs(v0[te]) < 1e-12
    for i, name in enumerate(GRAD_NAMES[:te]):
        assert abs(ad[i]) > 1e-6, name              # each one does depend on r0
        assert abs(ad[i] - fd[i]) < 1e-6 * abs(ad[i]), (name, ad[i], fd[i])
    # reverse mode too (the validated constructors on the way check primal values only)
    g = jax.grad(lambda r: study_pair(hk.study_blank_input(R0),
                                      dataclasses.replace(hk.StudySettings.make(R0), cutter_radius=r),
                                      "convex").pair.pinion.machine.radial_distance)(jnp.asarray(R0))
    # the two modes evaluate the study's tangent-cone blank solve in different programs,
    # which stop at different points of its rounding floor (see test_hypoid_blank.FLOOR;
    # measured 2.8e-12 relative here)
    assert abs(float(g) - ad[0]) < 5e-11 * abs(ad[0])


def test_study_pair_search_is_refused_under_jit():
    """The mean-contact root and the hand are chosen on concrete values: under jax.jit
    (no primal values) study_pair says so instead of failing somewhere inside."""
    inp = hk.study_blank_input(R0)
    with pytest.raises(ValueError, match="outside jax.jit"):
        jax.jit(lambda r: study_pair(inp, dataclasses.replace(hk.StudySettings.make(R0), cutter_radius=r),
                                     "convex").pair.pinion.machine.radial_distance)(R0)


def test_common_contact_kinematics_equal_the_pair_route_on_a_hypoid(conj):
    """The family-independent kinematics of the common TCA result
    (:func:`gearjax.tca.result.contact_kinematics`, pinion = member 1, rolling
    direction across the contact line) on this conjugate *hypoid* pair (offset 35 mm:
    the gear axis does not pass through the pinion's origin, so the ``r - c`` lever and
    the actual gear speed both matter) against the pair route of
    :mod:`gearjax.gears.hypoid.contact_kinematics` (gear = member 1, the model's
    direction normal to the contact line -- the same line for a conjugate pair):
    the members swap, the direction may flip, SRR changes sign; 1e-9 relative."""
    import gearjax as gj
    sp, prep, out = conj
    res = gj.run_tca(prep, line_contact=True, steps_per_pitch=8, half_pitches=1.0, n_pairs=3,
                     throw=False)
    on = np.asarray(res.on_flank)
    assert on.sum() >= 9
    np.testing.assert_allclose(np.asarray(res.path.phi2), np.asarray(out.path.phi2), rtol=0,
                               atol=1e-13)
    k = path_kinematics(prep.pair, res.path, line_contact=True)
    g = res.kinematics
    s = np.sign(np.asarray(k.u_e))[on]
    np.testing.assert_allclose(np.asarray(g.u_e)[on], s * np.asarray(k.u_e)[on], rtol=1e-9)
    np.testing.assert_allclose(np.asarray(g.u1)[on], s * np.asarray(k.u2)[on], rtol=1e-9)
    np.testing.assert_allclose(np.asarray(g.u2)[on], s * np.asarray(k.u1)[on], rtol=1e-9)
    np.testing.assert_allclose(np.asarray(g.srr)[on], -np.asarray(k.srr)[on], rtol=1e-9)
    np.testing.assert_allclose(np.asarray(g.r_x)[on], np.abs(np.asarray(k.r_eff))[on], rtol=1e-9)
    np.testing.assert_allclose(np.asarray(g.gear_ratio)[on], np.asarray(k.gear_ratio)[on],
                               rtol=1e-12)
    assert np.all(np.isinf(np.asarray(g.r_y)[on]))      # line contact
    assert np.ptp(np.asarray(g.srr)[on]) > 0.03           # the fields vary along the path
