"""The material of a gear pair for the loaded contact: Young's modulus, Poisson's
ratio and the reduced modulus E′.

One convention everywhere (Hertz, film, asperities, tooth compliance)::

    E′ = 2 / ((1 − ν1²)/E1 + (1 − ν2²)/E2)        (MPa; = 2 E* of [Johnson1985] §4.2)

For the two members of one material (the only case the design files describe: a
VH-CATT file's ``[material]`` table holds E and ν of both members) this is
``E′ = E/(1 − ν²)``, the plane-strain modulus; steel (E = 206 000 MPa, ν = 0.3) gives
E′ = 226 374 MPa (:data:`gearjax.tribology.STEEL_E_PRIME`).  The tooth compliance
(:mod:`gearjax.loading.tooth_compliance`: Weber/Cornell cantilever, Sainsot foundation, Weber
line contact; ISO 6336's single stiffness scaled by ``E/E_st``) takes E and ν of the
same material, so a stiffer material shortens both the Hertz approach and the tooth
deflection.

Where the material comes from (:func:`pair_material`), first match wins:

1. an explicit E′ (``E_prime=`` in Python, ``--E-prime-MPa`` on the command line):
   E′ as given, ν of the design's material (0.3 when it has none), E = E′ (1 − ν²);
2. the design's own material (a design object with a ``material()`` method returning
   a :class:`Material`: a VH-CATT design file, an involute design file with its
   optional ``[material]``);
3. the documented default, steel on steel (:data:`STEEL`), for designs that carry no
   material (inline involute pairs and involute files without ``[material]``,
   hypoid / spiral bevel, preset-TE bevel).

:class:`Material` carries the source, which the ``gearjax efficiency`` output reports
(``input.material_source``).  Units: MPa.  References (docs/references.md):
[Johnson1985]; [ISO6336-1].
"""

from __future__ import annotations

from typing import NamedTuple

from gearjax.errors import check_range, is_traced
from gearjax.loading.tooth_compliance import E_STEEL, NU_STEEL

__all__ = ["Material", "STEEL", "E_PRIME_RANGE_MPA", "YOUNGS_MODULUS_RANGE_MPA",
           "POISSON_RANGE", "reduced_modulus", "pair_material", "check_e_prime",
           "SOURCE_DESIGN", "SOURCE_DEFAULT"]

#: accepted reduced modulus E′ (MPa, low bound excluded): the range of the CLI flag
#: ``--E-prime-MPa``; E′ typed in Pa (steel: 2.26e11) is refused
E_PRIME_RANGE_MPA = (0.0, 1e7)
#: Young's modulus of a design file's material (MPa): 50..500 GPa
YOUNGS_MODULUS_RANGE_MPA = (5e4, 5e5)
#: Poisson's ratio of a design file's material
POISSON_RANGE = (0.0, 0.5)

#: ``Material.source`` of the design's own material and of the default
SOURCE_DESIGN = "design [material]"
SOURCE_DEFAULT = "default steel (E 206000 MPa, nu 0.3: the design has no material)"


class Material(NamedTuple):
    """The material of both members: ``youngs_modulus_MPa`` E, ``poisson`` ν and
    ``source`` (where it came from, module docstring).  ``e_prime_MPa`` is
    ``E/(1 − ν²)`` (:func:`reduced_modulus` of two equal members)."""

    youngs_modulus_MPa: float
    poisson: float
    source: str = SOURCE_DEFAULT

    @property
    def e_prime_MPa(self):
        return reduced_modulus(self.youngs_modulus_MPa, self.poisson)


#: the default material: steel on steel, E = 206 000 MPa, ν = 0.3 (E′ = 226 374 MPa)
STEEL = Material(E_STEEL, NU_STEEL, SOURCE_DEFAULT)


def reduced_modulus(E1, nu1, E2=None, nu2=None):
    """``E′ = 2 / ((1 − ν1²)/E1 + (1 − ν2²)/E2)`` (MPa); the second member defaults to
    the first (then ``E′ = E/(1 − ν²)``).  [Johnson1985] §4.2 (E′ = 2E*)."""
    E2 = E1 if E2 is None else E2
    nu2 = nu1 if nu2 is None else nu2
    return 2.0 / ((1.0 - nu1 ** 2) / E1 + (1.0 - nu2 ** 2) / E2)


def check_e_prime(value, name: str = "E_prime"):
    """``value`` (MPa) checked against :data:`E_PRIME_RANGE_MPA` (one-line ValueError
    naming ``name``, the value and the range; a traced value passes unchecked)."""
    if is_traced(value):
        return value
    return check_range(name, value, *E_PRIME_RANGE_MPA, lo_open=True, unit="MPa")


def pair_material(design, E_prime=None, *, override_source: str = "E_prime argument"
                  ) -> Material:
    """The material of the loaded contact of ``design`` (module docstring: an explicit
    ``E_prime`` (MPa) first, then the design's ``material()``, then :data:`STEEL`).

    A concrete ``E_prime`` is validated (:func:`check_e_prime`); with it the tooth
    compliance uses ``E = E′ (1 − ν²)`` with the design's ν (0.3 without one), and
    ``source`` is ``override_source`` (the CLI passes ``"--E-prime-MPa"``)."""
    get = getattr(design, "material", None)
    own = get() if callable(get) else None
    if E_prime is None:
        return own if own is not None else STEEL
    Ep = check_e_prime(E_prime)
    nu = own.poisson if own is not None else NU_STEEL
    return Material(Ep * (1.0 - nu ** 2), nu, override_source)
