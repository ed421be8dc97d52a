"""A tooth pair's compliance along its path of contact, the ISO 6336 reference
stiffness, and the virtual cylindrical gear of a bevel or hypoid member.

Built on the single-tooth compliance of :mod:`gearjax.loading.tooth_compliance`
(docs/compliance.md): the pair compliance at a point of the path is the sum of both
teeth's beam + foundation compliances and the contact compliance
(:func:`pair_compliance`, :func:`path_of_contact`, :func:`single_pair_stiffness`);
ISO 6336-1 method B's constant single stiffness (:func:`iso6336_single_stiffness`,
:func:`iso6336_mesh_stiffness`) [ISO6336-1]; the virtual cylindrical gear of
[ISO10300-1] (:func:`virtual_cylindrical_teeth`).  Pure ``jax.numpy`` functions of
continuous inputs.  Units: mm, N, MPa, rad; compliances per unit face width in mm²/N.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.loading.tooth_compliance import (E_STEEL, NU_STEEL, contact_compliance, inv,
                                              tooth_compliance, tooth_geometry)

__all__ = ["ISO6336_Q_COEFFICIENTS", "PathOfContact", "path_of_contact", "PairCompliance",
           "pair_compliance", "single_pair_stiffness", "normal_section_teeth",
           "ISO6336Stiffness", "iso6336_single_stiffness", "iso6336_mesh_stiffness",
           "VirtualCylindricalTeeth", "virtual_cylindrical_teeth"]

#: [ISO6336-1] method B, C1..C9 of q' = C1 + C2/zn1 + C3/zn2 + C4 x1 + C5 x1/zn1
#: + C6 x2 + C7 x2/zn2 + C8 x1² + C9 x2²  (q' in mm·µm/N).
ISO6336_Q_COEFFICIENTS = (0.04723, 0.15551, 0.25791, -0.00635, -0.11654, -0.00193,
                          -0.24188, 0.00529, 0.00182)


# ---------------------------------------------------------------------------------
# 4. a pair along its path of contact
# ---------------------------------------------------------------------------------

def normal_section_teeth(z, beta, alpha_n):
    """Virtual tooth number of a helical gear in the normal section.

        z_n = z / (cos² β_b cos β),   sin β_b = sin β cos α_n      ([ISO21771], [ISO6336-1]).
    """
    beta_b = jnp.arcsin(jnp.sin(beta) * jnp.cos(alpha_n))
    return z / (jnp.cos(beta_b) ** 2 * jnp.cos(beta))


class PathOfContact(NamedTuple):
    """Path of contact of the (virtual) spur pair, lengths in mm.

    s is measured along the line of action from the pitch point, positive toward the
    pinion tip (s_start < 0 < s_end for a usual pair); ``alpha_w`` operating pressure
    angle (rad); ``p_b`` base pitch; ``eps_alpha`` = (s_end − s_start)/p_b.
    ``interference`` is True where a mating tip reaches below a form circle.
    """

    s_start: jnp.ndarray
    s_end: jnp.ndarray
    alpha_w: jnp.ndarray
    p_b: jnp.ndarray
    eps_alpha: jnp.ndarray
    interference: jnp.ndarray


def _operating_angle(z1, z2, alpha, x1, x2, n_iter=30):
    """α_w from inv α_w = inv α + 2 tan α (x1 + x2)/(z1 + z2) (Newton, fixed count)."""
    target = inv(alpha) + 2.0 * jnp.tan(alpha) * (x1 + x2) / (z1 + z2)

    def body(_, a):
        return a - (inv(a) - target) / jnp.tan(a) ** 2

    a = jax.lax.fori_loop(0, n_iter, body, jax.lax.stop_gradient(alpha + 0.0 * target))
    a = jax.lax.stop_gradient(a)
    return a - (inv(a) - target) / jnp.tan(a) ** 2   # implicit derivative


def path_of_contact(z1, z2, m, alpha, x1=0.0, x2=0.0, ha=1.0, hf=1.25,
                    rho_f=0.38) -> PathOfContact:
    """Path of contact of an external spur pair at the zero-backlash centre distance.

        inv α_w = inv α + 2 tan α (x1 + x2)/(z1 + z2),  a_w = r_b1 + r_b2 over cos α_w,
        s_end = sqrt(r_a1² − r_b1²) − r_b1 tan α_w,
        s_start = −(sqrt(r_a2² − r_b2²) − r_b2 tan α_w),  p_b = π m cos α   ([ISO21771]).

    Tip radii r_a = r + (ha + x) m (no tip shortening).
    """
    g1 = tooth_geometry(z1, m, alpha, x1, ha, hf, rho_f)
    g2 = tooth_geometry(z2, m, alpha, x2, ha, hf, rho_f)
    a_w = _operating_angle(g1.z, g2.z, g1.alpha, g1.x, g2.x)
    s_end = jnp.sqrt(g1.r_a ** 2 - g1.r_b ** 2) - g1.r_b * jnp.tan(a_w)
    s_start = -(jnp.sqrt(g2.r_a ** 2 - g2.r_b ** 2) - g2.r_b * jnp.tan(a_w))
    p_b = jnp.pi * g1.m * jnp.cos(g1.alpha)
    # the mating tip must stay on the involute of the other member
    r1_min = jnp.sqrt(g1.r_b ** 2 + (g1.r_b * jnp.tan(a_w) + s_start) ** 2)
    r2_min = jnp.sqrt(g2.r_b ** 2 + (g2.r_b * jnp.tan(a_w) - s_end) ** 2)
    interference = (r1_min < g1.r_form) | (r2_min < g2.r_form)
    return PathOfContact(s_start, s_end, a_w, p_b, (s_end - s_start) / p_b, interference)


class PairCompliance(NamedTuple):
    """Single-pair compliance at roll positions s (mm²/N per unit face width).

    ``total = tooth1 + tooth2 + contact``; ``r1``, ``r2`` (mm): contact radii on the
    two members; ``stiffness`` = 1/total (N/mm²: N per mm of face width per mm of
    deflection; multiply by 1e-3 for N/(mm·µm)).
    """

    tooth1: jnp.ndarray
    tooth2: jnp.ndarray
    contact: jnp.ndarray
    total: jnp.ndarray
    r1: jnp.ndarray
    r2: jnp.ndarray
    stiffness: jnp.ndarray


def pair_compliance(s, z1, z2, m, alpha, x1=0.0, x2=0.0, beta=0.0, load_per_width=300.0,
                    ha=1.0, hf=1.25, rho_f=0.38, E=E_STEEL, nu=NU_STEEL,
                    rim_ratio=2.0) -> PairCompliance:
    """Compliance of one tooth pair at roll position ``s`` (mm from the pitch point).

        q(s) = q_tooth1(r1(s)) + q_tooth2(r2(s)) + q_c(w, s),
        r1 = sqrt(r_b1² + (r_b1 tan α_w + s)²),  r2 = sqrt(r_b2² + (r_b2 tan α_w − s)²),

    per unit face width, in mm²/N (deflection along the line of action per N/mm of
    normal load).  ``m`` is the normal module, ``alpha`` the normal pressure angle;
    for a helical pair (``beta`` ≠ 0, rad) the teeth are those of the virtual spur
    gears of the normal section, z_n = z/(cos² β_b cos β) (:func:`normal_section_teeth`),
    and s is measured in that section; the result is per unit length of the
    normal-section tooth (ISO 6336-1 multiplies its c'_th by cos β for the
    transverse-load stiffness per unit face width).  ``load_per_width`` w (N/mm)
    enters only the contact term (:func:`contact_compliance`).  s is broadcast
    (any shape); the other arguments are scalars (vmap for batches of pairs).
    """
    zn1 = normal_section_teeth(jnp.asarray(z1, float), beta, alpha)
    zn2 = normal_section_teeth(jnp.asarray(z2, float), beta, alpha)
    path = path_of_contact(zn1, zn2, m, alpha, x1, x2, ha, hf, rho_f)
    g1 = tooth_geometry(zn1, m, alpha, x1, ha, hf, rho_f)
    g2 = tooth_geometry(zn2, m, alpha, x2, ha, hf, rho_f)
    s = jnp.asarray(s, dtype=float)
    t1 = g1.r_b * jnp.tan(path.alpha_w) + s
    t2 = g2.r_b * jnp.tan(path.alpha_w) - s
    r1 = jnp.sqrt(g1.r_b ** 2 + t1 ** 2)
    r2 = jnp.sqrt(g2.r_b ** 2 + t2 ** 2)

    def one(r1_, r2_, rho1, rho2):
        c1 = tooth_compliance(r1_, zn1, m, alpha, x1, ha, hf, rho_f, E, nu, rim_ratio)
        c2 = tooth_compliance(r2_, zn2, m, alpha, x2, ha, hf, rho_f, E, nu, rim_ratio)
        h1 = c1.half_thickness / jnp.cos(c1.load_angle)
        h2 = c2.half_thickness / jnp.cos(c2.load_angle)
        qc = contact_compliance(load_per_width, rho1 * rho2 / (rho1 + rho2), h1, h2, E, nu)
        return c1.total, c2.total, qc

    flat = [jnp.ravel(v) for v in jnp.broadcast_arrays(r1, r2, t1, t2)]
    q1, q2, qc = jax.vmap(one)(*flat)
    shape = s.shape
    q1, q2, qc = (v.reshape(shape) for v in (q1, q2, qc))
    total = q1 + q2 + qc
    return PairCompliance(q1, q2, qc, total, r1, r2, 1.0 / total)


def single_pair_stiffness(z1, z2, m, alpha, x1=0.0, x2=0.0, beta=0.0, n_points=41,
                          **kwargs):
    """Maximum single-pair stiffness along the path and where it occurs.

    Returns ``(c_max, s_at_max)``: c_max = max_s 1/q(s) over ``n_points`` positions
    spread evenly on [s_start, s_end] of the normal-section virtual pair, refined by a
    parabola through the best three; in N/mm² (× 1e-3 for N/(mm·µm)), normal section
    (× cos β for ISO's c' of a helical pair).
    """
    zn1 = normal_section_teeth(jnp.asarray(z1, float), beta, alpha)
    zn2 = normal_section_teeth(jnp.asarray(z2, float), beta, alpha)
    hkw = {k: kwargs[k] for k in ("ha", "hf", "rho_f") if k in kwargs}
    path = path_of_contact(zn1, zn2, m, alpha, x1, x2, **hkw)
    s = jnp.linspace(path.s_start, path.s_end, n_points)
    c = pair_compliance(s, z1, z2, m, alpha, x1, x2, beta, **kwargs).stiffness
    i = jnp.clip(jnp.argmax(c), 1, n_points - 2)
    cm, c0, cp = c[i - 1], c[i], c[i + 1]
    h = s[1] - s[0]
    den = cm - 2.0 * c0 + cp
    off = jnp.where(den < 0, 0.5 * (cm - cp) / den, 0.0)
    off = jnp.clip(off, -1.0, 1.0)
    cmax = c0 - 0.25 * (cm - cp) * off
    return cmax, s[i] + off * h


# ---------------------------------------------------------------------------------
# 5. ISO 6336-1 reference
# ---------------------------------------------------------------------------------

class ISO6336Stiffness(NamedTuple):
    """ISO 6336-1 method B single stiffness.

    q_prime: minimum flexibility of a tooth pair q' (mm·µm/N); c_th = 1/q'
    (N/(mm·µm)); C_B basic-rack factor; c_prime = c_th C_M C_R C_B cos β (N/(mm·µm)).
    """

    q_prime: jnp.ndarray
    c_th: jnp.ndarray
    C_B: jnp.ndarray
    c_prime: jnp.ndarray


def iso6336_single_stiffness(z1, z2, x1=0.0, x2=0.0, beta=0.0, alpha_n=np.deg2rad(20.0),
                             hfp=1.25, C_M=0.8, C_R=1.0) -> ISO6336Stiffness:
    """The single stiffness of ISO 6336-1 (method B) — the standard's formula.

        q' = C1 + C2/z_n1 + C3/z_n2 + C4 x1 + C5 x1/z_n1 + C6 x2 + C7 x2/z_n2
             + C8 x1² + C9 x2²                                      (mm·µm/N),
        c'_th = 1/q',   c' = c'_th C_M C_R C_B cos β                (N/(mm·µm)),
        C_B = [1 + 0.5 (1.2 − h_fP/m_n)] [1 − 0.02 (20° − α_n)],   z_n = z/cos³ β,

    C1..C9 :data:`ISO6336_Q_COEFFICIENTS`; C_M = 0.8 (measured/theoretical for solid
    disc gears), C_R = 1 for solid gears; ``hfp`` h_fP/m_n of the basic rack;
    internal gears: z2 = inf.  Valid in the standard for x1 ≥ x2 and −0.5 ≤ x1 + x2
    ≤ 2.  (The C_B form is the 2006 edition's, with 1.2; α_n enters in degrees.)
    For F_t K_A/b < 100 N/mm the standard scales c' further; not applied here.
    """
    C = ISO6336_Q_COEFFICIENTS
    cb3 = jnp.cos(beta) ** 3
    zn1, zn2 = z1 / cb3, z2 / cb3
    q = (C[0] + C[1] / zn1 + C[2] / zn2 + C[3] * x1 + C[4] * x1 / zn1 + C[5] * x2
         + C[6] * x2 / zn2 + C[7] * x1 ** 2 + C[8] * x2 ** 2)
    c_th = 1.0 / q
    C_B = (1.0 + 0.5 * (1.2 - hfp)) * (1.0 - 0.02 * (20.0 - jnp.rad2deg(alpha_n)))
    return ISO6336Stiffness(q, c_th, C_B, c_th * C_M * C_R * C_B * jnp.cos(beta))


def iso6336_mesh_stiffness(c_prime, eps_alpha):
    """Mean mesh stiffness of ISO 6336-1: c_γα = c' (0.75 ε_α + 0.25) (ε_α ≥ 1.2)."""
    return c_prime * (0.75 * eps_alpha + 0.25)


# ---------------------------------------------------------------------------------
# 6. virtual cylindrical gears of bevel and hypoid members (ISO 10300-1)
# ---------------------------------------------------------------------------------

class VirtualCylindricalTeeth(NamedTuple):
    """Virtual tooth numbers of a bevel/hypoid member (ISO 10300-1).

    z_v: transverse virtual teeth z/cos δ; beta_vb: virtual base helix angle (rad);
    z_vn: normal-section virtual teeth (the spur tooth for :func:`tooth_compliance`
    at the mean normal module m_mn).
    """

    z_v: jnp.ndarray
    beta_vb: jnp.ndarray
    z_vn: jnp.ndarray


def virtual_cylindrical_teeth(z, pitch_angle, mean_spiral_angle,
                              normal_pressure_angle=np.deg2rad(20.0)) -> VirtualCylindricalTeeth:
    """Virtual cylindrical gear of a bevel or hypoid member ([ISO10300-1], method B).

        z_v = z / cos δ,
        β_vb = asin(sin β_m cos α_n),
        z_vn = z_v / (cos² β_vb cos β_m),

    δ the pitch angle, β_m the mean spiral angle of this member, α_n the normal
    pressure angle (rad).  For a hypoid pair each member uses its own β_m (ISO 10300
    builds one virtual pair with the mean of the two; using each member's own angle
    is the approximation here).  The tooth then follows from :func:`tooth_compliance`
    with z = z_vn at the mean normal module m_mn.
    """
    z_v = z / jnp.cos(pitch_angle)
    beta_vb = jnp.arcsin(jnp.sin(mean_spiral_angle) * jnp.cos(normal_pressure_angle))
    z_vn = z_v / (jnp.cos(beta_vb) ** 2 * jnp.cos(mean_spiral_angle))
    return VirtualCylindricalTeeth(z_v, beta_vb, z_vn)
