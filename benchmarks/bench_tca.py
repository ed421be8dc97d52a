"""Benchmark: 61-position, 3-pair TCA (gearjax, jitted scan of implicit Newton solves)
against a SciPy ``fsolve`` loop over the same contact equations, and the cost of
one full TCA gradient (jacfwd of the TCA summary with respect to the four
misalignments and all design fields) against the forward run.

Pair: 25/41 spur, m 2, 20 deg, pinion with profile crown 0.002/mm and lead crown
0.001/mm (point contact, 5x5 system).  Prints a table; not a test.

    python benchmarks/bench_tca.py
"""

from __future__ import annotations

import time

import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import fsolve

import gearjax as gj
from gearjax.gears.involute.geometry import InvolutePair, generated_flank
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


def main():
    pair = InvolutePair.create(25, 41, 2.0, 20.0)
    des = InvoluteTCA.create(pair, 20.0, profile_crown=0.002, lead_crown=0.001)
    mis = Misalignment.zero()

    t0 = time.perf_counter()
    path, margin, multi = involute_tca(des, mis)
    t_first = time.perf_counter() - t0
    t_fwd = _best(lambda: involute_tca(des, mis, throw=False))

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

    t_scipy = _best(scipy_run, repeat=2)
    X = scipy_run()
    dphi2 = np.max(np.abs(X[:, 4] - np.asarray(path.phi2)))

    # the full gradient: jacfwd of the summary by the design and the misalignment
    # through the one traceable entry point, one program
    f = gj.tca_function(des, kinematics=False)

    def summary(d, m):
        res = f(d, m)
        return tca_summary(res.path, res.multi)

    grad = jax.jit(lambda d, m: (summary(d, m), jax.jacfwd(summary, argnums=(0, 1))(d, m)))
    t0 = time.perf_counter()
    jax.block_until_ready(grad(des, mis))
    t_grad_first = time.perf_counter() - t0
    t_grad = _best(lambda: grad(des, mis), repeat=3)

    print(f"{'task':58s} {'time':>10s}")
    lab0 = 'gearjax TCA, 61 positions x 3 pairs'
    print(f"{lab0 + ', first call (compile)':58s} {t_first:9.2f} s")
    print(f"{'gearjax TCA, 61 positions x 3 pairs, jitted':58s} {t_fwd * 1e3:8.2f} ms")
    print(f"{'SciPy fsolve loop, same equations (jitted F and J)':58s} {t_scipy * 1e3:8.2f} ms")
    lab = 'full gradient (jacfwd, 4 misalignments + 9 design)'
    print(f"{lab + ', compile':58s} {t_grad_first:9.2f} s")
    print(f"{lab + ', jitted':58s} {t_grad * 1e3:8.2f} ms")
    print(f"gradient / forward cost: {t_grad / t_fwd:.1f}x;  SciPy / gearjax: {t_scipy / t_fwd:.1f}x")
    print(f"max |phi2(SciPy) - phi2(gearjax)| = {dphi2:.2e} rad = {dphi2 / ARCSEC:.2e} arcsec; "
          f"TE p-t-p {float(multi.ptp) / ARCSEC:.4f} arcsec")


if __name__ == "__main__":
    main()
