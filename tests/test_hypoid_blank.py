"""Public blank-design interface: validation, round trip, routes, sensitivities."""

import json
import math

import jax
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gearjax.errors import ConvergenceError
from gearjax.gears.hypoid import blank as hb
from gearjax.gears.hypoid.blank import BlankInput, blank_geometry, blank_sensitivity

SAMPLE2 = dict(method="iso23509-method1", z1=13, z2=42, offset_mm=15.0,
               gear_outer_pitch_diameter_mm=170.0, gear_face_width_mm=30.0,
               spiral_angle_deg=50.0, cutter_radius_mm=63.5)

# [Eigenfunctions] Table 1 gear set (docs/references.md): 6/39, d = 230 mm, E = 35 mm; cutters 6, 7.5, 9 inch.
# The paper gives neither spiral angle nor face width: gearjax uses Gleason's
# hypoid rules psi_p = 25 + 5 sqrt(z2/z1) + 90 E/d (deg) and F = 0.155 d.
SEED000 = dict(z1=6, z2=39, offset_mm=35.0, gear_outer_pitch_diameter_mm=230.0,
               gear_face_width_mm=0.155 * 230.0,
               spiral_angle_deg=25.0 + 5.0 * math.sqrt(39 / 6) + 90.0 * 35.0 / 230.0,
               pressure_angle_drive_deg=19.0, pressure_angle_coast_deg=19.0)


def test_round_trip_and_defaults():
    inp = BlankInput.from_dict(SAMPLE2)
    assert inp.shaft_angle == math.pi / 2 and inp.taper == "standard"
    d = inp.to_dict()
    assert BlankInput.from_dict(d) == inp
    assert d["spiral_angle_deg"] == 50.0 and d["shaft_angle_deg"] == 90.0
    json.dumps(d)


@settings(max_examples=40, deadline=None)
@given(beta=st.floats(1.0, 70.0), alpha=st.floats(10.0, 30.0), sig=st.floats(70.0, 100.0),
       off=st.floats(1.0, 40.0))
def test_round_trip_property(beta, alpha, sig, off):
    d = dict(SAMPLE2, spiral_angle_deg=beta, pressure_angle_drive_deg=alpha,
             shaft_angle_deg=sig, offset_mm=off, method="tangent-cones",
             spiral_member="gear")
    inp = BlankInput.from_dict(d)
    assert BlankInput.from_dict(inp.to_dict()) == inp


@pytest.mark.parametrize("change, field", [
    ({"colour": "red"}, "colour"),
    ({"cutter_radius_mm": -5.0}, "cutter_radius_mm = -5"),
    ({"gear_outer_pitch_diameter_mm": 0.0}, "gear_outer_pitch_diameter_mm = 0"),
    ({"z1": 50, "z2": 42}, "ratio z2/z1 = 0.84"),
    ({"gear_face_width_mm": 95.0}, "gear_face_width_mm = 95"),
    ({"spiral_angle_deg": 80.0}, "spiral_angle_deg = 80"),
    ({"pressure_angle_drive_deg": 50.0}, "pressure_angle_drive_deg = 50"),
    ({"offset_mm": 60.0}, "offset_mm = 60"),
    ({"method": "iso23509-method0"}, "offset_mm = 15"),
    ({"spiral_member": "gear"}, "spiral_member = 'gear'"),
    ({"method": "gleason"}, "method = 'gleason'"),
    ({"z1": 13.5}, "z1 = 13.5"),
    ({"taper": "steep"}, "taper = 'steep'"),
    ({"shaft_angle_deg": 120.0}, "shaft_angle_deg = 120"),
    ({"dedendum_factor": 0.9}, "dedendum_factor = 0.9"),
])
def test_validation_errors_name_field_and_value(change, field):
    with pytest.raises(ValueError) as e:
        BlankInput.from_dict(dict(SAMPLE2, **change))
    msg = str(e.value)
    assert field in msg and "\n" not in msg


def test_missing_required_key():
    d = dict(SAMPLE2)
    del d["cutter_radius_mm"]
    with pytest.raises(ValueError, match="cutter_radius_mm"):
        BlankInput.from_dict(d)


def test_three_routes_and_table():
    res = {}
    for m in hb.METHODS:
        d = dict(SAMPLE2, method=m)
        if m == "iso23509-method0":
            d["offset_mm"] = 0.0
        b = blank_geometry(BlankInput.from_dict(d))
        assert float(b.converged) == 1.0
        rows = b.to_table()
        assert [r[0] for r in rows] == [n for n, _, _ in hb.OUTPUTS]
        out = b.to_dict()
        json.dumps(out)
        assert out["method"] == m and set(out) == {n for n, _, _ in hb.OUTPUTS} | {"method", "units"}
        res[m] = out
    # Method 1 = ISO sample 2 (annex F.3): delta_a1 - theta_a1 = delta1 ~ 21.289 deg
    assert abs(res["iso23509-method1"]["delta1"] - 21.2877) < 1e-3
    # [Tangent-cones] route: contact point at mid face ([Tangent-cones] eq. (7))
    assert abs(res["tangent-cones"]["c_be2"] - 0.5) < 1e-12
    assert abs(res["tangent-cones"]["beta_m1"] - 50.0) < 1e-10
    # Method 0: closed-form bevel pitch angle, apexes at the crossing point
    assert abs(res["iso23509-method0"]["delta1"] - math.degrees(math.atan(13 / 42))) < 1e-12
    assert res["iso23509-method0"]["a1"] == 0.0


@pytest.mark.parametrize("method", hb.METHODS)
def test_blank_outputs_by_independent_relations(method):
    """Outputs of blank_geometry that the ISO sample tables do not list, each against
    a relation typed in from its definition (ISO 23509:2016 clause 7, [Tangent-cones]):

    * m_et2 = d_e2/z2 (126), a_p = R_m2 sin(beta_m1 - beta_m2) (115 with 27);
    * d_e2 and b2 are the inputs; Method 0: common apex at the crossing point
      (t_z1 = t_z2 = a1 = a2 = 0, pitch point at 90 deg from the common perpendicular:
      theta1 = -90, theta2 = +90 deg), no offset angle;
    * hypoid routes: theta2 = 90 deg - zeta_m (the pitch point seen from the gear
      axis), a1 = t_z1, a2 = t_z2 (same apex in two routes);
    * [Tangent-cones] route: the ratio condition u r1 cos b1 = r2 cos b2 (Gleason's hypoid
      factor, ISO (14)/(26)) and the pitch point at mid face, d_e2 = 2 (R_m2 + b2/2)
      sin delta2 ([Tangent-cones] eq. (7));
    * the machine table of [Tangent-cones]: dV = E sin theta2 - a1, dH = E cos theta2 + a2,
      cradle = theta2 + 90 deg (left hand), X_G = a2, tilt NaN (no solution) and
      the reciprocal tilt asin(tan alpha_lim / tan beta_m1).
    Closed forms and converged solves: 1e-10 (measured <= 3e-12, in a1 - t_z1)."""
    d = dict(SAMPLE2, method=method)
    if method == "iso23509-method0":
        d["offset_mm"] = 0.0
    inp = BlankInput.from_dict(d)
    b = {n: float(getattr(blank_geometry(inp), n)) for n, _, _ in hb.OUTPUTS}
    E, u = inp.offset, 42 / 13
    tol = dict(rtol=0, atol=1e-10)
    np.testing.assert_allclose([b["de2"], b["b2"]], [170.0, 30.0], **tol)
    np.testing.assert_allclose(b["m_et2"], 170.0 / 42, **tol)
    np.testing.assert_allclose(b["a_p"], b["Rm2"] * math.sin(b["beta_m1"] - b["beta_m2"]), **tol)
    if method == "iso23509-method0":
        np.testing.assert_allclose([b["a1"], b["a2"], b["tz1"], b["tz2"], b["zeta_m"]], 0.0, **tol)
        np.testing.assert_allclose([b["theta1"], b["theta2"]], [-math.pi / 2, math.pi / 2], **tol)
    else:
        np.testing.assert_allclose(b["theta2"], math.pi / 2 - b["zeta_m"], **tol)
        np.testing.assert_allclose([b["a1"], b["a2"]], [b["tz1"], b["tz2"]], rtol=0, atol=1e-10)
    if method == "tangent-cones":
        r1, r2 = b["Rm1"] * math.sin(b["delta1"]), b["Rm2"] * math.sin(b["delta2"])
        np.testing.assert_allclose(u * r1 * math.cos(b["beta_m1"]), r2 * math.cos(b["beta_m2"]),
                                   rtol=1e-11)
        np.testing.assert_allclose(2 * (b["Rm2"] + 15.0) * math.sin(b["delta2"]), 170.0, **tol)
    th2, a1, a2 = b["theta2"], b["a1"], b["a2"]
    np.testing.assert_allclose([b["machine_dV"], b["machine_dH"], b["machine_cradle"],
                                b["machine_X_G"]],
                               [E * math.sin(th2) - a1, E * math.cos(th2) + a2, th2 + math.pi / 2,
                                a2], **tol)
    # the tilt of [Tangent-cones] sin i = tan b1 / tan a_lim has no solution (|ratio| > 1, or
    # a_lim = 0 for Method 0): NaN; the reciprocal reading asin(tan a_lim / tan b1)
    assert math.isnan(b["machine_tilt"])
    np.testing.assert_allclose(b["machine_tilt_reciprocal"],
                               math.asin(math.tan(b["alpha_lim"]) / math.tan(b["beta_m1"])), **tol)


# The tangent-cones blank comes from a Newton solve whose residual stops at its rounding
# floor (about 1e-12, gearjax/gears/hypoid/pitch_cones.py); two compilations of it (eager
# ops, one jitted program, the sensitivity program) round differently and stop at
# different points of that floor: measured up to 4.9e-12 relative (XLA CPU loop
# emitters, tests/conftest.py).  A wiring error is O(1).
FLOOR = dict(rtol=5e-11, atol=5e-11)


def test_jit_matches_eager_and_no_nans():
    inp = BlankInput.from_dict(dict(SAMPLE2, method="tangent-cones"))
    a = blank_geometry(inp)
    b = jax.jit(lambda i: blank_geometry(i, throw=False))(inp)
    for n, _, _ in hb.OUTPUTS:
        if n == "machine_tilt":
            continue
        np.testing.assert_allclose(getattr(b, n), getattr(a, n), **FLOOR)
        assert np.isfinite(float(getattr(a, n))), n


@pytest.mark.parametrize("method", ["iso23509-method1", "tangent-cones"])
def test_sensitivity_matches_central_differences(method):
    inp = BlankInput.from_dict(dict(SAMPLE2, method=method))
    s = blank_sensitivity(inp)
    J = s["jacobian"]
    assert s["inputs"] == list(hb.SENSITIVITY_INPUTS) and J.shape == (len(s["outputs"]), 6)
    assert np.all(np.isfinite(J))
    def f(x):
        return hb._sens_values_jit(inp, x, names=tuple(s["outputs"]))

    x0 = np.array([inp.offset, inp.z2 / inp.z1, inp.gear_outer_pitch_diameter,
                   inp.gear_face_width, inp.cutter_radius, inp.spiral_angle])
    h = 1e-5 * np.maximum(np.abs(x0), 1.0)
    Jfd = np.stack([(f(x0 + h[i] * np.eye(6)[i]) - f(x0 - h[i] * np.eye(6)[i])) / (2 * h[i])
                    for i in range(6)], axis=1)
    scale = np.max(np.abs(J), axis=1, keepdims=True)
    keep = scale[:, 0] > 0                      # rows that do not depend on the inputs
    err = np.max(np.abs(J - Jfd)[keep] / scale[keep])
    worst = int(np.argmax(np.max(np.abs(J - Jfd) / np.where(scale > 0, scale, 1), axis=1)))
    assert err < 1e-6, (err, s["outputs"][worst])
    np.testing.assert_allclose(s["values"], f(x0), rtol=1e-13)
    # columns with a closed-form answer (independent of the difference quotients above,
    # which share the design-vector wiring): d_e2 and b2 are returned unchanged, the
    # limit curvature radius is the cutter radius (ISO 23509 (40)), m_et2 = d_e2/(u z1)
    # (126).  Exact but for the implicit-Newton round-off (measured <= 1.7e-13): 1e-11.
    col = {n: i for i, n in enumerate(hb.SENSITIVITY_INPUTS)}
    row = {n: i for i, n in enumerate(s["outputs"])}
    u = inp.z2 / inp.z1
    expect = {("de2", "gear_outer_pitch_diameter"): 1.0, ("b2", "gear_face_width"): 1.0,
              ("rho_lim", "cutter_radius"): 1.0, ("m_et2", "gear_outer_pitch_diameter"): 1 / inp.z2,
              ("m_et2", "ratio"): -inp.gear_outer_pitch_diameter / (inp.z1 * u ** 2)}
    if method == "tangent-cones":
        expect[("beta_m1", "spiral_angle")] = 1.0     # the pinion spiral angle is the input
    for name in ("de2", "b2", "rho_lim", "m_et2") + (("beta_m1",) if method == "tangent-cones" else ()):
        for c in hb.SENSITIVITY_INPUTS:
            np.testing.assert_allclose(J[row[name], col[c]], expect.get((name, c), 0.0),
                                       rtol=0, atol=1e-11, err_msg=f"{name} / {c}")
    # the values are the blank's outputs
    b = blank_geometry(inp)
    np.testing.assert_allclose(s["values"], [float(getattr(b, n)) for n in s["outputs"]],
                               **FLOOR)


@pytest.mark.parametrize("method", ["iso23509-method1", "tangent-cones"])
def test_seed000_cutter_study_trends(method):
    """[Eigenfunctions] Table 1: a larger cutter gives a smaller pinion pitch angle, a smaller
    drive-side pressure angle and (slightly) a wider pinion; our numbers beside the
    paper's are in docs/hypoid_blank.md (no agreement is forced)."""
    rows = []
    for rc0 in (76.2, 95.25, 114.3):
        b = blank_geometry(BlankInput.from_dict(dict(SEED000, method=method, cutter_radius_mm=rc0)))
        t = b.to_dict()
        np.testing.assert_allclose(t["rho_lim"], rc0, rtol=1e-10)
        rows.append((t["delta1"], t["alpha_nD"], t["alpha_nC"], t["b1"], t["beta_m2"]))
    d1, aD, aC, b1, b2 = np.array(rows).T
    assert np.all(np.diff(d1) < 0) and np.all(np.diff(aD) < 0) and np.all(np.diff(aC) > 0)
    assert np.all(np.diff(b1) > 0)
    np.testing.assert_allclose(aD + aC, 38.0, atol=1e-12)   # f_alim = 1: balanced about 19 deg


def test_non_convergence_strict_and_flag():
    inp = BlankInput.from_dict(dict(SAMPLE2, method="tangent-cones", cutter_radius_mm=2.0))
    with pytest.raises(ConvergenceError):
        blank_geometry(inp)
    b = blank_geometry(inp, throw=False)
    assert float(b.converged) == 0.0


def test_pytree_registration():
    inp = BlankInput.from_dict(SAMPLE2)
    leaves, tree = jax.tree_util.tree_flatten(inp)
    assert len(leaves) == 14                     # continuous fields only
    back = jax.tree_util.tree_unflatten(tree, leaves)
    assert back == inp
    # reverse mode over the whole pytree (Method 0: closed forms, cheap to compile;
    # Newton-based routes are differentiated in the sensitivity tests)
    inp0 = BlankInput.from_dict(dict(SAMPLE2, method="iso23509-method0", offset_mm=0.0))
    g = jax.grad(lambda i: blank_geometry(i, throw=False).dae1)(inp0)
    assert isinstance(g, BlankInput)
    assert all(np.isfinite(v) for v in jax.tree_util.tree_leaves(g))
    # d(dae1)/d(de2) at fixed angles: outer pitch diameters scale with d_e2 (de1 = de2 z1/z2)
    assert 13 / 42 < g.gear_outer_pitch_diameter < 1.0


def test_cutter_too_small_for_face_width_is_a_value_error():
    """Method 1 converges for r_c0 = 20 mm (ISO sample 2 otherwise), but the outer
    spiral angle (ISO 23509 (183), (193)) needs sin beta > 1."""
    inp = BlankInput.from_dict(dict(SAMPLE2, cutter_radius_mm=20.0))
    with pytest.raises(ValueError, match="cutter_radius_mm = 20"):
        blank_geometry(inp)
    b = blank_geometry(inp, throw=False)
    assert float(b.converged) == 1.0 and np.isnan(float(b.beta_e2))


def test_former_method_name_still_loads():
    """Design files written with the former method name load as "tangent-cones" and give
    the same blank (old files must keep working)."""
    old = BlankInput.from_dict(dict(SAMPLE2, method="seed003-tangency"))
    new = BlankInput.from_dict(dict(SAMPLE2, method="tangent-cones"))
    assert old.method == "tangent-cones" and old == new
