"""Benchmark: a 41x21 hypoid flank grid with gearjax vs a per-point SciPy ``fsolve`` loop.

Same design ([HFT-hypoid] 8/43 pinion, convex flank), same equations (meshing,
face-width, face-cone), same continuation order (tip row from mid face outwards, then
each row from the tip down) and the same tolerance (residual <= 1e-10 mm, checked
for both).  The SciPy side evaluates the equations with NumPy (no JAX in its loop)
and the meshing equation from the angular-velocity form of [HFT-hypoid].  Then the gradient
cost: ``jax.jacfwd`` of all grid points w.r.t. all 11 machine settings and the
cutter radius against central differences over the same 12 parameters.

Run:  python benchmarks/bench_hypoid_surface.py [--grid 41x21] [--member pinion --flank convex]
Not a test; numbers depend on the machine (2-core CPU in the project's CI).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import time

import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import fsolve

from gearjax.gears.hypoid.flank import (face_apex_offset, flank_points, flank_surface, mid_estimate,
                                  solve_tip)
from gearjax.gears.hypoid.design_file import load_design
from gearjax.gears.hypoid.machine import work_to_machine


def numpy_model(fl):
    """NumPy versions of the flank equations (for the SciPy loop)."""
    c, ms, b = fl.cutter, fl.machine, fl.blank
    R, al, sg = float(c.point_radius), float(c.blade_angle), int(c.sign)
    gp, gF = float(b.pitch_angle), float(b.face_angle)
    Ao, F = float(b.outer_cone_distance), float(b.face_width)
    xpf = float(face_apex_offset(b))
    from gearjax.gears.hypoid.machine import cutter_to_cradle
    Mc = np.asarray(cutter_to_cradle(ms))
    M0 = np.asarray(work_to_machine(ms, 0.0))
    Ra, C2, D6 = float(ms.ratio_of_roll), float(ms.modified_roll_2c), float(ms.modified_roll_6d)
    gen = ms.generated

    def rz(a):
        ca, sa = math.cos(a), math.sin(a)
        return np.array([[ca, -sa, 0, 0], [sa, ca, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])

    def phi(p):
        return Ra * (p - 0.5 * C2 * p * p - D6 / 6 * p ** 3) if gen else 0.0

    def dphi(p):
        return Ra * (1 - C2 * p - 0.5 * D6 * p * p) if gen else 0.0

    def point(s, th, p):
        rho = R - sg * s * math.sin(al)
        r_t = np.array([rho * math.cos(th), rho * math.sin(th), -s * math.cos(al), 1.0])
        n_t = np.array([sg * math.cos(al) * math.cos(th), sg * math.cos(al) * math.sin(th), -math.sin(al), 0.0])
        Mm = rz(p) @ Mc                                   # cutter -> machine
        r_m, n_m = Mm @ r_t, Mm @ n_t
        Mmw = M0 @ rz(phi(p))                             # work -> machine
        Mwm = np.linalg.inv(Mmw)
        return Mwm @ r_m, Mwm @ n_m, r_m, n_m, Mmw

    def f_all(s, th, p, xi0, tip):
        r_w, n_w, r_m, n_m, Mmw = point(s, th, p)
        if gen:
            w_w = dphi(p) * Mmw[:3, 2]
            v = np.cross(np.array([0, 0, 1.0]) - w_w, r_m[:3]) + np.cross(w_w, Mmw[:3, 3])
            f1 = n_m[:3] @ v
        else:
            f1 = p
        xA, RA = r_w[2], math.hypot(r_w[0], r_w[1])
        f2 = math.cos(gp) * xA + math.sin(gp) * RA - (Ao - 0.5 * F * (1 - xi0))
        out = [f1, f2]
        if tip:
            out.append(math.sin(gF) * (xA + xpf) - math.cos(gF) * RA)
        return np.array(out), r_w[:3]

    return f_all


def scipy_grid(fl, n_xi, n_s, x_mid):
    f_all = numpy_model(fl)
    s_min = float(fl.cutter.edge_radius) * (1 - math.sin(float(fl.cutter.blade_angle))) / math.cos(float(fl.cutter.blade_angle))
    xis = np.linspace(-1, 1, n_xi)
    ts = np.linspace(1, 0, n_s)
    pts = np.zeros((n_xi, n_s, 3))
    worst = 0.0
    nfev = 0
    failed = 0          # fsolve calls that did not report success (ier != 1)
    tips = {}
    for order in (xis[xis >= 0], xis[xis < 0][::-1]):
        x = np.array(x_mid)
        for xi0 in order:
            x, info, ier, _ = fsolve(lambda u: f_all(u[0], u[1], u[2], xi0, True)[0], x,
                                     xtol=1e-13, full_output=True)
            nfev += info["nfev"]
            failed += int(ier != 1)
            worst = max(worst, np.max(np.abs(f_all(x[0], x[1], x[2], xi0, True)[0])))
            tips[float(xi0)] = x.copy()
    for i, xi0 in enumerate(xis):
        tip = tips[float(xi0)]
        y = tip[1:].copy()
        for j, t in enumerate(ts):
            s = s_min + (tip[0] - s_min) * t
            y, info, ier, _ = fsolve(lambda u: f_all(s, u[0], u[1], xi0, False)[0], y,
                                     xtol=1e-13, full_output=True)
            nfev += info["nfev"]
            failed += int(ier != 1)
            F, r = f_all(s, y[0], y[1], xi0, False)
            worst = max(worst, np.max(np.abs(F)))
            pts[i, n_s - 1 - j] = r
    return pts, worst, nfev, failed


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grid", default="41x21")
    ap.add_argument("--member", default="pinion")
    ap.add_argument("--flank", default="convex")
    ap.add_argument("--design", default="example:hft_8x43")
    a = ap.parse_args()
    n_xi, n_s = (int(v) for v in a.grid.lower().split("x"))
    fl = load_design(a.design).flank(a.member, a.flank)
    rows = []

    t0 = time.perf_counter()
    g = flank_surface(fl, n_xi, n_s)
    jax.block_until_ready(g.points)
    t_first = time.perf_counter() - t0
    reps = 3
    t0 = time.perf_counter()
    for _ in range(reps):
        g = flank_surface(fl, n_xi, n_s)
        jax.block_until_ready(g.points)
    t_gj = (time.perf_counter() - t0) / reps
    res_gj = float(np.max(g.residual))

    x_mid = np.asarray(solve_tip(fl, 0.0, mid_estimate(fl)).x)
    t0 = time.perf_counter()
    pts, res_sp, nfev, failed = scipy_grid(fl, n_xi, n_s, x_mid)
    t_sp = time.perf_counter() - t0
    dev = float(np.max(np.abs(pts - np.asarray(g.points))))

    rows.append(("flank grid, gearjax (jit, compiled)", t_gj, f"max residual {res_gj:.1e} mm"))
    rows.append(("flank grid, gearjax first call (incl. compile)", t_first, ""))
    rows.append(("flank grid, SciPy fsolve per point", t_sp,
                 f"max residual {res_sp:.1e} mm, {nfev} F evals, {failed} fsolve calls "
                 f"without success flag, max |dr| {dev:.1e} mm"))

    # gradient cost over the 11 machine settings + cutter point radius
    names = ["radial_distance", "cradle_angle", "tilt", "swivel", "blank_offset",
             "machine_root_angle", "sliding_base", "center_to_back", "ratio_of_roll",
             "modified_roll_2c", "modified_roll_6d"]

    def with_p(p):
        m = dataclasses.replace(fl.machine, **{n: p[k] for k, n in enumerate(names)})
        return dataclasses.replace(fl, machine=m,
                                   cutter=dataclasses.replace(fl.cutter, point_radius=p[11]))

    p0 = jnp.stack([getattr(fl.machine, n) for n in names] + [fl.cutter.point_radius])
    jac = jax.jit(jax.jacfwd(lambda p: flank_points(with_p(p), n_xi, n_s).points))
    fwd = jax.jit(lambda p: flank_points(with_p(p), n_xi, n_s).points)
    t0 = time.perf_counter()
    J = jax.block_until_ready(jac(p0))
    t_jac_first = time.perf_counter() - t0
    t0 = time.perf_counter()
    J = jax.block_until_ready(jac(p0))
    t_jac = time.perf_counter() - t0
    jax.block_until_ready(fwd(p0))
    t0 = time.perf_counter()
    cols = []
    for k in range(p0.size):
        h = 1e-6 * max(1.0, abs(float(p0[k])))
        cols.append((np.asarray(fwd(p0.at[k].add(h))) - np.asarray(fwd(p0.at[k].add(-h)))) / (2 * h))
    t_cd = time.perf_counter() - t0
    FD = np.stack(cols, -1)
    rel = float(np.max(np.abs(np.asarray(J) - FD)) / np.max(np.abs(FD)))
    rows.append(("jacfwd, 12 parameters (compiled)", t_jac, f"vs CD max rel diff {rel:.1e}"))
    rows.append(("jacfwd first call (incl. compile)", t_jac_first, ""))
    rows.append(("central differences, 12 parameters (24 grids)", t_cd, ""))

    print(f"\nhypoid flank benchmark: {a.design} {a.member} {a.flank}, grid {n_xi}x{n_s} "
          f"({n_xi * n_s} points), jax {jax.__version__}, devices {jax.devices()}")
    w = max(len(r[0]) for r in rows)
    print(f"{'case':<{w}}  {'time (s)':>10}  note")
    for name, t, note in rows:
        print(f"{name:<{w}}  {t:10.3f}  {note}")
    tol = 1e-10
    print(f"\nsame tolerance: residual <= {tol:g} mm on both sides: "
          f"gearjax {'yes' if res_gj <= tol else 'NO'}, SciPy {'yes' if res_sp <= tol else 'NO'}")
    print(f"ratio SciPy / gearjax (compiled grid): {t_sp / t_gj:.1f}x")
    print(f"ratio central differences / jacfwd (compiled): {t_cd / t_jac:.2f}x")


if __name__ == "__main__":
    main()
