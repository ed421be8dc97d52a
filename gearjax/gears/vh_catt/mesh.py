"""The VH-CATT pair as the loaded-contact models see it (:class:`~gearjax.loading.loaded_contact.MeshTeeth`).

Each member's tooth is, for its bending, shear and foundation compliance, the
spur tooth of its middle section (an exact involute, [VH-CATT]): tooth number z,
module m, pressure angle alpha, no profile shift, addendum 1 m, dedendum 1.25 m;
the contact radius is the distance of the contact point from the member's axis.
The load is carried over the major axis of the contact ellipse of the TCA at its
elastic approach (0.00632 mm; :data:`gearjax.tca.path.DEFAULT_APPROACH`), at most the
face width b: the sections off the middle are close to the middle one (the trace's
tangential extent over the half face is ``R - sqrt(R^2 - b^2/4)``, 0.25 mm for the
seed's pair), so the cantilever of the middle section stands for them.  The Hertz
approach of the point contact is added by :mod:`gearjax.loading.loaded_contact`.

Units: mm, rad.  References (docs/references.md): [VH-CATT]; [ISO6336-1] (virtual
spur gear of a cylindrical pair); [Weber1949].
"""

from __future__ import annotations

import jax.numpy as jnp

from gearjax.gears.vh_catt.geometry import ADDENDUM, DEDENDUM, VHCattPair
from gearjax.loading.loaded_contact import MeshTeeth
from gearjax.tca.result import TCAResult

__all__ = ["vh_mesh_teeth"]


def vh_mesh_teeth(pair: VHCattPair, res: TCAResult, drive: bool) -> MeshTeeth:
    """:class:`~gearjax.loading.loaded_contact.MeshTeeth` of the pair along the path of ``res``
    (traceable; module docstring)."""
    z = jnp.stack([pair.z1, pair.z2]).astype(float)
    r_load = jnp.stack([res.path.radial1, res.path.radial2])
    b = pair.face_width
    width = jnp.minimum(2.0 * jnp.nan_to_num(res.path.semi_major, nan=0.0, posinf=1e9), b)
    width = jnp.where(width > 0.0, width, b)
    one = jnp.ones(2)
    al = pair.pressure_angle
    return MeshTeeth(z, pair.module, jnp.stack([al, al]), jnp.zeros_like(al), 0.0 * one,
                     ADDENDUM * one, DEDENDUM * one, r_load, width, None, jnp.asarray(drive))
