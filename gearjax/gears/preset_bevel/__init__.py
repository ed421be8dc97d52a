"""Pure-rolling bevel gears with a preset parabolic transmission error ([Preset-TE-bevel]):
``gearjax.preset_bevel``.

The design pytree (:class:`PresetBevelDesign`), its design file
(``[design] kind = "preset_te_bevel"``, :class:`PresetBevelFile`), the flank grid, and
the analysis of a TCA result against the preset TE (``analysis``: preset TE, deviation,
transfer gaps and jumps, sliding ratio, contact ends).  Its TCA runs through
:func:`gearjax.run_tca` like every family.
"""

from gearjax.gears.preset_bevel.geometry import PresetBevelDesign
from gearjax.gears.preset_bevel.design_file import PresetBevelFile, flank_grid
from gearjax.gears.preset_bevel import analysis

__all__ = ["PresetBevelDesign", "PresetBevelFile", "flank_grid", "analysis"]
