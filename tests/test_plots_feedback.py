"""Feedback on long commands and readable figures (issue [R], item 6).

Synthetic inputs (no solves), matplotlib Agg.  Each test names the planted bug it
catches:

* the TE axis of a conjugate pair (TE = 1e-10 arcsec of rounding noise) spans the
  fixed +-1 arcsec instead of autoscaling the noise (bug: no noise floor);
* contact path and ellipses are drawn only on the flank: off-flank and
  non-converged positions are gaps in the path, and no ellipse pixel lies outside
  the flank outline (bugs: mask dropped, clip path dropped);
* the SRR colour scale is symmetric about 0 and keeps negative values (bugs: |SRR|,
  a one-sided colour map);
* figures are >= 7 in wide, every text >= 9 pt, PNGs at 150 dpi;
* the progress line is silent off a terminal and shows its phases (and the
  compiling state) when forced.
"""

import io
import math
import struct
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.text import Text  # noqa: E402

ARCSEC = math.pi / (180.0 * 3600.0)          # rad per arcsec, typed in (not imported)
C0 = np.array([0x1F, 0x77, 0xB4])            # matplotlib's default first colour


# -- synthetic TCA results ------------------------------------------------------------

def _tca(te_arcsec, axial, radial, margin, converged=None, a=3.0, b=1.0):
    """(path, margin, multi) with contact points (radial, 0, axial), ellipse major
    axis along the gear axis (semi-axis ``a``) and minor axis radial (``b``)."""
    n = len(axial)
    te = np.asarray(te_arcsec, float) * ARCSEC
    phi = np.linspace(-0.3, 0.3, n)
    path = SimpleNamespace(
        phi1=phi, axial1=np.asarray(axial, float), radial1=np.asarray(radial, float),
        converged=np.ones(n, bool) if converged is None else np.asarray(converged, bool),
        point=np.stack([np.asarray(radial, float), np.zeros(n), np.asarray(axial, float)], 1),
        normal=np.tile([0.0, 1.0, 0.0], (n, 1)), major_dir=np.tile([0.0, 0.0, 1.0], (n, 1)),
        semi_major=np.full(n, a), semi_minor=np.full(n, b), te=te)
    multi = SimpleNamespace(te_pairs=np.stack([te, te, te]), envelope=te,
                            ptp=float(np.ptp(te)), transfer_phi1=np.array([-0.1, 0.1]),
                            contact_ratio=1.5)
    return path, np.asarray(margin, float), multi


LIMITS = dict(face_half=10.0, root_radius=20.0, tip_radius=30.0)   # rectangle, mm


def _te_axes(fig):
    return fig.axes[0]


def test_conjugate_te_axis_is_not_autoscaled_into_noise():
    from gearjax.plot.tca import plot_tca

    n = 41
    saw = 1e-10 * ((np.arange(n) % 7) - 3.0)              # 6e-10 arcsec sawtooth
    res = _tca(saw, np.zeros(n), np.linspace(21, 29, n), np.ones(n))
    fig = plot_tca([("drive", *res)], LIMITS)
    try:
        lo, hi = _te_axes(fig).get_ylim()
        # at least the 0.01 arcsec floor -- in fact the fixed +-1 arcsec about 0
        assert hi - lo >= 0.01 and hi - lo == pytest.approx(2.0)
        assert lo < saw.min() and hi > saw.max()
        notes = [t.get_text() for t in _te_axes(fig).texts]
        assert any("conjugate" in t and "0.01" in t for t in notes), notes
    finally:
        plt.close(fig)
    # a real TE (5 arcsec p-t-p) is autoscaled: the axis hugs the data
    real = 2.5 * np.cos(np.linspace(0, 4 * np.pi, n))
    fig = plot_tca([("drive", *_tca(real, np.zeros(n), np.linspace(21, 29, n), np.ones(n)))],
                   LIMITS)
    try:
        lo, hi = _te_axes(fig).get_ylim()
        assert 5.0 <= hi - lo < 6.0
        assert not any("conjugate" in t.get_text() for t in _te_axes(fig).texts)
    finally:
        plt.close(fig)


def test_te_axis_limits_floor_values():
    from gearjax.plot.style import te_axis_limits

    lims, spread, floor = te_axis_limits([1e-10, -2e-10, np.nan])
    assert lims == (-1.0, 1.0) and spread == pytest.approx(3e-10) and floor == 0.01
    # 0.03 arcsec is above the absolute floor, but below 1e-6 of a 25-tooth pitch
    pitch = 2 * math.pi / 25 / ARCSEC                      # 51840 arcsec
    assert te_axis_limits([0.0, 0.03])[0] is None
    lims, _, floor = te_axis_limits([3.20, 3.23], pitch)
    assert floor == pytest.approx(0.05184) and lims[1] - lims[0] == pytest.approx(2.0)
    assert lims[0] < 3.2 and lims[1] > 3.23


def test_off_flank_contact_is_not_drawn_and_ellipses_are_clipped():
    from gearjax.plot.tca import plot_tca

    n = 21
    axial = np.linspace(-14.0, 14.0, n)                     # crosses toe and heel (+-10)
    radial = np.full(n, 25.0)
    margin = np.where(np.abs(axial) <= 10.0, 1.0, -1.0)
    conv = np.ones(n, bool)
    conv[n // 2] = False                                    # inside, but not converged
    on = (margin >= 0) & conv
    # ellipses larger than the flank height (b = 8 mm > 5 mm to the tip/root)
    res = _tca(np.zeros(n) + 3 * np.cos(axial), axial, radial, margin, conv, a=4.0, b=8.0)
    fig = plot_tca([("drive", *res)], LIMITS)
    try:
        ax = fig.axes[1]
        (pth,) = [ln for ln in ax.lines if ln.get_label() == "path of contact"]
        x = np.asarray(pth.get_xdata(), float)
        assert np.array_equal(np.isfinite(x), on)           # off-flank points are gaps
        np.testing.assert_array_equal(x[on], axial[on])
        ax.get_legend().remove()                            # its C0 sample is not an ellipse
        fig.canvas.draw()
        img = np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(int)
        H = img.shape[0]
        bb = ax.get_window_extent()
        rows, cols = np.nonzero(np.all(np.abs(img - C0) <= 12, axis=-1))
        xd, yd = cols + 0.5, H - rows - 0.5                 # pixel centres, display coords
        inax = (xd > bb.x0) & (xd < bb.x1) & (yd > bb.y0) & (yd < bb.y1)
        xd, yd = xd[inax], yd[inax]
        assert xd.size > 200                                # ellipses were drawn at all
        (x0, y0), (x1, y1) = ax.transData.transform([[-10.0, 20.0], [10.0, 30.0]])
        tol = 2.0                                           # px: line width at the edge
        assert np.all((xd >= x0 - tol) & (xd <= x1 + tol) & (yd >= y0 - tol) & (yd <= y1 + tol))
        # the unclipped ellipses would reach 3 mm above the tip: they are cut at the edge
        assert yd.max() > y1 - 3.0
    finally:
        plt.close(fig)


# -- synthetic kinematics fields ------------------------------------------------------

def _fields(shape=(9, 7)):
    """A parallelogram flank (z 15..30 mm, radius 80..115 mm) in the plane y = 0."""
    u, v = np.meshgrid(np.linspace(0, 1, shape[0]), np.linspace(0, 1, shape[1]), indexing="ij")
    Z = 15.0 + 8.0 * v + 7.0 * u
    R = 80.0 + 35.0 * u
    r = np.stack([R, np.zeros_like(R), Z], -1)
    unit = lambda a, b: np.broadcast_to(np.array([a, 0.0, b]) / math.hypot(a, b), r.shape)
    return SimpleNamespace(
        axial=np.stack([Z, R], -1), r=r, contact_dir=unit(1.0, 1.0), v_dir=unit(1.0, -0.3),
        srr=-0.9 + 1.4 * v, u_e=-4.0 - 14.0 * v, u_s=-2.0 + 18.0 * v, r_eff=3.0 + 40.0 * v,
        k_II=0.02 + 0.0 * v, phi_I=1.0 + v, phi_II=2.0 + v), Z, R


def _mesh(ax):
    from matplotlib.collections import QuadMesh
    (m,) = [c for c in ax.collections if isinstance(c, QuadMesh)]
    return m


def test_srr_colour_scale_is_zero_centred_and_signed():
    from gearjax.plot.kinematics import field_maps

    f, Z, R = _fields()
    fig = field_maps({"case": f}, names=("u_e", "srr", "r_eff"))
    try:
        m = _mesh(fig.axes[1])                             # the SRR panel
        vals = np.asarray(m.get_array())
        assert vals.min() == pytest.approx(-0.9) and vals.max() == pytest.approx(0.5)
        lo, hi = m.norm.vmin, m.norm.vmax
        assert lo == pytest.approx(-0.9) and hi == pytest.approx(0.9)   # +- max|SRR|
        assert np.all(np.asarray(m.cmap(m.norm(0.0)))[:3] > 0.9)        # zero is white
        ue = _mesh(fig.axes[0])                             # u_e < 0 keeps its sign
        assert np.asarray(ue.get_array()).max() < 0 and ue.norm.vmin == -ue.norm.vmax
        reff = _mesh(fig.axes[2])                           # positive field: its own range
        assert reff.norm.vmin == pytest.approx(3.0)
        colorbars = [a for a in fig.axes if a.get_label() == "<colorbar>"]
        ylo, yhi = colorbars[1].get_ylim()
        assert ylo < 0 < yhi and ylo == pytest.approx(-yhi)
    finally:
        plt.close(fig)


def test_kinematics_segments_and_arrows_clipped_to_the_flank():
    from matplotlib.quiver import Quiver

    from gearjax.plot.kinematics import field_maps

    f, Z, R = _fields()
    fig = field_maps({"case": f}, names=("srr",))
    try:
        ax = fig.axes[0]
        corners = ax.transData.transform([[Z[0, 0], R[0, 0]], [Z[0, -1], R[0, -1]],
                                          [Z[-1, -1], R[-1, -1]], [Z[-1, 0], R[-1, 0]]])
        segs = [ln for ln in ax.lines if len(ln.get_xdata()) == 2]
        quiv = [c for c in ax.collections if isinstance(c, Quiver)]
        assert len(segs) > 10 and len(quiv) == 1
        for a in segs + quiv:
            cp = a.get_clip_path()
            assert cp is not None, a
            verts = cp.get_fully_transformed_path().vertices
            # the clip polygon is the flank outline: its four corners, all on its edges
            for c in corners:
                assert np.min(np.hypot(*(verts - c).T)) < 1e-6
            assert np.all(_on_edges(verts, corners))
    finally:
        plt.close(fig)


def _on_edges(p, corners):
    """Points within 1e-6 of the polygon's edges."""
    out = np.zeros(len(p), bool)
    for a, b in zip(corners, np.roll(corners, -1, axis=0)):
        t = np.clip(((p - a) @ (b - a)) / ((b - a) @ (b - a)), 0, 1)
        out |= np.hypot(*(p - (a + t[:, None] * (b - a))).T) < 1e-6
    return out


# -- size, fonts, resolution ----------------------------------------------------------

def _check_readable(fig):
    assert fig.get_size_inches()[0] >= 7.0
    fig.canvas.draw()
    small = [(t.get_text(), t.get_fontsize()) for t in fig.findobj(Text)
             if t.get_visible() and t.get_text().strip() and t.get_fontsize() < 9.0]
    assert not small, small


def _png_width_dpi(data):
    """(width in pixels, dots per inch from the pHYs chunk) of PNG bytes."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    width, pos, dpi = struct.unpack(">I", data[16:20])[0], 8, None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"pHYs":
            ppm, _, unit = struct.unpack(">IIB", data[pos + 8:pos + 17])
            assert unit == 1                                # pixels per metre
            dpi = ppm * 0.0254
        pos += 12 + n
    return width, dpi


def test_figures_are_report_sized(tmp_path):
    from gearjax.plot.flank import plot_flank_axial
    from gearjax.plot.kinematics import field_maps, save_figure, trend_plot
    from gearjax.plot.tca import plot_tca, save_tca_plot
    from gearjax.plot.tribology import mesh_friction_figure, save_figure_atomic, stribeck_figure

    n = 21
    res = _tca(np.cos(np.linspace(0, 6, n)), np.zeros(n), np.linspace(21, 29, n), np.ones(n))
    f, _, _ = _fields()
    x = np.logspace(-6, -3, 8)
    curve = SimpleNamespace(stribeck_number=x, lam=x * 1e4, u_e=x * 1e6, mu=0.05 + 0 * x,
                            friction=SimpleNamespace(regime=np.array([0, 0, 1, 1, 1, 2, 2, 2])))
    g = SimpleNamespace(points=np.stack(np.meshgrid(np.linspace(20, 25, 5), [0.0],
                                                    np.linspace(100, 140, 7), indexing="ij"),
                                        -1).reshape(5, 7, 3))
    figs = [plot_tca([("drive", *res)], LIMITS), field_maps({"c": f}),
            field_maps({"c": f}, names=("srr",)),
            trend_plot(np.arange(4.0), {"a": np.arange(4.0)}, {"a": np.ones(4)}),
            stribeck_figure([curve], ["F"]),
            mesh_friction_figure(np.linspace(0, 1, 5), np.full((5, 2), 0.05), np.ones(5)),
            plot_flank_axial(g).figure]
    try:
        for fig in figs:
            _check_readable(fig)
    finally:
        for fig in figs:
            plt.close(fig)
    # PNGs at 150 dpi (the resolution recorded in the file), >= 6.5 in of pixels wide
    # (a tight bounding box trims the margins of the >= 7 in figure)
    pngs = [save_tca_plot(tmp_path / "t.png", [("drive", *res)], LIMITS).read_bytes(),
            save_figure(field_maps({"c": f}, names=("srr",)), tmp_path / "k.png").read_bytes(),
            open(save_figure_atomic(stribeck_figure([curve]), tmp_path / "s.png"), "rb").read()]
    for data in pngs:
        width, dpi = _png_width_dpi(data)
        assert dpi == pytest.approx(150, abs=0.5) and width >= 6.5 * 150


# -- progress -------------------------------------------------------------------------

class _Tty(io.StringIO):
    def isatty(self):
        return True


def _fresh_jit_call():
    import jax
    import jax.numpy as jnp
    k = np.random.default_rng().integers(1, 10**9)          # a new program each call
    return jax.jit(lambda x: jnp.sin(x) * k)(jnp.ones(3)).block_until_ready()


def test_progress_silent_off_a_terminal(monkeypatch):
    from gearjax.progress import Progress

    monkeypatch.delenv("GEARJAX_PROGRESS", raising=False)
    s = io.StringIO()
    with Progress(2, "tca", stream=s) as bar:
        with bar.phase("drive side"):
            _fresh_jit_call()
        bar.update()
    assert s.getvalue() == ""
    monkeypatch.setenv("GEARJAX_PROGRESS", "0")             # silenced even on a terminal
    t = _Tty()
    with Progress(1, "tca", stream=t) as bar, bar.phase("drive side"):
        pass
    assert t.getvalue() == ""


def test_progress_phases_when_forced(monkeypatch):
    from gearjax.progress import COMPILE_TEXT, Progress

    monkeypatch.setenv("GEARJAX_PROGRESS", "1")
    s = io.StringIO()
    with Progress(2, "tca", stream=s) as bar:
        with bar.phase("drive side: contact solve"):
            _fresh_jit_call()
        bar.update()
        with bar.phase("coast side: contact solve"):
            pass
        bar.update()
    lines = s.getvalue().splitlines()
    assert "\r" not in s.getvalue()                         # a log: plain lines
    assert any("drive side: contact solve" in ln and COMPILE_TEXT in ln for ln in lines), lines
    assert any(ln.startswith("tca: drive side: contact solve done in") and "compiling" in ln
               for ln in lines), lines
    assert any(ln.startswith("tca: coast side: contact solve done in") for ln in lines)
    assert lines[-1].startswith("tca [") and "2/2" in lines[-1]
    # on a terminal the line is redrawn in place and the phase line stays
    monkeypatch.delenv("GEARJAX_PROGRESS")
    t = _Tty()
    with Progress(1, "kinematics", stream=t) as bar, bar.phase("7x5 grid"):
        _fresh_jit_call()
    out = t.getvalue()
    assert "\r" in out and COMPILE_TEXT in out and "kinematics: 7x5 grid done in" in out


def test_cli_progress_only_when_forced(capsys, monkeypatch):
    from gearjax.cli import main

    monkeypatch.delenv("GEARJAX_PROGRESS", raising=False)
    assert main(["blank", "example:hft_8x43"]) == 0
    # no progress line (the one warning line of the 8/43 blank is not progress)
    err = capsys.readouterr().err
    assert all(ln.startswith("gearjax: warning:") for ln in err.splitlines()), err
    monkeypatch.setenv("GEARJAX_PROGRESS", "1")
    assert main(["blank", "example:hft_8x43"]) == 0
    err = capsys.readouterr().err
    assert "blank: blank solve done in" in err
