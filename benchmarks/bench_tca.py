"""Benchmark: 61-position, 3-pair TCA (gearjax, jitted scan of implicit Newton solves)
against SciPy ``fsolve`` loops over the same contact equations, and the cost of one
full TCA gradient (jacfwd of the TCA summary with respect to the four misalignments
and all design fields) against the forward run; XLA's memory account of the traced
TCA and of its gradient (benchmarks/program_memory.py).

Pair: 25/41 spur, m 2, 20 deg, pinion with profile crown 0.002/mm and lead crown
0.001/mm (point contact, 5x5 system).  Three comparisons, each of the same work:

* the surface contact of tooth pair 0 (gearjax with ``face_ends=False``) against a
  SciPy loop over its positions;
* the whole TCA (surface contact and the ten edge candidates -- face ends, tip edges,
  corners -- continued over the grid, the contact made picked) against the SciPy
  surface loop plus a SciPy loop over the same edge-contact systems
  (:func:`gearjax.tca.edge_contact.edge_contact_system`) from the same start points,
  homotopy levels, predictors and give-up rule;
* the whole TCA against the surface loop alone (unlike work: what this benchmark
  printed before the edge loop was added).

The SciPy loops call jitted residuals and Jacobians, so they measure the solver
loop, not Python arithmetic.  Prints a table; not a test.

    python benchmarks/bench_tca.py
"""

from __future__ import annotations

import time
import warnings

import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import fsolve

import gearjax as gj
from program_memory import memory_cell, peak_rss_mb, program_memory
from gearjax.gears.involute.geometry import InvolutePair, generated_flank
from gearjax.tca.corners import CORNER_GIVE_UP, corner_end
from gearjax.tca.edge_contact import EDGE_NAMES, edge_contact_system, face_end_contact
from gearjax.tca.path import ARCSEC, contact_equations
from gearjax.tca.assembly import Misalignment
from gearjax.gears.involute.tca import (InvoluteTCA, reference_guess, crowned_pinion_flank,
                                        involute_assembly, tca_summary)


def involute_tca(des, mis, throw=True):
    """The contact path and TE envelope, edges and tips solved, no kinematics (what the
    SciPy loop computes, and more): the one entry point."""
    res = gj.run_tca(des, mis, kinematics=False, throw=throw)
    return res.path, res.margin, res.multi


def _best(f, repeat=5):
    ts = []
    for _ in range(repeat):
        t = time.perf_counter()
        jax.block_until_ready(f())
        ts.append(time.perf_counter() - t)
    return min(ts)


def edge_candidates():
    """``(pinion, e, tip, corner)`` of each edge candidate, from its name."""
    out = []
    for name in EDGE_NAMES:
        e = -1.0 if "toe" in name else (1.0 if "heel" in name else 0.0)
        out.append((float(name.startswith("pinion")), e, float("tip" in name),
                    float("corner" in name)))
    return out


def edge_setup(des, mis, steps_per_pitch):
    """The edge-contact system of the drive side, the surface path it starts from
    (gearjax, ``face_ends=False``) and gearjax's own edge contacts on that path (the
    candidates' TE, to check the SciPy loop against)."""
    fam = gj.family_of(des).fam
    r1, r2 = fam.flanks(des, True, False)
    parts, g1, g2, (t1, t2) = fam.edges(des)
    asm = fam.assembly(des)
    surf = gj.run_tca(des, mis, kinematics=False, face_ends=False, throw=False).path
    margin, _ = fam.boundaries(des, surf)
    edges = jax.jit(lambda sp, mg: face_end_contact(
        r1, r2, asm, mis, sp, mg, parts, g1, g2, drive=fam.forward(des, True), tips=(t1, t2),
        steps_per_pitch=steps_per_pitch)[2])(surf, margin)
    F, cs = edge_contact_system(r1, r2, asm, mis, g1, g2, t1, t2)
    return F, cs, (g1, g2, t1, t2), asm, surf, edges


def scipy_edge_loop(F, cs, fns, surf, n_homotopy=8, tol=1e-11):
    """The edge candidates of ``face_end_contact`` by ``fsolve``: for each, the start
    point (the reference for a face end, the converged grid point nearest the tip for
    a tip edge or corner), the homotopy ``s = 1 -> 0`` there, then the grid to its end
    and, from the homotopy's end, to its start; linear predictor from the two previous
    solutions (constant at the first step of each direction), a failed step keeps the
    previous solution, a tip/corner direction gives up after ``CORNER_GIVE_UP`` failed
    steps in a row.  Returns ``phi2`` per candidate and grid point (NaN: not solved)."""
    g1, g2, t1, t2 = fns
    Fj = jax.jit(F)
    Jj = jax.jit(jax.jacfwd(F))
    phis = np.asarray(surf.phi1)
    n = phis.size
    mid = n // 2
    conv = np.asarray(surf.converged)
    p1b, p2b = np.asarray(surf.p1_body), np.asarray(surf.p2_body)
    uv1, uv2, ph2 = np.asarray(surf.uv1), np.asarray(surf.uv2), np.asarray(surf.phi2)
    psi = [None if p is None else np.asarray(p) for p in (surf.psi1, surf.psi2)]
    vals = {}
    for pin, e, tip, corner in edge_candidates():
        fn = (t1 if pin else t2) if tip else (lambda q, e=e, g=(g1 if pin else g2): g(q, e))
        vals[(pin, e, tip)] = np.asarray(jax.vmap(fn)(jnp.asarray(p1b if pin else p2b)))
    ends = {e: np.asarray(jax.vmap(lambda a, b, e=e: corner_end(g1, g2, a, b, e))(
        jnp.asarray(p1b), jnp.asarray(p2b))) for e in (-1.0, 0.0, 1.0)}

    def f(z, th):
        return np.asarray(Fj(jnp.asarray(z), jnp.asarray(th)))

    def jac(z, th):
        return np.asarray(Jj(jnp.asarray(z), jnp.asarray(th)))

    def solve(pred, th):
        with warnings.catch_warnings():
            # a candidate that does not exist at a position (most tip edges) fails
            # there, as in gearjax; the residual test below decides
            warnings.simplefilter("ignore", RuntimeWarning)
            z = fsolve(f, pred, args=(th,), fprime=jac, xtol=1e-13)
        return z, bool(np.max(np.abs(f(z, th))) <= tol)

    out = np.full((len(EDGE_NAMES), n), np.nan)
    for k, (pin, e, tip, corner) in enumerate(edge_candidates()):
        gv = vals[(pin, e, tip)]
        i0 = int(np.argmin(np.where(conv, np.abs(gv), np.inf))) if tip and conv.any() else mid
        th0 = [phis[i0], 1.0, gv[i0], pin, e, tip, ends[e][i0], corner]
        z0 = np.asarray(cs.join(jnp.concatenate([uv1[i0], uv2[i0], ph2[i0][None]]),
                                *(None if p is None else p[i0] for p in psi)))
        prev, prev2, ok_h = z0, z0, True
        for s in np.linspace(1.0, 0.0, n_homotopy + 1)[1:]:
            z, ok = solve(2.0 * prev - prev2, [*th0[:1], s, *th0[2:]])
            prev, prev2 = (z, prev) if ok else (prev, prev2)
            ok_h = ok
        home = prev
        if ok_h:
            out[k, i0] = home[4]              # z = (u1, v1, u2, v2, phi2, psi...)
        for rng in (range(i0 + 1, n), range(i0 - 1, -1, -1)):
            prev, prev2, fails, first = home, home, 0, True
            for i in rng:
                if tip and (fails >= CORNER_GIVE_UP or not ok_h):
                    break
                pred = prev if first else 2.0 * prev - prev2
                first = False
                z, ok = solve(pred, [phis[i], 0.0, *th0[2:]])
                if ok:
                    prev, prev2, fails = z, prev, 0
                    if ok_h:
                        out[k, i] = z[4]
                else:
                    fails += 1
    return out


def main():
    pair = InvolutePair.create(25, 41, 2.0, 20.0)
    des = InvoluteTCA.create(pair, 20.0, profile_crown=0.002, lead_crown=0.001)
    mis = Misalignment.zero()

    t0 = time.perf_counter()
    path, margin, multi = involute_tca(des, mis)
    t_first = time.perf_counter() - t0
    t_fwd = _best(lambda: involute_tca(des, mis, throw=False), repeat=20)

    # SciPy: same equations, jitted residual and Jacobian, one fsolve per position,
    # previous solution as the start, from the reference outwards
    side = -1
    r1 = crowned_pinion_flank(des, side)
    r2 = generated_flank(pair.module, pair.pressure_angle, -pair.helix, pair.x2, pair.z2, side)
    F, _, _ = contact_equations(r1, r2, involute_assembly(pair), mis, False)
    Fj = jax.jit(F)
    Jj = jax.jit(jax.jacfwd(F))
    x_ref, _, _ = reference_guess(des, side)
    phis = np.asarray(path.phi1)
    mid = phis.size // 2
    Fj(jnp.asarray(x_ref), phis[mid]).block_until_ready()
    Jj(jnp.asarray(x_ref), phis[mid]).block_until_ready()

    def scipy_run():
        out = np.zeros((phis.size, 5))
        f = lambda x, p: np.asarray(Fj(jnp.asarray(x), p))     # noqa: E731
        j = lambda x, p: np.asarray(Jj(jnp.asarray(x), p))     # noqa: E731
        x = fsolve(f, np.asarray(x_ref), args=(phis[mid],), fprime=j, xtol=1e-13)
        out[mid] = x
        for rng in (range(mid + 1, phis.size), range(mid - 1, -1, -1)):
            xp = out[mid]
            for i in rng:
                xp = fsolve(f, xp, args=(phis[i],), fprime=j, xtol=1e-13)
                out[i] = xp
        return out

    t_scipy = _best(scipy_run, repeat=5)
    X = scipy_run()
    dphi2 = np.max(np.abs(X[:, 4] - np.asarray(path.phi2)))

    # the surface contact alone in gearjax (the work of the SciPy surface loop)
    t_surf = _best(lambda: gj.run_tca(des, mis, kinematics=False, face_ends=False,
                                      throw=False).path.te, repeat=20)
    # the edge candidates by SciPy, checked against gearjax's on the same surface path
    F_e, cs_e, fns, asm, surf, edges = edge_setup(des, mis, 24)
    scipy_edge_loop(F_e, cs_e, fns, surf)                 # compiles F and J
    t_edges = _best(lambda: scipy_edge_loop(F_e, cs_e, fns, surf), repeat=2)
    ph2_e = scipy_edge_loop(F_e, cs_e, fns, surf)
    sp = surf
    te_e = (np.asarray(sp.te)[mid] + asm.ratio_sign * (ph2_e - np.asarray(sp.phi2)[mid])
            - (asm.z1 / asm.z2) * (phis - phis[mid])[None, :])
    pitch = 2.0 * np.pi / asm.z2
    te_g = np.asarray(edges.te)
    both = np.isfinite(te_e) & np.isfinite(te_g)
    d = te_e[both] - te_g[both]
    d = d - np.round(d / pitch) * pitch
    dte_edges = float(np.max(np.abs(d))) if d.size else float("nan")
    n_valid = int(np.sum(np.asarray(edges.valid)))

    # the full gradient: jacfwd of the summary by the design and the misalignment
    # through the one traceable entry point, one program
    f = gj.tca_function(des, kinematics=False)

    def summary(d, m):
        res = f(d, m)
        return tca_summary(res.path, res.multi)

    def twice(d, m):
        s = summary(d, m)
        return s, s

    # the summary and its Jacobian from one forward-mode pass (the values as the primal
    # of the same pass; before 2026-11-29 the program ran the TCA a second time for them)
    grad = jax.jit(lambda d, m: jax.jacfwd(twice, argnums=(0, 1), has_aux=True)(d, m)[::-1])
    t0 = time.perf_counter()
    jax.block_until_ready(grad(des, mis))
    t_grad_first = time.perf_counter() - t0
    # XLA's memory account of the traced TCA and of its gradient (one program each)
    mem_fwd = program_memory(jax.jit(summary).trace(des, mis).lower().compile())
    mem_grad = program_memory(grad.trace(des, mis).lower().compile())
    t_grad = _best(lambda: grad(des, mis), repeat=10)

    print(f"{'task':58s} {'time':>10s}")
    lab0 = 'gearjax TCA, 61 positions x 3 pairs'
    print(f"{lab0 + ', first call (compile)':58s} {t_first:9.2f} s")
    print(f"{'gearjax TCA, 61 positions x 3 pairs, jitted':58s} {t_fwd * 1e3:8.2f} ms")
    print(f"{'gearjax surface contact only (face_ends=False), jitted':58s} {t_surf * 1e3:8.2f} ms")
    print(f"{'SciPy fsolve loop, surface contact (jitted F and J)':58s} {t_scipy * 1e3:8.2f} ms")
    print(f"{'SciPy fsolve loop, the 10 edge candidates':58s} {t_edges * 1e3:8.2f} ms")
    lab = 'full gradient (jacfwd, 4 misalignments + 9 design)'
    print(f"{lab + ', compile':58s} {t_grad_first:9.2f} s")
    print(f"{lab + ', jitted':58s} {t_grad * 1e3:8.2f} ms")
    print(f"gradient / forward cost: {t_grad / t_fwd:.1f}x")
    print(f"SciPy / gearjax, same work: surface {t_scipy / t_surf:.1f}x, "
          f"whole TCA (surface + edges) {(t_scipy + t_edges) / t_fwd:.1f}x; "
          f"surface loop / whole gearjax TCA (unlike work) {t_scipy / t_fwd:.1f}x")
    print(f"max |phi2(SciPy) - phi2(gearjax)| = {dphi2:.2e} rad = {dphi2 / ARCSEC:.2e} arcsec; "
          f"TE p-t-p {float(multi.ptp) / ARCSEC:.4f} arcsec")
    print(f"edge candidates: {n_valid} valid edge contacts in gearjax, max |TE(SciPy) - "
          f"TE(gearjax)| over {int(both.sum())} solved by both: {dte_edges / ARCSEC:.2e} arcsec")
    print(f"memory, MB peak (temporaries): traced TCA {memory_cell(mem_fwd)}, its gradient "
          f"{memory_cell(mem_grad)}; process peak RSS {peak_rss_mb():.0f} MB")


if __name__ == "__main__":
    main()
