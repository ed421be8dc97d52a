"""The program store (gearjax/program_store.py): a traced program written by one
process and read by the next runs the same computation, and the key tells programs
apart.

"A process" is simulated by forgetting what this one holds
(``compile_ahead._STORED``, JAX's caches): the next call then reads the file.

Planted bugs caught: a key that ignores a static argument, the argument shapes or the
source digest (two programs share a file: wrong shapes or stale code run); a lambda or
a closure stored by its name (its captured values are not in the key); an unreadable
file that raises instead of being traced again (or stays behind); the written program
not the one read back (weak types of the results: the next program's key differs
between the first run and the later ones, so every run writes again); the result tree
lost (a named tuple comes back as a list); the store used while it is off; the TCA
through the store not bit-identical to the plain run.
"""

from argparse import Namespace
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import gearjax.compile_ahead as ca
from gearjax import program_store as ps
from gearjax.compile_ahead import CompileAhead, call
from test_compile_ahead import compile_log  # noqa: F401 - the fixture
from test_family_driver import TOY, _toy


class Out(NamedTuple):
    y: jax.Array
    total: jax.Array


@jax.jit
def _scaled(x, k):
    return Out(x * k, jnp.sum(x) * k)


@pytest.fixture
def store(tmp_path, monkeypatch):
    """The store on in a fresh directory; the counters and this process's memo reset."""
    monkeypatch.setattr(ca, "_STORED", {})
    monkeypatch.setattr(ps, "STATS", {k: 0 for k in ps.STATS})
    ps.enable(tmp_path / "programs")
    try:
        yield tmp_path / "programs"
    finally:
        ps.disable()


def _new_process(monkeypatch):
    monkeypatch.setattr(ca, "_STORED", {})
    monkeypatch.setattr(ca, "_DONE", {})
    monkeypatch.setattr(ca, "_COMPILED", {})
    jax.clear_caches()


def test_written_then_read_by_the_next_process(store, monkeypatch):
    x = jnp.linspace(0.0, 1.0, 5)
    plain = _scaled(x, 3.0)
    first = call(_scaled, x, 3.0)
    assert ps.STATS["written"] == 1 and ps.STATS["loaded"] == 0
    files = sorted(store.glob("*.prog"))
    assert len(files) == 1 and files[0].name.startswith("scaled-")
    _new_process(monkeypatch)
    second = call(_scaled, x, 3.0)
    assert ps.STATS["loaded"] == 1 and ps.STATS["written"] == 1
    for got in (first, second):
        assert isinstance(got, Out)
        np.testing.assert_array_equal(np.asarray(got.y), np.asarray(plain.y))
        assert float(got.total) == float(plain.total)
    # another shape is another program
    call(_scaled, jnp.ones(3), 3.0)
    assert len(list(store.glob("*.prog"))) == 2


def test_off_by_default_and_nothing_written(tmp_path, monkeypatch):
    monkeypatch.setattr(ps, "STATS", {k: 0 for k in ps.STATS})
    assert ps.directory() is None
    np.testing.assert_array_equal(np.asarray(call(_scaled, jnp.ones(2), 2.0).y), [2.0, 2.0])
    assert ps.STATS == {k: 0 for k in ps.STATS}


def test_static_arguments_in_the_key():
    args = (jnp.ones(2),)
    k1 = ps.program_key(_scaled, args, {"n": 1})
    k2 = ps.program_key(_scaled, args, {"n": 2})
    assert k1 != k2
    assert ps.static_key(TOY.fam).endswith("ToySpur")
    assert ps.static_key(TOY.fam.flanks).endswith("ToySpur.flanks")
    assert (ps.static_key((1, 2.0, "a", None, True))
            == "(int:1,float:2.0,str:'a',NoneType:None,bool:True)")
    assert ps.static_key(1) != ps.static_key(1.0) != ps.static_key(True)
    with pytest.raises(ps.Unstorable):
        ps.static_key(lambda x: x)
    n = 3

    def closure(x):
        return x ** n
    with pytest.raises(ps.Unstorable):
        ps.static_key(closure)
    with pytest.raises(ps.Unstorable):
        ps.static_key(object())


def test_source_digest_in_the_key(monkeypatch):
    args = (jnp.ones(2), 1.0)
    k = ps.program_key(_scaled, args, {})
    monkeypatch.setattr(ps, "_DIGEST", "0" * 64)
    assert ps.program_key(_scaled, args, {}) != k


def test_unstorable_static_traced_as_usual(store):
    f = jax.jit(lambda x, g: g(x), static_argnames="g")
    got = call(f, jnp.float64(2.0), g=lambda v: v + 1.0)
    assert float(got) == 3.0
    assert ps.STATS["refused"] == 1 and not list(store.glob("*.prog"))


@pytest.mark.parametrize("damage", ["truncated", "foreign"])
def test_unreadable_file_dropped_and_traced_again(store, monkeypatch, damage):
    x = jnp.arange(3.0)
    call(_scaled, x, 2.0)
    (f,) = store.glob("*.prog")
    data = f.read_bytes()
    f.write_bytes(data[:len(data) // 3] if damage == "truncated" else b"PK\x03\x04" + data[4:])
    _new_process(monkeypatch)
    got = call(_scaled, x, 2.0)
    np.testing.assert_array_equal(np.asarray(got.y), [0.0, 2.0, 4.0])
    assert ps.STATS["dropped"] == 1 and ps.STATS["written"] == 2
    (g,) = store.glob("*.prog")
    assert g.name == f.name and not list(store.glob(".tmp-*"))
    _new_process(monkeypatch)                 # written again, whole: the next run reads it
    np.testing.assert_array_equal(np.asarray(call(_scaled, x, 2.0).total), 6.0)
    assert ps.STATS["loaded"] == 1 and ps.STATS["dropped"] == 1


def test_oldest_files_pruned(store, monkeypatch):
    monkeypatch.setattr(ps, "MAX_FILES", 2)
    for n in range(4):
        call(_scaled, jnp.ones(n + 1), 1.0)
    assert len(list(store.glob("*.prog"))) == 2


def test_compiled_ahead_programs_keep_their_keys_across_processes(store, monkeypatch):
    """The toy TCA's two programs (the second takes the first's result): the first run
    writes two programs, the next reads both and writes nothing -- the abstract result
    handed to the second program is the same in both (no weak type lost on the way) --
    and all three runs are bit-identical."""
    des = _toy(17, 29)
    ps.disable()
    plain = TOY.run(des, side="drive", steps_per_pitch=9)
    ps.enable(store)
    first = TOY.run(des, side="drive", steps_per_pitch=9)
    assert ps.STATS["written"] == 2, ps.STATS
    _new_process(monkeypatch)
    second = TOY.run(des, side="drive", steps_per_pitch=9)
    assert ps.STATS["written"] == 2 and ps.STATS["loaded"] == 2, ps.STATS
    names = sorted(f.name.split("-")[0] for f in store.glob("*.prog"))
    assert names == ["finish_program", "surface_program"]
    for got in (first, second):
        assert jax.tree.structure(got) == jax.tree.structure(plain)
        for a, b in zip(jax.tree.leaves(got), jax.tree.leaves(plain)):
            np.testing.assert_array_equal(np.asarray(a), np.asarray(b))


def test_submit_then_call_compiles_once(store, compile_log):
    """A program compiled ahead from the store is the one the concrete call runs, also
    on arguments that a stored program returned (placed on the device: a jitted call on
    them would compile once more for that placement)."""
    x = jnp.arange(4.0)
    with CompileAhead() as ahead:
        out = ahead.submit(_scaled, x, 5.0)
        ahead.submit(_scaled, out.y, 5.0)
    assert isinstance(out, Out) and out.y.shape == (4,)
    got = call(_scaled, x, 5.0)
    call(_scaled, got.y, 5.0)
    compiling = [m for m, _ in compile_log.records if m.startswith("Compiling jit(call)")]
    assert len(compiling) == 1, compiling
    np.testing.assert_array_equal(np.asarray(got.y), 5.0 * np.arange(4.0))
    assert ps.STATS["written"] == 1 and ps.STATS["loaded"] == 0
    assert len(ca._STORED) == 1


@jax.jit
def _mixed(x, y):
    return x * y


def test_weak_and_strong_arguments_are_two_programs(store, monkeypatch):
    """A Python float and a float64 array promote differently against float32: one
    program for each (a key without the weak type would run the first for both and
    return float32 where float64 is due)."""
    y = jnp.ones(3, jnp.float32)
    weak = call(_mixed, 2.0, y)
    _new_process(monkeypatch)
    strong = call(_mixed, jnp.float64(2.0), y)
    assert weak.dtype == jnp.float32 and strong.dtype == jnp.float64
    assert ps.STATS["written"] == 2 and len(list(store.glob("*.prog"))) == 2


def test_source_digest_reads_the_contents(tmp_path):
    """An edit that keeps every file name changes the digest (a stored program made by
    the old code is never read by the new); so does a new file."""
    root = tmp_path / "pkg"
    (root / "sub").mkdir(parents=True)
    (root / "a.py").write_text("X = 1\n")
    (root / "sub" / "b.py").write_text("Y = 2\n")
    d0 = ps.tree_digest(root)
    assert ps.tree_digest(root) == d0
    (root / "a.py").write_text("X = 2\n")
    d1 = ps.tree_digest(root)
    (root / "c.py").write_text("")
    assert len({d0, d1, ps.tree_digest(root)}) == 3
    assert len(ps.source_digest()) == 64


def test_failed_write_leaves_the_old_file(store, monkeypatch):
    """A write that fails part-way (disk full) leaves the file that was there whole and
    readable, and no temporary file behind."""
    x = jnp.arange(3.0)
    call(_scaled, x, 2.0)
    (f,) = store.glob("*.prog")
    good = f.read_bytes()
    real_fdopen = ps.os.fdopen

    class Half:
        def __init__(self, fh):
            self.fh = fh

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()
            return False

        def write(self, data):
            self.fh.write(data[:len(data) // 2])
            raise OSError(28, "No space left on device")

    monkeypatch.setattr(ps.os, "fdopen", lambda fd, mode: Half(real_fdopen(fd, mode)))
    ps._write(f, b"another program", None)
    assert f.read_bytes() == good and not list(store.glob(".tmp-*"))


def test_unreadable_file_deleted_on_read(store):
    f = store / "scaled-0.prog"
    f.write_bytes(ps._MAGIC + b"\x80\x04 truncated")
    assert ps._read(f) is None
    assert not f.exists() and ps.STATS["dropped"] == 1
    assert ps._read(store / "missing.prog") is None and ps.STATS["dropped"] == 1


def test_pruning_keeps_the_newest(store, monkeypatch):
    """Full store: the oldest files go, the one just written stays and is read."""
    import os
    monkeypatch.setattr(ps, "MAX_FILES", 2)
    for n in (1, 2):
        call(_scaled, jnp.ones(n), 1.0)
    for age, f in enumerate(sorted(store.glob("*.prog"))):
        os.utime(f, (1e9 + age, 1e9 + age))          # long ago, the second a bit later
    older = {f.name: f.stat().st_mtime for f in store.glob("*.prog")}
    oldest = min(older, key=older.get)
    call(_scaled, jnp.ones(3), 1.0)
    names = {f.name for f in store.glob("*.prog")}
    assert len(names) == 2 and oldest not in names
    _new_process(monkeypatch)
    call(_scaled, jnp.ones(3), 1.0)
    assert ps.STATS["loaded"] == 1


# ------------------------------------------------------------ gearjax warmup

def test_warmup_runs_its_jobs_and_refuses_without_the_store(store, monkeypatch, capsys):
    """``gearjax warmup`` runs each job's command in the process (its output kept back),
    reports the programs stored and fails (exit 1, one warning a job) when a job fails;
    without the store it is refused in one line; an unknown job is named."""
    import gearjax.commands.warmup as wu
    from gearjax.cli import main

    monkeypatch.setattr(wu, "JOBS", {"list": ("examples", ["example", "list"]),
                                     "bad": ("a missing design", ["tca", "example:nothing"])})
    assert main(["warmup", "--jobs", "list"]) == 0
    out, err = capsys.readouterr()
    assert "warmed 1 of 1 jobs" in out and f"in {store}" in out
    assert "hft_8x43" not in out                  # the job's own output is kept back
    assert "[1/1] list" in err
    assert main(["warmup"]) == 1
    out, err = capsys.readouterr()
    assert "warmed 1 of 2 jobs" in out
    assert "gearjax: warning: warmup job failed: bad:" in err and "nothing" in err
    assert main(["warmup", "--jobs", "list,tca"]) == 2
    assert "unknown job 'tca'" in capsys.readouterr().err
    ps.disable()
    assert main(["warmup", "--jobs", "list"]) == 2
    assert "needs the program store" in capsys.readouterr().err


def test_warmup_counts_new_programs_and_lists_without_running(store, monkeypatch, capsys):
    """The report's "new" is what the run added (a second warmup that stores nothing
    says 0 new); ``--list`` names every job and runs none."""
    import gearjax.commands.warmup as wu
    from gearjax import cli

    for i in range(3):
        (store / f"old-{i}.prog").write_bytes(b"")
    made = []

    def fake_main(argv):                      # a job that stores one program, once
        if not made:
            (store / "new-0.prog").write_bytes(b"")
            made.append(argv)
        return 0
    monkeypatch.setattr(wu, "JOBS", {"one": ("a job", ["tca", "example:x"])})
    monkeypatch.setattr(cli, "main", fake_main)
    assert wu.run(Namespace(jobs="one", list=False)) == 0
    assert "programs stored: 4 (1 new)" in capsys.readouterr().out
    assert wu.run(Namespace(jobs="one", list=False)) == 0
    assert "programs stored: 4 (0 new)" in capsys.readouterr().out

    def no_run(argv):
        raise AssertionError(f"--list ran {argv}")
    monkeypatch.setattr(cli, "main", no_run)
    monkeypatch.setattr(wu, "JOBS", {"a": ("first", ["tca", "x"]),
                                     "b": ("second", ["efficiency", "y"])})
    assert wu.run(Namespace(jobs="all", list=True)) == 0
    out = capsys.readouterr().out
    assert "a " in out and "first: gearjax tca x" in out and "second: gearjax efficiency y" in out
