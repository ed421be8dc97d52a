"""The involute family's public names (``gearjax.involute``): see :mod:`gearjax.gears.involute`,
whose ``__all__`` this module re-exports (the family's code lives in that folder)."""

from gearjax.gears.involute import *  # noqa: F401,F403
from gearjax.gears.involute import __all__  # noqa: F401
