"""Coupling along the face of the thin-slice line contact: a Pasternak (two-parameter)
elastic foundation per tooth pair, and the contact problem it poses at one mesh position.

**The foundation** ([Pasternak1954]; for a gear tooth [AjmiVelex2005]).  The deflection
``w(y)`` (mm, along the line of action) of one tooth pair's slices along the face obeys

    k(y) w - d/dy (G dw/dy) = q(y),        dw/dy = 0 at y = +-b/2 (free ends),

``q`` the load per unit face width (N/mm), ``k`` the Winkler stiffness per unit face
width of the thin-slice model (N/mm^2: :mod:`gearjax.gears.involute.line_load`) and ``G``
the shear-coupling stiffness (N), set by a coupling length ``lambda`` as ``G = lambda^2
k``: a load concentrated at one point of a long uniform face deflects it as
``exp(-|y|/lambda)``.  ``lambda = 0`` is the Winkler foundation (independent slices).

**Discretisation** (finite volumes on the slices of width ``dy``): integrating over
slice ``i`` of pair ``p``,

    k_i w_i + c_{i-1/2} (w_i - w_{i-1}) + c_{i+1/2} (w_i - w_{i+1}) = P_i,
    c_{i+1/2} = lambda^2 (kf_i + kf_{i+1}) / (2 dy^2),

``k_i`` the slice stiffness (N/mm), ``kf_i = dy / (cos(beta_b) q'_i)`` that of a whole
slice piece at the same point of the path (the mean of the two slices' per-width
stiffness times ``lambda^2`` is ``G`` on the face between them) and ``P_i`` the slice
load (N).  A piece only partly on the path (the fraction ``f_i`` at a tip circle) links
with the factor ``min(f_i, f_{i+1})``: a piece entering the path enters the coupling
with its length, so the loads stay continuous in the mesh position (a sliver is not
handed a finite share of its neighbour's load).  A link exists only between
neighbouring slices of the SAME tooth pair that both lie on the path; the end of a
contact line (a face end, or where a helical line leaves the path at a tip circle) has
no outer link: the free end ``dw/dy = 0``.  The
matrix ``A = diag(k) + L`` (``L`` the weighted graph Laplacian of the links) is a
symmetric, diagonally dominant M-matrix, tridiagonal in the pair-major order of the
points, block-diagonal per pair.

**Concentrated forces.**  Where a compressed end of a contact line has a slope (a
linearly misaligned flank), the continuous problem carries a concentrated end force
``G |dw/dy|`` at that end (the shear of the coupling layer stops there), and at a kink
of the separation along a line in contact (the start of a linear relief) the force
``G |jump of de/dy|``.  The discrete model puts each in the slice (or the two slices)
holding it (the end slice's load has ``c_{1/2} (w_0 - w_1)``), so that slice's line
load, and the p_max and K_Hbeta read from it, grow as the slices narrow, while the
forces themselves, the approach and the loads inside converge (docs/microgeometry.md).

**Contact** at one mesh position: with the unloaded separations ``e_j`` and the approach
``delta``, the gap ``g_j = w_j + e_j - delta`` and the loads satisfy

    A w = P,   P >= 0,   g >= 0,   P_j g_j = 0,   sum_j P_j = W,

a linear complementarity problem (the obstacle problem ``min w'Aw/2, w >= delta - e``
with its multiplier ``P``, plus the force balance that fixes ``delta``).  For an active
set ``S`` the equations ``w_j = delta - e_j`` (j in S) and ``(A w)_j = 0`` (j not in S)
are tridiagonal: ``w = w0 + delta w1`` from two Thomas solves, and since ``A``'s column
sums are ``k``, ``sum_j P_j = sum_j k_j w_j = W`` gives ``delta = (W - k.w0) / k.w1``.
The active set is found by the primal-dual active-set iteration (drop the points of
``S`` with a tensile load, add the points outside with a negative gap), started from the
Winkler solution, inside a ``lax.while_loop`` of at most ``steps`` iterations on values
without derivatives; the final set's system is then solved again on the live inputs, so
the derivatives with respect to every design field are those of the active piece, exact
(the same piecewise-smooth behaviour as the Winkler model).  ``converged`` requires the
set to have stopped changing within ``steps`` and the complementarity residual
(:func:`coupled_solve`) to be below :data:`COMPLEMENTARITY_TOL`.

Units: mm, N.  References (docs/references.md): [Pasternak1954]; [AjmiVelex2005].
"""

from __future__ import annotations

from typing import NamedTuple

import jax
import jax.numpy as jnp

__all__ = ["CoupledSolution", "coupled_solve", "face_links", "tridiagonal_solve",
           "COMPLEMENTARITY_TOL", "ACTIVE_SET_STEPS"]

#: largest complementarity residual of a converged position (relative, see coupled_solve)
COMPLEMENTARITY_TOL = 1e-9
#: default cap of the active-set iterations
ACTIVE_SET_STEPS = 64


class CoupledSolution(NamedTuple):
    """The coupled contact at one mesh position (shapes (n,) per point).

    delta : approach (mm).  w : deflections (mm).  load : slice loads ``P`` (N; 0 off the
    active set).  active : the final active set.  slope : ``dW/d delta`` of the active
    piece (N/mm).  residual : complementarity residual, ``max(max_j(-P_j)/W,
    max_j(-g_j)/c)`` with ``c = delta - min_j e_j`` the compression.  steps : active-set
    iterations.  converged : the set stopped changing and ``residual`` <=
    :data:`COMPLEMENTARITY_TOL`.
    """

    delta: jax.Array
    w: jax.Array
    load: jax.Array
    active: jax.Array
    slope: jax.Array
    residual: jax.Array
    steps: jax.Array
    converged: jax.Array


def face_links(k_full, share, dy, coupling_length):
    """Link conductances ``c_{i+1/2}`` (N/mm) between slice ``i`` and ``i + 1`` of each
    tooth pair (module docstring): ``k_full`` (..., N) whole-piece slice stiffnesses
    (N/mm), ``share`` (..., N) the part of each slice's piece on the path (0..1); the
    last slice's entry is 0 (no link to the next pair)."""
    both = jnp.minimum(share[..., :-1], share[..., 1:])
    c = coupling_length ** 2 * 0.5 * (k_full[..., :-1] + k_full[..., 1:]) / dy ** 2
    c = jnp.where(both > 0.0, c * both, 0.0)
    return jnp.concatenate([c, jnp.zeros(c.shape[:-1] + (1,))], axis=-1)


def tridiagonal_solve(lower, diag, upper, rhs):
    """``x`` with ``lower_j x_{j-1} + diag_j x_j + upper_j x_{j+1} = rhs_j`` (Thomas
    algorithm, no pivoting: for diagonally dominant systems); ``rhs`` (n, m)."""
    def forward(carry, row):
        c_prev, r_prev = carry
        lo, d, up, r = row
        den = d - lo * c_prev
        c = up / den
        rr = (r - lo * r_prev) / den
        return (c, rr), (c, rr)

    m = rhs.shape[1]
    _, (cs, rs) = jax.lax.scan(forward, (jnp.zeros(()), jnp.zeros(m)),
                               (lower, diag, upper, rhs))

    def backward(x_next, row):
        c, r = row
        x = r - c * x_next
        return x, x

    _, xs = jax.lax.scan(backward, jnp.zeros(m), (cs, rs), reverse=True)
    return xs


def _apply(k, link, w):
    """``A w`` (module docstring)."""
    prev = jnp.concatenate([jnp.zeros(1), link[:-1]])
    w_next = jnp.concatenate([w[1:], jnp.zeros(1)])
    w_prev = jnp.concatenate([jnp.zeros(1), w[:-1]])
    return k * w + link * (w - w_next) + prev * (w - w_prev)


def _active_solve(active, e, k, link, on, W):
    """``(delta, w, P, dW/ddelta)`` of the active set ``active`` (module docstring)."""
    prev = jnp.concatenate([jnp.zeros(1), link[:-1]])
    d = jnp.where(on, k + link + prev, 1.0)
    diag = jnp.where(active, 1.0, d)
    upper = jnp.where(active, 0.0, -link)
    lower = jnp.where(active, 0.0, -prev)
    rhs = jnp.stack([jnp.where(active, -e, 0.0), active.astype(float)], axis=1)
    x = tridiagonal_solve(lower, diag, upper, rhs)
    w0, w1 = x[:, 0], x[:, 1]
    slope = jnp.sum(k * w1)
    ok = slope > 0.0
    delta = (W - jnp.sum(k * w0)) / jnp.where(ok, slope, 1.0)
    w = w0 + delta * w1
    P = jnp.where(active, _apply(k, link, w), 0.0)
    return delta, w, P, slope


def coupled_solve(e, k, link, W, delta0, steps=ACTIVE_SET_STEPS) -> CoupledSolution:
    """The coupled contact of one mesh position (module docstring).

    e (n,) separations (mm; points off the path: a large value and ``k = 0``), k (n,)
    slice stiffnesses (N/mm), link (n,) link conductances (:func:`face_links`, N/mm,
    flattened pair-major), W the load to carry (N), delta0 the Winkler approach (the
    first active set is ``delta0 > e``), steps the iteration cap (static).
    """
    on = k > 0.0
    sg = jax.lax.stop_gradient
    e_, k_, link_, W_ = sg(e), sg(k), sg(link), sg(W)
    tol_g = 1e-14 * jnp.maximum(jnp.max(jnp.where(on, jnp.abs(e_), 0.0)), 1e-3)

    def update(active):
        delta, w, P, _ = _active_solve(active, e_, k_, link_, on, W_)
        g = w + e_ - delta
        return on & jnp.where(active, P >= 0.0, g < -tol_g)

    def cond(state):
        _, it, stable = state
        return (~stable) & (it < steps)

    def body(state):
        active, it, _ = state
        new = update(active)
        return new, it + 1, jnp.all(new == active)

    start = on & (sg(delta0) > e_)
    active, it, stable = jax.lax.while_loop(cond, body, (start, jnp.asarray(0),
                                                         jnp.asarray(False)))
    delta, w, P, slope = _active_solve(active, e, k, link, on, W)
    g = jnp.where(on, w + e - delta, 0.0)
    comp = jnp.maximum(delta - jnp.min(jnp.where(on, e, jnp.inf)), 1e-30)
    residual = jnp.maximum(jnp.max(jnp.maximum(-P, 0.0)) / W,
                           jnp.max(jnp.maximum(-g, 0.0)) / comp)
    residual = sg(residual)
    ok = stable & (residual <= COMPLEMENTARITY_TOL) & (slope > 0.0)
    return CoupledSolution(delta, w, P, active, slope, residual, it, ok)
