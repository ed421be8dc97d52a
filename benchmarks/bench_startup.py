"""Benchmark: the cost of first calls -- tracing, lowering, XLA compilation and the run.

For each job (the ``gearjax`` CLI main jobs, and the hypoid TCA, its gradient and
one local synthesis called from Python) two fresh Python processes are started
that share one new, empty persistent compilation cache directory:

* **cold**: the first process, empty cache: the job is run twice in the process;
  the first call's wall time is split with JAX's own monitoring events into
  tracing (Python -> jaxpr, ``/jax/core/compile/jaxpr_trace_duration``), lowering
  (jaxpr -> StableHLO) and XLA compilation (``backend_compile_duration``); the
  second call ("repeat") is the cost of a repeated call in the same process.
* **warm**: the second process, same cache: compilation is read from the cache,
  tracing and lowering are not (they are paid again in every process).

Every child also times one fixed reference program (trace + compile + run of a
small jitted function) and the table gives the cold first call as a multiple of
it ("x ref"), a ratio that carries across machines better than seconds.
``--binds`` adds a third child per job that counts primitive binds (calls of
``Primitive.bind``, the unit of tracing work) in the first call; it slows that
child down, so its times are not reported.

Usage (2-core CPU: the default set takes about 10 minutes)::

    python benchmarks/bench_startup.py                      # default jobs
    python benchmarks/bench_startup.py --jobs tca-hypoid,tca-grad --binds
    python benchmarks/bench_startup.py --jobs all           # + tca-grad, synthesis
    python benchmarks/bench_startup.py --list

``--wall`` times whole processes instead: each command of ``WALL`` (the console
command ``gearjax ...`` as a user types it, and ``python -c "import gearjax"``) is run
as a fresh Python process with ``GEARJAX_CACHE_DIR=off`` (no persistent compilation
cache: every process compiles from scratch), ``--repeat`` times (default 2), and the
minimum wall time is reported (process start to exit, output discarded)::

    python benchmarks/bench_startup.py --wall
    python benchmarks/bench_startup.py --wall --repeat 3 --json wall.json

``--wall-cached`` runs each command ``--repeat`` times (at least 2) sharing a new,
empty cache directory: the first run cold, the others warm (programs read back from
the program store, executables from the compilation cache), as a user's first and
later runs::

    python benchmarks/bench_startup.py --wall-cached --repeat 3

Results of past runs: ``benchmarks/results/startup_wall.md``.

Benchmarks are never tests.  Not for CI.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

HYPOID = "example:hft_8x43"
HYPOID_TCA = "example:hft_8x43_synthesised"   # localised bearing (the raw 8/43 set is not)
EFF_DESIGN = "example:hypoid_iso_10x41_synthesised"   # the packaged hypoid study's design

# name -> (description, kind, argument): kind "cli" runs gearjax.cli.main(argv)
JOBS = {
    "surface": ("gearjax surface (hypoid pinion flank, 41x21)", "cli",
                ["surface", HYPOID, "--member", "pinion", "--flank", "convex", "--grid", "41x21",
                 "--out", "{tmp}/flank.stl"]),
    "tca-hypoid": ("gearjax tca (hypoid 8/43 synthesised, drive)", "cli",
                   ["tca", HYPOID_TCA, "--pitches", "2"]),
    "tca-involute": ("gearjax tca (involute 20/40, crowned)", "cli",
                     ["tca", "involute:z1=20,z2=40,m=4,alpha=20,b=30,crown=0.001"]),
    "kinematics": ("gearjax kinematics (hypoid 6/39)", "cli",
                   ["kinematics", "example:hypoid_6x39_7p5in"]),
    "blank": ("gearjax blank (hypoid 8/43)", "cli", ["blank", HYPOID]),
    "friction": ("gearjax friction", "cli",
                 ["friction", "--load-N", "1000", "--rx-mm", "10", "--ry-mm", "300", "--ue", "5",
                  "--us", "1", "--oil", "mineral_vg100", "--sigma-um", "0.4"]),
    "efficiency": ("gearjax efficiency (spur 20/40, 200 N m, 1500 rpm)", "cli",
                   ["efficiency", "involute:z1=20,z2=40,m=4,alpha=20,b=30", "--torque-Nm", "200",
                    "--rpm", "1500", "--oil", "mineral_vg100", "--sigma-um", "0.4"]),
    "tca": ("run_tca hypoid (8/43 drive, prepare + TCA)", "py", "tca"),
    "tca-coast": ("run_tca hypoid drive, then coast (2nd side)", "py", "tca_coast"),
    "tca-grad": ("grad of TE p-t-p wrt pinion radial distance", "py", "tca_grad"),
    "synthesis": ("local synthesis (spiral bevel 10/30)", "py", "synthesis"),
    "eff": ("efficiency program, hypoid 10/41 (jit of efficiency_function)", "py", "eff"),
    "eff-grad": ("its gradient wrt every pair field (jit of grad)", "py", "eff_grad"),
}
DEFAULT = ["surface", "tca-hypoid", "tca-involute", "kinematics", "blank", "friction", "efficiency",
           "tca"]

# name -> gearjax argv for the whole-process (--wall) timings; None = only "import gearjax"
WALL = {
    "import": None,
    "example-list": ["example", "list"],
    "example-show-vh": ["example", "show", "vh_catt_17x23"],
    "tca-vh-11": ["tca", "example:vh_catt_17x23", "--positions", "11"],
    "tca-hypoid": ["tca", HYPOID_TCA, "--pitches", "2"],
    "efficiency": JOBS["efficiency"][2],
}

EVENTS = {"/jax/core/compile/jaxpr_trace_duration": "trace",
          "/jax/core/compile/jaxpr_to_mlir_module_duration": "lower",
          "/jax/core/compile/backend_compile_duration": "compile"}


# ------------------------------------------------------------------------- child side

def _py_job(name):
    import jax
    from dataclasses import replace

    import gearjax as gj
    from gearjax.gears.hypoid import tca as th
    from gearjax.gears.hypoid.design_file import load_design

    if name == "tca":
        def run():
            design = load_design(HYPOID_TCA)
            res = gj.run_tca(th.prepare(th.pair_flanks(design, "drive")), kinematics=False)
            return float(res.multi.ptp)
        return run
    if name == "tca_coast":
        def run():
            design = load_design(HYPOID_TCA)
            out = [float(gj.run_tca(th.prepare(th.pair_flanks(design, s)),
                                    kinematics=False).multi.ptp)
                   for s in ("drive", "coast")]
            return out
        return run
    if name == "tca_grad":
        def run():
            design = load_design(HYPOID_TCA)
            prep = th.prepare(th.pair_flanks(design, "drive"))
            f = gj.tca_function(prep, kinematics=False)

            def ptp(sr):
                pair = f.pair
                ms = replace(pair.pinion.machine, radial_distance=sr)
                return f(replace(pair, pinion=replace(pair.pinion, machine=ms))).multi.ptp
            return float(jax.jit(jax.grad(ptp))(f.pair.pinion.machine.radial_distance))
        return run
    if name in ("eff", "eff_grad"):
        from gearjax.loading.mesh_efficiency import efficiency_function

        # the loaded chain of the packaged hypoid study (200 N m, 1000 rpm), with the
        # command line's XLA options (one program each, as a study compiles them)
        f = efficiency_function(load_design(EFF_DESIGN))
        oil = gj.tribology.get_oil(gj.tribology.OILS[0])
        surf = gj.tribology.make_surface(0.4)

        def eta(pair):
            return f(pair, 200.0, 1000.0, oil, surf)[0].mean_efficiency
        fn = jax.jit(eta if name == "eff" else jax.grad(eta),
                     compiler_options=gj.FAST_COMPILE_OPTIONS)

        def run():
            return float(jax.tree.leaves(fn(f.pair))[0])
        return run
    if name == "synthesis":
        from gearjax.gears.hypoid import synthesis as sy

        def run():
            st = sy.start(load_design("example:spiral_bevel_10x30"), "drive")
            return bool(sy.synthesise(st).converged)
        return run
    raise ValueError(name)


def _reference():
    """Trace + compile + run of a fixed small program (the unit of the "x ref" column)."""
    import jax
    import jax.numpy as jnp

    def f(x):
        def body(c, _):
            y = jnp.sin(c) @ jnp.cos(c).T + 1e-3 * c
            return y / jnp.linalg.norm(y), jnp.trace(y)
        return jax.lax.scan(body, x, None, length=8)[1].sum()

    t = time.perf_counter()
    jax.block_until_ready(jax.jit(jax.grad(f))(jnp.eye(6)))
    return time.perf_counter() - t


def child(job, cache_dir, tmp, count_binds):
    import jax
    jax.config.update("jax_enable_x64", True)
    jax.config.update("jax_compilation_cache_dir", cache_dir)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
    acc = {v: 0.0 for v in EVENTS.values()}

    def listener(event, duration, **_):
        if event in EVENTS:
            acc[EVENTS[event]] += duration

    jax.monitoring.register_event_duration_secs_listener(listener)
    binds = [0]
    if count_binds:
        from jax._src import core
        orig = core.Primitive.bind

        def bind(self, *a, **k):
            binds[0] += 1
            return orig(self, *a, **k)
        core.Primitive.bind = bind

    t = time.perf_counter()
    import gearjax.cli  # noqa: F401  (imports jax and the package)
    t_import = time.perf_counter() - t
    ref = _reference()
    _, kind, arg = JOBS[job]
    if kind == "cli":
        from gearjax.cli import main
        argv = [a.format(tmp=tmp) for a in arg]

        def run():
            with contextlib.redirect_stdout(io.StringIO()):
                rc = main(argv)
            if rc:
                raise SystemExit(f"gearjax {' '.join(argv)} exited with {rc}")
    else:
        run = _py_job(arg)
    out = {"import": t_import, "ref": ref}
    for call in ("first", "repeat"):
        for k in acc:
            acc[k] = 0.0
        binds[0] = 0
        t = time.perf_counter()
        run()
        out[call] = time.perf_counter() - t
        out.update({f"{call}_{k}": v for k, v in acc.items()})
        out[f"{call}_binds"] = binds[0]
    print("RESULT " + json.dumps(out))


# ------------------------------------------------------------------------ parent side

def wall(names, repeat, cached=False):
    """Minimum over ``repeat`` fresh processes of the wall time of each ``WALL`` job
    (``GEARJAX_CACHE_DIR=off``); returns ``{name: [seconds of each run]}``.  With
    ``cached``: the processes of a job share a new, empty cache directory (compilation
    cache and program store), the first run is the cold one, the rest are warm; the
    line shows the first and the minimum of the rest."""
    env = dict(os.environ, GEARJAX_CACHE_DIR="off")
    # run outside any checkout: ``python -c`` puts the working directory first on
    # sys.path, so the package imported is the one the environment (PYTHONPATH) names
    cwd = tempfile.mkdtemp(prefix="gearjax-bench-wall-")
    out = {}
    for name in names:
        if cached:
            env["GEARJAX_CACHE_DIR"] = tempfile.mkdtemp(prefix="cache-", dir=cwd)
        argv = WALL[name]
        code = ("import gearjax" if argv is None else
                "import sys; from gearjax.cli import main; sys.argv[0] = 'gearjax'; "
                "raise SystemExit(main())")
        times = []
        for _ in range(repeat):
            t = time.perf_counter()
            p = subprocess.run([sys.executable, "-c", code] + (argv or []), env=env, cwd=cwd,
                               stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            times.append(time.perf_counter() - t)
            if p.returncode:
                raise RuntimeError(f"{name}: exit {p.returncode}: {p.stderr[-2000:]}")
        out[name] = times
        shown = " ".join(f"{x:.2f}" for x in times)
        if cached:
            warm = min(times[1:]) if len(times) > 1 else float("nan")
            print(f"{name:16s} cold {times[0]:7.2f}  warm {warm:7.2f}   (runs: {shown})",
                  flush=True)
        else:
            print(f"{name:16s} {min(times):7.2f}   (runs: {shown})", flush=True)
    shutil.rmtree(cwd, ignore_errors=True)
    import gearjax
    print(f"package: {os.path.dirname(gearjax.__file__)}")
    return out


def _spawn(job, cache_dir, tmp, binds=False):
    cmd = [sys.executable, os.path.abspath(__file__), "--child", job, "--cache", cache_dir,
           "--tmp", tmp] + (["--binds"] if binds else [])
    p = subprocess.run(cmd, capture_output=True, text=True)
    for line in p.stdout.splitlines():
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    raise RuntimeError(f"{job}: child failed (rc {p.returncode}):\n{p.stderr[-3000:]}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--jobs", default=",".join(DEFAULT),
                    help="comma-separated job names, or 'all' (see --list)")
    ap.add_argument("--binds", action="store_true", help="also count primitive binds")
    ap.add_argument("--no-warm", action="store_true", help="skip the warm-cache process")
    ap.add_argument("--json", default=None, help="write the raw numbers to this file")
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--wall", action="store_true",
                    help="whole-process wall times of the WALL commands, no compilation cache")
    ap.add_argument("--wall-cached", action="store_true",
                    help="as --wall, the runs of a command sharing a new cache: cold, then warm")
    ap.add_argument("--repeat", type=int, default=2, help="runs per --wall command (min shown)")
    ap.add_argument("--child", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--cache", default=None, help=argparse.SUPPRESS)
    ap.add_argument("--tmp", default=None, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.child:
        return child(args.child, args.cache, args.tmp, args.binds)
    if args.list:
        for k, (d, _, _) in JOBS.items():
            print(f"{k:14s} {d}{'  (default)' if k in DEFAULT else ''}")
        for k, a in WALL.items():
            cmd = 'python -c "import gearjax"' if a is None else "gearjax " + " ".join(a)
            print(f"{k:14s} --wall: {cmd}")
        return 0
    if args.wall or args.wall_cached:
        names = list(WALL) if args.jobs == ",".join(DEFAULT) else [
            j.strip() for j in args.jobs.split(",")]
        unknown = [j for j in names if j not in WALL]
        if unknown:
            ap.error(f"unknown --wall job(s) {unknown}; --list shows them")
        if args.wall_cached:
            print(f"seconds, {max(2, args.repeat)} fresh processes sharing a new cache")
        else:
            print(f"seconds, min of {args.repeat} fresh processes, GEARJAX_CACHE_DIR=off")
        res = wall(names, max(2, args.repeat) if args.wall_cached else args.repeat,
                   cached=args.wall_cached)
        if args.json:
            with open(args.json, "w") as fh:
                json.dump(res, fh, indent=1)
        return 0
    jobs = list(JOBS) if args.jobs == "all" else [j.strip() for j in args.jobs.split(",")]
    unknown = [j for j in jobs if j not in JOBS]
    if unknown:
        ap.error(f"unknown job(s) {unknown}; --list shows them")
    rows = {}
    hdr = (f"{'job':13s} {'cold 1st':>8s} {'trace':>6s} {'lower':>6s} {'compile':>7s} "
           f"{'run+py':>6s} {'x ref':>6s} {'repeat':>6s} {'warm 1st':>8s} {'w.trace':>7s} "
           f"{'w.comp':>6s}" + (f" {'binds':>8s}" if args.binds else ""))
    print("seconds; cold = empty compilation cache, warm = second process with that cache")
    print(hdr)
    for job in jobs:
        cache = tempfile.mkdtemp(prefix="gearjax-bench-cache-")
        tmp = tempfile.mkdtemp(prefix="gearjax-bench-out-")
        try:
            cold = _spawn(job, cache, tmp)
            warm = None if args.no_warm else _spawn(job, cache, tmp)
            nb = _spawn(job, tempfile.mkdtemp(dir=tmp), tmp, binds=True) if args.binds else None
        except RuntimeError as exc:
            print(f"{job:13s} FAILED: {str(exc)[-400:]}", flush=True)
            continue
        finally:
            shutil.rmtree(cache, ignore_errors=True)
            shutil.rmtree(tmp, ignore_errors=True)
        rows[job] = {"cold": cold, "warm": warm, "binds": nb}
        c = cold
        rest = c["first"] - c["first_trace"] - c["first_lower"] - c["first_compile"]
        line = (f"{job:13s} {c['first']:8.2f} {c['first_trace']:6.2f} {c['first_lower']:6.2f} "
                f"{c['first_compile']:7.2f} {rest:6.2f} {c['first'] / c['ref']:6.1f} "
                f"{c['repeat']:6.2f}")
        if warm:
            line += f" {warm['first']:8.2f} {warm['first_trace']:7.2f} {warm['first_compile']:6.2f}"
        else:
            line += f" {'-':>8s} {'-':>7s} {'-':>6s}"
        if nb:
            line += f" {nb['first_binds']:8d}"
        print(line, flush=True)
    if not rows:
        return 1
    ref = [r["cold"]["ref"] for r in rows.values()]
    print(f"reference program (x ref = 1): {min(ref):.2f} s (min over children); "
          f"import gearjax: {min(r['cold']['import'] for r in rows.values()):.2f} s")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
