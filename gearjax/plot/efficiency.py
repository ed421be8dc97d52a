"""Mesh-efficiency figure: load sharing, friction coefficient and sliding power loss
along one mesh cycle (:func:`gearjax.loading.mesh_efficiency`).

Three stacked panels against the pinion angle (deg): the torque share of each tooth
pair, μ of each loaded pair, and the power loss P_f (W) with the mean mesh
efficiency η̄ in the title.  Positions where a pair carries no load are gaps;
positions whose result is not valid are marked with a red cross on the P_f panel.
Built with the object API and the report style of :mod:`gearjax.plot.style` (never
``pyplot``); save with :func:`gearjax.plot.tribology.save_figure_atomic`.
"""

from __future__ import annotations

import numpy as np

from gearjax.plot.style import MIN_WIDTH_IN, report_style

__all__ = ["efficiency_figure"]


def efficiency_figure(eff, title=None):
    """Figure of a :class:`gearjax.MeshEfficiency` (module docstring)."""
    with report_style():
        return _efficiency(eff, title)


def _efficiency(eff, title):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(MIN_WIDTH_IN + 0.5, 8.0), layout="constrained")
    FigureCanvasAgg(fig)
    ax_s, ax_mu, ax_p = fig.subplots(3, 1, sharex=True)
    phi = np.degrees(np.asarray(eff.phi1, float))
    F = np.asarray(eff.loaded.load, float)
    share = np.asarray(eff.loaded.share, float)
    mu = np.asarray(eff.friction.mu, float)
    K = F.shape[0]
    for j in range(K):
        on = F[j] > 0.0
        if not on.any():
            continue
        label = f"pair {j - K // 2:+d}"
        line, = ax_s.plot(phi, np.where(on, share[j], np.nan), marker=".", label=label)
        ax_mu.plot(phi, np.where(on, mu[j], np.nan), marker=".", color=line.get_color(),
                   label=label)
    ax_s.set_ylabel("load share (-)")
    ax_s.set_ylim(-0.02, 1.05)
    ax_s.legend(loc="best")
    ax_s.set_title("load sharing between the tooth pairs")
    ax_mu.set_ylabel(r"friction coefficient $\mu$")
    ax_mu.set_ylim(bottom=0.0)
    ax_mu.set_title("friction coefficient of each loaded pair")
    pf = np.asarray(eff.power_loss, float)
    ax_p.plot(phi, pf, "k.-", label=r"$P_f$")
    bad = ~np.asarray(eff.valid, bool)
    if bad.any():
        ax_p.plot(phi[bad], pf[bad], "rx", ms=8, label="not valid")
        ax_p.legend(loc="best")
    ax_p.set_ylabel(r"power loss $P_f$ (W)")
    ax_p.set_ylim(bottom=0.0)
    ax_p.set_xlabel("pinion angle (deg)")
    eta = float(eff.mean_efficiency)
    ax_p.set_title(rf"sliding power loss; $\bar\eta$ = {100.0 * eta:.3f} %, "
                   rf"$P_{{in}}$ = {float(eff.power_in):.4g} W")
    for ax in (ax_s, ax_mu, ax_p):
        ax.grid(True, alpha=0.3)
    fig.suptitle(title or "mesh efficiency over one mesh cycle")
    return fig
