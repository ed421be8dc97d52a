"""Mesh efficiency of a gear pair: loaded contact, friction along the path, losses.

The chain, every step a JAX function of the design::

    TCAResult (unloaded TE of each tooth pair, contact points, kinematics)
      -> load sharing at each mesh position        gearjax.loading.loaded_contact
      -> at each loaded contact: entrainment and sliding vectors, R_x/R_y along and
         across the entrainment, the load -> mixed-lubrication friction
                                                   gearjax.tribology (mu, film, lambda)
      -> P_f(phi) = sum_k mu_k F_k |u_s,k|,  eta_m(phi) = 1 - P_f/P_in, mean over a pitch

**Positions.**  One mesh cycle = one angular pitch of the pinion: the
``steps_per_pitch`` grid positions centred on the reference.  Tooth pair ``k`` at a
position is pair 0 shifted by ``k`` pitches (:func:`gearjax.tca.path.pair_arrays`),
exactly as the unloaded TE envelope of :func:`gearjax.tca.multi_pair`.

**Velocities.**  ``ContactKinematics`` gives per rad/s of pinion speed the surface
velocities relative to the contact point along the rolling direction ``t`` (across
the ellipse) and the side components along the major axis.  The *entrainment
vector* ``u_e = (w1 + w2)/2`` has the components ``(u_e, u_e tan(theta_e))`` in the
``(t, e_major)`` frame (``theta_e`` the entrainment angle), the *sliding vector*
``(u_s, u_s_side)``.  The friction model gets the magnitudes ``|u_e|`` and
``|u_s|`` (the friction force opposes the sliding vector; its power is
``mu F |u_s|``) and the radii along and across the entrainment,
``1/R_x = cos^2(theta_e)/r_x + sin^2(theta_e)/r_y``, ``1/R_y = sin^2/r_x + cos^2/r_y``
(the normal curvature of the relative curvature tensor in those directions; for
entrainment along a principal direction these are the principal radii).  A line
contact (``r_y = inf``) of length ``L`` is given to the elliptic friction model as the
equivalent ellipse whose major semi-axis is ``L/2``:
``R_y = R_x (k/1.0339)^(1/0.636)`` with ``k^2 = pi E' (L/2)^3 / (6 F R_x)``
(Hamrock-Brewe ellipticity inverted, [HamrockBrewe1983]).

**Losses.**  ``P_f = sum_k mu_k F_k |u_s,k|`` (W), ``P_in = T1 omega1``,
``eta_m(phi) = 1 - P_f/P_in``, ``eta_bar = 1 - mean(P_f)/P_in`` over the cycle
(positions equally spaced in time) [VH-CATT].

**Material.**  The reduced modulus E′ of the Hertz contact, film and asperities and
the Young's modulus and Poisson's ratio of the tooth compliance are those of one
material (:mod:`gearjax.loading.materials`): an explicit ``E_prime`` (MPa), else the design's
own material (a VH-CATT file's ``[material]``), else steel (E 206 000 MPa, ν 0.3,
E′ = 226 374 MPa); with an explicit E′ the compliance uses E = E′ (1 − ν²).

**Compliance.**  One default everywhere (Python, the ``gearjax efficiency`` command,
the docs): :data:`DEFAULT_COMPLIANCE` = ``"weber"`` (Weber/Cornell cantilever +
Sainsot foundation + the contact: Hertz approach of a point contact, Weber's line
contact); ``"iso6336"``: ISO 6336-1's constant single stiffness
(:func:`gearjax.loading.loaded_contact.pair_compliance`).

Units: torque N m, pinion speed **rpm** in every public function (the keyword is
``pinion_rpm``: :func:`mesh_efficiency`, the ``f`` of :func:`efficiency_function`,
:func:`mesh_efficiency_traced`; rad/s only inside), loads N, speeds mm/s, radii mm,
power W, moduli MPa.
References (docs/references.md): [VH-CATT]; [Litvin2004]; [HamrockBrewe1983];
[ISO6336-1]; [Ohlendorf1958].
"""

from __future__ import annotations

import dataclasses
import functools
import math
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.compile_ahead import call
from gearjax.errors import check_range
from gearjax.loading.efficiency_inputs import (RPM_RANGE, TORQUE_RANGE_NM, check_models,
                                               check_efficiency_inputs, check_operating_point)
from gearjax.loading.loaded_contact import (LoadedContact, MeshTeeth, contact_stress,
                                            hertz_coefficient, lever_arms, pair_arrays,
                                            pair_compliance, share_torque)
from gearjax.tca.result import TCAResult, family_of
from gearjax.loading.tooth_compliance import NU_STEEL
from gearjax.tribology.friction import FILM_MIN_MM, STEEL_E_PRIME, FrictionResult, Surface
from gearjax.tribology.losses import mesh_losses_traced
from gearjax.loading.efficiency_checks import MAX_RADIUS_RATIO, plausibility
from gearjax.tribology.lubricant import Oil

__all__ = ["MeshEfficiency", "mesh_efficiency", "DEFAULT_COMPLIANCE", "COMPLIANCE_HELP",
           "check_efficiency_inputs", "efficiency_function", "mesh_efficiency_traced",
           "cycle_window", "check_operating_point", "cycle_summary", "CycleSummary", "soften_edges",
           "TORQUE_RANGE_NM", "RPM_RANGE", "FILM_MIN_MM", "equivalent_ry"]


#: the default tooth compliance model of every route (Python and the command line)
DEFAULT_COMPLIANCE = "weber"
#: the compliance models in one sentence, word for word in the README, ``gearjax
#: efficiency --help`` and the docstring of :func:`mesh_efficiency` (a test keeps them so)
COMPLIANCE_HELP = ("weber (the default): Weber/Cornell tooth cantilever + Sainsot fillet "
                   "foundation + the contact (Hertz approach of a point contact, Weber's "
                   "line contact); iso6336: the constant single stiffness c' of ISO 6336-1 "
                   "method B, scaled by E/206000 MPa")


class MeshEfficiency(NamedTuple):
    """Efficiency of a pair over one mesh cycle (module docstring).

    Shapes: (K, M) per tooth pair and position, (M,) per position.

    phi1 : (M,) pinion angles of the positions (rad).
    loaded : :class:`~gearjax.loading.loaded_contact.LoadedContact` (loads, shares, p_max,
        ellipses, loaded TE, balance).
    u_e, u_s : magnitudes of the entrainment and sliding vectors (mm/s).
    r_x, r_y : radii along and across the entrainment as given to the friction model (mm).
    friction : :class:`~gearjax.tribology.friction.FrictionResult` (mu, lambda, film, ...).
    power_loss : (M,) P_f (W).  efficiency : (M,) eta_m.  mean_efficiency : eta_bar.
    mean_mu : load- and sliding-weighted mean mu, ``sum mu F |u_s| / sum F |u_s|``.
    max_p_max : highest Hertz pressure over the cycle (MPa).
    power_in : P_in (W).
    valid : (M,) every loaded contact converged (load balance, Hertz, load sharing),
        some pair carries load, and the result is plausible
        (:func:`~gearjax.loading.efficiency_checks.plausibility`).
    truncated : the grid or the number of pairs does not cover every pair in contact.
    edge_loaded : (M,) an edge contact would be compressed under the load (its load
        is not modelled: the result is then not valid).
    degenerate : (M,) a contact of the TCA path whose relative curvature is not
        positive definite (``r_y > MAX_RADIUS_RATIO r_x`` or infinite: on or beyond the
        edge of regression of a generated flank, where the flank is undercut) would be
        compressed under the load; such contacts carry no modelled load, and the
        position is not valid.
    n_valid : number of valid positions, over which the four summaries are taken.
    te_loaded_ptp : peak-to-peak of the loaded TE over the valid positions (rad; NaN
        when none).
    edge_share : (M,) the part of the mesh stiffness the soft active set takes away,
        ``sum_k k_k (1 - s_k) / sum_k k_k`` over the pairs in contact (``k_k`` a pair's
        linear stiffness, ``s_k`` its softening factor within ``edge_softening_mm`` of a
        flank boundary; 0 without softening): where it is not small the softened model
        is not the hard one (:func:`mesh_efficiency_traced`).
    """

    phi1: jax.Array
    loaded: LoadedContact
    u_e: jax.Array
    u_s: jax.Array
    r_x: jax.Array
    r_y: jax.Array
    friction: FrictionResult
    power_loss: jax.Array
    efficiency: jax.Array
    mean_efficiency: jax.Array
    mean_mu: jax.Array
    max_p_max: jax.Array
    power_in: jax.Array
    valid: jax.Array
    truncated: jax.Array
    edge_loaded: jax.Array
    degenerate: jax.Array
    n_valid: jax.Array
    te_loaded_ptp: jax.Array
    edge_share: jax.Array


class CycleSummary(NamedTuple):
    """Summaries of one mesh cycle over its valid positions (:func:`cycle_summary`)."""

    mean_efficiency: jax.Array
    mean_mu: jax.Array
    max_p_max: jax.Array
    te_loaded_ptp: jax.Array
    n_valid: jax.Array


def cycle_summary(power_loss, power_in, mu, load, u_s, p_max, te_loaded, valid) -> CycleSummary:
    """Summaries of a mesh cycle over its valid positions only (traceable).

    ``power_loss`` (M,) W, ``power_in`` W, ``mu``, ``load`` (N), ``u_s``, ``p_max`` (MPa)
    (K, M), ``te_loaded`` (M,) rad, ``valid`` (M,) bool.  With ``V`` the valid positions
    (equally spaced in time)::

        eta_bar = 1 - sum_V P_f / (|V| P_in)
        mean mu = sum_V,k mu F |u_s| / sum_V,k F |u_s|      (loaded contacts)
        max p_max = max_V,k p_max                           (loaded contacts)
        loaded TE p-t-p = max_V te - min_V te

    A position that is not valid (load balance or friction not converged, a loaded
    edge or degenerate contact, no pair carrying load, a truncated grid) has no
    modelled loss: counting it with ``P_f = 0`` would report a silent 100 %.  Every
    summary is NaN when no position is valid (``n_valid = 0``); when only some are,
    the summaries describe the modelled part of the cycle and the result is flagged
    (:func:`~gearjax.loading.efficiency_checks.efficiency_warnings`).  Gradients are
    finite (the masks are constants of the derivative).
    """
    valid = jnp.asarray(valid, bool)
    n_valid = jnp.sum(valid)
    some = n_valid > 0
    nan = jnp.nan
    vf = valid.astype(float)
    pin = jnp.asarray(power_in, float)
    mean_eff = 1.0 - jnp.sum(vf * power_loss) / (jnp.maximum(n_valid, 1) * pin)
    loaded = (load > 0.0) & valid[None, :]
    w = jnp.where(loaded, load * jnp.abs(u_s), 0.0)
    den = jnp.sum(w)
    mean_mu = jnp.sum(jnp.where(loaded, mu, 0.0) * w) / jnp.where(den > 0.0, den, 1.0)
    pm = jnp.max(jnp.where(loaded, p_max, -jnp.inf))
    te_hi = jnp.max(jnp.where(valid, te_loaded, -jnp.inf))
    te_lo = jnp.min(jnp.where(valid, te_loaded, jnp.inf))
    return CycleSummary(jnp.where(some, mean_eff, nan), jnp.where(den > 0.0, mean_mu, nan),
                        jnp.where(jnp.any(loaded), pm, nan),
                        jnp.where(some, te_hi - te_lo, nan), n_valid)


def _pitch(phi1, steps_per_pitch):
    """The pinion angular pitch (rad) from the grid spacing of the positions."""
    return jnp.abs(phi1[1] - phi1[0]) * steps_per_pitch


def cycle_window(n_grid: int, steps_per_pitch: int) -> np.ndarray:
    """Grid indices of one mesh cycle (one pitch) on the reference: the half-open interval
    ``[phi_ref - p/2, phi_ref + p/2)`` of the grid (``steps_per_pitch`` angles, the
    reference at index ``steps_per_pitch // 2`` of the window; one pitch counted once)."""
    mid = n_grid // 2
    return np.arange(steps_per_pitch) + (mid - steps_per_pitch // 2)


def equivalent_ry(F, r_x, L, E_prime):
    """R_y of the ellipse whose major semi-axis is L/2 under F (line contact)."""
    k2 = jnp.pi * E_prime * (0.5 * L) ** 3 / (6.0 * F * r_x)
    k = jnp.sqrt(jnp.maximum(k2, 1.0))
    return r_x * (k / 1.0339) ** (1.0 / 0.636)


def soften_edges(q, c, margin, delta):
    """The soft active set (:func:`mesh_efficiency_traced`): ``(q/s, c/s, s)`` with
    ``s = 3t^2 - 2t^3``, ``t = clip(margin/delta, 0, 1)`` (floored at 1e-30), for the
    linear compliance ``q`` (mm/N) and the Hertz coefficient ``c`` (mm/N^(2/3)) of
    contacts ``margin`` mm inside their flank boundaries: the whole pair compliance
    grows as ``1/s`` towards the edge.  ``delta`` (mm, static) 0: unchanged, ``s = 1``."""
    if delta <= 0.0:
        return q, c, jnp.ones_like(q)
    t = jnp.clip(margin / delta, 0.0, 1.0)
    s = jnp.maximum(t * t * (3.0 - 2.0 * t), 1e-30)
    return q / s, c / s, s


def mesh_efficiency_traced(res: TCAResult, teeth: MeshTeeth, torque_Nm, pinion_rpm, oil: Oil,
                           surface: Surface, *, steps_per_pitch: int, n_pairs: int,
                           E_prime=STEEL_E_PRIME, poisson=NU_STEEL,
                           compliance: str = DEFAULT_COMPLIANCE,
                           viscosity_model: str = "roelands",
                           film_method: str = "auto",
                           edge_softening_mm: float = 0.0) -> MeshEfficiency:
    """Loaded contact, friction and efficiency of the pair over one mesh cycle
    (traceable; no validation; module docstring).

    ``res`` : the TCA result with kinematics; ``teeth`` : the family's
    :class:`~gearjax.loading.loaded_contact.MeshTeeth` for ``res``; ``steps_per_pitch`` and
    ``n_pairs`` : those of the TCA.  Torque on the pinion (N m), pinion speed (rpm;
    ``omega1 = pinion_rpm pi/30`` rad/s inside).  ``E_prime`` (MPa) and ``poisson``:
    the material (module docstring); the tooth compliance takes
    ``E = E_prime (1 - poisson^2)`` and ``poisson``.

    ``edge_softening_mm`` (``delta``, static; default 0: the hard model): the soft active
    set of the design studies.  A pair whose contact lies within ``delta`` of a flank
    boundary (margin ``m`` in mm) answers with its compliance divided by
    ``s(m/delta)``, ``s(t) = 3t^2 - 2t^3`` on [0, 1]: its load falls to zero smoothly as
    its contact reaches the boundary, instead of jumping from its share to nothing where
    a grid position crosses the boundary -- the cycle means, maxima and loaded TE are
    then continuous, with continuous gradients, in the design (a pair entering or
    leaving contact; docs/optimize.md).  The model is unchanged wherever every loaded
    contact is more than ``delta`` inside its flank.
    """
    path, kin = res.path, res.kinematics
    n = path.phi1.shape[0]
    win = cycle_window(n, steps_per_pitch)
    K = n_pairs
    on = res.on_flank & jnp.isfinite(kin.r_x) & jnp.isfinite(kin.u_e)
    line = teeth.line_length is not None
    # compliance and lever arms of pair 0 along the grid
    # a true point contact has a positive definite relative curvature; where it is
    # not (r_y > MAX_RADIUS_RATIO r_x, or infinite), the contact lies on or beyond the
    # edge of regression of a generated flank (undercut: that part of the flank is
    # not there) -- no surface contact: excluded like an edge contact, flagged when
    # the loaded gear would press on it
    degenerate0 = (on & ~(kin.r_y < MAX_RADIUS_RATIO * kin.r_x)) if not line else on & False
    on = on & ~degenerate0
    r_x0 = jnp.where(on, kin.r_x, 1.0)
    r_y0 = jnp.where(on, kin.r_y, jnp.inf) if line else jnp.where(on, kin.r_y, 1.0)
    l1_0, l2_0 = lever_arms(path.point, path.normal, jnp.where(on, kin.gear_ratio, 1.0))
    T1 = 1e3 * jnp.asarray(torque_Nm, float)
    # nominal load per unit length of a line contact (one pair carrying the torque):
    # it enters Weber's contact compliance only through a logarithm
    w_nom = T1 / (jnp.where(on, l1_0, 1.0) * teeth.width)
    E_young = E_prime * (1.0 - poisson ** 2)
    q0 = pair_compliance(teeth, r_x0, w_nom, compliance, E=E_young, nu=poisson)
    if line or compliance == "iso6336":
        c0 = jnp.zeros_like(q0)
    else:
        c0 = hertz_coefficient(r_x0, r_y0, E_prime)
    k_hard = 1.0 / q0                     # the pairs' linear stiffness before softening
    q0, c0, soft = soften_edges(q0, c0, jnp.where(on, res.margin, 0.0), edge_softening_mm)

    def pairs(a, fill):
        return pair_arrays(a, steps_per_pitch, K, fill, win)

    act = pairs(on, False)
    te = pairs(jnp.where(on, path.te, 0.0), 0.0)
    l1, l2, q, c = (pairs(jnp.where(on, a, 1.0), 1.0) for a in (l1_0, l2_0, q0, c0))
    env, y, F, w, bal, conv = share_torque(te, act, l1, l2, q, c, T1, teeth.drive)
    sgn = jnp.where(teeth.drive, 1.0, -1.0)
    te_loaded = env - sgn * y

    # kinematics of every pair at every position (speeds per rad/s -> mm/s)
    omega = jnp.asarray(pinion_rpm, float) * (math.pi / 30.0)
    th_e = pairs(jnp.where(on, kin.entrainment_angle, 0.0), 0.0)
    ue_t = pairs(jnp.where(on, kin.u_e, 1.0), 1.0) * omega
    us_t = pairs(jnp.where(on, kin.u_s, 0.0), 0.0) * omega
    us_side = pairs(jnp.where(on, kin.u_s_side, 0.0), 0.0) * omega
    rx_p = pairs(r_x0, 1.0)
    ue = jnp.abs(ue_t) * jnp.sqrt(1.0 + jnp.tan(th_e) ** 2)
    us = jnp.sqrt(us_t ** 2 + us_side ** 2 + 1e-300)
    cs, sn = jnp.cos(th_e), jnp.sin(th_e)
    if line:
        L = pairs(jnp.where(on, teeth.line_length, 1.0), 1.0)
        Fs = jnp.where(F > 0.0, F, 1.0)
        R_x = rx_p
        R_y = equivalent_ry(Fs, R_x, L, E_prime)
        p_max, a_ax, b_ax = contact_stress(F, R_x, jnp.inf, E_prime, line_length=L)
    else:
        ry_p = pairs(jnp.where(on, r_y0, 1.0), 1.0)
        kx, ky = 1.0 / rx_p, 1.0 / ry_p
        R_x = 1.0 / (cs ** 2 * kx + sn ** 2 * ky)
        R_y = 1.0 / (sn ** 2 * kx + cs ** 2 * ky)
        p_max, a_ax, b_ax = contact_stress(F, rx_p, ry_p, E_prime)

    power_in = T1 * omega * 1e-3           # N mm * rad/s -> W
    ml = mesh_losses_traced(F.T, us.T, ue.T, R_x.T, R_y.T, oil, surface, power_in, E_prime,
                            viscosity_model=viscosity_model, film_method=film_method)
    fr = FrictionResult(*(jnp.swapaxes(v, 0, 1) for v in ml.friction))
    loaded_on = F > 0.0
    share = l1 * F / T1
    # the stiffness the softening takes from the pairs in contact (closing: w > 0)
    k_in = jnp.where(act & (w > 0.0), pairs(jnp.where(on, k_hard, 0.0), 0.0), 0.0)
    k_all = jnp.sum(k_in, axis=0)
    edge_share = (jnp.sum(k_in * (1.0 - pairs(jnp.where(on, soft, 1.0), 1.0)), axis=0)
                  / jnp.where(k_all > 0.0, k_all, 1.0))
    lc = LoadedContact(F, share, w, p_max, a_ax, b_ax, y, te_loaded, bal, conv,
                       jnp.sum(loaded_on, axis=0))
    # coverage: pair 0 on the flank where no pair of the window sees it
    ks = np.arange(K) - K // 2
    seen = np.zeros(n, bool)
    for k in ks:
        src = win - k * steps_per_pitch
        seen[src[(src >= 0) & (src < n)]] = True
    inside0 = (res.margin >= 0.0) & path.converged
    truncated = jnp.any(inside0 & ~seen) | inside0[0] | inside0[-1]
    nothing_loaded = ~jnp.any(loaded_on, axis=0)

    def pressed(mask0):
        """(M,) a contact of pair 0 in ``mask0`` (no load modelled there) would be
        compressed by the loaded gear at the position: ahead of the loaded TE, or
        the position has no surface contact carrying load at all (the gear then rests
        on such a contact: an uncrowned pair whose every contact is at a face end)."""
        te_m = pairs(jnp.where(mask0, path.te, 0.0), 0.0)
        ahead = (sgn * (te_m - te_loaded) > 0.0) | nothing_loaded[None, :]
        return jnp.any(pairs(mask0, False) & ahead, axis=0)

    edge_loaded = pressed(res.edge_points)          # face-end (edge) contacts
    degenerate = pressed(degenerate0)              # beyond an edge of regression
    # a position where no pair carries load has no modelled loss: never valid
    # an implausible result (plausibility) is not a result either
    plaus = plausibility(ml.efficiency, ml.mu.T, F, p_max, y, _pitch(path.phi1, steps_per_pitch),
                         b_ax, R_x)
    valid = (conv & jnp.all(fr.converged | ~loaded_on, axis=0) & ~edge_loaded & ~truncated
             & ~degenerate & ~nothing_loaded & plaus.all)
    sm = cycle_summary(ml.power_loss, power_in, ml.mu.T, F, us, p_max, te_loaded, valid)
    return MeshEfficiency(path.phi1[win], lc, ue, us, R_x, R_y, fr, ml.power_loss, ml.efficiency,
                          sm.mean_efficiency, sm.mean_mu, sm.max_p_max, power_in, valid, truncated,
                          edge_loaded, degenerate, sm.n_valid, sm.te_loaded_ptp, edge_share)


def _grid_options(ad, design, tca_options: dict) -> dict:
    """The TCA options of the loaded chain: the family's defaults for ``design`` filled
    in (grid, contact mode; a family on the one driver resolves them for the design),
    without ``kinematics`` (the chain always needs them)."""
    opts = {**tca_options, **ad.resolve(design, tca_options)}
    opts.pop("kinematics", None)
    return opts


def efficiency_function(design, *, side=None, compliance: str = DEFAULT_COMPLIANCE,
                        E_prime=None, viscosity_model: str = "roelands",
                        film_method: str = "auto", edge_softening_mm: float = 0.0,
                        **tca_options):
    """A pure, traceable ``f(pair, torque_Nm, pinion_rpm, oil, surface, mis=None) ->
    (MeshEfficiency, TCAResult)`` of ``design`` for ``jax.grad``/``jit``/``vmap``.

    Torque on the pinion in N m, **pinion speed in rpm** (as :func:`mesh_efficiency`
    and the ``--rpm`` flag; before issue #28 ``f`` took rad/s).  The concrete set-up
    (reference guess, sense of rotation, contact mode) is done once here, as for
    :func:`gearjax.tca_function`; ``f.pair`` is the design's pair pytree (the natural
    point to differentiate at).  The material (module docstring) is resolved here,
    once, by :func:`gearjax.loading.materials.pair_material`: ``E_prime`` (MPa) if given, else
    the design's material, else steel; ``f.material`` is the
    :class:`~gearjax.loading.materials.Material` used.  ``compliance`` defaults to
    :data:`DEFAULT_COMPLIANCE` (as :func:`mesh_efficiency` and the command).
    ``tca_options`` as for :func:`gearjax.run_tca` (``steps_per_pitch``,
    ``half_pitches``, ``n_pairs``, ...).

    ``edge_softening_mm``: the soft active set of :func:`mesh_efficiency_traced` (mm, >= 0;
    0, the default, is the hard model of :func:`mesh_efficiency`).

    Concrete inputs are validated as by :func:`mesh_efficiency` (the design and the
    options here; ``pair``, torque, speed, oil and surface on every call of ``f`` with
    concrete values); traced values (under ``jit``/``grad``/``vmap``) are not.
    """
    from gearjax.loading.materials import pair_material
    from gearjax.tca.result import check_design

    mat = pair_material(design, E_prime)
    Ep, nu = float(mat.e_prime_MPa), float(mat.poisson)
    check_models(compliance, viscosity_model, film_method)
    soft = check_range("edge_softening_mm", edge_softening_mm, 0.0, 10.0, unit="mm")
    check_design(design)
    ad = family_of(design)
    opts = _grid_options(ad, design, tca_options)
    kw = {} if side is None else {"side": side}
    # the concrete set-up once (a hypoid design is prepared -- reference search --
    # by ``mesh``; the TCA then runs on the prepared pair)
    teeth_of, pair0, run_design = ad.mesh(design, **kw, **opts)
    f_tca = ad.traced(run_design, **kw, **opts)
    spp, K = int(opts["steps_per_pitch"]), int(opts["n_pairs"])

    def f(pair, torque_Nm, pinion_rpm, oil, surface, mis=None):
        check_efficiency_inputs(torque_Nm, pinion_rpm, oil, surface, Ep, nu, compliance,
                                viscosity_model, film_method)
        check_design(pair)
        res = f_tca(pair, mis)
        return loaded(pair, res, torque_Nm, pinion_rpm, oil, surface), res

    def loaded(pair, res, torque_Nm, pinion_rpm, oil, surface, edge_softening_mm=soft):
        """The loaded part of ``f`` on a TCA result ``res`` of ``pair`` (``f`` = the TCA
        then this); ``edge_softening_mm`` static (e.g. 0: the hard model)."""
        return mesh_efficiency_traced(res, teeth_of(pair, res), torque_Nm, pinion_rpm, oil,
                                      surface, steps_per_pitch=spp, n_pairs=K, E_prime=Ep,
                                      poisson=nu, compliance=compliance,
                                      viscosity_model=viscosity_model, film_method=film_method,
                                      edge_softening_mm=edge_softening_mm)

    f.pair = pair0
    f.loaded = loaded
    f.material = mat
    f.options = dict(opts, side=side, compliance=compliance, E_prime_MPa=Ep, poisson=nu,
                     material_source=mat.source, edge_softening_mm=soft)
    return f


def mesh_efficiency(design, torque_Nm, pinion_rpm, oil: Oil, surface: Surface, *,
                    misalignment=None, side=None, compliance: str = DEFAULT_COMPLIANCE,
                    E_prime=None, viscosity_model: str = "roelands", film_method: str = "auto",
                    throw: bool = True, **tca_options):
    """Loaded contact, friction along the path and mesh efficiency of ``design`` at
    pinion torque ``torque_Nm`` (N m) and pinion speed ``pinion_rpm`` (rpm) (module
    docstring).

    Material: ``E_prime`` (MPa, reduced modulus ``E' = 2/((1-nu1^2)/E1 + (1-nu2^2)/E2)``)
    overrides the design's material; by default (None) the design's own material
    (a VH-CATT file's ``[material]``) or, for families without one, steel (E 206 000
    MPa, nu 0.3: E' = 226 374 MPa) sets E' *and* the tooth compliance
    (:func:`gearjax.loading.materials.pair_material` says which applied).  ``compliance``, the
    same default as the ``gearjax efficiency`` command (:data:`DEFAULT_COMPLIANCE`):
    weber (the default): Weber/Cornell tooth cantilever + Sainsot fillet foundation +
    the contact (Hertz approach of a point contact, Weber's line contact); iso6336: the
    constant single stiffness c' of ISO 6336-1 method B, scaled by E/206000 MPa.

    Every concrete input is validated before any work, as the command line and the
    design-file loaders do (one-line ValueError naming the parameter, its value and
    the allowed range): the design's fields (:func:`gearjax.tca.result.check_design`:
    e.g. degrees typed into a radian field), torque, speed, E' (MPa: E' in Pa is
    refused), the oil and surface fields, the model names.

    Runs :func:`gearjax.run_tca` (its compiled program is shared with every other
    TCA of the same options) and then one jitted program for the loads, friction
    and losses.  Returns ``(MeshEfficiency, TCAResult)``; check ``eff.valid`` and
    :func:`~gearjax.loading.efficiency_checks.efficiency_warnings`.  ``throw``: raise
    ConvergenceError when the TCA fails on the working flank (as :func:`gearjax.run_tca`).
    """
    from gearjax.loading.materials import pair_material
    from gearjax.tca.result import check_design

    mat = pair_material(design, E_prime)
    Ep, nu = float(mat.e_prime_MPa), float(mat.poisson)
    check_efficiency_inputs(torque_Nm, pinion_rpm, oil, surface, Ep, nu, compliance,
                            viscosity_model, film_method)
    T, n = float(torque_Nm), float(pinion_rpm)
    check_design(design)
    ad = family_of(design)
    opts = _grid_options(ad, design, tca_options)
    kw = {} if side is None else {"side": side}
    teeth_of, pair, run_design = ad.mesh(design, **kw, **opts)
    oil = dataclasses.replace(oil, name="")
    # a family whose pair has static fields that only enter arithmetic (the tooth
    # numbers of an involute pair) passes them traced: one program for every pair
    blank, extra = ad.split_pair(pair)
    args = (blank, extra, jnp.asarray(T, float), jnp.asarray(n, float), oil, surface,
            jnp.asarray(Ep, float), jnp.asarray(nu, float))
    static = dict(teeth_of=teeth_of, join=ad.join_pair,
                  steps_per_pitch=int(opts["steps_per_pitch"]), n_pairs=int(opts["n_pairs"]),
                  compliance=compliance, viscosity_model=viscosity_model,
                  film_method=film_method)
    # the loads' program compiles beside the TCA's (gearjax/compile_ahead.py)
    res = ad.run(run_design, misalignment, **kw, **opts, kinematics=True, throw=throw,
                 also=lambda ahead, r: ahead.submit(_post_jit, r, *args, **static))
    eff = call(_post_jit, res, *args, **static)
    return eff, res


@functools.partial(jax.jit, static_argnames=("teeth_of", "join", "steps_per_pitch", "n_pairs",
                                             "compliance", "viscosity_model", "film_method"))
def _post_jit(res, pair, extra, T, n, oil, surface, E_prime, poisson, *, teeth_of, join,
              steps_per_pitch, n_pairs, compliance, viscosity_model, film_method):
    pair = join(pair, extra)
    return mesh_efficiency_traced(res, teeth_of(pair, res), T, n, oil, surface,
                                  steps_per_pitch=steps_per_pitch, n_pairs=n_pairs,
                                  E_prime=E_prime, poisson=poisson, compliance=compliance,
                                  viscosity_model=viscosity_model, film_method=film_method)

