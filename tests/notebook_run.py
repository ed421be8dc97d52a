"""Execute a notebook of notebooks/ in a fresh kernel and read back what it printed.

Each notebook's test sits at the end of the test file of its subject (test_ehl.py,
test_references_loaded.py, ...): the same pytest worker has just compiled the programs
the notebook runs (the same grids and options), and the kernel reads them from the
persistent compilation cache that tests/conftest.py points it to
(``JAX_COMPILATION_CACHE_DIR``).
"""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def run_notebook(name: str, tmp_path):
    """``(nb, text)``: the executed notebook ``notebooks/NAME.ipynb`` (a cell that raises
    fails the test) and the text of its outputs (streams and plain-text values)."""
    nbformat = pytest.importorskip("nbformat", reason="notebook tooling is in the test extra")
    nbclient = pytest.importorskip("nbclient", reason="notebook tooling is in the test extra")
    nb = nbformat.read(ROOT / "notebooks" / f"{name}.ipynb", as_version=4)
    client = nbclient.NotebookClient(nb, timeout=900, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    out = []
    for c in nb.cells:
        for o in c.get("outputs", []):
            out.append(o.get("text", "") if o.get("output_type") == "stream"
                       else "".join(o.get("data", {}).get("text/plain", "")))
    return nb, "\n".join(out)


def images(nb) -> int:
    """Number of figures the notebook displays (PNG outputs)."""
    return sum("image/png" in o.get("data", {}) for c in nb.cells for o in c.get("outputs", []))
