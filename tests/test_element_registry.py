"""The derivation registry (derivations.registry): every module found in derivations/elements/ and
derivations/terms/ is checked here without being named, so that a new element needs no edit of
this file: its generated code equals SymPy, its declared models exist in the simulator, it is a
runnable notebook, and adding a module leaves every other generated file up to date."""

from __future__ import annotations

import importlib
import inspect
import shutil
import subprocess
import sys

import numpy as np
import pytest
import sympy as sp

from derivations import codegen, element_stiffness as fem, notebook, registry

GENERATED = registry.generated()
ELEMENTS = registry.elements()


def test_registry_lists_the_folders():
    assert ELEMENTS and registry.terms()
    assert GENERATED == ELEMENTS + registry.terms()
    for kind in ("elements", "terms"):
        files = sorted(p.stem for p in (registry.HERE / kind).glob("*.py") if p.name != "__init__.py")
        assert sorted(registry.names(kind)) == files
    for name in GENERATED + registry.names("analyses"):
        assert registry.resolve(f"derivations/{registry.kind(name)}/{name}.py") == name
        assert registry.module(name).__file__ == str(registry.path(name))
    with pytest.raises(KeyError):
        registry.kind("no_such_module")


def test_element_order_dimension_nodes_and_extensions():
    decl = {n: registry.element(n) for n in ELEMENTS}
    dims = [(len(fem._REF[decl[n].cell][0]), len(fem._REF[decl[n].cell])) for n in ELEMENTS]
    assert dims == sorted(dims)  # 2D before 3D, fewer nodes first
    for n, d in decl.items():
        if d.extends:  # after the element it generalises, with only its other extensions between
            between = ELEMENTS[ELEMENTS.index(d.extends) + 1:ELEMENTS.index(n)]
            assert ELEMENTS.index(n) > ELEMENTS.index(d.extends)
            assert all(decl[m].extends == d.extends for m in between), (n, between)


def test_no_list_of_modules_in_codegen_or_registry():
    """Adding an element edits neither the code generator nor the registry."""
    for path in (registry.HERE / "codegen.py", registry.HERE / "registry.py"):
        text = path.read_text()
        for name in GENERATED:
            assert f'"{name}"' not in text and f"'{name}'" not in text, (path.name, name)


def test_adding_a_module_changes_no_other_hash(tmp_path, monkeypatch):
    """The source hash of a generated file covers the engine and its own module only."""
    before = {m: codegen.source_hash(m) for m in GENERATED}
    copy = tmp_path / "derivations"
    shutil.copytree(registry.HERE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.setattr(registry, "HERE", copy)
    monkeypatch.setattr(registry, "ROOT", tmp_path)
    assert {m: codegen.source_hash(m) for m in GENERATED} == before  # same files, same hashes
    (copy / "elements" / "zz_new_element.py").write_text("ELEMENT = None\n")
    assert "zz_new_element" in registry.names("elements")
    assert {m: codegen.source_hash(m) for m in GENERATED} == before
    own = copy / "elements" / f"{ELEMENTS[0]}.py"
    own.write_text(own.read_text() + "\n")
    after = {m: codegen.source_hash(m) for m in GENERATED}
    assert [m for m in GENERATED if after[m] != before[m]] == [ELEMENTS[0]]
    (copy / "element_stiffness.py").write_text((copy / "element_stiffness.py").read_text() + "\n")  # the engine: every file is stale
    assert all(codegen.source_hash(m) != after[m] for m in GENERATED)


@pytest.mark.parametrize("module", GENERATED)
def test_generated_file_exists_and_is_current(module):
    for path in (codegen.OUT / f"{module}.py", codegen.OUT / codegen.C_DIR / codegen.c_header(module)):
        src, body, _ = codegen._read_header(path)
        assert src == codegen.source_hash(module), path
        assert registry.relpath(module) in path.read_text().splitlines()[0]


@pytest.mark.parametrize("module", GENERATED)
def test_generated_code_equals_symbolic(module):
    """Generated (CSE'd) code against SymPy's own evaluation of the derived expressions, at random
    positive values (nu in (0.05, 0.45))."""
    d = registry.module(module).derive()
    gen = importlib.import_module(f"msslib.generated.{module}")
    assert gen.OUTPUTS == {f.name: tuple(f.outputs) for f in d.formulas + d.published}
    rng = np.random.default_rng(1)
    for f in d.formulas + d.published:
        fn = getattr(gen, f.name)
        assert list(inspect.signature(fn).parameters) == [str(a) for a in f.args]
        exprs = list(f.outputs.values())
        small = sum(sp.count_ops(e) for e in exprs) < 2000
        ref = None if small else sp.lambdify(f.args, exprs, modules="mpmath")
        for _ in range(3):
            vals = [rng.uniform(0.05, 0.45) if str(a) == "nu" else rng.uniform(0.6, 1.4) for a in f.args]
            got = fn(*vals)
            got = got if isinstance(got, tuple) else (got,)
            if small:
                sub = dict(zip(f.args, [sp.Float(v, 30) for v in vals]))
                want = [complex(sp.N(e.subs(sub), 20)) for e in exprs]
            else:
                want = [complex(w) for w in ref(*vals)]
            assert len(got) == len(want)
            for g, w in zip(got, want):
                assert abs(w.imag) < 1e-12
                assert np.isclose(float(g), w.real, rtol=1e-10, atol=1e-12), (f.name, g, w)


@pytest.mark.parametrize("module", ELEMENTS)
def test_element_declares_models_the_simulator_has(module):
    from msslib import scene

    decl = registry.element(module)
    assert decl.cell in fem._REF
    assert all(m in scene.MODELS for m in decl.models), (decl.models, scene.MODELS)
    assert all(scene.MSS_MODELS[m][0] == decl.cell for m in decl.models)  # the model meshes this cell type
    gen = importlib.import_module(f"msslib.generated.{module}")
    assert gen.MODELS == tuple(decl.models)  # carried into the generated module


def test_elements_and_model_specs_name_each_other():
    """Every mass-spring model is fed by exactly one element, and its spec names that element."""
    models = pytest.importorskip("msslib.models")
    fed = {m: n for n in ELEMENTS for m in registry.element(n).models}
    assert len(fed) == sum(len(registry.element(n).models) for n in ELEMENTS)  # no model fed twice
    specs = {name: spec for name, spec in models.registry().items() if spec.element is not None}
    assert {name: spec.element for name, spec in specs.items()} == fed
    for name, spec in specs.items():
        assert registry.element(spec.element).cell in spec.cells, name


@pytest.mark.parametrize("module", GENERATED)
def test_module_is_a_notebook(module):
    """The cheap part of the notebook page (the full render of one module: tests/test_notebooks.py):
    a jupytext notebook whose first cell is the title, whose code cells compile, and which
    ``python -m experiments.paper notebook NAME`` finds by its bare name."""
    import jupytext

    path = registry.path(module)
    assert notebook.find(module) == path
    cells = notebook.cells(path.read_text(encoding="utf-8"))
    assert cells[0][0] == "markdown" and cells[0][1].startswith("# ")
    for kind, text, start in cells:
        if kind == "code":
            compile("\n" * (start - 1) + text + "\n", str(path), "exec")
    nb = jupytext.read(path)
    assert sum(c.cell_type == "code" for c in nb.cells) >= 1


def test_modules_import_silently():
    code = "; ".join(f"import {registry.qualified(m)}" for m in GENERATED)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                       cwd=registry.ROOT)
    assert r.returncode == 0 and r.stdout == "", r.stderr
