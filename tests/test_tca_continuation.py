"""The continuation of gearjax.tca.path (one lax.scan over the pinion angles): every solve
starts from the linear predictor of the two previous points of the path (the first
from the tangent at the reference); a failed step keeps the previous solution and
drops the predictor for the next step."""

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.tca.path import _solve_grid, path_tangent


def _F(x, phi):
    """Root x = (phi, 2 phi) exactly; nonlinear, so a start off the root costs several
    Newton steps, and a start on it (the linear predictor of a linear path) costs one."""
    d = x - jnp.stack([phi, 2.0 * phi])
    return d ** 3 + d


def _G(x, phi):
    """Root on the unit circle: x = (cos phi, sin phi), tangent (-sin phi, cos phi)."""
    return jnp.stack([x[0] ** 2 + x[1] ** 2 - 1.0, x[0] * jnp.sin(phi) - x[1] * jnp.cos(phi)])


def test_path_tangent_closed_forms():
    np.testing.assert_allclose(np.asarray(path_tangent(_F, jnp.array([0.3, 0.6]), 0.3)),
                               [1.0, 2.0], rtol=0, atol=1e-14)
    phi = 0.7
    x = jnp.array([np.cos(phi), np.sin(phi)])
    np.testing.assert_allclose(np.asarray(path_tangent(_G, x, jnp.asarray(phi))),
                               [-np.sin(phi), np.cos(phi)], rtol=0, atol=1e-14)


def test_linear_predictor_starts_on_a_linear_path():
    phis = jnp.linspace(0.25, 2.0, 8)
    run = jax.jit(lambda x1, x2, p: _solve_grid(_F, x1, x2, p, 1e-12, 30))
    # first step from the previous solution alone (no predictor): several Newton steps
    # (0.25 off), then exact linear predictions (one step each)
    sols = run(jnp.zeros(2), jnp.zeros(2), phis)
    np.testing.assert_allclose(np.asarray(sols.x), np.stack([phis, 2 * phis], 1), atol=1e-12)
    steps = np.asarray(sols.steps)
    assert bool(np.all(np.asarray(sols.converged)))
    assert steps[0] >= 3
    np.testing.assert_array_equal(steps[1:], 1)
    # a tangent-built previous point makes the first prediction exact as well
    behind = -0.25 * path_tangent(_F, jnp.zeros(2), 0.0)
    np.testing.assert_array_equal(np.asarray(run(jnp.zeros(2), behind, phis).steps), 1)


def test_failed_step_restarts_from_the_last_solution():
    """max_steps 2 from a start 0.25 off fails; every later start is the last solution
    (0.25 k off, so the error of the unconverged iterate grows), never an
    extrapolation from a stale pair."""
    phis = jnp.linspace(0.25, 2.0, 8)
    sols = jax.jit(lambda x1, x2, p: _solve_grid(_F, x1, x2, p, 1e-12, 2))(
        jnp.zeros(2), jnp.zeros(2), phis)
    assert not np.asarray(sols.converged).any()
    err = np.abs(np.asarray(sols.x)[:, 0] - np.asarray(phis))
    assert np.all(np.diff(err) > 0)
