"""Unloaded tooth contact analysis of a spur or helical pair with flank micro-geometry,
by the thin-slice line contact of :mod:`gearjax.gears.involute.line_load`, and the
loaded transmission error over the mesh cycle at a set of torques.

**Unloaded TE.**  At mesh position ``s0`` (mm, path coordinate of pair 0 at the face
centre) every slice point ``j`` of every tooth pair on the path of contact has the
unloaded separation ``e_j = e_pinion(xi1, y) + e_gear(xi2, y) + f_ma y/b`` (µm, along
the line of action in the transverse plane: the modifications of both flanks in mesh
and the mesh misalignment).  Turning the gear back against the pinion closes the
smallest separation first, so the unloaded transmission error is

    TE0(s0) = min_j e_j(s0)                      (µm along the line of action),

``TE0 / r_b2`` of the gear in angle (rad; printed in arcsec).  Positive: the gear
lags the conjugate position.  An unmodified, aligned pair has ``TE0 = 0`` everywhere.
For a spur pair with a linear tip relief ``C_a`` on the pinion starting at roll length
``xi_s`` (``e`` grows with the pinion roll length), the lowest pair on the path sets
the minimum: ``TE0(s0) = C_a max((rho_P + s_low - xi_s)/L_a, 0)`` with ``s_low = s_A +
mod(s0 - s_A, p_bt)`` -- zero wherever a pair touches below the relief, the relief
at the point where the pair alone is in contact otherwise.

**Pairs in contact at zero load**: the tooth pairs that have a point within
:data:`TOUCH_TOL_UM` of the smallest separation; its mean over the cycle is the
contact ratio at zero load (``eps_alpha + eps_beta`` for an unmodified pair, up to the
sampling; 1 when the modifications leave one touching pair).  The **first contact**
is the slice point of the smallest separation (ties, such as the whole contact lines
of an unmodified pair: the first in pair order, then from end I).  The mesh position
as a pinion angle is ``phi1 = s0 / r_b1`` (rad, 0 with pair 0 at the pitch point).

**Loaded TE** at torque ``T1``: the approach ``delta`` of the same model
(:func:`~gearjax.gears.involute.line_load.line_load_traced`), per position.

Units: mm, µm, rad, N m for torques.  References (docs/references.md): [ISO21771];
[ISO1328-1]; [ISO6336-1]; [Litvin2004] (TCA).
"""

from __future__ import annotations

import dataclasses
from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.compile_ahead import call
from gearjax.errors import check_range
from gearjax.gears.involute.geometry import pair_geometry
from gearjax.gears.involute.line_load import line_load_traced
from gearjax.gears.involute.loaded_lines import (MISALIGNMENT_RANGE_UM, TORQUE_RANGE_NM,
                                                 line_design, line_options)

__all__ = ["LineTCA", "line_tca", "line_tca_traced", "TOUCH_TOL_UM"]

#: a pair whose smallest separation is within this of the smallest of all touches (µm)
TOUCH_TOL_UM = 1e-6
#: torque of the unloaded pass (N mm): the separations do not depend on it
_NOMINAL_NMM = 1.0


class LineTCA(NamedTuple):
    """The unloaded TCA of a modified line-contact pair (module docstring); shapes
    (M,) per mesh position, (T, M) per torque and position, (K, M, N) per pair,
    position and slice.

    s0_mm, phi1_rad : mesh positions (path coordinate, mm; pinion angle, rad).
    y_mm : (N,) slice centres.  pairs : (K,) tooth-pair indices.
    separation_um : (K, M, N) unloaded separations (µm; NaN off the path).
    te_um, te_arcsec : unloaded TE (µm along the line of action; arcsec of the gear).
    ptp_um, ptp_arcsec : its peak-to-peak over the cycle.
    pairs_in_contact : (M,) tooth pairs touching at zero load.
    contact_ratio_zero_load : mean of ``pairs_in_contact`` over the cycle.
    contact_ratio, overlap_ratio : eps_alpha, eps_beta of the pair (geometry).
    first_pair : (M,) pair of the first contact.  first_xi1_mm : its pinion roll length.
    first_r1_mm : its pinion radius.  first_y_mm : its face position.
    torque_Nm : (T,) torques of the loaded TE.  te_loaded_um : (T, M) approach (µm).
    te_loaded_ptp_um, te_loaded_mean_um, p_max_MPa, k_hbeta : (T,) per torque.
    converged : (T,) every position's torque balance converged.
    """

    s0_mm: jax.Array
    phi1_rad: jax.Array
    y_mm: jax.Array
    pairs: jax.Array
    separation_um: jax.Array
    te_um: jax.Array
    te_arcsec: jax.Array
    ptp_um: jax.Array
    ptp_arcsec: jax.Array
    pairs_in_contact: jax.Array
    contact_ratio_zero_load: jax.Array
    contact_ratio: jax.Array
    overlap_ratio: jax.Array
    first_pair: jax.Array
    first_xi1_mm: jax.Array
    first_r1_mm: jax.Array
    first_y_mm: jax.Array
    torque_Nm: jax.Array
    te_loaded_um: jax.Array
    te_loaded_ptp_um: jax.Array
    te_loaded_mean_um: jax.Array
    p_max_MPa: jax.Array
    k_hbeta: jax.Array
    converged: jax.Array


_ARCSEC = jnp.pi / (180.0 * 3600.0)


def line_tca_traced(pair, b, mods, f_ma, opts, E, nu, drive, torques_Nmm):
    """:class:`LineTCA` fields (traceable; ``torques_Nmm`` (T,), pinion N mm)."""
    geo = pair_geometry(pair)
    rb1, rb2, beta_b = geo["rb1"], geo["rb2"], geo["beta_b"]
    p_bt = 2.0 * jnp.pi * rb1 / pair.z1
    # the separations do not depend on the load nor on the foundation: the unloaded
    # pass without the coupled contact solve
    r = line_load_traced(pair, b, mods, _NOMINAL_NMM, f_ma, opts._replace(coupling_length=0.0),
                         E, nu, drive)
    K, M, N = r.separation_um.shape
    sep = r.separation_um
    te = r.te_unloaded_um
    on = jnp.isfinite(sep)
    sep_f = jnp.where(on, sep, jnp.inf)
    pair_min = jnp.min(sep_f, axis=2)                                  # (K, M)
    touching = pair_min <= te[None, :] + TOUCH_TOL_UM
    n_touch = jnp.sum(touching, axis=0)
    flat = jnp.moveaxis(sep_f, 1, 0).reshape(M, K * N)
    j = jnp.argmin(flat, axis=1)
    k_idx, n_idx = j // N, j % N
    xi1 = geo["rho_P"] + jnp.moveaxis(r.contact_s, 1, 0).reshape(M, K * N)[jnp.arange(M), j]
    ks = jnp.arange(opts.k_lo, opts.k_hi + 1)

    def loaded(T):
        q = line_load_traced(pair, b, mods, T, f_ma, opts, E, nu, drive)
        d = q.te_loaded_um
        return (d, jnp.max(d) - jnp.min(d), jnp.mean(d), jnp.max(q.p_max), q.k_hbeta_mean,
                jnp.all(q.converged))

    lo = jax.vmap(loaded)(torques_Nmm)
    te_rad = 1e-3 * te / rb2
    return (r.s0, r.s0 / rb1, r.y, ks, sep, te, te_rad / _ARCSEC, jnp.max(te) - jnp.min(te),
            (jnp.max(te_rad) - jnp.min(te_rad)) / _ARCSEC, n_touch, jnp.mean(n_touch),
            geo["contact_ratio"], b * jnp.tan(beta_b) / p_bt, ks[k_idx], xi1,
            jnp.sqrt(rb1 ** 2 + xi1 ** 2), r.y[n_idx], *lo)


def _split(pair):
    """The pair with tooth numbers 0 and the tooth numbers as a traced (2,) array."""
    return (dataclasses.replace(pair, z1=0, z2=0),
            jnp.asarray(np.array([pair.z1, pair.z2], dtype=float)))


@partial(jax.jit, static_argnames=("opts", "drive"))
def _program(blank, teeth, b, mods, f_ma, E, nu, torques_Nmm, opts, drive):
    p = dataclasses.replace(blank, z1=teeth[0], z2=teeth[1])
    return line_tca_traced(p, b, mods, f_ma, opts, E, nu, drive, torques_Nmm)


def line_tca(design, *, torques_Nm=(), side="drive", misalignment_um=0.0, positions=32,
             slices=20, compliance="weber", mods=None, coupling_length_mm=0.0) -> LineTCA:
    """The unloaded TCA of ``design`` (an involute design file, its ``[microgeometry]``
    tables, or an :class:`~gearjax.gears.involute.tca.InvoluteTCA` with ``mods``) by the
    thin-slice line contact, and the loaded TE at each of ``torques_Nm`` (pinion, N m;
    may be empty) -- :class:`LineTCA` (module docstring).  ``positions`` per base pitch,
    ``slices`` across the face; ``coupling_length_mm`` the Pasternak coupling of the slices
    along the face for the loaded TE (0: Winkler; the unloaded TE does not depend on it);
    one compiled program per option set and torque count."""
    T = np.atleast_1d(np.asarray(torques_Nm, float)) if np.size(torques_Nm) else np.zeros(0)
    if T.ndim != 1:
        raise ValueError("torques_Nm must be a 1-D list of torques (N m)")
    for t in T:
        check_range("torques_Nm", t, *TORQUE_RANGE_NM, unit="N m")
    f = check_range("misalignment_um", misalignment_um, *MISALIGNMENT_RANGE_UM, unit="um")
    pair, b, mods, mat = line_design(design, mods, side)
    opts = line_options(pair, b, positions, slices, compliance, coupling_length_mm)
    out = call(_program, *_split(pair), b, mods, f, mat.youngs_modulus_MPa, mat.poisson,
               jnp.asarray(1e3 * T), opts=opts, drive=side == "drive")
    return LineTCA(*out[:17], jnp.asarray(T), *out[17:])
