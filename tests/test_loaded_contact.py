"""Load sharing between tooth pairs (gearjax.loading.loaded_contact) against closed forms.

References: equal pairs share equally (textbook double contact); linear springs in
parallel with a gap; the Hertz point-contact approach delta = c F^(2/3) alone;
equilibrium sum l1 F = T1; implicit derivatives against central differences.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.contact import hertz_exact
from gearjax.loading.loaded_contact import (BALANCE_TOL, force_from_approach, pair_arrays,
                                            share_torque)

T1 = 2.0e5          # N mm
L1, L2 = 30.0, 60.0  # lever arms, mm


def _solve(te, act, q, c, drive=True, l1=L1, l2=L2):
    K, M = te.shape
    return share_torque(jnp.asarray(te), jnp.asarray(act), jnp.full((K, M), l1),
                        jnp.full((K, M), l2), jnp.asarray(q), jnp.asarray(c), T1, drive)


def test_force_from_approach_limits_and_derivative():
    w = jnp.array([-1e-3, 0.0, 2e-3, 1e-2])
    # linear spring alone: F = w/q
    F = force_from_approach(w, 1e-5, 0.0)
    np.testing.assert_allclose(F, [0.0, 0.0, 200.0, 1000.0], rtol=1e-13)
    # Hertz alone: F = (w/c)^(3/2)
    c = 3e-4
    F = force_from_approach(w, 1e-14, c)
    np.testing.assert_allclose(F[2:], (w[2:] / c) ** 1.5, rtol=1e-8)
    # both: the root satisfies q F + c F^(2/3) = w
    q = 2e-6
    F = force_from_approach(w[2:], q, c)
    np.testing.assert_allclose(q * F + c * F ** (2 / 3), w[2:], rtol=1e-13)
    # implicit derivatives against central differences in w, q, c
    for i, x in enumerate((2e-3, q, c)):
        args = [2e-3, q, c]

        def f(v, i=i):
            a = list(args)
            a[i] = v
            return force_from_approach(*a)

        h = 1e-6 * x
        fd = (f(x + h) - f(x - h)) / (2 * h)
        np.testing.assert_allclose(jax.grad(f)(x), fd, rtol=1e-7)


def test_equal_pairs_share_equally_and_single_pair_carries_all():
    # positions: double contact (equal TE), single contact (pair 1 alone)
    te = np.array([[0.0, 0.0], [0.0, 0.0]])
    act = np.array([[True, False], [True, True]])
    q = np.full((2, 2), 1e-5)
    env, y, F, w, bal, conv = _solve(te, act, q, np.zeros((2, 2)))
    assert np.all(conv) and np.all(bal <= BALANCE_TOL)
    np.testing.assert_allclose(F[:, 0] * L1 / T1, [0.5, 0.5], rtol=1e-12)
    np.testing.assert_allclose(F[:, 1] * L1 / T1, [0.0, 1.0], rtol=1e-12)
    # loaded deflection: springs in parallel (double) and one spring (single)
    Ft = T1 / L1
    np.testing.assert_allclose(y, [q[0, 0] * Ft / 2 / L2, q[0, 0] * Ft / L2], rtol=1e-12)


@pytest.mark.parametrize("drive", [True, False])
def test_gap_closed_by_the_load_linear_springs(drive):
    """Pair 0 trails the leading pair 1 by a gap g: it takes load only beyond it."""
    s = 1.0 if drive else -1.0
    q0, q1 = 1e-5, 2e-5
    g_small, g_large = 1e-5, 1e-2         # rad (gap w = L2 g: 0.6 um and 0.6 mm)
    te = np.array([[-s * g_small, -s * g_large], [0.0, 0.0]])
    act = np.ones((2, 2), bool)
    q = np.array([[q0, q0], [q1, q1]])
    env, y, F, w, bal, conv = _solve(te, act, q, np.zeros((2, 2)), drive=drive)
    assert np.all(conv)
    k0, k1 = L2 / q0, L2 / q1                 # N per rad of gear fall-back
    # closed form with both in contact: k1 y + k0 (y - g) = T1/L1
    y_both = (T1 / L1 + k0 * g_small) / (k0 + k1)
    assert y_both > g_small
    np.testing.assert_allclose(y[0], y_both, rtol=1e-12)
    np.testing.assert_allclose(F[0, 0], k0 * (y_both - g_small), rtol=1e-10)
    # large gap: the leading pair alone, the other unloaded with a gap left
    np.testing.assert_allclose(y[1], T1 / L1 / k1, rtol=1e-12)
    assert F[0, 1] == 0.0 and w[0, 1] < 0.0
    # loaded TE lies behind the envelope by y on the side's sense
    np.testing.assert_allclose(env, [0.0, 0.0], atol=0)


def test_hertz_point_contact_alone_against_hertz_approach():
    Rx, Ry, Ep = 12.0, 400.0, 226374.0
    c = float(hertz_exact(1.0, Rx, Ry, Ep).approach)
    te = np.zeros((1, 1))
    env, y, F, w, bal, conv = _solve(te, np.ones((1, 1), bool), np.full((1, 1), 1e-14),
                                     np.full((1, 1), c))
    Ft = T1 / L1
    # delta(F) of the Hertz solution at the full load, independently
    delta = float(hertz_exact(Ft, Rx, Ry, Ep).approach)
    np.testing.assert_allclose(w[0, 0], delta, rtol=1e-8)
    np.testing.assert_allclose(F[0, 0], Ft, rtol=1e-12)


def test_no_active_pair_is_not_converged_and_gives_no_load():
    env, y, F, w, bal, conv = _solve(np.zeros((2, 1)), np.zeros((2, 1), bool),
                                     np.full((2, 1), 1e-5), np.zeros((2, 1)))
    assert not bool(conv[0]) and np.all(F == 0.0) and np.isnan(y[0])


def test_share_gradients_against_central_differences():
    te = np.array([[-2e-6, -4e-6], [0.0, 0.0], [-1e-6, -8e-6]])
    act = np.ones((3, 2), bool)
    c = np.full((3, 2), 2e-4)

    def share(qs, T):
        q = jnp.array([[1e-5, 1e-5], [2e-5, 2e-5], [1.5e-5, 1.5e-5]]) * qs
        out = share_torque(jnp.asarray(te), jnp.asarray(act), jnp.full((3, 2), L1),
                           jnp.full((3, 2), L2), q, jnp.asarray(c), T, True)
        return out[2][0, 1] * L1 / T + out[1][0]

    for argnum, x, h in ((0, 1.0, 1e-5), (1, T1, 20.0)):
        def f(v, argnum=argnum):
            return share(v, T1) if argnum == 0 else share(1.0, v)
        fd = (f(x + h) - f(x - h)) / (2 * h)
        np.testing.assert_allclose(jax.grad(f)(x), fd, rtol=1e-6)


def test_pair_arrays_shift_by_whole_pitches():
    a = jnp.arange(10.0)
    out = pair_arrays(a, 3, 3, -1.0, np.array([4, 5]))
    # pair k at window index i is pair 0 at i - 3k
    np.testing.assert_array_equal(out, [[7.0, 8.0], [4.0, 5.0], [1.0, 2.0]])
    out = pair_arrays(a, 3, 3, -1.0, np.array([0, 9]))
    np.testing.assert_array_equal(out, [[3.0, -1.0], [0.0, 9.0], [-1.0, 6.0]])
