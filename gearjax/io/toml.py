"""TOML reading and writing, the value checks every design-file reader uses, and the
packaged examples.

Each family reads its own design files (for instance
:mod:`gearjax.gears.hypoid.design_file`) with :func:`read_toml`, :func:`check_keys`
and :func:`require_key` from here; a bad value is a one-line ``ValueError`` naming
the table, the key, the value and what is allowed.
"""

from __future__ import annotations

import math
import os
from importlib import resources
from pathlib import Path

import numpy as np

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover  (python < 3.11)
    import tomli as tomllib  # type: ignore


#: packaged examples renamed since (old name -> current name); still accepted
EXAMPLE_ALIASES = {"seed000_6x39_7p5in": "hypoid_6x39_7p5in"}


# TOML writer (the subset the design schema uses)


def _toml_key(k: str) -> str:
    if k and all(c.isalnum() or c in "_-" for c in k):
        return k
    return '"' + k.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        s = v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n").replace("\t", "\\t")
        return f'"{s}"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise ValueError(f"cannot write {type(v).__name__} value {v!r} to TOML")


def dumps_toml(data: dict) -> str:
    """Serialise nested dicts of str/int/float/bool/lists to TOML (tables as [a.b])."""
    out: list[str] = []

    def emit(tbl: dict, prefix: list[str]):
        scalars = [(k, v) for k, v in tbl.items() if not isinstance(v, dict)]
        tables = [(k, v) for k, v in tbl.items() if isinstance(v, dict)]
        if prefix and (scalars or not tables):
            out.append("[" + ".".join(_toml_key(p) for p in prefix) + "]")
        for k, v in scalars:
            out.append(f"{_toml_key(k)} = {_toml_value(v)}")
        if prefix and (scalars or not tables):
            out.append("")
        for k, v in tables:
            emit(v, prefix + [k])

    emit(data, [])
    return "\n".join(out).rstrip("\n") + "\n"


# --------------------------------------------------------------------------------------
# design files


def _table_name(where: str) -> str:
    return f"[{where}]" if where else "the top level"


def check_keys(where: str, d, allowed: set):
    """Raise ``ValueError`` unless ``d`` is a table whose keys are all in ``allowed``.

    ``where`` is the dotted table name ("pinion.convex.machine", "" for the top level);
    the message names the table and the unknown key as ``'where.key'``."""
    if not isinstance(d, dict):
        raise ValueError(f"{_table_name(where)} must be a table, got {type_name(d)} {d!r}")
    for k in d:
        if k not in allowed:
            raise ValueError(f"unknown key '{where}.{k}' in {_table_name(where)} "
                             f"(allowed: {', '.join(sorted(allowed))})")


def require_key(where: str, d: dict, key: str):
    """``d[key]``, or ``ValueError`` naming the table and the missing key."""
    if key not in d:
        raise ValueError(f"[{where}] is missing the required key '{key}'")
    return d[key]


def type_name(v) -> str:
    if isinstance(v, bool):
        return "a boolean"
    if isinstance(v, str):
        return "a string"
    if isinstance(v, (list, tuple)):
        return "an array"
    if isinstance(v, dict):
        return "a table"
    return f"a {type(v).__name__}"


def is_number(v) -> bool:
    """True for an int or float (a TOML number); False for bool, str, arrays, tables."""
    return isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))


def check_number(where: str, key: str, v, unit: str = "") -> float:
    """``float(v)`` of a finite number, or ``ValueError`` naming table and key.

    Refuses booleans, strings, arrays, tables, dates, NaN and +-inf (TOML allows
    ``nan`` and ``inf``)."""
    u = f" ({unit})" if unit else ""
    if not is_number(v):
        raise ValueError(f"[{where}] {key} = {v!r} must be a number{u}, got {type_name(v)}")
    x = float(v)
    if not math.isfinite(x):
        raise ValueError(f"[{where}] {key} = {v!r} must be a finite number{u}")
    return x


def check_integer(where: str, key: str, v, lo: int | None = None) -> int:
    """``int(v)`` of a TOML integer (>= ``lo``), or ``ValueError`` naming table and key."""
    if not isinstance(v, (int, np.integer)) or isinstance(v, (bool, np.bool_)):
        raise ValueError(f"[{where}] {key} = {v!r} must be an integer, got {type_name(v)}")
    if lo is not None and v < lo:
        raise ValueError(f"[{where}] {key} = {v} is outside the allowed range [{lo}, inf)")
    return int(v)


def check_string(where: str, key: str, v, choices=None) -> str:
    """``v`` if it is a string (one of ``choices`` when given), else ``ValueError``."""
    if not isinstance(v, str):
        raise ValueError(f"[{where}] {key} = {v!r} must be a string, got {type_name(v)}")
    if choices is not None and v not in choices:
        raise ValueError(f"[{where}] {key} = {v!r} must be one of "
                         + ", ".join(repr(c) for c in choices))
    return v


def list_examples() -> list[str]:
    """Names of the packaged example designs."""
    root = resources.files("gearjax") / "examples"
    return sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))


def example_path(name: str):
    """Path (Traversable) of a packaged example; ValueError naming the known ones."""
    names = list_examples()
    name = EXAMPLE_ALIASES.get(name, name)
    if name not in names:
        raise ValueError(f"unknown example {name!r} (known: {', '.join(names)})")
    return resources.files("gearjax") / "examples" / f"{name}.toml"


def _read_text(source) -> str:
    """Text of a design file (UTF-8, an optional BOM dropped) or of ``example:NAME``;
    ``ValueError`` naming the file for a missing file, a directory, an unreadable,
    binary or non-UTF-8 file."""
    if isinstance(source, str) and source.startswith("example:"):
        return example_path(source[len("example:"):]).read_text(encoding="utf-8")
    if not isinstance(source, (str, os.PathLike)):
        raise ValueError(f"design file must be a path or 'example:NAME', got {source!r}")
    p = Path(source)
    name = repr(str(source))
    if p.is_dir():
        raise ValueError(f"design file {name} is a directory, not a file")
    if not p.exists():
        raise ValueError(f"design file {name} does not exist")
    if not p.is_file():
        raise ValueError(f"design file {name} is not a regular file")
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise ValueError(f"design file {name} cannot be read: {exc.strerror or exc}") from None
    if b"\x00" in raw:
        raise ValueError(f"design file {name} is a binary file, not TOML text")
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise ValueError(f"design file {name} is not UTF-8 text (line {line}: byte "
                         f"{raw[exc.start:exc.start + 1]!r})") from None


def read_toml(source) -> dict:
    """Parse a TOML design file: a path or ``example:NAME``.

    ``ValueError`` (one line naming the file) for a missing file, a directory, a
    binary or non-UTF-8 file, a TOML syntax error and an empty file."""
    text = _read_text(source)
    name = repr(str(source))
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = " ".join(str(exc).split())
        raise ValueError(f"design file {name}: invalid TOML: {msg}") from None
    if not data:
        raise ValueError(f"design file {name} is empty (no tables)")
    return data
