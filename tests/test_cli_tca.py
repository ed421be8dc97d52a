"""``gearjax tca`` in-process (same static configuration as tests/test_tca.py, so the
compiled TCA is shared within one pytest run)."""

import json

import numpy as np

from gearjax.cli import main
from gearjax.gears.involute.geometry import InvolutePair, pair_geometry

DESIGN = "involute:z1=25,z2=41,m=2,alpha=20,b=20,crown=1e-4"


def test_json_te_is_the_parabola_of_the_profile_crown(capsys, tmp_path):
    png = tmp_path / "tca.png"
    assert main(["tca", DESIGN, "--json", "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("phi1_rad", "te_arcsec", "te_pairs_arcsec", "envelope_arcsec", "ptp_arcsec",
                "transfer_phi1_rad", "contact_ratio", "path", "ellipses", "flags"):
        assert key in out
    phi = np.array(out["phi1_rad"])
    te = np.array([np.nan if v is None else v for v in out["te_arcsec"]])
    on = np.array(out["flags"]["on_flank"])
    assert len(phi) == 61 and on.sum() > 30 and np.all(np.isfinite(te[on]))
    pair = InvolutePair.create(25, 41, 2.0, 20.0)
    geo = pair_geometry(pair)
    s = float(geo["rb1"]) * (phi - phi[30])
    theory = -1e-4 * (s * np.tan(np.radians(20.0))) ** 2 / float(geo["rb2"])
    theory /= np.pi / (180 * 3600)
    # first-order closed form; the O(a^2) remainder is < 0.5 % at a = 1e-4/mm
    assert np.max(np.abs(te[on] - theory[on])) < 5e-3 * np.max(np.abs(theory[on]))
    assert all(v is None for v in out["ellipses"]["semi_major_mm"])   # line contact
    # no contact of pair 0, no path point: null (0.0 read as a contact at mid-face)
    touch = on | np.array(out["flags"]["edge"])
    assert (~touch).sum() > 10
    for key in ("axial1_mm", "radial1_mm", "axial2_mm", "radial2_mm"):
        vals = out["path"][key]
        assert all((v is None) != bool(t) for v, t in zip(vals, touch)), key
        assert all((v is None) != bool(t) for v, t in zip(out["ellipses"]["semi_minor_mm"], touch))
    assert out["overlap_ratio"] == 0.0          # spur line contact: no overlap
    assert out["input"]["pitches"] == 1.25      # the family's default grid for this pair
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_table_output(capsys):
    assert main(["tca", DESIGN]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("# TCA involute:")
    assert "p-t-p" in lines[1]
    assert len(lines) == 3 + 61


def test_flanks_that_do_not_touch_exit_nonzero_with_one_line(capsys):
    assert main(["tca", DESIGN, "--misalign", "dE=40"]) == 3
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "do not touch" in err[0]


def test_hypoid_design_json_and_plot(capsys, tmp_path):
    """The shipped synthesised spiral-bevel pair: localised bearing on the flank,
    parabolic TE of a few arc-seconds, the bevel-gear path keys, a figure."""
    png = tmp_path / "sb.png"
    assert main(["tca", "example:spiral_bevel_10x30_synthesised", "--positions", "21", "--json",
                 "--plot", str(png)]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("xi1", "h1_mm", "xi2", "h2_mm", "axial1_mm"):
        assert len(out["path"][key]) == 21
    on = np.array(out["flags"]["on_flank"])
    assert on[10] and on.sum() >= 5
    assert abs(out["path"]["xi1"][10]) < 0.2                      # bearing near mid face
    # The design target of the synthesis (docs/tca.md, local synthesis): a parabolic TE
    # whose drop from the apex at +-half a pitch is 8 arcsec.  A parabola fitted to
    # pair 0 over its on-flank points (-0.25 ... +0.625 pitch at 8 steps per pitch)
    # gives 8.3 arcsec; the tolerance of 1 arcsec is what the cubic and quartic TE
    # terms do to a quadratic fit on this lopsided segment (cubic/quartic fits of the
    # same points give 7.4 / 7.9 arcsec on the on-flank side).  A wrong arc-second
    # conversion or a TE of the wrong pair fails it.
    phi = np.array(out["phi1_rad"])
    te = np.array([np.nan if v is None else v for v in out["te_arcsec"]])
    pitch = 2 * np.pi / 10
    c2 = np.polyfit((phi[on] - phi[10]) / pitch, te[on], 2)[0]
    assert abs(c2 * 0.25 - 8.0) < 1.0, c2 * 0.25
    # The envelope is the extremum of the pair curves: its peak-to-peak over one pitch
    # lies between the parabola's drop at the nearer transfer (>= 0.38 pitch from the
    # apex, docs/tca.md) and at the farther one (<= 0.62 pitch): 32*0.38^2 ... 32*0.62^2
    # arcsec for the 8-arcsec parabola, widened by the 1-arcsec fit tolerance.
    assert 32 * 0.38 ** 2 - 1.0 < out["ptp_arcsec"] < 32 * 0.62 ** 2 + 1.0, out["ptp_arcsec"]
    assert all(v is not None for v, o in zip(out["ellipses"]["semi_major_mm"], on) if o)
    # crossing flanks per point: on the flank without an ellipse (here: nowhere)
    no_ellipse = np.array([v is None for v in out["ellipses"]["semi_major_mm"]])
    assert out["flags"]["crossing_flanks"] == (on & no_ellipse).tolist()
    assert out["quality"]["crossing_flanks"] is False
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_bad_input_one_line(capsys):
    assert main(["tca", "example:no_such_design"]) == 2
    assert "no_such_design" in capsys.readouterr().err
    assert main(["tca", DESIGN, "--positions", "60"]) == 2
    assert "positions" in capsys.readouterr().err
    assert main(["tca", DESIGN, "--misalign", "dX=1"]) == 2
    assert "dX" in capsys.readouterr().err
    assert main(["tca", DESIGN, "--pitches", "5"]) == 2
    err = capsys.readouterr().err
    assert "pitches" in err and "4" in err and len(err.strip().splitlines()) == 1
