"""Sub-commands of the ``gearjax`` CLI, one module each (see ``gearjax/cli.py``), and
their shared output helpers: :func:`print_json` (throw JSON on stdout) and
:func:`warn_nonfinite` (one stderr warning line for results that are not finite)."""

from __future__ import annotations

import sys


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
