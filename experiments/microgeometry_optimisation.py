"""Robust micro-geometry optimisation of a helical pair over torques and misalignments
(issue #32 [U] item 5).

The pair: z 23/67, m_n 3 mm, alpha_n 20 deg, beta 20 deg, b 30 mm, x 0.2/-0.1, steel,
drive side, loaded line contact of :mod:`gearjax.gears.involute.line_load` (thin
slices, Weber/Sainsot compliance).  Design load: see ``DESIGN_TORQUE_NM`` below.

**Variables** (6, scaled to [0, 1] over their bounds; linear reliefs):
pinion and gear tip relief amount C_a (0..30 um) and roll length L_a (0.5..6 mm),
pinion lead crowning C_beta (0..20 um), pinion helix slope f_Hbeta (-15..15 um).
Start: the unmodified pair (amounts 0, slope 0; the relief lengths, which do nothing
at zero amount, start at 3 mm).

**Scenarios**: torques (0.5, 0.75, 1.0, 1.25) x design times mesh misalignments f_ma
(-10, 0, +10) um, 12 in one vmapped program.

**Objective**: the mean over the scenarios of the smooth loaded-TE peak-to-peak
(``smooth_ptp``, temperature 0.02 um; it exceeds the hard p-t-p by at most
2 T ln(positions) = 0.13 um); ``--worst``: a smooth maximum over the scenarios instead,
``T_w ln sum exp(ptp_s / T_w)`` with ``T_w`` = 0.05 um (at most T_w ln 12 = 0.12 um
above the largest).

**Constraints** (g <= 0, smooth, scaled to O(1)):

1. peak pressure: ``smax(p) / p_allow - 1``, ``smax`` a log-sum-exp over every
   loaded slice point, mesh position and scenario at temperature 0.002 p_allow (about
   3 MPa; an upper bound of the hard maximum, above it by at most 0.002 p_allow times
   the log of the number of points near the maximum).  ``p_allow`` = 1500 MPa, the
   contact endurance limit sigma_Hlim of case-hardened steel (ISO 6336-5, quality MQ):
   the nominal peak pressure of every scenario, 1.25 x overload and 10 um
   misalignment included, may not exceed it.  (The other choice of the brief, 1.05 x
   the aligned unmodified pair's peak at design load, is infeasible for any
   modification: at 1.25 x torque Hertz pressure alone rises by sqrt(1.25) = 1.118.)
2. edge loading: ``smax(r) / 1.2 - 1`` with ``r`` the load per unit face width in
   the two end slices over the mean load per unit face width, of the distribution
   averaged over the mesh cycle (the cycle-mean face load, whose maximum ratio is
   K_Hbeta), smooth-maxed (temperature 0.005) over both ends and all scenarios.  The
   cycle mean, not the per-position ``LineLoad.end_load``: in a helical pair the
   number of contact lines crossing a slice varies with the mesh position, so the
   per-position end ratio of the aligned, unmodified pair is already 1.25 -- a
   property of the overlap, not edge loading.

**Solvers**: :func:`gearjax.augmented_lagrangian.minimize_constrained` (exact
gradients in forward mode, one jitted program; KKT tolerance 1e-4), from the start and
two random starts, against derivative-free searches of scipy on the same jitted forward
program ``(f, g)``: COBYLA (constraints and bounds native) from the same start,
Nelder-Mead with bounds and a quadratic exterior penalty from the same start and the two
random starts, and differential evolution (constraints as a NonlinearConstraint); then
the augmented Lagrangian from the differential-evolution point (a gradient polish).
The objective's gradient is checked against central differences before optimising,
and one-sided difference quotients at the end point show whether it is a kink.
Results and discussion: experiments/results/microgeometry/README.md.

Run: ``python experiments/microgeometry_optimisation.py [--worst] [--quick]``; writes
``experiments/results/microgeometry/`` (result.json or result_worst.json, figures).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.augmented_lagrangian import minimize_constrained  # (float64 on)
from gearjax.gears.involute.geometry import InvolutePair, pair_geometry
from gearjax.gears.involute.line_load import (LineLoadOptions, line_load_traced, pair_range,
                                              smooth_ptp)
from gearjax.gears.involute.microgeometry import FlankModification, PairModification
from gearjax.gears.involute.tca import InvoluteTCA
from gearjax.loading.tooth_compliance import E_STEEL, NU_STEEL

OUT = Path(__file__).resolve().parent / "results" / "microgeometry"

FACE_WIDTH = 30.0
DESIGN_TORQUE_NM = 400.0
TORQUE_FACTORS = (0.5, 0.75, 1.0, 1.25)
MISALIGNMENTS_UM = (-10.0, 0.0, 10.0)
TEMPERATURE_UM = 0.02
WORST_TEMPERATURE_UM = 0.05
P_ALLOW = 1500.0
P_TEMPERATURE = 0.002          # relative to P_ALLOW
END_ALLOW = 1.2
END_TEMPERATURE = 0.005

#: (member, field, unit, lower, upper, start)
VARIABLES = (("pinion", "tip_relief", "um", 0.0, 30.0, 0.0),
             ("pinion", "tip_relief_length", "mm", 0.5, 6.0, 3.0),
             ("gear", "tip_relief", "um", 0.0, 30.0, 0.0),
             ("gear", "tip_relief_length", "mm", 0.5, 6.0, 3.0),
             ("pinion", "lead_crowning", "um", 0.0, 20.0, 0.0),
             ("pinion", "helix_slope", "um", -15.0, 15.0, 0.0))
LO = np.array([v[3] for v in VARIABLES])
HI = np.array([v[4] for v in VARIABLES])
X_START = (np.array([v[5] for v in VARIABLES]) - LO) / (HI - LO)


def make_pair():
    pair = InvolutePair.create(23, 67, 3.0, 20.0, 20.0, 0.2, -0.1)
    return pair, InvoluteTCA.create(pair, FACE_WIDTH)


def physical(x):
    return LO + (HI - LO) * np.asarray(x)


def modification(x) -> PairModification:
    """The pair's modifications of the scaled variables ``x`` (traceable)."""
    v = jnp.asarray(LO) + jnp.asarray(HI - LO) * x
    fields = {"pinion": {}, "gear": {}}
    for i, (member, name, *_rest) in enumerate(VARIABLES):
        fields[member][name] = v[i]
    return PairModification(dataclasses.replace(FlankModification.none(), **fields["pinion"]),
                            dataclasses.replace(FlankModification.none(), **fields["gear"]))


def _smax(a, t):
    return t * jax.nn.logsumexp(jnp.ravel(a) / t)


class Problem:
    """The scenarios, the options and the jitted programs of one run."""

    def __init__(self, opts: LineLoadOptions, worst: bool, design_torque_Nm: float):
        self.pair, self.design = make_pair()
        self.opts, self.worst = opts, worst
        self.T_design = design_torque_Nm
        self.torques = 1e3 * design_torque_Nm * np.array(TORQUE_FACTORS)
        self.f_ma = np.array(MISALIGNMENTS_UM)
        T, F = np.meshgrid(self.torques, self.f_ma, indexing="ij")
        self.sc_T, self.sc_f = jnp.asarray(T.ravel()), jnp.asarray(F.ravel())
        self.fun = self._fun_recorded            # one object: one compiled program
        self.al_trace, self.al_outer = [], []
        self.fg = jax.jit(self._fun)
        self.details = jax.jit(self._details)
        self.grad_f = jax.jit(jax.jacfwd(lambda x: self._fun(x)[0]))
        self.n_eval = 0

    def _scenario(self, mods, T, f):
        r = line_load_traced(self.pair, FACE_WIDTH, mods, T, f, self.opts, E_STEEL, NU_STEEL,
                             True)
        te = r.te_loaded_um
        cyc = jnp.mean(r.face_load, axis=0)
        end = jnp.stack([cyc[0], cyc[-1]]) / jnp.mean(cyc)
        p_rel = r.p_max / P_ALLOW
        return dict(ptp_smooth=smooth_ptp(te, TEMPERATURE_UM), ptp=jnp.max(te) - jnp.min(te),
                    p_smooth=_smax(p_rel, P_TEMPERATURE), p_max=jnp.max(r.p_max),
                    end_ratio=end, end_load_position=jnp.max(r.end_load),
                    k_hbeta=r.k_hbeta_mean, converged=jnp.all(r.converged),
                    te_mean=jnp.mean(te))

    def _details(self, x):
        mods = modification(x)
        return jax.vmap(lambda T, f: self._scenario(mods, T, f))(self.sc_T, self.sc_f)

    def _fun(self, x):
        d = self._details(x)
        if self.worst:
            J = _smax(d["ptp_smooth"], WORST_TEMPERATURE_UM)
        else:
            J = jnp.mean(d["ptp_smooth"])
        g_p = _smax(d["p_smooth"], P_TEMPERATURE) - 1.0
        g_e = _smax(d["end_ratio"] / END_ALLOW, END_TEMPERATURE) - 1.0
        return J, jnp.stack([g_p, g_e])

    def outer_callback(self, k, f, feas, stat):
        self.al_outer.append((k, f, feas, stat))

    def _record(self, J, g):
        self.al_trace.append((float(J), float(np.max(g))))

    def _fun_recorded(self, x):
        """``_fun`` reporting each evaluation's (f, max g) to ``al_trace`` (a debug
        callback on the primal values: once per evaluation also under ``jacfwd``)."""
        J, g = self._fun(x)
        jax.debug.callback(self._record, J, g)
        return J, g

    def numpy_fg(self, x):
        self.n_eval += 1
        f, g = self.fg(jnp.asarray(x, float))
        return float(f), np.asarray(g)

    def summary(self, x) -> dict:
        d = {k: np.asarray(v) for k, v in self.details(jnp.asarray(x, float)).items()}
        f, g = self.fg(jnp.asarray(x, float))
        shape = (len(self.torques), len(self.f_ma))
        return {"objective_um": float(f), "constraints": np.asarray(g).tolist(),
                "te_ptp_um": d["ptp"].reshape(shape).tolist(),
                "te_ptp_smooth_um": d["ptp_smooth"].reshape(shape).tolist(),
                "mean_te_ptp_um": float(d["ptp"].mean()),
                "worst_te_ptp_um": float(d["ptp"].max()),
                "p_max_MPa": d["p_max"].reshape(shape).tolist(),
                "max_p_max_MPa": float(d["p_max"].max()),
                "end_ratio_cycle_mean": d["end_ratio"].max(axis=1).reshape(shape).tolist(),
                "max_end_ratio_cycle_mean": float(d["end_ratio"].max()),
                "end_load_per_position": d["end_load_position"].reshape(shape).tolist(),
                "k_hbeta_cycle_mean": d["k_hbeta"].reshape(shape).tolist(),
                "all_converged": bool(d["converged"].all())}


def variables_dict(x) -> dict:
    v = physical(x)
    return {f"{m}.{n}": {"value": float(v[i]), "unit": u, "bounds": [lo, hi]}
            for i, (m, n, u, lo, hi, _s) in enumerate(VARIABLES)}


def gradient_check(prob: Problem, x) -> dict:
    """Forward-mode gradient of the objective against central differences (h = 1e-5
    in the scaled variables) at ``x``."""
    g = np.asarray(prob.grad_f(jnp.asarray(x)))
    h = 1e-5
    fd = np.zeros_like(g)
    for i in range(g.size):
        e = np.zeros_like(x)
        e[i] = h
        fd[i] = (prob.numpy_fg(x + e)[0] - prob.numpy_fg(x - e)[0]) / (2 * h)
    rel = np.abs(g - fd) / np.maximum(np.abs(fd), 1e-3 * np.max(np.abs(fd)))
    return {"x": np.asarray(x).tolist(), "ad": g.tolist(), "central": fd.tolist(),
            "max_rel_error": float(rel.max())}


def run_al(prob: Problem, x0, tol, max_outer, warm=True):
    """The augmented Lagrangian from ``x0``; ``warm``: a first call (compiling) before
    the timed one."""
    hist = prob.al_outer
    cb = prob.outer_callback          # one object: the compiled program is reused
    kw = dict(lower=np.zeros(x0.size), upper=np.ones(x0.size), max_outer=max_outer,
              max_inner=60, tol=tol, derivatives="forward", n_constraints=2, callback=cb)
    t_first = None
    if warm:
        t0 = time.perf_counter()
        r = minimize_constrained(prob.fun, jnp.asarray(x0), **kw)
        jax.block_until_ready(r.x)
        t_first = time.perf_counter() - t0
        hist.clear()
    prob.al_trace.clear()
    hist.clear()
    t0 = time.perf_counter()
    r = minimize_constrained(prob.fun, jnp.asarray(x0), **kw)
    jax.block_until_ready(r.x)
    t_run = time.perf_counter() - t0
    return r, {"seconds_first_call_incl_compile": t_first, "seconds": t_run,
               "outer_iterations": int(r.outer_iterations),
               "evaluations": int(r.evaluations),
               "evaluation_kind": "one forward pass with 6 forward-mode tangents (jacfwd)",
               "status": int(r.status), "message": r.message,
               "kkt_converged": bool(int(r.status) == 0),
               "stationarity": float(r.stationarity), "feasibility": float(r.feasibility),
               "complementarity": float(r.complementarity),
               "multipliers": np.asarray(r.multipliers).tolist(), "tol": tol,
               "history": [{"outer": k, "objective_um": f, "feasibility": fe,
                            "stationarity": s} for k, f, fe, s in hist],
               "recorded_evaluations": len(prob.al_trace)}, list(prob.al_trace)


def _cached_fg(prob: Problem):
    """``(fg, trace)``: ``prob.numpy_fg`` evaluated once per distinct point (scipy asks
    for the objective and the constraints of a point separately), and the trace of
    (objective, largest constraint) of every distinct point."""
    trace, cache = [], {}

    def fg(x):
        key = np.asarray(x).tobytes()
        if key not in cache:
            cache[key] = prob.numpy_fg(x)
            trace.append((cache[key][0], float(np.max(cache[key][1]))))
        return cache[key]
    return fg, trace


def run_cobyla(prob: Problem, x0, maxfev):
    from scipy.optimize import minimize
    fg, trace = _cached_fg(prob)
    prob.n_eval = 0
    t0 = time.perf_counter()
    r = minimize(lambda x: fg(x)[0], x0, method="COBYLA",
                 constraints=[{"type": "ineq", "fun": lambda x: -fg(x)[1]}],
                 bounds=list(zip(np.zeros(x0.size), np.ones(x0.size))),
                 options={"maxiter": maxfev, "rhobeg": 0.25, "tol": 1e-6})
    dt = time.perf_counter() - t0
    return r.x, {"method": "COBYLA (scipy), same start", "seconds": dt,
                 "evaluations": prob.n_eval, "message": str(r.message),
                 "success": bool(r.success)}, trace


def run_nelder_mead(prob: Problem, x0, maxfev, mu=1e4):
    from scipy.optimize import minimize
    trace = []

    def pen(x):
        J, g = prob.numpy_fg(x)
        trace.append((J, float(np.max(g))))
        return J + mu * float(np.sum(np.maximum(g, 0.0) ** 2))

    prob.n_eval = 0
    t0 = time.perf_counter()
    r = minimize(pen, x0, method="Nelder-Mead",
                 bounds=list(zip(np.zeros(x0.size), np.ones(x0.size))),
                 options={"maxfev": maxfev, "xatol": 1e-5, "fatol": 1e-6, "adaptive": True})
    dt = time.perf_counter() - t0
    return r.x, {"method": f"Nelder-Mead (scipy, adaptive) on J + {mu:g} sum max(g,0)^2",
                 "seconds": dt, "evaluations": prob.n_eval, "message": str(r.message),
                 "success": bool(r.success)}, trace


#: constraint value counted as feasible in the derivative-free traces and results
FEAS_TOL = 1e-4


def run_de(prob: Problem, maxiter, popsize=10):
    """scipy's differential evolution (a global derivative-free search) with the two
    constraints as a NonlinearConstraint (its feasibility rules), seed 0, no polish."""
    from scipy.optimize import NonlinearConstraint, differential_evolution
    fg, trace = _cached_fg(prob)
    prob.n_eval = 0
    t0 = time.perf_counter()
    r = differential_evolution(lambda x: fg(x)[0], [(0.0, 1.0)] * X_START.size,
                               constraints=NonlinearConstraint(lambda x: fg(x)[1], -np.inf,
                                                               0.0),
                               maxiter=maxiter, popsize=popsize, seed=0, polish=False,
                               tol=1e-8, init="latinhypercube")
    dt = time.perf_counter() - t0
    return r.x, {"method": f"differential evolution (scipy, popsize {popsize}, "
                 f"maxiter {maxiter}, seed 0, NonlinearConstraint)", "seconds": dt,
                 "evaluations": prob.n_eval, "message": str(r.message),
                 "success": bool(r.success)}, trace


def one_sided(prob: Problem, x, h=1e-6) -> dict:
    """One-sided difference quotients of the objective per variable at ``x`` (a kink:
    right and left quotients differ), next to the forward-mode gradient."""
    f0 = prob.numpy_fg(x)[0]
    g = np.asarray(prob.grad_f(jnp.asarray(x)))
    right, left = [], []
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        right.append((prob.numpy_fg(np.minimum(x + e, 1.0))[0] - f0) / h
                     if x[i] + h <= 1.0 else None)
        left.append((f0 - prob.numpy_fg(np.maximum(x - e, 0.0))[0]) / h
                    if x[i] - h >= 0.0 else None)
    return {"h": h, "gradient": g.tolist(), "right": right, "left": left}


def best_feasible(trace):
    best, out = math.inf, []
    for J, gmax in trace:
        if gmax <= FEAS_TOL and J < best:
            best = J
        out.append(best)
    return out


def torque_sweep(prob: Problem, x, factors):
    """Hard loaded-TE p-t-p over a fine torque sweep x each misalignment (T, A)."""
    mods = modification(jnp.asarray(x))

    @jax.jit
    def sweep(mods):
        def one(T, f):
            r = line_load_traced(prob.pair, FACE_WIDTH, mods, T, f, prob.opts, E_STEEL,
                                 NU_STEEL, True)
            return jnp.max(r.te_loaded_um) - jnp.min(r.te_loaded_um), jnp.max(r.p_max)
        return jax.vmap(lambda T: jax.vmap(lambda f: one(T, f))(jnp.asarray(prob.f_ma)))(
            jnp.asarray(1e3 * prob.T_design * factors))

    ptp, p = sweep(mods)
    return np.asarray(ptp), np.asarray(p)


def figures(prob, factors, sweeps, al, al_trace, dfs, before, tag):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4), sharey=True)
    colors = ("tab:blue", "tab:green", "tab:red")
    for a, (title, (ptp, _p)) in zip(ax, sweeps.items()):
        for j, f in enumerate(prob.f_ma):
            a.plot(factors * prob.T_design, ptp[:, j], color=colors[j],
                   label=f"f_ma = {f:+g} um")
        for t in TORQUE_FACTORS:
            a.axvline(t * prob.T_design, color="0.85", lw=0.8, zorder=0)
        a.set_title(title)
        a.set_xlabel("pinion torque (N m)")
        a.grid(alpha=0.3)
    ax[0].set_ylabel("loaded TE peak-to-peak (um)")
    ax[0].legend()
    fig.suptitle(f"z 23/67 helical pair, design {prob.T_design:g} N m "
                 "(grey: optimisation torques)")
    fig.tight_layout()
    fig.savefig(OUT / f"te_vs_torque{tag}.png", dpi=100)
    plt.close(fig)

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    h = [{"outer": 0, "objective_um": before["objective_um"],
          "feasibility": max(0.0, max(before["constraints"])), "stationarity": np.nan}]
    h += al["history"]
    ax[0].plot([r["outer"] for r in h], [r["objective_um"] for r in h], "o-", label="objective")
    ax[0].set_xlabel("augmented-Lagrangian outer iteration")
    ax[0].set_ylabel("objective (um)")
    a2 = ax[0].twinx()
    a2.semilogy([r["outer"] for r in h], [max(r["feasibility"], 1e-12) for r in h], "s--",
                color="tab:red", label="max(g, 0)")
    a2.semilogy([r["outer"] for r in h], [max(r["stationarity"], 1e-12) for r in h], "^:",
                color="tab:purple", label="stationarity")
    a2.set_ylabel("KKT measures")
    ax[0].legend(loc="upper center")
    a2.legend(loc="upper right")
    for name, (trace, info) in dfs.items():
        ax[1].plot(np.arange(1, len(trace) + 1), best_feasible(trace), label=name)
    ax[1].plot(np.arange(1, len(al_trace) + 1), best_feasible(al_trace), "k-", lw=2,
               label="augmented Lagrangian (exact gradients)")
    ax[1].axhline(al["objective_um"], color="k", ls="--", lw=0.8)
    ax[1].set_xscale("log")
    ax[1].set_xlabel("evaluations of (f, g)")
    ax[1].set_ylabel("best feasible objective (um)")
    ax[1].legend(fontsize=8)
    ax[1].grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(OUT / f"history{tag}.png", dpi=100)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--worst", action="store_true", help="smooth max over the scenarios")
    ap.add_argument("--quick", action="store_true", help="coarse model, short searches")
    ap.add_argument("--design-torque", type=float, default=DESIGN_TORQUE_NM, help="N m")
    a = ap.parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    positions, slices = (12, 6) if a.quick else (24, 12)
    pair, _des = make_pair()
    k_lo, k_hi = pair_range(pair, FACE_WIDTH)
    opts = LineLoadOptions(positions, slices, k_lo, k_hi, "weber")
    prob = Problem(opts, a.worst, a.design_torque)
    geo = pair_geometry(pair)
    print(f"pair: eps_alpha {float(geo['contact_ratio']):.3f}, beta_b "
          f"{math.degrees(float(geo['beta_b'])):.3f} deg; model: {positions} positions x "
          f"{slices} slices, pairs {k_lo}..{k_hi}")
    t0 = time.perf_counter()
    before = prob.summary(X_START)
    t_compile = time.perf_counter() - t0
    t0 = time.perf_counter()
    for _ in range(5):
        jax.block_until_ready(prob.fg(jnp.asarray(X_START)))
    t_eval = (time.perf_counter() - t0) / 5
    print(f"before: objective {before['objective_um']:.4f} um, max p_max "
          f"{before['max_p_max_MPa']:.0f} MPa, end ratio {before['max_end_ratio_cycle_mean']:.3f}"
          f"; one (f, g) {1e3 * t_eval:.1f} ms (first call {t_compile:.1f} s)")
    aligned_design = before["p_max_MPa"][TORQUE_FACTORS.index(1.0)][1]
    print(f"aligned unmodified p_max at {a.design_torque:g} N m: {aligned_design:.0f} MPa")
    # gradient check at an interior point (at the start the amounts sit on their bounds)
    x_chk = np.array([0.3, 0.5, 0.3, 0.4, 0.25, 0.55])
    gc = gradient_check(prob, x_chk)
    print(f"gradient check (jacfwd vs central differences): max rel. error "
          f"{gc['max_rel_error']:.2e}")

    al_res, al, al_trace = run_al(prob, X_START, tol=1e-4, max_outer=10 if a.quick else 30)
    x_al = np.asarray(al_res.x)
    after = prob.summary(x_al)
    al["objective_um"] = after["objective_um"]
    bf = best_feasible(al_trace)
    al["evaluations_to_within_1pct_of_final"] = next(
        (i + 1 for i, b in enumerate(bf) if b <= 1.01 * after["objective_um"]), None)
    al["evaluations_to_final_value"] = next(
        (i + 1 for i, b in enumerate(bf) if b <= after["objective_um"] + 1e-9), None)
    al["kink_check"] = one_sided(prob, x_al)
    print(f"augmented Lagrangian: {al['message']}, {al['outer_iterations']} outer, "
          f"{al['evaluations']} evaluations, {al['seconds']:.1f} s "
          f"(first call {al['seconds_first_call_incl_compile']:.1f} s); objective "
          f"{after['objective_um']:.4f} um, g {np.round(after['constraints'], 5)}")
    for k, v in variables_dict(x_al).items():
        print(f"  {k} = {v['value']:.3f} {v['unit']}")

    rng = np.random.default_rng(0)
    starts = [("start", X_START.copy())] + [(f"seed {s}", rng.uniform(0.0, 1.0, X_START.size))
                                            for s in range(1 if a.quick else 2)]
    al_seeds = []
    for label, x0 in starts[1:]:
        r, info, _tr = run_al(prob, x0, tol=1e-4, max_outer=10 if a.quick else 30,
                              warm=False)
        s = prob.summary(np.asarray(r.x))
        al_seeds.append({"start": label, "x0": x0.tolist(), "objective_um": s["objective_um"],
                         "constraints": s["constraints"], "evaluations": info["evaluations"],
                         "seconds": info["seconds"], "kkt_converged": info["kkt_converged"],
                         "variables": variables_dict(np.asarray(r.x))})
        print(f"augmented Lagrangian [{label}]: {info['message']}, objective "
              f"{s['objective_um']:.4f} um, {info['evaluations']} evaluations, "
              f"{info['seconds']:.1f} s")
    al["other_starts"] = al_seeds

    maxfev = 150 if a.quick else 1500
    dfs, df_info = {}, []
    xc, info, trace = run_cobyla(prob, X_START.copy(), maxfev)
    dfs["COBYLA"] = (trace, info)
    df_info.append((xc, info))
    for label, x0 in starts:
        xn, info, trace = run_nelder_mead(prob, x0, maxfev)
        info["start"] = label
        dfs[f"Nelder-Mead ({label})"] = (trace, info)
        df_info.append((xn, info))
    xd, info, trace = run_de(prob, 3 if a.quick else 40)
    info["start"] = "Latin hypercube population"
    dfs["differential evolution"] = (trace, info)
    df_info.append((xd, info))
    r, info, _tr = run_al(prob, np.clip(xd, 0.0, 1.0), tol=1e-4,
                          max_outer=10 if a.quick else 30, warm=False)
    s_pol = prob.summary(np.asarray(r.x))
    al["polish_of_differential_evolution"] = {
        "objective_um": s_pol["objective_um"], "constraints": s_pol["constraints"],
        "evaluations": info["evaluations"], "seconds": info["seconds"],
        "kkt_converged": info["kkt_converged"], "variables": variables_dict(np.asarray(r.x))}
    print(f"augmented Lagrangian from the differential-evolution point: {info['message']}, "
          f"objective {s_pol['objective_um']:.4f} um, {info['evaluations']} evaluations")
    df_out = []
    for xd, info in df_info:
        s = prob.summary(xd)
        info.update(objective_um=s["objective_um"], constraints=s["constraints"],
                    feasible=bool(max(s["constraints"]) <= FEAS_TOL),
                    variables=variables_dict(xd))
        tr = dfs[[k for k, v in dfs.items() if v[1] is info][0]][0]
        bf = best_feasible(tr)
        target = after["objective_um"] * 1.01
        hit = next((i + 1 for i, b in enumerate(bf) if b <= target), None)
        info["evaluations_to_within_1pct_of_al"] = hit
        df_out.append(info)
        print(f"{info['method']} [{info.get('start', 'start')}]: objective "
              f"{s['objective_um']:.4f} um, g {np.round(s['constraints'], 5)}, "
              f"{info['evaluations']} evaluations, {info['seconds']:.1f} s; within 1% of AL "
              f"after {hit} evaluations")

    factors = np.linspace(0.1, 1.6, 16 if a.quick else 31)
    sweeps = {"unmodified": torque_sweep(prob, X_START, factors),
              "optimised (augmented Lagrangian)": torque_sweep(prob, x_al, factors)}
    tag = "_worst" if a.worst else ""
    tag += "_quick" if a.quick else ""
    figures(prob, factors, sweeps, al, al_trace, dfs, before, tag)
    result = {
        "pair": {"z": [23, 67], "m_n_mm": 3.0, "alpha_n_deg": 20.0, "beta_deg": 20.0,
                 "face_width_mm": FACE_WIDTH, "x": [0.2, -0.1], "material": "steel",
                 "E_MPa": E_STEEL, "nu": NU_STEEL, "side": "drive"},
        "model": {"positions": positions, "slices": slices, "pairs": [k_lo, k_hi],
                  "compliance": "weber"},
        "design_torque_Nm": a.design_torque,
        "aligned_unmodified_p_max_at_design_MPa": aligned_design,
        "scenarios": {"torque_Nm": (a.design_torque * np.array(TORQUE_FACTORS)).tolist(),
                      "misalignment_um": list(MISALIGNMENTS_UM)},
        "objective": ("smooth max" if a.worst else "mean") + " over scenarios of smooth_ptp "
                     f"(T = {TEMPERATURE_UM} um) of the loaded TE",
        "constraints": [f"smooth max p_max / {P_ALLOW:g} MPa - 1 <= 0",
                        f"smooth max cycle-mean end-slice load ratio / {END_ALLOW} - 1 <= 0"],
        "seconds_per_evaluation_f_g": t_eval,
        "gradient_check": gc,
        "before": before, "after": after, "variables_after": variables_dict(x_al),
        "variables_before": variables_dict(X_START),
        "augmented_lagrangian": al, "derivative_free": df_out,
        "torque_sweep": {"factors": factors.tolist(),
                         "misalignment_um": list(MISALIGNMENTS_UM),
                         **{k: {"te_ptp_um": v[0].tolist(), "p_max_MPa": v[1].tolist()}
                            for k, v in sweeps.items()}},
    }
    (OUT / f"result{tag}.json").write_text(json.dumps(result, indent=1))
    print(f"wrote {OUT}/result{tag}.json")


if __name__ == "__main__":
    main()
