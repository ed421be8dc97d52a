"""The figure of a design study (``gearjax optimize``): the optimiser's history, the TE
before and after, the loss per position (loaded studies) or the |SRR| along the path,
and the change of every variable; the figure of a design sweep (``gearjax sweep``): the
objective of every design against each variable.  Agg backend; saved atomically by the
caller."""

from __future__ import annotations

import numpy as np

from gearjax.plot.style import MIN_WIDTH_IN, report_style, te_axis_limits
from gearjax.tca.path import ARCSEC

__all__ = ["study_figure", "line_study_figure", "kinematics_study_figure", "sweep_figure"]


def _history(ax, hist, title, start=None):
    """Objective and largest violation per iteration; ``start = (J0, violation0)``
    drawn as iteration 0 (None: not drawn)."""
    v = np.asarray(hist.get("objective", []), float)
    f = np.asarray(hist.get("feasibility", []), float)
    k0 = 1
    if start is not None:
        v, f, k0 = np.r_[start[0], v], np.r_[start[1], f], 0
    ax.plot(np.arange(k0, k0 + v.size), v, "o-", color="C0", label="objective J")
    ax.set_xlabel("iteration (0: the start)" if start is not None else "iteration")
    ax.set_ylabel("objective J (scaled)", color="C0")
    if f.size and np.any(f > 0):
        ax2 = ax.twinx()
        ax2.semilogy(np.arange(k0, k0 + f.size), np.maximum(f, 1e-16), "s--", color="C3",
                     label="largest violation")
        ax2.set_ylabel("largest constraint violation (scaled)", color="C3")
    ax.set_title(title)
    ax.grid(True, lw=0.3, alpha=0.6)


def _te(ax, res0, res1):
    for res, lab, c in ((res0, "start", "0.5"), (res1, "optimised", "C0")):
        phi = np.degrees(np.asarray(res.path.phi1))
        env = np.asarray(res.multi.envelope) / ARCSEC
        ptp = float(np.asarray(res.multi.ptp)) / ARCSEC
        ax.plot(phi - phi[phi.size // 2], env - np.nanmax(env), "-", color=c, lw=1.5,
                label=f"{lab}: p-t-p {ptp:.3g} arcsec")
    lims, _, floor = te_axis_limits(np.concatenate([
        np.asarray(r.multi.envelope).ravel() / ARCSEC - np.nanmax(np.asarray(r.multi.envelope)
                                                                   / ARCSEC)
        for r in (res0, res1)]))
    if lims is not None:        # conjugate pairs: rounding noise at its true size
        ax.set_ylim(*lims)
        ax.text(0.02, 0.95, f"conjugate: TE p-t-p < {floor:.2g} arcsec", transform=ax.transAxes,
                ha="left", va="top")
    ax.set_xlabel("pinion angle from the reference (deg)")
    ax.set_ylabel("unloaded TE envelope (arcsec, top at 0)")
    ax.set_title("transmission error (scenario 1)")
    ax.grid(True, lw=0.3, alpha=0.6)
    ax.legend(loc="lower center")


def _loss(ax, eff0, eff1):
    for eff, lab, c in ((eff0, "start", "0.5"), (eff1, "optimised", "C0")):
        phi = np.degrees(np.asarray(eff.phi1))
        p = np.where(np.asarray(eff.valid), np.asarray(eff.power_loss), np.nan)
        eta = float(np.asarray(eff.mean_efficiency))
        ax.plot(phi - phi[phi.size // 2], p, "o-", color=c, ms=3,
                label=f"{lab}: mean efficiency {100 * eta:.3f} %")
    ax.set_xlabel("pinion angle from the reference (deg)")
    ax.set_ylabel("sliding power loss (W)")
    ax.set_title("power loss over one mesh cycle (scenario 1; valid positions)")
    ax.grid(True, lw=0.3, alpha=0.6)
    ax.legend(loc="best")


def _srr(ax, res0, res1, mask0):
    for res, lab, c in ((res0, "start", "0.5"), (res1, "optimised", "C0")):
        phi = np.degrees(np.asarray(res.path.phi1))
        srr = np.where(mask0, np.abs(np.asarray(res.kinematics.srr)), np.nan)
        ax.plot(phi - phi[phi.size // 2], srr, "o-", color=c, ms=3, label=lab)
    ax.set_xlabel("pinion angle from the reference (deg)")
    ax.set_ylabel("|slide-to-roll ratio|")
    ax.set_title("|SRR| along the path of contact (scenario 1)")
    ax.grid(True, lw=0.3, alpha=0.6)
    ax.legend(loc="best")


def _variables(ax, variables):
    names = [v["field"] for v in variables]
    span = np.array([v["upper"] - v["lower"] for v in variables], float)
    rel0 = np.array([(v["start"] - v["lower"]) for v in variables], float) / span
    rel1 = np.array([(v["end"] - v["lower"]) for v in variables], float) / span
    y = np.arange(len(names))
    ax.barh(y, rel1 - rel0, left=rel0, color="C0", height=0.5, label="start -> end")
    ax.plot(rel0, y, "k|", ms=12, label="start")
    short = [n.split(".")[-1] for n in names]
    if len(set(short)) < len(short):          # e.g. the same key of pinion and gear
        short = [".".join(n.split(".")[-2:]) for n in names]
    ax.set_yticks(y, short)
    ax.set_xlim(0.0, 1.0)
    ax.set_xlabel("position in the bounds (0 = lower, 1 = upper)")
    ax.set_title("variables")
    ax.grid(True, axis="x", lw=0.3, alpha=0.6)
    ax.legend(loc="lower right")


def study_figure(report: dict, start: tuple, end: tuple, mask=None):
    """Four panels: history, TE, loss (or |SRR|), variables.  ``start``/``end``:
    ``(Q, res, eff)`` of :func:`gearjax.studies.study_run.run_study` (scenario 1 is
    drawn); ``mask``: the start design's on-flank points of scenario 1 (for |SRR|)."""
    import jax
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt

    first = lambda tree: jax.tree_util.tree_map(lambda a: np.asarray(a)[0], tree)  # noqa: E731
    res0, res1 = first(start[1]), first(end[1])
    with report_style():
        fig, ax = plt.subplots(2, 2, figsize=(max(MIN_WIDTH_IN, 12.0), 9.0))
        opt = report["optimizer"]
        _history(ax[0, 0], report["history"],
                 f"{report['study']}: {opt['method']}, {opt['iterations']} iterations, "
                 f"{opt['evaluations']} evaluations")
        _te(ax[0, 1], res0, res1)
        if start[2] is not None:
            _loss(ax[1, 0], first(start[2]), first(end[2]))
        else:
            m = np.ones(np.shape(res0.path.phi1), bool) if mask is None else np.asarray(mask)
            _srr(ax[1, 0], res0, res1, m)
        _variables(ax[1, 1], report["variables"])
        fig.tight_layout()
    return fig


def _te_vs_torque(ax, report, sweep=None):
    """Loaded TE p-t-p (hard, µm) against the torque, one colour per mesh misalignment,
    start dashed and end solid: at the study's scenarios (markers) and, with ``sweep =
    (T (n,), A (m,), ptp_start (n, m), ptp_end (n, m))``, over a torque sweep (lines)."""
    q = report["quantities"]["line_te_ptp_hard_um"]
    sc = report["scenarios"]
    T = np.array([s["torque_Nm"] for s in sc], float)
    A = np.array([s["f_ma_um"] for s in sc], float)
    levels = sorted(set(A.tolist()))
    for j, a in enumerate(levels):
        sel = A == a
        order = np.argsort(T[sel])
        for key, ls, lab in (("start", "--", "start"), ("end", "-", "optimised")):
            v = np.asarray(q[key], float)[sel][order]
            ax.plot(T[sel][order], v, "o" if sweep is not None else ls + "o", ms=4,
                    color=f"C{j}", mfc="none" if key == "start" else None,
                    label=None if sweep is not None else f"{lab}, f_ma = {a:g} µm")
    if sweep is not None:
        Ts, As, p0, p1 = (np.asarray(v, float) for v in sweep)
        for j, a in enumerate(As):
            c = f"C{levels.index(a)}" if a in levels else f"C{j}"
            ax.plot(Ts, p0[:, j], "--", color=c, lw=1.0, label=f"start, f_ma = {a:g} µm")
            ax.plot(Ts, p1[:, j], "-", color=c, lw=1.5, label=f"optimised, f_ma = {a:g} µm")
    ax.set_xlabel("pinion torque (N m)")
    ax.set_ylabel("loaded TE peak-to-peak (µm)")
    ax.set_ylim(bottom=0.0)
    ax.set_title("loaded TE against torque" + (" (markers: the study's scenarios)"
                                               if sweep is not None else ""))
    ax.grid(True, lw=0.3, alpha=0.6)
    ax.legend(loc="best", fontsize=7)


def line_study_figure(report: dict, flank_map=None, flank_label: str = "pinion flank",
                      sweep=None):
    """The figure of a line-contact study (:mod:`gearjax.studies.line_route`): history,
    loaded TE p-t-p against torque before and after (the scenarios' values; ``sweep``
    as :func:`_te_vs_torque` adds a torque sweep of both designs), the end design's
    modification map (``flank_map``, :func:`gearjax.plot.microgeometry.removal_map`'s
    triple; None: left empty) and the variables."""
    from gearjax.plot import headless
    from gearjax.plot.microgeometry import map_panel
    headless()
    import matplotlib.pyplot as plt

    with report_style():
        fig, ax = plt.subplots(2, 2, figsize=(max(MIN_WIDTH_IN, 12.0), 9.0))
        opt = report["optimizer"]
        _history(ax[0, 0], report["history"],
                 f"{report['study']}\n{opt['method']}, {opt['iterations']} iterations, "
                 f"{opt['evaluations']} evaluations",
                 (report["objective"]["start"], report["max_violation"]["start"]))
        _te_vs_torque(ax[0, 1], report, sweep)
        if flank_map is not None:
            map_panel(fig, ax[1, 0], flank_map, f"{flank_label} (optimised)")
        else:
            ax[1, 0].set_visible(False)
        _variables(ax[1, 1], report["variables"])
        fig.tight_layout()
    return fig


def kinematics_study_figure(report: dict):
    """The figure of a kinematics study (:mod:`gearjax.studies.kinematics_route`): the
    history, each quantity's end value over its start value, and the variables."""
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt

    with report_style():
        fig, ax = plt.subplots(1, 3, figsize=(max(MIN_WIDTH_IN, 15.0), 4.5))
        opt = report["optimizer"]
        _history(ax[0], report["history"],
                 f"{report['study']}\n{opt['method']}, {opt['iterations']} iterations",
                 (report["objective"]["start"], report["max_violation"]["start"]))
        qs = report["quantities"]
        names = list(qs)
        ratio = [qs[q]["end"][0] / qs[q]["start"][0] if qs[q]["start"][0] else np.nan
                 for q in names]
        y = np.arange(len(names))
        ax[1].barh(y, ratio, color="C0", height=0.5)
        ax[1].axvline(1.0, color="k", lw=0.8)
        ax[1].set_yticks(y, names)
        ax[1].set_xlabel("end / start")
        ax[1].set_title("quantities")
        ax[1].grid(True, axis="x", lw=0.3, alpha=0.6)
        _variables(ax[2], report["variables"])
        fig.tight_layout()
    return fig


def sweep_figure(names: list, x, J, ok, feasible, title: str):
    """The objective of every swept design against each variable (one panel per
    variable; row 0, the design's own point, as a star): feasible designs filled,
    designs that are ``ok`` but violate a constraint hollow, the others (TCA not
    converged, edge contact, a quantity not finite) as crosses.  ``x`` (n, nv) in the
    study file's units, ``J`` (n,) the study's scaled objective."""
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt

    x, J = np.asarray(x), np.asarray(J)
    ok, feasible = np.asarray(ok, bool), np.asarray(feasible, bool)
    nv = x.shape[1]
    cols = min(nv, 3)
    rows = -(-nv // cols)
    bad = ~ok & np.isfinite(J)
    with report_style():
        fig, axes = plt.subplots(rows, cols, figsize=(max(MIN_WIDTH_IN, 4.2 * cols),
                                                      3.6 * rows), squeeze=False)
        for i in range(rows * cols):
            ax = axes.flat[i]
            if i >= nv:
                ax.set_visible(False)
                continue
            ax.plot(x[feasible, i], J[feasible], "o", ms=4, color="C0", label="feasible")
            ax.plot(x[ok & ~feasible, i], J[ok & ~feasible], "o", ms=4, mfc="none",
                    color="C1", label="constraint violated")
            ax.plot(x[bad, i], J[bad], "x", ms=4, color="C3", label="flagged")
            ax.plot(x[:1, i], J[:1], "*", ms=12, color="k", label="the design")
            ax.set_xlabel(names[i])
            ax.set_ylabel("objective J (scaled)")
            ax.grid(True, alpha=0.3)
        axes.flat[0].legend(fontsize=8)
        fig.suptitle(title)
        fig.tight_layout()
    return fig
