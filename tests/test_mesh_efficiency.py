"""Mesh efficiency of a spur pair (gearjax.loading.mesh_efficiency) against independent routes.

* load sharing of the textbook: equal pairs share the load 50/50 in double contact
  and carry it alone in single contact; the double-contact part of the cycle is
  eps_alpha - 1 (ISO 6336 stiffness: constant along the path);
* torque balance sum l1 F = T1 to 1e-9 at every position;
* sliding speed against the closed form |u_s| = omega1 (1 + z1/z2) |s| of a point at
  roll distance s from the pitch point;
* the power loss against Ohlendorf's loss factor route P_V = mu_m H_V P_in with
  gearjax's own mean mu;
* the mean mesh stiffness of the Weber/Sainsot compliance against ISO 6336's
  c_gamma = c' (0.75 eps_alpha + 0.25);
* d eta_bar / d(torque, sigma, eta0) against central differences.
"""

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.gears.involute.geometry import pair_geometry
from gearjax.gears.involute.mesh import ohlendorf_loss_factor
from gearjax.loading.loaded_contact import BALANCE_TOL
from gearjax.loading.efficiency_checks import efficiency_warnings
from gearjax.loading.mesh_efficiency import mesh_efficiency, mesh_efficiency_traced
from gearjax.loading.pair_stiffness import iso6336_mesh_stiffness, iso6336_single_stiffness

Z1, Z2, M, B = 20, 40, 4.0, 30.0
TORQUE, RPM = 200.0, 1500.0


@pytest.fixture(scope="module")
def spur():
    pair = gj.involute.InvolutePair.create(Z1, Z2, M, 20.0)
    return pair, gj.involute.InvoluteTCA.create(pair, B)


@pytest.fixture(scope="module")
def oil_surface():
    return gj.tribology.get_oil(gj.tribology.OILS[0]), gj.tribology.make_surface(0.4)


@pytest.fixture(scope="module")
def iso_run(spur, oil_surface):
    return mesh_efficiency(spur[1], TORQUE, RPM, *oil_surface, compliance="iso6336")


@pytest.fixture(scope="module")
def weber_run(spur, oil_surface):
    return mesh_efficiency(spur[1], TORQUE, RPM, *oil_surface, compliance="weber")


def test_one_loaded_program_for_every_tooth_pair(spur, oil_surface, weber_run):
    """The loaded chain's jitted program takes the tooth numbers traced: a second pair
    (another tooth count, shift, module) with the same options reuses the program the
    20/40 run compiled, and its result is that pair's (eta_bar differs, all positions of
    a conjugate pair valid).  Planted bug caught: tooth numbers static again (one
    program per pair: the suite and every sweep pay a compilation per design)."""
    from gearjax.loading.mesh_efficiency import _post_jit
    n0 = _post_jit._cache_size()
    other = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(12, 24, 3.0, 20.0, 0.0, 0.6, 0.36), 20.0)
    eff, _ = mesh_efficiency(other, TORQUE, RPM, *oil_surface, compliance="weber")
    assert _post_jit._cache_size() == n0
    assert int(eff.n_valid) == eff.valid.shape[0]
    assert float(eff.mean_efficiency) != pytest.approx(float(weber_run[0].mean_efficiency),
                                                      rel=1e-6)
    # the same pair through its own fresh program (the static route) gives the same result
    # the same pair through a program of its own with the tooth numbers as Python ints
    # (the static route the traced one replaced)
    ad = gj.tca.family_of(other)
    opts = dict(ad.defaults)
    teeth_of, pair, run_des = ad.mesh(other, **opts)
    res = ad.run(run_des, None, **opts, kinematics=True)
    ref = jax.jit(lambda r: mesh_efficiency_traced(
        r, teeth_of(pair, r), TORQUE, RPM, *oil_surface, steps_per_pitch=opts["steps_per_pitch"],
        n_pairs=opts["n_pairs"], compliance="weber"))(res)
    np.testing.assert_allclose(np.asarray(eff.power_loss), np.asarray(ref.power_loss),
                               rtol=1e-9)


def test_the_loads_program_compiles_beside_the_tca(spur, oil_surface, weber_run, monkeypatch):
    """``mesh_efficiency`` offers its loads' program to the compilation of the TCA's two
    programs (gearjax/compile_ahead.py), after them, on the abstract TCA result: the
    first call compiles all three side by side.  Planted bug caught: ``also`` dropped (the
    loads' program compiled alone after the TCA's, ~2 s more on a first call); the oil's
    name a key of the program (each named oil compiling its own)."""
    import gearjax.compile_ahead as ca
    from gearjax.loading.mesh_efficiency import _post_jit
    submitted = []
    orig = ca.CompileAhead.submit

    def spy(self, fun, *args, **static):
        submitted.append(getattr(fun, "__name__", repr(fun)))
        return orig(self, fun, *args, **static)
    monkeypatch.setattr(ca.CompileAhead, "submit", spy)
    eff, _ = mesh_efficiency(spur[1], TORQUE, RPM, *oil_surface, compliance="weber")
    assert submitted == ["_surface_program", "_finish_program", "_post_jit"], submitted
    assert float(eff.mean_efficiency) == float(weber_run[0].mean_efficiency)
    n0 = _post_jit._cache_size()
    renamed = dataclasses.replace(oil_surface[0], name="the same oil, renamed")
    eff2, _ = mesh_efficiency(spur[1], TORQUE, RPM, renamed, oil_surface[1], compliance="weber")
    assert _post_jit._cache_size() == n0
    assert float(eff2.mean_efficiency) == float(eff.mean_efficiency)


def test_textbook_load_sharing_and_balance(spur, iso_run):
    eff, res = iso_run
    geo = pair_geometry(spur[0])
    share = np.asarray(eff.loaded.share)
    n = np.asarray(eff.loaded.n_loaded)
    assert np.all(np.asarray(eff.valid)) and efficiency_warnings(eff, res) == []
    # every position valid: the summaries are over the whole cycle
    assert int(eff.n_valid) == n.size
    te = np.asarray(eff.loaded.te_loaded)
    assert float(eff.te_loaded_ptp) == pytest.approx(te.max() - te.min(), rel=1e-12)
    assert set(n.tolist()) == {1, 2}
    np.testing.assert_allclose(share.sum(axis=0), 1.0, atol=1e-12)
    np.testing.assert_allclose(share[:, n == 2][share[:, n == 2] > 0], 0.5, rtol=1e-10)
    np.testing.assert_allclose(share.max(axis=0)[n == 1], 1.0, rtol=1e-12)
    assert np.all(np.asarray(eff.loaded.balance) <= BALANCE_TOL)
    # the double-contact part of the cycle is eps_alpha - 1 (one grid step of slack)
    M_pos = n.size
    frac = np.mean(n == 2)
    assert abs(frac - (float(geo["contact_ratio"]) - 1.0)) <= 1.0 / M_pos + 1e-12
    # the total normal load in single contact is T1 / r_b1
    F = np.asarray(eff.loaded.load)
    np.testing.assert_allclose(F.sum(axis=0)[n == 1], 1e3 * TORQUE / float(geo["rb1"]),
                               rtol=1e-9)


def test_sliding_speed_closed_form(spur, iso_run):
    eff, res = iso_run
    geo = pair_geometry(spur[0])
    from gearjax.loading.loaded_contact import pair_arrays
    from gearjax.loading.mesh_efficiency import cycle_window
    n = res.path.phi1.shape[0]
    spp = eff.phi1.shape[0]
    win = cycle_window(n, spp)
    r1 = np.asarray(pair_arrays(res.path.radial1, spp, 3, np.nan, win))
    s = np.sqrt(r1 ** 2 - float(geo["rb1"]) ** 2) - float(geo["rho_P"])
    omega = RPM * np.pi / 30.0
    loaded = np.asarray(eff.loaded.load) > 0
    expect = omega * (1.0 + Z1 / Z2) * np.abs(s)
    np.testing.assert_allclose(np.asarray(eff.u_s)[loaded], expect[loaded], rtol=1e-6,
                               atol=1e-6 * omega * float(geo["rb1"]))


def test_power_loss_against_ohlendorf(spur, iso_run):
    eff, _ = iso_run
    H_V = float(ohlendorf_loss_factor(spur[0]))
    P_ohl = float(eff.mean_mu) * H_V * float(eff.power_in)
    P_gj = float(np.mean(np.asarray(eff.power_loss)))
    # the grid averages a piecewise-linear function with jumps at the transfer
    # points (24 positions per pitch): agreement within 2 %
    assert abs(P_gj / P_ohl - 1.0) < 0.02, (P_gj, P_ohl)
    assert 0.0 < float(eff.mean_efficiency) < 1.0


def test_weber_mean_mesh_stiffness_against_iso6336(spur, weber_run):
    """Mean mesh stiffness c_gamma = F_total / (b w) over the cycle, w the approach of the
    leading pair, against c' (0.75 eps + 0.25) of ISO 6336-1: the Weber/Sainsot
    model is within -20 % .. +10 % of the standard's c' (docs/compliance.md)."""
    eff, res = weber_run
    geo = pair_geometry(spur[0])
    assert np.all(np.asarray(eff.valid))
    F_tot = 1e3 * TORQUE / float(geo["rb1"])
    w_lead = np.nanmax(np.asarray(eff.loaded.approach), axis=0)     # mm
    c_gamma = np.mean(F_tot / (B * w_lead)) * 1e-3                  # N/(mm um)
    c1 = float(iso6336_single_stiffness(Z1, Z2).c_prime)
    c_iso = float(iso6336_mesh_stiffness(c1, float(geo["contact_ratio"])))
    assert -0.22 < c_gamma / c_iso - 1.0 < 0.12, (c_gamma, c_iso)
    # the stiffer the mesh, the smaller the loaded TE: double contact deflects less
    y = np.asarray(eff.loaded.deflection)
    n = np.asarray(eff.loaded.n_loaded)
    assert y[n == 2].max() < y[n == 1].min()


def test_weber_single_contact_approach_is_the_path_model(spur, weber_run):
    """Weber/Sainsot through the whole loaded chain: in single contact the one loaded
    pair carries F = T1 / r_b1 and its approach is q F, q the stand-alone path model
    of gearjax.loading.tooth_compliance (per unit width, mm^2/N) over the face width at the
    roll distance of the contact (hand, from the contact radius) and the load per
    unit face width F / b.  Planted bugs caught: the nominal line load not taken per
    unit width (it enters the contact term's logarithm), the face width missing
    from q."""
    from gearjax.loading.pair_stiffness import pair_compliance as path_compliance
    eff, res = weber_run
    geo = pair_geometry(spur[0])
    rb1, rho_P = float(geo["rb1"]), float(geo["rho_P"])
    from gearjax.loading.loaded_contact import pair_arrays
    from gearjax.loading.mesh_efficiency import cycle_window
    spp = eff.phi1.shape[0]
    win = cycle_window(res.path.phi1.shape[0], spp)
    r1 = np.asarray(pair_arrays(res.path.radial1, spp, 3, np.nan, win))
    F = np.asarray(eff.loaded.load)
    single = np.asarray(eff.loaded.n_loaded) == 1
    assert single.sum() >= 4
    k = np.argmax(F, axis=0)[single]
    j = np.nonzero(single)[0]
    F_tot = 1e3 * TORQUE / rb1
    np.testing.assert_allclose(F[k, j], F_tot, rtol=1e-9)
    s = np.sqrt(r1[k, j] ** 2 - rb1 ** 2) - rho_P
    q = path_compliance(jnp.asarray(s), Z1, Z2, M, np.radians(20.0),
                        load_per_width=F_tot / B).total / B                 # mm/N
    w = np.asarray(eff.loaded.approach)[k, j]
    np.testing.assert_allclose(w, np.asarray(q) * F_tot, rtol=1e-8)


def test_line_contact_equivalent_ellipse_spans_the_face(spur, iso_run):
    """The line contact goes to the elliptic friction model as the ellipse whose major
    semi-axis is half the contact line (module docstring): with R_y of the run, the
    Hamrock-Dowson ellipse a = (6 k^2 E F R / (pi E'))^(1/3), k = 1.0339 (R_y/R_x)^0.636,
    E = 1.0003 + 0.5968 R_x/R_y, R = R_x R_y / (R_x + R_y) (hand), spans b/2 to the
    approximation's own accuracy.  Planted bug caught: the semi-axis set to the whole
    line length."""
    from gearjax.tribology import STEEL_E_PRIME
    eff, _ = iso_run
    F = np.asarray(eff.loaded.load)
    on = F > 0.0
    Rx, Ry = np.asarray(eff.r_x)[on], np.asarray(eff.r_y)[on]
    assert np.all(Ry > 20.0 * Rx)
    k = 1.0339 * (Ry / Rx) ** 0.636
    ell = 1.0003 + 0.5968 * Rx / Ry
    R = Rx * Ry / (Rx + Ry)
    a = (6.0 * k ** 2 * ell * F[on] * R / (np.pi * STEEL_E_PRIME)) ** (1.0 / 3.0)
    np.testing.assert_allclose(a, 0.5 * B, rtol=5e-3)


def test_line_contact_slices_reproduce_the_spur_chain(spur, weber_run, oil_surface):
    """The thin-slice line-contact model (gearjax.gears.involute.line_load), run at the mesh
    positions of the TCA chain's cycle, reproduces the chain's spur result: the same
    pair loads and the same loaded fall-back (approach = y r_b2) at every position, for
    any number of slices (the aligned unmodified spur face is uniform).  Two routes to
    the same physics: the chain from the TCA's contacts, lever arms and curvatures, the
    slices from closed-form involute geometry.  The same for the sliding power loss at
    every position (gearjax.gears.involute.line_efficiency: closed-form speeds, each
    slice given its whole line's equivalent ellipse).  Planted bugs caught (either
    model): the nominal line load of the contact term, the lever arms, the virtual-gear
    radii, the entrainment speed halved or doubled, a slice's own length taken for the
    line's."""
    from gearjax.gears.involute.line_efficiency import line_efficiency_traced
    from gearjax.gears.involute.line_load import LineLoadOptions, line_load_traced, pair_range
    from gearjax.gears.involute.microgeometry import PairModification
    from gearjax.loading.loaded_contact import pair_arrays
    from gearjax.loading.mesh_efficiency import cycle_window
    eff, res = weber_run
    pair = spur[0]
    geo = pair_geometry(pair)
    rb1, rb2, rho_P = float(geo["rb1"]), float(geo["rb2"]), float(geo["rho_P"])
    spp = eff.phi1.shape[0]
    win = cycle_window(res.path.phi1.shape[0], spp)
    r1 = np.asarray(pair_arrays(res.path.radial1, spp, 3, np.nan, win))
    F_chain = np.asarray(eff.loaded.load)
    k = np.argmax(F_chain, axis=0)                   # a loaded pair at each position
    s0 = np.sqrt(r1[k, np.arange(spp)] ** 2 - rb1 ** 2) - rho_P
    k_lo, k_hi = pair_range(pair, B)
    for slices in (1, 7):
        r = jax.jit(line_load_traced, static_argnames="opts")(
            pair, B, PairModification.none(), 1e3 * TORQUE, 0.0,
            LineLoadOptions(spp, slices, k_lo, k_hi, "weber"), s0=jnp.asarray(s0))
        assert bool(np.all(np.asarray(r.converged)))
        F_sl = np.sort(np.asarray(r.pair_load), axis=0)[::-1][:2]
        np.testing.assert_allclose(F_sl, np.sort(F_chain, axis=0)[::-1][:2], rtol=1e-7,
                                   atol=1e-7 * F_chain.max())
        np.testing.assert_allclose(np.asarray(r.te_loaded_um),
                                   1e3 * rb2 * np.asarray(eff.loaded.deflection), rtol=1e-7)
    le = jax.jit(line_efficiency_traced, static_argnames="opts")(
        pair, B, PairModification.none(), 1e3 * TORQUE, 0.0, RPM, *oil_surface,
        LineLoadOptions(spp, 3, k_lo, k_hi, "weber"), s0=jnp.asarray(s0))
    assert bool(np.all(np.asarray(le.valid)))
    P = np.asarray(eff.power_loss)          # (at the pitch point u_s is zero to rounding)
    np.testing.assert_allclose(np.asarray(le.power_loss), P, rtol=1e-6, atol=1e-12 * P.max())


def test_loaded_edge_contact_is_flagged_and_not_valid(spur, oil_surface, weber_run):
    """A crossed uncrowned spur pair (dSigma = 0.05 deg) touches at the leading face end
    (the closed form of tests/test_edge_contact.py): that edge contact is the one the
    loaded gear presses, and its load is not modelled -- every position where it is the
    contact made is flagged ``edge_loaded`` and is not valid, and the warnings say so;
    the aligned pair has none.  Same compiled programs as ``weber_run`` (the
    misalignment is traced).  (No surface contact carries load there: the positions count
    as pressed whatever the sign of the 'pressed by the loaded gear' comparison, which
    test_tip_contact_ahead_of_the_loaded_gear_is_flagged decides.)"""
    eff0, _ = weber_run
    assert not np.any(np.asarray(eff0.edge_loaded))
    mis = gj.Misalignment.create(dSigma_deg=0.05)
    eff, res = mesh_efficiency(spur[1], TORQUE, RPM, *oil_surface, compliance="weber",
                               misalignment=mis, throw=False)
    from gearjax.loading.loaded_contact import pair_arrays
    from gearjax.loading.mesh_efficiency import cycle_window
    spp = eff.phi1.shape[0]
    win = cycle_window(res.path.phi1.shape[0], spp)
    edge_pairs = np.asarray(pair_arrays(res.edge_points, spp, 3, False, win))
    made = edge_pairs.any(axis=0)
    assert made.sum() >= spp // 2, "the crossed uncrowned pair must be in edge contact"
    flagged = np.asarray(eff.edge_loaded)
    np.testing.assert_array_equal(flagged, made)
    assert not np.any(np.asarray(eff.valid) & flagged)
    assert any("edge" in w for w in efficiency_warnings(eff, res))


@pytest.mark.parametrize("dalpha", [1.0, -1.0], ids=["premature", "prolonged"])
def test_tip_contact_ahead_of_the_loaded_gear_is_flagged(spur, oil_surface, weber_run, dalpha):
    """A base-pitch mismatch (the pinion cut with the pressure angle 1 deg larger /
    smaller): the rigid teeth touch at a tooth tip off the line of action, where the
    incoming pair's gear tip (premature contact) or the outgoing pair's pinion tip
    (prolonged contact) leads the mesh (closed forms in tests/test_edge_contact.py),
    while the other pair's surface contact -- the only contact whose load is modelled
    -- is behind it.  Second route: the TCA's rigid TE envelope (with the tip contacts)
    against the envelope of the surface contacts alone.  Where a tip contact leads
    every surface contact it is ahead of the loaded gear whatever the deflection (the
    loaded TE falls back from the surface envelope), so the gear presses on it: the
    position is flagged ``edge_loaded`` and is not valid, although a surface contact
    carries load there; at every other position no edge is touched and the position
    is valid.  Same compiled programs as ``weber_run`` (the mismatch is a traced field
    of the design).  Planted bug caught: the sign of the 'pressed by the loaded gear'
    test (an edge contact behind the loaded gear flagged, the one it presses not)."""
    from gearjax.loading.loaded_contact import pair_arrays
    from gearjax.loading.mesh_efficiency import cycle_window
    des = gj.involute.InvoluteTCA.create(spur[0], B, dalpha_deg=dalpha)
    eff, res = mesh_efficiency(des, TORQUE, RPM, *oil_surface, compliance="weber", throw=False)
    spp = eff.phi1.shape[0]
    win = cycle_window(res.path.phi1.shape[0], spp)
    te_surface = np.asarray(pair_arrays(jnp.where(res.on_flank, res.path.te, -jnp.inf), spp, 3,
                                        -np.inf, win)).max(axis=0)
    rigid = np.asarray(res.multi.envelope)[win]
    tip_leads = rigid > te_surface + 1e-8                     # rad
    assert 3 <= tip_leads.sum() <= spp // 2
    edge = np.asarray(pair_arrays(res.edge_points, spp, 3, False, win)).any(axis=0)
    np.testing.assert_array_equal(edge, tip_leads)            # the tip contact made
    n_loaded = np.asarray(eff.loaded.n_loaded)
    assert np.all(n_loaded[tip_leads] >= 1)                   # a surface contact carries load
    np.testing.assert_array_equal(np.asarray(eff.edge_loaded), tip_leads)
    np.testing.assert_array_equal(np.asarray(eff.valid), ~tip_leads)
    assert any("edge contact under load" in w for w in efficiency_warnings(eff, res))


def test_line_contact_material_scaling(spur, oil_surface, iso_run, weber_run):
    """E' doubled (``E_prime=``; an involute pair has no material table, the default is
    steel): at single-contact positions the load is statics only, the line-contact Hertz
    pressure p_max = sqrt(w E' / (2 pi R)) grows by sqrt(2) exactly, and the ISO 6336
    stiffness scales with E (c' E/E_st), so the fall-back halves exactly; with the
    Weber/Sainsot teeth it nearly halves (the contact term's logarithm of the Hertz
    half-width changes with E)."""
    from gearjax.tribology import STEEL_E_PRIME
    for base, comp in ((iso_run, "iso6336"), (weber_run, "weber")):
        e1 = base[0]
        e2, _ = mesh_efficiency(spur[1], TORQUE, RPM, *oil_surface, compliance=comp,
                                E_prime=2.0 * STEEL_E_PRIME)
        n1, n2 = np.asarray(e1.loaded.n_loaded), np.asarray(e2.loaded.n_loaded)
        single = (n1 == 1) & (n2 == 1)
        assert single.sum() >= 4
        F1, F2 = (np.asarray(e.loaded.load).sum(axis=0)[single] for e in (e1, e2))
        np.testing.assert_allclose(F2, F1, rtol=1e-10)
        p1, p2 = (np.asarray(e.loaded.p_max).max(axis=0)[single] for e in (e1, e2))
        np.testing.assert_allclose(p2 / p1, np.sqrt(2.0), rtol=1e-10)
        y1, y2 = (np.asarray(e.loaded.deflection)[single] for e in (e1, e2))
        if comp == "iso6336":
            np.testing.assert_allclose(y2 / y1, 0.5, rtol=1e-9)
        else:
            assert np.all(np.abs(y2 / y1 - 0.5) < 0.03), y2 / y1
        assert float(e2.te_loaded_ptp) != float(e1.te_loaded_ptp)


@pytest.fixture(scope="module")
def traced_spur(spur, oil_surface, iso_run):
    """The loaded chain of the spur run as one jitted function of
    ``v = (torque, sigma, eta0, a, b, c, d)``: perturbations of the TCA result -- a TE
    slope ``a (phi1 - phi1_ref)`` (rad/rad, a base-pitch-mismatch-like separation of the
    pairs in double contact), a scale ``1 + b`` on the radii r_x, a side sliding
    ``u_s_side = c u_s`` (along the ellipse's major axis) and an entrainment angle
    ``d`` (rad from the rolling direction) -- returning the whole MeshEfficiency; and
    the unperturbed point."""
    oil, surf = oil_surface
    oil = dataclasses.replace(oil, name="")
    _, res = iso_run
    des = spur[1]
    teeth_of = gj.tca.family_of(des).mesh(des)[0]

    def full(v):
        T, sigma, eta0, a, b, c, d = v
        mid = res.path.phi1.shape[0] // 2
        path = res.path._replace(te=res.path.te + a * (res.path.phi1 - res.path.phi1[mid]))
        kin = res.kinematics._replace(r_x=res.kinematics.r_x * (1.0 + b),
                                      u_s_side=c * res.kinematics.u_s,
                                      entrainment_angle=res.kinematics.entrainment_angle + d)
        r = dataclasses.replace(res, path=path, kinematics=kin)
        return mesh_efficiency_traced(r, teeth_of(des, r), T, RPM,
                                      dataclasses.replace(oil, eta0=eta0),
                                      dataclasses.replace(surf, sigma=sigma),
                                      steps_per_pitch=24, n_pairs=3, compliance="weber")

    x0 = jnp.array([TORQUE, float(surf.sigma), float(oil.eta0), 0.0, 0.0, 0.0, 0.0])
    return full, x0


def test_gradients_against_central_differences(spur, oil_surface, traced_spur):
    """d eta_bar through the loads, kinematics and friction: with respect to torque,
    roughness, viscosity and the four perturbations of the TCA result of
    ``traced_spur``, against central differences.  (The TCA's own gradients
    w.r.t. design fields are tested in tests/test_tca*.py; the whole chain of the
    hypoid example against central differences is experiments/efficiency_gradients.py.)"""
    oil, surf = oil_surface
    full, x0 = traced_spur
    des = spur[1]

    def eta(v):
        return full(v).mean_efficiency

    jfull = jax.jit(full)
    # the traced route takes the speed in rpm, as mesh_efficiency (one convention)
    eff_w = mesh_efficiency(des, TORQUE, RPM, oil, surf, compliance="weber")[0]
    assert float(jfull(x0).mean_efficiency) == pytest.approx(float(eff_w.mean_efficiency),
                                                              rel=1e-12)
    g = jax.jit(jax.grad(eta))(x0)
    assert np.all(np.isfinite(g))
    for i in range(x0.shape[0]):
        h = 1e-4 * float(x0[i]) if x0[i] != 0 else 1e-6
        fd = (jfull(x0.at[i].add(h)).mean_efficiency
              - jfull(x0.at[i].add(-h)).mean_efficiency) / (2 * h)
        np.testing.assert_allclose(g[i], fd, rtol=1e-5, atol=1e-12)
    # the separations matter: a TE slope unbalances the double-contact sharing
    assert abs(float(g[3])) > 1e-6
    # sliding and entrainment magnitudes from their components (ContactKinematics):
    # the sliding vector has u_s along the rolling direction and u_s_side across it,
    # |u_s| = omega sqrt(u_s^2 + u_s_side^2); u_e is the component along the rolling
    # direction of an entrainment vector at angle theta_e, |u_e| = omega |u_e| / cos
    # theta_e.  (A spur pair has neither; the perturbation gives them.)  Planted bugs
    # caught: the side component dropped, cos for 1/cos.
    c, d = 0.3, 0.4
    e0, e1 = jfull(x0), jfull(x0.at[5].set(c).at[6].set(d))
    on = np.asarray(e0.loaded.load) > 0.0
    np.testing.assert_allclose(np.asarray(e1.u_s)[on],
                               np.sqrt(1.0 + c * c) * np.asarray(e0.u_s)[on], rtol=1e-9,
                               atol=1e-6)                     # mm/s (the pitch point: 0)
    np.testing.assert_allclose(np.asarray(e1.u_e)[on], np.asarray(e0.u_e)[on] / math.cos(d),
                               rtol=1e-9)


def test_cycle_summary_over_valid_positions_only():
    """The summaries on a small synthetic cycle against values by hand.  Planted bugs
    caught: a mean over all positions (the invalid ones, with no modelled loss, pull
    eta_bar towards 100 %: 0.95 instead of 0.90), invalid or unloaded contacts in mean
    mu / max p_max / loaded TE, and a silent number (instead of NaN) when nothing is
    valid."""
    from gearjax.loading.mesh_efficiency import cycle_summary
    P_in = 100.0
    P_f = jnp.array([10.0, 0.0, 10.0, 0.0])          # positions 1, 3 carry no modelled load
    load = jnp.array([[100.0, 0.0, 50.0, 0.0], [0.0, 0.0, 50.0, 0.0]])
    us = jnp.array([[2.0, 1.0, 1.0, 1.0], [1.0, 1.0, 4.0, 1.0]])
    mu = jnp.array([[0.05, 9.0, 0.02, 9.0], [9.0, 9.0, 0.07, 9.0]])
    p_max = jnp.array([[1000.0, 0.0, 900.0, 5e4], [0.0, 0.0, 1100.0, 0.0]])
    te = jnp.array([-1e-5, 3e-3, -4e-5, -3e-3])
    valid = jnp.array([True, False, True, False])
    s = cycle_summary(P_f, P_in, mu, load, us, p_max, te, valid)
    assert int(s.n_valid) == 2
    assert float(s.mean_efficiency) == pytest.approx(1.0 - 20.0 / (2 * 100.0), rel=1e-14)
    w = np.array([200.0, 50.0, 200.0])
    assert float(s.mean_mu) == pytest.approx(np.dot([0.05, 0.02, 0.07], w) / w.sum(), rel=1e-14)
    assert float(s.max_p_max) == 1100.0
    assert float(s.te_loaded_ptp) == pytest.approx(3e-5, rel=1e-12)
    none = cycle_summary(P_f, P_in, mu, load, us, p_max, te, valid & False)
    assert int(none.n_valid) == 0
    assert all(np.isnan(float(v)) for v in none[:4])
    g = jax.grad(lambda p: cycle_summary(p, P_in, mu, load, us, p_max, te, valid)
                 .mean_efficiency)(P_f)
    np.testing.assert_allclose(g, [-1 / 200.0, 0.0, -1 / 200.0, 0.0], rtol=1e-14)


def test_efficiency_guard_cannot_be_raised_by_invalidating_positions(iso_run):
    """On the 20/40 spur run: invalidating the lossiest valid position raises the plain
    eta_bar over the valid positions (the gaming the issue names) but lowers the guarded
    eta, by at least (P_in - P_f)/(|V0| P_in); n_lost counts it.  With every nominal
    position valid the guard is the plain eta_bar and its gradient that of the losses
    (-1/(|V0| P_in) per valid position, 0 elsewhere).  Values by hand (NumPy) from the
    run's arrays.  Planted bugs caught: a lost position dropped from the mean (guard
    rises), counted at P_f = 0 (guard rises to ~1), a mean over the current valid set
    instead of the fixed nominal one, n_lost counting positions outside V0."""
    from gearjax.loading.mesh_efficiency import cycle_summary
    from gearjax.loading.efficiency_checks import efficiency_guard
    eff, _ = iso_run
    v0 = np.asarray(eff.valid)
    P_f, P_in = np.asarray(eff.power_loss, float), float(eff.power_in)
    assert v0.sum() >= 10
    g0 = efficiency_guard(eff, v0)
    assert int(g0.n_lost) == 0
    np.testing.assert_allclose(float(g0.mean_efficiency), 1 - P_f[v0].sum() / (v0.sum() * P_in),
                               rtol=1e-14)
    np.testing.assert_allclose(float(g0.mean_efficiency), float(eff.mean_efficiency), rtol=1e-14)
    worst = int(np.argmax(np.where(v0, P_f, -np.inf)))
    gamed_valid = v0.copy()
    gamed_valid[worst] = False
    gamed = eff._replace(valid=jnp.asarray(gamed_valid))
    plain = float(cycle_summary(eff.power_loss, P_in, eff.friction.mu, eff.loaded.load,
                                eff.u_s, eff.loaded.p_max, eff.loaded.te_loaded, gamed_valid)
                  .mean_efficiency)
    g1 = efficiency_guard(gamed, v0)
    assert plain > float(eff.mean_efficiency)                 # the plain mean is gamed
    assert int(g1.n_lost) == 1
    drop = float(g0.mean_efficiency) - float(g1.mean_efficiency)
    np.testing.assert_allclose(drop, (P_in - P_f[worst]) / (v0.sum() * P_in), rtol=1e-12)
    # positions outside V0 never count: the gamed position, invalid now, was not in
    # the nominal set (every position of this run is valid, so the invalid one must be
    # made: with eff's own flags an "all invalid positions" count would be 0 too)
    extra = v0.copy()
    extra[worst] = False
    assert int(efficiency_guard(gamed, extra).n_lost) == 0
    assert int(efficiency_guard(eff, extra).n_lost) == 0
    grad = jax.grad(lambda p: efficiency_guard(eff._replace(power_loss=p), v0)
                    .mean_efficiency)(eff.power_loss)
    np.testing.assert_allclose(grad, np.where(v0, -1 / (v0.sum() * P_in), 0.0), rtol=1e-14)


def test_plausibility_thresholds_on_synthetic_positions():
    """Each check at its documented threshold on a synthetic cycle (one position
    failing one check each).  Planted bugs caught: a check dropped or with a flipped
    comparison, eta = 0 or eta > 1 accepted, an unloaded contact's value counted, a
    NaN passing, a deflection limit not scaled by the pitch, a contact with a
    vanishing share of the load checked (or one with a small real share not)."""
    from gearjax.loading.efficiency_checks import (DEFLECTION_MAX_PITCH, HERTZ_SIZE_MAX, MU_MAX,
                                                   P_MAX_LIMIT_MPA, plausibility)
    pitch = 2 * np.pi / 20
    eta = jnp.array([0.99, 1.0, 0.0, 1.0 + 1e-12, 0.98, 0.98, 0.98, np.nan])
    load = jnp.array([[1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0],
                      [0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]])
    mu = jnp.array([[0.05, MU_MAX, 0.05, 0.05, MU_MAX * 1.01, 0.05, 0.05, 0.05],
                    [9.0, 0.05, 9.0, 9.0, 9.0, 9.0, 9.0, 9.0]])      # unloaded: ignored
    pm = jnp.array([[1e3, P_MAX_LIMIT_MPA, 1e3, 1e3, 1e3, 5001.0, 1e3, 1e3],
                    [9e9, 1e3, 9e9, 9e9, 9e9, 9e9, 9e9, 9e9]])
    y = jnp.array([0.0, DEFLECTION_MAX_PITCH * pitch, 0.0, 0.0, 0.0, 0.0,
                   DEFLECTION_MAX_PITCH * pitch * 1.001, 0.0])
    r_x = jnp.full((2, 8), 10.0)
    hw = jnp.array([[0.1, 10.0 * HERTZ_SIZE_MAX, 0.1, 0.1, 0.1, 0.1, 0.1, 5.01],
                    [99.0, 0.1, 99.0, 99.0, 99.0, 99.0, 99.0, 99.0]])
    p = plausibility(eta, mu, load, pm, y, pitch, hw, r_x)
    np.testing.assert_array_equal(p.efficiency, [1, 1, 0, 0, 1, 1, 1, 0])
    np.testing.assert_array_equal(p.mu, [1, 1, 1, 1, 0, 1, 1, 1])
    np.testing.assert_array_equal(p.p_max, [1, 1, 1, 1, 1, 0, 1, 1])
    np.testing.assert_array_equal(p.deflection, [1, 1, 1, 1, 1, 1, 0, 1])
    np.testing.assert_array_equal(p.contact, [1, 1, 1, 1, 1, 1, 1, 0])
    np.testing.assert_array_equal(p.all, [1, 1, 0, 0, 0, 0, 0, 0])
    # a contact with a vanishing share of the position's load (a pair entering its
    # flank under the soft active set: 4.5e-31 N beside 8782 N, mu 1.2e5 on the ISO
    # 10/41 study) is not checked; one with 1e-6 of it is; a NaN load elsewhere at the
    # position does not exempt the others
    load = jnp.array([[8782.0, 8782.0, 8782.0, 8782.0, np.nan],
                      [4.5e-31, 8782.0 * 1e-6, 8782.0 * 0.5e-9, 8782.0 * 2e-9, 1.0]])
    mu = jnp.array([[0.05] * 5, [1.2e5, 0.31, 1.2e5, 0.31, 0.31]])
    p = plausibility(jnp.full(5, 0.98), mu, load, jnp.full((2, 5), 1e3), jnp.zeros(5), pitch,
                     jnp.full((2, 5), 0.1), jnp.full((2, 5), 10.0))
    np.testing.assert_array_equal(p.mu, [1, 0, 1, 0, 0])


def test_implausible_results_are_flagged_and_not_valid(spur, iso_run):
    """The iso run's result with planted implausible values, through
    ``efficiency_warnings`` (concrete, no new program): a warning line per failed
    check naming the threshold; a film below FILM_MIN_MM warns, not at a contact with a
    vanishing share of the load.  Planted bugs caught: a check that never fires on a
    real result's fields (wrong field, wrong axis), a warning line without the value,
    the warnings' notion of a loaded contact not that of ``plausibility``."""
    from gearjax.loading.mesh_efficiency import FILM_MIN_MM
    from gearjax.loading.efficiency_checks import MU_MAX, P_MAX_LIMIT_MPA
    eff, res = iso_run
    assert all("implausible" not in w for w in efficiency_warnings(eff, res))
    fr = eff.friction._replace(mu=eff.friction.mu * 100.0, h_c=eff.friction.h_c * 0 + 1e-6)
    ld = eff.loaded._replace(p_max=eff.loaded.p_max * 100.0,
                             deflection=eff.loaded.deflection + 1.0,
                             semi_minor=eff.loaded.semi_minor * 1e3)
    bad = eff._replace(friction=fr, loaded=ld, efficiency=eff.efficiency - 2.0)
    w = "\n".join(efficiency_warnings(bad, res))
    assert f"mu above {MU_MAX:g}" in w and f"p_max above {P_MAX_LIMIT_MPA:g} MPa" in w
    assert "eta_m outside (0, 1]" in w and "fall-back" in w and "of a pinion pitch" in w
    assert f"{1e6 * FILM_MIN_MM:g} nm" in w and "1 nm" in w
    assert "Hertz half-width above" in w and "viscosity law extrapolated above 3 GPa" in w
    # the spur run's own contacts are far inside Hertz theory (half-width / R_x)
    hw = np.asarray(eff.loaded.semi_minor) / np.asarray(eff.r_x)
    assert np.max(hw[np.asarray(eff.loaded.load) > 0]) < 0.1
    # a contact with a vanishing share of its position's load (a pair entering its
    # flank under the soft active set) is not a loaded contact for the warnings either:
    # an absurd mu and a 1 nm film there raise nothing
    F = np.asarray(eff.loaded.load)
    k, m = np.argwhere(F == 0.0)[0]
    F2 = F.copy()
    F2[k, m] = 4.5e-31
    mu2 = np.asarray(eff.friction.mu).copy()
    mu2[k, m] = 1.2e5
    h2 = np.asarray(eff.friction.h_c).copy()
    h2[k, m] = 1e-6
    tiny = eff._replace(loaded=eff.loaded._replace(load=jnp.asarray(F2)),
                        friction=eff.friction._replace(mu=jnp.asarray(mu2), h_c=jnp.asarray(h2)))
    assert efficiency_warnings(tiny, res) == efficiency_warnings(eff, res)


def test_cycle_is_one_pitch_starting_half_a_pitch_before_the_reference(spur, iso_run):
    """The mesh cycle is one angular pitch 2 pi/z1 of the pinion centred on the TCA
    reference angle (the middle of the odd TCA grid, phi1_ref): the half-open interval
    [phi1_ref - pi/z1, phi1_ref + pi/z1) sampled with the grid step 2 pi/(z1 spp).
    Indices by hand: the grid has 2 k + 1 angles (middle index k = N // 2); the cycle
    takes grid indices k - spp/2 .. k + spp/2 - 1, the reference at cycle index spp/2.
    Planted bug caught: the window shifted one grid step off the reference."""
    eff, res = iso_run
    phi = np.asarray(res.path.phi1)
    cyc = np.asarray(eff.phi1)
    n, spp = phi.shape[0], cyc.shape[0]
    assert n % 2 == 1 and spp % 2 == 0
    h = 2.0 * np.pi / (Z1 * spp)
    np.testing.assert_allclose(np.diff(phi), h, rtol=1e-12)
    ref = phi[(n - 1) // 2]
    # the half-open pitch [ref - pi/z1, ref + pi/z1) on the grid ref + j h
    np.testing.assert_allclose(cyc, ref + h * np.arange(-spp // 2, spp // 2), rtol=0,
                               atol=1e-12)
    np.testing.assert_allclose(cyc[0], ref - np.pi / Z1, rtol=0, atol=1e-12)
    assert cyc[-1] < ref + np.pi / Z1 - 0.5 * h
    start = (n - 1) // 2 - spp // 2
    np.testing.assert_array_equal(cyc, phi[start:start + spp])


def test_efficiency_function_is_mesh_efficiency_as_a_pure_function(spur, oil_surface):
    """``gj.efficiency_function`` -- the traceable entry point optimisers use -- gives the
    numbers of ``mesh_efficiency`` for the same design, material and options (one jitted
    program: TCA, loads, friction): mean efficiency, mean mu, every load and p_max and
    the loaded TE.  Planted bugs caught: the material's E' or nu not passed on (or
    swapped), another compliance model or grid than the one documented, the speed
    taken in rad/s, the TCA options dropped.  Concrete inputs are checked on every call
    (a negative torque: one-line ValueError before any work)."""
    from gearjax.tribology import STEEL_E_PRIME
    oil, surf = oil_surface
    des = spur[1]
    f = gj.efficiency_function(des, E_prime=1.5 * STEEL_E_PRIME)
    assert f.material.e_prime_MPa == pytest.approx(1.5 * STEEL_E_PRIME)
    assert f.options["compliance"] == gj.loading.DEFAULT_COMPLIANCE
    got, res = jax.jit(lambda p, T: f(p, T, RPM, oil, surf))(f.pair, jnp.asarray(TORQUE))
    want, res_w = mesh_efficiency(des, TORQUE, RPM, oil, surf, E_prime=1.5 * STEEL_E_PRIME)
    for name in ("mean_efficiency", "mean_mu", "te_loaded_ptp"):
        assert float(getattr(got, name)) == pytest.approx(float(getattr(want, name)),
                                                          rel=1e-10, abs=1e-15), name
    for name in ("load", "p_max", "deflection"):
        np.testing.assert_allclose(np.asarray(getattr(got.loaded, name)),
                                   np.asarray(getattr(want.loaded, name)), rtol=1e-10,
                                   atol=1e-12, err_msg=name)
    np.testing.assert_allclose(np.asarray(res.path.te), np.asarray(res_w.path.te), atol=1e-14)
    with pytest.raises(ValueError, match="torque"):
        f(f.pair, -5.0, RPM, oil, surf)
    # the loaded chain runs on the grid the family picks for the design (no compile
    # here): a 40/80, 14.5 deg pair (contact ratio 2.16, its path reaching 1.1 pitches
    # from the pitch point) gets 2 pitches and 5 pairs, as in gearjax.run_tca
    high = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(40, 80, 1.5, 14.5), 20.0)
    g = gj.efficiency_function(high)
    assert (g.options["half_pitches"], g.options["n_pairs"]) == (2.0, 5)
    assert g.options["line_contact"] is True
    for k in ("steps_per_pitch", "half_pitches", "n_pairs", "line_contact"):
        assert g.options[k] == gj.tca.family_of(high).resolve(high, {})[k], k


def test_coast_side_of_a_symmetric_pair(spur, oil_surface, weber_run):
    """``side="coast"`` reaches the TCA the loads stand on (its result is the coast
    side's) and, by the mirror symmetry of an unmodified spur pair, gives the drive
    side's efficiency (equal to the last bit here: mirrored arithmetic).  Planted bug
    caught: the side dropped from the TCA call (coast teeth on the drive TCA)."""
    eff, res = mesh_efficiency(spur[1], TORQUE, RPM, *oil_surface, compliance="weber",
                               side="coast")
    assert res.side == "coast" and weber_run[1].side == "drive"
    assert float(eff.mean_efficiency) == pytest.approx(float(weber_run[0].mean_efficiency),
                                                      rel=1e-12)
