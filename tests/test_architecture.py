"""The import rules of docs/architecture.md, read from the source with ``ast``: the
backbone imports no family, study, plot or command; ``io.py`` imports nothing of
gearjax; families import no other family, study, plot or command; no module imports
another module's private (underscore) name; commands use the public API and the
boundary helpers only; the public API lists only names that exist."""

import ast
from pathlib import Path

import gearjax

PKG = Path(gearjax.__file__).resolve().parent
BACKBONE = {"frames", "newton", "surfaces", "kinematics", "tca", "multi_pair", "edge_contact", "tca_result", "family", "contact",
            "tooth_compliance", "loaded_contact", "optimize", "io", "errors", "progress", "fields",
            "materials"}


def _imports(path: Path):
    """(module imported, names) for every ``import``/``from ... import`` of gearjax."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    rel = path.relative_to(PKG.parent).with_suffix("").parts
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = list(rel[:-node.level])
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            if mod.startswith("gearjax"):
                out.append((mod, [a.name for a in node.names]))
        elif isinstance(node, ast.Import):
            out += [(a.name, []) for a in node.names if a.name.startswith("gearjax")]
    return out


def _modules():
    for p in sorted(PKG.rglob("*.py")):
        yield ".".join(p.relative_to(PKG.parent).with_suffix("").parts), p


def _targets(mod, names):
    """Full names of what an import refers to (a module, or module.name)."""
    return [mod] + [f"{mod}.{n}" for n in names]


def test_backbone_imports_no_family_study_plot_or_command():
    bad = []
    for name, path in _modules():
        parts = name.split(".")
        if len(parts) == 2 and parts[1] in BACKBONE:
            for mod, names in _imports(path):
                for t in _targets(mod, names):
                    if t.startswith(("gearjax.gears", "gearjax.studies", "gearjax.plot",
                                     "gearjax.commands", "gearjax.cli", "gearjax.tribology")):
                        bad.append((name, t))
    assert not bad, bad


def test_io_is_a_leaf():
    assert _imports(PKG / "io.py") == []


def test_families_do_not_import_each_other_or_the_layers_above():
    bad = []
    for name, path in _modules():
        if not name.startswith("gearjax.gears."):
            continue
        fam = name.split(".")[2]
        for mod, names in _imports(path):
            for t in _targets(mod, names):
                other_family = t.startswith("gearjax.gears.") and t.split(".")[2] != fam
                above = t.startswith(("gearjax.studies", "gearjax.plot", "gearjax.commands",
                                      "gearjax.cli"))
                # the top-level API (gearjax/__init__) imports the families: a family
                # importing a name from it would be a cycle (submodules are fine)
                from_api = (mod == "gearjax" and t != "gearjax"
                            and not (PKG / f"{t.split('.')[1]}.py").exists())
                if other_family or above or from_api:
                    bad.append((name, t))
    assert not bad, bad


def test_no_module_imports_a_private_name_of_another():
    bad = []
    for name, path in _modules():
        for mod, names in _imports(path):
            if mod == name:
                continue
            bad += [(name, mod, n) for n in names if n.startswith("_")]
    assert not bad, bad


def test_commands_use_the_public_api_and_boundary_helpers():
    allowed = ("gearjax.errors", "gearjax.io", "gearjax.progress", "gearjax.plot",
               "gearjax.tribology", "gearjax.studies", "gearjax.commands")
    bad = []
    for name, path in _modules():
        if not name.startswith("gearjax.commands") and name != "gearjax.cli":
            continue
        for mod, names in _imports(path):
            if mod == "gearjax":
                bad += [(name, n) for n in names if n not in gearjax.__all__ and n != "cli"]
            elif not mod.startswith(allowed):
                bad.append((name, mod))
    assert not bad, bad


def test_public_api_names_exist_and_tca_entry_points_are_there():
    missing = [n for n in gearjax.__all__ if not hasattr(gearjax, n)]
    assert not missing
    for n in ("run_tca", "tca_function", "tca_sensitivity", "TCAResult", "load_design",
              "flank_surface", "synthesise", "friction_coefficient", "least_squares_lm",
              "contact_kinematics", "Misalignment"):
        assert n in gearjax.__all__, n
