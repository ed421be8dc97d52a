"""Axial-plane view of a bevel/hypoid flank grid (matplotlib, saved atomically).

Every grid point is rotated into one axial plane: axial coordinate ``x_A`` (from the
pitch apex along the work axis, mm) against radius ``R_A`` (mm) -- the projection
gear engineers use for tooth contact and blank drawings.  Grid lines along the face
width (s = const) and along the height (xi = const) are drawn, the blank's face and
root cones and the toe/heel limits are overlaid when a blank is given, and toe,
heel, root and tip are labelled.  Report size (7.5 x 5.5 in, fonts >= 9 pt, 150 dpi;
:mod:`gearjax.plot.style`).  Nothing is shown on screen.
"""

from __future__ import annotations

import io as _io
from pathlib import Path

import numpy as np

from gearjax.plot.style import DPI, MIN_WIDTH_IN, report_style

__all__ = ["axial_projection", "plot_flank_axial", "save_flank_plot"]


def axial_projection(points):
    """(x_A, R_A) of work-frame points (..., 3): axial coordinate and radius (mm)."""
    P = np.asarray(points, dtype=float)
    return P[..., 2], np.hypot(P[..., 0], P[..., 1])


def plot_flank_axial(grid, blank=None, ax=None, label: str = "flank", color="C0"):
    """Draw ``grid`` (a :class:`~gearjax.io.FlankGrid`) in the axial plane.

    ``blank`` (optional :class:`~gearjax.gears.hypoid.flank.MemberBlank`) adds the face and
    root cones and the toe/heel lines (normal to the pitch generatrix at
    ``A_o - F`` and ``A_o``).  Returns the matplotlib Axes.
    """
    with report_style():
        return _draw_flank(grid, blank, ax, label, color)


def _draw_flank(grid, blank, ax, label, color):
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(MIN_WIDTH_IN + 0.5, 5.5))
    x, R = axial_projection(grid.points)
    for j in range(x.shape[1]):
        ax.plot(x[:, j], R[:, j], color=color, lw=0.6, alpha=0.8)
    for i in range(x.shape[0]):
        ax.plot(x[i, :], R[i, :], color=color, lw=0.6, alpha=0.8)
    ax.plot([], [], color=color, label=label)
    if blank is not None:
        from gearjax.gears.hypoid.flank import face_apex_offset, root_apex_offset
        gp, gF, gR = (float(v) for v in (blank.pitch_angle, blank.face_angle, blank.root_angle))
        Ao, F = float(blank.outer_cone_distance), float(blank.face_width)
        xs = np.linspace(x.min() - 0.15 * np.ptp(x) - 1, x.max() + 0.15 * np.ptp(x) + 1, 50)
        ax.plot(xs, np.tan(gF) * (xs + float(face_apex_offset(blank))), "k--", lw=0.8,
                label="face cone")
        ax.plot(xs, np.tan(gR) * (xs + float(root_apex_offset(blank))), "k:", lw=0.8,
                label="root cone")
        for A in (Ao - F, Ao):
            p = np.array([A * np.cos(gp), A * np.sin(gp)])
            d = np.array([-np.sin(gp), np.cos(gp)])
            seg = np.stack([p - 14 * d, p + 14 * d])
            ax.plot(seg[:, 0], seg[:, 1], color="0.5", lw=0.8)
    # labels: toe/heel at mid height, root/tip at mid face
    jm, im = x.shape[1] // 2, x.shape[0] // 2
    kw = dict(fontsize=9, ha="center", va="center",
              bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="0.7", alpha=0.85))
    ax.annotate("toe", (x[0, jm], R[0, jm]), **kw)
    ax.annotate("heel", (x[-1, jm], R[-1, jm]), **kw)
    ax.annotate("root", (x[im, 0], R[im, 0]), **kw)
    ax.annotate("tip", (x[im, -1], R[im, -1]), **kw)
    ax.set_xlabel("axial coordinate x_A from pitch apex (mm)")
    ax.set_ylabel("radius R_A (mm)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, lw=0.3)
    ax.legend(loc="best")
    return ax


def save_flank_plot(path, grid, blank=None, title: str | None = None, label: str = "flank") -> Path:
    """Save the axial-plane figure to ``path`` (format from the extension), atomically."""
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt

    from gearjax.io import atomic_write

    path = Path(path)
    with report_style():
        fig, ax = plt.subplots(figsize=(MIN_WIDTH_IN + 0.5, 5.5))
    try:
        plot_flank_axial(grid, blank, ax=ax, label=label)
        with report_style():
            if title:
                ax.set_title(title)
            buf = _io.BytesIO()
            fig.savefig(buf, format=path.suffix.lstrip(".") or "png", dpi=DPI,
                        bbox_inches="tight")
    finally:
        plt.close(fig)
    return atomic_write(path, buf.getvalue())
