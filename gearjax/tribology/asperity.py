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
``s = ln(φ/(1-φ))`` by a fixed number of Halley steps from an explicit start
(:func:`load_sharing_traced`), derivatives by the implicit function theorem:

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
from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.newton import implicit_root
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


# Load sharing: 32-node rule (ln F_5/2 within 1.4e-13 of an adaptive quadrature for
# every λ ≥ 0, the same as the 96-node rule of log_F_n; tests/test_tribology.py)
_LS_STEPS = 4             # Halley steps from the explicit start (measured: 1e-15 in s)
_LS_TOL = 1e-11           # residual tolerance of the converged flag (as the former solve)
_LGAMMA_3_5 = math.lgamma(3.5)



def _moments(n):
    """Nodes v² on [0, 1] and the columns weighting e^{-λt - t²/2} for I_5/2, I_3/2,
    I_1/2, I_2 (t^n dt = 2 T^{n+1} v^{2n+1} dv) of the n-node Gauss–Legendre rule."""
    x, w = np.polynomial.legendre.leggauss(n)
    v, w = 0.5 * (x + 1.0), 0.5 * w
    return v * v, np.stack([w * v ** 6, w * v ** 4, w * v ** 2, w * v ** 5], axis=-1)


_LS_V2, _LS_MOMENTS = _moments(32)
# 16 nodes: ln F_5/2 within 3e-5 (I_3/2/I_5/2 within 2e-5 relative) for every λ ≥ 0 —
# used for the start and the first Halley steps only; the last two steps, the
# residual and the flag use the 32-node rule (Halley's cubic convergence removes the
# difference: 3e-5 -> ~1e-14 -> round-off)
_LS_V2_COARSE, _LS_MOMENTS_COARSE = _moments(16)
_LS_FINE_STEPS = 2


def _gt_integrals(lam, coarse=False):
    """ln F_5/2(λ) and the ratios I_3/2/I_5/2, I_1/2/I_5/2, I_2/I_5/2 (= F_n/F_5/2) from
    ONE set of 32 (``coarse``: 16) exponentials (the I_n share the factor
    e^{-λt - t²/2}, t = T v²); the four weighted sums are one small matrix product."""
    v2, mom = (_LS_V2_COARSE, _LS_MOMENTS_COARSE) if coarse else (_LS_V2, _LS_MOMENTS)
    T = _tail_scale(lam)
    t = T[..., None] * v2
    e = jnp.exp(-lam[..., None] * t - 0.5 * t * t)
    m = e @ mom
    i52 = m[..., 0]
    sT = jnp.sqrt(T)
    log_f52 = -0.5 * lam * lam - _LOG_SQRT_2PI + jnp.log(2.0 * (T * T * T * sT) * i52)
    return log_f52, m[..., 1] / (T * i52), m[..., 2] / (T * T * i52), m[..., 3] / (sT * i52)


class _Contact(NamedTuple):
    """Parameters of the load-sharing equation (a pytree: the θ of the implicit rule)."""

    F: jax.Array
    Rx: jax.Array
    k: jax.Array
    a: jax.Array
    b: jax.Array
    u_e: jax.Array
    eta0: jax.Array
    alpha: jax.Array
    E_prime: jax.Array
    sigma: jax.Array
    density: jax.Array
    beta: jax.Array
    c_a: jax.Array


def _log_cap(th):
    """ln(π a b K_GT E'/F_n): the asperity load ratio is φ = cap · F_5/2(λ)."""
    return jnp.log(jnp.pi * th.a * th.b * gt_coefficient(th.sigma, th.density, th.beta)
                   * th.E_prime / th.F)


def _film(log_gamma1, th, film_method):
    """(h_c, h_min) of the fluid load F_n/γ1 on E'/γ1 (Johnson, Greenwood & Poon)."""
    g = jnp.exp(log_gamma1)
    return film_thickness_traced(th.F / g, th.Rx, th.k, th.a, th.u_e, th.eta0, th.alpha,
                                 th.E_prime / g, film_method)


def _ls_residual(s, th, film_method):
    """R(s) = ln φ - ln(π a b K_GT E'/F_n) - ln F_5/2(h_c(F_n/γ1, E'/γ1)/σ), φ = sigmoid(s)."""
    hc = _film(jax.nn.softplus(s), th, film_method)[0]
    return -jax.nn.softplus(-s) - _log_cap(th) - _gt_integrals(th.c_a * hc / th.sigma)[0]


def _ls_iterate(th, film_method):
    """Fixed Halley steps on R(s), elementwise.

    Every film formula is a power law in γ1 at fixed F_n/E' and a (Hamrock–Dowson
    h_c ∝ γ1^0.14, Pan–Hamrock ∝ γ1^0.222, the blend in between), so
    ``λ(s) = λ0 exp(c softplus(s))`` with ``c = ln[h_c(γ1 = e)/h_c(1)]``: each step
    costs one quadrature and no film evaluation.  With F_n' = -n F_{n-1},

        R'  = σ(-s) + 2.5 (I_3/2/I_5/2) λ',      λ' = c σ(s) λ,
        R'' = -σ(s)σ(-s) - d²lnF_5/2/dλ² λ'² + 2.5 (I_3/2/I_5/2) λ'',

    R' > 0 (R is increasing: the root is unique).  The start is the larger of the
    full-film asymptote ``s = ln cap + ln F_5/2(λ0)`` (φ ≪ 1: λ = λ0) and the
    boundary lower bound ``s_b = ln(λ_b/λ0)/c`` where λ_b solves ln F_5/2(λ_b) =
    -ln cap (R(s_b) = ln φ(s_b) ≤ 0); λ_b from the tail form ``ln F_5/2 ≈ -λ²/2 -
    ln√(2π) + ln Γ(7/2) - 3.5 ln(λ + 1.245)`` (exact at λ = 0, within 0.7 of the
    log elsewhere: a start only).  Halley's step is bounded by ``|Δs| ≤ 2/(c σ(s))``
    upward and its denominator by 1/2.
    """
    h0 = _film(jnp.zeros_like(th.F), th, film_method)[0]
    lam0 = th.c_a * h0 / th.sigma          # the λ of the asperity pressure (c_a: see below)
    c = jnp.log(_film(jnp.ones_like(th.F), th, film_method)[0] / h0)
    L = _log_cap(th)
    s_ff = L + _gt_integrals(lam0, coarse=True)[0]
    y = -L
    lb = jnp.sqrt(jnp.maximum(2.0 * (_LGAMMA_3_5 - _LOG_SQRT_2PI - 3.5 * math.log(1.245) - y), 0.0))
    for _ in range(4):
        g = -0.5 * lb * lb - _LOG_SQRT_2PI + _LGAMMA_3_5 - 3.5 * jnp.log(lb + 1.245) - y
        lb = jnp.maximum(lb + g / (lb + 3.5 / (lb + 1.245)), 0.0)
    s_b = jnp.log(jnp.maximum(lb, 1e-300) / lam0) / c
    s = jnp.where(lb > lam0, jnp.maximum(s_ff, s_b), s_ff)
    for i in range(_LS_STEPS):
        sg = jax.nn.sigmoid(s)
        sp = jax.nn.softplus(s)
        lam = lam0 * jnp.exp(c * sp)
        log_f, q32, q12, _ = _gt_integrals(lam, coarse=i < _LS_STEPS - _LS_FINE_STEPS)
        r = s - sp - L - log_f                                # ln φ = -softplus(-s) = s - softplus(s)
        dl = c * sg * lam
        ddl = dl * (c * sg + 1.0 - sg)
        d2 = -2.5 * (-1.5 * q12 + 2.5 * q32 * q32)        # d² ln F_5/2 / dλ²
        rp = (1.0 - sg) + 2.5 * q32 * dl
        rpp = -sg * (1.0 - sg) - d2 * dl * dl + 2.5 * q32 * ddl
        ds = -r / rp
        ds = ds / jnp.maximum(1.0 + 0.5 * ds * rpp / rp, 0.5)
        ds = jnp.minimum(ds, 2.0 / (c * sg))
        s = s + jnp.where(jnp.isfinite(ds), ds, 0.0)
    return s


def load_sharing_traced(F, Rx, k, a, b, u_e, eta0, alpha, E_prime, sigma, density, beta,
                        film_method="auto", asperity_film_factor=1.0):
    """Solve the Johnson–Greenwood–Poon load sharing (elementwise over broadcast arrays).

    F N; Rx, a, b (Hertz semi-axes), σ, β mm; k = a/b; u_e mm/s; η0 Pa·s; α 1/MPa;
    E' MPa; η_s 1/mm².  No validation.  Returns :class:`LoadSharing`.

    The logit s of φ solves R(s) = 0 by four Halley steps from an explicit start
    (:func:`_ls_iterate`; no while loop or line search, so a batch costs the same
    for every point); the residual is then recomputed with the film formula itself
    and ``converged`` is ``|R| ≤ 1e-11`` (and finite).  ds/dθ by the implicit function
    theorem (:func:`gearjax.newton.implicit_root`).

    ``asperity_film_factor`` c_a (default 1: the model above): the asperities are
    loaded as if the separation were ``c_a h_c`` instead of the central film h_c,
    ``F_a = π a b p_a(c_a h_c/σ)``.  An optional correction towards the numerical
    mixed-EHL reference, where the asperities touch mostly in the exit constriction
    and the side lobes (h < h_c); the fitted value and its range are in
    docs/friction.md (:data:`gearjax.tribology.friction.EHL_ASPERITY_FILM_FACTOR`).
    The reported λ and films are those of the fluid (c_a does not scale them).
    """
    th = _Contact(*jnp.broadcast_arrays(*(jnp.asarray(v, float) for v in (
        F, Rx, k, a, b, u_e, eta0, alpha, E_prime, sigma, density, beta,
        asperity_film_factor))))
    s = implicit_root(partial(_ls_iterate, film_method=film_method),
                      partial(_ls_residual, film_method=film_method), th)
    phi = jax.nn.sigmoid(s)
    lg1 = jax.nn.softplus(s)
    # the films are power laws in γ1 (see _ls_iterate): h(γ1) = h(1) γ1^c with
    # c = ln[h(e)/h(1)], the same numbers as film_thickness_traced(F/γ1, E'/γ1) to
    # round-off (tested), for two film evaluations instead of three
    hc0, hm0 = _film(jnp.zeros_like(s), th, film_method)
    hc1, hm1 = _film(jnp.ones_like(s), th, film_method)
    hc = hc0 * jnp.exp(jnp.log(hc1 / hc0) * lg1)
    hm = hm0 * jnp.exp(jnp.log(hm1 / hm0) * lg1)
    lam = hc / th.sigma
    log_f52, _, _, q2 = _gt_integrals(th.c_a * lam)
    res = -jax.nn.softplus(-s) - _log_cap(th) - log_f52
    conv = jnp.isfinite(s) & (jnp.abs(res) <= _LS_TOL)
    # A_r/A = π² (η_s β σ)² F_2(λ), F_2 = F_5/2 I_2/I_5/2 (same exponentials)
    area = math.pi ** 2 * (density * beta * sigma) ** 2 * jnp.exp(log_f52) * q2
    return LoadSharing(phi, jnp.exp(lg1), hc, hm, lam, hc0, area, res, conv)
