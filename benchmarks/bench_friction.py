"""Throughput of the friction model: μ for 1e5 contact points per call, forward and
gradient, the per-stage breakdown (Hertz ellipse, load sharing, shear integral, each
jitted alone on the same points), against a NumPy/SciPy per-point loop (same model,
same equations) on a subset, scaled.  Prints a table; not a test.

    python benchmarks/bench_friction.py [--points 100000] [--baseline-points 200] [--devices 2]

Before the fixed-step kernel (commit bcd37da, vmapped while-loop Newton solves with
line search, lax.map over chunks of 1024) this machine measured 4.4e4 points/s
forward and 3.8e4 points/s gradient at 2e4 points (docs/friction.md, Performance).
The first fixed-step kernel (commit afbe9cf: 48-node shear rule, pow-based film
formulas, 32-node load-sharing steps) measured 0.26 s of CPU per 1e5 points forward
(3.8e5 points per CPU-second) and 0.70 s gradient; stages 0.029 (Hertz), 0.113
(load sharing), 0.152 (shear) s of CPU per 1e5 points, in the same window as the
current figures of docs/friction.md.  The third pass (2026-11-29: the AGM unrolled and
the shear rule node by node for batches of 4096 points or more) took 1e5 points from
7.4e5 to 1.2e6 points/s forward and 2.8e5 to 4.1e5 gradient (docs/friction.md).  The
stage rows run the same routes as the kernel (same array sizes).

``--devices N`` (N > 1) sets ``XLA_FLAGS=--xla_force_host_platform_device_count=N``
before JAX starts and shards the points over the N CPU devices (a deployment option
of the calling program: the flag is process-wide and must be set before JAX
initialises, so the library does not set it).  A single CPU device already runs the
large fused kernels on all cores; measured gain of 2 devices: ~3 % (quiet machine).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np

# benchmark the checkout this file belongs to, not an installed gearjax
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def numpy_mu(F, ue, us, Rx, Ry, Ep, eta0, z, tau0, sigma, dens, beta, fc, vslip):
    """Per-point reference implementation with scipy (elliptic integrals, brentq, quad)."""
    from scipy.integrate import quad
    from scipy.optimize import brentq
    from scipy.special import ellipe, ellipkm1
    from scipy.stats import norm

    r = Ry / Rx

    def g(kp):
        K, E = ellipkm1(kp * kp), ellipe(1 - kp * kp)
        return (E / kp**2 - K) / (K - E) - r

    kp = brentq(g, 1e-7, 1 - 1e-6, xtol=1e-15)
    E = ellipe(1 - kp * kp)
    R = Rx * Ry / (Rx + Ry)
    b = (6 * E * kp * F * R / (math.pi * Ep)) ** (1 / 3)
    a = b / kp
    k = 1 / kp
    pmax = 1.5 * F / (math.pi * a * b)
    alpha = z * (math.log(eta0) + 9.67) * 5.1e-3
    KGT = 16 * math.sqrt(2) * math.pi / 15 * (dens * beta * sigma) ** 2 * math.sqrt(sigma / beta)

    def film(g1):
        Fe, Ee = F / g1, Ep / g1
        U = eta0 * 1e-6 * ue / (Ee * Rx)
        hp = Rx * 2.69 * U**0.67 * (alpha * Ee) ** 0.53 * (Fe / (Ee * Rx * Rx)) ** -0.067 * (1 - 0.61 * math.exp(-0.73 * k))
        hl = Rx * 2.922 * (0.75 * Fe / a / (Ee * Rx)) ** -0.166 * U**0.692 * (alpha * Ee) ** 0.47
        x = min(max(math.log(k / 8) / math.log(8), 0), 1)
        s = x * x * (3 - 2 * x)
        return hp ** (1 - s) * hl**s

    def logF52(lam):  # ln F_5/2 = ln φ(λ) + ln ∫ t^2.5 exp(-λt - t²/2) dt
        T = 60.0 / (lam + 5.0)  # the integrand is below e^-40 of its peak beyond T
        i = quad(lambda t: t**2.5 * math.exp(-lam * t - 0.5 * t * t), 0, T, limit=100)[0]
        return norm.logpdf(lam) + math.log(i)

    def res(sv):
        logphi = -np.logaddexp(0.0, -sv)
        hc = film(1.0 + math.exp(sv))  # γ1 = 1/(1-φ) = 1 + e^s
        return logphi - math.log(math.pi * a * b * KGT * Ep / F) - logF52(hc / sigma)

    sv = brentq(res, -700, 35, xtol=1e-12)
    phi = 1 / (1 + math.exp(-sv))
    hc = film(1.0 + math.exp(sv))

    def tau_s(s):
        p = (1 - phi) * pmax * s
        eta = eta0 * math.exp((math.log(eta0) + 9.67) * ((1 + p / (1 / 5.1e-3)) ** z - 1))
        return tau0 * math.asinh(eta * 1e-6 * us / (hc * tau0)) * s

    Ft = 2 * math.pi * a * b * quad(tau_s, 0, 1)[0]
    return fc * phi * math.tanh(us / vslip) + Ft / F


def random_contacts(n: int, seed: int = 0):
    """``(F, u_e, u_s, R_x, R_y)`` of ``n`` random contacts (N, mm/s, mm/s, mm, mm): the
    benchmark's points (also benchmarks/bench_devices.py)."""
    rng = np.random.default_rng(seed)
    F = rng.uniform(200, 3000, n)
    ue = rng.uniform(500, 20000, n)
    us = ue * rng.uniform(0.0, 0.5, n)
    Rx = rng.uniform(5, 30, n)
    Ry = Rx * rng.uniform(2, 200, n)
    return F, ue, us, Rx, Ry


def _stage_times(timeit, cpu_times, args_j, oil, surf, Ep):
    """Each stage of the kernel jitted alone on the same points (its inputs precomputed)."""
    import jax
    import jax.numpy as jnp

    from gearjax.contact import hertz_exact
    from gearjax.tribology.asperity import load_sharing_traced
    from gearjax.tribology.friction import _S, _WS, shear_integral
    from gearjax.tribology.lubricant import eyring_shear, viscosity

    F, ue, us, Rx, Ry = args_j
    hz_f = jax.jit(lambda F, Rx, Ry: hertz_exact(F, Rx, Ry, Ep))
    hz = hz_f(F, Rx, Ry)
    ls_f = jax.jit(lambda F, Rx, k, a, b, ue: load_sharing_traced(
        F, Rx, k, a, b, ue, oil.eta0, oil.alpha, Ep, surf.sigma, surf.density, surf.beta))
    ls = ls_f(F, Rx, hz.k, hz.a, hz.b, ue)

    def shear(phi, pmax, us, hc, a, b, F):
        X0 = oil.eta0 * 1e-6 * us / (hc * oil.tau0)
        return 2 * jnp.pi * a * b * oil.tau0 * shear_integral((1.0 - phi) * pmax, X0, oil) / F

    def shear_48(phi, pmax, us, hc, a, b, F):   # the former fixed 48-node rule in s
        p_f = ((1.0 - phi) * pmax)[:, None] * jnp.asarray(_S)
        tau = eyring_shear(viscosity(p_f, oil), us[:, None], hc[:, None], oil.tau0)
        return 2 * jnp.pi * a * b * jnp.sum(_WS * _S * tau, axis=-1) / F

    sh_f, sh48_f = jax.jit(shear), jax.jit(shear_48)
    sh_args = (ls.phi, hz.p_max, us, ls.h_c, hz.a, hz.b, F)
    runs = [("Hertz ellipse (hertz_exact)", hz_f, (F, Rx, Ry)),
            ("load sharing (load_sharing_traced)", ls_f, (F, Rx, hz.k, hz.a, hz.b, ue)),
            ("shear integral (16-node sinh-mapped)", sh_f, sh_args),
            ("(former 48-node shear rule, comparison)", sh48_f, sh_args)]
    return [(name, timeit(f, *a), cpu_times[f]) for name, f, a in runs]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--points", type=int, default=100_000)
    ap.add_argument("--baseline-points", type=int, default=200)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--devices", type=int, default=1,
                    help="shard over this many CPU devices (sets XLA_FLAGS before JAX starts)")
    args = ap.parse_args()

    if args.devices > 1:
        os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "") +
                                   f" --xla_force_host_platform_device_count={args.devices}")
    import jax
    import jax.numpy as jnp

    import gearjax  # noqa: F401
    from gearjax.tribology import get_oil, make_surface
    from gearjax.tribology.friction import friction_traced

    n = args.points
    F, ue, us, Rx, Ry = random_contacts(n)
    oil = get_oil("mineral_vg100")
    surf = make_surface(0.5)
    Ep = 226374.0
    args_j = [jnp.asarray(v) for v in (F, ue, us, Rx, Ry)]
    if args.devices > 1:
        from jax.sharding import Mesh, NamedSharding, PartitionSpec
        mesh = Mesh(np.array(jax.devices()[:args.devices]), ("points",))
        args_j = [jax.device_put(v, NamedSharding(mesh, PartitionSpec("points"))) for v in args_j]

    fwd = jax.jit(lambda F, ue, us, Rx, Ry: friction_traced(F, ue, us, Rx, Ry, oil, surf, Ep).mu)

    def total_mu(F, ue, us, Rx, Ry, eta0, sigma):
        o = oil.__class__(eta0, oil.z, oil.tau0, oil.rho0)
        s = surf.__class__(sigma, surf.density, surf.beta, surf.f_c, surf.v_slip)
        return jnp.sum(friction_traced(F, ue, us, Rx, Ry, o, s, Ep).mu)

    grad = jax.jit(jax.grad(total_mu, argnums=(0, 1, 2, 3, 4, 5, 6)))

    cpu_times = {}

    def timeit(fn, *a):
        """(first call incl. compile, best wall time of the repeats); the process CPU time
        of the best repeat goes to ``cpu_times`` (a loaded shared machine inflates wall
        time, not the CPU time of a single-threaded kernel)."""
        t0 = time.perf_counter()
        jax.block_until_ready(fn(*a))
        compile_s = time.perf_counter() - t0
        best, best_cpu = math.inf, math.inf
        for _ in range(args.repeats):
            t0, c0 = time.perf_counter(), time.process_time()
            jax.block_until_ready(fn(*a))
            best = min(best, time.perf_counter() - t0)
            best_cpu = min(best_cpu, time.process_time() - c0)
        cpu_times[fn] = best_cpu
        return compile_s, best

    c_f, t_f = timeit(fwd, *args_j)
    c_g, t_g = timeit(grad, *args_j, oil.eta0, surf.sigma)
    stages = _stage_times(timeit, cpu_times, args_j, oil, surf, Ep)

    m = args.baseline_points
    t0 = time.perf_counter()
    mu_np = [numpy_mu(F[i], ue[i], us[i], Rx[i], Ry[i], Ep, 0.088, float(oil.z), 5.0, 5e-4, 1e4, 1e-2,
                      0.1, 1.0) for i in range(m)]
    t_np = time.perf_counter() - t0
    mu_j = np.asarray(fwd(*args_j))[:m]
    agree = np.max(np.abs(np.asarray(mu_np) - mu_j) / np.abs(mu_j))

    print(f"gearjax friction benchmark ({jax.devices()[0].platform}, {os.cpu_count()} cores, "
          f"{len(jax.devices())} device(s), {n} points per call, load average "
          f"{os.getloadavg()[0]:.1f})")
    print(f"{'route':44s} {'points/s':>12s} {'call (s)':>10s} {'compile (s)':>12s} "
          f"{'CPU s/call':>11s}")
    print(f"{'JAX forward mu (jit)':44s} {n / t_f:12.4g} {t_f:10.3f} {c_f:12.2f} "
          f"{cpu_times[fwd]:11.3f}")
    print(f"{'JAX gradient of sum(mu) wrt 7 inputs':44s} {n / t_g:12.4g} {t_g:10.3f} {c_g:12.2f} "
          f"{cpu_times[grad]:11.3f}")
    print(f"{'NumPy/SciPy per-point loop (forward only)':44s} {m / t_np:12.4g} "
          f"{t_np * n / m:10.3f} {'-':>12s}   (timed on {m} points, scaled)")
    for name, (_, t), cpu in stages:
        print(f"{'  stage: ' + name:44s} {n / t:12.4g} {t:10.3f} {'-':>12s} {cpu:11.3f}")
    print(f"forward per CPU-second: {n / cpu_times[fwd]:.3g} points; gradient: "
          f"{n / cpu_times[grad]:.3g} points")
    print(f"speed-up of JAX forward over the loop: {(m / t_np) and (n / t_f) / (m / t_np):.0f}x; "
          f"max relative difference of mu on the subset: {agree:.1e}")


if __name__ == "__main__":
    main()
