"""The notebooks run top to bottom without error (executed in a fresh kernel), and the
quick start's gradient agrees with its central difference."""

import re
from pathlib import Path

import pytest

nbformat = pytest.importorskip("nbformat", reason="notebook tooling is in the test extra")
nbclient = pytest.importorskip("nbclient", reason="notebook tooling is in the test extra")

ROOT = Path(__file__).resolve().parents[1]


def _run(path, tmp_path):
    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(nb, timeout=900, kernel_name="python3",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()
    return nb


def _text(nb):
    out = []
    for c in nb.cells:
        for o in c.get("outputs", []):
            out.append(o.get("text", "") if o.get("output_type") == "stream"
                       else "".join(o.get("data", {}).get("text/plain", "")))
    return "\n".join(out)


def _images(nb):
    """Number of figures the notebook displays (PNG outputs)."""
    return sum("image/png" in o.get("data", {}) for c in nb.cells for o in c.get("outputs", []))


def test_quickstart_runs_and_its_gradient_matches(tmp_path):
    nb = _run(ROOT / "notebooks" / "01_quickstart.ipynb", tmp_path)
    text = _text(nb)
    assert "float64: True" in text
    m = re.search(r"rel\. error ([0-9.e+-]+)", text)
    assert m, text[-2000:]
    assert float(m.group(1)) < 1e-6
    flags = re.search(r"flags\s+(\{.*\})", text).group(1)
    assert "'converged': True" in flags


def test_design_study_notebook_runs_and_converges(tmp_path):
    nb = _run(ROOT / "notebooks" / "02_design_study.ipynb", tmp_path)
    text = _text(nb)
    assert _images(nb) == 1         # the study figure, in the kernel's inline backend
    assert "converged:" in text and "accepted: True []" in text, text[-2000:]
    kkt = re.search(r"stationarity ([0-9.e+-]+), feasibility ([0-9.e+-]+)", text)
    assert float(kkt.group(1)) <= 1e-4 and float(kkt.group(2)) <= 1e-4


def test_ehl_check_notebook_meets_its_references(tmp_path):
    """The EHL notebook (48²: the programs of test_ehl.py): the smooth film against
    Hamrock-Dowson, the fast model against the numerical rough contact, and the adjoint
    gradients against central differences (what the notebook prints, read back)."""
    text = _text(_run(ROOT / "notebooks" / "03_ehl_check.ipynb", tmp_path))
    assert "converged True" in text and "numerical solve converged True" in text, text[-2000:]
    ratio = float(re.search(r"h_c  numerical .* ratio ([0-9.]+)", text).group(1))
    assert 0.9 <= ratio <= 1.1
    mu = re.search(r"^mu\s+([0-9.]+)\s+([0-9.]+)\s+([0-9.]+)$", text, re.M)
    assert 0.7 <= float(mu.group(3)) <= 1.3, mu.group(0)
    worst = float(re.search(r"largest relative difference ([0-9.e+-]+)", text).group(1))
    assert worst < 1e-5


def test_vh_catt_notebook_efficiency_and_its_gradient(tmp_path):
    """The VH-CATT notebook: the efficiency at the operating point of docs/vh_catt.md
    (0.987854, the table there), every sweep point valid, and the jitted gradient of the
    efficiency by the cutter radii against central differences."""
    text = _text(_run(ROOT / "notebooks" / "04_vh_catt_efficiency.ipynb", tmp_path))
    eta = float(re.search(r"mean mesh efficiency ([0-9.]+)", text).group(1))
    assert abs(eta - 0.987854) <= 2e-6, text[-2000:]
    rows = re.findall(r"^\s+[0-9.]+\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+(\d+)$", text, re.M)
    assert len(rows) == 15 and all(int(n) == 24 for _, n in rows), rows
    worst = float(re.search(r"largest relative error ([0-9.e+-]+)", text).group(1))
    assert worst < 5e-5


def test_preset_te_bevel_notebook_preset_sweep_and_derivatives(tmp_path):
    """The preset-TE bevel notebook (the TCA programs of test_preset_bevel_tca.py): the
    preset parabola followed (docs/preset_te_bevel.md: 0.21 arcsec), smooth transfers
    aligned, the jump under dG shrinking as kappa grows, and the forward-mode
    derivatives by kappa and rho1 against central differences."""
    text = _text(_run(ROOT / "notebooks" / "05_preset_te_bevel.ipynb", tmp_path))
    dev = float(re.search(r"preset parabola ([0-9.]+) arcsec", text).group(1))
    assert dev < 0.5, text[-2000:]
    gaps = re.search(r"preset .* transfer gaps ([-+0-9.]+) / ([-+0-9.]+) arcsec", text)
    assert float(gaps.group(1)) < 0 and float(gaps.group(2)) < 0
    rows = re.findall(r"^\s+([0-9.]+)\s+[0-9.]+\s+[0-9.]+\s+([-0-9.]+)\s+(?:\[|none)", text, re.M)
    jumps = [float(g) for _, g in rows]
    assert len(jumps) == 4 and all(a > b for a, b in zip(jumps, jumps[1:])), rows
    worst = float(re.search(r"largest relative error ([0-9.e+-]+)", text).group(1))
    assert worst < 1e-5


def test_cutter_radius_notebook_table_fields_and_derivatives(tmp_path):
    """The cutter-radius notebook (7 x 5: the programs of test_cutter_radius_study.py):
    the seed's Table 1 trends, the curvature-interference case found, the sweep's
    derivatives against central differences, and the field maps displayed (a plot
    module that forced the Agg backend on import hid them)."""
    nb = _run(ROOT / "notebooks" / "06_cutter_radius_study.ipynb", tmp_path)
    text = _text(nb)
    rows = re.findall(r"^(\S+in)\s+[0-9.]+\s+([0-9.]+)\s+[0-9.]+\s+([0-9.]+)", text, re.M)
    d1 = [float(r[1]) for r in rows]
    assert len(rows) == 3 and d1[0] > d1[1] > d1[2], rows
    assert "curvature interference inside: True" in text
    worst = float(re.search(r"central difference ([0-9.e+-]+)$", text, re.M).group(1))
    assert worst < 1e-6
    assert _images(nb) == 2
