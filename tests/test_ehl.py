"""Tests of the numerical EHL point-contact solver (gearjax.tribology.ehl).

Every expected value comes from an independent reference (closed forms of the
elastic half-space, the Hertz solution, Hamrock–Dowson, central differences,
the Greenwood–Tripp functions of gearjax.tribology.asperity) — never from the
solver itself.  The solves use one coarse 48 x 48 grid (domain X ∈ [-4.5, 1.5],
Y ∈ [-2.5, 2.5]; 11 nodes across the Hertz diameter) so that the whole module
compiles one Newton program, one gradient program and one mixed program; the
tolerances of the grid-dependent checks are set by that resolution (measured
errors at 48², 128², 256² are in docs/ehl.md).
"""

from __future__ import annotations

import dataclasses
import math
import re

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from gearjax.contact import hertz_point
from gearjax.errors import ConvergenceError
from gearjax.tribology.asperity import asperity_pressure
from gearjax.tribology.ehl import ehl_fields, ehl_gradients, ehl_traced, make_grid, solve_ehl
from gearjax.tribology.ehl.grid import deformation, influence_kernel
from gearjax.tribology.ehl.model import make_case, scales
from gearjax.tribology.film import hamrock_dowson
from notebook_run import run_notebook

N = 48
BASE = dict(F=100.0, u_e=1000.0, u_s=200.0, Rx=10.0, Ry=10.0, eta0=0.088, alpha_per_GPa=22.0)


def _solve(**kw):
    args = dict(BASE)
    args.update(kw)
    return solve_ehl(args.pop("F"), args.pop("u_e"), args.pop("u_s"), args.pop("Rx"),
                     args.pop("Ry"), args.pop("eta0"), args.pop("alpha_per_GPa"), n=N, **args)


@pytest.fixture(scope="module")
def base():
    return _solve()


# ---------------------------------------------------------------- elastic kernel


def _love_rect(x, y, hx, hy):
    """∫∫ dA'/r over |x'| ≤ hx, |y'| ≤ hy at (x, y) (Love 1929), plain NumPy."""
    def f(u, v):
        with np.errstate(divide="ignore", invalid="ignore"):
            t1 = np.where(u == 0, 0.0, u * np.arcsinh(v / np.abs(u)))
            t2 = np.where(v == 0, 0.0, v * np.arcsinh(u / np.abs(v)))
        return t1 + t2
    return f(x + hx, y + hy) - f(x - hx, y + hy) - f(x + hx, y - hy) + f(x - hx, y - hy)


def test_dcfft_uniform_rectangle_is_exact_without_wraparound():
    # uniform pressure on a 10 x 6 block of cells near a corner of the grid: the discrete
    # convolution must equal Love's closed form for the whole rectangle everywhere,
    # including the far side of the grid (a periodic FFT would wrap the load around).
    g = make_grid(32, domain=(-3.0, 2.0, -2.0, 2.5))
    k = 1.7
    X, Y = g.nodes()
    P = np.zeros((g.ny, g.nx))
    P[2:8, 1:11] = 1.0
    khat = jnp.fft.rfft2(influence_kernel(g, k))
    w = np.asarray(deformation(jnp.asarray(P), khat, g))
    xc = 0.5 * (X[0, 1] + X[0, 10])
    yc = 0.5 * (Y[2, 0] + Y[7, 0]) * k
    hx = 5.0 * g.dx
    hy = 3.0 * g.dy * k
    ref = _love_rect(X - xc, Y * k - yc, hx, hy)
    assert np.max(np.abs(w - ref)) <= 1e-10 * np.max(np.abs(ref))


def test_deformation_of_hertz_pressure_matches_half_space_closed_form():
    # Johnson (1985) eq. 3.42: p = p0 sqrt(1 - r²/a²) gives the combined displacement
    # w = π p0 (2a² - r²)/(2 a E') (E' = 2E*).  In units a = 1, p0 = 1, with
    # w = (2/(π E')) Σ K P:  (2/π) Σ K P = π (2 - r²)/2 inside r < 1.
    g = make_grid(128, domain=(-2.0, 2.0, -2.0, 2.0))
    X, Y = g.nodes()
    P = np.sqrt(np.maximum(1.0 - X * X - Y * Y, 0.0))
    khat = jnp.fft.rfft2(influence_kernel(g, 1.0))
    w = 2.0 / np.pi * np.asarray(deformation(jnp.asarray(P), khat, g))
    r2 = X * X + Y * Y
    inside = r2 < 0.9
    ref = np.pi * (2.0 - r2) / 2.0
    # cell-centred piecewise-constant pressure: O(Δ^1.5) error from the sqrt edge;
    # at Δ = 1/32 the measured error is 3e-4 relative
    assert np.max(np.abs(w - ref)[inside]) <= 2e-3 * np.pi


def test_deformation_of_elliptic_hertz_pressure_is_quadratic():
    # Hertz: inside the ellipse the elastic displacement of the Hertz pressure closes
    # the gap, w = δ - x²/(2Rx) - y²/(2Ry) (Johnson 1985, §3.5); δ from gearjax.contact.
    F, Rx, Ry, E = 100.0, 10.0, 50.0, 226373.6
    case = make_case(F, 1000.0, 0.0, Rx, Ry, 0.088, 22.0)
    sc = scales(case)
    hz = hertz_point(F, Rx, Ry, E)
    g = make_grid(96, domain=(-1.5, 1.5, -1.5, 1.5))
    X, Y = g.nodes()
    P = np.sqrt(np.maximum(1.0 - X * X - Y * Y, 0.0))
    khat = jnp.fft.rfft2(influence_kernel(g, sc.k))
    w = float(sc.c_w) * np.asarray(deformation(jnp.asarray(P), khat, g)) * float(sc.h_unit)
    x, y = X * float(hz.b), Y * float(hz.a)
    gap_closed = w + x * x / (2 * Rx) + y * y / (2 * Ry)
    inside = X * X + Y * Y < 0.8
    delta = float(hz.approach)
    assert np.max(np.abs(gap_closed[inside] - delta)) <= 5e-3 * delta


# ---------------------------------------------------------------- full solves


def test_base_case_converges_with_load_balance_and_symmetry(base):
    res, case, grid = base
    assert bool(res.converged)
    assert float(res.residual) <= 1e-9
    assert float(res.load_error) <= 1e-6
    assert abs(float(res.F_fluid) - 100.0) <= 1e-6 * 100.0
    assert float(res.F_asperity) == 0.0
    f = ehl_fields(res, case, grid)
    p = f["p"]
    # θ = 0: the problem is symmetric in Y
    assert np.max(np.abs(p - p[::-1, :])) <= 1e-8 * p.max()
    # the pressure vanishes in the cavitated outlet and is never negative
    assert p.min() >= -1e-8 * p.max()


def test_base_case_film_against_hamrock_dowson(base):
    res, case, grid = base
    hc, hm = (float(v) for v in hamrock_dowson(case.F, case.Rx, 1.0, case.u_e, case.eta0,
                                               case.alpha, case.E_prime))
    # Hamrock & Dowson fit their own numerical results within about ±5 %; the 48² grid
    # adds ~3 % (h_c) and ~10 % (h_min, the side lobes are 1–2 cells wide) of
    # discretisation error (docs/ehl.md: grid convergence)
    assert abs(float(res.h_c) / hc - 1.0) <= 0.10
    assert abs(float(res.h_min) / hm - 1.0) <= 0.25
    assert float(res.h_min) < float(res.h_c)


def test_elliptic_case_film_against_hamrock_dowson():
    res, case, grid = _solve(Ry=40.0)
    k = float(scales(case).k)
    hc, hm = (float(v) for v in hamrock_dowson(case.F, case.Rx, k, case.u_e, case.eta0,
                                               case.alpha, case.E_prime))
    assert abs(float(res.h_c) / hc - 1.0) <= 0.10
    assert abs(float(res.h_min) / hm - 1.0) <= 0.25


def test_pseudo_transient_continuation_changes_the_path_not_the_root(base):
    # the shift s (J + s I) of pseudo-transient continuation (used by the nested
    # fine-grid solve) vanishes as the residual does: from the same Hertz start it must
    # reach the root of plain Newton (same compiled program: ptc is traced)
    res0, case, grid = base
    res1 = ehl_traced(case, grid, ptc=1.0)
    assert bool(res1.converged) and float(res1.residual) <= 1e-9
    assert int(res1.steps) != int(res0.steps) or float(res1.residual) != float(res0.residual)
    for f in ("h_c", "h_min", "mu"):
        assert abs(float(getattr(res1, f)) / float(getattr(res0, f)) - 1.0) <= 1e-8, f


def test_lower_speed_pressure_tends_to_hertz(base):
    # dry-contact limit: as u_e falls (Moes M 168 -> 416) the pressure approaches the
    # Hertz pressure (48² cannot resolve much larger M: the exit constriction would
    # need a film thinner than one cell allows, and the solver then rightly reports
    # non-convergence)
    def rms_to_hertz(res, case, grid):
        f = ehl_fields(res, case, grid)
        P = f["p"] / float(scales(case).p_h)
        Ph = np.sqrt(np.maximum(1.0 - f["X"] ** 2 - f["Y"] ** 2, 0.0))
        return np.sqrt(np.mean((P - Ph) ** 2)), P.max()

    rms_base, _ = rms_to_hertz(*base)
    rms_slow, pmax = rms_to_hertz(*_solve(u_e=300.0, u_s=60.0))
    assert rms_slow <= 0.03
    assert rms_slow < 0.8 * rms_base
    assert 0.95 <= pmax <= 1.2


def test_friction_is_ree_eyring_of_the_fields(base):
    # μ recomputed from the nodal fields with lubricant.eyring_shear-like closed form
    res, case, grid = base
    f = ehl_fields(res, case, grid)
    sc = scales(case)
    z = 0.022 * 196.078431372549 / (math.log(0.088) + 9.67)
    eta = 0.088 * np.exp((math.log(0.088) + 9.67) * ((1 + f["p"] / 196.078431372549) ** z - 1))
    tau = 5.0 * np.arcsinh(eta * 1e-6 * 200.0 / (f["h"] * 5.0))
    dA = grid.dx * grid.dy * float(sc.a) * float(sc.b)
    assert abs(float(res.mu) - tau.sum() * dA / 100.0) <= 1e-9
    assert 0.0 < float(res.mu) < 0.2


def test_mixed_lubrication_load_split_and_greenwood_tripp():
    sig_um = 0.4
    res, case, grid = _solve(sigma_um=sig_um)
    assert bool(res.converged)
    assert abs(float(res.F_fluid + res.F_asperity) / 100.0 - 1.0) <= 1e-6
    assert 0.0 < float(res.F_asperity) < 0.5 * 100.0
    f = ehl_fields(res, case, grid, mixed=True)
    ref = np.asarray(asperity_pressure(jnp.asarray(f["h"] / (sig_um * 1e-3)), sig_um * 1e-3,
                                       1.0e4, 10e-3, 226373.6))
    assert np.max(np.abs(f["p_a"] - ref)) <= 1e-8 * ref.max()
    # boundary friction f_c F_a/F (u_s ≫ v_slip)
    assert abs(float(res.mu_boundary) - 0.1 * float(res.F_asperity) / 100.0) <= 1e-12


def test_efficiency_ehl_check_passes_the_fast_models_inputs_in_its_units():
    # gearjax efficiency --ehl-check: the numerical solve of a contact must see the
    # fast model's inputs in the EHL's units (α in 1/GPa, σ and β in µm): at λ ≈ 1.5 the
    # two models agree on h_c to a few per cent and on μ to tens of per cent (docs/
    # friction.md), while a unit slip (σ or α off by 1e3) changes them by far more.
    # A line-contact-like ellipse (Ry/Rx = 100) is skipped with the reason.  48²: the
    # mixed program of the test above is reused.
    from types import SimpleNamespace
    from gearjax.commands.ehl_check import ehl_check
    from gearjax.tribology.friction import friction_coefficient, make_surface
    from gearjax.tribology.lubricant import make_oil
    oil = make_oil(0.088, alpha_per_GPa=22.0, tau0_MPa=5.0)
    surf = make_surface(0.3)
    F, ue, us = np.array([[100.0, 100.0]]), np.array([[1000.0, 1000.0]]), np.array([[200.0, 200.0]])
    rx, ry = np.array([[10.0, 10.0]]), np.array([[10.0, 1000.0]])
    fr = friction_coefficient(F, ue, us, rx, ry, oil, surf)
    eff = SimpleNamespace(phi1=np.array([0.0, 0.1]), u_e=ue, u_s=us, r_x=rx, r_y=ry, friction=fr,
                          loaded=SimpleNamespace(load=F, p_max=fr.p_max))
    rows = ehl_check(eff, oil, surf, 226373.6, 2, N)
    assert len(rows) == 2 and "Ry/Rx" in rows[1]["skipped"] and rows[0]["skipped"] is None
    r = rows[0]
    assert r["converged"] and r["residual"] <= 1e-9
    assert r["mu_fast"] == float(fr.mu[0, 0]) and r["h_c_fast_um"] == float(fr.h_c[0, 0]) * 1e3
    assert abs(r["h_c_ehl_um"] / r["h_c_fast_um"] - 1.0) < 0.08, r
    assert abs(r["mu_ehl"] / r["mu_fast"] - 1.0) < 0.3, r
    assert 0.0 < r["phi_ehl"] < 0.5


def test_asperity_film_factor_loads_the_asperities_at_c_a_h_c():
    # the fast model's documented correction (docs/friction.md): with
    # asperity_film_factor c_a the load sharing must solve
    #   φ = π a b K_GT E' F_5/2(c_a h_c/σ) / F,  h_c = film(F(1-φ), E'(1-φ))
    # (Johnson–Greenwood–Poon with the asperities at c_a h_c), checked here by
    # evaluating the right-hand side independently at the returned φ; c_a < 1 must
    # raise φ and μ; dμ/dc_a (implicit load-sharing gradient) against central
    # differences.
    from gearjax.contact import hertz_exact
    from gearjax.tribology.asperity import F_n, gt_coefficient
    from gearjax.tribology.film import film_thickness_traced
    from gearjax.tribology.friction import friction_coefficient, friction_traced, make_surface
    from gearjax.tribology.lubricant import make_oil
    oil = make_oil(0.088, alpha_per_GPa=22.0, tau0_MPa=5.0)
    F, ue, us, Rx, Ry, E = 300.0, 2000.0, 400.0, 10.0, 50.0, 226373.6
    sig = 0.35
    out = {}
    for ca in (1.0, 0.8):
        surf = make_surface(sig, asperity_film_factor=ca)
        fr = friction_coefficient(F, ue, us, Rx, Ry, oil, surf, E)
        hz = hertz_exact(F, Rx, Ry, E)
        phi = float(fr.phi)
        g1 = 1.0 / (1.0 - phi)
        hc = float(film_thickness_traced(F / g1, Rx, hz.k, hz.a, ue, oil.eta0, oil.alpha, E / g1,
                                         "auto")[0])
        assert abs(float(fr.h_c) / hc - 1.0) <= 1e-10      # λ and films stay the fluid's
        rhs = float(np.pi * hz.a * hz.b * gt_coefficient(sig * 1e-3, 1e4, 10e-3) * E
                    * F_n(ca * hc / (sig * 1e-3), 2.5) / F)
        assert abs(phi / rhs - 1.0) <= 1e-9, (ca, phi, rhs)
        out[ca] = fr
    assert float(out[0.8].phi) > 1.5 * float(out[1.0].phi) > 0.0
    assert float(out[0.8].mu) > float(out[1.0].mu)

    s0 = make_surface(sig)

    @jax.jit
    def mu(ca):
        return friction_traced(F, ue, us, Rx, Ry, oil,
                               dataclasses.replace(s0, asperity_film_factor=ca), E).mu
    ad = float(jax.jit(jax.grad(mu))(jnp.asarray(0.85)))
    h = 1e-5
    fd = (float(mu(jnp.asarray(0.85 + h))) - float(mu(jnp.asarray(0.85 - h)))) / (2 * h)
    assert abs(ad - fd) <= 1e-6 * abs(fd), (ad, fd)


def test_implicit_gradients_match_central_differences(base):
    res, case, grid = base
    grads = ehl_gradients(res, case, grid)
    for name in ("F", "u_e", "u_s", "Rx", "Ry", "eta0", "alpha"):
        v = float(getattr(case, name))
        h = 1e-4 * v
        outs = []
        for s in (1.0, -1.0):
            c2 = dataclasses.replace(case, **{name: jnp.asarray(v + s * h)})
            r = ehl_traced(c2, grid, 0.0, False, (), 1e-11)
            assert bool(r.converged)
            outs.append(r)
        for out in ("h_c", "h_min", "mu"):
            fd = (float(getattr(outs[0], out)) - float(getattr(outs[1], out))) / (2 * h)
            ad = float(getattr(grads[out], name))
            scale = abs(float(getattr(res, out))) / v       # natural size of the derivative
            assert abs(ad - fd) <= 1e-5 * abs(fd) + 1e-8 * scale, (name, out, ad, fd)


# ---------------------------------------------------------------- upwind schemes


@pytest.mark.parametrize("beta, order", [(0.0, 1.0), (1.0, 2.0)])
def test_couette_difference_has_the_order_of_its_scheme(beta, order):
    # the Couette part of the Reynolds operator (ε = 0, P = 0, ρ̄ = 1) must be
    # -(cos θ ∂H/∂X + k⁻¹ sin θ ∂H/∂Y) of a smooth film; its error must fall like
    # ΔX for first-order upwind (β = 0) and like ΔX² with the second-order correction
    # (β = 1).  A wrong correction coefficient or a wrong upstream index leaves
    # first order (or no convergence).
    from gearjax.tribology.ehl.model import Fields, Scales, reynolds_operator
    k, th = 1.3, 30.0
    sc = Scales(*(jnp.asarray(1.0),) * 2, jnp.asarray(k), *(jnp.asarray(1.0),) * 7)
    errs = []
    for n in (40, 80):
        g = make_grid(n, th, upwind=beta)
        X, Y = g.nodes()
        H = np.sin(0.7 * X + 0.3) * np.cos(0.5 * Y) + 2.0
        dHx = 0.7 * np.cos(0.7 * X + 0.3) * np.cos(0.5 * Y)
        dHy = -0.5 * np.sin(0.7 * X + 0.3) * np.sin(0.5 * Y)
        c, s = math.cos(math.radians(th)), math.sin(math.radians(th))
        ref = -(c * dHx + s / k * dHy)
        z = jnp.zeros_like(jnp.asarray(H))
        fl = Fields(jnp.asarray(H), z, z + 1.0, z + 1.0, z)
        L = np.asarray(reynolds_operator(z, fl, sc, g, th))
        inner = (np.abs(X) <= 1.5) & (np.abs(Y) <= 1.5)      # away from the edges
        errs.append(np.max(np.abs(L - ref)[inner]))
    observed = math.log2(errs[0] / errs[1])
    assert abs(observed - order) < 0.25, (errs, observed)


def _couette_only(H, g, th, k=1.0):
    """Couette part -(cos θ ∂X + k⁻¹ sin θ ∂Y)(H) of the Reynolds operator (ε = 0, ρ̄ = 1)."""
    from gearjax.tribology.ehl.model import Fields, Scales, reynolds_operator
    sc = Scales(*(jnp.asarray(1.0),) * 2, jnp.asarray(k), *(jnp.asarray(1.0),) * 7)
    z = jnp.zeros_like(jnp.asarray(H))
    return np.asarray(reynolds_operator(z, Fields(jnp.asarray(H), z, z + 1.0, z + 1.0, z), sc,
                                        g, th))


def test_van_albada_limited_scheme_is_second_order_and_keeps_a_step_monotone():
    # (1) on a smooth monotone film the limited second-order scheme converges like ΔX²
    # (a limiter that clipped smooth slopes, or a wrong slope pair, would leave first
    # order); (2) across a step in ρ̄H the limited face fluxes make no new extremum:
    # the flux difference never takes the sign opposite to the jump, whereas the
    # unlimited correction gives -(3·2 - 4·2 + 1)/2 = +0.5 (per ΔX) of the wrong sign
    # just behind the step (the check fails for the unlimited scheme, below).
    errs = []
    for n in (40, 80):
        g = make_grid(n, 0.0, upwind=1.0, limiter="van_albada")
        X, Y = g.nodes()
        H = 2.0 + np.tanh(0.6 * X + 0.2) + 0.1 * Y
        ref = -0.6 / np.cosh(0.6 * X + 0.2) ** 2
        inner = (np.abs(X) <= 1.0) & (np.abs(Y) <= 1.5)   # the domain ends at X = 1.5
        errs.append(np.max(np.abs(_couette_only(H, g, 0.0) - ref)[inner]))
    assert abs(math.log2(errs[0] / errs[1]) - 2.0) < 0.3, errs
    for lim, ok in (("van_albada", True), ("none", False)):
        g = make_grid(40, 0.0, upwind=1.0, limiter=lim)
        X, _ = g.nodes()
        H = np.where(X < 0.0, 1.0, 2.0)            # ρ̄H jumps up along the flow (+X)
        d = -_couette_only(H, g, 0.0) * g.dx       # f_e - f_w: must be >= 0 everywhere
        assert (np.min(d) >= -1e-9) == ok, (lim, np.min(d))


def test_limiter_name_is_checked():
    with pytest.raises(ValueError, match="limiter"):
        make_grid(32, limiter="minmod")


# ---------------------------------------------------------------- input checking


def test_non_converged_solve_raises_or_is_flagged():
    with pytest.raises(ConvergenceError):
        _solve(tol=1e-30, continuation=())
    res, _, _ = _solve(tol=1e-30, continuation=(), throw=False)
    assert not bool(res.converged)


@pytest.mark.parametrize("kw, word", [
    (dict(F=-1.0), "F"), (dict(u_e=0.0), "u_e"), (dict(Ry=1e4), "Ry/Rx"),
    (dict(eta0=1e-6), "eta0"), (dict(n=8), "n"), (dict(n=40.5), "n"),
    (dict(angle_deg=270.0), "angle_deg"), (dict(F=1e7), "p_max"),
    (dict(mixed=True), "sigma_um"), (dict(upwind=1.5), "upwind"),
])
def test_bad_inputs_raise_value_error_naming_the_parameter(kw, word):
    args = dict(BASE)
    n = kw.pop("n", N)
    args.update(kw)
    with pytest.raises(ValueError, match=word):
        solve_ehl(args.pop("F"), args.pop("u_e"), args.pop("u_s"), args.pop("Rx"),
                  args.pop("Ry"), args.pop("eta0"), args.pop("alpha_per_GPa"), n=n, **args)


# -- the notebook of this subject (tests/notebook_run.py: after this file's tests,
# whose compiled programs it reuses)


def test_ehl_check_notebook_meets_its_references(tmp_path):
    """The EHL notebook (48²: the programs of test_ehl.py): the smooth film against
    Hamrock-Dowson, the fast model against the numerical rough contact, and the adjoint
    gradients against central differences (what the notebook prints, read back)."""
    _, text = run_notebook("03_ehl_check", tmp_path)
    assert "converged True" in text and "numerical solve converged True" in text, text[-2000:]
    ratio = float(re.search(r"h_c  numerical .* ratio ([0-9.]+)", text).group(1))
    assert 0.9 <= ratio <= 1.1
    mu = re.search(r"^mu\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)$", text, re.M)
    assert 0.7 <= float(mu.group(3)) <= 1.3, mu.group(0)
    worst = float(re.search(r"largest relative difference ([0-9.e+-]+)", text).group(1))
    assert worst < 1e-5
