"""Objective -> gradient -> optimiser: the shared optimisation layer.

Every design study in gearjax writes a scalar objective ``fun(x) -> J`` of a flat
float64 parameter vector ``x`` (scaled by the caller to O(1)) and hands it here:

* :func:`minimize_optax` -- a first-order optax optimiser (Adam by default) run as
  one jitted ``lax.scan`` over ``steps`` iterations; box bounds by projection
  (``x <- clip(x, lower, upper)`` after each update: projected gradient).  The
  gradient is ``jax.grad`` (reverse mode) or ``jax.jacfwd`` (forward mode, cheaper
  for a handful of parameters with implicit Newton solves inside).
* :func:`minimize_lbfgsb` -- bounded L-BFGS-B from jaxopt.  jaxopt is archived
  upstream; it is imported only here (lazily), with its import-time
  ``DeprecationWarning`` filtered, so that it can be replaced in one place.

Both return an :class:`OptResult` with the history of objective values, so a study
can report how it got there; neither prints.  Reference: Kingma & Ba, Adam (2015);
Byrd, Lu, Nocedal & Zhu, L-BFGS-B (1995).
"""

from __future__ import annotations

import warnings
from typing import Callable, NamedTuple

import jax
import jax.numpy as jnp
import optax

__all__ = ["OptResult", "value_and_grad", "minimize_optax", "minimize_lbfgsb"]


class OptResult(NamedTuple):
    """x: final parameters; value: objective there; history: objective before each
    step (``steps`` values) ; x_history: parameters before each step
    (``steps, n``); grad_norm: ``|grad|`` at ``x`` (of the projected problem: the
    components pushing against an active bound are dropped); steps: iterations."""

    x: jnp.ndarray
    value: jnp.ndarray
    history: jnp.ndarray
    x_history: jnp.ndarray
    grad_norm: jnp.ndarray
    steps: int


def value_and_grad(fun: Callable, mode: str = "rev") -> Callable:
    """``x -> (fun(x), grad)`` by reverse (``"rev"``) or forward (``"fwd"``) mode."""
    if mode == "rev":
        return jax.value_and_grad(fun)
    if mode == "fwd":
        def vg(x):
            return fun(x), jax.jacfwd(fun)(x)
        return vg
    raise ValueError(f"mode = {mode!r} must be 'rev' or 'fwd'")


def _projected_grad_norm(x, g, lower, upper):
    at_lo = (x <= lower) & (g > 0)
    at_hi = (x >= upper) & (g < 0)
    return jnp.linalg.norm(jnp.where(at_lo | at_hi, 0.0, g))


def minimize_optax(fun: Callable, x0, *, optimizer=None, steps: int = 100, lower=None,
                   upper=None, mode: str = "rev") -> OptResult:
    """Minimise ``fun`` from ``x0`` with an optax optimiser in a jitted ``lax.scan``.

    ``optimizer``: an ``optax.GradientTransformation`` (default ``optax.adam(1e-2)``);
    ``lower``/``upper``: box bounds (scalars or arrays; projection after each step);
    ``mode``: gradient by ``"rev"`` or ``"fwd"`` mode.  ``x0`` is projected first.
    """
    steps = int(steps)
    if steps < 1:
        raise ValueError(f"steps = {steps} must be >= 1")
    x0 = jnp.asarray(x0, float)
    lo = jnp.full_like(x0, -jnp.inf) if lower is None else jnp.broadcast_to(
        jnp.asarray(lower, float), x0.shape)
    hi = jnp.full_like(x0, jnp.inf) if upper is None else jnp.broadcast_to(
        jnp.asarray(upper, float), x0.shape)
    opt = optax.adam(1e-2) if optimizer is None else optimizer
    vg = value_and_grad(fun, mode)

    @jax.jit
    def run(x0, lo, hi):
        x0 = jnp.clip(x0, lo, hi)

        def step(carry, _):
            x, state = carry
            v, g = vg(x)
            upd, state = opt.update(g, state, x)
            xn = jnp.clip(optax.apply_updates(x, upd), lo, hi)
            return (xn, state), (v, x)

        (x, _), (hist, xs) = jax.lax.scan(step, (x0, opt.init(x0)), None, length=steps)
        v, g = vg(x)
        return x, v, hist, xs, _projected_grad_norm(x, g, lo, hi)

    x, v, hist, xs, gn = run(x0, lo, hi)
    return OptResult(x, v, hist, xs, gn, steps)


def _jaxopt():
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", category=DeprecationWarning)
        import jaxopt
    return jaxopt


def minimize_lbfgsb(fun: Callable, x0, lower, upper, *, maxiter: int = 200,
                    tol: float = 1e-10) -> OptResult:
    """Bounded L-BFGS-B (jaxopt) on ``fun`` from ``x0`` within ``[lower, upper]``.

    History: the objective at each accepted iterate (as many as iterations; jaxopt
    runs in a jitted while loop, so the history is recorded by a scan over
    ``maxiter`` single updates, padded with the final value after convergence).
    """
    jaxopt = _jaxopt()
    x0 = jnp.asarray(x0, float)
    lo = jnp.broadcast_to(jnp.asarray(lower, float), x0.shape)
    hi = jnp.broadcast_to(jnp.asarray(upper, float), x0.shape)
    solver = jaxopt.LBFGSB(fun=fun, maxiter=int(maxiter), tol=float(tol))

    @jax.jit
    def run(x0):
        x0 = jnp.clip(x0, lo, hi)
        state = solver.init_state(x0, bounds=(lo, hi))

        def step(carry, _):
            x, st = carry
            v = fun(x)
            done = st.error <= tol
            xn, stn = solver.update(x, st, bounds=(lo, hi))
            x = jnp.where(done, x, xn)
            st = jax.tree_util.tree_map(lambda a, b: jnp.where(done, a, b), st, stn)
            return (x, st), (v, x)

        (x, st), (hist, xs) = jax.lax.scan(step, (x0, state), None, length=int(maxiter))
        g = jax.grad(fun)(x)
        return x, fun(x), hist, xs, _projected_grad_norm(x, g, lo, hi), st.iter_num

    x, v, hist, xs, gn, it = run(x0)
    return OptResult(x, v, hist, xs, gn, int(it))
