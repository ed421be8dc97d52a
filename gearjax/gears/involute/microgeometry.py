"""Micro-geometry of cylindrical involute flanks: profile and lead modifications as
differentiable design fields (ISO 21771 / ISO 1328-1 names, common practice).

A modification is the material *removed* from the nominal involute flank (µm,
positive = removed), measured as ISO 1328-1 measures profile and helix deviations:
in the transverse plane along the tangent to the base circle, i.e. along the line of
action.  It is a function of two coordinates of the flank:

* the roll length ``xi`` (mm): the length of the tangent from the point to the base
  circle, ``xi = sqrt(r^2 - r_b^2)`` for a point at radius ``r`` (the roll angle is
  ``xi / r_b``); the active profile runs from the start of active profile (SAP, the
  lowest point the mate reaches) to the tip, ``xi_SAP <= xi <= xi_tip``, its length
  ``L_alpha`` is the length of the path of contact for both members;
* the face coordinate ``y`` (mm) along the axis from the face centre, ``-b/2 <= y <=
  b/2``; end I is ``y = -b/2``, end II ``y = +b/2`` (one axis for the pair: the two
  members' face centres coincide).

With ``t_a = (xi - (xi_tip - L_a)) / L_a``, ``t_f = ((xi_SAP + L_f) - xi) / L_f``,
``u = (xi - xi_m) / L_alpha`` (``xi_m`` the middle of the active profile) and
``v = y / b``, the removal is the sum of

    tip relief        C_a  max(t_a, 0)^p_a          (amount C_a at the tip)
    root relief       C_f  max(t_f, 0)^p_f          (amount C_f at the SAP)
    profile crowning  C_alpha (2u)^2                (C_alpha at both ends, 0 in the middle)
    profile slope     f_Halpha u                    (+f/2 at the tip, -f/2 at the SAP)
    lead crowning     C_beta (2v)^2                 (C_beta at both ends)
    end relief I      C_I  max(t_I, 0)^p_I,   t_I  = (-b/2 + L_I - y) / L_I
    end relief II     C_II max(t_II, 0)^p_II, t_II = (y - b/2 + L_II) / L_II
    helix slope       f_Hbeta v                     (+f/2 at end II, -f/2 at end I)
    bias (twist)      S u v                         (profile slope +S/2 at end II,
                                                     -S/2 at end I: a difference S)

``p = 1`` is a linear relief, ``p = 2`` a parabolic one (the exponent is a field, so
it may be optimised too; it must stay >= 1 for a relief with no kink inside).  The
relief lengths ``L_a``, ``L_f`` are roll lengths along the line of action (mm; the
start diameter of a tip relief is ``d_Ca = 2 sqrt(r_b^2 + (xi_tip - L_a)^2)``), the end
relief lengths ``L_I``, ``L_II`` axial lengths from the face end (mm).  The signs of
the slopes and the bias are the convention written here (positive removes material
toward the tip and toward end II); ISO 1328-1 defines the deviations' magnitudes,
not which way a modification is counted.

The misalignment of the shafts in the plane of action, ``f_ma`` (µm over the face
width, ISO 6336-1's mesh misalignment), enters the separation as ``f_ma v``
(:func:`misalignment_um`); it is an operating condition, not a flank field.

Units: µm for amounts, mm for lengths and coordinates.  References
(docs/references.md): [ISO21771]; [ISO1328-1]; [ISO6336-1].
"""

from __future__ import annotations

from dataclasses import dataclass, fields, replace

import jax
import jax.numpy as jnp

from gearjax.errors import check_range
from gearjax.fields import float64_array

__all__ = ["FlankModification", "PairModification", "MicroGeometry", "FIELD_UNITS",
           "flank_removal_um", "misalignment_um", "check_modification"]

#: field -> (unit, lower bound, upper bound) of :class:`FlankModification`
FIELD_UNITS = {
    "tip_relief": ("um", 0.0, 500.0), "tip_relief_length": ("mm", 0.0, 1e3),
    "tip_relief_exponent": ("", 1.0, 4.0),
    "root_relief": ("um", 0.0, 500.0), "root_relief_length": ("mm", 0.0, 1e3),
    "root_relief_exponent": ("", 1.0, 4.0),
    "profile_crowning": ("um", -500.0, 500.0), "profile_slope": ("um", -500.0, 500.0),
    "lead_crowning": ("um", -500.0, 500.0),
    "end_relief_I": ("um", 0.0, 500.0), "end_relief_I_length": ("mm", 0.0, 1e3),
    "end_relief_II": ("um", 0.0, 500.0), "end_relief_II_length": ("mm", 0.0, 1e3),
    "end_relief_exponent": ("", 1.0, 4.0),
    "helix_slope": ("um", -500.0, 500.0), "bias": ("um", -500.0, 500.0),
}


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class FlankModification:
    """The modifications of one flank (module docstring); every field differentiable.

    Amounts in µm, lengths in mm (roll lengths for the profile reliefs, axial lengths
    for the end reliefs), exponents dimensionless (1 linear, 2 parabolic).
    """

    tip_relief: jax.Array
    tip_relief_length: jax.Array
    tip_relief_exponent: jax.Array
    root_relief: jax.Array
    root_relief_length: jax.Array
    root_relief_exponent: jax.Array
    profile_crowning: jax.Array
    profile_slope: jax.Array
    lead_crowning: jax.Array
    end_relief_I: jax.Array
    end_relief_I_length: jax.Array
    end_relief_II: jax.Array
    end_relief_II_length: jax.Array
    end_relief_exponent: jax.Array
    helix_slope: jax.Array
    bias: jax.Array

    @classmethod
    def none(cls) -> "FlankModification":
        """The unmodified flank (every amount 0; linear reliefs of unit length)."""
        one = ("tip_relief_length", "tip_relief_exponent", "root_relief_length",
               "root_relief_exponent", "end_relief_I_length", "end_relief_II_length",
               "end_relief_exponent")
        return cls(**{f.name: float64_array(1.0 if f.name in one else 0.0)
                      for f in fields(cls)})

    @classmethod
    def create(cls, **values) -> "FlankModification":
        """Validated constructor: the fields by name (module docstring units), the rest
        unmodified; a value outside :data:`FIELD_UNITS` or a relief with an amount but
        no length raises ``ValueError`` naming the field."""
        unknown = sorted(set(values) - set(FIELD_UNITS))
        if unknown:
            raise ValueError(f"unknown modification field {unknown[0]!r}: allowed "
                             f"{', '.join(FIELD_UNITS)}")
        out = replace(cls.none(), **{k: float64_array(v) for k, v in values.items()})
        check_modification(out)
        return out


def check_modification(mod: FlankModification, where: str = "") -> None:
    """Range checks of a concrete :class:`FlankModification` (traced values pass)."""
    for k, (unit, lo, hi) in FIELD_UNITS.items():
        check_range(f"{where}{k}", getattr(mod, k), lo, hi, unit=unit)
    for amount, length in (("tip_relief", "tip_relief_length"),
                           ("root_relief", "root_relief_length"),
                           ("end_relief_I", "end_relief_I_length"),
                           ("end_relief_II", "end_relief_II_length")):
        a, L = getattr(mod, amount), getattr(mod, length)
        if not isinstance(a, jax.core.Tracer) and float(a) > 0.0 and float(L) <= 0.0:
            raise ValueError(f"{where}{length} = {float(L):g} mm: a relief of {float(a):g} um "
                             "needs a length > 0 mm")


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class PairModification:
    """The modifications of the two flanks in mesh: ``pinion`` and ``gear``
    (:class:`FlankModification` each)."""

    pinion: FlankModification
    gear: FlankModification

    @classmethod
    def none(cls) -> "PairModification":
        return cls(FlankModification.none(), FlankModification.none())


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class MicroGeometry:
    """The modifications of a pair's four working flanks: ``drive`` (the flanks in mesh
    when the pinion drives) and ``coast`` (the other two), a :class:`PairModification`
    each."""

    drive: PairModification
    coast: PairModification

    @classmethod
    def none(cls) -> "MicroGeometry":
        return cls(PairModification.none(), PairModification.none())

    def flanks(self, side: str) -> PairModification:
        """The flanks in mesh on ``side`` (``"drive"`` or ``"coast"``)."""
        if side not in ("drive", "coast"):
            raise ValueError(f"side = {side!r} must be 'drive' or 'coast'")
        return self.drive if side == "drive" else self.coast


def _relief(amount, t, exponent):
    """``amount * max(t, 0)^exponent`` with a safe power at ``t <= 0`` (zero value and
    zero gradient there)."""
    pos = t > 0.0
    ts = jnp.where(pos, t, 1.0)
    return jnp.where(pos, amount * ts ** exponent, 0.0)


def _safe(length):
    return jnp.where(length > 0.0, length, 1.0)


def flank_removal_um(mod: FlankModification, xi, y, xi_sap, xi_tip, face_width):
    """Material removed (µm) at roll length ``xi`` (mm) and face position ``y`` (mm)
    of a flank whose active profile is ``[xi_sap, xi_tip]`` and face width
    ``face_width`` (mm); the sum of the module docstring.  Broadcasts ``xi`` and ``y``;
    traceable and differentiable in every argument."""
    xi, y = jnp.asarray(xi, float), jnp.asarray(y, float)
    L_alpha = xi_tip - xi_sap
    u = (xi - 0.5 * (xi_sap + xi_tip)) / L_alpha
    v = y / face_width
    La, Lf = _safe(mod.tip_relief_length), _safe(mod.root_relief_length)
    LI, LII = _safe(mod.end_relief_I_length), _safe(mod.end_relief_II_length)
    profile = (_relief(mod.tip_relief, (xi - (xi_tip - La)) / La, mod.tip_relief_exponent)
               + _relief(mod.root_relief, ((xi_sap + Lf) - xi) / Lf, mod.root_relief_exponent)
               + mod.profile_crowning * (2.0 * u) ** 2 + mod.profile_slope * u)
    half = 0.5 * face_width
    lead = (mod.lead_crowning * (2.0 * v) ** 2 + mod.helix_slope * v
            + _relief(mod.end_relief_I, (-half + LI - y) / LI, mod.end_relief_exponent)
            + _relief(mod.end_relief_II, (y - half + LII) / LII, mod.end_relief_exponent))
    return profile + lead + mod.bias * u * v


def misalignment_um(f_ma, y, face_width):
    """Separation (µm) added by a mesh misalignment ``f_ma`` (µm across the face width,
    positive opening end II): ``f_ma y / b``."""
    return f_ma * jnp.asarray(y, float) / face_width
