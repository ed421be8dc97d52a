"""Matplotlib figures for friction studies (Stribeck curves, μ along a mesh cycle).

Figures are built with the object API (``matplotlib.figure.Figure`` + Agg canvas),
never ``pyplot``, so they work headless and never open windows.  Files are written
atomically (:func:`save_figure_atomic`, 150 dpi); report size and fonts of
:mod:`gearjax.plot.style` (7.5 x 4.8 in, fonts >= 9 pt).
"""

from __future__ import annotations

import os

import numpy as np

from gearjax.plot.style import DPI, MIN_WIDTH_IN, report_style

__all__ = ["stribeck_figure", "mesh_friction_figure", "save_figure_atomic"]


def _figure(size=(MIN_WIDTH_IN + 0.5, 4.8)):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def stribeck_figure(curves, labels=None, x="stribeck", title=None):
    """Stribeck curves μ(x) on a log x axis.

    ``curves``: sequence of :class:`gearjax.tribology.losses.StribeckCurve`;
    ``x``: ``"stribeck"`` (η0 u_e/F_n, 1/m), ``"lambda"`` (smooth-surface λ_s) or
    ``"speed"`` (u_e, m/s).  Regime bands (from the first curve's asperity load ratio)
    are shaded.  Returns the Figure.
    """
    with report_style():
        return _stribeck(curves, labels, x, title)


def _stribeck(curves, labels, x, title):
    from matplotlib.patches import Patch

    fig = _figure()
    ax = fig.add_subplot()
    labels = labels or [None] * len(curves)
    for c, lab in zip(curves, labels):
        xs = {"stribeck": np.asarray(c.stribeck_number), "lambda": np.asarray(c.lam),
              "speed": np.asarray(c.u_e) * 1e-3}[x]
        ax.semilogx(xs, np.asarray(c.mu), marker=".", label=lab)
    if curves:
        c = curves[0]
        xs = {"stribeck": np.asarray(c.stribeck_number), "lambda": np.asarray(c.lam),
              "speed": np.asarray(c.u_e) * 1e-3}[x]
        reg = np.asarray(c.friction.regime)
        colors = {0: "#f4cccc", 1: "#fff2cc", 2: "#d9ead3"}
        order = np.argsort(xs)
        xo, ro = xs[order], reg[order]
        mid = np.sqrt(xo[1:] * xo[:-1])  # band edges half-way (log scale) between samples
        edges = np.concatenate([[xo[0]], mid, [xo[-1]]])
        for i, code in enumerate(ro):
            ax.axvspan(edges[i], edges[i + 1], color=colors[int(code)], alpha=0.5, lw=0)
        names = {0: "boundary", 1: "mixed", 2: "full film"}
        regime_patches = [Patch(color=colors[g], alpha=0.5, label=f"{names[g]} regime")
                          for g in sorted({int(g) for g in ro})]
    else:
        regime_patches = []
    ax.set_xlabel({"stribeck": r"$\eta_0 u_e / F_n$ (1/m)", "lambda": r"$\lambda_s = h_{c,smooth}/\sigma$",
                   "speed": r"$u_e$ (m/s)"}[x])
    ax.set_ylabel(r"friction coefficient $\mu$")
    ax.set_ylim(bottom=0)
    ax.grid(True, which="both", alpha=0.3)
    handles, _ = ax.get_legend_handles_labels()
    if handles or regime_patches:
        ax.legend(handles=handles + regime_patches, loc="best")
    ax.set_title(title or "Stribeck curve (lubrication regimes shaded)")
    return fig


def mesh_friction_figure(position, mu, power_loss_W=None, title=None,
                         xlabel="mesh position: pinion angle (rad)"):
    """μ (per contact point) and optionally the power loss along a mesh cycle.

    ``position``: (n_positions,) mesh position (e.g. pinion angle, rad; name it and
    its unit in ``xlabel``); ``mu``: (n_positions, n_points), zeros for inactive
    points are not drawn.
    """
    with report_style():
        return _mesh_friction(position, mu, power_loss_W, title, xlabel)


def _mesh_friction(position, mu, power_loss_W, title, xlabel):
    fig = _figure()
    ax = fig.add_subplot()
    mu = np.asarray(mu, float)
    for j in range(mu.shape[1]):
        m = np.where(mu[:, j] > 0, mu[:, j], np.nan)
        ax.plot(position, m, marker=".", label=f"point {j}")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(r"friction coefficient $\mu$")
    if power_loss_W is not None:
        ax2 = ax.twinx()
        ax2.plot(position, np.asarray(power_loss_W), "k--", label="power loss")
        ax2.set_ylabel("power loss (W)")
    ax.legend(loc="upper left")
    ax.set_title(title or "friction along the mesh cycle")
    return fig


def save_figure_atomic(fig, path, dpi=DPI):
    """Save ``fig`` to ``path`` atomically (temp file in the same directory, then
    ``os.replace``; see :func:`gearjax.io.atomic_write`)."""
    import io as _io

    from gearjax.io import atomic_write

    path = os.fspath(path)
    ext = os.path.splitext(path)[1] or ".png"
    buf = _io.BytesIO()
    with report_style():
        fig.savefig(buf, dpi=dpi, format=ext.lstrip("."))
    atomic_write(path, buf.getvalue())
    return path
