"""Face-milled spiral-bevel and hypoid gears: ``gearjax.hypoid``.

The blank (ISO 23509 methods 0 and 1 and the tangent-cone route), the face-mill cutter
and the cradle-type machine, the generated flanks, a pair of members, the design
file (``[design] kind`` = ``hypoid``, ``spiral_bevel``, ...), local synthesis of the
machine settings, the reference contact, corrective machine settings from a measured
flank (:mod:`~gearjax.gears.hypoid.flank_correction`) and for a target ease-off
(:mod:`~gearjax.gears.hypoid.ease_off`).  Its TCA runs through
:func:`gearjax.run_tca` like every family.  docs/architecture.md lists the modules.
"""

from gearjax.gears.hypoid.blank import BlankInput, blank_geometry, blank_sensitivity
from gearjax.gears.hypoid.cutter import FaceMillCutter, make_cutter
from gearjax.gears.hypoid.machine import MachineSettings
from gearjax.gears.hypoid.flank import FlankSpec, MemberBlank, flank_surface
from gearjax.gears.hypoid.pair import HypoidPair, complementary_pinion, pair_flanks
from gearjax.gears.hypoid.design_file import KINDS, HypoidDesign, save_design
from gearjax.gears.hypoid.tca import pinion_outline, prepare
from gearjax.gears.hypoid import synthesis
from gearjax.gears.hypoid.synthesis import Targets, synthesise
from gearjax.gears.hypoid.synthesis import start as synthesis_start
from gearjax.gears.hypoid import flank_correction
from gearjax.gears.hypoid.flank_correction import (correct_flanks, corrected_design,
                                                   correction_problem, model_deviations)
from gearjax.gears.hypoid import ease_off

__all__ = ["BlankInput", "blank_geometry", "blank_sensitivity", "FaceMillCutter", "make_cutter",
           "MachineSettings", "FlankSpec", "MemberBlank", "flank_surface", "HypoidPair",
           "complementary_pinion", "pair_flanks", "KINDS", "HypoidDesign", "save_design",
           "pinion_outline", "prepare", "synthesis", "Targets", "synthesise", "synthesis_start",
           "flank_correction", "correction_problem", "correct_flanks", "corrected_design",
           "model_deviations", "ease_off"]
