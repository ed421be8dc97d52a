"""TCA of face-milled spiral-bevel pairs: conjugacy of a pair cut by one crown gear,
localised contact from a cutter-radius mismatch (TE identically zero), the parabolic
TE of a modified roll against first-order theory, gradients against central
differences, the misalignment table, and the checks of the adapter (bad input, no
contact)."""

from dataclasses import replace
from functools import partial

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.io import load_design
from gearjax import tca_hypoid as th
from gearjax.tca import ARCSEC, Misalignment, NoContactError

STEPS, HALF = 8, 1.5          # 25 grid positions, 1.5 pitches each side
MID = int(round(STEPS * HALF))


@pytest.fixture(scope="module")
def conjugate():
    d = load_design("example:spiral_bevel_10x30")
    pair = th.pair_flanks(d, "drive")
    p_fl, g_fl = th.complementary_pinion(pair.gear, pair.pinion.blank)
    return th.prepare(replace(pair, pinion=p_fl, gear=g_fl))


def _modified(prep, d_radius, c2):
    pair = prep.pair
    p = th.with_point_radius(pair.pinion, d_radius, prep.x_ref[0])
    p = replace(p, machine=replace(p.machine, modified_roll_2c=jnp.asarray(c2, float)))
    return replace(pair, pinion=p)


@pytest.fixture(scope="module")
def point_tca(conjugate):
    f = jax.jit(partial(th.hypoid_tca_traced, line_contact=False, steps_per_pitch=STEPS,
                        half_pitches=HALF, n_pairs=3, drive=conjugate.drive))
    return lambda pair, mis=Misalignment.zero(): f(pair, mis, jnp.asarray(conjugate.x_ref),
                                                   conjugate.phi1_ref)


def test_crown_gear_complementary_pair_is_conjugate(conjugate):
    res = th.hypoid_tca(conjugate, line_contact=True, steps_per_pitch=STEPS, half_pitches=HALF,
                        n_pairs=3, strict=False)
    p = res.path
    assert bool(np.all(np.asarray(p.converged)))
    te = np.abs(np.asarray(p.te)) / ARCSEC
    assert te.max() < 1e-6                                  # issue: below 1e-6 arcsec
    assert float(np.max(np.asarray(p.residual))) < 1e-10
    assert np.all(np.isinf(np.asarray(p.semi_major)))       # line contact
    # the contact line crosses the working flank during the cycle
    assert np.any(np.asarray(res.margin) > 1.0)


def test_cutter_radius_mismatch_localises_with_zero_te(conjugate, point_tca):
    """Blade cones tangent along the blade through the mean point: the pinion equals
    the conjugate one along the curve that blade generates, so the contact runs on
    that curve with TE identically zero and a finite contact ellipse."""
    res = point_tca(_modified(conjugate, 2.0, 0.0))
    p = res.path
    on = np.asarray(res.margin) >= 0
    assert on.sum() >= 6 and bool(np.all(np.asarray(p.converged)[on]))
    assert np.abs(np.asarray(p.te)[on]).max() / ARCSEC < 1e-6
    a, b = np.asarray(p.semi_major)[on], np.asarray(p.semi_minor)[on]
    assert np.all(np.isfinite(a)) and np.all(a > b) and np.all(b > 0.05)
    # bearing at the reference is the pinion's mean point (mid face)
    assert abs(float(res.coords["xi1"][MID])) < 0.1
    # the opposite mismatch (hollow pinion) has no such contact: the flanks cross
    bad = point_tca(_modified(conjugate, -2.0, 0.0))
    conv = np.asarray(bad.path.converged)
    assert not np.all(conv) or np.any(~np.isfinite(np.asarray(bad.path.semi_major)))


def test_modified_roll_gives_the_parabola_of_first_order_theory(conjugate, point_tca):
    """Modified roll phi = R_a (psi - C psi^2) turns each generated line of the pinion
    by -R_a C psi^2; in mesh psi = dphi1/R_a, so TE = (z1/z2)(C/R_a)(phi1 - phi1_0)^2
    to first order in C (gear angle)."""
    c2 = 0.02
    pair = _modified(conjugate, 2.0, c2)
    res = point_tca(pair)
    p = res.path
    assert bool(np.all(np.asarray(p.converged)))
    x = np.asarray(p.phi1) - float(p.phi1[MID])
    te = np.asarray(p.te) / ARCSEC
    coef = np.polyfit(x, te, 3)
    theory = (pair.z1 / pair.z2) * (0.5 * c2 / float(pair.pinion.machine.ratio_of_roll)) / ARCSEC
    assert abs(coef[1] / theory - 1.0) < 0.01
    fit = np.polyval(np.polyfit(x, te, 2), x)
    assert np.abs(fit - te).max() < 0.02 * np.ptp(te)        # a parabola over +-1.5 pitches
    m = res.multi
    assert np.isfinite(float(m.ptp)) and float(m.ptp) / ARCSEC > 1.0
    assert 1.0 < float(m.contact_ratio) < 3.0


def test_gradients_match_central_differences(conjugate, point_tca):
    """d(TE ptp, bearing position, ellipse) / d(pinion settings, misalignments)."""
    def summary(v):
        pair = _modified(conjugate, 2.0 + v[0], 0.02 + v[1])
        mis = Misalignment(v[2], v[3], v[4], v[5])
        return th.tca_summary(pair, point_tca(pair, mis))

    idx = np.array([0, 2, 3, 6])          # ptp, xi1, h1, semi_major
    v0 = jnp.zeros(6)
    J = np.asarray(jax.jit(jax.jacfwd(summary))(v0))[idx]
    f = summary                       # eager glue around the compiled TCA
    for k, h in enumerate([1e-3, 1e-4, 1e-3, 1e-3, 1e-3, 1e-5]):
        e = np.zeros(6)
        e[k] = h
        # 4th-order central difference
        fd = (-np.asarray(f(v0 + 2 * e)) + 8 * np.asarray(f(v0 + e)) - 8 * np.asarray(f(v0 - e))
              + np.asarray(f(v0 - 2 * e)))[idx] / (12 * h)
        scale = np.maximum(np.abs(J[:, k]), 1e-3 * np.abs(np.asarray(f(v0))[idx]) + 1e-12)
        err = np.abs(fd - J[:, k]) / scale
        np.testing.assert_array_less(err, 1e-5, err_msg=f"variable {k}")
    assert np.all(np.isfinite(J))


def test_bad_input_and_no_contact(conjugate):
    with pytest.raises(ValueError, match="steps_per_pitch"):
        th.hypoid_tca(conjugate, steps_per_pitch=1)
    with pytest.raises(ValueError, match="n_pairs"):
        th.hypoid_tca(conjugate, n_pairs=4)
    with pytest.raises(ValueError, match="side"):
        th.pair_flanks(load_design("example:spiral_bevel_10x30"), "reverse")
    # pinion turned inside out (the other blade side): its flank cannot meet the gear's
    pair = conjugate.pair
    wrong = replace(pair, pinion=replace(pair.pinion, cutter=replace(pair.pinion.cutter,
                                                                     sign=-pair.pinion.cutter.sign)))
    with pytest.raises(NoContactError):
        th.prepare(wrong)
