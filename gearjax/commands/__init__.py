"""Sub-commands of the ``gearjax`` CLI, one module each (see ``gearjax/cli.py``), and
their shared output helpers: :func:`print_json` (throw JSON on stdout),
:func:`warn_nonfinite` (one stderr warning line for results that are not finite) and
:func:`output_dir` (an ``--out`` directory checked before any work)."""

from __future__ import annotations

import os
import sys


def output_dir(out: str, name: str, suffixes) -> str:
    """The ``--out`` directory ``out`` (created if missing), after checking that the files
    ``NAME + suffix`` can be written there (``ValueError`` naming ``--out`` otherwise)."""
    from gearjax.io import check_output_path
    if os.path.exists(out) and not os.path.isdir(out):
        raise ValueError(f"--out = {out!r} exists and is not a directory")
    os.makedirs(out, exist_ok=True)
    for suffix in suffixes:
        check_output_path(os.path.join(out, name + suffix), "--out")
    return out


def print_json(obj, indent=1) -> list[str]:
    """Print ``obj`` as strict JSON on stdout (non-finite floats as ``null``, one
    warning line on stderr naming them) and return the names of those keys."""
    from gearjax.io import dumps_json

    text, bad = dumps_json(obj, indent=indent)
    warn_nonfinite(bad)
    sys.stdout.write(text + "\n")
    return bad


def warn_nonfinite(names) -> None:
    """One stderr warning line for results that are not finite numbers."""
    names = list(names)
    if names:
        shown = ", ".join(names[:6]) + (f" and {len(names) - 6} more" if len(names) > 6 else "")
        sys.stderr.write(f"gearjax: warning: {len(names)} result value(s) are not finite "
                         f"(NaN or inf; null in JSON): {shown}\n")
