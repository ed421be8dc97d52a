"""Hertz theory of elastic point (elliptical) and line contact, differentiable in JAX.

Units
-----
Lengths in mm, forces in N, moduli and pressures in MPa (N/mm²).

Conventions
-----------
``x`` is the rolling (entrainment) direction and ``Rx`` the relative radius of
curvature in it; ``y`` is the transverse direction with relative radius ``Ry``
(``1/Rx = 1/R_x1 ± 1/R_x2`` etc. — the *relative* principal radii of the two
surfaces, with aligned principal directions).  The contact ellipse has semi-axis
``a`` along ``y`` and ``b`` along ``x`` (Hamrock's convention), ellipticity
``k = a/b``; ``k > 1`` when ``Ry > Rx`` (the usual gear-flank case, elongated
across the rolling direction).

The modulus is the *reduced modulus of elasticity* of Hamrock and Dowson,

    E' = 2 / [(1 - ν1²)/E1 + (1 - ν2²)/E2]  = 2 E*,

E* being the contact modulus of Johnson (Contact Mechanics, 1985).  E' is also
what the EHL film formulas use (``gearjax.tribology.film``).  [VH-CATT]
(see docs/references.md; eq. for a, b) writes ``a = k_a [3w / (2E'(A+B))]^(1/3)`` without defining E';
gearjax uses E' = 2E* everywhere and says so.

Exact solution (Johnson 1985, §4.2; Hamrock, Schmid & Jacobson, *Fundamentals of
Fluid Film Lubrication*, 2004, ch. 3).  With ``k' = b/a = 1/k``, ``m = 1 - k'²``,
complete elliptic integrals ``K(m)``, ``E(m)`` and the auxiliary functions

    D(m) = (K - E)/m,     B(m) = (E - k'² K)/m = K - D,

the ellipticity follows from the curvature ratio

    Ry/Rx = B(m) / (k'² D(m)),                                   (1)

and then, with ``1/R = 1/Rx + 1/Ry``,

    b³ = 6 E(m) k' F R / (π E'),   a = k b,                      (2)
    p_max = 3 F / (2 π a b),                                     (3)
    δ (approach) = 2 p_max b K(m) / E'.                          (4)

(1)–(4) contain ``K - E`` only through ``D`` and ``B``, which are computed without
cancellation by the arithmetic–geometric mean (AGM) — so the circle (m = 0) and
the very elongated contact (m → 1, Ry/Rx up to 1e15) are both evaluated to
machine precision and differentiably.  Equation (1) is solved for
``t = ln k`` by three Newton steps from an explicit start (Hamrock–Brewe near the
circle, the elongated-ellipse asymptote beyond), derivatives by the implicit
function theorem (:func:`gearjax.newton.implicit_root`).  ``t < 0`` (Rx > Ry) is
the analytic continuation to ``m < 0``; the AGM works there too, so both
orientations need no branch.

Line contact is the limit Ry/Rx → ∞ at fixed load per unit length ``w'``:
``b = sqrt(8 w' Rx / (π E'))``, ``p_max = 2 w' / (π b)``
(:func:`hertz_line`).  The exact elliptical solution tends to it: the centre-line
load intensity ``w'_c = π p_max b / 2 = 3F/(4a)`` satisfies ``b → 4 p_max Rx / E'``
(tested).

Curve-fit approximations (for hand checks and comparison with older design codes;
``method`` of :func:`hertz_point`), with ``α_r = Ry/Rx ≥ 1``:

* ``"brewe_hamrock_1977"`` (alias ``"hamrock_brewe"``) — least-squares fits of
  Brewe & Hamrock, J. Lubr. Technol. 99 (1977) 485–487:
  ``k ≈ 1.0339 α_r^0.6360``, ``ℰ ≈ 1.0003 + 0.5968/α_r``,
  ``ℱ ≈ 1.5277 + 0.6023 ln α_r``;
* ``"hamrock_brewe_1983"`` — the simplified forms of Hamrock & Brewe,
  J. Lubr. Technol. 105 (1983) 171–177: ``k ≈ α_r^(2/π)``,
  ``ℰ ≈ 1 + q/α_r``, ``ℱ ≈ π/2 + q ln α_r`` with ``q = π/2 - 1``; exact at the circle.

(ℱ, ℰ: complete elliptic integrals of the first and second kind, ``K`` and ``E``
here.)  Then ``a = (6 k² ℰ F R/(π E'))^(1/3)``, ``b = (6 ℰ F R/(π k E'))^(1/3)``,
``δ = ℱ [9/(2 ℰ R) (F/(π k E'))²]^(1/3)``.  Both are applied to the larger/smaller
radius ratio and the semi-axes are swapped back when ``Ry < Rx`` (the exact solution
is symmetric under that swap; the 1983 paper's extension to ellipticities below 1 is
this case).  gearjax warns outside ``1 ≤ max/min radius ≤ 100``.  Errors against the
exact solution, measured by gearjax (the papers' own error tables were not available
to us): ``docs/friction.md`` and ``tests/test_contact.py``.
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import check_positive, check_range, require_converged
from gearjax.newton import implicit_root

__all__ = [
    "HertzResult",
    "combined_modulus",
    "ellipk_agm",
    "ellipe_agm",
    "elliptic_KD",
    "hertz_point",
    "hertz_point_traced",
    "hertz_line",
    "hertz_line_traced",
]

_AGM_STEPS = 12  # enough for |ln k| <= 40 (checked against scipy in the tests)
#: from this many points per array (static shape) the friction kernels unroll their
#: fixed loops into one fused elementwise pass (the AGM here, the shear rule's nodes in
#: gearjax/tribology/friction.py): faster on large batches, a larger program to compile
FUSED_MIN_POINTS = 4096


class HertzResult(NamedTuple):
    """Hertz point-contact solution (all arrays broadcast to the input shape).

    a : semi-axis along y (transverse), mm.
    b : semi-axis along x (rolling), mm.
    k : ellipticity a/b.
    p_max : maximum (central) pressure, MPa.
    p_mean : mean pressure F/(π a b), MPa.
    approach : mutual approach of distant points δ, mm.
    K, E : complete elliptic integrals K(m), E(m) at m = 1 - (b/a)².
    converged : ellipticity solve converged (always True for Hamrock–Brewe).
    """

    a: jax.Array
    b: jax.Array
    k: jax.Array
    p_max: jax.Array
    p_mean: jax.Array
    approach: jax.Array
    K: jax.Array
    E: jax.Array
    converged: jax.Array


# ----------------------------------------------------------------------------
# materials
# ----------------------------------------------------------------------------

def combined_modulus(E1, nu1, E2=None, nu2=None):
    """Reduced modulus E' = 2/[(1-ν1²)/E1 + (1-ν2²)/E2] (MPa; Hamrock's E', = 2E*).

    ``E1``, ``E2`` in MPa; body 2 defaults to body 1.  Validates its inputs.
    Example: steel 206 GPa, ν = 0.3 on steel → E' = 226 374 MPa.
    """
    E2 = E1 if E2 is None else E2
    nu2 = nu1 if nu2 is None else nu2
    for name, v in (("E1", E1), ("E2", E2)):
        check_positive(name, np.min(np.asarray(v, float)), "MPa")
    for name, v in (("nu1", nu1), ("nu2", nu2)):
        arr = np.asarray(v, float)
        check_range(name, np.min(arr), -1.0, 0.5, lo_open=True, hi_open=True)
        check_range(name, np.max(arr), -1.0, 0.5, lo_open=True, hi_open=True)
    return 2.0 / ((1.0 - jnp.asarray(nu1) ** 2) / jnp.asarray(E1, float)
                  + (1.0 - jnp.asarray(nu2) ** 2) / jnp.asarray(E2, float))


# ----------------------------------------------------------------------------
# complete elliptic integrals by the AGM
# ----------------------------------------------------------------------------

def elliptic_KD(t):
    """K(m) and D(m) = (K - E)/m at ``m = 1 - exp(-2t)`` (i.e. k' = exp(-t)).

    Arithmetic–geometric mean ``a_{n+1} = (a_n+b_n)/2``, ``b_{n+1} = sqrt(a_n b_n)``,
    ``a_0 = 1``, ``b_0 = k'``; ``K = π/(2 a_∞)`` and
    ``K - E = K Σ_{n≥0} 2^{n-1} c_n²`` with ``c_0² = m``,
    ``c_{n+1} = c_n²/(4 a_{n+1})`` (Abramowitz & Stegun 17.6).  The series is
    carried as ``s_n = c_n²/m`` (``s_0 = 1``, ``s_{n+1} = s_n² m/(16 a_{n+1}²)``),
    so ``D = K Σ 2^{n-1} s_n`` has no cancellation at m → 0.  Valid for any real
    ``t`` (m < 0 for t < 0), jit/grad/vmap-friendly (fixed 12 steps).
    """
    t = jnp.asarray(t, float)
    kp = jnp.exp(-t)
    m = -jnp.expm1(-2.0 * t)
    one = jnp.ones_like(kp)

    def step(_, c):
        a, b, s, w, total = c
        a_new = 0.5 * (a + b)
        s = s * s * m / (16.0 * a_new * a_new)
        w = 2.0 * w
        return a_new, jnp.sqrt(a * b), s, w, total + w * s

    # unrolled for many points: the twelve steps fuse into one elementwise kernel (as a
    # loop, each step wrote its five arrays to memory and read them back; on 1e5
    # contacts the Hertz stage 33 -> 18 ms, its gradient 112 -> 57 ms, results
    # bit-identical); a loop for few (one body in the program: the loaded contact's
    # solves, where compilation is the cost)
    a, _, _, _, total = jax.lax.fori_loop(0, _AGM_STEPS, step, (one, kp, one, 0.5 * one,
                                                                 0.5 * one),
                                          unroll=jnp.size(kp) >= FUSED_MIN_POINTS)
    K = 0.5 * jnp.pi / a
    return K, K * total


def ellipk_agm(m):
    """Complete elliptic integral of the first kind K(m), m < 1 (parameter convention)."""
    m = jnp.asarray(m, float)
    t = -0.5 * jnp.log1p(-m)
    return elliptic_KD(t)[0]


def ellipe_agm(m):
    """Complete elliptic integral of the second kind E(m) = K - m D, m < 1."""
    m = jnp.asarray(m, float)
    t = -0.5 * jnp.log1p(-m)
    K, D = elliptic_KD(t)
    return K - m * D


# ----------------------------------------------------------------------------
# point contact
# ----------------------------------------------------------------------------

def _ratio_residual(t, log_ratio):
    """ln(Ry/Rx) from eq. (1) minus the target: ln B - ln D + 2t - ln(Ry/Rx)."""
    K, D = elliptic_KD(t)
    return jnp.log(K - D) - jnp.log(D) + 2.0 * t - log_ratio


def _ratio_residual_of(t, log_ratio):
    return _ratio_residual(t, log_ratio)


def _ratio_residual_and_slope(t, log_ratio):
    """:func:`_ratio_residual` and its t-derivative from the same AGM (no forward-mode
    pass, which would double the AGM work): with m = 1 - e^{-2t}, B = K - D,
    dK/dt = B, dD/dt = (K - (2 - m) D)/m, so dR/dt = (B - D')/B - D'/D + 2.  D' loses
    ~1e-16/|m| relative to cancellation near the circle; for |m| < 1e-7 the slope is
    taken as its circle value 3/2 (a Newton slope only: the root is unchanged, the
    steps converge at rate ≤ 1e-7 there)."""
    K, D = elliptic_KD(t)
    m = -jnp.expm1(-2.0 * t)
    B = K - D
    r = jnp.log(B) - jnp.log(D) + 2.0 * t - log_ratio
    small = jnp.abs(m) < 1e-7
    dD = (K - (2.0 - m) * D) / jnp.where(small, 1.0, m)
    return r, jnp.where(small, 1.5, (B - dD) / B - dD / D + 2.0)


_T_STEPS = 3          # Newton steps on (1) from the explicit start (measured: 1e-14 in t)
_T_TOL = 1e-12        # residual tolerance of the converged flag (as the former while-loop solve)


def _t_start(log_ratio):
    """Explicit start for t = ln k solving (1), odd in ``log_ratio``.

    Near the circle Hamrock–Brewe's ``t ≈ (2/π) ln(Ry/Rx)``; for an elongated
    ellipse (k' → 0: K ≈ ln 4k, E → 1, so D ≈ ln 4k - 1 and B ≈ 1) equation (1)
    becomes ``ln(Ry/Rx) ≈ 2t - ln(t + ln 4 - 1)``, solved by one fixed-point pass.
    Off by ≤ 0.07 in t over |ln(Ry/Rx)| ≤ 34; three Newton steps bring it to
    1e-14 (tests/test_contact.py).
    """
    x = jnp.abs(log_ratio)
    h = 0.5 * x
    t_big = h + 0.5 * jnp.log(jnp.log(4.0) - 1.0 + h + 0.5 * jnp.log(jnp.maximum(h, 1.0)))
    return jnp.sign(log_ratio) * jnp.where(x < 3.0, (2.0 / jnp.pi) * x, t_big)


def _t_iterate(log_ratio):
    """Fixed Newton steps on (1), a loop of fixed length, no line search (the residual
    is smooth and increasing in t with slope between 3/2 at the circle and 2 as k → ∞)."""
    def step(_, t):
        r, dr = _ratio_residual_and_slope(t, log_ratio)
        dt = -r / dr
        return t + jnp.where(jnp.isfinite(dt), jnp.clip(dt, -4.0, 4.0), 0.0)

    return jax.lax.fori_loop(0, _T_STEPS, step, _t_start(log_ratio))


def hertz_exact(F, Rx, Ry, E_prime):
    """Exact Hertz ellipse, eqs. (1)–(4); elementwise over broadcast arrays (no validation).

    Equation (1) is solved for t = ln k by three Newton steps from the explicit
    start :func:`_t_start` (no while loop, so a batch costs the same for every
    point); the residual at the returned t is recomputed and ``converged`` is
    ``|residual| ≤ 1e-12`` (and finite).  Derivatives of t by the implicit function
    theorem (:func:`gearjax.newton.implicit_root`).
    """
    F, Rx, Ry, E_prime = (jnp.asarray(v, float) for v in (F, Rx, Ry, E_prime))
    lr = jnp.log(Ry) - jnp.log(Rx)
    t = implicit_root(_t_iterate, _ratio_residual_of, lr)
    K, D = elliptic_KD(t)
    res = jnp.log(K - D) - jnp.log(D) + 2.0 * t - lr
    conv = jnp.isfinite(t) & (jnp.abs(res) <= _T_TOL)
    m = -jnp.expm1(-2.0 * t)
    E = K - m * D
    # 1/R = 1/Rx + 1/Ry, written to stay finite for Ry -> huge
    R = Rx / (1.0 + Rx / Ry)
    log_b = (jnp.log(6.0 / jnp.pi) + jnp.log(E) - t + jnp.log(F) + jnp.log(R)
             - jnp.log(E_prime)) / 3.0
    b = jnp.exp(log_b)
    a = jnp.exp(log_b + t)
    p_max = 1.5 * F / (jnp.pi * a * b)
    approach = 2.0 * p_max * b * K / E_prime
    return HertzResult(a, b, jnp.exp(t), p_max, p_max / 1.5, approach, K, E, conv)


_FIT_METHODS = ("brewe_hamrock_1977", "hamrock_brewe", "hamrock_brewe_1983")
_METHODS = ("exact",) + _FIT_METHODS


def _fit_integrals(alpha_r, method):
    """Curve-fit (k, ℰ, ℱ) for the radius ratio ``alpha_r = R_big/R_small ≥ 1``."""
    if method == "hamrock_brewe_1983":
        q = 0.5 * jnp.pi - 1.0
        return alpha_r ** (2.0 / jnp.pi), 1.0 + q / alpha_r, 0.5 * jnp.pi + q * jnp.log(alpha_r)
    return (1.0339 * alpha_r ** 0.6360, 1.0003 + 0.5968 / alpha_r,
            1.5277 + 0.6023 * jnp.log(alpha_r))


def _hertz_fit(F, Rx, Ry, E_prime, method):
    swap = Ry < Rx
    R_small = jnp.minimum(Rx, Ry)
    R_big = jnp.maximum(Rx, Ry)
    k, E, K = _fit_integrals(R_big / R_small, method)
    R = Rx * Ry / (Rx + Ry)
    # D_y = 2 (6 k² ℰ F R/(π E'))^(1/3), D_x = 2 (6 ℰ F R/(π k E'))^(1/3)
    a_big = (6.0 * k * k * E * F * R / (jnp.pi * E_prime)) ** (1.0 / 3.0)  # along R_big
    b_small = (6.0 * E * F * R / (jnp.pi * k * E_prime)) ** (1.0 / 3.0)
    a = jnp.where(swap, b_small, a_big)
    b = jnp.where(swap, a_big, b_small)
    p_max = 1.5 * F / (jnp.pi * a * b)
    approach = K * (4.5 / (E * R) * (F / (jnp.pi * k * E_prime)) ** 2) ** (1.0 / 3.0)
    return HertzResult(a, b, a / b, p_max, p_max / 1.5, approach, K, E,
                       jnp.ones_like(p_max, dtype=bool))


def _method_error(method):
    return ValueError(f"method = {method!r} must be one of {', '.join(map(repr, _METHODS))}")


def hertz_point_traced(F, Rx, Ry, E_prime, method: str = "exact") -> HertzResult:
    """Traceable core of :func:`hertz_point` (no validation; jit/grad/vmap-friendly).

    Broadcasts its array arguments.  ``method`` is ``"exact"`` or one of the curve
    fits ``"brewe_hamrock_1977"`` (= ``"hamrock_brewe"``), ``"hamrock_brewe_1983"``
    (static).
    """
    F, Rx, Ry, E_prime = jnp.broadcast_arrays(*(jnp.asarray(v, float) for v in (F, Rx, Ry, E_prime)))
    if method == "exact":
        return hertz_exact(F, Rx, Ry, E_prime)
    if method in _FIT_METHODS:
        return _hertz_fit(F, Rx, Ry, E_prime, method)
    raise _method_error(method)


_hertz_point_jit = jax.jit(hertz_point_traced, static_argnames=("method",))


#: highest accepted normal load (N) and reduced modulus E' (MPa; diamond on diamond
#: is about 2.4e6 MPa) of the validated entry points
LOAD_MAX_N = 1.0e7
E_PRIME_MAX_MPA = 1.0e7


def _check_array_positive(name, value, unit, hi=None):
    """Every entry finite and in (0, hi]; ``ValueError`` naming the first bad one."""
    arr = np.asarray(value, dtype=float)
    if arr.size == 0:
        raise ValueError(f"{name} is empty")
    bad = ~np.isfinite(arr) | (arr <= 0)
    if hi is not None:
        bad |= arr > hi
    if np.any(bad):
        check_range(name, arr[bad].ravel()[0], 0.0, hi, lo_open=True, unit=unit)
    return arr


def hertz_point(F, Rx, Ry, E_prime, method: str = "exact", throw: bool = True) -> HertzResult:
    """Hertz elliptical point contact (validated public entry point).

    Parameters
    ----------
    F : normal load, N (in (0, 1e7]).
    Rx, Ry : relative principal radii of curvature in the rolling and transverse
        directions, mm (> 0, finite; for an infinitely long line contact use
        :func:`hertz_line`).
    E_prime : reduced modulus E' = 2E*, MPa (in (0, 1e7]).
    method : ``"exact"`` (AGM elliptic integrals + Newton for the ellipticity) or a
        curve fit: ``"brewe_hamrock_1977"`` (alias ``"hamrock_brewe"``) or
        ``"hamrock_brewe_1983"`` (warned outside 1 ≤ max/min radius ≤ 100).
    throw : raise :class:`gearjax.errors.ConvergenceError` if a solve failed
        (default); with False the ``converged`` mask is returned instead.

    Returns
    -------
    :class:`HertzResult` (a, b in mm; p_max, p_mean in MPa; approach in mm).
    Equations (1)–(4) of the module docstring.
    """
    _check_array_positive("F", F, "N", hi=LOAD_MAX_N)
    rx = _check_array_positive("Rx", Rx, "mm")
    ry = _check_array_positive("Ry", Ry, "mm")
    _check_array_positive("E_prime", E_prime, "MPa", hi=E_PRIME_MAX_MPA)
    if method not in _METHODS:
        raise _method_error(method)
    ratio = np.maximum(rx, ry) / np.minimum(rx, ry)
    if method == "exact" and np.any(np.abs(np.log(ratio)) > 34.0):
        raise ValueError(f"Ry/Rx = {float(np.max(ry / rx)):g} is outside the allowed range "
                         "[1e-15, 1e15]; use hertz_line for a line contact")
    if method in _FIT_METHODS and np.any(ratio > 100.0):
        warnings.warn(f"Hamrock-Brewe approximations ({method}) used outside their range "
                      f"1 <= Ry/Rx <= 100 (got {float(np.max(ratio)):g}); use method='exact'",
                      stacklevel=2)
    out = _hertz_point_jit(F, Rx, Ry, E_prime, method=method)
    if throw:
        require_converged(out.converged, "Hertz ellipticity solve")
    return out


# ----------------------------------------------------------------------------
# line contact
# ----------------------------------------------------------------------------

def hertz_line_traced(w, Rx, E_prime):
    """Line-contact semi-width b (mm) and maximum pressure (MPa); no validation.

    ``b = sqrt(8 w Rx / (π E'))``, ``p_max = 2 w / (π b)`` with ``w`` the load per
    unit length (N/mm).  Johnson (1985) eq. 4.45 with E' = 2E*.
    """
    w, Rx, E_prime = (jnp.asarray(v, float) for v in (w, Rx, E_prime))
    b = jnp.sqrt(8.0 * w * Rx / (jnp.pi * E_prime))
    return b, 2.0 * w / (jnp.pi * b)


def hertz_line(w, Rx, E_prime):
    """Validated :func:`hertz_line_traced`: w (N/mm), Rx (mm), E' (MPa) all > 0."""
    _check_array_positive("w", w, "N/mm")
    _check_array_positive("Rx", Rx, "mm")
    _check_array_positive("E_prime", E_prime, "MPa")
    return hertz_line_traced(w, Rx, E_prime)


# radius-ratio ceiling of the exact solver, also used by callers
MAX_LOG_RATIO = 34.0
