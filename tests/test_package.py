"""Packaging contract of issue [F] item 1–2: metadata, console script, float64 on import,
the README's two set-up commands and the CI script that runs the test command."""

import os
import re
import subprocess
import sys
import tomllib
from importlib.metadata import entry_points

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _pyproject():
    with open(os.path.join(ROOT, "pyproject.toml"), "rb") as fh:
        return tomllib.load(fh)


def test_pyproject_metadata():
    proj = _pyproject()["project"]
    assert proj["name"] == "gearjax"
    assert proj["requires-python"] == ">=3.11"
    runtime = {re.split(r"[<>=!~ ;\[]", d, maxsplit=1)[0].lower() for d in proj["dependencies"]}
    # flatbuffers: JAX's export format (gearjax/program_store.py)
    assert runtime == {"jax", "jaxopt", "optax", "numpy", "matplotlib", "flatbuffers"}
    test = {re.split(r"[<>=!~ ;\[]", d, maxsplit=1)[0].lower()
            for d in proj["optional-dependencies"]["test"]}
    assert {"pytest", "pytest-xdist", "hypothesis", "scipy"} <= test
    assert proj["scripts"]["gearjax"] == "gearjax.cli:main"
    assert proj["optional-dependencies"]["gpu"] == ["jax[cuda12]"]


def test_console_script_is_installed():
    eps = entry_points(group="console_scripts", name="gearjax")
    assert [ep.value for ep in eps] == ["gearjax.cli:main"]


def test_importing_gearjax_enables_float64():
    # a fresh interpreter: conftest.py enables x64 itself, so this must not run in-process
    code = ("import jax, jax.numpy as jnp; assert not jax.config.jax_enable_x64; "
            "import gearjax; print(jax.config.jax_enable_x64, jnp.asarray(1.0).dtype)")
    env = {k: v for k, v in os.environ.items() if k != "JAX_ENABLE_X64"}
    env["JAX_PLATFORMS"] = "cpu"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                         cwd=ROOT, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "float64"]


def test_readme_has_the_two_commands_and_ci_runs_the_test_command():
    readme = open(os.path.join(ROOT, "README.md"), encoding="utf-8").read()
    section = readme.split("## Two commands", 1)[1].split("\n## ", 1)[0]
    blocks = re.findall(r"```bash\n(.*?)\n```", section, flags=re.S)
    assert len(blocks) == 2 and all("\n" not in b.strip() for b in blocks)
    main_job, tests = (b.strip() for b in blocks)
    assert "pip install -e ." in main_job and "gearjax optimize example:" in main_job
    assert 'pip install -e ".[test]"' in tests and tests.endswith("python -m pytest -q")
    ci = open(os.path.join(ROOT, ".ci", "run"), encoding="utf-8").read()
    assert "python3 -m venv" in ci and 'pip install -q -e ".[test]" && python -m pytest -q' in ci
    assert "set -euo pipefail" in ci  # a failing test fails the script
