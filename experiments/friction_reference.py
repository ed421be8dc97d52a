"""Compare gearjax's mixed-lubrication μ with empirical gear friction formulas.

Conditions (a documented grid of gear-like contacts): maximum Hertz pressure
1, 2, 3 GPa; entrainment speed 1, 5, 20 m/s; slide-to-roll ratio SRR = u_s/u_e
0.05, 0.2, 0.5; inlet viscosity 10, 30, 100 mPa·s.  Fixed: steel/steel
(E' = 226.4 GPa), Rx = 10 mm, Ry = 300 mm (an elongated gear-flank contact,
k ≈ 14), composite RMS roughness σ = 0.4 µm (Ra ≈ σ/(1.25 √2) = 0.23 µm per
surface, Gaussian surfaces), one mineral-oil family with Roelands index z = 0.6
(so α = 15.5, 18.8, 22.5 GPa⁻¹ at 10, 30, 100 mPa·s), Eyring stress 5 MPa, f_c = 0.1, default asperity density/radius.  The load is
chosen to give the pressure.

Empirical formulas (used exactly as published; gearjax is not tuned to them):

* Xu, Kahraman, Anderson & Maddock, J. Mech. Des. 129 (2007) 58–68 (EHL-based
  regression):  μ = e^f P_h^b2 |SR|^b3 V_e^b6 ν0^b7 R^b8,
  f = b1 + b4 |SR| P_h log10(ν0) + b5 exp(-|SR| P_h log10 ν0) + b9 e^S,
  b1..b9 = -8.916465, 1.03303, 1.036077, -0.354068, 2.812084, -0.100601,
  0.752755, -0.390958, 0.620305 (coefficient table as reproduced in secondary
  sources; units P_h GPa, V_e entrainment m/s, ν0 mPa·s, S composite RMS µm, and
  R in metres as in independent implementations — with R in mm μ would be 15x
  smaller; the original paper was not accessible to check).
* ISO/TR 14179-2 (Schlenk 1994) mean coefficient of friction of a gear mesh:
  μ_mz = 0.048 (w / (v_Σ ρ_red))^0.2 η^-0.05 Ra^0.25 X_L with w load per unit
  face width (N/mm; here the Hertz centre-line intensity 3F/(4a)), v_Σ = 2 u_e
  (m/s), ρ_red = Rx (mm), η in mPa·s, Ra mean arithmetic roughness (µm), X_L = 1
  (mineral oil).  It is a mesh average: it has no SRR dependence.
* Benedict & Kelley, ASLE Trans. 4 (1961) 59–70, in the SI form found in an
  open-source contact-mechanics code: μ = 0.0127 log10(0.02966 w / (η V_s V_Σ²))
  with w N/m, η Pa·s, V_s sliding and V_Σ = 2u_e rolling-sum speed (m/s); the
  roughness factor C_R of the original is not included (C_R = 1).  The original
  paper was not accessible; treat this column with caution.  It diverges as
  V_s → 0.

Writes experiments/results/friction_reference.json and .md.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import warnings

import numpy as np

import gearjax  # noqa: F401
from gearjax.contact import hertz_point
from gearjax.tribology import REGIMES, friction_coefficient, make_oil, make_surface

E_PRIME = 226374.0
RX, RY = 10.0, 300.0
SIGMA_UM = 0.4
RA_UM = SIGMA_UM / (1.25 * math.sqrt(2.0))
XU_B = [-8.916465, 1.03303, 1.036077, -0.354068, 2.812084, -0.100601, 0.752755, -0.390958, 0.620305]


def xu_kahraman(p_GPa, srr, ue_m_s, nu_mPas, R_mm, S_um):
    b1, b2, b3, b4, b5, b6, b7, b8, b9 = XU_B
    x = abs(srr) * p_GPa * math.log10(nu_mPas)
    f = b1 + b4 * x + b5 * math.exp(-x) + b9 * math.exp(S_um)
    return math.exp(f) * p_GPa ** b2 * abs(srr) ** b3 * ue_m_s ** b6 * nu_mPas ** b7 * (R_mm * 1e-3) ** b8


def iso_14179_2(w_N_mm, ue_m_s, R_mm, eta_mPas, Ra_um, XL=1.0):
    return 0.048 * (w_N_mm / (2.0 * ue_m_s * R_mm)) ** 0.2 * eta_mPas ** -0.05 * Ra_um ** 0.25 * XL


def benedict_kelley(w_N_mm, eta_Pas, us_m_s, ue_m_s):
    return 0.0127 * math.log10(0.02966 * (w_N_mm * 1e3) / (eta_Pas * us_m_s * (2.0 * ue_m_s) ** 2))


def main():
    pressures = [1.0, 2.0, 3.0]
    speeds = [1.0, 5.0, 20.0]
    srrs = [0.05, 0.2, 0.5]
    etas = [10.0, 30.0, 100.0]
    # load giving each pressure: p ∝ F^(1/3)
    h1 = hertz_point(1000.0, RX, RY, E_PRIME)
    loads = {p: 1000.0 * (p * 1e3 / float(h1.p_max)) ** 3 for p in pressures}
    surf = make_surface(SIGMA_UM)
    rows = []
    for p, ue, srr, eta in itertools.product(pressures, speeds, srrs, etas):
        F = loads[p]
        oil = make_oil(eta * 1e-3, tau0_MPa=5.0, z=0.6)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            r = friction_coefficient(F, ue * 1e3, srr * ue * 1e3, RX, RY, oil, surf, E_PRIME)
        w = 0.75 * F / float(r.a)  # centre-line load intensity, N/mm
        rows.append(dict(
            p_max_GPa=float(r.p_max) * 1e-3, u_e_m_s=ue, srr=srr, eta0_mPas=eta, load_N=F,
            w_N_mm=w, lambda_smooth=float(r.lam_smooth), asperity_load_ratio=float(r.phi),
            regime=REGIMES[int(r.regime)], mu_gearjax=float(r.mu),
            mu_xu_kahraman=xu_kahraman(p, srr, ue, eta, RX, SIGMA_UM),
            mu_iso_tr_14179_2=iso_14179_2(w, ue, RX, eta, RA_UM),
            mu_benedict_kelley=benedict_kelley(w, eta * 1e-3, srr * ue, ue)))
    g = np.array([r["mu_gearjax"] for r in rows])
    summary = {}
    for key in ("mu_xu_kahraman", "mu_iso_tr_14179_2", "mu_benedict_kelley"):
        o = np.array([r[key] for r in rows])
        ratio = g / o
        summary[key] = dict(median_ratio=float(np.median(ratio)), min_ratio=float(ratio.min()),
                            max_ratio=float(ratio.max()),
                            spearman=float(np.corrcoef(np.argsort(np.argsort(g)),
                                                       np.argsort(np.argsort(o)))[0, 1]))
    out = dict(conditions=dict(Rx_mm=RX, Ry_mm=RY, E_prime_MPa=E_PRIME, sigma_um=SIGMA_UM,
                               Ra_um=RA_UM, roelands_z=0.6, tau0_MPa=5.0, f_c=0.1,
                               asperity_density_per_mm2=1e4, asperity_radius_um=10.0),
               summary=summary, rows=rows)
    here = os.path.dirname(os.path.abspath(__file__))
    os.makedirs(os.path.join(here, "results"), exist_ok=True)
    with open(os.path.join(here, "results", "friction_reference.json"), "w") as fh:
        json.dump(out, fh, indent=1)
    lines = ["# gearjax μ against empirical gear friction formulas", "",
             "Generated by `experiments/friction_reference.py` (see its docstring for the formulas, "
             "units and sources).  Rx = 10 mm, Ry = 300 mm, σ = 0.4 µm, Roelands z = 0.6, τ0 = 5 MPa, f_c = 0.1.", "",
             "| p_max GPa | u_e m/s | SRR | η0 mPa·s | λ_s | F_a/F_n | regime | μ gearjax | μ Xu–Kahraman | μ ISO/TR 14179-2 | μ Benedict–Kelley |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['p_max_GPa']:.2f} | {r['u_e_m_s']:g} | {r['srr']:g} | {r['eta0_mPas']:g} | "
                     f"{r['lambda_smooth']:.2f} | {r['asperity_load_ratio']:.2g} | {r['regime']} | "
                     f"{r['mu_gearjax']:.4f} | {r['mu_xu_kahraman']:.4f} | {r['mu_iso_tr_14179_2']:.4f} | "
                     f"{r['mu_benedict_kelley']:.4f} |")
    lines += ["", "Summary of μ_gearjax / μ_formula over the 81 cases:", "",
              "| formula | median ratio | min | max | rank correlation |", "|---|---|---|---|---|"]
    for k, s in summary.items():
        lines.append(f"| {k[3:]} | {s['median_ratio']:.2f} | {s['min_ratio']:.2f} | {s['max_ratio']:.2f} | "
                     f"{s['spearman']:.2f} |")
    with open(os.path.join(here, "results", "friction_reference.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    print("\n".join(lines[-6:]))


if __name__ == "__main__":
    main()
