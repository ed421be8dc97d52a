"""The import rules of docs/architecture.md, read from the source with ``ast``: the
backbone (top-level modules and the tca/, loading/ and io/ folders) imports no family,
study, plot or command; ``io/`` imports nothing of gearjax outside itself; families import no other family, study, plot or command; no module imports
another module's private (underscore) name; commands use the public API and the
boundary helpers only; the public API lists only names that exist."""

import ast
from pathlib import Path

import gearjax

PKG = Path(gearjax.__file__).resolve().parent
BACKBONE = {"frames", "newton", "surfaces", "kinematics", "tca", "contact", "loading",
            "optimize", "augmented_lagrangian", "io", "errors", "progress", "fields",
            "compile_ahead", "program_store", "correction"}
#: the loaded chain (loading/) stands on tribology/; the rest of the backbone below it
ABOVE_TRIBOLOGY = {"loading"}


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
        if len(parts) >= 2 and parts[1] in BACKBONE:
            for mod, names in _imports(path):
                for t in _targets(mod, names):
                    tribology = (t.startswith("gearjax.tribology")
                                 and parts[1] not in ABOVE_TRIBOLOGY)
                    if tribology or t.startswith(("gearjax.gears", "gearjax.studies",
                                                  "gearjax.plot", "gearjax.commands",
                                                  "gearjax.cli")):
                        bad.append((name, t))
    assert not bad, bad


def test_io_is_a_leaf():
    bad = [(name, mod) for name, path in _modules() if name.startswith("gearjax.io")
           for mod, _ in _imports(path) if not mod.startswith("gearjax.io")]
    assert not bad, bad


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
                            and not (PKG / f"{t.split('.')[1]}.py").exists()
                            and not (PKG / t.split('.')[1]).is_dir())
                if other_family or above or from_api:
                    bad.append((name, t))
    assert not bad, bad


def test_no_module_imports_a_private_name_of_another():
    bad = []
    for name, path in _modules():
        for mod, names in _imports(path):
            if mod == name:
                continue
            bad += [(name, mod, n) for n in names if n.startswith("_") and not n.endswith("__")]
    assert not bad, bad


def test_commands_use_the_public_api_and_boundary_helpers():
    import importlib

    allowed = ("gearjax.errors", "gearjax.io", "gearjax.progress", "gearjax.plot",
               "gearjax.tribology", "gearjax.studies", "gearjax.commands",
               "gearjax.program_store")
    # namespaces: only the names they list
    namespaces = ("gearjax", "gearjax.hypoid", "gearjax.involute", "gearjax.vh_catt",
                  "gearjax.preset_bevel", "gearjax.loading", "gearjax.tca")
    bad = []
    for name, path in _modules():
        if not name.startswith("gearjax.commands") and name != "gearjax.cli":
            continue
        for mod, names in _imports(path):
            if mod in namespaces:
                public = importlib.import_module(mod).__all__
                bad += [(name, mod, n) for n in names if n not in public and n != "cli"]
            elif not mod.startswith(allowed):
                bad.append((name, mod))
    assert not bad, bad


def test_public_face_is_small_and_has_the_family_namespaces():
    """About 40 verbs and types at the top level, no concrete/traced twins, the four
    family namespaces and tribology; every namespace lists only names that exist."""
    assert len(gearjax.__all__) <= 45, len(gearjax.__all__)
    assert not [n for n in gearjax.__all__ if n.endswith("_traced")]
    for ns in ("hypoid", "involute", "vh_catt", "preset_bevel", "tribology"):
        mod = getattr(gearjax, ns)
        assert ns in gearjax.__all__
        assert [n for n in mod.__all__ if not hasattr(mod, n)] == [], ns


def test_public_api_names_exist_and_tca_entry_points_are_there():
    missing = [n for n in gearjax.__all__ if not hasattr(gearjax, n)]
    assert not missing
    for n in ("run_tca", "tca_function", "tca_sensitivity", "TCAResult", "load_design",
              "mesh_efficiency", "efficiency_function", "least_squares_lm",
              "contact_kinematics", "Misalignment"):
        assert n in gearjax.__all__, n
    assert "flank_surface" in gearjax.hypoid.__all__ and "synthesise" in gearjax.hypoid.__all__
    assert "friction_coefficient" in gearjax.tribology.__all__


def _module_of(target: str):
    """The module (dotted name) an import target refers to: the longest prefix that is a
    module file or a package of gearjax."""
    parts = target.split(".")
    for k in range(len(parts), 0, -1):
        path = PKG.parent.joinpath(*parts[:k])
        if path.with_suffix(".py").is_file() or (path / "__init__.py").is_file():
            return ".".join(parts[:k])
    return None


def test_no_import_circles():
    """No two modules import each other, directly or round a longer circle -- imports
    inside functions and type-only imports included (a circle made lazy is still a
    circle of meaning).  A package's ``__init__`` counts as its own module."""
    graph = {}
    for name, path in _modules():
        if name.endswith(".__init__"):
            name = name[: -len(".__init__")]
        edges = graph.setdefault(name, set())
        for mod, names in _imports(path):
            # ``from pkg import sub`` imports the submodule, not the package's names
            subs = [f"{mod}.{n}" for n in names if _module_of(f"{mod}.{n}") == f"{mod}.{n}"]
            others = len(subs) < len(names) or not names
            for t in subs + ([mod] if others else []):
                m = _module_of(t)
                if m and m != name:
                    edges.add(m)
    state, circles = {}, []

    def visit(n, stack):
        state[n] = 1
        stack.append(n)
        for m in sorted(graph.get(n, ())):
            if state.get(m) == 1:
                circles.append(stack[stack.index(m):] + [m])
            elif m not in state:
                visit(m, stack)
        stack.pop()
        state[n] = 2

    for n in sorted(graph):
        if n not in state:
            visit(n, [])
    assert not circles, circles[:5]
