"""Consecutive tooth pairs of a TCA and their unloaded TE envelope (traceable).

Pair ``k`` is pair 0's contact path shifted by ``k`` angular pitches of the pinion
(``steps_per_pitch`` grid steps); at each pinion angle the pair that carries the contact
is the one furthest ahead in the sense of the load (drive: the largest TE, coast: the
smallest), and the envelope of those TEs is the unloaded transmission error of the mesh
([Litvin2004] ch. 9).  Split out of :mod:`gearjax.tca.path` (which re-exports every name
here); the contact path itself is solved there.
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

__all__ = ["MultiPair", "multi_pair", "pair_arrays", "interp_uniform", "flank_crossings",
           "transfer_gaps"]


class MultiPair(NamedTuple):
    """Consecutive tooth pairs and the unloaded TE envelope (over the grid of one pair).

    te_pairs : (K, N) TE of pairs k = -(K//2) .. K//2 on the common grid (rad);
        pair k is pair 0 shifted by k pinion pitches, NaN where that pair is not on
        the flank (edge/no contact) or outside the computed range.
    inside : (K, N) pair k has a valid contact inside both flank boundaries.
    envelope : (N,) unloaded TE: max over pairs in contact (drive) or min (coast).
    active : (N,) index (into ``te_pairs``) of the pair carrying the contact.
    ptp : peak-to-peak of the envelope over one pitch around the reference (rad).
    transfer_phi1 : (2,) pinion angles of the transfer points into / out of pair 0
        (linear interpolation between grid points; NaN if none).
    contact_ratio : length of the pinion-angle interval in which pair 0 is on the
        flank, divided by the angular pitch 2 pi/z1 (boundary crossings
        interpolated linearly in the boundary margin); NaN (not found) unless pair 0
        enters the flanks before it leaves them within the grid.
    pitch : the pinion's angular pitch 2 pi/z1 (rad).
    sign : +1 where the envelope is the maximum over the pairs (the flank pushing the
        gear forward), -1 where it is the minimum.
    """

    te_pairs: jnp.ndarray
    inside: jnp.ndarray
    envelope: jnp.ndarray
    active: jnp.ndarray
    ptp: jnp.ndarray
    transfer_phi1: jnp.ndarray
    contact_ratio: jnp.ndarray
    pitch: jnp.ndarray = float("nan")
    sign: jnp.ndarray = 1.0


def _crossing(phi, f):
    """Linear-interpolated first sign change of ``f`` from <0 to >=0 along ``phi`` (NaN if none)."""
    neg = f[:-1] < 0.0
    pos = f[1:] >= 0.0
    hit = neg & pos
    idx = jnp.argmax(hit)
    t = f[idx] / (f[idx] - f[idx + 1])
    val = phi[idx] + t * (phi[idx + 1] - phi[idx])
    return jnp.where(jnp.any(hit), val, jnp.nan)


def pair_arrays(arr, steps_per_pitch: int, n_pairs: int, fill, window):
    """Values of tooth pairs ``k = -(K//2) .. K//2`` at the grid positions ``window``.

    ``arr`` : (N, ...) a quantity of tooth pair 0 on the uniform TCA grid (pair k is
    pair 0 shifted by k pinion pitches = ``k * steps_per_pitch`` grid steps, as in
    :func:`multi_pair`).  Returns (K, len(window), ...), ``fill`` where
    the shifted index falls outside the grid.
    """
    n = arr.shape[0]
    ks = np.arange(n_pairs) - n_pairs // 2
    window = np.asarray(window)
    out = []
    for k in ks:
        src = window - k * steps_per_pitch
        ok = (src >= 0) & (src < n)
        v = arr[np.clip(src, 0, n - 1)]
        okb = ok.reshape(ok.shape + (1,) * (v.ndim - 1))
        out.append(jnp.where(okb, v, fill))
    return jnp.stack(out)


def multi_pair(path, margin, steps_per_pitch: int, z1: int, drive: bool = True,
               n_pairs: int = 3) -> MultiPair:
    """Shift pair 0 by whole pitches and form the unloaded TE envelope (traceable).

    ``path`` : the :class:`~gearjax.tca.path.ContactPath` of pair 0.  Its grid
    ``path.phi1`` must be uniform with step ``2 pi/(z1 steps_per_pitch)`` so that a
    shift by one pitch is a shift by ``steps_per_pitch`` grid indices (no
    interpolation of the TE curves).  ``margin`` : (N,) boundary margin of pair 0
    (>= 0 inside both flanks, mm).  ``drive`` chooses the max (drive) or min (coast)
    envelope (the flank pushing the gear decides its position).
    """
    n = path.phi1.shape[0]
    mid = n // 2
    m = steps_per_pitch
    inside0 = (margin >= 0.0) & path.converged
    te0 = jnp.where(inside0, path.te, jnp.nan)
    idx = np.arange(n)
    te_pairs = pair_arrays(te0, m, n_pairs, jnp.nan, idx)
    inside = pair_arrays(inside0, m, n_pairs, False, idx)
    sgn = jnp.where(drive, 1.0, -1.0)        # ``drive`` may be traced
    key = jnp.where(inside, sgn * te_pairs, -jnp.inf)
    active = jnp.argmax(key, axis=0)
    env = sgn * jnp.max(key, axis=0)
    window = np.abs(idx - mid) <= m // 2
    ew = jnp.where(window & jnp.isfinite(env), env, jnp.nan)
    ptp = jnp.nanmax(ew) - jnp.nanmin(ew)
    k0 = n_pairs // 2
    # transfer from pair -1 (earlier tooth) to pair 0 and from pair 0 to pair +1:
    # sign change of the TE difference where both are on the flank, else of who is on
    def lead(a, b):
        both = inside[a] & inside[b]
        return jnp.where(both, sgn * (jnp.nan_to_num(te_pairs[a]) - jnp.nan_to_num(te_pairs[b])),
                         jnp.where(inside[a], 1.0, -1.0))

    d_in = lead(k0, k0 - 1)
    d_out = lead(k0 + 1, k0)
    transfer = jnp.stack([_crossing(path.phi1, d_in), _crossing(path.phi1, d_out)])
    lo = _crossing(path.phi1, jnp.where(path.converged, margin, -1.0))
    hi = _crossing(path.phi1[::-1], jnp.where(path.converged, margin, -1.0)[::-1])
    # not found (NaN) unless pair 0 enters before it leaves: where it touches in several
    # intervals that reach the ends of the grid, its first entry may follow its last exit
    cr = jnp.where(hi > lo, (hi - lo) / (2.0 * jnp.pi / z1), jnp.nan)
    return MultiPair(te_pairs, inside, env, active, ptp, transfer, cr,
                     jnp.asarray(2.0 * np.pi / z1), sgn)


def interp_uniform(x0, h, f, x):
    """Quadratic (3-point Lagrange) interpolation of samples ``f`` on the uniform grid
    ``x0 + h i`` at ``x`` (the stencil's index carries no derivative)."""
    n = f.shape[0]
    i = jnp.clip(jnp.round(jax.lax.stop_gradient((x - x0) / h)).astype(int), 1, n - 2)
    s = (x - x0) / h - i
    return (f[i - 1] * 0.5 * s * (s - 1.0) + f[i] * (1.0 - s * s)
            + f[i + 1] * 0.5 * s * (s + 1.0))


def flank_crossings(path, margin):
    """``(phi_in, phi_out)``: pinion angles where pair 0's boundary margin crosses zero
    entering and leaving the flanks (bracketed on the grid, then two Newton steps on the
    quadratic interpolant of the margin: error O(h^3); NaN if none).  Traceable."""
    phi = path.phi1
    m = jnp.where(path.converged, margin, -1.0)
    h = phi[1] - phi[0]

    def refine(x):
        for _ in range(2):
            mx, dm = jax.jvp(lambda y: interp_uniform(phi[0], h, m, y), (x,),
                             (jnp.ones_like(x),))
            x = x - mx / dm
        return x

    return refine(_crossing(phi, m)), refine(_crossing(phi[::-1], m[::-1]))


def transfer_gaps(path, margin, multi: MultiPair):
    """``(gap_in, gap_out)`` (rad): the TE gaps where tooth pair 0 enters and leaves the
    flanks (traceable).

    Where pair 0 enters (``phi_in``, :func:`flank_crossings`) pair -1 -- pair 0 one
    pitch ``p`` later, ``TE_{-1}(phi) = TE_0(phi + p)`` -- carries the motion, where it
    leaves pair +1 (``TE_0(phi - p)``); with ``s = multi.sign``::

        gap_in  = s (TE_0(phi_in)  - TE_0(phi_in + p)),
        gap_out = s (TE_0(phi_out) - TE_0(phi_out - p)).

    ``> 0``: the TE envelope jumps at the transfer (the entering pair is ahead of the
    one carrying the load, or the leaving one runs off its flank while still ahead);
    ``< 0``: the TE curves cross inside the overlap (a smooth transfer, the gap its
    reserve).  TE of pair 0 between grid points by quadratic interpolation of the
    contact path's TE, which continues beyond the flank boundaries (the surfaces are
    extended there), so it is smooth across them."""
    phi = path.phi1
    h = phi[1] - phi[0]
    a, b = flank_crossings(path, margin)
    p, s = multi.pitch, multi.sign

    def te0(x):
        return interp_uniform(phi[0], h, path.te, x)

    return s * (te0(a) - te0(a + p)), s * (te0(b) - te0(b - p))
