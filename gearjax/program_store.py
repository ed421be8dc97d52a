"""Traced programs kept on disk between processes: JAX's export format, keyed by what
makes the program.

A warm command-line run (every compiled program in JAX's persistent compilation
cache) still traces each program again -- Python walks gearjax's functions to build
the graph whose hash finds the cached executable.  That tracing is most of a warm run:
of the 4.6 s of a warm ``gearjax tca`` of the 8/43 hypoid on the 2-core CPU, about 3 s.
The store keeps each traced program as a serialized :class:`jax.export.Exported`
(StableHLO): a later process reads it (milliseconds), wraps it in ``jax.jit`` (tracing
the wrapper is a single call), and the compilation of that wrapper is a hit of the
persistent compilation cache.  Nothing about what is computed changes: the exported
module is the program as traced, compiled by the same XLA (results bit-identical; the
tests compare).

**Key.**  The SHA-256 of: the store's format version; the program's name (module and
qualified name of the jitted function); its static arguments (:func:`static_key`:
numbers, strings, tuples, module-level functions, and objects that name themselves by
a ``program_key`` string, as the gear families do); the tree structure of the
arguments and each leaf's shape, dtype and weak type; the digest of gearjax's source
files (:func:`source_digest`: an edited or upgraded gearjax never reads an older
program); the versions of JAX and jaxlib, the backend platform and whether 64-bit
floats are on.  A static argument without a stable key (a closure, an object named by
its memory address) makes the program not storable: it is traced as without the store.

**File.**  ``<name>-<key>.prog`` in the store's directory: a magic line, then a pickle of the
serialized module and of the argument and result tree structures (the tree structures
name gearjax's own classes; the directory is the user's own cache, trusted as JAX's
compilation cache is).  Written to a temporary file and renamed (atomic); one that
cannot be read (a truncated write, another format) is deleted and the program traced
again.  At most :data:`MAX_FILES` programs are kept; the oldest go first.

**Where.**  Off in the library (nothing is written unless asked); the command line
turns it on next to its compilation cache (``$GEARJAX_CACHE_DIR/programs``, off with
``GEARJAX_CACHE_DIR=off`` or ``GEARJAX_PROGRAM_STORE=0``); :func:`enable` for a
notebook.  The programs that pass through :mod:`gearjax.compile_ahead` (the TCA's two
stages, the hypoid set-up's mean points, the loaded chain's efficiency program) are the
ones stored.

Reference: JAX documentation, "Exporting and serializing staged-out computations"
(``jax.export``).
"""

from __future__ import annotations

import hashlib
import os
import pickle
import tempfile
import threading
import types
from pathlib import Path
from typing import NamedTuple

import jax

__all__ = ["enable", "disable", "directory", "stored_program", "static_key", "source_digest",
           "Program", "STATS", "MAX_FILES"]

#: bumped when the file layout or the key changes
FORMAT = 1
_MAGIC = b"gearjax-program %d\n" % FORMAT
#: the most programs kept in the directory (each 0.1-1 MB); the oldest are deleted
MAX_FILES = 256
#: counters of this process: programs ``loaded`` from the store, ``written`` to it,
#: ``refused`` (not storable or the export failed: traced as without the store),
#: ``dropped`` (unreadable files deleted)
STATS = {"loaded": 0, "written": 0, "refused": 0, "dropped": 0}

_DIR: Path | None = None
_LOCK = threading.Lock()
_DIGEST: str | None = None


class Unstorable(Exception):
    """A static argument has no stable key (the program is traced, not stored)."""


def enable(path) -> None:
    """Keep traced programs in the directory ``path`` (created if missing)."""
    global _DIR
    p = Path(path)
    p.mkdir(parents=True, exist_ok=True)
    _DIR = p


def disable() -> None:
    """Trace every program again (the library's default)."""
    global _DIR
    _DIR = None


def directory() -> Path | None:
    """The store's directory, or None when it is off."""
    return _DIR


def source_digest() -> str:
    """SHA-256 of gearjax's source files (:func:`tree_digest` of the package), computed
    once per process."""
    global _DIGEST
    if _DIGEST is None:
        _DIGEST = tree_digest(Path(__file__).resolve().parent)
    return _DIGEST


def tree_digest(root: Path) -> str:
    """SHA-256 of the ``*.py`` files under ``root``: their paths relative to it and their
    bytes."""
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        h.update(f.relative_to(root).as_posix().encode())
        h.update(b"\0")
        h.update(f.read_bytes())
        h.update(b"\0")
    return h.hexdigest()


def static_key(v) -> str:
    """A key of a static argument that is the same in every process, or
    :class:`Unstorable`: numbers, strings, None, tuples (named tuples with their type),
    module-level functions and methods by their qualified names, objects with a
    ``program_key`` string (e.g. :class:`gearjax.tca.family.GearFamily`)."""
    if v is None or isinstance(v, (bool, int, float, str)):
        return f"{type(v).__name__}:{v!r}"
    if isinstance(v, tuple):
        name = type(v).__qualname__ if type(v) is not tuple else ""
        return f"{name}(" + ",".join(static_key(x) for x in v) + ")"
    if isinstance(v, types.MethodType):
        return f"{static_key(v.__self__)}.{v.__func__.__qualname__}"
    if isinstance(v, types.FunctionType):
        if "<" in v.__qualname__ or v.__closure__:
            raise Unstorable(v.__qualname__)       # a lambda or a closure: its values
        return f"{v.__module__}.{v.__qualname__}"
    key = getattr(v, "program_key", None)
    if isinstance(key, str):
        return key
    raise Unstorable(type(v).__qualname__)


def _leaf_key(x) -> str:
    a = jax.typeof(x)
    return f"{a.dtype.name}{list(a.shape)}{'w' if getattr(a, 'weak_type', False) else ''}"


def program_key(fun, args, static) -> str:
    """The store's key of ``fun(*args, **static)`` (module docstring); raises
    :class:`Unstorable`."""
    leaves, tree = jax.tree.flatten(args)
    tree_text = str(tree)
    if " at 0x" in tree_text:
        raise Unstorable("argument tree")          # a node named by its address
    import jaxlib
    parts = [str(FORMAT), f"{fun.__module__}.{fun.__qualname__}",
             ";".join(f"{k}={static_key(static[k])}" for k in sorted(static)),
             tree_text, ",".join(_leaf_key(x) for x in leaves), source_digest(),
             jax.__version__, jaxlib.__version__, jax.default_backend(),
             str(bool(jax.config.jax_enable_x64))]
    return hashlib.sha256("\n".join(parts).encode()).hexdigest()


class Program(NamedTuple):
    """A stored program: ``program(*args)`` runs it on arguments of the signature it
    was made for (the result as ``fun``'s); ``out_info`` the abstract result
    (``jax.ShapeDtypeStruct`` leaves), ``jitted`` the ``jax.jit`` of the exported call
    on the flat leaves (``jitted.trace(*leaves)`` to compile it ahead)."""

    jitted: object
    out_tree: object
    out_info: object

    def __call__(self, *args):
        return jax.tree.unflatten(self.out_tree, self.jitted(*jax.tree.leaves(args)))

    def trace(self, *args):
        return self.jitted.trace(*jax.tree.leaves(args))


def _program(exported, out_tree) -> Program:
    info = [jax.ShapeDtypeStruct(a.shape, a.dtype, weak_type=a.weak_type)
            for a in exported.out_avals]
    return Program(jax.jit(exported.call), out_tree, jax.tree.unflatten(out_tree, info))


def _read(path: Path):
    """``(Exported, out_tree)`` of a file, or None (missing); an unreadable file is
    deleted (None)."""
    from jax import export
    try:
        data = path.read_bytes()
    except OSError:
        return None
    try:
        if not data.startswith(_MAGIC):
            raise ValueError("not a program file of this format")
        blob, out_tree = pickle.loads(data[len(_MAGIC):])
        return export.deserialize(bytearray(blob)), out_tree
    except Exception:  # noqa: BLE001 - any unreadable file is a miss
        STATS["dropped"] += 1
        try:
            path.unlink()
        except OSError:
            pass
        return None


def _write(path: Path, blob: bytes, out_tree) -> None:
    data = _MAGIC + pickle.dumps((blob, out_tree), protocol=4)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=".tmp-", suffix=".prog")
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except OSError:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        return
    STATS["written"] += 1
    _prune(path.parent)


def _prune(d: Path) -> None:
    files = sorted(d.glob("*.prog"), key=lambda f: f.stat().st_mtime if f.exists() else 0.0)
    for f in files[:max(0, len(files) - MAX_FILES)]:
        try:
            f.unlink()
        except OSError:
            pass


def _export(fun, args, static):
    """``(Exported, out_tree)`` of ``fun(*args, **static)`` on the flat leaves of
    ``args`` (traced here)."""
    from jax import export
    leaves, tree = jax.tree.flatten(args)
    box = {}

    def flat(*lv):
        out = fun(*jax.tree.unflatten(tree, lv), **static)
        leaves_out, box["tree"] = jax.tree.flatten(out)
        return leaves_out

    exported = export.export(jax.jit(flat), platforms=[jax.default_backend()])(*leaves)
    return exported, box["tree"]


def stored_program(fun, args, static) -> Program | None:
    """The :class:`Program` of ``fun(*args, **static)`` (``fun`` a ``jax.jit``
    function, ``args`` concrete or ``jax.ShapeDtypeStruct`` leaves): read from the
    store, or traced, exported and written to it; None when the store is off or the
    program cannot be stored (then ``fun`` is traced as usual)."""
    d = _DIR
    if d is None:
        return None
    try:
        key = program_key(fun, args, static)
    except Unstorable:
        STATS["refused"] += 1
        return None
    path = d / f"{fun.__qualname__.strip('_')}-{key}.prog"
    with _LOCK:
        got = _read(path)
    if got is not None:
        STATS["loaded"] += 1
        return _program(*got)
    from jax import export
    try:
        exported, out_tree = _export(fun, args, static)
        blob = bytes(exported.serialize())
        # this process runs what a later one will read (a module read back has no
        # weak types on its results, a fresh one may: the next program's key would
        # differ between the first run and the later ones)
        exported = export.deserialize(bytearray(blob))
    except Exception:  # noqa: BLE001 - not exportable: traced as without the store
        STATS["refused"] += 1
        return None
    with _LOCK:
        _write(path, blob, out_tree)
    return _program(exported, out_tree)
