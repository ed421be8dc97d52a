"""The involute pair as the loaded-contact models see it (:class:`~gearjax.loading.loaded_contact.MeshTeeth`).

Each member is the spur gear of its normal section, ``z_n = z / (cos^2(beta_b)
cos(beta))`` with the normal module and pressure angle ([ISO6336-1] virtual gear);
the contact radius ``r`` (transverse) maps onto it at the same height above the
reference circle, ``r_v = z_n m_n / 2 + (r - z m_n / (2 cos beta))``.  Rack-generated
teeth: addendum ``(1 + x) m_n`` of the pinion/gear tip circles, dedendum 1.25 m_n.

Load-carrying width: a line contact (spur pair) carries its load along the whole
face width ``b``; a point contact (crowned pinion) over the major axis of its
contact ellipse at the elastic approach of the TCA (0.00632 mm, the bearing
length of Gleason practice), at most ``b``.  A helical pair in *line* contact is
not supported here (its contact lines leave the transverse section of the TCA: give
the pinion a lead crown, which every helical pinion carries in practice); the line
contact of spur and helical pairs, with their micro-geometry, is
:mod:`gearjax.gears.involute.line_load` (``gearjax loaded``).

Units: mm, rad.  References (docs/references.md): [ISO6336-1].
"""

from __future__ import annotations

import jax.numpy as jnp

from gearjax.gears.involute.geometry import pair_geometry
from gearjax.loading.loaded_contact import MeshTeeth
from gearjax.tca.result import TCAResult

__all__ = ["involute_mesh_teeth", "virtual_teeth", "check_mesh_supported", "ohlendorf_loss_factor"]


def check_mesh_supported(des, line_contact: bool) -> None:
    """Refuse a helical pair in line contact (concrete; module docstring)."""
    if line_contact and float(des.pair.helix) != 0.0:
        raise ValueError(f"helix = {float(des.pair.helix) * 180 / jnp.pi:g} deg in line contact: "
                         "this loaded contact (through the TCA) needs point contact: give the "
                         "pinion a lead crown (e.g. lead_crown=1e-4 1/mm), or analyse the line "
                         "contact with `gearjax loaded --rpm ...` "
                         "(gearjax.involute.loaded_te_map)")


def involute_mesh_teeth(des, res: TCAResult, line_contact: bool,
                        drive: bool) -> MeshTeeth:
    """:class:`~gearjax.loading.loaded_contact.MeshTeeth` of the involute pair along the path of
    ``res`` (traceable; module docstring)."""
    b = des.face_width
    if line_contact:
        width = jnp.full(res.path.phi1.shape, 1.0) * b
        line = width
    else:
        width = jnp.minimum(2.0 * jnp.nan_to_num(res.path.semi_major, nan=0.0, posinf=1e9), b)
        width = jnp.where(width > 0.0, width, b)
        line = None
    return virtual_teeth(des.pair, res.path.radial1, res.path.radial2, width, line, drive,
                         des.dalpha)


def virtual_teeth(p, radial1, radial2, width, line, drive, dalpha=0.0) -> MeshTeeth:
    """:class:`~gearjax.loading.loaded_contact.MeshTeeth` of the pair ``p`` at contact radii
    ``radial1``, ``radial2`` (mm, transverse, any shape (N,)) carried over ``width``
    (mm) and, for a line contact, along ``line`` (mm; ``None`` for a point contact):
    the virtual spur gears of the normal section (module docstring); ``dalpha`` the
    pinion rack's pressure-angle change (rad).  Traceable."""
    geo = pair_geometry(p)
    beta = p.helix
    cb = jnp.cos(geo["beta_b"]) ** 2 * jnp.cos(beta)
    z = jnp.stack([p.z1 / cb, p.z2 / cb]).astype(float)
    mn = p.module
    r_ref = jnp.stack([0.5 * p.z1 * mn / jnp.cos(beta), 0.5 * p.z2 * mn / jnp.cos(beta)])
    r_load = 0.5 * z[:, None] * mn + (jnp.stack([radial1, radial2]) - r_ref[:, None])
    one = jnp.ones(2)
    return MeshTeeth(z, mn, jnp.stack([p.pressure_angle + dalpha, p.pressure_angle]),
                     beta, jnp.stack([p.x1, p.x2]), one, 1.25 * one, r_load, width, line,
                     jnp.asarray(drive))


def ohlendorf_loss_factor(pair):
    """Ohlendorf's tooth loss factor of a cylindrical pair ([Ohlendorf1958], as in
    [ISO/TR 14179-2] and Niemann & Winter):

        H_V = pi (u + 1) / (z1 u cos(beta_b)) (1 - eps_a + eps_1^2 + eps_2^2),

    u = z2/z1, eps_a the transverse contact ratio, eps_1, eps_2 the addendum contact
    ratios of pinion and gear (path from the pitch point to the end / from the start
    of contact, over the transverse base pitch).  It assumes the load shared equally
    in double contact (line load constant along the path for helical pairs) and a
    constant mu: the mean sliding loss is ``P_V = mu_m H_V P_in`` (for eps_a < 2
    with the pitch point in single contact).  Traceable."""
    geo = pair_geometry(pair)
    p_bt = 2.0 * jnp.pi * geo["rb1"] / pair.z1
    e1 = (geo["rho_E"] - geo["rho_P"]) / p_bt
    e2 = (geo["rho_P"] - geo["rho_A"]) / p_bt
    u = pair.z2 / pair.z1
    return (jnp.pi * (u + 1.0) / (pair.z1 * u * jnp.cos(geo["beta_b"]))
            * (1.0 - geo["contact_ratio"] + e1 ** 2 + e2 ** 2))
