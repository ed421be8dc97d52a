"""Continuous fields of a design pytree by dotted name.

A design (for example a :class:`~gearjax.gears.hypoid.pair.HypoidPair`, an
:class:`~gearjax.gears.involute.tca.InvoluteTCA` or a
:class:`~gearjax.tca.assembly.Misalignment`) is a pytree whose array leaves are its continuous
fields.  These helpers name them by their path (``"pinion.machine.modified_roll_2c"``,
``"pair.x1"``) so that a sensitivity study, a finite-difference check or an
optimiser can pick the fields it varies and put new values back, without writing a
``dataclasses.replace`` chain per field.  Pure and traceable: values may be tracers.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp

__all__ = ["field_names", "get_fields", "with_fields", "with_scaled_fields", "strong_float64",
           "float64_array"]


def _name(path) -> str:
    parts = []
    for k in path:
        for attr in ("name", "key", "idx"):
            if hasattr(k, attr):
                parts.append(str(getattr(k, attr)))
                break
        else:
            parts.append(str(k))
    return ".".join(parts)


def field_names(tree) -> list[str]:
    """Dotted names of the array leaves of ``tree``, in leaf order."""
    return [_name(p) for p, _ in jax.tree_util.tree_flatten_with_path(tree)[0]]


def get_fields(tree, names=None) -> dict:
    """``{name: leaf}`` for ``names`` (default: every leaf); KeyError naming unknown ones."""
    flat = {_name(p): leaf for p, leaf in jax.tree_util.tree_flatten_with_path(tree)[0]}
    if names is None:
        return flat
    unknown = [n for n in names if n not in flat]
    if unknown:
        raise KeyError(f"unknown field(s) {unknown} (known: {', '.join(flat)})")
    return {n: flat[n] for n in names}


def with_fields(tree, values: dict):
    """``tree`` with the leaves named in ``values`` replaced (same structure and static
    fields); KeyError naming an unknown field."""
    flat, treedef = jax.tree_util.tree_flatten_with_path(tree)
    names = [_name(p) for p, _ in flat]
    unknown = set(values) - set(names)
    if unknown:
        raise KeyError(f"unknown field(s) {sorted(unknown)} (known: {', '.join(names)})")
    return jax.tree_util.tree_unflatten(treedef, [values.get(n, leaf)
                                                  for n, (_, leaf) in zip(names, flat)])


def with_scaled_fields(tree, names, x0, scale, u):
    """``tree`` with the fields ``names`` at ``x = x0 + scale * u`` (arrays of
    ``len(names)``: start values, scales in field units, the scaled point of an
    optimiser; traceable)."""
    x = x0 + scale * u
    return with_fields(tree, {n: x[i] for i, n in enumerate(names)})


def float64_array(v):
    """``v`` as a strongly typed float64 array (a tracer stays a tracer): the leaf type
    of every continuous design field (see :func:`strong_float64`)."""
    return jnp.asarray(v, jnp.float64)


def floats_for_ints(obj, names) -> None:
    """In a frozen dataclass's ``__post_init__``: each field of ``names`` given as a Python
    or NumPy integer (a tooth number, a hand +-1, a blade sign) stored as a float64 array,
    so that the pytree has only inexact leaves (``jax.grad`` of a whole design refuses
    integer leaves) and one compiled program serves ints and floats.  Anything else
    (arrays, tracers, the placeholders JAX unflattens with) is left as it is."""
    import numpy as np
    for name in names:
        v = getattr(obj, name)
        if isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_)):
            object.__setattr__(obj, name, jnp.asarray(float(v), jnp.float64))


def strong_float64(tree):
    """``tree`` with every floating-point leaf as a strongly typed float64 array.

    A leaf made from a Python float (``jnp.asarray(0.0)``) is *weakly* typed; a jitted
    program called first with such a leaf and then with the same field as an ordinary
    float64 array (after ``with_fields``, a user's update, an optimiser step) would
    be traced and compiled twice.  The jitted entry points (TCA, EHL) canonicalise
    their pytree arguments with this (values unchanged; tracers pass through).
    """
    def leaf(v):
        if isinstance(v, (bool, int)) or not jnp.issubdtype(jnp.result_type(v), jnp.floating):
            return v
        return float64_array(v)
    return jax.tree_util.tree_map(leaf, tree)
