"""Mesh hygiene: coincident nodes, floating parts and free rigid-body modes before a static solve,
unused materials, and bad mesh files (one-line errors, never SystemExit)."""

from __future__ import annotations

import struct
from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml

from msslib import mesh as M
from msslib.cli import main
from msslib.errors import MsslibWarning
from msslib.scene import load_scene, prepare, run_scene

SCENES = Path(__file__).resolve().parents[1] / "experiments" / "scenes"
MAT = {"E": 1.0e6, "nu": 0.3, "density": 1000.0}


def _two_cubes(gap: float = 0.0) -> M.Mesh:
    """Two hexahedra of edge 0.1 m side by side along x, each with its own 8 nodes: with
    ``gap == 0`` nodes 8, 10, 12, 14 of the second sit exactly on nodes 1, 3, 5, 7 of the first."""
    a = M.hex_grid(0.1, 0.1, 0.1, 1, 1, 1)
    points = np.vstack([a.points, a.points + [0.1 + gap, 0.0, 0.0]])
    return M.Mesh(points, np.vstack([a.cells, a.cells + 8]), "hexahedron", [0, 1])


def _beam_scene(geometry, **changes) -> dict:
    scene = {
        "geometry": geometry,
        "materials": [MAT, MAT],
        "model": "golec_cube",
        "boundary": [{"select": {"plane": ["x", 0.0]}, "fix": "all"}],
        "loads": [{"type": "traction", "select": {"plane": ["x", 0.2]}, "traction": [1.0e4, 0.0, 2.0e3]}],
        "solver": {"type": "static", "load_steps": 1, "tol": 1.0e-10},
    }
    scene.update(changes)
    return scene


def _cube_scene(boundary, **changes) -> dict:
    scene = {
        "geometry": {"generator": "hex_grid", "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": 2, "ny": 2, "nz": 2}},
        "materials": [MAT],
        "model": "golec_cube",
        "boundary": boundary,
        "solver": {"type": "static"},
    }
    scene.update(changes)
    return scene


def _write_scene(tmp_path: Path, data: dict) -> Path:
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _cli_error(tmp_path, capsys, scene_path) -> str:
    """Run the scene through the CLI; it must fail with exactly one line and leave no output."""
    out = tmp_path / "out.nc"
    assert main(["run", str(scene_path), "--out", str(out), "--quiet"]) == 1
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("msslib: error: "), captured.err
    assert captured.out == ""
    assert not out.exists()
    return lines[0]


def _by_position(points, values):
    order = np.lexsort(points.T[::-1])
    return points[order], values[order]


# --------------------------------------------------------------------------------------------
# coincident nodes
# --------------------------------------------------------------------------------------------


def test_coincident_nodes_merged_keep_lowest_index_and_material():
    two = _two_cubes()
    rep = M.coincident_nodes(two.points)
    expected = np.arange(16)
    expected[[8, 10, 12, 14]] = [1, 3, 5, 7]
    np.testing.assert_array_equal(rep, expected)
    with pytest.warns(MsslibWarning, match=r"mesh: merged 4 coincident node\(s\).*node 8 = node 1 at \(0\.1, 0, 0\)"):
        merged = M.resolve_coincident_nodes(two)
    assert merged.n_nodes == 12 and merged.n_cells == 2
    np.testing.assert_array_equal(merged.material, [0, 1])
    np.testing.assert_array_equal(merged.cells[0], two.cells[0])  # the first cube keeps its nodes
    np.testing.assert_array_equal(merged.cells[1, [0, 3, 4, 7]], [1, 3, 5, 7])  # its shared face
    single = M.hex_grid(0.2, 0.1, 0.1, 2, 1, 1)
    np.testing.assert_allclose(_by_position(merged.points, merged.points)[0],
                               _by_position(single.points, single.points)[0])
    assert M.connected_parts(merged)[0] == 1 and M.connected_parts(two)[0] == 2
    with pytest.raises(ValueError, match=r"4 coincident node\(s\).*node 8 = node 1.*allowed: distinct nodes"):
        M.resolve_coincident_nodes(two, "error")
    assert M.resolve_coincident_nodes(two, "keep") is two
    apart = _two_cubes(gap=1e-3)  # 1 mm apart is not coincident
    assert M.resolve_coincident_nodes(apart, "error") is apart


def test_merge_refuses_a_cell_it_would_collapse():
    t = M.tet_grid(1.0, 1.0, 1.0, 1, 1, 1)
    points = np.vstack([t.points, t.points[t.cells[2, 0]]])  # node 8 on corner 0 of cell 2
    cells = t.cells.copy()
    cells[2, 3] = 8
    bad = M.Mesh(points, cells, "tetra")
    for policy in ("merge", "error"):
        with pytest.raises(ValueError, match=r"tetra cell 2 has two coincident corners"):
            M.resolve_coincident_nodes(bad, policy)


def test_read_merges_coincident_nodes_naming_the_file(tmp_path):
    path = M.write_vtu(tmp_path / "two.vtu", _two_cubes())
    with pytest.warns(MsslibWarning, match=r"two\.vtu: merged 4 coincident node\(s\)"):
        merged = M.read(path)
    assert merged.n_nodes == 12 and list(merged.material) == [0, 1]
    with pytest.raises(ValueError, match=r"two\.vtu: 4 coincident node\(s\).*node 8 = node 1 at \(0\.1, 0, 0\)"):
        M.read(path, coincident_nodes="error")
    assert M.read(path, coincident_nodes="keep").n_nodes == 16
    with pytest.raises(ValueError, match="coincident_nodes must be one of"):
        M.read(path, coincident_nodes="ignore")


def test_two_cube_file_solves_like_one_mesh_or_is_refused(tmp_path, capsys):
    M.write_vtu(tmp_path / "two.vtu", _two_cubes())
    with pytest.warns(MsslibWarning, match="merged 4 coincident node"):
        ds = run_scene(load_scene(_beam_scene({"file": "two.vtu"}), base_dir=tmp_path), progress=False)
    ref = run_scene(_beam_scene({"generator": "hex_grid", "args": {"lx": 0.2, "ly": 0.1, "lz": 0.1, "nx": 2,
                                                                   "ny": 1, "nz": 1}},
                                materials=[MAT]), progress=False)
    x, u = _by_position(ds["rest_position"].values, ds["displacement"].values)
    xr, ur = _by_position(ref["rest_position"].values, ref["displacement"].values)
    np.testing.assert_allclose(x, xr)
    assert np.abs(ur).max() > 1e-4  # the load does something
    np.testing.assert_allclose(u, ur, rtol=0, atol=1e-10 * np.abs(ur).max())

    refused = _beam_scene({"file": "two.vtu"}, checks={"coincident_nodes": "error"})
    with pytest.raises(ValueError, match=r"scene\.geometry\.file: .*two\.vtu: 4 coincident node\(s\).*node 8 = node 1"):
        prepare(load_scene(refused, base_dir=tmp_path))
    line = _cli_error(tmp_path, capsys, _write_scene(tmp_path, refused))
    assert "two.vtu" in line and "coincident" in line and "coincident_nodes: merge" in line


def test_unmerged_twins_would_leave_the_second_cube_floating():
    kept = _two_cubes()
    fixed = np.zeros((16, 3), dtype=bool)
    fixed[np.isclose(kept.points[:, 0], 0.0)] = True
    (loose,) = M.loose_parts(kept, fixed)
    assert loose.floating and (loose.part, loose.n_parts, loose.n_cells, loose.node) == (1, 2, 1, 8)
    with pytest.warns(MsslibWarning):
        merged = M.resolve_coincident_nodes(kept, "merge")
    assert M.loose_parts(merged, np.isclose(merged.points[:, [0, 0, 0]], 0.0)) == []


# --------------------------------------------------------------------------------------------
# floating parts and free rigid-body modes
# --------------------------------------------------------------------------------------------


def test_floating_part_is_refused_before_a_static_solve(tmp_path, capsys):
    M.write_vtu(tmp_path / "apart.vtu", _two_cubes(gap=0.05))
    scene = _beam_scene({"file": "apart.vtu"}, loads=[])
    with pytest.raises(ValueError, match=r"scene\.boundary: part 2 of 2 \(1 hexahedron cells, node 8 at "
                                         r"\(0\.15, 0, 0\)\) is floating.*fix at least 6 dofs.*dynamic solver"):
        prepare(load_scene(scene, base_dir=tmp_path))
    assert "is floating" in _cli_error(tmp_path, capsys, _write_scene(tmp_path, scene))
    # a dynamic run may let it fly
    dynamic = dict(scene, solver={"type": "dynamic", "dt": 1e-4, "t_end": 1e-3})
    assert prepare(load_scene(dynamic, base_dir=tmp_path)).mesh.n_cells == 2
    # holding the second cube too is enough
    held = dict(scene, boundary=scene["boundary"] + [{"select": {"plane": ["x", 0.25]}, "fix": "all"}])
    assert prepare(load_scene(held, base_dir=tmp_path)).fixed.sum() == 24


def test_nothing_fixed_at_all_is_floating():
    with pytest.raises(ValueError, match=r"scene\.boundary: the mesh \(8 hexahedron cells, node 0 at \(0, 0, 0\)\) "
                                         r"is floating"):
        prepare(load_scene(_cube_scene([])))


def test_single_free_rotation_is_named():
    axis = {"select": {"box": [[0.0, 0.0, None], [0.0, 0.0, None]]}, "fix": "all"}  # the line x = y = 0
    with pytest.raises(ValueError, match=r"scene\.boundary: the mesh .* has 1 free rigid-body mode\(s\): "
                                         r"rotation about the z axis;.*or use a dynamic solver"):
        prepare(load_scene(_cube_scene([axis])))
    line = {"select": {"box": [[0.1, None, 0.05], [0.1, None, 0.05]]}, "fix": "all"}  # x = 0.1, z = 0.05
    with pytest.raises(ValueError, match=r"1 free rigid-body mode\(s\): rotation about the line x = 0\.1, z = 0\.05 "
                                         r"\(parallel to y\)"):
        prepare(load_scene(_cube_scene([line])))


def test_free_translation_and_2d_rotation_are_named():
    sym = [{"select": {"plane": ["z", 0.0]}, "fix": ["z"]}, {"select": {"plane": ["x", 0.0]}, "fix": ["x"]}]
    with pytest.raises(ValueError, match=r"1 free rigid-body mode\(s\): translation along y;"):
        prepare(load_scene(_cube_scene(sym)))
    membrane = {
        "geometry": {"generator": "quad_grid", "args": {"lx": 0.2, "ly": 0.1, "nx": 2, "ny": 1}},
        "materials": [MAT], "thickness": 0.01, "model": "fem_linear",
        "boundary": [{"select": {"box": [[0.1, 0.1], [0.1, 0.1]]}, "fix": "all"}],
    }
    with pytest.raises(ValueError, match=r"1 free rigid-body mode\(s\): rotation about the point \(0\.1, 0\.1\)"):
        prepare(load_scene(membrane))
    membrane["boundary"] = [{"select": {"plane": ["y", 0.0]}, "fix": ["y"]}]
    with pytest.raises(ValueError, match=r"1 free rigid-body mode\(s\): translation along x;"):
        prepare(load_scene(membrane))


def test_symmetry_plane_supports_are_accepted():
    sym = [{"select": {"plane": ["z", 0.0]}, "fix": ["z"]}, {"select": {"plane": ["x", 0.0]}, "fix": ["x"]},
           {"select": {"plane": ["y", 0.0]}, "fix": ["y"]}]
    setup = prepare(load_scene(_cube_scene(sym)))
    assert M.loose_parts(setup.mesh, setup.fixed) == []
    assert setup.fixed.sum() == 27
    for name in ("golec_compression", "membrane_lloyd_stretch", "membrane_fem_stretch"):
        setup = prepare(load_scene(SCENES / f"{name}.yaml"))
        assert not setup.fixed.all(axis=1).all()  # sliding supports, not a clamp everywhere
        assert M.loose_parts(setup.mesh, setup.fixed) == []


# --------------------------------------------------------------------------------------------
# unused materials
# --------------------------------------------------------------------------------------------


def test_unused_material_is_an_error():
    boundary = [{"select": {"plane": ["z", 0.0]}, "fix": "all"}]
    with pytest.raises(ValueError, match=r"scene\.materials\[1\]: no cell uses material 1 \(cells use materials 0\)"):
        prepare(load_scene(_cube_scene(boundary, materials=[MAT, MAT])))
    everything = [{"box": [None, None], "material": 1}]  # after the regions, no cell keeps material 0
    with pytest.raises(ValueError, match=r"scene\.materials\[0\]: no cell uses material 0 \(cells use materials 1\)"):
        prepare(load_scene(_cube_scene(boundary, materials=[MAT, MAT], regions=everything)))
    half = [{"box": [[0.05, None, None], None], "material": 1}]
    setup = prepare(load_scene(_cube_scene(boundary, materials=[MAT, MAT], regions=half)))
    assert sorted(set(setup.mesh.material)) == [0, 1]


# --------------------------------------------------------------------------------------------
# bad mesh files
# --------------------------------------------------------------------------------------------

TET_POINTS = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def _make(kind: str, directory: Path) -> Path:
    if kind == "empty":
        path = directory / "empty.vtu"
        path.write_bytes(b"")
    elif kind == "garbage":  # meshio's vtu reader fails and meshio calls sys.exit
        path = directory / "garbage.vtu"
        path.write_bytes(bytes(range(256)) * 3)
    elif kind == "not_utf8":
        path = directory / "latin1.obj"
        path.write_bytes("o caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".encode("latin-1"))
    elif kind == "unknown_suffix":
        path = directory / "part.xyz"
        path.write_text("0 0 0\n")
    elif kind == "directory":
        path = directory / "folder.vtu"
        path.mkdir()
    elif kind == "no_cells":
        path = directory / "points.obj"
        path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
    elif kind == "node_out_of_range":
        path = directory / "outside.vtk"
        meshio.write(path, meshio.Mesh(TET_POINTS, [("tetra", np.array([[0, 1, 2, 7]]))]))
    elif kind == "nan_coordinate":
        path = directory / "nan.vtu"
        points = TET_POINTS.copy()
        points[3, 2] = np.nan
        meshio.write(path, meshio.Mesh(points, [("tetra", np.array([[0, 1, 2, 3]]))]))
    elif kind == "fractional_material":
        path = directory / "half.vtu"
        meshio.write(path, meshio.Mesh(TET_POINTS, [("tetra", np.array([[0, 1, 2, 3]]))],
                                       cell_data={"material": [np.array([0.5])]}))
    else:
        raise AssertionError(kind)
    return path


BAD_FILES = {
    "empty": "the file is empty",
    "garbage": "cannot read mesh",
    "not_utf8": "not UTF-8",
    "unknown_suffix": r"unknown mesh file suffix '\.xyz'; allowed: the suffixes meshio reads.*\.msh.*\.vtu",
    "directory": "is a directory",
    "no_cells": r"the mesh has no cells \(3 points\); allowed: " + ", ".join(M.CELL_TYPES) + " cells",  # the registry's
    "node_out_of_range": r"tetra cell 0 refers to node 7, which does not exist; allowed: nodes 0 to 3",
    "nan_coordinate": r"node 3 has coordinates \(0, 0, nan\)",
    "fractional_material": r"cell data 'material' of cell 0 is 0\.5; allowed: integer",
}


@pytest.mark.parametrize("kind", sorted(BAD_FILES))
def test_bad_mesh_file_read_is_one_line_value_error(kind, tmp_path):
    path = _make(kind, tmp_path)
    with pytest.raises(ValueError, match=BAD_FILES[kind]) as info:
        M.read(path)
    text = str(info.value)
    assert "\n" not in text and text.startswith(str(path))


@pytest.mark.parametrize("kind", sorted(BAD_FILES))
def test_bad_mesh_file_through_the_cli(kind, tmp_path, capsys):
    path = _make(kind, tmp_path)
    scene = _write_scene(tmp_path, _beam_scene({"file": path.name}, materials=[MAT]))
    line = _cli_error(tmp_path, capsys, scene)
    assert "scene.geometry.file" in line and path.name in line


def test_missing_mesh_file():
    with pytest.raises(FileNotFoundError, match="no_such.vtu"):
        M.read("no_such.vtu")


def test_meshio_sys_exit_and_odd_exceptions_never_escape(tmp_path, monkeypatch):
    garbage = _make("garbage", tmp_path)
    with pytest.raises(SystemExit):  # what meshio itself does with this file
        meshio.read(garbage)
    with pytest.raises(ValueError, match=r"garbage\.vtu: cannot read mesh: Couldn't read file"):
        M.read(garbage)
    scene = load_scene(_beam_scene({"file": garbage.name}, materials=[MAT]), base_dir=tmp_path)
    with pytest.raises(ValueError, match=r"scene\.geometry\.file: .*garbage\.vtu: cannot read mesh"):
        run_scene(scene, progress=False)

    good = M.write_vtu(tmp_path / "good.vtu", M.hex_grid(0.2, 0.1, 0.1, 2, 1, 1))
    for exc, shown in ((SystemExit(3), "meshio chatter"), (struct.error("unpack requires a buffer"), "error: unpack"),
                       (KeyError("CellData"), "KeyError: 'CellData'"), (IndexError("index 5"), "IndexError: index 5")):
        def fail(*args, exc=exc, **kwargs):
            meshio._common.error("meshio chatter")  # how meshio speaks (a rich console on stderr)
            raise exc

        monkeypatch.setattr(meshio, "read", fail)
        with pytest.raises(ValueError, match=r"good\.vtu: cannot read mesh: ") as info:
            M.read(good)
        assert shown in str(info.value) and "\n" not in str(info.value)
        with pytest.raises(ValueError, match="cannot read mesh"):
            run_scene(load_scene(_beam_scene({"file": good.name}, materials=[MAT]), base_dir=tmp_path),
                      progress=False)
