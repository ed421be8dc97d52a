"""Closed-loop flank correction of the VH-CATT family: cutter radius, blade offset and blade
angles from a measured flank (gearjax/gears/vh_catt/flank_correction.py, the fit of
gearjax/correction.py, docs/correct.md "VH-CATT").

Synthetic measurements: the design with known errors written into its file (the "cut"
part); its own reference grid met by the nominal normals through tangent planes gives the
measured deviations (a route independent of the fit's line-flank solve); seeded noise of
1 um.  One example (vh_catt_17x23), one grid (9x5, margins 0.1): the grid program and the
fit program (two flanks; one flank) are compiled once per module."""

import json
import math

import numpy as np
import pytest

import gearjax
from gearjax.cli import main
from gearjax.correction import correct_flanks, model_deviations
from gearjax.gears.vh_catt import flank_correction as vc
from gearjax.gears.vh_catt.design_file import design_from_dict
from gearjax.io import MeasuredGrid, read_measured_grid, write_reference_grid

EX = "example:vh_catt_17x23"
GRID = (9, 5)
MARGIN = 0.1
FLANKS = ("convex", "concave")


def _grids(design, member, flanks=FLANKS):
    return {f: design.reference_grid(member, f, *GRID, MARGIN, MARGIN) for f in flanks}


def _second_route(design, member, errors, rotation_deg=0.0, flanks=FLANKS, nominal=None):
    """Deviations (n_f, n_xi, n_s) um of the perturbed design's flanks (turned by the
    rotation) from the nominal grid: its own grid met by the nominal normals through the
    tangent plane at each of its points."""
    bad = vc.with_setting_errors(design, member, errors)
    c, s = math.cos(math.radians(rotation_deg)), math.sin(math.radians(rotation_deg))
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    g0, g1 = _grids(nominal or design, member, flanks), _grids(bad, member, flanks)
    out = []
    for f in flanks:
        P, n = np.asarray(g0[f].points), np.asarray(g0[f].normals)
        Q, m = np.asarray(g1[f].points) @ R.T, np.asarray(g1[f].normals) @ R.T
        out.append(np.sum(m * (Q - P), -1) / np.sum(m * n, -1) / 1e-3)
    return np.stack(out)


def _measured(design, member, dev, flanks=FLANKS):
    g = _grids(design, member, flanks)
    st = lambda a: np.stack([np.asarray(getattr(g[f], a)) for f in flanks])
    return MeasuredGrid(design.name, member, *GRID, MARGIN, MARGIN, tuple(flanks), st("points"),
                        st("normals"), np.asarray(dev, float), "synthetic")


def _internal(errors, rotation_deg=0.0):
    out = {k: (math.radians(v) if vc.UNITS[k.split(".")[-1]] == "deg" else v)
           for k, v in errors.items()}
    if rotation_deg:
        out["axis_rotation"] = math.radians(rotation_deg)
    return out


@pytest.fixture(scope="module")
def design():
    return gearjax.load_design(EX)


@pytest.fixture(scope="module")
def ref_file(design, tmp_path_factory):
    """``gearjax surface --reference-grid`` of the VH-CATT pinion (both flanks)."""
    p = tmp_path_factory.mktemp("vh") / "pinion_grid.csv"
    assert main(["surface", EX, "--member", "pinion", "--reference-grid", "--out", str(p)]) == 0
    return p


@pytest.fixture(scope="module")
def problems(design):
    """Zero-deviation problems of both members with the default unknowns."""
    return {m: vc.correction_problem(design, _measured(design, m, np.zeros((2,) + GRID)))
            for m in ("pinion", "gear")}


def test_reference_grid_file_frame_and_zero_measurement(design, ref_file, problems):
    m = read_measured_grid(ref_file, require_deviations=False)
    assert (m.member, m.n_xi, m.n_s, m.flanks) == ("pinion", 9, 5, FLANKS)
    assert "body frame of the member" in ref_file.read_text()
    b = float(design.pair.face_width)
    for k, f in enumerate(FLANKS):
        g = design.reference_grid("pinion", f, 9, 5, MARGIN, MARGIN)
        np.testing.assert_allclose(m.points[k], np.asarray(g.points), atol=1e-9)
        np.testing.assert_allclose(m.normals[k], np.asarray(g.normals), atol=1e-9)
        # sections inside the margins (z = +-(b/2 - 0.1 b)), xi -1 .. 1, heights 0.1 .. 0.9
        np.testing.assert_allclose(m.points[k][[0, -1], :, 2], [[-0.4 * b] * 5, [0.4 * b] * 5],
                                   atol=1e-9)
        np.testing.assert_allclose(np.asarray(g.xi)[[0, -1]], [-1.0, 1.0], atol=1e-12)
        full = design.surface_grid("pinion", f, 9, 11)
        r = lambda P: np.hypot(P[..., 0], P[..., 1])
        rf, rg = r(np.asarray(full.points)), r(m.points[k])
        assert np.all(rg[:, 0] > rf[4, 0]) and np.all(rg[:, -1] < rf[4, -1])
        # normals out of the tooth: the convex pinion flank (sigma = +1) faces +x at tooth 0
        assert np.all(np.sign(m.normals[k][..., 0]) == (1.0 if f == "convex" else -1.0))
    # zero deviations: zero correction, zero residual
    res = correct_flanks(problems["pinion"])
    assert res.converged
    assert np.max(np.abs(res.delta)) < 1e-9
    assert np.max(np.abs(res.after_um)) < 1e-8


def test_jacobian_matches_central_differences(problems):
    """Exact Jacobian (jacfwd through the line-flank solve) against central differences of
    the model deviations, for every correctable field and the rotation, at a point away
    from the nominal."""
    prob = problems["gear"]
    x0 = {"cutter_radius": 3.0, "blade_offset": -0.5, "convex.blade_angle": 2e-4,
          "concave.blade_angle": -3e-4, "axis_rotation": 2e-5}
    steps = {"cutter_radius": 0.05, "blade_offset": 0.05, "convex.blade_angle": 1e-5,
             "concave.blade_angle": 1e-5, "axis_rotation": 1e-6}
    _, J = model_deviations(prob, x0)
    for i, n in enumerate(prob.unknowns):
        h = steps[n]
        hi = model_deviations(prob, {**x0, n: x0[n] + h})[0].reshape(-1)
        lo = model_deviations(prob, {**x0, n: x0[n] - h})[0].reshape(-1)
        fd = (hi - lo) / (2 * h)
        assert np.max(np.abs(J[:, i])) > 0.1, n          # the field moves the flank
        assert np.max(np.abs(J[:, i] - fd)) < 1e-5 * np.max(np.abs(J[:, i])), n


@pytest.mark.parametrize("member", ["pinion", "gear"])
def test_model_deviations_match_the_perturbed_design(design, problems, member):
    """The fit's model (exact line-flank intersection with the fields changed) against
    the design file written with those errors, measured by the second route, to 0.02 um
    (a field mapped to the wrong member, flank or sign is microns off)."""
    errors = {"cutter_radius": 6.0, "blade_offset": 1.5, "convex.blade_angle": 0.03,
              "concave.blade_angle": -0.02}
    dev, _ = model_deviations(problems[member], _internal(errors, 0.003))
    meas = _second_route(design, member, errors, 0.003)
    assert np.max(np.abs(meas)) > 2.0
    assert np.max(np.abs(dev - meas)) < 0.02
    # one field at a time: each moves the flank by a non-trivial, field-specific map
    for k in errors:
        one, _ = model_deviations(problems[member], _internal({k: errors[k]}))
        np.testing.assert_allclose(one, _second_route(design, member, {k: errors[k]}),
                                   atol=0.02)


def test_second_loop_on_a_design_with_member_blade_settings(design):
    """A design that already carries per-member blade settings (a corrected one) is the
    nominal of the next loop: zero deviation at zero correction, and the model matches
    the second route (each flank's own blade angle and the member's own offset are used
    as the start of the increments)."""
    data = design.to_dict()
    data["gear"] = {"convex_blade_angle_deg": 20.3, "concave_blade_angle_deg": 19.8,
                    "blade_offset_mm": 3.6}
    d2 = design_from_dict(data)
    prob = vc.correction_problem(d2, _measured(d2, "gear", np.zeros((2,) + GRID)))
    dev0, _ = model_deviations(prob, {})
    assert np.max(np.abs(dev0)) < 1e-6
    errors = {"cutter_radius": 4.0, "blade_offset": -1.0, "convex.blade_angle": 0.02,
              "concave.blade_angle": -0.03}
    dev, _ = model_deviations(prob, _internal(errors))
    np.testing.assert_allclose(dev, _second_route(d2, "gear", errors), atol=0.02)


CASES = {
    "pinion": ({"cutter_radius": 5.0, "convex.blade_angle": 0.03, "blade_offset": 2.0}, 0.003),
    "gear": ({"cutter_radius": -6.0, "blade_offset": -1.5, "convex.blade_angle": -0.02,
              "concave.blade_angle": 0.025}, 0.0),
}


@pytest.mark.parametrize("member", ["pinion", "gear"])
def test_recovery_within_the_noise_and_corrected_design(design, member):
    errors, rot = CASES[member]
    rng = np.random.default_rng(33 if member == "pinion" else 34)
    clean = _second_route(design, member, errors, rot)
    prob = vc.correction_problem(design, _measured(design, member,
                                                   clean + rng.normal(0.0, 1.0, clean.shape)))
    res = correct_flanks(prob)
    assert res.converged and not res.indistinguishable
    assert res.condition_number < 10.0
    assert 0.7 < res.noise_um < 1.3
    truth = {n: 0.0 for n in res.unknowns}
    truth.update(errors)
    truth["axis_rotation"] = rot
    for n in res.unknowns:
        assert abs(res.fitted[n] - truth[n]) < 3.0 * res.uncertainty[n], n
        if truth[n]:
            assert res.uncertainty[n] < 0.5 * abs(truth[n]), n        # informative
    assert res.correction["cutter_radius"] == pytest.approx(-res.fitted["cutter_radius"])
    # the corrected design: this member's fields corrected, the other member untouched
    new = vc.corrected_design(res)
    other = "gear" if member == "pinion" else "pinion"
    assert vc.member_fields(new, other) == vc.member_fields(design, other)
    now, was = vc.member_fields(new, member), vc.member_fields(design, member)
    for n in res.unknowns[:-1]:
        assert now[n] - was[n] == pytest.approx(-res.fitted[n], abs=1e-9)
    # cut with the same errors, it is the nominal flank to well below the noise
    before = np.sqrt(np.mean(clean ** 2))
    left = _second_route(new, member, errors, 0.0, nominal=design)
    assert before > 1.0 and np.sqrt(np.mean(left ** 2)) < 0.4


def test_one_flank_cutter_radius_and_blade_offset_cannot_be_told_apart(design):
    """With the convex flank alone, R_T and e act on it only through its trace radius
    rho_0 = R_T - (w/2 + e): reported as indistinguishable, the regularised fit splits
    the change minimum-norm (equal column scales: R_T = -e) and still fits the flank."""
    errors = {"cutter_radius": 5.0}
    clean = _second_route(design, "pinion", errors, flanks=("convex",))
    rng = np.random.default_rng(35)
    meas = _measured(design, "pinion", clean + rng.normal(0.0, 1.0, clean.shape), ("convex",))
    res = correct_flanks(vc.correction_problem(design, meas,
                                               ["cutter_radius", "blade_offset", "blade_angle"]))
    assert res.converged and res.condition_number > 1e8
    assert len(res.indistinguishable) == 1
    text, s, coef = res.indistinguishable[0]
    assert s < 1e-6 and set(coef) == {"cutter_radius", "blade_offset"}
    assert coef["cutter_radius"] == pytest.approx(coef["blade_offset"], abs=1e-6)
    R, e = res.fitted["cutter_radius"], res.fitted["blade_offset"]
    assert abs(R + e) < 1e-3 * abs(R)                               # minimum-norm split
    assert abs((R - e) - 5.0) < 2.0                                 # rho_0 recovered
    assert 0.6 < res.noise_um < 1.3


def test_command_corrects_the_member_and_refuses_bad_files(design, ref_file, tmp_path,
                                                           capsys):
    errors, rot = CASES["pinion"]
    rng = np.random.default_rng(36)
    dev = _second_route(design, "pinion", errors, rot)
    dev = dev + rng.normal(0.0, 1.0, dev.shape)
    meas = write_reference_grid(tmp_path / "m.csv", design=design.name, member="pinion",
                                grids=_grids(design, "pinion"), face_margin=MARGIN,
                                height_margin=MARGIN,
                                deviation_um={f: dev[k] for k, f in enumerate(FLANKS)})
    out = tmp_path / "corrected.toml"
    capsys.readouterr()
    assert main(["correct", EX, "--measured", str(meas), "--out", str(out), "--json"]) == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["unknowns"] == ["cutter_radius", "blade_offset", "convex.blade_angle",
                               "concave.blade_angle", "axis_rotation"]
    assert rep["units"]["convex.blade_angle"] == "deg"
    new = gearjax.load_design(str(out))
    assert set(new.data["pinion"]) == {"blade_offset_mm", "convex_blade_angle_deg",
                                       "concave_blade_angle_deg"}
    assert "gear" not in new.data
    assert new.data["pair"]["cutter_radius2_mm"] == design.data["pair"]["cutter_radius2_mm"]
    assert new.data["pair"]["cutter_radius1_mm"] == pytest.approx(
        400.0 - rep["fitted_error"]["cutter_radius"])
    # refused with one line, status 2: another member's grid, a NaN, an unknown setting
    text = meas.read_text()
    bad = {"gear": text.replace("# member = pinion", "# member = gear"),
           "nan": text.replace(text.splitlines()[-1].rsplit(",", 1)[1], "nan"),
           "setting": text}
    for k, t in bad.items():
        p = tmp_path / f"bad_{k}.csv"
        p.write_text(t)
        extra = ["--settings", "cutter_radius,point_radius"] if k == "setting" else []
        assert main(["correct", EX, "--measured", str(p), "--out",
                     str(tmp_path / "x.toml"), *extra]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("gearjax: error:"), err
        assert {"gear": "reference grid", "nan": "finite", "setting": "point_radius"}[k] in err[0]
    assert not (tmp_path / "x.toml").exists()


def test_member_blade_keys_validated_and_honoured_by_the_flank(design):
    data = design.to_dict()
    for mem, key, v, msg in (("pinion", "convex_blade_angle_deg", 22.5,
                              "[pinion] convex_blade_angle_deg = 22.5 deg is outside the "
                              "allowed range [18, 22] deg"),
                             ("gear", "blade_offset_mm", -0.1,
                              "[gear] blade_offset_mm = -0.1 mm is outside the allowed range "
                              "[0, 20] mm"),
                             ("gear", "tip_angle_deg", 1.0, "unknown key 'gear.tip_angle_deg'")):
        d = {**data, mem: {key: v}}
        with pytest.raises(ValueError) as exc:
            design_from_dict(d)
        assert msg in str(exc.value) and "\n" not in str(exc.value)
    # the pair's values written per member: the same flanks
    same = design_from_dict({**data, "pinion": {"convex_blade_angle_deg": 20.0,
                                                "blade_offset_mm": 3.0}})
    g0 = {f: np.asarray(design.reference_grid("pinion", f, 3, 3, 0.1, 0.1).points)
          for f in FLANKS}
    np.testing.assert_allclose(same.reference_grid("pinion", "convex", 3, 3, 0.1, 0.1).points,
                               g0["convex"], atol=1e-12)
    # a pinion convex blade angle moves that flank only (not the concave one, not the gear)
    d1 = design_from_dict({**data, "pinion": {"convex_blade_angle_deg": 20.5}})
    dc = np.asarray(d1.reference_grid("pinion", "convex", 3, 3, 0.1, 0.1).points) - g0["convex"]
    assert np.max(np.abs(dc)) > 1e-3
    np.testing.assert_allclose(d1.reference_grid("pinion", "concave", 3, 3, 0.1, 0.1).points,
                               g0["concave"], atol=1e-12)
    np.testing.assert_allclose(d1.reference_grid("gear", "convex", 3, 3, 0.1, 0.1).points,
                               design.reference_grid("gear", "convex", 3, 3, 0.1, 0.1).points,
                               atol=1e-12)


# ------------------------------------------------------------------ target ease-off
# (gearjax/gears/vh_catt/ease_off.py, docs/correct.md "Target ease-off": VH-CATT)

EASE_GRID = (9, 5)


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _gaps_at_meshing(design, pinion_design, side="drive"):
    """Signed gaps (um, (n_xi, n_s)) between the grid points of the pinion of
    ``pinion_design`` and the gear flank of ``design``, each point taken at the pinion
    angle where it meets the gear's meshing condition: the TCA's mounting (pinion about
    +z, gear about +z through (0, a, 0), ratio -z1/z2, both turned to the reference
    pitch point), the point's normal line cut with the gear flank (the correction's line
    solve, started from the nearest point of a fine gear grid).  A pinion conjugate to the
    gear touches it at every grid point (zero gap): a contact line at each angle."""
    import jax
    import jax.numpy as jnp
    from gearjax.gears.vh_catt.ease_off import SIDES
    from gearjax.gears.vh_catt.geometry import pair_geometry
    from gearjax.gears.vh_catt.tca import reference_guess
    pf, gf, sigma = SIDES[side]
    pair = design.pair
    ratio = pair.z1 / pair.z2
    c = np.array([0.0, float(pair_geometry(pair)["a"]), 0.0])
    x, ph1r = reference_guess(pair, sigma)
    ph1r, ph2r = float(ph1r), float(x[4])
    g = pinion_design.reference_grid("pinion", pf, *EASE_GRID, 0.1, 0.25)
    P, n = np.asarray(g.points).reshape(-1, 3), np.asarray(g.normals).reshape(-1, 3)
    ez = jnp.array([0.0, 0.0, 1.0])

    def mesh(ph, P1, n1):        # n . (v1 - v2), omega1 = 1, omega2 = -z1/z2
        Rp = jnp.array([[jnp.cos(ph), -jnp.sin(ph), 0.0], [jnp.sin(ph), jnp.cos(ph), 0.0],
                        [0.0, 0.0, 1.0]])
        X = Rp @ P1
        return (Rp @ n1) @ (jnp.cross(ez, X) + ratio * jnp.cross(ez, X - c))

    def solve(P1, n1):
        ph = jnp.asarray(ph1r)
        for _ in range(12):
            f, d = jax.jvp(lambda q: mesh(q, P1, n1), (ph,), (1.0,))
            ph = ph - f / d
        return ph, mesh(ph, P1, n1)

    ph, res = jax.vmap(solve)(jnp.asarray(P), jnp.asarray(n))
    ph = np.asarray(ph)
    assert np.abs(np.asarray(res)).max() < 1e-9
    ph2 = ph2r - ratio * (ph - ph1r)
    Y = np.stack([_rz(-b) @ (_rz(a) @ p - c) for a, b, p in zip(ph, ph2, P)])
    m = np.stack([_rz(-b) @ (_rz(a) @ v) for a, b, v in zip(ph, ph2, n)])
    fine = design.reference_grid("gear", gf, 31, 21, 0.0, 0.0)
    GP = np.asarray(fine.points).reshape(-1, 3)
    start = np.asarray(fine.params).reshape(-1, 3)[
        np.argmin(((Y[:, None] - GP[None]) ** 2).sum(-1), axis=1)]
    t, conv = vc.flank_deviations(vc.flank_setup(pair, "gear", gf), jnp.zeros(3),
                                  jnp.asarray(Y), jnp.asarray(m), jnp.asarray(start), 0.0)
    assert bool(np.all(conv))
    return np.asarray(t).reshape(EASE_GRID) / 1e-3


@pytest.fixture(scope="module")
def ease(design):
    """The conjugate pinion of the drive side and the ease-off of the design's pinion."""
    from gearjax.gears.vh_catt import ease_off as veo
    conj = veo.conjugate_design(design, "drive")
    return conj, veo.ease_off(veo.ease_off_problem(design, "drive"))


def test_ease_off_conjugate_pinion_line_contact_and_crowning_closed_form(design, ease):
    """The conjugate pinion (the gear flank's trace radius and blade angle) has zero
    ease-off against itself and touches the gear at every grid point at its meshing angle
    (a wrong R_c, e.g. the sign of w + e_1 + e_2, leaves gaps of ~10 um); the design's
    pinion gaps against the gear agree with its ease-off (a second route through the
    mounting), and both with the trace circles' closed form ``cos(alpha) z^2/2 (1/rho_c -
    1/rho_1)``, rho_1 = R_T1 + w/2 + e (pinion concave), rho_c = R_T2 - w/2 - e (gear
    convex): 4.5 um at the grid's face ends."""
    from gearjax.gears.vh_catt import ease_off as veo
    conj, e = ease
    e_self = veo.ease_off(veo.ease_off_problem(conj, "drive"))
    assert np.abs(e_self).max() < 1e-6
    assert np.abs(_gaps_at_meshing(design, conj)).max() < 1e-5
    gap = _gaps_at_meshing(design, design)
    assert np.abs(gap - e).max() < 0.01, np.round(gap - e, 4)
    pr = design.data["pair"]
    w, e0 = math.pi * pr["module_mm"] / 2, pr["blade_offset_mm"]
    rho1, rhoc = pr["cutter_radius1_mm"] + w / 2 + e0, pr["cutter_radius2_mm"] - w / 2 - e0
    z = np.asarray(design.reference_grid("pinion", "concave", *EASE_GRID, 0.1, 0.25).points)[
        ..., 2]
    closed = math.cos(math.radians(pr["pressure_angle_deg"])) * z ** 2 / 2 * (
        1 / rhoc - 1 / rho1) / 1e-3
    assert closed.max() > 4.0
    assert np.abs(e - closed).max() < 0.05, np.round(e - closed, 3)


def test_ease_off_of_known_pinion_changes_is_recovered_and_written(design, tmp_path):
    """The ease-off of the pinion cut with +12 mm cutter radius and +0.05 deg concave blade
    angle, used as the target of the design, is met by the fit (residual < 0.01 um) with
    the true changes (the blade offset left out: one flank cannot tell it from the
    radius); the written design, read back, has that ease-off and the gear's fields."""
    from gearjax.gears.vh_catt import ease_off as veo
    true = {"cutter_radius": 12.0, "concave.blade_angle": 0.05}
    target = veo.ease_off(veo.ease_off_problem(vc.with_setting_errors(design, "pinion", true),
                                               "drive"))
    assert np.abs(target).max() > 5.0
    prob = veo.ease_off_problem(design, "drive", target,
                                settings=["cutter_radius", "blade_angle", "axis_rotation"])
    res = veo.fit_ease_off(prob)
    assert res.converged and np.nanmax(np.abs(res.after_um)) < 0.01
    assert res.correction["cutter_radius"] == pytest.approx(12.0, abs=0.05)
    assert res.correction["blade_angle"] == pytest.approx(0.05, abs=5e-4)
    new = veo.ease_off_design(res)
    path = tmp_path / "eased.toml"
    from gearjax.io import atomic_write, dumps_toml
    atomic_write(path, dumps_toml(new.data))
    back = gearjax.load_design(str(path))
    assert back.data["pinion"]["concave_blade_angle_deg"] == pytest.approx(20.05, abs=5e-4)
    assert "convex_blade_angle_deg" not in back.data["pinion"] and "gear" not in back.data
    assert back.data["pair"]["cutter_radius2_mm"] == design.data["pair"]["cutter_radius2_mm"]
    e_back = veo.ease_off(veo.ease_off_problem(back, "drive"))
    assert np.abs(e_back - target).max() < 0.01


def test_ease_off_command_on_vh_catt_crowning_target(design, tmp_path, capsys):
    """``gearjax ease-off`` on the VH-CATT example with a 10 um lengthwise crowning: the
    written design meets it (read back from the file), the trace radius it writes gives
    the closed form's 10 um at the face ends, the regularised fit splits the radius and
    the offset equally (so the other pinion flank, rho = R_T - w/2 - e, is unchanged),
    the gear is unchanged, and the TCA runs before and after."""
    out = tmp_path / "eased.toml"
    capsys.readouterr()
    rc = main(["ease-off", EX, "--out", str(out), "--crowning-um", "10", "--json"])
    rep = json.loads(capsys.readouterr().out)
    assert rc == 0 and rep["converged"]
    assert rep["fit_rms_um"] < 0.05 and rep["written_vs_target_rms_um"] < 0.05
    ch = rep["change"]
    assert ch["cutter_radius"] == pytest.approx(ch["blade_offset"], rel=1e-3)
    new = gearjax.load_design(str(out))
    pr, pr0 = new.data["pair"], design.data["pair"]
    assert pr["cutter_radius2_mm"] == pr0["cutter_radius2_mm"] and "gear" not in new.data
    w = math.pi * pr0["module_mm"] / 2
    e1 = new.data["pinion"]["blade_offset_mm"]
    rho1 = pr["cutter_radius1_mm"] + w / 2 + e1
    rhoc = pr0["cutter_radius2_mm"] - w / 2 - pr0["blade_offset_mm"]
    z = 0.5 * pr0["face_width_mm"] * (1 - 2 * 0.1)
    closed = math.cos(math.radians(20.0)) * z ** 2 / 2 * (1 / rhoc - 1 / rho1) / 1e-3
    assert closed == pytest.approx(10.0, rel=0.02)
    assert pr["cutter_radius1_mm"] - e1 == pytest.approx(
        pr0["cutter_radius1_mm"] - pr0["blade_offset_mm"], abs=1e-3)
    for k in ("design", "written"):
        t = rep["tca"][k]
        assert t is not None and "error" not in t and t["contact_ratio"] > 1.4


def test_setting_errors_of_the_synthetic_machine():
    """The synthetic "machine" of the recovery tests: a plain ``blade_angle`` error tilts
    both blades of the member, a flank's own adds to its blade only, the head's fields
    are shared, and the other member is untouched (a machine that cut the wrong blades
    would make every recovery test check the wrong thing)."""
    d = gearjax.load_design("example:vh_catt_17x23")
    bad = vc.with_setting_errors(d, "pinion", {"blade_angle": 0.04, "convex.blade_angle": 0.01,
                                               "cutter_radius": 3.0, "blade_offset": -0.5})
    a, b = vc.member_fields(d, "pinion"), vc.member_fields(bad, "pinion")
    change = {k: b[k] - a[k] for k in a}
    expect = {"convex.blade_angle": 0.05, "concave.blade_angle": 0.04, "cutter_radius": 3.0,
              "blade_offset": -0.5}
    for k, v in expect.items():
        assert change[k] == pytest.approx(v, abs=1e-9), (k, change[k])
    assert vc.member_fields(bad, "gear") == vc.member_fields(d, "gear")
    with pytest.raises(ValueError, match="convex.cutter_radius"):
        vc.with_setting_errors(d, "pinion", {"convex.cutter_radius": 1.0})
