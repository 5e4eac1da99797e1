import os
import re

import netCDF4
import numpy as np
import pytest
import xarray as xr

import msslib
from msslib.results import CONVENTIONS, SCHEMA_VERSION, git_commit, make_dataset, mesh_from_result, read_result, write_result, write_text
from msslib.mesh import Mesh

COMMIT_RE = re.compile(r"^(unknown|[0-9a-f]{40,64}(\+dirty)?)$")


def two_tets():
    points = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]], float)
    cells = np.array([[0, 1, 2, 3], [1, 2, 3, 4]])
    if np.linalg.det(points[cells[1, 1:]] - points[cells[1, 0]]) < 0:
        cells[1, [1, 2]] = cells[1, [2, 1]]
    return Mesh(points=points, cells=cells, cell_type="tetra", material=[0, 1])


def full_dataset():
    mesh = two_tets()
    rng = np.random.default_rng(0)
    n = mesh.n_nodes
    springs = np.array([[0, 1], [1, 2], [2, 3], [3, 4]])
    fixed = np.zeros((n, 3), bool)
    fixed[0] = True
    fixed[1, 2] = True
    history = {
        "time": np.array([0.0, 0.5, 1.0]),
        "step": np.array([0, 10, 20]),
        "displacement": rng.normal(size=(3, n, 3)) * 1e-3,
        "velocity": rng.normal(size=(3, n, 3)),
    }
    ds = make_dataset(
        mesh,
        history["displacement"][-1],
        model="lloyd_tetrahedron",
        E=[1e6, 2e6],
        nu=[0.3, 0.25],
        scene="box:\n  size: [1, 1, 1]\n",
        springs=springs,
        spring_constant=rng.random(4) * 1e3,
        rest_length=rng.random(4),
        reaction=rng.normal(size=(n, 3)),
        fixed=fixed,
        history=history,
        solver_stats={"iterations": 12, "converged": True, "residual": 1.5e-9, "message": None,
                      "residual_history": [1.0, 1e-3, 1e-9], "newton": {"line_search": "armijo", "steps": 3},
                      "flags": ["a", "b"]},
        wall_time=1.25,
        extra_vars={"strain_energy": (("cell",), np.array([0.1, 0.2]), {"units": "J", "long_name": "strain energy"})},
        extra_attrs={"load_case": "compression", "sample_size_m": 0.1},
    )
    return mesh, ds


#: variables that are not quantities (topology, connectivity, indices, flags, labels): no units
NOT_QUANTITIES = {"mesh", "spring_network", "cells", "springs", "cell_shape", "cell_material", "material",
                  "fixed", "axis_name"}


def test_make_dataset_schema():
    mesh, ds = full_dataset()
    for name, var in ds.variables.items():
        assert var.attrs.get("long_name"), name
        assert ("units" in var.attrs) == (name not in NOT_QUANTITIES), name
    assert ds["rest_position"].dims == ("node", "axis")
    assert list(ds["axis_name"].values) == ["x", "y", "z"]
    for i, a in enumerate("xyz"):
        np.testing.assert_array_equal(ds[f"node_{a}"].values, mesh.points[:, i])
    assert ds["cells"].attrs["cell_type"] == "tetra"
    np.testing.assert_array_equal(ds["cell_material"].values, [0, 1])
    np.testing.assert_array_equal(ds["material_E"].values, [1e6, 2e6])
    np.testing.assert_array_equal(ds["material_nu"].values, [0.3, 0.25])
    assert ds["material_E"].attrs["units"] == "Pa" and ds["material_nu"].attrs["units"] == "1"
    assert "material_density" not in ds and "thickness" not in ds  # not given
    assert ds["displacement_history"].dims == ("time", "node", "axis")
    assert ds["step"].dims == ("time",)
    assert ds["springs"].dims == ("spring", "spring_end") and ds.sizes["spring_end"] == 2
    assert ds["spring_constant"].attrs["units"] == "N m-1"
    for key in ("Conventions", "msslib_schema", "title", "source", "history", "model", "scene", "msslib_version",
                "git_commit", "created", "python_version", "numpy_version", "wall_time_s"):
        assert key in ds.attrs, key
    assert "E" not in ds.attrs and "nu" not in ds.attrs  # material constants are variables with units
    assert ds.attrs["Conventions"] == CONVENTIONS == "CF-1.11 UGRID-1.0"
    assert ds.attrs["msslib_schema"] == SCHEMA_VERSION
    assert ds.attrs["msslib_version"] == msslib.__version__
    assert ds.attrs["numpy_version"] == np.__version__
    assert COMMIT_RE.match(ds.attrs["git_commit"])
    assert re.match(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\+00:00$", ds.attrs["created"])
    assert ds.attrs["solver_iterations"] == 12
    assert ds.attrs["solver_converged"] == 1
    assert "solver_message" not in ds.attrs  # None drops the attribute
    assert ds.attrs["solver_newton_line_search"] == "armijo"
    assert ds.attrs["solver_newton_steps"] == 3
    assert ds.attrs["solver_flags"] == '["a", "b"]'
    np.testing.assert_array_equal(ds.attrs["solver_residual_history"], [1.0, 1e-3, 1e-9])


def test_round_trip(tmp_path):
    mesh, ds = full_dataset()
    path = write_result(tmp_path / "run.nc", ds)
    assert path == tmp_path / "run.nc"
    back = read_result(path)
    xr.testing.assert_identical(back, ds)  # data, dims, coords, variable and global attrs
    for name, var in back.variables.items():
        assert var.attrs["long_name"] and (name in NOT_QUANTITIES or var.attrs["units"]), name
    assert back["fixed"].dtype == bool
    assert back["cells"].dtype == np.int64
    np.testing.assert_array_equal(back["material_E"].values, [1e6, 2e6])
    assert back.attrs["scene"] == ds.attrs["scene"]
    assert back.attrs["wall_time_s"] == 1.25
    assert COMMIT_RE.match(back.attrs["git_commit"])
    # the file is closed: it can be replaced while the dataset is still in use
    os.replace(path, tmp_path / "moved.nc")
    assert float(back["displacement"].sum()) == pytest.approx(float(ds["displacement"].sum()))
    # on disk, fixed is int8
    with netCDF4.Dataset(tmp_path / "moved.nc") as nc:
        assert nc["fixed"].dtype == np.int8
        assert nc.getncattr("Conventions") == CONVENTIONS
        assert nc.getncattr("msslib_schema") == SCHEMA_VERSION
    m = mesh_from_result(back)
    np.testing.assert_array_equal(m.points, mesh.points)
    np.testing.assert_array_equal(m.cells, mesh.cells)
    np.testing.assert_array_equal(m.material, mesh.material)
    assert m.cell_type == "tetra"
    md = mesh_from_result(back, deformed=True)
    np.testing.assert_allclose(md.points, mesh.points + ds["displacement"].values)
    # a dataset read back can be written again unchanged
    again = read_result(write_result(tmp_path / "again.nc", back))
    xr.testing.assert_identical(again, ds)


def test_minimal_2d_round_trip_step_history(tmp_path):
    mesh = Mesh(points=[[0, 0], [1, 0], [1, 1], [0, 1]], cells=[[0, 1, 2, 3]], cell_type="quad")
    u = np.array([[0, 0], [0.1, 0], [0.1, -0.02], [0, -0.02]])
    ds = make_dataset(mesh, u, model="fem_linear", E=1e5, nu=0.3,
                      history={"step": [0, 1], "displacement": [u / 2, u]}, fixed=[True, False, False, True])
    assert list(ds["axis_name"].values) == ["x", "y"]
    assert ds["displacement_history"].dims == ("step", "node", "axis")
    assert ds.attrs["scene"] == "" and np.isnan(ds.attrs["wall_time_s"])
    assert ds["fixed"].values.tolist() == [[True, True], [False, False], [False, False], [True, True]]
    back = read_result(write_result(tmp_path / "q.nc", ds))
    xr.testing.assert_identical(back, ds)
    assert back["material_E"].values.tolist() == [1e5] and back.attrs["model"] == "fem_linear"
    assert mesh_from_result(back).cell_type == "quad"


def test_make_dataset_validation():
    mesh = two_tets()
    u = np.zeros((mesh.n_nodes, 3))
    with pytest.raises(ValueError, match="displacement"):
        make_dataset(mesh, u[:, :2], model="m", E=1.0, nu=0.3)
    with pytest.raises(ValueError, match="E"):
        make_dataset(mesh, u, model="m", E=[1.0], nu=0.3)  # two materials
    with pytest.raises(ValueError, match="springs"):
        make_dataset(mesh, u, model="m", E=1.0, nu=0.3, spring_constant=[1.0])
    with pytest.raises(ValueError, match="lacks"):
        make_dataset(mesh, u, model="m", E=1.0, nu=0.3, extra_vars={"a": (("node",), np.zeros(5), {"units": "1"})})
    with pytest.raises(ValueError, match="collides"):
        make_dataset(mesh, u, model="m", E=1.0, nu=0.3, extra_attrs={"git_commit": "x"})
    with pytest.raises(ValueError, match="history"):
        make_dataset(mesh, u, model="m", E=1.0, nu=0.3, history={"displacement": u[None]})
    with pytest.raises(ValueError, match="2D meshes only"):
        make_dataset(mesh, u, model="m", E=1.0, nu=0.3, thickness=0.01)
    with pytest.raises(ValueError, match="material_names"):
        make_dataset(mesh, u, model="m", E=1.0, nu=0.3, material_names=["only one"])
    with pytest.raises(ValueError, match="E has 2 entries but there are 3 materials"):  # 3 densities
        make_dataset(mesh, u, model="m", E=[1.0, 2.0], nu=0.3, density=[1.0, 2.0, 3.0])


def test_refuses_non_finite_displacement(tmp_path):
    mesh, ds = full_dataset()
    for name in ("displacement", "displacement_history"):
        bad = ds.copy(deep=True)
        bad[name].values.flat[3] = np.nan
        with pytest.raises(ValueError, match=name):
            write_result(tmp_path / "bad.nc", bad)
        assert os.listdir(tmp_path) == []


def test_failed_write_leaves_no_file_and_keeps_old(tmp_path, monkeypatch):
    mesh, ds = full_dataset()
    target = tmp_path / "run.nc"
    write_result(target, ds)
    before = target.read_bytes()

    def boom(*args, **kwargs):
        raise RuntimeError("disk full")

    monkeypatch.setattr(xr.Dataset, "to_netcdf", boom)
    with pytest.raises(RuntimeError, match="disk full"):
        write_result(target, ds)
    assert os.listdir(tmp_path) == ["run.nc"]  # temporary file removed
    assert target.read_bytes() == before  # old result untouched


def test_unwritable_or_missing_directory(tmp_path):
    _, ds = full_dataset()
    missing = tmp_path / "nope" / "run.nc"
    with pytest.raises(OSError, match="nope") as info:
        write_result(missing, ds)
    assert info.value.filename == str(missing)
    assert not (tmp_path / "nope").exists()
    not_a_dir = tmp_path / "file"
    not_a_dir.write_text("x")
    with pytest.raises(OSError, match="file"):
        write_result(not_a_dir / "run.nc", ds)
    assert sorted(os.listdir(tmp_path)) == ["file"]


def test_permission_error_names_path(tmp_path, monkeypatch):
    _, ds = full_dataset()
    real_open = os.open

    def denied(path, flags, *args, **kwargs):
        if flags & os.O_CREAT:
            raise PermissionError(13, "Permission denied", str(path))
        return real_open(path, flags, *args, **kwargs)

    monkeypatch.setattr(os, "open", denied)
    target = tmp_path / "run.nc"
    with pytest.raises(PermissionError, match="Permission denied") as info:
        write_result(target, ds)
    assert info.value.filename == str(target)
    monkeypatch.undo()
    assert os.listdir(tmp_path) == []


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root ignores permissions")
def test_read_only_directory(tmp_path):
    _, ds = full_dataset()
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o500)
    try:
        with pytest.raises(PermissionError, match="ro"):
            write_result(ro / "run.nc", ds)
        assert os.listdir(ro) == []
    finally:
        ro.chmod(0o700)


def test_git_commit():
    commit = git_commit()
    assert COMMIT_RE.match(commit)
    assert make_dataset(two_tets(), np.zeros((5, 3)), model="m", E=1.0, nu=0.3).attrs["git_commit"]


def test_git_commit_unknown_outside_a_repository(tmp_path, monkeypatch):
    monkeypatch.setenv("GIT_CEILING_DIRECTORIES", str(tmp_path.parent))
    assert git_commit(tmp_path) == "unknown"
    monkeypatch.setenv("PATH", str(tmp_path))  # no git executable
    assert git_commit() == "unknown"


def test_write_text_replaces_atomically_and_leaves_nothing_on_error(tmp_path):
    out = tmp_path / "table.md"
    out.write_text("old\n")
    assert write_text(out, "| a |\n") == out
    assert out.read_text() == "| a |\n"
    assert sorted(q.name for q in tmp_path.iterdir()) == ["table.md"]

    class Boom:  # not a str: the write fails after the temporary file is opened
        pass

    with pytest.raises(TypeError):
        write_text(out, Boom())
    assert out.read_text() == "| a |\n"  # untouched
    assert sorted(q.name for q in tmp_path.iterdir()) == ["table.md"]
    with pytest.raises(FileNotFoundError):
        write_text(tmp_path / "missing" / "t.md", "x")
    assert sorted(q.name for q in tmp_path.iterdir()) == ["table.md"]
