"""Gradients of μ and of mesh efficiency against central finite differences, across
regimes, at pure rolling and at the film-formula blend boundaries."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.tribology.friction import Surface, friction_point_traced
from gearjax.tribology.losses import mesh_losses_traced
from gearjax.tribology.lubricant import Oil

NAMES = ["F", "u_e", "u_s", "Rx", "Ry", "eta0", "sigma", "f_c"]
E_PRIME = 226374.0


def mu_of(x):
    F, ue, us, Rx, Ry, eta0, sigma, fc = x
    oil = Oil(eta0, jnp.asarray(0.596), jnp.asarray(5.0), jnp.asarray(880.0))
    surf = Surface(sigma, jnp.asarray(1e4), jnp.asarray(1e-2), fc, jnp.asarray(1.0))
    return friction_point_traced(F, ue, us, Rx, Ry, oil, surf, E_PRIME).mu


_mu = jax.jit(mu_of)
_grad = jax.jit(jax.grad(mu_of))

# (label, point): full film, mixed, boundary-dominated, pure rolling, film blend ends
CASES = {
    "full film": [1000.0, 15000.0, 3000.0, 10.0, 100.0, 0.088, 1e-4, 0.1],
    "mixed": [1000.0, 3000.0, 600.0, 10.0, 100.0, 0.088, 6e-4, 0.1],
    "boundary": [1000.0, 300.0, 60.0, 10.0, 100.0, 0.088, 2.5e-3, 0.1],
    "pure rolling": [1000.0, 3000.0, 0.0, 10.0, 100.0, 0.088, 6e-4, 0.1],
    "near rolling": [1000.0, 3000.0, 0.3, 10.0, 100.0, 0.088, 6e-4, 0.1],
    "regime edge": [1000.0, 6500.0, 1300.0, 10.0, 100.0, 0.088, 6e-4, 0.1],
}


def _fd(x, i, rel=1e-5):
    x = np.asarray(x, float)
    # at u_s = 0 an absolute step: 1e-6 mm/s would leave an O(h²) truncation error of
    # 7.7e-7 relative (the Eyring/tanh curvature at high viscosity), 1e-9 leaves 7.7e-13
    h = rel * abs(x[i]) if x[i] != 0 else 1e-9
    xp, xm = x.copy(), x.copy()
    xp[i] += h
    xm[i] -= h
    return (float(_mu(jnp.asarray(xp))) - float(_mu(jnp.asarray(xm)))) / (2 * h)


@pytest.mark.parametrize("case", list(CASES))
def test_mu_gradient_matches_central_differences(case):
    x = jnp.asarray(CASES[case])
    g = np.asarray(_grad(x))
    assert np.all(np.isfinite(g))
    mu = float(_mu(x))
    for i, name in enumerate(NAMES):
        fd = _fd(x, i)
        # relative agreement 1e-6 on each derivative, measured on the scale of μ/x_i
        scale = max(abs(fd), 1e-3 * mu / abs(float(x[i]) if x[i] != 0 else 1.0))
        assert abs(g[i] - fd) <= 1e-6 * scale, (case, name, g[i], fd)


def test_gradient_at_regime_classes_and_blend_edges_is_finite():
    # ellipticity exactly at the film-blend ends k = 8 and k = 64 (Ry/Rx chosen for it)
    from gearjax.contact import hertz_point
    from scipy.optimize import brentq
    for k_target in (8.0, 64.0):
        ratio = brentq(lambda r: float(hertz_point(1000.0, 10.0, 10.0 * r, E_PRIME).k) - k_target,
                       2.0, 1e5, xtol=1e-12)
        x = jnp.asarray([1000.0, 3000.0, 600.0, 10.0, 10.0 * ratio, 0.088, 6e-4, 0.1])
        g = np.asarray(_grad(x))
        assert np.all(np.isfinite(g))
        fd = _fd(np.asarray(x), 4, rel=1e-6)
        assert abs(g[4] - fd) <= 1e-5 * max(abs(fd), 1e-12)


def _mesh_eff(theta):
    eta0, sigma, fc, load_scale, speed_scale = theta
    F = load_scale * jnp.array([[600.0, 400.0], [1000.0, 0.0], [1000.0, 0.0], [450.0, 550.0]])
    us = speed_scale * jnp.array([[-900.0, 1500.0], [0.0, 0.0], [500.0, 0.0], [900.0, -1400.0]])
    ue = speed_scale * jnp.array([[4000.0, 4500.0], [4300.0, 1.0], [4400.0, 1.0], [4600.0, 4100.0]])
    Rx = jnp.array([[6.0, 9.0], [8.0, 1.0], [9.0, 1.0], [10.0, 7.0]])
    oil = Oil(eta0, jnp.asarray(0.596), jnp.asarray(5.0), jnp.asarray(880.0))
    surf = Surface(sigma, jnp.asarray(1e4), jnp.asarray(1e-2), fc, jnp.asarray(1.0))
    p_in = 18000.0 * load_scale * speed_scale
    out = mesh_losses_traced(F, us, ue, Rx, 20.0 * Rx, oil, surf, p_in)
    return jnp.concatenate([out.efficiency, out.mean_efficiency[None]])


def test_efficiency_gradients_match_central_differences():
    theta0 = np.array([0.088, 6e-4, 0.1, 1.0, 1.0])
    f = jax.jit(_mesh_eff)
    J = np.asarray(jax.jit(jax.jacfwd(_mesh_eff))(jnp.asarray(theta0)))
    Jr = np.asarray(jax.jit(jax.jacrev(_mesh_eff))(jnp.asarray(theta0)))
    assert np.all(np.isfinite(J))
    np.testing.assert_allclose(J, Jr, rtol=1e-10, atol=1e-15)
    for i in range(5):
        h = 1e-5 * theta0[i]
        tp, tm = theta0.copy(), theta0.copy()
        tp[i] += h
        tm[i] -= h
        fd = (np.asarray(f(jnp.asarray(tp))) - np.asarray(f(jnp.asarray(tm)))) / (2 * h)
        # efficiencies are ~0.99: compare derivatives of the loss 1 - η on its own scale
        np.testing.assert_allclose(J[:, i], fd, rtol=1e-6, atol=1e-9 * np.abs(fd).max())
    # pure-rolling position (index 1) has zero loss and zero sensitivity
    assert J[1].tolist() == [0.0] * 5


def test_public_entry_points_are_jit_safe_and_match_the_concrete_call():
    """``friction_coefficient`` and ``mesh_losses`` are one function each for concrete and
    traced use: under ``jax.jit`` they give the concrete call's numbers (which went
    through validation and the padded kernel), under ``jax.grad`` the kernel's gradient;
    a concrete call still refuses bad input."""
    from gearjax.tribology import friction_coefficient, get_oil, make_surface, mesh_losses

    oil, surf = get_oil("mineral_vg100"), make_surface(0.4, f_c=0.1)
    args = (np.array([800.0, 1200.0]), np.array([3000.0, 5000.0]), np.array([600.0, 900.0]),
            np.array([8.0, 12.0]), np.array([80.0, 150.0]))
    mu_c = np.asarray(friction_coefficient(*args, oil, surf).mu)
    mu_j = np.asarray(jax.jit(lambda *a: friction_coefficient(*a, oil, surf).mu)(*args))
    np.testing.assert_allclose(mu_j, mu_c, rtol=1e-12)
    g = jax.grad(lambda F: jnp.sum(friction_coefficient(F, *args[1:], oil, surf).mu))(args[0])
    h = 1e-3
    fd = [(np.sum(friction_coefficient(args[0] + h * e, *args[1:], oil, surf).mu)
           - np.sum(friction_coefficient(args[0] - h * e, *args[1:], oil, surf).mu)) / (2 * h)
          for e in np.eye(2)]
    np.testing.assert_allclose(np.asarray(g), fd, rtol=1e-5)
    with pytest.raises(ValueError, match="load = -1 N"):
        friction_coefficient(-1.0, 3000.0, 600.0, 8.0, 80.0, oil, surf)
    # traced only in the oil or the surface (a study of the lubricant or roughness)
    mu_s = jax.jit(lambda s: friction_coefficient(*args, oil, s).mu)(surf)
    mu_o = jax.jit(lambda o: friction_coefficient(*args, o, surf).mu)(oil)
    np.testing.assert_allclose(np.asarray(mu_s), mu_c, rtol=1e-12)
    np.testing.assert_allclose(np.asarray(mu_o), mu_c, rtol=1e-12)
    F = np.array([[600.0, 400.0], [1000.0, 0.0]])
    us, ue = np.array([[-900.0, 1500.0], [500.0, 0.0]]), np.array([[4000.0, 4500.0], [4400.0, 1.0]])
    Rx = np.array([[6.0, 9.0], [9.0, 1.0]])
    eta_c = float(mesh_losses(F, us, ue, Rx, 20 * Rx, oil, surf, 9000.0).mean_efficiency)
    eta_j = float(jax.jit(lambda F: mesh_losses(F, us, ue, Rx, 20 * Rx, oil, surf,
                                                  9000.0).mean_efficiency)(F))
    assert abs(eta_j - eta_c) < 1e-12 and 0.9 < eta_c < 1.0
    for bad in (0.0, -5.0, float("nan")):     # refused before any work, naming the input
        with pytest.raises(ValueError, match="power_in"):
            mesh_losses(F, us, ue, Rx, 20 * Rx, oil, surf, bad)
