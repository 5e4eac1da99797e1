"""Baudet Figs. 12-13: does the line load hold the L-block's error up?

The experiment ``l_block`` loads the six vertical edges of the L by a line load (20 N in all), whose
solution is singular along the loaded edges. Here the same block carries, beside it, the same total
force as a uniform traction (+x) on the faces normal to x (x = 0, 2 and 4 m: 32 m^2, 0.625 Pa), whose
solution has no singularity at the load. For each load, the MSS (derived factor, both readings of the
correction) at n = 2, 4, 8 cubes per edge (Baudet's) and 16 is compared with linear FEM
on a fine mesh (Q1, n = 48, as the experiment ``l_block``) and with linear
FEM on the MSS's own mesh (Q1, same nodes, same nodal loads: the lattice's error alone, without the discretisation of the singular field); the same-mesh
FEM is also compared with the fine reference. Errors as in the experiment: per-node |u - u_ref| over
the largest reference displacement (Baudet's M, SD, MAX). The rate of a refinement is the ratio of
the mean errors at n and 2n; the published rates are those of the printed means (6.99 / 3.37 / 0.66).
"""

import time

import numpy as np
import xarray as xr

from experiments.baudet import baudet_common as C
from experiments.baudet import make_l_block as LB

LOADS = ("line", "face")
NS = (2, 4, 8, 16)  # n = 16 has no published counterpart: the refinement continued
REF_N = 48  # the experiment l_block's reference
MODELS = ("mss_boundary", "mss_element", "fem_same_mesh")
STATS = ("mean", "sd", "max")
FACES = (0.0, 2.0, 4.0)  # x of the faces normal to x (boundary facets only: at x = 2 the upper arm's face)
PUBLISHED_MEAN = tuple(LB.PUBLISHED[n][0] / 100 if n in LB.PUBLISHED else np.nan for n in NS)


def face_loads():
    area = LB.S * LB.S + 2 * (LB.S / 2) * LB.S  # x = 0 (S x S), x = S/2 and x = S (S/2 x S each)
    t = LB.F / area
    return [{"type": "traction", "select": {"plane": ["x", x]}, "traction": [t, 0.0, 0.0]} for x in FACES]


def run(model, n, load):
    """One run of the L-block scene of ``l_block.yaml`` with another model, resolution or load."""
    from msslib.experiment import load_experiment, merge, scene_of
    from msslib.scene import load_scene, run_scene

    exp = load_experiment(LB.Path(LB.__file__).with_name("l_block.yaml"))
    sc = scene_of(exp, "lateral", exp.reference)
    over = {"model": model, "geometry": {"args": {"n": int(n)}}}
    sc = merge(sc, over)
    sc["loads"] = LB.loads(n) if load == "line" else face_loads()
    return run_scene(load_scene(sc, base_dir=exp.base_dir), progress=False)


def stats(result, reference):
    from msslib.compare import compare_results

    e = compare_results(result, reference).error
    return [e.rel_mean, e.rel_std, e.rel_max]


def main():
    args = C.parse(__doc__)
    t0 = time.perf_counter()
    ns = NS[:1] if args.quick else NS
    ref_n = 4 if args.quick else REF_N
    err = np.full((len(LOADS), len(MODELS), len(NS), len(STATS)), np.nan)  # against the fine reference
    same = np.full((len(LOADS), 2, len(NS), len(STATS)), np.nan)  # MSS against same-mesh FEM
    umax = np.full(len(LOADS), np.nan)
    wall = np.full((len(LOADS), len(NS)), np.nan)
    for i, load in enumerate(LOADS):
        ref = run("fem_linear", ref_n, load)
        umax[i] = float(np.linalg.norm(ref["displacement"].transpose("node", "axis").values, axis=1).max())
        for j, n in enumerate(ns):
            t1 = time.perf_counter()
            fem = run("fem_linear", n, load)
            err[i, 2, j] = stats(fem, ref)
            for m, reading in enumerate(("boundary", "element")):
                mss = run({"type": "baudet_cube", "correction": reading}, n, load)
                err[i, m, j] = stats(mss, ref)
                same[i, m, j] = stats(mss, fem)
            wall[i, j] = time.perf_counter() - t1
            print(f"{load} n={n}: mean MSS {err[i, 0, j, 0]:.4f} (element {err[i, 1, j, 0]:.4f}), same-mesh FEM "
                  f"{err[i, 2, j, 0]:.4f}; MSS vs same-mesh FEM {same[i, 0, j, 0]:.4f} ({wall[i, j]:.1f} s)", flush=True)
    ds = xr.Dataset(coords={"load": list(LOADS), "model": list(MODELS), "n": list(NS), "stat": list(STATS),
                            "reading": ["boundary", "element"]})
    ds["load"].attrs = {"long_name": "line: uniform line load on the six vertical edges; face: the same total force "
                                     "as a uniform traction on the faces normal to x"}
    ds["error"] = (("load", "model", "n", "stat"), err, {"units": "1", "long_name": "per-node error against linear FEM "
                   f"(Q1, n = {ref_n}) / its largest displacement, at the nodes of the n mesh"})
    ds["error_vs_same_mesh"] = (("load", "reading", "n", "stat"), same, {"units": "1", "long_name": "MSS against "
                                "linear FEM (Q1) on the same mesh, per-node error / largest same-mesh displacement"})
    mean = err[..., 0]
    ds["rate"] = (("load", "model", "n"), np.concatenate([mean[..., :-1] / mean[..., 1:], np.full(mean.shape[:2] + (1,), np.nan)], axis=-1),
                  {"units": "1", "long_name": "mean error at n / mean error at 2n (NaN at the finest n)"})
    pm = np.array(PUBLISHED_MEAN)
    ds["published_mean"] = ("n", pm, {"units": "1", "long_name": "Baudet's published M"})
    ds["published_rate"] = ("n", np.append(pm[:-1] / pm[1:], np.nan), {"units": "1", "long_name": "published M at n / "
                            "at 2n"})
    ds["reference_max_displacement"] = ("load", umax, {"units": "m", "long_name": "largest displacement, fine FEM"})
    ds["wall_time"] = (("load", "n"), wall, {"units": "s", "long_name": "wall time of the runs at n"})
    ds.attrs.update(title="Baudet L-block: line load against face traction", quick=int(args.quick),
                    reference=f"Q1 n = {ref_n}", total_force_N=LB.F)
    C.write(ds, args.out, t0)
    print(f"wrote {args.out} in {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
