"""The quick start notebook runs top to bottom in a fresh kernel and its gradient agrees
with its central difference.  Every other notebook is tested at the end of the test
file of its subject, after the tests whose compiled programs it reuses
(tests/notebook_run.py)."""

import re

from notebook_run import run_notebook


def test_quickstart_runs_and_its_gradient_matches(tmp_path):
    _, text = run_notebook("01_quickstart", tmp_path)
    assert "float64: True" in text
    m = re.search(r"rel\. error ([0-9.e+-]+)", text)
    assert m, text[-2000:]
    assert float(m.group(1)) < 1e-6
    flags = re.search(r"flags\s+(\{.*\})", text).group(1)
    assert "'converged': True" in flags
