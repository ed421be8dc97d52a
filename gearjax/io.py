"""File formats shared by every gear family: TOML reading and writing, packaged
examples, atomic writes, output-path checks, strict JSON, flank exports (CSV, XYZ, STL).

This module is a leaf: it imports no gear family.  Each family reads its own design
files (:mod:`gearjax.gears.hypoid.design_file` for spiral-bevel/hypoid designs) with
:func:`read_toml`, :func:`check_keys` and :func:`require_key` from here.

Every file is written atomically: to a temporary file in the target directory,
flushed and fsync-ed, then ``os.replace``; a failing export never touches an
existing file and leaves no temporary file behind (:func:`atomic_write`,
:func:`atomic_write_figure`).  Commands check their output paths with
:func:`check_output_path` before any work, and write JSON with :func:`dumps_json`
(non-finite numbers become ``null``: the output is always valid JSON).
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from importlib import resources
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover  (python < 3.11)
    import tomli as tomllib  # type: ignore

__all__ = ["read_toml", "check_keys", "require_key", "check_number", "check_integer",
           "check_string", "is_number", "dumps_toml", "list_examples",
           "example_path", "atomic_write", "atomic_write_figure", "figure_bytes",
           "check_output_path", "WriteError", "finite_json", "dumps_json",
           "write_csv", "write_xyz", "write_stl_flank",
           "write_stl_tooth", "tooth_mesh", "flank_triangles", "write_flank",
           "register_design_kind", "design_kinds", "design_from_dict", "load_design",
           "DesignFileMixin",
           "FlankGrid"]

#: packaged examples renamed since (old name -> current name); still accepted
EXAMPLE_ALIASES = {"seed000_6x39_7p5in": "hypoid_6x39_7p5in"}


# --------------------------------------------------------------------------------------
# atomic writes, output paths, JSON


class WriteError(OSError):
    """An output file could not be written (``filename`` is the target, not the
    temporary file); the target was left unchanged."""


def _fsync_dir(directory) -> None:
    """Flush a directory entry to disk where the platform allows it (POSIX)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write(path, data) -> Path:
    """Write ``data`` (``str``, written as UTF-8 with ``\\n`` newlines, or ``bytes``)
    to ``path`` atomically.

    The data go to a temporary file in the target directory, which is flushed
    and ``fsync``-ed and then renamed over ``path`` (``os.replace``, atomic on
    POSIX and Windows).  On any error (``OSError`` such as a full disk, a
    permission or file-size limit, or an interrupt) the temporary file is
    removed, ``path`` keeps its old content and a :class:`WriteError` (an
    ``OSError`` naming ``path``) is raised; other exceptions propagate unchanged.
    Returns ``path`` as a :class:`~pathlib.Path`.
    """
    path = Path(path)
    if isinstance(data, str):
        data = data.encode("utf-8")
    elif not isinstance(data, (bytes, bytearray, memoryview)):
        raise TypeError(f"atomic_write needs str or bytes, got {type(data).__name__}")
    directory = path.parent if str(path.parent) else Path(".")
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory)
    except OSError as exc:
        raise WriteError(exc.errno, exc.strerror or str(exc), os.fspath(path)) from exc
    umask = os.umask(0)
    os.umask(umask)
    try:
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the usual file mode
        with os.fdopen(fd, "wb") as f:
            fd = None
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        if fd is not None:
            try:
                os.close(fd)
            except OSError:
                pass
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError) and not isinstance(exc, WriteError):
            raise WriteError(exc.errno, exc.strerror or str(exc), os.fspath(path)) from exc
        raise
    _fsync_dir(directory)
    return path


def figure_bytes(fig, fmt: str = "png", dpi: int = 110, **savefig_kw) -> bytes:
    """Render a matplotlib figure to bytes in ``fmt`` (png, pdf, svg) without
    touching the file system."""
    import io as _io

    buf = _io.BytesIO()
    fig.savefig(buf, format=fmt, dpi=dpi, **savefig_kw)
    return buf.getvalue()


def atomic_write_figure(fig, path, dpi: int = 110, close: bool = True, **savefig_kw) -> Path:
    """Save a matplotlib figure to ``path`` atomically (format from the extension,
    default PNG): rendered in memory first, then :func:`atomic_write`, so a
    failing save never leaves a half-written image.  Closes ``fig`` unless
    ``close=False``."""
    path = Path(path)
    try:
        data = figure_bytes(fig, path.suffix.lstrip(".").lower() or "png", dpi, **savefig_kw)
    finally:
        if close:
            import matplotlib.pyplot as plt
            plt.close(fig)
    return atomic_write(path, data)


def check_output_path(path, flag: str, allowed_suffixes=None) -> Path:
    """Check, before any work is done, that an output file can be written.

    ``flag`` names the option in the error (e.g. ``"--out"``); ``allowed_suffixes``
    is an iterable of extensions such as ``(".csv", ".stl")`` (case-insensitive;
    None accepts any).  Raises ``ValueError`` when the extension is not allowed,
    the path is an existing directory, its parent directory does not exist or is
    not a directory, the directory is not writable (no new file can be created
    in it; atomic writes need that) or an existing file at ``path`` is not
    writable.  Returns ``path`` as a :class:`~pathlib.Path`.
    """
    text = os.fspath(path)
    if not text:
        raise ValueError(f"{flag} = '': an output file name is required")
    p = Path(text)
    if allowed_suffixes is not None:
        allowed = tuple(s.lower() for s in allowed_suffixes)
        if p.suffix.lower() not in allowed:
            raise ValueError(f"{flag} = {text!r}: extension must be "
                             f"{', '.join(allowed[:-1]) + ' or ' if len(allowed) > 1 else ''}"
                             f"{allowed[-1]}")
    if p.is_dir():
        raise ValueError(f"{flag} = {text!r} is a directory, not a file")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.exists():
        raise ValueError(f"{flag} = {text!r}: directory {str(parent)!r} does not exist")
    if not parent.is_dir():
        raise ValueError(f"{flag} = {text!r}: {str(parent)!r} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"{flag} = {text!r}: directory {str(parent)!r} is not writable")
    # permission bits do not tell everything (a superuser, a read-only mount, sysfs):
    # create and remove a probe file where the output's temporary file will go
    try:
        fd, probe = tempfile.mkstemp(prefix=".gearjax-probe-", dir=parent)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise ValueError(f"{flag} = {text!r}: directory {str(parent)!r} is not writable "
                         f"({exc.strerror or exc})") from None
    if p.exists() and not os.access(p, os.W_OK):
        raise ValueError(f"{flag} = {text!r}: the existing file is not writable")
    return p


def finite_json(obj, _where: str = ""):
    """Copy of a JSON-like structure with every non-finite float (NaN, ±inf, also
    NumPy scalars and arrays) replaced by ``None``.

    Returns ``(clean, bad)``: ``bad`` lists the key paths (``"a.b[3]"``) whose
    values were not finite, so a caller can flag them.  NumPy arrays become lists.
    """
    bad: list[str] = []

    def walk(o, where):
        if isinstance(o, dict):
            return {k: walk(v, f"{where}.{k}" if where else str(k)) for k, v in o.items()}
        if isinstance(o, (list, tuple)):
            return [walk(v, f"{where}[{i}]") for i, v in enumerate(o)]
        if isinstance(o, np.ndarray):
            return walk(o.tolist(), where)
        if isinstance(o, (bool, np.bool_)):
            return bool(o)
        if isinstance(o, (int, np.integer)):
            return int(o)
        if isinstance(o, (float, np.floating)):
            if math.isfinite(float(o)):
                return float(o)
            bad.append(where)
            return None
        return o

    return walk(obj, _where), bad


def dumps_json(obj, indent=1) -> tuple[str, list[str]]:
    """Strict JSON text of ``obj`` (non-finite floats written as ``null``; never the
    bare ``NaN``/``Infinity`` tokens that are not JSON) and the key paths that
    were replaced (see :func:`finite_json`)."""
    clean, bad = finite_json(obj)
    return json.dumps(clean, indent=indent, allow_nan=False), bad


# --------------------------------------------------------------------------------------
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
        raise ValueError(f"{_table_name(where)} must be a table, got {_type_name(d)} {d!r}")
    for k in d:
        if k not in allowed:
            raise ValueError(f"unknown key '{where}.{k}' in {_table_name(where)} "
                             f"(allowed: {', '.join(sorted(allowed))})")


def require_key(where: str, d: dict, key: str):
    """``d[key]``, or ``ValueError`` naming the table and the missing key."""
    if key not in d:
        raise ValueError(f"[{where}] is missing the required key '{key}'")
    return d[key]


def _type_name(v) -> str:
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
        raise ValueError(f"[{where}] {key} = {v!r} must be a number{u}, got {_type_name(v)}")
    x = float(v)
    if not math.isfinite(x):
        raise ValueError(f"[{where}] {key} = {v!r} must be a finite number{u}")
    return x


def check_integer(where: str, key: str, v, lo: int | None = None) -> int:
    """``int(v)`` of a TOML integer (>= ``lo``), or ``ValueError`` naming table and key."""
    if not isinstance(v, (int, np.integer)) or isinstance(v, (bool, np.bool_)):
        raise ValueError(f"[{where}] {key} = {v!r} must be an integer, got {_type_name(v)}")
    if lo is not None and v < lo:
        raise ValueError(f"[{where}] {key} = {v} is outside the allowed range [{lo}, inf)")
    return int(v)


def check_string(where: str, key: str, v, choices=None) -> str:
    """``v`` if it is a string (one of ``choices`` when given), else ``ValueError``."""
    if not isinstance(v, str):
        raise ValueError(f"[{where}] {key} = {v!r} must be a string, got {_type_name(v)}")
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


# --------------------------------------------------------------------------------------
class DesignFileMixin:
    """``name`` and ``to_dict`` of a family's design-file object from its validated
    ``data`` dict (file units) -- the part every family's file class shares."""

    @property
    def name(self) -> str:
        return self.data.get("design", {}).get("name", "")

    def to_dict(self) -> dict:
        import copy
        return copy.deepcopy(self.data)


# design files of every family: one loader, dispatched on [design] kind

#: kind -> reader(data: dict) -> design; filled by the families when they are imported
_DESIGN_READERS: dict = {}


def register_design_kind(kind: str, reader) -> None:
    """Register the reader of the design files whose ``[design] kind`` is ``kind``.

    ``reader(data)`` validates a parsed design file (file units: mm, degrees) and
    returns the family's design object, or raises ``ValueError`` naming the table
    and the key.  The object provides ``name`` (str), ``data`` (the validated dict,
    written back by ``save_design``) and ``defaults_lines()`` (the documented
    defaults it relies on, printed by ``gearjax example show``).  So that the
    contact commands take it, its type is registered with
    ``gearjax.tca_result.register_family`` (``gearjax tca`` and ``gearjax efficiency``
    call ``run_tca(design, mis, side=...)`` / ``mesh_efficiency``); so that
    ``gearjax surface`` takes it, it provides ``surface_grid(member, flank, n_u, n_v)``
    (a grid with ``points``, ``normals`` (n_u, n_v, 3), ``params`` (n_u, n_v, k), ``xi``
    (n_u,), ``residual`` and ``converged`` (n_u, n_v): see :func:`write_csv`) and
    ``teeth(member)`` (int).  The hypoid family registers ``hypoid`` and
    ``spiral_bevel``.
    """
    _DESIGN_READERS[kind] = reader


def design_kinds() -> tuple:
    """The ``[design] kind`` values a design file may have (registered families)."""
    return tuple(sorted(_DESIGN_READERS))


def design_from_dict(data, kinds=None):
    """A design object from a parsed design file, by its ``[design] kind``.

    ``kinds`` restricts the accepted kinds (a command made for one family);
    ``ValueError`` naming the table and the key for a missing, unknown or refused kind."""
    if not isinstance(data, dict):
        raise ValueError(f"a design must be a table (dict), got {_type_name(data)}")
    des = data.get("design")
    if not isinstance(des, dict):
        raise ValueError("missing table [design] (with kind = one of "
                         + ", ".join(repr(k) for k in design_kinds()) + ")")
    kind = check_string("design", "kind", require_key("design", des, "kind"), design_kinds())
    if kinds is not None and kind not in kinds:
        raise ValueError(f"[design] kind = {kind!r}: this command takes "
                         + " or ".join(repr(k) for k in kinds) + " designs")
    return _DESIGN_READERS[kind](data)


def load_design(source, kinds=None):
    """Load and validate a design file of any registered family: a path or
    ``example:NAME``.  ``ValueError`` (one line naming the file, the table and the
    key) for any invalid input; ``kinds`` as in :func:`design_from_dict`."""
    data = read_toml(source)
    try:
        return design_from_dict(data, kinds)
    except ValueError as exc:
        raise ValueError(f"design file {str(source)!r}: {exc}") from None


# --------------------------------------------------------------------------------------
# exports


class FlankGrid(NamedTuple):
    """The flank grid of the surface-export protocol, one type for every family
    (returned by the designs' ``surface_grid`` and by the families' grid functions;
    written by :func:`write_flank`).  Shapes (n_xi, n_s) per field, index j from the
    root to the tip (mm, rad):

    points (n_xi, n_s, 3) and normals (n_xi, n_s, 3, out of the tooth) in the
    member's frame; params (n_xi, n_s, k) the family's surface parameters (hypoid:
    s, theta, psi; preset-TE bevel: height above the pitch cone, curve parameter t,
    profile parameter u; VH-CATT: blade coordinate u, trace parameter v, NaN);
    xi (n_xi,) the face-width positions (hypoid: xi; preset-TE bevel: (L - A_i)/b;
    VH-CATT: axial z, mm); residual (n_xi, n_s) of the point solves; converged
    (n_xi, n_s) bool.  The families' grid functions document their parameters.  A
    NamedTuple, so a pytree: JAX or NumPy arrays.
    """

    points: Any
    normals: Any
    params: Any
    xi: Any
    residual: Any
    converged: Any


def _np(a):
    return np.asarray(a, dtype=float)


class UnconvergedExportError(RuntimeError):
    """A surface export refused because some grid points are not converged solves
    (:func:`check_grid_converged`); nothing is written.  The command maps it to one
    ``gearjax: error:`` line and status 3 (a solve failed on valid input)."""


def check_grid_converged(grid, what: str = "flank") -> None:
    """Refuse to export a grid with any point that is not a converged solve.

    A point is exported only when its ``converged`` flag is set and its position and
    normal are finite; otherwise :class:`UnconvergedExportError` with one line naming
    ``what``, the count of bad points out of the total and the largest residual
    (mm).  Every writer of this module calls it before writing (CSV, XYZ, STL flank,
    STL tooth), so no format carries a point that is not on the surface."""
    conv = np.asarray(grid.converged, bool)
    P, N = _np(grid.points), _np(grid.normals)
    ok = conv & np.all(np.isfinite(P), axis=-1) & np.all(np.isfinite(N), axis=-1)
    bad = int(np.sum(~ok))
    if bad:
        res = _np(grid.residual)
        worst = np.nanmax(np.where(ok, -np.inf, np.abs(res)))
        worst_txt = f"{worst:.3g} mm" if np.isfinite(worst) else "not finite"
        raise UnconvergedExportError(
            f"{what}: {bad} of {ok.size} grid points are not converged solves (largest "
            f"residual {worst_txt}); nothing written -- the grid reaches beyond the flank "
            "that the solves find (check the blank: addendum, dedendum, face width)")


def write_csv(path, grid) -> Path:
    """CSV with one row per grid point: indices, xi, (s, theta, psi), point, normal,
    residual and converged flag (mm, rad).  Refused unless every point converged
    (:func:`check_grid_converged`)."""
    check_grid_converged(grid)
    P, N, prm = _np(grid.points), _np(grid.normals), _np(grid.params)
    res, conv, xi = _np(grid.residual), np.asarray(grid.converged), _np(grid.xi)
    lines = ["i,j,xi,s_mm,theta_rad,psi_rad,x_mm,y_mm,z_mm,nx,ny,nz,residual_mm,converged"]
    for i in range(P.shape[0]):
        for j in range(P.shape[1]):
            vals = [xi[i], *prm[i, j], *P[i, j], *N[i, j], res[i, j]]
            lines.append(f"{i},{j}," + ",".join(f"{v:.17g}" for v in vals) + f",{int(conv[i, j])}")
    return atomic_write(path, "\n".join(lines) + "\n")


def write_xyz(path, grid) -> Path:
    """XYZ point cloud with normals: ``x y z nx ny nz`` per line (mm).  Refused unless
    every point converged (:func:`check_grid_converged`)."""
    check_grid_converged(grid)
    P, N = _np(grid.points).reshape(-1, 3), _np(grid.normals).reshape(-1, 3)
    lines = [" ".join(f"{v:.12g}" for v in (*p, *n)) for p, n in zip(P, N)]
    return atomic_write(path, "\n".join(lines) + "\n")


def flank_triangles(points, normals=None):
    """Triangles (T, 3, 3) of a (n_xi, n_s, 3) grid; oriented along ``normals`` if given."""
    P = _np(points)
    a, b, c, d = P[:-1, :-1], P[1:, :-1], P[1:, 1:], P[:-1, 1:]
    tri = np.concatenate([np.stack([a, b, c], -2).reshape(-1, 3, 3),
                          np.stack([a, c, d], -2).reshape(-1, 3, 3)])
    if normals is not None:
        N = _np(normals)
        nq = (N[:-1, :-1] + N[1:, :-1] + N[1:, 1:] + N[:-1, 1:]).reshape(-1, 3)
        nq = np.concatenate([nq, nq])
        tri = _orient(tri, nq)
    return tri


def _orient(tri, direction):
    fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    flip = np.einsum("ij,ij->i", fn, direction) < 0
    tri = tri.copy()
    tri[flip] = tri[flip][:, [0, 2, 1]]
    return tri


def _stl_text(tri, name) -> str:
    out = [f"solid {name}"]
    for t in tri:
        n = np.cross(t[1] - t[0], t[2] - t[0])
        ln = np.linalg.norm(n)
        n = n / ln if ln > 0 else n
        out.append(f"  facet normal {n[0]:.9g} {n[1]:.9g} {n[2]:.9g}")
        out.append("    outer loop")
        for v in t:
            out.append(f"      vertex {v[0]:.12g} {v[1]:.12g} {v[2]:.12g}")
        out.append("    endloop")
        out.append("  endfacet")
    out.append(f"endsolid {name}")
    return "\n".join(out) + "\n"


def write_stl_flank(path, grid, name: str = "flank") -> Path:
    """ASCII STL of one flank (facets oriented out of the material).  Refused unless
    every point converged (:func:`check_grid_converged`)."""
    check_grid_converged(grid, name)
    return atomic_write(path, _stl_text(flank_triangles(grid.points, grid.normals), name))


def _rot_z(P, a):
    c, s = math.cos(a), math.sin(a)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    return P @ R.T


def tooth_mesh(convex, concave, teeth: int):
    """Closed triangle mesh of one tooth: both flanks, top land, root, toe and heel.

    The convex flank is turned by ``k 2 pi / teeth`` (k in -1, 0, 1) so that both
    flanks bound one tooth: each flank's outward normal at mid face points away
    from the other flank.  The root face joins the fillet-start rows (the flank
    grid of [HFT-hypoid] ends there).  Returns triangles (T, 3, 3) in mm.
    """
    Pv, Nv = _np(convex.points), _np(convex.normals)
    Pc, Nc = _np(concave.points), _np(concave.normals)
    i0, j0 = Pv.shape[0] // 2, Pv.shape[1] // 2
    best = None
    for k in (-1, 0, 1):
        a = 2.0 * math.pi * k / int(teeth)
        Q = _rot_z(Pv, a)
        M = _rot_z(Nv, a)
        dvec = Q[i0, j0] - Pc[i0, j0]
        if np.dot(Nc[i0, j0], dvec) < 0 and np.dot(M[i0, j0], -dvec) < 0:
            dist = np.linalg.norm(dvec)
            if best is None or dist < best[0]:
                best = (dist, Q, M)
    if best is None:
        raise ValueError("the convex and concave flanks do not bound a tooth "
                         "(normals do not point away from each other)")
    _, Qv, Mv = best
    parts = [flank_triangles(Qv, Mv), flank_triangles(Pc, Nc)]
    centre = 0.5 * (Qv.reshape(-1, 3).mean(0) + Pc.reshape(-1, 3).mean(0))
    caps = []
    for A, B in [(Qv[:, -1], Pc[:, -1]), (Qv[:, 0], Pc[:, 0]), (Qv[0, :], Pc[0, :]),
                 (Qv[-1, :], Pc[-1, :])]:
        G = np.stack([A, B], axis=1)            # (n, 2, 3) strip between the two edges
        caps.append(flank_triangles(G))
    caps = np.concatenate(caps)
    ctr = caps.mean(axis=1)
    caps = _orient(caps, ctr - centre)
    return np.concatenate(parts + [caps])


def write_stl_tooth(path, convex, concave, teeth: int, name: str = "tooth") -> Path:
    """ASCII STL of a whole tooth (see :func:`tooth_mesh`).  Refused unless every point
    of both flanks converged (:func:`check_grid_converged`)."""
    check_grid_converged(convex, f"{name}: convex flank")
    check_grid_converged(concave, f"{name}: concave flank")
    return atomic_write(path, _stl_text(tooth_mesh(convex, concave, teeth), name))


def write_flank(path, grid, name: str = "flank") -> Path:
    """Write a flank grid by file extension: .csv, .xyz or .stl."""
    ext = Path(path).suffix.lower()
    if ext == ".csv":
        return write_csv(path, grid)
    if ext == ".xyz":
        return write_xyz(path, grid)
    if ext == ".stl":
        return write_stl_flank(path, grid, name)
    raise ValueError(f"output file {str(path)!r}: extension must be .csv, .xyz or .stl")
