"""VH-CATT cylindrical gears (variable hyperbolic circular-arc tooth trace), [VH-CATT]:
``gearjax.vh_catt``.

The pair (:class:`VHCattPair`: flanks as envelopes of the dual-blade cutter carried by
the generating roll) and its design file (``[design] kind = "vh_catt"``,
:class:`VHCattDesign`, with its ``[material]``).  Its TCA and mesh efficiency run
through :func:`gearjax.run_tca` and :func:`gearjax.mesh_efficiency` like every family;
its closed-loop flank correction (cutter radius and blade settings from a measured flank)
is :mod:`~gearjax.gears.vh_catt.flank_correction` (``gearjax correct``), its target
ease-off fit :mod:`~gearjax.gears.vh_catt.ease_off` (``gearjax ease-off``).
"""

from gearjax.gears.vh_catt.geometry import VHCattPair
from gearjax.gears.vh_catt.design_file import VHCattDesign
from gearjax.gears.vh_catt import flank_correction, ease_off

__all__ = ["VHCattPair", "VHCattDesign", "flank_correction", "ease_off"]
