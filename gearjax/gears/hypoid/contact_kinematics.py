"""Rolling, sliding and curvature at the contact points of a hypoid/spiral-bevel TCA.

For every point of a :class:`~gearjax.tca.path.ContactPath` of a
:class:`~gearjax.gears.hypoid.tca.HypoidPair` this module computes the quantities of
[Eigenfunctions] §1 (see docs/references.md) twice:

* **model** -- the eigenfunction kinematics of [Eigenfunctions] (:func:`gearjax.kinematics.
  eigen_kinematics`) with the gear as member 1 (its flank's Weingarten map), the
  pinion as its *conjugate* member 2 and the nominal ratio: what the study of [Eigenfunctions]
  computes at that gear-flank point;
* **pair** -- the same quantities from the actual pair: the surface velocities
  relative to the *moving contact point* of the TCA, ``u_i = (omega_i x r_i - v_c) . t``
  along ``t = p/|p|`` (the model's direction normal to the contact line), with the
  contact-point velocity ``v_c = d r_contact / d phi1`` and the actual gear speed
  ``d phi2/d phi1`` from the implicit derivative of the contact equations
  (``dx/dphi1 = -F_x^-1 F_phi1``); and the relative normal curvature of the two
  flanks in the direction ``t``, ``k_rel = kappa_gear(t) - kappa_pinion(t)``, from both
  flanks' own autodiff curvatures (the pinion an envelope of its machine settings),
  ``r_eff = 1/k_rel``.

For a conjugate pair both routes describe the same contact and must agree (an
independent check of the TCA, of the generated pinion and of the eigenfunction
formulas); for a localised pair the difference is the effect of the mismatch on
the rolling/sliding velocities and on the effective radius seen by the
lubricant film.  Common normal ``n``: out of the pinion material, into the gear
tooth (the orientation of [Eigenfunctions]: ``R_eff > 0`` for a convex contact).  Definitions
(gear = member 1): ``u_e = (u1 + u2)/2``, ``u_s = u1 - u2``, ``SRR = u_s/u_e``.
Velocities in mm per radian of pinion roll (pinion speed 1 rad/s).

References (docs/references.md): [Eigenfunctions] §1-§2; [Litvin2004] ch. 8-9
(relative velocity of the contact point).
"""

from __future__ import annotations

import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp

from gearjax.gears.hypoid import tca as th
from gearjax.gears.hypoid.flank import work_point
from gearjax.frames import matrix_z
from gearjax.kinematics import Kinematics, Mesh, eigen_kinematics
from gearjax.surfaces import GeneratedSurface, curvature_in_direction
from gearjax.tca.path import ContactPath, relative_curvature
from gearjax.tca.assembly import Misalignment
from gearjax.tca.result import contact_motion

__all__ = ["PathKinematics", "path_kinematics"]


class PathKinematics(NamedTuple):
    """Kinematics along a TCA path (arrays over the path; gear = member 1).

    u1, u2, u_e, u_s, srr : pair route, surface velocities of gear (1) and pinion (2)
        relative to the moving contact point along ``t`` (mm/rad), entrainment,
        sliding, slide-to-roll ratio.
    k_rel, r_eff : relative normal curvature gear - pinion along ``t`` (1/mm) and
        its inverse (mm), from both flanks.
    k_along : relative normal curvature along the model's contact line ``n x t``
        (1/mm; 0 for a conjugate pair).
    lam_min, lam_max : principal relative curvatures of the two flanks (1/mm,
        oriented so that the trace is >= 0; point contact: both > 0).
    v_contact : (N, 3) contact-point velocity (mm/rad, fixed frame).
    gear_ratio : actual ``d phi2/d phi1`` (rad/rad).
    model : :class:`~gearjax.kinematics.Kinematics` of the eigenfunction model at the
        same points (``u1, u2, u_e, u_s, srr, k_II, r_eff, phi_I, phi_II, p, ...``).
    """

    u1: jax.Array
    u2: jax.Array
    u_e: jax.Array
    u_s: jax.Array
    srr: jax.Array
    k_rel: jax.Array
    r_eff: jax.Array
    k_along: jax.Array
    lam_min: jax.Array
    lam_max: jax.Array
    v_contact: jax.Array
    gear_ratio: jax.Array
    model: Kinematics


def _outward_normal(fl, surf, uv):
    """Unit normal of a member flank at ``uv`` out of its material (body frame)."""
    psi = surf.solve(uv).x if isinstance(surf, GeneratedSurface) else 0.0
    return work_point(fl, uv[1], uv[0], psi)[1]


def path_kinematics(pair: th.HypoidPair, path: ContactPath, mis: Misalignment | None = None,
                    *, line_contact: bool = False) -> PathKinematics:
    """Model and pair kinematics at every point of ``path`` (module docstring; jitted).

    ``path`` is the :attr:`~gearjax.TCAResult.path` of a TCA of ``pair``
    with misalignment ``mis`` (default none) in the same contact mode
    (``line_contact``).  Points where the path did not converge give meaningless
    values: mask them with ``path.converged``.
    """
    from gearjax.gears.hypoid.pair import program_pair   # one program for every pair
    mis = Misalignment.zero() if mis is None else mis
    return _path_kinematics(program_pair(pair), path, mis, line_contact=line_contact)


@functools.partial(jax.jit, static_argnames=("line_contact",))
def _path_kinematics(pair, path, mis, *, line_contact):
    r1 = th.flank_function(pair.pinion, pair.pinion_crossing)
    r2 = th.flank_function(pair.gear, pair.gear_crossing)
    asm = th.hypoid_assembly(pair)
    mid = path.phi1.shape[0] // 2
    motion, (R, c) = contact_motion(r1, r2, asm, mis, line_contact, path.uv1[mid, 1])
    k2 = R[:, 2]
    ez = jnp.array([0.0, 0.0, 1.0])

    def one(uv1, uv2, ph2, ph1):
        n = matrix_z(ph1) @ _outward_normal(pair.pinion, r1, uv1)
        r, v_c, dph2, W1, W2 = motion(uv1, uv2, ph2, ph1, n)
        # model: gear = member 1 with its axis through the origin (frame shifted by c),
        # pinion = member 2 about the z axis (through -c), nominal ratio
        w_gear = asm.ratio_sign * (asm.z1 / asm.z2) * k2
        kin = eigen_kinematics(Mesh(omega1=w_gear, omega2=ez, a=-c), r - c, n, W2)
        t = kin.p / jnp.linalg.norm(kin.p)
        u1 = jnp.dot(jnp.cross(dph2 * k2, r - c) - v_c, t)
        u2 = jnp.dot(jnp.cross(ez, r) - v_c, t)
        kg = curvature_in_direction(n, W2, t)[0]
        kp = curvature_in_direction(n, W1, t)[0]
        along = jnp.cross(n, t)
        k_along = curvature_in_direction(n, W2, along)[0] - curvature_in_direction(n, W1, along)[0]
        B, _ = relative_curvature(n, W2, W1, t)
        B = jnp.where(B[0, 0] + B[1, 1] < 0.0, -B, B)
        h = 0.5 * (B[0, 0] + B[1, 1])
        g = jnp.sqrt(0.25 * (B[0, 0] - B[1, 1]) ** 2 + B[0, 1] ** 2 + 1e-300)
        u_e = 0.5 * (u1 + u2)
        return (u1, u2, u_e, u1 - u2, (u1 - u2) / u_e, kg - kp, 1.0 / (kg - kp), k_along,
                h - g, h + g, v_c, dph2, kin)

    out = jax.vmap(one)(path.uv1, path.uv2, path.phi2, path.phi1)
    return PathKinematics(*out)

