"""ISO 23509 blank geometry of face-milled spiral-bevel and hypoid gears.

Implements the pitch-cone parameters of ISO 23509:2016 clause 6 for

* **Method 0** (spiral bevel, hypoid offset ``a = 0``), formulae (1)-(7), and
* **Method 1** (hypoid, the Gleason method), formulae (8)-(41), face milling
  (the lengthwise tooth mean radius of curvature is the cutter radius,
  ``rho_mbeta = r_c0``, formula (40)),

and the gear dimensions of clause 7 that a blank drawing needs, formulae
(110)-(200) and (216)-(225): offset angles, limit pressure angle and generated
pressure angles, cone distances, mean/inner/outer depths, face and root angles
(with the wheel addendum/dedendum angles from the depthwise taper of annex C.5),
pinion face width (Method 0 and Method 1 rules), inner/outer spiral angles for
face milling, pitch and outside diameters and crown-to-crossing-point distances.
Tooth thickness (7.8) and the undercut check (clause 8) are not implemented.

Every function is pure JAX (float64, mm and rad) and differentiable; the single
iteration of Method 1 (find the wheel offset angle ``eta`` in the axial plane so
that the limit radius of curvature equals the cutter radius, ISO 23509
6.2.2 "change eta until rho_mbeta / rho_lim = 1") is solved by the
implicit-differentiated :func:`gearjax.newton.newton_solve` instead of the
standard's trial-and-error with a 1 % stopping rule, so the result is converged to
machine precision and ``jax.jacfwd`` gives exact sensitivities.

Conventions: angles in rad; ``Sigma`` is the shaft angle, ``u = z2/z1`` the gear
ratio (a float here so it can be differentiated as a continuous quantity), ``a``
the hypoid offset (>= 0; the blank geometry does not depend on the sign/hand).
Member 1 is the pinion, member 2 the wheel (gear).

Reference: ISO 23509:2016, *Bevel and hypoid gear geometry*, clauses 6 and 7 and
annex C.5; Gleason Works, *Method for designing hypoid gear blanks* (1971).
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

from gearjax.newton import newton_solve

__all__ = ["physical_branch", "method0_pitch_cones", "method1_pitch_cones", "limit_pressure_angle",
           "limit_curvature_radius", "gear_dimensions", "TAPERS"]

TAPERS = ("standard", "uniform", "constant-slot", "modified-slot", "manual")


def limit_pressure_angle(delta1, delta2, Rm1, Rm2, beta1, beta2, zeta_mp):
    """Limit pressure angle ``alpha_lim`` (rad), ISO 23509 formula (32) = (117).

        alpha_lim = -arctan[ tan d1 tan d2 / cos zeta_mp
                             (Rm1 sin b1 - Rm2 sin b2) / (Rm1 tan d1 + Rm2 tan d2) ]

    ``delta`` pitch angles, ``Rm`` mean cone distances (mm), ``beta`` mean spiral
    angles, ``zeta_mp`` the offset angle in the pitch plane (= beta1 - beta2).
    Wildhaber's limit normal: the tooth normal at the pitch point for which the
    first-order meshing limit passes through it.  Zero for spiral bevel gears.
    """
    t1, t2 = jnp.tan(delta1), jnp.tan(delta2)
    return -jnp.arctan(t1 * t2 / jnp.cos(zeta_mp)
                       * (Rm1 * jnp.sin(beta1) - Rm2 * jnp.sin(beta2))
                       / (Rm1 * t1 + Rm2 * t2))


def limit_curvature_radius(delta1, delta2, Rm1, Rm2, beta1, beta2, alpha_lim):
    """Limit radius of lengthwise tooth curvature ``rho_lim`` (mm), ISO 23509 (33).

        rho_lim = (tan b1 - tan b2) / cos a_lim
                  / [ -tan a_lim (tan b1/(Rm1 tan d1) + tan b2/(Rm2 tan d2))
                      + 1/(Rm1 cos b1) - 1/(Rm2 cos b2) ]

    A face-milled hypoid pair whose cutter radius equals ``rho_lim`` has the limit
    normal of both flanks at the pitch point (Gleason's design condition).  The
    expression is 0/0 for ``a = 0`` (spiral bevel gears do not constrain the
    cutter radius).
    """
    num = (jnp.tan(beta1) - jnp.tan(beta2)) / jnp.cos(alpha_lim)
    den = (-jnp.tan(alpha_lim) * (jnp.tan(beta1) / (Rm1 * jnp.tan(delta1))
                                  + jnp.tan(beta2) / (Rm2 * jnp.tan(delta2)))
           + 1.0 / (Rm1 * jnp.cos(beta1)) - 1.0 / (Rm2 * jnp.cos(beta2)))
    return num / den


def physical_branch(delta1, delta2, Sigma, Rm1, rho_lim):
    """True where a root is the physical one: ``0 < delta_i < Sigma``, ``Rm1 > 0``,
    ``rho_lim > 0``, ``delta1 + delta2 <= Sigma`` (the pitch cones of a hypoid pair
    are "opened up" by the offset, never closed).  Spurious roots of the pitch-cone
    equations (negative pitch angles) exist; a solve that lands on one is reported
    as not converged."""
    return ((delta1 > 0) & (delta2 > 0) & (delta1 < Sigma) & (delta2 < Sigma) & (Rm1 > 0)
            & (rho_lim > 0) & (delta1 + delta2 <= Sigma + 1e-12))


def method0_pitch_cones(u, Sigma, de2, b2, beta_m):
    """ISO 23509 Method 0 (spiral bevel, a = 0), formulae (1)-(7).

    ``tan delta1 = sin Sigma / (u + cos Sigma)``, ``delta2 = Sigma - delta1``,
    ``Re = de2 / (2 sin delta2)``, ``Rm = Re - b2/2``, ``beta_m1 = beta_m2 = beta_m``,
    ``c_be2 = 1/2``.  Returns a dict of pitch-cone quantities (mm, rad).
    """
    delta1 = jnp.arctan2(jnp.sin(Sigma), u + jnp.cos(Sigma))
    delta2 = Sigma - delta1
    Re = de2 / (2.0 * jnp.sin(delta2))
    Rm = Re - 0.5 * b2
    beta = beta_m + 0.0 * u
    one = jnp.ones_like(Rm)
    return dict(delta1=delta1, delta2=delta2, Rm1=Rm, Rm2=Rm, beta_m1=beta, beta_m2=beta,
                c_be2=0.5 * one, eta=0.0 * one,
                rho_lim=jnp.inf + jax.lax.stop_gradient(0.0 * one),  # 0/0 at a = 0: undefined
                residual=0.0 * one, steps=jnp.asarray(0), converged=jnp.asarray(True))


def _method1_start(u, Sigma, a, de2, b2, beta_d1, rmpt2=None):
    """ISO 23509 formulae (10)-(16): approximate quantities and the start value of eta.

    ``rmpt2`` overrides formula (12) (used by the [Tangent-cones] route to start from a
    Method 1 solution with its own wheel mean radius).
    """
    dS = Sigma - 0.5 * jnp.pi
    delta_int2 = jnp.arctan(u * jnp.cos(dS) / (1.2 * (1.0 - u * jnp.sin(dS))))      # (11)
    if rmpt2 is None:
        rmpt2 = 0.5 * (de2 - b2 * jnp.sin(delta_int2))                               # (12)
    eps_i = jnp.arcsin(a * jnp.sin(delta_int2) / rmpt2)                              # (13)
    K1 = jnp.tan(beta_d1) * jnp.sin(eps_i) + jnp.cos(eps_i)                           # (14)
    rmn1 = rmpt2 * K1 / u                                                             # (15)
    eta0 = jnp.arctan(a / (rmpt2 * (jnp.tan(delta_int2) * jnp.cos(dS) - jnp.sin(dS)) + rmn1))  # (16)
    return dict(dS=dS, delta_int2=delta_int2, rmpt2=rmpt2, K1=K1, rmn1=rmn1, eta0=eta0)


def _method1_eval(eta, u, a, beta_d1, st):
    """ISO 23509 formulae (17)-(33) for a trial wheel offset angle ``eta`` (rad)."""
    dS, rmpt2, K1, rmn1 = st["dS"], st["rmpt2"], st["K1"], st["rmn1"]
    se = jnp.sin(eta)
    eps2 = jnp.arcsin((a - rmn1 * se) / rmpt2)                                        # (17)
    delta_int1 = jnp.arctan(se / (jnp.tan(eps2) * jnp.cos(dS)) + jnp.tan(dS) * jnp.cos(eta))  # (18)
    eps2p = jnp.arcsin(jnp.sin(eps2) * jnp.cos(dS) / jnp.cos(delta_int1))             # (19)
    beta_int1 = jnp.arctan((K1 - jnp.cos(eps2p)) / jnp.sin(eps2p))                     # (20)
    dK = jnp.sin(eps2p) * (jnp.tan(beta_d1) - jnp.tan(beta_int1))                      # (21)
    d_rmpt1 = rmpt2 * dK / u                                                          # (22)
    eps1 = jnp.arcsin(jnp.sin(eps2) - d_rmpt1 / rmpt2 * se)                           # (23)
    delta1 = jnp.arctan(se / (jnp.tan(eps1) * jnp.cos(dS)) + jnp.tan(dS) * jnp.cos(eta))  # (24)
    eps1p = jnp.arcsin(jnp.sin(eps1) * jnp.cos(dS) / jnp.cos(delta1))                 # (25)
    beta1 = jnp.arctan((K1 + dK - jnp.cos(eps1p)) / jnp.sin(eps1p))                    # (26)
    beta2 = beta1 - eps1p                                                             # (27)
    delta2 = jnp.arctan(jnp.sin(eps1) / (jnp.tan(eta) * jnp.cos(dS)) + jnp.cos(eps1) * jnp.tan(dS))  # (28)
    Rm1 = (rmn1 + d_rmpt1) / jnp.sin(delta1)                                          # (29)
    Rm2 = rmpt2 / jnp.sin(delta2)                                                     # (30)
    alim = limit_pressure_angle(delta1, delta2, Rm1, Rm2, beta1, beta2, eps1p)        # (32)
    rho = limit_curvature_radius(delta1, delta2, Rm1, Rm2, beta1, beta2, alim)        # (33)
    return dict(delta1=delta1, delta2=delta2, Rm1=Rm1, Rm2=Rm2, beta_m1=beta1, beta_m2=beta2,
                zeta_mp=eps1p, alpha_lim=alim, rho_lim=rho)


@jax.jit
def method1_pitch_cones(u, Sigma, a, de2, b2, beta_d1, rc0, rmpt2=None):
    """ISO 23509 Method 1 (Gleason hypoid), formulae (8)-(41), face milling.

    Solves ``rho_lim(eta) = r_c0`` (formulae (33), (40)) for the wheel offset angle
    ``eta`` with the implicit-differentiated Newton, starting from formula (16).
    ``beta_d1`` is the desired pinion mean spiral angle; as in the standard the
    resulting ``beta_m1`` (26) differs from it slightly (one linearised correction
    step, formulae (20)-(22)).  ``c_be2 = (de2/(2 sin delta2) - Rm2)/b2`` (41):
    the calculation point is not exactly at mid face because ``rmpt2`` (12) uses the
    approximate wheel pitch angle (11).

    Returns a dict (mm, rad) with ``delta1, delta2, Rm1, Rm2, beta_m1, beta_m2,
    c_be2, eta, rho_lim, zeta_mp, alpha_lim`` and the Newton ``residual``
    (relative, ``rho_lim/r_c0 - 1``), ``steps``, ``converged``.  No exception is
    raised here; callers check ``converged`` on concrete values.
    """
    st = _method1_start(u, Sigma, a, de2, b2, beta_d1, rmpt2)

    def F(eta, th):
        u_, a_, bd_, rc_, st_ = th
        return _method1_eval(eta, u_, a_, bd_, st_)["rho_lim"] / rc_ - 1.0

    res = newton_solve(F, jax.lax.stop_gradient(st["eta0"]), (u, a, beta_d1, rc0, st),
                       tol=1e-12, xtol=1e-14)
    out = _method1_eval(res.x, u, a, beta_d1, st)
    out["c_be2"] = (de2 / (2.0 * jnp.sin(out["delta2"])) - out["Rm2"]) / b2              # (41)
    out.update(eta=res.x, residual=res.residual, steps=res.steps,
               converged=res.converged & physical_branch(out["delta1"], out["delta2"], Sigma,
                                                        out["Rm1"], out["rho_lim"]))
    return out


def _wheel_angles(taper, hfm1, hfm2, ham2, hmw, Rm2, Re2, met2, alpha_n, beta2, rc0,
                  theta_a2, theta_f2):
    """Wheel addendum/dedendum angles from the depthwise taper, ISO 23509 annex C.5.

    standard:      theta_a2 = atan(hfm1/Rm2), theta_f2 = atan(hfm2/Rm2)          (C.3)
    uniform:       0, 0
    constant-slot: sum = pi/2 met2/(Re2 tan a_n cos b2) (1 - Rm2 sin b2 / rc0)   (C.5)
                   theta_a2 = sum ham2/hmw, theta_f2 = sum - theta_a2           (C.8, C.9)
    modified-slot: as constant-slot with sum = min(C.5, 1.3 sum_standard)     (C.6, C.10)
    manual:        the given ``theta_a2``, ``theta_f2``.
    (The annex writes C.5 in degrees with a factor 90; here it is pi/2 in rad.)
    """
    s_std = jnp.arctan(hfm1 / Rm2) + jnp.arctan(hfm2 / Rm2)
    s_c = (0.5 * jnp.pi * met2 / (Re2 * jnp.tan(alpha_n) * jnp.cos(beta2))
           * (1.0 - Rm2 * jnp.sin(beta2) / rc0))
    if taper == "standard":
        ta = jnp.arctan(hfm1 / Rm2)
        return ta, s_std - ta
    if taper == "uniform":
        return 0.0 * Rm2, 0.0 * Rm2
    if taper == "constant-slot":
        ta = s_c * ham2 / hmw
        return ta, s_c - ta
    if taper == "modified-slot":
        s_m = jnp.minimum(s_c, 1.3 * s_std)
        ta = s_m * ham2 / hmw
        return ta, s_m - ta
    if taper == "manual":
        return theta_a2 + 0.0 * Rm2, theta_f2 + 0.0 * Rm2
    raise ValueError(f"taper = {taper!r} is not one of {TAPERS}")


def gear_dimensions(pc, *, z1, u, Sigma, a, b2, rc0, alpha_dD, alpha_dC, f_alim, khap, khfp,
                    xhm1, taper="standard", theta_a2=0.0, theta_f2=0.0, pinion_rule="method1"):
    """Gear dimensions of ISO 23509 clause 7 from the pitch-cone parameters ``pc``.

    ``pc`` needs ``delta1, delta2, Rm1, Rm2, beta_m1, beta_m2, c_be2`` (mm, rad).
    ``z1`` pinion tooth number, ``u`` the ratio; ``z2 = u z1`` (a float, so that the
    ratio can be varied continuously with ``z1`` held).
    Tooth data are ISO data type I: ``khap`` basic crown gear addendum factor,
    ``khfp`` dedendum factor, ``xhm1`` profile shift coefficient (table 3/4).
    ``pinion_rule`` is ``"method0"`` (b1 = b2, formulae (156)-(158)) or
    ``"method1"`` (formulae (159)-(166)).  Face milling throughout.

    Formulae: basic data (110)-(131), depths (132)-(139), face/root angles
    (140)-(153), pinion face width (154)-(166), inner/outer spiral angles for face
    milling (174)-(175), (183)-(188), (193)-(194), depths at the ends (195)-(200),
    remaining dimensions (216)-(225).  Returns a dict (mm, rad).
    """
    d1, d2 = pc["delta1"], pc["delta2"]
    Rm1, Rm2 = pc["Rm1"], pc["Rm2"]
    b1m, b2m = pc["beta_m1"], pc["beta_m2"]
    cbe2 = pc["c_be2"]
    sin, cos, tan = jnp.sin, jnp.cos, jnp.tan
    z2 = u * z1
    r = {}
    # 7.2 basic data
    dm1 = 2.0 * Rm1 * sin(d1)                                                         # (110)
    dm2 = 2.0 * Rm2 * sin(d2)                                                         # (111)
    dS = Sigma - 0.5 * jnp.pi                                                         # (112)
    zeta_m = jnp.arcsin(2.0 * a / (dm2 + dm1 * cos(d2) / cos(d1)))                    # (113)
    zeta_mp = jnp.arcsin(sin(zeta_m) * sin(Sigma) / cos(d1))                          # (114)
    ap = Rm2 * sin(zeta_mp)                                                           # (115)
    m_mn = 2.0 * Rm2 * sin(d2) * cos(b2m) / z2                                    # (116)
    alim = limit_pressure_angle(d1, d2, Rm1, Rm2, b1m, b2m, zeta_mp)                   # (117)
    anD = alpha_dD + f_alim * alim                                                    # (118)
    anC = alpha_dC - f_alim * alim                                                    # (119)
    aeD = anD - alim                                                                  # (120)
    aeC = anC + alim                                                                  # (121)
    Re2 = Rm2 + cbe2 * b2                                                             # (122)
    Ri2 = Re2 - b2                                                                    # (123)
    de2 = 2.0 * Re2 * sin(d2)                                                         # (124)
    di2 = 2.0 * Ri2 * sin(d2)                                                         # (125)
    met2 = de2 / z2                                                                   # (126)
    be2 = Re2 - Rm2                                                                   # (127)
    bi2 = Rm2 - Ri2                                                                   # (128)
    tzm2 = (dm1 * sin(d2) / (2.0 * cos(d1))
            - 0.5 * cos(zeta_m) * tan(dS) * (dm2 + dm1 * cos(d2) / cos(d1)))           # (129)
    tzm1 = 0.5 * dm2 * cos(zeta_m) * cos(dS) - tzm2 * sin(dS)                         # (130)
    tz1 = Rm1 * cos(d1) - tzm1                                                        # (131)
    tz2 = Rm2 * cos(d2) - tzm2                                                        # (131)
    # 7.3 depths at the calculation point
    hmw = 2.0 * m_mn * khap                                                           # (132)
    ham2 = m_mn * (khap - xhm1)                                                       # (133)
    hfm2 = m_mn * (khfp + xhm1)                                                       # (134)
    ham1 = m_mn * (khap + xhm1)                                                       # (135)
    hfm1 = m_mn * (khfp - xhm1)                                                       # (136)
    c = m_mn * (khfp - khap)                                                          # (137)
    hm = m_mn * (khap + khfp)                                                         # (138)
    alpha_n = 0.5 * (anD + anC)                                                       # (201)
    ta2, tf2 = _wheel_angles(taper, hfm1, hfm2, ham2, hmw, Rm2, Re2, met2, alpha_n, b2m,
                             rc0, theta_a2, theta_f2)
    # 7.4 face and root angles
    da2 = d2 + ta2                                                                    # (140)
    df2 = d2 - tf2                                                                    # (141)
    phiR = jnp.arctan(a * tan(dS) * cos(df2) / (Rm2 * cos(tf2) - tz2 * cos(df2)))     # (142)
    phio = jnp.arctan(a * tan(dS) * cos(da2) / (Rm2 * cos(ta2) - tz2 * cos(da2)))     # (143)
    zetaR = jnp.arcsin(a * cos(phiR) * sin(df2) / (Rm2 * cos(tf2) - tz2 * cos(df2))) - phiR  # (144)
    zetao = jnp.arcsin(a * cos(phio) * sin(da2) / (Rm2 * cos(ta2) - tz2 * cos(da2))) - phio  # (145)
    da1 = jnp.arcsin(sin(dS) * sin(df2) + cos(dS) * cos(df2) * cos(zetaR))            # (146)
    df1 = jnp.arcsin(sin(dS) * sin(da2) + cos(dS) * cos(da2) * cos(zetao))            # (147)
    ta1 = da1 - d1                                                                    # (148)
    tf1 = d1 - df1                                                                    # (149)
    tzF2 = tz2 - (Rm2 * sin(ta2) - ham2 * cos(ta2)) / sin(da2)                        # (150)
    tzR2 = tz2 + (Rm2 * sin(tf2) - hfm2 * cos(tf2)) / sin(df2)                        # (151)
    tzF1 = (a * sin(zetaR) * cos(df2) - tzR2 * sin(df2) - c) / sin(da1)               # (152)
    tzR1 = (a * sin(zetao) * cos(da2) - tzF2 * sin(da2) - c) / sin(df1)               # (153)
    # 7.5 pinion face width
    bp1 = jnp.sqrt(Re2 ** 2 - ap ** 2) - jnp.sqrt(Ri2 ** 2 - ap ** 2)                 # (154)
    if pinion_rule == "method0":
        b1 = b2 + 0.0 * Rm1                                                           # (156)
        be1 = cbe2 * b1                                                               # (157)
        bi1 = b1 - be1                                                                # (158)
    elif pinion_rule == "method1":
        lam = jnp.arctan(sin(zeta_mp) * cos(d2)
                         / (u * cos(d1) + cos(d2) * cos(zeta_mp)))                    # (159)
        breri1 = b2 * cos(lam) / cos(zeta_mp - lam)                                   # (160)
        dbx1 = hmw * sin(zetaR) * (1.0 - 1.0 / u)                                     # (161)
        dgxe = cbe2 * breri1 / cos(ta1) * cos(da1) + dbx1 - (hfm2 - c) * sin(d1)      # (162)
        dgxi = (1.0 - cbe2) * breri1 / cos(ta1) * cos(da1) + dbx1 + (hfm2 - c) * sin(d1)  # (163)
        be1 = (dgxe + ham1 * sin(d1)) / cos(da1) * cos(ta1)                           # (164)
        bi1 = (dgxi - ham1 * sin(d1)) / (cos(d1) - tan(ta1) * sin(d1))                # (165)
        b1 = bi1 + be1                                                                # (166)
    else:
        raise ValueError(f"pinion_rule = {pinion_rule!r} is not 'method0' or 'method1'")
    # 7.6 inner/outer spiral angles (face milling)
    Re21 = jnp.sqrt(Rm2 ** 2 + be1 ** 2 + 2.0 * Rm2 * be1 * cos(zeta_mp))             # (174)
    Ri21 = jnp.sqrt(Rm2 ** 2 + bi1 ** 2 - 2.0 * Rm2 * bi1 * cos(zeta_mp))             # (175)
    k = 2.0 * Rm2 * rc0 * sin(b2m) - Rm2 ** 2
    be21 = jnp.arcsin((k + Re21 ** 2) / (2.0 * Re21 * rc0))                            # (183)
    bi21 = jnp.arcsin((k + Ri21 ** 2) / (2.0 * Ri21 * rc0))                            # (184)
    beta_e1 = be21 + jnp.arcsin(ap / Re21)                                             # (185), (187)
    beta_i1 = bi21 + jnp.arcsin(ap / Ri21)                                             # (186), (188)
    beta_e2 = jnp.arcsin((k + Re2 ** 2) / (2.0 * Re2 * rc0))                           # (193)
    beta_i2 = jnp.arcsin((k + Ri2 ** 2) / (2.0 * Ri2 * rc0))                           # (194)
    # 7.7 depths at the ends of the face width
    hae1 = ham1 + be1 * tan(ta1)                                                      # (195)
    hae2 = ham2 + be2 * tan(ta2)
    hfe1 = hfm1 + be1 * tan(tf1)                                                      # (196)
    hfe2 = hfm2 + be2 * tan(tf2)
    hai1 = ham1 - bi1 * tan(ta1)                                                      # (198)
    hai2 = ham2 - bi2 * tan(ta2)
    hfi1 = hfm1 - bi1 * tan(tf1)                                                      # (199)
    hfi2 = hfm2 - bi2 * tan(tf2)
    # 7.9 remaining dimensions
    Re1 = Rm1 + be1                                                                   # (216)
    Ri1 = Rm1 - bi1                                                                   # (217)
    de1 = 2.0 * Re1 * sin(d1)                                                         # (218)
    di1 = 2.0 * Ri1 * sin(d1)                                                         # (219)
    dae1 = de1 + 2.0 * hae1 * cos(d1)                                                 # (220)
    dae2 = de2 + 2.0 * hae2 * cos(d2)
    dfe1 = de1 - 2.0 * hfe1 * cos(d1)                                                 # (221)
    dfe2 = de2 - 2.0 * hfe2 * cos(d2)
    dai1 = di1 + 2.0 * hai1 * cos(d1)                                                 # (222)
    dai2 = di2 + 2.0 * hai2 * cos(d2)
    txo1 = tzm1 + be1 * cos(d1) - hae1 * sin(d1)                                      # (224)
    txo2 = tzm2 + be2 * cos(d2) - hae2 * sin(d2)
    txi1 = tzm1 - bi1 * cos(d1) - hai1 * sin(d1)                                      # (225)
    txi2 = tzm2 - bi2 * cos(d2) - hai2 * sin(d2)
    r.update(dm1=dm1, dm2=dm2, zeta_m=zeta_m, zeta_mp=zeta_mp, ap=ap, m_mn=m_mn,
             alpha_lim=alim, alpha_nD=anD, alpha_nC=anC, alpha_eD=aeD, alpha_eC=aeC,
             Re2=Re2, Ri2=Ri2, de2=de2, di2=di2, met2=met2, be2=be2, bi2=bi2,
             tzm1=tzm1, tzm2=tzm2, tz1=tz1, tz2=tz2, hmw=hmw, ham1=ham1, ham2=ham2,
             hfm1=hfm1, hfm2=hfm2, c=c, hm=hm, theta_a2=ta2, theta_f2=tf2,
             delta_a2=da2, delta_f2=df2, zeta_R=zetaR, zeta_o=zetao, delta_a1=da1,
             delta_f1=df1, theta_a1=ta1, theta_f1=tf1, tzF1=tzF1, tzR1=tzR1, tzF2=tzF2,
             tzR2=tzR2, bp1=bp1, b1=b1, be1=be1, bi1=bi1, Re21=Re21, Ri21=Ri21,
             beta_e1=beta_e1, beta_i1=beta_i1, beta_e2=beta_e2, beta_i2=beta_i2,
             hae1=hae1, hae2=hae2, hfe1=hfe1, hfe2=hfe2, he1=hae1 + hfe1, he2=hae2 + hfe2,
             hai1=hai1, hai2=hai2, hfi1=hfi1, hfi2=hfi2, hi1=hai1 + hfi1, hi2=hai2 + hfi2,
             Re1=Re1, Ri1=Ri1, de1=de1, di1=di1, dae1=dae1, dae2=dae2, dfe1=dfe1, dfe2=dfe2,
             dai1=dai1, dai2=dai2, txo1=txo1, txo2=txo2, txi1=txi1, txi2=txi2,
             alpha_n=alpha_n)
    return r
