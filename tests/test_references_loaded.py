"""Independent references for the loaded chain (issue 28, item 5).

Every reference here is computed in the test by a second route -- numpy closed forms,
a hand solution of the equilibrium, scipy's elliptic integrals, the ISO 6336-1
polynomial typed from the standard -- never by calling the library function under
test.  Library outputs are used only as the *inputs* of a hand computation (a contact
point, a curvature, a load), never as the expected value.

* two-pair static equilibrium by hand (linear springs and Hertz springs, distinct
  lever arms per pair): loads, fall-back, torque balance about both axes;
* lever arms from the contact point and normal, and equal to the base radii for an
  involute pair; the gear lever arm against the gear angle's numerical derivative;
* line-contact Hertz per unit width, point-contact Hertz against scipy's elliptic
  integrals (Johnson's equations, with E* = E'/2);
* ISO 6336-1 method B (q', C_B, c', c_gamma) from the polynomial of the standard;
* Weber's pair compliance of the loaded chain against the stand-alone path model;
* Ohlendorf's H_V by hand and the constant-mu sliding power by hand at every position;
* loaded TE by a second route (delta = F q, y = delta / r_b2) and its sign;
* drive/coast and member-swap symmetry of a spur pair;
* VH-CATT and preset bevel: exact Hertz and the balances by hand at the loaded contacts.

Units: mm, N, N mm, rad, MPa, W.  docs/testing.md ("Independent references for the
loaded chain") lists which slip each test catches.
"""

import math
import re

import jax.numpy as jnp
import numpy as np
import pytest
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

import gearjax as gj
from gearjax.loading.loaded_contact import (MeshTeeth, contact_stress, hertz_coefficient,
                                            lever_arms, pair_compliance, share_torque)
from gearjax.tca.path import pair_arrays
from gearjax.loading.pair_stiffness import (iso6336_mesh_stiffness, iso6336_single_stiffness,
                                            pair_compliance as path_pair_compliance)
from notebook_run import run_notebook

E_STEEL, NU = 206000.0, 0.3
E_PRIME = 2.0 / (2.0 * (1.0 - NU ** 2) / E_STEEL)       # Hamrock's E' = 2 E*, steel/steel
ALPHA = math.radians(20.0)

# ISO 6336-1:2006 method B, Table (C1..C9) -- typed from the standard
ISO_C = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193, -0.24188, 0.00529, 0.00182)


# ---------------------------------------------------------------------------------
# hand references
# ---------------------------------------------------------------------------------

def _iso_c_prime(z1, z2, x1=0.0, x2=0.0, beta=0.0, alpha_n_deg=20.0, hfp=1.25, C_M=0.8,
                 C_R=1.0):
    """ISO 6336-1 method B single stiffness c' (N/(mm um)) and q' (mm um/N) by hand."""
    zn1, zn2 = z1 / math.cos(beta) ** 3, z2 / math.cos(beta) ** 3
    C = ISO_C
    q = (C[0] + C[1] / zn1 + C[2] / zn2 + C[3] * x1 + C[4] * x1 / zn1 + C[5] * x2
         + C[6] * x2 / zn2 + C[7] * x1 ** 2 + C[8] * x2 ** 2)
    C_B = (1.0 + 0.5 * (1.2 - hfp)) * (1.0 - 0.02 * (20.0 - alpha_n_deg))
    return (1.0 / q) * C_M * C_R * C_B * math.cos(beta), q, C_B


def _hertz_johnson(F, Rx, Ry, Ep):
    """Hertz point contact by Johnson (1985) eqs. 4.37-4.39 with scipy's K, E.

    Returns (p0, semi-axis along y, semi-axis along x, approach).  E* = E'/2.
    a >= b: a along the direction of the larger relative radius."""
    Es = 0.5 * Ep
    R_big, R_small = max(Rx, Ry), min(Rx, Ry)
    A, B = 0.5 / R_big, 0.5 / R_small
    if abs(R_big / R_small - 1.0) < 1e-14:           # circle: a^3 = 3 F R_e / (4 E*)
        Re = R_big
        a = (3.0 * F * Re / (4.0 * Es)) ** (1.0 / 3.0)
        p0 = 3.0 * F / (2.0 * math.pi * a * a)
        return p0, a, a, a * a / Re

    def ratio(m):      # B/A = [(a/b)^2 E - K] / (K - E),  m = e^2,  (a/b)^2 = 1/(1 - m)
        K, E = ellipk(m), ellipe(m)
        return (E / (1.0 - m) - K) / (K - E)

    m = brentq(lambda m: math.log(ratio(m)) - math.log(B / A), 1e-12, 1.0 - 1e-15,
               xtol=1e-300, rtol=1e-15, maxiter=500)
    K, E = ellipk(m), ellipe(m)
    # A = p0 b (K - E) / (E* e^2 a^2),  p0 = 3F/(2 pi a b)  =>  a^3
    a = (3.0 * F * (K - E) / (2.0 * math.pi * A * Es * m)) ** (1.0 / 3.0)
    b = a * math.sqrt(1.0 - m)
    p0 = 3.0 * F / (2.0 * math.pi * a * b)
    delta = p0 * b * K / Es
    if Ry >= Rx:
        return p0, a, b, delta
    return p0, b, a, delta


def _force_of_approach(w, q, c):
    """Root F of q F + c F^(2/3) = w by bisection (numpy; 0 for w <= 0)."""
    if w <= 0.0:
        return 0.0
    lo, hi = 0.0, w / q
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if q * mid + c * mid ** (2.0 / 3.0) > w:
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def _hand_equilibrium(T1, g, l1, l2, q, c):
    """Fall-back y with sum_k l1_k F_k(l2_k (y - g_k)) = T1, by bisection (numpy)."""
    def H(y):
        return sum(l1[k] * _force_of_approach(l2[k] * (y - g[k]), q[k], c[k])
                   for k in range(len(g))) - T1
    lo, hi = 0.0, 1.0
    while H(hi) < 0.0:
        hi *= 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if H(mid) > 0.0:
            hi = mid
        else:
            lo = mid
    y = 0.5 * (lo + hi)
    F = [_force_of_approach(l2[k] * (y - g[k]), q[k], c[k]) for k in range(len(g))]
    return y, np.array(F)


# ---------------------------------------------------------------------------------
# load sharing by hand (gearjax.loading.loaded_contact.share_torque)
# ---------------------------------------------------------------------------------

T1 = 1.5e5                                   # N mm
L1 = np.array([31.0, 28.5])                  # distinct lever arms per pair (mm)
L2 = np.array([63.0, 55.5])
Q = np.array([1.1e-5, 1.7e-5])               # mm/N


@pytest.mark.parametrize("drive", [True, False])
def test_two_pair_linear_equilibrium_by_hand(drive):
    """Two linear tooth springs, pair 1 leading, pair 0 trailing by a gap g.

    Hand: w_k = l2_k (y - g_k), F_k = w_k / q_k, sum l1_k F_k = T1 gives
    y = (T1 + sum l1 l2 g / q) / sum(l1 l2 / q) (both touching); one pair alone
    y = q T1 / (l1 l2) when the gap stays open."""
    s = 1.0 if drive else -1.0
    env_te = 3.0e-6
    gaps = np.array([2.0e-6, 5.0e-3])               # rad: closed by the load / left open
    te = np.array([[env_te - s * gaps[0], env_te - s * gaps[1]], [env_te, env_te]])
    act = np.ones((2, 2), bool)
    rep = lambda v: jnp.asarray(np.repeat(v[:, None], 2, axis=1))  # noqa: E731
    env, y, F, w, bal, conv = share_torque(jnp.asarray(te), jnp.asarray(act), rep(L1), rep(L2),
                                           rep(Q), jnp.zeros((2, 2)), T1, drive)
    assert np.all(np.asarray(conv))
    np.testing.assert_allclose(env, [env_te, env_te], rtol=1e-14)
    k = L1 * L2 / Q
    g = np.array([gaps[0], 0.0])
    y_both = (T1 + np.sum(k * g)) / np.sum(k)
    assert y_both > gaps[0]
    F_both = L2 * (y_both - g) / Q
    np.testing.assert_allclose(y[0], y_both, rtol=1e-11)
    np.testing.assert_allclose(F[:, 0], F_both, rtol=1e-10)
    np.testing.assert_allclose(w[:, 0], L2 * (y_both - g), rtol=1e-10)
    # single pair: the gap stays open
    y1 = Q[1] * T1 / (L1[1] * L2[1])
    np.testing.assert_allclose(y[1], y1, rtol=1e-11)
    np.testing.assert_allclose(F[:, 1], [0.0, T1 / L1[1]], rtol=1e-11, atol=0.0)
    np.testing.assert_allclose(w[0, 1], L2[0] * (y1 - gaps[1]), rtol=1e-11)
    # moments about the pinion axis balance T1; about the gear axis the hand sum
    Fn = np.asarray(F)
    np.testing.assert_allclose(L1 @ Fn, [T1, T1], rtol=1e-11)
    assert np.all(np.asarray(bal) <= 1e-10)


def test_two_pair_hertz_equilibrium_by_hand():
    """Linear + Hertz springs q F + c F^(2/3) = w, equilibrium by bisection in numpy;
    c from the circular Hertz closed form (delta = a^2/R at 1 N)."""
    R = 9.0
    a1 = (3.0 * 1.0 * R / (4.0 * 0.5 * E_PRIME)) ** (1.0 / 3.0)
    c_circ = a1 * a1 / R                                      # mm / N^(2/3)
    c = np.array([c_circ, 1.7 * c_circ])
    g = np.array([1.5e-6, 0.0])
    te = np.array([[-g[0]], [0.0]])
    y_ref, F_ref = _hand_equilibrium(T1, g, L1, L2, Q, c)
    assert np.all(F_ref > 0.0)
    env, y, F, w, bal, conv = share_torque(jnp.asarray(te), jnp.ones((2, 1), bool),
                                           jnp.asarray(L1[:, None]), jnp.asarray(L2[:, None]),
                                           jnp.asarray(Q[:, None]), jnp.asarray(c[:, None]),
                                           T1, True)
    assert bool(conv[0])
    np.testing.assert_allclose(y[0], y_ref, rtol=1e-9)
    np.testing.assert_allclose(F[:, 0], F_ref, rtol=1e-8)
    # the library's Hertz coefficient for the same circle equals the closed form
    np.testing.assert_allclose(hertz_coefficient(R, R, E_PRIME), c_circ, rtol=1e-10)


def test_lever_arms_from_point_and_normal():
    """l1 = |(r x n) . z| by numpy's cross product; l2 = l1 / |dphi2/dphi1|."""
    rng = np.random.default_rng(3)
    p = rng.normal(size=(5, 3)) * 40.0
    n = rng.normal(size=(5, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    ratio = np.array([-0.5, 0.25, -2.0, 1.3, -0.77])
    l1, l2 = lever_arms(jnp.asarray(p), jnp.asarray(n), jnp.asarray(ratio))
    l1_ref = np.abs(np.cross(p, n)[:, 2])
    np.testing.assert_allclose(l1, l1_ref, rtol=1e-13)
    np.testing.assert_allclose(l2, l1_ref / np.abs(ratio), rtol=1e-13)


# ---------------------------------------------------------------------------------
# Hertz
# ---------------------------------------------------------------------------------

def test_line_contact_hertz_per_unit_width():
    """p_max = sqrt(w' E' / (2 pi R)), b = sqrt(8 w' R / (pi E')) with w' = F / L."""
    F = np.array([800.0, 5000.0, 0.0])
    L = np.array([10.0, 30.0, 30.0])
    R = np.array([7.5, 12.0, 12.0])
    p, a, b = contact_stress(jnp.asarray(F), jnp.asarray(R), jnp.inf, E_PRIME,
                             line_length=jnp.asarray(L))
    wp = F[:2] / L[:2]
    np.testing.assert_allclose(p[:2], np.sqrt(wp * E_PRIME / (2 * np.pi * R[:2])), rtol=1e-13)
    np.testing.assert_allclose(b[:2], np.sqrt(8 * wp * R[:2] / (np.pi * E_PRIME)), rtol=1e-13)
    np.testing.assert_allclose(a[:2], L[:2] / 2, rtol=1e-15)
    assert float(p[2]) == 0.0 and float(a[2]) == 0.0 and float(b[2]) == 0.0
    # the pressure integrates to the load: (pi/2) p_max b L = F
    np.testing.assert_allclose(0.5 * np.pi * p[:2] * b[:2] * L[:2], F[:2], rtol=1e-13)


@pytest.mark.parametrize("Rx, Ry", [(10.0, 10.0), (8.0, 40.0), (5.0, 900.0), (60.0, 12.0)])
def test_point_contact_hertz_against_scipy_elliptic_integrals(Rx, Ry):
    F = 2300.0
    p_ref, ay_ref, bx_ref, d_ref = _hertz_johnson(F, Rx, Ry, E_PRIME)
    p, a, b = contact_stress(jnp.asarray([F]), jnp.asarray([Rx]), jnp.asarray([Ry]), E_PRIME)
    np.testing.assert_allclose(p[0], p_ref, rtol=1e-9)
    np.testing.assert_allclose(a[0], ay_ref, rtol=1e-9)
    np.testing.assert_allclose(b[0], bx_ref, rtol=1e-9)
    # p_max = 3F / (2 pi a b)
    np.testing.assert_allclose(p[0], 3 * F / (2 * np.pi * a[0] * b[0]), rtol=1e-12)
    # approach: delta = c F^(2/3) with the library's coefficient
    c = float(hertz_coefficient(Rx, Ry, E_PRIME))
    np.testing.assert_allclose(c * F ** (2.0 / 3.0), d_ref, rtol=1e-9)


# ---------------------------------------------------------------------------------
# ISO 6336-1 and Weber compliance
# ---------------------------------------------------------------------------------

ISO_CASES = [  # z1, z2, x1, x2, beta (deg), alpha_n (deg), hfp
    (20, 40, 0.0, 0.0, 0.0, 20.0, 1.25),
    (17, 71, 0.3, -0.1, 0.0, 20.0, 1.25),
    (23, 57, 0.2, 0.1, 15.0, 22.5, 1.4),
    (31, 31, 0.0, 0.0, 30.0, 17.5, 1.2),
]


@pytest.mark.parametrize("case", ISO_CASES)
def test_iso6336_single_and_mesh_stiffness_from_the_standard(case):
    z1, z2, x1, x2, bd, ad, hfp = case
    beta = math.radians(bd)
    c_ref, q_ref, CB_ref = _iso_c_prime(z1, z2, x1, x2, beta, ad, hfp)
    r = iso6336_single_stiffness(z1, z2, x1, x2, beta, math.radians(ad), hfp)
    np.testing.assert_allclose(r.q_prime, q_ref, rtol=1e-13)
    np.testing.assert_allclose(r.C_B, CB_ref, rtol=1e-13)
    np.testing.assert_allclose(r.c_prime, c_ref, rtol=1e-13)
    # the standard's order of magnitude: c' about 11-17 N/(mm um) for steel pairs
    assert 10.0 < c_ref < 18.0
    np.testing.assert_allclose(iso6336_mesh_stiffness(c_ref, 1.6), c_ref * (0.75 * 1.6 + 0.25),
                               rtol=1e-14)


def _spur_teeth(z1, z2, r_load, width, line_length):
    n = r_load.shape[1]
    one = jnp.ones(2)
    return MeshTeeth(jnp.asarray([float(z1), float(z2)]), 4.0, ALPHA * one, 0.0, 0.0 * one,
                     one, 1.25 * one, jnp.asarray(r_load), jnp.full(n, width),
                     None if line_length is None else jnp.full(n, line_length), True)


def test_loaded_chain_iso_compliance_is_the_standard_over_the_width():
    """q = 1e-3 / (c' b) (mm/N) with c' of the standard (constant along the path)."""
    z1, z2, b = 20, 40, 30.0
    r = np.array([[40.0, 42.0], [78.0, 76.0]])
    q = pair_compliance(_spur_teeth(z1, z2, r, b, b), jnp.ones(2), 100.0, "iso6336")
    c_ref = _iso_c_prime(z1, z2)[0]
    np.testing.assert_allclose(q, 1e-3 / (c_ref * b), rtol=1e-12)


def test_loaded_chain_weber_compliance_is_the_path_model_over_the_width():
    """The line-contact Weber compliance of the loaded chain (mm/N) equals the
    stand-alone path model of gearjax.loading.tooth_compliance (mm^2/N, per unit width) over
    the face width, at the same roll positions and load per unit width: two routes
    to the contact radii (hand involute geometry here, the path model there) and to
    the Hertz depths h = y_m / cos(alpha_m) of Weber's contact term."""
    z1, z2, m, b = 20, 40, 4.0, 30.0
    wp = 180.0                                               # N/mm
    s = np.array([-5.0, -1.0, 0.0, 2.5, 6.0])                # mm from the pitch point
    rb1, rb2 = 0.5 * m * z1 * math.cos(ALPHA), 0.5 * m * z2 * math.cos(ALPHA)
    rho1 = rb1 * math.tan(ALPHA) + s
    rho2 = rb2 * math.tan(ALPHA) - s
    r = np.stack([np.hypot(rb1, rho1), np.hypot(rb2, rho2)])
    Rred = rho1 * rho2 / (rho1 + rho2)
    q = pair_compliance(_spur_teeth(z1, z2, r, b, b), jnp.asarray(Rred), wp, "weber")
    ref = path_pair_compliance(jnp.asarray(s), z1, z2, m, ALPHA, load_per_width=wp)
    np.testing.assert_allclose(ref.r1, r[0], rtol=1e-12)
    np.testing.assert_allclose(q, np.asarray(ref.total) / b, rtol=1e-10)
    # a point contact (no line) has no contact term: the teeth alone
    qp = pair_compliance(_spur_teeth(z1, z2, r, 12.0, None), jnp.asarray(Rred), wp, "weber")
    np.testing.assert_allclose(qp, (np.asarray(ref.tooth1) + np.asarray(ref.tooth2)) / 12.0,
                               rtol=1e-10)


# ---------------------------------------------------------------------------------
# a spur pair through gearjax.loading.mesh_efficiency (ISO compliance: constant along the path)
# ---------------------------------------------------------------------------------

SZ1, SZ2, SM, SB = 20, 40, 4.0, 30.0
TORQUE_NM, RPM = 200.0, 1500.0


def _spur_hand(z1, z2, m=SM):
    """Involute geometry of a standard spur pair (x = 0, ha = 1) by hand."""
    rb1, rb2 = 0.5 * m * z1 * math.cos(ALPHA), 0.5 * m * z2 * math.cos(ALPHA)
    ra1, ra2 = 0.5 * m * z1 + m, 0.5 * m * z2 + m
    a = 0.5 * m * (z1 + z2)
    rho_P = rb1 * math.tan(ALPHA)                          # pinion roll distance at the pitch point
    rho_E = math.sqrt(ra1 ** 2 - rb1 ** 2)                 # end of contact (pinion tip)
    rho_A = a * math.sin(ALPHA) - math.sqrt(ra2 ** 2 - rb2 ** 2)   # start (gear tip)
    p_b = math.pi * m * math.cos(ALPHA)
    return dict(rb1=rb1, rb2=rb2, a=a, rho_P=rho_P, rho_E=rho_E, rho_A=rho_A, p_b=p_b,
                eps=(rho_E - rho_A) / p_b)


@pytest.fixture(scope="module")
def oil_surface():
    return gj.tribology.get_oil(gj.tribology.OILS[0]), gj.tribology.make_surface(0.4)


def _spur_run(z1, z2, torque, side, oil_surface):
    des = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(z1, z2, SM, 20.0), SB)
    kw = {} if side is None else {"side": side}
    return gj.mesh_efficiency(des, torque, RPM, *oil_surface, compliance="iso6336", **kw)


@pytest.fixture(scope="module")
def spur_drive(oil_surface):
    return _spur_run(SZ1, SZ2, TORQUE_NM, None, oil_surface)


@pytest.fixture(scope="module")
def spur_coast(oil_surface):
    return _spur_run(SZ1, SZ2, TORQUE_NM, "coast", oil_surface)


@pytest.fixture(scope="module")
def spur_swapped(oil_surface):
    # the 40-tooth member drives with the torque that gives the same normal load
    return _spur_run(SZ2, SZ1, TORQUE_NM * SZ2 / SZ1, None, oil_surface)


def _per_pair(res, eff, arr, fill=np.nan):
    """Pair-0 grid quantity -> (K, M) values of the pairs at the cycle's positions."""
    from gearjax.loading.mesh_efficiency import cycle_window
    spp, K = eff.phi1.shape[0], eff.loaded.load.shape[0]
    win = cycle_window(res.path.phi1.shape[0], spp)
    return np.asarray(pair_arrays(jnp.asarray(arr), spp, K, fill, win))


def _hand_spur_loads(run, z1, z2, torque_Nm):
    """Hand loads of the cycle: roll distance of each pair from its pinion radius, the
    pairs inside [rho_A, rho_E] share T1 / r_b1 equally (equal constant stiffness,
    zero unloaded TE).  Returns (s, in_contact, F_hand, hand geometry)."""
    eff, res = run
    h = _spur_hand(z1, z2)
    r1 = _per_pair(res, eff, res.path.radial1)
    rho1 = np.sqrt(np.maximum(r1 ** 2 - h["rb1"] ** 2, 0.0))
    inside = (rho1 >= h["rho_A"] - 1e-9) & (rho1 <= h["rho_E"] + 1e-9) & np.isfinite(r1)
    n = inside.sum(axis=0)
    F_tot = 1e3 * torque_Nm / h["rb1"]
    F = np.where(inside, F_tot / np.maximum(n, 1), 0.0)
    # positions exactly at a transfer point are ambiguous on the grid: left out
    edge = np.any(np.isfinite(r1) & ((np.abs(rho1 - h["rho_A"]) < 1e-7)
                                     | (np.abs(rho1 - h["rho_E"]) < 1e-7)), axis=0)
    return rho1 - h["rho_P"], inside, F, ~edge, h


def test_spur_lever_arms_are_the_base_radii(spur_drive):
    """Involute pair: the normal force acts along the line of action, tangent to both
    base circles -- its moment arms about the two axes are r_b1 and r_b2 (hand), and
    the gear ratio is the negative tooth ratio, also by differencing the gear angle."""
    eff, res = spur_drive
    h = _spur_hand(SZ1, SZ2)
    on = np.asarray(res.on_flank)
    l1, l2 = lever_arms(res.path.point, res.path.normal, res.kinematics.gear_ratio)
    np.testing.assert_allclose(np.asarray(l1)[on], h["rb1"], rtol=1e-9)
    np.testing.assert_allclose(np.asarray(l2)[on], h["rb2"], rtol=1e-9)
    phi1, phi2 = np.asarray(res.path.phi1), np.asarray(res.path.phi2)
    dphi = np.gradient(phi2, phi1)
    np.testing.assert_allclose(dphi[on], -SZ1 / SZ2, rtol=1e-8)


def test_spur_loads_and_loaded_te_by_second_route(spur_drive):
    """Single pair: F = T1 / r_b1, delta = q F, y = delta / r_b2; double contact: two
    equal springs in parallel.  q = 1e-3 / (c' b) with c' of ISO 6336-1 by hand.  The
    loaded TE lies behind the unloaded envelope (~0 for a conjugate pair) by y, the
    gear falling back under the load on the drive side: te_loaded = -y."""
    eff, res = spur_drive
    s, inside, F_hand, ok, h = _hand_spur_loads(spur_drive, SZ1, SZ2, TORQUE_NM)
    F = np.asarray(eff.loaded.load)
    n = inside.sum(axis=0)
    assert np.all(np.asarray(eff.valid)) and set(n[ok].tolist()) == {1, 2}
    np.testing.assert_allclose(F[:, ok], F_hand[:, ok], rtol=1e-9, atol=1e-9)
    q = 1e-3 / (_iso_c_prime(SZ1, SZ2)[0] * SB)                     # mm/N
    F_tot = 1e3 * TORQUE_NM / h["rb1"]
    delta = q * F_tot / n                                             # approach of each pair
    y_ref = delta / h["rb2"]
    np.testing.assert_allclose(np.asarray(eff.loaded.deflection)[ok], y_ref[ok], rtol=1e-9)
    w = np.asarray(eff.loaded.approach)
    np.testing.assert_allclose(np.where(inside, w, 0.0)[:, ok],
                               np.where(inside, delta[None, :], 0.0)[:, ok], rtol=1e-9, atol=1e-15)
    te_unloaded = np.nanmax(np.where(inside, _per_pair(res, eff, res.path.te), np.nan), axis=0)
    assert np.all(np.abs(te_unloaded[ok]) < 1e-12)
    np.testing.assert_allclose(np.asarray(eff.loaded.te_loaded)[ok], (te_unloaded - y_ref)[ok],
                               rtol=1e-9, atol=1e-15)
    assert np.all(np.asarray(eff.loaded.te_loaded)[ok] < 0.0)


def test_spur_line_hertz_and_torque_balance_in_the_run(spur_drive):
    """p_max = sqrt(w' E' / (2 pi R)) with w' = F / b (load per unit face width) and
    R = rho1 rho2 / (rho1 + rho2) from the roll distances (hand); moments of the
    loads about both axes: sum F r_b1 = T1, sum F r_b2 = T2 = T1 z2 / z1."""
    eff, res = spur_drive
    s, inside, F_hand, ok, h = _hand_spur_loads(spur_drive, SZ1, SZ2, TORQUE_NM)
    F = np.asarray(eff.loaded.load)
    loaded = F > 0.0
    rho1 = h["rho_P"] + s
    rho2 = h["a"] * math.sin(ALPHA) - rho1
    R = rho1 * rho2 / (rho1 + rho2)
    p_ref = np.sqrt(F / SB * E_PRIME / (2.0 * np.pi * np.where(loaded, R, 1.0)))
    p = np.asarray(eff.loaded.p_max)
    np.testing.assert_allclose(p[loaded], p_ref[loaded], rtol=1e-8)
    assert np.all(p[~loaded] == 0.0)
    b_ref = np.sqrt(8.0 * F / SB * np.where(loaded, R, 1.0) / (np.pi * E_PRIME))
    np.testing.assert_allclose(np.asarray(eff.loaded.semi_minor)[loaded], b_ref[loaded],
                               rtol=1e-8)
    T1 = 1e3 * TORQUE_NM
    np.testing.assert_allclose(h["rb1"] * F.sum(axis=0), T1, rtol=1e-10)
    np.testing.assert_allclose(h["rb2"] * F.sum(axis=0), T1 * SZ2 / SZ1, rtol=1e-10)
    np.testing.assert_allclose(np.asarray(eff.loaded.share).sum(axis=0), 1.0, rtol=1e-10)


def test_spur_power_balance_and_ohlendorf_by_hand(spur_drive):
    """P_in = T omega; eta_m = 1 - P_f/P_in, P_f = sum mu F |u_s|.  At constant mu the
    sliding power sum F |u_s| at every position equals the hand value with the hand
    loads and |u_s| = omega1 (1 + z1/z2) |s|; its mean over the cycle is
    H_V P_in / mu of Ohlendorf (H_V by hand), up to the grid's discretisation."""
    eff, res = spur_drive
    omega = RPM * math.pi / 30.0
    P_in = TORQUE_NM * omega
    np.testing.assert_allclose(eff.power_in, P_in, rtol=1e-13)
    P_f = np.asarray(eff.power_loss)
    np.testing.assert_allclose(np.asarray(eff.efficiency), 1.0 - P_f / P_in, rtol=1e-13)
    F = np.asarray(eff.loaded.load)
    us = np.asarray(eff.u_s)                                         # mm/s
    mu = np.asarray(eff.friction.mu)
    np.testing.assert_allclose(P_f, 1e-3 * np.sum(mu * F * us, axis=0), rtol=1e-9)
    np.testing.assert_allclose(float(eff.mean_efficiency), 1.0 - P_f.mean() / P_in, rtol=1e-12)
    # constant-mu sliding power by hand
    s, inside, F_hand, ok, h = _hand_spur_loads(spur_drive, SZ1, SZ2, TORQUE_NM)
    us_hand = omega * (1.0 + SZ1 / SZ2) * np.abs(s)
    P_hand = 1e-3 * np.sum(np.where(inside, F_hand * us_hand, 0.0), axis=0)      # W per unit mu
    P_lib = 1e-3 * np.sum(F * us, axis=0)
    np.testing.assert_allclose(P_lib[ok], P_hand[ok], rtol=1e-6, atol=1e-9 * P_hand.max())
    # Ohlendorf: H_V = pi (u + 1)/(z1 u) (1 - eps + eps1^2 + eps2^2)
    u = SZ2 / SZ1
    e1 = (h["rho_E"] - h["rho_P"]) / h["p_b"]
    e2 = (h["rho_P"] - h["rho_A"]) / h["p_b"]
    H_V = math.pi * (u + 1.0) / (SZ1 * u) * (1.0 - h["eps"] + e1 ** 2 + e2 ** 2)
    from gearjax.gears.involute.mesh import ohlendorf_loss_factor
    np.testing.assert_allclose(ohlendorf_loss_factor(gj.involute.InvolutePair.create(SZ1, SZ2, SM, 20.0)),
                               H_V, rtol=1e-12)
    # the cycle mean of a piecewise-linear loss on 24 positions: within 2 % of the integral
    assert abs(P_lib.mean() / (H_V * P_in) - 1.0) < 0.02


def test_spur_drive_coast_symmetry(spur_drive, spur_coast):
    """A symmetric pair: the coast side carries the same loads, pressures and
    fall-back as the drive side (positions mirrored), and the loaded TE lies on the
    other side of the envelope (te_loaded = +y on coast)."""
    (d, _), (c, _) = spur_drive, spur_coast
    for name in ("load", "p_max", "approach"):
        a = np.sort(np.asarray(getattr(d.loaded, name)).ravel())
        b = np.sort(np.asarray(getattr(c.loaded, name)).ravel())
        np.testing.assert_allclose(b, a, rtol=1e-8, atol=1e-12, err_msg=name)
    np.testing.assert_allclose(np.sort(np.asarray(c.loaded.deflection)),
                               np.sort(np.asarray(d.loaded.deflection)), rtol=1e-8)
    y = np.asarray(c.loaded.deflection)
    np.testing.assert_allclose(np.asarray(c.loaded.te_loaded), y, rtol=1e-9, atol=1e-15)
    assert np.all(np.asarray(c.loaded.te_loaded) > 0.0)
    np.testing.assert_allclose(float(c.mean_efficiency), float(d.mean_efficiency), rtol=1e-6)


def test_spur_member_swap(spur_drive, spur_swapped):
    """Swap the members (the 40-tooth gear drives at T1 z2/z1): the normal loads
    and contact pressures are those of the original pair (same line of action), the
    compliance is ISO's q' with z1, z2 swapped, and the fall-back is now measured on
    the 20-tooth member: y = q F / r_b(20) (hand)."""
    (d, _), (w, _) = spur_drive, spur_swapped
    F_tot = 1e3 * TORQUE_NM / _spur_hand(SZ1, SZ2)["rb1"]
    s, inside, F_hand, ok, h = _hand_spur_loads(spur_swapped, SZ2, SZ1, TORQUE_NM * SZ2 / SZ1)
    np.testing.assert_allclose(np.asarray(w.loaded.load).sum(axis=0), F_tot, rtol=1e-10)
    np.testing.assert_allclose(np.asarray(w.loaded.load)[:, ok], F_hand[:, ok], rtol=1e-9,
                               atol=1e-9)
    n = inside.sum(axis=0)
    q_sw = 1e-3 / (_iso_c_prime(SZ2, SZ1)[0] * SB)
    y_ref = q_sw * F_tot / n / h["rb2"]
    assert math.isclose(h["rb2"], _spur_hand(SZ1, SZ2)["rb1"])
    np.testing.assert_allclose(np.asarray(w.loaded.deflection)[ok], y_ref[ok], rtol=1e-9)
    # pressures: the same set of line-contact pressures as the pair driven the other
    # way round (sorted over the cycle; both grids sample the same path)
    pd = np.sort(np.asarray(d.loaded.p_max).ravel())
    pw = np.sort(np.asarray(w.loaded.p_max).ravel())
    np.testing.assert_allclose(pw.max(), pd.max(), rtol=0.05)
    np.testing.assert_allclose(pw[pw > 0].min(), pd[pd > 0].min(), rtol=0.05)


# ---------------------------------------------------------------------------------
# VH-CATT: the loaded contact by hand at the loaded contact points
# ---------------------------------------------------------------------------------

VH_TORQUE, VH_RPM = 100.0, 1000.0
# the example file's [material] (E 203 GPa, nu 0.3), which sets E' and the tooth
# compliance of its loaded contact: E' = E/(1 - nu^2) of two equal members
VH_E, VH_NU = 203000.0, 0.3
VH_E_PRIME = VH_E / (1.0 - VH_NU ** 2)


@pytest.fixture(scope="module")
def vh_run(oil_surface):
    des = gj.load_design("example:vh_catt_17x23")
    return des.pair, gj.mesh_efficiency(des, VH_TORQUE, VH_RPM, *oil_surface)


def test_vh_catt_hertz_by_hand_at_the_loaded_contacts(vh_run):
    """Exact Hertz (scipy elliptic integrals, Johnson's equations) of each loaded
    contact from the library's load and principal relative radii."""
    pair, (eff, res) = vh_run
    F = np.asarray(eff.loaded.load)
    rx = _per_pair(res, eff, res.kinematics.r_x)
    ry = _per_pair(res, eff, res.kinematics.r_y)
    loaded = F > 0.0
    assert np.all(np.asarray(eff.valid)) and loaded.sum() >= 24
    p, a, b = (np.asarray(v) for v in (eff.loaded.p_max, eff.loaded.semi_major,
                                       eff.loaded.semi_minor))
    for k, j in zip(*np.nonzero(loaded)):
        p_ref, ay, bx, _ = _hertz_johnson(F[k, j], rx[k, j], ry[k, j], VH_E_PRIME)
        np.testing.assert_allclose([p[k, j], a[k, j], b[k, j]], [p_ref, ay, bx], rtol=1e-8)


def _arms_and_balances(res, eff, T1, ratio, rtol_gear):
    """Moment arms of every loaded pair by hand -- about the pinion axis (z) from the
    contact point and normal (numpy cross product), about the gear axis l1 / |dphi2/dphi1|
    with the derivative by differencing the TCA's gear angle -- and the moment balances
    sum l1 F = T1 (N mm) and sum l2 F = T1 ratio.  Returns (l1, l2) per pair."""
    F = np.asarray(eff.loaded.load)
    loaded = F > 0.0
    pt, nn = np.asarray(res.path.point), np.asarray(res.path.normal)
    l1_0 = np.abs(np.cross(pt, nn)[:, 2])
    dphi = np.gradient(np.asarray(res.path.phi2), np.asarray(res.path.phi1))
    l1 = _per_pair(res, eff, l1_0)
    l2 = _per_pair(res, eff, l1_0 / np.abs(dphi))
    np.testing.assert_allclose(np.sum(np.where(loaded, l1 * F, 0.0), axis=0), T1, rtol=1e-7)
    np.testing.assert_allclose(np.sum(np.where(loaded, l2 * F, 0.0), axis=0), T1 * ratio,
                               rtol=rtol_gear)
    return l1, l2


def _single_contact(eff, l2, min_positions, rtol):
    """Single-contact positions: (pair index k, position j, approach w, fall-back y) of
    the one loaded pair, after checking w = l2 y (the gear's fall-back seen along the
    normal at its arm)."""
    F = np.asarray(eff.loaded.load)
    single = (F > 0.0).sum(axis=0) == 1
    assert single.sum() >= min_positions
    j = np.nonzero(single)[0]
    k = np.argmax(F, axis=0)[j]
    w = np.asarray(eff.loaded.approach)[k, j]
    y = np.asarray(eff.loaded.deflection)[j]
    np.testing.assert_allclose(w / y, l2[k, j], rtol=rtol)
    return k, j, w, y


def test_vh_catt_lever_arms_balances_and_approach_by_hand(vh_run):
    """Aligned VH-CATT pair: the contact lies in the middle section, an exact involute,
    so the normal force's moment arm about the pinion axis is r_b1 = m z1 cos(alpha)/2
    (hand, from the point and normal by numpy's cross product); about the gear axis
    l2 = l1 / |dphi2/dphi1| with the derivative by differencing the TCA's gear angle.
    Moments: sum l1 F = T1 and sum l2 F = T1 z2 / z1 (power balance).  In single
    contact the approach is q F + delta_Hertz(F): q from the two teeth's compliance
    over the loaded width, delta_Hertz by scipy."""
    pair, (eff, res) = vh_run
    from gearjax.loading.tooth_compliance import tooth_compliance
    z1, z2 = int(pair.z1), int(pair.z2)
    m, al, bw = float(pair.module), float(pair.pressure_angle), float(pair.face_width)
    F = np.asarray(eff.loaded.load)
    loaded = F > 0.0
    l1, l2 = _arms_and_balances(res, eff, 1e3 * VH_TORQUE, z2 / z1, 1e-6)
    rb1 = 0.5 * m * z1 * math.cos(al)
    np.testing.assert_allclose(l1[loaded], rb1, rtol=1e-7)
    # single contact: the leading pair (gap 0) has w = l2 y
    kk, j, w, y = _single_contact(eff, l2, 5, 1e-6)
    k = np.zeros(F.shape[1], int)
    k[j] = kk
    # the approach by the compliance route
    rad1 = _per_pair(res, eff, res.path.radial1)[k[j], j]
    rad2 = _per_pair(res, eff, res.path.radial2)[k[j], j]
    width = np.minimum(2.0 * _per_pair(res, eff, res.path.semi_major)[k[j], j], bw)
    rx = _per_pair(res, eff, res.kinematics.r_x)[k[j], j]
    ry = _per_pair(res, eff, res.kinematics.r_y)[k[j], j]
    for i, jj in enumerate(j):
        Fi = F[k[jj], jj]
        q = (float(tooth_compliance(rad1[i], z1, m, al, 0.0, 1.0, 1.25, E=VH_E, nu=VH_NU).total)
             + float(tooth_compliance(rad2[i], z2, m, al, 0.0, 1.0, 1.25, E=VH_E, nu=VH_NU).total)) / width[i]
        w_ref = q * Fi + _hertz_johnson(Fi, rx[i], ry[i], VH_E_PRIME)[3]
        np.testing.assert_allclose(w[i], w_ref, rtol=1e-7)
    # the loaded TE lies behind the unloaded envelope by y (drive)
    te = np.where(loaded, _per_pair(res, eff, res.path.te), -np.inf).max(axis=0)
    np.testing.assert_allclose(np.asarray(eff.loaded.te_loaded)[j], te[j] - y, rtol=1e-9)


# ---------------------------------------------------------------------------------
# involute: the virtual spur teeth of ISO 6336-1 by hand
# ---------------------------------------------------------------------------------

def test_involute_mesh_teeth_by_hand():
    """MeshTeeth of a crowned helical pair with a pinion pressure-angle change, from a
    path given by hand (contact radii and ellipse semi-axes): z_n = z / (cos^2(beta_b)
    cos(beta)), the normal module, the pinion's normal pressure angle alpha_n + dalpha
    (its rack's, InvoluteTCA docstring) and the gear's alpha_n, the load radius at the
    same height over the reference circle on the virtual gear, and the load-carrying
    width of a point contact: the full major axis 2a of the contact ellipse, at most b.
    A spur pair in line contact carries its load over b along a line of length b.
    Planted bugs caught: the width set to the semi-axis a, the sign of dalpha, the
    virtual tooth numbers of the transverse section."""
    from types import SimpleNamespace
    from gearjax.gears.involute.mesh import involute_mesh_teeth
    z1, z2, m, an, bd, b, dad = 19, 53, 3.0, 20.0, 17.0, 24.0, 0.4
    des = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(z1, z2, m, an, bd, 0.25, -0.1), b,
                                dalpha_deg=dad, lead_crown=2e-4)
    beta, alpha_n = math.radians(bd), math.radians(an)
    alpha_t = math.atan(math.tan(alpha_n) / math.cos(beta))
    beta_b = math.atan(math.tan(beta) * math.cos(alpha_t))
    r1_ref, r2_ref = 0.5 * z1 * m / math.cos(beta), 0.5 * z2 * m / math.cos(beta)
    semi = np.array([2.0, 7.5, 11.9, 12.1, 40.0])
    path = SimpleNamespace(phi1=np.zeros(5), radial1=r1_ref + np.linspace(-2.0, 2.5, 5),
                           radial2=r2_ref + np.linspace(2.0, -2.5, 5), semi_major=semi)
    t = involute_mesh_teeth(des, SimpleNamespace(path=path), False, True)
    zn = [z / (math.cos(beta_b) ** 2 * math.cos(beta)) for z in (z1, z2)]
    np.testing.assert_allclose(t.z, zn, rtol=1e-12)
    np.testing.assert_allclose(t.module, m, rtol=1e-14)
    np.testing.assert_allclose(t.alpha, [alpha_n + math.radians(dad), alpha_n], rtol=1e-12)
    np.testing.assert_allclose(t.beta, beta, rtol=1e-14)
    np.testing.assert_allclose(t.x, [0.25, -0.1], rtol=1e-14)
    np.testing.assert_allclose(t.r_load[0], 0.5 * zn[0] * m + (path.radial1 - r1_ref), rtol=1e-12)
    np.testing.assert_allclose(t.r_load[1], 0.5 * zn[1] * m + (path.radial2 - r2_ref), rtol=1e-12)
    np.testing.assert_allclose(t.width, [4.0, 15.0, 23.8, 24.0, 24.0], rtol=1e-14)
    assert t.line_length is None and bool(t.drive)
    spur = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(z1, z2, m, an), b)
    t = involute_mesh_teeth(spur, SimpleNamespace(path=path), True, False)
    np.testing.assert_allclose(t.width, b, rtol=1e-14)
    np.testing.assert_allclose(t.line_length, b, rtol=1e-14)
    assert not bool(t.drive)


# ---------------------------------------------------------------------------------
# preset bevel: the virtual cylindrical teeth of ISO 10300-1 by hand
# ---------------------------------------------------------------------------------

def test_preset_bevel_virtual_teeth_by_hand(pb_run):
    """MeshTeeth of the preset-TE bevel pair against ISO 10300-1 by hand: pitch
    angles, mean cone distance R_m = A_o - b/2, m_mn = 2 R_m sin(delta1) cos(beta)/z1,
    z_vn = z / (cos(delta) cos^2(beta_vb) cos(beta)), the load radius r_v = z_vn m_mn/2
    + h, the heights over m_mn and the loaded width min(2 a, b).  On the TCA of the
    loaded run below (the family's default grid; one TCA program for the module)."""
    from gearjax.gears.preset_bevel.mesh import preset_mesh_teeth
    des, (_, res) = pb_run
    t = preset_mesh_teeth(des, res, True)
    z1, z2 = des.z1, des.z2
    S, beta, an = float(des.shaft_angle), float(des.beta), float(des.alpha_n)
    d1 = math.atan(math.sin(S) / (z2 / z1 + math.cos(S)))
    d2 = S - d1
    Ao = float(des.module_t) * z1 / (2.0 * math.sin(d1))
    np.testing.assert_allclose(Ao * math.sin(d2) * 2.0 / z2, float(des.module_t), rtol=1e-12)
    Rm = Ao - 0.5 * float(des.face_width)
    m_mn = 2.0 * Rm * math.sin(d1) * math.cos(beta) / z1
    bvb = math.asin(math.sin(beta) * math.cos(an))
    zvn = [z / (math.cos(d) * math.cos(bvb) ** 2 * math.cos(beta)) for z, d in ((z1, d1), (z2, d2))]
    np.testing.assert_allclose(t.module, m_mn, rtol=1e-12)
    np.testing.assert_allclose(t.z, zvn, rtol=1e-12)
    np.testing.assert_allclose(t.alpha, [an, an], rtol=1e-14)
    np.testing.assert_allclose(t.beta, beta, rtol=1e-14)
    np.testing.assert_allclose(t.ha, float(des.addendum) / m_mn, rtol=1e-12)
    np.testing.assert_allclose(t.hf, float(des.dedendum) / m_mn + 0.25, rtol=1e-12)
    ok = np.asarray(res.path.converged) & np.isfinite(np.asarray(res.coords["h1"]))
    for i, key in ((0, "h1"), (1, "h2")):
        r_ref = 0.5 * zvn[i] * m_mn + np.asarray(res.coords[key])
        np.testing.assert_allclose(np.asarray(t.r_load[i])[ok], r_ref[ok], rtol=1e-12)
    a = np.asarray(res.path.semi_major)
    fin = ok & np.isfinite(a) & (a > 0)
    np.testing.assert_allclose(np.asarray(t.width)[fin],
                               np.minimum(2.0 * a[fin], float(des.face_width)), rtol=1e-14)
    assert t.line_length is None and bool(t.drive)


PB_TORQUE, PB_RPM = 150.0, 1200.0


@pytest.fixture(scope="module")
def pb_run(oil_surface):
    des = gj.load_design("example:preset_te_bevel_10x30").design
    return des, gj.mesh_efficiency(des, PB_TORQUE, PB_RPM, *oil_surface)


def _pb_virtual(des):
    """ISO 10300-1 virtual cylindrical teeth of the preset bevel by hand (as in
    test_preset_bevel_virtual_teeth_by_hand): m_mn, (z_vn1, z_vn2)."""
    z1, z2 = des.z1, des.z2
    S, beta, an = float(des.shaft_angle), float(des.beta), float(des.alpha_n)
    d1 = math.atan(math.sin(S) / (z2 / z1 + math.cos(S)))
    d2 = S - d1
    Rm = float(des.module_t) * z1 / (2.0 * math.sin(d1)) - 0.5 * float(des.face_width)
    m_mn = 2.0 * Rm * math.sin(d1) * math.cos(beta) / z1
    bvb = math.asin(math.sin(beta) * math.cos(an))
    return m_mn, [z / (math.cos(d) * math.cos(bvb) ** 2 * math.cos(beta))
                  for z, d in ((z1, d1), (z2, d2))]


def test_preset_bevel_loaded_contacts_by_hand(pb_run):
    """The preset-TE bevel pair through the loaded chain (steel: the example has no
    material table): exact Hertz of every loaded contact (scipy, Johnson), the normal
    force's moment arm about the pinion axis from the contact point and normal (numpy
    cross product), the pinion moment balance sum l1 F = T1, the gear's sum l2 F = T1
    z2/z1 to the preset TE's ratio variation, and in single contact the approach
    w = q F + delta_Hertz with q of the two virtual teeth (Weber/Sainsot, the ISO
    10300-1 virtual gears by hand) over the loaded width min(2a, b) and w = l2 y.
    Planted bugs caught: the virtual tooth height, dedendum or width slips of the
    preset mesh, a TE envelope with the wrong pitch (loads of the wrong pairs), Hertz
    of a wrong radius, the gear lever arm."""
    from gearjax.loading.tooth_compliance import tooth_compliance
    des, (eff, res) = pb_run
    z1, z2 = des.z1, des.z2
    F = np.asarray(eff.loaded.load)
    loaded = F > 0.0
    assert np.all(np.asarray(eff.valid)) and loaded.sum() >= 16
    rx = _per_pair(res, eff, res.kinematics.r_x)
    ry = _per_pair(res, eff, res.kinematics.r_y)
    p, a, b = (np.asarray(v) for v in (eff.loaded.p_max, eff.loaded.semi_major,
                                       eff.loaded.semi_minor))
    for k, j in zip(*np.nonzero(loaded)):
        p_ref, ay, bx, _ = _hertz_johnson(F[k, j], rx[k, j], ry[k, j], E_PRIME)
        np.testing.assert_allclose([p[k, j], a[k, j], b[k, j]], [p_ref, ay, bx], rtol=1e-8)
    l1, l2 = _arms_and_balances(res, eff, 1e3 * PB_TORQUE, z2 / z1, 2e-3)
    kk, j, w, y = _single_contact(eff, l2, 3, 1e-5)
    k = np.zeros(F.shape[1], int)
    k[j] = kk
    m_mn, zv = _pb_virtual(des)
    an = float(des.alpha_n)
    ha, hf = float(des.addendum) / m_mn, float(des.dedendum) / m_mn + 0.25
    h1 = _per_pair(res, eff, res.coords["h1"])[k[j], j]
    h2 = _per_pair(res, eff, res.coords["h2"])[k[j], j]
    width = np.minimum(2.0 * _per_pair(res, eff, res.path.semi_major)[k[j], j],
                       float(des.face_width))
    for i, jj in enumerate(j):
        Fi = F[k[jj], jj]
        q = sum(float(tooth_compliance(0.5 * zv[m] * m_mn + h, zv[m], m_mn, an, 0.0, ha, hf).total)
                for m, h in ((0, h1[i]), (1, h2[i]))) / width[i]
        w_ref = q * Fi + _hertz_johnson(Fi, rx[k[jj], jj], ry[k[jj], jj], E_PRIME)[3]
        np.testing.assert_allclose(w[i], w_ref, rtol=1e-7)
    # the loaded TE lies behind the unloaded envelope by y in the sense of the load: the
    # drive flank of this family pushes the gear backwards for increasing phi1 (its
    # envelope is the minimum over the pairs, gearjax.gears.preset_bevel.pair.drives_forward)
    from gearjax.gears.preset_bevel.pair import drives_forward
    sense = 1.0 if drives_forward("drive") else -1.0
    assert sense == -1.0
    te = sense * np.where(loaded, sense * _per_pair(res, eff, res.path.te), -np.inf).max(axis=0)
    np.testing.assert_allclose(np.asarray(eff.loaded.te_loaded)[j], te[j] - sense * y,
                               rtol=1e-9)


def test_vh_catt_friction_radii_along_the_entrainment_by_hand(vh_run):
    """Point contact (r_x != r_y): the radii given to the friction model are the
    relative radii of curvature along and across the entrainment vector.  By hand,
    with the curvature tensor diag(1/r_x, 1/r_y) of the TCA kinematics in its
    principal frame (t, e_major) and the entrainment direction d = (1, tan theta_e)
    normalised (the vector's components, module docstring) -- the normal curvature
    d^T K d (Euler) and that of the perpendicular direction; at theta_e = 0 they are
    r_x and r_y themselves.  Planted bug caught: R_x built with cos/sin swapped."""
    pair, (eff, res) = vh_run
    F = np.asarray(eff.loaded.load)
    loaded = F > 0.0
    assert loaded.sum() >= 24
    rx = _per_pair(res, eff, res.kinematics.r_x)[loaded]
    ry = _per_pair(res, eff, res.kinematics.r_y)[loaded]
    th = _per_pair(res, eff, res.kinematics.entrainment_angle)[loaded]
    assert np.all(ry > 2.0 * rx)                       # a true point contact
    d = np.stack([np.ones_like(th), np.tan(th)]) / np.sqrt(1.0 + np.tan(th) ** 2)
    e = np.stack([-d[1], d[0]])                        # across the entrainment
    K = np.stack([1.0 / rx, 1.0 / ry])                 # principal curvatures
    Rx_hand = 1.0 / np.sum(K * d ** 2, axis=0)
    Ry_hand = 1.0 / np.sum(K * e ** 2, axis=0)
    Rx, Ry = np.asarray(eff.r_x)[loaded], np.asarray(eff.r_y)[loaded]
    np.testing.assert_allclose(Rx, Rx_hand, rtol=1e-12)
    np.testing.assert_allclose(Ry, Ry_hand, rtol=1e-12)
    # where the entrainment runs along t the radii are the principal ones
    zero = np.abs(th) < 1e-9
    np.testing.assert_allclose(Rx[zero], rx[zero], rtol=1e-12)


# -- the notebook of this subject (tests/notebook_run.py: after this file's tests,
# whose compiled programs it reuses)


def test_vh_catt_notebook_efficiency_and_its_gradient(tmp_path):
    """The VH-CATT notebook: the efficiency at the operating point of docs/vh_catt.md
    (0.987854, the table there), every sweep point valid, and the jitted gradient of the
    efficiency by the cutter radii against central differences."""
    _, text = run_notebook("04_vh_catt_efficiency", tmp_path)
    eta = float(re.search(r"mean mesh efficiency ([0-9.]+)", text).group(1))
    assert abs(eta - 0.987854) <= 2e-6, text[-2000:]
    rows = re.findall(r"^\s+[0-9.]+\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+(\d+)$", text, re.M)
    assert len(rows) == 15 and all(int(n) == 24 for _, n in rows), rows
    worst = float(re.search(r"largest relative error ([0-9.e+-]+)", text).group(1))
    assert worst < 5e-5
