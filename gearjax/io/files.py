"""Atomic writes, output-path checks and throw JSON: how every gearjax output reaches
the disk.

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
from pathlib import Path

import numpy as np


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
