"""Figures of the [Eigenfunctions] flank fields (matplotlib, Agg; no ``plt.show``).

* :func:`field_maps` -- fields (u_e, SRR, R_eff, ...) over the gear flank in the
  axial projection (coordinate along the gear axis, radius from it; mm), with the
  instantaneous contact-line directions (short segments) and the directions of
  sliding (arrows, v21 projected); zero curves of Phi_I / Phi_II when present.
* :func:`trend_plot` -- a statistic against the cutter radius with its derivative.
* :func:`save_figure` -- PNG written atomically (:func:`gearjax.io.atomic_write`).
"""

from __future__ import annotations

import io as _io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from gearjax.io import atomic_write  # noqa: E402

__all__ = ["axial_components", "field_maps", "trend_plot", "save_figure"]

_LABELS = {"u_e": "|u_e| entrainment (mm/rad)", "srr": "SRR", "r_eff": "R_eff (mm)",
           "abs_srr": "|SRR|", "u_s": "u_s sliding (mm/rad)", "phi_I": "Phi_I",
           "phi_II": "Phi_II", "k_II": "K_II (1/mm)"}


def axial_components(r, t):
    """Components of tangent vectors ``t`` at points ``r`` (fixed frame, gear axis z)
    in the axial projection: (along the axis, along the radius)."""
    r = np.asarray(r)
    t = np.asarray(t)
    rho = np.linalg.norm(r[..., :2], axis=-1)
    er = np.concatenate([r[..., :2] / rho[..., None], np.zeros_like(rho)[..., None]], -1)
    return t[..., 2], np.sum(t * er, -1)


def _panel(ax, f, name, title=None):
    A = np.asarray(f.axial)
    Z, R = A[..., 0], A[..., 1]
    if name == "u_e":
        V = np.abs(np.asarray(f.u_e))
    elif name == "abs_srr":
        V = np.abs(np.asarray(f.srr))
    else:
        V = np.asarray(getattr(f, name))
    m = ax.pcolormesh(Z, R, V, shading="gouraud", cmap="viridis")
    cz, cr = axial_components(f.r, f.contact_dir)
    Lz, Lr = 0.05 * np.ptp(Z), 0.05 * np.ptp(R)
    sub = (slice(None, None, max(1, Z.shape[0] // 8)), slice(None, None, max(1, Z.shape[1] // 6)))
    for (z, r, a, b) in zip(Z[sub].ravel(), R[sub].ravel(), cz[sub].ravel(), cr[sub].ravel()):
        # tangent in data coordinates, drawn with a fixed length on the (auto-aspect) axes
        vis = np.hypot(a / Lz, b / Lr) + 1e-300
        ax.plot([z - a / vis, z + a / vis], [r - b / vis, r + b / vis], "w-", lw=0.7)
    vz, vr = axial_components(f.r, f.v_dir)
    s = sub
    vis = np.hypot(vz / Lz, vr / Lr) + 1e-300
    ax.quiver(Z[s], R[s], (1.2 * vz / vis)[s], (1.2 * vr / vis)[s], color="k", width=0.005,
              angles="xy", scale_units="xy", scale=1.0, pivot="mid")
    for fld, col in (("phi_I", "r"), ("phi_II", "m")):
        P = np.asarray(getattr(f, fld))
        if P.min() < 0 < P.max():
            ax.contour(Z, R, P, levels=[0.0], colors=col, linewidths=1.5)
    ax.set_aspect("auto")
    ax.set_xlabel("z along gear axis (mm)", fontsize=7)
    ax.set_ylabel("radius (mm)", fontsize=7)
    ax.tick_params(labelsize=6)
    ax.set_title(title or _LABELS.get(name, name), fontsize=8)
    cb = ax.figure.colorbar(m, ax=ax, shrink=0.8)
    cb.ax.tick_params(labelsize=6)


def field_maps(fields_by_case: dict, names=("u_e", "abs_srr", "r_eff")):
    """Figure with one row per case (``{label: FlankFields}``) and one column per
    field name.  White segments: contact-line direction; black arrows: sliding
    direction (v21); red / magenta curves: Phi_I = 0 / Phi_II = 0 if present."""
    nr, nc = len(fields_by_case), len(names)
    fig, axes = plt.subplots(nr, nc, figsize=(3.3 * nc, 2.6 * nr), squeeze=False)
    for i, (label, f) in enumerate(fields_by_case.items()):
        for j, nm in enumerate(names):
            _panel(axes[i, j], f, nm, f"{label}: {_LABELS.get(nm, nm)}")
    fig.tight_layout()
    return fig


def trend_plot(r0, values: dict, derivatives: dict, marks=None):
    """Statistics (top row) and their derivatives d/dr0 (bottom row) against the
    cutter radius ``r0`` (mm); ``marks``: radii to mark (the cutters of [Eigenfunctions])."""
    names = list(values)
    fig, axes = plt.subplots(2, len(names), figsize=(2.6 * len(names), 4.4), squeeze=False)
    for j, nm in enumerate(names):
        axes[0, j].plot(r0, values[nm], "b-")
        axes[1, j].plot(r0, derivatives[nm], "r-")
        axes[0, j].set_title(nm, fontsize=8)
        axes[1, j].set_title(f"d {nm} / d r0 (1/mm)", fontsize=8)
        for a in axes[:, j]:
            a.tick_params(labelsize=6)
            a.set_xlabel("r0 (mm)", fontsize=7)
            for x in (marks or ()):
                a.axvline(x, color="0.7", lw=0.6)
            a.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def save_figure(fig, path, dpi: int = 90):
    """Write ``fig`` as PNG to ``path`` atomically and close it."""
    buf = _io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    plt.close(fig)
    return atomic_write(path, buf.getvalue())
