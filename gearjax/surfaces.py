"""Differential geometry of parametric and enveloped surfaces by autodiff.

A surface is a function ``r(uv) -> (3,)`` of a parameter pair ``uv = (u, v)``
(mm).  Everything below is obtained by differentiating that function with JAX —
no hand-derived derivative formulas:

* tangents ``r_u, r_v``; unit normal ``n = (r_u x r_v)/|r_u x r_v|``;
* first fundamental form ``I = [[E, F], [F, G]]``, ``E = r_u.r_u`` ...;
* second fundamental form ``II = [[L, M], [M, N]]``, ``L = r_uu.n`` ...;
* the Weingarten map as a 3x3 matrix ``W`` with ``dn = W dr`` for every tangent
  ``dr`` (``W = [n_u n_v] I^{-1} [r_u r_v]^T``; ``W n = 0``);
* normal curvature and geodesic torsion in a tangent direction ``t`` (unit):

      kappa_n(t) = -dn[t].t = II(w, w)/I(w, w),      tau_g(t) = -dn[t].(n x t),

  so that ``dn[t] = -kappa_n t - tau_g (n x t)`` (Rodrigues/Bertrand; the
  convention of the equation for p in [Eigenfunctions] §1, docs/references.md).
  With this sign a sphere of radius R with its *outward* normal has
  kappa_n = -1/R: curvature is positive when the surface bends towards ``n``;
* principal curvatures ``k1 >= k2`` and unit principal directions ``e1, e2``
  (Euler: ``kappa_n = k1 cos^2 phi + k2 sin^2 phi``, ``tau_g = (k2 - k1) sin phi cos phi``).

Enveloped (generated) surfaces.  A tool surface carried by a motion is a family
``r_w(uv, psi)`` in the workpiece frame.  Its relative velocity per unit motion
parameter is ``dr_w/dpsi`` (autodiff) and the meshing (envelope) equation is

    f(uv, psi) = n_w(uv, psi) . dr_w/dpsi = 0 .

The generated surface is the implicit function ``uv -> r_w(uv, psi*(uv))`` with
``psi*`` from :func:`gearjax.newton.newton_solve`; its curvatures come from
differentiating through that solution (implicit function theorem, to any order).
A tool whose unit normal is known in closed form may hand it over
(``GeneratedSurface(..., normal=)``, e.g. a blade cone carried by a machine): the
meshing function then differentiates the family in ``psi`` only; the caller tests
that normal against the autodiff one.

Reference: do Carmo, *Differential Geometry of Curves and Surfaces*, ch. 3;
Litvin & Fuentes, *Gear Geometry and Applied Theory*, 2nd ed., ch. 6–8.
"""

from __future__ import annotations

from functools import partial
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp

from gearjax.newton import NewtonResult, with_value, newton_solve, solve_small

__all__ = [
    "tangents", "unit_normal", "point_and_normal", "fundamental_forms", "weingarten",
    "LocalGeometry", "local_geometry", "principal_curvatures", "normal_curvature",
    "geodesic_torsion", "curvature_in_direction", "meshing_function", "solve_envelope",
    "GeneratedSurface",
]


def _safe_norm(x, axis=-1):
    sq = jnp.sum(x * x, axis=axis)
    pos = sq > 0
    return jnp.where(pos, jnp.sqrt(jnp.where(pos, sq, 1.0)), 0.0)


def tangents(r: Callable, uv):
    """Return ``(r_u, r_v)`` of the surface ``r`` at ``uv`` (forward-mode autodiff)."""
    J = jax.jacfwd(r)(jnp.asarray(uv, float))
    return J[:, 0], J[:, 1]


def unit_normal(r: Callable, uv):
    """Unit normal ``(r_u x r_v)/|r_u x r_v|`` (orientation follows the parametrisation)."""
    return point_and_normal(r, uv)[1]


def point_and_normal(r: Callable, uv):
    """``(r(uv), unit_normal(r, uv))`` from one forward-mode pass."""
    J, p = jax.jacfwd(with_value(r), has_aux=True)(jnp.asarray(uv, float))
    N = jnp.cross(J[:, 0], J[:, 1])
    return p, N / jnp.linalg.norm(N)


def fundamental_forms(r: Callable, uv):
    """First and second fundamental forms ``(I, II)`` as 2x2 matrices (mm, 1)."""
    uv = jnp.asarray(uv, float)
    J = jax.jacfwd(r)(uv)
    H = jax.jacfwd(jax.jacfwd(r))(uv)  # (3, 2, 2)
    n = jnp.cross(J[:, 0], J[:, 1])
    n = n / jnp.linalg.norm(n)
    I = J.T @ J
    II = jnp.einsum("k,kij->ij", n, H)
    return I, II


class LocalGeometry(NamedTuple):
    """First- and second-order geometry of a surface at one point.

    r (3,) mm; n (3,) unit normal; ru, rv (3,) tangents; W (3,3) Weingarten map
    (dn = W dr, 1/mm); k1 >= k2 principal curvatures (1/mm, sign convention of
    the module docstring); e1, e2 (3,) unit principal directions with
    ``e1 x e2 = n``.
    """

    r: jnp.ndarray
    n: jnp.ndarray
    ru: jnp.ndarray
    rv: jnp.ndarray
    W: jnp.ndarray
    k1: jnp.ndarray
    k2: jnp.ndarray
    e1: jnp.ndarray
    e2: jnp.ndarray


def _normal_and_first_order(r):
    """``uv -> (n, (J, r(uv), n))``: the unit normal with the Jacobian and point of its
    own forward-mode pass as ``jacfwd(..., has_aux=True)``'s aux, so that ``dn/duv``,
    the tangents and the point come from one pass."""
    def nfun(uv):
        J, p = jax.jacfwd(with_value(r), has_aux=True)(uv)
        N = jnp.cross(J[:, 0], J[:, 1])
        n = N / jnp.linalg.norm(N)
        return n, (J, p, n)
    return nfun


def weingarten(r: Callable, uv):
    """Weingarten map ``W`` (3x3, 1/mm): ``dn = W dr`` for tangent ``dr``; ``W n = 0``.

    ``W = [n_u n_v] (J^T J)^{-1} J^T`` with ``J = [r_u r_v]``.
    """
    uv = jnp.asarray(uv, float)
    Jn, (J, _, _) = jax.jacfwd(_normal_and_first_order(r), has_aux=True)(uv)
    return Jn @ solve_small(J.T @ J, J.T)


def _principal_from_W(n, W, ru):
    """Principal curvatures/directions from the Weingarten map in an orthonormal frame."""
    a1 = ru / jnp.linalg.norm(ru)
    a2 = jnp.cross(n, a1)
    A = jnp.stack([a1, a2], axis=1)           # (3, 2)
    B = -A.T @ W @ A                          # symmetric shape operator, kappa_n = t.B.t
    B = 0.5 * (B + B.T)
    h = 0.5 * (B[0, 0] + B[1, 1])
    d = 0.5 * (B[0, 0] - B[1, 1])
    g = _safe_norm(jnp.stack([d, B[0, 1]]))
    k1, k2 = h + g, h - g
    phi = 0.5 * jnp.arctan2(B[0, 1], d)
    e1 = jnp.cos(phi) * a1 + jnp.sin(phi) * a2
    e2 = jnp.cross(n, e1)
    return k1, k2, e1, e2


def local_geometry(r: Callable, uv) -> LocalGeometry:
    """Position, normal, Weingarten map, principal curvatures and directions at ``uv``.

    For a :class:`GeneratedSurface` one envelope solve and first-order implicit
    derivatives suffice (:func:`_generated_local_geometry`).
    """
    if isinstance(r, GeneratedSurface):
        return _generated_local_geometry(r, uv)
    uv = jnp.asarray(uv, float)
    Jn, (J, p, n) = jax.jacfwd(_normal_and_first_order(r), has_aux=True)(uv)
    ru, rv = J[:, 0], J[:, 1]
    W = Jn @ solve_small(J.T @ J, J.T)
    k1, k2, e1, e2 = _principal_from_W(n, W, ru)
    return LocalGeometry(p, n, ru, rv, W, k1, k2, e1, e2)


def principal_curvatures(r: Callable, uv):
    """Principal curvatures ``(k1, k2)``, ``k1 >= k2`` (1/mm), and unit directions ``(e1, e2)``."""
    g = local_geometry(r, uv)
    return g.k1, g.k2, g.e1, g.e2


def curvature_in_direction(n, W, t):
    """Normal curvature and geodesic torsion ``(kappa_n, tau_g)`` for tangent ``t``.

    ``kappa_n = -dn[t].t/|t|^2``, ``tau_g = -dn[t].(n x t)/|t|^2`` with ``dn[t] = W t``
    (the normal component of ``t`` is removed first).
    """
    t = t - jnp.dot(t, n) * n
    tt = jnp.dot(t, t)
    dn = W @ t
    return -jnp.dot(dn, t) / tt, -jnp.dot(dn, jnp.cross(n, t)) / tt


def normal_curvature(r: Callable, uv, t):
    """Normal curvature (1/mm) of surface ``r`` at ``uv`` in tangent direction ``t`` (3,)."""
    g = local_geometry(r, uv)
    return curvature_in_direction(g.n, g.W, t)[0]


def geodesic_torsion(r: Callable, uv, t):
    """Geodesic torsion (1/mm) of surface ``r`` at ``uv`` in tangent direction ``t`` (3,)."""
    g = local_geometry(r, uv)
    return curvature_in_direction(g.n, g.W, t)[1]


# --------------------------------------------------------------------------- envelopes

def _tool_at(family: Callable, uv, psi, normal=None):
    """``(r_w, n_w, dr_w/dpsi)`` of the tool family at ``(uv, psi)``: the point, its unit
    normal at fixed ``psi`` (``r_u x r_v/|r_u x r_v|``) and the relative velocity, from
    one forward-mode pass.  ``normal(uv, psi)``, where given, is that normal in closed
    form: the pass then needs the ``psi`` direction only."""
    uv = jnp.asarray(uv, float)
    psi = jnp.asarray(psi, float)
    if normal is not None:
        r, v = jax.jvp(lambda p: family(uv, p), (psi,), (jnp.ones_like(psi),))
        return r, normal(uv, psi), v
    (J, v), r = jax.jacfwd(with_value(family), argnums=(0, 1), has_aux=True)(uv, psi)
    N = jnp.cross(J[:, 0], J[:, 1])
    return r, N / jnp.linalg.norm(N), v


def meshing_function(family: Callable, uv, psi, normal: Callable | None = None):
    """Envelope (meshing) function ``f = n_w . dr_w/dpsi`` (mm per rad of ``psi``).

    ``family(uv, psi) -> (3,)`` is the tool surface in the workpiece frame at motion
    parameter ``psi``; ``n_w`` is its unit normal at fixed ``psi`` (by autodiff, or
    ``normal(uv, psi)`` where the tool's normal is known in closed form).
    """
    _, n, v = _tool_at(family, uv, psi, normal)
    return jnp.dot(n, v)


def solve_envelope(family: Callable, uv, psi0, normal: Callable | None = None,
                   **newton_options) -> NewtonResult:
    """Solve the meshing equation ``f(uv, psi) = 0`` for ``psi`` near ``psi0``.

    Returns the :class:`~gearjax.newton.NewtonResult` for ``psi`` (differentiable
    with respect to ``uv`` and anything ``family`` closes over).
    """
    return newton_solve(lambda psi, q: meshing_function(family, q, psi, normal), psi0,
                        jnp.asarray(uv, float), **newton_options)


class GeneratedSurface:
    """The surface enveloped by a tool family: ``uv -> r_w(uv, psi*(uv))``.

    Parameters
    ----------
    family : ``family(uv, psi) -> (3,)`` tool surface in the workpiece frame (mm).
    psi0 : initial guess for the motion parameter: a number or a callable ``psi0(uv)``.
    normal : optional ``normal(uv, psi) -> (3,)``: the tool's unit normal at fixed
        ``psi`` in closed form, equal to ``r_u x r_v/|r_u x r_v|`` of ``family`` (with
        its orientation and its derivatives with respect to everything it closes
        over); the meshing function and :meth:`at` then differentiate the family in
        ``psi`` only (a smaller program).  Default: by autodiff.
    newton_options : forwarded to :func:`gearjax.newton.newton_solve`.

    Calling the object returns the generated point; ``solve(uv)`` returns the
    Newton result for ``psi`` (with residual and converged flag); ``normal(uv)``
    returns the tool normal at the contact, which equals the generated surface's
    normal wherever the envelope is regular.  The object is a valid surface for
    every function of this module (curvatures differentiate through the solve).
    """

    def __init__(self, family: Callable, psi0, *, normal: Callable | None = None,
                 **newton_options):
        self.family = family
        self.psi0 = psi0
        self.normal = normal
        self.newton_options = newton_options

    def _psi0(self, uv):
        return self.psi0(uv) if callable(self.psi0) else self.psi0

    def solve(self, uv) -> NewtonResult:
        uv = jnp.asarray(uv, float)
        if _cacheable(self):
            return _cached("solve", self, uv)
        return self._solve(uv)

    def _solve(self, uv) -> NewtonResult:
        return solve_envelope(self.family, uv, jax.lax.stop_gradient(self._psi0(uv)),
                              self.normal, **self.newton_options)

    def __call__(self, uv):
        uv = jnp.asarray(uv, float)
        return self.family(uv, self.solve(uv).x)

    def tool_normal(self, uv):
        """Unit normal of the tool surface at the contact (orientation of the tool)."""
        return self.point_normal(uv)[1]

    def point_normal(self, uv):
        """Generated point and tool normal at the solved motion (one envelope solve)."""
        uv = jnp.asarray(uv, float)
        if _cacheable(self):
            return _cached("point_normal", self, uv)
        return self._point_normal(uv)

    def _point_normal(self, uv):
        psi = self._solve(uv).x
        if self.normal is not None:
            return self.family(uv, psi), self.normal(uv, psi)
        return point_and_normal(lambda q: self.family(q, psi), uv)

    def at(self, uv, psi):
        """``(point, tool normal, meshing residual)`` at a *given* motion parameter
        ``psi`` -- explicit, no envelope solve (one forward-mode pass).  On the
        envelope, i.e. where the residual ``n . dr_w/dpsi`` is 0, point and normal are
        those of the generated surface: a contact analysis can carry ``psi`` as an
        unknown with the meshing equation beside its contact equations instead of
        nesting the envelope solve (Litvin & Fuentes ch. 9)."""
        uv = jnp.asarray(uv, float)
        psi = jnp.asarray(psi, float)
        if _cacheable(self):
            return _surface_at_jit("at", self.family, uv, psi, self.normal)
        return _at_impl(self.family, uv, psi, self.normal)

    def local_geometry_at(self, uv, psi) -> "LocalGeometry":
        """:func:`local_geometry` of the generated surface at ``uv`` given the solved
        motion parameter ``psi`` of that point (no envelope solve; ``psi`` must satisfy
        the meshing equation)."""
        uv = jnp.asarray(uv, float)
        psi = jnp.asarray(psi, float)
        if _cacheable(self):
            return _surface_at_jit("geometry", self.family, uv, psi)
        return _generated_local_geometry_at(self, uv, psi)


# --------------------------------------------------------------------------- trace once
#
# A generated surface is evaluated many times in one program: every contact
# equation, every Newton step and line search, every Jacobian (``jacfwd`` = ``vmap``
# of ``jvp``) and every implicit-derivative rule calls the envelope solve again, and
# Python would trace the tool family, its meshing function and the Newton loop
# anew each time (hundreds of thousands of primitive binds for one hypoid TCA).
# When the family is a :class:`jax.tree_util.Partial` of a module-level function
# (a pytree: the function is static, its arguments are leaves) and ``psi0`` is a
# number or such a ``Partial``, the solve, the point-and-normal and the local
# geometry go through ``jax.jit`` functions of ``(family, psi0, uv)``: each is
# traced once per argument structure and shape, and JAX caches the jvp, vmap,
# partial-evaluation and transpose of that one jaxpr, so nested transformations
# reuse it instead of tracing the Python again.  Values are unchanged.

def _cacheable(surf) -> bool:
    P = jax.tree_util.Partial
    return (isinstance(surf.family, P) and (isinstance(surf.psi0, P) or not callable(surf.psi0))
            and (surf.normal is None or isinstance(surf.normal, P)))


def _cached(what, surf, uv):
    psi0 = surf.psi0 if callable(surf.psi0) else jnp.asarray(surf.psi0, float)
    opts = tuple(sorted(surf.newton_options.items()))
    return _surface_jit(what, opts, surf.family, psi0, uv, surf.normal)


@partial(jax.jit, static_argnums=(0, 1))
def _surface_jit(what, opts, family, psi0, uv, normal):
    surf = GeneratedSurface(family, psi0, normal=normal, **dict(opts))
    if what == "solve":
        return surf._solve(uv)
    if what == "point_normal":
        return surf._point_normal(uv)
    return _generated_local_geometry_impl(surf, uv)


def _at_impl(family, uv, psi, normal=None):
    r, n, v = _tool_at(family, uv, psi, normal)
    return r, n, jnp.dot(n, v)


@partial(jax.jit, static_argnums=(0,))
def _surface_at_jit(what, family, uv, psi, normal=None):
    if what == "at":
        return _at_impl(family, uv, psi, normal)
    return _generated_local_geometry_at(GeneratedSurface(family, 0.0), uv, psi)


def _generated_local_geometry(surf: GeneratedSurface, uv) -> LocalGeometry:
    uv = jnp.asarray(uv, float)
    if _cacheable(surf):
        return _cached("geometry", surf, uv)
    return _generated_local_geometry_impl(surf, uv)


def _generated_local_geometry_impl(surf: GeneratedSurface, uv) -> LocalGeometry:
    """:func:`local_geometry` of an enveloped surface with one envelope solve.

    With ``z = (u, v, psi)``, ``g(z)`` the tool family, ``n_t(z)`` its unit normal at
    fixed ``psi`` and ``f(z) = n_t . g_psi`` the meshing function, the solution
    ``psi*(uv)`` of ``f = 0`` has ``dpsi*/duv = -f_uv/f_psi`` (implicit function
    theorem), the envelope's tangents are ``J = g_uv + g_psi dpsi*/duv`` and its unit
    normal is ``n = J_u x J_v/|.|`` -- the same quantities that differentiating
    ``r(uv) = g(uv, psi*(uv))`` gives.  Along a regular envelope the envelope and
    the tool share their tangent plane, ``n(uv) = sgn n_t(uv, psi*(uv))`` (``sgn =
    +-1``), so the Weingarten map needs only *first* derivatives of ``psi*``:
    ``dn/duv = sgn (n_t,uv + n_t,psi dpsi*/duv)`` -- no second derivative through
    the implicit solve (which would trace and compile the solve again for every
    order).  Derivatives with respect to anything the family closes over flow
    through ``psi*`` (custom JVP of the solve) and ``g``.
    """
    return _generated_local_geometry_at(surf, uv, surf._solve(uv).x)


def _generated_local_geometry_at(surf: GeneratedSurface, uv, psi) -> LocalGeometry:
    """The body of :func:`_generated_local_geometry_impl` at a solved ``psi``."""
    z = jnp.concatenate([uv, jnp.reshape(psi, (1,))])

    def g(z):
        return surf.family(z[:2], z[2])

    def nf(z):
        Jz, r = jax.jacfwd(with_value(g), has_aux=True)(z)
        N = jnp.cross(Jz[:, 0], Jz[:, 1])
        nt = N / jnp.linalg.norm(N)
        return jnp.concatenate([nt, jnp.stack([jnp.dot(nt, Jz[:, 2])])]), (Jz, nt, r)

    D, (Jz, nt, r) = jax.jacfwd(nf, has_aux=True)(z)      # (4, 3): d(n_t, f)/dz
    psi_uv = -D[3, :2] / D[3, 2]
    J = Jz[:, :2] + jnp.outer(Jz[:, 2], psi_uv)
    ru, rv = J[:, 0], J[:, 1]
    N = jnp.cross(ru, rv)
    n = N / jnp.linalg.norm(N)
    sgn = jnp.sign(jnp.dot(n, nt))
    Jn = sgn * (D[:3, :2] + jnp.outer(D[:3, 2], psi_uv))
    W = Jn @ solve_small(J.T @ J, J.T)
    k1, k2, e1, e2 = _principal_from_W(n, W, ru)
    return LocalGeometry(r, n, ru, rv, W, k1, k2, e1, e2)
