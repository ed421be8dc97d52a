"""Lubricant laws, film thickness, asperity statistics and load sharing against
hand-worked numbers and scipy quadrature."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.special import erfc
from scipy.stats import norm

from gearjax.contact import hertz_point
from gearjax.tribology import get_oil, make_oil, make_surface
from gearjax.tribology.asperity import (F_n, asperity_pressure, load_sharing_traced, log_F_n,
                                        real_area_ratio)
from gearjax.tribology.film import (blend_weight, film_thickness_traced, hamrock_dowson,
                                    pan_hamrock_line)
from gearjax.tribology.lubricant import (barus_viscosity, dowson_higginson_density, eyring_shear,
                                         roelands_viscosity, roelands_z, viscosity)

E_PRIME = 226374.0


# ---------------------------------------------------------------- lubricant

def test_roelands_matches_seed_formula_in_si_units():
    eta0, p_Pa = 0.088, 1.2e9
    seed = eta0 * math.exp((math.log(eta0) + 9.67) * ((1 + 5.1e-9 * p_Pa) ** 0.68 - 1))
    assert float(roelands_viscosity(p_Pa * 1e-6, eta0, 0.68)) == pytest.approx(seed, rel=1e-12)


def test_roelands_z_from_alpha_matches_barus_slope_at_zero():
    oil = get_oil("mineral_vg100")
    dlog = jax.grad(lambda p: jnp.log(viscosity(p, oil)))(0.0)
    assert float(dlog) == pytest.approx(float(oil.alpha), rel=1e-12)
    assert float(oil.alpha) == pytest.approx(0.022, rel=1e-12)  # the α it was built from
    seed_oil = make_oil(0.1, z=0.68)
    assert float(seed_oil.alpha) == pytest.approx(0.68 * (math.log(0.1) + 9.67) * 5.1e-3, rel=1e-12)
    assert 0.4 < float(roelands_z(oil.eta0, oil.alpha)) < 0.8
    # roelands_z (the jnp route) gives the z whose Roelands law has initial slope α
    z = roelands_z(0.196, 0.024)
    slope = jax.grad(lambda p: jnp.log(roelands_viscosity(p, 0.196, z)))(0.0)
    assert float(slope) == pytest.approx(0.024, rel=1e-12)
    # Roelands is below Barus at high pressure (the known Barus over-prediction)
    assert float(viscosity(1500.0, oil)) < float(viscosity(1500.0, oil, "barus"))
    assert float(barus_viscosity(100.0, 0.1, 0.02)) == pytest.approx(0.1 * math.exp(2.0), rel=1e-14)


def test_dowson_higginson_density_and_limit():
    assert float(dowson_higginson_density(0.0, 880.0)) == 880.0
    p = 500.0
    assert float(dowson_higginson_density(p, 880.0)) == pytest.approx(
        880.0 * (1 + 0.6e-9 * p * 1e6 / (1 + 1.7e-9 * p * 1e6)), rel=1e-14)
    assert float(dowson_higginson_density(1e9, 880.0)) == pytest.approx(880.0 * (1 + 0.6 / 1.7), rel=1e-6)


def test_eyring_newtonian_limit_and_units():
    # η u/h = 0.1 Pa·s * 1 m/s / 1e-6 m = 1e5 Pa = 0.1 MPa; τ0 = 5 MPa -> nearly Newtonian
    tau = float(eyring_shear(0.1, 1000.0, 1e-3, 5.0))
    assert tau == pytest.approx(5.0 * math.asinh(0.1 / 5.0), rel=1e-14)
    assert tau == pytest.approx(0.1, rel=1e-4)


def test_example_oils_and_bad_oil():
    for name in ("mineral_vg100", "mineral_vg220", "pao_vg100"):
        oil = get_oil(name)
        assert oil.name == name and float(oil.eta0) > 0
    with pytest.raises(ValueError, match="not a known oil"):
        get_oil("castor")
    with pytest.raises(ValueError, match="eta0"):
        make_oil(-0.1, 20.0)
    with pytest.raises(ValueError, match="alpha"):
        make_oil(0.1, 0.0)
    with pytest.warns(UserWarning, match="alpha = 80"):
        make_oil(0.1, 80.0)
    with pytest.raises(ValueError, match="exactly one"):
        make_oil(0.1, 20.0, z=0.6)


# ---------------------------------------------------------------- film

def _hd_by_hand_SI(F, Rx_m, k, u, eta0, alpha_Pa, Ep_Pa):
    U = eta0 * u / (Ep_Pa * Rx_m)
    G = alpha_Pa * Ep_Pa
    W = F / (Ep_Pa * Rx_m ** 2)
    hc = Rx_m * 2.69 * U ** 0.67 * G ** 0.53 * W ** -0.067 * (1 - 0.61 * math.exp(-0.73 * k))
    hm = Rx_m * 3.63 * U ** 0.68 * G ** 0.49 * W ** -0.073 * (1 - math.exp(-0.68 * k))
    return hc, hm


def test_hamrock_dowson_worked_example():
    # F = 1000 N, Rx = 10 mm, k = 4, u_e = 5 m/s, η0 = 0.088 Pa·s, α = 22 /GPa, E' = 226.374 GPa
    # worked in SI: U = 1.9437e-10, G = 4980.2, W = 4.4175e-5
    U = 0.088 * 5.0 / (226.374e9 * 0.01)
    assert U == pytest.approx(1.9437e-10, rel=1e-4)
    hc_si, hm_si = _hd_by_hand_SI(1000.0, 0.01, 4.0, 5.0, 0.088, 22e-9, 226.374e9)
    hc, hm = hamrock_dowson(1000.0, 10.0, 4.0, 5000.0, 0.088, 0.022, E_PRIME)
    assert float(hc) * 1e-3 == pytest.approx(hc_si, rel=1e-12)
    assert float(hm) * 1e-3 == pytest.approx(hm_si, rel=1e-12)
    assert 0.5e-6 < hc_si < 2e-6  # about a micrometre, as expected for such a contact
    assert float(hm) < float(hc)
    # worked by hand (factors to 5 digits): U^0.67 = 3.1144e-7, G^0.53 = 91.105,
    # W^-0.067 = 1.9578, 1 - 0.61 e^-2.92 = 0.96710 -> H_c = 1.4452e-4, h_c = 1.4452 µm;
    # U^0.68 = 2.4904e-7, G^0.49 = 64.812, W^-0.073 = 2.0792, 1 - e^-2.72 = 0.93413
    # -> H_min = 1.1380e-4, h_min = 1.1380 µm
    assert float(hc) * 1e3 == pytest.approx(1.4452, rel=1e-4)
    assert float(hm) * 1e3 == pytest.approx(1.1380, rel=1e-4)


def test_pan_hamrock_line_worked_example():
    w_SI = 300e3  # 300 N/mm
    U = 0.088 * 5.0 / (226.374e9 * 0.01)
    G = 22e-9 * 226.374e9
    Wl = w_SI / (226.374e9 * 0.01)
    hc_si = 0.01 * 2.922 * Wl ** -0.166 * U ** 0.692 * G ** 0.470
    hm_si = 0.01 * 1.714 * Wl ** -0.128 * U ** 0.694 * G ** 0.568
    hc, hm = pan_hamrock_line(300.0, 10.0, 5000.0, 0.088, 0.022, E_PRIME)
    assert float(hc) * 1e-3 == pytest.approx(hc_si, rel=1e-12)
    assert float(hm) * 1e-3 == pytest.approx(hm_si, rel=1e-12)
    # worked by hand: W' = 1.3252e-4; W'^-0.166 = 4.4025, U^0.692 = 1.9043e-7,
    # G^0.470 = 54.665 -> h_c = 10 mm x 2.922 x ... = 1.3391 µm;
    # W'^-0.128 = 3.1358, U^0.694 = 1.8210e-7, G^0.568 = 125.90 -> h_min = 1.2323 µm
    assert float(hc) * 1e3 == pytest.approx(1.3391, rel=1e-4)
    assert float(hm) * 1e3 == pytest.approx(1.2323, rel=1e-4)


def _ph_by_hand_SI(w_N_m, Rx_m, u, eta0, alpha_Pa, Ep_Pa):
    U = eta0 * u / (Ep_Pa * Rx_m)
    G = alpha_Pa * Ep_Pa
    Wl = w_N_m / (Ep_Pa * Rx_m)
    return (Rx_m * 2.922 * Wl ** -0.166 * U ** 0.692 * G ** 0.470,
            Rx_m * 1.714 * Wl ** -0.128 * U ** 0.694 * G ** 0.568)


def test_elongated_ellipse_film_uses_centre_line_load():
    """film_method="line" on a Hertz ellipse: Pan–Hamrock (typed in SI) with the load per
    unit length carried across the middle of the ellipse, obtained here by integrating
    the Hertz pressure p_max sqrt(1 - x²/b²) along the rolling direction (scipy quad;
    π p_max b/2 = 3F/(4a) in closed form).  Tolerance 1e-11: quadrature and the
    SI/mm unit round trip."""
    F, Rx = 1500.0, 10.0
    hz = hertz_point(F, Rx, 1e4 * Rx, E_PRIME)
    b, pm = float(hz.b), float(hz.p_max)
    w = quad(lambda x: pm * math.sqrt(1.0 - (x / b) ** 2), -b, b, epsabs=0, epsrel=1e-13)[0]
    hc_si, hm_si = _ph_by_hand_SI(w * 1e3, Rx * 1e-3, 4.0, 0.088, 22e-9, E_PRIME * 1e6)
    hc, hm = film_thickness_traced(F, Rx, hz.k, hz.a, 4000.0, 0.088, 0.022, E_PRIME, "line")
    assert float(hc) * 1e-3 == pytest.approx(hc_si, rel=1e-11)
    assert float(hm) * 1e-3 == pytest.approx(hm_si, rel=1e-11)


def test_auto_film_inside_the_blend():
    """Inside the blend (8 < k < 64) "auto" is ln h = (1-s) ln h_HD + s ln h_PH with the
    smoothstep s = 3x² - 2x³ of x = ln(k/8)/ln(64/8) (docs/friction.md; a gearjax
    choice).  At k = 16, x = 1/3 and s = 7/27 exactly, so h = h_HD^(20/27) h_PH^(7/27)
    with both formulas typed in SI (Hamrock–Dowson at k = 16, Pan–Hamrock with
    w = 3F/(4a)).  Both h_c and h_min; tolerance 1e-12 (round-off of the powers)."""
    F, Rx, a, k, ue = 1200.0, 10.0, 2.0, 16.0, 4000.0
    hp = _hd_by_hand_SI(F, Rx * 1e-3, k, ue * 1e-3, 0.088, 22e-9, E_PRIME * 1e6)
    hl = _ph_by_hand_SI(0.75 * F / a * 1e3, Rx * 1e-3, ue * 1e-3, 0.088, 22e-9, E_PRIME * 1e6)
    auto = film_thickness_traced(F, Rx, k, a, ue, 0.088, 0.022, E_PRIME, "auto")
    for got, p, l in zip(auto, hp, hl):
        assert float(got) * 1e-3 == pytest.approx(p ** (20 / 27) * l ** (7 / 27), rel=1e-12)
    assert float(blend_weight(k)) == pytest.approx(7 / 27, rel=1e-14)


def test_groups_use_rx_not_geometric_mean():
    # doubling Ry (Rx fixed) changes h only through k: with k fixed it does not change at all
    h1 = hamrock_dowson(1000.0, 10.0, 4.0, 5000.0, 0.088, 0.022, E_PRIME)
    hx = hamrock_dowson(1000.0, 20.0, 4.0, 5000.0, 0.088, 0.022, E_PRIME)
    # h/Rx ∝ Rx^-(0.67) * Rx^(2*0.067): h ∝ Rx^(1 - 0.67 + 0.134)
    assert float(hx[0] / h1[0]) == pytest.approx(2 ** (1 - 0.67 + 0.134), rel=1e-12)


def test_auto_film_blend_limits_and_continuity():
    F, Rx, ue = 1500.0, 10.0, 4000.0
    for ratio, expect in ((2.0, "point"), (1e4, "line")):
        hz = hertz_point(F, Rx, Rx * ratio, E_PRIME)
        auto = film_thickness_traced(F, Rx, hz.k, hz.a, ue, 0.088, 0.022, E_PRIME, "auto")
        ref = film_thickness_traced(F, Rx, hz.k, hz.a, ue, 0.088, 0.022, E_PRIME, expect)
        assert float(auto[0]) == pytest.approx(float(ref[0]), rel=1e-14)
    ks = np.array([8.0 - 1e-9, 8.0 + 1e-9, 64.0 - 1e-9, 64.0 + 1e-9])
    w = np.asarray(blend_weight(ks))
    assert np.all(np.abs(w[[0, 1]]) < 1e-15) and np.all(np.abs(w[[2, 3]] - 1) < 1e-15)
    dw = jax.vmap(jax.grad(blend_weight))(jnp.asarray([8.0 + 1e-6, 64.0 - 1e-6]))
    assert np.all(np.abs(np.asarray(dw)) < 1e-5)  # C¹ at both ends


# ---------------------------------------------------------------- asperities

@pytest.mark.parametrize("n", [2.0, 2.5])
@pytest.mark.parametrize("lam", [0.0, 0.3, 1.0, 2.0, 2.5, 3.0, 4.0, 6.0, 9.0])
def test_F_n_against_scipy_quad(n, lam):
    ref = quad(lambda s: (s - lam) ** n * norm.pdf(s), lam, np.inf, epsabs=0, epsrel=1e-13, limit=200)[0]
    assert float(F_n(lam, n)) == pytest.approx(ref, rel=1e-12)


def test_F2_closed_form_and_far_tail():
    for lam in [0.0, 0.7, 2.2, 5.0]:
        Q = 0.5 * erfc(lam / math.sqrt(2))
        closed = (1 + lam * lam) * Q - lam * norm.pdf(lam)
        assert float(F_n(lam, 2.0)) == pytest.approx(closed, rel=1e-10)
    # far tail: asymptotic F_n ~ Γ(n+1) φ(λ)/λ^(n+1) (1 + O(1/λ²))
    lam = 40.0
    asym = math.lgamma(3.5) - 0.5 * lam * lam - 0.5 * math.log(2 * math.pi) - 3.5 * math.log(lam)
    assert float(log_F_n(lam, 2.5)) == pytest.approx(asym, abs=0.02)
    assert np.isfinite(float(jax.grad(log_F_n)(lam, 2.5)))


def test_dF_dlambda_identity():
    # dF_n/dλ = -n F_{n-1}
    for lam in [0.5, 2.0, 3.5]:
        g = float(jax.grad(F_n)(lam, 2.5))
        assert g == pytest.approx(-2.5 * float(F_n(lam, 1.5)), rel=1e-11)


def test_power_law_fit_is_poor_beyond_2_5():
    # the reason for quadrature: 4.4086e-5 (4 - λ)^6.804 is 35 % low at λ = 2.5, 74 % at 3
    for lam, lo in ((2.5, 0.3), (3.0, 0.7)):
        fit = 4.4086e-5 * (4 - lam) ** 6.804
        assert abs(fit / float(F_n(lam, 2.5)) - 1) > lo


def test_gt_pressure_and_area_formulas():
    sig, dens, beta, lam = 4e-4, 1e4, 1e-2, 1.5
    K = 16 * math.sqrt(2) * math.pi / 15 * (dens * beta * sig) ** 2 * math.sqrt(sig / beta)
    F52 = quad(lambda s: (s - lam) ** 2.5 * norm.pdf(s), lam, np.inf, epsabs=0, epsrel=1e-13, limit=200)[0]
    F2 = quad(lambda s: (s - lam) ** 2 * norm.pdf(s), lam, np.inf, epsabs=0, epsrel=1e-13, limit=200)[0]
    assert float(asperity_pressure(lam, sig, dens, beta, E_PRIME)) == pytest.approx(K * E_PRIME * F52, rel=1e-11)
    assert float(real_area_ratio(lam, sig, dens, beta)) == pytest.approx(
        math.pi ** 2 * (dens * beta * sig) ** 2 * F2, rel=1e-11)


# ---------------------------------------------------------------- load sharing

def _sharing(F, ue, sigma_um, Rx=10.0, Ry=100.0, film="point"):
    oil = get_oil("mineral_vg100")
    s = make_surface(sigma_um)
    hz = hertz_point(F, Rx, Ry, E_PRIME)
    ls = load_sharing_traced(F, Rx, hz.k, hz.a, hz.b, ue, oil.eta0, oil.alpha, E_PRIME,
                             s.sigma, s.density, s.beta, film)
    return ls, hz, oil, s


@pytest.mark.parametrize("ue,sigma_um", [(200.0, 0.8), (2000.0, 0.8), (20000.0, 0.4), (500.0, 2.0)])
def test_load_sharing_satisfies_both_equations(ue, sigma_um):
    F, Rx = 1000.0, 10.0
    ls, hz, oil, s = _sharing(F, ue, sigma_um)
    assert bool(ls.converged)
    phi, g1, hc = float(ls.phi), float(ls.gamma1), float(ls.h_c)
    assert 1.0 / g1 == pytest.approx(1.0 - phi, rel=1e-12, abs=1e-15)
    # fluid: Hamrock–Dowson (by hand, SI) with F/γ1 and E'/γ1
    hc_si, hm_si = _hd_by_hand_SI(F / g1, Rx * 1e-3, float(hz.k), ue * 1e-3, 0.088, 22e-9,
                                  226.374e9 / g1)
    assert hc * 1e-3 == pytest.approx(hc_si, rel=1e-9)
    assert float(ls.h_min) * 1e-3 == pytest.approx(hm_si, rel=1e-9)  # same film, h_min formula
    # asperities: F_a = π a b K E' F_5/2(h/σ) with F_5/2 by scipy quad
    sig, dens, beta = float(s.sigma), float(s.density), float(s.beta)
    lam = hc / sig
    F52 = quad(lambda t: (t - lam) ** 2.5 * norm.pdf(t), lam, np.inf, epsabs=0, epsrel=1e-13, limit=200)[0]
    K = 16 * math.sqrt(2) * math.pi / 15 * (dens * beta * sig) ** 2 * math.sqrt(sig / beta)
    Fa = math.pi * float(hz.a) * float(hz.b) * K * E_PRIME * F52
    assert phi * F == pytest.approx(Fa, rel=1e-8)
    # real area ratio π²(η_s β σ)² F_2(λ) at the load-sharing film, F_2 in closed form
    # (1 + λ²) Q(λ) - λ φ(λ); rel 1e-8 as F_a (λ carries the solve's tolerance)
    F2 = (1 + lam * lam) * 0.5 * erfc(lam / math.sqrt(2)) - lam * norm.pdf(lam)
    assert float(ls.area_ratio) == pytest.approx(math.pi ** 2 * (dens * beta * sig) ** 2 * F2, rel=1e-8)


@pytest.mark.filterwarnings("ignore:Greenwood-Tripp asperity model")
def test_load_sharing_limits():
    smooth, *_ = _sharing(1000.0, 10000.0, 0.02)
    assert float(smooth.phi) < 1e-30
    assert float(smooth.h_c) == pytest.approx(float(smooth.h_c_smooth), rel=1e-12)
    rough, *_ = _sharing(1000.0, 50.0, 3.0)
    assert float(rough.phi) > 0.999
    assert float(rough.h_c_smooth) / 3e-3 < 0.05  # smooth-surface λ_s -> 0
