"""The slices of the loaded line contact coupled along the face: the Pasternak foundation
of gearjax.gears.involute.face_coupling, against closed forms and its own equations.

* coupling length 0 (and a vanishing one) is the Winkler model to round-off;
* an aligned unmodified pair has a uniform deflection along each line: the coupling does
  no work, the loads, approach and mesh stiffness are the Winkler ones exactly;
* the continuous Pasternak beam k w - G w'' = q with free ends, solved in closed form for
  a spur pair in single contact (a) under a linear mesh misalignment (the concentrated
  force G f/b at the compressed end, the open zone at the other with w = A cosh) and
  (b) with a linear end relief (the open zone dragged along over the coupling length,
  the force G C/L at the relief's start): the discrete solution converges to them;
* the discrete equations themselves, built independently here (a tridiagonal matrix per
  tooth pair, no link between pairs or to a piece off the path), hold at the solution,
  with complementarity (no tensile load, no interpenetration), on a seeded sweep;
* derivatives of the smooth LTE p-t-p, p_max, K_Hbeta and mean LTE against central
  differences; the non-converged active set is flagged;
* the loads are continuous in the mesh position as a piece enters the path;
* the option reaches the model from the public entry points, the command and a study.
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import brentq

import gearjax as gj
from cli_call import cli_call
from gearjax.gears.involute.face_coupling import coupled_solve
from gearjax.gears.involute.geometry import pair_geometry
from gearjax.gears.involute.line_load import (LineLoadOptions, line_load_traced, pair_range,
                                              smooth_ptp)
from gearjax.gears.involute.microgeometry import FlankModification, PairModification

LAM = 3.0                                     # coupling length of the tests (mm)
SPUR = (28, 28, 3.175, 20.0)
B_SPUR = 30.0
HELICAL = (23, 67, 3.0, 20.0, 20.0, 0.2, -0.1)
B_HEL = 30.0

_traced = jax.jit(line_load_traced, static_argnames=("opts", "drive"))


def _pair(z1, z2, m, a, beta=0.0, x1=0.0, x2=0.0):
    return gj.involute.InvolutePair.create(z1, z2, m, a, beta, x1, x2)


def _opts(pair, b, slices, lam, compliance="iso6336", positions=8, steps=64):
    k_lo, k_hi = pair_range(pair, b)
    return LineLoadOptions(positions, slices, k_lo, k_hi, compliance, 0, float(lam), steps)


def _run(pair, b, mods, T_Nmm, f_ma, slices, lam, s0=None, compliance="iso6336", steps=64,
         positions=8):
    return _traced(pair, b, mods, T_Nmm, f_ma,
                   _opts(pair, b, slices, lam, compliance, positions, steps),
                   s0=None if s0 is None else jnp.asarray(s0, float))


def _single_contact(pair):
    """A mesh position of a spur pair in single contact (pair 0 alone)."""
    geo = pair_geometry(pair)
    p_b = 2 * math.pi * float(geo["rb1"]) / pair.z1
    L = (float(geo["contact_ratio"]) - 1.0) * p_b
    s_A = float(geo["rho_A"] - geo["rho_P"])
    return np.array([s_A + L + 0.5 * (p_b - L)]), float(geo["rb1"])


def _hel_mods(scale=1.0):
    p = FlankModification.create(tip_relief=8.0 * scale, tip_relief_length=2.5,
                                 lead_crowning=4.0 * scale, end_relief_I=5.0 * scale,
                                 end_relief_I_length=4.0, helix_slope=2.0 * scale)
    g = FlankModification.create(tip_relief=6.0 * scale, tip_relief_length=2.0,
                                 profile_crowning=2.0 * scale)
    return PairModification(p, g)


@pytest.fixture(scope="module")
def spur():
    pair = _pair(*SPUR)
    s0, rb1 = _single_contact(pair)
    T = 150e3
    W = T / rb1                                  # spur: the load along the line of action
    # the Winkler stiffness per unit face width, from the uniform load of the aligned pair
    r = _run(pair, B_SPUR, PairModification.none(), T, 0.0, 10, 0.0, s0=s0)
    k_w = W / (B_SPUR * 1e-3 * float(r.te_loaded_um[0]))
    return pair, s0, T, W, k_w


# ------------------------------------------------------------------ Winkler limit

def test_zero_coupling_is_the_winkler_model():
    """coupling_length 0 is today's program (the default option, bit for bit through the
    public entry point), and a vanishing coupling length (1e-6 mm) runs the coupled
    active-set solve to the Winkler loads, approach and stiffness to round-off.  Planted
    bugs caught: the coupled route's first active set or load formula off the Winkler
    one, the mesh stiffness of the coupled route not dW/d delta."""
    pair = _pair(*HELICAL)
    mods = _hel_mods()
    des = gj.involute.InvoluteTCA.create(pair, B_HEL)
    a = gj.involute.line_contact(des, 200.0, mods=mods, misalignment_um=8.0, positions=8,
                                 slices=12)
    b = gj.involute.line_contact(des, 200.0, mods=mods, misalignment_um=8.0, positions=8,
                                 slices=12, coupling_length_mm=0.0)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(np.asarray(x), np.asarray(y))
    w = _run(pair, B_HEL, mods, 200e3, 8.0, 12, 0.0, compliance="weber")
    c = _run(pair, B_HEL, mods, 200e3, 8.0, 12, 1e-6, compliance="weber")
    assert bool(np.all(c.converged))
    np.testing.assert_allclose(np.asarray(c.load), np.asarray(w.load), rtol=0,
                               atol=1e-9 * float(np.max(w.load)))
    np.testing.assert_allclose(np.asarray(c.te_loaded_um), np.asarray(w.te_loaded_um),
                               rtol=1e-10)
    np.testing.assert_allclose(np.asarray(c.mesh_stiffness), np.asarray(w.mesh_stiffness),
                               rtol=1e-9)


def test_uniform_deflection_is_unchanged_by_the_coupling():
    """An aligned unmodified helical pair (Weber compliance, varying along the path): the
    separation is zero along every line, the Winkler deflection is the approach
    everywhere, and a constant deflection has no curvature, so the coupled solution is
    the Winkler one: same loads, approach and mesh stiffness, exact.  Planted bugs
    caught: a fixed (w = 0) instead of a free end (the end slices would pull), a link to
    a piece off the path, a sliver's link not scaled by its share."""
    pair = _pair(*HELICAL)
    none = PairModification.none()
    w = _run(pair, B_HEL, none, 200e3, 0.0, 12, 0.0, compliance="weber")
    c = _run(pair, B_HEL, none, 200e3, 0.0, 12, LAM, compliance="weber")
    assert bool(np.all(c.converged))
    np.testing.assert_allclose(np.asarray(c.load), np.asarray(w.load), rtol=1e-12,
                               atol=1e-12 * float(np.max(w.load)))
    np.testing.assert_allclose(np.asarray(c.te_loaded_um), np.asarray(w.te_loaded_um),
                               rtol=1e-12)
    np.testing.assert_allclose(np.asarray(c.mesh_stiffness), np.asarray(w.mesh_stiffness),
                               rtol=1e-12)


# ------------------------------------------------------------------ closed forms

def _slice_loads(r):
    return np.asarray(r.load).sum(axis=0)[0]           # (N,), spur: along the line of action


def test_misalignment_closed_form_of_the_pasternak_beam(spur):
    """Spur pair in single contact, constant stiffness k per unit face width, mesh
    misalignment f (separation e = s y, s = f/b, end II opening), G = lambda^2 k.
    Continuous solution: contact on [-b/2, a], w = delta - s y there; on (a, b/2] no load,
    k w - G w'' = 0 with w'(b/2) = 0, so w = A cosh((b/2 - y)/lambda); w and w' continuous
    at a give A = s lambda / sinh(L/lambda), delta = s a + s lambda coth(L/lambda)
    (L = b/2 - a); the free end I, where w' = -s, carries the concentrated force G s
    (the jump of the shear G w' to zero), so W = k [delta (a + b/2) - s (a^2 - b^2/4)/2]
    + G s fixes a.  (The end force never vanishes for s != 0: it would be tensile at a
    compressed end II, so end II always opens.)  The discrete model puts the end force in
    the end slice.  Checked: approach, the end slice's load, the loaded length and the gap
    of the open zone converge to the closed form as the slices go 40 -> 80 -> 160.
    Planted bugs caught: the sign of G (the end force and the open zone reverse), G
    linear in lambda, the end condition dropped (a fixed end: no end force), the load
    of the end slice without its link term."""
    pair, s0, T, W, k_w = spur
    b, f_um = B_SPUR, 30.0
    s = 1e-3 * f_um / b
    G = LAM ** 2 * k_w

    def parts(a):
        L = b / 2 - a
        delta = s * a + s * LAM / math.tanh(L / LAM)
        return delta, k_w * (delta * (a + b / 2) - s * (a * a - b * b / 4) / 2) + G * s

    a = brentq(lambda a: parts(a)[1] - W, -b / 2 + 1e-9, b / 2 - 1e-9, xtol=1e-14)
    delta = parts(a)[0]
    L = b / 2 - a
    A = s * LAM / math.sinh(L / LAM)
    assert 1.0 < L < 10.0                                 # an open zone of a few slices
    errs = []
    for N in (40, 80, 160):
        r = _run(pair, b, PairModification.none(), T, f_um, N, LAM, s0=s0)
        assert bool(r.converged[0]) and float(r.complementarity[0]) < 1e-12
        dy = b / N
        y = -b / 2 + dy * (np.arange(N) + 0.5)
        P = _slice_loads(r)
        d = 1e-3 * float(r.te_loaded_um[0])
        end = P[0] - (k_w * dy * (delta - s * y[0]) + G * s)
        loaded = y[P > 0]
        open_ = y > a + dy
        gap = 1e-3 * np.nansum(np.asarray(r.gap_um), axis=0)[0]
        g_cf = A * np.cosh((b / 2 - y) / LAM) - (delta - s * y)
        errs.append((abs(d - delta) / delta, abs(end) / (G * s),
                     abs(loaded.max() + dy / 2 - a) / dy,
                     np.max(np.abs(gap[open_] - g_cf[open_])) / delta))
    errs = np.array(errs)
    # measured at 160 slices: 2e-6, 4e-7, 0.64, 2e-5 (the approach's error is not
    # monotone in the slices: the contact edge falls at varying places inside a slice)
    assert np.all(errs[-1] < [2e-5, 1e-5, 1.0, 1e-4]), errs
    assert errs[2, 0] < errs[0, 0] and errs[2, 1] < errs[0, 1] / 3, errs
    assert errs[2, 3] < errs[0, 3] / 3, errs


def test_end_relief_is_spread_over_the_coupling_length(spur):
    """Spur pair in single contact, a linear end relief I of C over L_I (e = s (y_r - y)
    for y < y_r = -b/2 + L_I, s = C/L_I).  With the Winkler foundation the relieved zone
    with e > delta is open and undeflected (gap e - delta).  Coupled, the contact ends at
    a with w, w' continuous; the open zone [-b/2, a) is dragged along,
    w = A cosh((y + b/2)/lambda), decaying from the contact edge over lambda: A = s lambda
    / sinh(L_o/lambda), delta = e(a) + s lambda coth(L_o/lambda) (L_o = a + b/2); the
    kink of e at the relief's start carries the force G s, so W = k [delta (b/2 - a) -
    s (y_r - a)^2 / 2] + G s.  Checked: approach, loaded length, the open zone's gap
    (within 1e-3 of the approach at 160 slices, converging) and the kink force in the
    slices around y_r.  Planted bugs caught: coupling off (no deflection of the open zone),
    a wrong coupling length scale, the active set frozen at the Winkler start (the
    contact edge would stay at e = delta)."""
    pair, s0, T, W, k_w = spur
    b, C, LI = B_SPUR, 20.0, 10.0
    s = 1e-3 * C / LI
    yr = -b / 2 + LI
    G = LAM ** 2 * k_w
    mods = PairModification(FlankModification.create(end_relief_I=C, end_relief_I_length=LI),
                            FlankModification.none())

    def parts(a):
        Lo = a + b / 2
        delta = s * (yr - a) + s * LAM / math.tanh(Lo / LAM)
        return delta, k_w * (delta * (b / 2 - a) - s * (yr - a) ** 2 / 2) + G * s

    a = brentq(lambda a: parts(a)[1] - W, -b / 2 + 1e-9, yr - 1e-9, xtol=1e-14)
    delta = parts(a)[0]
    A = s * LAM / math.sinh((a + b / 2) / LAM)
    e_of = lambda y: np.where(y < yr, s * (yr - y), 0.0)             # noqa: E731
    # the Winkler contact ends where e = delta; coupled, the deflection w(a) > 0 at the
    # edge, so the contact ends where e < delta, nearer the relief's start
    rw = _run(pair, b, mods, T, 0.0, 80, 0.0, s0=s0)
    a_w = yr - 1e-3 * float(rw.te_loaded_um[0]) / s
    assert a > a_w + 0.5, (a, a_w)
    errs = []
    for N in (40, 80, 160):
        r = _run(pair, b, mods, T, 0.0, N, LAM, s0=s0)
        assert bool(r.converged[0]) and float(r.complementarity[0]) < 1e-12
        dy = b / N
        y = -b / 2 + dy * (np.arange(N) + 0.5)
        P = _slice_loads(r)
        d = 1e-3 * float(r.te_loaded_um[0])
        gap = 1e-3 * np.nansum(np.asarray(r.gap_um), axis=0)[0]
        open_ = y < a - dy
        g_cf = A * np.cosh((y + b / 2) / LAM) + e_of(y) - delta
        # the five slices around y_r (the sampled kink falls between two slice centres)
        i = int(np.searchsorted(y + dy / 2, yr))                    # slice holding y_r
        lo, hi = y[i - 2] - dy / 2, y[i + 2] + dy / 2
        dist = k_w * (delta * (hi - lo) - s * (yr - lo) ** 2 / 2)  # k (delta - e) there
        errs.append((abs(d - delta) / delta, abs(y[P > 0].min() - dy / 2 - a) / dy,
                     np.max(np.abs(gap[open_] - g_cf[open_])) / delta,
                     abs(P[i - 2:i + 3].sum() - dist - G * s) / (G * s)))
    errs = np.array(errs)
    # measured at 160 slices: 1.1e-5, 0.55, 4.5e-5, 2.1e-4
    assert np.all(errs[-1] < [5e-5, 1.0, 2e-4, 1e-3]), errs
    assert errs[2, 0] < errs[0, 0] / 3 and errs[2, 2] < errs[0, 2] / 3, errs
    # the open zone is dragged along: positive deflection w = gap - e + delta there
    w_open = (gap - e_of(y) + d)[open_]
    assert np.all(w_open > 0.0) and np.all(np.diff(w_open) > 0.0)


# ------------------------------------------------------------------ the equations

def _check_equations(pair, b, mods, T, f_ma, slices, lam, k_unit, compliance="weber"):
    """The coupled solution against the discrete equations built here: per tooth pair a
    tridiagonal A (k_i on the diagonal plus links c = lambda^2 (kf_i + kf_{i+1}) / (2
    dy^2) min(f_i, f_{i+1}) between neighbouring slices of the pair on the path), A w =
    P; P >= 0, gap >= 0, P gap = 0, sum P = W.  ``k_unit``: the Winkler slice stiffness
    of each point (from an aligned unmodified run at the same torque)."""
    r = _run(pair, b, mods, T, f_ma, slices, lam, compliance=compliance)
    assert bool(np.all(r.converged)), np.asarray(r.complementarity)
    geo = pair_geometry(pair)
    cb = math.cos(float(geo["beta_b"]))
    dy = b / slices
    P = np.asarray(r.load) / cb                          # (K, M, N)
    e = 1e-3 * np.asarray(r.separation_um)
    gap = 1e-3 * np.asarray(r.gap_um)
    on = np.isfinite(e)
    d = 1e-3 * np.asarray(r.te_loaded_um)[None, :, None]
    w = np.where(on, gap - e + d, 0.0)
    frac = np.asarray(r.length) / (dy / cb)
    kf = np.where(on, k_unit / np.where(on, frac, 1.0), 0.0)
    c = lam ** 2 * 0.5 * (kf[..., :-1] + kf[..., 1:]) / dy ** 2 * np.minimum(
        frac[..., :-1], frac[..., 1:])
    Aw = k_unit * w
    Aw[..., :-1] += c * (w[..., :-1] - w[..., 1:])
    Aw[..., 1:] += c * (w[..., 1:] - w[..., :-1])
    Wt = T / (float(geo["rb1"]) * cb ** 2)
    scale = Wt
    assert np.all(P >= 0.0)
    np.testing.assert_allclose(P[on], Aw[on], rtol=0, atol=1e-9 * scale)
    assert np.all(gap[on] >= -1e-12)
    assert np.all(np.abs(P * np.where(on, gap, 0.0)) <= 1e-12 * scale)
    np.testing.assert_allclose(P.sum(axis=(0, 2)), Wt, rtol=1e-9)
    return r


def test_coupled_equations_and_complementarity_on_a_seeded_sweep():
    """Seeded random modifications, misalignments and torques of the helical pair (Weber
    compliance) and a spur pair: the solution satisfies the discrete Pasternak equations
    built here independently (block per tooth pair), carries no tensile load, has no
    interpenetration, is complementary and balances the torque.  Planted bugs caught: a
    link between two tooth pairs (the last slice of one and the first of the next), the
    sign of G, a link to a piece off the path, an end slice with a ghost neighbour, a
    tensile point kept in the active set, a penetrating point left out."""
    rng = np.random.default_rng(20261129)
    cases = [(_pair(*HELICAL), B_HEL), (_pair(*SPUR), B_SPUR)]
    for pair, b in cases:
        for i in range(4):
            T = float(rng.uniform(40e3, 400e3))
            base = _run(pair, b, PairModification.none(), T, 0.0, 12, 0.0, compliance="weber")
            cb = math.cos(float(pair_geometry(pair)["beta_b"]))
            k_unit = np.asarray(base.load) / cb / (1e-3 * np.asarray(base.te_loaded_um)
                                                   [None, :, None])
            fm = lambda: FlankModification.create(                       # noqa: E731
                tip_relief=rng.uniform(0, 20), tip_relief_length=rng.uniform(1.0, 4.0),
                lead_crowning=rng.uniform(0, 10), helix_slope=rng.uniform(-8, 8),
                end_relief_II=rng.uniform(0, 15), end_relief_II_length=rng.uniform(2, 8),
                profile_crowning=rng.uniform(0, 4))
            mods = PairModification(fm(), fm())
            lam = float(rng.uniform(1.0, 6.0)) if i else LAM
            # the Winkler stiffness of a point is the same with any modification
            r = _check_equations(pair, b, mods, T, float(rng.uniform(-25, 25)), 12, lam,
                                 k_unit)
            assert int(np.max(r.n_points)) > 0


# ------------------------------------------------------------------ derivatives

def test_gradients_with_coupling_against_central_differences():
    """d(smooth LTE p-t-p, p_max, K_Hbeta, mean LTE)/d(nine modification fields, torque,
    misalignment) of the coupled helical pair (jacfwd through the re-solve of the final
    active set) against central differences (one vmapped program over the +-h designs),
    and reverse mode against forward mode.  Planted bugs caught: a stop_gradient on the
    re-solve's inputs, the derivative taken through the loop's frozen values, a
    derivative of the approach missing the link stiffness."""
    pair = _pair(*HELICAL)
    b = B_HEL
    opts = _opts(pair, b, 12, LAM, "weber", positions=6)
    names = [("pinion", "tip_relief"), ("pinion", "tip_relief_length"),
             ("pinion", "lead_crowning"), ("pinion", "end_relief_I"),
             ("pinion", "end_relief_I_length"), ("pinion", "helix_slope"),
             ("gear", "tip_relief"), ("gear", "tip_relief_length"),
             ("gear", "profile_crowning")]
    mods0 = _hel_mods()

    def mods_of(v):
        kw = {"pinion": {}, "gear": {}}
        for (m, f), x in zip(names, v):
            kw[m][f] = x
        import dataclasses
        return PairModification(dataclasses.replace(mods0.pinion, **kw["pinion"]),
                                dataclasses.replace(mods0.gear, **kw["gear"]))

    def outputs(v):
        r = line_load_traced(pair, b, mods_of(v[:-2]), v[-2], v[-1], opts)
        return jnp.stack([smooth_ptp(r.te_loaded_um, 0.05), jnp.max(r.p_max),
                          r.k_hbeta_mean, jnp.mean(r.te_loaded_um)])

    x0 = jnp.array([float(getattr(getattr(mods0, m), f)) for m, f in names] + [250e3, 8.0])
    J = np.asarray(jax.jit(jax.jacfwd(outputs))(x0))
    h = np.maximum(1e-6 * np.abs(np.asarray(x0)), 1e-7)
    E = np.diag(h)
    fwd = jax.jit(jax.vmap(outputs))
    fd = ((np.asarray(fwd(x0 + E)) - np.asarray(fwd(x0 - E))) / (2 * h[:, None])).T
    assert np.all(np.isfinite(J))
    scale = np.abs(fd).max(axis=1, keepdims=True)
    err = np.abs(J - fd) / scale
    assert err.max() < 1e-5, (np.unravel_index(err.argmax(), err.shape), err.max())
    # reverse mode (through the same re-solve) gives the same derivative
    g = np.asarray(jax.jit(jax.grad(lambda v: outputs(v)[0]))(x0))
    np.testing.assert_allclose(g, J[0], rtol=1e-9, atol=1e-12 * np.abs(J[0]).max())
    # the coupling changes the derivatives (they are not the Winkler ones)
    opts_w = _opts(pair, b, 12, 0.0, "weber", positions=6)
    r_w = jax.jacfwd(lambda v: jnp.mean(line_load_traced(pair, b, mods_of(v[:-2]), v[-2],
                                                         v[-1], opts_w).te_loaded_um))(x0)
    assert np.max(np.abs(np.asarray(r_w) - J[3])) > 1e-3 * np.max(np.abs(J[3]))


# ------------------------------------------------------------------ flags and inputs

def test_non_converged_active_set_is_flagged():
    """With the active-set iterations capped at 1 a case whose set changes from the
    Winkler start is reported not converged (the flag reaches LineLoad.converged and
    loaded_te_map's), never as a valid result; the solver's own residual names it.
    Planted bugs caught: the loop's stop flag ignored, converged set without the
    complementarity residual."""
    pair = _pair(*HELICAL)
    r = _run(pair, B_HEL, _hel_mods(), 200e3, 15.0, 12, LAM, compliance="weber", steps=1)
    assert not bool(np.all(r.converged))
    r = _run(pair, B_HEL, _hel_mods(), 200e3, 15.0, 12, LAM, compliance="weber")
    assert bool(np.all(r.converged))
    # the solver alone: a tensile point forced into the set is seen by the residual
    e = jnp.array([0.0, 0.0, 0.01, 0.02])
    k = jnp.full(4, 1e3)
    link = jnp.array([1e4, 1e4, 1e4, 0.0])
    sol = coupled_solve(e, k, link, 1.0, jnp.asarray(0.05), 0)      # no iteration at all
    assert not bool(sol.converged) and float(sol.residual) > 1e-3
    sol = coupled_solve(e, k, link, 1.0, jnp.asarray(0.05), 16)
    assert bool(sol.converged) and float(sol.residual) < 1e-12


def test_coupling_length_is_range_checked():
    """One-line errors naming the parameter, value and range at the entry points."""
    des = gj.involute.InvoluteTCA.create(_pair(*SPUR), 10.0)
    with pytest.raises(ValueError, match=r"coupling_length_mm = -1 mm.*\[0, 1000\]"):
        gj.involute.line_contact(des, 100.0, coupling_length_mm=-1.0)
    with pytest.raises(ValueError, match=r"coupling_length_mm = 2000 mm"):
        gj.involute.loaded_te_map(des, [100.0], coupling_length_mm=2000.0)
    assert gj.involute.module_coupling_length(des) == pytest.approx(3.175)


STUDY = """
[study]
name = "mgc"
design = "example:helical_microgeometry"

[scenarios]
torque_Nm = [200.0, 400.0]
f_ma_um = [10.0]

[line]
positions = 8
slices = 6
coupling_length_mm = 3.0

[[variables]]
field = "microgeometry.pinion.tip_relief_um"
lower = 0.0
upper = 30.0
scale = 30.0

[[objective]]
quantity = "line_te_ptp_um"
scale = 1.0
"""


def test_study_route_takes_the_coupling_length(tmp_path):
    """``[line] coupling_length_mm`` reaches the study's model: its quantities equal
    loaded_te_map with the same coupling (and differ from the Winkler map); a value out of
    range is refused naming the table, key, value and range.  Planted bug caught: the
    key read but not passed to the model options."""
    from gearjax.studies import study_run as sr
    from gearjax.studies.study_file import read_study
    p = tmp_path / "s.toml"
    p.write_text(STUDY.replace("3.0\n\n[[var", "-2.0\n\n[[var"))
    with pytest.raises(ValueError, match=r"\[line\] coupling_length_mm = -2 mm.*\[0, 1000\]"):
        read_study(str(p))
    p.write_text(STUDY)
    prob = sr.set_up(read_study(str(p)))
    Q0 = np.asarray(sr.start_point(prob)[0])
    qi = {q: i for i, q in enumerate(prob.study.quantities)}
    kw = dict(positions=8, slices=6, temperature_um=0.02)
    m = gj.involute.loaded_te_map(prob.design, [200.0, 400.0], [10.0], coupling_length_mm=3.0,
                                  **kw)
    np.testing.assert_allclose(Q0[:, qi["line_te_ptp_hard_um"]], np.asarray(m.te_ptp_um).ravel(),
                               rtol=1e-12)
    w = gj.involute.loaded_te_map(prob.design, [200.0, 400.0], [10.0], **kw)
    assert np.max(np.abs(np.asarray(w.te_ptp_um) - np.asarray(m.te_ptp_um))) > 1e-3


_cli = cli_call


def test_cli_flag_reaches_the_model_and_is_checked(monkeypatch):
    """``gearjax loaded --coupling-length-mm module``: the JSON ``input`` names the λ used
    (the normal module) and the values are the library map's with that coupling; a bad
    value is one line naming the flag, before any work.  Planted bugs caught: the flag
    parsed but not passed, ``module`` not resolved to m_n."""
    import json
    ex = "example:helical_microgeometry"
    small = ["--torque-Nm", "200", "--positions", "8", "--slices", "6"]
    rc, out, err = _cli(["loaded", ex, *small, "--coupling-length-mm", "module", "--json"])
    assert rc == 0, err
    js = json.loads(out)
    assert js["input"]["coupling_length_mm"] == pytest.approx(3.0)
    # the slice dependence of p_max and K_Hbeta with coupling is said (and only then)
    assert sum("coupled along the face" in w for w in js["warnings"]) == 1
    assert "--slices" in err and "grow with the slice count (6 here)" in err
    m = gj.involute.loaded_te_map(gj.load_design(ex), [200.0], positions=8, slices=6,
                                  coupling_length_mm=3.0)
    assert js["te_ptp_um"][0][0] == pytest.approx(float(m.te_ptp_um[0, 0]), rel=1e-12)
    # p_max is where the coupling shows at this aligned point (the TE p-t-p hardly moves)
    assert js["p_max_MPa"][0][0] == pytest.approx(float(m.p_max[0, 0]), rel=1e-12)
    w = gj.involute.loaded_te_map(gj.load_design(ex), [200.0], positions=8, slices=6)
    assert abs(float(w.p_max[0, 0]) - float(m.p_max[0, 0])) > 1.0
    monkeypatch.setattr(gj.involute, "loaded_te_map",
                        lambda *a, **k: pytest.fail("computed on bad input"))
    for bad in ("-1", "abc", "2000"):
        rc, out, err = _cli(["loaded", ex, *small, "--coupling-length-mm", bad])
        assert rc == 2 and out == "" and len(err.splitlines()) == 1, err
        assert "--coupling-length-mm" in err


def test_loads_continuous_as_a_piece_enters_the_path():
    """A helical pair with a helix slope (the line in contact with a slope along the face):
    at the mesh positions 1e-7 mm either side of the one where slice 0's piece of pair 0
    enters the path at s_A, every point's load changes by as little as in the Winkler
    model (measured 6e-5 N; the entering sliver links with its share of the path).
    Planted bug caught: a sliver linked with a whole piece's conductance (a finite load
    handed to a piece of vanishing length: 28 N jump)."""
    pair = _pair(*HELICAL)
    b, N = B_HEL, 12
    geo = pair_geometry(pair)
    tb = math.tan(float(geo["beta_b"]))
    s_A = float(geo["rho_A"] - geo["rho_P"])
    dy = b / N
    s_in = s_A - 0.5 * dy * tb - (-b / 2 + dy / 2) * tb
    mods = PairModification(FlankModification.create(helix_slope=10.0), FlankModification.none())
    jumps = []
    for lam in (0.0, LAM):
        r = _run(pair, b, mods, 200e3, 0.0, N, lam, s0=[s_in - 1e-7, s_in + 1e-7],
                 compliance="weber")
        assert bool(np.all(r.converged))
        F = np.asarray(r.load)
        jumps.append(np.abs(F[:, 1] - F[:, 0]).max())
    assert jumps[1] < 1e-3 and jumps[1] < 10 * jumps[0] + 1e-6, jumps


def test_complementarity_residual_is_its_definition():
    """The reported residual of a wrong active set against its definition by hand,
    ``max(max(-P)/W, max(-g)/(delta - min e))``, where the wrong set leaves points
    interpenetrating (the gap term decides).  Planted bugs caught: the
    interpenetration scaled by the load instead of the compression (a residual 2000x too
    small that would pass a wrong set as converged), a tensile load not counted."""
    e = jnp.array([0.0, 0.0, 0.01, 0.02])
    k = jnp.full(4, 1e3)
    link = jnp.array([1e3, 1e3, 1e3, 0.0])
    W = 100.0
    sol = coupled_solve(e, k, link, W, jnp.asarray(0.005), 0)     # the set {0, 1}, kept
    P, w, d = (np.asarray(a) for a in (sol.load, sol.w, sol.delta))
    g = w + np.asarray(e) - d
    assert g[2] < -1e-3                      # point 2 interpenetrates: the set is wrong
    want = max(np.max(np.maximum(-P, 0.0)) / W, np.max(np.maximum(-g, 0.0)) / (d - 0.0))
    assert float(sol.residual) == pytest.approx(want, rel=1e-12) and want > 0.1
    assert not bool(sol.converged)


def test_coupled_mesh_stiffness_is_dW_by_d_delta():
    """The mesh stiffness of the coupled contact under a misalignment and modifications
    (the active set not the whole line) against the difference quotient of the load
    over the approach between two torques 1e-6 apart (same active set): c_gamma =
    cos^2(beta_b) (dW/d delta) / b.  Planted bug caught: the Winkler slope (sum of the
    loaded slices' k), which the coupling changes where the contact is partial.  (ISO
    6336 compliance: constant per slice; Weber's contact term depends on the load, so
    there dW/d delta between two torques also holds the change of k.)"""
    pair = _pair(*HELICAL)
    geo = gj.involute.pair_geometry(pair)
    rb1, cb = float(geo["rb1"]), math.cos(float(geo["beta_b"]))
    T, h = 200e3, 1e-6
    r0 = _run(pair, B_HEL, _hel_mods(), T, 15.0, 12, LAM)
    r1 = _run(pair, B_HEL, _hel_mods(), T * (1.0 + h), 15.0, 12, LAM)
    assert bool(np.all(r0.converged)) and bool(np.all(r1.converged))
    dW = T * h / (rb1 * cb ** 2)
    dd = 1e-3 * (np.asarray(r1.te_loaded_um) - np.asarray(r0.te_loaded_um))      # mm
    fd = cb ** 2 * dW / dd / B_HEL * 1e-3
    np.testing.assert_allclose(np.asarray(r0.mesh_stiffness), fd, rtol=1e-5)
    w = _run(pair, B_HEL, _hel_mods(), T, 15.0, 12, 0.0)
    assert np.max(np.abs(np.asarray(w.mesh_stiffness) / fd - 1.0)) > 1e-3   # coupling acts
