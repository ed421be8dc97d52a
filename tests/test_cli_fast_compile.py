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
