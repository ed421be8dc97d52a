"""Tooth contact analysis (TCA) of two tooth surfaces — the generic core.

Two tooth surfaces, each given in its own body frame whose rotation axis is the
body z axis, are mounted in one fixed frame with the misalignments dE, dP, dG,
dSigma (:mod:`gearjax.tca.assembly`: the mounting equations and their definition).

**Contact equations** (Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd
ed., ch. 9): for a given pinion angle phi1, unknowns x = (u1, v1, u2, v2, phi2),

    r1f(u1, v1, phi1) - r2f(u2, v2, phi2) = 0                   (3 equations)
    n1f . ta = 0,   n1f . tb = 0                                (2 equations)

with ``ta = k2 x n2f/|k2 x n2f|`` (``k2`` the gear axis) and ``tb = n2f x ta`` an
orthonormal basis of the gear's tangent plane: the normals are collinear exactly
when n1 is orthogonal to that plane (orientation-free).  The normals are the
*tool* normals at the solved generating motion where a flank is a
:class:`~gearjax.surfaces.GeneratedSurface` (same tangent plane as the envelope,
one derivative fewer to compile).  This square 5x5 system is regular for *point
contact*.  For *line contact* (conjugate pairs, and any pair whose flanks touch
along a line, e.g. a spur pair with a profile-only modification) its Jacobian is
singular along the contact line.  Line-contact mode fixes the pinion face-width
coordinate ``v1`` (at its value in the initial guess of the reference point) and
drops ``n1f . tb``: at a line contact the relative curvature tensor annihilates
the contact-line direction, so of the two normal equations only the one across
the contact line carries information; ``ta`` is perpendicular to the gear axis,
hence never along the contact line of a spur or helical flank (contact lines
parallel or inclined at the base helix angle to the axis).  Unknowns then are
(u1, u2, v2, phi2): 4 equations, 4 unknowns.

The solve is the implicit-differentiated Newton of :mod:`gearjax.newton`,
continued along the mesh cycle with ``lax.scan`` from the reference point (the
middle grid point) forwards and backwards, each step started from a linear
predictor of the two previous solutions.

**Transmission error** (unloaded), reported in arc-seconds at the output boundary:

    TE(phi1) = s2 (phi2 - phi2_0) - |rho| (phi1 - phi1_0)

with ``rho`` the nominal signed ratio (phi2 turns by rho*dphi1 about the gear body
axis, e.g. ``-z1/z2`` for an external parallel pair) and ``s2 = sign(rho)``:
TE > 0 means the gear is ahead of its nominal position in its direction of
motion.  ``(phi1_0, phi2_0)`` is the reference contact (the middle grid point).

**Contact ellipse** for an elastic approach ``delta`` (default 0.00632 mm, Litvin's
customary value): with both flanks' Weingarten maps taken for the common normal,
the relative (induced) curvature tensor of the tangent plane is
``B = B1 - B2`` (``B_i = -A^T W_i A`` in an orthonormal tangent basis ``A``); the
gap between the flanks at a tangent offset t is ``t.B.t/2`` to second order, so the
contact ellipse ``t.B.t/2 = delta`` has semi-axes ``sqrt(2 delta/lambda_i)``
(``lambda_i`` eigenvalues of B) along its eigenvectors (Litvin & Fuentes §9.4:
``2a = 2 sqrt(delta/A)``, ``A = lambda_min/2``).  For line contact the long axis is
infinite (reported as ``inf``).

Family adapters build the flanks, the assembly, the initial guess and the flank
boundaries: :mod:`gearjax.gears.involute.tca` (rack-generated involute pairs) and
:mod:`gearjax.gears.hypoid.tca` (face-milled spiral-bevel and hypoid pairs).  Figures:
:mod:`gearjax.plot.tca`; CLI: ``gearjax tca``; documentation: ``docs/tca.md``.

Units: mm, rad inside; arc-seconds only in keys/fields named ``*_arcsec``.
"""

from __future__ import annotations

from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.frames import matrix_z
from gearjax.errors import ConvergenceError, check_int, check_range, require_converged
from gearjax.newton import newton_solve, split_derivative
from gearjax.tca.assembly import Assembly, Misalignment, gear_mount, rotation_about  # re-exported
from gearjax.tca.multi_pair import MultiPair, multi_pair, pair_arrays  # re-exported
from gearjax.surfaces import GeneratedSurface, local_geometry, point_and_normal

__all__ = ["pair_arrays", "Misalignment", "Assembly", "contact_equations", "contact_system", "ContactSystem",
           "local_geometry_on", "point_normal", "flank_at", "path_tangent", "relative_to_start",
           "whole_turns_removed",
           "solve_grid", "gear_mount",
           "ContactPath", "contact_path", "te_arcsec", "smallest_margin", "require_path",
           "ARCSEC", "ellipse_from_weingarten", "rotation_about", "relative_curvature",
           "MultiPair", "multi_pair", "DEFAULT_APPROACH", "NoContactError",
           "check_on_flank_converged", "check_tca_options", "pinion_angle_grid"]

class NoContactError(ConvergenceError):
    """The flanks do not touch inside their boundaries (a :class:`ConvergenceError`)."""


ARCSEC = np.pi / (180.0 * 3600.0)   # rad per arc-second
DEFAULT_APPROACH = 0.00632          # mm, elastic approach of the contact ellipse



class ContactPath(NamedTuple):
    """TCA of one tooth pair over a grid of pinion angles (arrays over the grid).

    phi1, phi2 : pinion angle (input) and solved gear angle (rad).
    te : transmission error (rad, sign convention of the module docstring).
    uv1, uv2 : (N, 2) surface parameters of the contact on pinion and gear.
    point : (N, 3) contact point, fixed frame (mm); normal : (N, 3) pinion normal.
    p1_body, p2_body : (N, 3) contact point in the pinion / gear body frame (mm).
    axial1, radial1, axial2, radial2 : axial-projection coordinates (mm) of the
        contact on each flank (body z and distance from the body axis).
    semi_major, semi_minor : contact-ellipse semi-axes (mm; inf for line contact).
    major_dir : (N, 3) unit direction of the major axis (fixed frame).
    residual : max |F| of the contact solve (mm / dimensionless); where the solve
        this point is continued from (the reference contact) failed, at least that
        solve's residual -- every point's TE and pair angle are relative to it.
    converged : Newton converged (and the residual is finite), the reference contact
        too (a point not converged reports the residual of the solve that failed).
    weingarten1, weingarten2 : (N, 3, 3) Weingarten maps of pinion and gear flank in
        the fixed frame for the common normal ``normal`` (1/mm; ``dn = W dr``), the
        curvatures the ellipses come from; the kinematics at the contact points reuse
        them.  ``None`` in paths built by hand.
    psi1, psi2 : (N,) motion parameter of the generating tool at the contact point of a
        generated flank (:class:`~gearjax.surfaces.GeneratedSurface`; NaN for another
        flank), solved with the contact (:func:`contact_system`).
    edge_kind : (N,) int, -1 where the contact is a tangency of the two flanks, else
        the edge (face end or tip) carrying it (index into :data:`gearjax.tca.edge_contact.EDGE_NAMES`;
        there the semi-axes are NaN: no Hertz ellipse at an edge).  ``None`` where face ends were not examined.
    newton_work : () int, the Newton iterations the solves of this path executed, each
        ``vmap``-ed batch counted as its number of lanes times the iterations of its
        slowest lane (a batched ``while_loop`` runs every lane that long): the
        computational work of the TCA, deterministic up to round-off
        (:func:`newton_work`; the cost guard, tests/test_cost_guard.py).
    """

    phi1: jnp.ndarray
    phi2: jnp.ndarray
    te: jnp.ndarray
    uv1: jnp.ndarray
    uv2: jnp.ndarray
    point: jnp.ndarray
    normal: jnp.ndarray
    p1_body: jnp.ndarray
    p2_body: jnp.ndarray
    axial1: jnp.ndarray
    radial1: jnp.ndarray
    axial2: jnp.ndarray
    radial2: jnp.ndarray
    semi_major: jnp.ndarray
    semi_minor: jnp.ndarray
    major_dir: jnp.ndarray
    residual: jnp.ndarray
    converged: jnp.ndarray
    weingarten1: jnp.ndarray | None = None
    weingarten2: jnp.ndarray | None = None
    psi1: jnp.ndarray | None = None
    psi2: jnp.ndarray | None = None
    edge_kind: jnp.ndarray | None = None
    newton_work: jnp.ndarray | None = None


def newton_work(steps):
    """Newton iterations executed by a ``vmap``-ed continuation (int scalar): ``steps``
    (..., T) are the iterations of each lane at each of the T scanned solves; the
    batch runs every lane as long as its slowest, so the work is the number of lanes
    times the sum over the solves of the largest lane count."""
    steps = jnp.asarray(steps)
    lanes = int(np.prod(steps.shape[:-1]))
    return lanes * jnp.sum(jnp.max(steps.reshape(lanes, -1), axis=0))


def smallest_margin(parts):
    """The boundary margin (mm) from its parts (k, ...): the smallest part, taken by
    index so that its derivative is that of the part that is smallest.

    ``jnp.min``'s derivative divides by the number of parts equal to the minimum; where
    the compiled program computes the parts twice (once for the minimum, once for the
    equality test) with different round-off, none is equal and the tangent is
    0/0 = NaN -- seen in forward mode on an involute pair at its tooth-form limit, with
    the CPU backend at optimisation level 0.  ``jnp.minimum``'s derivative tests
    equality the same way (a zero tangent there)."""
    parts = jnp.asarray(parts)
    k = jnp.argmin(parts, axis=0)
    return jnp.take_along_axis(parts, k[None], axis=0)[0]


def te_arcsec(te_rad):
    """Transmission error in arc-seconds (output boundary)."""
    return jnp.asarray(te_rad) / ARCSEC


def relative_curvature(n, W1, W2, t_ref):
    """Relative curvature tensor ``B = B1 - B2`` (2x2, 1/mm) and its tangent basis.

    ``W1, W2`` are the Weingarten maps of the two flanks for the *same* unit normal
    ``n`` (dn = W dr).  ``B_i = -A^T W_i A`` with ``A = [a1, n x a1]``, ``a1`` the unit
    tangent closest to ``t_ref``.  Returns ``(B, A)``.
    """
    a1 = t_ref - jnp.dot(t_ref, n) * n
    a1 = a1 / jnp.linalg.norm(a1)
    A = jnp.stack([a1, jnp.cross(n, a1)], axis=1)
    B = -A.T @ (W1 - W2) @ A
    return 0.5 * (B + B.T), A


def ellipse_from_weingarten(n, W1, W2, t_ref, approach=DEFAULT_APPROACH):
    """Contact ellipse ``(semi_major, semi_minor, major_dir)`` for elastic approach (mm).

    Semi-axes ``sqrt(2 delta/lambda_i)`` from the eigenvalues of the relative
    curvature tensor (module docstring), oriented so that its trace is >= 0 (the
    gap does not depend on the sense of ``n``); ``inf`` where an eigenvalue is <= 0
    (line contact, or flanks that cross, where the quadratic theory gives no ellipse).
    """
    B, A = relative_curvature(n, W1, W2, t_ref)
    # the gap between the flanks does not depend on which way ``n`` points: orient B
    # so that its trace is >= 0 (a definite B then has two positive eigenvalues; an
    # indefinite one -- the flanks cross, no ellipse -- keeps a negative one)
    B = jnp.where(B[0, 0] + B[1, 1] < 0.0, -B, B)
    h = 0.5 * (B[0, 0] + B[1, 1])
    dd = 0.5 * (B[0, 0] - B[1, 1])
    g = jnp.sqrt(dd ** 2 + B[0, 1] ** 2 + 1e-300)
    lam_min, lam_max = h - g, h + g
    ang = 0.5 * jnp.arctan2(B[0, 1], dd) + 0.5 * jnp.pi   # eigenvector of lam_min
    major_dir = A @ jnp.stack([jnp.cos(ang), jnp.sin(ang)])

    def axis(lam):
        ok = lam > 1e-12
        return jnp.where(ok, jnp.sqrt(2.0 * approach / jnp.where(ok, lam, 1.0)), jnp.inf)

    return axis(lam_min), axis(lam_max), major_dir


def point_normal(surf, uv):
    """Point and unit normal of a flank at ``uv``.

    For a :class:`~gearjax.surfaces.GeneratedSurface` the normal is the tool normal
    at the solved motion parameter (the envelope and the tool share the tangent
    plane), which needs only first derivatives of the tool family and one envelope
    solve; otherwise ``n = r_u x r_v/|r_u x r_v|``.  The orientation is not fixed
    (the contact equations do not depend on it).
    """
    uv = jnp.asarray(uv, float)
    if isinstance(surf, GeneratedSurface):
        return surf.point_normal(uv)
    return point_and_normal(surf, uv)


def solve_grid(F, x_prev, x_prev2, phis, tol, max_steps):
    """Continuation over ``phis`` (lax.scan; ``phis`` may be a tuple of arrays scanned
    together, passed to ``F`` as its parameter): each solve starts from the linear
    predictor ``2 x_prev - x_prev2`` of the two previous points of the path.  A step
    that fails keeps ``x_prev`` and drops the predictor (``x_prev2 = x_prev``) for the
    next step.

    The scan runs without derivatives; those of its roots are attached after it, one
    implicit-function rule per root (:func:`gearjax.newton.split_derivative`): a
    gradient then neither traces nor compiles the scan's linearisation."""
    F_frozen, attach = split_derivative(F, x_prev, jax.tree.map(lambda a: a[0], phis))
    sols = _continue_frozen(F_frozen, x_prev, x_prev2, phis, tol, max_steps)
    return sols._replace(x=jax.vmap(attach)(sols.x, phis))


def _continue_frozen(F_frozen, x_prev, x_prev2, phis, tol, max_steps):
    """The scan of :func:`solve_grid` on a system cut from differentiation
    (``F_frozen`` of :func:`gearjax.newton.split_derivative`); roots without
    derivatives."""
    sg = jax.lax.stop_gradient

    def step(carry, phi):
        x_prev, x_prev2 = carry
        pred = 2.0 * x_prev - x_prev2
        sol = newton_solve(F_frozen, pred, phi, tol=tol, max_steps=max_steps,
                           natural_monotonicity=True, noise_floor=True)
        ok = sol.converged
        return (jnp.where(ok, sol.x, x_prev), x_prev), sol

    _, sols = jax.lax.scan(step, (sg(x_prev), sg(x_prev2)), sg(phis))
    return sols


_solve_grid = solve_grid


def relative_to_start(converged, residual, start_converged, start_residual):
    """``(converged, residual)`` of solves continued from a start solve: a point is
    converged only where the start converged too, and its residual is at least the
    start's where the start failed (a continuation from a failed start solves the
    equations relative to a wrong reference: its own tiny residual must not read as
    a converged point, and a convergence message must report the start's residual)."""
    conv = converged & start_converged
    res = jnp.where(start_converged, residual,
                    jnp.maximum(residual, jnp.where(jnp.isfinite(start_residual),
                                                    start_residual, jnp.inf)))
    return conv, res


def whole_turns_removed(te, ph2, ratio_sign):
    """``(te, phi2)`` with whole gear turns taken out of the TE (rad): a solve may land on
    the gear turned by ``2 pi k`` from the pair's position -- the same contact of the same
    teeth, exactly -- whose TE computed from the raw angle is off by ``2 pi k``
    (a KHK 12/24 spur pair at 8 grid steps per pitch: tip-edge contacts at 50, 100 and
    150 rad of TE).  ``k = round(te / 2 pi)``; ``phi2`` moves with it.  No derivative flows
    through ``k`` (piecewise constant)."""
    k = jax.lax.stop_gradient(jnp.round(te / (2.0 * jnp.pi)))
    return te - 2.0 * jnp.pi * k, ph2 - ratio_sign * 2.0 * jnp.pi * k


def path_tangent(F, x, phi):
    """``dx/dphi = -F_x^{-1} F_phi`` of the root ``x(phi)`` of ``F(x, phi) = 0`` at a
    solved point (no derivative flows through it): the first-order predictor of a
    continuation step."""
    x = jax.lax.stop_gradient(x)
    phi = jax.lax.stop_gradient(phi)
    J, F_phi = jax.jacfwd(F, (0, 1))(x, phi)          # one forward-mode pass
    return -jnp.linalg.solve(J, F_phi)


def _contact_residual(asm_mount, mis, line_contact, ph1, ph2, q1, m1, q2, m2):
    """The 5 (line contact: 4) contact equations of the module docstring from the two
    flanks' body-frame points and normals."""
    R, c = asm_mount
    ez = jnp.array([0.0, 0.0, 1.0])
    R1 = matrix_z(ph1)
    R2 = R @ matrix_z(ph2)
    p1 = R1 @ q1 + mis.dP * ez
    p2 = c + R2 @ q2
    n1 = R1 @ m1
    n2 = R2 @ m2
    ta = jnp.cross(R[:, 2], n2)
    ta = ta / jnp.linalg.norm(ta)
    if line_contact:
        return jnp.concatenate([p1 - p2, jnp.stack([jnp.dot(n1, ta)])])
    tb = jnp.cross(n2, ta)
    return jnp.concatenate([p1 - p2, jnp.stack([jnp.dot(n1, ta), jnp.dot(n1, tb)])])


def _packing(line_contact, v1_fixed):
    def unpack(x):
        if line_contact:
            return jnp.stack([x[0], jnp.asarray(v1_fixed, float)]), x[1:3], x[3]
        return x[0:2], x[2:4], x[4]

    def pack(x5):
        if line_contact:
            return jnp.stack([x5[0], x5[2], x5[3], x5[4]])
        return x5
    return unpack, pack


def contact_equations(r1: Callable, r2: Callable, asm: Assembly, mis: Misalignment,
                      line_contact: bool, v1_fixed=0.0):
    """The contact system ``F(x, phi1)`` of the module docstring, with ``unpack`` and
    ``pack`` between the solver unknowns and ``(uv1, uv2, phi2)`` / the 5-vector.

    Point contact: x = (u1, v1, u2, v2, phi2), 5 equations.  Line contact: x =
    (u1, u2, v2, phi2) with ``v1 = v1_fixed``, 4 equations.  Position equations in
    mm, normal equations dimensionless.  A generated flank's point and normal come
    from its envelope solve (nested); :func:`contact_system` carries the motion
    parameters as unknowns instead.
    """
    mount = gear_mount(asm, mis)
    unpack, pack = _packing(line_contact, v1_fixed)

    def F(x, ph1):
        uv1, uv2, ph2 = unpack(x)
        q1, m1 = point_normal(r1, uv1)
        q2, m2 = point_normal(r2, uv2)
        return _contact_residual(mount, mis, line_contact, ph1, ph2, q1, m1, q2, m2)

    return F, unpack, pack


class ContactSystem(NamedTuple):
    """The contact equations with the envelope parameters as unknowns
    (:func:`contact_system`).  ``F(z, phi1)``; ``split(z) -> (x, psi1, psi2)`` and
    ``join(x, psi1, psi2) -> z`` (``psi_i`` is ``None`` for a flank that is not a
    :class:`~gearjax.surfaces.GeneratedSurface`); ``unpack``/``pack`` as in
    :func:`contact_equations`; ``point1(z, phi1)`` the pinion contact point in the
    fixed frame."""

    F: Callable
    split: Callable
    join: Callable
    unpack: Callable
    pack: Callable
    point1: Callable


def flank_at(r, uv, psi):
    """Body-frame point, unit normal and meshing residual of a flank at ``uv``: at the
    motion ``psi`` of a generated flank (:meth:`~gearjax.surfaces.GeneratedSurface.at`),
    or ``(point, normal, None)`` of another flank (``psi`` is then ``None``)."""
    if psi is None:
        q, m = point_normal(r, uv)
        return q, m, None
    return r.at(uv, psi)


def contact_system(r1: Callable, r2: Callable, asm: Assembly, mis: Misalignment,
                   line_contact: bool, v1_fixed=0.0) -> ContactSystem:
    """The contact system with each generated flank's motion parameter ``psi_i`` as an
    unknown and its meshing equation ``n_i . dr_i/dpsi_i = 0`` beside the contact
    equations (Litvin & Fuentes ch. 9): unknowns ``z = (x, psi1, psi2)`` (the
    ``psi`` of the generated flanks only), equations the 5 (4) of
    :func:`contact_equations` and one meshing equation per generated flank (mm/rad).
    Same roots and the same implicit derivatives as the nested form (where a root
    satisfies the meshing equations, point and tool normal are the envelope's), but
    every function inside the Newton iteration is explicit -- no envelope solve
    nested in the contact solve, its Jacobian or its derivative rule.
    """
    mount = gear_mount(asm, mis)
    unpack, pack = _packing(line_contact, v1_fixed)
    gen = (isinstance(r1, GeneratedSurface), isinstance(r2, GeneratedSurface))
    nx = 4 if line_contact else 5

    def split(z):
        x, i, psis = z[:nx], nx, []
        for g in gen:
            psis.append(z[i] if g else None)
            i += int(g)
        return x, psis[0], psis[1]

    def join(x, psi1, psi2):
        extra = [jnp.reshape(p, (1,)) for g, p in zip(gen, (psi1, psi2)) if g]
        return jnp.concatenate([x] + extra)

    def F(z, ph1):
        x, psi1, psi2 = split(z)
        uv1, uv2, ph2 = unpack(x)
        q1, m1, f1 = flank_at(r1, uv1, psi1)
        q2, m2, f2 = flank_at(r2, uv2, psi2)
        eqs = _contact_residual(mount, mis, line_contact, ph1, ph2, q1, m1, q2, m2)
        mesh = [jnp.reshape(f, (1,)) for f in (f1, f2) if f is not None]
        return jnp.concatenate([eqs] + mesh)

    def point1(z, ph1):
        x, psi1, _ = split(z)
        uv1 = unpack(x)[0]
        q1 = r1(uv1) if psi1 is None else r1.family(uv1, psi1)
        return matrix_z(ph1) @ q1 + mis.dP * jnp.array([0.0, 0.0, 1.0])

    return ContactSystem(F, split, join, unpack, pack, point1)


def local_geometry_on(r, uv, psi):
    """Local geometry of a flank at ``uv`` (at the solved motion ``psi`` of a generated
    flank: no envelope solve)."""
    if psi is None:
        return local_geometry(r, uv)
    return r.local_geometry_at(uv, psi)


def contact_path(r1: Callable, r2: Callable, asm: Assembly, mis: Misalignment, phi1,
                 x_ref, *, line_contact: bool, approach=DEFAULT_APPROACH,
                 tol: float = 1e-11, max_steps: int = 30) -> ContactPath:
    """Solve the contact equations at every pinion angle of the grid ``phi1`` (traceable).

    ``r1``, ``r2`` : flank functions ``uv -> (3,)`` in the body frames (may close over
    traced design parameters).  ``phi1`` : (N,) increasing grid, N odd; the reference
    contact is at the middle index ``N // 2``.  ``x_ref`` : initial
    guess ``(u1, v1, u2, v2, phi2)`` at ``phi1[N//2]``; it is solved first, then the
    path is continued forwards and backwards.  In line-contact mode ``v1`` stays at
    ``x_ref[1]`` (no derivative flows into it).

    Returns a :class:`ContactPath` (TE relative to the reference contact, in rad).
    """
    phi1 = jnp.asarray(phi1, float)
    n_pts = phi1.shape[0]
    if n_pts % 2 == 0 or n_pts < 3:
        raise ValueError(f"phi1 has {n_pts} positions: an odd number >= 3 is required "
                         "(the reference contact is the middle one)")
    mid = n_pts // 2
    R, c = gear_mount(asm, mis)
    ez = jnp.array([0.0, 0.0, 1.0])
    v1_fixed = jax.lax.stop_gradient(jnp.asarray(x_ref)[1])
    cs = contact_system(r1, r2, asm, mis, line_contact, v1_fixed)

    x_ref = jax.lax.stop_gradient(jnp.asarray(x_ref, float))
    # start values of the motion parameters: the envelope solves at the guess
    psi_ref = [jax.lax.stop_gradient(r.solve(uv).x) if isinstance(r, GeneratedSurface) else None
               for r, uv in ((r1, x_ref[0:2]), (r2, x_ref[2:4]))]
    z0 = cs.join(cs.pack(x_ref), *psi_ref)
    # the reference contact, then one scan vmapped over the two directions away from
    # it; the first step of each starts from the tangent predictor at the reference
    # (a virtual previous point one grid step behind it), later steps from the
    # linear predictor of the two previous points
    # every solve runs without derivatives (``F_frozen``); those of the roots, the
    # reference included, are attached after the scans in one ``vmap``
    # (:func:`solve_grid`): one implicit-function rule in the program, not two
    sg = jax.lax.stop_gradient
    F_frozen, attach = split_derivative(cs.F, z0, phi1[mid])
    ref = newton_solve(F_frozen, z0, sg(phi1[mid]), tol=tol, max_steps=max_steps,
                       natural_monotonicity=True)
    tangent = path_tangent(F_frozen, ref.x, phi1[mid])
    seqs = sg(jnp.stack([phi1[mid + 1:], phi1[:mid][::-1]]))
    behind = ref.x[None, :] - (seqs[:, :1] - sg(phi1[mid])) * tangent[None, :]
    sols = jax.vmap(lambda x2, s: _continue_frozen(F_frozen, ref.x, x2, s, tol, max_steps))(
        behind, seqs)

    def whole(two_ways, at_ref):
        return jnp.concatenate([two_ways[1][::-1], at_ref[None], two_ways[0]], axis=0)

    Z = jax.vmap(attach)(whole(sols.x, ref.x), phi1)
    conv, res = relative_to_start(whole(sols.converged, ref.converged),
                                  whole(sols.residual, ref.residual), ref.converged,
                                  ref.residual)
    ref_x = cs.split(Z[mid])[0]

    def post(z, ph1):
        x, psi1, psi2 = cs.split(z)
        uv1, uv2, ph2 = cs.unpack(x)
        R1, R2 = matrix_z(ph1), R @ matrix_z(ph2)
        g1 = local_geometry_on(r1, uv1, psi1)
        g2 = local_geometry_on(r2, uv2, psi2)
        n = R1 @ g1.n
        W1 = R1 @ g1.W @ R1.T
        n2 = R2 @ g2.n
        s = jnp.sign(jnp.dot(n, n2))
        W2 = s * (R2 @ g2.W @ R2.T)
        a, b, major = ellipse_from_weingarten(n, W1, W2, R1 @ g1.ru, approach)
        p1b = g1.r
        p2b = g2.r
        point = R1 @ p1b + mis.dP * ez
        nan = jnp.full((), jnp.nan)
        return (ph2, uv1, uv2, point, n, p1b, p2b, a, b, major, W1, W2,
                nan if psi1 is None else psi1, nan if psi2 is None else psi2)

    (ph2, uv1, uv2, point, n, p1b, p2b, a, b, major, W1, W2, psi1,
     psi2) = jax.vmap(post)(Z, phi1)
    ph2_0 = ref_x[-1]
    rho = asm.z1 / asm.z2
    te = asm.ratio_sign * (ph2 - ph2_0) - rho * (phi1 - phi1[mid])
    te, ph2 = whole_turns_removed(te, ph2, asm.ratio_sign)
    if line_contact:
        a = jnp.full_like(a, jnp.inf)
    rad1 = jnp.linalg.norm(p1b[:, :2], axis=1)
    rad2 = jnp.linalg.norm(p2b[:, :2], axis=1)
    return ContactPath(phi1, ph2, te, uv1, uv2, point, n, p1b, p2b, p1b[:, 2], rad1,
                       p2b[:, 2], rad2, a, b, major, res, conv, W1, W2, psi1, psi2,
                       newton_work=ref.steps + newton_work(sols.steps))


def require_path(path: ContactPath, what: str = "tooth contact analysis") -> None:
    """Raise :class:`~gearjax.errors.ConvergenceError` if any contact solve failed."""
    require_converged(path.converged, what, path.residual)


def check_on_flank_converged(path: ContactPath, margin) -> None:
    """Raise ConvergenceError if a solve failed between on-flank points, and
    :class:`~gearjax.tca.path.NoContactError` if no grid point is on both flanks (concrete)."""
    conv, res = np.asarray(path.converged), np.asarray(path.residual)   # host arrays
    inside = np.asarray(margin) >= 0.0
    mid = conv.shape[0] // 2
    if not conv[mid]:
        require_converged(conv[mid:mid + 1], "tooth contact at the reference point",
                          res[mid:mid + 1])
    idx = np.nonzero(inside & conv)[0]
    if idx.size == 0:
        raise NoContactError("no contact inside the flank boundaries at any grid position "
                             "(the flanks do not touch); pass throw=False to get the masks")
    if idx.size:
        sl = slice(idx[0], idx[-1] + 1)
        require_converged(conv[sl], "tooth contact analysis on the flank", res[sl])


def check_tca_options(steps_per_pitch, half_pitches, n_pairs, approach) -> None:
    """Validate the grid and ellipse options of the adapters' public TCA functions
    (ValueError naming the parameter and its allowed range)."""
    check_int("steps_per_pitch", steps_per_pitch, lo=2, hi=1000)
    check_int("n_pairs", n_pairs, lo=3, hi=9)
    if n_pairs % 2 == 0:
        raise ValueError(f"n_pairs = {n_pairs} must be odd (pairs -k..k)")
    check_range("half_pitches", half_pitches, 0.5, 4.0)
    check_range("approach", approach, 0.0, 1.0, lo_open=True, unit="mm")


def pinion_angle_grid(phi1_ref, z1: int, steps_per_pitch: int, half_pitches: float):
    """The TCA grid of pinion angles (rad) of every adapter: ``phi1_ref + h k`` with
    ``h = 2 pi/(z1 steps_per_pitch)`` and ``|k| <= round(half_pitches steps_per_pitch)``
    (``2 round(half_pitches steps_per_pitch) + 1`` angles, the middle one ``phi1_ref``).
    ``phi1_ref`` may be traced; the rest are static."""
    h = 2.0 * np.pi / (z1 * steps_per_pitch)
    k = int(round(half_pitches * steps_per_pitch))
    return phi1_ref + h * jnp.arange(-k, k + 1, dtype=float)
