"""The ``gearjax`` command.

Each sub-command lives in ``gearjax/commands/<name>.py`` and exposes
``register(subparsers)``, which adds its parser and sets ``func`` (a callable taking
the parsed arguments and returning the exit code).  Bad input exits with status 2
and one line on stderr naming the parameter and the allowed range.
"""

from __future__ import annotations

import argparse
import importlib
import sys

# sub-command modules, in the order they appear in ``gearjax --help``
COMMANDS = [
    "gearjax.commands.involute",
    "gearjax.commands.example",
    "gearjax.commands.blank",
    "gearjax.commands.surface",
    "gearjax.commands.friction",
    "gearjax.commands.kinematics",
    "gearjax.commands.tca",
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


def _enable_compilation_cache() -> None:
    """Persist compiled JAX programs between CLI runs (``$GEARJAX_CACHE_DIR`` or
    ``~/.cache/gearjax/jax``; set ``GEARJAX_CACHE_DIR=off`` to disable)."""
    import os

    import jax

    path = os.environ.get("GEARJAX_CACHE_DIR", os.path.join(os.path.expanduser("~"), ".cache",
                                                            "gearjax", "jax"))
    if path.lower() in ("off", "none", ""):
        return
    try:
        os.makedirs(path, exist_ok=True)
        jax.config.update("jax_compilation_cache_dir", path)
        jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.5)
    except (OSError, AttributeError, ValueError):  # read-only home or an older JAX
        pass


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if argv is None:  # a real command-line run, not an in-process call
        _enable_compilation_cache()
    try:
        return int(args.func(args) or 0)
    except BrokenPipeError:  # output piped into `head` and the like
        import os
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except ValueError as exc:
        sys.stderr.write(f"gearjax: error: {exc}\n")
        return 2


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
