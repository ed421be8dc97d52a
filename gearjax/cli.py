"""The ``gearjax`` command.

Each sub-command lives in ``gearjax/commands/<name>.py`` and exposes
``register(subparsers)``, which adds its parser and sets ``func`` (a callable taking
the parsed arguments and returning the exit code).  Bad input exits with status 2
and one line on stderr naming the parameter and the allowed range.
"""

from __future__ import annotations

import argparse
import importlib
import os
import sys
import warnings

from gearjax import FAST_COMPILE_OPTIONS

# sub-command modules, in the order they appear in ``gearjax --help``
COMMANDS = [
    "gearjax.commands.involute",
    "gearjax.commands.example",
    "gearjax.commands.blank",
    "gearjax.commands.surface",
    "gearjax.commands.correct",
    "gearjax.commands.ease_off",
    "gearjax.commands.friction",
    "gearjax.commands.kinematics",
    "gearjax.commands.tca",
    "gearjax.commands.efficiency",
    "gearjax.commands.loaded",
    "gearjax.commands.optimize",
    "gearjax.commands.sensitivity",
    "gearjax.commands.sweep",
    "gearjax.commands.warmup",
]


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one clear line, exit status 2
        sys.stderr.write(f"gearjax: error: {message}\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="gearjax", description="Differentiable gear design in JAX.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name in COMMANDS:
        importlib.import_module(name).register(sub)
    return parser


#: default location of the persistent compilation cache (``$GEARJAX_CACHE_DIR`` overrides)
DEFAULT_CACHE_DIR = os.path.join(os.path.expanduser("~"), ".cache", "gearjax", "jax")


#: the values of an environment switch that turn it off
_OFF = ("off", "none", "0", "false")


def _cache_dir() -> str | None:
    """The cache directory from ``$GEARJAX_CACHE_DIR`` (None when switched off)."""
    path = os.environ.get("GEARJAX_CACHE_DIR", DEFAULT_CACHE_DIR)
    if path.strip().lower() in _OFF + ("",):
        return None
    return path


def _drop_cache_entry(path: str, key: str) -> None:
    """Delete the files of one cache entry (JAX's LRU file cache stores entry ``key``
    as ``<key>-cache`` with its access time in ``<key>-atime``)."""
    for suffix in ("-cache", "-atime"):
        try:
            os.unlink(os.path.join(path, f"{key}{suffix}"))
        except OSError:
            pass


#: the start of the warning JAX gives for a cache entry it cannot read
CACHE_READ_WARNING = "Error reading persistent compilation cache entry"


def _decompress(data: bytes) -> bytes:
    """Decompress a cache entry with the codec JAX writes it with (zstd where Python
    has it -- ``compression.zstd`` or the ``zstandard`` package -- else zlib)."""
    try:
        from compression import zstd          # Python >= 3.14
        return zstd.decompress(data)
    except ImportError:
        pass
    try:
        import zstandard
    except ImportError:
        import zlib
        return zlib.decompress(data)
    return zstandard.ZstdDecompressor().decompress(data)


def drop_unreadable_entries(path: str) -> int:
    """Delete every entry of the cache directory ``path`` whose payload does not
    decompress (a run killed while it wrote the entry); returns how many."""
    dropped = 0
    for name in sorted(os.listdir(path)):
        if not name.endswith("-cache"):
            continue
        try:
            with open(os.path.join(path, name), "rb") as f:
                _decompress(f.read())
        except OSError:
            continue
        except Exception:  # noqa: BLE001 - any undecodable payload is a bad entry
            _drop_cache_entry(path, name[:-len("-cache")])
            dropped += 1
    return dropped


def _install_cache_repair(path: str) -> None:
    """Make a corrupt cache entry a one-off cache miss instead of a warning on every run.

    When JAX cannot read an entry (truncated or corrupt) it warns
    (:data:`CACHE_READ_WARNING`), recompiles, and would keep the bad file (its ``put``
    skips a key whose file exists), so that every later run warned again.  The warning
    hook installed here (Python's ``warnings.showwarning``) drops the unreadable
    entries instead of printing (:func:`drop_unreadable_entries`; JAX then stores a
    good entry); every other warning is shown as before."""
    previous = warnings.showwarning
    if getattr(previous, "_gearjax_repair", False):
        return

    def showwarning(message, category, filename, lineno, file=None, line=None):
        if str(message).startswith(CACHE_READ_WARNING):
            drop_unreadable_entries(path)
            return
        previous(message, category, filename, lineno, file, line)

    showwarning._gearjax_repair = True
    warnings.showwarning = showwarning


def _enable_compilation_cache() -> None:
    """Persist compiled JAX programs between CLI runs (``$GEARJAX_CACHE_DIR`` or
    ``~/.cache/gearjax/jax``; set ``GEARJAX_CACHE_DIR=off`` to disable).  A corrupt
    or truncated entry is deleted and recompiled once (:func:`_install_cache_repair`).
    The traced programs go to ``programs/`` in the same directory
    (:mod:`gearjax.program_store`: a warm run does not trace them again), unless
    ``GEARJAX_PROGRAM_STORE=0``."""
    import jax

    import gearjax.program_store as program_store

    path = _cache_dir()
    if path is None:
        return
    try:
        os.makedirs(path, exist_ok=True)
        if not os.access(path, os.W_OK | os.X_OK):
            return                      # a read-only cache directory: run without the cache
        _install_cache_repair(path)
        jax.config.update("jax_compilation_cache_dir", path)
        # every program, the small ones of a set-up's eager arithmetic too: read back
        # they cost less than compiled again (the hypoid `gearjax tca` warm 2.5 -> 2.1 s)
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
        if os.environ.get("GEARJAX_PROGRAM_STORE", "1").strip().lower() not in _OFF:
            program_store.enable(os.path.join(path, "programs"))
    except (OSError, AttributeError, ValueError):  # read-only home or an older JAX
        pass


#: XLA options for a command-line run on the CPU: the command compiles its programs
#: once and runs them for a fraction of a second, so compile time is what the user
#: waits for.  LLVM optimisation level 0 and XLA's older loop emitters halve it (cold
#: ``gearjax tca`` of the 8/43 hypoid 30.0 -> 15.8 s, ``gearjax efficiency`` of a spur
#: pair 26.3 -> 13.1 s on 2 cores) and about double the run time of the compiled
#: programs (the bench TCA 32 -> 62 ms); one LLVM module instead of XLA's default split
#: into parts (which at level 0 are compiled one after the other: the split only adds
#: work) takes about 10 % more off (the spur pair's TCA program 9.1 -> 6.8 s of
#: compilation).  Results agree to round-off (the test suite runs with the same
#: options).  ``GEARJAX_FAST_COMPILE=0`` keeps XLA's defaults (long runs); an option
#: already in ``XLA_FLAGS`` is kept.
FAST_COMPILE_FLAGS = tuple((name, str(value).lower())
                           for name, value in FAST_COMPILE_OPTIONS.items())


def _fast_compile_flags() -> None:
    """Add :data:`FAST_COMPILE_FLAGS` to ``XLA_FLAGS`` (before JAX starts its backend;
    ``import gearjax`` does not start it) for a CPU run: not with
    ``GEARJAX_FAST_COMPILE=0``, nor where ``JAX_PLATFORMS`` names another platform or a
    GPU plugin of JAX is installed (optimised GPU kernels matter more there)."""
    if os.environ.get("GEARJAX_FAST_COMPILE", "1").strip().lower() in ("0", "off", "false", "no"):
        return
    platforms = os.environ.get("JAX_PLATFORMS", "").strip().lower()
    if platforms and platforms != "cpu":
        return
    if not platforms and _accelerator_plugin_installed():
        return
    flags = os.environ.get("XLA_FLAGS", "")
    for name, value in FAST_COMPILE_FLAGS:
        if name not in flags:
            flags = f"{flags} --{name}={value}".strip()
    os.environ["XLA_FLAGS"] = flags


def _accelerator_plugin_installed() -> bool:
    """A PJRT plugin (CUDA, ROCm, ...) that JAX would load: JAX finds them as entry
    points of the group ``jax_plugins`` or as modules of the ``jax_plugins`` namespace
    package (the same two places JAX looks; a few milliseconds)."""
    import importlib.util
    import pkgutil
    from importlib import metadata

    if metadata.entry_points(group="jax_plugins"):
        return True
    spec = importlib.util.find_spec("jax_plugins")
    return spec is not None and any(
        True for _ in pkgutil.iter_modules(spec.submodule_search_locations or []))


def main(argv=None) -> int:
    if argv is None:  # a real command-line run, not an in-process call
        _fast_compile_flags()
    from gearjax import ConvergenceError
    from gearjax.io import UnconvergedExportError

    parser = build_parser()
    args = parser.parse_args(argv)
    if argv is None:
        _enable_compilation_cache()
    try:
        return int(args.func(args) or 0)
    except BrokenPipeError:  # output piped into `head` and the like
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except ValueError as exc:
        sys.stderr.write(f"gearjax: error: {exc}\n")
        return 2
    except (ConvergenceError, UnconvergedExportError) as exc:
        # a solve failed on valid input (or an export would carry such points): one
        # line, status 3
        msg = str(exc).split("; pass throw=False")[0]
        sys.stderr.write(f"gearjax: error: {msg}\n")
        return 3
    except OSError as exc:  # a write (or read) failed: disk full, permissions, size limit
        sys.stderr.write(f"gearjax: error: {_os_error_line(exc)}\n")
        return 1


def _os_error_line(exc: OSError) -> str:
    from gearjax.io import WriteError

    what = exc.strerror or str(exc) or type(exc).__name__
    if isinstance(exc, WriteError):
        return (f"cannot write {os.fspath(exc.filename)!r}: {what} "
                "(nothing written; an existing file is left unchanged)")
    if exc.filename:
        return f"{os.fspath(exc.filename)!r}: {what}"
    return f"input/output error: {what}"


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
