"""Lubrication and friction of Hertzian gear contacts ([VH-CATT], see docs/references.md).

Modules (imports flow downwards):

    lubricant.py  Oil, example oils, Roelands/Barus viscosity, density, Ree–Eyring
    film.py       Hamrock–Dowson (ellipse) and Pan–Hamrock (line) film thickness
    asperity.py   Greenwood–Tripp F_2, F_5/2 by quadrature; film/asperity load sharing
    friction.py   μ = (f_c F_a + ∫τ dA)/F_n at contact points
    losses.py     sliding power loss, mesh efficiency, Stribeck curves

The empirical gear friction formulas used only for comparison (Xu–Kahraman,
ISO/TR 14179-2, Benedict–Kelley) live outside the package, in
``experiments/friction_reference.py``; gearjax is not tuned to them.

Hertz contact lives in :mod:`gearjax.contact` (its entry points are re-exported here);
the numerical EHL reference in :mod:`gearjax.tribology.ehl`.  Units: mm, N, s, MPa; viscosity
Pa·s; speeds mm/s.
"""

from gearjax.tribology.friction import (REGIMES, STEEL_E_PRIME, FrictionResult, Surface,
                                        friction_coefficient, make_surface)
from gearjax.tribology.losses import mesh_losses, stribeck_curve
from gearjax.tribology.lubricant import OILS, Oil, get_oil, make_oil
from gearjax.tribology.ehl import solve_ehl
from gearjax.contact import HertzResult, hertz_line, hertz_point

__all__ = ["REGIMES", "STEEL_E_PRIME", "FrictionResult", "Surface", "friction_coefficient",
           "make_surface", "mesh_losses",
           "stribeck_curve", "OILS", "Oil", "get_oil", "make_oil", "solve_ehl", "HertzResult",
           "hertz_line", "hertz_point"]
