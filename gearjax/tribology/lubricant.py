"""Lubricant rheology: piezoviscosity (Roelands, Barus), density, Ree–Eyring shear.

Units: pressure p in MPa (N/mm²); viscosity η in Pa·s at the API (the library
converts to MPa·s = N·s/mm² internally, 1 Pa·s = 1e-6 MPa·s); pressure–viscosity
coefficient α in 1/MPa (1 GPa⁻¹ = 1e-3 MPa⁻¹); Eyring stress τ0 in MPa; density in
kg/m³.

Roelands ([VH-CATT]; [Roelands1966], see docs/references.md):

    η(p) = η0 exp{ (ln η0 + 9.67) [ (1 + p/p_R)^z - 1 ] },   p_R = 1/5.1e-9 Pa = 196.08 MPa,

with η0 in **Pa·s** (the constant 9.67 = -ln(6.31e-5 Pa·s) belongs to that unit;
in mPa·s it would be 2.76).  [VH-CATT] fixes ``z = 0.68``.  gearjax takes z from
the oil's pressure–viscosity coefficient α at η0 so that both laws share the
initial slope d(ln η)/dp at p = 0:

    z = α p_R / (ln η0 + 9.67)                                  (Hamrock 2004, ch. 4)

An :class:`Oil` stores ``z`` (a property of the oil family, nearly independent of
temperature in Roelands' correlation) and derives ``α = z (ln η0 + 9.67)/p_R`` from
it.  So a change of η0 (e.g. a temperature change, or a derivative dμ/dη0) moves α
with it, as Roelands' correlation says.  Holding α fixed instead while raising η0
would *lower* z and hence the high-pressure viscosity — that reverses the
"μ rises with viscosity" trend of [VH-CATT] and is not what a more viscous oil does.
``make_oil(..., z=0.68)`` or ``roelands_viscosity(..., z=0.68)`` reproduce [VH-CATT].
Barus: ``η = η0 exp(α p)``.
Dowson–Higginson density: ``ρ = ρ0 [1 + 0.6e-3 p / (1 + 1.7e-3 p)]`` (p in MPa).
Ree–Eyring: ``τ = τ0 asinh(η u_s / (h τ0))`` ([VH-CATT]; [ReeEyring1955]).
"""

from __future__ import annotations

import dataclasses
import warnings

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import check_range
from gearjax.fields import float64_array

__all__ = ["Oil", "make_oil", "get_oil", "OILS", "roelands_z", "roelands_viscosity",
           "barus_viscosity", "viscosity", "dowson_higginson_density", "eyring_shear",
           "P_ROELANDS_MPA", "PA_S_TO_MPA_S", "LN_ETA_INF", "LN_ETA_CAP", "log_viscosity_ratio"]

P_ROELANDS_MPA = 1.0 / 5.1e-3   # 196.08 MPa  (5.1e-9 1/Pa)
PA_S_TO_MPA_S = 1e-6            # 1 Pa·s = 1e-6 N·s/mm²
LN_ETA_INF = 9.67               # -ln(6.31e-5 Pa·s)
LN_ETA_CAP = 150.0              # overflow guard for ln(η/η0) at absurd pressures
_LN_ETA_INF, _LN_ETA_CAP = LN_ETA_INF, LN_ETA_CAP
ETA0_MAX_PAS = 100.0            # highest accepted inlet viscosity, Pa·s
ALPHA_MAX_PER_GPA = 100.0       # highest accepted pressure-viscosity coefficient, 1/GPa
TAU0_MAX_MPA = 100.0            # highest accepted Eyring stress, MPa


@dataclasses.dataclass(frozen=True)
class Oil:
    """A lubricant (pytree: numeric fields are differentiable, ``name`` is static).

    eta0 : dynamic viscosity at ambient pressure and the inlet temperature, Pa·s.
    z : Roelands pressure-viscosity index (-).
    tau0 : Eyring stress, MPa.
    rho0 : density at ambient pressure, kg/m³ (only used by the density law).
    name : label.
    Build validated instances with :func:`make_oil` or :func:`get_oil`.
    """

    eta0: jax.Array
    z: jax.Array
    tau0: jax.Array
    rho0: jax.Array
    name: str = "custom"

    @property
    def alpha(self):
        """Pressure–viscosity coefficient α = z (ln η0 + 9.67)/p_R, 1/MPa."""
        return self.z * (jnp.log(self.eta0) + _LN_ETA_INF) / P_ROELANDS_MPA


jax.tree_util.register_dataclass(Oil, data_fields=["eta0", "z", "tau0", "rho0"],
                                 meta_fields=["name"])


def make_oil(eta0, alpha_per_GPa=None, tau0_MPa=5.0, rho0=880.0, name="custom", *, z=None) -> Oil:
    """Validated :class:`Oil` from η0 (Pa·s), α at η0 (GPa⁻¹) *or* Roelands z, τ0 (MPa), ρ0 (kg/m³).

    Accepted ranges (``ValueError`` naming the parameter otherwise): η0 in
    (6.31e-5, 100] Pa·s (above Roelands' asymptotic viscosity, below which the
    Roelands law is undefined, up to a hundred times the heaviest gear oils),
    α in (0, 100] GPa⁻¹, z in (0, 3], τ0 in (0, 100] MPa, ρ0 in (0, 20000] kg/m³.
    Values of η0 below 1e-3 Pa·s or above 10 Pa·s warn, as do α outside
    5–40 GPa⁻¹ and z outside 0.3–1.0 (outside the fits, still computable).
    """
    check_range("eta0", eta0, math_eta_inf(), ETA0_MAX_PAS, lo_open=True, unit="Pa·s")
    if (alpha_per_GPa is None) == (z is None):
        raise ValueError("give exactly one of alpha (1/GPa) and z (Roelands index)")
    if z is not None:
        check_range("z", z, 0.0, 3.0, lo_open=True)
        z = float(z)
        alpha_per_GPa = z * (np.log(float(eta0)) + _LN_ETA_INF) / P_ROELANDS_MPA * 1e3
        if not (0.3 <= z <= 1.0):
            warnings.warn(f"Roelands index z = {z:g} is outside the usual range 0.3..1.0",
                          stacklevel=2)
    else:
        check_range("alpha", alpha_per_GPa, 0.0, ALPHA_MAX_PER_GPA, lo_open=True, unit="1/GPa")
        z = float(alpha_per_GPa) * 1e-3 * P_ROELANDS_MPA / (np.log(float(eta0)) + _LN_ETA_INF)
    check_range("tau0", tau0_MPa, 0.0, TAU0_MAX_MPA, lo_open=True, unit="MPa")
    check_range("rho0", rho0, 0.0, 2.0e4, lo_open=True, unit="kg/m^3")
    if not (1e-3 <= float(eta0) <= 10.0):
        warnings.warn(f"eta0 = {float(eta0):g} Pa·s is outside the range 1e-3..10 Pa·s for "
                      "which the Roelands/Hamrock-Dowson correlations were established",
                      stacklevel=2)
    if not (5.0 <= float(alpha_per_GPa) <= 40.0):
        warnings.warn(f"alpha = {float(alpha_per_GPa):g} 1/GPa is outside the range 5..40 1/GPa "
                      "of the Hamrock-Dowson film-thickness fits", stacklevel=2)
    return Oil(*(float64_array(float(v)) for v in (eta0, z, tau0_MPa, rho0)), name)


def math_eta_inf() -> float:
    """Roelands' asymptotic viscosity exp(-9.67) = 6.31e-5 Pa·s."""
    return float(np.exp(-_LN_ETA_INF))


# Example oils at 40 °C.  Viscosity: ISO 3448 grade mid-point kinematic viscosity
# (VG 100: 100 mm²/s, VG 220: 220 mm²/s at 40 °C) times a typical density.
# α: mid-range values for paraffinic mineral oils (15–30 GPa⁻¹) and PAO (≈ 10–16
# GPa⁻¹) as tabulated in Hamrock, Schmid & Jacobson, Fundamentals of Fluid Film
# Lubrication (2004), ch. 4, and Höglund, Wear 232 (1999) 176–184.
# τ0: Eyring stresses of mineral and synthetic oils measured by Johnson &
# Tevaarwerk, Proc. R. Soc. A 356 (1977) 215–236, lie between about 2 and 10 MPa.
# These are representative values for examples and tests, not data of one product.
_OIL_TABLE = {
    "mineral_vg100": dict(eta0=0.088, alpha_per_GPa=22.0, tau0_MPa=5.0, rho0=880.0),
    "mineral_vg220": dict(eta0=0.196, alpha_per_GPa=24.0, tau0_MPa=5.0, rho0=890.0),
    "pao_vg100": dict(eta0=0.085, alpha_per_GPa=14.0, tau0_MPa=4.0, rho0=850.0),
}
OILS = tuple(_OIL_TABLE)


def get_oil(name: str) -> Oil:
    """One of the documented example oils (see ``OILS``) as an :class:`Oil`."""
    if name not in _OIL_TABLE:
        raise ValueError(f"oil = {name!r} is not a known oil; choose one of {', '.join(OILS)}")
    return make_oil(name=name, **_OIL_TABLE[name])


def roelands_z(eta0, alpha):
    """Roelands pressure index z = α p_R / (ln η0 + 9.67); η0 Pa·s, α 1/MPa."""
    return alpha * P_ROELANDS_MPA / (jnp.log(eta0) + _LN_ETA_INF)


def roelands_viscosity(p, eta0, z=0.68):
    """Roelands viscosity η(p), Pa·s.  p in MPa (> -196 MPa), η0 in Pa·s, z dimensionless.

    ``η = η0 exp{(ln η0 + 9.67)[(1 + p/196.08)^z - 1]}`` ([VH-CATT] with p in MPa).
    """
    p = jnp.asarray(p, float)
    ln_ratio = (jnp.log(eta0) + _LN_ETA_INF) * ((1.0 + p / P_ROELANDS_MPA) ** z - 1.0)
    return eta0 * jnp.exp(jnp.minimum(ln_ratio, _LN_ETA_CAP))


def barus_viscosity(p, eta0, alpha):
    """Barus viscosity ``η0 exp(α p)``, Pa·s; p in MPa, α in 1/MPa."""
    p = jnp.asarray(p, float)
    return eta0 * jnp.exp(jnp.minimum(alpha * p, _LN_ETA_CAP))


def viscosity(p, oil: Oil, model: str = "roelands"):
    """η(p) of ``oil`` in Pa·s; ``model`` = ``"roelands"`` (the oil's z) or ``"barus"`` (its α)."""
    if model == "roelands":
        return roelands_viscosity(p, oil.eta0, oil.z)
    if model == "barus":
        return barus_viscosity(p, oil.eta0, oil.alpha)
    raise ValueError(f"viscosity model = {model!r} must be 'roelands' or 'barus'")


def log_viscosity_ratio(p, oil: Oil, model: str = "roelands"):
    """ln(η(p)/η0) of ``oil`` *without* the cap ``LN_ETA_CAP`` of :func:`viscosity`:
    Roelands ``(ln η0 + 9.67) expm1(z log1p(p/p_R))`` (one log and one exp per value),
    Barus ``α p``; p in MPa."""
    p = jnp.asarray(p, float)
    if model == "roelands":
        return (jnp.log(oil.eta0) + _LN_ETA_INF) * jnp.expm1(oil.z * jnp.log1p(p / P_ROELANDS_MPA))
    if model == "barus":
        return oil.alpha * p
    raise ValueError(f"viscosity model = {model!r} must be 'roelands' or 'barus'")


def dowson_higginson_density(p, rho0):
    """Dowson–Higginson density ``ρ0 [1 + 0.6e-3 p/(1 + 1.7e-3 p)]``; p in MPa."""
    p = jnp.asarray(p, float)
    return rho0 * (1.0 + 0.6e-3 * p / (1.0 + 1.7e-3 * p))


def eyring_shear(eta_Pas, u_s, h, tau0):
    """Ree–Eyring shear stress ``τ0 asinh(η u_s/(h τ0))`` in MPa.

    η in Pa·s, sliding speed u_s in mm/s, film h in mm, τ0 in MPa.  Smooth at
    u_s = 0 (slope η/h).
    """
    return tau0 * jnp.arcsinh(eta_Pas * PA_S_TO_MPA_S * u_s / (h * tau0))
