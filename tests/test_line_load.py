"""Loaded line contact of spur and helical pairs (gearjax.gears.involute.line_load) and the
involute micro-geometry (gearjax.gears.involute.microgeometry) against closed forms.

* the Harris rule: a spur pair with 1 < eps_alpha < 2, constant pair stiffness k and
  linear "long" tip relief C = W/k on both members over (eps_alpha - 1) p_b has a
  loaded TE p-t-p of exactly |W' - W| / (2k) at every load W' (zero at the design
  load) -- derived in the test's docstring;
* ISO 6336-1's face load factor of a linear load distribution on a uniform face,
  K_Hbeta = 1 + F_beta c b / (2 F) (no separation) and sqrt(2 F_beta c b / F)
  (separation), from a mesh misalignment;
* an aligned unmodified helical pair: equal normal approach at every loaded point,
  so line load x compliance is the same everywhere (uniform line load with a constant
  compliance); with an integer overlap ratio the total contact-line length is
  eps_alpha b / cos(beta_b) at every position;
* mean mesh stiffness against ISO 6336-1's c_gamma_alpha;
* every modification field: value at its defining points; gradients of the loaded-TE
  p-t-p (smooth), the peak pressure and the mean TE against central differences;
* a seeded sweep of valid designs with complementarity and balance checks.
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.gears.involute.geometry import pair_geometry
from gearjax.gears.involute.line_efficiency import line_efficiency_traced
from gearjax.gears.involute.line_load import (LineLoadOptions, line_load_traced, pair_range,
                                              smooth_ptp)
from gearjax.gears.involute.loaded_lines import line_contact, loaded_te_map
from gearjax.gears.involute.microgeometry import (FIELD_UNITS, FlankModification,
                                                  PairModification, flank_removal_um)
from gearjax.loading.pair_stiffness import iso6336_mesh_stiffness, iso6336_single_stiffness

NASA = (28, 28, 3.175, 20.0)          # the NASA gear-noise-rig spur pair, b = 6.35 mm
B_NASA = 6.35


def _pair(z1, z2, m, a, beta=0.0, x1=0.0, x2=0.0):
    return gj.involute.InvolutePair.create(z1, z2, m, a, beta, x1, x2)


@pytest.fixture(scope="module")
def nasa():
    pair = _pair(*NASA)
    return pair, gj.involute.InvoluteTCA.create(pair, B_NASA)


_traced = jax.jit(line_load_traced, static_argnames=("opts", "drive"))


def _run(pair, b, mods, T_Nmm, f_ma=0.0, s0=None, compliance="iso6336", slices=1):
    k_lo, k_hi = pair_range(pair, b)
    opts = LineLoadOptions(8, slices, k_lo, k_hi, compliance)
    return _traced(pair, b, mods, T_Nmm, f_ma, opts, s0=None if s0 is None
                   else jnp.asarray(s0, float))


# ------------------------------------------------------------------ modification law

def test_modification_values_at_their_defining_points():
    """Each field at the points that define it (module docstring of microgeometry):
    amount at the tip / SAP / face end, zero at the relief start, a quarter of the
    amount half-way along a parabolic relief, slopes +-f/2 at the ends, the bias as
    the difference of the end slopes.  Planted bugs caught: a relief measured from the
    wrong end, the exponent ignored, a slope's sign or halving, a bias on one end."""
    sap, tip, b = 10.0, 22.0, 30.0
    f = lambda mod, xi, y: float(flank_removal_um(mod, xi, y, sap, tip, b))   # noqa: E731
    m = FlankModification.create(tip_relief=8.0, tip_relief_length=3.0)
    assert f(m, tip, 0.0) == pytest.approx(8.0)
    assert f(m, tip - 3.0, 0.0) == 0.0 and f(m, tip - 1.5, 5.0) == pytest.approx(4.0)
    m = FlankModification.create(tip_relief=8.0, tip_relief_length=3.0, tip_relief_exponent=2.0)
    assert f(m, tip - 1.5, 0.0) == pytest.approx(2.0)
    m = FlankModification.create(root_relief=6.0, root_relief_length=2.0)
    assert f(m, sap, 0.0) == pytest.approx(6.0) and f(m, sap + 2.0, 0.0) == 0.0
    assert f(m, sap + 0.5, 0.0) == pytest.approx(4.5)
    m = FlankModification.create(profile_crowning=5.0)
    assert f(m, sap, 3.0) == pytest.approx(5.0) == f(m, tip, -3.0)
    assert f(m, 0.5 * (sap + tip), 0.0) == 0.0
    m = FlankModification.create(profile_slope=4.0)
    assert (f(m, tip, 0.0), f(m, sap, 0.0)) == pytest.approx((2.0, -2.0))
    m = FlankModification.create(lead_crowning=7.0)
    assert f(m, 15.0, b / 2) == pytest.approx(7.0) == f(m, 15.0, -b / 2)
    m = FlankModification.create(helix_slope=6.0)
    assert (f(m, 15.0, b / 2), f(m, 15.0, -b / 2)) == pytest.approx((3.0, -3.0))
    m = FlankModification.create(end_relief_I=9.0, end_relief_I_length=5.0,
                                 end_relief_II=3.0, end_relief_II_length=2.0)
    assert f(m, 15.0, -b / 2) == pytest.approx(9.0) and f(m, 15.0, b / 2) == pytest.approx(3.0)
    assert f(m, 15.0, -b / 2 + 2.5) == pytest.approx(4.5) and f(m, 15.0, 0.0) == 0.0
    m = FlankModification.create(bias=10.0)
    # profile slope (tip minus SAP) at end II minus that at end I is the bias
    slope = lambda y: f(m, tip, y) - f(m, sap, y)                             # noqa: E731
    assert slope(b / 2) - slope(-b / 2) == pytest.approx(10.0)
    assert slope(b / 2) == pytest.approx(5.0)


def test_bad_modifications_are_refused():
    """One-line errors naming the field, value and range; a relief with no length."""
    with pytest.raises(ValueError, match=r"tip_relief = -1.*\[0, 500\]"):
        FlankModification.create(tip_relief=-1.0)
    with pytest.raises(ValueError, match="tip_relief_length = 0 mm: a relief of 5 um"):
        FlankModification.create(tip_relief=5.0, tip_relief_length=0.0)
    with pytest.raises(ValueError, match="unknown modification field 'tip'"):
        FlankModification.create(tip=1.0)
    with pytest.raises(ValueError, match="tip_relief_exponent"):
        FlankModification.create(tip_relief_exponent=0.5)


# ------------------------------------------------------------------ Harris rule

def test_harris_long_relief_closed_form(nasa):
    """Constant pair stiffness k (ISO 6336 compliance) and linear relief C over
    L = (eps - 1) p_b at both tips.  In double contact at fraction t of the double zone
    the entering pair has the gear's relief C (1 - t), the leaving pair the pinion's
    C t: with both loaded, k (d - C(1-t)) + k (d - C t) = W' gives d = (W' + C)/(2k),
    in single contact d = W'/k.  With C = W/k: p-t-p = (W' - W)/(2k) above the design
    load; below it the zone ends carry one pair (d = W'/k there) and the middle
    d = W'/(2k) + C/2, so p-t-p = (W - W')/(2k).  Zero at W.  Evaluated at the exact
    positions of the extremes (zone ends, middles, single contact).  Planted bugs caught:
    the gear's relief mapped to the wrong end of the path, the pinion's or gear's
    roll length off the pitch point, the exact solve's active count off by one, the
    unloaded TE not the smallest separation."""
    pair, des = nasa
    geo = pair_geometry(pair)
    p_b = 2 * math.pi * float(geo["rb1"]) / pair.z1
    eps = float(geo["contact_ratio"])
    s_A = float(geo["rho_A"] - geo["rho_P"])
    L = (eps - 1.0) * p_b
    T_design = 71.8e3                                      # N mm
    rb1 = float(geo["rb1"])
    c_prime = float(iso6336_single_stiffness(*NASA[:2]).c_prime)
    k = c_prime * 1e3 * B_NASA                            # N/mm, one pair
    C_um = 1e3 * T_design / rb1 / k
    relief = FlankModification.create(tip_relief=C_um, tip_relief_length=L)
    mods = PairModification(relief, relief)
    # positions of pair 0: double zone start, middle, end; single contact
    s0 = np.array([s_A, s_A + 0.25 * L, s_A + 0.5 * L, s_A + 0.75 * L, s_A + L - 1e-9,
                   s_A + L + 0.5 * (p_b - L)])
    for T in (0.5 * T_design, T_design, 1.6 * T_design):
        r = _run(pair, B_NASA, mods, T, s0=s0)
        assert bool(np.all(r.converged))
        te = np.asarray(r.te_loaded_um)
        want = 1e3 * abs(T - T_design) / rb1 / (2 * k)
        assert np.ptp(te) == pytest.approx(want, abs=1e-9), (T, te)
        assert te[-1] == pytest.approx(1e3 * T / rb1 / k, rel=1e-12)   # single contact
        # unloaded: the smaller of the two reliefs, min(C (1-t), C t), at most C/2
        te0 = np.asarray(r.te_unloaded_um)
        t = np.clip((s0 - s_A) / L, 0.0, 1.0)
        want0 = np.where(s0 - s_A <= L, C_um * np.minimum(t, 1.0 - t), 0.0)
        np.testing.assert_allclose(te0, want0, atol=1e-9)
        assert te0[2] == pytest.approx(C_um / 2, rel=1e-12)
    # unmodified: single/double contact deflections W/k and W/(2k)
    r = _run(pair, B_NASA, PairModification.none(), T_design, s0=s0)
    te = np.asarray(r.te_loaded_um)
    np.testing.assert_allclose(te[1:4], 0.5 * te[-1], rtol=1e-12)


def test_one_member_relief_acts_on_its_own_tip(nasa):
    """Linear long relief C = W/(2k) on the pinion only, constant stiffness: at fraction t
    of the first double zone the entering pair (at the gear's tip, unmodified) has no
    separation and the leaving pair (at the pinion's tip) C t, so d = W/(2k) + C t/2; in
    single contact d = W/k.  Mirrored in time if the relief were put on the gear's tip.
    Planted bugs caught: the members' modifications evaluated on each other's roll
    lengths, the gear's roll length measured from the wrong end."""
    pair, des = nasa
    geo = pair_geometry(pair)
    p_b = 2 * math.pi * float(geo["rb1"]) / pair.z1
    L = (float(geo["contact_ratio"]) - 1.0) * p_b
    s_A = float(geo["rho_A"] - geo["rho_P"])
    T = 71.8e3
    k = float(iso6336_single_stiffness(*NASA[:2]).c_prime) * 1e3 * B_NASA
    W_k_um = 1e3 * T / float(geo["rb1"]) / k
    C = 0.5 * W_k_um
    mods = PairModification(FlankModification.create(tip_relief=C, tip_relief_length=L),
                            FlankModification.none())
    t = np.array([0.1, 0.3, 0.6, 0.9])
    r = _run(pair, B_NASA, mods, T, s0=np.concatenate([s_A + t * L, [s_A + L + 0.5 * (p_b - L)]]))
    want = np.concatenate([0.5 * W_k_um + 0.5 * C * t, [W_k_um]])
    np.testing.assert_allclose(np.asarray(r.te_loaded_um), want, rtol=1e-12)


def test_slice_fraction_at_the_path_ends():
    """A helical slice whose contact-line piece crosses an end of the path carries the
    part on the path: centred h/2 inside s_A (h its half-extent along the path,
    dy tan(beta_b)/2) it carries 3/4 of its length, centred on s_A one half, centred h/2
    outside one quarter.  Planted bug caught: the piece's extent along the path doubled
    or halved (the total over a tiling face is unchanged by it: only a local check
    sees it)."""
    pair = _pair(23, 67, 3.0, 20.0, 20.0, 0.2, -0.1)
    geo = pair_geometry(pair)
    b, N = 30.0, 10
    dy = b / N
    tb, cb = math.tan(float(geo["beta_b"])), math.cos(float(geo["beta_b"]))
    h = 0.5 * dy * tb
    s_A = float(geo["rho_A"] - geo["rho_P"])
    y0 = -0.5 * b + 0.5 * dy                       # centre of slice 0
    s0 = np.array([s_A + 0.5 * h, s_A, s_A - 0.5 * h]) - y0 * tb
    r = _run(pair, b, PairModification.none(), 200e3, s0=s0, slices=N)
    k0 = -pair_range(pair, b)[0]                  # index of pair k = 0
    np.testing.assert_allclose(np.asarray(r.length)[k0, :, 0] / (dy / cb), [0.75, 0.5, 0.25],
                               rtol=1e-12)


# ------------------------------------------------------------------ face load factor

@pytest.mark.parametrize("f_ma", [4.0, 20.0, -20.0], ids=["linear", "separated", "end II"])
def test_face_load_factor_is_iso6336(nasa, f_ma):
    """A spur pair in single contact (one contact line, uniform stiffness c' per unit
    face width) under a mesh misalignment f_ma: the load per unit width is linear
    across the face, w(y) = k'(d - f_ma y/b)+.  ISO 6336-1: K_Hbeta = 1 + f_ma c' b/(2 F)
    while the line stays closed, sqrt(2 f_ma c' b / F) when it opens.  200 slices; the
    discrete maximum is at the end slice's centre, so the linear case is compared with
    the exact discrete value (1e-12) and both with the standard (1 %).  A positive f_ma
    opens end II, so end I carries the peak.  Planted bugs caught: the misalignment's
    sign or scale, the face load not summed per slice width, K taken at the mean."""
    pair, des = nasa
    geo = pair_geometry(pair)
    p_b = 2 * math.pi * float(geo["rb1"]) / pair.z1
    s_single = float(geo["rho_A"] - geo["rho_P"]) + 0.8 * p_b
    T = 71.8e3
    F = T / float(geo["rb1"])
    c = float(iso6336_single_stiffness(*NASA[:2]).c_prime) * 1e3        # N/mm^2
    N = 200
    r = _run(pair, B_NASA, PairModification.none(), T, f_ma=f_ma, s0=[s_single], slices=N)
    K = float(r.k_hbeta[0])
    x = abs(f_ma) * 1e-3 * c * B_NASA / F
    iso = 1 + x / 2 if x <= 2 else math.sqrt(2 * x)
    assert K == pytest.approx(iso, rel=0.01)
    if x <= 2:
        dy = B_NASA / N
        assert K == pytest.approx(1 + x / 2 * (B_NASA - dy) / B_NASA, rel=1e-12)
    face = np.asarray(r.face_load[0])
    assert (face[0] > face[-1]) == (f_ma > 0)
    assert float(r.end_load[0]) == pytest.approx(K, rel=1e-12)


# ------------------------------------------------------------------ helical pairs

def test_aligned_helical_pair_equal_approach_and_contact_length():
    """Aligned, unmodified helical pair with overlap ratio exactly 1 (b = p_bt /
    tan beta_b): the contact lines tile the plane of action, so the total line length
    is eps_alpha b / cos(beta_b) at every position (1e-9), the mean of the model's
    stiffness-weighted lengths aside.  Every loaded point has the same normal approach:
    line load x compliance per unit length is the same at all of them (Weber model;
    with the ISO constant compliance the line load itself is uniform).  Planted bugs
    caught: a slice's fraction on the path computed from its centre only, the line
    length without 1/cos(beta_b), the helix offset's sign (the end-I/end-II axis of
    the docs mirrored: an end relief would act on the other end), the Hertz radius
    not that of the normal section."""
    pair = _pair(23, 67, 3.0, 20.0, 20.0, 0.2, -0.1)
    geo = pair_geometry(pair)
    p_bt = 2 * math.pi * float(geo["rb1"]) / pair.z1
    b = p_bt / math.tan(float(geo["beta_b"]))
    eps = float(geo["contact_ratio"])
    cb = math.cos(float(geo["beta_b"]))
    s0 = float(geo["rho_A"] - geo["rho_P"]) + p_bt * np.linspace(0.0, 1.0, 13)[:-1]
    for model in ("iso6336", "weber"):
        r = _run(pair, b, PairModification.none(), 300e3, s0=s0, compliance=model, slices=24)
        assert bool(np.all(r.converged))
        Ltot = np.asarray(r.length).sum(axis=(0, 2))
        np.testing.assert_allclose(Ltot, eps * b / cb, rtol=1e-9)
        # the documented axis: along each contact line the path coordinate grows from
        # end I to end II by b tan(beta_b), so a pair first touches at end II (its
        # end reliefs and slopes act on the end the user named)
        ds = np.diff(np.asarray(r.s), axis=2)
        np.testing.assert_allclose(ds, b / 24 * math.tan(float(geo["beta_b"])), rtol=1e-9)
        if model == "iso6336":
            # the face is loaded evenly over the cycle (the ends like the middle), to the
            # sampling of the cycle: 12 positions leave 0.9 % (the per-position ratio is
            # 1.25: it follows the contact lines crossing each slice)
            assert abs(float(r.end_load_mean) - 1.0) < 0.015
            assert abs(float(r.k_hbeta_mean) - 1.0) < 0.015
            assert float(np.max(r.end_load)) > 1.1
        on = np.asarray(r.load) > 0
        w = np.asarray(r.line_load)[on]
        if model == "iso6336":
            np.testing.assert_allclose(w, w.mean(), rtol=1e-9)
            # Hertz line contact of the normal section ([Johnson1985] 4.45):
            # p = sqrt(w E' / (2 pi R)), R = xi1 xi2 / ((xi1 + xi2) cos(beta_b)), at the
            # slices wholly on the path (their centre is their contact point)
            full = on & np.isclose(np.asarray(r.length), b / 24 / cb, rtol=1e-12)
            xi1 = float(geo["rho_P"]) + np.asarray(r.s)[full]
            xi2 = float(geo["a_w"]) * math.sin(float(geo["alpha_wt"])) - xi1
            R = xi1 * xi2 / ((xi1 + xi2) * cb)
            Ep = 206000.0 / (1 - 0.3 ** 2)
            wf = np.asarray(r.line_load)[full]
            np.testing.assert_allclose(np.asarray(r.p_max)[full],
                                       np.sqrt(wf * Ep / (2 * math.pi * R)), rtol=1e-12)
        else:
            k = np.asarray(r.load)[on] / cb / 1.0     # normal load = k (d - e) cos(beta_b)
            # normal approach = F / k_slice; k_slice = length / q'  ->  w q' = const
            lengths = np.asarray(r.length)[on]
            te = np.repeat(np.asarray(r.te_loaded_um)[None, :, None], 24, axis=2)
            te = np.broadcast_to(te, r.load.shape)[on]
            approach = 1e-3 * te * cb                 # e = 0 everywhere
            q = approach * lengths / k / cb           # q' from F = (l/q') approach
            np.testing.assert_allclose(w * q, approach, rtol=1e-9)
            assert np.ptp(w) / w.mean() > 0.05        # the compliance does vary


def test_mean_mesh_stiffness_against_iso6336():
    """Mean mesh stiffness c_gamma over the cycle (Weber/Sainsot compliance) against
    ISO 6336-1's c_gamma_alpha = c' (0.75 eps + 0.25), spur and helical: within the
    band the single-pair model keeps against the standard (-22 % .. +12 %,
    tests/test_tooth_compliance.py, docs/compliance.md).  Measured: 28/28 +5.6 %,
    20/40 -2.2 %, 23/67 beta 20 deg -9.7 %, 17/51 beta 30 deg -9.4 %.  Planted bugs
    caught: the stiffness not summed over the loaded pairs, the cos^2(beta_b) of the
    transverse projection lost (helical +12 % and more)."""
    for (z1, z2, m, beta, b, x1, x2) in ((28, 28, 3.175, 0.0, 6.35, 0.0, 0.0),
                                         (20, 40, 4.0, 0.0, 30.0, 0.0, 0.0),
                                         (23, 67, 3.0, 20.0, 30.0, 0.2, -0.1),
                                         (17, 51, 2.5, 30.0, 25.0, 0.3, 0.0)):
        pair = _pair(z1, z2, m, 20.0, beta, x1, x2)
        des = gj.involute.InvoluteTCA.create(pair, b)
        r = line_contact(des, 200.0, positions=32, slices=16)
        c1 = float(iso6336_single_stiffness(z1, z2, x1, x2, math.radians(beta)).c_prime)
        c_iso = float(iso6336_mesh_stiffness(c1, float(pair_geometry(pair)["contact_ratio"])))
        ratio = float(np.mean(r.mesh_stiffness)) / c_iso
        assert -0.22 < ratio - 1.0 < 0.12, (z1, z2, beta, ratio)


# ------------------------------------------------------------------ gradients

def _flat(mods):
    return jnp.concatenate([jnp.stack(jax.tree.leaves(mods.pinion)),
                            jnp.stack(jax.tree.leaves(mods.gear))])


def _unflat(v, like):
    n = len(jax.tree.leaves(like.pinion))
    tp = jax.tree.structure(like.pinion)
    return PairModification(jax.tree.unflatten(tp, list(v[:n])),
                            jax.tree.unflatten(tp, list(v[n:])))


def test_gradients_of_every_field_against_central_differences():
    """d(smooth LTE p-t-p, p_max, mean LTE, power loss)/d(every field of both flanks,
    torque, misalignment) of a modified helical pair (jacfwd through the exact solve) against
    central differences (one vmapped program over the +-h designs).  Every field carries
    a non-zero amount, so no derivative is zero by construction.  Planted bugs caught: a
    stop_gradient or a non-differentiable step in the solve or the relief law, the
    active-set count differentiated."""
    pair = _pair(23, 67, 3.0, 20.0, 20.0, 0.2, -0.1)
    b = 30.0
    vals = dict(tip_relief=8.0, tip_relief_length=2.5, tip_relief_exponent=1.5,
                root_relief=4.0, root_relief_length=2.0, root_relief_exponent=1.3,
                profile_crowning=2.0, profile_slope=1.5, lead_crowning=5.0,
                end_relief_I=6.0, end_relief_I_length=4.0, end_relief_II=5.0,
                end_relief_II_length=3.0, end_relief_exponent=1.7, helix_slope=2.0, bias=3.0)
    mods = PairModification(FlankModification.create(**vals),
                            FlankModification.create(**{k: 0.8 * v if "exponent" not in k
                                                        else v for k, v in vals.items()}))
    k_lo, k_hi = pair_range(pair, b)
    opts = LineLoadOptions(24, 12, k_lo, k_hi, "weber")

    oil, surface = gj.tribology.get_oil(gj.tribology.OILS[0]), gj.tribology.make_surface(0.4)

    def outputs(v):
        md = _unflat(v[:-2], mods)
        le = line_efficiency_traced(pair, b, md, v[-2], v[-1], 1500.0, oil, surface, opts)
        r = le.loads
        return jnp.stack([smooth_ptp(r.te_loaded_um, 0.05), jnp.max(r.p_max),
                          jnp.mean(r.te_loaded_um), jnp.mean(le.power_loss)])

    x0 = jnp.concatenate([_flat(mods), jnp.array([250e3, 8.0])])
    J = jax.jit(jax.jacfwd(outputs))(x0)
    h = np.maximum(1e-5 * np.abs(np.asarray(x0)), 1e-6)
    E = np.diag(h)
    fwd = jax.jit(jax.vmap(outputs))
    fd = (np.asarray(fwd(x0 + E)) - np.asarray(fwd(x0 - E))) / (2 * h[:, None])
    J, fd = np.asarray(J), fd.T
    assert np.all(np.isfinite(J))
    scale = np.abs(fd).max(axis=1, keepdims=True)
    err = np.abs(J - fd) / scale
    assert err.max() < 1e-5, (np.unravel_index(err.argmax(), err.shape), err.max())
    # every field moves the smooth p-t-p or the mean TE
    moved = (np.abs(fd[0]) + np.abs(fd[2])) / np.abs(fd[[0, 2]]).max()
    assert np.all(moved > 1e-9), np.nonzero(moved <= 1e-9)


# ------------------------------------------------------------------ sweep

def test_seeded_sweep_of_valid_designs():
    """24 seeded spur and helical pairs (z 14..60, m_n 1..8 mm, beta 0..35 deg, shifts,
    b 0.3..1.2 of the reference diameter of the pinion capped, random modifications,
    misalignments and torques): every position converged, loads >= 0, complementarity
    (loaded points separated by less than the approach, unloaded by more), torque
    balance, unmodified aligned pairs with zero unloaded TE.  One program per k-range.
    Planted bugs caught: a pair range that misses a pair in contact (balance holds but
    the loaded TE rises: the unloaded/loaded identity of each design's loads fails),
    NaN at partial slices."""
    rng = np.random.default_rng(20261129)
    done = 0
    while done < 24:
        z1 = int(rng.integers(14, 40))
        z2 = int(rng.integers(z1, 90))
        beta = float(rng.choice([0.0, rng.uniform(5, 35)]))
        x1 = float(rng.uniform(0.0, 0.5))
        x2 = float(rng.uniform(-0.3, 0.3))
        m = float(rng.uniform(1.0, 8.0))
        try:
            pair = _pair(z1, z2, m, 20.0, beta, x1, x2)
        except ValueError:
            continue
        b = float(min(rng.uniform(0.3, 1.2) * z1 * m, 150.0))
        modified = done % 2 == 1
        vals = dict(tip_relief=rng.uniform(0, 20), tip_relief_length=rng.uniform(0.5, 3) * m,
                    lead_crowning=rng.uniform(0, 10), helix_slope=rng.uniform(-5, 5),
                    profile_crowning=rng.uniform(0, 4)) if modified else {}
        fm = FlankModification.create(**vals)
        mods = PairModification(fm, fm)
        f_ma = float(rng.uniform(-20, 20)) if modified else 0.0
        des = gj.involute.InvoluteTCA.create(pair, b)
        T = float(rng.uniform(0.2, 2.0)) * 1e-3 * m ** 2 * z1 * b * 30.0     # N m
        r = line_contact(des, T, mods=mods, misalignment_um=f_ma, positions=16, slices=10)
        assert bool(np.all(r.converged)), (z1, z2, m, beta, b)
        F = np.asarray(r.load)
        assert np.all(F >= 0.0)
        e = np.asarray(r.separation_um)
        d = np.asarray(r.te_loaded_um)[None, :, None]
        on = np.isfinite(e)
        dd = np.broadcast_to(d, e.shape)[on]
        loaded = F[on] > 0
        # separations below the approach carry load, the others none (to rounding)
        assert np.all(e[on][loaded] < dd[loaded] + 1e-9)
        assert np.all(e[on][~loaded] > dd[~loaded] - 1e-9)
        geo = pair_geometry(pair)
        cb = math.cos(float(geo["beta_b"]))
        tq = F.sum(axis=(0, 2)) * float(geo["rb1"]) * cb
        np.testing.assert_allclose(tq, 1e3 * T, rtol=1e-9)
        if not modified:
            np.testing.assert_allclose(np.asarray(r.te_unloaded_um), 0.0, atol=1e-12)
        done += 1


def test_loaded_te_map_is_one_program_and_matches_single_runs(nasa):
    """The torque x misalignment map (one vmapped program) equals single runs at the
    same points; p-t-p rises with torque for an unmodified pair.  Planted bug caught:
    the map's axes swapped."""
    _, des = nasa
    relief = FlankModification.create(tip_relief=10.0, tip_relief_length=5.0)
    mods = PairModification(relief, relief)
    m = loaded_te_map(des, [30.0, 70.0, 120.0], [0.0, 15.0], mods=mods, positions=16, slices=8)
    assert m.te_ptp_um.shape == (3, 2) and bool(np.all(m.converged))
    for i, T in enumerate((30.0, 70.0, 120.0)):
        for j, f in enumerate((0.0, 15.0)):
            r = line_contact(des, T, mods=mods, misalignment_um=f, positions=16, slices=8)
            assert float(m.te_ptp_um[i, j]) == pytest.approx(float(np.ptp(r.te_loaded_um)),
                                                             rel=1e-12)
            assert float(m.p_max[i, j]) == pytest.approx(float(np.max(r.p_max)), rel=1e-12)
    assert np.all(np.asarray(m.te_ptp_smooth_um) >= np.asarray(m.te_ptp_um))
    assert np.all(np.asarray(m.te_ptp_smooth_um) - np.asarray(m.te_ptp_um)
                  <= 2 * 0.01 * math.log(16) + 1e-12)
    assert set(FIELD_UNITS) == {f for f in FlankModification.__dataclass_fields__}


# ------------------------------------------------------------------ sliding losses

def test_sliding_loss_factor_closed_forms(nasa):
    """Sliding power per unit mu, sum F |u_s|, over the cycle against closed forms of the
    tooth loss factor H_V (pi (u+1)/(z1 u cos beta_b) times a bracket in the addendum
    contact ratios eps_1, eps_2 of pinion and gear), with the ISO constant compliance:

    * spur, equal load sharing in double contact: Ohlendorf's bracket
      (1 - eps_alpha + eps_1^2 + eps_2^2) [Ohlendorf1958];
    * helical with overlap ratio 1 (total line length constant, line load uniform):
      every contact line sweeps the path evenly, so the bracket is
      (eps_1^2 + eps_2^2)/eps_alpha -- not Ohlendorf's, whose equal-sharing assumption
      is the spur one (for this pair 0.1482 against 0.1248: the model follows the
      physics, docs/microgeometry.md).

    Spur: the loss jumps at the transfer points, so 256 positions per pitch leave
    ~0.1 % (tolerance 0.4 %); helical: smooth, 64 positions and 40 slices, 2e-4.
    Planted bugs caught: the sliding speed without the gear's share (omega1 s), the
    slice loads not the normal loads, the positions not one base pitch."""
    oil, surface = gj.tribology.get_oil(gj.tribology.OILS[0]), gj.tribology.make_surface(0.4)
    for pair, b, M, N, bracket, tol in (
            (nasa[0], B_NASA, 256, 1, "ohlendorf", 4e-3),
            (_pair(23, 67, 3.0, 20.0, 20.0, 0.2, -0.1), None, 64, 40, "uniform", 2e-4)):
        geo = pair_geometry(pair)
        p_bt = 2 * math.pi * float(geo["rb1"]) / pair.z1
        if b is None:
            b = p_bt / math.tan(float(geo["beta_b"]))       # overlap ratio 1
        e1 = float(geo["rho_E"] - geo["rho_P"]) / p_bt
        e2 = float(geo["rho_P"] - geo["rho_A"]) / p_bt
        ea = e1 + e2
        u = pair.z2 / pair.z1
        k = math.pi * (u + 1) / (pair.z1 * u * math.cos(float(geo["beta_b"])))
        H_V = k * ((1 - ea + e1 ** 2 + e2 ** 2) if bracket == "ohlendorf"
                   else (e1 ** 2 + e2 ** 2) / ea)
        opts = LineLoadOptions(M, N, *pair_range(pair, b), "iso6336")
        le = jax.jit(line_efficiency_traced, static_argnames="opts")(
            pair, b, PairModification.none(), 200e3, 0.0, 1500.0, oil, surface, opts)
        assert bool(np.all(le.valid))
        ours = float(np.mean(le.sliding_power_per_mu)) / float(le.power_in)
        assert ours == pytest.approx(H_V, rel=tol), (bracket, ours, H_V)
        if bracket == "ohlendorf":
            if pair.helix == 0.0:
                from gearjax.gears.involute.mesh import ohlendorf_loss_factor
                assert float(ohlendorf_loss_factor(pair)) == pytest.approx(H_V, rel=1e-12)


# ------------------------------------------------------------------ the notebook

def test_microgeometry_notebook_runs(tmp_path):
    """notebooks/08_microgeometry.ipynb top to bottom (after this file's programs): every
    operating point converged, its exact gradient against central differences, its
    robust design better than the unmodified and the packaged flanks, three figures."""
    import re

    from notebook_run import images, run_notebook
    nb, text = run_notebook("08_microgeometry", tmp_path)
    assert "all converged: True" in text
    assert float(re.search(r"max rel\. error ([0-9.e+-]+)", text).group(1)) < 1e-6
    m = re.search(r"unmodified ([0-9.]+), packaged ([0-9.]+), robust design ([0-9.]+)", text)
    unmod, packaged, robust = map(float, m.groups())
    assert robust < packaged < unmod
    assert images(nb) == 3


def test_library_entry_points_refuse_bad_input(nasa, monkeypatch):
    """One-line ValueErrors naming the parameter before any work (the programs are never
    called): the map's torques, misalignments, smoothing temperature, resolution and
    model; a rack mismatch of the TCA route (not a flank modification of this model);
    speed without lubrication.  Planted bugs caught: a refusal dropped (a zero
    temperature gives NaN, a crowned design is analysed as unmodified)."""
    from gearjax.gears.involute import loaded_lines
    monkeypatch.setattr(loaded_lines, "_map", None)      # any call would fail differently
    monkeypatch.setattr(loaded_lines, "_one", None)
    pair, des = nasa
    cases = [
        (dict(torques_Nm=[0.0]), r"torques_Nm = 0 .*\[0.001, 1e\+07\]"),
        (dict(misalignments_um=[2000.0]), r"misalignments_um = 2000"),
        (dict(temperature_um=0.0), r"temperature_um = 0"),
        (dict(positions=2), r"positions = 2"),
        (dict(slices=0), r"slices = 0"),
        (dict(compliance="steel"), r"compliance = 'steel'"),
        (dict(pinion_rpm=1000.0), r"pinion_rpm needs an oil"),
    ]
    for kw, msg in cases:
        args = dict(torques_Nm=[100.0])
        args.update(kw)
        with pytest.raises(ValueError, match=msg):
            loaded_lines.loaded_te_map(des, **args)
    for field in ("lead_crown", "profile_crown", "dalpha"):
        crowned = gj.involute.InvoluteTCA(pair, **{**dict(dalpha=des.dalpha,
                                                          profile_crown=des.profile_crown,
                                                          lead_crown=des.lead_crown,
                                                          face_width=des.face_width),
                                                   field: jnp.asarray(1e-4)})
        with pytest.raises(ValueError, match=f"{field} = 0.0001: the line-contact model"):
            loaded_lines.loaded_te_map(crowned, [100.0])
        with pytest.raises(ValueError, match=field):
            loaded_lines.line_contact(crowned, 100.0)
    with pytest.raises(TypeError, match="involute pairs"):
        loaded_lines.line_contact(gj.load_design("example:hft_8x43"), 100.0)


def test_friction_only_where_the_path_is():
    """The friction evaluated at the bound of path points per position
    (``path_points_bound``) equals the friction at every pair's slices (1e-12), for a
    helical and a spur pair; the bound is never exceeded over a cycle, and a bound set
    too small is reported (the positions not valid), never silently truncated.
    Planted bugs caught: the compacted friction put back at the wrong points, the
    bound one pair short."""
    from gearjax.gears.involute.line_load import path_points_bound
    oil, surface = gj.tribology.get_oil(gj.tribology.OILS[0]), gj.tribology.make_surface(0.4)
    relief = FlankModification.create(tip_relief=6.0, tip_relief_length=2.0, lead_crowning=4.0)
    mods = PairModification(relief, relief)
    run = jax.jit(line_efficiency_traced, static_argnames="opts")
    for pair, b in ((_pair(23, 67, 3.0, 20.0, 20.0, 0.2, -0.1), 30.0),):
        k_lo, k_hi = pair_range(pair, b)
        full = LineLoadOptions(16, 10, k_lo, k_hi, "weber")
        P = path_points_bound(pair, b, 10)
        assert P < (k_hi - k_lo + 1) * 10
        ref = run(pair, b, mods, 200e3, 5.0, 1500.0, oil, surface, full)
        cut = run(pair, b, mods, 200e3, 5.0, 1500.0, oil, surface, full._replace(path_points=P))
        on = np.asarray(ref.loads.length) > 0
        assert int(on.reshape(on.shape[0], 16, 10).sum(axis=(0, 2)).max()) <= P
        np.testing.assert_allclose(np.asarray(cut.mu), np.asarray(ref.mu), rtol=1e-12, atol=0)
        np.testing.assert_allclose(np.asarray(cut.power_loss), np.asarray(ref.power_loss),
                                   rtol=1e-12)
        assert bool(np.all(cut.valid)) and bool(np.all(ref.valid))
        short = run(pair, b, mods, 200e3, 5.0, 1500.0, oil, surface,
                    full._replace(path_points=P // 3))
        assert not bool(np.all(short.valid))
