"""One sparse solver layer for every solve: every variant of the speed-against-error study (each
mass-spring model solved non-linearly and linearised, linear FEM, the non-linear FEM law, the
quadratic reference) reaches its linear systems through
:func:`msslib.solvers.linear.solve_linear_system`, and no sparse factorisation of SciPy runs
outside it; no module outside :mod:`msslib.solvers` calls SciPy's sparse direct solvers."""

import ast
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import msslib.scene
from msslib.solvers import linear as solvers_linear

ROOT = Path(__file__).resolve().parents[1]
CANTILEVER = ROOT / "experiments" / "performance" / "scenes" / "cantilever.yaml"
DIRECT = ("spsolve", "splu", "factorized", "spilu")
#: modules outside msslib/solvers allowed to call them, and why
ALLOWED = {
    # the least-squares fit of spring constants (no simulation solve): an LU with its own pivoting
    "msslib/models/lsq.py",
    # the "before" the benchmark measures against: plain SuperLU
    "benchmarks/statics.py",
}


@pytest.fixture
def layer(monkeypatch):
    """Counts the calls of the layer's entry point, and SciPy's direct sparse solves made outside it."""
    state = {"layer": 0, "inside": 0, "outside": []}
    real = solvers_linear.solve_linear_system

    def entry(*args, **kw):
        state["layer"] += 1
        state["inside"] += 1
        try:
            return real(*args, **kw)
        finally:
            state["inside"] -= 1

    for target in ("msslib.solvers.linear.solve_linear_system", "msslib.solvers.statics.solve_linear_system",
                   "msslib.stepping.generic.solve_linear_system"):
        monkeypatch.setattr(target, entry)
    for name in DIRECT:
        original = getattr(spla, name)

        def watched(*args, _original=original, _name=name, **kw):
            if not state["inside"]:
                state["outside"].append(_name)
            return _original(*args, **kw)

        monkeypatch.setattr(spla, name, watched)
    return state


def test_every_variant_of_the_speed_against_error_study_solves_through_the_layer(layer, monkeypatch):
    from msslib.planning import MODELS, measure_front

    seen = []
    real_run = msslib.scene.run_scene

    def run(scene, *args, **kw):
        before, outside = layer["layer"], len(layer["outside"])
        out = real_run(scene, *args, **kw)
        seen.append((scene.model, bool(scene.solver.get("linear")), layer["layer"] - before,
                     layer["outside"][outside:]))
        return out

    monkeypatch.setattr(msslib.scene, "run_scene", run)
    before_reference = layer["layer"]
    front = measure_front(str(CANTILEVER), levels=[1], models=MODELS["hexahedron"], repeats=1, budget=None,
                          progress=None, linear_variants=True)
    assert layer["outside"] == []
    variants = {(m, lin) for m, lin, _, _ in seen}
    mss = [m for m in MODELS["hexahedron"] if not m.startswith("fem_")]
    assert variants == {(m, lin) for m in mss for lin in (False, True)} | {("fem_linear", False),
                                                                           ("fem_neohookean", False)}
    for model, linear, calls, outside in seen:
        assert calls >= 1 and outside == [], (model, linear, calls, outside)
    # the quadratic reference too: more layer calls than the runs made
    assert layer["layer"] - before_reference > sum(c for *_, c, _ in seen)
    assert np.isfinite(front.error_max.values).all()


def test_the_scene_runner_routes_static_linearised_and_dynamic_solves_through_the_layer(layer):
    from msslib.scene import load_scene, run_scene
    import yaml

    raw = yaml.safe_load(CANTILEVER.read_text())
    cases = {
        "static": raw["solver"],
        "linear": {**raw["solver"], "linear": True},
        "dynamic": {"type": "dynamic", "dt": 0.01, "t_end": 0.03, "method": "implicit_euler"},
    }
    for name, solver in cases.items():
        before = layer["layer"]
        run_scene(load_scene({**raw, "solver": solver}), progress=False)
        assert layer["layer"] > before, name
    assert layer["outside"] == []


def test_linearised_mss_equals_a_direct_solve_of_its_stiffness():
    """The linearised run (now through the layer) equals SciPy's SuperLU on the same matrix."""
    from msslib.scene import load_scene, prepare, run_scene
    import yaml

    raw = yaml.safe_load(CANTILEVER.read_text())
    raw["geometry"]["args"].update(nx=12, ny=3, nz=3)
    raw["solver"] = {**raw["solver"], "linear": True}
    res = run_scene(load_scene(raw), progress=False)
    model = prepare(load_scene(raw)).model
    free = model.free
    K, f = model.stiffness(model.x0, 1.0).tocsc(), model.force(model.x0, 1.0)
    u = np.zeros(K.shape[0])
    u[free] = spla.splu(K[free][:, free].tocsc()).solve(f[free])
    got = np.ravel(res["displacement"].values)
    assert np.abs(got - u).max() <= 1e-9 * np.abs(u).max()
    assert "msslib.solvers" in res.attrs.get("solver", str(res.attrs))


def test_fem_solve_sparse_goes_through_the_layer(layer):
    from msslib import fem

    A = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(50, 50), format="csr")
    b = np.ones(50)
    x = fem.solve_sparse(A, b)
    assert layer["layer"] == 1 and layer["outside"] == []
    np.testing.assert_allclose(A @ x, b, rtol=0, atol=1e-12)
    with pytest.raises(np.linalg.LinAlgError):
        fem.solve_sparse(sp.csr_matrix((3, 3)), np.ones(3))


def _direct_calls(path):
    """Calls of SciPy's sparse direct solvers in a source file (any alias)."""
    tree = ast.parse(path.read_text())
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("scipy.sparse"):
            found += [a.name for a in node.names if a.name in DIRECT]
        elif (isinstance(node, ast.Attribute) and node.attr in DIRECT
              and isinstance(node.value, (ast.Name, ast.Attribute))):
            found.append(node.attr)
    return found


def test_no_module_outside_the_solver_layer_calls_scipys_sparse_direct_solvers():
    offenders = {}
    for top in ("msslib", "experiments", "benchmarks"):
        for path in sorted((ROOT / top).rglob("*.py")):
            rel = path.relative_to(ROOT).as_posix()
            if rel.startswith("msslib/solvers/") or rel in ALLOWED:
                continue
            calls = _direct_calls(path)
            if calls:
                offenders[rel] = calls
    assert offenders == {}
    # the check sees a call: the allowed baseline has one
    assert _direct_calls(ROOT / "benchmarks" / "statics.py")
    assert re.search(r"\bsplu\b", (ROOT / "msslib" / "solvers" / "direct.py").read_text())
