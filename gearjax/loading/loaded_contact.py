"""Loaded tooth contact: the torque shared between the tooth pairs in mesh.

At every mesh position the pinion torque ``T1`` is carried by the tooth pairs
``k`` whose unloaded separations the load closes.  The unloaded TCA gives, per
pair, its transmission error ``te_k`` (rad, gear angle); on the drive side the
pair with the largest TE touches first (the envelope).  Under load the gear falls
back by ``y`` (rad) behind the envelope; the normal approach of pair ``k`` is

    w_k = l2_k (y - g_k),     g_k = s (te_env - te_k) >= 0,      (s = +1 drive, -1 coast)

with ``l2_k`` the lever arm of the normal force about the gear axis (mm).  Each
pair answers with the normal load ``F_k(w_k)`` of its compliance,

    w = q_k F + c_k F^(2/3)      (w > 0),     F = 0     (w <= 0),

``q_k`` (mm/N) the linear compliance of the two teeth (bending, shear, fillet
foundation; for a line contact also the contact, [Weber1949]/[Sainsot2004], see
:mod:`gearjax.loading.tooth_compliance`) divided by the width that carries the load, and
``c_k F^(2/3)`` the Hertz approach of a point contact (``c_k`` = approach at 1 N of
:func:`gearjax.contact.hertz_exact` for the flanks' principal radii; the local
ease-off across the ellipse enters through them).  Equilibrium of the pinion,

    H(y) = sum_k l1_k F_k(w_k(y)) = T1,

with the pinion lever arms ``l1_k`` (mm), closes the system.  ``F(w)`` is the
inverse of a concave increasing function, hence convex and increasing, and so is
``H``: Newton's method started above the root (the deflection of the leading pair
alone carrying the whole torque) converges monotonically, and the complementarity
``F_k >= 0, w_k F_k = 0 where w_k <= 0`` is exact (no smoothing; ``F`` is C^1 at
contact onset for point contact and Lipschitz for line contact).  ``y`` is
differentiated by the implicit function theorem (:func:`gearjax.newton.newton_solve`)
and ``F(w)`` by its own implicit rule, so every load, the loaded TE and everything
downstream carry exact gradients.  The lever arms follow from the contact:
``l1 = |(r x n) . z1|`` (pinion axis = fixed z axis) and ``l2 = l1/|dphi2/dphi1|``
(equal normal velocities of the two flanks at the contact point, [Litvin2004] ch. 9).

Units: mm, N, N mm (torque), rad, MPa.
References (docs/references.md): [Litvin2004]; [Weber1949]; [Sainsot2004];
[ISO6336-1] (mesh stiffness, load sharing); [ISO10300-1]; [Johnson1985] (Hertz).
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

from gearjax.contact import hertz_exact, hertz_line_traced
from gearjax.newton import newton_solve
from gearjax.tca.path import pair_arrays
from gearjax.loading.tooth_compliance import (E_STEEL, NU_STEEL, contact_compliance,
                                              tooth_compliance, tooth_geometry)
from gearjax.loading.pair_stiffness import iso6336_single_stiffness

__all__ = ["LoadedContact", "MeshTeeth", "TeethOf", "pair_compliance", "COMPLIANCE_MODELS",
           "hertz_coefficient", "contact_stress", "force_from_approach", "share_torque", "pair_arrays",
           "lever_arms", "BALANCE_TOL"]

#: relative tolerance of the torque balance sum_k l1_k F_k = T1
BALANCE_TOL = 1e-11
_INNER_STEPS = 40
_OUTER_STEPS = 60


def _force_solve(w, q, c):
    """``F`` with ``q F + c F^(2/3) = w`` for w > 0 by Newton in ``s = F^(1/3)``
    from an upper bound (monotone convergence: the cubic is convex on s >= 0)."""
    s_q = jnp.cbrt(w / q)
    s_c = jnp.sqrt(w / jnp.where(c > 0.0, c, 1.0))
    s = jnp.where(c > 0.0, jnp.minimum(s_q, s_c), s_q)

    def step(_, s):
        p = (q * s + c) * s * s - w
        dp = (3.0 * q * s + 2.0 * c) * s
        return jnp.where(dp > 0.0, s - p / jnp.where(dp > 0.0, dp, 1.0), s)

    s = jax.lax.fori_loop(0, _INNER_STEPS, step, s)
    return s * s * s


@jax.custom_jvp
def force_from_approach(w, q, c):
    """Normal load ``F`` (N) of a pair compressed by ``w`` (mm): the root of
    ``q F + c F^(2/3) = w`` for ``w > 0`` and 0 otherwise (module docstring).

    ``q`` linear compliance (mm/N, > 0), ``c`` Hertz approach coefficient
    (mm/N^(2/3), >= 0; 0 for a line contact).  Differentiable (implicit rule
    ``dF = (dw - F dq - F^(2/3) dc) / (q + 2/3 c F^(-1/3))``); elementwise.
    """
    pos = w > 0.0
    F = _force_solve(jnp.where(pos, w, 1.0), q, c)
    return jnp.where(pos, F, 0.0)


@force_from_approach.defjvp
def _force_jvp(primals, tangents):
    w, q, c = primals
    dw, dq, dc = tangents
    F = force_from_approach(w, q, c)
    pos = F > 0.0
    Fs = jnp.where(pos, F, 1.0)
    F23 = jnp.cbrt(Fs) ** 2
    den = q + (2.0 / 3.0) * c / jnp.cbrt(Fs)
    dF = (dw - Fs * dq - F23 * dc) / den
    return F, jnp.where(pos, dF, 0.0)


class LoadedContact(NamedTuple):
    """Loads of the tooth pairs at the mesh positions (module docstring).

    Shapes: (K, M) for K tooth pairs at M positions, (M,) per position.

    load : normal load of each pair (N; 0 where the pair does not touch).
    share : torque share ``l1_k F_k / T1`` of each pair (sums to 1).
    approach : normal approach ``w_k`` (mm; < 0: gap left under load).
    p_max : maximum Hertz pressure (MPa; 0 where unloaded).
    semi_major, semi_minor : Hertz contact ellipse (mm; line contact: half the
        contact-line length and the half-width).
    deflection : ``y``, loaded fall-back of the gear behind the unloaded TE
        envelope (rad, >= 0).
    te_loaded : loaded transmission error ``te_env - s y`` (rad).
    balance : ``|sum_k l1_k F_k - T1| / T1``.
    converged : the equilibrium Newton converged and the balance is below
        :data:`BALANCE_TOL`.
    n_loaded : number of pairs carrying load.
    """

    load: jax.Array
    share: jax.Array
    approach: jax.Array
    p_max: jax.Array
    semi_major: jax.Array
    semi_minor: jax.Array
    deflection: jax.Array
    te_loaded: jax.Array
    balance: jax.Array
    converged: jax.Array
    n_loaded: jax.Array


def _residual(y, th):
    g, l1, l2, q, c, act, T1 = th
    F = force_from_approach(jnp.where(act, l2 * (y - g), -1.0), q, c)
    return jnp.sum(l1 * F) / T1 - 1.0


def _one_position(te, act, l1, l2, q, c, T1, sgn):
    """Equilibrium at one position: (K,) arrays -> (y, F (K,), w (K,), balance, conv)."""
    some = jnp.any(act)
    act = act & some
    te = jnp.where(act, te, 0.0)
    key = jnp.where(act, sgn * te, -jnp.inf)
    lead = jnp.argmax(key)
    env = te[lead]
    g = jnp.where(act, sgn * (env - te), 0.0)
    l1s, l2s = jnp.where(act, l1, 1.0), jnp.where(act, l2, 1.0)
    qs, cs = jnp.where(act, q, 1.0), jnp.where(act, c, 0.0)
    # upper bound: the leading pair (g = 0) alone carries the torque
    F_lead = T1 / l1s[lead]
    y0 = (qs[lead] * F_lead + cs[lead] * jnp.cbrt(F_lead) ** 2) / l2s[lead]
    # with no pair active the lead stands in, so that the solve stays regular (the
    # position is reported not converged)
    act_or_lead = act | ((jnp.arange(act.shape[0]) == lead) & ~some)
    th = (g, l1s, l2s, qs, cs, act_or_lead, T1)
    sol = newton_solve(_residual, jax.lax.stop_gradient(y0) * (1.0 + 1e-12), th,
                       tol=BALANCE_TOL, max_steps=_OUTER_STEPS, xtol=0.0)
    y = sol.x
    w = jnp.where(act, l2s * (y - g), -jnp.inf)
    F = force_from_approach(jnp.where(act, w, -1.0), qs, cs)
    bal = jnp.abs(jnp.sum(l1s * F) / T1 - 1.0)
    conv = sol.converged & (bal <= BALANCE_TOL) & some
    nan = jnp.nan
    return (jnp.where(some, env, nan), jnp.where(some, y, nan), F, w,
            jnp.where(some, bal, nan), conv)


def share_torque(te, active, l1, l2, q, c, torque_Nmm, drive=True):
    """Solve the load sharing at every position (traceable; module docstring).

    te : (K, M) unloaded TE of each pair (rad; any value where not ``active``).
    active : (K, M) bool, the pair has a valid surface contact on both flanks.
    l1, l2 : (K, M) lever arms of the normal force about the pinion and gear axes (mm).
    q : (K, M) linear compliance (mm/N).  c : (K, M) Hertz coefficient (mm/N^(2/3)).
    torque_Nmm : pinion torque (N mm, > 0).  drive : side (``True``: max envelope).

    Returns ``(te_env (M,), y (M,), F (K, M), w (K, M), balance (M,), converged (M,))``.
    """
    sgn = jnp.where(drive, 1.0, -1.0)
    T1 = jnp.asarray(torque_Nmm, float)
    fn = jax.vmap(_one_position, in_axes=(1, 1, 1, 1, 1, 1, None, None),
                  out_axes=(0, 0, 1, 1, 0, 0))
    return fn(te, active, l1, l2, q, c, T1, sgn)


def lever_arms(point, normal, gear_ratio):
    """Lever arms (mm) of the normal force about the pinion axis (fixed z) and the
    gear axis: ``l1 = |(r x n)_z|``, ``l2 = l1 / |dphi2/dphi1|``."""
    l1 = jnp.abs(point[..., 0] * normal[..., 1] - point[..., 1] * normal[..., 0])
    return l1, l1 / jnp.abs(gear_ratio)


def hertz_coefficient(r_x, r_y, E_prime):
    """Approach of a Hertz point contact at 1 N (mm/N^(2/3)); ``delta = c F^(2/3)``."""
    return hertz_exact(jnp.ones_like(jnp.asarray(r_x, float)), r_x, r_y, E_prime).approach


def contact_stress(F, r_x, r_y, E_prime, line_length=None):
    """``(p_max, semi_major, semi_minor)`` of the loaded contacts (0 where ``F = 0``).

    Point contact: exact Hertz ellipse of ``F`` with principal radii ``r_x`` (across)
    and ``r_y`` (along).  Line contact (``line_length`` given, mm): Hertz line
    contact of ``w = F/L`` (semi-major = L/2)."""
    on = F > 0.0
    Fs = jnp.where(on, F, 1.0)
    if line_length is None:
        hz = hertz_exact(Fs, r_x, r_y, E_prime)
        p, a, b = hz.p_max, hz.a, hz.b
    else:
        Ls = jnp.where(on, line_length, 1.0)
        b, p = hertz_line_traced(Fs / Ls, r_x, E_prime)
        a = 0.5 * Ls
    z = jnp.zeros_like(Fs)
    return jnp.where(on, p, z), jnp.where(on, a, z), jnp.where(on, b, z)


class TeethOf(NamedTuple):
    """``teeth(pair, res) -> MeshTeeth`` of a family with its concrete options (hashable
    by value, so that jitted programs taking it as a static argument are reused)."""

    fn: object
    options: tuple = ()

    def __call__(self, pair, res):
        return self.fn(pair, res, **dict(self.options))


class MeshTeeth(NamedTuple):
    """The teeth of a pair as the compliance models see them, at every point of the
    TCA path of pair 0 (built by each family; traceable).

    Each member is represented by the spur gear of its normal section (cylindrical:
    the virtual gear of [ISO6336-1]; bevel/hypoid: the virtual cylindrical gear of
    [ISO10300-1] at the mean point): ``z`` (2,) virtual tooth numbers (floats),
    ``module`` normal module (mm), ``alpha`` (2,) normal pressure angles (rad),
    ``beta`` helix / mean spiral angle (rad), ``x`` (2,) profile-shift coefficients,
    ``ha``, ``hf`` (2,) addendum and dedendum coefficients, ``r_load`` (2, N) radius
    of the contact point on each virtual gear (mm), ``width`` (N,) face width that
    carries the load (mm), ``line_length`` (N,) length of the contact line (mm) for
    a line contact, else ``None``; ``drive`` (bool array) the sense of the unloaded
    TE envelope (True: max).
    """

    z: jax.Array
    module: jax.Array
    alpha: jax.Array
    beta: jax.Array
    x: jax.Array
    ha: jax.Array
    hf: jax.Array
    r_load: jax.Array
    width: jax.Array
    line_length: jax.Array | None
    drive: jax.Array


COMPLIANCE_MODELS = ("weber", "iso6336")


def pair_compliance(teeth: MeshTeeth, r_x, load_per_width, model: str = "weber",
                    E=E_STEEL, nu=NU_STEEL):
    """Linear compliance ``q`` (mm/N) of tooth pair 0 at every path point (module
    docstring; the Hertz term of a point contact is added by the caller).

    ``E`` (MPa) and ``nu``: Young's modulus and Poisson's ratio of both members (the
    pair's material, :mod:`gearjax.loading.materials`; default steel, 206 000 MPa and 0.3).
    Every term is that of linear elasticity, so ``q`` scales as ``1/E`` at fixed ν.

    ``"weber"`` (default): both teeth as cantilevers of the virtual spur gears --
    bending, shear and axial compression of the variable section plus the fillet
    foundation ([Weber1949], [Sainsot2004]; :func:`gearjax.loading.tooth_compliance.tooth_compliance`)
    -- per unit width, over the width carrying the load; a line contact adds Weber's
    contact compliance of the line at ``load_per_width`` (N/mm) with the reduced
    radius ``r_x`` (:func:`gearjax.loading.tooth_compliance.contact_compliance`), a point
    contact gets the Hertz approach instead (nonlinear, :func:`hertz_coefficient`).

    ``"iso6336"``: the single stiffness ``c'`` of [ISO6336-1] method B, constant along
    the path: ``q = 1e-3 / (c' width)`` (the 1e-3 converts um to mm); the standard's
    stiffness includes the flattening of the contact, so no Hertz term is added.  The
    standard's c' is that of steel (E_st = 206 000 MPa); another material scales it by
    ``E/E_st`` ([ISO6336-1], material ratio of a pair of two equal materials; the
    standard's formula has no ν).
    """
    if model not in COMPLIANCE_MODELS:
        raise ValueError(f"compliance model = {model!r} must be one of {COMPLIANCE_MODELS}")
    z, x, al = teeth.z, teeth.x, teeth.alpha
    if model == "iso6336":
        cb3 = jnp.cos(teeth.beta) ** 3      # the standard forms z_n = z / cos^3(beta)
        c1 = iso6336_single_stiffness(z[0] * cb3, z[1] * cb3, x[0], x[1], teeth.beta,
                                      alpha_n=0.5 * (al[0] + al[1])).c_prime
        return 1e-3 / (c1 * (E / E_STEEL) * teeth.width)

    def tooth(zi, ai, xi, hai, hfi, r_load):
        g = tooth_geometry(zi, teeth.module, ai, xi, hai, hfi)
        r = jnp.clip(r_load, g.r_form, g.r_a)
        return jax.vmap(lambda ri: tooth_compliance(ri, zi, teeth.module, ai, xi, hai, hfi,
                                                    E=E, nu=nu))(r)

    # both members in one vmap: the compliance model is traced (and compiled) once
    both = jax.vmap(tooth)(*(jnp.broadcast_to(jnp.asarray(a, float), (2,) + jnp.shape(a)[1:])
                             for a in (z, al, x, teeth.ha, teeth.hf, teeth.r_load)))
    t1, t2 = (jax.tree.map(lambda a, i=i: a[i], both) for i in (0, 1))
    q = (t1.total + t2.total) / teeth.width
    if teeth.line_length is not None:
        # Weber's body depths: from the contact point to each tooth's centre line
        # along the load line, h = y_m / cos(alpha_m) (docs/compliance.md)
        h1 = t1.half_thickness / jnp.cos(t1.load_angle)
        h2 = t2.half_thickness / jnp.cos(t2.load_angle)
        qc = contact_compliance(load_per_width, r_x, h1, h2, E, nu)
        q = q + qc / teeth.line_length
    return q
