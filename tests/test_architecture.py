"""The shape of the code: imports go one way (derivations -> generated -> msslib -> experiments ->
paper), no module imports one that imports it back (function-level imports included), and no
hand-written source file is over 600 lines."""

from __future__ import annotations

import ast
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("derivations", "msslib", "experiments", "benchmarks")
#: what each package may import (besides itself): the library needs nothing of the derivations (sympy is
#: not needed to simulate); the paper builder and the plotting are workflow (experiments.paper, .plotting)
ALLOWED = {"derivations": set(), "msslib": set(), "experiments": {"msslib", "derivations"},
           "benchmarks": {"msslib", "derivations", "experiments"}}


def _modules():
    mods = {}
    for package in PACKAGES:
        for path in (ROOT / package).rglob("*.py"):
            if "generated" in path.parts and package == "msslib":
                continue
            name = ".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
            mods[name] = path
    return mods


def _imports(name, path, mods):
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom):
            base = package
            for _ in range(max(node.level - 1, 0)):
                base = base.rsplit(".", 1)[0]
            full = (base + ("." + node.module if node.module else "")) if node.level else (node.module or "")
            candidates = [full] + [f"{full}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            candidates = [a.name for a in node.names]
        else:
            continue
        for c in candidates:
            while c and c not in mods:
                c = c.rsplit(".", 1)[0] if "." in c else ""
            if c and c != name and not name.startswith(c + "."):
                out.add(c)
    return out


def test_imports_go_one_way():
    mods = _modules()
    bad = [(m, d) for m, p in mods.items() for d in _imports(m, p, mods)
           if d.split(".")[0] != m.split(".")[0] and d.split(".")[0] not in ALLOWED[m.split(".")[0]]]
    assert not bad, bad


def test_no_import_cycles():
    mods = _modules()
    graph = {m: _imports(m, p, mods) for m, p in mods.items()}
    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10000))
    index, low, stack, on, cycles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                cycles.append(sorted(component))

    for v in graph:
        if v not in index:
            visit(v)
    assert not cycles, cycles


@pytest.mark.parametrize("package", PACKAGES + ("tests",))
def test_no_hand_written_file_over_600_lines(package):
    long = [(str(p.relative_to(ROOT)), n) for p in (ROOT / package).rglob("*.py")
            if "generated" not in p.parts and (n := len(p.read_text(encoding="utf-8").splitlines())) > 600]
    assert not long, long


def test_a_concern_is_a_package_not_prefixed_siblings():
    """A concern that outgrows one file becomes a package (msslib.export, msslib.results, ...), not
    prefixed sibling modules beside the library's face (export, export_files, export_text, ...)."""
    top = ROOT / "msslib"
    names = sorted({p.stem for p in top.glob("*.py") if not p.stem.startswith("_")}
                   | {p.name for p in top.iterdir() if (p / "__init__.py").is_file() and p.name != "generated"})
    siblings = [(a, b) for a in names for b in names if b.startswith(a + "_")]
    assert not siblings, siblings
    assert not (top / "paper.py").exists() and not (top / "plotting.py").exists()  # workflow, not library


def test_package_faces_export_public_names_only():
    """A package's ``__init__`` imports no underscore name: internals are imported from the module
    that defines them, so every name has one path."""
    bad = []
    for init in (ROOT / "msslib").rglob("__init__.py"):
        if "generated" in init.parts:
            continue
        for node in ast.walk(ast.parse(init.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("msslib")):
                bad += [f"{init.relative_to(ROOT)}: {a.name}" for a in node.names
                        if a.name.startswith("_") and not a.name.startswith("__")]
    assert not bad, bad


def test_underscore_names_stay_inside_their_package():
    """A name with a leading underscore is imported only by modules of the package that defines it
    (``msslib.solvers.statics`` may take ``msslib.solvers.memo._Memo``, ``msslib.system`` may not take
    ``msslib.terms.assembly``'s helpers): what another package needs is public in its module."""
    bad = []
    for path in (ROOT / "msslib").rglob("*.py"):
        if "generated" in path.parts:
            continue
        name = ".".join(path.relative_to(ROOT).with_suffix("").parts).removesuffix(".__init__")
        own = name.split(".")[:2]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and not node.level and (node.module or "").startswith("msslib."):
                if node.module.split(".")[:2] != own:
                    bad += [f"{name}: {node.module}.{a.name}" for a in node.names
                            if a.name.startswith("_") and not a.name.startswith("__")]
    assert not bad, bad


def test_no_module_is_named_like_a_sibling_package():
    """A module beside a package of (nearly) the same name (``model`` beside ``models``, ``plan``
    beside ``plans``) gives one concept two paths; every name says what it holds."""
    clashes = []
    for package in (ROOT / "msslib").rglob("__init__.py"):
        folder = package.parent
        if "generated" in folder.parts:
            continue
        modules = {p.stem for p in folder.glob("*.py") if p.stem != "__init__"}
        packages = {p.name for p in folder.iterdir() if (p / "__init__.py").is_file()}
        clashes += [f"{folder.relative_to(ROOT)}/{m}.py beside {m}s/" for m in modules if f"{m}s" in packages]
        clashes += [f"{folder.relative_to(ROOT)}/{m}.py beside {m[:-1]}/" for m in modules
                    if m.endswith("s") and m[:-1] in packages]
    assert not clashes, clashes


def test_the_stepping_package_does_not_import_the_layers_above_it():
    """Time stepping has one home, ``msslib.stepping``; it builds on the solvers, terms and mesh
    and imports nothing of the scene, planning, comparison, export or command-line layers (node
    selection lives with the mesh, ``msslib.mesh.selection``); and the solvers below it import
    nothing of it (no arrow running back up)."""
    mods = _modules()
    above = ("msslib.scene", "msslib.planning", "msslib.compare", "msslib.export", "msslib.cli", "msslib.experiment",
             "msslib.api")
    bad = [(m, d) for m, p in mods.items() if m.startswith("msslib.stepping")
           for d in _imports(m, p, mods) if d.startswith(above)]
    bad += [(m, d) for m, p in mods.items() if m.startswith(("msslib.solvers", "msslib.terms", "msslib.mesh"))
            for d in _imports(m, p, mods) if d.startswith("msslib.stepping")]
    assert not bad, bad
    assert not any(m.startswith(("msslib.simulator", "msslib.explicit")) for m in mods)  # the old homes are gone
