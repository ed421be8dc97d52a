"""Validation of the operating inputs of the mesh-efficiency entry points
(:func:`gearjax.loading.mesh_efficiency.mesh_efficiency`, ``efficiency_function``): torque, pinion
speed, E′, ν, the oil's and the surface's fields and the model names, checked on
concrete values before any work, as the command line does (one-line ``ValueError``
naming the parameter, its value and the allowed range; traced values pass).

Units: torque N m, speed rpm, moduli MPa; oil and surface fields in the library units
of :func:`gearjax.tribology.make_oil` / :func:`~gearjax.tribology.make_surface`.
"""

from __future__ import annotations

import math

import numpy as np

from gearjax.errors import check_range, is_traced
from gearjax.loading.loaded_contact import COMPLIANCE_MODELS

__all__ = ["TORQUE_RANGE_NM", "RPM_RANGE", "check_operating_point", "check_efficiency_inputs",
           "check_models"]

#: accepted pinion torque (N m) and speed (rpm)
TORQUE_RANGE_NM = (1e-3, 1e6)
RPM_RANGE = (1e-3, 1e6)


def check_operating_point(torque_Nm, pinion_rpm) -> tuple[float, float]:
    """Validate the operating point (concrete): torque (N m) and pinion speed (rpm) in
    :data:`TORQUE_RANGE_NM` and :data:`RPM_RANGE` (one-line ValueError naming the
    parameter, its value and the range; traced values pass unchecked)."""
    T = check_range("torque_Nm", torque_Nm, *TORQUE_RANGE_NM, unit="N m")
    n = check_range("pinion_rpm", pinion_rpm, *RPM_RANGE, unit="rpm")
    return T, n


#: ranges of an Oil's and a Surface's fields in library units (those of make_oil and
#: make_surface: eta0 Pa s, tau0 MPa, rho0 kg/m^3, z; sigma and beta mm, density 1/mm^2,
#: v_slip mm/s): (low, high, low bound excluded, unit)
_OIL_RANGES = {"eta0": (math.exp(-9.67), 100.0, True, "Pa s"), "z": (0.0, 3.0, True, ""),
               "tau0": (0.0, 100.0, True, "MPa"), "rho0": (0.0, 2e4, True, "kg/m^3")}
_SURFACE_RANGES = {"sigma": (0.0, 0.01, True, "mm"), "density": (0.0, 1e6, True, "1/mm^2"),
                   "beta": (0.0, 1.0, True, "mm"), "f_c": (0.0, 1.0, False, ""),
                   "v_slip": (0.0, 1000.0, True, "mm/s"),
                   "asperity_film_factor": (0.5, 1.0, False, "")}


def _check_fields(what, obj, ranges):
    """The scalar fields of an Oil / Surface in their ranges (concrete values only:
    traced fields and batches -- arrays with dimensions -- are not checked here)."""
    for name, (lo, hi, lo_open, unit) in ranges.items():
        v = getattr(obj, name)
        if is_traced(v) or np.ndim(v):
            continue
        check_range(f"{what}.{name}", v, lo, hi, lo_open=lo_open, unit=unit)


def check_efficiency_inputs(torque_Nm, pinion_rpm, oil, surface, E_prime, poisson,
                            compliance, viscosity_model, film_method):
    """Validate the concrete operating inputs of :func:`mesh_efficiency` /
    :func:`efficiency_function` before any work, as the command line does: torque and
    speed (:func:`check_operating_point`), E′ in (0, 1e7] MPa (E′ typed in Pa is
    refused), ν in [0, 0.5], the oil and surface fields in the ranges of
    :func:`gearjax.tribology.make_oil` / :func:`~gearjax.tribology.make_surface`, and
    the model names.  Traced values are not checked.  One-line ValueError."""
    from gearjax.loading.materials import POISSON_RANGE, check_e_prime

    check_operating_point(torque_Nm, pinion_rpm)
    check_e_prime(E_prime)
    check_range("poisson", poisson, *POISSON_RANGE)
    _check_fields("oil", oil, _OIL_RANGES)
    _check_fields("surface", surface, _SURFACE_RANGES)
    check_models(compliance, viscosity_model, film_method)


def check_models(compliance, viscosity_model, film_method):
    """The model names (one-line ValueError listing the allowed ones)."""
    for name, v, allowed in (("compliance", compliance, COMPLIANCE_MODELS),
                             ("viscosity_model", viscosity_model, ("roelands", "barus")),
                             ("film_method", film_method, ("auto", "point", "line"))):
        if v not in allowed:
            raise ValueError(f"{name} = {v!r} must be one of {tuple(allowed)}")
