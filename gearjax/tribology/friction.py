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

   evaluated by a 16-node Gauss–Legendre rule after a per-point sinh map that
   clusters the nodes where the Eyring argument crosses 1 (:func:`shear_integral`).
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
import functools
import math
import warnings
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.contact import (E_PRIME_MAX_MPA, FUSED_MIN_POINTS, LOAD_MAX_N, MAX_LOG_RATIO,
                             hertz_exact)
from gearjax.errors import any_traced, check_range, require_converged
from gearjax.fields import float64_array
from gearjax.tribology.asperity import load_sharing_traced
from gearjax.tribology.lubricant import (LN_ETA_CAP, LN_ETA_INF, P_ROELANDS_MPA, PA_S_TO_MPA_S, Oil,
                                        log_viscosity_ratio)

__all__ = ["Surface", "make_surface", "FrictionResult", "friction_point_traced",
           "friction_traced", "friction_coefficient", "REGIMES", "STEEL_E_PRIME",
           "validate_contact_inputs", "EHL_ASPERITY_FILM_FACTOR"]

REGIMES = ("boundary", "mixed", "full film")
STEEL_E_PRIME = 2.0 / (2.0 * (1.0 - 0.3 ** 2) / 206000.0)   # 226 374 MPa, steel on steel
SIGMA_MAX_UM = 10.0          # highest accepted composite roughness, µm
SPEED_MAX_MM_S = 5.0e5       # highest accepted entrainment / sliding speed, mm/s (500 m/s)

#: asperity film factor c_a fitted to the numerical mixed-EHL reference (gearjax.tribology.ehl,
#: 64² grid): least squares of ln φ over the 17 mixed points (0.01 ≤ φ ≤ 0.9) of the regime
#: grid λ_s 0.3–5, p_max 0.5–2.5 GPa, Ry/Rx 1–20, u_e 2 m/s, default surface; rms error of
#: ln φ 0.42 -> 0.18 (experiments/ehl_fast_check.py, docs/friction.md).  Not the default.
EHL_ASPERITY_FILM_FACTOR = 0.86

_GL_X, _GL_W = np.polynomial.legendre.leggauss(48)
_S = 0.5 * (_GL_X + 1.0)      # the former fixed 48-node rule on [0, 1] (benchmarks, tests)
_WS = 0.5 * _GL_W
_SH_U, _SH_W = np.polynomial.legendre.leggauss(16)   # nodes of the sinh-mapped shear rule


@dataclasses.dataclass(frozen=True)
class Surface:
    """Surface-pair properties (pytree; all fields differentiable).

    sigma : composite RMS roughness sqrt(σ1² + σ2²), mm.
    density : asperity (summit) density η_s, 1/mm².
    beta : mean asperity tip radius β, mm.
    f_c : boundary friction coefficient at asperity contacts (-).
    v_slip : regularisation speed of the boundary friction, mm/s.
    asperity_film_factor : c_a, the asperities are loaded at the separation c_a h_c
        (default 1: the plain load sharing of [JohnsonGreenwoodPoon1972]; an
        optional correction towards the numerical EHL reference, see
        :func:`gearjax.tribology.asperity.load_sharing_traced` and docs/friction.md).
    """

    sigma: jax.Array
    density: jax.Array
    beta: jax.Array
    f_c: jax.Array
    v_slip: jax.Array
    asperity_film_factor: jax.Array = 1.0


jax.tree_util.register_dataclass(Surface, data_fields=["sigma", "density", "beta", "f_c", "v_slip",
                                                       "asperity_film_factor"],
                                 meta_fields=[])


def make_surface(sigma_um, density_per_mm2=1.0e4, beta_um=10.0, f_c=0.1, v_slip_mm_s=1.0,
                 asperity_film_factor=1.0) -> Surface:
    """Validated :class:`Surface` from σ (µm), η_s (1/mm²), β (µm), f_c, v_slip (mm/s).

    ``asperity_film_factor`` c_a in [0.5, 1] (default 1, no correction): the
    asperities carry the Greenwood–Tripp pressure of the separation c_a h_c;
    ``EHL_ASPERITY_FILM_FACTOR`` is the value fitted to the numerical mixed-EHL
    reference over the range stated in docs/friction.md.

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
    check_range("asperity_film_factor", asperity_film_factor, 0.5, 1.0)
    ebs = float(density_per_mm2) * float(beta_um) * float(sigma_um) * 1e-6
    if not (0.005 <= ebs <= 0.2):
        warnings.warn(f"Greenwood-Tripp asperity model: eta_s*beta*sigma = {ebs:g} is outside "
                      "the range 0.005..0.2 typical of engineering surfaces", stacklevel=2)
    return Surface(*(float64_array(float(v)) for v in
                     (float(sigma_um) * 1e-3, density_per_mm2, float(beta_um) * 1e-3, f_c,
                      v_slip_mm_s, asperity_film_factor)))


class FrictionResult(NamedTuple):
    """Friction at contact points (arrays of the broadcast input shape).

    mu : friction coefficient; mu_boundary, mu_fluid : its asperity and fluid parts.
    friction_force : μ F_n, N.
    a, b : Hertz semi-axes (transverse, rolling), mm; k = a/b; p_max MPa.
    h_c, h_min : central and minimum film under load sharing, mm.
    lam : λ = h_c/σ (under load sharing).  lam_smooth : h_c,smooth/σ (smooth-surface film).
    phi : asperity load ratio F_a/F_n.  area_ratio : A_real/A.
    regime : 0 boundary, 1 mixed, 2 full film (from φ: ≥ 0.9, ≥ 0.01, below; boundary
      also where h_c < :data:`FILM_MIN_MM`, 5 nm, below the film model's range).
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


def _asinh(x):
    """asinh(x) as ±log1p(|x| + x²/(1 + sqrt(1 + x²))): accurate to round-off from
    |x| ≪ 1 (relative) to |x| ~ 1e150, odd (signed sliding speeds), slope 1 at 0,
    cheaper than the general ``jnp.arcsinh`` in XLA CPU."""
    pos = x >= 0.0
    xa = jnp.where(pos, x, -x)
    y = jnp.log1p(xa + xa * xa / (1.0 + jnp.sqrt(1.0 + xa * xa)))
    return jnp.where(pos, y, -y)


def _shear_map(p_f, X0, oil, viscosity_model):
    """Parameters (a, c, h) of the sinh map of :func:`shear_integral`, elementwise.

    The integrand asinh(X0 e^{L(s)}), L = ln(η(p_f s)/η0), has its nearest complex
    singularities where L(s) = -ln X0 ± iπ/2 (the branch points of asinh at ±i);
    in closed form s* = ((1 + (L_c ± iπ/2)/A)^{1/z} - 1)/β (Roelands, β = p_f/p_R,
    L_c = -ln X0) or s* = (L_c ± iπ/2)/(α p_f) (Barus).  a is Re s* clamped to the
    interval [0, h], c its distance to s* (≤ 10).  h = min(1, s_cap) ends the
    analytic part where the cap ln(η/η0) = 150 is reached (beyond it the integrand
    is constant).
    """
    Lc = -jnp.log(jnp.maximum(jnp.abs(X0), 1e-300))
    if viscosity_model == "roelands":
        A = jnp.log(oil.eta0) + LN_ETA_INF
        beta = jnp.maximum(p_f / P_ROELANDS_MPA, 1e-30)
        wr, wi = 1.0 + Lc / A, 0.5 * jnp.pi / A
        rz = jnp.exp(0.5 * jnp.log(wr * wr + wi * wi) / oil.z)
        th = jnp.arctan2(wi, wr) / oil.z
        sr, si = (rz * jnp.cos(th) - 1.0) / beta, rz * jnp.sin(th) / beta
        s_cap = jnp.expm1(jnp.log1p(LN_ETA_CAP / A) / oil.z) / beta
    else:
        ap = jnp.maximum(oil.alpha * p_f, 1e-30)
        sr, si = Lc / ap, 0.5 * jnp.pi / ap
        s_cap = LN_ETA_CAP / ap
    h = jnp.minimum(s_cap, 1.0)
    a = jnp.clip(sr, 0.0, h)
    c = jnp.minimum(jnp.hypot(si, sr - a), 10.0)
    ok = jnp.isfinite(a) & jnp.isfinite(c) & (c > 0.0)
    return jnp.where(ok, a, 0.0), jnp.where(ok, c, 10.0), jnp.where(jnp.isfinite(h), h, 1.0)


def shear_integral(p_f, X0, oil: Oil, viscosity_model="roelands"):
    """J = ∫_0^1 asinh(X0 η(p_f s)/η0) s ds, elementwise (the fluid shear over the
    Hertz ellipse is ``2π a b τ0 J``; X0 = η0 u_s/(h_c τ0) is the Eyring argument at
    the edge of the contact, p_f the fluid's peak pressure, MPa).

    16-node Gauss–Legendre rule after the sinh transformation (Johnston & Elliott,
    Int. J. Numer. Meth. Eng. 62 (2005) 564–578) ``s = a + c sinh(μ u - ν)``,
    u ∈ [-1, 1], which clusters the nodes at the nearly singular point a ± ic of the
    integrand (:func:`_shear_map`): where X crosses 1 the integrand turns from
    ~X to ~ln 2X over a width ~1/(dL/ds), which is ~1/40 of the interval at gear
    pressures.  Relative error ≤ 5e-10 over p_f ≤ 4 GPa, X0 = 1e-10..1e5,
    η0 = 3e-3..3 Pa·s, z = 0.3..1, Roelands and Barus (tests/test_friction_kernel.py;
    the former fixed 48-node rule in s: up to 1e-4 there), ~1e-11 at gear
    conditions.  Per node: three exp, two log, one sqrt.  The part beyond the
    viscosity cap (s > h) is added in closed form.  The map is held constant under
    differentiation (stop_gradient): the derivative is the same rule applied to the
    derivative of the integrand, whose singularities are the same.

    Two routes, the same rule: below :data:`~gearjax.contact.FUSED_MIN_POINTS` points a
    points x nodes array (the smaller program), from there on node by node in one fused
    loop with the partials in closed form as its derivative rule (docs/friction.md,
    "Third pass"; values equal to 4e-16, derivatives to 1e-11).
    """
    shape = jnp.broadcast_shapes(jnp.shape(p_f), jnp.shape(X0), jnp.shape(oil.eta0), jnp.shape(oil.z))
    p_f, X0 = (jnp.broadcast_to(jnp.asarray(v, float), shape) for v in (p_f, X0))
    if math.prod(shape) >= FUSED_MIN_POINTS:
        return _shear_rule(viscosity_model, p_f, X0, oil)
    return _shear_stacked(viscosity_model, p_f, X0, oil)


def _shear_start(viscosity_model, p_f, X0, oil):
    """``(a, c, h, mu, nu)``: the sinh map (held constant) and its ``s = a + c sinh(mu
    u - nu)`` over u in [-1, 1]."""
    sg = jax.lax.stop_gradient
    a, c, h = _shear_map(sg(p_f), sg(X0), jax.tree_util.tree_map(sg, oil), viscosity_model)
    r1, r2 = jnp.arcsinh(a / c), jnp.arcsinh((h - a) / c)
    return a, c, h, 0.5 * (r1 + r2), 0.5 * (r1 - r2)


def _shear_stacked(viscosity_model, p_f, X0, oil):
    """The rule of :func:`shear_integral` on a points x nodes array: the smaller program
    (the route of the loaded chain's few contacts, where compilation is the cost)."""
    a, c, h, mu, nu = _shear_start(viscosity_model, p_f, X0, oil)
    oil = jax.tree_util.tree_map(lambda v: jnp.asarray(v)[..., None], oil)   # against the nodes
    e = jnp.exp(mu[..., None] * _SH_U - nu[..., None])
    ei = 1.0 / e
    s = a[..., None] + (0.5 * c)[..., None] * (e - ei)              # a + c sinh(t)
    w = (0.5 * c * mu)[..., None] * (_SH_W * (e + ei))              # c μ cosh(t) du
    L = jnp.minimum(log_viscosity_ratio(p_f[..., None] * s, oil, viscosity_model), LN_ETA_CAP)
    body = jnp.sum(w * s * _asinh(X0[..., None] * jnp.exp(L)), axis=-1)
    tail = _asinh(X0 * math.exp(LN_ETA_CAP)) * 0.5 * (1.0 - h * h)
    return body + tail


def _asinh_slopes(X0, L):
    """``(d/dX0, d/dL)`` of ``asinh(X0 e^L)``: ``e^L/sqrt(1 + y^2)`` and
    ``y/sqrt(1 + y^2)``, ``y = X0 e^L``, written to stay finite for ``|y|`` up to
    overflow (then ``1/(|X0| sqrt(1 + 1/y^2))`` and ``sign(y)/sqrt(1 + 1/y^2)``)."""
    eL = jnp.exp(L)
    y = X0 * eL
    big = jnp.abs(y) > 1.0
    inv = 1.0 / jnp.where(big, y, 1.0)
    root_big = jnp.sqrt(1.0 + inv * inv)
    root = jnp.sqrt(1.0 + jnp.where(big, 1.0, y * y))
    d_x = jnp.where(big, 1.0 / (jnp.abs(jnp.where(big, X0, 1.0)) * root_big), eL / root)
    d_l = jnp.where(big, jnp.sign(y) / root_big, y / root)
    return d_x, d_l


def _shear_nodes(viscosity_model, p_f, X0, oil, partials=False):
    """The rule of :func:`shear_integral` (``p_f``, ``X0`` of one shape), one node at a
    time on arrays of the points' shape: XLA fuses the whole rule into one elementwise
    loop (on a points x nodes array it wrote four intermediate arrays to memory; 1e5
    points 59 -> 19 ms, the same values to 4e-16).  With ``partials``: ``(J, dJ/dp_f,
    dJ/dX0, dJ/deta0, dJ/dz)`` from the same loop (the map held constant), with
    ``L = A expm1(z ln(1 + q))``, ``A = ln eta0 + 9.67``, ``q = p_f s/p_R`` (Roelands)
    or ``L = z A p_f s/p_R`` (Barus, ``alpha = z A/p_R``), and ``dL = 0`` past the cap."""
    a, c, h, mu, nu = _shear_start(viscosity_model, p_f, X0, oil)
    half_c, half_cmu = 0.5 * c, 0.5 * c * mu
    A = jnp.log(oil.eta0) + LN_ETA_INF
    zero = jnp.zeros(jnp.shape(p_f))

    def node(k, acc):
        body, j_p, j_x, j_e, j_z = acc
        u, wq = (jnp.asarray(_SH_U)[k], jnp.asarray(_SH_W)[k]) if partials else (_SH_U[k], _SH_W[k])
        e = jnp.exp(mu * u - nu)
        ei = 1.0 / e
        s = a + half_c * (e - ei)                                     # a + c sinh(t)
        w = half_cmu * (wq * (e + ei))                                # c μ cosh(t) du
        L_raw = log_viscosity_ratio(p_f * s, oil, viscosity_model)
        L = jnp.minimum(L_raw, LN_ETA_CAP)
        body = body + w * s * _asinh(X0 * jnp.exp(L))
        if not partials:
            return body, j_p, j_x, j_e, j_z
        d_x, d_l = _asinh_slopes(X0, L)
        ws = w * s
        d_l = jnp.where(L_raw < LN_ETA_CAP, ws * d_l, 0.0)
        if viscosity_model == "roelands":
            q = p_f * s / P_ROELANDS_MPA
            ell = jnp.log1p(q)
            P = jnp.exp(oil.z * ell)
            l_p = A * oil.z * P / (1.0 + q) * s / P_ROELANDS_MPA
            l_e = jnp.expm1(oil.z * ell) / oil.eta0
            l_z = A * P * ell
        else:
            l_p = oil.z * A * s / P_ROELANDS_MPA
            l_e = oil.z / (P_ROELANDS_MPA * oil.eta0) * p_f * s
            l_z = A / P_ROELANDS_MPA * p_f * s
        j_p, j_e, j_z = j_p + d_l * l_p, j_e + d_l * l_e, j_z + d_l * l_z
        j_x = j_x + ws * d_x
        return body, j_p, j_x, j_e, j_z

    if partials:
        # a loop (the five sums as its carry): unrolled, the partials' sixteen nodes gave
        # a program that compiled 2 s longer and ran slower (1e5 points: 74 -> 32 ms)
        body, j_p, j_x, j_e, j_z = jax.lax.fori_loop(0, len(_SH_U), node, (zero,) * 5)
    else:
        # unrolled: one fused elementwise loop (as a loop over nodes, 19 -> 42 ms)
        body = zero
        for k in range(len(_SH_U)):
            body = node(k, (body, zero, zero, zero, zero))[0]
    tail_w = 0.5 * (1.0 - h * h)
    value = body + _asinh(X0 * math.exp(LN_ETA_CAP)) * tail_w
    if not partials:
        return value
    j_x = j_x + _asinh_slopes(X0, jnp.full_like(X0, LN_ETA_CAP))[0] * tail_w
    return value, j_p, j_x, j_e, j_z


@functools.partial(jax.custom_jvp, nondiff_argnums=(0,))
def _shear_rule(viscosity_model, p_f, X0, oil):
    return _shear_nodes(viscosity_model, p_f, X0, oil)


@functools.partial(_shear_rule.defjvp, symbolic_zeros=True)
def _shear_rule_jvp(viscosity_model, primals, tangents):
    """``dJ = J_p dp_f + J_X dX0 + J_eta dη0 + J_z dz`` with the partials of the same
    fused node loop (:func:`_shear_nodes`): reverse mode keeps four partials per point
    instead of the loop's intermediates at every node.  (τ0 and ρ0 do not enter J.)"""
    value, j_p, j_x, j_e, j_z = _shear_nodes(viscosity_model, *primals, partials=True)
    dp, dx, doil = tangents
    out = jnp.zeros_like(value)
    for j, d in ((j_p, dp), (j_x, dx), (j_e, doil.eta0), (j_z, doil.z)):
        if not isinstance(d, jax.custom_derivatives.SymbolicZero):
            out = out + j * d
    return value, out


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
                             surface.sigma, surface.density, surface.beta, film_method,
                             surface.asperity_film_factor)
    p_f = (1.0 - ls.phi) * hz.p_max
    X0 = oil.eta0 * PA_S_TO_MPA_S * u_s / (ls.h_c * oil.tau0)
    F_tau = 2.0 * jnp.pi * hz.a * hz.b * oil.tau0 * shear_integral(p_f, X0, oil, viscosity_model)
    mu_f = F_tau / F
    mu_b = surface.f_c * ls.phi * jnp.tanh(u_s / surface.v_slip)
    mu = mu_b + mu_f
    # bands of the asperity load ratio; a film thinner than FILM_MIN_MM (a few molecular
    # layers) is boundary lubrication whatever the continuum model's share says
    regime = jnp.where((ls.phi >= 0.9) | (ls.h_c < FILM_MIN_MM), 0,
                       jnp.where(ls.phi >= 1e-2, 1, 2))
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


#: smallest central film thickness (mm; 5 nm) inside the range of the film /
#: asperity-load-sharing model: a continuum EHL film a few molecular layers thick is
#: already boundary lubrication; below it the regime label and the asperity share
#: are not reliable (:func:`warn_validity` warns)
FILM_MIN_MM = 5e-6


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
    h_c = np.asarray(out.h_c, float)
    if np.any(h_c < FILM_MIN_MM):
        warnings.warn(f"central film h_c down to {1e6 * np.nanmin(h_c):.3g} nm, below the film/"
                      f"asperity model's range ({1e6 * FILM_MIN_MM:g} nm, FILM_MIN_MM): labelled "
                      "boundary there (a film a few molecular layers thick); the asperity load "
                      "share and mu there are not reliable", stacklevel=3)
    pm = np.asarray(out.p_max)
    if np.any(pm > 3000.0):
        warnings.warn(f"{viscosity_model.capitalize()} viscosity law extrapolated above 3 GPa "
                      f"(p_max up to {pm.max():.0f} MPa); its validity range is about 0-3 GPa",
                      stacklevel=3)


def friction_coefficient(F, u_e, u_s, Rx, Ry, oil: Oil, surface: Surface, E_prime=STEEL_E_PRIME,
                         *, viscosity_model="roelands", film_method="auto",
                         throw=True) -> FrictionResult:
    """Mixed-lubrication friction at contact points: the one entry point, concrete or traced.

    With concrete inputs it validates them first (a one-line ``ValueError`` naming the
    parameter and its range), runs one compiled kernel on padded arrays and raises
    :class:`~gearjax.errors.ConvergenceError` on a failed solve when ``throw``.  Inside
    ``jax.jit``, ``jax.grad`` or ``jax.vmap`` (any input traced) it is the traced kernel
    itself: no validation, no exception, the ``converged`` mask in the result.

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
    throw : raise ConvergenceError if any solve failed (default); else return
        the ``converged`` mask.

    Returns :class:`FrictionResult`.
    """
    if any_traced(F, u_e, u_s, Rx, Ry, E_prime, oil, surface):
        return friction_traced(F, u_e, u_s, Rx, Ry, oil, surface, E_prime,
                               viscosity_model=viscosity_model, film_method=film_method)
    validate_contact_inputs(F, u_e, u_s, Rx, Ry, E_prime)
    if viscosity_model not in ("roelands", "barus"):
        raise ValueError(f"viscosity_model = {viscosity_model!r} must be 'roelands' or 'barus'")
    if film_method not in ("auto", "point", "line"):
        raise ValueError(f"film_method = {film_method!r} must be 'auto', 'point' or 'line'")
    out = friction_padded(F, u_e, u_s, Rx, Ry, oil, surface, E_prime, viscosity_model, film_method)
    if throw:
        require_converged(out.converged, "friction (Hertz / load-sharing solves)")
    warn_validity(out, film_method, viscosity_model)
    return out
