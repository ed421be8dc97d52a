"""Film-thickness formulas in Moes variables, used to validate the numerical solver.

Moes variables (Moes 1992; Venner & Lubrecht, *Multilevel Methods in
Lubrication*, 2000), with U = η0 u_e/(E' Rx), W = F/(E' Rx²), G = α E':

    M = W (2U)^(-3/4),   L = G (2U)^(1/4),   H = (h/Rx) (2U)^(-1/2),   D = Rx/Ry.

Nijenbanning, Venner & Moes (Wear 176 (1994) 217–229) central-film formula for
elliptical contacts, fitted to their numerical (multigrid) solutions:

    H_c = [ (H_RI^(3/2) + (H_EI^-4 + H_00^-4)^(-3/8))^(2s/3)
            + (H_RP^-8 + H_EP^-8)^(-s/8) ]^(1/s),
    H_RI = 145 (1 + 0.796 D^(14/15))^(-15/7) D^-1 M^-2,
    H_EI = 3.18 (1 + 0.006 ln D + 0.63 D^(4/7))^(-14/25) D^(-1/15) M^(-2/15),
    H_RP = 1.29 (1 + 0.691 D)^(-2/3) L^(2/3),
    H_EP = 1.48 (1 + 0.006 ln D + 0.63 D^(4/7))^(-7/20) D^(-1/24) M^(-1/12) L^(3/4),
    H_00 = 1.8 D^-1,   s = 1.5 (1 + exp(-1.2 H_EI/H_RI)).

Caveat: the coefficients above were transcribed from secondary sources and could
not be checked against the 1994 paper here; the limits are consistent (the
rigid–isoviscous asymptote reproduces Hamrock's rigid-isoviscous point-contact
film, 41 M⁻² against 35 M⁻² for h_min, D = 1), but treat agreement to better than
~15 % as unverified.  It lies 5–17 % above both the numerical solver and
Hamrock–Dowson over M = 20–1000, L = 5–20; it is kept for reference but not used
as validation evidence (docs/ehl.md).  Hamrock–Dowson is in
:mod:`gearjax.tribology.film`.
"""

from __future__ import annotations

import jax.numpy as jnp

from gearjax.tribology.lubricant import PA_S_TO_MPA_S

__all__ = ["moes_variables", "nvm_central_film", "film_from_moes"]


def moes_variables(F, u_e, Rx, eta0, alpha, E_prime):
    """(M, L, sqrt(2U)) of a contact; F N, u_e mm/s, Rx mm, η0 Pa·s, α 1/MPa, E' MPa."""
    U = eta0 * PA_S_TO_MPA_S * u_e / (E_prime * Rx)
    W = F / (E_prime * Rx * Rx)
    return W * (2.0 * U) ** -0.75, alpha * E_prime * (2.0 * U) ** 0.25, jnp.sqrt(2.0 * U)


def nvm_central_film(M, L, D=1.0):
    """Nijenbanning–Venner–Moes dimensionless central film H_c(M, L, D = Rx/Ry)."""
    lnD = jnp.log(D)
    c = 1.0 + 0.006 * lnD + 0.63 * D ** (4.0 / 7.0)
    h_ri = 145.0 * (1.0 + 0.796 * D ** (14.0 / 15.0)) ** (-15.0 / 7.0) / D * M ** -2.0
    h_ei = 3.18 * c ** (-14.0 / 25.0) * D ** (-1.0 / 15.0) * M ** (-2.0 / 15.0)
    h_rp = 1.29 * (1.0 + 0.691 * D) ** (-2.0 / 3.0) * L ** (2.0 / 3.0)
    h_ep = 1.48 * c ** (-7.0 / 20.0) * D ** (-1.0 / 24.0) * M ** (-1.0 / 12.0) * L ** 0.75
    h_00 = 1.8 / D
    s = 1.5 * (1.0 + jnp.exp(-1.2 * h_ei / h_ri))
    a = (h_ri ** 1.5 + (h_ei ** -4.0 + h_00 ** -4.0) ** (-3.0 / 8.0)) ** (2.0 * s / 3.0)
    b = (h_rp ** -8.0 + h_ep ** -8.0) ** (-s / 8.0)
    return (a + b) ** (1.0 / s)


def film_from_moes(F, u_e, Rx, Ry, eta0, alpha, E_prime):
    """NVM central film h_c in mm for a physical contact (units as moes_variables)."""
    M, L, s2u = moes_variables(F, u_e, Rx, eta0, alpha, E_prime)
    return nvm_central_film(M, L, Rx / Ry) * Rx * s2u
