"""TCA figures: TE of all pairs with the envelope, and the contact pattern.

The contact pattern is drawn on the axial projection of the pinion flank (axial
coordinate = body z, radial = distance from the body axis, mm): the path of
contact and the instantaneous contact ellipses (semi-axes from
:func:`gearjax.tca.path.ellipse_from_weingarten`, projected from the tangent plane),
with the flank limits (face ends = toe/heel, form circle = root, tip circle =
tip) marked; only positions whose contact converged on the flank are drawn, and
the ellipses and the path are clipped to the flank outline.  A conjugate pair's
TE (zero up to rounding) is shown on a fixed +-1 arcsec axis, not autoscaled.  One column per flank side (drive, coast).  Figures are rendered
with the Agg backend and saved atomically (``gearjax.io.atomic_write`` of the PNG
bytes); nothing is shown on screen.
"""

from __future__ import annotations

import io as _io

import numpy as np

from gearjax.plot.style import DPI, MIN_WIDTH_IN, clip_to, report_style, te_axis_limits
from gearjax.tca.path import ARCSEC

__all__ = ["ellipse_outline_axial", "flank_outline", "on_flank_mask", "plot_tca", "save_tca_plot"]


def ellipse_outline_axial(path, i, points=48):
    """(axial, radial) outline (n, 2) of contact ellipse ``i`` on the pinion flank.

    Ellipse in the tangent plane ``P + a cos(t) e_maj + b sin(t) e_min`` (fixed
    frame), rotated back into the pinion body frame by ``-phi1`` and projected.
    Infinite (line-contact) major axes are clipped to 1e3 mm before projection.
    """
    phi = float(path.phi1[i])
    c, s = np.cos(-phi), np.sin(-phi)
    Rb = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    n = np.asarray(path.normal[i])
    e = np.asarray(path.major_dir[i])
    f = np.cross(n, e)
    a = min(float(path.semi_major[i]), 1e3)
    b = float(path.semi_minor[i])
    t = np.linspace(0.0, 2 * np.pi, points)
    P = np.asarray(path.point[i])[None, :] + a * np.cos(t)[:, None] * e + b * np.sin(t)[:, None] * f
    Q = P @ Rb.T
    return np.stack([Q[:, 2], np.hypot(Q[:, 0], Q[:, 1])], axis=1)


def flank_outline(lim):
    """Closed outline polygon (n, 2) of the pinion flank in the axial projection (mm)
    from a ``limits`` entry of :func:`plot_tca` (``outline`` or the cylindrical
    ``face_half`` / ``root_radius`` / ``tip_radius``), or ``None``."""
    if lim is None:
        return None
    if "outline" in lim:
        return np.asarray(lim["outline"], float)
    h, r0, r1 = float(lim["face_half"]), float(lim["root_radius"]), float(lim["tip_radius"])
    return np.array([[-h, r0], [h, r0], [h, r1], [-h, r1], [-h, r0]])


def on_flank_mask(path, margin):
    """Grid points whose contact converged and lies inside every flank boundary."""
    return (np.asarray(margin) >= 0.0) & np.asarray(path.converged, bool)


def _te_panel(ax, label, path, multi, title, pitch_arcsec):
    phi = np.degrees(np.asarray(path.phi1))
    te = np.asarray(multi.te_pairs) / ARCSEC
    env = np.asarray(multi.envelope) / ARCSEC
    for q in range(te.shape[0]):
        ax.plot(phi, te[q], lw=1.2, label=f"pair {q - te.shape[0] // 2:+d}")
    ax.plot(phi, env, "k--", lw=1.6, label="envelope")
    for tp in np.asarray(multi.transfer_phi1):
        if np.isfinite(tp):
            ax.axvline(np.degrees(tp), color="0.6", lw=0.8)
    ptp = float(multi.ptp) / ARCSEC
    lims, spread, floor = te_axis_limits(np.concatenate([te.ravel(), env]), pitch_arcsec)
    if lims is not None:     # conjugate: keep rounding noise at its true size
        ax.set_ylim(*lims)
        ax.text(0.02, 0.95, f"conjugate: TE p-t-p < {floor:.2g} arcsec\n"
                            f"(computed {ptp:.2g}; rounding noise)",
                transform=ax.transAxes, ha="left", va="top", fontsize=9,
                bbox=dict(boxstyle="round,pad=0.3", fc="white", ec="0.7", alpha=0.9))
        head = f"p-t-p < {floor:.2g} arcsec"
    else:
        head = f"p-t-p {ptp:.3g} arcsec"
    ax.set_xlabel("pinion angle (deg)")
    ax.set_ylabel("transmission error (arcsec)")
    ax.set_title(f"{title}: {label}\nTE {head}, contact ratio {float(multi.contact_ratio):.3f}")
    ax.grid(True, lw=0.3, alpha=0.6)
    ax.legend(loc="best", ncol=2)


def _pattern_panel(ax, label, path, margin, lim):
    on = on_flank_mask(path, margin)
    o = flank_outline(lim)
    ax1 = np.where(on, np.asarray(path.axial1, float), np.nan)   # gaps where off the flank
    rd1 = np.where(on, np.asarray(path.radial1, float), np.nan)
    kinds = getattr(path, "edge_kind", None)     # paths built by hand may lack it
    edge = (np.zeros(np.shape(on), bool) if kinds is None
            else on & (np.asarray(kinds) >= 0))
    drawn = []
    for i in np.nonzero(on & ~edge)[0][::3]:     # no ellipse at an edge contact
        e = ellipse_outline_axial(path, i)
        drawn += ax.plot(e[:, 0], e[:, 1], color="C0", lw=0.8)
    if drawn:
        line = np.any(np.isinf(np.asarray(path.semi_major))[on & ~edge])
        drawn[0].set_label("contact lines (line contact)" if line else "contact ellipses")
    drawn += ax.plot(ax1, rd1, "r.-", lw=1.2, ms=4, label="path of contact")
    if edge.any():
        drawn += ax.plot(np.asarray(path.axial1, float)[edge], np.asarray(path.radial1, float)[edge],
                         "kx", ms=6, mew=1.5, label="edge contact (face end)")
    if o is not None:
        clip_to(drawn, o, ax)
        ax.plot(o[:, 0], o[:, 1], "k-", lw=1.2)
        lo, hi = o[:-1].min(axis=0), o[:-1].max(axis=0)
        span = hi - lo
        if "outline" in lim:     # bevel: toe-root, heel-root, heel-tip, toe-tip
            mid = lambda a, c: 0.5 * (o[a] + o[c])
            places = (((0, 3), "toe ", "right", "center"), ((1, 2), " heel", "left", "center"),
                      ((2, 3), "tip", "center", "bottom"), ((0, 1), "root", "center", "top"))
            for (a, c), txt, ha, va in places:
                x, y = mid(a, c)
                ax.text(x, y, txt, ha=ha, va=va)
        else:
            cy = 0.5 * (lo[1] + hi[1])
            ax.text(lo[0], cy, "toe ", ha="right", va="center")
            ax.text(hi[0], cy, " heel", ha="left", va="center")
            ax.text(0.5 * (lo[0] + hi[0]), hi[1], "tip", ha="center", va="bottom")
            ax.text(0.5 * (lo[0] + hi[0]), lo[1], "root", ha="center", va="top")
        ax.set_xlim(lo[0] - 0.25 * span[0], hi[0] + 0.25 * span[0])
        ax.set_ylim(lo[1] - 0.2 * span[1], hi[1] + 0.2 * span[1])
    ax.set_xlabel("axial position (mm)")
    ax.set_ylabel("radius (mm)")
    n_off = int(np.size(on) - np.count_nonzero(on))
    ax.set_title(f"contact pattern on the pinion flank: {label}"
                 + (f"\n({n_off} of {np.size(on)} positions off the flank, not drawn)"
                    if n_off else ""))
    ax.legend(loc="upper right")


def plot_tca(results, limits=None, title="TCA", pitch_rad=None):
    """Figure for ``results``: a list of ``(label, path, margin, multi)``.

    Top row: TE of every tooth pair and the envelope against the pinion angle (deg,
    arcsec); a conjugate pair (TE spread below the noise floor of
    :func:`gearjax.plot.style.te_axis_limits`) gets a fixed +-1 arcsec axis and a note
    instead of autoscaled rounding noise.  Bottom row: path of contact and contact
    ellipses on the pinion flank, only at positions whose contact converged inside
    the flank (``margin >= 0``), clipped to the flank outline.

    ``limits`` (optional) draws the flank boundary of the pinion: a dict with
    ``face_half``, ``root_radius``, ``tip_radius`` (mm, cylindrical gears), or one
    dict per result with ``outline`` (a closed (5, 2) polygon toe-root, heel-root,
    heel-tip, toe-tip, mm; bevel gears).  ``pitch_rad``: angular pitch of the pinion
    (2 pi/z1, rad) for the relative noise floor.  Returns the matplotlib Figure.
    """
    from gearjax.plot import headless
    headless()
    import matplotlib.pyplot as plt

    k = len(results)
    pitch_arcsec = None if pitch_rad is None else float(pitch_rad) / ARCSEC
    with report_style():
        fig, axes = plt.subplots(2, k, figsize=(max(MIN_WIDTH_IN + 0.5, 6.5 * k), 10.0),
                                 squeeze=False)
        for j, (label, path, margin, multi) in enumerate(results):
            lim = limits[j] if isinstance(limits, (list, tuple)) else limits
            _te_panel(axes[0, j], label, path, multi, title, pitch_arcsec)
            _pattern_panel(axes[1, j], label, path, margin, lim)
        fig.tight_layout()
    return fig


def save_tca_plot(path_png, results, limits=None, title="TCA", pitch_rad=None):
    """Render :func:`plot_tca` and write the PNG (150 dpi) atomically; returns the path."""
    import matplotlib.pyplot as plt

    from gearjax.io import atomic_write

    fig = plot_tca(results, limits, title, pitch_rad)
    buf = _io.BytesIO()
    with report_style():
        fig.savefig(buf, format="png", dpi=DPI)
    plt.close(fig)
    return atomic_write(path_png, buf.getvalue())
