"""Bad input: every entry point refuses it with an error that names the offending value."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import yaml

from msslib.models.baudet import baudet_correction, baudet_cube_springs
from msslib.models.golec import golec_cube_springs
from msslib.models.lloyd import lloyd_square_springs, lloyd_tet_springs, lloyd_triangle_springs, van_gelder_springs
from msslib import cli, fem
from msslib import mesh as M
from msslib import parameters as P
from msslib.results import write_result
from msslib.scene import load_scene, run_scene
from scene_helpers import pressed_cube

E, T = 1.0e6, 0.01
BAD_E = [-1.0, 0.0, float("nan")]
BAD_NU = [0.5, 0.7, -1.0, -1.5]

# ---- parameters --------------------------------------------------------------------------

PARAMETER_FUNCTIONS_E = {
    "lloyd_triangle": lambda e: P.lloyd_triangle(e, t=T),
    "van_gelder_triangle": lambda e: P.van_gelder_triangle(e, t=T, area=0.5, length=1.0),
    "lloyd_square": lambda e: P.lloyd_square(e, t=T),
    "lloyd_tetrahedron": lambda e: P.lloyd_tetrahedron(e, l=1.0),
    "lloyd_tetrahedron_volume": lambda e: P.lloyd_tetrahedron_volume(e, l=1.0, nu=0.3),
    "baudet_cube": lambda e: P.baudet_cube(e, nu=0.3, a=1.0),
    "golec_cube": lambda e: P.golec_cube(e, nu=0.3, a=1.0, A=1.0),
}
PARAMETER_FUNCTIONS_NU = {
    "lloyd_triangle": lambda nu: P.lloyd_triangle(E, t=T, nu=nu),
    "van_gelder_triangle": lambda nu: P.van_gelder_triangle(E, t=T, area=0.5, length=1.0, nu=nu),
    "lloyd_square": lambda nu: P.lloyd_square(E, t=T, nu=nu),
    "lloyd_tetrahedron": lambda nu: P.lloyd_tetrahedron(E, l=1.0, nu=nu),
    "lloyd_tetrahedron_volume": lambda nu: P.lloyd_tetrahedron_volume(E, l=1.0, nu=nu),
    "baudet_cube": lambda nu: P.baudet_cube(E, nu=nu, a=1.0),
    "golec_cube": lambda nu: P.golec_cube(E, nu=nu, a=1.0, A=1.0),
}


@pytest.mark.parametrize("value", BAD_E)
@pytest.mark.parametrize("name", sorted(PARAMETER_FUNCTIONS_E))
def test_parameters_reject_bad_E(name, value):
    with pytest.raises(ValueError, match=rf"E must be finite and > 0, got {value!r}"):
        PARAMETER_FUNCTIONS_E[name](value)


@pytest.mark.parametrize("value", BAD_NU)
@pytest.mark.parametrize("name", sorted(PARAMETER_FUNCTIONS_NU))
def test_parameters_reject_bad_nu(name, value):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", P.FormulaValidityWarning)
        with pytest.raises(ValueError, match=rf"nu must lie in \(-1, 0\.5\), got {value!r}"):
            PARAMETER_FUNCTIONS_NU[name](value)


@pytest.mark.parametrize("name", ["lloyd_triangle", "van_gelder_triangle", "lloyd_square"])
def test_formula_outside_validity_warns(name):
    with pytest.warns(P.FormulaValidityWarning, match=r"exact only for nu = 0\.333333; got nu = 0\.3"):
        PARAMETER_FUNCTIONS_NU[name](0.3)
    with warnings.catch_warnings():
        warnings.simplefilter("error", P.FormulaValidityWarning)
        PARAMETER_FUNCTIONS_NU[name](1 / 3)


# ---- model builders ----------------------------------------------------------------------

TRI = M.triangle_grid_equilateral(1.0, 1.0, 2)
QUAD = M.quad_grid(1.0, 1.0, 2, 2)
TET = M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1)
HEX = M.hex_grid(1.0, 1.0, 1.0, 1, 1, 1)
BUILDERS = {
    "lloyd_triangle_springs": lambda mats: lloyd_triangle_springs(TRI, mats, T),
    "van_gelder_springs": lambda mats: van_gelder_springs(TRI, mats, T),
    "lloyd_square_springs": lambda mats: lloyd_square_springs(QUAD, mats, T),
    "lloyd_tet_springs": lambda mats: lloyd_tet_springs(TET, mats),
    "lloyd_tet_springs_volume": lambda mats: lloyd_tet_springs(TET, mats, volume=True),
    "baudet_cube_springs": lambda mats: baudet_cube_springs(HEX, mats),
    "baudet_correction": lambda mats: baudet_correction(HEX, mats, np.ones((HEX.n_nodes, 3))),
    "golec_cube_springs": lambda mats: golec_cube_springs(HEX, mats, 1.0),
}


@pytest.mark.parametrize("value", BAD_E)
@pytest.mark.parametrize("name", sorted(BUILDERS))
def test_builders_reject_bad_E(name, value):
    with pytest.raises(ValueError, match=rf"E must be finite and > 0, got {value!r}"):
        BUILDERS[name]([(value, 0.3)])


@pytest.mark.parametrize("value", [0.5, -1.0])
@pytest.mark.parametrize("name", sorted(BUILDERS))
def test_builders_reject_bad_nu(name, value):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", P.FormulaValidityWarning)
        with pytest.raises(ValueError, match=rf"nu must lie in \(-1, 0\.5\), got {value!r}"):
            BUILDERS[name]([(E, value)])


@pytest.mark.parametrize("name", ["lloyd_triangle_springs", "lloyd_square_springs"])
def test_builders_warn_outside_formula_validity(name):
    with pytest.warns(P.FormulaValidityWarning, match="nu = 0.3"):
        BUILDERS[name]([(E, 0.3)])


def test_builder_names_the_bad_material_of_several():
    mesh = M.Mesh(HEX.points, HEX.cells, HEX.cell_type, np.array([1]))
    with pytest.raises(ValueError, match=r"got 0\.7"):
        golec_cube_springs(mesh, [(E, 0.3), (E, 0.7)], 1.0)


# ---- FEM ---------------------------------------------------------------------------------

def _fem_calls(E_, nu_):
    fixed = np.zeros((TET.n_nodes, 3), bool)
    fixed[np.isclose(TET.points[:, 2], 0.0)] = True
    return {
        "solve_linear": lambda: fem.solve_linear(TET, E_, nu_, fixed=fixed),
        "solve_nonlinear": lambda: fem.solve_nonlinear(TET, E_, nu_, fixed=fixed, law="neohookean", steps=1),
        "element_stiffness": lambda: fem.element_stiffness("tetra", TET.points[TET.cells[0]], E_, nu_),
    }


@pytest.mark.parametrize("call", ["solve_linear", "solve_nonlinear", "element_stiffness"])
@pytest.mark.parametrize("value", BAD_E)
def test_fem_rejects_bad_E(call, value):
    with pytest.raises(ValueError, match=rf"E={value!r} of material 0 must be > 0"):
        _fem_calls(value, 0.3)[call]()


@pytest.mark.parametrize("call", ["solve_linear", "solve_nonlinear", "element_stiffness"])
@pytest.mark.parametrize("value", BAD_NU)
def test_fem_rejects_bad_nu(call, value):
    with pytest.raises(ValueError, match=rf"nu={value!r} of material 0 must satisfy -1 < nu < 0\.5"):
        _fem_calls(E, value)[call]()


# ---- degenerate and inverted meshes ------------------------------------------------------

# cell 1 is degenerate: a collinear triangle, a flat tetrahedron
COLLINEAR = M.Mesh(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [2.0, 0.0]]), np.array([[0, 1, 2], [0, 1, 3]]), "triangle")
FLAT = M.Mesh(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0]]), np.array([[0, 1, 2, 3], [0, 1, 2, 4]]),
              "tetra")


@pytest.mark.parametrize("call", [
    lambda: lloyd_triangle_springs(COLLINEAR, [(E, 1 / 3)], T),
    lambda: van_gelder_springs(COLLINEAR, [(E, 1 / 3)], T),
    lambda: fem.solve_linear(COLLINEAR, E, 0.3, fixed=np.ones((4, 2), bool)),
    lambda: lloyd_tet_springs(FLAT, [(E, 0.25)]),
    lambda: lloyd_tet_springs(FLAT, [(E, 0.25)], volume=True),
    lambda: fem.solve_linear(FLAT, E, 0.3, fixed=np.ones((5, 3), bool)),
    lambda: fem.solve_nonlinear(FLAT, E, 0.3, fixed=np.ones((5, 3), bool)),
], ids=["lloyd_triangle", "van_gelder", "fem_triangle", "lloyd_tet", "lloyd_tet_volume", "fem_linear_tet", "fem_svk_tet"])
def test_degenerate_cell_named(call):
    with pytest.raises(ValueError, match=r"1 degenerate (triangle|tetra) cell\(s\): cell 1 \(measure 0\.000e\+00\)"):
        call()


def test_inverted_cell_named_by_fem():
    cells = TET.cells.copy()
    cells[3] = cells[3][[0, 2, 1, 3]]
    inverted = M.Mesh(TET.points, cells, "tetra")
    with pytest.raises(ValueError, match=r"1 inverted tetra cell\(s\): cell 3 "):
        fem.solve_linear(inverted, E, 0.3, fixed=np.ones((TET.n_nodes, 3), bool))
    with pytest.raises(ValueError, match=r"1 inverted tetra cell\(s\): cell 3 "):
        lloyd_tet_springs(inverted, [(E, 0.25)])


# ---- scenes and the command line ---------------------------------------------------------

def _scene(**changes):
    return pressed_cube("bad_input", cells=1, **changes)


def _run_cli(tmp_path, capsys, scene, out_name="out.nc"):
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene) if isinstance(scene, dict) else scene)
    out = tmp_path / out_name
    code = cli.main(["run", str(path), "--out", str(out), "--quiet"])
    return code, capsys.readouterr().err, out


def _leftovers(directory):
    return sorted(p.name for p in directory.iterdir() if p.name != "scene.yaml")


def test_cli_valid_scene_runs(tmp_path, capsys):
    code, err, out = _run_cli(tmp_path, capsys, _scene())
    assert code == 0 and out.exists(), err


@pytest.mark.parametrize("material, key, shown", [
    ({"E": -1.0e6, "nu": 0.3}, "scene.materials[0].E", "-1000000.0"),
    ({"E": 0, "nu": 0.3}, "scene.materials[0].E", "0"),
    ({"E": 1.0e6, "nu": 0.5}, "scene.materials[0].nu", "0.5"),
    ({"E": 1.0e6, "nu": -1.2}, "scene.materials[0].nu", "-1.2"),
])
def test_cli_bad_material(tmp_path, capsys, material, key, shown):
    code, err, out = _run_cli(tmp_path, capsys, _scene(materials=[material]))
    assert code == 1
    assert err.startswith("msslib: error:") and key in err and f"got {shown}" in err
    assert _leftovers(tmp_path) == []


def test_cli_unknown_key(tmp_path, capsys):
    code, err, _ = _run_cli(tmp_path, capsys, _scene(solvr={"type": "static"}))
    assert code == 1 and "scene.solvr: unknown key" in err and "did you mean 'solver'" in err
    assert _leftovers(tmp_path) == []
    with pytest.raises(ValueError, match=r"scene\.materials\[0\]\.young: unknown key"):
        load_scene(_scene(materials=[{"E": 1e6, "nu": 0.3, "young": 1}]))


def test_cli_missing_mesh_file(tmp_path, capsys):
    code, err, _ = _run_cli(tmp_path, capsys, _scene(geometry={"file": "no_such_mesh.vtu"}))
    assert code == 1 and "mesh file not found" in err and "no_such_mesh.vtu" in err
    assert _leftovers(tmp_path) == []


def test_cli_output_parent_is_a_file(tmp_path, capsys):
    blocker = tmp_path / "blocker"
    blocker.write_text("not a directory")
    code, err, out = _run_cli(tmp_path, capsys, _scene(), out_name="blocker/out.nc")
    assert code == 1
    assert str(out) in err and "is not a directory" in err
    assert blocker.read_text() == "not a directory"
    assert _leftovers(tmp_path) == ["blocker"]


def test_write_result_parent_is_a_file(tmp_path):
    blocker = tmp_path / "blocker"
    blocker.write_text("x")
    ds = run_scene(_scene(), progress=False)
    with pytest.raises(NotADirectoryError, match="blocker"):
        write_result(blocker / "out.nc", ds)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["blocker"]
