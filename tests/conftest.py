import jax
import pytest

jax.config.update("jax_enable_x64", True)

import gearjax  # noqa: E402,F401  (enables float64 as well)


@pytest.fixture(autouse=True, scope="module")
def _release_compiled_code():
    """Drop JAX's compiled executables after each test module.

    One pytest process compiles several hundred XLA executables (the TCA, synthesis
    and kinematics tests compile large nested implicit solves); LLVM maps code
    sections for each, and a full run exhausted the process's memory-map limit
    (``vm.max_map_count``, 65530 here) and aborted in a late compile.  Clearing the
    caches between modules keeps the mapping count bounded, at the price of
    recompiling what two modules would otherwise share.
    """
    yield
    jax.clear_caches()
