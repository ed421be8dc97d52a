"""gearjax — differentiable gear design in JAX.

Importing gearjax enables 64-bit floats in JAX (``jax_enable_x64``): micrometre
geometry on 100 mm parts and arc-second transmission errors need float64.

The chain (docs/architecture.md), each step a pure JAX function so that
``jax.grad`` runs from any design field to any result::

    design (pytree)  -> cutter + machine -> tooth flanks      gearjax.gears.<family>
                     -> tooth contact analysis (TCAResult)     gearjax.tca, gearjax.tca_result
                     -> kinematics at the contact points       gearjax.tca_result, gearjax.kinematics
                     -> Hertz load, film, friction, losses     gearjax.contact, gearjax.tribology
                     -> load sharing, mesh efficiency          gearjax.loaded_contact, gearjax.mesh_efficiency
                     -> objective -> gradient -> optimiser     gearjax.optimize

Backbone (top level): ``frames`` (4x4 transforms), ``newton`` (implicit-differentiated
Newton), ``surfaces`` (autodiff differential geometry, envelopes), ``kinematics``
(eigenfunction kinematics of conjugate surfaces), ``tca`` (contact of two flanks:
paths, TE, ellipses, tooth pairs), ``tca_result`` (the one TCA result type, the
kinematics at its contact points, the family registry), ``contact`` (Hertz),
``optimize`` (the optimisation layer), ``fields`` (design fields by dotted name),
``io`` (file formats, atomic writes), ``errors``, ``progress``.  Families: ``gears.involute`` (rack-generated spur and
helical pairs) and ``gears.hypoid`` (face-milled spiral-bevel and hypoid pairs:
cutter, machine, blank design, flank, pair, design file, TCA, formate pinions,
local synthesis, contact kinematics).  ``tribology`` (lubricant, film, asperities,
friction, losses, numerical EHL), ``studies`` (the cutter-radius study), ``plot``
(figures), ``cli``/``commands`` (the ``gearjax`` command).

The names below are the public API (``gearjax.__all__``); docs/architecture.md
lists them by step of the chain.  Units inside: mm, N, s, rad; degrees only at the
boundary (design files, CLI flags, printed tables).
"""

import jax as _jax

_jax.config.update("jax_enable_x64", True)

__version__ = "0.1.0"

# -- backbone ------------------------------------------------------------------------
from gearjax.errors import ConvergenceError  # noqa: E402
from gearjax.fields import field_names, get_fields, with_fields  # noqa: E402
from gearjax.frames import rot_axis, rot_x, rot_y, rot_z, translate  # noqa: E402
from gearjax.newton import NewtonResult, newton_solve  # noqa: E402
from gearjax.surfaces import GeneratedSurface, local_geometry  # noqa: E402
from gearjax.kinematics import (Kinematics, Mesh, crossed_axes, eigen_kinematics,  # noqa: E402
                                parallel_axes)
from gearjax.edge_contact import EDGE_NAMES  # noqa: E402
from gearjax.tca import ARCSEC, ContactPath, Misalignment, MultiPair, NoContactError  # noqa: E402
from gearjax.tca_result import (SIDES, ContactKinematics, TCAResult,  # noqa: E402
                                contact_kinematics, family_of)
from gearjax.contact import HertzResult, hertz_line, hertz_point  # noqa: E402
from gearjax.optimize import (LMResult, OptResult, least_squares_lm, minimize_lbfgsb,  # noqa: E402
                              minimize_optax, status_message)
from gearjax.io import atomic_write, example_path, list_examples  # noqa: E402
# -- gear families (importing them registers their TCA adapters) -----------------------
from gearjax.gears.involute.geometry import InvolutePair, generated_flank, pair_geometry  # noqa: E402
from gearjax.gears.involute.geometry import path_kinematics as involute_path_kinematics  # noqa: E402
from gearjax.gears.involute.geometry import path_table as involute_path_table  # noqa: E402
from gearjax.gears.involute.tca import InvoluteTCA, involute_limits  # noqa: E402
from gearjax.gears.involute.design_file import InvoluteFile  # noqa: E402
from gearjax.gears.hypoid.blank import BlankInput, blank_geometry, blank_sensitivity  # noqa: E402
from gearjax.gears.hypoid.cutter import FaceMillCutter, make_cutter  # noqa: E402
from gearjax.gears.hypoid.machine import MachineSettings  # noqa: E402
from gearjax.gears.hypoid.flank import FlankSpec, MemberBlank, flank_surface  # noqa: E402
from gearjax.gears.hypoid.pair import HypoidPair, complementary_pinion, pair_flanks  # noqa: E402
from gearjax.gears.hypoid.design_file import HypoidDesign, save_design  # noqa: E402
from gearjax.gears.hypoid.design_file import KINDS as HYPOID_KINDS  # noqa: E402
from gearjax.io import design_from_dict, load_design  # noqa: E402  (any family, by [design] kind)
from gearjax.gears.hypoid.tca import pinion_outline  # noqa: E402
from gearjax.gears.hypoid.tca import prepare as prepare_hypoid  # noqa: E402
from gearjax.gears.hypoid import synthesis  # noqa: E402
from gearjax.gears.hypoid.synthesis import Targets, synthesise  # noqa: E402
from gearjax.gears.hypoid.synthesis import start as synthesis_start  # noqa: E402
from gearjax.gears.preset_bevel.geometry import PresetBevelDesign  # noqa: E402
from gearjax.gears.preset_bevel.design_file import PresetBevelFile  # noqa: E402
from gearjax.gears.preset_bevel.design_file import flank_grid as preset_bevel_flank_grid  # noqa: E402
from gearjax.gears.preset_bevel import analysis as preset_bevel_analysis  # noqa: E402
from gearjax.gears.vh_catt.geometry import VHCattPair  # noqa: E402
from gearjax.gears.vh_catt.design_file import VHCattDesign  # noqa: E402  (registers kind "vh_catt")
# -- lubrication and friction --------------------------------------------------------
from gearjax.tribology import (OILS, FrictionResult, Oil, Surface, friction_coefficient,  # noqa: E402
                               friction_traced, get_oil, make_oil, make_surface, mesh_losses,
                               mesh_losses_traced, stribeck_curve)
from gearjax.tribology.ehl import solve_ehl  # noqa: E402
# -- loaded contact and mesh efficiency ---------------------------------------------
from gearjax.loaded_contact import COMPLIANCE_MODELS, LoadedContact  # noqa: E402
from gearjax.mesh_efficiency import (COMPLIANCE_HELP, DEFAULT_COMPLIANCE,  # noqa: E402
                                     RPM_RANGE, TORQUE_RANGE_NM, MeshEfficiency, check_operating_point,
                                     efficiency_function, efficiency_guard, efficiency_warnings,
                                     mesh_efficiency)
from gearjax.materials import E_PRIME_RANGE_MPA, Material, pair_material  # noqa: E402
from gearjax.materials import STEEL as STEEL_MATERIAL  # noqa: E402
from gearjax.tca_result import check_design  # noqa: E402


def run_tca(design, misalignment=None, *, side=None, **options) -> TCAResult:
    """Tooth contact analysis of any family: the one entry point.

    ``design`` : an :class:`InvoluteTCA` (involute pair with optional pinion
    modifications), a loaded spiral-bevel/hypoid design (:func:`load_design`), a
    :class:`HypoidPair` or a prepared hypoid pair.  ``misalignment`` : a
    :class:`Misalignment` (dE, dP, dG in mm, dSigma in rad; default none).  ``side`` :
    "drive" (default) or "coast" (for a :class:`HypoidPair` its flanks decide).
    Options: ``steps_per_pitch``, ``half_pitches``, ``n_pairs``, ``line_contact``,
    ``approach`` (mm), ``kinematics`` (default True: :class:`ContactKinematics` at
    every contact point), ``strict`` (default True: raise
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
    ``strict``: check ``result.path.converged`` and ``result.on_flank``).
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
    # designs and files
    "load_design", "save_design", "design_from_dict", "HypoidDesign", "HYPOID_KINDS", "list_examples",
    "example_path", "atomic_write",
    # pairs and blanks
    "InvolutePair", "InvoluteTCA", "InvoluteFile", "pair_geometry", "HypoidPair", "pair_flanks",
    "complementary_pinion", "prepare_hypoid", "pinion_outline", "involute_limits", "BlankInput", "blank_geometry",
    "blank_sensitivity",
    "VHCattPair", "VHCattDesign",
    # flanks
    "FaceMillCutter", "make_cutter", "MachineSettings", "MemberBlank", "FlankSpec",
    "flank_surface", "generated_flank", "GeneratedSurface", "local_geometry",
    # tooth contact analysis
    "run_tca", "tca_function", "tca_sensitivity", "TCAResult", "ContactPath", "MultiPair",
    "Misalignment", "SIDES", "ARCSEC", "NoContactError", "EDGE_NAMES", "family_of",
    # kinematics
    "ContactKinematics", "contact_kinematics", "Kinematics", "Mesh", "eigen_kinematics",
    "parallel_axes", "crossed_axes", "involute_path_kinematics", "involute_path_table",
    # synthesis
    "synthesis", "synthesis_start", "synthesise", "Targets",
    # contact and friction
    "HertzResult", "hertz_point", "hertz_line", "Oil", "OILS", "get_oil", "make_oil",
    "Surface", "make_surface", "FrictionResult", "friction_coefficient", "friction_traced",
    "mesh_losses", "mesh_losses_traced", "stribeck_curve", "solve_ehl",
    # loaded contact and mesh efficiency
    "mesh_efficiency", "efficiency_function", "efficiency_warnings", "efficiency_guard",
    "MeshEfficiency",
    "DEFAULT_COMPLIANCE", "COMPLIANCE_HELP", "Material", "STEEL_MATERIAL", "pair_material",
    "E_PRIME_RANGE_MPA",
    "check_design",
    "LoadedContact", "check_operating_point", "TORQUE_RANGE_NM", "RPM_RANGE", "COMPLIANCE_MODELS",
    # optimisers and solvers
    "minimize_optax", "minimize_lbfgsb", "least_squares_lm", "OptResult", "LMResult",
    "status_message", "newton_solve", "NewtonResult", "ConvergenceError",
    # design fields by name
    "field_names", "get_fields", "with_fields",
    # frames
    "rot_x", "rot_y", "rot_z", "rot_axis", "translate",
    # pure-rolling bevel pairs with a preset TE
    "PresetBevelDesign", "PresetBevelFile", "preset_bevel_flank_grid", "preset_bevel_analysis",
]
