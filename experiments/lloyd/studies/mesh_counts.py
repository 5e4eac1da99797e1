"""Lloyd et al., Secs. 5.6-5.7: node and tetrahedron counts of the cylinder with a hole and the cone.

The paper's meshes have 873 nodes and 3 807 tetrahedra (cylinder with a spherical hole, Fig. 16) and
982 nodes and 4 407 tetrahedra (cone, Fig. 17); the experiment files' gmsh meshes have the paper's
node count (or nearly) but fewer tetrahedra. This study meshes both geometries of the experiment
files with gmsh over a range of element sizes h and records the nodes and tetrahedra of each mesh:
whether any h gives both of the paper's counts, the tetrahedra at the paper's node count and the
nodes at its tetrahedron count (linear interpolation in log h between the two nearest meshes), and
the tetrahedra per node.

    python -m experiments.lloyd.studies.mesh_counts --out results/lloyd/studies/mesh_counts.nc [--quick]
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from experiments import script
from msslib.mesh import unstructured
from msslib.results import write_result

LLOYD = Path(__file__).resolve().parents[1]
SHAPES = {"cylinder_hole": ("cylinder_with_hole_mesh", 873, 3807), "cone": ("cone_mesh", 982, 4407)}


def geometry_args(name):
    return yaml.safe_load((LLOYD / f"{name}.yaml").read_text())["scene"]["geometry"]["args"]


def at(x_target, xs, ys):
    """ys at x_target, linear in log h between the meshes (xs increasing with the index) around it."""
    order = np.argsort(xs)
    return float(np.interp(x_target, np.asarray(xs)[order], np.asarray(ys)[order]))


def main(argv=None):
    args = script.args(__doc__, argv)
    t0 = time.perf_counter()
    n_h = 5 if args.quick else 25
    ds = xr.Dataset(coords={"shape": list(SHAPES), "level": np.arange(n_h)})
    keys = ("h", "n_nodes", "n_cells")
    out = {k: np.full((len(SHAPES), n_h), np.nan) for k in keys}
    summary = {k: np.full(len(SHAPES), np.nan) for k in (
        "paper_nodes", "paper_cells", "file_h", "file_nodes", "file_cells", "cells_at_paper_nodes",
        "nodes_at_paper_cells", "cells_per_node_paper", "cells_per_node_file", "both_counts_within_2_percent")}
    for i, (name, (generator, nodes, cells)) in enumerate(SHAPES.items()):
        a = geometry_args(name)
        make = getattr(unstructured, generator)
        hs = a["h"] * np.geomspace(0.8, 1.25, n_h)
        for k, h in enumerate(hs):
            m = make(**dict(a, h=float(h)))
            out["h"][i, k], out["n_nodes"][i, k], out["n_cells"][i, k] = h, m.n_nodes, m.n_cells
        f = make(**a)
        both = np.any((np.abs(out["n_nodes"][i] / nodes - 1) < 0.02) & (np.abs(out["n_cells"][i] / cells - 1) < 0.02))
        summary["paper_nodes"][i], summary["paper_cells"][i] = nodes, cells
        summary["file_h"][i], summary["file_nodes"][i], summary["file_cells"][i] = a["h"], f.n_nodes, f.n_cells
        summary["cells_at_paper_nodes"][i] = at(nodes, out["n_nodes"][i], out["n_cells"][i])
        summary["nodes_at_paper_cells"][i] = at(cells, out["n_cells"][i], out["n_nodes"][i])
        summary["cells_per_node_paper"][i] = cells / nodes
        summary["cells_per_node_file"][i] = f.n_cells / f.n_nodes
        summary["both_counts_within_2_percent"][i] = float(both)
        print(f"{name}: file h = {a['h']:g} m: {f.n_nodes} nodes, {f.n_cells} tetrahedra; at the paper's {nodes} nodes "
              f"{summary['cells_at_paper_nodes'][i]:.0f} tetrahedra (paper {cells}); at its {cells} tetrahedra "
              f"{summary['nodes_at_paper_cells'][i]:.0f} nodes; both within 2 %: {bool(both)}", flush=True)
    units = {"h": "m", "n_nodes": "1", "n_cells": "1"}
    for k, v in out.items():
        ds[k] = (("shape", "level"), v, {"units": units[k], "long_name": {"h": "gmsh element size",
                                                                          "n_nodes": "nodes", "n_cells": "tetrahedra"}[k]})
    for k, v in summary.items():
        ds[k] = ("shape", v, {"units": "m" if k == "file_h" else "1", "long_name": k.replace("_", " ")})
    ds.attrs.update(study="lloyd_mesh_counts", quick=int(args.quick), wall_time_s=time.perf_counter() - t0,
                    description=__doc__.strip().splitlines()[0])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_result(args.out, ds)


if __name__ == "__main__":
    main()
