"""The family interface is enough: a tiny toy family written in the test, run by the
one TCA driver (gearjax/tca/family.py) through the public entry points.

The toy is a standard spur pair with closed-form involute flanks -- no tool, no
generation: a point at radius R of member i lies at the polar angle
``pi/2 + s psi_i(R)``, ``psi_i(R) = s_i/(2 r_i) + inv(alpha) - inv(arccos(r_bi/R))``
(half the tooth thickness at the pitch circle as an angle, then the involute), ``s``
the flank side, ``z`` the axial coordinate.  Parallel axes at the standard centre
distance, line contact.  Closed forms it must meet: TE = 0 (a conjugate pair), every
contact on the line of action (the line through the pitch point at the pressure angle
to the common tangent, mirrored for the other side), and the transverse contact ratio of ISO 21771
``eps_alpha = (sqrt(r_a1^2 - r_b1^2) + sqrt(r_a2^2 - r_b2^2) - a sin(alpha)) /
(pi m cos(alpha))``.  The family says only what the pair is (flanks, mounting,
boundaries, reference, summary); the grid, the continuation, the tooth pairs, the
envelope, the contact ratio, the kinematics, the derivatives and the option checks
are the driver's.  Planted bugs caught: a driver that ignores the family's
flanks or mounting (TE and line of action), drops its boundaries (contact ratio),
loses ``line_contact`` or the side (the option tests), or a registry that does not
dispatch a new design type.
"""

from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.tca.family import DriverAdapter, GearFamily
from gearjax.tca.assembly import Assembly
from gearjax.tca.result import register_family


class ToyPair(NamedTuple):
    z1: jnp.ndarray
    z2: jnp.ndarray
    m: jnp.ndarray
    alpha: jnp.ndarray
    b: jnp.ndarray


def _inv(a):
    return jnp.tan(a) - a


def _member(pair, i):
    z = pair.z1 if i == 0 else pair.z2
    r = 0.5 * z * pair.m
    return dict(r=r, rb=r * jnp.cos(pair.alpha), ra=r + pair.m, s=0.5 * jnp.pi * pair.m)


def _psi(pair, i, R):
    # (below the base circle, where a Newton iterate may wander, the involute is
    # continued at its base-circle value: finite values and derivatives everywhere)
    g = _member(pair, i)
    c = jnp.minimum(g["rb"] / R, 1.0 - 1e-12)
    return g["s"] / (2 * g["r"]) + _inv(pair.alpha) - _inv(jnp.arccos(c))


class ToySpur(GearFamily):
    name = "toy_spur"
    defaults = dict(steps_per_pitch=8, half_pitches=1.25, n_pairs=3)
    line_contact_modes = (True,)
    contact_mode_reason = "straight spur teeth touch along a line"
    summary_keys = ("ptp_rad", "phi2_ref_rad")

    @staticmethod
    def _sig(drive):
        return jnp.where(drive, 1.0, -1.0)

    def flanks(self, pair, drive, line_contact=False):
        s = self._sig(drive)

        def flank(i):
            def r(uv):
                t = 0.5 * jnp.pi + s * _psi(pair, i, uv[0])
                return jnp.stack([uv[0] * jnp.cos(t), uv[0] * jnp.sin(t), uv[1]])
            return r
        return flank(0), flank(1)

    def assembly(self, pair):
        a = _member(pair, 0)["r"] + _member(pair, 1)["r"]
        return Assembly(jnp.eye(3), jnp.stack([0.0 * a, a, 0.0 * a]),
                        jnp.array([0.0, 1.0, 0.0]), pair.z1, pair.z2, -1)

    def reference(self, pair, side):
        # the pitch point (0, r1): the pinion turned so that its pitch-circle point is
        # there, the gear so that its own is (polar angle -pi/2 about its centre)
        s = 1.0 if side == "drive" else -1.0
        r1, r2 = _member(pair, 0)["r"], _member(pair, 1)["r"]
        phi1 = -s * _psi(pair, 0, r1)
        phi2 = -jnp.pi - s * _psi(pair, 1, r2)
        return jnp.stack([r1, 0.0, r2, 0.0, phi2]), phi1

    def boundaries(self, pair, path):
        # margins as roll lengths along the line of action (mm), tip and base circle:
        # sqrt(R^2 - r_b^2) is linear in the pinion angle along the path, so the
        # driver's linear interpolation of the margin's zero crossings is exact
        # (margins in radius would put kinks into their minimum)
        parts = []
        for i, radial in ((0, path.radial1), (1, path.radial2)):
            g = _member(pair, i)
            roll = jnp.sqrt(jnp.maximum(radial ** 2 - g["rb"] ** 2, 0.0))
            parts += [jnp.sqrt(g["ra"] ** 2 - g["rb"] ** 2) - roll, roll]
        parts.append(0.5 * pair.b - jnp.abs(path.axial1))
        return jnp.min(jnp.stack(parts), axis=0), {}

    def summary(self, pair, res):
        mid = res.path.phi1.shape[0] // 2
        return jnp.stack([res.multi.ptp, res.path.phi2[mid]])


TOY = DriverAdapter(ToySpur())
register_family(ToyPair, TOY)


def _toy(z1=18.0, z2=31.0, m=3.0, alpha_deg=20.0, b=20.0):
    return ToyPair(*(jnp.asarray(float(v)) for v in (z1, z2, m, np.radians(alpha_deg), b)))


def _iso_contact_ratio(z1, z2, m, alpha):
    r1, r2 = 0.5 * z1 * m, 0.5 * z2 * m
    rb1, rb2 = r1 * np.cos(alpha), r2 * np.cos(alpha)
    return ((np.sqrt((r1 + m) ** 2 - rb1 ** 2) + np.sqrt((r2 + m) ** 2 - rb2 ** 2)
             - (r1 + r2) * np.sin(alpha)) / (np.pi * m * np.cos(alpha)))


@pytest.fixture(scope="module")
def toy_runs():
    out = {}
    for z1, z2 in ((18, 31), (25, 41)):          # one program: tooth numbers are data
        for side in ("drive", "coast"):
            out[(z1, z2, side)] = gj.run_tca(_toy(z1, z2), side=side, kinematics=True)
    return out


@pytest.mark.parametrize("z1, z2", [(18, 31), (25, 41)])
@pytest.mark.parametrize("side", ["drive", "coast"])
def test_toy_family_meets_the_closed_forms(toy_runs, z1, z2, side):
    res = toy_runs[(z1, z2, side)]
    assert res.family == "toy_spur" and res.side == side
    on = np.asarray(res.on_flank)
    assert on.sum() >= 5 and bool(np.all(np.asarray(res.path.converged)[on]))
    te = np.asarray(res.path.te)[on]
    assert np.max(np.abs(te)) / gj.ARCSEC < 1e-6
    # the contact points on the line of action through the pitch point (0, r1) at the
    # pressure angle, on the side's flank (mirror image x -> -x for the other side)
    alpha = np.radians(20.0)
    p = np.asarray(res.path.point)[on]
    r1 = 0.5 * z1 * 3.0
    d_plus = np.abs((p[:, 1] - r1) * np.cos(alpha) - p[:, 0] * np.sin(alpha))
    d_minus = np.abs((p[:, 1] - r1) * np.cos(alpha) + p[:, 0] * np.sin(alpha))
    assert min(d_plus.max(), d_minus.max()) < 1e-9, (d_plus.max(), d_minus.max())
    eps = _iso_contact_ratio(z1, z2, 3.0, alpha)
    assert float(res.contact_ratio) == pytest.approx(eps, rel=1e-9)
    # the driver's kinematics on the toy: no sliding at the pitch point
    mid = np.asarray(res.path.phi1).size // 2
    assert abs(float(np.asarray(res.kinematics.srr)[mid])) < 1e-9


def test_toy_family_options_sensitivity_and_gradient():
    """The driver's option checks and a reverse-mode derivative through
    ``tca_function`` for the toy family: the gear angle at the reference against a
    centre-distance change dE, against central differences (and not zero: a larger
    centre distance turns the gear back by the backlash it opens)."""
    des = _toy()
    with pytest.raises(ValueError, match=r"line_contact = False is not available for "
                                         r"toy_spur pairs: straight spur teeth"):
        gj.run_tca(des, line_contact=False)
    with pytest.raises(ValueError, match="unknown TCA option 'pitches'"):
        gj.tca_function(des, pitches=2)
    f = gj.tca_function(des, side="drive", kinematics=False)

    def te_shift(dE):
        mid = 10
        return f(des, gj.Misalignment(dE, 0.0 * dE, 0.0 * dE, 0.0 * dE)).path.phi2[mid]

    g = jax.grad(te_shift)(jnp.asarray(0.0))
    h = 1e-5
    fd = (te_shift(jnp.asarray(h)) - te_shift(jnp.asarray(-h))) / (2 * h)
    assert float(g) == pytest.approx(float(fd), rel=1e-6)
    assert abs(float(g)) > 1e-4


def _call_names(jaxpr, out):
    for eqn in jaxpr.eqns:
        if "name" in eqn.params:
            out.add(eqn.params["name"])
        for v in eqn.params.values():
            for sub in (v if isinstance(v, (tuple, list)) else (v,)):
                inner = getattr(sub, "jaxpr", sub)
                if hasattr(inner, "eqns"):
                    _call_names(inner, out)
    return out


def test_a_traced_tca_runs_its_stages_inline():
    """Under a trace the driver's two stages run inline in it, not as the nested jitted
    programs a concrete run compiles: ``grad`` would trace each nested program and then
    transform its jaxpr again, and partial evaluation across their boundaries kept
    residuals it drops inline (the hypoid efficiency gradient was 7 % larger).  Planted
    bug caught: the driver calling its jitted programs inside a trace, or handing the
    inline stages its arguments in another order than the programs (the coast side
    traced as the drive side: the jitted coast path against the concrete one)."""
    des = _toy()
    f = gj.tca_function(des, side="coast", kinematics=False)

    def phi2(dE):
        return f(des, gj.Misalignment(dE, 0.0 * dE, 0.0 * dE, 0.0 * dE)).path.phi2

    jaxpr = jax.make_jaxpr(phi2)(0.0)
    names = _call_names(jaxpr.jaxpr, set())
    assert not names & {"_surface_program", "_finish_program"}, names
    assert jaxpr.out_avals[0].shape[0] > 3        # the path itself was traced
    concrete = f(des).path
    np.testing.assert_allclose(jax.jit(phi2)(0.0), concrete.phi2, rtol=0, atol=1e-12)


def test_an_option_given_as_none_takes_the_family_default(toy_runs):
    """Every TCA option given as None means the family's default (what a command line
    or a study file passes for an option it leaves out): the same static options and the
    same result, bit-identical, as the run without them (its compiled program)."""
    des = _toy(18, 31)
    names = ("steps_per_pitch", "half_pitches", "n_pairs", "line_contact", "approach",
             "face_ends", "kinematics")
    assert TOY.resolve(des, dict.fromkeys(names)) == TOY.resolve(des, {})
    res = gj.run_tca(des, side="drive", **dict.fromkeys(names))
    ref = toy_runs[(18, 31, "drive")]
    for name in ("phi1", "phi2", "te", "converged"):
        np.testing.assert_array_equal(np.asarray(getattr(res.path, name)),
                                      np.asarray(getattr(ref.path, name)), err_msg=name)
    assert res.kinematics is not None


def test_driver_strict_default_and_masks():
    """``throw`` defaults to True in the driver's ``run``: a pair with no grid point on
    both flanks (here a negative face width: every face margin < 0) is a
    ``NoContactError`` (a ``ConvergenceError``), and ``throw=False`` returns the result
    with its masks instead (the same compiled program as the closed-form runs)."""
    bad = _toy(b=-1.0)
    with pytest.raises(gj.ConvergenceError, match="no contact inside the flank boundaries"):
        gj.run_tca(bad, side="drive")
    res = gj.run_tca(bad, side="drive", throw=False)
    assert not np.any(np.asarray(res.on_flank))


def test_on_flank_check_spans_the_converged_points_inside():
    """``check_on_flank_converged`` (the strict default's check, on host arrays): it
    raises for a failed solve *between* converged on-flank points, not for a failed
    solve outside that span whose junk margin happens to be >= 0, and says "no contact"
    when no converged point is inside.  Planted bugs caught: the span taken over
    unconverged points too; the residual of the whole path reported."""
    from types import SimpleNamespace
    from gearjax.tca.path import NoContactError, check_on_flank_converged

    def path(conv):
        conv = np.asarray(conv, bool)
        return SimpleNamespace(converged=conv, residual=np.where(conv, 1e-13, 3e-2))
    margin = np.array([-1.0, -1.0, 0.5, 1.0, 0.5, -1.0, -1.0, 0.7, -1.0])
    # failed solve at 7 (margin junk, >= 0) outside the converged span 2..4
    check_on_flank_converged(path([1, 1, 1, 1, 1, 1, 1, 0, 1]), margin)
    # failed solve at 3, inside the span 2..5 (4 is the reference point, converged):
    # reported with its own residual
    with pytest.raises(gj.ConvergenceError, match=r"on the flank: 1 of 4 solves .*worst "
                                                  r"residual among them 0\.03"):
        check_on_flank_converged(path([1, 1, 1, 0, 1, 1, 1, 1, 1]),
                                 np.array([-1.0, -1.0, 0.5, 1.0, 0.5, 0.6, -1.0, -1.0, -1.0]))
    # only an unconverged point inside: no contact
    with pytest.raises(NoContactError, match="no contact inside the flank boundaries"):
        check_on_flank_converged(path([1, 1, 1, 1, 1, 1, 1, 0, 1]),
                                 np.where(np.arange(9) == 7, 0.7, -1.0))


def test_driver_solves_edges_only_when_asked():
    """``face_ends`` reaches the family: its ``edges`` are asked for exactly when the
    option is on (traced only, nothing compiled)."""
    from gearjax.tca.family import tca_parts

    calls = []

    class Spy(ToySpur):
        def edges(self, pair):
            calls.append(1)
            return None

    des = _toy()
    x_ref, phi1_ref = Spy().reference(des, "drive")
    for flag, n in ((False, 0), (True, 1)):
        calls.clear()
        jax.eval_shape(lambda p: tca_parts(Spy(), p, gj.Misalignment.zero(), x_ref, phi1_ref,
                                           jnp.asarray(True), 0.00632, steps_per_pitch=8,
                                           half_pitches=1.25, n_pairs=3, kinematics=False,
                                           face_ends=flag, line_contact=True), des)
        assert len(calls) == n, flag


def test_driver_sensitivity_table_matches_central_differences(toy_runs):
    """``gj.tca_sensitivity`` through the driver (its own ``jacfwd`` program) against
    central differences of the same summary from ``run_tca`` (the program of the
    closed-form runs): the gear angle at the reference per mm of dE, and the TE p-t-p,
    which stays 0 for the conjugate pair.  A table differentiated at the wrong point or
    not at all (zero) fails."""
    des = _toy()
    values, table = gj.tca_sensitivity(des, side="drive")
    mid = 10
    assert values["phi2_ref_rad"] == pytest.approx(
        float(toy_runs[(18, 31, "drive")].path.phi2[mid]), rel=1e-12)
    h = 1e-6

    def phi2(dE):
        mis = gj.Misalignment(*(jnp.asarray(v) for v in (dE, 0.0, 0.0, 0.0)))
        return float(gj.run_tca(des, mis, side="drive").path.phi2[mid])
    fd = (phi2(h) - phi2(-h)) / (2 * h)
    assert table["phi2_ref_rad"]["dE"] == pytest.approx(fd, rel=1e-6)
    assert abs(fd) > 1e-4
    assert abs(table["ptp_rad"]["dE"]) < 1e-9
