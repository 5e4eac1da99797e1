"""Lloyd et al., Sec. 5.6 (Fig. 15): the tetrahedral cylinder on a mesh with the paper's 91 nodes.

The experiment ``experiments/lloyd/cylinder.yaml`` meshes the cylinder with gmsh, whose coarsest
mesh has 106 nodes and 289 tetrahedra (the paper's: 91 and 274). This study runs the same three
cases (the file's tractions; Lloyd's eqs. 12-13 against linear FEM on the same mesh) on the 91-node
mesh of ``experiments/lloyd/meshes/cylinder91.msh`` (7 layers of a 12-gon and its centre, 348
tetrahedra: see its script) and, beside it, on the file's mesh: largest and mean node distance, the
ratio mean/max (which does not depend on the load) and the deformation of the top face (linear FEM),
against the published errors.

    python -m experiments.lloyd.studies.cylinder91 --out results/lloyd/studies/cylinder91.nc [--quick]
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from experiments.lloyd.studies.load_sweep import (
    LLOYD,
    arrays,
    deformation,
    load_direction,
)
from msslib.experiment import UNITS, load_experiment, scene_of
from msslib.results import write_result
from msslib.scene import load_scene, run_scene

CASES = ("stretch", "compression", "shear")
MESHES = {"paper_counts": {"file": "meshes/cylinder91.msh"}, "file": None}


def run(exp, case, model, geometry, quick):
    sc = scene_of(exp, case, model, quick)
    if geometry is not None:
        sc["geometry"] = geometry
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return run_scene(load_scene(sc, base_dir=exp.base_dir), progress=False)


def main(argv=None):
    args = script.args(__doc__, argv)
    t0 = time.perf_counter()
    exp = load_experiment(LLOYD / "cylinder.yaml")
    shape = (len(MESHES), len(CASES))
    out = {k: np.full(shape, np.nan) for k in ("error_max", "error_mean", "ratio", "deformation", "n_nodes",
                                               "n_cells", "published_max", "published_mean", "max_over_published")}
    for i, (mesh_name, geometry) in enumerate(MESHES.items()):
        for j, case in enumerate(CASES):
            ref = run(exp, case, "fem", geometry, args.quick)
            mss = run(exp, case, "mss", geometry, args.quick)
            X, u_ref = arrays(ref)
            _, u = arrays(mss)
            d = np.linalg.norm(u - u_ref, axis=1)
            pub = exp.published[case]["mss"]
            out["error_max"][i, j], out["error_mean"][i, j] = d.max(), d.mean()
            out["ratio"][i, j] = d.mean() / d.max()
            out["deformation"][i, j] = deformation(X, u_ref, load_direction(scene_of(exp, case, "mss", args.quick)))
            out["n_nodes"][i, j], out["n_cells"][i, j] = len(X), ref.sizes["cell"]
            out["published_max"][i, j] = pub["max"][0] * UNITS[pub["max"][1]]
            out["published_mean"][i, j] = pub["mean"][0] * UNITS[pub["mean"][1]]
            out["max_over_published"][i, j] = d.max() / out["published_max"][i, j]
            print(f"{mesh_name} ({len(X)} nodes) {case}: max {d.max() * 1e3:.3g} mm, mean {d.mean() * 1e3:.3g} mm, "
                  f"ratio {d.mean() / d.max():.3f}, deformation {out['deformation'][i, j] * 100:.3g} %", flush=True)
    ds = xr.Dataset(coords={"mesh": list(MESHES), "case": list(CASES)})
    meta = {"error_max": ("m", "largest node distance MSS - linear FEM"), "error_mean": ("m", "mean node distance"),
            "ratio": ("1", "mean / max node distance"),
            "deformation": ("1", "mean top-face displacement along the load over the height, linear FEM"),
            "n_nodes": ("1", "nodes"), "n_cells": ("1", "tetrahedra"), "published_max": ("m", "published maximum"),
            "published_mean": ("m", "published mean"), "max_over_published": ("1", "ours / published maximum")}
    for k, v in out.items():
        ds[k] = (("mesh", "case"), v, {"units": meta[k][0], "long_name": meta[k][1]})
    ds["published_ratio"] = ds.published_mean / ds.published_max
    ds["published_ratio"].attrs.update(units="1", long_name="published mean / max")
    ds.attrs.update(study="lloyd_cylinder91", quick=int(args.quick), wall_time_s=time.perf_counter() - t0,
                    description=__doc__.strip().splitlines()[0])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_result(args.out, ds)


if __name__ == "__main__":
    main()
