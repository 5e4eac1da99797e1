"""Node and tetrahedron counts of Lloyd's cylinder with a hole and cone against the paper's
(experiments/lloyd/studies/mesh_counts.py)."""

import numpy as np
import pytest
import xarray as xr

from experiments.lloyd.studies import mesh_counts as MC
from msslib.mesh import unstructured


def test_interpolation_between_meshes_is_linear_and_order_free():
    assert MC.at(15.0, [10.0, 20.0], [100.0, 300.0]) == pytest.approx(200.0)
    assert MC.at(15.0, [20.0, 10.0], [300.0, 100.0]) == pytest.approx(200.0)


def test_paper_counts_and_file_meshes(tmp_path):
    out = tmp_path / "mesh_counts.nc"
    MC.main(["--out", str(out), "--quick"])
    with xr.open_dataset(out) as ds:
        ds = ds.load()
    assert ds.paper_nodes.sel(shape="cylinder_hole") == 873 and ds.paper_cells.sel(shape="cylinder_hole") == 3807
    assert ds.paper_nodes.sel(shape="cone") == 982 and ds.paper_cells.sel(shape="cone") == 4407
    hole = unstructured.cylinder_with_hole_mesh(radius=0.01, height=0.02, hole_radius=0.005, h=0.0021, seed=0)
    assert (ds.file_nodes.sel(shape="cylinder_hole"), ds.file_cells.sel(shape="cylinder_hole")) == (hole.n_nodes, hole.n_cells)
    cone = unstructured.cone_mesh(r_bottom=0.01, r_top=0.005, height=0.02, h=0.00168, seed=0)
    assert (ds.file_nodes.sel(shape="cone"), ds.file_cells.sel(shape="cone")) == (cone.n_nodes, cone.n_cells)
    assert float(ds.cells_per_node_file.sel(shape="cone")) == pytest.approx(cone.n_cells / cone.n_nodes)
    # coarser meshes (larger h) have fewer nodes
    n = ds.n_nodes.sel(shape="cone").values
    assert n[0] > n[-1] and np.all(np.diff(ds.h.sel(shape="cone").values) > 0)
