"""Rack-generated involute spur and helical gears: ``gearjax.involute``.

The pair (:class:`InvolutePair`), its generated flanks and closed-form geometry, the
pair with pinion modifications that the TCA takes (:class:`InvoluteTCA`), the design
file (``[design] kind = "involute"``, :class:`InvoluteFile`), the kinematics along
the path of contact.  Its TCA runs through :func:`gearjax.run_tca` like every family.
"""

from gearjax.gears.involute.geometry import (InvolutePair, generated_flank, pair_geometry,
                                             path_kinematics, path_table)
from gearjax.gears.involute.tca import InvoluteTCA
from gearjax.gears.involute.limits import involute_limits
from gearjax.gears.involute.design_file import InvoluteFile

__all__ = ["InvolutePair", "generated_flank", "pair_geometry", "path_kinematics", "path_table",
           "InvoluteTCA", "involute_limits", "InvoluteFile"]
