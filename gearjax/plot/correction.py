"""Deviation maps of a measured flank before and after a machine-setting correction
(matplotlib, saved atomically; ``gearjax correct --plot``), and the ease-off maps of
``gearjax ease-off --plot`` (:func:`save_map_panels`: design, target, written design).

One row per measured flank, two panels: the measured normal deviations (um, positive =
material added) and the residual the fitted settings leave, over the measuring grid --
face-width position xi (toe -1 .. heel +1) across, fraction of the active blade
length (root 0 .. tip 1) up.  One diverging colour scale, symmetric about 0, for all
panels, so that before and after compare directly.  Report size
(:mod:`gearjax.plot.style`); nothing is shown on screen.
"""

from __future__ import annotations

import io as _io
from pathlib import Path

import numpy as np

from gearjax.plot.style import DPI, MIN_WIDTH_IN, report_style, signed_scale

__all__ = ["save_correction_plot", "save_map_panels"]


def save_correction_plot(path, flanks, xi, height, before_um, after_um,
                         title: str | None = None) -> Path:
    """Save the before/after deviation maps to ``path`` (png, pdf, svg), atomically.

    ``flanks`` : flank names; ``xi`` (n_xi,), ``height`` (n_s,) grid coordinates;
    ``before_um``, ``after_um`` (n_f, n_xi, n_s) deviations (um)."""
    b, a = np.asarray(before_um, float), np.asarray(after_um, float)
    rows = [(f, [("measured", b[k]), ("after correction", a[k])]) for k, f in enumerate(flanks)]
    return save_map_panels(path, rows, xi, height,
                           "normal deviation (um, + = material added)", title=title)


def save_map_panels(path, rows, xi, height, label: str, title: str | None = None) -> Path:
    """Save rows of grid maps to ``path`` (png, pdf, svg), atomically, on one diverging
    colour scale symmetric about 0.

    ``rows`` : [(row name, [(panel name, (n_xi, n_s) um), ...]), ...]; ``xi`` (n_xi,),
    ``height`` (n_s,) grid coordinates; ``label`` : the colour bar's label.  Each panel
    is titled with its rms (NaN entries, lines left out, are blank)."""
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt

    from gearjax.io import atomic_write

    values = np.concatenate([np.asarray(v, float).ravel() for _, ps in rows for _, v in ps])
    norm, cmap = signed_scale(values[np.isfinite(values)])
    n_r, n_c = len(rows), max(len(ps) for _, ps in rows)
    with report_style():
        fig, axes = plt.subplots(n_r, n_c, figsize=(MIN_WIDTH_IN + 2.0 * (n_c - 1),
                                                    3.2 * n_r + 0.6),
                                 squeeze=False, sharex=True, sharey=True)
    try:
        with report_style():
            for k, (row, panels) in enumerate(rows):
                for c, (what, v) in enumerate(panels):
                    v = np.asarray(v, float)
                    ax = axes[k, c]
                    m = ax.pcolormesh(np.asarray(xi), np.asarray(height), v.T, norm=norm,
                                      cmap=cmap, shading="nearest")
                    rms = float(np.sqrt(np.nanmean(v ** 2)))
                    ax.set_title(f"{row}: {what}\nrms {rms:.2f} um")
                    if k == n_r - 1:
                        ax.set_xlabel("face width xi (toe -1, heel +1)")
                    if c == 0:
                        ax.set_ylabel("blade fraction (root 0, tip 1)")
                for c in range(len(panels), n_c):
                    axes[k, c].set_visible(False)
            fig.colorbar(m, ax=axes, label=label)
            if title:
                fig.suptitle(title, y=1.0 + 0.1 / n_r)     # above the panel titles
            buf = _io.BytesIO()
            fig.savefig(buf, format=Path(path).suffix.lstrip(".") or "png", dpi=DPI,
                        bbox_inches="tight")
    finally:
        plt.close(fig)
    return atomic_write(path, buf.getvalue())
