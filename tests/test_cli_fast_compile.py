"""The command line's compile options (gearjax/cli.py, FAST_COMPILE_FLAGS): added to
XLA_FLAGS for a CPU run before JAX starts its backend, never over a user's choice, and
only effective because ``import gearjax`` does not start the backend."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest

from gearjax import cli


@pytest.fixture
def env(monkeypatch):
    for k in ("XLA_FLAGS", "GEARJAX_FAST_COMPILE", "JAX_PLATFORMS"):
        monkeypatch.delenv(k, raising=False)
    return monkeypatch


def _flags():
    return os.environ.get("XLA_FLAGS", "")


def test_flags_added_for_a_cpu_run(env):
    env.setattr(cli, "_accelerator_plugin_installed", lambda: False)
    cli._fast_compile_flags()
    assert _flags().split() == ["--xla_backend_optimization_level=0",
                                "--xla_cpu_use_fusion_emitters=false",
                                "--xla_cpu_parallel_codegen_split_count=1"]
    cli._fast_compile_flags()                      # idempotent
    assert len(_flags().split()) == 3


def test_a_users_choice_is_kept(env):
    env.setattr(cli, "_accelerator_plugin_installed", lambda: False)
    env.setenv("XLA_FLAGS", "--xla_backend_optimization_level=3 --xla_dump_to=/x")
    cli._fast_compile_flags()
    assert _flags().split() == ["--xla_backend_optimization_level=3", "--xla_dump_to=/x",
                                "--xla_cpu_use_fusion_emitters=false",
                                "--xla_cpu_parallel_codegen_split_count=1"]


@pytest.mark.parametrize("setting", [("GEARJAX_FAST_COMPILE", "0"),
                                     ("GEARJAX_FAST_COMPILE", "off"),
                                     ("JAX_PLATFORMS", "cuda")])
def test_switched_off_or_not_a_cpu_run(env, setting):
    env.setattr(cli, "_accelerator_plugin_installed", lambda: False)
    env.setenv(*setting)
    cli._fast_compile_flags()
    assert _flags() == ""


def test_not_with_a_gpu_plugin_installed(env):
    env.setattr(cli, "_accelerator_plugin_installed", lambda: True)
    cli._fast_compile_flags()
    assert _flags() == ""
    env.setenv("JAX_PLATFORMS", "cpu")             # the user asks for the CPU: flags apply
    cli._fast_compile_flags()
    assert "--xla_backend_optimization_level=0" in _flags()


def test_plugin_discovery_finds_jax_plugins(tmp_path, monkeypatch):
    """Where JAX looks for PJRT plugins: a module of the ``jax_plugins`` namespace
    package counts; this environment (CPU only) has none."""
    assert cli._accelerator_plugin_installed() is False
    (tmp_path / "jax_plugins" / "xla_fake").mkdir(parents=True)
    (tmp_path / "jax_plugins" / "xla_fake" / "__init__.py").write_text("")
    monkeypatch.syspath_prepend(str(tmp_path))
    assert cli._accelerator_plugin_installed() is True


def test_importing_gearjax_does_not_start_the_backend(tmp_path):
    """XLA reads XLA_FLAGS when its backend starts: flags set after ``import gearjax``
    (and after the command modules are imported) must still take effect.  An XLA dump
    directory named only then is created by the first computation."""
    dump = tmp_path / "dump"
    code = textwrap.dedent(f"""
        import os
        import gearjax, gearjax.cli, gearjax.hypoid, gearjax.involute, gearjax.vh_catt
        import gearjax.preset_bevel, gearjax.tribology
        gearjax.cli.build_parser()
        os.environ["XLA_FLAGS"] = "--xla_dump_to={dump}"
        import jax.numpy as jnp
        (jnp.ones(3) + 1.0).block_until_ready()
    """)
    env = {k: v for k, v in os.environ.items() if k != "XLA_FLAGS"}
    subprocess.run([sys.executable, "-c", code], check=True, env=env, timeout=120)
    assert dump.is_dir() and any(dump.iterdir())


def test_only_a_real_command_line_run_sets_the_flags(env, monkeypatch, capsys):
    """``main(argv)`` called in-process (a notebook, a test, another program) leaves
    the caller's ``XLA_FLAGS`` alone; ``main()`` -- the console command, arguments from
    ``sys.argv`` -- adds the options."""
    env.setattr(cli, "_accelerator_plugin_installed", lambda: False)
    env.setenv("GEARJAX_CACHE_DIR", "off")
    assert cli.main(["example", "list"]) == 0
    assert _flags() == ""
    monkeypatch.setattr(sys, "argv", ["gearjax", "example", "list"])
    assert cli.main() == 0
    assert "--xla_cpu_parallel_codegen_split_count=1" in _flags()
    capsys.readouterr()


def test_fast_compile_options_for_one_program():
    """``gearjax.FAST_COMPILE_OPTIONS`` (the command line's options, for
    ``jax.jit(..., compiler_options=...)``) are accepted by this XLA -- a misspelt or
    retired option is an error at compile time -- and change a Newton solve and its
    implicit derivative only at the rounding level; the command line's flags are the
    same options."""
    import jax
    import jax.numpy as jnp
    import gearjax as gj

    def root(a):
        res = gj.newton_solve(lambda x, p: jnp.stack([x[0] ** 3 + x[1] - p, x[1] - 0.5 * x[0]]),
                              jnp.array([1.0, 0.5]), a)
        return res.x[0]

    f = jax.value_and_grad(root)
    v0, g0 = jax.jit(f)(2.0)
    v1, g1 = jax.jit(f, compiler_options=gj.FAST_COMPILE_OPTIONS)(2.0)
    assert abs(float(v1) - float(v0)) < 1e-14 and abs(float(g1) - float(g0)) < 1e-13
    # x^3 + x/2 = 2: x = 1.1173..., dx/da = 1 / (3 x^2 + 1/2)
    assert float(g0) == pytest.approx(1.0 / (3.0 * float(v0) ** 2 + 0.5), rel=1e-12)
    assert dict(cli.FAST_COMPILE_FLAGS) == {k: str(v).lower()
                                            for k, v in gj.FAST_COMPILE_OPTIONS.items()}
