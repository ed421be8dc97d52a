"""Programs compiled ahead side by side (gearjax/compile_ahead.py) are the programs the
run then calls: each traced once, compiled on a worker thread, found in JAX's caches by
the concrete call.

Planted bugs caught: abstract arguments of a next program that differ from the concrete
ones (a weak type or dtype lost: the concrete call traces and compiles a second time),
a submission that ignores its static arguments, ahead compilation inside a trace
(``submit`` must decline tracers), the memo that skips a program compiled once, a TCA
driver that no longer runs its two stages through :class:`CompileAhead` or hands a
next program an abstract result unlike the concrete one.  (That the efficiency program
is offered to the TCA's compilation: tests/test_mesh_efficiency.py.)
"""

import logging

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax as gj
import gearjax.compile_ahead as ca
from gearjax.compile_ahead import CompileAhead
from test_family_driver import TOY, _toy


class _Log(logging.Handler):
    """JAX's compile log (``jax_log_compiles``): (message, thread name) records."""

    def __init__(self):
        super().__init__(logging.WARNING)
        self.records = []

    def emit(self, record):
        self.records.append((record.getMessage(), record.threadName))

    def traces(self, name):
        return sum(m.startswith(f"Finished tracing {name} ") for m, _ in self.records)

    def compile_threads(self, name):
        return [t for m, t in self.records if m.startswith("Finished XLA compilation")
                and f"jit({name})" in m]


class _CountingTrace:
    """A jitted function that counts its ``trace`` calls."""

    def __init__(self, fun):
        self.fun, self.n = fun, 0

    def trace(self, *args, **static):
        self.n += 1
        return self.fun.trace(*args, **static)


@pytest.fixture
def compile_log():
    log = _Log()
    logger = logging.getLogger("jax")
    logger.addHandler(log)
    was = jax.config.jax_log_compiles
    # globally: a config context is thread-local, the compilations run on other threads
    jax.config.update("jax_log_compiles", True)
    try:
        yield log
    finally:
        jax.config.update("jax_log_compiles", was)
        logger.removeHandler(log)


def test_next_program_from_abstract_outputs_is_traced_once(compile_log):
    """A chain of two programs (the second on the first's abstract outputs, a weak-typed
    scalar among them) and a static argument: each traced once, compiled on a worker
    thread, the concrete calls hit; a second submission is served by the memo."""
    @jax.jit
    def first(x, a):
        return {"y": jnp.sin(x) * a, "s": jnp.sum(x), "w": a * 2.0}

    def second_(d, *, k):
        return d["y"] * k + d["s"] + d["w"]
    second = jax.jit(second_, static_argnames="k")

    x = jnp.linspace(0.0, 1.0, 5)
    with CompileAhead() as ahead:
        out = ahead.submit(first, x, 3.0)
        assert jax.typeof(out["w"]).weak_type          # the weak type travels
        ahead.submit(second, out, k=4)
    got = second(first(x, 3.0), k=4)
    np.testing.assert_allclose(np.asarray(got), np.sin(np.linspace(0, 1, 5)) * 12.0 + 2.5 + 6.0,
                               rtol=1e-14)
    assert compile_log.traces("first") == 1 and compile_log.traces("second_") == 1
    threads = compile_log.compile_threads("first") + compile_log.compile_threads("second_")
    assert threads and all(t.startswith("gearjax-compile") for t in threads), threads
    # compiled ahead once: a second submission traces nothing (not even a hit in JAX's
    # trace cache: the memo answers)
    counted = _CountingTrace(first)
    with CompileAhead() as ahead:
        ahead.submit(counted, x, 3.0)
    with CompileAhead() as ahead:
        assert jax.typeof(ahead.submit(counted, x, 3.0)["s"]) == jax.typeof(jnp.float64(0.0))
    assert counted.n == 1 and compile_log.traces("first") == 1
    # another static argument is another program
    with CompileAhead() as ahead:
        ahead.submit(second, out, k=5)
    assert compile_log.traces("second_") == 2


def test_inside_a_trace_nothing_is_compiled_ahead():
    f = jax.jit(lambda x: 2.0 * x)
    seen = []

    def g(x):
        with CompileAhead() as ahead:
            seen.append(ahead.submit(f, x))
        return f(x)
    assert float(jax.jit(g)(1.5)) == 3.0 and float(jax.grad(g)(1.5)) == 2.0
    assert seen == [None, None]


def test_the_tca_runs_its_two_programs_compiled_ahead(compile_log):
    """The concrete TCA (toy family, a grid no other test uses): both stages traced
    once and compiled on worker threads; ``also`` is offered the abstract result, whose
    every leaf has the concrete result's abstract value (else a program compiled on it
    would compile again when called)."""
    des = _toy(18, 31)
    seen = []
    res = TOY.run(des, side="drive", steps_per_pitch=11, also=lambda a, r: seen.append(r))
    assert compile_log.traces("_surface_program") == 1
    assert compile_log.traces("_finish_program") == 1
    for name in ("_surface_program", "_finish_program"):
        threads = compile_log.compile_threads(name)
        assert threads and all(t.startswith("gearjax-compile") for t in threads), (name, threads)
    assert len(seen) == 1
    abstract = jax.tree.map(jax.typeof, seen[0])
    concrete = jax.tree.map(jax.typeof, res)
    assert jax.tree.structure(abstract) == jax.tree.structure(concrete)
    assert jax.tree.leaves(abstract) == jax.tree.leaves(concrete)
    assert (seen[0].side, seen[0].family) == ("drive", "toy_spur")
    # and the two-program run is the one-program traced TCA
    f = gj.tca_function(des, side="drive", steps_per_pitch=11)
    one = jax.jit(lambda p: f(p).path.te)(f.pair)
    np.testing.assert_allclose(np.asarray(res.path.te), np.asarray(one), rtol=0, atol=1e-15)



def test_prefetch_then_submit_waits_for_the_same_compilation(compile_log):
    """:func:`prefetch` on abstract arguments starts the compilation; a submission of the
    same program on concrete arguments later waits for it (one trace, no second
    compilation) and the concrete call hits."""
    @jax.jit
    def third(x, n):
        return jnp.cumsum(x) * n

    ca.prefetch(third, jax.ShapeDtypeStruct((4,), jnp.float64),
                jax.ShapeDtypeStruct((), jnp.float64))
    x = jnp.arange(4.0)
    with CompileAhead() as ahead:
        ahead.submit(third, x, jnp.float64(2.0))
    np.testing.assert_array_equal(np.asarray(third(x, jnp.float64(2.0))), [0.0, 2.0, 6.0, 12.0])
    assert compile_log.traces("third") == 1
    assert len(compile_log.compile_threads("third")) == 1
    assert not ca._RUNNING


def test_hypoid_mean_points_prefetched_as_they_run(monkeypatch, compile_log, cold_jax_caches):
    """The hypoid set-up starts compiling its mean-point programs before the blank is
    computed (``mean_points_ahead``); they must be the programs ``mean_points`` then
    submits and calls: the same abstract signatures (a crossing point of another dtype
    or weak type, or another flank, would compile a second program): two traces, one
    per member (JAX's caches cleared before the test)."""
    from gearjax.gears.hypoid.pair import mean_points, mean_points_ahead, pair_flanks
    monkeypatch.setattr(ca, "_STARTED", set())     # as in a fresh process
    keys = []
    orig = CompileAhead.submit

    def spy(self, fun, *args, **static):
        keys.append((fun.__name__, ca._signature(args, static)))
        return orig(self, fun, *args, **static)
    monkeypatch.setattr(CompileAhead, "submit", spy)
    d = gj.load_design(gj.example_path("hft_8x43_synthesised"))
    mean_points_ahead(d, "coast")
    mean_points(pair_flanks(d, "coast"))
    assert len(keys) == 4 and keys[:2] == keys[2:], keys
    assert compile_log.traces("_mean_point") == 2
    assert keys[0][1] != keys[1][1]            # pinion and gear: two programs


@pytest.mark.parametrize("side", ["drive", "coast"])
def test_hypoid_tca_compiled_before_its_set_up_is_the_one_run(monkeypatch, side):
    """A hypoid design file's TCA programs start compiling from the family's
    ``early_setup`` (placeholder crossing points, reference and sense), before the blank
    and the reference search; the run's own submissions must have the same abstract
    arguments, or the early compilations are wasted and the run compiles again.
    Traced only: the compilations are replaced by their abstract outputs, and the run
    stops before it compiles."""
    import gearjax.tca.family as family

    early, real = [], []

    class Stop(Exception):
        pass

    def fake_prefetch(fun, *args, **static):
        early.append((fun.__name__, ca._signature(args, static)))
        return fun.trace(*args, **static).out_info

    orig = CompileAhead.submit

    def fake_submit(self, fun, *args, **static):
        if fun.__name__ not in ("_surface_program", "_finish_program"):
            return orig(self, fun, *args, **static)          # the set-up's mean points
        real.append((fun.__name__, ca._signature(args, static)))
        if len(real) == 2:
            raise Stop
        return fun.trace(*args, **static).out_info
    monkeypatch.setattr(family, "prefetch", fake_prefetch)
    monkeypatch.setattr(CompileAhead, "submit", fake_submit)
    monkeypatch.setattr(ca, "_STARTED", set())     # as in a fresh process
    d = gj.load_design(gj.example_path("hft_8x43_synthesised"))
    with pytest.raises(Stop):
        gj.run_tca(d, side=side, half_pitches=2.0)
    assert [n for n, _ in early] == ["_surface_program", "_finish_program"]
    assert early == real
    # once per option set: a second run builds no early arguments
    early.clear()
    real.clear()
    with pytest.raises(Stop):
        gj.run_tca(d, side=side, half_pitches=2.0)
    assert early == [] and len(real) == 2
