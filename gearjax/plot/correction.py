"""Deviation maps of a measured flank before and after a machine-setting correction
(matplotlib, saved atomically; ``gearjax correct --plot``).

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

__all__ = ["save_correction_plot"]


def save_correction_plot(path, flanks, xi, height, before_um, after_um,
                         title: str | None = None) -> Path:
    """Save the before/after deviation maps to ``path`` (png, pdf, svg), atomically.

    ``flanks`` : flank names; ``xi`` (n_xi,), ``height`` (n_s,) grid coordinates;
    ``before_um``, ``after_um`` (n_f, n_xi, n_s) deviations (um)."""
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt

    from gearjax.io import atomic_write

    b, a = np.asarray(before_um, float), np.asarray(after_um, float)
    norm, cmap = signed_scale(np.concatenate([b.ravel(), a.ravel()]))
    n_f = len(flanks)
    with report_style():
        fig, axes = plt.subplots(n_f, 2, figsize=(MIN_WIDTH_IN + 2.0, 3.2 * n_f + 0.6),
                                 squeeze=False, sharex=True, sharey=True)
    try:
        with report_style():
            for k, f in enumerate(flanks):
                for c, (what, v) in enumerate((("measured", b[k]), ("after correction", a[k]))):
                    ax = axes[k, c]
                    m = ax.pcolormesh(np.asarray(xi), np.asarray(height), v.T, norm=norm,
                                      cmap=cmap, shading="nearest")
                    rms = float(np.sqrt(np.nanmean(v ** 2)))
                    ax.set_title(f"{f}: {what}\nrms {rms:.2f} um")
                    if k == n_f - 1:
                        ax.set_xlabel("face width xi (toe -1, heel +1)")
                    if c == 0:
                        ax.set_ylabel("blade fraction (root 0, tip 1)")
            fig.colorbar(m, ax=axes, label="normal deviation (um, + = material added)")
            if title:
                fig.suptitle(title)
            buf = _io.BytesIO()
            fig.savefig(buf, format=Path(path).suffix.lstrip(".") or "png", dpi=DPI,
                        bbox_inches="tight")
    finally:
        plt.close(fig)
    return atomic_write(path, buf.getvalue())
