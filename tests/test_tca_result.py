"""The common TCA result: side convention, contact-quality flags, kinematics at the
contact points against the closed form of an involute spur pair, the one entry point."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
from gearjax.tca.path import ContactPath, MultiPair
from gearjax.tca.result import TCAResult, check_side

Z1, Z2, M, ALPHA, B = 25, 41, 2.0, 20.0, 20.0


# -- side convention ----------------------------------------------------------------

def test_side_names_and_former_codes():
    assert check_side("drive") == "drive" and check_side("coast") == "coast"
    assert check_side(-1) == "drive" and check_side(1) == "coast"   # former involute codes
    for bad in ("Drive", 0, 2, True, None, "both"):
        with pytest.raises(ValueError, match="side"):
            check_side(bad)


def test_unknown_design_type_is_a_type_error():
    with pytest.raises(TypeError, match="no tooth contact analysis for a dict"):
        gj.run_tca({"z1": 25})


# -- contact-quality flags on hand-made results (each flag raised alone) ----------------

N = 11


def _result(margin, te_pairs, inside, transfer, cr, converged=None):
    z = jnp.zeros(N)
    z3 = jnp.zeros((N, 3))
    conv = jnp.ones(N, bool) if converged is None else jnp.asarray(converged)
    path = ContactPath(jnp.linspace(-1.0, 1.0, N), z, z, jnp.zeros((N, 2)), jnp.zeros((N, 2)),
                       z3, z3, z3, z3, z, z, z, z, z + 1.0, z + 0.5, z3, z, conv)
    multi = MultiPair(jnp.asarray(te_pairs), jnp.asarray(inside), z, jnp.zeros(N, int),
                      jnp.asarray(0.0), jnp.asarray(transfer), jnp.asarray(cr))
    return TCAResult(path, jnp.asarray(margin), multi, {}, None, "drive", "test")


def _crossing_case():
    # pair 0 on the flank everywhere, pairs -1/+1 as well; TE curves cross at
    # phi = -0.5 and +0.5 (grid step 0.2): a hand-over inside the flanks
    phi = np.linspace(-1.0, 1.0, N)
    te = np.stack([-(phi + 1.0) ** 2, -phi ** 2, -(phi - 1.0) ** 2])
    inside = np.ones((3, N), bool)
    return np.ones(N), te, inside, np.array([-0.5, 0.5]), 1.6


def test_flags_all_clear_for_a_hand_over_where_the_te_curves_cross():
    f = _result(*_crossing_case()).flags()
    assert f == dict(converged=True, reference_on_flank=True, edge_contact=False,
                     low_contact_ratio=False, face_end_contact=False, tip_contact=False,
                     large_te=False, crossing_flanks=False)
    assert _result(*_crossing_case()).warnings() == []


def _curved(res, B_at, normal=(0.0, 0.0, 1.0), carrying=(4, 5, 6)):
    """``res`` with the unit normal ``normal`` and major direction e_x at every point, pair
    0 the envelope's active pair at ``carrying`` and pinion Weingarten maps giving the
    relative curvature ``B_at[i]`` (2x2, 1/mm; gear map 0): in the basis (e_x, n x e_x)
    of :func:`~gearjax.tca.path.relative_curvature`, ``B = -A^T W1 A``."""
    n = np.asarray(normal, float)
    A = np.stack([[1.0, 0.0, 0.0], np.cross(n, [1.0, 0.0, 0.0])], axis=1)
    W1 = np.stack([-A @ np.asarray(B_at[i], float) @ A.T for i in range(N)])
    path = res.path._replace(normal=jnp.tile(jnp.asarray(n), (N, 1)),
                             major_dir=jnp.tile(jnp.array([1.0, 0.0, 0.0]), (N, 1)),
                             weingarten1=jnp.asarray(W1), weingarten2=jnp.zeros((N, 3, 3)))
    active = np.where(np.isin(np.arange(N), carrying), 1, 0)
    return TCAResult(path, res.margin, res.multi._replace(active=jnp.asarray(active)),
                     {}, None, "drive", "test")


def test_crossing_flanks_where_pair_0_carries_at_an_indefinite_relative_curvature():
    """Hand-made paths with curvatures (docs/tca.md, "Crossing flanks"): the flag is
    raised alone exactly when pair 0 carries the load at an on-flank point whose relative
    curvature is indefinite -- whatever the sense of the normal, an off-diagonal B
    included, a line contact (det B = 0 to round-off) not; an indefinite point that
    carries no load, or lies off the flank, is marked per point but raises nothing.
    Planted bugs caught: the sign of the determinant, a test of the diagonal alone, the
    tolerance scaled wrongly, the carrying or on-flank mask dropped."""
    base = _result(*_crossing_case())
    good, saddle = np.diag([1.0, 2.0]), np.diag([1.0, -2.0])
    skew = np.array([[1.0, 2.0], [2.0, 1.0]])               # det -3, both diagonals > 0
    line = np.diag([-1e-12, 0.5])                            # a line contact's round-off

    def run(bad, at, **kw):
        B = [bad if i == at else good for i in range(N)]
        r = _curved(base, B, **kw)
        return np.asarray(r.flanks_cross), r.flags(), r.warnings()

    clear = dict(converged=True, reference_on_flank=True, edge_contact=False,
                 low_contact_ratio=False, face_end_contact=False, tip_contact=False,
                 large_te=False, crossing_flanks=False)
    cross, f, w = run(good, 5)
    assert not cross.any() and f == clear and w == []
    for bad, normal in ((saddle, (0.0, 0.0, 1.0)), (saddle, (0.0, 0.0, -1.0)),
                        (skew, (0.0, 0.0, 1.0)), (-skew, (0.0, 1.0, 0.0))):
        cross, f, w = run(bad, 5, normal=normal)
        assert np.array_equal(np.nonzero(cross)[0], [5])
        assert f == {**clear, "crossing_flanks": True}
        assert len(w) == 1 and w[0].startswith("crossing flanks")
    cross, f, w = run(line, 5)
    assert not cross.any() and not f["crossing_flanks"] and w == []
    # the tolerance does not depend on the tangent basis: a line contact with round-off
    # (eigenvalues 2 and -1.5e-9: det -3e-9 against the bound -1e-9 (4 + ...)) is not
    # crossing however its line lies, eigenvalues 2 and -2.5e-9 (det -5e-9) are
    for delta, crossing in ((1.5e-9, False), (2.5e-9, True)):
        for angle in (0.0, 0.3, np.pi / 4):
            c, s_ = np.cos(angle), np.sin(angle)
            R = np.array([[c, -s_], [s_, c]])
            cross, f, w = run(R @ np.diag([2.0, -delta]) @ R.T, 5)
            assert bool(cross[5]) is crossing and f["crossing_flanks"] is crossing, (delta, angle)
    cross, f, w = run(saddle, 8)                              # not carrying
    assert np.array_equal(np.nonzero(cross)[0], [8]) and not f["crossing_flanks"]
    margin = np.ones(N)
    margin[4] = -0.1                                          # off the flank
    off = _result(margin, *_crossing_case()[1:])
    r = _curved(off, [saddle if i == 4 else good for i in range(N)])
    assert bool(r.flanks_cross[4]) and not r.flags()["crossing_flanks"]


def test_curvature_definiteness_closed_form_and_central_differences():
    """``curvature_definiteness`` = l1 l2/(l1^2 + l2^2) of the principal relative
    curvatures, whatever the sense of the normal and the tangent basis (closed form on
    hand-made B); its derivative w.r.t. the Weingarten map and the normal (the study
    quantity's gradient flows through them) against central differences."""
    from gearjax.tca.result import curvature_definiteness
    base = _result(*_crossing_case())
    for l1, l2 in ((1.0, 2.0), (1.0, -2.0), (3e-4, 0.05), (0.0, 1.0)):
        for angle, normal in ((0.0, (0.0, 0.0, 1.0)), (0.7, (0.0, 0.0, -1.0)),
                              (np.pi / 4, (0.0, 1.0, 0.0))):
            c, s_ = np.cos(angle), np.sin(angle)
            R = np.array([[c, -s_], [s_, c]])
            r = _curved(base, [R @ np.diag([l1, l2]) @ R.T] * N, normal=normal)
            q = np.asarray(curvature_definiteness(r.path))
            np.testing.assert_allclose(q, l1 * l2 / (l1 ** 2 + l2 ** 2), rtol=1e-12, atol=1e-16)
    rng = np.random.default_rng(3)
    W = rng.normal(size=(N, 3, 3))
    n = rng.normal(size=(N, 3))
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    p0 = _curved(base, [np.diag([1.0, 2.0])] * N).path

    def total(W1, normal):
        p = p0._replace(weingarten1=W1, normal=normal)
        return jnp.sum(jnp.arange(1.0, N + 1.0) * curvature_definiteness(p))

    gW, gn = jax.grad(total, argnums=(0, 1))(jnp.asarray(W), jnp.asarray(n))
    h = 1e-6
    for idx in ((0, 0, 0), (3, 1, 2), (7, 2, 1)):
        e = np.zeros_like(W)
        e[idx] = h
        cd = (float(total(W + e, n)) - float(total(W - e, n))) / (2 * h)
        assert float(gW[idx]) == pytest.approx(cd, rel=1e-6, abs=1e-9)
    for idx in ((2, 0), (5, 2)):
        e = np.zeros_like(n)
        e[idx] = h
        cd = (float(total(W, n + e)) - float(total(W, n - e))) / (2 * h)
        assert float(gn[idx]) == pytest.approx(cd, rel=1e-6, abs=1e-9)


def test_min_definiteness_skips_failed_solves_and_paths_without_curvatures():
    """The study quantity ``min_definiteness`` is the smooth minimum over the mask's
    *converged* points: a failed solve with a crossing curvature inside the mask does not
    enter it (bounds of the smooth minimum of equal values: q - T ln n <= . <= q).  A path
    that carries no curvatures has no definiteness (NaN) and no crossing point.  The
    quantity is offered for every family (each path carries its curvatures)."""
    from gearjax.studies.quantities import DEFINITENESS_TEMPERATURE, QUANTITIES
    from gearjax.tca.result import curvature_definiteness
    base = _result(*_crossing_case())
    assert base.path.weingarten1 is None
    assert np.all(np.isnan(np.asarray(curvature_definiteness(base.path))))
    assert not np.asarray(base.flanks_cross).any() and not base.flags()["crossing_flanks"]
    good, saddle = np.diag([1.0, 2.0]), np.diag([1.0, -2.0])       # 0.4 and -0.4
    B_at = [saddle if i == 5 else good for i in range(N)]
    r = _curved(base, B_at)
    conv = np.ones(N, bool)
    conv[5] = False
    failed = _curved(_result(*_crossing_case(), converged=conv), B_at)
    mask = np.ones(N, bool)
    q = QUANTITIES["min_definiteness"]
    T = DEFINITENESS_TEMPERATURE
    assert q.families == ()
    v = float(q.fn(failed, None, jnp.asarray(mask), None))
    assert 0.4 - T * np.log(N - 1) - 1e-12 <= v <= 0.4
    v = float(q.fn(r, None, jnp.asarray(mask), None))                 # converged: it counts
    assert v == pytest.approx(-0.4, abs=1e-12)


def test_tca_json_marks_crossing_flanks_at_on_flank_points_only():
    """``gearjax tca --json``: ``flags.crossing_flanks`` per grid point is ``on_flank &
    flanks_cross`` -- a crossing curvature at an edge point (no surface contact there)
    or off the flank is not marked; ``quality.crossing_flanks`` is the flag."""
    from gearjax.commands.tca import _side_json
    saddle, good = np.diag([1.0, -2.0]), np.diag([1.0, 2.0])
    margin = np.ones(N)
    margin[9] = -0.1                                          # off the flank
    r = _curved(_result(margin, *_crossing_case()[1:]),
                [saddle if i in (4, 6, 9) else good for i in range(N)])
    kind = np.full(N, -1)
    kind[6] = 0                                               # an edge point (pinion toe)
    r = TCAResult(r.path._replace(edge_kind=jnp.asarray(kind)), r.margin, r.multi, {},
                  None, "drive", "test")
    out = _side_json(r)
    assert out["flags"]["crossing_flanks"] == [i == 4 for i in range(N)]
    assert out["flags"]["edge"] == [i == 6 for i in range(N)]
    assert out["quality"]["crossing_flanks"] is True


def test_edge_contact_when_a_pair_leaves_its_flank_at_the_hand_over():
    margin, te, inside, transfer, cr = _crossing_case()
    inside[0, 2:] = False        # pair -1 runs off its flank before the crossing
    te[0, 2:] = np.nan
    transfer = np.array([-0.7, 0.5])
    assert _result(margin, te, inside, transfer, cr).flags()["edge_contact"]


def test_contact_ratio_is_not_found_when_pair_0_leaves_before_it_enters():
    """multi_pair: pair 0 on the flanks at both ends of the grid and off between (edge
    contacts can do that): its first entry follows its last exit -- no contact ratio
    (NaN, flagged), not a negative one; one interval inside the grid gives its length."""
    from gearjax.tca.path import multi_pair
    phi = jnp.linspace(-1.0, 1.0, N)
    path = _result(np.ones(N), np.zeros((3, N)), np.ones((3, N), bool), [0.0, 0.0],
                   1.0).path._replace(phi1=phi)
    two = np.where(np.abs(np.asarray(phi)) < 0.5, -1.0, 1.0)       # on, off, on
    assert np.isnan(float(multi_pair(path, jnp.asarray(two), 4, 10).contact_ratio))
    one = 0.55 - np.abs(np.asarray(phi))                         # on for |phi| <= 0.55
    cr = float(multi_pair(path, jnp.asarray(one), 4, 10).contact_ratio)
    assert cr == pytest.approx(1.1 / (2 * np.pi / 10), rel=1e-12)


def test_no_edge_contact_where_the_te_curves_coincide():
    margin, te, inside, transfer, cr = _crossing_case()
    te[:] = 0.0
    inside[0, 6:] = False          # pair -1 leaves; the transfer lands on its last point
    te[0, 6:] = np.nan
    assert not _result(margin, te, inside, np.array([0.15, 0.5]), cr).flags()["edge_contact"]
    te[1] = 1e-6                   # no longer coincident: an edge hand-over
    assert _result(margin, te, inside, np.array([0.15, 0.5]), cr).flags()["edge_contact"]


def _parabolic_pair(delta, offset, m=8, z1=10, w_pitches=0.55, a=4.9e-4):
    """Pair 0 of a parabolic-TE design on a uniform grid of ``m`` steps a pitch shifted
    by ``offset`` steps: TE_0 = -a (phi - delta)^2 (rad), on the flanks for
    abs(phi) <= w (margin w - abs(phi)); pairs +-1 are pair 0 shifted by a pitch p."""
    from gearjax.tca.path import multi_pair
    p = 2 * np.pi / z1
    n = 4 * m + 1
    phi = (jnp.arange(n) - n // 2 + offset) * (p / m)       # traceable in every argument
    te = -a * (phi - delta) ** 2
    margin = w_pitches * p - jnp.abs(phi)
    z, z3 = jnp.zeros(n), jnp.zeros((n, 3))
    path = ContactPath(phi, z, te, jnp.zeros((n, 2)), jnp.zeros((n, 2)), z3, z3, z3, z3, z,
                       z, z, z, z + 1.0, z + 0.5, z3, z, jnp.ones(n, bool))
    multi = multi_pair(path, margin, m, z1)
    return TCAResult(path, margin, multi, {}, None, "drive", "test"), phi, p


def test_edge_flag_does_not_depend_on_where_the_grid_falls():
    """A parabolic TE design whose curves cross just inside the flank boundary (delta
    0.03 p: crossing at 0.53 p, exit at 0.55 p) hands over smoothly; one whose crossing
    lies beyond it (delta 0.08 p) runs off its flank while still ahead (edge contact).
    The grid check alone cannot tell the first from the second wherever no grid point
    lies between the crossing and the boundary; the flag must give the closed-form
    verdict at every offset of the grid, and the continuous gap at the exit is the
    closed form TE_0(w) - TE_0(w - p) = -a p (2 (w - delta) - p)."""
    from gearjax.tca.multi_pair import transfer_gaps
    a, w = 4.9e-4, 0.55
    uncovered = 0
    for frac, edge in ((0.03, False), (0.08, True)):
        for offset in np.linspace(0.0, 1.0, 8, endpoint=False):
            res, phi, p = _parabolic_pair(frac * 2 * np.pi / 10, offset)
            delta = frac * p
            gap_out = float(transfer_gaps(res.path, res.margin, res.multi)[1])
            closed = -a * p * (2 * (w * p - delta) - p)
            assert gap_out == pytest.approx(closed, rel=1e-9, abs=1e-15), (frac, offset)
            assert float(res.multi.contact_ratio) == pytest.approx(2 * w, rel=1e-9)
            f = res.flags()
            assert f["edge_contact"] is edge, (frac, offset, gap_out / gj.ARCSEC)
            assert not (f["face_end_contact"] or f["tip_contact"] or f["low_contact_ratio"])
            cross = delta + p / 2
            phi = np.asarray(phi)
            uncovered += (not edge) and not np.any((phi > cross) & (phi <= w * p))
    assert uncovered >= 4        # the offsets where the grid alone would flag an edge


def test_edge_contact_when_no_transfer_point_is_found():
    margin, te, inside, _, cr = _crossing_case()
    assert _result(margin, te, inside, np.array([np.nan, 0.5]), cr).flags()["edge_contact"]


def test_low_contact_ratio_and_off_flank_reference_and_failed_solve():
    margin, te, inside, transfer, _ = _crossing_case()
    r = _result(margin, te, inside, transfer, 0.93)
    assert r.flags()["low_contact_ratio"] and "below 1" in r.warnings()[0]
    assert _result(margin, te, inside, transfer, np.nan).flags()["low_contact_ratio"]
    m = margin.copy()
    m[N // 2] = -0.1
    assert not _result(m, te, inside, transfer, 1.6).flags()["reference_on_flank"]
    conv = np.ones(N, bool)
    conv[3] = False                      # a failed solve between on-flank points
    f = _result(margin, te, inside, transfer, 1.6, converged=conv).flags()
    assert not f["converged"]


# -- kinematics at the contact points: involute spur pair, closed form -------------------

@pytest.fixture(scope="module")
def spur():
    pair = gj.involute.InvolutePair.create(Z1, Z2, M, ALPHA)
    des = gj.involute.InvoluteTCA.create(pair, B)
    return pair, {side: gj.run_tca(des, side=side, steps_per_pitch=12) for side in gj.SIDES}


@pytest.mark.parametrize("side", ["drive", "coast"])
def test_spur_kinematics_equal_the_line_of_action_closed_form(spur, side):
    """Spur pair, pinion at 1 rad/s: the contact point runs along the line of action;
    the flanks' velocities across the contact line are ``omega_i rho_i`` (rho_i the
    roll distances from the base-circle tangency points, rho1 + rho2 = a_w sin
    alpha_wt), the effective radius ``rho1 rho2/(rho1 + rho2)``.  Pinion = member 1."""
    pair, res = spur
    r = res[side]
    geo = gj.involute.pair_geometry(pair)
    on = np.asarray(r.on_flank)
    assert on.sum() >= 8
    rho1 = np.sqrt(np.asarray(r.path.radial1) ** 2 - float(geo["rb1"]) ** 2)
    rho2 = float(geo["a_w"]) * math.sin(float(geo["alpha_wt"])) - rho1
    u1, u2 = rho1, (Z1 / Z2) * rho2
    k = r.kinematics
    np.testing.assert_allclose(np.asarray(k.u1)[on], u1[on], rtol=1e-8)
    np.testing.assert_allclose(np.asarray(k.u2)[on], u2[on], rtol=1e-8)
    np.testing.assert_allclose(np.asarray(k.u_e)[on], 0.5 * (u1 + u2)[on], rtol=1e-8)
    np.testing.assert_allclose(np.asarray(k.srr)[on], ((u1 - u2) / (0.5 * (u1 + u2)))[on],
                               rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(np.asarray(k.r_x)[on], (rho1 * rho2 / (rho1 + rho2))[on],
                               rtol=1e-8)
    assert np.all(np.isinf(np.asarray(k.r_y)[on]))          # line contact
    np.testing.assert_allclose(np.asarray(k.gear_ratio)[on], -Z1 / Z2, rtol=1e-10)
    np.testing.assert_allclose(np.asarray(k.u_s_side)[on], 0.0, atol=1e-9)
    # the pitch point: pure rolling
    i = int(np.argmin(np.abs(rho1 - float(geo["rho_P"]))))
    assert abs(float(k.srr[i])) < 0.05


def test_spur_result_quantities_and_flags(spur):
    _, res = spur
    for side, r in res.items():
        assert r.side == side and r.family == "involute"
        assert float(r.ptp) < 1e-3 * gj.ARCSEC                # conjugate: no TE
        geo = gj.involute.pair_geometry(gj.involute.InvolutePair.create(Z1, Z2, M, ALPHA))
        assert abs(float(r.contact_ratio) - float(geo["contact_ratio"])) < 0.02
        f = r.flags()
        assert f["converged"] and f["reference_on_flank"] and not f["low_contact_ratio"]
        # conjugate: the TE curves of consecutive pairs coincide, both pairs touch at
        # the hand-over, no pair carries the load alone at a flank edge
        assert not f["edge_contact"]


def test_continuous_te_ptp_is_exact_for_a_parabolic_te_wherever_the_grid_falls():
    """``te_ptp_arcsec`` of a study (gearjax.studies.quantities.te_ptp_continuous) on the
    parabolic-TE closed form: p-t-p = a (p/2)^2 (top at the vertex, bottom at the
    transfers delta +- p/2), at 8 offsets of the grid and three vertex positions, and
    its derivative in the curvature ``a`` is (p/2)^2.  The sample maximum (or a smooth
    maximum at a small temperature) misses the vertex by up to a (h/2)^2 and its
    derivative jumps as the top passes a grid point; linear interpolation of the bottom
    errs by a h^2/8.  Contact ratios 1.4 (a grid point always lies between each
    crossing and the flank boundary) and 1.1 (at some offsets none does: the grid alone
    would take the hand-over for an edge and fall back to the grid value)."""
    import itertools

    import jax
    from gearjax.studies.quantities import te_ptp_continuous
    p = 2 * np.pi / 10

    @jax.jit
    def value_and_derivative(a, delta, offset, w):
        return jax.value_and_grad(lambda aa: te_ptp_continuous(
            _parabolic_pair(delta, offset, w_pitches=w, a=aa)[0]))(a)

    for frac, w in itertools.product((0.0, 0.013, -0.041), (0.7, 0.55)):
        for offset in np.linspace(0.0, 1.0, 8, endpoint=False):
            a = 4.9e-4
            val, der = value_and_derivative(a, frac * p, offset, w)
            want = a * (p / 2) ** 2 / gj.ARCSEC
            assert float(val) == pytest.approx(want, rel=1e-9), (frac, offset)
            assert float(der) == pytest.approx((p / 2) ** 2 / gj.ARCSEC, rel=1e-9)


def test_handover_definiteness_at_the_continuous_hand_overs_wherever_the_grid_falls():
    """``handover_definiteness`` on the parabolic-TE closed form (hand-overs at delta -+
    p/2) with the curvature definiteness prescribed linear along the path, D(phi) = c
    (phi_e - phi) (B = diag(1, l2), l2 the small root of D (1 + l2^2) = l2): the value is
    the smooth minimum (T = 1e-4) of D at the two hand-overs, at 8 grid offsets, three
    vertex positions and three slopes c; its derivative in delta is -c (both hand-overs
    move with the vertex) and in c the softmin-weighted phi_e - t.  Planted bugs caught:
    the grid's transfer angles instead of the continuous hand-overs (the value moves
    with the offset), one hand-over only (either), the largest instead of the smallest,
    the hand-overs held fixed in the derivative (d/d delta = 0), the interpolation's
    origin a grid step off (``handovers`` itself is checked: delta -+ p/2).  A path
    without curvatures, or without a transfer on the grid, gives NaN."""
    import itertools

    from gearjax.studies.quantities import (DEFINITENESS_TEMPERATURE, QUANTITIES,
                                            handover_definiteness, handovers)
    p = 2 * np.pi / 10
    T = DEFINITENESS_TEMPERATURE
    phi_e = 0.9 * p
    q = QUANTITIES["handover_definiteness"]
    assert q.families == () and not q.path and not q.loaded

    def curved(res, c):
        D = c * (phi_e - res.path.phi1)
        l2 = 2.0 * D / (1.0 + jnp.sqrt(1.0 - 4.0 * D ** 2))      # small root, D = 0 safe
        n = D.shape[0]
        W1 = jnp.zeros((n, 3, 3)).at[:, 0, 0].set(-1.0).at[:, 1, 1].set(-l2)   # B = -W1
        path = res.path._replace(normal=jnp.tile(jnp.array([0.0, 0.0, 1.0]), (n, 1)),
                                 major_dir=jnp.tile(jnp.array([1.0, 0.0, 0.0]), (n, 1)),
                                 weingarten1=W1, weingarten2=jnp.zeros((n, 3, 3)))
        return TCAResult(path, res.margin, res.multi, {}, None, "drive", "test")

    @jax.jit
    def value_and_grads(c, delta, offset):
        return jax.value_and_grad(lambda cc, dd: handover_definiteness(
            curved(_parabolic_pair(dd, offset)[0], cc)), argnums=(0, 1))(c, delta)

    # the definiteness falling along the path (lowest where pair 0 leaves), rising
    # (lowest where it enters) and nearly level (both hand-overs weigh in the minimum)
    for c, frac in itertools.product((0.05, -0.05, 2e-4), (0.0, 0.013, -0.041)):
        delta = frac * p
        t = np.array([delta - p / 2, delta + p / 2])
        D = c * (phi_e - t)
        m = D.min()
        w = np.exp(-(D - m) / T)
        want = m - T * np.log(w.sum())
        w = w / w.sum()
        for offset in np.linspace(0.0, 1.0, 8, endpoint=False):
            val, (dc, dd) = value_and_grads(c, delta, offset)
            assert float(val) == pytest.approx(want, rel=1e-10, abs=1e-14), (frac, offset)
            assert float(dd) == pytest.approx(-c, rel=1e-8), (frac, offset)
            assert float(dc) == pytest.approx(float(w @ (phi_e - t)), rel=1e-8), (frac, offset)
            if c == 0.05 and offset in (0.0, 0.5):      # the hand-overs themselves
                tt, found = handovers(_parabolic_pair(delta, offset)[0])
                assert bool(found)
                np.testing.assert_allclose(np.asarray(tt), t, rtol=0, atol=1e-12 * p)
    assert np.isnan(float(handover_definiteness(_parabolic_pair(0.0, 0.3)[0])))
    # no transfer found on the grid (NaN transfer angle): NaN, not the value at angle 0
    res = curved(_parabolic_pair(0.0, 0.3)[0], 0.05)
    assert np.isfinite(float(handover_definiteness(res)))
    for transfer in ([np.nan, 0.3], [-0.3, np.nan]):
        res_nt = TCAResult(res.path, res.margin,
                           res.multi._replace(transfer_phi1=jnp.asarray(transfer)), {}, None,
                           "drive", "test")
        assert np.isnan(float(handover_definiteness(res_nt))), transfer
