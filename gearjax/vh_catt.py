"""The vh_catt family's public names (``gearjax.vh_catt``): see :mod:`gearjax.gears.vh_catt`,
whose ``__all__`` this module re-exports (the family's code lives in that folder)."""

from gearjax.gears.vh_catt import *  # noqa: F401,F403
from gearjax.gears.vh_catt import __all__  # noqa: F401
