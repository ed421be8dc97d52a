"""Measured flank grids: the reference grid to measure at and the normal deviations a
coordinate measuring machine (CMM) reports there, as one CSV file per member.

The format (docs/correct.md, "The measured-grid file"): comment lines ``# key = value``
first, then one CSV header line and one row per grid point and flank.

Header keys (``#`` lines; other comment lines are ignored):

* ``member``  (required) ``pinion`` or ``gear``;
* ``grid``    (required) ``N_XIxN_S``: face-width positions (toe -> heel) by points
  along the profile (root -> tip), each in [2, 101];
* ``face_margin``, ``height_margin`` (required) fractions in [0, 0.4]: the border left
  at the toe and heel (of the face width) and at the root and tip (of the active blade
  length, fillet start to tip);
* ``design`` (informational) the design's name.

Columns (any order, extra columns ignored):

==============  =====  ===================================================================
column          unit   meaning
==============  =====  ===================================================================
flank           --     ``convex`` or ``concave``
i               --     face-width index, 0 (toe) .. N_XI - 1 (heel)
j               --     profile index, 0 (root side) .. N_S - 1 (tip side)
xi              --     face-width position, -1 toe .. +1 heel (informational)
height          --     fraction of the active blade length, 0 fillet start .. 1 tip
                       (informational)
x_mm y_mm z_mm  mm     nominal point in the member's work frame (origin at the pitch-cone
                       apex, z along the member's axis from the apex towards the heel)
nx ny nz        --     nominal unit normal, pointing out of the tooth material
deviation_um    um     measured normal deviation: signed distance from the nominal point
                       to the measured flank along the nominal normal; positive = material
                       added (the measured flank lies outside the nominal one).  Empty in
                       a reference grid written by ``gearjax surface --reference-grid``.
==============  =====  ===================================================================

:func:`read_measured_grid` refuses, with one ``ValueError`` line naming the file and
the point, a file whose header or columns are missing or malformed, a point index off
the grid, a repeated or missing point, a non-finite number, a deviation beyond
:data:`MAX_DEVIATION_UM` and deviations that look like millimetres (all below
:data:`MM_SUSPECT_UM` and not all zero).  :func:`check_on_reference` refuses a grid
whose points or normals are not those of the design's reference grid.

A leaf module (NumPy and the standard library); files are written atomically.
"""

from __future__ import annotations

import csv
import io as _io
import math
import re
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from gearjax.io.files import atomic_write

__all__ = ["MeasuredGrid", "COLUMNS", "FLANK_NAMES", "MAX_DEVIATION_UM", "MM_SUSPECT_UM",
           "POSITION_TOL_MM", "NORMAL_TOL", "grid_heights", "write_reference_grid",
           "read_measured_grid", "check_on_reference", "parse_grid_size"]

COLUMNS = ("flank", "i", "j", "xi", "height", "x_mm", "y_mm", "z_mm", "nx", "ny", "nz",
           "deviation_um")
FLANK_NAMES = ("convex", "concave")
#: largest |deviation| accepted (um): beyond it the file is not a flank measurement
MAX_DEVIATION_UM = 1000.0
#: deviations all below this (um) and not all zero look like millimetres
MM_SUSPECT_UM = 0.05
#: a point farther than this from the nominal grid point (mm) is not on the reference grid
POSITION_TOL_MM = 0.01
#: a normal differing by more than this (|n - n_ref|, ~ rad) from the nominal one
NORMAL_TOL = 2e-3
#: the frame of the positions of a bevel / hypoid member's grid (a header comment)
WORK_FRAME = "work frame: origin at the pitch-cone apex, z the axis towards the heel"
_MAX_POINTS = 101
_HEADER_REQUIRED = ("member", "grid", "face_margin", "height_margin")


class MeasuredGrid(NamedTuple):
    """A measured (or reference) grid of one member (NumPy arrays; flanks in the order of
    :data:`FLANK_NAMES` that the file holds).

    design : name from the header ('' if absent); member : 'pinion' | 'gear';
    n_xi, n_s : grid size; face_margin, height_margin : fractions; flanks : tuple of
    flank names; points, normals : (n_f, n_xi, n_s, 3) mm and unit vectors;
    deviation_um : (n_f, n_xi, n_s) um, NaN where the file leaves it empty (a reference
    grid); path : the file read.
    """

    design: str
    member: str
    n_xi: int
    n_s: int
    face_margin: float
    height_margin: float
    flanks: tuple
    points: Any
    normals: Any
    deviation_um: Any
    path: str = ""


def parse_grid_size(text: str, where: str) -> tuple[int, int]:
    """``"9x5"`` -> (9, 5), each in [2, 101]; ``ValueError`` naming ``where``."""
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", str(text))
    if not m:
        raise ValueError(f"{where} = {text!r} must look like 9x5 (face-width x profile points)")
    n = int(m.group(1)), int(m.group(2))
    for what, v in zip(("face-width", "profile"), n):
        if not 2 <= v <= _MAX_POINTS:
            raise ValueError(f"{where} {what} points = {v} is outside the allowed range "
                             f"[2, {_MAX_POINTS}]")
    return n


def grid_heights(n_s: int, height_margin: float) -> np.ndarray:
    """Profile fractions of the grid, root -> tip: ``linspace(m_h, 1 - m_h, n_s)``."""
    return np.linspace(float(height_margin), 1.0 - float(height_margin), int(n_s))


def write_reference_grid(path, *, design: str, member: str, grids: dict, face_margin: float,
                         height_margin: float, deviation_um: dict | None = None,
                         comments=(), frame: str | None = None) -> Path:
    """Write the grid(s) ``grids`` (flank name -> :class:`gearjax.io.FlankGrid` of the
    reference grid) as a measured-grid CSV (module docstring), atomically.  Without
    ``deviation_um`` (flank -> (n_xi, n_s) um) the deviation column is left empty;
    ``comments``: extra free-text comment lines (without ``key = value``); ``frame``: the
    family's description of the positions' frame (default: the bevel/hypoid work frame,
    :data:`WORK_FRAME`)."""
    flanks = [f for f in FLANK_NAMES if f in grids]
    if not flanks:
        raise ValueError("write_reference_grid: no flank grid given")
    g0 = grids[flanks[0]]
    n_xi, n_s = np.asarray(g0.points).shape[:2]
    hs = grid_heights(n_s, height_margin)
    out = ["# gearjax measured grid (docs/correct.md)",
           f"# design = {design}", f"# member = {member}", f"# grid = {n_xi}x{n_s}",
           f"# face_margin = {float(face_margin):.6g}",
           f"# height_margin = {float(height_margin):.6g}",
           f"# units: positions mm ({WORK_FRAME if frame is None else frame}); normals out of "
           "the material; deviation_um in um, positive = material added",
           *(f"# {c}" for c in comments), ",".join(COLUMNS)]
    for f in flanks:
        g = grids[f]
        P, N, xi = (np.asarray(a, float) for a in (g.points, g.normals, g.xi))
        if P.shape[:2] != (n_xi, n_s):
            raise ValueError(f"write_reference_grid: flank {f} has shape {P.shape[:2]}, "
                             f"expected {(n_xi, n_s)}")
        dev = None if deviation_um is None else np.asarray(deviation_um[f], float)
        for i in range(n_xi):
            for j in range(n_s):
                d = "" if dev is None else f"{dev[i, j]:.6f}"
                vals = [xi[i], hs[j], *P[i, j], *N[i, j]]
                out.append(f"{f},{i},{j}," + ",".join(f"{v:.10f}" for v in vals) + f",{d}")
    return atomic_write(path, "\n".join(out) + "\n")


def _header(lines, src):
    head = {}
    for ln in lines:
        m = re.fullmatch(r"#\s*([A-Za-z_]+)\s*=\s*(.*?)\s*", ln)
        if m:
            head[m.group(1).lower()] = m.group(2)
    for k in _HEADER_REQUIRED:
        if k not in head:
            raise ValueError(f"{src}: header line '# {k} = ...' is missing (required: "
                             f"{', '.join(_HEADER_REQUIRED)}; docs/correct.md)")
    member = head["member"]
    if member not in ("pinion", "gear"):
        raise ValueError(f"{src}: header member = {member!r} must be 'pinion' or 'gear'")
    n_xi, n_s = parse_grid_size(head["grid"], f"{src}: header grid")
    margins = []
    for k in ("face_margin", "height_margin"):
        try:
            v = float(head[k])
        except ValueError:
            raise ValueError(f"{src}: header {k} = {head[k]!r} must be a number") from None
        if not (math.isfinite(v) and 0.0 <= v <= 0.4):
            raise ValueError(f"{src}: header {k} = {head[k]} is outside the allowed range "
                             f"[0, 0.4]")
        margins.append(v)
    return head.get("design", ""), member, n_xi, n_s, margins[0], margins[1]


def read_measured_grid(path, *, require_deviations: bool = True) -> MeasuredGrid:
    """Read and check a measured-grid CSV (module docstring); ``ValueError`` (one line
    naming the file, the line and the point) for anything malformed.  With
    ``require_deviations=False`` empty deviations are allowed (a reference grid) and
    read as NaN."""
    src = f"--measured {str(path)!r}"
    try:
        text = Path(path).read_text(encoding="utf-8-sig")   # a BOM is dropped
    except UnicodeDecodeError:
        raise ValueError(f"{src}: not a UTF-8 text file") from None
    except IsADirectoryError:
        raise ValueError(f"{src} is a directory, not a file") from None
    except FileNotFoundError:
        raise ValueError(f"{src}: no such file") from None
    lines = text.splitlines()
    comments = [ln.strip() for ln in lines if ln.strip().startswith("#")]
    body = [(k + 1, ln) for k, ln in enumerate(lines)
            if ln.strip() and not ln.strip().startswith("#")]
    design, member, n_xi, n_s, fm, hm = _header(comments, src)
    if not body:
        raise ValueError(f"{src}: no column header line ({','.join(COLUMNS)})")
    hdr_line, hdr = body[0]
    cols = [c.strip().lower() for c in next(csv.reader([hdr]))]
    missing = [c for c in COLUMNS if c not in cols]
    if missing:
        raise ValueError(f"{src} line {hdr_line}: column(s) {', '.join(missing)} missing "
                         f"(required: {','.join(COLUMNS)})")
    at = {c: cols.index(c) for c in COLUMNS}
    P = np.full((2, n_xi, n_s, 3), np.nan)
    N = np.full((2, n_xi, n_s, 3), np.nan)
    D = np.full((2, n_xi, n_s), np.nan)
    seen = np.zeros((2, n_xi, n_s), bool)
    for ln_no, ln in body[1:]:
        row = [c.strip() for c in next(csv.reader(_io.StringIO(ln)))]
        where = f"{src} line {ln_no}"
        if len(row) < len(cols):
            raise ValueError(f"{where}: {len(row)} fields, the header has {len(cols)}")
        f = row[at["flank"]].lower()
        if f not in FLANK_NAMES:
            raise ValueError(f"{where}: flank = {row[at['flank']]!r} must be 'convex' or "
                             f"'concave'")
        idx = []
        for c, n in (("i", n_xi), ("j", n_s)):
            try:
                v = int(row[at[c]])
            except ValueError:
                raise ValueError(f"{where}: {c} = {row[at[c]]!r} must be an integer") from None
            if not 0 <= v < n:
                raise ValueError(f"{where}: {c} = {v} is outside the grid [0, {n - 1}] of the "
                                 f"header grid = {n_xi}x{n_s} (wrong grid)")
            idx.append(v)
        k = FLANK_NAMES.index(f)
        i, j = idx
        if seen[k, i, j]:
            raise ValueError(f"{where}: point ({f}, i={i}, j={j}) is given twice")
        seen[k, i, j] = True
        vals = {}
        for c in ("x_mm", "y_mm", "z_mm", "nx", "ny", "nz", "deviation_um"):
            s = row[at[c]]
            if s == "" and c == "deviation_um" and not require_deviations:
                vals[c] = math.nan
                continue
            if s == "":
                raise ValueError(f"{where}: {c} of point ({f}, i={i}, j={j}) is empty "
                                 f"(a value is required at every point)")
            try:
                v = float(s)
            except ValueError:
                raise ValueError(f"{where}: {c} = {s!r} at point ({f}, i={i}, j={j}) is not "
                                 f"a number") from None
            if not math.isfinite(v):
                raise ValueError(f"{where}: {c} = {s} at point ({f}, i={i}, j={j}) must be a "
                                 f"finite number")
            vals[c] = v
        P[k, i, j] = vals["x_mm"], vals["y_mm"], vals["z_mm"]
        N[k, i, j] = vals["nx"], vals["ny"], vals["nz"]
        D[k, i, j] = vals["deviation_um"]
    present = [k for k in range(2) if seen[k].any()]
    if not present:
        raise ValueError(f"{src}: no grid points (one row per point and flank is required)")
    for k in present:
        if not seen[k].all():
            i, j = np.argwhere(~seen[k])[0]
            raise ValueError(f"{src}: point ({FLANK_NAMES[k]}, i={i}, j={j}) is missing: "
                             f"{int(seen[k].sum())} of {n_xi * n_s} points of the "
                             f"{FLANK_NAMES[k]} flank given (grid = {n_xi}x{n_s})")
    nrm = np.linalg.norm(N[present], axis=-1)
    if np.max(np.abs(nrm - 1.0)) > 1e-3:
        raise ValueError(f"{src}: the normals (nx, ny, nz) must be unit vectors (largest "
                         f"|norm - 1| = {np.max(np.abs(nrm - 1.0)):.3g}, allowed 1e-3)")
    dev = D[present]
    if require_deviations:
        big = np.max(np.abs(dev))
        if big > MAX_DEVIATION_UM:
            k, i, j = np.unravel_index(np.argmax(np.abs(dev)), dev.shape)
            raise ValueError(f"{src}: deviation_um = {dev[k, i, j]:g} at point "
                             f"({FLANK_NAMES[present[k]]}, i={i}, j={j}) is outside the "
                             f"allowed range [-{MAX_DEVIATION_UM:g}, {MAX_DEVIATION_UM:g}] um")
        if 0.0 < big < MM_SUSPECT_UM:
            raise ValueError(f"{src}: every |deviation_um| is below {MM_SUSPECT_UM:g} um "
                             f"(largest {big:.3g}): the deviations look like mm, the column "
                             f"is in um (1 mm = 1000 um; a measurement has ~1 um of noise)")
    return MeasuredGrid(design, member, n_xi, n_s, fm, hm,
                        tuple(FLANK_NAMES[k] for k in present), P[present], N[present], dev,
                        str(path))


def check_on_reference(measured: MeasuredGrid, points, normals,
                       tol_mm: float = POSITION_TOL_MM, tol_normal: float = NORMAL_TOL) -> None:
    """Refuse (``ValueError``, one line naming the worst point) a measured grid whose
    points or normals are not the nominal ones ``points``/``normals`` ((n_f, n_xi, n_s,
    3), the design's reference grid for the same flanks, grid and margins) within
    ``tol_mm`` / ``tol_normal``: the file was made for another design, grid or
    margins."""
    P, N = np.asarray(points, float), np.asarray(normals, float)
    src = f"--measured {measured.path!r}"
    for what, a, b, tol, unit in (("point", measured.points, P, tol_mm, " mm"),
                                  ("normal", measured.normals, N, tol_normal, "")):
        d = np.linalg.norm(np.asarray(a) - b, axis=-1)
        if not np.max(d) <= tol:
            k, i, j = np.unravel_index(np.argmax(d), d.shape)
            raise ValueError(
                f"{src}: the {what} of ({measured.flanks[k]}, i={i}, j={j}) is {d[k, i, j]:.4g}"
                f"{unit} from the design's reference grid (allowed {tol:g}{unit}): the file is "
                f"not on this design's grid (grid = {measured.n_xi}x{measured.n_s}, margins "
                f"{measured.face_margin:g}/{measured.height_margin:g}; write it with gearjax "
                f"surface --reference-grid)")
