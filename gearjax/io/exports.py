"""Flank exports (CSV, XYZ, STL) of the one flank-grid type every family returns.

A grid with any non-converged point is refused before anything is written
(:func:`check_grid_converged`); files are written atomically
(:func:`gearjax.io.files.atomic_write`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from gearjax.io.files import atomic_write


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
