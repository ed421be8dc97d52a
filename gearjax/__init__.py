"""gearjax — differentiable gear design in JAX.

Importing gearjax enables 64-bit floats in JAX (``jax_enable_x64``): micrometre
geometry on 100 mm parts and arc-second transmission errors need float64.

The chain (docs/architecture.md), each step a pure JAX function so that
``jax.grad`` runs from any design field to any result::

    design (pytree)  -> cutter + machine -> tooth flanks      gearjax.<family>
                     -> tooth contact analysis (TCAResult)     run_tca, tca_function
                     -> kinematics at the contact points       TCAResult.kinematics
                     -> Hertz load, film, friction, losses     gearjax.tribology
                     -> load sharing, mesh efficiency          mesh_efficiency, efficiency_function
                     -> objective -> gradient -> optimiser     minimize_constrained, ...
                     -> design studies (gearjax optimize)      gearjax.studies

The public face is the ~40 names of ``gearjax.__all__`` (verbs and types of the chain,
one per job), four family namespaces -- ``gearjax.hypoid``, ``gearjax.involute``,
``gearjax.vh_catt``, ``gearjax.preset_bevel`` -- and ``gearjax.tribology`` (oils,
surfaces, friction, losses, Hertz, the numerical EHL reference).  The modules behind
them (``gearjax.tca``, ``gearjax.loading``, ``gearjax.io``, ``gearjax.frames``,
``gearjax.kinematics``, ...) are importable for research code; docs/architecture.md
says what each holds.  Units inside: mm, N, s, rad; degrees only at the boundary
(design files, CLI flags, printed tables).
"""

import jax as _jax

_jax.config.update("jax_enable_x64", True)

__version__ = "0.1.0"

# -- the verbs and types of the chain -------------------------------------------------
from gearjax.compile_ahead import FAST_COMPILE_OPTIONS  # noqa: E402
from gearjax.errors import ConvergenceError  # noqa: E402
from gearjax.fields import field_names, get_fields, with_fields  # noqa: E402
from gearjax.newton import NewtonResult, newton_solve  # noqa: E402
from gearjax.tca.path import ARCSEC, ContactPath, NoContactError  # noqa: E402
from gearjax.tca.assembly import Misalignment  # noqa: E402
from gearjax.tca.result import (SIDES, ContactKinematics, TCAResult, check_design,  # noqa: E402
                                contact_kinematics, family_of)
from gearjax.optimize import (LMResult, OptResult, least_squares_lm, minimize_lbfgsb,  # noqa: E402
                              minimize_optax, status_message)
from gearjax.augmented_lagrangian import minimize_constrained  # noqa: E402
from gearjax.io import design_from_dict, example_path, list_examples, load_design  # noqa: E402
from gearjax.loading.loaded_contact import LoadedContact  # noqa: E402
from gearjax.loading.mesh_efficiency import (MeshEfficiency, check_operating_point,  # noqa: E402
                                             efficiency_function, mesh_efficiency)
from gearjax.loading.efficiency_checks import efficiency_guard, efficiency_warnings  # noqa: E402
from gearjax.loading.materials import Material, pair_material  # noqa: E402
# -- namespaces (importing the families registers their design kinds and TCA) --------
from gearjax import hypoid, involute, preset_bevel, vh_catt  # noqa: E402
from gearjax import tribology  # noqa: E402


def run_tca(design, misalignment=None, *, side=None, **options) -> TCAResult:
    """Tooth contact analysis of any family: the one entry point.

    ``design`` : an :class:`InvoluteTCA` (involute pair with optional pinion
    modifications), a loaded spiral-bevel/hypoid design (:func:`load_design`), a
    :class:`HypoidPair` or a prepared hypoid pair.  ``misalignment`` : a
    :class:`Misalignment` (dE, dP, dG in mm, dSigma in rad; default none).  ``side`` :
    "drive" (default) or "coast" (for a :class:`HypoidPair` its flanks decide).
    Options: ``steps_per_pitch``, ``half_pitches``, ``n_pairs``, ``line_contact``,
    ``approach`` (mm), ``kinematics`` (default True: :class:`ContactKinematics` at
    every contact point), ``throw`` (default True: raise
    :class:`ConvergenceError` when a contact solve fails on the working flank).

    Returns a :class:`TCAResult`; ``result.flags()`` gives the contact-quality flags.
    The concrete design is validated first (:func:`check_design`: a field out of
    range, e.g. degrees typed into a radian field, is a one-line ValueError); jitted:
    a second call with the same shapes and options reuses the compiled program.  For
    gradients use :func:`tca_function`.
    """
    check_design(design)
    kw = dict(options)
    if side is not None:
        kw["side"] = side
    return family_of(design).run(design, misalignment, **kw)


def tca_function(design, *, side=None, **options):
    """A pure, traceable TCA ``f(pair, misalignment=None) -> TCAResult`` for ``jax.grad``,
    ``jax.jit`` and ``jax.vmap``.

    The concrete set-up (reference guess, hand of the mounting, sense of rotation) is
    done once here from ``design``; ``f`` then takes the differentiable pair pytree:
    an :class:`InvoluteTCA` for involute pairs, a :class:`HypoidPair` for
    spiral-bevel/hypoid pairs (``f.pair`` is the prepared pair of the design, the
    natural point to differentiate at).  Options as for :func:`run_tca` (no
    ``throw``: check ``result.path.converged`` and ``result.on_flank``).

    ``f(pair, misalignment, reference=(x_ref, phi1_ref))`` starts the contact path from
    another reference guess (unknowns ``(u1, v1, u2, v2, phi2)`` at pinion angle
    ``phi1_ref``; may be traced): by default the one found for ``design`` (for
    involute pairs: inside the program, where it moves with the design).  Every call
    of every ``f`` with the same family and options runs one compiled program (the
    side is an argument of it, not part of its key).
    """
    check_design(design)
    kw = dict(options)
    if side is not None:
        kw["side"] = side
    ad = family_of(design)
    f = ad.traced(design, **kw)
    if not hasattr(f, "pair"):
        f.pair = design
    return f


def tca_sensitivity(design, misalignment=None, *, side=None, **options):
    """Sensitivity of the TCA summary (TE peak-to-peak, TE shift at the reference,
    bearing position, ellipse length, ...) to dE, dP, dG (per mm) and dSigma (per rad)
    by forward-mode autodiff through every contact solve.

    Returns ``(values, table)``: ``values[key]`` the summary at ``misalignment`` and
    ``table[key] = {"dE": .., "dP": .., "dG": .., "dSigma": ..}``; the keys are the
    family's summary keys (same shape for every family).
    """
    kw = dict(options)
    if side is not None:
        kw["side"] = side
    return family_of(design).sensitivity(design, misalignment, **kw)


__all__ = [
    "__version__",
    # designs
    "load_design", "design_from_dict", "list_examples", "example_path", "check_design",
    # tooth contact analysis
    "run_tca", "tca_function", "tca_sensitivity", "TCAResult", "ContactPath", "Misalignment",
    "ContactKinematics", "contact_kinematics", "SIDES", "ARCSEC",
    # loaded contact and mesh efficiency
    "mesh_efficiency", "efficiency_function", "MeshEfficiency", "LoadedContact", "Material",
    "pair_material", "check_operating_point", "efficiency_warnings", "efficiency_guard",
    # optimisers and solvers, their results and status
    "minimize_optax", "minimize_lbfgsb", "minimize_constrained", "least_squares_lm",
    "OptResult", "LMResult",
    "status_message", "newton_solve", "NewtonResult", "ConvergenceError", "NoContactError",
    # compile time: XLA options for jax.jit(..., compiler_options=...) on the CPU
    "FAST_COMPILE_OPTIONS",
    # design fields by name
    "field_names", "get_fields", "with_fields",
    # namespaces
    "hypoid", "involute", "vh_catt", "preset_bevel", "tribology",
]
