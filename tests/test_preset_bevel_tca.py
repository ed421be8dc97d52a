"""TCA of the preset-TE bevel pair ([Preset-TE-bevel]): pure rolling, the preset parabola,
the transfer, the CLI.  One compiled TCA program for every case (the design, the side
and the misalignment are data; the grid options are those of ``gearjax tca --positions
41 --pitches 1``, so the in-process CLI tests reuse it)."""

import dataclasses
import json
import math
import re

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from cost_guard import check_cost

import gearjax as gj
from gearjax.cli import main
from gearjax.gears.preset_bevel import analysis as A
from gearjax.gears.preset_bevel import geometry as G
from gearjax.gears.preset_bevel.pair import preset_assembly, side_flanks
from gearjax.tca.assembly import gear_mount
from gearjax.tca.result import strong_float64
from notebook_run import run_notebook

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
            "plain_dG": gj.run_tca(plain, dg, side="drive", throw=False, **OPTS),
            "mod_dG": gj.run_tca(des, dg, side="drive", throw=False, **OPTS)}


def test_cost_of_the_preset_bevel_tca(runs):
    """Cost guard (tests/cost_guard.py): Newton work of the preset-TE bevel TCA with its
    edge search (modified pair, both sides) against the recorded baseline."""
    for case in ("mod", "mod_coast"):
        check_cost(f"tca_preset_bevel_{case}", newton_work=int(runs[case].path.newton_work))


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
                                   large_te=False, crossing_flanks=False)
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
    # the study quantity is the smooth maximum of the two gaps (within T log 2, above)
    from gearjax.studies.quantities import GAP_TEMPERATURE, QUANTITIES
    for case in ("plain_dG", "mod_dG", "mod", "mod_coast"):
        res = runs[case]
        g = max(float(v) for v in A.transfer_gaps(res, 10, 16)) / gj.ARCSEC
        q = float(QUANTITIES["transfer_gap_arcsec"].fn(res, None, None, None))
        assert g <= q <= g + GAP_TEMPERATURE * math.log(2), case
    # pair 0 never leaving the flanks on the grid (every margin positive): no transfer is
    # found, and the quantity is NaN -- not the other gap alone, nor -inf, either of which
    # a constraint "transfer_gap <= 0" would read as satisfied
    res = runs["mod"]
    m = np.asarray(res.margin)
    for margin in (np.where(np.arange(m.size) > m.size // 2, 1.0, m), np.ones_like(m)):
        cut = dataclasses.replace(res, margin=jnp.asarray(margin))
        assert not np.all(np.isfinite([float(v) for v in A.transfer_gaps(cut, 10, 16)]))
        assert np.isnan(float(QUANTITIES["transfer_gap_arcsec"].fn(cut, None, None, None)))


def test_summary_is_the_result_at_the_reference(runs):
    """The summary the sensitivity table differentiates (``preset_summary``, keys
    ``SUMMARY_KEYS``) is read off the result by name at the reference grid point: a
    swapped or misread entry would put the wrong quantity into every sensitivity."""
    from gearjax.gears.preset_bevel.tca import SUMMARY_KEYS, preset_summary
    # (misaligned: aligned, the contact at the reference lies on the pitch line of both
    # members, L1 = L2 and h1 = h2 = 0, where a swap would not show)
    for case in ("mod_dG", "plain_dG"):
        res = runs[case]
        p, c = res.path, res.coords
        mid = np.asarray(p.phi1).size // 2
        want = {"ptp_rad": res.multi.ptp, "phi2_ref_rad": p.phi2[mid], "L1_mm": c["L1"][mid],
                "h1_mm": c["h1"][mid], "L2_mm": c["L2"][mid], "h2_mm": c["h2"][mid],
                "semi_major_mm": p.semi_major[mid]}
        got = np.asarray(preset_summary(res))
        for k, v in zip(SUMMARY_KEYS, got):
            assert v == pytest.approx(float(want[k]), rel=0, abs=0), (case, k)
        assert abs(got[3] - got[5]) > 1e-6 and abs(got[2] - got[4]) > 1e-6, got


@pytest.mark.parametrize("fn", ["run_tca", "tca_function", "tca_sensitivity"])
def test_options_are_checked_by_the_one_driver(des, fn):
    """The family runs through the one TCA driver (gearjax.tca.family): an unknown option
    or a contact mode the family does not have is a one-line ValueError naming it,
    before any work, in every entry point (before the driver the family's adapter
    dropped both silently); an option given as None takes the family default."""
    call = getattr(gj, fn)
    with pytest.raises(ValueError, match=r"unknown TCA option 'steps'"):
        call(des, steps=16)
    with pytest.raises(ValueError, match=r"line_contact = True is not available for "
                                         r"preset_bevel pairs: the profile arcs"):
        call(des, line_contact=True)
    with pytest.raises(ValueError, match=r"steps_per_pitch"):
        call(des, steps_per_pitch=1)
    assert gj.tca.family_of(des).resolve(des, {"half_pitches": None})["half_pitches"] == 1.0

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


# --- edge contact (toe/heel, tip edges) and the forward-mode gradient -------------------

#: misalignments beyond the robustness range of the docs: the bearing leaves a face end
EDGE_CASES = {"dE": gj.Misalignment.create(dE=0.01),
              "dSigma": gj.Misalignment.create(dSigma_deg=0.5)}


@pytest.fixture(scope="module")
def surface_only(des):
    """The surface-contact TCA without the edge solve (drive side) and, in the same
    jitted program, the forward-mode derivative of (TE p-t-p, TE at one grid point)
    along a direction ``dtheta`` of (kappa, rho1): the implicit derivatives of every
    contact solve (one program for every design, misalignment and direction)."""
    f = gj.tca_function(des, side="drive", face_ends=False, **OPTS)

    @jax.jit
    def run(d, mis, dtheta):
        def g(th):
            dd = dataclasses.replace(d, kappa=th[0], rho1=th[1])
            res = f(dd, mis)
            return jnp.stack([res.multi.ptp, res.path.te[GRAD_POINT]]), res
        _, dval, res = jax.jvp(g, (jnp.stack([d.kappa, d.rho1]),), (dtheta,), has_aux=True)
        return res, dval

    def call(d, mis=None, dtheta=(0.0, 0.0)):
        mis = gj.Misalignment.zero() if mis is None else mis
        return run(strong_float64(d), strong_float64(mis), jnp.asarray(dtheta, float))
    return call


GRAD_POINT = 12            # a grid point of pair 0 on the flanks, 4 steps before mid-face


@pytest.mark.parametrize("case", ["mod", "mod_coast", "plain"])
def test_aligned_pairs_have_no_edge_contact_and_same_envelope(des, runs, surface_only, case):
    res = runs[case]
    assert np.all(np.asarray(res.path.edge_kind) == -1)
    if case == "mod_coast":
        return                      # the reference program is the drive side's
    d = des if case == "mod" else dataclasses.replace(des, kappa=jnp.asarray(0.0))
    ref, _ = surface_only(d)
    env, env0 = np.asarray(res.multi.envelope), np.asarray(ref.multi.envelope)
    fin = np.isfinite(env0)
    np.testing.assert_array_equal(np.isfinite(env), fin)
    assert np.max(np.abs(env[fin] - env0[fin])) / gj.ARCSEC <= 1e-9


def _normal(r, uv):
    """Unit normal of the flank ``r`` at ``uv`` from its parameter derivatives."""
    J = np.asarray(jax.jacfwd(r)(jnp.asarray(uv)))
    n = np.cross(J[:, 0], J[:, 1])
    return n / np.linalg.norm(n)


@pytest.mark.parametrize("case", list(EDGE_CASES))
def test_misaligned_pair_touches_at_a_face_end(des, surface_only, case):
    """A misalignment beyond the robustness range of the docs pushes the bearing off a
    face end: there the edge of one member touches the mating flank.  Checked from the
    flank functions and the mounting directly: the edge point on the toe/heel sphere,
    the two flank points coincide, the separation along the mating normal is zero and
    the edge tangent lies in the mating tangent plane; the surface contact (no edge
    solve) lies off the flanks there, and the TE envelope takes the edge contact."""
    mis = EDGE_CASES[case]
    res = gj.run_tca(des, mis, side="drive", throw=False, **OPTS)
    ref, _ = surface_only(des, mis)
    p = res.path
    kind = np.asarray(p.edge_kind)
    at = np.nonzero(kind >= 0)[0]
    assert at.size >= 1 and np.all(kind[at] < 4)          # face ends (toe/heel)
    r1, r2 = side_flanks(des, "drive")
    R, c = (np.asarray(a) for a in gear_mount(preset_assembly(des), mis))
    Ai, _, Ao = (float(v) for v in G.cone_distances(des))
    for i in at:
        k = int(kind[i])
        uv1, uv2 = np.asarray(p.uv1[i]), np.asarray(p.uv2[i])
        q1, q2 = np.asarray(r1(jnp.asarray(uv1))), np.asarray(r2(jnp.asarray(uv2)))
        p1 = _rz(float(p.phi1[i])) @ q1 + float(mis.dP) * np.array([0.0, 0.0, 1.0])
        p2 = c + R @ _rz(float(p.phi2[i])) @ q2
        n1 = _rz(float(p.phi1[i])) @ _normal(r1, uv1)
        n2 = R @ _rz(float(p.phi2[i])) @ _normal(r2, uv2)
        pinion = k < 2
        q_edge, A = (q1 if pinion else q2), (Ai if k % 2 == 0 else Ao)
        assert abs(np.linalg.norm(q_edge) - A) <= 1e-9                # on the face end
        assert np.linalg.norm(p1 - p2) <= 1e-9                         # common point
        n_mate = n2 if pinion else n1
        assert abs(np.dot(p1 - p2, n_mate)) <= 1e-9                    # separation (mm)
        # edge tangent: along the end sphere on the edge member's flank (central
        # differences of the flank at fixed |q| = A), in the mating tangent plane
        r, uv, Rk = (r1, uv1, _rz(float(p.phi1[i]))) if pinion else \
            (r2, uv2, R @ _rz(float(p.phi2[i])))
        J = np.asarray(jax.jacfwd(r)(jnp.asarray(uv)))
        grad_L = q_edge / np.linalg.norm(q_edge) @ J                   # d|q|/d(u, t)
        tang = Rk @ (J @ np.array([grad_L[1], -grad_L[0]]))
        assert abs(np.dot(tang / np.linalg.norm(tang), n_mate)) <= 1e-7
        # the surface contact lies off the flanks here; the envelope takes the edge
        assert float(ref.margin[i]) < 0.0
    env = np.asarray(res.multi.envelope)
    te_pairs = np.asarray(res.multi.te_pairs)
    k0 = te_pairs.shape[0] // 2
    np.testing.assert_allclose(te_pairs[k0, at], np.asarray(p.te)[at], rtol=0, atol=1e-15)
    assert np.all(np.isfinite(env[at]))
    # flags: the bearing runs off the face end
    f = res.flags()
    assert f["face_end_contact"] and f["edge_contact"]


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def test_te_gradient_wrt_kappa_and_rho1_matches_central_differences(des, surface_only):
    """d(TE p-t-p, TE at one grid point)/d(kappa, rho1) by forward mode (the program of
    the reference TCA above) against central differences of the public TCA (the
    compiled program of the other tests, relative steps 1e-3: measured 7e-9 (kappa) and
    8e-7 (rho1) relative; 1e-4 and below lose digits to the solver tolerances)."""

    def val(**kw):
        r = gj.run_tca(dataclasses.replace(des, **kw), side="drive", **OPTS)
        return np.array([float(r.multi.ptp), float(r.path.te[GRAD_POINT])])

    for j, name in enumerate(("kappa", "rho1")):
        x = float(getattr(des, name))
        h = 1e-3 * x
        fd = (val(**{name: jnp.asarray(x + h)}) - val(**{name: jnp.asarray(x - h)})) / (2 * h)
        assert np.all(np.abs(fd) > 0.0)
        ad = np.asarray(surface_only(des, dtheta=np.eye(2)[j])[1])
        np.testing.assert_allclose(ad, fd, rtol=1e-5)


def test_cli_surface_refuses_points_beyond_the_flank(tmp_path, capsys):
    """#28 item 4: addendum = dedendum = 21 mm puts grid rows beyond the flank that the
    solves reach (before: 58 of 205 points not converged written with status 0, STL and
    XYZ without any flag).  Every format is refused with one line, status 3, nothing
    written."""
    src = gj.example_path("preset_te_bevel_10x30").read_text()
    bad = tmp_path / "deep.toml"
    bad.write_text(src.replace("addendum_mm = 4.5", "addendum_mm = 21.0")
                   .replace("dedendum_mm = 4.5", "dedendum_mm = 21.0"))
    for out, extra in (("f.xyz", []), ("f.csv", []), ("f.stl", []), ("t.stl", ["--tooth"])):
        capsys.readouterr()
        rc = main(["surface", str(bad), "--member", "pinion", "--flank", "concave",
                   "--grid", "41x5", "--out", str(tmp_path / out), *extra])
        err = capsys.readouterr().err.strip().splitlines()
        assert rc == 3 and len(err) == 1, err
        assert re.search(r"gearjax: error: .*: \d+ of \d+ grid points are not converged "
                         r"solves .*nothing written", err[0]), err
        assert not (tmp_path / out).exists()


# -- the notebook of this subject (tests/notebook_run.py: after this file's tests,
# whose compiled programs it reuses)


def test_preset_te_bevel_notebook_preset_sweep_and_derivatives(tmp_path):
    """The preset-TE bevel notebook (the TCA programs of test_preset_bevel_tca.py): the
    preset parabola followed (docs/preset_te_bevel.md: 0.21 arcsec), smooth transfers
    aligned, the jump under dG shrinking as kappa grows, and the forward-mode
    derivatives by kappa and rho1 against central differences."""
    _, text = run_notebook("05_preset_te_bevel", tmp_path)
    dev = float(re.search(r"preset parabola ([0-9.]+) arcsec", text).group(1))
    assert dev < 0.5, text[-2000:]
    gaps = re.search(r"preset .* transfer gaps ([-+0-9.]+) / ([-+0-9.]+) arcsec", text)
    assert float(gaps.group(1)) < 0 and float(gaps.group(2)) < 0
    rows = re.findall(r"^\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+([-0-9.]+)\s+(?:\[|none)", text, re.M)
    jumps = [float(g) for _, g in rows]
    assert len(jumps) == 4 and all(a > b for a, b in zip(jumps, jumps[1:])), rows
    worst = float(re.search(r"largest relative error ([0-9.e+-]+)", text).group(1))
    assert worst < 1e-5
