"""Rack-generated involute spur and helical gears: ``gearjax.involute``.

The pair (:class:`InvolutePair`), its generated flanks and closed-form geometry, the
pair with pinion modifications that the TCA takes (:class:`InvoluteTCA`), the design
file (``[design] kind = "involute"``, :class:`InvoluteFile`), the kinematics along
the path of contact.  Its TCA runs through :func:`gearjax.run_tca` like every family.
The flank micro-geometry (:class:`MicroGeometry`, :func:`flank_removal_um`) and the
loaded line contact of spur and helical pairs (:func:`line_contact`,
:func:`loaded_te_map`, the unloaded TCA of the modified flanks :func:`line_tca`) are
this family's own (docs/microgeometry.md).
"""

from gearjax.gears.involute.geometry import (InvolutePair, generated_flank, pair_geometry,
                                             path_kinematics, path_table)
from gearjax.gears.involute.tca import InvoluteTCA
from gearjax.gears.involute.limits import involute_limits
from gearjax.gears.involute.design_file import InvoluteFile
from gearjax.gears.involute.microgeometry import (FlankModification, MicroGeometry,
                                                  PairModification, flank_removal_um)
from gearjax.gears.involute.loaded_lines import (COUPLING_LENGTH_RANGE_MM,
                                                 MISALIGNMENT_RANGE_UM, TORQUE_RANGE_NM,
                                                 LoadedTEMap, line_contact, loaded_te_map,
                                                 module_coupling_length, resolution_warnings)
from gearjax.gears.involute.line_tca import LineTCA, line_tca

__all__ = ["InvolutePair", "generated_flank", "pair_geometry", "path_kinematics", "path_table",
           "InvoluteTCA", "involute_limits", "InvoluteFile", "FlankModification",
           "PairModification", "MicroGeometry", "flank_removal_um", "line_contact",
           "loaded_te_map", "LoadedTEMap", "TORQUE_RANGE_NM", "MISALIGNMENT_RANGE_UM",
           "resolution_warnings", "line_tca", "LineTCA", "COUPLING_LENGTH_RANGE_MM",
           "module_coupling_length"]
