"""Edge contact at the face ends (toe, heel) and tip edges of tooth flanks, found by the TCA.

The surface contact of :func:`gearjax.tca.path.contact_path` is a tangency of the two
flanks.  Where that tangency lies beyond a face end (an uncrowned pair under a
shaft-angle error, a bearing pushed off the face by a misalignment) the flanks
do not touch there: the rigid teeth touch first at the *edge* of one tooth, the
curve where its flank meets its face-end surface.  This module finds those
contacts and picks, at every pinion angle, the one that is actually made.

**Face ends.**  The adapter of a gear family describes the face ends of member
``k`` by a body-frame function ``g_k(q, e)`` (mm) that is zero on the end
``e = -1`` (toe, front end, ``z = -b/2``) or ``e = +1`` (heel, back end) and
grows into the face, e.g. ``g = q_z - e b/2`` for an involute gear and
``g = (F/2)(xi(q) - e)`` with the face-width position ``xi`` for a bevel gear.
The edge curve is the intersection of the flank with ``g_k = 0``; its tangent at
a point ``q`` is ``m_k x grad g_k(q)`` (``m_k`` the flank normal).

**Edge-contact equations** (curve-to-surface tangency, Litvin & Fuentes,
*Gear Geometry and Applied Theory*, 2nd ed., §9.3 and ch. 15, where the crossing
of the axes of unmodified helical gears causes edge contact): at pinion angle
``phi1``, unknowns ``(u1, v1, u2, v2, phi2)`` and the generating motions of the
generated flanks (as in :func:`gearjax.tca.path.contact_system`), for an edge of
member ``k`` touching flank ``j``::

    r1f - r2f = 0                                        (3)  common point
    g_k(q_k, e) = 0                                      (1)  on the edge
    n_jf . R_k (m_k x grad g_k) / |m_k x grad g_k| = 0   (1)  edge tangent in
                                                              flank j's tangent plane
    n_i . dr_i/dpsi_i = 0                                     meshing equations

a square system of the same size as the point-contact system.  It is reached
from the surface contact at the reference pinion angle by a homotopy
``g_k = s g_k(q_ref)``, ``s = 1 -> 0`` (at ``s = 1`` the surface contact solves it:
the normals are collinear, so any tangent is in flank j's tangent plane), and
continued along the grid of pinion angles like the surface contact (the
implicit-differentiated Newton of :mod:`gearjax.newton`; derivatives of the
edge contact with respect to every design field follow).

**Which contact is made.**  The teeth are rigid: at a pinion angle the gear
turns until the first pair of points touches.  The candidates are the surface
contact (valid where it lies inside both flanks) and the edge contacts -- four face
ends, two tips, four corners -- (valid where the edge point lies inside the other boundaries of its
flank -- tip or face width, root -- and the point of flank ``j`` inside flank ``j``).  The contact made
is the candidate furthest ahead in the sense of the load, ``max s TE`` with
``s = +1`` on the drive side and ``-1`` on the coast side -- the rule of the TE
envelope of consecutive pairs (:func:`gearjax.tca.multi_pair`).  Where the surface
contact lies off the flanks, an edge contact of pair 0 is kept only where it carries
the load, i.e. is not behind the neighbouring pairs (pair 0 shifted by whole
pitches); one far behind them would touch only under a load that closes that gap,
and is reported in :class:`EdgeContact` but not taken into the path.  Where the
face-width section ``z`` touches at ``f(z)`` (the TE of the profile section at
``z``), this is ``max f`` over the face: the interior tangency where ``f`` peaks
inside, an end where it peaks there.  The surface contact is kept unless an edge
leads it by more than ``EDGE_LEAD`` (1e-9 rad, 2e-4 arcsec): along a line contact
(a conjugate pair) every section touches at once and the contact is not an edge;
for the same reason, in line-contact mode (one face-width section solved), a
face-end contact with the TE of that section is a point of its contact line.

At an edge contact no Hertz ellipse exists (one radius of curvature is zero: the
load concentrates on the edge); the path reports the semi-axes as NaN there and
marks the point in ``edge_kind`` (its major axis and Weingarten maps are those of
the surface solve at that angle, kept finite so that no NaN enters a derivative;
the kinematics at edge points are NaN, :func:`gearjax.tca.result.contact_kinematics`).
**Tip edges** (with ``tips``).  The same system with the tip function ``t_k(q)``
(mm, zero on the tip surface -- addendum cylinder ``r_a - |q_xy|`` of an involute
member, the face cone of a bevel member -- and positive below it) in place of
``g_k``: the contact of a member's tip edge with the mating flank off the path of
contact (premature contact of an incoming pair, prolonged contact of an outgoing
one: the corner contacts of a base-pitch mismatch).  With the TE ``f(r)`` at which
the profile point at radius ``r`` touches, it is the end ``r = r_a`` of ``max f``
over the flank.  Two more candidates (pinion tip, gear tip) in the same ``vmap``.
A spur tip edge is parallel to the mating generatrix: the tangency equation vanishes
identically, so in line-contact mode a tip edge is solved in the face-width section
of the surface path (``v1 = v1`` of the path replaces the tangency: the tip corner of
that transverse profile).  A tip candidate starts at the converged grid point where
the surface contact is nearest its tip (the face ends at the reference).  Root
boundaries are not edges: a generated flank joins its fillet with a common tangent
plane; a tip candidate whose mating point lies below the mating root boundary is
not valid (tip/fillet interference, the fillet is not modelled), and a contact path
that reaches a root boundary leaves the flank (``margin < 0``), which the contact
ratio, the TE envelope and the quality flags report.

**Corners** (with ``tips`` and ``corners``).  Where the TE at which a tip-edge point
touches grows along the face (a shaft-angle error tilts the tip edge against the mating
flank; the flanks of a localised pair diverge differently at the tip), ``max f`` over
the tip edge lies at one of its ends: the corner where the tip surface meets a face
end.  Its contact with flank ``j`` replaces the tangency of the tip-edge system by the
end equation::

    r1f - r2f = 0,   t_k(q_k) = 0,   G_e(q_1, q_2) = 0,   (+ meshing equations)
    G_e = e max(e g_1(q_1, e), e g_2(q_2, e))

(3 + 1 + 1 equations, the size of the edge system): ``G_e = 0`` puts the common point
on the first face end ``e`` of the two members -- the tip's own corner, or, where that
corner lies beyond the mating member's face (face widths or axial positions differ,
the mating face end is crossed first), the point where the tip edge crosses the mating
face end.  (``max`` is not smooth where both face ends are reached at once -- equal
face widths, aligned -- and both branches then give the same point.)  Four more
candidates (two tips x two ends, :data:`CORNER_KINDS`) in the same ``vmap``, started like
the tip edges (homotopy ``t_k = s t_k(q_0)``, ``G_e = s G_e(q_0)`` from the surface
contact nearest the tip) and valid where the point lies above both root boundaries,
inside the mating tip and inside both face widths (to ``CORNER_TOL`` = 1e-8 mm: it lies
on a face end by its equations), and where it is a local maximum of the TE over the
tip's flank (in the sense of the load): the TE at which the flank point ``eps`` from the
corner touches falls along the tip edge into the face and down the profile from the
tip (first-order slopes, :func:`~gearjax.tca.corners.corner_slope`; without this a far branch -- the corner
on the mating flank from inside the mating tooth, thousands of arcsec "ahead" -- was
taken on a localised spiral-bevel pair).  A corner or tip-edge continuation that fails
two grid steps in a row gives up (``CORNER_GIVE_UP``: its Newton loops would hold the
others of the same ``vmap``; giving up on the tip edges too made the involute TCA 2.3x
faster with results bit-identical on every packaged example and 30 crowned, shifted,
helical and misaligned involute cases).  The selection rule is unchanged (a corner
with the TE of the tip-edge candidate -- a spur pair in line contact, aligned -- loses
the tie to the tip edge, which comes first).  In line-contact mode the tip edges are solved in the
section of the path, the corners are not: under a shaft-angle error the corner that
leads is found, ahead of that section by about ``(b/2) dSigma cos(alpha)/r_b2``.

Units: mm, rad.
"""

from __future__ import annotations

from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.frames import matrix_z
from gearjax.newton import newton_solve, split_derivative
from gearjax.tca.corners import (CORNER_GIVE_UP, CORNER_TOL, corner_end, corner_leads,
                                 corner_slope, pose)
from gearjax.tca.path import (ContactPath, contact_system, flank_at, relative_to_start,
                              whole_turns_removed, newton_work)
from gearjax.tca.assembly import gear_mount

__all__ = ["EDGE_NAMES", "FACE_END_KINDS", "TIP_KINDS", "CORNER_KINDS", "EDGE_LEAD",
           "EdgeContact", "edge_contact_system", "face_end_contact"]

#: names of the edges, in the order of :attr:`EdgeContact.kind`: the four face ends,
#: the tip edges of pinion and gear, then the corners (appended: the indices before
#: keep their meaning): the toe/heel end of a member's tip edge where it touches the
#: mating flank -- the member's own corner, or, where that lies beyond the mating
#: member's face, the point where the tip edge crosses the mating face end
EDGE_NAMES = ("pinion toe", "pinion heel", "gear toe", "gear heel", "pinion tip", "gear tip",
              "pinion tip/toe corner", "pinion tip/heel corner",
              "gear tip/toe corner", "gear tip/heel corner")
#: indices into :data:`EDGE_NAMES` of the face ends (toe/heel), of the tip edges and of
#: the corners (tip edge x face end; a corner contact is a tip contact)
FACE_END_KINDS = (0, 1, 2, 3)
TIP_KINDS = (4, 5)
CORNER_KINDS = (6, 7, 8, 9)
#: per candidate: the edge (or tip) belongs to the pinion; its face end e (-1 toe,
#: +1 heel, 0 none); a tip edge; a corner
_PINION = np.array([1.0, 1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0])
_END = np.array([-1.0, 1.0, -1.0, 1.0, 0.0, 0.0, -1.0, 1.0, -1.0, 1.0])
_TIP = np.array([0.0] * 4 + [1.0] * 6)
_CORNER = np.array([0.0] * 6 + [1.0] * 4)

#: rad: an edge contact replaces the surface contact only when it is this far ahead
EDGE_LEAD = 1e-9


class EdgeContact(NamedTuple):
    """The edge contacts beside a surface contact path (arrays over the grid; ``K`` = 4
    face ends, 6 with the tip edges, 10 with the corners, in the order of
    :data:`EDGE_NAMES`).

    kind : (N,) int, -1 where the contact is the surface contact, else the index into
        :data:`EDGE_NAMES` of the edge carrying the contact.
    te : (K, N) TE of each edge contact (rad, the path's reference), NaN where
        that candidate is not valid.
    valid : (K, N) the edge contact converged and lies inside the other
        boundaries of both flanks.
    residual : (K, N) max |F| of the edge-contact solves.
    """

    kind: jax.Array
    te: jax.Array
    valid: jax.Array
    residual: jax.Array


def edge_contact_system(r1: Callable, r2: Callable, asm, mis, g1: Callable, g2: Callable,
                        t1: Callable | None = None, t2: Callable | None = None, *,
                        line_contact: bool = False, v1_fixed=0.0):
    """The edge-contact system ``F(z, theta)`` of the module docstring.

    ``theta = (phi1, s, g0, pinion, e, tip, g0b, corner)``: pinion angle, homotopy
    level, the edge function at the start point, 1.0 for an edge of the pinion (0.0: of
    the gear), face end ``e`` and 1.0 for the tip edge (then ``t_k(q)`` replaces
    ``g_k(q, e)``; ``t1``, ``t2`` default to the face ends); for a corner (``corner``
    1.0, with ``tip``) the tangency is replaced by the end equation
    ``G_e - s g0b = 0``, ``G_e = e max(e g_1(q_1, e), e g_2(q_2, e))`` (zero where the
    common point reaches the first of the two face ends ``e`` -- the tip's own corner,
    or the mating face end where the tip edge crosses it first), ``g0b`` its value at
    the start point.  With ``line_contact`` the tip-edge candidates (not the
    corners) take the line-contact treatment: the edge tangency is replaced by
    ``v1 = v1_fixed`` (one face-width section, that of the surface path).  The unknown
    ``z`` is packed as in :func:`gearjax.tca.path.contact_system` (point contact).  Returns
    ``(F, cs)`` with ``cs`` that :class:`~gearjax.tca.path.ContactSystem`.
    """
    R, c = gear_mount(asm, mis)
    cs = contact_system(r1, r2, asm, mis, False)
    ez = jnp.array([0.0, 0.0, 1.0])

    def edge_fn(g, t):
        if t is None:
            return lambda q, e, tip: g(q, e)
        return lambda q, e, tip: jnp.where(tip > 0.5, t(q), g(q, e))

    h1, h2 = edge_fn(g1, t1), edge_fn(g2, t2)

    def tangency(n_other, Rk, m, grad_g):
        t = Rk @ jnp.cross(m, grad_g)
        nt = jnp.linalg.norm(t)
        return jnp.dot(n_other, t) / jnp.where(nt > 0.0, nt, 1.0)

    def F(z, theta):
        ph1, s, g0, pinion, e, tip, g0b, corner = theta
        q1, m1, f1, q2, m2, f2, R1, R2 = pose(cs, r1, r2, R, z, ph1)
        uv1 = cs.unpack(cs.split(z)[0])[0]
        p1 = R1 @ q1 + mis.dP * ez
        p2 = c + R2 @ q2
        ga, da = jax.value_and_grad(h1)(q1, e, tip)
        gb, db = jax.value_and_grad(h2)(q2, e, tip)
        is1 = pinion > 0.5
        on_edge = jnp.where(is1, ga, gb) - s * g0
        tang = jnp.where(is1, tangency(R2 @ m2, R1, m1, da), tangency(R1 @ m1, R2, m2, db))
        is_corner = corner > 0.5
        if line_contact:
            # a tip edge parallel to the mating generatrix (spur) touches along a
            # line: fix the face-width section instead of the (degenerate) tangency
            tang = jnp.where((tip > 0.5) & ~is_corner, uv1[1] - v1_fixed, tang)
        # a corner: the tip edge meets the first face end e (own or mating member)
        tang = jnp.where(is_corner, corner_end(g1, g2, q1, q2, e) - s * g0b, tang)
        mesh = [jnp.reshape(f, (1,)) for f in (f1, f2) if f is not None]
        return jnp.concatenate([p1 - p2, jnp.stack([on_edge, tang])] + mesh)

    return F, cs


def neighbour_key(key, steps_per_pitch: int):
    """``max_{k != 0} key[i + k p]`` over every whole pitch ``p = steps_per_pitch`` that
    stays on the grid (``-inf`` where none): the load key of the neighbouring tooth pairs
    at grid point ``i`` (pair 0's contact shifted by ``k`` angular pitches is pair
    ``k``'s contact at the same angle, ``k`` = +-1, +-2, ... up to the grid's length)."""
    n = key.shape[0]
    idx = np.arange(n)
    others = jnp.full((n,), -jnp.inf)
    for k in range(1, n // max(steps_per_pitch, 1) + 1):
        for src in (idx - k * steps_per_pitch, idx + k * steps_per_pitch):
            ok = (src >= 0) & (src < n)
            others = jnp.maximum(others, jnp.where(ok, key[np.clip(src, 0, n - 1)], -jnp.inf))
    return others


def _give_up_system(F):
    """``G(z, (theta, keep, dead)) = z - keep`` where ``dead``, else ``F(z, theta)``
    (a pure function of its arguments: the implicit derivative of
    :func:`gearjax.newton.newton_solve` sees every traced value in ``theta``)."""
    def G(z, th):
        th_, keep, dead = th
        return jnp.where(dead, z - keep, F(z, th_))
    return G


def _continue(F, z0, thetas, fresh, restart, n_homotopy, tol, max_steps, give_up=False):
    """Solve ``F(z, theta_i) = 0`` along the scanned ``thetas`` (lax.scan), each solve
    from the linear predictor of the two previous solutions (uniform steps of the
    homotopy level, then of the angle) -- a constant predictor where ``fresh`` (the
    first angle step of each direction).  Where ``restart`` (the first step of the
    second direction) the continuation starts again from the end of the homotopy.  A
    failed step keeps the previous solution.  Where the homotopy has not reached its
    end (its last solve failed) the angle steps are marked not converged.

    With ``give_up`` (traced bool; the tip edges and corners) a direction's
    continuation stops after the homotopy failed or :data:`CORNER_GIVE_UP` angle steps
    failed in a row: its remaining steps are marked not converged and solve the trivial
    ``z - z_prev = 0`` instead (one Newton step), so that a lost candidate does not keep
    the candidates solved beside it in the same ``vmap`` iterating to ``max_steps``
    (their Newton loops run as long as the slowest).

    The scan runs without derivatives; those of its roots are attached after it
    (:func:`gearjax.newton.split_derivative`, as :func:`gearjax.tca.path.solve_grid`)."""
    sg = jax.lax.stop_gradient
    th0 = jax.tree.map(lambda a: a[0], thetas)
    G_frozen, attach = split_derivative(_give_up_system(F), z0, (th0, z0, jnp.asarray(False)))

    def step(carry, inp):
        x_prev, x_prev2, x_home, ok_h, fails = carry
        theta, new, again, i = inp
        x_prev = jnp.where(again, x_home, x_prev)
        fails = jnp.where(again, 0, fails)
        linear = 2.0 * x_prev - x_prev2
        pred = jnp.where(new, x_prev, linear)
        dead = give_up & ((fails >= CORNER_GIVE_UP) | ((i >= n_homotopy) & ~ok_h))

        sol = newton_solve(G_frozen, pred, (theta, pred, dead),
                           tol=tol, max_steps=max_steps, natural_monotonicity=True,
                           noise_floor=True)
        ok = sol.converged & ~dead
        ok_h = jnp.where(i == n_homotopy - 1, ok, ok_h)
        sol = sol._replace(converged=ok & ((i < n_homotopy) | ok_h))
        fails = jnp.where(i >= n_homotopy, jnp.where(ok, 0, fails + 1), 0)
        x_new = jnp.where(ok, sol.x, x_prev)
        x_home = jnp.where(i == n_homotopy - 1, x_new, x_home)
        return (x_new, x_prev, x_home, ok_h, fails), (sol, pred, dead)

    idx = jnp.arange(fresh.shape[0])
    z0 = sg(z0)
    _, (sols, preds, deads) = jax.lax.scan(
        step, (z0, z0, z0, jnp.asarray(True), jnp.asarray(0)), (sg(thetas), fresh, restart, idx))
    return sols._replace(x=jax.vmap(attach)(sols.x, (thetas, preds, deads)))


def face_end_contact(r1: Callable, r2: Callable, asm, mis, path: ContactPath, margin,
                     margin_parts: Callable, g1: Callable, g2: Callable, *, drive,
                     steps_per_pitch: int, line_contact: bool = False, tips=None,
                     corners: bool = True, tol: float = 1e-11, max_steps: int = 30,
                     n_homotopy: int = 8):
    """Edge contacts (face ends, and tip edges with ``tips``) beside ``path`` and the
    contact actually made (traceable).

    ``path``, ``margin`` : the surface contact path and its boundary margin (mm).
    ``margin_parts(p1_body, p2_body, uv1, uv2) -> (face1, tip1, root1, face2, tip2, root2)`` :
    boundary margins (mm, >= 0 inside) of each member's face width, tip and root (form
    circle / fillet) boundaries at body-frame points (N, 3) with their flank parameters
    (N, 2) (a generated flank continues past its edge of regression onto a second
    branch at the same radii: the parameters tell the branches apart); without ``tips`` also
    ``(face1, rest1, face2, rest2)``, tip and root together.  ``g1, g2`` : face-end
    functions of pinion and gear (module docstring).  ``tips = (t1, t2)`` : tip-edge
    functions ``t_k(q)`` (mm, zero on the tip surface, > 0 below it) of pinion and
    gear, or ``None`` (face ends only).  ``corners`` (with ``tips``): also the four
    corner candidates (each tip edge at each end; module docstring, "Corners").  ``drive`` : True on the drive side (may be traced).
    ``steps_per_pitch`` : grid steps per angular pitch (the neighbouring tooth pairs
    are pair 0 shifted by that many steps).
    ``line_contact`` : ``path`` was solved in line-contact mode (one face-width section):
    a face-end contact with the TE of that section lies on its contact line and is
    not an edge contact; the tip edges are solved in that section
    (:func:`edge_contact_system`).

    Returns ``(path, margin, edges)``: the path with the contact made at every grid
    point (surface or edge), its margin (>= 0 on the flanks; 0 on the edge's own face
    end), and the :class:`EdgeContact`.  The TE keeps the reference of ``path``.  An
    edge candidate counts only within half a gear pitch of that reference
    (``|TE - TE_ref| < pi/z2``): further off, its solve converged onto a neighbouring
    gear tooth, not a contact of tooth pair 0 (docs/reliability.md).
    """
    n = path.phi1.shape[0]
    mid = n // 2
    t1, t2 = (None, None) if tips is None else tips
    nc = 4 if tips is None else (10 if corners else 6)
    v1_fixed = jax.lax.stop_gradient(path.uv1[mid, 1])
    F, cs = edge_contact_system(r1, r2, asm, mis, g1, g2, t1, t2, line_contact=line_contact,
                                v1_fixed=v1_fixed)
    R, c = gear_mount(asm, mis)
    s_levels = jnp.linspace(1.0, 0.0, n_homotopy + 1)[1:]
    k = n_homotopy
    steps = np.arange(n - 1)
    levels = jnp.concatenate([s_levels, jnp.zeros(n - 1)])
    cols = jnp.arange(n)

    def start_value(g, t, q, e, tip):
        return g(q, e) if t is None else jnp.where(tip > 0.5, t(q), g(q, e))

    def edge_values(g, t, q, e, tip):
        return jax.vmap(lambda qq: start_value(g, t, qq, e, tip))(q)

    def end_values(e):
        # the corner's end function along the path
        return jax.vmap(lambda a, b: corner_end(g1, g2, a, b, e))(path.p1_body, path.p2_body)

    def one_edge(pinion, e, tip, corner):
        # the start: the surface contact at the reference (face ends) or, for a tip
        # edge, at the converged grid point where the surface contact is nearest that
        # tip (the homotopy is then short and starts on the branch the corner takes
        # where the contact path leaves the flank over the tip)
        gv = jnp.where(pinion > 0.5, edge_values(g1, t1, path.p1_body, e, tip),
                       edge_values(g2, t2, path.p2_body, e, tip))
        gv = jax.lax.stop_gradient(gv)
        near = jnp.argmin(jnp.where(path.converged, jnp.abs(gv), jnp.inf))
        i0 = jnp.where((tip > 0.5) & jnp.any(path.converged), near, mid)
        g0 = gv[i0]
        g0b = jax.lax.stop_gradient(end_values(e))[i0]
        x0 = jnp.concatenate([path.uv1[i0], path.uv2[i0], path.phi2[i0][None]])
        psi0 = [None if p is None else p[i0] for p in (path.psi1, path.psi2)]
        z0 = jax.lax.stop_gradient(cs.join(x0, *psi0))
        # the homotopy s = 1 -> 0 at the start angle, then the continuation along the
        # grid away from the start, first forwards to the grid's end, then again from
        # the start backwards to its beginning -- one scan, one Newton in the program
        n_fwd = n - 1 - i0
        back = steps >= n_fwd
        cols_run = jnp.where(back, i0 - 1 - (steps - n_fwd), i0 + 1 + steps)
        ph0 = jnp.full((k,), path.phi1[i0])
        phis = jnp.concatenate([ph0, path.phi1[jnp.clip(cols_run, 0, n - 1)]])
        # a constant predictor at the first angle step of each direction, the linear
        # predictor of the two previous solutions elsewhere
        turn = steps == n_fwd
        fresh = jnp.concatenate([jnp.zeros((k,), bool), (steps == 0) | turn])
        restart = jnp.concatenate([jnp.zeros((k,), bool), turn & (steps > 0)])
        const = [v + 0.0 * levels for v in (g0, pinion, e, tip, g0b, corner)]
        sols = _continue(F, z0, (phis, levels, *const), fresh, restart, k, tol, max_steps,
                         give_up=tip > 0.5)
        ok_ref = sols.converged[k - 1]
        pos = jnp.where(cols < i0, k + n_fwd + i0 - cols - 1,
                        jnp.where(cols > i0, k + cols - i0 - 1, k - 1))

        def whole(field):
            return field[pos]

        conv_e, res_e = relative_to_start(
            whole(sols.converged), whole(sols.residual), ok_ref, sols.residual[k - 1])
        return whole(sols.x), conv_e, res_e, sols.steps

    pin_np, tip_np, corner_np = _PINION[:nc], _TIP[:nc], _CORNER[:nc]
    Z, conv, res, steps = jax.vmap(one_edge)(*(jnp.asarray(a) for a in
                                             (pin_np, _END[:nc], tip_np, corner_np)))

    def post(z, ph1):
        x, psi1, psi2 = cs.split(z)
        uv1, uv2, ph2 = cs.unpack(x)
        q1, m1, _ = flank_at(r1, uv1, psi1)
        q2, m2, _ = flank_at(r2, uv2, psi2)
        nan = jnp.full((), jnp.nan)
        return (ph2, uv1, uv2, q1, q2, matrix_z(ph1) @ m1, R @ matrix_z(ph2) @ m2,
                nan if psi1 is None else psi1, nan if psi2 is None else psi2)

    (ph2, uv1, uv2, q1, q2, n1, n2, psi1, psi2) = jax.vmap(
        lambda zz: jax.vmap(post)(zz, path.phi1))(Z)
    parts = jax.vmap(margin_parts)(q1, q2, uv1, uv2)
    if nc > 6:
        slope = jax.vmap(lambda zz, pk, ek: jax.vmap(
            lambda z1, p1: corner_slope(cs, r1, r2, R, c, mis, asm, g1, g2, t1, t2, z1, p1,
                                         pk, ek))(zz, path.phi1))(
            Z, jnp.asarray(_PINION[:nc]), jnp.asarray(_END[:nc]))
    else:
        slope = jnp.zeros(Z.shape[:2] + (2,))
    if len(parts) == 4:
        # face ends only: (face1, rest1, face2, rest2), tip and root margins together
        if tips is not None:
            raise ValueError("margin_parts must give (face1, tip1, root1, face2, tip2, root2) "
                             "with tips")
        face1, tip1, face2, tip2 = parts
        root1, root2 = tip1, tip2
    else:
        face1, tip1, root1, face2, tip2, root2 = parts
    pin = pin_np[:, None] > 0.5
    is_tip = tip_np[:, None] > 0.5
    is_corner = corner_np[:, None] > 0.5
    # the edge point inside the other boundaries of its own flank (a face end: tip and
    # root; a tip edge: face width and root; a corner: face width and root, its tip is
    # its equation) and the mating point inside its flank.  A corner lies on a face end
    # of one member by its end equation, and with equal face widths on both: its face
    # margins are zero to the solver's tolerance and count with CORNER_TOL (both ends
    # are checked: the end equation bounds the point at end e only)
    slack = jnp.where(is_corner, CORNER_TOL, 0.0)
    own_root = jnp.where(pin, root1, root2)
    own = jnp.where(is_tip, jnp.where(pin, face1, face2), jnp.where(pin, tip1, tip2)) + slack
    mate = jnp.where(pin, jnp.minimum(face2 + slack, jnp.minimum(tip2, root2)),
                     jnp.minimum(face1 + slack, jnp.minimum(tip1, root1)))
    other = jnp.minimum(jnp.minimum(own, own_root), mate)
    # a corner leads only where the tip edge runs from it into the face behind it in
    # the sense of the load (module docstring, "Corners"): else the tip edge's interior
    # would pass through the mating flank (a corner point on the flank from inside)
    ahead = ~is_corner | corner_leads(slope, drive)
    valid = conv & (other >= 0.0) & ahead
    # TE from the reference contact of the path (not from the path's own value at each
    # angle: where the surface solve failed that may be NaN, and an edge contact there
    # is still a contact)
    te = (path.te[mid] + asm.ratio_sign * (ph2 - path.phi2[mid])
          - (asm.z1 / asm.z2) * (path.phi1 - path.phi1[mid])[None, :])
    te, ph2 = whole_turns_removed(te, ph2, asm.ratio_sign)
    # a contact of tooth pair 0 lies within half a gear pitch of its reference TE: a
    # solve that converged onto the gear turned by a whole pitch (a corner or tip edge
    # against the neighbouring gear tooth, TE about 2 pi / z2 off) is that neighbour's
    # contact, which the multi-pair envelope takes from pair 0 shifted by whole pitches
    valid = valid & (jnp.abs(te - path.te[mid]) < jnp.pi / asm.z2)
    sgn = jnp.where(drive, 1.0, -1.0)
    surf_ok = (margin >= 0.0) & path.converged
    key_s = jnp.where(surf_ok, sgn * path.te, -jnp.inf)
    key_e = jnp.where(valid, sgn * te, -jnp.inf)
    best = jnp.argmax(key_e, axis=0)
    lead = jnp.max(key_e, axis=0)
    # (a) an edge ahead of the surface contact on the flanks replaces it
    use = surf_ok & jnp.isfinite(lead) & (lead > key_s + EDGE_LEAD)
    if line_contact:
        # a face-end point on the line contact of the section solved (same TE): part
        # of the line contact, not an edge contact, also where that section lies off
        # the flanks (on the flanks, (a)'s lead tolerance already keeps it)
        same = path.converged & (jnp.abs(lead - sgn * path.te) <= EDGE_LEAD)
    else:
        same = jnp.zeros_like(use)
    # (b) where the surface contact is off the flanks, an edge contact counts where it
    # carries the load: not behind the neighbouring tooth pairs (pair 0 shifted by
    # whole pitches, with the contacts of (a))
    key_a = jnp.where(use, lead, key_s)
    carries = lead >= neighbour_key(key_a, steps_per_pitch) - EDGE_LEAD
    use = use | (~surf_ok & ~same & jnp.isfinite(lead) & carries)
    kind = jnp.where(use, best, -1)
    cols = jnp.arange(n)

    def pick(edge_arr, surf_arr):
        e = edge_arr[best, cols]
        u = use.reshape(use.shape + (1,) * (surf_arr.ndim - 1))
        return jnp.where(u, e, surf_arr)

    normal_e = jnp.where(pin[..., None], n2, n1)          # the mating flank's normal
    nanv = jnp.full_like(path.semi_major, jnp.nan)
    out = path._replace(
        phi2=pick(ph2, path.phi2), te=pick(te, path.te), uv1=pick(uv1, path.uv1),
        uv2=pick(uv2, path.uv2), normal=pick(normal_e, path.normal),
        p1_body=pick(q1, path.p1_body), p2_body=pick(q2, path.p2_body),
        residual=pick(res, path.residual), converged=pick(conv, path.converged),
        semi_major=jnp.where(use, nanv, path.semi_major),
        semi_minor=jnp.where(use, nanv, path.semi_minor))
    p1b = out.p1_body
    out = out._replace(point=jax.vmap(lambda p, q: matrix_z(p) @ q)(path.phi1, p1b)
                       + mis.dP * jnp.array([0.0, 0.0, 1.0]),
                       axial1=p1b[:, 2], radial1=jnp.linalg.norm(p1b[:, :2], axis=1),
                       axial2=out.p2_body[:, 2],
                       radial2=jnp.linalg.norm(out.p2_body[:, :2], axis=1))
    if path.psi1 is not None:
        out = out._replace(psi1=pick(psi1, path.psi1), psi2=pick(psi2, path.psi2))
    work = newton_work(steps) if path.newton_work is None else path.newton_work + newton_work(steps)
    out = out._replace(edge_kind=kind, newton_work=work)
    edge_margin = jnp.maximum(other[best, cols], 0.0)
    margin_out = jnp.where(use, edge_margin, margin)
    te_valid = jnp.where(valid, te, jnp.nan)
    return out, margin_out, EdgeContact(kind, te_valid, valid, res)
