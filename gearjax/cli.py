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
    "gearjax.commands.friction",
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


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except ValueError as exc:
        sys.stderr.write(f"gearjax: error: {exc}\n")
        return 2


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
