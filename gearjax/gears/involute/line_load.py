"""Loaded contact of spur and helical pairs in line contact: the contact lines in the
plane of action cut into face-width slices, the load distribution along them, loaded
TE, line load and Hertz pressure per slice, the face load factor.

**Geometry** ([ISO21771]).  In the plane of action every contact of a cylindrical
involute pair lies on straight contact lines inclined at the base helix angle
``beta_b`` to the axis.  A point is located by its transverse path coordinate ``s``
(mm along the line of action from the pitch point, positive toward the pinion tip;
the pinion roll length is ``xi1 = rho_P + s``, the gear's ``xi2 = g - xi1`` with ``g =
a_w sin alpha_wt``) and its face coordinate ``y`` (mm from the face centre).  At mesh
position ``s0`` the contact line of tooth pair ``k`` is

    s_k(y) = s0 + k p_bt + y tan(beta_b),        s_A <= s_k(y) <= s_E,

``p_bt`` the transverse base pitch and ``[s_A, s_E]`` the path of contact between the
tip circles.  (So each pair first touches at end II, ``y = +b/2``, at the pinion's
root: that fixes which axial end is end II for a given hand; the modifications of
:mod:`gearjax.gears.involute.microgeometry` use the same axis.)  The face is cut into
``N`` slices of width ``dy = b/N``; a slice carries a contact-line piece of length
``dy / cos(beta_b)`` where it lies inside the path (a fraction at the path's ends,
so the load of a helical pair enters and leaves continuously).

**Separation and approach.**  The unloaded separation of a slice point, measured like
the modifications in the transverse plane along the line of action, is
``e = e_pinion(xi1, y) + e_gear(xi2, y) + f_ma y/b`` (µm:
:func:`~gearjax.gears.involute.microgeometry.flank_removal_um` of both flanks in mesh
and the mesh misalignment).  A rigid approach ``delta`` of the two bodies along the
line of action (transverse, mm) compresses the point by ``(delta - e) cos(beta_b)``
along its normal.

**Compliance: a Winkler foundation of thin slices.**  This is the elastic foundation
behind ISO 6336-1's face load factor: the mesh as independent springs of stiffness
``c_gamma`` per unit face width.  Their linear load distribution under a mesh
misalignment gives the standard's K_Hbeta formulas, which the tests reproduce.  By
default the slices are not coupled along the face, so a modification's effect spreads
only as far as the slice width.  With ``opts.coupling_length`` > 0 the slices of each
tooth pair are coupled by a Pasternak foundation along the face, ``k w - G w'' = q``
with free ends ([Pasternak1954], [AjmiVelex2005]), and the equilibrium below becomes a
linear complementarity problem solved per position by an active-set method
(:mod:`gearjax.gears.involute.face_coupling`).  A slice of contact-line length
``l`` has the normal stiffness ``k = l / q'(s)`` (N/mm), ``q'`` the compliance of the
tooth pair per unit length of contact line at that point of the path: both teeth as
Weber/Sainsot cantilevers of the virtual spur gears of the normal section plus
Weber's contact compliance of the line, or the constant single stiffness of ISO
6336-1 (:func:`gearjax.loading.loaded_contact.pair_compliance`, docs/compliance.md).
The contact term is taken at the nominal line load ``T1 / (r_b1 b)`` (one pair
carrying the torque, as the point-contact chain does); it enters through a
logarithm only.

**Equilibrium** of the pinion torque ``T1`` (N mm):

    T1 / (r_b1 cos^2 beta_b) = sum_j k_j max(delta - e_j, 0),

a continuous, piecewise-linear, increasing function of ``delta``: solved exactly by
sorting the separations (the count ``m`` of points in contact is the number of
breakpoints below the load, then ``delta = (W + sum_{j<m} k_j e_j) / sum_{j<m} k_j``),
with no iteration and no smoothing; the derivative of ``delta`` (and of every load)
with respect to every design field is that of the active piece, exact.  The results
are therefore piecewise smooth in the design: the derivative jumps where a slice point
enters or leaves contact, and where a sampled point crosses the start of a linear
relief (a parabolic relief has no such kink).  At a kink the gradient is one of the
one-sided slopes; an optimiser's stationarity test is limited there (the
augmented Lagrangian stops as stalled, :mod:`gearjax.augmented_lagrangian`).  The normal
load of a point is ``F_j = k_j max(delta - e_j, 0) cos(beta_b)``.

**Outputs**: the loaded transmission error as the approach ``delta`` (µm along the line
of action, positive: the gear lags; the angle is ``delta / r_b2`` of the gear), the
unloaded TE ``min_j e_j`` (the approach at zero load), loads, line loads ``F / l``
(N/mm) and Hertz pressures of the line contact of the normal-section radii ``rho_n =
xi / cos(beta_b)`` ([Johnson1985] eq. 4.45), the mesh stiffness ``c_gamma =
cos^2(beta_b) (dW/d delta) / b``, ``dW/d delta = sum_(loaded) k`` for the Winkler
foundation (N/(mm µm) after the unit factor: transverse load along the line of action
per unit face width per µm of approach), and the face load
factor ``K_Hbeta = max_y w(y) / mean_y w(y)`` of the load per unit face width ``w(y)``
(summed over the pairs; per position and for the cycle-mean distribution, [ISO6336-1]).

Units: mm, N, N mm, MPa, µm where named.  References (docs/references.md):
[ISO21771]; [ISO6336-1]; [Weber1949]; [Sainsot2004]; [Johnson1985]; [Pasternak1954];
[AjmiVelex2005].
"""

from __future__ import annotations

import math
from typing import NamedTuple

import jax
import jax.numpy as jnp

from gearjax.contact import hertz_line_traced
from gearjax.gears.involute.face_coupling import ACTIVE_SET_STEPS, coupled_solve, face_links
from gearjax.gears.involute.geometry import InvolutePair, pair_geometry
from gearjax.gears.involute.mesh import virtual_teeth
from gearjax.gears.involute.microgeometry import (PairModification, flank_removal_um,
                                                  misalignment_um)
from gearjax.loading.loaded_contact import pair_compliance
from gearjax.loading.tooth_compliance import E_STEEL, NU_STEEL

__all__ = ["LineLoad", "LineLoadOptions", "line_load_traced", "pair_range", "smooth_ptp",
           "path_points_bound",
           "BALANCE_TOL"]

#: relative tolerance of the torque balance of a converged position
BALANCE_TOL = 1e-9
#: separation (mm) standing for "not on the path" (above any load's approach)
_FAR = 1e9


class LineLoadOptions(NamedTuple):
    """Static options (part of a compiled program's key).

    positions : mesh positions per base pitch.  slices : face-width slices.
    k_lo, k_hi : the tooth pairs ``k_lo <= k <= k_hi`` tried (:func:`pair_range`).
    compliance : ``"weber"`` or ``"iso6336"`` (module docstring).
    path_points : at most this many slice points of one position lie on the path
        (:func:`path_points_bound`; 0: no bound known).  The friction of
        :mod:`gearjax.gears.involute.line_efficiency` is evaluated at that many points
        per position instead of at every pair's slices.
    coupling_length : the coupling length ``lambda`` (mm) of the Pasternak foundation
        along the face (:mod:`gearjax.gears.involute.face_coupling`); 0: the Winkler
        foundation of independent slices (the module docstring's model, the default).
    coupling_steps : cap of the coupled contact's active-set iterations.
    """

    positions: int = 32
    slices: int = 20
    k_lo: int = -2
    k_hi: int = 3
    compliance: str = "weber"
    path_points: int = 0
    coupling_length: float = 0.0
    coupling_steps: int = ACTIVE_SET_STEPS


def path_points_bound(pair: InvolutePair, face_width, slices: int) -> int:
    """An upper bound of the slice points on the path at any mesh position (concrete
    values): along one slice the pairs lie ``p_bt`` apart in ``s`` and a piece reaches
    ``dy tan(beta_b)/2`` either side of its centre, so at most ``floor((s_E - s_A +
    dy tan(beta_b)) / p_bt) + 1`` of them touch the path ``[s_A, s_E]``; times the
    slices, plus one pair's worth of margin for a design an optimiser moves."""
    geo = pair_geometry(pair)
    p_bt = 2.0 * math.pi * float(geo["rb1"]) / pair.z1
    extent = float(geo["rho_E"] - geo["rho_A"]) + float(face_width) / slices * math.tan(
        float(geo["beta_b"]))
    return int(slices) * (math.floor(extent / p_bt) + 2)


def pair_range(pair: InvolutePair, face_width, margin: int = 1) -> tuple[int, int]:
    """``(k_lo, k_hi)`` covering every pair on the path for mesh positions ``s0`` in
    one base pitch from ``s_A`` (concrete values): ``k`` from ``-ceil(eps_beta/2) - 1``
    to ``ceil(eps_alpha + eps_beta/2)``, widened by ``margin`` each way so that a
    design moved by an optimiser keeps its pairs, and to at least ``-3 .. 4`` (the
    range is a static option: every pair with eps_beta <= 2 and eps_alpha + eps_beta/2
    <= 3 then shares one compiled program)."""
    geo = pair_geometry(pair)
    p_bt = 2.0 * math.pi * float(geo["rb1"]) / pair.z1
    eps_a = float(geo["contact_ratio"])
    eps_b = float(face_width) * math.tan(float(geo["beta_b"])) / p_bt
    return (min(-math.ceil(eps_b / 2.0) - 1 - margin, -3),
            max(math.ceil(eps_a + eps_b / 2.0) + margin, 4))


class LineLoad(NamedTuple):
    """The loaded line contact over one mesh cycle (module docstring).

    Shapes: (K, M, N) per pair, position and slice; (M,) per position; (N,) per slice.

    s0 : (M,) mesh positions (mm, path coordinate of pair 0 at the face centre).
    y : (N,) slice centres (mm).  s : (K, M, N) path coordinates of the slice centres.
    contact_s : (K, M, N) path coordinate where each slice's load acts: its centre, or
        for a piece crossing an end of the path the middle of the part on the path
        (the middle of the path off it).
    r_x : (K, M, N) reduced radius of the normal section there,
        ``xi1 xi2 / ((xi1 + xi2) cos(beta_b))`` (mm; Hertz, contact compliance, friction).
    length : (K, M, N) contact-line length carried by each slice (mm, 0 off the path).
    separation_um : (K, M, N) unloaded separations (µm; NaN off the path).
    load : (K, M, N) normal loads (N).  line_load : (K, M, N) normal load per unit
        length of contact line (N/mm).  p_max : (K, M, N) Hertz pressure (MPa).
    pair_load : (K, M) normal load of each tooth pair (N).
    te_loaded_um : (M,) loaded TE, the approach delta (µm).
    te_unloaded_um : (M,) unloaded TE, min separation (µm).
    mesh_stiffness : (M,) c_gamma (N/(mm µm)).
    face_load : (M, N) load per unit face width along the face (N/mm, normal).
    k_hbeta : (M,) face load factor per position.  k_hbeta_mean : the factor of the
        cycle-mean distribution.
    end_load : (M,) load per unit face width in the end slices over the mean, per
        position (the larger end).  For a helical pair it also follows how many contact
        lines cross each slice at that position (1.25 for an aligned unmodified pair),
        so the edge loading is read from ``end_load_mean``.
    end_load_mean : the same of the cycle-mean distribution (> 1: the face ends carry
        more than the middle over the cycle; 1 for an aligned unmodified pair).
    n_points : (M,) slice points carrying load.
    balance : (M,) relative torque residual.  converged : (M,) balance below
        :data:`BALANCE_TOL` and some point on the path (with coupling also the active
        set found and the complementarity residual below its tolerance).
    gap_um : (K, M, N) loaded gap ``w + e - delta`` of each slice point (µm; 0 where
        loaded, NaN off the path), ``w`` the slice's deflection: ``max(delta - e, 0)``
        for the Winkler foundation, the coupled solution's with coupling.
    complementarity : (M,) complementarity residual: the largest tensile load over the
        transmitted load, or interpenetration over the compression
        (:func:`~gearjax.gears.involute.face_coupling.coupled_solve`; 0 for the Winkler
        foundation, whose loads are ``k max(delta - e, 0)`` by construction).
    """

    s0: jax.Array
    y: jax.Array
    s: jax.Array
    contact_s: jax.Array
    r_x: jax.Array
    length: jax.Array
    separation_um: jax.Array
    load: jax.Array
    line_load: jax.Array
    p_max: jax.Array
    pair_load: jax.Array
    te_loaded_um: jax.Array
    te_unloaded_um: jax.Array
    mesh_stiffness: jax.Array
    face_load: jax.Array
    k_hbeta: jax.Array
    k_hbeta_mean: jax.Array
    end_load: jax.Array
    end_load_mean: jax.Array
    n_points: jax.Array
    balance: jax.Array
    converged: jax.Array
    gap_um: jax.Array
    complementarity: jax.Array


def _solve(e, k, W):
    """``delta`` with ``sum_j k_j max(delta - e_j, 0) = W`` (1-D arrays; exact, module
    docstring).  Points off the path have ``k = 0`` and ``e = _FAR``."""
    order = jnp.argsort(e)
    es, ks = e[order], k[order]
    cum_k = jnp.cumsum(ks)
    cum_ke = jnp.cumsum(ks * es)
    # H at each breakpoint e_i: the load carried when the approach is e_i
    h = es * jnp.concatenate([jnp.zeros(1), cum_k[:-1]]) - jnp.concatenate([jnp.zeros(1),
                                                                           cum_ke[:-1]])
    m = jnp.maximum(jnp.sum(h < W), 1)
    den = cum_k[m - 1]
    return (W + cum_ke[m - 1]) / jnp.where(den > 0.0, den, 1.0), den > 0.0


def line_load_traced(pair: InvolutePair, face_width, mods: PairModification, torque_Nmm,
                     misalignment_um_, opts: LineLoadOptions, E=E_STEEL, nu=NU_STEEL,
                     drive=True, s0=None) -> LineLoad:
    """The loaded line contact of ``pair`` (traceable; module docstring).

    face_width (mm); mods: the two flanks in mesh; torque_Nmm: pinion torque (> 0);
    misalignment_um_: ``f_ma`` (µm); E (MPa), nu: both members' material; ``s0``
    (optional, (M,) mm): the mesh positions, instead of ``opts.positions`` spread
    evenly over one base pitch from ``s_A``.
    """
    geo = pair_geometry(pair)
    b = jnp.asarray(face_width, float)
    rb1, rb2 = geo["rb1"], geo["rb2"]
    beta_b = geo["beta_b"]
    cb, tb = jnp.cos(beta_b), jnp.tan(beta_b)
    g = geo["a_w"] * jnp.sin(geo["alpha_wt"])
    rho_P, rho_A, rho_E = geo["rho_P"], geo["rho_A"], geo["rho_E"]
    s_A, s_E = rho_A - rho_P, rho_E - rho_P
    p_bt = 2.0 * jnp.pi * rb1 / pair.z1
    N = opts.slices
    ks = jnp.arange(opts.k_lo, opts.k_hi + 1, dtype=float)
    if s0 is None:
        s0 = s_A + p_bt * jnp.arange(opts.positions) / opts.positions
    s0 = jnp.asarray(s0, float)
    M = s0.shape[0]
    dy = b / N
    y = -0.5 * b + dy * (jnp.arange(N) + 0.5)
    sc = s0[None, :, None] + ks[:, None, None] * p_bt + (y * tb)[None, None, :]
    # the part of each slice's contact-line piece on the path [s_A, s_E]
    half = 0.5 * dy * tb
    lo = jnp.maximum(sc - half, s_A)
    hi = jnp.minimum(sc + half, s_E)
    frac = jnp.where(half > 0.0, jnp.clip((hi - lo) / jnp.where(half > 0.0, 2.0 * half, 1.0),
                                          0.0, 1.0),
                     ((sc >= s_A) & (sc <= s_E)).astype(float))
    length = frac * dy / cb
    on = length > 0.0           # (not frac > 0: a sliver's length may round to 0)
    s = jnp.where(on, jnp.where(half > 0.0, 0.5 * (lo + hi), sc), 0.5 * (s_A + s_E))
    yy = jnp.broadcast_to(y, s.shape)
    xi1 = rho_P + s
    xi2 = g - xi1
    e_um = (flank_removal_um(mods.pinion, xi1, yy, rho_A, rho_E, b)
            + flank_removal_um(mods.gear, xi2, yy, g - rho_E, g - rho_A, b)
            + misalignment_um(misalignment_um_, yy, b))
    e = jnp.where(on, 1e-3 * e_um, _FAR)
    # compliance of a unit-length piece at each point (mm/N per mm of line)
    T1 = jnp.asarray(torque_Nmm, float)
    w_nom = T1 / (rb1 * b)
    unit = jnp.ones(s.size)
    teeth = virtual_teeth(pair, jnp.sqrt(rb1 ** 2 + xi1 ** 2).ravel(),
                          jnp.sqrt(rb2 ** 2 + xi2 ** 2).ravel(), unit, unit, drive)
    r_n = xi1 * xi2 / ((xi1 + xi2) * cb)          # reduced radius of the normal section
    q_unit = pair_compliance(teeth, r_n.ravel(), w_nom, opts.compliance, E=E,
                             nu=nu).reshape(s.shape)
    k = jnp.where(on, length / q_unit, 0.0)
    W = T1 / (rb1 * cb ** 2)
    # per position: points of all pairs and slices together
    e_pos = jnp.moveaxis(e, 1, 0).reshape(M, -1)
    k_pos = jnp.moveaxis(k, 1, 0).reshape(M, -1)
    delta, some = jax.vmap(_solve, in_axes=(0, 0, None))(e_pos, k_pos, W)
    if opts.coupling_length > 0.0:
        # Pasternak foundation along each pair's face (face_coupling); links per pair
        link = face_links(jnp.where(on, dy / (cb * q_unit), 0.0), frac, dy,
                          opts.coupling_length)
        link_pos = jnp.moveaxis(link, 1, 0).reshape(M, -1)
        sol = jax.vmap(lambda e_, k_, c_, d_: coupled_solve(e_, k_, c_, W, d_,
                                                            opts.coupling_steps))(
            e_pos, k_pos, link_pos, delta)
        delta = sol.delta
        F = jnp.moveaxis(sol.load.reshape(M, k.shape[0], N), 0, 1) * cb
        gap = jnp.moveaxis(sol.w.reshape(M, k.shape[0], N), 0, 1) + e - delta[None, :, None]
        slope = sol.slope
        comp_res = sol.residual
        solved = sol.converged
    else:
        F = k * jnp.maximum(delta[None, :, None] - e, 0.0) * cb
        gap = jnp.maximum(e - delta[None, :, None], 0.0)
        slope = jnp.sum(jnp.where(F > 0.0, k, 0.0), axis=(0, 2))
        comp_res = jnp.zeros(M)
        solved = True
    balance = jnp.abs(jnp.sum(F, axis=(0, 2)) * rb1 * cb / T1 - 1.0)
    converged = some & (balance <= BALANCE_TOL) & solved
    w_line = jnp.where(on, F / jnp.where(on, length, 1.0), 0.0)
    E_prime = E / (1.0 - nu ** 2)
    loaded = F > 0.0
    half_w, p = hertz_line_traced(jnp.where(loaded, w_line, 1.0), r_n, E_prime)
    p_max = jnp.where(loaded, p, 0.0)
    stiff = cb ** 2 * slope / b * 1e-3
    face = jnp.sum(F, axis=0) / dy                    # (M, N) normal load per face width
    mean_face = jnp.mean(face, axis=1)
    k_hb = jnp.max(face, axis=1) / mean_face
    cyc = jnp.mean(face, axis=0)
    return LineLoad(s0=s0, y=y, s=sc, contact_s=s, r_x=r_n, length=length,
                    separation_um=jnp.where(on, e_um, jnp.nan), load=F, line_load=w_line,
                    p_max=p_max, pair_load=jnp.sum(F, axis=2), te_loaded_um=1e3 * delta,
                    te_unloaded_um=1e3 * jnp.min(e_pos, axis=1), mesh_stiffness=stiff,
                    face_load=face, k_hbeta=k_hb, k_hbeta_mean=jnp.max(cyc) / jnp.mean(cyc),
                    end_load=jnp.maximum(face[:, 0], face[:, -1]) / mean_face,
                    end_load_mean=jnp.maximum(cyc[0], cyc[-1]) / jnp.mean(cyc),
                    n_points=jnp.sum(loaded, axis=(0, 2)), balance=balance,
                    converged=converged, gap_um=jnp.where(on, 1e3 * gap, jnp.nan),
                    complementarity=comp_res)


def smooth_ptp(x, temperature):
    """Smooth peak-to-peak of ``x`` (1-D): ``T logsumexp(x/T) + T logsumexp(-x/T)``, an
    upper bound of ``max - min`` by at most ``2 T log(len(x))`` (same units as ``x``
    and ``T``), differentiable everywhere."""
    x = jnp.asarray(x, float)
    return temperature * (jax.nn.logsumexp(x / temperature)
                          + jax.nn.logsumexp(-x / temperature))
