"""Checks of a mesh-efficiency result: which positions are plausible, the objective an
optimiser cannot game, and the warnings a concrete result prints.

A position whose numbers fail a plausibility check (:func:`plausibility`: eta_m in
(0, 1], mu <= MU_MAX, p_max <= P_MAX_LIMIT_MPA, Hertz half-width <= HERTZ_SIZE_MAX R_x,
loaded fall-back <= DEFLECTION_MAX_PITCH of a pitch) is not valid
(:class:`~gearjax.loading.mesh_efficiency.MeshEfficiency`).  :func:`efficiency_guard`
counts a lost position as a total loss (docs/efficiency.md, "Objectives that cannot
be gamed"); :func:`efficiency_warnings` gives one line per problem.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.tribology.friction import FILM_MIN_MM

from gearjax.tca.result import TCAResult

__all__ = ["MAX_RADIUS_RATIO", "MU_MAX", "P_MAX_LIMIT_MPA", "DEFLECTION_MAX_PITCH",
           "HERTZ_SIZE_MAX", "NEGLIGIBLE_LOAD_SHARE", "checked_contacts", "Plausibility",
           "PLAUSIBILITY_TEXT", "plausibility",
           "EfficiencyGuard", "efficiency_guard", "efficiency_warnings"]


#: largest accepted r_y / r_x of a point contact (beyond: degenerate, flagged)
MAX_RADIUS_RATIO = 1e4

# -- plausibility of the results (:func:`plausibility`; docs/efficiency.md) ----------
#: largest plausible friction coefficient of a lubricated steel contact: boundary
#: friction of steel on steel under oil is 0.1-0.15, dry steel ~0.6; above 0.3 the
#: mixed-lubrication model is outside anything it was fitted to
MU_MAX = 0.3
#: largest plausible maximum Hertz pressure (MPa) of a steel gear contact: far above
#: the contact-fatigue allowables of case-hardened steel (~1500 MPa) and at the onset
#: of gross subsurface yield, where the elastic Hertz/EHL model no longer holds
P_MAX_LIMIT_MPA = 5000.0
#: largest plausible loaded fall-back ``y`` of the gear behind the unloaded TE envelope,
#: as a fraction of the pinion's angular pitch (2 % of a pitch: ~0.25 mm of arc at
#: m = 4; elastic tooth deflections at rated load are tens of micrometres)
DEFLECTION_MAX_PITCH = 0.02
#: largest plausible Hertz half-width (semi-minor axis) of a loaded contact relative to
#: its radius R_x along the entrainment: Hertz theory needs a contact small against the
#: radii (a few per cent at rated load); half the radius means a contact as wide as the
#: tooth flank, an approach beyond what the tooth allows
HERTZ_SIZE_MAX = 0.5
#: a contact carrying less than this share of its position's total normal load is not
#: checked for plausibility: the friction and film models are outside their range at a
#: vanishing load (a film's mu grows as F^(-1/3) as F -> 0) while its loss mu F u_s
#: vanishes with F.  A pair that enters its flank under the soft active set starts
#: from F = 0+ (ISO 10/41 study: 4.5e-31 N beside 8782 N, mu = 1.2e5; extrapolated as
#: F^(-1/3), mu falls to MU_MAX near 3e-14 N) and would otherwise make its position
#: invalid at the grid point where it enters -- a jump of the cycle's mean loss with
#: nothing physical behind it (docs/efficiency.md)
NEGLIGIBLE_LOAD_SHARE = 1e-9
#: FILM_MIN_MM (gearjax.tribology.friction): the thinnest film inside the film model's
#: range (a warning, not a failure)


class EfficiencyGuard(NamedTuple):
    """The efficiency objective of an optimisation on a fixed set of positions
    (:func:`efficiency_guard`)."""

    mean_efficiency: jax.Array
    n_lost: jax.Array


def efficiency_guard(eff, nominal_valid) -> EfficiencyGuard:
    """η̄ over a fixed nominal set of positions, with a lost position counted as a total
    loss, so that an optimiser cannot raise it by invalidating positions (traceable).

    ``nominal_valid`` (M,) bool: the positions valid at the start (``eff0.valid`` of the
    nominal design), kept fixed during the run -- like the mask of
    :meth:`gearjax.TCAResult.objectives`.  With ``V0`` that set and ``valid`` the
    positions valid now::

        eta_guard = 1 - sum_{i in V0} (valid_i ? P_f,i : P_in) / (|V0| P_in)
        n_lost    = |{i in V0 : not valid_i}|

    On a run that keeps every nominal position valid ``eta_guard`` is the plain η̄ of
    those positions (:func:`cycle_summary` over V0) and its gradient is the gradient of
    the modelled losses.  A position that leaves the valid set (off the flank, load
    balance or friction not converged, implausible) counts as ``P_f = P_in`` (η = 0 there),
    the worst case, instead of dropping out of the mean: ``eta_guard`` then falls by at
    least ``(P_in − P_f,i)/(|V0| P_in)`` ≈ 1/|V0|, whereas the plain η̄ over the valid
    positions rises when the position left was a lossy one.  The step is not
    differentiable (the masks are constants of the derivative): add the C¹ penalty of
    ``res.mask_check(on0)`` to push contacts back onto the flank before they leave, and
    accept an end point only with ``n_lost == 0`` -- otherwise the run is a flagged
    failure (docs/efficiency.md, "Objectives that cannot be gamed").
    """
    v0 = jnp.asarray(nominal_valid, bool)
    valid = jnp.asarray(eff.valid, bool)
    pin = jnp.asarray(eff.power_in, float)
    loss = jnp.where(valid, jnp.where(v0, eff.power_loss, 0.0), jnp.where(v0, pin, 0.0))
    n0 = jnp.sum(v0)
    eta = 1.0 - jnp.sum(loss) / (jnp.maximum(n0, 1) * pin)
    return EfficiencyGuard(jnp.where(n0 > 0, eta, jnp.nan), jnp.sum(v0 & ~valid))


class Plausibility(NamedTuple):
    """(M,) per position: the result passes each plausibility check
    (:func:`plausibility`)."""

    efficiency: jax.Array
    mu: jax.Array
    p_max: jax.Array
    deflection: jax.Array
    contact: jax.Array

    @property
    def all(self):
        return self.efficiency & self.mu & self.p_max & self.deflection & self.contact


#: the reason printed for each failed check of :class:`Plausibility`
PLAUSIBILITY_TEXT = {
    "efficiency": "eta_m outside (0, 1]",
    "mu": f"mu above {MU_MAX:g} (MU_MAX)",
    "p_max": f"p_max above {P_MAX_LIMIT_MPA:g} MPa (P_MAX_LIMIT_MPA: beyond the elastic "
             "range of steel)",
    "deflection": f"loaded fall-back behind the unloaded TE above {DEFLECTION_MAX_PITCH:g} of "
                  "a pinion pitch (DEFLECTION_MAX_PITCH: beyond what a tooth allows)",
    "contact": f"Hertz half-width above {HERTZ_SIZE_MAX:g} R_x (HERTZ_SIZE_MAX: an approach "
               "beyond what the tooth allows, outside Hertz theory)",
}


def checked_contacts(load):
    """(K, M) the contacts whose plausibility is checked: ``load`` (N, (K, M)) above
    :data:`NEGLIGIBLE_LOAD_SHARE` of the position's total (traceable)."""
    return load > NEGLIGIBLE_LOAD_SHARE * jnp.sum(jnp.where(load > 0.0, load, 0.0), axis=0)


def plausibility(efficiency, mu, load, p_max, deflection, pitch, semi_minor, r_x
                 ) -> Plausibility:
    """Plausibility of the results at each position (traceable; (M,) booleans).

    ``efficiency`` (M,) eta_m, ``mu``, ``load`` (N), ``p_max`` (MPa) (K, M),
    ``deflection`` (M,) loaded fall-back y (rad), ``pitch`` the pinion angular pitch
    (rad), ``semi_minor`` (K, M) Hertz half-width and ``r_x`` (K, M) radius along the
    entrainment (mm).  A position passes when ``0 < eta_m <= 1``, every loaded contact
    has ``mu <= MU_MAX``, ``p_max <= P_MAX_LIMIT_MPA`` and
    ``semi_minor <= HERTZ_SIZE_MAX r_x``, and
    ``y <= DEFLECTION_MAX_PITCH * pitch`` (NaN fails every check); a loaded contact is
    one carrying more than :data:`NEGLIGIBLE_LOAD_SHARE` of the position's load
    (:func:`checked_contacts`).  A position that fails one is not valid
    (:class:`MeshEfficiency`): its numbers are not a result.
    """
    loaded = checked_contacts(load)
    eff_ok = (efficiency > 0.0) & (efficiency <= 1.0)
    mu_ok = jnp.all(~loaded | (mu <= MU_MAX), axis=0)
    p_ok = jnp.all(~loaded | (p_max <= P_MAX_LIMIT_MPA), axis=0)
    y_ok = deflection <= DEFLECTION_MAX_PITCH * pitch
    c_ok = jnp.all(~loaded | (semi_minor <= HERTZ_SIZE_MAX * r_x), axis=0)
    return Plausibility(eff_ok, mu_ok, p_ok, y_ok, c_ok)


def efficiency_warnings(eff, res: TCAResult, *, film_method: str = "auto",
                        viscosity_model: str = "roelands") -> list[str]:
    """One line per problem of a concrete result (``eff`` a
    :class:`~gearjax.loading.mesh_efficiency.MeshEfficiency`, ``res`` its TCA): TCA
    quality flags, load balance or friction solves not converged, grid too short,
    loaded edge contact, implausible results (:func:`plausibility`: one line per
    failed check with the worst value), a
    film below :data:`FILM_MIN_MM`, the film formula outside its fitted ellipticity
    range and the viscosity law above 3 GPa (``film_method``, ``viscosity_model`` as
    given to the friction model)."""
    out = list(res.warnings())
    valid = np.asarray(eff.valid)
    F = np.asarray(eff.loaded.load, float)
    loaded = np.asarray(checked_contacts(F))
    phi = np.asarray(eff.phi1, float)
    pl = plausibility(np.asarray(eff.efficiency), np.asarray(eff.friction.mu), F,
                      np.asarray(eff.loaded.p_max), np.asarray(eff.loaded.deflection),
                      float(np.abs(phi[1] - phi[0]) * phi.shape[0]) if phi.size > 1 else np.inf,
                      np.asarray(eff.loaded.semi_minor), np.asarray(eff.r_x))
    # only where the load sharing converged (elsewhere the values are not results and
    # the non-convergence is its own warning)
    conv = np.asarray(eff.loaded.converged, bool)
    eta = np.asarray(eff.efficiency, float)
    mu = np.where(loaded, np.asarray(eff.friction.mu, float), -np.inf)
    pm = np.where(loaded, np.asarray(eff.loaded.p_max, float), -np.inf)
    y = np.asarray(eff.loaded.deflection, float)
    hw = np.where(loaded, np.asarray(eff.loaded.semi_minor, float) / np.asarray(eff.r_x, float),
                  -np.inf)
    worst = {
        "efficiency": lambda b: f"eta_m from {np.min(eta[b]):.9g} to {np.max(eta[b]):.9g}",
        "mu": lambda b: f"mu up to {np.max(mu[:, b]):.4g}",
        "p_max": lambda b: f"p_max up to {np.max(pm[:, b]):.0f} MPa",
        "deflection": lambda b: f"fall-back up to {np.max(y[b]) * 206264.80624709636:.0f} arcsec",
        "contact": lambda b: f"half-width / R_x up to {np.max(hw[:, b]):.3g}",
    }
    for name, ok in pl._asdict().items():
        bad = ~np.asarray(ok) & conv
        if np.any(bad):
            out.append(f"implausible result at {int(bad.sum())} of {bad.size} positions: "
                       f"{PLAUSIBILITY_TEXT[name]}; {worst[name](bad)} (not valid)")
    h_c = np.asarray(eff.friction.h_c, float)
    thin = loaded & (h_c < FILM_MIN_MM)
    if np.any(thin):
        out.append(f"film h_c down to {1e6 * np.nanmin(np.where(thin, h_c, np.inf)):.3g} nm "
                   f"at {int(thin.sum())} loaded contacts, below the film/asperity model's range "
                   f"({1e6 * FILM_MIN_MM:g} nm, FILM_MIN_MM): labelled boundary there; the "
                   "asperity share and mu there are not reliable")
    k = np.asarray(eff.friction.k, float)[loaded]
    if k.size and film_method in ("auto", "point") and np.any(k < 1.0):
        out.append(f"Hamrock-Dowson film formula used outside its fitted ellipticity range "
                   f"1 <= k <= 8 (k down to {k.min():.3g})")
    pmx = np.asarray(eff.loaded.p_max, float)[loaded]
    if pmx.size and np.any(pmx > 3000.0):
        out.append(f"{viscosity_model.capitalize()} viscosity law extrapolated above 3 GPa "
                   f"(p_max up to {pmx.max():.0f} MPa at {int(np.sum(pmx > 3000.0))} loaded "
                   "contacts); its validity range is about 0-3 GPa")
    if bool(np.asarray(eff.truncated)):
        out.append("the TCA grid or the number of tooth pairs does not cover every pair in "
                   "contact: widen --pitches / raise the number of pairs")
    if np.any(np.asarray(eff.edge_loaded)):
        out.append(f"edge contact under load at {int(np.sum(np.asarray(eff.edge_loaded)))} "
                   "positions (its load is not modelled)")
    if np.any(np.asarray(eff.degenerate)):
        out.append(f"contact beyond the edge of regression of a flank (relative curvature not "
                   f"positive definite, r_y/r_x > {MAX_RADIUS_RATIO:g}) under load at "
                   f"{int(np.sum(np.asarray(eff.degenerate)))} positions: not modelled")
    if not np.all(np.asarray(eff.loaded.converged)):
        out.append("load sharing did not converge at some positions")
    if not np.all(valid):
        nv = int(np.sum(valid))
        if nv:
            out.append(f"{int(np.sum(~valid))} of {valid.size} positions are not valid "
                       f"(see the 'valid' flags): eta_bar, mean mu, max p_max and loaded TE "
                       f"are over the {nv} valid positions only (a partial cycle)")
        else:
            out.append(f"none of the {valid.size} positions is valid: no summary")
    return out
