"""Micro-geometry and loaded-TE figure of ``gearjax loaded``
(:func:`gearjax.involute.loaded_te_map`).

Left: the modification map of one flank (by default the pinion's drive flank) -- the
material removed (µm, :func:`gearjax.involute.flank_removal_um`) over the roll length
``xi`` (mm, from the start of active profile to the tip) and the face position ``y``
(mm from the face centre; end I at ``-b/2``, end II at ``+b/2``), filled contours with
a colour bar.  Right: the peak-to-peak loaded transmission error (µm along the line of
action) against the pinion torque, one line per mesh misalignment; operating points
that did not converge are marked with a red cross.

``gearjax tca`` of a design with micro-geometry (:func:`line_tca_figure`): the
modification maps of both flanks in mesh, the unloaded TE over the mesh cycle (µm,
against the pinion angle; the loaded TE at each torque dashed) and, with torques, the
loaded TE p-t-p against torque.  ``gearjax efficiency`` of such a design
(:func:`line_efficiency_figure`): the pinion flank's map, the mesh efficiency and the
power loss against torque, and the loaded TE p-t-p against torque.  Built with the
object API and the
report style of :mod:`gearjax.plot.style` (never ``pyplot``); written atomically by
:func:`save_loaded_plot`.
"""

from __future__ import annotations

import numpy as np

from gearjax.plot.style import DPI, MIN_WIDTH_IN, report_style

__all__ = ["removal_map", "loaded_figure", "save_loaded_plot", "map_panel", "line_tca_figure",
           "save_line_tca_plot", "line_efficiency_figure", "save_line_efficiency_plot"]


def removal_map(design, member: str = "pinion", side: str = "drive", n_xi: int = 41,
                n_y: int = 31):
    """``(xi, y, removal)`` of one flank of ``design`` (an involute design file or an
    :class:`~gearjax.involute.InvoluteTCA`, unmodified without ``[microgeometry]``):
    roll lengths (n_xi,) mm over the active profile, face positions (n_y,) mm and the
    removal (n_y, n_xi) µm."""
    import jax.numpy as jnp

    from gearjax.involute import MicroGeometry, flank_removal_um, pair_geometry
    if member not in ("pinion", "gear"):
        raise ValueError(f"member = {member!r} must be 'pinion' or 'gear'")
    micro = getattr(design, "micro", None) or MicroGeometry.none()
    des = getattr(design, "design", design)
    mod = getattr(micro.flanks(side), member)
    geo = pair_geometry(des.pair)
    rho_A, rho_E = float(geo["rho_A"]), float(geo["rho_E"])
    if member == "gear":
        g = float(geo["a_w"]) * float(np.sin(float(geo["alpha_wt"])))
        rho_A, rho_E = g - rho_E, g - rho_A
    b = float(des.face_width)
    xi = np.linspace(rho_A, rho_E, n_xi)
    y = np.linspace(-0.5 * b, 0.5 * b, n_y)
    rem = flank_removal_um(mod, jnp.asarray(xi)[None, :], jnp.asarray(y)[:, None], rho_A,
                           rho_E, b)
    return xi, y, np.asarray(rem, float)


def loaded_figure(flank_map, te_map, title=None, flank_label="pinion drive flank"):
    """Figure: ``flank_map`` = :func:`removal_map`'s ``(xi, y, removal)``; ``te_map`` a
    :class:`~gearjax.involute.LoadedTEMap` (module docstring)."""
    with report_style():
        return _figure(flank_map, te_map, title, flank_label)


def _figure(flank_map, te_map, title, flank_label):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(MIN_WIDTH_IN + 3.0, 4.2), layout="constrained")
    FigureCanvasAgg(fig)
    ax_m, ax_t = fig.subplots(1, 2)
    map_panel(fig, ax_m, flank_map, flank_label)
    T = np.asarray(te_map.torque_Nm, float)
    A = np.asarray(te_map.misalignment_um, float)
    ptp = np.asarray(te_map.te_ptp_um, float)
    conv = np.asarray(te_map.converged, bool)
    for j, a in enumerate(A):
        ax_t.plot(T, ptp[:, j], marker="o", ms=3.5, label=f"f_ma = {a:g} µm")
        bad = ~conv[:, j]
        if bad.any():
            ax_t.plot(T[bad], ptp[bad, j], "rx", ms=8)
    ax_t.set_xlabel("pinion torque (N m)")
    ax_t.set_ylabel("loaded TE peak-to-peak (µm)")
    ax_t.set_ylim(bottom=0.0)
    ax_t.set_title("loaded transmission error")
    ax_t.grid(True, alpha=0.3)
    ax_t.legend(loc="best")
    if title:
        fig.suptitle(title)
    return fig


def map_panel(fig, ax, flank_map, flank_label: str) -> None:
    """Draw :func:`removal_map`'s ``(xi, y, removal)`` on ``ax`` of ``fig``: filled
    contours of the material removed (µm) with a colour bar, or "unmodified flank"."""
    xi, y, rem = flank_map
    span = float(np.nanmax(rem) - np.nanmin(rem)) if rem.size else 0.0
    if span > 1e-9:
        cs = ax.contourf(xi, y, rem, levels=16, cmap="viridis")
        ax.contour(xi, y, rem, levels=cs.levels[1:-1], colors="k", linewidths=0.3, alpha=0.5)
        fig.colorbar(cs, ax=ax, label="material removed (µm)")
    else:
        ax.text(0.5, 0.5, "unmodified flank", ha="center", va="center",
                transform=ax.transAxes)
        ax.set_xlim(xi[0], xi[-1])
        ax.set_ylim(y[0], y[-1])
    ax.set_xlabel("roll length ξ (mm): SAP → tip")
    ax.set_ylabel("face position y (mm): end I → end II")
    ax.set_title(f"modification map, {flank_label}")


def save_loaded_plot(path, flank_map, te_map, title=None, dpi: int = DPI) -> None:
    """Write :func:`loaded_figure` to ``path`` atomically (a failing save leaves no
    half-written file; :func:`gearjax.plot.tribology.save_figure_atomic`)."""
    from gearjax.plot.tribology import save_figure_atomic
    save_figure_atomic(loaded_figure(flank_map, te_map, title), path, dpi=dpi)


def _torque_ptp(ax, T, ptp, conv, label=None):
    T, ptp, conv = (np.asarray(a, float) for a in (T, ptp, conv))
    ax.plot(T, ptp, marker="o", ms=3.5, label=label)
    bad = ~conv.astype(bool)
    if bad.any():
        ax.plot(T[bad], ptp[bad], "rx", ms=8)
    ax.set_xlabel("pinion torque (N m)")
    ax.set_ylabel("loaded TE peak-to-peak (µm)")
    ax.set_ylim(bottom=0.0)
    ax.set_title("loaded TE against torque")
    ax.grid(True, alpha=0.3)


def line_tca_figure(maps, results, title=None):
    """Figure of the line-contact TCA: ``maps`` a list of ``(label, removal_map)`` (the
    two flanks), ``results`` ``{side: LineTCA}`` (:func:`gearjax.involute.line_tca`)."""
    with report_style():
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        loaded = any(np.size(r.torque_Nm) for r in results.values())
        fig = Figure(figsize=(MIN_WIDTH_IN + 4.0, 7.6), layout="constrained")
        FigureCanvasAgg(fig)
        axs = fig.subplots(2, 2)
        for ax, (label, fm) in zip(axs[0], maps):
            map_panel(fig, ax, fm, label)
        ax_te, ax_t = axs[1]
        allT = np.concatenate([np.asarray(r.torque_Nm, float) for r in results.values()])
        if loaded:
            from matplotlib.cm import ScalarMappable
            from matplotlib.colors import Normalize
            norm = Normalize(allT.min(), allT.max() if allT.max() > allT.min()
                             else allT.min() + 1.0)
            smap = ScalarMappable(norm=norm, cmap="plasma")
        for (side, r), ls, c in zip(results.items(), ("--", ":"), ("k", "0.45")):
            phi = np.degrees(np.asarray(r.phi1_rad, float))
            ax_te.plot(phi, np.asarray(r.te_um, float), color=c, marker=".",
                       label=f"{side}: unloaded")
            for T, te in zip(np.asarray(r.torque_Nm, float), np.asarray(r.te_loaded_um, float)):
                ax_te.plot(phi, te, ls=ls, lw=1.0, color=smap.to_rgba(T))
            if np.size(r.torque_Nm):
                ax_te.plot([], [], ls=ls, color="0.3", label=f"{side}: loaded")
                _torque_ptp(ax_t, r.torque_Nm, r.te_loaded_ptp_um, r.converged, label=side)
        if loaded:
            fig.colorbar(smap, ax=ax_te, label="pinion torque (N m)")
        ax_te.set_xlabel("pinion angle φ1 (deg)")
        ax_te.set_ylabel("transmission error (µm along the line of action)")
        ax_te.set_title("TE over the mesh cycle")
        lo, hi = ax_te.get_ylim()             # zero and at least 1 µm in view: a
        ax_te.set_ylim(min(lo, 0.0), max(hi, 1.0))   # constant TE is not blown up
        ax_te.grid(True, alpha=0.3)
        ax_te.legend(loc="best", fontsize="small")
        if loaded:
            ax_t.legend(loc="best")
        else:
            ax_t.axis("off")
            ax_t.text(0.5, 0.5, "no --torque-Nm: unloaded TCA only", ha="center",
                      va="center", transform=ax_t.transAxes)
        if title:
            fig.suptitle(title)
        return fig


def save_line_tca_plot(path, maps, results, title=None, dpi: int = DPI) -> None:
    """Write :func:`line_tca_figure` to ``path`` atomically."""
    from gearjax.plot.tribology import save_figure_atomic
    save_figure_atomic(line_tca_figure(maps, results, title), path, dpi=dpi)


def line_efficiency_figure(flank_map, te_map, title=None, flank_label="pinion drive flank"):
    """Figure of the line-contact efficiency: the flank's :func:`removal_map`, the mesh
    efficiency and power loss against torque, the loaded TE p-t-p against torque
    (``te_map`` a :class:`~gearjax.involute.LoadedTEMap` with the efficiency columns,
    one misalignment)."""
    with report_style():
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(figsize=(MIN_WIDTH_IN + 6.0, 4.2), layout="constrained")
        FigureCanvasAgg(fig)
        ax_m, ax_e, ax_t = fig.subplots(1, 3)
        map_panel(fig, ax_m, flank_map, flank_label)
        T = np.asarray(te_map.torque_Nm, float)
        eta = 100.0 * np.asarray(te_map.efficiency, float)[:, 0]
        loss = np.asarray(te_map.power_loss_W, float)[:, 0]
        ax_e.plot(T, eta, marker="o", ms=3.5, color="C0")
        ax_e.set_xlabel("pinion torque (N m)")
        ax_e.set_ylabel("mesh efficiency (%)", color="C0")
        ax_e.grid(True, alpha=0.3)
        ax_p = ax_e.twinx()
        ax_p.plot(T, loss, marker="s", ms=3.5, color="C1")
        ax_p.set_ylabel("sliding power loss (W)", color="C1")
        ax_e.set_title("efficiency and power loss")
        _torque_ptp(ax_t, T, np.asarray(te_map.te_ptp_um, float)[:, 0],
                    np.asarray(te_map.converged, bool)[:, 0])
        if title:
            fig.suptitle(title)
        return fig


def save_line_efficiency_plot(path, flank_map, te_map, title=None, dpi: int = DPI) -> None:
    """Write :func:`line_efficiency_figure` to ``path`` atomically."""
    from gearjax.plot.tribology import save_figure_atomic
    save_figure_atomic(line_efficiency_figure(flank_map, te_map, title), path, dpi=dpi)
