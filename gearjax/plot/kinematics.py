"""Figures of the [Eigenfunctions] flank fields (matplotlib, Agg; no ``plt.show``).

* :func:`field_maps` -- fields (u_e, SRR, R_eff, ...) over the gear flank in the
  axial projection (coordinate along the gear axis, radius from it; mm), with the
  instantaneous contact-line directions (short segments) and the directions of
  sliding (arrows, v21 projected), both clipped to the flank; zero curves of
  Phi_I / Phi_II when present.  Signed fields keep their sign: a diverging colour
  map with limits symmetric about zero.
* :func:`trend_plot` -- a statistic against the cutter radius with its derivative.
* :func:`save_figure` -- PNG written atomically (:func:`gearjax.io.atomic_write`).
"""

from __future__ import annotations

import io as _io

from gearjax.plot import headless

headless()
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from matplotlib.lines import Line2D  # noqa: E402

from gearjax.io import atomic_write  # noqa: E402
from gearjax.plot.style import (DPI, MIN_WIDTH_IN, clip_to, grid_outline, report_style,  # noqa: E402
                                signed_scale)

__all__ = ["SIGNED", "axial_components", "field_values", "field_maps", "trend_plot", "save_figure"]

_LABELS = {"u_e": "u_e entrainment (mm/rad)", "srr": "SRR slide-to-roll ratio (-)",
           "r_eff": "R_eff effective radius (mm)", "abs_srr": "|SRR| (-)",
           "u_s": "u_s sliding (mm/rad)", "phi_I": "Phi_I", "phi_II": "Phi_II",
           "k_II": "K_II induced curvature (1/mm)"}
# fields whose sign means something: zero-centred diverging colour scale
SIGNED = frozenset({"u_e", "u_s", "srr", "phi_I", "phi_II", "k_II"})


def axial_components(r, t):
    """Components of tangent vectors ``t`` at points ``r`` (fixed frame, gear axis z)
    in the axial projection: (along the axis, along the radius)."""
    r = np.asarray(r)
    t = np.asarray(t)
    rho = np.linalg.norm(r[..., :2], axis=-1)
    er = np.concatenate([r[..., :2] / rho[..., None], np.zeros_like(rho)[..., None]], -1)
    return t[..., 2], np.sum(t * er, -1)


def field_values(f, name):
    """The array drawn for ``name``: the field itself (signed), or ``|SRR|`` for
    ``abs_srr``."""
    if name == "abs_srr":
        return np.abs(np.asarray(f.srr))
    return np.asarray(getattr(f, name))


def _panel(ax, f, name, title=None):
    A = np.asarray(f.axial)
    Z, R = A[..., 0], A[..., 1]
    V = field_values(f, name)
    if name in SIGNED or (np.nanmin(V) < 0.0 < np.nanmax(V)):
        norm, cmap = signed_scale(V)           # white = 0, sign kept in the colour bar
    else:
        norm, cmap = None, "viridis"
    m = ax.pcolormesh(Z, R, V, shading="gouraud", cmap=cmap, norm=norm)
    outline = grid_outline(Z, R)
    cz, cr = axial_components(f.r, f.contact_dir)
    Lz, Lr = 0.05 * np.ptp(Z), 0.05 * np.ptp(R)
    sub = (slice(None, None, max(1, Z.shape[0] // 8)), slice(None, None, max(1, Z.shape[1] // 6)))
    segs = []
    for (z, r, a, b) in zip(Z[sub].ravel(), R[sub].ravel(), cz[sub].ravel(), cr[sub].ravel()):
        # tangent in data coordinates, drawn with a fixed length on the (auto-aspect) axes
        vis = np.hypot(a / Lz, b / Lr) + 1e-300
        segs += ax.plot([z - a / vis, z + a / vis], [r - b / vis, r + b / vis], "-",
                        color="0.1", lw=0.9)
    vz, vr = axial_components(f.r, f.v_dir)
    s = sub
    vis = np.hypot(vz / Lz, vr / Lr) + 1e-300
    q = ax.quiver(Z[s], R[s], (1.2 * vz / vis)[s], (1.2 * vr / vis)[s], color="gold",
                  edgecolor="k", linewidth=0.5, width=0.007, angles="xy", scale_units="xy",
                  scale=1.0, pivot="mid")
    clip_to(segs + [q], outline, ax)           # nothing drawn past the flank edge
    ax.plot(outline[:, 0], outline[:, 1], "k-", lw=0.8)
    for fld, col in (("phi_I", "r"), ("phi_II", "m")):
        P = np.asarray(getattr(f, fld))
        if P.min() < 0 < P.max():
            ax.contour(Z, R, P, levels=[0.0], colors=col, linewidths=1.5)
    ax.set_aspect("auto")
    ax.set_xlabel("z along gear axis (mm)")
    ax.set_ylabel("radius (mm)")
    ax.set_title(title or _LABELS.get(name, name))
    cb = ax.figure.colorbar(m, ax=ax, shrink=0.9)
    cb.set_label(_LABELS.get(name, name))
    return m, cb


def field_maps(fields_by_case: dict, names=("u_e", "srr", "r_eff")):
    """Figure with one row per case (``{label: FlankFields}``) and one column per
    field name.  Signed fields (u_e, u_s, SRR, K_II, Phi) use a diverging colour map
    with limits symmetric about 0 (white = 0), so the colour bar keeps the sign;
    ``abs_srr`` draws |SRR|.  Dark segments: contact-line direction; gold arrows:
    sliding direction (v21); both clipped to the flank outline.  Red / magenta
    curves: Phi_I = 0 / Phi_II = 0 if present.  At least 7 in wide, fonts >= 9 pt."""
    nr, nc = len(fields_by_case), len(names)
    with report_style():
        fig, axes = plt.subplots(nr, nc, figsize=(max(MIN_WIDTH_IN, 4.6 * nc), 4.0 * nr + 0.6),
                                 squeeze=False)
        for i, (label, f) in enumerate(fields_by_case.items()):
            for j, nm in enumerate(names):
                _panel(axes[i, j], f, nm, f"{label}\n{_LABELS.get(nm, nm)}")
        handles = [Line2D([], [], color="0.1", lw=0.9, label="contact-line direction"),
                   Line2D([], [], color="gold", marker=">", ms=8, mec="k", ls="-", lw=2,
                          label="sliding direction (v21)")]
        fig.legend(handles=handles, loc="lower center", ncol=2, frameon=False)
        fig.tight_layout(rect=(0, 0.06, 1, 1))
    return fig


def trend_plot(r0, values: dict, derivatives: dict, marks=None):
    """Statistics (top row) and their derivatives d/dr0 (bottom row) against the
    cutter radius ``r0`` (mm); ``marks``: radii to mark (the cutters of [Eigenfunctions])."""
    names = list(values)
    with report_style():
        fig, axes = plt.subplots(2, len(names), figsize=(max(MIN_WIDTH_IN, 3.2 * len(names)), 6.0),
                                 squeeze=False)
        for j, nm in enumerate(names):
            axes[0, j].plot(r0, values[nm], "b-")
            axes[1, j].plot(r0, derivatives[nm], "r-")
            axes[0, j].set_title(nm)
            axes[1, j].set_title(f"d {nm} / d r0 (1/mm)")
            for a in axes[:, j]:
                a.set_xlabel("r0 (mm)")
                for x in (marks or ()):
                    a.axvline(x, color="0.7", lw=0.6)
                a.grid(alpha=0.3)
        fig.tight_layout()
    return fig


def save_figure(fig, path, dpi: int = DPI):
    """Write ``fig`` as PNG to ``path`` atomically (150 dpi by default) and close it."""
    buf = _io.BytesIO()
    with report_style():
        fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return atomic_write(path, buf.getvalue())
