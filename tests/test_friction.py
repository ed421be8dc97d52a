"""Friction coefficient: limits and trends required by the issue ([VH-CATT] trend table, docs/references.md),
Stribeck shifts, mesh losses and bad input."""

import math
import warnings

import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import ellipe, ellipkm1
from scipy.stats import norm

from gearjax.errors import ConvergenceError
from gearjax.tribology import (friction_coefficient, get_oil, make_oil, make_surface, mesh_losses,
                               stribeck_curve)
from gearjax.tribology.friction import Surface
from gearjax.tribology.losses import input_power
from gearjax.tribology.lubricant import Oil

OIL = get_oil("mineral_vg100")
F, RX, RY = 1000.0, 10.0, 100.0
# steel on steel, E = 206 GPa, ν = 0.3: E' = 2/(2(1 - ν²)/E) = E/(1 - ν²) (the default of
# friction_coefficient, typed here so that the references below do not read it)
E_STEEL = 206000.0 / (1.0 - 0.3 ** 2)
P_R = 1.0 / 5.1e-3      # Roelands reference pressure 1/(5.1e-9 Pa), MPa
LN_ETA_INF = 9.67       # -ln(6.31e-5 Pa·s), Roelands


# The references below type the published formulas in mm, N, MPa, MPa·s (η Pa·s × 1e-6).

def _hertz(F, Rx, Ry, Ep):
    """Hertz ellipse (a transverse, b rolling, k = a/b, p_max) for Ry ≥ Rx by an independent
    route: Johnson's (Contact Mechanics, 1985, §4.2) ellipticity equation solved with
    scipy's elliptic integrals and brentq (as in tests/test_contact.py, not gearjax code)."""
    r = Ry / Rx

    def g(kp):  # curvature ratio as a function of k' = b/a
        K, E = ellipkm1(kp * kp), ellipe(1 - kp * kp)
        return (E / kp ** 2 - K) / (K - E) - r

    kp = brentq(g, 1e-7, 1 - 1e-6, xtol=1e-16, rtol=1e-15)
    E = ellipe(1 - kp * kp)
    b = (3 * F * E * kp / (2 * np.pi * 0.5 * (1 / Rx + 1 / Ry) * (Ep / 2))) ** (1 / 3)
    a = b / kp
    return a, b, a / b, 1.5 * F / (np.pi * a * b)


def _hd(F, Rx, k, ue, eta0, alpha, Ep, minimum=False):
    """Hamrock & Dowson (1977) central (or minimum) film, mm."""
    U = eta0 * 1e-6 * ue / (Ep * Rx)
    G, W = alpha * Ep, F / (Ep * Rx * Rx)
    if minimum:
        return Rx * 3.63 * U ** 0.68 * G ** 0.49 * W ** -0.073 * (1.0 - math.exp(-0.68 * k))
    return Rx * 2.69 * U ** 0.67 * G ** 0.53 * W ** -0.067 * (1.0 - 0.61 * math.exp(-0.73 * k))


def _ph(w, Rx, ue, eta0, alpha, Ep):
    """Pan & Hamrock (1989) line-contact central film, mm (w load per length, N/mm)."""
    U = eta0 * 1e-6 * ue / (Ep * Rx)
    return Rx * 2.922 * (w / (Ep * Rx)) ** -0.166 * U ** 0.692 * (alpha * Ep) ** 0.470


def mu_at(ue, us, sigma_um=0.4, oil=OIL, F=F, f_c=0.1, **kw):
    return friction_coefficient(F, ue, us, RX, RY, oil, make_surface(sigma_um, f_c=f_c), **kw)


@pytest.mark.filterwarnings("ignore:Greenwood-Tripp asperity model")
def test_boundary_limit_mu_to_fc():
    # very rough surfaces / slow speeds: λ_s -> 0, asperities carry the load, μ -> f_c
    ue = np.array([2000.0, 500.0, 50.0])
    r = mu_at(ue, 0.2 * ue, sigma_um=3.0, f_c=0.12)
    lam_s = np.asarray(r.lam_smooth)
    mu = np.asarray(r.mu)
    assert np.all(np.diff(lam_s) < 0) and lam_s[-1] < 0.05
    assert np.all(np.asarray(r.phi) > 0.99)
    assert abs(mu[-1] - 0.12) < 0.002 * 0.12 + float(r.mu_fluid[-1]) + 1e-12
    assert abs(mu[-1] / 0.12 - 1) < 0.01
    assert np.all(np.asarray(r.regime) == 0)


def test_pure_rolling_mu_to_zero():
    us = np.array([0.0, 1e-4, 1e-2, 1.0, 100.0])
    r = mu_at(np.full(5, 500.0), us, sigma_um=0.8)
    mu = np.asarray(r.mu)
    assert mu[0] == 0.0
    assert np.all(np.diff(mu) > 0)
    assert mu[1] < 1e-4 * mu[-1] * 10


def test_full_film_mu_rises_with_viscosity():
    # the same oil family (Roelands z fixed) at two viscosities, e.g. two temperatures
    thin = make_oil(0.05, z=0.6)
    thick = make_oil(0.2, z=0.6)
    r1 = mu_at(10000.0, 2000.0, sigma_um=0.1, oil=thin)
    r2 = mu_at(10000.0, 2000.0, sigma_um=0.1, oil=thick)
    assert int(r1.regime) == 2 and int(r2.regime) == 2
    assert float(r2.mu) > float(r1.mu)


def test_mixed_regime_mu_falls_with_speed():
    # gear-like: p_max 1.54 GPa (F 1000 N, Rx 10 mm, Ry 100 mm), SRR 0.2, σ 0.8 µm, f_c = 0.1
    ue = np.logspace(np.log10(300.0), np.log10(20000.0), 15)
    r = mu_at(ue, 0.2 * ue, sigma_um=0.8)
    mixed = np.asarray(r.regime) == 1
    assert mixed.sum() >= 6
    # regime classes from the asperity share, thresholds as documented (docs/friction.md:
    # boundary φ ≥ 0.9, mixed 0.01 ≤ φ < 0.9, full film φ < 0.01); the sweep has points
    # with 0.001 ≤ φ < 0.01, so a misplaced 1 % threshold changes their class
    phi = np.asarray(r.phi)
    assert np.any((phi >= 1e-3) & (phi < 1e-2))
    np.testing.assert_array_equal(r.regime, np.where(phi >= 0.9, 0, np.where(phi >= 0.01, 1, 2)))
    assert np.all(np.diff(np.asarray(r.mu)[mixed]) < 0)
    # and in full film it rises again (EHL branch of the Stribeck curve)
    assert np.asarray(r.regime)[-1] == 2 and float(r.mu[-1]) > float(np.asarray(r.mu).min())


def test_roughness_increases_mu_in_mixed_regime():
    r = [float(mu_at(3000.0, 600.0, sigma_um=s).mu) for s in (0.4, 0.6, 0.8, 1.0)]
    assert np.all(np.diff(r) > 0)


def _transition_x(F_load=F, sigma_um=0.8, oil=OIL):
    ue = np.logspace(1.5, 5.5, 41)
    c = stribeck_curve(F_load, RX, RY, 0.2, ue, oil, make_surface(sigma_um))
    phi = np.asarray(c.friction.phi)
    x = np.asarray(c.stribeck_number)
    i = np.argmax(phi < 0.5)  # first point with the asperity share below one half
    assert 0 < i < len(ue) - 1
    # log-interpolate the crossing of phi = 0.5
    t = (np.log(phi[i - 1]) - np.log(0.5)) / (np.log(phi[i - 1]) - np.log(phi[i]))
    return np.exp(np.log(x[i - 1]) + t * (np.log(x[i]) - np.log(x[i - 1]))), np.exp(
        np.log(ue[i - 1]) + t * (np.log(ue[i]) - np.log(ue[i - 1])))


def test_stribeck_shifts_as_in_seed():
    x0, u0 = _transition_x()
    x_load, _ = _transition_x(F_load=2000.0)
    x_rough, _ = _transition_x(sigma_um=1.0)
    _, u_visc = _transition_x(oil=make_oil(0.176, z=float(OIL.z)))
    assert x_load < x0          # load: curve shifts left
    assert x_rough > x0         # roughness: shifts right
    assert u_visc < u0          # viscosity: mixed-to-EHL transition at lower speed


def test_stribeck_curve_definitions():
    """Stribeck sweep against its definitions through a second route: the Stribeck
    number η0 u_e/F_n in 1/m (η0 Pa·s, u_e in m/s, F_n N; typed from the docstring), μ
    and λ_s equal to friction_coefficient at u_s = SRR·u_e ([VH-CATT]: SRR = u_s/u_e)."""
    ue = np.array([800.0, 3000.0, 12000.0])
    surf = make_surface(0.8)
    c = stribeck_curve(F, RX, RY, 0.2, ue, OIL, surf)
    np.testing.assert_allclose(c.stribeck_number, 0.088 * (ue / 1000.0) / F, rtol=1e-14)
    r = friction_coefficient(F, ue, 0.2 * ue, RX, RY, OIL, surf)
    np.testing.assert_allclose(c.mu, r.mu, rtol=1e-13)
    np.testing.assert_allclose(c.lam, r.lam_smooth, rtol=1e-13)


def test_fluid_friction_newtonian_constant_viscosity_limit():
    """Newtonian, constant-viscosity limit of the fluid shear: τ = η0 u_s/h over the Hertz
    ellipse gives F_f = η0 u_s π a b / h_c, μ_f = F_f / F (closed form).

    The model is driven to the limit: Roelands z = 1e-9 (η(p) = η0 to 2e-8 at 1.5 GPa),
    τ0 = 1e5 MPa (Eyring argument ~3e-5: asinh(x) = x to 2e-10) and σ = 1e-9 mm (no
    asperity contact: φ ~ 1e-217).  Hertz by the scipy route (_hertz); h_c Hamrock–Dowson
    typed (k = 2.5) and Pan–Hamrock with w = 3F/(4a) (k = 68, where "auto" is the pure
    line formula), both to 1e-12.  The default E' (steel) enters through the film and
    the ellipse, typed as E_STEEL.  Tolerance: the viscosity excess is bounded by
    η(p_max)/η0 - 1 (computed, 1.6e-8), so μ_f/ref - 1 must lie in [-1e-12, that bound
    + 1e-12].
    """
    eta0, z = 0.088, 1e-9
    alpha = z * (math.log(eta0) + LN_ETA_INF) / P_R
    oil = Oil(jnp.asarray(eta0), jnp.asarray(z), jnp.asarray(1e5), jnp.asarray(880.0))
    surf = Surface(jnp.asarray(1e-9), jnp.asarray(1e4), jnp.asarray(1e-2), jnp.asarray(0.1),
                   jnp.asarray(1.0))
    ue, us, Ry = 5000.0, 1.0, np.array([40.0, 1e4])
    r = friction_coefficient(F, ue, us, RX, Ry, oil, surf)
    a, b, k, pm = np.transpose([_hertz(F, RX, ry, E_STEEL) for ry in Ry])
    assert k[0] < 8.0 and k[1] > 64.0
    h = np.array([_hd(F, RX, k[0], ue, eta0, alpha, E_STEEL),
                  _ph(0.75 * F / a[1], RX, ue, eta0, alpha, E_STEEL)])
    np.testing.assert_allclose(r.h_c, h, rtol=1e-12)
    ref = eta0 * 1e-6 * us * np.pi * a * b / (h * F)
    excess = np.exp((math.log(eta0) + LN_ETA_INF) * ((1 + pm / P_R) ** z - 1)) - 1
    dev = np.asarray(r.mu_fluid) / ref - 1
    assert np.all(dev > -1e-12) and np.all(dev < excess + 1e-12), (dev, excess)
    assert np.all(np.asarray(r.mu_boundary) < 1e-200)


def test_fluid_friction_eyring_saturated_limit_barus():
    """Eyring-saturated limit, Barus viscosity: for X = η u_s/(τ0 h) >> 1,
    τ = τ0 asinh X = τ0 [ln(2X) + 1/(4X²) + ...], and with η = η0 exp(α p) over the
    Hertz pressure (∫ p dA = F in full film)

        F_f = τ0 [π a b ln(2 η0 u_s/(τ0 h_c)) + α F] + R,   0 < R ≤ τ0 π a b / (4 X0²),

    X0 = η0 u_s/(τ0 h_c) the smallest argument (edge of the ellipse).  τ0 = 1e-4 MPa
    makes X0 ≈ 650, so the bound is 1.7e-8 of μ_f; h_c is Hamrock–Dowson typed; φ = 0
    (σ = 0.01 µm, λ ≈ 140).  The assert uses that bound.
    """
    oil = Oil(jnp.asarray(0.088), OIL.z, jnp.asarray(1e-4), jnp.asarray(880.0))
    alpha = 0.022   # the α (1/MPa) the oil's z was made from (get_oil: 22 /GPa)
    surf = Surface(jnp.asarray(1e-5), jnp.asarray(1e4), jnp.asarray(1e-2), jnp.asarray(0.1),
                   jnp.asarray(1.0))
    ue, us, Ry = 5000.0, 1000.0, 40.0
    r = friction_coefficient(F, ue, us, RX, Ry, oil, surf, viscosity_model="barus")
    a, b, k, _ = _hertz(F, RX, Ry, E_STEEL)
    area = math.pi * a * b
    h = _hd(F, RX, k, ue, 0.088, alpha, E_STEEL)
    assert float(r.phi) == 0.0
    X0 = 0.088e-6 * us / (1e-4 * h)
    ref = 1e-4 * (area * math.log(2 * X0) + alpha * F) / F
    bound = 1e-4 * area / (4 * X0 ** 2) / F
    assert -1e-12 * ref <= float(r.mu_fluid) - ref <= bound + 1e-12 * ref
    assert bound < 2e-8 * ref


def test_mixed_friction_against_quadrature_and_load_sharing_equations():
    """Mixed regime (φ ≈ 1 %): every part of μ against an independent route.

    * load sharing: h_c is Hamrock–Dowson typed for the fluid load F(1-φ) on E'(1-φ)
      (Johnson, Greenwood & Poon 1972), and φF equals the Greenwood–Tripp asperity load
      π a b K E' F_5/2(h_c/σ) with F_5/2 by scipy quad (rel 1e-9: the Newton tolerance);
    * fluid: μ_f = (1/F) ∫ τ0 asinh(η((1-φ)p_H) u_s/(τ0 h_c)) dA with the Roelands law
      typed (z from α = 22 /GPa) and the area integral done by adaptive quadrature in the
      polar radius ρ of the ellipse, p_H = p_max sqrt(1 - ρ²), dA = 2π a b ρ dρ (the
      library uses 48-point Gauss–Legendre in s = sqrt(1-ρ²)); rel 1e-10;
    * boundary: f_c φ tanh(u_s/v_slip);  μF = friction force; λ = h_c/σ; h_min
      (Hamrock–Dowson) and the real area ratio π²(η_s β σ)² F_2(λ) of the same film.
    """
    ue, us, sig_um = 3000.0, 600.0, 0.6
    r = mu_at(ue, us, sigma_um=sig_um)
    a, b, k, pm = _hertz(F, RX, RY, E_STEEL)
    phi = float(r.phi)
    assert 0.01 < phi < 0.05 and int(r.regime) == 1
    hc = _hd(F * (1 - phi), RX, k, ue, 0.088, 0.022, E_STEEL * (1 - phi))
    assert float(r.h_c) == pytest.approx(hc, rel=1e-9)
    hm = _hd(F * (1 - phi), RX, k, ue, 0.088, 0.022, E_STEEL * (1 - phi), minimum=True)
    assert float(r.h_min) == pytest.approx(hm, rel=1e-9)
    sig, dens, beta = sig_um * 1e-3, 1e4, 1e-2
    lam = hc / sig
    F52 = quad(lambda t: (t - lam) ** 2.5 * norm.pdf(t), lam, np.inf, epsabs=0, epsrel=1e-13,
               limit=200)[0]
    K = 16 * math.sqrt(2) * math.pi / 15 * (dens * beta * sig) ** 2 * math.sqrt(sig / beta)
    assert phi * F == pytest.approx(math.pi * a * b * K * E_STEEL * F52, rel=1e-9)
    F2 = quad(lambda t: (t - lam) ** 2 * norm.pdf(t), lam, np.inf, epsabs=0, epsrel=1e-13,
              limit=200)[0]
    assert float(r.area_ratio) == pytest.approx(math.pi ** 2 * (dens * beta * sig) ** 2 * F2, rel=1e-9)
    z = 0.022 * P_R / (math.log(0.088) + LN_ETA_INF)

    def tau(p):
        eta = 0.088 * math.exp((math.log(0.088) + LN_ETA_INF) * ((1 + p / P_R) ** z - 1))
        return 5.0 * math.asinh(eta * 1e-6 * us / (hc * 5.0))

    integral = quad(lambda rho: tau((1 - phi) * pm * math.sqrt(1 - rho * rho)) * rho, 0.0, 1.0,
                    epsabs=0, epsrel=1e-13, limit=200)[0]
    mu_f = 2 * math.pi * a * b * integral / F
    mu_b = 0.1 * phi * math.tanh(us / 1.0)
    assert float(r.mu_fluid) == pytest.approx(mu_f, rel=1e-10)
    assert float(r.mu_boundary) == pytest.approx(mu_b, rel=1e-9)
    assert float(r.mu) == pytest.approx(mu_f + mu_b, rel=1e-10)
    assert float(r.friction_force) == pytest.approx((mu_f + mu_b) * F, rel=1e-10)
    assert float(r.lam) == pytest.approx(hc / sig, rel=1e-9)


def test_chunked_evaluation_matches_single_batch():
    """More than 1024 points run in chunks of 1024 (lax.map over vmap, the last chunk
    padded); the same points evaluated as small single batches (≤ 64, no chunking) are
    the second route.  1100 points, 948 of them padding in the last chunk; per-point
    solves are independent, so the results agree to round-off (rel 1e-13)."""
    from gearjax.tribology.friction import _friction_jit
    rng = np.random.default_rng(7)
    n = 1100
    ue = rng.uniform(500.0, 15000.0, n)
    us = 0.3 * ue * rng.uniform(0.0, 1.0, n)
    Fn = rng.uniform(300.0, 2000.0, n)
    Rx = rng.uniform(5.0, 15.0, n)
    surf = make_surface(0.6)
    big = _friction_jit(Fn, ue, us, Rx, 10.0 * Rx, OIL, surf, E_STEEL,
                        viscosity_model="roelands", film_method="auto")
    assert np.asarray(big.mu).shape == (n,)
    for sl in (slice(0, 50), slice(1030, 1080), slice(n - 20, n)):
        small = friction_coefficient(Fn[sl], ue[sl], us[sl], Rx[sl], 10.0 * Rx[sl], OIL, surf)
        np.testing.assert_allclose(np.asarray(big.mu)[sl], small.mu, rtol=1e-13)
        np.testing.assert_allclose(np.asarray(big.h_c)[sl], small.h_c, rtol=1e-13)


def _mesh_case():
    # 5 mesh positions x 2 points; sliding changes sign at the pitch point (position 2)
    F = np.array([[600.0, 400.0], [1000.0, 0.0], [1000.0, 0.0], [1000.0, 0.0], [450.0, 550.0]])
    us = np.array([[-900.0, 1500.0], [-500.0, 0.0], [0.0, 0.0], [500.0, 0.0], [900.0, -1400.0]])
    ue = np.array([[4000.0, 4500.0], [4200.0, 1.0], [4300.0, 1.0], [4400.0, 1.0], [4600.0, 4100.0]])
    Rx = np.array([[6.0, 9.0], [7.0, 1.0], [8.0, 1.0], [9.0, 1.0], [10.0, 7.0]])
    Ry = 20.0 * Rx
    return F, us, ue, Rx, Ry


def test_mesh_losses_against_pointwise_route():
    F, us, ue, Rx, Ry = _mesh_case()
    surf = make_surface(0.5)
    p_in = float(input_power(120.0, 150.0))  # 120 N·m at 150 rad/s = 18 kW
    out = mesh_losses(F, us, ue, Rx, Ry, OIL, surf, p_in)
    act = F > 0
    r = friction_coefficient(F[act], ue[act], np.abs(us[act]), Rx[act], Ry[act], OIL, surf)
    P = np.zeros(5)
    np.add.at(P, np.nonzero(act)[0], np.asarray(r.mu) * F[act] * np.abs(us[act]) * 1e-3)
    np.testing.assert_allclose(np.asarray(out.power_loss), P, rtol=1e-10)
    assert float(out.power_loss[2]) == 0.0  # pure rolling at the pitch point
    np.testing.assert_allclose(np.asarray(out.efficiency), 1 - P / p_in, rtol=1e-12)
    assert float(out.mean_efficiency) == pytest.approx(1 - P.mean() / p_in, rel=1e-12)
    w = np.array([0.5, 1, 1, 1, 0.5])
    outw = mesh_losses(F, us, ue, Rx, Ry, OIL, surf, p_in, weights=w)
    assert float(outw.mean_efficiency) == pytest.approx(1 - (w * P).sum() / (w.sum() * p_in), rel=1e-12)
    # input power varying along the cycle: the cycle efficiency is the ratio of energies
    # 1 - Σ w P_f / Σ w P_in ([VH-CATT]: losses integrated over the path of contact), which
    # here differs from the (weighted) mean of the instantaneous efficiencies by 1.3e-3
    p_var = p_in * np.array([0.3, 1.0, 1.4, 1.2, 0.5])
    outv = mesh_losses(F, us, ue, Rx, Ry, OIL, surf, p_var, weights=w)
    np.testing.assert_allclose(outv.efficiency, 1 - P / p_var, rtol=1e-12)
    ref = 1 - (w * P).sum() / (w * p_var).sum()
    assert float(outv.mean_efficiency) == pytest.approx(ref, rel=1e-12)
    assert abs(ref - (w * (1 - P / p_var)).sum() / w.sum()) > 1e-4  # resolved by rel 1e-12
    # an unloaded point that slides (a tooth pair out of contact still has kinematics):
    # it adds no loss and reports μ = 0
    us_idle = us.copy()
    us_idle[1, 1] = 700.0
    outi = mesh_losses(F, us_idle, ue, Rx, Ry, OIL, surf, p_in)
    np.testing.assert_allclose(outi.power_loss, P, rtol=1e-10)
    assert float(outi.mu[1, 1]) == 0.0
    assert np.all(np.asarray(out.mu)[~act] == 0)


@pytest.mark.parametrize("kw,name", [
    (dict(F=-5.0), "load"), (dict(F=0.0), "load"), (dict(ue=-1.0), "u_e"), (dict(us=-3.0), "u_s"),
    (dict(Rx=0.0), "Rx"), (dict(Ry=-2.0), "Ry"), (dict(E_prime=0.0), "E_prime"),
    (dict(Ry=np.nan), "Ry")])
def test_bad_contact_input(kw, name):
    args = dict(F=F, ue=1000.0, us=100.0, Rx=RX, Ry=RY, E_prime=226374.0)
    args.update(kw)
    with pytest.raises(ValueError, match=name):
        friction_coefficient(args["F"], args["ue"], args["us"], args["Rx"], args["Ry"], OIL,
                             make_surface(0.4), args["E_prime"])


@pytest.mark.parametrize("call,name", [
    (lambda: make_surface(0.0), "sigma"), (lambda: make_surface(-1.0), "sigma"),
    (lambda: make_surface(0.4, density_per_mm2=0.0), "asperity density"),
    (lambda: make_surface(0.4, beta_um=-1.0), "asperity radius"),
    (lambda: make_surface(0.4, f_c=1.5), "f_c"),
    (lambda: make_oil(0.0, 20.0), "eta0")])
def test_bad_material_input(call, name):
    with pytest.raises(ValueError, match=name):
        call()


def test_mesh_bad_input():
    F, us, ue, Rx, Ry = _mesh_case()
    s = make_surface(0.5)
    # an input power far below the losses: eta_m < 0 is implausible and warned
    # (before: an efficiency of -59509 at 1e-3 W, silently).  Planted bug caught: the
    # check dropped or testing eta < 1 instead of the range (0, 1]
    with pytest.warns(UserWarning, match=r"implausible efficiency.*outside \(0, 1\]"):
        bad = mesh_losses(F, us, ue, Rx, Ry, OIL, s, 1e-3)
    assert float(np.min(bad.efficiency)) < 0.0
    with pytest.raises(ValueError, match="power_in"):
        mesh_losses(F, us, ue, Rx, Ry, OIL, s, -1.0)
    Fb = F.copy()
    Fb[0, 0] = -1.0
    with pytest.raises(ValueError, match="load"):
        mesh_losses(Fb, us, ue, Rx, Ry, OIL, s, 1e4)
    ueb = ue.copy()
    ueb[0, 0] = -1.0
    with pytest.raises(ValueError, match="u_e"):
        mesh_losses(F, us, ueb, Rx, Ry, OIL, s, 1e4)


def test_validity_warnings_name_formula_and_range():
    with pytest.warns(UserWarning, match=r"Hamrock-Dowson.*1 <= k <= 8"):
        friction_coefficient(F, 3000.0, 300.0, 5.0, 5000.0, OIL, make_surface(0.4), film_method="point")
    # default "auto" film: Hamrock-Dowson alone below k = 1 (Rx > Ry) is outside its fit
    with pytest.warns(UserWarning, match=r"Hamrock-Dowson.*1 <= k <= 8"):
        friction_coefficient(F, 3000.0, 300.0, 30.0, 12.0, OIL, make_surface(0.4))
    with pytest.warns(UserWarning, match=r"Pan-Hamrock line-contact.*not elongated"):
        friction_coefficient(F, 3000.0, 300.0, RX, 2.0 * RX, OIL, make_surface(0.4), film_method="line")
    with pytest.warns(UserWarning, match=r"Roelands viscosity.*3 GPa"):
        friction_coefficient(40000.0, 3000.0, 300.0, 5.0, 10.0, OIL, make_surface(0.4))
    with pytest.warns(UserWarning, match=r"Greenwood-Tripp.*0.005..0.2"):
        make_surface(0.4, density_per_mm2=1e6)
    # a film of ~1 nm (u_e = 1e-4 m/s) is below the film model's range (FILM_MIN_MM):
    # before, labelled "mixed" with ~21 % of the load on the asperities, no warning.
    # Planted bug caught: the film check dropped or in the wrong unit (um vs mm)
    with pytest.warns(UserWarning, match=r"central film h_c down to .* nm, below .*5 nm"):
        thin = friction_coefficient(F, 0.1, 0.01, RX, RY, OIL, make_surface(0.4))
    # ... and labelled boundary (regime 0) whatever the asperity share (here < 0.9)
    assert float(thin.h_c) < 5e-6 and float(thin.phi) < 0.9 and int(thin.regime) == 0
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        friction_coefficient(F, 3000.0, 300.0, RX, RY, OIL, make_surface(0.4))


def test_nonconvergence_is_not_returned_as_valid(monkeypatch):
    import gearjax.tribology.friction as fr
    real = fr._friction_jit

    def fake(*a, **k):
        out = real(*a, **k)
        return out._replace(converged=out.converged & False)

    monkeypatch.setattr(fr, "_friction_jit", fake)
    with pytest.raises(ConvergenceError):
        friction_coefficient(F, 3000.0, 300.0, RX, RY, OIL, make_surface(0.4))
    r = friction_coefficient(F, 3000.0, 300.0, RX, RY, OIL, make_surface(0.4), throw=False)
    assert not bool(r.converged)
