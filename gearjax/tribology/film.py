"""Elastohydrodynamic film thickness for elliptical and (near-)line contacts.

Units: lengths mm, load N, load per length N/mm, speed mm/s, E' MPa, η0 Pa·s
(converted to MPa·s inside), α 1/MPa.  ``u_e`` is the entrainment (mean rolling)
speed ``(u1 + u2)/2``.

Dimensionless groups — all from the radius ``Rx`` in the *rolling* direction
(not from sqrt(Rx Ry)), as in Hamrock & Dowson:

    U = η0 u_e / (E' Rx),   G = α E',   W = F / (E' Rx²),   W' = w' / (E' Rx),
    H = h / Rx.

Elliptical contact, Hamrock & Dowson (J. Lubr. Technol. 99 (1977) 264–276), fitted
for ellipticity 1 ≤ k ≤ 8:

    H_c   = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 exp(-0.73 k)),
    H_min = 3.63 U^0.68 G^0.49 W^-0.073 (1 - exp(-0.68 k)).

Line contact, Pan & Hamrock (J. Tribol. 111 (1989) 246–251):

    H_c   = 2.922 W'^-0.166 U^0.692 G^0.470,
    H_min = 1.714 W'^-0.128 U^0.694 G^0.568.

A very elongated ellipse (gear flanks: k ≫ 8) is treated as a line contact whose
load per unit length is the Hertzian centre-line load intensity
``w' = π p_max b / 2 = 3F/(4a)`` (the load carried per unit length across the
middle of the ellipse), see :func:`film_thickness_traced`.  Between the two
validity ranges the formulas disagree by up to ~20 % (measured: Ry/Rx = 30,
k = 8.9: Hamrock–Dowson h_c is 21 % above Pan–Hamrock), so ``method="auto"``
does not switch abruptly: it interpolates ln h with a C¹ smoothstep in ln k from
pure Hamrock–Dowson at ``k ≤ k_point`` (8, the end of its fit) to pure line
contact at ``k ≥ k_line`` (64).  This blend is a gearjax modelling choice, not a
published formula; ``"point"`` and ``"line"`` give either formula alone.
"""

from __future__ import annotations

import math

import jax.numpy as jnp

from gearjax.tribology.lubricant import PA_S_TO_MPA_S

__all__ = ["hamrock_dowson", "pan_hamrock_line", "film_thickness_traced", "blend_weight",
           "K_POINT_DEFAULT", "K_LINE_DEFAULT"]

K_POINT_DEFAULT = 8.0
K_LINE_DEFAULT = 64.0


def _log_inputs(Rx, u_e, eta0, alpha, E_prime):
    """ln U, ln G of the dimensionless groups (shared by both film formulas)."""
    return jnp.log(eta0 * PA_S_TO_MPA_S * u_e / (E_prime * Rx)), jnp.log(alpha * E_prime)


def _log_hamrock_dowson(F, Rx, k, lnU, lnG, E_prime):
    """(ln h_c, ln h_min) of Hamrock–Dowson, mm: the power laws as one exp of a sum of
    logs (three logs for the whole formula instead of six pows)."""
    lnW = jnp.log(F / (E_prime * Rx * Rx))
    lnR = jnp.log(Rx)
    lhc = (math.log(2.69) + 0.67 * lnU + 0.53 * lnG - 0.067 * lnW
           + jnp.log1p(-0.61 * jnp.exp(-0.73 * k)) + lnR)
    lhm = (math.log(3.63) + 0.68 * lnU + 0.49 * lnG - 0.073 * lnW
           + jnp.log1p(-jnp.exp(-0.68 * k)) + lnR)
    return lhc, lhm


def _log_pan_hamrock(w, Rx, lnU, lnG, E_prime):
    """(ln h_c, ln h_min) of Pan–Hamrock, mm."""
    lnWl = jnp.log(w / (E_prime * Rx))
    lnR = jnp.log(Rx)
    lhc = math.log(2.922) - 0.166 * lnWl + 0.692 * lnU + 0.470 * lnG + lnR
    lhm = math.log(1.714) - 0.128 * lnWl + 0.694 * lnU + 0.568 * lnG + lnR
    return lhc, lhm


def hamrock_dowson(F, Rx, k, u_e, eta0, alpha, E_prime):
    """Hamrock–Dowson central and minimum film (h_c, h_min) in mm.

    F N, Rx mm, ellipticity k = a/b (-), u_e mm/s, η0 Pa·s, α 1/MPa, E' MPa:
    ``h_c/Rx = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 e^{-0.73k})``,
    ``h_min/Rx = 3.63 U^0.68 G^0.49 W^-0.073 (1 - e^{-0.68k})``,
    U = η0 u_e/(E' Rx), G = α E', W = F/(E' Rx²).
    """
    lnU, lnG = _log_inputs(Rx, u_e, eta0, alpha, E_prime)
    lhc, lhm = _log_hamrock_dowson(F, Rx, k, lnU, lnG, E_prime)
    return jnp.exp(lhc), jnp.exp(lhm)


def pan_hamrock_line(w, Rx, u_e, eta0, alpha, E_prime):
    """Pan–Hamrock line-contact central and minimum film (h_c, h_min) in mm.

    w load per unit length N/mm, Rx mm, u_e mm/s, η0 Pa·s, α 1/MPa, E' MPa:
    ``h_c/Rx = 2.922 W'^-0.166 U^0.692 G^0.470``,
    ``h_min/Rx = 1.714 W'^-0.128 U^0.694 G^0.568``, W' = w/(E' Rx).
    """
    lnU, lnG = _log_inputs(Rx, u_e, eta0, alpha, E_prime)
    lhc, lhm = _log_pan_hamrock(w, Rx, lnU, lnG, E_prime)
    return jnp.exp(lhc), jnp.exp(lhm)


def blend_weight(k, k_point=K_POINT_DEFAULT, k_line=K_LINE_DEFAULT):
    """Weight of the line formula: C¹ smoothstep 3x² - 2x³ of x = ln(k/k_point)/ln(k_line/k_point)."""
    x = jnp.clip(jnp.log(k / k_point) / jnp.log(k_line / k_point), 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def film_thickness_traced(F, Rx, k, a, u_e, eta0, alpha, E_prime, method="auto",
                          k_point=K_POINT_DEFAULT, k_line=K_LINE_DEFAULT):
    """Central and minimum film (mm) of a Hertzian ellipse; no validation.

    ``F`` N, ``Rx`` mm, ellipticity ``k`` and transverse semi-axis ``a`` (mm) from
    the Hertz solution, ``u_e`` mm/s.  ``method``: ``"point"`` (Hamrock–Dowson),
    ``"line"`` (Pan–Hamrock with ``w' = 3F/(4a)``) or ``"auto"``
    (``ln h = (1-s) ln h_point + s ln h_line`` with ``s = blend_weight(k)``).

    The load-sharing solver calls this with ``F/γ1`` and ``E'/γ1`` (Johnson,
    Greenwood & Poon 1972), keeping ``k`` and ``a`` of the total load.
    """
    if method not in ("auto", "point", "line"):
        raise ValueError(f"film method = {method!r} must be 'auto', 'point' or 'line'")
    lnU, lnG = _log_inputs(Rx, u_e, eta0, alpha, E_prime)
    if method == "point":
        lhc, lhm = _log_hamrock_dowson(F, Rx, k, lnU, lnG, E_prime)
        return jnp.exp(lhc), jnp.exp(lhm)
    lc_l, lm_l = _log_pan_hamrock(0.75 * F / a, Rx, lnU, lnG, E_prime)
    if method == "line":
        return jnp.exp(lc_l), jnp.exp(lm_l)
    lc_p, lm_p = _log_hamrock_dowson(F, Rx, k, lnU, lnG, E_prime)
    s = blend_weight(k, k_point, k_line)
    return jnp.exp(lc_p + s * (lc_l - lc_p)), jnp.exp(lm_p + s * (lm_l - lm_p))
