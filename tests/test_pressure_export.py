"""Pressure loads through export (every format carries a dead pressure; a follower one is carried
by CSV/JSON and named as not carried elsewhere) and through the command line (run, compare, plan,
export) on a gmsh mesh of a hollow body whose inner wall is a physical surface."""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from msslib import export
from msslib import mesh as M
from msslib.export import text
from msslib.export.simulators import mjcf_text, sofa_text
from msslib.terms import pressure_nodal_forces

from cli_helpers import run_cli

P = 300.0


def _scene(follow, model="lloyd_tetrahedron"):
    return {"name": "block", "geometry": {"generator": "tet_grid", "args": {"lx": 1.0, "ly": 1.0, "lz": 2.0,
                                                                         "nx": 1, "ny": 1, "nz": 2}},
            "materials": [{"E": 1.0e4, "nu": 0.25}], "model": model,
            "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
            "loads": [{"type": "traction", "select": {"plane": ["x", 1.0]}, "traction": [0.0, 0.0, 5.0]},
                      {"type": "pressure", "select": {"plane": ["z", 2.0]}, "pressure": P, "follow": follow}]}


def _expected(exp):
    mesh = exp.setup.mesh
    facets = M.boundary_facets(mesh)
    top = facets[np.all(np.isclose(mesh.points[facets][:, :, 2], 2.0), axis=1)]
    return top, pressure_nodal_forces(mesh.points, top, P)


def test_every_format_carries_a_dead_pressure(tmp_path):
    exp = export.build(_scene(False))
    top, forces = _expected(exp)
    assert forces[:, 2].sum() == pytest.approx(-P * 1.0, rel=1e-12)
    tables = exp.tables()
    # CSV/JSON: the facets, outward (as the mesh's boundary lists them), the pressure, the reading
    facets = np.column_stack([tables["pressure_1"][f"node_{a}"] for a in range(3)])
    assert {tuple(f) for f in facets.tolist()} == {tuple(f) for f in top.tolist()}
    np.testing.assert_array_equal(tables["pressure_1"]["pressure"], P)
    np.testing.assert_array_equal(tables["pressure_1"]["follow"], 0)
    nodes = tables["pressure_1_forces"]["node"]
    np.testing.assert_allclose(tables["pressure_1_forces"]["f_z"], forces[nodes, 2], rtol=1e-15)
    doc = json.loads(text.json_text(exp))
    entry = next(t for t in doc["terms"] if t.get("table") == "pressure_1")
    assert entry["follow"] is False and entry["pressure"] == P and entry["scales_with_load"] is True
    assert entry["energy"] == "-f . x (f: the nodal forces at rest, table pressure_1_forces)"
    # the surface loads table keeps the traction only
    assert np.abs(exp.loads[:, 2]).sum() == pytest.approx(5.0 * 2.0)
    # VTU: point data pressure_1 (N, load factor 1)
    text.write_vtu(tmp_path / "m.vtu", exp)
    np.testing.assert_allclose(meshio.read(tmp_path / "m.vtu").point_data["pressure_1"], forces, rtol=1e-15)
    assert "NOT CARRIED" not in (tmp_path / "m.vtu").read_text(errors="replace")
    # MuJoCo: constant actuators pressure_1_node*_z on the free joints of the loaded nodes
    root = ET.fromstring(mjcf_text(exp))
    got = {g.get("name"): float(g.get("biasprm").split()[0]) for g in root.iter("general")
           if g.get("name").startswith("pressure_1_")}
    want = {f"pressure_1_node{i}_{a}": forces[i, k] for i in range(len(forces)) for k, a in enumerate("xyz")
            if forces[i, k] != 0}
    assert got.keys() == want.keys() and all(got[k] == pytest.approx(want[k], rel=1e-15) for k in want)
    assert "NOT CARRIED" not in mjcf_text(exp)
    # SOFA: a ConstantForceField named pressure_1
    field = next(e for e in ET.fromstring(sofa_text(exp)).iter("ConstantForceField") if e.get("name") == "pressure_1")
    idx = np.array(field.get("indices").split(), dtype=int)
    np.testing.assert_allclose(np.array(field.get("forces").split(), dtype=float).reshape(-1, 3), forces[idx])
    assert set(idx) == set(np.flatnonzero(np.any(forces != 0, axis=1)))


def test_a_follower_pressure_is_in_the_tables_and_named_where_it_cannot_be_carried(tmp_path):
    exp = export.build(_scene(True))
    tables = exp.tables()
    np.testing.assert_array_equal(tables["pressure_1"]["follow"], 1)
    entry = next(t for t in json.loads(text.json_text(exp))["terms"] if t.get("table") == "pressure_1")
    assert entry["follow"] is True and entry["energy"] is None and entry["conservative"] is False
    for fmt in ("vtu", "mjcf", "sofa"):
        notes = export.not_carried(exp, fmt)
        assert any("follower pressure 300 Pa on 2 facets (table pressure_1" in n for n in notes), (fmt, notes)
    assert export.not_carried(exp, "csv") == [] and export.not_carried(exp, "json") == []
    assert "follower pressure 300 Pa" in mjcf_text(exp) and "NOT CARRIED" in mjcf_text(exp)
    assert "follower pressure 300 Pa" in sofa_text(exp)
    # no constant force stands in for it
    assert "pressure_1_node" not in mjcf_text(exp)
    text.write_vtu(tmp_path / "m.vtu", exp)
    assert "pressure_1" not in meshio.read(tmp_path / "m.vtu").point_data
    head = (tmp_path / "m.vtu").read_bytes()[:600].decode(errors="replace")
    assert "NOT CARRIED" in head and "follower pressure 300 Pa" in head


# --------------------------------------------------------------------------------------------
# the command line on a gmsh mesh of a hollow body
# --------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def hollow(tmp_path_factory):
    """A gmsh tetrahedral mesh of a unit cube with a cubic cavity (side 0.5, centred); physical
    volume ``body`` and physical surface ``inner`` (the cavity walls), and the scene files."""
    gmsh = pytest.importorskip("gmsh")
    folder = tmp_path_factory.mktemp("hollow")
    gmsh.initialize(["-v", "0"])
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("hollow")
        outer = gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        cavity = gmsh.model.occ.addBox(0.25, 0.25, 0.25, 0.5, 0.5, 0.5)
        body, _ = gmsh.model.occ.cut([(3, outer)], [(3, cavity)])
        gmsh.model.occ.synchronize()
        walls = [tag for dim, tag in gmsh.model.getBoundary(body, oriented=False)
                 if min(gmsh.model.getBoundingBox(dim, tag)[:3]) > 1e-6
                 and max(gmsh.model.getBoundingBox(dim, tag)[3:]) < 1 - 1e-6]
        assert len(walls) == 6
        gmsh.model.addPhysicalGroup(3, [body[0][1]], name="body")
        gmsh.model.addPhysicalGroup(2, walls, name="inner")
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)
        gmsh.write(str(folder / "hollow.msh"))
    finally:
        gmsh.finalize()
    for model in ("lloyd_tetrahedron", "fem_linear"):
        (folder / f"{model}.yaml").write_text(
            f"name: hollow_{model}\n"
            "geometry: {file: hollow.msh}\n"
            "materials: [{E: 1.0e4, nu: 0.25}]\n"
            f"model: {model}\n"
            "boundary:\n  - {select: {plane: [z, 0.0]}, fix: all}\n"
            "loads:\n  - {type: pressure, select: {group: inner}, pressure: 300.0}\n"
            "solver: {type: static, load_steps: 2}\n", encoding="utf-8")
    return folder


def test_cli_run_compare_export_plan_on_a_gmsh_hollow_body(hollow, capsys, monkeypatch):
    import xarray as xr

    monkeypatch.chdir(hollow)
    mesh = M.read(hollow / "hollow.msh")
    assert set(mesh.facet_groups) == {"inner"}
    for model in ("lloyd_tetrahedron", "fem_linear"):
        code, err = run_cli(capsys, "run", f"{model}.yaml", "--out", f"{model}.nc", "--quiet")
        assert code == 0, err
    walls = np.unique(mesh.facet_groups["inner"])
    for model in ("lloyd_tetrahedron", "fem_linear"):
        with xr.open_dataset(hollow / f"{model}.nc") as ds:
            u = ds.displacement.values
        radial = np.einsum("ij,ij->i", u[walls], mesh.points[walls] - 0.5)
        assert np.all(radial > 0), model  # the cavity opens: every wall node moves away from its centre
    code, err = run_cli(capsys, "compare", "lloyd_tetrahedron.nc", "fem_linear.nc", "--out", "table.md")
    assert code == 0, err
    assert "| max |" in (hollow / "table.md").read_text()
    code, err = run_cli(capsys, "export", "lloyd_tetrahedron.yaml", "--out", "exported/")
    assert code == 0, err
    assert "follower pressure 300 Pa" in err and "mjcf and sofa not written" in err
    facets = np.loadtxt(hollow / "exported" / "hollow_lloyd_tetrahedron_pressure_0.csv", delimiter=",", skiprows=1)
    assert len(facets) == len(mesh.facet_groups["inner"]) and np.all(facets[:, 4] == 300.0)
    from msslib import cli

    code = cli.main(["plan", "lloyd_tetrahedron.yaml", "--max-error", "0.6", "--levels", "1", "--repeats", "1"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    # the MSS models measured against the non-linear FEM reference, which takes the follower pressure
    assert "reference (quadratic elements, neohookean) level 1" in captured.err
    assert "lloyd_tetrahedron level 1:" in captured.err and "choice:" in captured.out + captured.err
