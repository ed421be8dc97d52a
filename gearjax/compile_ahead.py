"""Compile the programs of one concrete run side by side, on the machine's other cores.

A concrete run (:func:`gearjax.run_tca`, :func:`gearjax.mesh_efficiency`, the command
line) calls two or three jitted programs one after the other, each needing the one
before's outputs.  The first call of each is dominated by its compilation: tracing
(Python, holds the interpreter lock), then XLA's passes and LLVM (C++, release it; on
2 cores the hypoid TCA spends about 3 s tracing and 9 s compiling).  Called one after
the other, the compilations queue behind each other on one core.

:class:`CompileAhead` traces and lowers each program in the calling thread -- the
next program from the abstract outputs of the one before (``jax.jit(...).trace``) --
and hands its XLA compilation to a worker thread, so that a program compiles while the
next is traced, and two compile at once.  Leaving the ``with`` block waits for every
compilation; the run then calls the jitted functions as usual and finds each in JAX's
own caches (tracing, lowering and executables are cached per abstract signature, so a
concrete call with the same shapes, dtypes and weak types hits what was compiled
ahead; JAX's persistent compilation cache serves a warm process as before).  A
program compiled ahead once in a process is not submitted again (after
``jax.clear_caches()`` it compiles on its call, as it would without this module).
Nothing changes in what is computed: the same jitted functions run on the same
arguments (the TCA as two programs: bit-identical on 54 TCAs of every family, their
sensitivity tables and two efficiencies).

With the program store on (:mod:`gearjax.program_store`, the command line), a program
is traced once per installation instead of once per process: :meth:`CompileAhead.submit`
reads (or writes) the stored program and compiles that, and :func:`call` runs it with
the executable compiled ahead.

:func:`prefetch` starts a compilation without waiting (abstract arguments allowed),
for a program a run needs only after other work; :data:`FAST_COMPILE_OPTIONS` are the
command line's XLA options, for one program.

Inside a trace (``jax.jit``, ``jax.grad`` of a :func:`gearjax.tca_function`) there is
nothing to compile ahead: :meth:`CompileAhead.submit` returns None and the caller
runs its stages inline in that trace (:func:`gearjax.tca.family._result`).  A
compilation that fails ahead is not reported here: the concrete call that follows
compiles again and raises the error where it belongs.
"""

from __future__ import annotations

import concurrent.futures
import os
import threading

import jax

from gearjax import program_store

__all__ = ["CompileAhead", "call", "prefetch", "first_time", "FAST_COMPILE_OPTIONS"]

#: XLA options that trade run time for compile time on the CPU, for a program compiled
#: once and run a few times (``jax.jit(f, compiler_options=FAST_COMPILE_OPTIONS)``; the
#: command line sets the same ones for its whole process, gearjax/cli.py): LLVM
#: optimisation level 0, XLA's older loop emitters, one LLVM module per program.  They
#: halve to third the compilation of gearjax's programs and about double their run time;
#: results agree to round-off (the test suite runs with them).  CPU only: on a GPU they
#: would slow the kernels down.
FAST_COMPILE_OPTIONS = {"xla_backend_optimization_level": 0,
                        "xla_cpu_use_fusion_emitters": False,
                        "xla_cpu_parallel_codegen_split_count": 1}

_POOL: concurrent.futures.ThreadPoolExecutor | None = None
_POOL_LOCK = threading.Lock()
#: (function, static arguments, abstract signature) -> abstract outputs, of every
#: program compiled ahead in this process
_DONE: dict = {}
#: the same key -> (abstract outputs, future) of a compilation not yet waited for
_RUNNING: dict = {}
#: (store directory, the same key) -> the program store's program (None: not stored)
_STORED: dict = {}
#: (store directory, the same key) -> (stored program, its executable compiled ahead)
_COMPILED: dict = {}
#: keys of the early starts made in this process (:func:`first_time`)
_STARTED: set = set()


def _pool() -> concurrent.futures.ThreadPoolExecutor:
    global _POOL
    with _POOL_LOCK:
        if _POOL is None:
            _POOL = concurrent.futures.ThreadPoolExecutor(
                max_workers=max(4, min(8, os.cpu_count() or 1)),
                thread_name_prefix="gearjax-compile")
        return _POOL


def _signature(args, static) -> tuple | None:
    """The key of a call: tree structure, abstract value of each leaf, static
    arguments; None where a leaf is a tracer (inside a trace: nothing to compile)."""
    leaves, tree = jax.tree.flatten(args)
    if any(isinstance(x, jax.core.Tracer) for x in leaves):
        return None
    return tree, tuple(jax.typeof(x) for x in leaves), tuple(sorted(static.items()))


class CompileAhead:
    """``with CompileAhead() as ahead: out = ahead.submit(f, *args, **static)`` (module
    docstring): ``f`` a ``jax.jit`` function, ``static`` its static arguments."""

    def __init__(self):
        self._pending = []

    def submit(self, fun, *args, **static):
        """Trace and lower ``fun(*args, **static)`` here, compile it on a worker thread;
        returns its abstract outputs (``jax.ShapeDtypeStruct`` leaves, the arguments of
        a next program), or None inside a trace (an argument is a tracer)."""
        sig = _signature(args, static)
        if sig is None:
            return None
        key = (fun, sig)
        if key in _DONE:
            return _DONE[key]
        if key not in _RUNNING:             # (else: submitted by :func:`prefetch`)
            prog = _stored(key, fun, args, static)
            if prog is not None:            # the program store's: not traced again
                traced, out = prog.trace(*args), prog.out_info
            else:
                traced = fun.trace(*args, **static)
                out = traced.out_info
            _RUNNING[key] = out, _pool().submit(traced.lower().compile), prog
        out, future, prog = _RUNNING[key]
        self._pending.append((key, out, future, prog))
        return out

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        for key, out, future, prog in self._pending:
            _RUNNING.pop(key, None)
            try:
                compiled = future.result()
            except Exception:   # the concrete call compiles again and raises it
                continue
            _DONE[key] = out
            if prog is not None:
                # the concrete call runs this executable: the stored program's results
                # are placed on the device (committed), and a jitted call on them would
                # compile once more for that placement
                _COMPILED[(program_store.directory(), key)] = prog, compiled
        self._pending = []
        return False


def _stored(key, fun, args, static):
    """The stored program of ``key`` (:mod:`gearjax.program_store`; read or exported
    once per process), or None when the store is off or the program not storable."""
    k = (program_store.directory(), key)
    if k not in _STORED:
        _STORED[k] = program_store.stored_program(fun, args, static)
    return _STORED[k]


def call(fun, *args, **static):
    """``fun(*args, **static)`` for a concrete run: by the program store's program
    when the store is on (:mod:`gearjax.program_store`: not traced again), else the
    jitted ``fun`` itself.  Inside a trace (an argument is a tracer): ``fun``."""
    if program_store.directory() is None:
        return fun(*args, **static)
    sig = _signature(args, static)
    if sig is None:
        return fun(*args, **static)
    key = (fun, sig)
    done = _COMPILED.get((program_store.directory(), key))
    if done is not None:
        prog, compiled = done
        return jax.tree.unflatten(prog.out_tree, compiled(*jax.tree.leaves(args)))
    prog = _stored(key, fun, args, static)
    return prog(*args) if prog is not None else fun(*args, **static)


def prefetch(fun, *args, **static):
    """Start compiling ``fun(*args, **static)`` (abstract arguments allowed:
    ``jax.ShapeDtypeStruct``) and go on without waiting: a later
    :meth:`CompileAhead.submit` of the same program (same abstract arguments) waits for
    this compilation instead of starting another.  For a program a run will need once
    work that does not feed its shapes is done (a set-up's solve compiles while the
    blank is computed).  Returns the abstract outputs, as :meth:`CompileAhead.submit`."""
    return CompileAhead().submit(fun, *args, **static)


def first_time(key) -> bool:
    """True the first time ``key`` is asked in this process.  An early start whose
    arguments cost something to build (a design file's flanks) is made once per key,
    not on every run: a later run finds its programs compiled, and a run whose programs
    differ compiles them side by side as usual."""
    if key in _STARTED:
        return False
    _STARTED.add(key)
    return True
