"""Mesh groups: gmsh physical groups, cell sets and node sets kept by msslib.mesh.read, carried
through node renumbering, and used by scenes (materials keyed by group, select: {group: ...})."""

from __future__ import annotations

import re
import warnings
from dataclasses import replace
from pathlib import Path

import meshio
import numpy as np
import pytest
import yaml

from msslib import mesh as M
from msslib.cli import main
from msslib.errors import MsslibWarning
from msslib.results import mesh_from_result, read_result
from msslib.scene import load_scene, prepare, run_scene

gmsh = pytest.importorskip("gmsh")

SOFT = {"E": 1.0e6, "nu": 0.3}
STIFF = {"E": 5.0e6, "nu": 0.25}
TRACTION = [0.0, 1.0e3, -1.0e4]
INTERFACE_TAG = 7  # an unnamed physical surface: known by its number


def _gmsh_start(name):
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    for option, value in (("General.Terminal", 0), ("General.NumThreads", 1), ("Mesh.RandomSeed", 0)):
        gmsh.option.setNumber(option, value)
    gmsh.model.add(name)


def _surfaces_at(dim, axis, value):
    """Tags of the entities of dimension ``dim`` whose centre of mass has coordinate ``value``."""
    return [t for _, t in gmsh.model.getEntities(dim)
            if abs(gmsh.model.occ.getCenterOfMass(dim, t)[axis] - value) < 1e-9]


def _two_boxes(path: Path, version: float = 4.1) -> Path:
    """Unit cube of two conforming halves: "soft" z < 0.5 and "stiff" z > 0.5 (physical volumes),
    "block" both; physical surfaces "base" (z = 0), "top" (z = 1) and the interface z = 0.5 as the
    unnamed physical group 7."""
    _gmsh_start("two_boxes")
    try:
        occ = gmsh.model.occ
        soft = occ.addBox(0, 0, 0, 1, 1, 0.5)
        stiff = occ.addBox(0, 0, 0.5, 1, 1, 0.5)
        occ.fragment([(3, soft)], [(3, stiff)])
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [soft], name="soft")
        gmsh.model.addPhysicalGroup(3, [stiff], name="stiff")
        gmsh.model.addPhysicalGroup(3, [soft, stiff], name="block")
        gmsh.model.addPhysicalGroup(2, _surfaces_at(2, 2, 0.0), name="base")
        gmsh.model.addPhysicalGroup(2, _surfaces_at(2, 2, 1.0), name="top")
        gmsh.model.addPhysicalGroup(2, _surfaces_at(2, 2, 0.5), tag=INTERFACE_TAG)
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
        gmsh.option.setNumber("Mesh.MshFileVersion", version)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


def _plate_with_inclusion(path: Path) -> Path:
    """2D plate [0, 2] x [0, 1] with a disc inclusion (centre (1, 0.5), radius 0.25): physical
    surfaces "matrix" and "inclusion", physical curves "left" (x = 0) and "right" (x = 2), the
    physical point "origin" (0, 0)."""
    _gmsh_start("plate")
    try:
        occ = gmsh.model.occ
        plate = occ.addRectangle(0, 0, 0, 2, 1)
        disc = occ.addDisk(1, 0.5, 0, 0.25, 0.25)
        out, _ = occ.fragment([(2, plate)], [(2, disc)])
        occ.synchronize()
        surfaces = [t for d, t in out if d == 2]
        inclusion = [t for t in surfaces if abs(occ.getMass(2, t) - np.pi * 0.25**2) < 1e-6]
        gmsh.model.addPhysicalGroup(2, [t for t in surfaces if t not in inclusion], name="matrix")
        gmsh.model.addPhysicalGroup(2, inclusion, name="inclusion")
        gmsh.model.addPhysicalGroup(1, _surfaces_at(1, 0, 0.0), name="left")
        gmsh.model.addPhysicalGroup(1, _surfaces_at(1, 0, 2.0), name="right")
        origin = [t for _, t in gmsh.model.getEntities(0) if np.allclose(gmsh.model.getValue(0, t, []), 0.0)]
        gmsh.model.addPhysicalGroup(0, origin, name="origin")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.2)
        gmsh.model.mesh.generate(2)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    return path


@pytest.fixture(scope="module")
def meshes(tmp_path_factory):
    """The two-box mesh as .msh (v4) and .vtu (meshio's conversion, physical tags as cell data)."""
    d = tmp_path_factory.mktemp("groups")
    msh = _two_boxes(d / "two.msh")
    m = meshio.read(msh)
    tags = {name: int(value[0]) for name, value in m.field_data.items()}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        physical = {"gmsh:physical": m.cell_data["gmsh:physical"]}
        meshio.write(d / "two.vtu", meshio.Mesh(m.points, m.cells, cell_data=physical))
    return {"dir": d, "msh": msh, "vtu": d / "two.vtu", "tags": tags}


def _scene(path: Path, data: dict, name: str = "scene.yaml") -> Path:
    out = path / name
    out.write_text(yaml.safe_dump(data, sort_keys=False))
    return out


def _keyed(mesh_file: str, **overrides) -> dict:
    data = {
        "geometry": {"file": mesh_file},
        "materials": {"soft": SOFT, "stiff": STIFF},
        "model": "fem_linear",
        "boundary": [{"select": {"group": "base"}}],
        "loads": [{"type": "traction", "select": {"group": "top"}, "traction": TRACTION}],
    }
    data.update(overrides)
    return data


def _boxed(mesh_file: str) -> dict:
    """The same scene with the materials by region and the boundaries by plane."""
    return {
        "geometry": {"file": mesh_file},
        "materials": [SOFT, STIFF],
        "regions": [{"box": [[None, None, 0.5], None], "material": 1}],
        "model": "fem_linear",
        "boundary": [{"select": {"plane": ["z", 0.0]}}],
        "loads": [{"type": "traction", "select": {"plane": ["z", 1.0]}, "traction": TRACTION}],
    }


def _validate_error(scene_path: Path, capsys) -> str:
    assert main(["validate", str(scene_path)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("msslib: error: "), err
    return err[0]


def _centroids(mesh):
    return mesh.points[mesh.cells].mean(axis=1)


# --------------------------------------------------------------------------------------------
# reading
# --------------------------------------------------------------------------------------------


def test_read_keeps_gmsh_physical_groups(meshes):
    mesh = M.read(meshes["msh"])
    assert mesh.cell_type == "tetra"
    assert set(mesh.cell_groups) == {"soft", "stiff", "block"}
    assert set(mesh.facet_groups) == {"base", "top", str(INTERFACE_TAG)}
    assert mesh.node_groups == {}
    soft, stiff = mesh.cell_groups["soft"], mesh.cell_groups["stiff"]
    z = _centroids(mesh)[:, 2]
    np.testing.assert_array_equal(soft, np.flatnonzero(z < 0.5))
    np.testing.assert_array_equal(stiff, np.flatnonzero(z > 0.5))
    np.testing.assert_array_equal(mesh.cell_groups["block"], np.arange(mesh.n_cells))
    assert np.all(mesh.material == 0)  # no material cell data: materials come from the scene
    for name, height, faces in (("base", 0.0, 1), ("top", 1.0, 1), (str(INTERFACE_TAG), 0.5, 2)):
        facets = mesh.facet_groups[name]
        np.testing.assert_allclose(mesh.points[facets][..., 2], height, atol=1e-12)
        assert M.facet_areas(mesh, facets).sum() == pytest.approx(1.0, rel=1e-12)
        assert np.all(M.facet_cell_counts(mesh, facets) == faces)  # base and top on the boundary
    assert not mesh.cell_groups["soft"].flags.writeable


def test_vtu_keeps_the_groups_by_number(meshes):
    """VTU holds no sets and no group names: meshio writes the gmsh physical tags as cell data."""
    by_name, by_number = M.read(meshes["msh"]), M.read(meshes["vtu"])
    tags = meshes["tags"]
    np.testing.assert_array_equal(by_number.cells, by_name.cells)
    for name in ("soft", "stiff"):
        np.testing.assert_array_equal(by_number.cell_groups[str(tags[name])], by_name.cell_groups[name])
    for name in ("base", "top"):
        np.testing.assert_array_equal(by_number.facet_groups[str(tags[name])], by_name.facet_groups[name])


def test_abaqus_and_exodus_cell_and_node_sets(meshes, tmp_path):
    mesh = M.read(meshes["msh"])
    base_nodes = np.unique(mesh.facet_groups["base"])
    sets = {"soft": [mesh.cell_groups["soft"]], "stiff": [mesh.cell_groups["stiff"]]}
    out = meshio.Mesh(mesh.points, [("tetra", mesh.cells)], cell_sets=sets, point_sets={"base": base_nodes})
    meshio.write(tmp_path / "two.inp", out)  # Abaqus: ELSET and NSET
    inp = M.read(tmp_path / "two.inp")
    np.testing.assert_array_equal(inp.cell_groups["stiff"], mesh.cell_groups["stiff"])
    np.testing.assert_array_equal(inp.node_groups["base"], base_nodes)
    meshio.write(tmp_path / "two.e", meshio.Mesh(mesh.points, [("tetra", mesh.cells)], point_sets={"base": base_nodes}))
    np.testing.assert_array_equal(M.read(tmp_path / "two.e").node_groups["base"], base_nodes)  # Exodus node set


def test_node_set_on_a_node_no_cell_uses_is_dropped_with_a_warning(meshes, tmp_path):
    mesh = M.read(meshes["msh"])
    points = np.vstack([mesh.points, [[5.0, 5.0, 5.0]]])  # a node no cell uses
    out = meshio.Mesh(points, [("tetra", mesh.cells)],
                      point_sets={"base": np.unique(mesh.facet_groups["base"]), "far": np.array([len(points) - 1])})
    meshio.write(tmp_path / "orphan.inp", out)
    with pytest.warns(MsslibWarning, match=r"node group 'far' dropped: 1 of its node entries .*belong to no tetra"):
        read = M.read(tmp_path / "orphan.inp")
    assert set(read.node_groups) == {"base"}


def test_gmsh2_file_repeating_elements_reads_as_gmsh_4(tmp_path):
    """Format 2 writes an element once per physical group (the volumes in "block" too): each is one
    cell, in all its groups, as in format 4."""
    two = M.read(_two_boxes(tmp_path / "two_v2.msh", version=2.2))
    four = M.read(_two_boxes(tmp_path / "two_v4.msh", version=4.1))
    assert two.n_cells == four.n_cells and set(two.cell_groups) == {"soft", "stiff", "block"}
    np.testing.assert_array_equal(two.cells, four.cells)
    for name in ("soft", "stiff", "block"):
        np.testing.assert_array_equal(two.cell_groups[name], four.cell_groups[name])
    np.testing.assert_array_equal(two.cell_groups["block"], np.arange(two.n_cells))


def test_gmsh_file_with_elements_outside_every_group_is_one_line(tmp_path):
    """meshio cannot align gmsh:physical when some entities are in no physical group (SaveAll)."""
    _gmsh_start("save_all")
    try:
        occ = gmsh.model.occ
        lower, upper = occ.addBox(0, 0, 0, 1, 1, 0.5), occ.addBox(0, 0, 0.5, 1, 1, 0.5)
        occ.fragment([(3, lower)], [(3, upper)])
        occ.synchronize()
        gmsh.model.addPhysicalGroup(3, [upper], name="stiff")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.option.setNumber("Mesh.SaveAll", 1)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(tmp_path / "save_all.msh"))
    finally:
        gmsh.finalize()
    with pytest.raises(ValueError, match=r"save_all\.msh: cannot read mesh: .*gmsh:physical.* save without "
                                         r"Mesh\.SaveAll, or put every entity in a physical group"):
        M.read(tmp_path / "save_all.msh")


def test_2d_plate_with_inclusion(tmp_path):
    mesh = M.read(_plate_with_inclusion(tmp_path / "plate.msh"))
    assert mesh.cell_type == "triangle" and mesh.dim == 2
    assert set(mesh.cell_groups) == {"matrix", "inclusion"} and set(mesh.facet_groups) == {"left", "right"}
    assert set(mesh.node_groups) == {"origin"}  # a physical point: a group of nodes
    np.testing.assert_array_equal(mesh.points[mesh.node_groups["origin"]], [[0.0, 0.0]])
    r = np.linalg.norm(_centroids(mesh) - [1.0, 0.5], axis=1)
    assert r[mesh.cell_groups["inclusion"]].max() < 0.25 < r[mesh.cell_groups["matrix"]].min()
    np.testing.assert_allclose(mesh.points[mesh.facet_groups["right"], 0], 2.0)
    scene = {"geometry": {"file": "plate.msh"}, "thickness": 0.01, "model": "fem_linear",
             "materials": {"matrix": SOFT, "inclusion": STIFF},
             "boundary": [{"select": {"group": "left"}}],
             "loads": [{"type": "traction", "select": {"group": "right"}, "traction": [1.0e4, 0.0]}]}
    setup = prepare(load_scene(_scene(tmp_path, scene)))
    np.testing.assert_array_equal(np.flatnonzero(setup.mesh.material == 1), mesh.cell_groups["inclusion"])
    assert setup.surface_forces[:, 0].sum() == pytest.approx(1.0e4 * 1.0 * 0.01, rel=1e-12)
    assert np.all(setup.fixed[np.unique(mesh.facet_groups["left"])])
    assert setup.fixed.sum() == 2 * len(np.unique(mesh.facet_groups["left"]))


# --------------------------------------------------------------------------------------------
# renumbering carries the groups
# --------------------------------------------------------------------------------------------


def _facet_points(mesh, name):
    return mesh.points[mesh.facet_groups[name]]


def test_merging_coincident_nodes_carries_the_groups(meshes, tmp_path):
    """The stiff half gets its own copies of the interface nodes, numbered first: merging drops
    the original nodes and shifts every number; groups must still name the same places."""
    mesh = M.read(meshes["msh"])
    iface = np.unique(mesh.facet_groups[str(INTERFACE_TAG)])
    k = len(iface)
    shift = np.arange(mesh.n_nodes) + k
    copy_of = np.full(mesh.n_nodes, -1)
    copy_of[iface] = np.arange(k)
    cells = shift[mesh.cells]
    stiff = mesh.cell_groups["stiff"]
    on_iface = copy_of[mesh.cells[stiff]] >= 0
    cells[stiff] = np.where(on_iface, copy_of[mesh.cells[stiff]], cells[stiff])
    facets = {name: shift[f] for name, f in mesh.facet_groups.items()}
    facets["iface_stiff"] = copy_of[mesh.facet_groups[str(INTERFACE_TAG)]]
    split = M.Mesh(np.vstack([mesh.points[iface], mesh.points]), cells, "tetra", cell_groups=mesh.cell_groups,
                   facet_groups=facets, node_groups={"iface_copies": np.arange(k), "top_nodes": shift[
                       np.unique(mesh.facet_groups["top"])]})
    assert M.connected_parts(split)[0] == 2
    with pytest.warns(MsslibWarning, match=rf"merged {k} coincident node"):
        merged = M.resolve_coincident_nodes(split)
    assert merged.n_nodes == mesh.n_nodes and M.connected_parts(merged)[0] == 1
    for name in mesh.facet_groups:
        np.testing.assert_array_equal(_facet_points(merged, name), _facet_points(mesh, name))
    np.testing.assert_array_equal(_facet_points(merged, "iface_stiff"), _facet_points(mesh, str(INTERFACE_TAG)))
    for name, expected in (("iface_copies", iface), ("top_nodes", np.unique(mesh.facet_groups["top"]))):
        got = merged.points[merged.node_groups[name]]
        want = mesh.points[expected]
        np.testing.assert_array_equal(got[np.lexsort(got.T)], want[np.lexsort(want.T)])
    for name, cells_of in mesh.cell_groups.items():
        np.testing.assert_array_equal(merged.cell_groups[name], cells_of)
        np.testing.assert_array_equal(merged.points[merged.cells[cells_of]], mesh.points[mesh.cells[cells_of]])

    # the same split mesh from a file: read merges the nodes and keeps the sets
    sets = meshio.Mesh(split.points, [("tetra", split.cells)], cell_sets={"stiff": [stiff]},
                       point_sets={"iface_copies": np.arange(k)})
    meshio.write(tmp_path / "split.inp", sets)
    with pytest.warns(MsslibWarning, match="merged"):
        read = M.read(tmp_path / "split.inp")
    np.testing.assert_array_equal(read.cell_groups["stiff"], stiff)
    np.testing.assert_array_equal(read.node_groups["iface_copies"], merged.node_groups["iface_copies"])


def test_orient_carries_the_groups(meshes):
    mesh = M.read(meshes["msh"])
    flipped = mesh.cells.copy()
    flipped[::3] = flipped[::3][:, [0, 2, 1, 3]]
    oriented = M.orient(replace(mesh, cells=flipped))
    assert np.all(M.cell_measures(oriented) > 0)
    for kind in ("cell_groups", "facet_groups", "node_groups"):
        assert getattr(oriented, kind).keys() == getattr(mesh, kind).keys()
        for name, members in getattr(mesh, kind).items():
            np.testing.assert_array_equal(getattr(oriented, kind)[name], members)


def test_mesh_rejects_bad_groups():
    grid = M.hex_grid(1, 1, 1, 1, 1, 1)
    with pytest.raises(ValueError, match=r"cell_groups\['a'\] refers to cell 1, which does not exist"):
        M.Mesh(grid.points, grid.cells, "hexahedron", cell_groups={"a": [0, 1]})
    with pytest.raises(ValueError, match=r"facet_groups\['f'\]: expected shape \(k, 4\)"):
        M.Mesh(grid.points, grid.cells, "hexahedron", facet_groups={"f": [[0, 1, 2]]})
    with pytest.raises(ValueError, match=r"node_groups\['n'\] is empty"):
        M.Mesh(grid.points, grid.cells, "hexahedron", node_groups={"n": []})


# --------------------------------------------------------------------------------------------
# scenes
# --------------------------------------------------------------------------------------------


def test_materials_keyed_by_group_solve_like_regions(meshes, tmp_path, capsys):
    keyed = _scene(tmp_path, _keyed(str(meshes["msh"])), "keyed.yaml")
    boxed = _scene(tmp_path, _boxed(str(meshes["msh"])), "boxed.yaml")
    assert main(["validate", str(keyed)]) == 0
    assert "keyed.yaml: ok" in capsys.readouterr().out
    assert main(["run", str(keyed), "--out", str(tmp_path / "keyed.nc"), "--quiet"]) == 0
    ds = read_result(tmp_path / "keyed.nc")
    ref = run_scene(boxed, progress=False)
    groups = M.read(meshes["msh"]).cell_groups
    material = mesh_from_result(ds).material
    np.testing.assert_array_equal(np.flatnonzero(material == 1), groups["stiff"])
    np.testing.assert_array_equal(np.flatnonzero(material == 0), groups["soft"])
    np.testing.assert_array_equal(mesh_from_result(ref).material, material)
    assert list(ds["material_name"].values) == ["soft", "stiff"]
    u, u_ref = ds["displacement"].values, ref["displacement"].values
    assert np.abs(u).max() > 1e-3  # a real deformation
    np.testing.assert_allclose(u, u_ref, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(ds["fixed"].values, ref["fixed"].values)


def test_unnamed_groups_by_number_from_vtu(meshes, tmp_path):
    tags = meshes["tags"]
    data = _keyed(str(meshes["vtu"]), materials={tags["soft"]: SOFT, str(tags["stiff"]): STIFF},
                  boundary=[{"select": {"group": tags["base"]}}],
                  loads=[{"type": "traction", "select": {"group": tags["top"]}, "traction": TRACTION}])
    by_number = run_scene(load_scene(_scene(tmp_path, data)), progress=False)
    by_name = run_scene(load_scene(_scene(tmp_path, _keyed(str(meshes["msh"])), "named.yaml")), progress=False)
    np.testing.assert_allclose(by_number["displacement"].values, by_name["displacement"].values, rtol=0, atol=1e-10)


def test_group_with_plane_or_box_is_the_intersection(meshes, tmp_path):
    mesh = M.read(meshes["msh"])
    half = {"group": "top", "box": [[None, None, None], [0.5, None, None]]}
    data = _keyed(str(meshes["msh"]), boundary=[{"select": {"group": "base"}}, {"select": half, "fix": ["y"]}],
                  loads=[{"type": "traction", "select": half, "traction": [0.0, 0.0, -1.0e4]}])
    setup = prepare(load_scene(_scene(tmp_path, data)))
    top = mesh.facet_groups["top"]
    inside = (mesh.points[top][..., 0] <= 0.5 + 1e-8).all(axis=1)
    assert 0 < inside.sum() < len(top)
    assert setup.surface_forces[:, 2].sum() == pytest.approx(-1.0e4 * M.facet_areas(mesh, top[inside]).sum(), rel=1e-12)
    top_nodes = np.unique(top)
    expected = top_nodes[mesh.points[top_nodes, 0] <= 0.5 + 1e-8]
    np.testing.assert_array_equal(np.flatnonzero(setup.fixed[:, 1] & ~setup.fixed[:, 0]), expected)


def test_traction_on_a_cell_group_loads_its_boundary_facets(meshes, tmp_path):
    """select: {group: stiff, plane: [z, 1]} loads the top facets of the stiff cells: the same
    forces as the facet group top."""
    by_cells = _keyed(str(meshes["msh"]), loads=[{"type": "traction", "select": {"group": "stiff", "plane": ["z", 1.0]},
                                                  "traction": TRACTION}])
    a = prepare(load_scene(_scene(tmp_path, by_cells)))
    b = prepare(load_scene(_scene(tmp_path, _keyed(str(meshes["msh"])), "b.yaml")))
    np.testing.assert_allclose(a.surface_forces, b.surface_forces, rtol=0, atol=1e-9)


def test_one_material_on_a_grouped_mesh_is_fine(meshes, tmp_path, capsys):
    data = _keyed(str(meshes["msh"]), materials=[SOFT])
    assert main(["validate", str(_scene(tmp_path, data))]) == 0
    assert "ok" in capsys.readouterr().out


@pytest.mark.parametrize("change, expected", [
    ({"materials": {"soft": SOFT, "stif": STIFF}},
     r"scene\.materials\.stif: the mesh has no cell group 'stif' \(did you mean 'stiff'\?\); its groups: block, soft, "
     r"stiff \(cells\); 7, base, top \(boundary facets\)"),
    ({"materials": {"soft": SOFT}},
     r"scene\.materials: \d+ of \d+ cell\(s\) are in none of the groups soft, e\.g\. cell \d+ at \(.*\) \(in the "
     r"group\(s\) block, stiff\); allowed: every cell in exactly one of them"),
    ({"materials": {"soft": SOFT, "block": STIFF}},
     r"scene\.materials: \d+ of \d+ cell\(s\) are in two or more of the groups soft, block, e\.g\. cell \d+ .* in "
     r"soft, block; allowed: every cell in exactly one"),
    ({"materials": [SOFT, STIFF]},
     r"scene\.materials: 2 materials listed, but the mesh gives every cell material 0 .* has the cell groups "
     r"block \(\d+ cells\), soft \(\d+ cells\), stiff \(\d+ cells\); key the materials by group"),
    ({"boundary": [{"select": {"group": "bottom"}}]},
     r"scene\.boundary\[0\]\.select\.group: the mesh has no group 'bottom'.*; its groups: block, soft, stiff "
     r"\(cells\); 7, base, top \(boundary facets\)"),
    ({"loads": [{"type": "traction", "select": {"group": "tpo"}, "traction": TRACTION}]},
     r"scene\.loads\[0\]\.select\.group: the mesh has no group 'tpo' \(did you mean 'top'\?\)"),
    ({"loads": [{"type": "traction", "select": {"group": INTERFACE_TAG}, "traction": TRACTION}]},
     r"scene\.loads\[0\]\.select\.group: \d+ of the \d+ facets of group '7' are not on the boundary of the mesh: .* "
     r"lies between two cells; allowed: a traction on boundary facets"),
    ({"boundary": [{"select": {"group": "base", "plane": ["z", 1.0]}}]},
     r"scene\.boundary\[0\]\.select: group 'base' \(\d+ nodes\) has no node in plane \[z, 1\]"),
    ({"regions": [{"box": [None, None], "material": "steel"}]},
     r"scene\.regions\[0\]\.material: unknown material 'steel'; expected one of the keys of scene\.materials, "
     r"soft, stiff"),
    ({"boundary": [{"select": {"group": True}}]},
     r"scene\.boundary\[0\]\.select\.group: expected the name of a mesh group"),
])
def test_group_errors_are_one_line_naming_the_group(meshes, tmp_path, capsys, change, expected):
    line = _validate_error(_scene(tmp_path, _keyed(str(meshes["msh"]), **change)), capsys)
    assert re.search(expected, line), line


def test_groups_on_a_generated_mesh_are_refused(tmp_path, capsys):
    data = {"geometry": {"generator": "hex_grid", "args": {"lx": 1, "ly": 1, "lz": 1, "nx": 1, "ny": 1, "nz": 1}},
            "materials": {"soft": SOFT}, "model": "fem_linear"}
    line = _validate_error(_scene(tmp_path, data), capsys)
    assert "scene.materials: keyed by mesh group (soft), but the generated mesh (hex_grid) has no groups" in line
    data.update(materials=[SOFT], boundary=[{"select": {"group": "base"}}])
    line = _validate_error(_scene(tmp_path, data), capsys)
    assert "scene.boundary[0].select.group: the mesh has no group 'base': it has no groups at all" in line


def test_name_of_cells_and_nodes_selects_the_nodes_with_a_warning(meshes, tmp_path):
    """An Abaqus file with an element set and a node set both called "base"."""
    mesh = M.read(meshes["msh"])
    base_nodes = np.unique(mesh.facet_groups["base"])
    sets = {"base": [mesh.cell_groups["soft"]], "stiff": [mesh.cell_groups["stiff"]]}
    meshio.write(tmp_path / "twin.inp", meshio.Mesh(mesh.points, [("tetra", mesh.cells)], cell_sets=sets,
                                                    point_sets={"base": base_nodes}))
    data = _keyed("twin.inp", materials={"base": SOFT, "stiff": STIFF},
                  loads=[{"type": "nodal_force", "select": {"plane": ["z", 1.0]}, "total": [0.0, 0.0, -1.0]}])
    with pytest.warns(MsslibWarning, match=r"select\.group: 'base' names a group of cells and a group of nodes"):
        setup = prepare(load_scene(_scene(tmp_path, data)))
    np.testing.assert_array_equal(np.flatnonzero(setup.fixed.all(axis=1)), base_nodes)
    np.testing.assert_array_equal(np.flatnonzero(setup.mesh.material == 0), mesh.cell_groups["soft"])
