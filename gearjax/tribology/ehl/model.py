"""Physical case, Hertzian scaling and the discrete EHL equations (residual).

Dimensionless variables (Venner & Lubrecht, *Multilevel Methods in Lubrication*,
2000, ch. 7), with the Hertz semi-axes a (transverse, radius Ry) and b (rolling
axis, radius Rx) and the maximum Hertz pressure p_h of :mod:`gearjax.contact`:

    X = x/b,  Y = y/a,  P = p/p_h,  H = h Rx/b²,  k = a/b.

Steady isothermal compressible Reynolds equation with the mean surface velocity
``u_e (cos θ, sin θ)`` at the angle θ to the X axis:

    ∂X(ε ∂X P) + k⁻² ∂Y(ε ∂Y P) - cos θ ∂X(ρ̄ H) - k⁻¹ sin θ ∂Y(ρ̄ H) = 0,
    ε = ρ̄ H³ / (η̄ λ),   λ = 12 η0 u_e Rx² / (b³ p_h),

film  ``H = H0 + X²/2 + (Rx a²)/(Ry b²) Y²/2 + (2 p_h Rx)/(π E' b) Σ K_ij P_j``
(:mod:`gearjax.tribology.ehl.grid`), load balance ``∫∫ P dX dY = 2π/3``,
Roelands viscosity ``η̄ = exp{(ln η0 + 9.67)[(1 + p/p_R)^z - 1]}`` with
``z = α p_R/(ln η0 + 9.67)`` and Dowson–Higginson density
``ρ̄ = 1 + 0.6e-3 p/(1 + 1.7e-3 p)`` (p in MPa), as in
:mod:`gearjax.tribology.lubricant`.

Discretisation: finite volumes, central Poiseuille fluxes with face-averaged ε,
upwind Couette fluxes along the entrainment vector: first order (default) or, with
``EHLGrid.upwind`` = β > 0, with the second-order upwind correction (β = 1: the
"second-order upstream" scheme of Venner & Lubrecht, ch. 7).  Cavitation
(Reynolds condition) as the complementarity problem P ≥ 0, -L(P) ≥ 0,
P·L(P) = 0 (L the Reynolds operator), written with the Fischer–Burmeister
function ``φ(P, -L) = P - L - sqrt(P² + L²) = 0``.

Mixed lubrication (statistical, optional): the Greenwood–Tripp asperity pressure
``p_a = K_GT E' F_5/2(h/σ)`` (:mod:`gearjax.tribology.asperity`) acts at every
node on top of the fluid pressure; the surfaces deform under ``p + p_a`` and
the load balance is ``∫∫ (P + P_a) dX dY = 2π/3``.  h is the separation of the
mean planes (the smooth-surface Reynolds equation without flow factors).
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.contact import hertz_exact
from gearjax.errors import check_positive, check_range
from gearjax.fields import float64_array
from gearjax.tribology.asperity import gt_coefficient, log_F_n
from gearjax.tribology.ehl.grid import EHLGrid, deformation, influence_kernel
from gearjax.tribology.lubricant import P_ROELANDS_MPA, PA_S_TO_MPA_S

__all__ = ["EHLCase", "make_case", "Scales", "scales", "Fields", "fields", "residual",
           "LN_ETA_INF", "residual_core", "kernel_hat", "van_albada"]

LN_ETA_INF = 9.67


@dataclasses.dataclass(frozen=True)
class EHLCase:
    """Operating point of one contact (pytree; every field differentiable).

    F : load N.  u_e : entrainment speed |u1 + u2|/2, mm/s.  u_s : sliding speed
    along the entrainment direction, mm/s.  Rx, Ry : radii along X and Y, mm.
    eta0 : Pa·s.  alpha : pressure–viscosity coefficient at η0, 1/MPa (Roelands z
    is derived from it, so α is held fixed when η0 varies).  E_prime : MPa.
    tau0 : Eyring stress MPa.  sigma : composite roughness mm (0: smooth),
    density : asperity density 1/mm², beta : asperity radius mm, f_c : boundary
    friction coefficient, v_slip : its regularisation speed mm/s.
    """

    F: jax.Array
    u_e: jax.Array
    u_s: jax.Array
    Rx: jax.Array
    Ry: jax.Array
    eta0: jax.Array
    alpha: jax.Array
    E_prime: jax.Array
    tau0: jax.Array
    sigma: jax.Array
    density: jax.Array
    beta: jax.Array
    f_c: jax.Array
    v_slip: jax.Array


jax.tree_util.register_dataclass(EHLCase, data_fields=[f.name for f in dataclasses.fields(EHLCase)],
                                 meta_fields=[])


def make_case(F, u_e, u_s, Rx, Ry, eta0, alpha_per_GPa, E_prime=226373.6, tau0_MPa=5.0,
              sigma_um=0.0, density_per_mm2=1.0e4, beta_um=10.0, f_c=0.1,
              v_slip_mm_s=1.0) -> EHLCase:
    """Validated :class:`EHLCase` (F N, speeds mm/s, radii mm, η0 Pa·s, α 1/GPa, E' MPa,
    τ0 MPa, σ and β µm, density 1/mm²).  ValueError names the parameter and range."""
    check_positive("F", F, "N")
    check_positive("u_e", u_e, "mm/s")
    check_range("u_s", u_s, 0.0, None, unit="mm/s")
    check_positive("Rx", Rx, "mm")
    check_positive("Ry", Ry, "mm")
    check_range("Ry/Rx", float(Ry) / float(Rx), 0.05, 50.0)
    check_range("eta0", eta0, float(np.exp(-LN_ETA_INF)), None, lo_open=True, unit="Pa·s")
    check_range("alpha", alpha_per_GPa, 0.0, 60.0, lo_open=True, unit="1/GPa")
    check_positive("E_prime", E_prime, "MPa")
    check_positive("tau0", tau0_MPa, "MPa")
    check_range("sigma", sigma_um, 0.0, None, unit="um")
    check_positive("asperity density", density_per_mm2, "1/mm^2")
    check_positive("asperity radius", beta_um, "um")
    check_range("f_c", f_c, 0.0, 1.0)
    check_positive("v_slip", v_slip_mm_s, "mm/s")
    vals = (F, u_e, u_s, Rx, Ry, eta0, float(alpha_per_GPa) * 1e-3, E_prime, tau0_MPa,
            float(sigma_um) * 1e-3, density_per_mm2, float(beta_um) * 1e-3, f_c, v_slip_mm_s)
    case = EHLCase(*(float64_array(float(v)) for v in vals))
    p_h = float(_scales_jit(case).p_h)
    check_range("p_max (Hertz)", p_h, 50.0, 3500.0, unit="MPa")
    return case


class Scales(NamedTuple):
    """Hertzian scales of a case: a, b mm; k = a/b; p_h MPa; lam (Reynolds λ);
    c_w (deformation factor 2 p_h Rx/(π E' b)); g_y ((Rx a²)/(Ry b²)); z (Roelands);
    h_unit = b²/Rx mm; ln_eta (ln η0 + 9.67)."""

    a: jax.Array
    b: jax.Array
    k: jax.Array
    p_h: jax.Array
    lam: jax.Array
    c_w: jax.Array
    g_y: jax.Array
    z: jax.Array
    h_unit: jax.Array
    ln_eta: jax.Array


def scales(case: EHLCase) -> Scales:
    """Hertz solution and dimensionless groups of ``case``."""
    hz = hertz_exact(case.F, case.Rx, case.Ry, case.E_prime)
    a, b, p_h = hz.a, hz.b, hz.p_max
    lam = 12.0 * case.eta0 * PA_S_TO_MPA_S * case.u_e * case.Rx ** 2 / (b ** 3 * p_h)
    c_w = 2.0 * p_h * case.Rx / (jnp.pi * case.E_prime * b)
    g_y = case.Rx * a * a / (case.Ry * b * b)
    ln_eta = jnp.log(case.eta0) + LN_ETA_INF
    z = case.alpha * P_ROELANDS_MPA / ln_eta
    return Scales(a, b, a / b, p_h, lam, c_w, g_y, z, b * b / case.Rx, ln_eta)


_scales_jit = jax.jit(scales)


class Fields(NamedTuple):
    """Nodal fields of a state (arrays (ny, nx)); H dimensionless, P_a = p_a/p_h."""

    H: jax.Array
    P_a: jax.Array
    eta: jax.Array
    rho: jax.Array
    eps: jax.Array


H_FLOOR = 1e-9


def fluid_props(P, sc: Scales):
    """Roelands η̄ = η/η0 and Dowson–Higginson ρ̄ = ρ/ρ0 at P ≥ 0."""
    p = jnp.maximum(P, 0.0) * sc.p_h
    ln_r = sc.ln_eta * ((1.0 + p / P_ROELANDS_MPA) ** sc.z - 1.0)
    eta = jnp.exp(jnp.minimum(ln_r, 150.0))
    rho = 1.0 + 0.6e-3 * p / (1.0 + 1.7e-3 * p)
    return eta, rho


def asperity_P(H, case: EHLCase, sc: Scales, mixed: bool):
    """Greenwood–Tripp asperity pressure p_a(h/σ)/p_h on the grid (0 if not mixed)."""
    if not mixed:
        return jnp.zeros_like(H)
    lam_s = jnp.maximum(H * sc.h_unit / case.sigma, -2.0)
    K = gt_coefficient(case.sigma, case.density, case.beta)
    return K * case.E_prime / sc.p_h * jnp.exp(log_F_n(lam_s, 2.5))


def fields(P, H0, P_a, case: EHLCase, sc: Scales, grid: EHLGrid, khat) -> Fields:
    """Film, properties and ε for the fluid pressure P and asperity pressure P_a."""
    X, Y = (jnp.asarray(v) for v in grid.nodes())
    H = H0 + 0.5 * X * X + 0.5 * sc.g_y * Y * Y + sc.c_w * deformation(P + P_a, khat, grid)
    eta, rho = fluid_props(P, sc)
    Hf = jnp.maximum(H, H_FLOOR)
    eps = rho * Hf ** 3 / (eta * sc.lam)
    return Fields(H, P_a, eta, rho, eps)


def _pad(A, mode):
    if mode == "zero":
        return jnp.pad(A, 1)
    return jnp.pad(A, 1, mode="edge")


VA_DELTA = 1e-12


def van_albada(a, b, delta=VA_DELTA):
    """Van Albada's limited slope ``[a(b² + δ) + b(a² + δ)]/(a² + b² + 2δ)`` of the
    backward and forward differences a, b ([VanAlbada1982]: van Albada, van Leer &
    Roberts, Astron. Astrophys. 108 (1982) 76–84).  ≈ (a + b)/2 where a ≈ b (second
    order), → 0 at an
    extremum (ab < 0), and — unlike minmod or van Leer's limiter — differentiable
    everywhere (δ > 0), so the Newton Jacobian and the implicit gradients exist."""
    return (a * (b * b + delta) + b * (a * a + delta)) / (a * a + b * b + 2.0 * delta)


def _couette_faces(q, c, s, beta, limiter="none"):
    """Upwind Couette face fluxes (east, west, north, south) of ``q = ρ̄H`` (ny, nx).

    Face flux along +X at the face i+1/2 (flow c > 0): ``q_i + (β/2)(q_i - q_{i-1})``,
    i.e. first-order upwind (β = 0) plus the second-order upwind correction (β = 1:
    ``(f_e - f_w) = (3q_i - 4q_{i-1} + q_{i-2})/2``, the "second-order upstream"
    scheme of Venner & Lubrecht 2000, ch. 7); mirrored for c < 0 and along Y.
    With ``limiter="van_albada"`` the correction slope ``q_i - q_{i-1}`` is replaced
    by the limited slope :func:`van_albada` of (q_i - q_{i-1}, q_{i+1} - q_i) (a
    MUSCL reconstruction of the upwind cell; second order where q is smooth, no
    overshoot at a sharp extremum such as the exit constriction).
    ``q`` is extended by constant values beyond the edges.
    """
    q2 = jnp.pad(q, 2, mode="edge")
    ny, nx = q.shape
    h = 0.5 * beta
    cp, cm = max(c, 0.0), min(c, 0.0)
    sp, sm = max(s, 0.0), min(s, 0.0)
    R = slice(2, 2 + ny)
    C = slice(2, 2 + nx)
    col = lambda d: q2[R, 2 + d:2 + d + nx]
    row = lambda d: q2[2 + d:2 + d + ny, C]

    def face(get, d):            # flux through the face between nodes d and d+1 (offsets)
        if limiter == "van_albada":
            pos = get(d) + h * van_albada(get(d) - get(d - 1), get(d + 1) - get(d))
            neg = get(d + 1) + h * van_albada(get(d + 1) - get(d + 2), get(d) - get(d + 1))
            return pos, neg
        pos = get(d) + h * (get(d) - get(d - 1))
        neg = get(d + 1) + h * (get(d + 1) - get(d + 2))
        return pos, neg

    pe, ne = face(col, 0)
    pw, nw = face(col, -1)
    pn, nn = face(row, 0)
    ps, ns = face(row, -1)
    return (cp * pe + cm * ne, cp * pw + cm * nw, sp * pn + sm * nn, sp * ps + sm * ns)


def reynolds_operator(P, fl: Fields, sc: Scales, grid: EHLGrid, angle_deg: float):
    """L(P) per unit area (dimensionless), shape (ny, nx)."""
    dx, dy, k = grid.dx, grid.dy, sc.k
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    Pp = _pad(P, "zero")
    ep = _pad(fl.eps, "edge")
    Pc, ec = Pp[1:-1, 1:-1], ep[1:-1, 1:-1]
    e_e = 0.5 * (ec + ep[1:-1, 2:])
    e_w = 0.5 * (ec + ep[1:-1, :-2])
    e_n = 0.5 * (ec + ep[2:, 1:-1])
    e_s = 0.5 * (ec + ep[:-2, 1:-1])
    Lx = (e_e * (Pp[1:-1, 2:] - Pc) - e_w * (Pc - Pp[1:-1, :-2])) / dx ** 2
    Ly = (e_n * (Pp[2:, 1:-1] - Pc) - e_s * (Pc - Pp[:-2, 1:-1])) / (dy * k) ** 2
    fx_e, fx_w, fy_n, fy_s = _couette_faces(fl.rho * jnp.maximum(fl.H, H_FLOOR), c, s,
                                            grid.upwind, grid.limiter)
    return Lx + Ly - (fx_e - fx_w) / dx - (fy_n - fy_s) / (dy * k)


def row_scale(fl: Fields, sc: Scales, grid: EHLGrid):
    """Positive row weights 1/(1 + ε (2/ΔX² + 2/(kΔY)²)): balance the Poiseuille-dominated
    inlet against the Couette-dominated contact (does not change the solution)."""
    return 1.0 / (1.0 + fl.eps * (2.0 / grid.dx ** 2 + 2.0 / (grid.dy * sc.k) ** 2))


def unpack(x, grid: EHLGrid, mixed: bool):
    n = grid.nx * grid.ny
    P = x[:n].reshape(grid.ny, grid.nx)
    P_a = x[n:2 * n].reshape(grid.ny, grid.nx) if mixed else jnp.zeros_like(P)
    return P, P_a, x[-1]


def residual_core(x, case: EHLCase, sc: Scales, khat, grid: EHLGrid, angle_deg: float,
                  mixed: bool):
    """:func:`residual` with the Hertz scales ``sc`` and the kernel transform ``khat``
    precomputed (they do not depend on x; hoisting them out of the Newton loop keeps the
    compiled program small)."""
    P, P_a, H0 = unpack(x, grid, mixed)
    fl = fields(P, H0, P_a, case, sc, grid, khat)
    L = row_scale(fl, sc, grid) * reynolds_operator(P, fl, sc, grid, angle_deg)
    fb = P - L - jnp.sqrt(P * P + L * L + 1e-300)
    load = grid.dx * grid.dy * jnp.sum(P + P_a) / (2.0 * jnp.pi / 3.0) - 1.0
    parts = [fb.ravel()]
    if mixed:
        parts.append((P_a - asperity_P(fl.H, case, sc, True)).ravel())
    parts.append(jnp.reshape(load, (1,)))
    return jnp.concatenate(parts)


def kernel_hat(grid: EHLGrid, sc: Scales):
    """rfft2 of the zero-padded DC-FFT influence kernel for the ellipticity ``sc.k``."""
    return jnp.fft.rfft2(influence_kernel(grid, sc.k))


def residual(x, case: EHLCase, grid: EHLGrid, angle_deg: float, mixed: bool):
    """Residual vector of the discrete EHL problem for the unknown vector x.

    x = [P (ny·nx), P_a (ny·nx, only if mixed), H0].  Equations: Fischer–Burmeister
    complementarity of the (row-scaled) Reynolds equation at each node; (mixed) P_a - p_a(H)/p_h
    = 0; load balance ``(ΔXΔY Σ(P + P_a))/(2π/3) - 1 = 0``.
    """
    sc = scales(case)
    return residual_core(x, case, sc, kernel_hat(grid, sc), grid, angle_deg, mixed)
