"""Benchmark: throughput of the four kernels on every kind of device of this machine.

The same script runs unchanged on a CPU-only machine and on a CUDA machine (install
``pip install -e ".[gpu]"``, the ``jax[cuda12]`` extra): each kernel is jitted, its
inputs are placed on the device (``jax.device_put``) and it is timed there, on the
default device (a GPU where JAX finds one) and on the CPU; the table gives the rate on
each and their ratio.

Kernels (float64 throughout, as the library computes):

* **flank points/s**: the 41 x 21 hypoid flank grid of ``benchmarks/bench_hypoid_surface.py``
  (8/43 pinion, convex flank), vmapped over ``--designs`` pinions whose radial
  distance differs (``jax.vmap`` of :func:`gearjax.gears.hypoid.flank.flank_points`);
* **TCAs/s**: the traced TCA of ``benchmarks/bench_tca.py``'s crowned 25/41 spur pair
  (61 positions x 3 pairs, edges solved), vmapped over ``--designs`` profile crowns;
* **friction points/s**: ``friction_traced`` on ``--points`` random contacts (the
  inputs of ``benchmarks/bench_friction.py``);
* **sweep designs/s**: the evaluator of the ``spur_sliding`` study
  (:func:`gearjax.studies.sweep.sweep_program`) on ``--designs`` Latin-hypercube
  designs, one device.

Each rate is the best of ``--repeats`` calls after a first (compiling) call.  Usage::

    python benchmarks/bench_devices.py                     # default device and CPU
    python benchmarks/bench_devices.py --designs 256 --points 1000000

Results: ``benchmarks/results/devices.md``.  Benchmarks are never tests.  Not for CI.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import time


# benchmark the checkout this file belongs to, not an installed gearjax; the
# benchmarks' own helpers (bench_friction's points)
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def _best(fn, args, repeats):
    """(first call incl. compile, best of ``repeats`` calls) in seconds."""
    import jax
    t = time.perf_counter()
    jax.block_until_ready(fn(*args))
    first = time.perf_counter() - t
    best = float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        jax.block_until_ready(fn(*args))
        best = min(best, time.perf_counter() - t)
    return first, best


def flank_kernel(n, device):
    """``(fn, args, units)``: n hypoid flank grids of 861 points."""
    import jax
    import jax.numpy as jnp

    from gearjax.gears.hypoid.design_file import load_design
    from gearjax.gears.hypoid.flank import flank_points, program_pair

    fl = program_pair(load_design("example:hft_8x43").flank("pinion", "convex"))
    sr = fl.machine.radial_distance + jnp.linspace(-1.0, 1.0, n)

    def one(r):
        f = dataclasses.replace(fl, machine=dataclasses.replace(fl.machine, radial_distance=r))
        return flank_points(f, 41, 21).points
    return jax.jit(jax.vmap(one)), (sr,), n * 41 * 21


def tca_kernel(n, device):
    """``(fn, args, units)``: n TCAs of the crowned 25/41 spur pair."""
    import jax
    import jax.numpy as jnp

    import gearjax as gj
    from gearjax.gears.involute.geometry import InvolutePair
    from gearjax.gears.involute.tca import InvoluteTCA

    des = InvoluteTCA.create(InvolutePair.create(25, 41, 2.0, 20.0), 20.0,
                             profile_crown=0.002, lead_crown=0.001)
    f = gj.tca_function(des, kinematics=False)
    crowns = 0.002 * jnp.linspace(0.8, 1.2, n)

    def one(c):
        return f(dataclasses.replace(f.pair, profile_crown=c)).multi.ptp
    return jax.jit(jax.vmap(one)), (crowns,), n


def friction_kernel(n, device):
    """``(fn, args, units)``: friction at n random contacts."""
    import jax
    import jax.numpy as jnp

    from gearjax.tribology import get_oil, make_surface
    from gearjax.tribology.friction import friction_traced

    from bench_friction import random_contacts

    F, ue, us, Rx, Ry = random_contacts(n)
    oil, surf = get_oil("mineral_vg100"), make_surface(0.5)
    fn = jax.jit(lambda F, ue, us, Rx, Ry: friction_traced(F, ue, us, Rx, Ry, oil, surf,
                                                           226374.0).mu)
    return fn, tuple(jnp.asarray(v) for v in (F, ue, us, Rx, Ry)), n


def sweep_kernel(n, device):
    """``(fn, args, units)``: the spur_sliding study at n designs on ``device``."""
    import jax.numpy as jnp

    from gearjax.studies.study_file import read_study
    from gearjax.studies.sweep import sample_points, set_up_sweep, sweep_program

    prob = set_up_sweep(read_study("example:spur_sliding"))
    prog, _, _ = sweep_program(prob, [device])
    U = jnp.asarray(sample_points(prob.lower, prob.upper, "random", samples=n)[:n])
    return (lambda U, data: prog(U, data)[0]), (U, prob.data), n


#: name -> ``kernel(batch, device) -> (fn, args, units)`` (the sweep's program is laid
#: out on the device itself; the others run where their arguments are)
KERNELS = {"flank points/s": flank_kernel, "TCAs/s": tca_kernel,
           "friction points/s": friction_kernel, "sweep designs/s": sweep_kernel}


def measure(name, size, device, repeats):
    """(first call s, units per second) of kernel ``name`` on ``device``."""
    import jax

    with jax.default_device(device):
        fn, args, units = KERNELS[name](size, device)
        args = jax.device_put(args, device)
        first, best = _best(fn, args, repeats)
    return first, units / best


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=32, help="designs per batched call")
    ap.add_argument("--points", type=int, default=100_000, help="friction contacts per call")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--only", default=None, help="comma-separated kernel names (see the table)")
    args = ap.parse_args(argv)
    import jax

    import gearjax  # noqa: F401 - float64

    default = jax.devices()[0]
    cpu = jax.devices("cpu")[0]
    devices = [default] if default.platform == "cpu" else [default, cpu]
    names = list(KERNELS) if not args.only else [n.strip() for n in args.only.split(",")]
    print(f"devices: {', '.join(f'{d.platform}:{d.device_kind}' for d in devices)}; jax "
          f"{jax.__version__}; {os.cpu_count()} CPU cores; float64")
    head = " | ".join(f"{d.platform} (first call s / rate)" for d in devices)
    print(f"| kernel | batch | {head} |" + (" ratio |" if len(devices) > 1 else ""))
    print("|---|---:|" + "---:|" * (len(devices) + (len(devices) > 1)))
    for name in names:
        size = args.points if name.startswith("friction") else args.designs
        got = [measure(name, size, d, args.repeats) for d in devices]
        cells = " | ".join(f"{first:.1f} / {rate:.4g}" for first, rate in got)
        ratio = f" {got[0][1] / got[1][1]:.2f}x |" if len(got) > 1 else ""
        print(f"| {name} | {size} | {cells} |{ratio}", flush=True)


if __name__ == "__main__":
    main()
