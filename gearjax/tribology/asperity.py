"""Asperity contact (Greenwood–Williamson / Greenwood–Tripp) and film/asperity load sharing.

Units: lengths mm (σ, β, film h), asperity density η_s in 1/mm², loads N,
pressures and E' in MPa.

Statistical functions (Gaussian summit heights, φ the standard normal density):

    F_n(λ) = ∫_λ^∞ (s - λ)^n φ(s) ds = φ(λ) I_n(λ),   I_n(λ) = ∫_0^∞ t^n e^{-λt - t²/2} dt.

``I_n`` is evaluated by 96-point Gauss–Legendre quadrature after the substitution
``t = T v²`` (``T(λ) = 1/(λ/45 + 1/11)`` covers the integrand to below 1e-16 of its
peak), which makes the integrand smooth (``t^n dt = 2 T^{n+1} v^{2n+1} dv``), so
F_2 and F_5/2 are accurate to ~1e-13 relative for every λ ≥ 0 (tested against
``scipy.integrate.quad`` and, for F_2, the closed form
``(1+λ²) Q(λ) - λ φ(λ)``), and ``log F_n`` stays finite far into the tail
(λ = 40: F_5/2 ≈ 1e-353 would underflow; its logarithm does not).  The popular
power-law fit ``F_5/2 ≈ 4.4086e-5 (4 - λ)^6.804`` (Arjmand/Hamrock) is off by
tens of per cent beyond λ ≈ 2.5 and is *not* used.

Greenwood–Tripp (Proc. IMechE 185 (1970) 625–633) asperity pressure and real
area ratio, in the form used in mixed-EHL models (Gelinck & Schipper, Tribol.
Int. 33 (2000) 175–181):

    p_a(λ) = K_GT E' F_5/2(λ),   K_GT = (16√2 π/15) (η_s β σ)² sqrt(σ/β),
    A_r/A  = π² (η_s β σ)² F_2(λ),

with λ = h/σ the separation of the mean planes over the composite roughness σ
and E' = 2E* (the reduced modulus of :mod:`gearjax.contact`).  Note: authors
differ on whether this coefficient goes with E' or E* (a factor 2 in p_a);
gearjax uses E', as Gelinck & Schipper.

Load sharing (Johnson, Greenwood & Poon, Wear 19 (1972) 91–108): the normal load
splits as F_n = F_h + F_a with F_h = F_n/γ1, F_a = F_n/γ2, 1/γ1 + 1/γ2 = 1.  The
fluid forms its film as if it carried F_n/γ1 on bodies of modulus E'/γ1 (film
formula of :mod:`gearjax.tribology.film`), the asperities carry
``F_a = π a b p_a(h_c/σ)`` over the Hertz ellipse of the total load.  The single
unknown is the asperity share φ = F_a/F_n = 1/γ2, solved for its logit
``s = ln(φ/(1-φ))`` with the implicit-differentiated Newton solver:

    R(s) = ln φ - ln(π a b K_GT E' / F_n) - ln F_5/2(h_c(F_n/γ1, E'/γ1)/σ) = 0.

R is increasing in s, so the root is unique; in logit form the solve is
well conditioned from full film (φ ~ 1e-30) to boundary lubrication (1-φ ~ 1e-30).

Note a property of this model: as φ → 1 the fluid "sees" F/γ1 → 0 on a modulus
E'/γ1 → 0 and the Hamrock–Dowson film grows like γ1^0.14, so λ = h_c/σ under load
sharing levels off at a finite value in the boundary regime instead of tending to
0.  The *smooth-surface* specific film thickness λ_s = h_c,smooth/σ (Tallian) does
tend to 0; gearjax reports both and classifies the regime by φ.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.newton import newton_solve
from gearjax.tribology.film import film_thickness_traced

__all__ = ["log_F_n", "F_n", "gt_coefficient", "asperity_pressure", "real_area_ratio",
           "load_sharing_traced", "LoadSharing"]

_NODES, _WEIGHTS = np.polynomial.legendre.leggauss(96)
_V = 0.5 * (_NODES + 1.0)          # nodes on [0, 1]
_WV = 0.5 * _WEIGHTS
_LOG_SQRT_2PI = 0.5 * math.log(2.0 * math.pi)


def _tail_scale(lam):
    return 1.0 / (jnp.maximum(lam, 0.0) / 45.0 + 1.0 / 11.0)


def log_F_n(lam, n):
    """ln F_n(λ) for λ ≥ 0 (n > -1 static, e.g. 2 or 2.5).  Differentiable in λ."""
    lam = jnp.asarray(lam, float)
    T = _tail_scale(lam)
    v = jnp.asarray(_V)
    t = T[..., None] * v * v
    log_integrand = (2.0 * n + 1.0) * jnp.log(v) - lam[..., None] * t - 0.5 * t * t
    I = 2.0 * T ** (n + 1.0) * jnp.sum(_WV * jnp.exp(log_integrand), axis=-1)
    return -0.5 * lam * lam - _LOG_SQRT_2PI + jnp.log(I)


def F_n(lam, n):
    """Greenwood–Williamson statistical function F_n(λ) (λ ≥ 0)."""
    return jnp.exp(log_F_n(lam, n))


def gt_coefficient(sigma, density, beta):
    """K_GT = (16√2π/15)(η_s β σ)² sqrt(σ/β) (dimensionless); σ, β mm, η_s 1/mm²."""
    return 16.0 * math.sqrt(2.0) * math.pi / 15.0 * (density * beta * sigma) ** 2 * jnp.sqrt(sigma / beta)


def asperity_pressure(lam, sigma, density, beta, E_prime):
    """Greenwood–Tripp nominal asperity pressure K_GT E' F_5/2(λ), MPa."""
    return gt_coefficient(sigma, density, beta) * E_prime * F_n(lam, 2.5)


def real_area_ratio(lam, sigma, density, beta):
    """Greenwood–Tripp real-to-nominal contact area π² (η_s β σ)² F_2(λ)."""
    return math.pi ** 2 * (density * beta * sigma) ** 2 * F_n(lam, 2.0)


class LoadSharing(NamedTuple):
    """Film/asperity load sharing at one contact.

    phi : asperity load ratio F_a/F_n (-).
    gamma1 : F_n/F_h (≥ 1).
    h_c, h_min : central and minimum film thickness under load sharing, mm.
    lam : λ = h_c/σ (film under load sharing).
    h_c_smooth : central film of the smooth surfaces (γ1 = 1), mm.
    area_ratio : real/nominal contact area (Greenwood–Tripp).
    residual, converged : of the Newton solve.
    """

    phi: jax.Array
    gamma1: jax.Array
    h_c: jax.Array
    h_min: jax.Array
    lam: jax.Array
    h_c_smooth: jax.Array
    area_ratio: jax.Array
    residual: jax.Array
    converged: jax.Array


def load_sharing_traced(F, Rx, k, a, b, u_e, eta0, alpha, E_prime, sigma, density, beta,
                        film_method="auto"):
    """Solve the Johnson–Greenwood–Poon load sharing at one contact (scalars; vmap it).

    F N; Rx, a, b (Hertz semi-axes), σ, β mm; k = a/b; u_e mm/s; η0 Pa·s; α 1/MPa;
    E' MPa; η_s 1/mm².  No validation.  Returns :class:`LoadSharing`.
    """
    log_cap = jnp.log(jnp.pi * a * b * gt_coefficient(sigma, density, beta) * E_prime / F)

    def film(log_gamma1):
        g = jnp.exp(log_gamma1)
        return film_thickness_traced(F / g, Rx, k, a, u_e, eta0, alpha, E_prime / g, film_method)

    def residual(s, _theta):
        log_phi = -jax.nn.softplus(-s)
        hc = film(jax.nn.softplus(s))[0]
        return log_phi - log_cap - log_F_n(hc / sigma, 2.5)

    hc0 = film(jnp.asarray(0.0))[0]
    s0 = jnp.clip(log_cap + log_F_n(hc0 / sigma, 2.5), -700.0, 30.0)
    s0 = jax.lax.stop_gradient(s0)
    res = newton_solve(residual, s0, (), tol=1e-11, xtol=1e-14, max_steps=80)
    s = res.x
    phi = jax.nn.sigmoid(s)
    lg1 = jax.nn.softplus(s)
    hc, hm = film(lg1)
    lam = hc / sigma
    return LoadSharing(phi, jnp.exp(lg1), hc, hm, lam, hc0,
                       real_area_ratio(lam, sigma, density, beta), res.residual, res.converged)
