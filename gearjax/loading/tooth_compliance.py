"""Tooth compliance of involute teeth: beam, fillet foundation and contact terms.

The compliance model behind loaded tooth contact (issue [M]); docs/compliance.md
gives the equations, the units and the comparison with ISO 6336.  Everything is a
pure ``jax.numpy`` function of continuous inputs (tooth numbers may be floats: the
virtual tooth numbers of helical, bevel and hypoid gears are not integers), so
``jit``, ``vmap`` and ``grad`` apply to every argument.

Units: mm, N, MPa (N/mm²), rad.  A *compliance per unit face width* q is the
deflection along the line of action (mm) per unit normal load per unit face width
(N/mm): q in mm²/N.  ISO 6336 quotes the flexibility q' in mm·µm/N and the
stiffness c' = 1/q' in N/(mm·µm); ``1 mm²/N = 1000 mm·µm/N``, hence
``c' [N/(mm·µm)] = 1e-3 / q [mm²/N]`` (:data:`MM2_PER_N_TO_MM_UM_PER_N`).

The parts (docs/compliance.md):

1. Geometry of a rack-generated tooth of a (virtual) spur gear: the involute flank
   and the trochoidal root fillet cut by the rounded tip of the basic rack
   (:func:`tooth_geometry`, :func:`involute_point`, :func:`fillet_point`)
   [Litvin2004] ch. 10; [ISO21771].
2. The tooth as a cantilever of variable section clamped on the root circle
   (bending, shear, axial compression by the energy method, Gauss–Legendre
   quadrature: :func:`beam_compliance`) [Weber1949] [Cornell1981], plus the fillet
   foundation of [Sainsot2004] (:func:`foundation_compliance`); together
   :func:`tooth_compliance`.
3. The Hertzian line contact with Weber's body-depth correction
   (:func:`contact_compliance`) [Weber1949] [Cornell1981].
4.-6. A pair along its path of contact, the reference formula of ISO 6336-1 method B
   and the virtual cylindrical gear of a bevel/hypoid member: in
   :mod:`gearjax.loading.pair_stiffness`.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

__all__ = [
    "E_STEEL", "NU_STEEL", "MM2_PER_N_TO_MM_UM_PER_N", "SAINSOT_COEFFICIENTS",
    "ToothGeometry", "tooth_geometry", "involute_point", "fillet_point",
    "involute_half_thickness", "inv",
    "BeamCompliance", "beam_compliance", "foundation_compliance", "ToothCompliance",
    "tooth_compliance", "contact_compliance",
]

E_STEEL = 206000.0   # MPa
NU_STEEL = 0.3
#: 1 mm²/N expressed in mm·µm/N (the unit of ISO 6336's flexibility q').
MM2_PER_N_TO_MM_UM_PER_N = 1000.0

#: [Sainsot2004] Table (also reproduced in [Chaari2009]): rows L*, M*, P*, Q*;
#: columns A_i, B_i, C_i, D_i, E_i, F_i of
#: X*(h_fi, θ_f) = A_i/θ_f² + B_i h_fi² + C_i h_fi/θ_f + D_i/θ_f + E_i h_fi + F_i,
#: θ_f in rad, h_fi = r_f/r_int.
SAINSOT_COEFFICIENTS = np.array([
    [-5.574e-5, -1.9986e-3, -2.3015e-4, 4.7702e-3, 0.0271, 6.8045],
    [60.111e-5, 28.100e-3, -83.431e-4, -9.9256e-3, 0.1624, 0.9086],
    [-50.952e-5, 185.50e-3, 0.0538e-4, 53.300e-3, 0.2895, 0.9236],
    [-6.2042e-5, 9.0889e-3, -4.0964e-4, 7.8297e-3, -0.1472, 0.6904],
])

# Gauss–Legendre nodes and weights on [-1, 1] (numpy constants, traced as literals)
_GL_N = 32
_GL_X, _GL_W = np.polynomial.legendre.leggauss(_GL_N)


def inv(a):
    """Involute function inv a = tan a − a."""
    return jnp.tan(a) - a


def _gauss(a, b):
    """Gauss–Legendre nodes and weights mapped to [a, b] (a, b scalars)."""
    half = 0.5 * (b - a)
    return 0.5 * (a + b) + half * _GL_X, half * _GL_W


# ---------------------------------------------------------------------------------
# 1. geometry of the rack-generated tooth
# ---------------------------------------------------------------------------------

class ToothGeometry(NamedTuple):
    """Geometry of one rack-generated external spur tooth (lengths in mm, angles rad).

    The tooth centre line is the x axis of the tooth frame (origin at the gear
    centre); ``y`` is the half-thickness (distance of the flank from the centre line).

    Attributes
    ----------
    z, m, alpha, x : tooth number (float), module, pressure angle, profile shift coefficient.
    r, r_b, r_a, r_f : pitch, base, tip and root radii.
    r_form : radius of the form circle (involute/fillet junction).
    theta_b : half-angle of the tooth at the base circle, ψ_p + inv α.
    theta_f : half-angle of the tooth at the root circle (where the fillet meets it).
    s_f : tooth thickness at the root circle, S_f = 2 r_f θ_f ([Sainsot2004]).
    rho : tool tip radius ρ_fP = rho_f m.
    xc0, yc0 : centre of the tool tip rounding in the rack at the reference
        position (x radial, y along the rack pitch line), used by :func:`fillet_point`.
    t_junction : fillet parameter at the involute junction (t = 0 at the root circle).
    undercut : True where the rack's straight flank cuts below the base circle
        (the involute is undercut; the model is not valid there).
    """

    z: jnp.ndarray
    m: jnp.ndarray
    alpha: jnp.ndarray
    x: jnp.ndarray
    r: jnp.ndarray
    r_b: jnp.ndarray
    r_a: jnp.ndarray
    r_f: jnp.ndarray
    r_form: jnp.ndarray
    theta_b: jnp.ndarray
    theta_f: jnp.ndarray
    s_f: jnp.ndarray
    rho: jnp.ndarray
    xc0: jnp.ndarray
    yc0: jnp.ndarray
    t_junction: jnp.ndarray
    undercut: jnp.ndarray


def tooth_geometry(z, m, alpha, x=0.0, ha=1.0, hf=1.25, rho_f=0.38) -> ToothGeometry:
    """Geometry of a tooth generated by a basic rack with a rounded tip.

    The basic rack has pressure angle ``alpha``, addendum ``hf m`` (it cuts the
    gear's dedendum), tip radius ``rho_f m``; the gear gets addendum ``ha m``; the rack
    reference line is shifted ``x m`` away from the gear centre ([ISO21771]):

        r = m z/2,  r_b = r cos α,  r_a = r + (ha + x) m,  r_f = r − (hf − x) m,
        ψ_p = (π/2 + 2 x tan α)/z        (tooth half-angle at the pitch circle),
        θ_b = ψ_p + inv α                (half-angle at the base circle).

    Tool tip rounding centre (rack frame: height above the gear centre x_c0, position
    along the pitch line y_c0, the gear tooth centre line at y = 0):

        x_c0 = r_f + ρ,   y_c0 = π m/4 + (hf m − ρ) tan α + ρ/cos α

    (the shift moves the rack radially only).

    The fillet meets the root circle at the half-angle θ_f = y_c0/r (the classical
    θ_f = [π/2 + 2 tan α (hf − ρ_f) + 2 ρ_f/cos α]/z) and the involute
    at the form circle r_form = sqrt(r_b² + (r sin α − h_j/sin α)²), with
    h_j = (hf − x) m − ρ (1 − sin α) the depth below the pitch line of the point
    where the rounding meets the rack's straight flank; undercut when h_j > r sin²α.
    """
    z, m, alpha, x = (jnp.asarray(v, dtype=float) for v in (z, m, alpha, x))
    r = 0.5 * m * z
    r_b = r * jnp.cos(alpha)
    r_a = r + (ha + x) * m
    r_f = r - (hf - x) * m
    psi_p = (0.5 * jnp.pi + 2.0 * x * jnp.tan(alpha)) / z
    theta_b = psi_p + inv(alpha)
    rho = rho_f * m
    xc0 = r_f + rho
    yc0 = 0.25 * jnp.pi * m + (hf * m - rho) * jnp.tan(alpha) + rho / jnp.cos(alpha)
    theta_f = yc0 / r
    h_j = (hf - x) * m - rho * (1.0 - jnp.sin(alpha))
    r_form = jnp.sqrt(r_b ** 2 + (r * jnp.sin(alpha) - h_j / jnp.sin(alpha)) ** 2)
    # the rounding touches the straight flank when (C − I) ∥ the flank normal
    t_junction = (xc0 - r) / jnp.tan(alpha)
    return ToothGeometry(z=z, m=m, alpha=alpha, x=x, r=r, r_b=r_b, r_a=r_a, r_f=r_f,
                         r_form=r_form, theta_b=theta_b, theta_f=theta_f,
                         s_f=2.0 * r_f * theta_f, rho=rho, xc0=xc0, yc0=yc0,
                         t_junction=t_junction, undercut=h_j > r * jnp.sin(alpha) ** 2)


def involute_half_thickness(r, z, m, alpha, x=0.0):
    """Half-angle ψ(r) (rad) and half-thickness y(r) = r sin ψ (mm) of the involute tooth.

        ψ(r) = ψ_p + inv α − inv α_r,   cos α_r = r_b / r      ([ISO21771]).
    """
    g = tooth_geometry(z, m, alpha, x)
    psi = g.theta_b - inv(jnp.arccos(g.r_b / r))
    return psi, r * jnp.sin(psi)


def involute_point(g: ToothGeometry, eps):
    """Point of the involute flank at roll angle ``eps`` = tan α_r, in the tooth frame.

    r = r_b sqrt(1 + ε²), ψ = θ_b − (ε − atan ε); returns (x, y) = r (cos ψ, sin ψ) (mm).
    """
    rr = g.r_b * jnp.sqrt(1.0 + eps ** 2)
    psi = g.theta_b - (eps - jnp.arctan(eps))
    return rr * jnp.cos(psi), rr * jnp.sin(psi)


def fillet_point(g: ToothGeometry, t):
    """Point of the trochoidal fillet, in the tooth frame (mm).

    Generating motion: the gear turns by φ while the rack moves r φ along its pitch
    line x = r; with t = y_c0 − r φ the rounding centre sits at C = (x_c0, t) in the
    fixed frame and the pitch point at I = (r, 0).  The generated point lies on the
    common normal through I ([Litvin2004] ch. 10):

        P = C + ρ (C − I)/|C − I|,    P_tooth = R(φ) P     (φ = (y_c0 − t)/r),

    t runs from ``g.t_junction`` (< 0, meets the involute) to 0 (the root circle, at
    half-angle θ_f).  The tooth's upper flank (y > 0) is returned.
    """
    cx = g.xc0 - g.r
    d = jnp.sqrt(cx ** 2 + t ** 2)
    px = g.xc0 + g.rho * cx / d
    py = t + g.rho * t / d
    phi = (g.yc0 - t) / g.r
    # the gear has turned by −φ (clockwise) while the rack moved −r φ: back to the
    # tooth frame by R(+φ)
    c, s = jnp.cos(phi), jnp.sin(phi)
    return c * px - s * py, s * px + c * py


def _fillet_base(g: ToothGeometry):
    """Fillet parameter t0 where the fillet's centre-line coordinate equals r_f.

    Bisection (monotone on [t_junction, 0]), then one Newton step whose iterate is
    held constant for differentiation, which gives the implicit derivative
    dt0 = −(∂X/∂θ dθ)/(∂X/∂t) at the root.
    """
    def xf(t):
        return fillet_point(g, t)[0] - g.r_f

    lo0, hi0 = g.t_junction, jnp.zeros_like(g.t_junction)

    def body(_, lohi):
        lo, hi = lohi
        mid = 0.5 * (lo + hi)
        pos = xf(mid) > 0.0          # X decreases toward t = 0
        return jnp.where(pos, mid, lo), jnp.where(pos, hi, mid)

    lo, hi = jax.lax.fori_loop(0, 60, body, (jax.lax.stop_gradient(lo0),
                                             jax.lax.stop_gradient(hi0)))
    t = jax.lax.stop_gradient(0.5 * (lo + hi))
    # the value and the slope from one forward-mode pass (one evaluation of the fillet)
    x_t, slope = jax.jvp(xf, (t,), (jnp.ones_like(t),))
    return t - x_t / jax.lax.stop_gradient(slope)


# ---------------------------------------------------------------------------------
# 2. the tooth as a cantilever, and the foundation
# ---------------------------------------------------------------------------------

class BeamCompliance(NamedTuple):
    """Cantilever compliances along the load line, per unit face width (mm²/N)."""

    bending: jnp.ndarray
    shear: jnp.ndarray
    axial: jnp.ndarray


def beam_compliance(xs, ys, ws, x_load, y_load, load_angle, E=E_STEEL, nu=NU_STEEL,
                    plane_strain=True) -> BeamCompliance:
    """Energy-method compliance of a cantilever of variable section, unit face width.

    The normal load F at the flank point (x_load, y_load) of a beam along the x axis
    (clamped at the lower end of the quadrature range) makes the angle ``load_angle``
    α_m with the normal to the centre line; by Castigliano ([Weber1949]
    [Cornell1981]), the deflection along the load line per unit load per unit width:

        q_b = ∫ [cos α_m (x_m − x) − sin α_m y_m]² / (E' I(x)) dx,   I = (2y)³/12,
        q_s = ∫ 1.2 cos² α_m / (G A(x)) dx,                          A = 2y,
        q_a = ∫ sin² α_m / (E' A(x)) dx,

    E' = E/(1 − ν²) (plane strain, wide teeth; E' = E when ``plane_strain`` is
    False), G = E/(2(1 + ν)).  ``xs, ys, ws`` are quadrature nodes along the centre
    line (mm), the half-thickness there (mm) and the weights (mm, including any
    dx/du Jacobian).  Returns mm²/N.
    """
    E_ = E / (1.0 - nu ** 2) if plane_strain else E
    G = E / (2.0 * (1.0 + nu))
    ca, sa = jnp.cos(load_angle), jnp.sin(load_angle)
    area = 2.0 * ys
    inertia = area ** 3 / 12.0
    arm = ca * (x_load - xs) - sa * y_load
    q_b = jnp.sum(ws * arm ** 2 / (E_ * inertia))
    q_s = jnp.sum(ws * 1.2 * ca ** 2 / (G * area))
    q_a = jnp.sum(ws * sa ** 2 / (E_ * area))
    return BeamCompliance(q_b, q_s, q_a)


def foundation_compliance(u_f, s_f, theta_f, h_fi, load_angle, E=E_STEEL):
    """Fillet-foundation compliance of [Sainsot2004], per unit face width (mm²/N).

        q_f = cos² α_m / E · [L* (u_f/S_f)² + M* (u_f/S_f) + P* (1 + Q* tan² α_m)],
        X*(h_fi, θ_f) = A_i/θ_f² + B_i h_fi² + C_i h_fi/θ_f + D_i/θ_f + E_i h_fi + F_i,

    u_f (mm): distance along the centre line from the root circle to the point where
    the load line crosses the centre line; S_f (mm): tooth thickness at the root
    circle; θ_f (rad): tooth half-angle at the root circle; h_fi = r_f/r_int (root
    radius over bore/rim inner radius); coefficients :data:`SAINSOT_COEFFICIENTS`.
    E is used as published (no plane-strain factor).  Fitted for h_fi in about
    [1.4, 7] and θ_f in about [0.01, 0.12] rad ([Sainsot2004]).
    """
    c = SAINSOT_COEFFICIENTS
    feats = jnp.stack([1.0 / theta_f ** 2, h_fi ** 2, h_fi / theta_f, 1.0 / theta_f,
                       h_fi, jnp.ones_like(h_fi * theta_f)])
    L, M, P, Q = (jnp.tensordot(c[i], feats, axes=1) for i in range(4))
    ratio = u_f / s_f
    return (jnp.cos(load_angle) ** 2 / E
            * (L * ratio ** 2 + M * ratio + P * (1.0 + Q * jnp.tan(load_angle) ** 2)))


class ToothCompliance(NamedTuple):
    """Compliance of one tooth loaded on its flank (mm²/N, per unit face width).

    ``total = bending + shear + axial + foundation``; ``load_angle`` α_m (rad),
    ``half_thickness`` y_m (mm) at the load point and ``u_f`` (mm) are returned for
    the contact term and for checks.
    """

    bending: jnp.ndarray
    shear: jnp.ndarray
    axial: jnp.ndarray
    foundation: jnp.ndarray
    total: jnp.ndarray
    load_angle: jnp.ndarray
    half_thickness: jnp.ndarray
    u_f: jnp.ndarray


def tooth_compliance(r_load, z, m, alpha, x=0.0, ha=1.0, hf=1.25, rho_f=0.38,
                     E=E_STEEL, nu=NU_STEEL, rim_ratio=2.0,
                     plane_strain=True) -> ToothCompliance:
    """Compliance of one tooth loaded normally at radius ``r_load`` of its involute.

    The tooth (:func:`tooth_geometry`) is a cantilever along its centre line,
    clamped on the root circle (x = r_f), with the half-thickness of the trochoidal
    fillet from x = r_f to the form circle and of the involute above; the load acts
    along the normal of the involute at r_load (the line of action), at

        α_m = tan α_r − θ_b   (cos α_r = r_b/r_load),  ψ_m = θ_b − inv α_r,
        x_m = r_load cos ψ_m,  y_m = r_load sin ψ_m.

    Bending + shear + axial from :func:`beam_compliance` (Gauss–Legendre, 32 nodes on
    the fillet and 32 on the involute) and the foundation of :func:`foundation_compliance`
    with u_f = x_m − y_m tan α_m − r_f, S_f = 2 r_f θ_f and h_fi = ``rim_ratio`` =
    r_f/r_int (default 2: a solid disc or a thick rim).  Deflection along the line of
    action per unit normal load per unit face width, mm²/N.  ``r_load`` must lie on
    the involute (r_form ≤ r_load ≤ r_a); outside, the numbers are extrapolations.
    """
    g = tooth_geometry(z, m, alpha, x, ha, hf, rho_f)
    r_load = jnp.asarray(r_load, dtype=float)
    eps_m = jnp.sqrt((r_load / g.r_b) ** 2 - 1.0)
    alpha_m = eps_m - g.theta_b
    x_m, y_m = involute_point(g, eps_m)

    # fillet part: t from t0 (x = r_f) to the junction (x increases as t decreases)
    t0 = _fillet_base(g)
    tn, tw = _gauss(g.t_junction, t0)
    # points and their x-derivatives from one forward-mode pass each
    (fx, fy), (dfx, _) = jax.jvp(lambda tt: fillet_point(g, tt), (tn,), (jnp.ones_like(tn),))
    wf = -tw * dfx                        # integrate from x = r_f upward
    # involute part: roll angle from the form circle to the load point
    eps_f = jnp.sqrt((g.r_form / g.r_b) ** 2 - 1.0)
    en, ew = _gauss(eps_f, eps_m)
    (ix, iy), (dix, _) = jax.jvp(lambda ee: involute_point(g, ee), (en,),
                                 (jnp.ones_like(en),))
    wi = ew * dix

    xs = jnp.concatenate([fx, ix])
    ys = jnp.concatenate([fy, iy])
    ws = jnp.concatenate([wf, wi])
    beam = beam_compliance(xs, ys, ws, x_m, y_m, alpha_m, E, nu, plane_strain)
    u_f = x_m - y_m * jnp.tan(alpha_m) - g.r_f
    q_f = foundation_compliance(u_f, g.s_f, g.theta_f, jnp.asarray(rim_ratio, float),
                                alpha_m, E)
    total = beam.bending + beam.shear + beam.axial + q_f
    return ToothCompliance(beam.bending, beam.shear, beam.axial, q_f, total, alpha_m,
                           y_m, u_f)


# ---------------------------------------------------------------------------------
# 3. contact
# ---------------------------------------------------------------------------------

def contact_compliance(load_per_width, rho_red, h1, h2, E=E_STEEL, nu=NU_STEEL):
    """Contact compliance of a steel/steel line contact, per unit face width (mm²/N).

    Weber's approach deflection of two elastic strips of depths h1, h2 (distance from
    the contact point to each tooth's centre line along the load line, mm) under a
    Hertzian pressure of half-width b_H ([Weber1949], in the form of [Cornell1981]):

        δ_c = 2 w (1 − ν²)/(π E) · [ln(2 h1/b_H) + ln(2 h2/b_H) − ν/(1 − ν)],
        b_H = sqrt(8 w ρ_red (1 − ν²)/(π E))       ([Johnson1985] §4.2, two equal materials),

    w = ``load_per_width`` (N/mm), ρ_red = ρ1 ρ2/(ρ1 + ρ2) (mm).  Returns q_c = δ_c/w,
    which depends on w only through the logarithm (mildly nonlinear: the secant
    compliance; the tangent one is d(δ_c)/dw = q_c − 2(1−ν²)/(πE)).
    """
    k = 2.0 * (1.0 - nu ** 2) / (jnp.pi * E)
    b_h = jnp.sqrt(8.0 * load_per_width * rho_red * (1.0 - nu ** 2) / (jnp.pi * E))
    return k * (jnp.log(2.0 * h1 / b_h) + jnp.log(2.0 * h2 / b_h) - nu / (1.0 - nu))
