"""Computational grid and elastic deformation of the EHL point-contact solver.

Dimensionless coordinates (Hertz semi-axes of :mod:`gearjax.contact`): ``X = x/b``
along the rolling axis of the ellipse (radius Rx, semi-axis b), ``Y = y/a`` along
the transverse axis (radius Ry, semi-axis a), so the Hertz ellipse is the unit
circle.  Cell-centred nodes, ``N_x x N_y`` of them, with ``P = 0`` one spacing
beyond the edges.

Elastic deformation of the half-space (Love 1929; Johnson, *Contact Mechanics*,
1985, §3.9): a uniform pressure on a rectangle ``|x'| <= h_x, |y'| <= h_y`` gives

    ∫∫ dA'/r = f(x+h_x, y+h_y) - f(x-h_x, y+h_y) - f(x+h_x, y-h_y) + f(x-h_x, y-h_y),
    f(u, v) = u asinh(v/|u|) + v asinh(u/|v|),

and ``w = (2/(π E')) Σ_j p_j ∫∫_j dA'/r``.  The discrete convolution with these
influence coefficients is evaluated exactly (no periodic wrap-around) by the
DC-FFT method (Liu, Wang & Liu, Wear 243 (2000) 101–111): kernel and pressure are
zero-padded to ``2N_x x 2N_y`` and multiplied in Fourier space.

Coefficients are computed in units of b with the cell ``ΔX x kΔY`` (k = a/b), in
JAX so that derivatives with respect to k (radii, load) flow through them.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp
import numpy as np

__all__ = ["EHLGrid", "make_grid", "influence_kernel", "deformation", "default_domain"]


@dataclasses.dataclass(frozen=True)
class EHLGrid:
    """Static grid description (hashable; pass as a static argument).

    nx, ny : nodes along X (rolling axis) and Y (transverse axis).
    x_lo, x_hi, y_lo, y_hi : domain edges in units of b (X) and a (Y); nodes sit at
        cell centres, the pressure is zero on the edges.
    upwind : weight β of the second-order correction of the upwind Couette fluxes
        (:func:`gearjax.tribology.ehl.model.reynolds_operator`): 0 first-order upwind
        (default), 1 second-order upwind, in between a blend.
    limiter : ``"none"`` (the correction as it stands) or ``"van_albada"`` (the
        correction slope limited by van Albada's smooth limiter; see
        :func:`gearjax.tribology.ehl.model.van_albada`).
    """

    nx: int
    ny: int
    x_lo: float
    x_hi: float
    y_lo: float
    y_hi: float
    upwind: float = 0.0
    limiter: str = "none"

    @property
    def dx(self) -> float:
        return (self.x_hi - self.x_lo) / self.nx

    @property
    def dy(self) -> float:
        return (self.y_hi - self.y_lo) / self.ny

    def nodes(self):
        """Node coordinates (X, Y) as NumPy arrays of shape (ny, nx) (rows = Y)."""
        x = self.x_lo + (np.arange(self.nx) + 0.5) * self.dx
        y = self.y_lo + (np.arange(self.ny) + 0.5) * self.dy
        return np.meshgrid(x, y)


def default_domain(angle_deg: float):
    """Domain edges for entrainment at ``angle_deg`` to the X axis.

    Inlet length 3.0 semi-axes upstream of a 1.5-semi-axis box (Venner &
    Lubrecht's X ∈ [-4.5, 1.5] for angle 0), the side walls at ±(1.5 + 1.0) on the
    cross-flow axis, rotated continuously with the entrainment direction.
    """
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    bx = 1.5 + 1.0 * abs(s)
    by = 1.5 + 1.0 * abs(c)
    return (-(bx + 3.0 * max(c, 0.0)), bx + 3.0 * max(-c, 0.0),
            -(by + 3.0 * max(s, 0.0)), by + 3.0 * max(-s, 0.0))


def make_grid(n: int, angle_deg: float = 0.0, ny: int | None = None, domain=None,
              upwind: float = 0.0, limiter: str = "none") -> EHLGrid:
    """Grid with ``n`` nodes along X (``ny`` along Y, default ``n``), ``default_domain``;
    ``upwind`` the second-order upwind weight β in [0, 1] and ``limiter`` ("none" or
    "van_albada") of its correction (see :class:`EHLGrid`)."""
    for name, v in (("n", n), ("ny", n if ny is None else ny)):
        if not (isinstance(v, (int, np.integer)) and 8 <= v <= 4096):
            raise ValueError(f"grid {name} = {v!r} is outside the allowed range [8, 4096] "
                             "(integer)")
    dom = default_domain(angle_deg) if domain is None else tuple(float(d) for d in domain)
    if not (dom[0] < -1.0 and dom[1] > 1.0 and dom[2] < -1.0 and dom[3] > 1.0):
        raise ValueError(f"domain = {dom} must contain the Hertz ellipse: x_lo < -1 < 1 < x_hi "
                         "and y_lo < -1 < 1 < y_hi")
    if not (isinstance(upwind, (int, float, np.integer, np.floating)) and 0.0 <= upwind <= 1.0):
        raise ValueError(f"upwind = {upwind!r} is outside the allowed range [0, 1] (0: first-"
                         "order upwind, 1: second-order upwind)")
    if limiter not in LIMITERS:
        raise ValueError(f"limiter = {limiter!r} must be one of {LIMITERS}")
    return EHLGrid(int(n), int(n if ny is None else ny), *dom, float(upwind), limiter)


LIMITERS = ("none", "van_albada")


def _f(u, v):
    # u, v are never 0 on the corners (cell offsets are (n ± 1/2) spacings)
    return u * jnp.arcsinh(v / jnp.abs(u)) + v * jnp.arcsinh(u / jnp.abs(v))


def influence_kernel(grid: EHLGrid, k):
    """DC-FFT kernel: ∫∫ dA'/r (units of b) of unit pressure on one cell, wrapped on 2N.

    Returns the real array of shape (2 ny, 2 nx) whose entry at offset
    (m, n) (negative offsets wrapped to the end, the Nyquist row/column zero) is
    the deflection at offset (m ΔY, n ΔX) of the cell at the origin.
    """
    hx = 0.5 * grid.dx
    hy = 0.5 * grid.dy * k
    ox = np.concatenate([np.arange(grid.nx), [0], np.arange(-grid.nx + 1, 0)]) * grid.dx
    oy = np.concatenate([np.arange(grid.ny), [0], np.arange(-grid.ny + 1, 0)]) * grid.dy
    x = jnp.asarray(ox)[None, :]
    y = jnp.asarray(oy)[:, None] * k
    K = _f(x + hx, y + hy) - _f(x - hx, y + hy) - _f(x + hx, y - hy) + _f(x - hx, y - hy)
    mask = np.ones((2 * grid.ny, 2 * grid.nx))
    mask[grid.ny, :] = 0.0
    mask[:, grid.nx] = 0.0
    return K * mask


def deformation(P, kernel_hat, grid: EHLGrid):
    """Linear (non-periodic) convolution Σ_j K_ij P_j by zero-padded FFT; P (ny, nx)."""
    Pp = jnp.zeros((2 * grid.ny, 2 * grid.nx), P.dtype).at[:grid.ny, :grid.nx].set(P)
    w = jnp.fft.irfft2(jnp.fft.rfft2(Pp) * kernel_hat, s=Pp.shape)
    return w[:grid.ny, :grid.nx]
