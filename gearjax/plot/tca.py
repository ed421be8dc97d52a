"""TCA figures: TE of all pairs with the envelope, and the contact pattern.

The contact pattern is drawn on the axial projection of the pinion flank (axial
coordinate = body z, radial = distance from the body axis, mm): the path of
contact and the instantaneous contact ellipses (semi-axes from
:func:`gearjax.tca.ellipse_from_weingarten`, projected from the tangent plane),
with the flank limits (face ends = toe/heel, form circle = root, tip circle =
tip) marked.  One column per flank side (drive, coast).  Figures are rendered
with the Agg backend and saved atomically (``gearjax.io.atomic_write`` of the PNG
bytes); nothing is shown on screen.
"""

from __future__ import annotations

import io as _io

import numpy as np

from gearjax.tca import ARCSEC

__all__ = ["ellipse_outline_axial", "plot_tca", "save_tca_plot"]


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


def plot_tca(results, limits=None, title="TCA"):
    """Figure for ``results``: a list of ``(label, path, margin, multi)``.

    ``limits`` (optional) draws the flank boundary of the pinion: a dict with
    ``face_half``, ``root_radius``, ``tip_radius`` (mm, cylindrical gears), or one
    dict per result with ``outline`` (a closed (5, 2) polygon toe-root, heel-root,
    heel-tip, toe-tip, mm; bevel gears).  Returns the matplotlib Figure.
    """
    import matplotlib
    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    k = len(results)
    fig, axes = plt.subplots(2, k, figsize=(6 * k, 8), squeeze=False)
    for j, (label, path, margin, multi) in enumerate(results):
        lim = limits[j] if isinstance(limits, (list, tuple)) else limits
        ax = axes[0, j]
        phi = np.degrees(np.asarray(path.phi1))
        te = np.asarray(multi.te_pairs) / ARCSEC
        for q in range(te.shape[0]):
            ax.plot(phi, te[q], lw=1.0, label=f"pair {q - te.shape[0] // 2:+d}")
        ax.plot(phi, np.asarray(multi.envelope) / ARCSEC, "k--", lw=1.6, label="envelope")
        for tp in np.asarray(multi.transfer_phi1):
            if np.isfinite(tp):
                ax.axvline(np.degrees(tp), color="0.6", lw=0.8)
        ax.set_xlabel("pinion angle (deg)")
        ax.set_ylabel("TE (arcsec)")
        ax.set_title(f"{title} — {label}: p-t-p {float(multi.ptp) / ARCSEC:.3g} arcsec, "
                     f"CR {float(multi.contact_ratio):.3f}", fontsize=9)
        ax.legend(fontsize=7)
        ax = axes[1, j]
        inside = np.asarray(margin) >= 0.0
        ax.plot(np.asarray(path.axial1)[inside], np.asarray(path.radial1)[inside], "r.-", lw=1,
                label="path of contact")
        for i in np.nonzero(inside)[0][::3]:
            o = ellipse_outline_axial(path, i)
            ax.plot(o[:, 0], o[:, 1], color="C0", lw=0.7)
        if lim is not None and "outline" in lim:
            o = np.asarray(lim["outline"])          # toe-root, heel-root, heel-tip, toe-tip
            ax.plot(o[:, 0], o[:, 1], "k-", lw=1)
            mid = lambda a, c: 0.5 * (o[a] + o[c])
            for (a, c), txt, ha, va in (((0, 3), "toe ", "right", "center"),
                                        ((1, 2), " heel", "left", "center"),
                                        ((2, 3), "tip", "center", "bottom"),
                                        ((0, 1), "root", "center", "top")):
                x, y = mid(a, c)
                ax.text(x, y, txt, ha=ha, va=va)
            span = np.ptp(o, axis=0)
            ax.set_xlim(o[:, 0].min() - 0.25 * span[0], o[:, 0].max() + 0.25 * span[0])
            ax.set_ylim(o[:, 1].min() - 0.2 * span[1], o[:, 1].max() + 0.2 * span[1])
        elif lim is not None:
            h, r0, r1 = lim["face_half"], lim["root_radius"], lim["tip_radius"]
            ax.plot([-h, h, h, -h, -h], [r0, r0, r1, r1, r0], "k-", lw=1)
            ax.text(-h, 0.5 * (r0 + r1), "toe ", ha="right", va="center")
            ax.text(h, 0.5 * (r0 + r1), " heel", ha="left", va="center")
            ax.text(0.0, r1, "tip", ha="center", va="bottom")
            ax.text(0.0, r0, "root", ha="center", va="top")
            ax.set_xlim(-1.4 * h, 1.4 * h)
            ax.set_ylim(r0 - 0.15 * (r1 - r0), r1 + 0.15 * (r1 - r0))
        ax.set_xlabel("axial (mm)")
        ax.set_ylabel("radius (mm)")
        ax.set_title(f"contact pattern on the pinion flank — {label}", fontsize=9)
    fig.tight_layout()
    return fig


def save_tca_plot(path_png, results, limits=None, title="TCA"):
    """Render :func:`plot_tca` and write the PNG atomically; returns the path."""
    import matplotlib.pyplot as plt

    from gearjax.io import atomic_write

    fig = plot_tca(results, limits, title)
    buf = _io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return atomic_write(path_png, buf.getvalue())
