"""TCA of the preset-TE bevel pair ([Preset-TE-bevel]): pure rolling, the preset parabola,
the transfer, the CLI.  One compiled TCA program for every case (the design, the side
and the misalignment are data; the grid options are those of ``gearjax tca --positions
41 --pitches 1``, so the in-process CLI tests reuse it)."""

import dataclasses
import json
import math

import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.cli import main
from gearjax.gears.preset_bevel import analysis as A
from gearjax.gears.preset_bevel import geometry as G

OPTS = dict(steps_per_pitch=16, half_pitches=1.0, n_pairs=3, kinematics=False)
EX = "example:preset_te_bevel_10x30"


@pytest.fixture(scope="module")
def des():
    return gj.load_design(EX).design


@pytest.fixture(scope="module")
def runs(des):
    plain = dataclasses.replace(des, kappa=jnp.asarray(0.0))
    dg = gj.Misalignment.create(dG=0.05)
    return {"plain": gj.run_tca(plain, side="drive", **OPTS),
            "plain_coast": gj.run_tca(plain, side="coast", **OPTS),
            "mod": gj.run_tca(des, side="drive", **OPTS),
            "mod_coast": gj.run_tca(des, side="coast", **OPTS),
            "plain_dG": gj.run_tca(plain, dg, side="drive", strict=False, **OPTS),
            "mod_dG": gj.run_tca(des, dg, side="drive", strict=False, **OPTS)}


@pytest.mark.parametrize("case", ["plain", "plain_coast"])
def test_unmodified_pair_rolls_along_the_designed_curve(des, runs, case):
    res = runs[case]
    p = res.path
    assert bool(np.all(np.asarray(p.converged)))
    phase = 0.0 if case == "plain" else math.pi / des.z1
    # closed form: u = v = 0, t1 = t2 = phi1 - phase, phi2 = -(z1/z2) phi1, TE = 0
    np.testing.assert_allclose(p.uv1[:, 0], 0.0, atol=1e-10)
    np.testing.assert_allclose(p.uv2[:, 0], 0.0, atol=1e-10)
    np.testing.assert_allclose(p.uv1[:, 1], p.phi1 - phase, atol=1e-10)
    np.testing.assert_allclose(p.uv2[:, 1], p.phi1 - phase, atol=1e-10)
    np.testing.assert_allclose(np.asarray(p.te) / gj.ARCSEC, 0.0, atol=1e-6)
    np.testing.assert_allclose(res.coords["h1"], 0.0, atol=1e-9)     # on the pitch cone
    # sliding: relative velocity at the contact with the gear speed of the TCA path
    # (central differences of phi2), over the pitch-line speed
    phi, phi2 = np.asarray(p.phi1), np.asarray(p.phi2)
    w2 = np.gradient(phi2, phi)[1:-1]
    r = np.asarray(p.point)[1:-1]
    g = np.asarray(G.gear_assembly_rotation(des.shaft_angle))[:, 2]
    v12 = np.cross([0.0, 0.0, 1.0], r) - w2[:, None] * np.cross(g, r)
    speed = np.hypot(r[:, 0], r[:, 1])
    assert np.max(np.linalg.norm(v12, axis=1) / speed) < 1e-9
    # contact ratio: the flank spans t_max - t_min of pinion rotation
    t0, _, t1 = (float(v) for v in G.curve_range(des))
    assert float(res.multi.contact_ratio) == pytest.approx((t1 - t0) / (2 * math.pi / 10),
                                                           rel=2e-3)
    assert float(res.multi.ptp) / gj.ARCSEC < 1e-6


def test_preset_parabola_is_followed(des, runs):
    for case, sign in (("mod", 1.0), ("mod_coast", -1.0)):
        res = runs[case]
        on = np.asarray(res.on_flank)
        assert on.sum() > 15
        dev = float(A.preset_deviation(des, res)) / gj.ARCSEC
        assert dev < 0.5                                 # arcsec (gear angle), measured 0.21
        te = np.asarray(res.path.te)[on] / gj.ARCSEC
        # 36 arcsec of pinion rotation at the face ends = 12 arcsec of gear angle
        assert (sign * te).max() == pytest.approx(12.0, abs=1.0)
        assert np.all(sign * te > -1e-9)
        assert res.flags() == dict(converged=True, reference_on_flank=True,
                                   edge_contact=False, face_end_contact=False,
                                   tip_contact=False, low_contact_ratio=False,
                                   large_te=False)
        # smooth transfer (curves cross inside the overlap), at +-half a pitch
        assert all(float(g) < 0.0 for g in A.transfer_gaps(res, 10, 16))
        mid = float(res.path.phi1[res.path.phi1.shape[0] // 2])
        np.testing.assert_allclose(np.asarray(res.multi.transfer_phi1) - mid,
                                   [-math.pi / 10, math.pi / 10], atol=0.01)
    # the unmodified pair's contact reaches the face ends, the modified one's does not
    ends0, ends1 = A.contact_ends(des, runs["plain"]), A.contact_ends(des, runs["mod"])
    assert ends0["first"]["from_toe_mm"] == pytest.approx(0.0, abs=1e-4)
    assert ends0["last"]["from_heel_mm"] == pytest.approx(0.0, abs=1e-4)
    assert ends1["first"]["from_toe_mm"] > 1.0 and ends1["last"]["from_heel_mm"] > 1.0


def test_preset_absorbs_part_of_a_misalignment(runs):
    g0 = max(float(g) for g in A.transfer_gaps(runs["plain_dG"], 10, 16))
    g1 = max(float(g) for g in A.transfer_gaps(runs["mod_dG"], 10, 16))
    assert g0 > 0.0                      # the unmodified pair jumps at the transfer
    assert g1 < g0                       # less with the preset parabola
    # the jump of the unmodified pair is the TE envelope's largest step on the grid, up
    # to the change of the TE over one grid step (the typical step)
    env = np.asarray(runs["plain_dG"].multi.envelope)
    steps = np.abs(np.diff(env[np.isfinite(env)]))
    regular = np.median(steps)
    assert steps.max() > 5 * regular
    assert abs(steps.max() - g0) <= 2 * regular


def test_cli_tca_and_surface(des, runs, tmp_path, capsys):
    assert main(["tca", EX, "--positions", "41", "--pitches", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["ptp_arcsec"] == pytest.approx(float(runs["mod"].multi.ptp) / gj.ARCSEC, rel=1e-9)
    xyz = tmp_path / "p.xyz"
    assert main(["surface", EX, "--member", "gear", "--flank", "convex", "--grid", "5x3",
                 "--out", str(xyz)]) == 0
    pts = np.loadtxt(xyz)
    assert pts.shape == (15, 6)
    Ai, _, Ao = (float(v) for v in G.cone_distances(des))
    L = np.linalg.norm(pts[:, :3], axis=1)
    np.testing.assert_allclose(np.sort(L)[[0, -1]], [Ai, Ao], rtol=1e-10)
    stl = tmp_path / "t.stl"
    assert main(["surface", EX, "--member", "pinion", "--flank", "convex", "--grid", "5x3",
                 "--tooth", "--out", str(stl)]) == 0
    assert stl.read_text().startswith("solid")
