"""The preset_bevel family's public names (``gearjax.preset_bevel``): see :mod:`gearjax.gears.preset_bevel`,
whose ``__all__`` this module re-exports (the family's code lives in that folder)."""

from gearjax.gears.preset_bevel import *  # noqa: F401,F403
from gearjax.gears.preset_bevel import __all__  # noqa: F401
