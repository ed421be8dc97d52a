"""How the two members of a pair are mounted: the nominal assembly and the
misalignments (the inputs every TCA shares).

Two tooth surfaces, each given in its own body frame whose rotation axis is the
body z axis, are mounted in one fixed frame:

    pinion (member 1):  r1f = Rz(phi1) r1(u1, v1) + dP e_z
    gear   (member 2):  r2f = c + R Rz(phi2) r2(u2, v2)
                        R = Rot(d, dSigma) R0,   c = c0 + dE d + dG (R e_z)

``R0`` maps the gear body frame to the fixed frame at phi2 = 0, ``c0`` is the
point of the gear axis on the common perpendicular (the crossing point) and ``d``
the unit common perpendicular (for parallel axes: the centre line).  The
misalignments (:class:`Misalignment`, mm and rad) are: ``dE`` shift of the gear
along ``d`` (change of offset / centre distance), ``dP`` axial shift of the pinion
along its axis, ``dG`` axial shift of the gear along its axis, ``dSigma`` rotation
of the gear axis about ``d`` through the crossing point (change of shaft angle).

Used by the contact path (:mod:`gearjax.tca.path`) and by every family's assembly.
Units: mm, rad.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import check_range
from gearjax.frames import matrix_axis

__all__ = ["Misalignment", "Assembly", "rotation_about", "gear_mount"]


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class Misalignment:
    """Assembly errors (differentiable): dE, dP, dG in mm, dSigma in rad.

    See the module docstring for their definition.  ``Misalignment.zero()`` is the
    nominal assembly.
    """

    dE: jnp.ndarray
    dP: jnp.ndarray
    dG: jnp.ndarray
    dSigma: jnp.ndarray

    @classmethod
    def zero(cls):
        z = jnp.asarray(0.0, float)
        return cls(z, z, z, z)

    @classmethod
    def create(cls, dE=0.0, dP=0.0, dG=0.0, dSigma_deg=0.0):
        """Validated constructor (mm, mm, mm, degrees) for user input: finite numbers
        (not bool or str) with |dE|, |dP|, |dG| <= 50 mm, |dSigma| <= 5 deg; ValueError
        names the parameter, the value and the range.  Traced values (inside
        ``jax.grad``) pass through."""
        for k, v in (("dE", dE), ("dP", dP), ("dG", dG), ("dSigma", dSigma_deg)):
            if v is None or isinstance(v, (bool, np.bool_, str, bytes, list, tuple, dict)):
                raise ValueError(f"{k} = {v!r} must be a number, got {type(v).__name__}")
        vals = [check_range(k, v, -lim, lim, unit=u) for k, v, lim, u in
                (("dE", dE, 50.0, "mm"), ("dP", dP, 50.0, "mm"), ("dG", dG, 50.0, "mm"),
                 ("dSigma", dSigma_deg, 5.0, "deg"))]
        return cls(*(jnp.asarray(v, float) for v in vals[:3]),
                   jnp.asarray(vals[3] * (np.pi / 180.0), float))


@jax.tree_util.register_dataclass
@dataclass(frozen=True)
class Assembly:
    """Nominal mounting of the gear (see module docstring).

    R0 : (3,3) gear body frame -> fixed frame at phi2 = 0.
    c0 : (3,) crossing point on the gear axis (mm).
    d : (3,) unit common perpendicular (direction of dE, axis of dSigma).
    z1, z2 : tooth numbers (data, so that pairs of other tooth numbers share a compiled
        program: they only enter the nominal ratio); ratio_sign : sign of the nominal
        rho (static).
    """

    R0: jnp.ndarray
    c0: jnp.ndarray
    d: jnp.ndarray
    z1: jnp.ndarray
    z2: jnp.ndarray
    ratio_sign: int = field(metadata=dict(static=True), default=-1)


def rotation_about(axis, angle):
    """Rodrigues rotation matrix about ``axis`` by ``angle`` (rad); :func:`gearjax.frames.matrix_axis`."""
    return matrix_axis(axis, angle)


def gear_mount(asm: Assembly, mis: Misalignment):
    """Misaligned gear mounting ``(R, c)``: r2f = c + R Rz(phi2) r2."""
    R = rotation_about(asm.d, mis.dSigma) @ asm.R0
    c = asm.c0 + mis.dE * asm.d + mis.dG * R[:, 2]
    return R, c
