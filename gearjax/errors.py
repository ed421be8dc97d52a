"""Exception types and validation helpers used at the library boundary.

Validation happens on concrete values (constructors meant for users, file loaders,
the CLI) before anything is traced; traced code never validates.  The helpers let a
traced value (a ``jax`` tracer, e.g. inside ``jax.grad`` of a function that calls a
validated constructor) through unchanged: its value is not known, so it cannot be
checked, and the constructors stay usable in differentiated code.
"""

from __future__ import annotations

import math
from typing import Any

import jax
import numpy as np


class ConvergenceError(RuntimeError):
    """A solver did not converge where a valid result was required."""


def is_traced(value: Any) -> bool:
    """True for a JAX tracer (a value whose number is not known while tracing)."""
    return isinstance(value, jax.core.Tracer)


def any_traced(*trees: Any) -> bool:
    """True when any leaf of the pytrees ``trees`` is a JAX tracer: the call runs inside
    ``jax.jit``/``grad``/``vmap``, where a public entry point skips its validation (and
    never raises on a solve's status; the result carries its ``converged`` flags)."""
    return any(is_traced(leaf) for leaf in jax.tree_util.tree_leaves(trees))


def _fmt(value: Any) -> str:
    try:
        return f"{float(value):g}"
    except (TypeError, ValueError):
        return repr(value)


def check_range(name: str, value: Any, lo: float | None = None, hi: float | None = None,
                *, lo_open: bool = False, hi_open: bool = False, unit: str = "") -> float:
    """Return ``float(value)`` or raise ``ValueError`` naming the parameter and range.

    ``lo``/``hi`` are the bounds (None for unbounded); ``lo_open``/``hi_open`` make a
    bound exclusive.  A traced value is returned unchanged (not checked).
    """
    if is_traced(value) or is_traced(lo) or is_traced(hi):
        return value
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise ValueError(f"{name} must be a number, got {value!r}")
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    ok = math.isfinite(v)
    if ok and lo is not None:
        ok = v > lo if lo_open else v >= lo
    if ok and hi is not None:
        ok = v < hi if hi_open else v <= hi
    if not ok:
        left = "(" if (lo_open or lo is None) else "["
        right = ")" if (hi_open or hi is None) else "]"
        lo_s = "-inf" if lo is None else _fmt(lo)
        hi_s = "inf" if hi is None else _fmt(hi)
        u = f" {unit}" if unit else ""
        raise ValueError(f"{name} = {_fmt(value)}{u} is outside the allowed range "
                         f"{left}{lo_s}, {hi_s}{right}{u}")
    return v


def check_positive(name: str, value: Any, unit: str = "") -> float:
    """Raise ``ValueError`` unless ``value`` is a finite number > 0."""
    return check_range(name, value, 0.0, None, lo_open=True, unit=unit)


def check_int(name: str, value: Any, lo: int | None = None, hi: int | None = None) -> int:
    """Return ``int(value)`` or raise ``ValueError`` if not an integer in [lo, hi]."""
    bad = ValueError(f"{name} = {value!r} must be an integer"
                     + (f" >= {lo}" if lo is not None else ""))
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise bad
    try:
        f = float(np.asarray(value))
    except (TypeError, ValueError):
        raise bad from None
    if not f.is_integer():
        raise bad
    v = int(np.asarray(value))
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        rng = f"[{lo if lo is not None else '-inf'}, {hi if hi is not None else 'inf'}]"
        raise ValueError(f"{name} = {v} is outside the allowed range {rng}")
    return v


def require_converged(converged: Any, what: str, residual: Any = None) -> None:
    """Raise ``ConvergenceError`` unless every entry of ``converged`` is True."""
    c = np.asarray(converged)
    if not bool(np.all(c)):
        n_bad = int(c.size - np.count_nonzero(c))
        msg = f"{what}: {n_bad} of {c.size} solves did not converge"
        if residual is not None:
            # the residual of the failed solves only (a converged neighbour's residual
            # says nothing about them)
            r = np.broadcast_to(np.asarray(residual, float), c.shape)[~c.astype(bool)]
            msg += f" (worst residual among them {float(np.max(np.where(np.isfinite(r), r, np.inf))):.3g})"
        raise ConvergenceError(msg + "; pass throw=False to get masks instead")
