"""Mixed-lubrication friction coefficient of a Hertzian contact ([VH-CATT], see docs/references.md).

    μ = F_f / F_n = [ f_c F_a r(u_s) + ∫_A τ dA ] / F_n,                      [VH-CATT]
    τ = τ0 asinh( η(p_f) u_s / (h_c τ0) )                                     (Ree–Eyring)

Ingredients, per contact point:

1. Hertz ellipse of the total load F_n (:func:`gearjax.contact.hertz_point_traced`):
   semi-axes a (transverse), b (rolling), p_max.
2. Film/asperity load sharing (:func:`gearjax.tribology.asperity.load_sharing_traced`):
   asperity load F_a = φ F_n, fluid load F_h = (1-φ) F_n, central film h_c, λ = h_c/σ.
3. Fluid shear integrated over the Hertz ellipse with the local pressure-dependent
   viscosity.  The fluid carries the Hertzian pressure shape scaled by its share,
   ``p_f(x, y) = (1-φ) p_max sqrt(1 - x²/b² - y²/a²)``; the film is taken uniform
   (h_c) over the ellipse (the EHL plateau).  In elliptic polar coordinates with
   ``s = sqrt(1 - ρ²)`` the area integral becomes one-dimensional,

       ∫_A τ dA = 2π a b ∫_0^1 τ((1-φ) p_max s) s ds,

   evaluated by 48-point Gauss–Legendre quadrature (the integrand is analytic).
4. Boundary friction f_c F_a at the asperities.  The ``F_c = f_c F_a`` of [VH-CATT] is a
   Coulomb law: it does not vanish in pure rolling and jumps at u_s = 0.  gearjax
   multiplies it by ``r(u_s) = tanh(u_s / v_slip)`` (a regularised Coulomb law,
   v_slip = 1 mm/s by default, i.e. r = 1 to machine precision for u_s > 40 mm/s),
   so that μ → 0 in pure rolling as the issue requires and μ is smooth in u_s.

Speeds are in **mm/s** inside the library (the CLI takes m/s).  Loads N, radii mm,
E' MPa, η0 Pa·s, α 1/MPa, τ0 MPa, σ and β mm, asperity density 1/mm².

Regime, from the asperity load ratio φ = F_a/F_n (gearjax's thresholds):
boundary φ ≥ 0.9, mixed 0.01 ≤ φ < 0.9, full film φ < 0.01 (asperities carry less
than 1 % of the load; the minimum of the Stribeck curve lies near φ ≈ 0.5–1 % in
the examples of docs/friction.md); code 0/1/2
(``REGIMES``).  (With the JGP load sharing λ under load sharing levels off in the
boundary regime, see :mod:`gearjax.tribology.asperity`; the classical bands on the
smooth-surface λ_s — boundary < 1 < mixed < 3 < full film — are close to these
for the default surfaces but not identical.)
"""

from __future__ import annotations

import dataclasses
import warnings
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.contact import E_PRIME_MAX_MPA, LOAD_MAX_N, MAX_LOG_RATIO, hertz_exact
from gearjax.errors import check_range, require_converged
from gearjax.fields import float64_array
from gearjax.tribology.asperity import load_sharing_traced
from gearjax.tribology.lubricant import Oil, eyring_shear, viscosity

__all__ = ["Surface", "make_surface", "FrictionResult", "friction_point_traced",
           "friction_traced", "friction_coefficient", "REGIMES", "STEEL_E_PRIME",
           "validate_contact_inputs"]

REGIMES = ("boundary", "mixed", "full film")
STEEL_E_PRIME = 2.0 / (2.0 * (1.0 - 0.3 ** 2) / 206000.0)   # 226 374 MPa, steel on steel
SIGMA_MAX_UM = 10.0          # highest accepted composite roughness, µm
SPEED_MAX_MM_S = 5.0e5       # highest accepted entrainment / sliding speed, mm/s (500 m/s)

_GL_X, _GL_W = np.polynomial.legendre.leggauss(48)
_S = 0.5 * (_GL_X + 1.0)
_WS = 0.5 * _GL_W


@dataclasses.dataclass(frozen=True)
class Surface:
    """Surface-pair properties (pytree; all fields differentiable).

    sigma : composite RMS roughness sqrt(σ1² + σ2²), mm.
    density : asperity (summit) density η_s, 1/mm².
    beta : mean asperity tip radius β, mm.
    f_c : boundary friction coefficient at asperity contacts (-).
    v_slip : regularisation speed of the boundary friction, mm/s.
    """

    sigma: jax.Array
    density: jax.Array
    beta: jax.Array
    f_c: jax.Array
    v_slip: jax.Array


jax.tree_util.register_dataclass(Surface, data_fields=["sigma", "density", "beta", "f_c", "v_slip"],
                                 meta_fields=[])


def make_surface(sigma_um, density_per_mm2=1.0e4, beta_um=10.0, f_c=0.1, v_slip_mm_s=1.0) -> Surface:
    """Validated :class:`Surface` from σ (µm), η_s (1/mm²), β (µm), f_c, v_slip (mm/s).

    Defaults (η_s = 1e4 mm⁻² = 1e10 m⁻², β = 10 µm, f_c = 0.1) are representative of
    ground steel gear flanks (η_s β σ ≈ 0.03–0.05 for σ ≈ 0.3–0.5 µm, the range
    quoted by Gelinck & Schipper 2000); measured values should replace them.

    Accepted ranges (``ValueError`` otherwise): σ in (0, 10] µm (superfinished to
    rough-milled flanks), η_s in (0, 1e6] mm⁻², β in (0, 1000] µm, f_c in [0, 1],
    v_slip in (0, 1000] mm/s.
    """
    check_range("sigma", sigma_um, 0.0, SIGMA_MAX_UM, lo_open=True, unit="um")
    check_range("asperity density", density_per_mm2, 0.0, 1e6, lo_open=True, unit="1/mm^2")
    check_range("asperity radius", beta_um, 0.0, 1000.0, lo_open=True, unit="um")
    check_range("f_c", f_c, 0.0, 1.0)
    check_range("v_slip", v_slip_mm_s, 0.0, 1000.0, lo_open=True, unit="mm/s")
    ebs = float(density_per_mm2) * float(beta_um) * float(sigma_um) * 1e-6
    if not (0.005 <= ebs <= 0.2):
        warnings.warn(f"Greenwood-Tripp asperity model: eta_s*beta*sigma = {ebs:g} is outside "
                      "the range 0.005..0.2 typical of engineering surfaces", stacklevel=2)
    return Surface(*(float64_array(float(v)) for v in
                     (float(sigma_um) * 1e-3, density_per_mm2, float(beta_um) * 1e-3, f_c,
                      v_slip_mm_s)))


class FrictionResult(NamedTuple):
    """Friction at contact points (arrays of the broadcast input shape).

    mu : friction coefficient; mu_boundary, mu_fluid : its asperity and fluid parts.
    friction_force : μ F_n, N.
    a, b : Hertz semi-axes (transverse, rolling), mm; k = a/b; p_max MPa.
    h_c, h_min : central and minimum film under load sharing, mm.
    lam : λ = h_c/σ (under load sharing).  lam_smooth : h_c,smooth/σ (smooth-surface film).
    phi : asperity load ratio F_a/F_n.  area_ratio : A_real/A.
    regime : 0 boundary, 1 mixed, 2 full film (from φ).
    converged : both solves (Hertz ellipticity, load sharing) converged.
    """

    mu: jax.Array
    mu_boundary: jax.Array
    mu_fluid: jax.Array
    friction_force: jax.Array
    a: jax.Array
    b: jax.Array
    k: jax.Array
    p_max: jax.Array
    h_c: jax.Array
    h_min: jax.Array
    lam: jax.Array
    lam_smooth: jax.Array
    phi: jax.Array
    area_ratio: jax.Array
    regime: jax.Array
    converged: jax.Array


def friction_point_traced(F, u_e, u_s, Rx, Ry, oil: Oil, surface: Surface, E_prime,
                          viscosity_model="roelands", film_method="auto") -> FrictionResult:
    """Friction at contact points, elementwise over broadcast arrays (no validation;
    jit/vmap/grad-friendly; the name is historical: scalars give one point).

    F N, u_e and u_s (≥ 0) mm/s, Rx, Ry mm, E' MPa.  Every stage is array code with
    a fixed amount of work per point (no while loops), so one call handles any
    number of points at the same cost per point.
    """
    F, u_e, u_s, Rx, Ry, E_prime = jnp.broadcast_arrays(
        *(jnp.asarray(v, float) for v in (F, u_e, u_s, Rx, Ry, E_prime)))
    hz = hertz_exact(F, Rx, Ry, E_prime)
    ls = load_sharing_traced(F, Rx, hz.k, hz.a, hz.b, u_e, oil.eta0, oil.alpha, E_prime,
                             surface.sigma, surface.density, surface.beta, film_method)
    p_f = ((1.0 - ls.phi) * hz.p_max)[..., None] * _S
    eta = viscosity(p_f, oil, viscosity_model)
    tau = eyring_shear(eta, u_s[..., None], ls.h_c[..., None], oil.tau0)
    F_tau = 2.0 * jnp.pi * hz.a * hz.b * jnp.sum(_WS * _S * tau, axis=-1)
    mu_f = F_tau / F
    mu_b = surface.f_c * ls.phi * jnp.tanh(u_s / surface.v_slip)
    mu = mu_b + mu_f
    regime = jnp.where(ls.phi >= 0.9, 0, jnp.where(ls.phi >= 1e-2, 1, 2))
    return FrictionResult(mu, mu_b, mu_f, mu * F, hz.a, hz.b, hz.k, hz.p_max, ls.h_c, ls.h_min,
                          ls.lam, ls.h_c_smooth / surface.sigma, ls.phi, ls.area_ratio, regime,
                          hz.converged & ls.converged)


def friction_traced(F, u_e, u_s, Rx, Ry, oil: Oil, surface: Surface, E_prime=STEEL_E_PRIME,
                    viscosity_model="roelands", film_method="auto") -> FrictionResult:
    """Vectorised friction over broadcast arrays of any shape (no validation).

    Same as :func:`friction_point_traced` (which is elementwise); kept as the
    documented entry point for arrays such as (n_positions, n_points).
    """
    return friction_point_traced(F, u_e, u_s, Rx, Ry, oil, surface, E_prime,
                                 viscosity_model=viscosity_model, film_method=film_method)


_friction_jit = jax.jit(friction_traced, static_argnames=("viscosity_model", "film_method"))


def friction_padded(F, u_e, u_s, Rx, Ry, oil, surface, E_prime, viscosity_model, film_method):
    """Run the jitted kernel on flat arrays padded to a power-of-two length (≥ 64).

    Padding (with copies of the first point) lets calls of different sizes share a
    few compiled kernels instead of compiling once per shape.  Concrete inputs only.
    """
    arrays = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (F, u_e, u_s, Rx, Ry, E_prime)))
    shape, n = arrays[0].shape, arrays[0].size
    nb = max(64, 1 << (n - 1).bit_length())
    flat = [np.concatenate([a.ravel(), np.full(nb - n, a.ravel()[0])]) for a in arrays]
    oil = dataclasses.replace(oil, name="")  # the label must not trigger recompilation
    out = _friction_jit(*flat[:5], oil, surface, flat[5],
                        viscosity_model=viscosity_model, film_method=film_method)
    return FrictionResult(*(jnp.reshape(v[:n], shape) for v in out))


def _check_all(name, value, unit, allow_zero=False, hi=None):
    """Check every entry of ``value`` against (0, hi] (or [0, hi]); the first bad
    entry is named in the ``ValueError``."""
    arr = np.asarray(value, dtype=float)
    bad = ~np.isfinite(arr) | ((arr < 0) if allow_zero else (arr <= 0))
    if hi is not None:
        bad |= arr > hi
    if np.any(bad):
        check_range(name, arr[bad].ravel()[0], 0.0, hi, lo_open=not allow_zero, unit=unit)
    return arr


def validate_contact_inputs(F, u_e, u_s, Rx, Ry, E_prime, allow_signed_us=False):
    """Boundary checks shared by the public entry points (raise ValueError).

    Ranges: load F in (0, 1e7] N, u_e in (0, 5e5] mm/s (500 m/s: above the
    pitch-line speeds of the fastest turbo gears, about 200 m/s), u_s in
    [0, 5e5] mm/s (signed: |u_s| <= 5e5 mm/s), Rx, Ry > 0 mm with Ry/Rx in
    [1e-15, 1e15], E' in (0, 1e7] MPa.
    """
    _check_all("load", F, "N", hi=LOAD_MAX_N)
    _check_all("u_e", u_e, "mm/s", hi=SPEED_MAX_MM_S)
    if allow_signed_us:
        arr = np.asarray(u_s, float)
        bad = ~np.isfinite(arr) | (np.abs(arr) > SPEED_MAX_MM_S)
        if np.any(bad):
            check_range("u_s", arr[bad].ravel()[0], -SPEED_MAX_MM_S, SPEED_MAX_MM_S, unit="mm/s")
    else:
        _check_all("u_s", u_s, "mm/s", allow_zero=True, hi=SPEED_MAX_MM_S)
    rx = _check_all("Rx", Rx, "mm")
    ry = _check_all("Ry", Ry, "mm")
    _check_all("E_prime", E_prime, "MPa", hi=E_PRIME_MAX_MPA)
    lr = np.abs(np.log(ry) - np.log(rx))
    if np.any(lr > MAX_LOG_RATIO):
        raise ValueError(f"Ry/Rx = {float(np.max(ry / rx)):g} is outside the allowed range "
                         "[1e-15, 1e15]")


def warn_validity(out: FrictionResult, film_method: str, viscosity_model: str):
    """Warn (naming formula and range) where a correlation is used outside its fit.

    Film: Hamrock–Dowson is fitted for 1 <= k <= 8 ("point"; with "auto" it is used
    alone for k <= 8, so k < 1 — the ellipse elongated along the rolling direction,
    Rx > Ry — lies outside its fit); Pan–Hamrock is a line-contact formula, which
    "line" applies also to contacts that are not elongated (k < 8).  Viscosity laws:
    0–3 GPa.
    """
    k = np.asarray(out.k)
    if film_method == "point" and (np.any(k > 8.0) or np.any(k < 1.0)):
        warnings.warn("Hamrock-Dowson film formula used outside its fitted ellipticity range "
                      f"1 <= k <= 8 (k from {k.min():.3g} to {k.max():.3g}); "
                      "consider film_method='auto'", stacklevel=3)
    if film_method == "auto" and np.any(k < 1.0):
        warnings.warn("Hamrock-Dowson film formula used outside its fitted ellipticity range "
                      f"1 <= k <= 8 (k down to {k.min():.3g}: Rx > Ry, the contact is elongated "
                      "along the rolling direction)", stacklevel=3)
    if film_method == "line" and np.any(k < 8.0):
        warnings.warn("Pan-Hamrock line-contact film formula applied to a contact that is not "
                      f"elongated (k down to {k.min():.3g}; line contact needs k >> 8, the "
                      "Hamrock-Dowson range is 1 <= k <= 8); consider film_method='auto'",
                      stacklevel=3)
    pm = np.asarray(out.p_max)
    if np.any(pm > 3000.0):
        warnings.warn(f"{viscosity_model.capitalize()} viscosity law extrapolated above 3 GPa "
                      f"(p_max up to {pm.max():.0f} MPa); its validity range is about 0-3 GPa",
                      stacklevel=3)


def friction_coefficient(F, u_e, u_s, Rx, Ry, oil: Oil, surface: Surface, E_prime=STEEL_E_PRIME,
                         *, viscosity_model="roelands", film_method="auto",
                         strict=True) -> FrictionResult:
    """Mixed-lubrication friction at contact points (validated public entry point).

    Parameters (arrays broadcast together)
    ----------
    F : normal load, N (in (0, 1e7]).
    u_e : entrainment speed (u1+u2)/2, mm/s (in (0, 5e5], i.e. up to 500 m/s).
    u_s : sliding speed |u1-u2|, mm/s (in [0, 5e5]).
    Rx, Ry : relative radii of curvature in the rolling / transverse direction, mm.
    oil : :class:`gearjax.tribology.lubricant.Oil` (``get_oil`` / ``make_oil``).
    surface : :class:`Surface` (``make_surface``).
    E_prime : reduced modulus E' = 2E*, MPa (in (0, 1e7]; default steel/steel 226 374 MPa).
    viscosity_model : ``"roelands"`` (default) or ``"barus"``.
    film_method : ``"auto"`` (default), ``"point"`` or ``"line"`` (see
        :mod:`gearjax.tribology.film`).
    strict : raise ConvergenceError if any solve failed (default); else return
        the ``converged`` mask.

    Returns :class:`FrictionResult`.
    """
    validate_contact_inputs(F, u_e, u_s, Rx, Ry, E_prime)
    if viscosity_model not in ("roelands", "barus"):
        raise ValueError(f"viscosity_model = {viscosity_model!r} must be 'roelands' or 'barus'")
    if film_method not in ("auto", "point", "line"):
        raise ValueError(f"film_method = {film_method!r} must be 'auto', 'point' or 'line'")
    out = friction_padded(F, u_e, u_s, Rx, Ry, oil, surface, E_prime, viscosity_model, film_method)
    if strict:
        require_converged(out.converged, "friction (Hertz / load-sharing solves)")
    warn_validity(out, film_method, viscosity_model)
    return out
