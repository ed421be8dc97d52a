"""The fixed-step friction kernel against an independent per-point SciPy route over a
broad sweep (boundary / mixed / full film, ellipticity 1.1–35, loads 10–1e4 N, speeds
0.1–30 m/s), central-difference gradients on part of the sweep, and the convergence
flags of the fixed-step solves.

The reference (``_reference_mu``) types the model of docs/friction.md with SciPy:
Johnson's ellipticity equation by ``brentq`` with ``ellipkm1``/``ellipe``, the
Hamrock–Dowson / Pan–Hamrock films and their blend, the Greenwood–Tripp F_5/2 by
adaptive ``quad``, the load sharing by ``brentq`` on the asperity share, the Roelands
viscosity and the Ree–Eyring shear integrated by adaptive ``quad`` over the ellipse.
No gearjax code is used.
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq
from scipy.special import ellipe, ellipkm1
from scipy.stats import norm

from gearjax.tribology.friction import Surface, friction_traced
from gearjax.tribology.lubricant import Oil

P_R = 1.0 / 5.1e-3      # Roelands reference pressure, MPa
ETA0, Z, TAU0 = 0.088, 0.596, 5.0
DENS, BETA, FC, VSLIP = 1e4, 1e-2, 0.1, 1.0


def _reference_mu(F, ue, us, Rx, Ry, Ep, sigma, eta0=ETA0, z=Z, tau0=TAU0):
    """(μ, φ, h_c) of one contact by SciPy (F N, speeds mm/s, lengths mm, E' MPa)."""
    r = Ry / Rx

    def g(kp):  # Johnson's ellipticity equation in k' = b/a
        K, E = ellipkm1(kp * kp), ellipe(1 - kp * kp)
        return (E / kp ** 2 - K) / (K - E) - r

    kp = brentq(g, 1e-9, 1 - 1e-9, xtol=1e-16, rtol=1e-15)
    E = ellipe(1 - kp * kp)
    R = Rx * Ry / (Rx + Ry)
    b = (6 * E * kp * F * R / (math.pi * Ep)) ** (1 / 3)
    a, k = b / kp, 1 / kp
    pmax = 1.5 * F / (math.pi * a * b)
    alpha = z * (math.log(eta0) + 9.67) / P_R
    KGT = 16 * math.sqrt(2) * math.pi / 15 * (DENS * BETA * sigma) ** 2 * math.sqrt(sigma / BETA)

    def film(g1):  # Johnson-Greenwood-Poon: F/γ1 on E'/γ1; Hamrock-Dowson / Pan-Hamrock blend
        Fe, Ee = F / g1, Ep / g1
        U = eta0 * 1e-6 * ue / (Ee * Rx)
        hp = Rx * 2.69 * U ** 0.67 * (alpha * Ee) ** 0.53 * (Fe / (Ee * Rx * Rx)) ** -0.067 * (
            1 - 0.61 * math.exp(-0.73 * k))
        hl = Rx * 2.922 * (0.75 * Fe / a / (Ee * Rx)) ** -0.166 * U ** 0.692 * (alpha * Ee) ** 0.47
        x = min(max(math.log(k / 8) / math.log(8), 0), 1)
        s = x * x * (3 - 2 * x)
        return hp ** (1 - s) * hl ** s

    def logF52(lam):
        sc = 1.0 / (1.0 + lam)   # t = sc u: the integrand decays on the scale 1/(1 + λ)
        i = quad(lambda u: (sc * u) ** 2.5 * math.exp(-lam * sc * u - 0.5 * (sc * u) ** 2) * sc,
                 0, np.inf, epsabs=0, epsrel=1e-13, limit=200)[0]
        return norm.logpdf(lam) + math.log(i)

    def res(sv):  # ln φ - ln(π a b K E'/F) - ln F_5/2(h_c/σ), φ = sigmoid(sv), γ1 = 1 + e^sv
        return (-np.logaddexp(0.0, -sv) - math.log(math.pi * a * b * KGT * Ep / F)
                - logF52(film(1.0 + math.exp(sv)) / sigma))

    sv = brentq(res, -700, 60, xtol=1e-13, rtol=1e-15)
    phi = 1 / (1 + math.exp(-sv))
    hc = film(1.0 + math.exp(sv))

    def tau_s(s):
        p = (1 - phi) * pmax * s
        eta = eta0 * math.exp((math.log(eta0) + 9.67) * ((1 + p / P_R) ** z - 1))
        return tau0 * math.asinh(eta * 1e-6 * us / (hc * tau0)) * s

    Ft = 2 * math.pi * a * b * quad(tau_s, 0, 1, epsabs=0, epsrel=1e-13, limit=200)[0]
    return FC * phi * math.tanh(us / VSLIP) + Ft / F, phi, hc


def _sweep(n=30):
    rng = np.random.default_rng(2024)
    F = 10 ** rng.uniform(1, 4, n)
    ue = 10 ** rng.uniform(2, math.log10(3e4), n)
    us = ue * rng.uniform(0.0, 1.0, n)
    Rx = 10 ** rng.uniform(math.log10(3), math.log10(50), n)
    Ry = Rx * 10 ** rng.uniform(math.log10(1.2), math.log10(400), n)
    sigma = 10 ** rng.uniform(-4, math.log10(2e-3), n)   # 0.1 .. 2 µm
    return F, ue, us, Rx, Ry, sigma


def _mu(x, sigma, E_prime=226374.0, eta0=ETA0):
    F, ue, us, Rx, Ry = x
    oil = Oil(jnp.asarray(eta0), jnp.asarray(Z), jnp.asarray(TAU0), jnp.asarray(880.0))
    surf = Surface(jnp.asarray(sigma), jnp.asarray(DENS), jnp.asarray(BETA), jnp.asarray(FC),
                   jnp.asarray(VSLIP))
    return friction_traced(F, ue, us, Rx, Ry, oil, surf, E_prime)


_fr = jax.jit(_mu)


def _mu_of(x):
    """μ of x = (F, u_e, u_s, Rx, Ry, σ, η0, E')."""
    return _mu(x[:5], x[5], x[7], x[6]).mu


_mu_j = jax.jit(_mu_of)
_grad_j = jax.jit(jax.grad(_mu_of))


def test_kernel_matches_scipy_reference_over_sweep():
    """30 points; μ within 1e-8 relative (measured 8e-10: the 48-node Gauss–Legendre
    shear integral against adaptive quad), φ within 1e-11 (relative to max(φ, 1e-6)),
    h_c within 1e-11 (measured 1e-14; the reference's brentq/quad tolerances are 1e-13)."""
    F, ue, us, Rx, Ry, sigma = _sweep()
    out = _fr(jnp.asarray([F, ue, us, Rx, Ry]), jnp.asarray(sigma))
    assert bool(jnp.all(out.converged))
    ref = np.array([_reference_mu(*v, 226374.0, sg) for *v, sg in zip(F, ue, us, Rx, Ry, sigma)])
    mu, phi, hc = (np.asarray(v) for v in (out.mu, out.phi, out.h_c))
    # the sweep spans the regimes and the film formulas
    regimes = set(np.asarray(out.regime).tolist())
    assert regimes == {0, 1, 2}, regimes
    k = np.asarray(out.k)
    assert k.min() < 1.5 and k.max() > 30.0
    np.testing.assert_allclose(mu, ref[:, 0], rtol=1e-8)
    assert np.all(np.abs(phi - ref[:, 1]) <= 1e-11 * np.maximum(ref[:, 1], 1e-6))
    np.testing.assert_allclose(hc, ref[:, 2], rtol=1e-11)


@pytest.mark.parametrize("i", [0, 3, 7, 12, 21])
def test_kernel_gradient_matches_central_differences(i):
    """d μ / d(F, u_e, u_s, Rx, Ry, σ, η0, E') at sweep points, reverse mode against
    central differences (relative step 1e-5; agreement 1e-6 of max(|fd|, 1e-3 μ/x))."""
    F, ue, us, Rx, Ry, sigma = _sweep()
    x0 = np.array([F[i], ue[i], us[i], Rx[i], Ry[i], sigma[i], ETA0, 226374.0])
    fj = _mu_j
    g = np.asarray(_grad_j(jnp.asarray(x0)))
    assert np.all(np.isfinite(g))
    mu = float(fj(jnp.asarray(x0)))
    for j in range(8):
        h = 1e-5 * abs(x0[j])
        xp, xm = x0.copy(), x0.copy()
        xp[j] += h
        xm[j] -= h
        fd = (float(fj(jnp.asarray(xp))) - float(fj(jnp.asarray(xm)))) / (2 * h)
        scale = max(abs(fd), 1e-3 * mu / abs(x0[j]))
        assert abs(g[j] - fd) <= 1e-6 * scale, (i, j, g[j], fd)


def test_fixed_step_solves_converge_over_their_ranges():
    """Hertz: every ln(Ry/Rx) in [-34, 34] (the validated range); load sharing: a grid
    from full film (σ = 1 nm, φ ~ 0) to deep boundary (σ = 10 µm, slow, light) at
    ellipticities 1–1000.  Every point converged (residual recomputed after the fixed
    steps), φ in [0, 1]; the load-sharing residual is zero to its tolerance."""
    from gearjax.contact import hertz_exact
    from gearjax.tribology.asperity import load_sharing_traced
    lr = jnp.linspace(-34.0, 34.0, 2001)
    hz = jax.jit(hertz_exact)(1000.0, 10.0, 10.0 * jnp.exp(lr), 226374.0)
    assert bool(jnp.all(hz.converged))
    # odd in ln(Ry/Rx): k(Ry/Rx) k(Rx/Ry) = 1
    np.testing.assert_allclose(np.log(np.asarray(hz.k)) + np.log(np.asarray(hz.k))[::-1], 0.0,
                               atol=1e-12)
    g = np.meshgrid(np.logspace(1, 5, 5), np.logspace(1, 5, 5), np.logspace(-6, -2, 9),
                    np.array([1.0, 10.0, 1e3, 1e6]), indexing="ij")
    F, ue, sig, ratio = (jnp.asarray(v.ravel()) for v in g)
    hz = hertz_exact(F, 10.0, 10.0 * ratio, 226374.0)
    alpha = Z * (math.log(ETA0) + 9.67) / P_R
    ls = jax.jit(load_sharing_traced, static_argnums=12)(
        F, 10.0, hz.k, hz.a, hz.b, ue, ETA0, alpha, 226374.0, sig, DENS, BETA, "auto")
    assert bool(jnp.all(ls.converged)), int(jnp.sum(~ls.converged))
    phi = np.asarray(ls.phi)
    assert phi.min() < 1e-30 and phi.max() > 1 - 1e-12 and np.all((phi >= 0) & (phi <= 1))
    assert float(jnp.max(jnp.abs(ls.residual))) <= 1e-11


def test_convergence_flags_are_computed_not_assumed(monkeypatch):
    """With too few fixed steps the recomputed residuals exceed the tolerances and the
    flags say so (the flags are not set from the iteration count)."""
    import gearjax.contact as contact
    import gearjax.tribology.asperity as asperity
    F, ue, us, Rx, Ry, sigma = _sweep()
    x = jnp.asarray([F, ue, us, Rx, Ry])
    assert bool(jnp.all(_mu(x, jnp.asarray(sigma)).converged))
    monkeypatch.setattr(contact, "_T_STEPS", 0)
    hz = contact.hertz_exact(jnp.asarray(F), jnp.asarray(Rx), jnp.asarray(Ry), 226374.0)
    assert not bool(jnp.any(hz.converged))
    monkeypatch.setattr(contact, "_T_STEPS", 3)
    monkeypatch.setattr(asperity, "_LS_STEPS", 0)
    out = _mu(x, jnp.asarray(sigma))
    assert not bool(jnp.all(out.converged))


@pytest.mark.parametrize("model", ["roelands", "barus"])
def test_shear_integral_matches_graded_composite_rule(model):
    """The 16-node sinh-mapped shear rule against a graded composite Gauss rule
    (NumPy: 20 nodes on each of 300 panels geometrically refined towards s = 0, split
    at the viscosity cap) over p_f = 0..4 GPa, Eyring edge arguments X0 = 1e-10..1e5,
    η0 = 3e-3..3 Pa·s, z = 0.3..1 (far beyond gear practice; the former fixed 48-node
    rule in s is off by up to 1e-4 here)."""
    from gearjax.tribology.friction import shear_integral
    rng = np.random.default_rng(7)
    n = 1500
    pf = np.concatenate([rng.uniform(0, 4000, n // 2), 10 ** rng.uniform(-1, 3.6, n - n // 2)])
    X0 = 10 ** rng.uniform(-10, 5, n)
    eta0 = 10 ** rng.uniform(-2.5, 0.5, n)
    z = rng.uniform(0.3, 1.0, n)
    A = np.log(eta0) + 9.67
    oil = Oil(jnp.asarray(eta0), jnp.asarray(z), jnp.asarray(TAU0), jnp.asarray(880.0))

    def L(s):  # ln(eta/eta0), uncapped
        if model == "roelands":
            return A[:, None] * ((1 + pf[:, None] * s / P_R) ** z[:, None] - 1)
        return (z * A / P_R)[:, None] * pf[:, None] * s

    one = np.ones(1)
    h = np.minimum(1.0, [brentq(lambda s, i=i: L(s * one)[i, 0] - 150.0, 0, 1) if L(one)[i, 0] > 150
                         else 1.0 for i in range(n)])
    x, wx = np.polynomial.legendre.leggauss(20)
    edges = np.concatenate([[0.0], np.geomspace(1e-7, 1.0, 300)])
    S = np.concatenate([lo + (hi - lo) * (x + 1) / 2 for lo, hi in zip(edges[:-1], edges[1:])])
    W = np.concatenate([(hi - lo) / 2 * wx for lo, hi in zip(edges[:-1], edges[1:])])
    s = S * h[:, None]
    ref = (np.sum(W * h[:, None] * s * np.arcsinh(X0[:, None] * np.exp(np.minimum(L(s), 150.0))),
                  axis=1) + np.arcsinh(X0 * np.exp(150.0)) * (1 - h * h) / 2)
    got = np.asarray(jax.jit(shear_integral, static_argnums=3)(pf, X0, oil, model))
    np.testing.assert_allclose(got, ref, rtol=2e-9)   # observed 3.9e-10 / 4.7e-10
    # the fused route of large batches (>= FUSED_MIN_POINTS points: the nodes unrolled)
    # against the same reference: the sweep three times over
    oil3 = Oil(*(jnp.tile(v, 3) for v in (oil.eta0, oil.z)), oil.tau0, oil.rho0)
    got3 = np.asarray(jax.jit(shear_integral, static_argnums=3)(np.tile(pf, 3), np.tile(X0, 3),
                                                                 oil3, model))
    np.testing.assert_allclose(got3, np.tile(ref, 3), rtol=2e-9)
    # odd in X0 (signed sliding speeds in mesh arrays), as asinh
    neg = np.asarray(jax.jit(shear_integral, static_argnums=3)(pf, -X0, oil, model))
    np.testing.assert_allclose(neg, -got, rtol=1e-14)
    # at u_s = 0 the integral and its derivative in X0 are finite (∫ η/η0 s ds)
    oil1 = Oil(*(jnp.asarray(v) for v in (ETA0, Z, TAU0, 880.0)))
    assert float(shear_integral(1500.0, 0.0, oil1, model)) == 0.0
    d = jax.grad(lambda x: shear_integral(1500.0, x, oil1, model))(0.0)
    assert np.isfinite(float(d)) and float(d) > 1.0


@pytest.mark.parametrize("model", ["roelands", "barus"])
def test_fused_large_batch_route_is_the_stacked_rule(model):
    """From FUSED_MIN_POINTS points on, the shear rule runs node by node (one fused
    loop) with its own derivative rule (the partials in closed form, a custom JVP), and
    the AGM of the Hertz ellipse is unrolled.  Against the points x nodes route of
    small batches on the same 5000 points (p_f 0-4 GPa, |X0| 0 and 1e-10..1e5 of either
    sign, per-point η0 and z): the value, the forward derivative along each of p_f, X0,
    η0, z, the reverse gradient and a second derivative in p_f; and the fused route's
    derivative along each input against central differences of its own values; and the
    unrolled AGM of the Hertz ellipse against the loop, bit for bit.  Planted bugs
    caught (tools/mutations/tribology.toml, shear-fused-*): a wrong factor in a partial
    of either viscosity law, the tail's X0 slope dropped, the large-argument form of the
    asinh slope replaced by the plain one or without its sign (negative X0), the
    tangents of η0 and z swapped.  (The cap's zero slope inside the loop is not
    reachable: the nodes lie inside [0, h], below the cap.)"""
    from gearjax.contact import FUSED_MIN_POINTS, hertz_exact
    from gearjax.tribology import friction
    n = 5000
    assert n >= FUSED_MIN_POINTS
    rng = np.random.default_rng(11)
    pf = jnp.asarray(np.concatenate([rng.uniform(0, 4000, n - 100), np.zeros(50),
                                     rng.uniform(100, 2000, 50)]))
    # a third of the Eyring arguments negative (signed sliding speeds: J is odd in X0)
    sign = np.where(rng.uniform(size=n - 50) < 1 / 3, -1.0, 1.0)
    X0 = jnp.asarray(np.concatenate([sign * 10 ** rng.uniform(-10, 5, n - 50), np.zeros(50)]))
    eta0 = jnp.asarray(10 ** rng.uniform(-2.5, 0.5, n))
    z = jnp.asarray(rng.uniform(0.3, 1.0, n))

    def route(fn):
        def J(p, x, e, zz):
            return fn(model, p, x, Oil(e, zz, jnp.asarray(TAU0), jnp.asarray(880.0)))
        return J

    fused, stacked = route(friction._shear_rule), route(friction._shear_stacked)
    args = (pf, X0, eta0, z)
    value = jax.jit(fused)
    v_f, v_s = value(*args), jax.jit(stacked)(*args)
    np.testing.assert_allclose(np.asarray(v_f), np.asarray(v_s), rtol=1e-13, atol=1e-300)

    def jvps(fn):   # the derivative along each input, one program per route
        def all_four(*a):
            return [jax.jvp(fn, a, tuple(jnp.ones_like(x) if j == i else jnp.zeros_like(x)
                                         for j, x in enumerate(a)))[1] for i in range(4)]
        return jax.jit(all_four)(*args)

    for i, (d_f, d_s) in enumerate(zip(jvps(fused), jvps(stacked))):
        assert np.all(np.isfinite(np.asarray(d_f))), i
        np.testing.assert_allclose(np.asarray(d_f), np.asarray(d_s), rtol=1e-11, atol=0,
                                   err_msg=str(i))
        # central differences of the fused values (relative step 1e-6; points where
        # the value moves well above its round-off; not at X0 = 0, where a step of any
        # size leaves the linear part of asinh(X0 e^L) for e^L up to e^150)
        step = 1e-6 * jnp.where(args[i] != 0.0, jnp.abs(args[i]), 1e-3)
        shift = [tuple(a + sgn * step if j == i else a for j, a in enumerate(args))
                 for sgn in (1.0, -1.0)]
        cd = (value(*shift[0]) - value(*shift[1])) / (2.0 * step)
        ok = np.asarray((jnp.abs(d_f * step) > 1e-7 * jnp.abs(v_f)) & (X0 != 0.0))
        assert ok.sum() > n // 5, i
        np.testing.assert_allclose(np.asarray(cd)[ok], np.asarray(d_f)[ok], rtol=1e-5,
                                   err_msg=str(i))
    g_f = jax.jit(jax.grad(lambda *a: jnp.sum(fused(*a)), argnums=(0, 1, 2, 3)))(*args)
    g_s = jax.jit(jax.grad(lambda *a: jnp.sum(stacked(*a)), argnums=(0, 1, 2, 3)))(*args)
    for a, b in zip(g_f, g_s):
        np.testing.assert_allclose(np.asarray(a), np.asarray(b), rtol=1e-11, atol=0)
    # second derivative in p_f (the partials are themselves differentiable)
    h_f = jax.jit(jax.grad(lambda *a: jnp.sum(jax.jvp(
        fused, a, (jnp.ones_like(pf), *(jnp.zeros_like(v) for v in a[1:])))[1])))(*args)
    h_s = jax.jit(jax.grad(lambda *a: jnp.sum(jax.jvp(
        stacked, a, (jnp.ones_like(pf), *(jnp.zeros_like(v) for v in a[1:])))[1])))(*args)
    # (entries many orders below the largest lose digits to cancellation in both routes:
    # Barus, entries of 1e-17 against a largest of 1.5e-4 differ by 2e-19; so the bound
    # is also relative to the largest)
    np.testing.assert_allclose(np.asarray(h_f), np.asarray(h_s), rtol=1e-8,
                               atol=1e-10 * float(jnp.max(jnp.abs(h_s))))
    if model == "barus":
        return
    # the Hertz ellipse: the unrolled AGM of a large batch is the loop's, bit for bit
    F = jnp.asarray(rng.uniform(10, 1e4, n))
    Rx = jnp.asarray(rng.uniform(1, 50, n))
    Ry = Rx * jnp.asarray(10 ** rng.uniform(-3, 4, n))
    big = jax.jit(lambda *a: hertz_exact(*a, 226374.0))(F, Rx, Ry)
    one = jax.jit(jax.vmap(lambda *a: hertz_exact(*a, 226374.0)))(F, Rx, Ry)
    for name in ("a", "b", "p_max", "approach"):
        np.testing.assert_array_equal(np.asarray(getattr(big, name)),
                                      np.asarray(getattr(one, name)), err_msg=name)
