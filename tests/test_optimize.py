"""gearjax.optimize: known minima of closed-form objectives (independent of the code)."""

import warnings

import jax.numpy as jnp
import numpy as np
import optax
import pytest

from gearjax import optimize


def quad(x):
    # minimum at (1, -2, 0.5), value 3
    c = jnp.array([1.0, -2.0, 0.5])
    w = jnp.array([1.0, 4.0, 0.25])
    return jnp.sum(w * (x - c) ** 2) + 3.0


def test_optax_unbounded_quadratic():
    res = optimize.minimize_optax(quad, jnp.zeros(3), optimizer=optax.adam(0.05), steps=600)
    np.testing.assert_allclose(np.asarray(res.x), [1.0, -2.0, 0.5], atol=1e-4)
    assert float(res.value) == pytest.approx(3.0, abs=1e-7)
    assert res.history.shape == (600,) and res.x_history.shape == (600, 3)
    assert float(res.history[0]) == pytest.approx(float(quad(jnp.zeros(3))))


def test_optax_box_projection_and_forward_mode():
    # box x2 >= -1 is active: constrained minimum (1, -1, 0.5), value 3 + 4
    lo = jnp.array([-5.0, -1.0, -5.0])
    res = optimize.minimize_optax(quad, jnp.zeros(3), optimizer=optax.adam(0.05), steps=600,
                                  lower=lo, upper=5.0, mode="fwd")
    np.testing.assert_allclose(np.asarray(res.x), [1.0, -1.0, 0.5], atol=1e-4)
    assert float(res.value) == pytest.approx(7.0, abs=1e-6)
    assert float(res.grad_norm) < 1e-3
    assert np.all(np.asarray(res.x_history)[:, 1] >= -1.0)


def test_lbfgsb_rosenbrock_bounded():
    def rosen(x):
        return (1 - x[0]) ** 2 + 100 * (x[1] - x[0] ** 2) ** 2
    with warnings.catch_warnings():
        warnings.simplefilter("error", DeprecationWarning)   # filtered inside optimize
        res = optimize.minimize_lbfgsb(rosen, jnp.array([-1.2, 1.0]), -2.0, 2.0, maxiter=200)
    np.testing.assert_allclose(np.asarray(res.x), [1.0, 1.0], atol=1e-6)
    # with x1 <= 0.5 the minimum is on the bound: x = (0.5, 0.25), f = 0.25
    res = optimize.minimize_lbfgsb(rosen, jnp.array([-1.2, 1.0]), -2.0,
                                   jnp.array([0.5, 2.0]), maxiter=200)
    np.testing.assert_allclose(np.asarray(res.x), [0.5, 0.25], atol=1e-6)
    assert float(res.value) == pytest.approx(0.25, abs=1e-10)


def test_bad_arguments():
    with pytest.raises(ValueError, match="steps"):
        optimize.minimize_optax(quad, jnp.zeros(3), steps=0)
    with pytest.raises(ValueError, match="mode"):
        optimize.value_and_grad(quad, "sideways")
