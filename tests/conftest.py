import jax

jax.config.update("jax_enable_x64", True)

import gearjax  # noqa: E402,F401  (enables float64 as well)
