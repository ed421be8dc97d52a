"""The hypoid family's public names (``gearjax.hypoid``): see :mod:`gearjax.gears.hypoid`,
whose ``__all__`` this module re-exports (the family's code lives in that folder)."""

from gearjax.gears.hypoid import *  # noqa: F401,F403
from gearjax.gears.hypoid import __all__  # noqa: F401
