"""Public entry points of the numerical (mixed-)EHL point-contact solver.

:func:`solve_ehl` (validated, float inputs in gearjax units) and
:func:`ehl_traced` (an :class:`EHLCase` pytree, jit/grad friendly) return an
:class:`EHLResult`; :func:`ehl_gradients` returns d(h_c, h_min, μ)/d(case) by
implicit differentiation (:mod:`gearjax.tribology.ehl.implicit`);
:func:`ehl_fields` the nodal pressure and film of a solution.

Units: load N, speeds mm/s, radii mm, η0 Pa·s, α 1/GPa at the API (1/MPa inside
:class:`EHLCase`), E' and pressures MPa, films mm.  The governing equations are in
:mod:`gearjax.tribology.ehl.model`.

Continuation: heavily loaded cases (large Moes M, where the Hertz start is far
from the EHL solution) are solved by continuation in the Reynolds coefficient:
the entrainment speed (equivalently η0 u_e, at fixed α) is first multiplied by
each factor of ``continuation`` in turn (each stage started from the previous
solution), then the case itself is solved.  ``continuation="auto"`` (the
validated entry point only) tries the schedules of ``AUTO_SCHEDULES`` in turn —
the direct solve from the Hertz start first, then factors < 1 (a heavier start,
for light loads), then factors > 1 — until one converges, and as a last resort
nested iteration: the solution on the grid with n/2 nodes (itself "auto"),
interpolated, as start, solved with pseudo-transient continuation.  Above
``NESTED_ABOVE`` = 128 nodes nested iteration is tried first (a failed direct solve
on a fine grid is expensive); it recurses, so 512² starts from 256², which starts
from 128².  Only the final solve counts for the convergence flag.
"""

from __future__ import annotations

import dataclasses
from functools import partial
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from gearjax.errors import ConvergenceError, check_range
from gearjax.fields import strong_float64
from gearjax.tribology.ehl.grid import EHLGrid, make_grid
from gearjax.tribology.ehl.implicit import attach_implicit_gradient
from gearjax.tribology.ehl.model import EHLCase, fields, make_case, scales, unpack
from gearjax.tribology.ehl.outputs import EHLOutputs, outputs
from gearjax.tribology.ehl.solver import newton_krylov, solve_state
from gearjax.tribology.lubricant import PA_S_TO_MPA_S

__all__ = ["EHLResult", "solve_ehl", "ehl_traced", "ehl_gradients", "ehl_fields",
           "moes_parameters", "AUTO_SCHEDULES", "default_tol"]


_RESULT_DOC = """Outcome of one EHL solve: the scalar outputs of
:class:`gearjax.tribology.ehl.outputs.EHLOutputs` followed by the solver's state.

h_c, h_min : central film (bilinear at the contact centre) and minimum nodal film, mm.
mu, mu_fluid, mu_boundary : friction coefficient and its Ree–Eyring / asperity parts.
F_fluid, F_asperity : loads carried by the fluid and by the asperities, N.
residual : max|R| of the discrete equations (Fischer–Burmeister residual in
    units of p_h; relative load error).
load_error : |∫∫(p + p_a) dA / F - 1|.
steps : Newton steps of the last stage.  converged : residual ≤ tol, finite.
x : the state vector [P, (P_a), H0] (dimensionless; see ehl_fields).
"""

# the output fields are declared once, in EHLOutputs; the result appends the state
EHLResult = NamedTuple("EHLResult", [(f, jax.Array) for f in EHLOutputs._fields]
                       + [(f, jax.Array) for f in ("residual", "load_error", "steps",
                                                   "converged", "x")])
EHLResult.__doc__ = _RESULT_DOC


def moes_parameters(case: EHLCase):
    """Moes dimensionless load and material parameters (M, L) of a case.

    ``U = η0 u_e/(E' Rx)``, ``W = F/(E' Rx²)``, ``G = α E'``;
    ``M = W (2U)^(-3/4)``, ``L = G (2U)^(1/4)`` (Moes 1992; Venner & Lubrecht 2000,
    with u_e the mean rolling speed).
    """
    U = case.eta0 * PA_S_TO_MPA_S * case.u_e / (case.E_prime * case.Rx)
    W = case.F / (case.E_prime * case.Rx ** 2)
    G = case.alpha * case.E_prime
    return W * (2.0 * U) ** -0.75, G * (2.0 * U) ** 0.25


AUTO_SCHEDULES = ((), (0.125, 0.25, 0.5), (8.0, 4.0, 2.0), (32.0, 16.0, 8.0, 4.0, 2.0))


_outputs_jit = jax.jit(outputs, static_argnames=("grid", "mixed"))


def ehl_traced(case: EHLCase, grid: EHLGrid, angle_deg: float = 0.0, mixed: bool = False,
               continuation=(), tol=1e-9, max_steps: int = 60, x0=None, ptc=0.0) -> EHLResult:
    """Solve the EHL problem of ``case`` on ``grid`` (no validation; differentiable).

    The Newton iterations see ``stop_gradient(case)``; derivatives of the outputs
    w.r.t. ``case`` flow only through the implicit-function rule (reverse mode).
    ``continuation`` : tuple of λ multipliers (static), see the module docstring.
    ``x0`` : optional start state (default: Hertz pressure, Hamrock–Dowson H0).
    ``ptc`` : initial pseudo-transient shift (0: plain damped Newton; see
    :func:`gearjax.tribology.ehl.solver.newton_krylov`).
    """
    case = strong_float64(case)          # one compiled solve for every case
    cs = jax.lax.stop_gradient(case)
    st = solve_state(cs, grid, angle_deg, mixed, tol=tol, max_steps=max_steps,
                     continuation=tuple(continuation), x0=x0, ptc=ptc)
    x_star = jax.lax.stop_gradient(st.x)
    out = _attached_outputs(x_star, case, grid, float(angle_deg), bool(mixed))
    return EHLResult(*out, st.residual, st.load_error, st.steps, st.converged, x_star)


@partial(jax.jit, static_argnames=("grid", "angle_deg", "mixed"))
def _attached_outputs(x_star, case, grid, angle_deg, mixed):
    xd = attach_implicit_gradient(x_star, case, grid, angle_deg, mixed)
    return outputs(xd, case, grid, mixed)[0]


def _check_grid_inputs(n, angle_deg):
    check_range("n", n, 16, 1024)
    check_range("angle_deg", angle_deg, -180.0, 180.0, unit="deg")


def solve_ehl(F, u_e, u_s, Rx, Ry, eta0, alpha_per_GPa, E_prime=226373.6, tau0_MPa=5.0,
              sigma_um=0.0, density_per_mm2=1.0e4, beta_um=10.0, f_c=0.1, v_slip_mm_s=1.0,
              *, n=128, angle_deg=0.0, mixed=None, continuation="auto", tol=None,
              max_steps=60, throw=True, upwind=0.0,
              limiter="none") -> tuple[EHLResult, EHLCase, EHLGrid]:
    """Numerical EHL point contact (validated entry point).

    F N, u_e (mean rolling speed, along the direction ``angle_deg`` from the
    X (Rx) axis) and u_s (sliding speed, same direction) mm/s, Rx and Ry mm, η0 Pa·s,
    α 1/GPa, E' MPa, τ0 MPa, σ and β µm, asperity density 1/mm², boundary friction
    f_c, v_slip mm/s.  ``n`` nodes per direction (n × n grid, domain of
    :func:`gearjax.tribology.ehl.grid.default_domain`).  ``mixed`` (default: σ > 0)
    switches on the Greenwood–Tripp asperity pressure.  ``upwind`` : weight β of the
    second-order upwind correction of the Couette fluxes (0 first order, the default
    and the scheme of the validation tables; 1 second-order upwind; see
    :class:`gearjax.tribology.ehl.grid.EHLGrid`).  ``limiter`` : ``"none"`` or
    ``"van_albada"`` (smooth limiter of that correction, see
    :func:`gearjax.tribology.ehl.model.van_albada`).

    ``tol`` : convergence tolerance on max|R| (p_h units and relative load error);
    None (default) takes :func:`default_tol` of the grid (1e-9 up to 128², 1e-6 above).

    Returns ``(result, case, grid)``.  With ``throw=True`` (default) a solve that
    did not converge raises :class:`gearjax.errors.ConvergenceError`; with
    ``throw=False`` check ``result.converged`` yourself.
    """
    if isinstance(n, bool) or not float(n).is_integer():
        raise ValueError(f"n = {n!r} must be an integer in [16, 1024]")
    _check_grid_inputs(n, angle_deg)
    tol_arg = tol
    tol = default_tol(int(n)) if tol is None else tol
    check_range("tol", tol, 0.0, 1e-3, lo_open=True)
    case = make_case(F, u_e, u_s, Rx, Ry, eta0, alpha_per_GPa, E_prime, tau0_MPa, sigma_um,
                     density_per_mm2, beta_um, f_c, v_slip_mm_s)
    if mixed is None:
        mixed = float(sigma_um) > 0.0
    if mixed and float(sigma_um) <= 0.0:
        raise ValueError(f"mixed = True needs sigma_um > 0, got sigma_um = {sigma_um!r}")
    grid = make_grid(int(n), float(angle_deg), upwind=upwind, limiter=limiter)
    auto = isinstance(continuation, str) and continuation == "auto"
    schedules = AUTO_SCHEDULES if auto else (tuple(continuation),)
    res = None
    if auto and int(n) > NESTED_ABOVE:
        res = _nested(locals(), grid)
    # on a fine grid the direct schedules are not tried after a nested solve whose
    # coarse grid converged: they failed in every case tried (256²: 18 min) and cost
    # up to 60 Newton steps each; the nested result is returned with its residual
    if res is None or (not bool(res.converged) and int(n) <= NESTED_ABOVE):
        for sched in schedules:
            res = ehl_traced(case, grid, float(angle_deg), bool(mixed), sched, tol,
                             int(max_steps))
            if bool(res.converged):
                break
    if auto and int(n) <= NESTED_ABOVE and not bool(res.converged) and int(n) // 2 >= 32:
        res = _nested(locals(), grid) or res
    if throw and not bool(res.converged):
        raise ConvergenceError(
            f"EHL solve did not converge (residual {float(res.residual):.3g} > tol {tol:g}, "
            f"{int(res.steps)} Newton steps); refine the grid, add continuation stages or "
            "pass throw=False to inspect the state")
    return res, case, grid


NESTED_ABOVE = 128
FINE_GRID_TOL = 1e-6


def default_tol(n: int) -> float:
    """Default convergence tolerance of :func:`solve_ehl` on an n × n grid: 1e-9 up to
    ``NESTED_ABOVE`` nodes per side, ``FINE_GRID_TOL`` = 1e-6 above.  On 256² the
    Newton iteration stops decreasing max|R| at about 3e-7 (p_h units), on 512² at about
    3e-6 (flagged at this default): the cavitation-boundary nodes change their active
    set from step to step (docs/ehl.md, "Grid convergence").  At 256² one further
    Newton step changes h_c by 2e-4 relative (measured), ~100× below the grid-to-grid
    change there."""
    return 1e-9 if n <= NESTED_ABOVE else FINE_GRID_TOL


NESTED_PTC = 1.0


def _nested(a, grid):
    """Nested iteration: auto-solve on n/2 nodes, interpolate (bilinear, P, P_a and H0),
    solve on ``grid`` by Newton–Krylov with pseudo-transient continuation (initial
    shift ``NESTED_PTC``): plain Newton from the interpolated state stalls on 256²
    (the sharper exit spike of the fine grid), the damped iteration does not."""
    coarse, _, cgrid = solve_ehl(a["F"], a["u_e"], a["u_s"], a["Rx"], a["Ry"], a["eta0"],
                                 a["alpha_per_GPa"], a["E_prime"], a["tau0_MPa"],
                                 a["sigma_um"], a["density_per_mm2"], a["beta_um"], a["f_c"],
                                 a["v_slip_mm_s"], n=int(a["n"]) // 2,
                                 angle_deg=a["angle_deg"], mixed=a["mixed"],
                                 continuation="auto", tol=a["tol_arg"],
                                 max_steps=a["max_steps"],
                                 throw=False, upwind=a["upwind"], limiter=a["limiter"])
    if not bool(coarse.converged):
        return None
    x0 = _prolong(coarse.x, cgrid, grid, bool(a["mixed"]))
    return ehl_traced(a["case"], grid, float(a["angle_deg"]), bool(a["mixed"]), (), a["tol"],
                      int(a["max_steps"]), x0=x0, ptc=NESTED_PTC)


def _prolong(x, cgrid: EHLGrid, grid: EHLGrid, mixed: bool):
    """Bilinear interpolation of a state from ``cgrid`` to ``grid`` (same domain,
    cell-centred nodes), the load renormalised; H0 kept."""
    P, P_a, H0 = unpack(x, cgrid, mixed)
    res = lambda A: jax.image.resize(A, (grid.ny, grid.nx), "linear")
    Pf, Paf = jnp.maximum(res(P), 0.0), jnp.maximum(res(P_a), 0.0)
    s = (2.0 * jnp.pi / 3.0) / (grid.dx * grid.dy * jnp.sum(Pf + Paf))
    parts = [(s * Pf).ravel()] + ([(s * Paf).ravel()] if mixed else []) + [jnp.reshape(H0, (1,))]
    return jnp.concatenate(parts)


@partial(jax.jit, static_argnames=("grid", "angle_deg", "mixed"))
def _output_jacobian(x_star, case, grid, angle_deg, mixed):
    def f(c):
        xd = attach_implicit_gradient(x_star, c, grid, angle_deg, mixed)
        out, _ = outputs(xd, c, grid, mixed)
        return jnp.stack([out.h_c, out.h_min, out.mu])
    return jax.jacrev(f)(case)


def ehl_gradients(result: EHLResult, case: EHLCase, grid: EHLGrid, angle_deg: float = 0.0,
                  mixed: bool = False) -> dict:
    """d(h_c, h_min, μ)/d(field of ``case``) at a converged ``result`` (implicit VJP).

    Returns ``{"h_c": EHLCase, "h_min": EHLCase, "mu": EHLCase}`` of partial
    derivatives (units: output unit per case-field unit, e.g. dh_c/dF in mm/N,
    d/dalpha per (1/MPa)).  ValueError if ``result`` is not converged; NaN entries if
    the adjoint solve did not reach 1e-8 relative
    (:data:`gearjax.tribology.ehl.implicit.ADJOINT_ACCEPT`).
    """
    if not bool(result.converged):
        raise ValueError("result.converged = False: gradients exist only at a converged "
                         "solution")
    J = _output_jacobian(result.x, case, grid, float(angle_deg), bool(mixed))
    pick = lambda i: jax.tree_util.tree_map(lambda a: a[i], J)
    return {"h_c": pick(0), "h_min": pick(1), "mu": pick(2)}


def ehl_fields(result: EHLResult, case: EHLCase, grid: EHLGrid, mixed: bool = False):
    """Nodal fields of a solution: dict with X, Y (in b, a units), x, y (mm),
    p, p_a (MPa), h (mm), each (ny, nx)."""
    sc = scales(case)
    P, P_a, H0 = unpack(result.x, grid, mixed)
    _, fl = _outputs_jit(result.x, case, grid, mixed)
    X, Y = grid.nodes()
    return {"X": X, "Y": Y, "x": X * float(sc.b), "y": Y * float(sc.a),
            "p": np.asarray(P) * float(sc.p_h), "p_a": np.asarray(P_a) * float(sc.p_h),
            "h": np.asarray(fl.H) * float(sc.h_unit)}
