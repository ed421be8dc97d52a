"""Friction coefficient: limits and trends required by the issue (seed 001 trend table),
Stribeck shifts, mesh losses and bad input."""

import warnings

import numpy as np
import pytest

from gearjax.errors import ConvergenceError
from gearjax.tribology import (friction_coefficient, get_oil, make_oil, make_surface, mesh_losses,
                               stribeck_curve)
from gearjax.tribology.losses import input_power

OIL = get_oil("mineral_vg100")
F, RX, RY = 1000.0, 10.0, 100.0


def mu_at(ue, us, sigma_um=0.4, oil=OIL, F=F, f_c=0.1, **kw):
    return friction_coefficient(F, ue, us, RX, RY, oil, make_surface(sigma_um, f_c=f_c), **kw)


@pytest.mark.filterwarnings("ignore:Greenwood-Tripp asperity model")
def test_boundary_limit_mu_to_fc():
    # very rough surfaces / slow speeds: λ_s -> 0, asperities carry the load, μ -> f_c
    ue = np.array([2000.0, 500.0, 50.0])
    r = mu_at(ue, 0.2 * ue, sigma_um=3.0, f_c=0.12)
    lam_s = np.asarray(r.lam_smooth)
    mu = np.asarray(r.mu)
    assert np.all(np.diff(lam_s) < 0) and lam_s[-1] < 0.05
    assert np.all(np.asarray(r.phi) > 0.99)
    assert abs(mu[-1] - 0.12) < 0.002 * 0.12 + float(r.mu_fluid[-1]) + 1e-12
    assert abs(mu[-1] / 0.12 - 1) < 0.01
    assert np.all(np.asarray(r.regime) == 0)


def test_pure_rolling_mu_to_zero():
    us = np.array([0.0, 1e-4, 1e-2, 1.0, 100.0])
    r = mu_at(np.full(5, 500.0), us, sigma_um=0.8)
    mu = np.asarray(r.mu)
    assert mu[0] == 0.0
    assert np.all(np.diff(mu) > 0)
    assert mu[1] < 1e-4 * mu[-1] * 10


def test_full_film_mu_rises_with_viscosity():
    # the same oil family (Roelands z fixed) at two viscosities, e.g. two temperatures
    thin = make_oil(0.05, z=0.6)
    thick = make_oil(0.2, z=0.6)
    r1 = mu_at(10000.0, 2000.0, sigma_um=0.1, oil=thin)
    r2 = mu_at(10000.0, 2000.0, sigma_um=0.1, oil=thick)
    assert int(r1.regime) == 2 and int(r2.regime) == 2
    assert float(r2.mu) > float(r1.mu)


def test_mixed_regime_mu_falls_with_speed():
    # gear-like: p_max 1.54 GPa (F 1000 N, Rx 10 mm, Ry 100 mm), SRR 0.2, σ 0.8 µm, f_c = 0.1
    ue = np.logspace(np.log10(300.0), np.log10(20000.0), 15)
    r = mu_at(ue, 0.2 * ue, sigma_um=0.8)
    mixed = np.asarray(r.regime) == 1
    assert mixed.sum() >= 6
    assert np.all(np.diff(np.asarray(r.mu)[mixed]) < 0)
    # and in full film it rises again (EHL branch of the Stribeck curve)
    assert np.asarray(r.regime)[-1] == 2 and float(r.mu[-1]) > float(np.asarray(r.mu).min())


def test_roughness_increases_mu_in_mixed_regime():
    r = [float(mu_at(3000.0, 600.0, sigma_um=s).mu) for s in (0.4, 0.6, 0.8, 1.0)]
    assert np.all(np.diff(r) > 0)


def _transition_x(F_load=F, sigma_um=0.8, oil=OIL):
    ue = np.logspace(1.5, 5.5, 41)
    c = stribeck_curve(F_load, RX, RY, 0.2, ue, oil, make_surface(sigma_um))
    phi = np.asarray(c.friction.phi)
    x = np.asarray(c.stribeck_number)
    i = np.argmax(phi < 0.5)  # first point with the asperity share below one half
    assert 0 < i < len(ue) - 1
    # log-interpolate the crossing of phi = 0.5
    t = (np.log(phi[i - 1]) - np.log(0.5)) / (np.log(phi[i - 1]) - np.log(phi[i]))
    return np.exp(np.log(x[i - 1]) + t * (np.log(x[i]) - np.log(x[i - 1]))), np.exp(
        np.log(ue[i - 1]) + t * (np.log(ue[i]) - np.log(ue[i - 1])))


def test_stribeck_shifts_as_in_seed():
    x0, u0 = _transition_x()
    x_load, _ = _transition_x(F_load=2000.0)
    x_rough, _ = _transition_x(sigma_um=1.0)
    _, u_visc = _transition_x(oil=make_oil(0.176, z=float(OIL.z)))
    assert x_load < x0          # load: curve shifts left
    assert x_rough > x0         # roughness: shifts right
    assert u_visc < u0          # viscosity: mixed-to-EHL transition at lower speed


def test_result_fields_consistent():
    r = mu_at(4000.0, 800.0, sigma_um=0.5)
    assert float(r.mu) == pytest.approx(float(r.mu_boundary) + float(r.mu_fluid), rel=1e-14)
    assert float(r.friction_force) == pytest.approx(float(r.mu) * F, rel=1e-14)
    assert float(r.lam) == pytest.approx(float(r.h_c) / 5e-4, rel=1e-12)
    assert float(r.h_min) < float(r.h_c)


def _mesh_case():
    # 5 mesh positions x 2 points; sliding changes sign at the pitch point (position 2)
    F = np.array([[600.0, 400.0], [1000.0, 0.0], [1000.0, 0.0], [1000.0, 0.0], [450.0, 550.0]])
    us = np.array([[-900.0, 1500.0], [-500.0, 0.0], [0.0, 0.0], [500.0, 0.0], [900.0, -1400.0]])
    ue = np.array([[4000.0, 4500.0], [4200.0, 1.0], [4300.0, 1.0], [4400.0, 1.0], [4600.0, 4100.0]])
    Rx = np.array([[6.0, 9.0], [7.0, 1.0], [8.0, 1.0], [9.0, 1.0], [10.0, 7.0]])
    Ry = 20.0 * Rx
    return F, us, ue, Rx, Ry


def test_mesh_losses_against_pointwise_route():
    F, us, ue, Rx, Ry = _mesh_case()
    surf = make_surface(0.5)
    p_in = float(input_power(120.0, 150.0))  # 120 N·m at 150 rad/s = 18 kW
    out = mesh_losses(F, us, ue, Rx, Ry, OIL, surf, p_in)
    act = F > 0
    r = friction_coefficient(F[act], ue[act], np.abs(us[act]), Rx[act], Ry[act], OIL, surf)
    P = np.zeros(5)
    np.add.at(P, np.nonzero(act)[0], np.asarray(r.mu) * F[act] * np.abs(us[act]) * 1e-3)
    np.testing.assert_allclose(np.asarray(out.power_loss), P, rtol=1e-10)
    assert float(out.power_loss[2]) == 0.0  # pure rolling at the pitch point
    np.testing.assert_allclose(np.asarray(out.efficiency), 1 - P / p_in, rtol=1e-12)
    assert float(out.mean_efficiency) == pytest.approx(1 - P.mean() / p_in, rel=1e-12)
    w = np.array([0.5, 1, 1, 1, 0.5])
    outw = mesh_losses(F, us, ue, Rx, Ry, OIL, surf, p_in, weights=w)
    assert float(outw.mean_efficiency) == pytest.approx(1 - (w * P).sum() / (w.sum() * p_in), rel=1e-12)
    assert np.all(np.asarray(out.mu)[~act] == 0)


@pytest.mark.parametrize("kw,name", [
    (dict(F=-5.0), "load"), (dict(F=0.0), "load"), (dict(ue=-1.0), "u_e"), (dict(us=-3.0), "u_s"),
    (dict(Rx=0.0), "Rx"), (dict(Ry=-2.0), "Ry"), (dict(E_prime=0.0), "E_prime"),
    (dict(Ry=np.nan), "Ry")])
def test_bad_contact_input(kw, name):
    args = dict(F=F, ue=1000.0, us=100.0, Rx=RX, Ry=RY, E_prime=226374.0)
    args.update(kw)
    with pytest.raises(ValueError, match=name):
        friction_coefficient(args["F"], args["ue"], args["us"], args["Rx"], args["Ry"], OIL,
                             make_surface(0.4), args["E_prime"])


@pytest.mark.parametrize("call,name", [
    (lambda: make_surface(0.0), "sigma"), (lambda: make_surface(-1.0), "sigma"),
    (lambda: make_surface(0.4, density_per_mm2=0.0), "asperity density"),
    (lambda: make_surface(0.4, beta_um=-1.0), "asperity radius"),
    (lambda: make_surface(0.4, f_c=1.5), "f_c"),
    (lambda: make_oil(0.0, 20.0), "eta0")])
def test_bad_material_input(call, name):
    with pytest.raises(ValueError, match=name):
        call()


def test_mesh_bad_input():
    F, us, ue, Rx, Ry = _mesh_case()
    s = make_surface(0.5)
    with pytest.raises(ValueError, match="power_in"):
        mesh_losses(F, us, ue, Rx, Ry, OIL, s, -1.0)
    Fb = F.copy()
    Fb[0, 0] = -1.0
    with pytest.raises(ValueError, match="load"):
        mesh_losses(Fb, us, ue, Rx, Ry, OIL, s, 1e4)
    ueb = ue.copy()
    ueb[0, 0] = -1.0
    with pytest.raises(ValueError, match="u_e"):
        mesh_losses(F, us, ueb, Rx, Ry, OIL, s, 1e4)


def test_validity_warnings_name_formula_and_range():
    with pytest.warns(UserWarning, match=r"Hamrock-Dowson.*1 <= k <= 8"):
        friction_coefficient(F, 3000.0, 300.0, 5.0, 5000.0, OIL, make_surface(0.4), film_method="point")
    # default "auto" film: Hamrock-Dowson alone below k = 1 (Rx > Ry) is outside its fit
    with pytest.warns(UserWarning, match=r"Hamrock-Dowson.*1 <= k <= 8"):
        friction_coefficient(F, 3000.0, 300.0, 30.0, 12.0, OIL, make_surface(0.4))
    with pytest.warns(UserWarning, match=r"Pan-Hamrock line-contact.*not elongated"):
        friction_coefficient(F, 3000.0, 300.0, RX, 2.0 * RX, OIL, make_surface(0.4), film_method="line")
    with pytest.warns(UserWarning, match=r"Roelands viscosity.*3 GPa"):
        friction_coefficient(40000.0, 3000.0, 300.0, 5.0, 10.0, OIL, make_surface(0.4))
    with pytest.warns(UserWarning, match=r"Greenwood-Tripp.*0.005..0.2"):
        make_surface(0.4, density_per_mm2=1e6)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        friction_coefficient(F, 3000.0, 300.0, RX, RY, OIL, make_surface(0.4))


def test_nonconvergence_is_not_returned_as_valid(monkeypatch):
    import gearjax.tribology.friction as fr
    real = fr._friction_jit

    def fake(*a, **k):
        out = real(*a, **k)
        return out._replace(converged=out.converged & False)

    monkeypatch.setattr(fr, "_friction_jit", fake)
    with pytest.raises(ConvergenceError):
        friction_coefficient(F, 3000.0, 300.0, RX, RY, OIL, make_surface(0.4))
    r = friction_coefficient(F, 3000.0, 300.0, RX, RY, OIL, make_surface(0.4), strict=False)
    assert not bool(r.converged)
