"""Cradle-type hypoid generator: geometric machine settings and the Gleason No. 116 dials.

Frames (all right-handed, transforms from :mod:`gearjax.frames`, active rotations):

* S_t  cutter frame (see :mod:`gearjax.gears.hypoid.cutter`): ``z_t`` is the cutter axis,
  pointing from the cutter head towards the work; blade tips lie in ``z_t = 0``.
* S_c  cradle frame: ``z_c`` is the cradle axis (same sense as ``z_t`` at zero
  tilt), origin at the machine centre in the machine plane (the plane of the blade
  tips at zero tilt).  S_c turns by the cradle roll ``psi`` about ``z_c``.
* S_m  machine frame, fixed, coincides with S_c at ``psi = 0``.
* S_w  workpiece frame: ``z_w`` is the work axis, origin at the work's pitch-cone
  apex; S_w turns by the work roll ``phi`` about ``z_w``.

Cutter in the cradle (geometric settings, Litvin & Fuentes ch. 21 style): the
cutter centre sits at radial distance ``S_r`` and cradle angle ``q``; the cutter
axis is tilted by ``i`` about a line in the cradle plane whose direction is the
radial line turned by ``-j`` (swivel):

    M_ct = T(S_r cos q, S_r sin q, 0) . Rz(q - j) . Rx(i)

Work on the machine: root line of the work along ``+x_m`` in the machine plane;
the work axis makes the machine root angle ``gamma_m`` with the machine plane;
the work slides by ``Delta X_D`` along its own axis (machine centre to back
increment, positive away from the machine centre), is offset by ``E_m`` along
``y_m`` (blank offset) and by ``X_B`` along the cradle axis (sliding base):

    M_mw(phi) = T(0, E_m, X_B) . Ry(pi/2 - gamma_m) . T(0, 0, Delta X_D) . Rz(phi)

Generating roll with modified roll (Gleason 2C, 6D):

    phi(psi) = R_a * (psi - (2C/2) psi^2 - (6D/6) psi^3)

with ``R_a`` the ratio of roll (work turns per cradle turn, ``m_wc`` of [HFT-hypoid], see docs/references.md).
The cutter surface in the work frame is

    r_w(s, theta, psi) = M_mw(phi(psi))^-1 . Rz(psi) . M_ct . r_t(s, theta).

A *formate* member (non-generated gear) has no roll: ``r_w = M_mw(0)^-1 . M_ct . r_t``.

Gleason No. 116 dials ([HFT-hypoid]): cradle dial ``phi_c``, eccentric ``phi_e``,
swivel ``phi_s``, tilt ``phi_t``, wedge angle ``eps = 15 deg`` and machine length
``l = 222.25/2 mm``.  The cutter centre is carried by two arms of length ``l``
(cradle -> eccentric -> cutter spindle) and the cutter spindle by the tilt drum,
whose axis is inclined by ``eps`` to the spindle:

    M_ct^dial = T(l(cos phi_c - cos(phi_c+phi_e)), l(sin phi_c - sin(phi_c+phi_e)), 0)
                . Rz(tau) . R_k(phi_t),    tau = phi_c + phi_e + phi_s,
                k = (sin eps, 0, cos eps),

read in a cradle frame mirrored in y (``P M P``, P = diag(1, -1, 1); the mirror
leaves ``a11`` unchanged and is the reading under which the pinion dials of [HFT-hypoid]
cut the left-hand pinion of its Table 1), whose first element is the paper's
``a11 = cos(tau)(cos^2 eps cos phi_t + sin^2 eps) - sin(tau) cos(eps) sin(phi_t)``.
Hence ``S_r = 2 l sin(phi_e/2)``, ``q = -(phi_c + phi_e/2 - pi/2)`` (minus the paper's ``q_0``),
``cos i = cos^2 eps + sin^2 eps cos phi_t`` and the swivel from the azimuth of the
tilted cutter axis.  [HFT-hypoid] gives only ``a11``; the remaining elements follow from
this product and are tested by an independent route (both transforms place every
cutter point on the same cone).

Units: mm, rad.  References (docs/references.md): [HFT-hypoid], [Tangent-cones];
[Litvin2004] ch. 21-22.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import jax
import jax.numpy as jnp
import numpy as np

from gearjax import frames
from gearjax.errors import check_positive, check_range

__all__ = ["MachineSettings", "No116Dials", "WEDGE_ANGLE", "MACHINE_LENGTH",
           "cutter_to_cradle", "work_to_machine", "roll_angle", "cutter_to_work",
           "dial_cutter_to_cradle", "dials_to_geometric", "geometric_to_dials",
           "SETTING_FIELDS"]

WEDGE_ANGLE = math.radians(15.0)      # eps, Gleason No. 116 ([HFT-hypoid])
MACHINE_LENGTH = 222.25 / 2.0         # l (mm), Gleason No. 116 ([HFT-hypoid])

SETTING_FIELDS = ["radial_distance", "cradle_angle", "tilt", "swivel", "blank_offset",
                  "machine_root_angle", "sliding_base", "center_to_back", "ratio_of_roll",
                  "modified_roll_2c", "modified_roll_6d"]


@functools.partial(jax.tree_util.register_dataclass, data_fields=SETTING_FIELDS,
                   meta_fields=["generated"])
@dataclass(frozen=True)
class MachineSettings:
    """Geometric settings of a cradle-type generator (a pytree; mm and rad).

    radial_distance S_r (mm), cradle_angle q, tilt i, swivel j (rad),
    blank_offset E_m (mm), machine_root_angle gamma_m (rad), sliding_base X_B (mm),
    center_to_back Delta X_D (mm, machine-centre-to-back increment),
    ratio_of_roll R_a (-), modified_roll_2c (2C, 1/rad), modified_roll_6d (6D, 1/rad^2).
    ``generated`` (static): True for a generated member (cradle roll), False for a
    formate member (the flank is the cutter surface placed by the settings).
    """

    radial_distance: jax.Array
    cradle_angle: jax.Array
    tilt: jax.Array
    swivel: jax.Array
    blank_offset: jax.Array
    machine_root_angle: jax.Array
    sliding_base: jax.Array
    center_to_back: jax.Array
    ratio_of_roll: jax.Array
    modified_roll_2c: jax.Array
    modified_roll_6d: jax.Array
    generated: bool = True

    @staticmethod
    def create(*, radial_distance, cradle_angle, machine_root_angle, tilt=0.0, swivel=0.0,
               blank_offset=0.0, sliding_base=0.0, center_to_back=0.0, ratio_of_roll=0.0,
               modified_roll_2c=0.0, modified_roll_6d=0.0, generated=True) -> "MachineSettings":
        """Validated constructor from internal units (mm, rad); traced values (inside
        ``jax.grad``) pass through unchecked.

        Allowed (concrete values): every setting a finite number (not bool or str);
        radial_distance > 0 mm; tilt in [0, pi/2) rad; cradle_angle, swivel and
        machine_root_angle in [-2 pi, 2 pi] rad (one turn either way: published
        settings such as a machine root angle of 356.67 deg fit); ratio_of_roll > 0
        for a generated member; ``generated`` a bool.  ValueError names the
        parameter, the value and the allowed range."""
        if not isinstance(generated, (bool, np.bool_)):
            raise ValueError(f"generated = {generated!r} must be True or False")
        values = dict(radial_distance=radial_distance, cradle_angle=cradle_angle, tilt=tilt,
                      swivel=swivel, blank_offset=blank_offset,
                      machine_root_angle=machine_root_angle, sliding_base=sliding_base,
                      center_to_back=center_to_back, ratio_of_roll=ratio_of_roll,
                      modified_roll_2c=modified_roll_2c, modified_roll_6d=modified_roll_6d)
        for name, v in values.items():
            if v is None or isinstance(v, (bool, np.bool_, str, bytes, list, tuple, dict)):
                raise ValueError(f"{name} = {v!r} must be a number, got {type(v).__name__}")
        check_positive("radial_distance", radial_distance, "mm")
        check_range("tilt", tilt, 0.0, math.pi / 2, hi_open=True, unit="rad")
        for name in ("cradle_angle", "swivel", "machine_root_angle"):
            check_range(name, values[name], -2.0 * math.pi, 2.0 * math.pi, unit="rad")
        for name in ("blank_offset", "sliding_base", "center_to_back", "ratio_of_roll",
                     "modified_roll_2c", "modified_roll_6d"):
            check_range(name, values[name])
        if generated:
            check_positive("ratio_of_roll", ratio_of_roll)
        f = lambda v: jnp.asarray(v, float)
        return MachineSettings(f(radial_distance), f(cradle_angle), f(tilt), f(swivel),
                               f(blank_offset), f(machine_root_angle), f(sliding_base),
                               f(center_to_back), f(ratio_of_roll), f(modified_roll_2c),
                               f(modified_roll_6d), bool(generated))


def cutter_to_cradle(ms: MachineSettings):
    """M_ct = T(S_r cos q, S_r sin q, 0) Rz(q - j) Rx(i): cutter frame -> cradle frame."""
    S, q = ms.radial_distance, ms.cradle_angle
    return frames.compose(frames.translate(S * jnp.cos(q), S * jnp.sin(q), 0.0),
                          frames.rot_z(q - ms.swivel), frames.rot_x(ms.tilt))


def work_to_machine(ms: MachineSettings, phi=0.0):
    """M_mw(phi) = T(0, E_m, X_B) Ry(pi/2 - gamma_m) T(0, 0, dX_D) Rz(phi): work -> machine."""
    return frames.compose(frames.translate(0.0, ms.blank_offset, ms.sliding_base),
                          frames.rot_y(0.5 * jnp.pi - ms.machine_root_angle),
                          frames.translate(0.0, 0.0, ms.center_to_back), frames.rot_z(phi))


def roll_angle(ms: MachineSettings, psi):
    """Work roll phi(psi) = R_a (psi - (2C/2) psi^2 - (6D/6) psi^3) (rad); 0 for formate."""
    if not ms.generated:
        return jnp.zeros_like(jnp.asarray(psi, float))
    return ms.ratio_of_roll * (psi - 0.5 * ms.modified_roll_2c * psi ** 2
                               - ms.modified_roll_6d / 6.0 * psi ** 3)


def cutter_to_work(ms: MachineSettings, psi=0.0):
    """M_wt(psi) = M_mw(phi(psi))^-1 Rz(psi) M_ct (cutter -> work); psi ignored for formate."""
    if ms.generated:
        return frames.compose(frames.inverse(work_to_machine(ms, roll_angle(ms, psi))),
                              frames.rot_z(psi), cutter_to_cradle(ms))
    return frames.compose(frames.inverse(work_to_machine(ms, 0.0)), cutter_to_cradle(ms))


# --------------------------------------------------------------------------------------
# Gleason No. 116 dial settings ([HFT-hypoid])


@functools.partial(jax.tree_util.register_dataclass,
                   data_fields=["cradle", "eccentric", "swivel", "tilt"], meta_fields=[])
@dataclass(frozen=True)
class No116Dials:
    """Dial settings of a Gleason No. 116 hypoid generator (rad): phi_c, phi_e, phi_s, phi_t."""

    cradle: jax.Array
    eccentric: jax.Array
    swivel: jax.Array
    tilt: jax.Array


def _rot_k(phi_t, eps):
    """Active rotation by phi_t about k = (sin eps, 0, cos eps) (the tilt drum axis)."""
    return frames.rot_axis(jnp.stack([jnp.sin(eps), 0.0 * eps, jnp.cos(eps)]), phi_t)


_MIRROR_Y = np.diag([1.0, -1.0, 1.0, 1.0])


def dial_cutter_to_cradle(d: No116Dials, eps=WEDGE_ANGLE, length=MACHINE_LENGTH):
    """M_ct of [HFT-hypoid] from the No. 116 dials (cutter frame -> cradle frame), 4x4.

    The paper's product, A = T(l(cos phi_c - cos(phi_c+phi_e)), l(sin phi_c -
    sin(phi_c+phi_e)), 0) Rz(phi_c + phi_e + phi_s) R_k(phi_t), k = (sin eps, 0, cos eps),
    is read in a cradle frame mirrored in y: ``M_ct = P A P`` with P = diag(1, -1, 1).
    ``a11`` is unchanged by the mirror (so the paper's a11 holds for both readings);
    only the mirrored reading gives its 8/43 pinion the left hand of Table 1
    (the unmirrored one cuts a right-hand pinion) -- see docs/hypoid.md.
    """
    c, e = d.cradle, d.eccentric
    T = frames.translate(length * (jnp.cos(c) - jnp.cos(c + e)),
                         length * (jnp.sin(c) - jnp.sin(c + e)), 0.0)
    A = frames.compose(T, frames.rot_z(c + e + d.swivel), _rot_k(d.tilt, eps))
    return _MIRROR_Y @ A @ _MIRROR_Y


def _wrap(a):
    return jnp.arctan2(jnp.sin(a), jnp.cos(a))


def dials_to_geometric(d: No116Dials, eps=WEDGE_ANGLE, length=MACHINE_LENGTH):
    """(S_r, q, i, j) from the No. 116 dials (mm, rad), differentiable.

    In the (unmirrored) frame of [HFT-hypoid]: S_r = 2 l sin(phi_e/2), q0 = phi_c + phi_e/2 - pi/2
    (the paper's q0), cos i = cos^2 eps + sin^2 eps cos phi_t, azimuth of the tilted
    cutter axis lam = tau + atan2(-sin phi_t, cos eps (1 - cos phi_t)), and from the
    axis (sin i sin(q-j), -sin i cos(q-j), cos i) of :func:`cutter_to_cradle`
    j0 = q0 - pi/2 - lam.  The mirror in y (see :func:`dial_cutter_to_cradle`) gives
    q = -q0 and j = -pi - j0.  Angles wrapped to (-pi, pi].
    """
    c, e, s, t = d.cradle, d.eccentric, d.swivel, d.tilt
    S = 2.0 * length * jnp.sin(0.5 * e)
    q0 = c + 0.5 * e - 0.5 * jnp.pi
    ax_z = jnp.cos(eps) ** 2 + jnp.sin(eps) ** 2 * jnp.cos(t)
    ax_xy = jnp.sin(eps) * jnp.sqrt((jnp.cos(eps) * (1 - jnp.cos(t))) ** 2 + jnp.sin(t) ** 2)
    i = jnp.arctan2(ax_xy, ax_z)
    lam = c + e + s + jnp.arctan2(-jnp.sin(t), jnp.cos(eps) * (1.0 - jnp.cos(t)))
    j0 = q0 - 0.5 * jnp.pi - lam
    return S, _wrap(-q0), i, _wrap(-jnp.pi - j0)


def geometric_to_dials(S_r, q, i, j, eps=WEDGE_ANGLE, length=MACHINE_LENGTH) -> No116Dials:
    """Inverse of :func:`dials_to_geometric` (tilt dial in [0, pi], eccentric in [0, pi]).

    Raises ValueError (concrete inputs) when ``S_r > 2 l`` or ``i > 2 eps``.
    """
    S_r, i = float(S_r), float(i)
    check_range("radial_distance", S_r, 0.0, 2 * length, unit="mm")
    check_range("tilt", i, 0.0, 2 * eps, unit="rad")
    q0, j0 = -float(q), -math.pi - float(j)          # undo the mirror in y
    e = 2.0 * math.asin(S_r / (2.0 * length))
    c = q0 - 0.5 * e + 0.5 * math.pi
    ct = (math.cos(i) - math.cos(eps) ** 2) / math.sin(eps) ** 2
    t = math.acos(max(-1.0, min(1.0, ct)))
    lam = q0 - 0.5 * math.pi - j0
    s = lam - c - e - math.atan2(-math.sin(t), math.cos(eps) * (1.0 - math.cos(t)))
    s = math.atan2(math.sin(s), math.cos(s))
    return No116Dials(jnp.asarray(c), jnp.asarray(e), jnp.asarray(s), jnp.asarray(t))
