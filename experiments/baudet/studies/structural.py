"""Baudet's three structural experiments read one way, and the references' own errors.

*Same-mesh reading.* If Baudet's reference was FEM on the MSS's own mesh, his published mean errors
(M) are those of the MSS against linear FEM (Q1 hexahedra, 2x2x2 Gauss points) with the same nodes
and the same loads. For the sheared beam (2x2x6, 4x4x12, 8x8x24), the cantilever (4x1x1, 8x2x2,
16x4x4) and the L-block (line load, n = 2, 4, 8) this study runs the MSS (derived factor, element
reading, the reading the paper adopts) and Q1 on its mesh, from the scenes of the experiment files,
and writes M of the MSS against it (per-node error over the largest same-mesh displacement) beside
the published M.

*The references' own errors.* The sheared beam is compared with a Q1 reference; here Q1 at
12x12x36 and 24x24x72 and quadratic elements (Q2, 27 nodes, msslib.planning.reference.solve_setup)
at 6x6x18 are compared with Q2 at 12x12x36, whose dofs hold their nodes, in the experiment's
measure (mean and largest per-node error over the largest Q2 displacement, at the checked mesh's
own nodes). The L-block's line load is singular along the loaded edges, where the exact
displacement is unbounded (logarithmically): there no reference converges (and Q2 with the forces
at its vertices would carry point loads). For it, the element-reading MSS at n = 8 is compared with
Q1 at n = 16, 32 and 48 (all holding the n = 8 nodes), at all its nodes and at those off the six
loaded edges, and each Q1 reference with the one at n = 48 at the same nodes.
"""

import time

import numpy as np
import xarray as xr

from experiments.baudet import baudet_common as C
from experiments.baudet import make_l_block as LB

EXPERIMENTS = ("shear_beam", "cantilever", "l_block")
LEVELS = ("coarse", "middle", "fine")
MESHES = {"shear_beam": ((2, 2, 6), (4, 4, 12), (8, 8, 24)), "cantilever": ((4, 1, 1), (8, 2, 2), (16, 4, 4)),
          "l_block": (2, 4, 8)}
PUBLISHED = {"shear_beam": (13.0, 6.0, 3.0), "cantilever": (16.31, 7.08, 0.68),
             "l_block": tuple(LB.PUBLISHED[n][0] for n in (2, 4, 8))}
CASE = {"shear_beam": "shear", "cantilever": "gravity", "l_block": "lateral"}
# the sheared beam's references checked against Q2, at their own nodes: (experiment, name, order, mesh);
# the last Q2 is the best, whose dofs hold the nodes of every other
CHECKS = (("shear_beam", "Q1_12x12x36", 1, (12, 12, 36)), ("shear_beam", "Q1_24x24x72", 1, (24, 24, 72)),
          ("shear_beam", "Q2_6x6x18", 2, (6, 6, 18)), ("shear_beam", "Q2_12x12x36", 2, (12, 12, 36)),
          )
QUICK_CHECKS = ("Q1_12x12x36", "Q2_6x6x18")
# the L-block's line load: Q1 references whose nodes hold the MSS nodes at n = 8 (its finest level)
L_REFS = (16, 32, 48)
NODES = ("all", "off_edges")
STATS = ("mean", "max")


def tag(mesh):
    return "x".join(str(v) for v in mesh) if isinstance(mesh, tuple) else f"n{mesh}"


def experiment_path(name):
    from pathlib import Path

    return Path(C.__file__).with_name(f"{name}.yaml")


def experiment(name):
    from msslib.experiment import load_experiment

    return load_experiment(experiment_path(name))


def scene(name, model, mesh):
    """The experiment's scene for ``model`` on ``mesh`` (its MSS variant's settings where it has one)."""
    from msslib.experiment import merge, scene_of

    exp = experiment(name)
    if name == "l_block":
        sc = merge(scene_of(exp, CASE[name], exp.reference), {"model": model, "geometry": {"args": {"n": int(mesh)}}})
        sc["loads"] = LB.loads(mesh)
        return sc, exp.base_dir
    variant = f"mss_{tag(mesh)}_element"
    if isinstance(model, dict) and variant in exp.models:
        return scene_of(exp, CASE[name], variant), exp.base_dir
    sc = scene_of(exp, CASE[name], exp.reference)
    return merge(sc, {"model": model, "geometry": {"args": dict(zip(("nx", "ny", "nz"), mesh))}}), exp.base_dir


def run(name, model, mesh):
    from msslib.scene import load_scene, run_scene

    sc, base = scene(name, model, mesh)
    return run_scene(load_scene(sc, base_dir=base), progress=False)


def same_mesh(name, mesh):
    """(M of the element-reading MSS against Q1 on its own mesh, the MSS result)."""
    from msslib.compare import compare_results

    mss = run(name, {"type": "baudet_cube", "correction": "element"}, mesh)
    fem = run(name, "fem_linear", mesh)
    return float(compare_results(mss, fem).error.rel_mean), mss


def eq10_axis(ds):
    """(tip, largest) deviation of a cantilever result's neutral axis (mean deflection of each
    section) from eq. 10 at the same x, over eq. 10's tip deflection (signed at the tip)."""
    import yaml

    raw = yaml.safe_load(experiment_path("cantilever").read_text())
    geo, mat = raw["scene"]["geometry"]["args"], raw["scene"]["materials"][0]
    g = -float(raw["scene"]["loads"][0]["g"][2])
    L, T, H, E = float(geo["lx"]), float(geo["ly"]), float(geo["lz"]), float(mat["E"])
    x, w = C.section_deflection(ds)
    y = float(mat["density"]) * T * H * g / (24 * E * T * H ** 3 / 12) * (6 * L ** 2 * x ** 2 - 4 * L * x ** 3 + x ** 4)
    d = (w - y) / y[-1]
    return float(d[-1]), float(np.abs(d).max())


def loaded_edge_nodes(X):
    """Mask of the L-block nodes ``X`` (n_nodes, 3) on the six vertical edges the line load acts on."""
    on = np.zeros(len(X), bool)
    for x, y, z0, z1 in LB.EDGES:
        on |= np.isclose(X[:, 0], x) & np.isclose(X[:, 1], y) & (X[:, 2] >= z0 - 1e-9) & (X[:, 2] <= z1 + 1e-9)
    return on


def solve(name, order, mesh):
    """(rest positions of the mesh's nodes, their displacements, the FEM result, wall time) of a Q1
    or Q2 solve of the experiment's scene."""
    from msslib.planning.reference import solve_setup
    from msslib.scene import load_scene
    from msslib.scene.prepare import prepare

    t = time.perf_counter()
    sc, base = scene(name, "fem_linear", mesh)
    setup = prepare(load_scene(sc, base_dir=base))
    res = solve_setup(setup, order=order)
    return setup.mesh.points, res.displacement, res, time.perf_counter() - t


def main():
    from msslib.planning.reference import at_points

    args = C.parse(__doc__)
    t0 = time.perf_counter()
    same = np.full((len(EXPERIMENTS), len(LEVELS)), np.nan)
    axis = np.full((len(LEVELS) + 1, 2), np.nan)  # the cantilever's MSS levels and its Q1 reference
    for i, name in enumerate(EXPERIMENTS):
        for j, mesh in enumerate(MESHES[name][:1] if args.quick else MESHES[name]):
            same[i, j], mss = same_mesh(name, mesh)
            if name == "cantilever":
                axis[j] = eq10_axis(mss)
            print(f"{name} {tag(mesh)}: MSS vs same-mesh Q1 M = {100 * same[i, j]:.3f} % "
                  f"(published {PUBLISHED[name][j]} %)", flush=True)
    exp = experiment("cantilever")
    axis[-1] = eq10_axis(run("cantilever", exp.models[exp.reference]["model"], MESHES["cantilever"][-1] if args.quick
                             else tuple(exp.models[exp.reference]["geometry"]["args"][k] for k in ("nx", "ny", "nz"))))
    print("cantilever axis against eq. 10 (tip, largest): " + ", ".join(f"{a:+.4f} / {b:.4f}" for a, b in axis),
          flush=True)
    checks = CHECKS
    # quick: the two coarse meshes only (Q1 12x12x36 against Q2 6x6x18, whose dofs hold its nodes); the rest NaN
    u = {c[1]: solve(c[0], c[2], c[3]) for c in checks if not args.quick or c[1] in QUICK_CHECKS}
    best = {c[0]: c[1] for c in checks if c[2] == 2 and c[1] in u}  # the last Q2 of each experiment
    err = np.full((len(checks), len(STATS)), np.nan)
    wall = np.full(len(checks), np.nan)
    for k, (name, ref, _, _) in enumerate(checks):
        if ref not in u:
            continue
        X, uc, _, wall[k] = u[ref]
        ub = at_points(u[best[name]][2], X)
        d = np.linalg.norm(uc - ub, axis=1) / np.linalg.norm(u[best[name]][2].dof_displacement, axis=1).max()
        err[k] = d.mean(), d.max()
        print(f"{name} {ref}: against {best[name]}: M {100 * err[k, 0]:.3f} %, MAX {100 * err[k, 1]:.3f} % "
              f"({wall[k]:.1f} s)", flush=True)
    l_refs = L_REFS[:2] if args.quick else L_REFS  # quick: the finest is n = 32
    mss8 = run("l_block", {"type": "baudet_cube", "correction": "element"}, 8)
    X8 = mss8["rest_position"].transpose("node", "axis").values
    u8 = mss8["displacement"].transpose("node", "axis").values
    on_edge = loaded_edge_nodes(X8)
    lref = {}
    for n in l_refs:
        X, _, res, tw = solve("l_block", 1, n)
        lref[n] = (at_points(res, X8), np.linalg.norm(res.displacement, axis=1).max(), tw)
        print(f"l_block Q1 n{n}: {tw:.1f} s", flush=True)
    l_mss = np.full((len(L_REFS), len(NODES)), np.nan)
    l_ref = np.full((len(L_REFS), len(NODES)), np.nan)
    ub, ubmax = lref[l_refs[-1]][:2]
    for k, n in enumerate(l_refs):
        ur, urmax = lref[n][:2]
        for m, sel in enumerate((np.ones(len(X8), bool), ~on_edge)):
            l_mss[k, m] = (np.linalg.norm(u8 - ur, axis=1) / urmax)[sel].mean()
            l_ref[k, m] = (np.linalg.norm(ur - ub, axis=1) / ubmax)[sel].mean()
        print(f"l_block: MSS n=8 against Q1 n{n}: M {100 * l_mss[k, 0]:.3f} % (off the loaded edges "
              f"{100 * l_mss[k, 1]:.3f} %); Q1 n{n} against n{l_refs[-1]}: {100 * l_ref[k, 0]:.3f} % "
              f"({100 * l_ref[k, 1]:.3f} %)", flush=True)
    ds = xr.Dataset(coords={"experiment": list(EXPERIMENTS), "level": list(LEVELS), "check": [c[1] for c in checks],
                            "stat": list(STATS), "l_reference": [f"Q1_n{n}" for n in L_REFS], "nodes": list(NODES)})
    ds["nodes"].attrs = {"long_name": "all: every node of the n = 8 MSS; off_edges: those not on a loaded edge"}
    ds["l_block_mss_error"] = (("l_reference", "nodes"), l_mss, {"units": "1", "long_name": "L-block, line load: "
                               "mean per-node error of the element-reading MSS at n = 8 against the Q1 reference / "
                               "the reference's largest displacement"})
    ds["l_block_reference_error"] = (("l_reference", "nodes"), l_ref, {"units": "1", "long_name": "L-block, line "
                                     "load: mean per-node difference of the Q1 reference from Q1 at the finest n, at "
                                     "the n = 8 nodes / the finest one's largest displacement"})
    ds["l_block_reference_wall_time"] = ("l_reference", [lref[n][2] if n in lref else np.nan for n in L_REFS],
                                         {"units": "s", "long_name": "wall time of the Q1 solve"})
    ds["level"].attrs = {"long_name": "the paper's three resolutions, coarse to fine"}
    ds["mesh"] = (("experiment", "level"), [[tag(m) for m in MESHES[e]] for e in EXPERIMENTS])
    ds["same_mesh_error"] = (("experiment", "level"), same, {"units": "1", "long_name": "M of the element-reading "
                             "MSS against Q1 on its own mesh (per-node error / largest same-mesh displacement)"})
    ds["published_mean"] = (("experiment", "level"), np.array([PUBLISHED[e] for e in EXPERIMENTS]) / 100,
                            {"units": "1", "long_name": "Baudet's published M"})
    ds["same_mesh_ratio"] = ds["same_mesh_error"] / ds["published_mean"]
    ds["same_mesh_ratio"].attrs = {"units": "1", "long_name": "same-mesh M / published M"}
    ds["check_experiment"] = ("check", [c[0] for c in checks])
    ds["axis_model"] = ("axis_model", [f"mss_{tag(m)}_element" for m in MESHES["cantilever"]] + ["fem_reference"])
    ds["eq10_axis_deviation"] = (("axis_model", "measure"), axis, {"units": "1", "long_name": "cantilever: "
                                 "neutral axis (mean deflection of each section) minus eq. 10, over eq. 10's tip "
                                 "deflection: signed at the tip, largest magnitude along the beam"})
    ds["measure"] = ("measure", ["tip", "largest"])
    ds["reference_error"] = (("check", "stat"), err, {"units": "1", "long_name": "per-node error against the "
                             "experiment's finest Q2 solution / its largest displacement, at the checked mesh's nodes"})
    ds["reference_wall_time"] = ("check", wall, {"units": "s", "long_name": "wall time of the solve"})
    ds.attrs.update(title="Baudet structural experiments: same-mesh reading and the references' own errors",
                    quick=int(args.quick))
    C.write(ds, args.out, t0)
    print(f"wrote {args.out} in {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
