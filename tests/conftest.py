import os

# XLA's backend (LLVM) optimisation level 0 for the test run.  The suite compiles
# several hundred large programs (nested implicit solves) that each run for well
# under a second; optimising their machine code is about a third of the suite's CPU
# time and buys nothing here.  It changes round-off, not results: on a spiral-bevel
# TCA every converged contact agrees with the default level to 1e-12 relative (only
# non-converged, flagged grid points differ).  Set before the first computation
# (the backend reads XLA_FLAGS when it starts); the notebook kernels and CLI
# subprocesses inherit it.  A level given in the environment is kept.
#
# Likewise XLA's CPU fusion emitters are switched off (the older loop emitters
# compile the same fused loops in about half the time: a spiral-bevel TCA program
# 11.2 s -> 6.3 s at level 0, run time unchanged; converged TE equal to 2e-10
# arcsec).  A choice given in the environment is kept.
#
# And one LLVM module per program instead of XLA's default split into parts (at
# level 0 the parts are compiled one after the other, so the split only adds work: a
# spur TCA program 9.1 -> 6.8 s; the command line uses the same three options).
for _flag, _default in (("xla_backend_optimization_level", "0"),
                        ("xla_cpu_use_fusion_emitters", "false"),
                        ("xla_cpu_parallel_codegen_split_count", "1")):
    if _flag not in os.environ.get("XLA_FLAGS", ""):
        os.environ["XLA_FLAGS"] = (os.environ.get("XLA_FLAGS", "")
                                   + f" --{_flag}={_default}").strip()

import jax  # noqa: E402
import pytest  # noqa: E402

jax.config.update("jax_enable_x64", True)

import gearjax  # noqa: E402,F401  (enables float64 as well)


def pytest_configure(config):
    """Keep compiled XLA executables on disk for the rest of the run (and later runs).

    The suite's time is mostly compilation of the large nested implicit solves (TCA,
    synthesis), several of which are compiled again by later modules (the caches are
    cleared between modules, see below; CLI tests compile what library tests did).
    JAX's persistent compilation cache returns an executable compiled for the same
    program, flags and JAX version instead; it changes no result.  It lives in
    pytest's own cache directory (ignored by git), is shared by pytest-xdist workers,
    ``GEARJAX_TEST_COMPILE_CACHE_DIR`` puts it elsewhere (the mutation runner,
    tools/mutation_run.py, shares one between its temporary copies) and
    ``GEARJAX_TEST_NO_COMPILE_CACHE=1`` switches it off.
    """
    if os.environ.get("GEARJAX_TEST_NO_COMPILE_CACHE") == "1":
        return
    path = os.environ.get("GEARJAX_TEST_COMPILE_CACHE_DIR")
    if not path:
        if getattr(config, "cache", None) is None:
            return
        path = config.cache.mkdir("jax-compilation")
    jax.config.update("jax_compilation_cache_dir", str(path))
    # every program, however short its compile: the caches are cleared between modules
    # (below), and the small programs (eager operations, blank and flank solves) that
    # every module compiles again each took 10 ms - 0.5 s; reading them back is
    # cheaper (8 light modules in one process, cold: 95 s CPU instead of 101-107 s)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    # the same cache for the notebook kernels the suite starts (JAX reads these)
    os.environ["JAX_COMPILATION_CACHE_DIR"] = str(path)
    os.environ["JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS"] = "0"


def _held_too_much():
    """True when the process holds more than :data:`MAP_SHARE` of its memory-map limit or
    more than :data:`RSS_LIMIT` bytes resident; also where /proc does not say."""
    try:
        with open("/proc/self/maps", "rb") as f:
            maps = sum(1 for _ in f)
        with open("/proc/sys/vm/max_map_count") as f:
            limit = int(f.read())
        with open("/proc/self/statm") as f:
            rss = int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return True
    return maps > MAP_SHARE * limit or rss > RSS_LIMIT


#: clear JAX's caches after a module once the process holds this share of its map
#: limit, or this many bytes resident (clearing after every module, a worker peaked at
#: 3.1 GB in a full run; with the map bound alone at 6.6 GB)
MAP_SHARE = 0.3
RSS_LIMIT = 4 * 2**30


@pytest.fixture(autouse=True, scope="module")
def _release_compiled_code():
    """Drop JAX's compiled executables after a test module when they hold too much.

    One pytest process compiles several hundred XLA executables (the TCA, synthesis
    and kinematics tests compile large nested implicit solves); LLVM maps code
    sections for each, and a full run exhausted the process's memory-map limit
    (``vm.max_map_count``, 65530 here) and aborted in a late compile.  After a module
    whose process then holds more than :data:`MAP_SHARE` of that limit or more than
    :data:`RSS_LIMIT` resident, the caches are cleared (after every module where /proc
    cannot be read); below both, the next module finds the programs, traces and small
    eager operations of the earlier ones in memory instead of tracing, lowering and
    reading them back from the persistent cache again (docs/testing.md).  A test that
    needs cold caches asks for the ``cold_jax_caches`` fixture.
    """
    yield
    if _held_too_much():
        jax.clear_caches()


@pytest.fixture
def cold_jax_caches():
    """JAX's caches cleared before the test (it counts traces or compilations of
    library programs that an earlier module of the same process may have run)."""
    jax.clear_caches()


# Test files in decreasing order of their cold-cache time (measured on 2 cores, mostly
# XLA compilation; see docs/testing.md).  pytest-xdist hands whole files to the
# workers in collection order (`--dist loadfile --no-loadscope-reorder` in
# pyproject.toml; its default order, by number of tests, put the slowest files --
# those with few, large tests -- last); starting the longest files first keeps a
# worker from idling while the other finishes a long file at the end.  Files not
# listed follow in their usual order.  A new slow file belongs in this list.
# The fuzz module (the largest, ~105 s CPU cold) starts third on purpose: it reuses the
# hypoid TCA program that test_gradients_end_to_end.py compiles early, and it compiles
# the HFT program that test_synthesis_hypoid.py reuses (persistent cache, same options).
# A notebook's test sits at the end of its subject's file (tests/notebook_run.py), so
# its kernel finds that file's programs in the persistent cache; the file's time here
# includes it (test_references_loaded.py: the VH-CATT notebook's efficiency gradient).
SLOWEST_FIRST = (
    "test_bevel_sweep.py", "test_gradients_end_to_end.py", "test_cutter_radius_pair.py", "test_fuzz_designs.py",
    "test_optimize_study.py", "test_tca_hypoid.py", "test_synthesis.py",
    "test_references_loaded.py", "test_preset_bevel_tca.py",
    "test_synthesis_hypoid.py",
    "test_edge_contact.py", "test_involute_sweep.py", "test_cutter_radius_study.py",
    "test_cli_tca.py",
    "test_formate_pair.py", "test_tca.py", "test_cutter_radius_optimize.py",
    "test_involute.py", "test_ehl.py", "test_kinematics.py", "test_notebooks.py",
    "test_hypoid_surface.py", "test_tca_result.py",
    "test_vh_catt.py", "test_materials.py",
)


def pytest_collection_modifyitems(config, items):
    rank = {name: i for i, name in enumerate(SLOWEST_FIRST)}
    # a stable sort: the tests of a file keep their order (module fixtures)
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))
