"""Materials and units of the loaded chain (issue #28 item 3), on the VH-CATT example
(the family whose design file has a ``[material]`` table):

* the design's material sets E' *and* the tooth compliance: E = 100 vs 500 GPa give
  different p_max, loaded fall-back and loaded TE, in the expected direction, and at a
  single-contact position (one pair carries the whole torque, so the load is the same
  for both materials) p_max follows Hertz' point contact p_max ~ E'^(2/3) exactly and
  the fall-back lies between the linear (1/E) and the Hertz (E'^(-2/3)) scalings;
* ``--E-prime-MPa`` overrides the file with the file's nu (E = E'(1 - nu^2)): the same
  numbers as a file with that E; the JSON names the source;
* the command and ``gearjax.loading.mesh_efficiency`` give the same eta_bar (one default
  compliance model);
* concrete inputs typed in the wrong unit are refused in one line before any work,
  traced ones are not checked.

One compiled TCA program and one loaded-contact program serve every run here (the
material enters as data).
"""

import contextlib
import copy
import dataclasses
import inspect
import io
import json

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.cli import main
from gearjax.loading.materials import SOURCE_DESIGN, SOURCE_DEFAULT, reduced_modulus
from gearjax.loading.mesh_efficiency import check_efficiency_inputs, mesh_efficiency_traced

EX = "example:vh_catt_17x23"
T, RPM = 100.0, 1000.0
CLI = ["efficiency", EX, "--torque-Nm", "100", "--rpm", "1000", "--oil", "mineral_vg100",
       "--sigma-um", "0.4", "--json"]


@pytest.fixture(scope="module")
def vh():
    return gj.load_design(EX)


@pytest.fixture(scope="module")
def oil_surface():
    return gj.tribology.get_oil("mineral_vg100"), gj.tribology.make_surface(0.4)


def _with_E(design, E_GPa):
    data = copy.deepcopy(design.data)
    data["material"]["youngs_modulus_GPa"] = E_GPa
    return gj.design_from_dict(data)


@pytest.fixture(scope="module")
def runs(vh, oil_surface):
    """Python runs at the file's material (203 GPa) and at E = 100 and 500 GPa."""
    return {E: gj.mesh_efficiency(_with_E(vh, E), T, RPM, *oil_surface)[0]
            for E in (203.0, 100.0, 500.0)}


def _cli(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = main(argv)
    return rc, json.loads(out.getvalue()), err.getvalue()


def test_pair_material_precedence(vh):
    """Explicit E' > the design's [material] > steel; the source is said."""
    m = gj.pair_material(vh)
    assert m.source == SOURCE_DESIGN and m.youngs_modulus_MPa == 203000.0 and m.poisson == 0.3
    assert float(m.e_prime_MPa) == pytest.approx(203000.0 / 0.91, rel=1e-15)
    # E' = 2/((1-nu1^2)/E1 + (1-nu2^2)/E2): two equal members give E/(1-nu^2)
    assert reduced_modulus(203000.0, 0.3, 203000.0, 0.3) == pytest.approx(203000.0 / 0.91)
    assert reduced_modulus(206000.0, 0.3, 70000.0, 0.33) == pytest.approx(
        2.0 / (0.91 / 206000.0 + (1 - 0.33 ** 2) / 70000.0), rel=1e-15)
    o = gj.pair_material(vh, 300000.0, override_source="--E-prime-MPa")
    assert o.source == "--E-prime-MPa" and o.poisson == 0.3
    assert float(o.e_prime_MPa) == pytest.approx(300000.0, rel=1e-15)
    spur = gj.involute.InvoluteTCA.create(gj.involute.InvolutePair.create(20, 40, 4.0, 20.0), 30.0)
    s = gj.pair_material(spur)
    assert s == gj.loading.STEEL and s.source == SOURCE_DEFAULT
    assert float(s.e_prime_MPa) == pytest.approx(gj.tribology.STEEL_E_PRIME, rel=1e-12)


def test_material_sets_hertz_and_compliance(runs):
    """E = 100 vs 500 GPa: stiffer teeth and contacts -- higher p_max, smaller fall-back
    and loaded TE; at the positions where one pair carries the torque (same load for
    both materials) p_max ~ E'^(2/3) (Hertz point contact at fixed load and radii) and
    the fall-back y = (q F + c F^(2/3))/l2 scales between 1/E (tooth compliance q) and
    E'^(-2/3) (Hertz approach c): both parts follow the material.  Before #28 the file's
    material was ignored (identical results for 100, 203 and 500 GPa)."""
    soft, hard = runs[100.0], runs[500.0]
    assert all(bool(np.all(np.asarray(e.valid))) for e in (soft, hard))
    assert float(hard.max_p_max) > float(soft.max_p_max)
    assert float(hard.te_loaded_ptp) < float(soft.te_loaded_ptp)
    assert float(hard.mean_efficiency) != float(soft.mean_efficiency)
    n_s, n_h = np.asarray(soft.loaded.n_loaded), np.asarray(hard.loaded.n_loaded)
    single = (n_s == 1) & (n_h == 1)
    assert single.sum() >= 4
    F_s, F_h = (np.asarray(e.loaded.load).sum(axis=0)[single] for e in (soft, hard))
    np.testing.assert_allclose(F_h, F_s, rtol=1e-10)           # same load: statics only
    p_s, p_h = (np.asarray(e.loaded.p_max).max(axis=0)[single] for e in (soft, hard))
    np.testing.assert_allclose(p_h / p_s, 5.0 ** (2.0 / 3.0), rtol=1e-9)
    y_s, y_h = (np.asarray(e.loaded.deflection)[single] for e in (soft, hard))
    ratio = y_h / y_s
    assert np.all(ratio > 1.0 / 5.0) and np.all(ratio < 5.0 ** (-2.0 / 3.0)), ratio


def test_cli_equals_python_and_reports_the_material(runs):
    """One default compliance model: the command and mesh_efficiency give the same
    eta_bar (before #28: 0.987533 on the command, iso6336, vs 0.987853 in Python,
    weber); the file's material is used and said; --E-prime-MPa overrides it with the
    file's nu, giving exactly the run of a file with E = E'(1 - nu^2)."""
    rc, out, _ = _cli(CLI)
    assert rc == 0
    assert out["input"]["compliance"] == gj.loading.DEFAULT_COMPLIANCE == "weber"
    assert out["input"]["material_source"] == SOURCE_DESIGN
    assert out["input"]["E_prime_MPa"] == pytest.approx(203000.0 / 0.91, rel=1e-15)
    assert out["input"]["youngs_modulus_MPa"] == 203000.0 and out["input"]["poisson"] == 0.3
    assert out["mean_efficiency"] == pytest.approx(float(runs[203.0].mean_efficiency), rel=1e-13)
    assert out["max_p_max_MPa"] == pytest.approx(float(runs[203.0].max_p_max), rel=1e-13)
    rc, over, _ = _cli(CLI + ["--E-prime-MPa", repr(500000.0 / 0.91)])
    assert rc == 0 and over["input"]["material_source"] == "--E-prime-MPa"
    assert over["input"]["youngs_modulus_MPa"] == pytest.approx(500000.0, rel=1e-14)
    assert over["mean_efficiency"] == pytest.approx(float(runs[500.0].mean_efficiency),
                                                    rel=1e-12)
    assert over["te_loaded_ptp_arcsec"] == pytest.approx(
        float(runs[500.0].te_loaded_ptp) / gj.ARCSEC, rel=1e-9)


def test_speed_is_in_rpm_in_every_public_function():
    """One speed convention: the pinion speed is ``pinion_rpm`` (rpm) in
    mesh_efficiency, mesh_efficiency_traced and the f of efficiency_function (before
    #28 f took rad/s)."""
    for fn in (gj.mesh_efficiency, mesh_efficiency_traced, gj.check_operating_point):
        names = list(inspect.signature(fn).parameters)
        assert "pinion_rpm" in names and "rpm" not in names and "speed_rad_s" not in names
    assert "pinion_rpm" in gj.efficiency_function.__doc__


@pytest.mark.parametrize("case,words", [
    ("pressure_angle_deg", ["pressure_angle", "20", "0.174533", "0.523599", "rad"]),
    ("E_prime_Pa", ["E_prime", "2.26e+11", "1e+07", "MPa"]),
    ("rpm_zero", ["pinion_rpm", "0", "0.001"]),
    ("tau0_Pa", ["oil.tau0", "5e+06", "100", "MPa"]),
    ("sigma_um", ["surface.sigma", "0.4", "0.01", "mm"]),
])
def test_wrong_units_refused_in_one_line_before_any_work(vh, oil_surface, monkeypatch,
                                                         case, words):
    """Degrees typed into a radian field, E' in Pa, a zero speed, an Eyring stress in
    Pa, a roughness in um: one-line ValueError naming the parameter, its value and the
    range, before any TCA runs."""
    oil, surf = oil_surface
    def forbidden(*a, **k):
        raise AssertionError("work started on bad input")
    monkeypatch.setattr(gj.tca.family_of(vh), "run", forbidden)
    monkeypatch.setattr(gj.tca.family_of(vh), "mesh", forbidden)
    args = dict(design=vh, torque_Nm=T, pinion_rpm=RPM, oil=oil, surface=surf, E_prime=None)
    if case == "pressure_angle_deg":
        args["design"] = dataclasses.replace(vh.pair, pressure_angle=jnp.asarray(20.0))
    elif case == "E_prime_Pa":
        args["E_prime"] = 2.26e11
    elif case == "rpm_zero":
        args["pinion_rpm"] = 0.0
    elif case == "tau0_Pa":
        args["oil"] = dataclasses.replace(oil, tau0=jnp.asarray(5e6))
    else:
        args["surface"] = dataclasses.replace(surf, sigma=jnp.asarray(0.4))
    with pytest.raises(ValueError) as exc:
        gj.mesh_efficiency(**args)
    msg = str(exc.value)
    assert "\n" not in msg and all(w in msg for w in words), msg
    if case in ("pressure_angle_deg", "E_prime_Pa"):
        with pytest.raises(ValueError, match=words[0]):
            if case == "pressure_angle_deg":
                gj.run_tca(args["design"])
            else:
                gj.efficiency_function(vh, E_prime=args["E_prime"])


def test_traced_values_are_not_checked(vh, oil_surface):
    """Under a transformation the same wrong numbers pass the checks (no Python
    branching on traced values): the checks trace to nothing."""
    oil, surf = oil_surface
    jaxpr = jax.make_jaxpr(lambda a: gj.check_design(
        dataclasses.replace(vh.pair, pressure_angle=a)))(20.0)
    assert len(jaxpr.eqns) == 0
    jaxpr = jax.make_jaxpr(lambda e, n: check_efficiency_inputs(
        T, n, oil, surf, e, 0.3, "weber", "roelands", "auto"))(2.26e11, 0.0)
    assert len(jaxpr.eqns) == 0


def test_one_compliance_sentence_in_readme_help_and_docstring():
    """The default compliance model is documented identically (the same sentence) in the
    README, ``gearjax efficiency --help`` and the docstring of mesh_efficiency, and the
    defaults agree (before #28: README and Python weber, the command iso6336)."""
    import os

    from gearjax.cli import build_parser
    norm = lambda t: " ".join(t.split())           # noqa: E731  (line breaks aside)
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    with open(os.path.join(root, "README.md"), encoding="utf-8") as fh:
        readme = norm(fh.read())
    sub = build_parser()._subparsers._group_actions[0].choices["efficiency"]
    helptext = norm(sub.format_help())
    sentence = norm(gj.loading.COMPLIANCE_HELP)
    assert sentence in readme and sentence in helptext
    assert sentence in norm(gj.mesh_efficiency.__doc__)
    comp = [a for a in sub._actions if a.dest == "compliance"][0]
    for fn in (gj.mesh_efficiency, gj.efficiency_function, mesh_efficiency_traced):
        assert inspect.signature(fn).parameters["compliance"].default == comp.default == "weber"


@pytest.mark.parametrize("field,words", [
    ("blade_angle", ["pinion.cutter.blade_angle", "20 rad", "0.785398"]),
    ("shaft_angle", ["shaft_angle", "90 rad", "3.14159"]),
])
def test_hand_built_hypoid_pair_checked_before_work(field, words):
    """A HypoidPair built by hand with degrees in a radian field is refused by
    run_tca / tca_function in one line, as make_cutter and the design file would."""
    pair = gj.hypoid.pair_flanks(gj.load_design("example:spiral_bevel_10x30"), "drive")
    gj.check_design(pair)                                    # the loader's pair passes
    if field == "blade_angle":
        cut = dataclasses.replace(pair.pinion.cutter, blade_angle=jnp.asarray(20.0))
        bad = dataclasses.replace(pair, pinion=dataclasses.replace(pair.pinion, cutter=cut))
    else:
        bad = dataclasses.replace(pair, shaft_angle=jnp.asarray(90.0))
    for fn in (gj.run_tca, gj.tca_function):
        with pytest.raises(ValueError) as exc:
            fn(bad)
        msg = str(exc.value)
        assert "\n" not in msg and all(w in msg for w in words), msg


def test_operating_point_accepts_its_documented_range():
    """The operating point accepted by the Python entry points and the command line is
    the documented one (docs/efficiency.md): torque 1e-3..1e6 N m, pinion speed 1e-3..1e6
    rpm -- high-speed gearing (turbine and e-drive pinions at 2e4..1e5 rpm) included --
    and one step outside either end is refused in one line naming the parameter.
    Planted bugs caught: a range narrowed below the documented one (a legitimate
    high-speed point refused), an open end."""
    from gearjax.loading.efficiency_inputs import check_operating_point
    for T, n in ((1e-3, 1e-3), (200.0, 1500.0), (50.0, 3.0e4), (5.0, 1.2e5), (1e6, 1e6)):
        assert check_operating_point(T, n) == (T, n)
    for T, n, name in ((0.5e-3, 1500.0, "torque_Nm"), (2e6, 1500.0, "torque_Nm"),
                       (200.0, 0.5e-3, "pinion_rpm"), (200.0, 2e6, "pinion_rpm")):
        with pytest.raises(ValueError) as exc:
            check_operating_point(T, n)
        msg = str(exc.value)
        assert "\n" not in msg and name in msg, msg
