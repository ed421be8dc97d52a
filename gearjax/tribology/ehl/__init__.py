"""Numerical (mixed) elastohydrodynamic point contact: a differentiable reference.

Steady isothermal EHL of an elliptical point contact on a grid (Reynolds equation
with Roelands viscosity, Dowson–Higginson density, DC-FFT elastic deformation,
Fischer–Burmeister cavitation, load balance), optional Greenwood–Tripp asperity
pressure and Ree–Eyring friction, solved by damped Newton–Krylov and
differentiated implicitly.  See ``docs/ehl.md`` and the submodules:

* :mod:`.grid` — grid, DC-FFT influence coefficients (Liu, Wang & Liu 2000);
* :mod:`.model` — case, scales, discrete equations (Venner & Lubrecht 2000);
* :mod:`.precondition`, :mod:`.solver` — Newton–Krylov solver;
* :mod:`.outputs` — film, loads, friction; :mod:`.implicit` — adjoint gradients;
* :mod:`.api` — public entry points; :mod:`.references` — film formulas for validation.
"""

from gearjax.tribology.ehl.api import (EHLResult, AUTO_SCHEDULES, ehl_fields,
                                       ehl_gradients, ehl_traced, moes_parameters,
                                       solve_ehl)
from gearjax.tribology.ehl.grid import EHLGrid, make_grid
from gearjax.tribology.ehl.model import EHLCase, make_case

__all__ = ["EHLResult", "EHLCase", "EHLGrid", "make_case", "make_grid", "solve_ehl",
           "ehl_traced", "ehl_gradients", "ehl_fields", "moes_parameters",
           "AUTO_SCHEDULES"]
