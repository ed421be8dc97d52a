"""Shared figure conventions: report size and fonts, TE axis noise floor, flank clipping,
zero-centred colour scales for signed fields.

* :data:`REPORT_RC` -- matplotlib settings every gearjax figure is built under
  (:func:`report_style`): fonts >= 9 pt, figures >= 7 in wide (:data:`MIN_WIDTH_IN`),
  saved at :data:`DPI` = 150 dots per inch with a tight bounding box.
* :func:`te_axis_limits` -- the TE axis of a conjugate pair.  A conjugate pair's TE
  is zero up to the solver's rounding (~1e-10 arcsec); autoscaling would blow that
  noise up into a sawtooth filling the axis.  Below the noise floor
  ``max(TE_FLOOR_ARCSEC, TE_FLOOR_REL * pitch)`` (0.01 arcsec, or 1e-6 of the angular
  pitch in arcsec when it is given) the axis is fixed at +- :data:`TE_HALF_SPAN_ARCSEC`
  (1 arcsec) about the mid value instead.
* :func:`clip_to` -- clip artists to a flank outline polygon (data coordinates), so
  contact ellipses, contact-line segments and sliding arrows end at the flank edge.
* :func:`signed_scale` -- a diverging colour map with limits symmetric about 0, so a
  signed field (SRR, u_s, u_e) keeps its sign in the colour bar.
"""

from __future__ import annotations

import numpy as np

__all__ = ["REPORT_RC", "MIN_WIDTH_IN", "MIN_FONT_PT", "DPI", "TE_FLOOR_ARCSEC",
           "TE_FLOOR_REL", "TE_HALF_SPAN_ARCSEC", "report_style", "te_axis_limits",
           "clip_to", "grid_outline", "signed_scale"]

MIN_WIDTH_IN = 7.0          # smallest figure width (in): a report column at full size
MIN_FONT_PT = 9.0           # smallest font on any figure (pt)
DPI = 150                   # PNG resolution (dots per inch)

REPORT_RC = {
    "font.size": 10.0, "axes.titlesize": 11.0, "axes.labelsize": 10.0,
    "xtick.labelsize": 9.0, "ytick.labelsize": 9.0, "legend.fontsize": 9.0,
    "legend.title_fontsize": 9.0, "figure.titlesize": 12.0,
    "savefig.dpi": DPI, "savefig.bbox": "tight", "axes.grid": False,
    "axes.formatter.useoffset": False,     # no "1e-11" offsets above an axis
}

TE_FLOOR_ARCSEC = 0.01      # absolute TE noise floor (arcsec)
TE_FLOOR_REL = 1e-6         # relative to the angular pitch (arcsec / arcsec)
TE_HALF_SPAN_ARCSEC = 1.0   # half span of the fixed TE axis of a conjugate pair (arcsec)


def report_style():
    """Context manager applying :data:`REPORT_RC` (``matplotlib.rc_context``)."""
    import matplotlib

    return matplotlib.rc_context(REPORT_RC)


def te_axis_limits(te_arcsec, pitch_arcsec=None):
    """``(limits, spread, floor)`` for a TE axis (all arcsec).

    ``te_arcsec``: any array of plotted TE values (NaN ignored); ``pitch_arcsec``:
    the pinion's angular pitch 2 pi/z1 in arcsec (optional).  ``spread`` is
    max - min of the finite values, ``floor = max(TE_FLOOR_ARCSEC, TE_FLOOR_REL *
    pitch)``.  ``limits`` is ``None`` (autoscale) when ``spread >= floor``, else
    ``(mid - 1, mid + 1)`` with ``mid`` the mid value (rounded to a multiple of
    ``floor``, so the tick labels do not show the noise either).
    """
    v = np.asarray(te_arcsec, dtype=float)
    v = v[np.isfinite(v)]
    floor = TE_FLOOR_ARCSEC
    if pitch_arcsec is not None and np.isfinite(pitch_arcsec):
        floor = max(floor, TE_FLOOR_REL * abs(float(pitch_arcsec)))
    if v.size == 0:
        return None, float("nan"), floor
    spread = float(v.max() - v.min())
    if spread >= floor:
        return None, spread, floor
    mid = floor * round(0.5 * (v.max() + v.min()) / floor)
    return (mid - TE_HALF_SPAN_ARCSEC, mid + TE_HALF_SPAN_ARCSEC), spread, floor


def grid_outline(X, Y):
    """Closed boundary polygon (n, 2) of a structured grid ``X, Y`` (m, k): the four
    edges of the parameter rectangle, in order."""
    X, Y = np.asarray(X, float), np.asarray(Y, float)
    P = np.stack([X, Y], axis=-1)
    ring = np.concatenate([P[0, :], P[1:, -1], P[-1, -2::-1], P[-2::-1, 0]])
    return ring


def clip_to(artists, outline, ax):
    """Clip each artist to the polygon ``outline`` ((n, 2), data coordinates of ``ax``).

    Returns the clipping :class:`matplotlib.patches.Polygon` (not drawn itself)."""
    from matplotlib.patches import Polygon

    poly = Polygon(np.asarray(outline, float), closed=True, transform=ax.transData,
                   facecolor="none", edgecolor="none")
    for a in artists:
        a.set_clip_path(poly)
    return poly


def signed_scale(values, cmap="RdBu_r"):
    """``(norm, cmap)`` for a signed field: limits +- max|v| about 0 (white = 0).

    A field of one sign still gets symmetric limits, so its colour bar shows the sign
    (and how far from zero it stays); an all-zero field gets +-1."""
    from matplotlib.colors import Normalize

    v = np.asarray(values, float)
    m = float(np.nanmax(np.abs(v))) if np.any(np.isfinite(v)) else 0.0
    m = m if m > 0.0 else 1.0
    return Normalize(vmin=-m, vmax=m), cmap
