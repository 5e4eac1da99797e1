"""Baudet Fig. 11 (and the mass readings of Fig. 10): the cantilever under growing weight.

The paper gives no load for Fig. 11 ("results ... totally wrong for small deformation conditions with
finite element", linear FEM out of its domain; the MSS "within an acceptable range"), so the weight
is swept: densities from the printed 0.0125 kg/m^3 up to past the two other readings of the printed
"mass of 0.0125" (a linear density of 0.0125 kg/m, a total mass of 0.0125 kg), which are levels of
the sweep. At each level: the Baudet MSS at 4x1x1, 8x2x2 and 16x4x4 cubes (springs are geometrically exact;
static Newton, 4x1x1 by damped implicit-Euler relaxation, its section modes being zero-energy), linear
FEM (Q1, scales with the load) and the non-linear reference, neo-Hookean FEM (Q1, total Lagrangian,
dead load), both on 24x6x6 hexahedra. Errors per node (error_stats: relative to the largest reference
displacement, and to each node's own) of every model against the non-linear and against the linear
FEM, and the tip deflection (mean -u_z of the end section).

The resolution limit of Fig. 11 (left) at the largest density: the MSS under the element reading of the
correction (each cube's correction from the forces on it) at 8x2x2, 16x4x4 and 32x8x8 cubes, with the
level's load steps; the 16x4x4 once more with twice as many load steps and the 32x8x8 with half as many
(the correction is not conservative: a static equilibrium need not be unique, and the load path can
pick another one; the shorter path keeps the check cheap at 32x8x8).
"""

import time

import numpy as np
import xarray as xr

from experiments.baudet import baudet_common as C
from experiments.baudet import cantilever_common as K

FEM_N = (24, 6, 6)
MSS = ((4, 1, 1), (8, 2, 2), (16, 4, 4))
SHAPE_MSS = (16, 4, 4)  # the MSS drawn in the figure
LIMIT_MSS = ((8, 2, 2), (16, 4, 4), (32, 8, 8))  # element reading, largest density only


def label(n):
    return "x".join(str(v) for v in n)


def at_points(ds, u, X):
    from msslib.compare import interpolate
    from msslib.results import mesh_from_result

    Xr = ds["rest_position"].transpose("node", "axis").values
    if X.shape == Xr.shape and np.allclose(X, Xr):
        return u
    return interpolate(mesh_from_result(ds), u, X)


def limit_runs(rho, steps, size, nl, refs, stat_names):
    """The element-reading MSS at the resolutions of LIMIT_MSS at density ``rho`` (``steps`` load steps;
    the middle one also with twice as many, the finest also with half as many): errors against ``refs``
    (the neo-Hookean and the linear FEM displacements on the mesh of ``nl``), tip deflections, load
    steps, wall time."""
    from msslib.scene import load_scene, run_scene

    t = time.perf_counter()
    err, tip, nsteps = {}, {}, {}
    runs = [(n, steps, f"mss_{label(n)}_element") for n in LIMIT_MSS]
    runs.append((LIMIT_MSS[1], 2 * steps, f"mss_{label(LIMIT_MSS[1])}_element_other_path"))
    runs.append((LIMIT_MSS[-1], max(1, steps // 2), f"mss_{label(LIMIT_MSS[-1])}_element_other_path"))
    for n, st, name in runs:
        solver = {"type": "static", "load_steps": st, "tol": 1e-9}
        sc, base_dir = K.scene("baudet_cube", size(n), density=rho, solver=solver)
        sc["model"] = {"type": "baudet_cube", "correction": "element"}
        X, u = K.fields(run_scene(load_scene(sc, base_dir=base_dir), progress=False))
        err[name] = [[K.error_stats(u, at_points(nl, ref, X))[k] for k in stat_names] for ref in refs]
        tip[name] = K.tip(X, u)
        nsteps[name] = st
        print(f"  {name} ({st} load steps): tip/L {tip[name] / K.base()[0]:.4f}, max error vs non-linear FEM "
              f"{err[name][0][stat_names.index('max_max')]:.4f}", flush=True)
    return err, tip, nsteps, time.perf_counter() - t


def main():
    args = C.parse(__doc__)
    t0 = time.perf_counter()
    L, T, H, E, _nu, rho0, g = K.base()
    readings = {k: float(f"{v:.12g}") for k, v in K.mass_readings().items()}  # 3.125, not 3.1249999999999996
    fem_n, mss = FEM_N, MSS
    # --quick keeps the model labels and runs every mesh at a reduced size, at the three readings only
    size = (lambda n: (8, 2, 2)) if args.quick else (lambda n: n)
    if args.quick:
        levels = [readings["density"], readings["linear_density"], readings["total_mass"]]
    else:
        levels = sorted({readings["density"], 0.5, readings["linear_density"], readings["total_mass"], 8.0})
    shape_n = SHAPE_MSS
    # eq. 10 (linear Euler-Bernoulli) tip / L per unit density: the load steps follow it
    tip_per_rho = T * H * g * L**4 / (8 * E * T * H**3 / 12) / L
    lin = K.run("fem_linear", size(fem_n))
    X_f, u_lin1 = K.fields(lin)
    models = [f"mss_{label(n)}" for n in mss] + ["fem_linear"]
    stat_names = sorted(K.error_stats(u_lin1, u_lin1 + 1e-9))
    refs = ("nonlinear", "linear")
    err = np.full((len(levels), len(models), len(refs), len(stat_names)), np.nan)
    tip = np.full((len(levels), len(models) + 1), np.nan)
    tip_x = np.full_like(tip, np.nan)
    shapes = {}
    for i, rho in enumerate(levels):
        t1 = time.perf_counter()
        s = rho / rho0
        steps = int(max(1, np.ceil(rho * tip_per_rho / 0.08)))
        nl = K.run("fem_neohookean", size(fem_n), density=rho,
                   solver={"type": "static", "load_steps": steps, "tol": 1e-8, "max_iter": 50})
        _, u_nl = K.fields(nl)
        u_l = u_lin1 * s
        fields = {}
        for n in mss:
            if size(n)[1] == 1:  # zero-energy section modes: relax dynamically; the relaxation time grows with the mass
                solver = {"type": "dynamic", "method": "implicit_euler", "dt": 0.005 * s, "t_end": 2.0 * s,
                          "damping": 100.0, "save_every": 400}
            else:
                solver = {"type": "static", "load_steps": steps, "tol": 1e-9}
            fields[f"mss_{label(n)}"] = K.fields(K.run("baudet_cube", size(n), density=rho, solver=solver))
        fields["fem_linear"] = (X_f, u_l)
        for j, m in enumerate(models):
            X, u = fields[m]
            for r, (ref_u) in enumerate((u_nl, u_l)):
                st = K.error_stats(u, at_points(nl, ref_u, X))
                err[i, j, r] = [st[k] for k in stat_names]
            tip[i, j] = K.tip(X, u)
            end = np.isclose(X[:, 0], L)
            tip_x[i, j] = float(u[end, 0].mean())
        tip[i, -1] = K.tip(X_f, u_nl)
        tip_x[i, -1] = float(u_nl[np.isclose(X_f[:, 0], L), 0].mean())
        if i == len(levels) - 1:
            limit = limit_runs(rho, steps, size, nl, (u_nl, u_l), stat_names)
            shapes = {"mss": fields[f"mss_{label(shape_n)}"], "fem_linear": (X_f, u_l), "fem_nonlinear": (X_f, u_nl)}
        k_mean = stat_names.index("max_mean")
        print(f"density {rho:.4g} kg/m^3 ({steps} steps): tip/L nonlinear FEM {tip[i, -1] / L:.4f}, linear {tip[i, -2] / L:.4f}; "
              "mean error vs non-linear FEM " + ", ".join(f"{m} {err[i, j, 0, k_mean]:.4f}" for j, m in enumerate(models))
              + f" ({time.perf_counter() - t1:.1f} s)", flush=True)

    ds = xr.Dataset(coords={"density": np.array(levels), "model": models, "reference": list(refs), "stat": stat_names,
                            "tip_model": models + ["fem_nonlinear"]})
    ds["density"].attrs = {"units": "kg/m^3", "long_name": "density of the beam"}
    ds["error"] = (("density", "model", "reference", "stat"), err,
                   {"units": "1", "long_name": "per-node displacement error statistics (cantilever_common.error_stats)"})
    ds["tip_deflection"] = (("density", "tip_model"), tip, {"units": "m", "long_name": "tip deflection, downwards"})
    ds["tip_axial"] = (("density", "tip_model"), tip_x, {"units": "m", "long_name": "axial displacement of the free end"})
    ds["tip_ratio"] = ds["tip_deflection"] / L
    ds["tip_ratio"].attrs = {"units": "1", "long_name": "tip deflection / length"}
    ds["largest_density"] = ((), levels[-1], {"units": "kg/m^3", "long_name": "largest density of the sweep"})
    ds["largest_error"] = ds["error"].isel(density=-1).drop_vars("density").assign_attrs(
        long_name="error statistics at the largest density")
    ds["largest_tip_ratio"] = ds["tip_ratio"].isel(density=-1).drop_vars("density").assign_attrs(
        units="1", long_name="tip deflection / length at the largest density")
    ds["tip_ratio_eq10"] = ("density", np.array(levels) * tip_per_rho, {"units": "1", "long_name": "eq. 10 tip deflection / length"})
    for k, v in readings.items():
        ds[f"reading_{k}"] = ((), v, {"units": "kg/m^3", "long_name": f"density implied by reading 0.0125 as {k.replace('_', ' ')}"})
    at = ds.sel(density=list(readings.values())).rename(density="reading").assign_coords(reading=list(readings))
    ds["reading_error"] = at["error"].assign_attrs(long_name="error statistics at the three readings of the printed mass")
    ds["reading_tip_ratio"] = (at["tip_deflection"] / L).assign_attrs(units="1", long_name="tip deflection / length at the three readings")
    for name, (X, u) in shapes.items():
        ds[f"rest_{name}"] = ((f"node_{name}", "axis"), X, {"units": "m", "long_name": f"rest positions, {name}"})
        ds[f"displacement_{name}"] = ((f"node_{name}", "axis"), u, {"units": "m",
                                       "long_name": f"displacement at the largest density, {name}"})
    lim_err, lim_tip, lim_steps, lim_time = limit
    lim_models = list(lim_tip)
    ds["limit_error"] = (("limit_model", "reference", "stat"), np.array([lim_err[m] for m in lim_models]),
                         {"units": "1", "long_name": "error statistics at the largest density, element reading "
                                                     "(reference: nonlinear = neo-Hookean FEM, linear = linear FEM)"})
    ds["limit_tip_ratio"] = ("limit_model", np.array([lim_tip[m] for m in lim_models]) / L,
                             {"units": "1", "long_name": "tip deflection / length at the largest density, element reading"})
    ds["limit_load_steps"] = ("limit_model", np.array([lim_steps[m] for m in lim_models]),
                              {"units": "1", "long_name": "load steps of the static solve"})
    ds["limit_wall_time"] = ((), lim_time, {"units": "s", "long_name": "wall time of the element-reading runs"})
    ds = ds.assign_coords(limit_model=lim_models)
    ds.attrs.update(title="Baudet cantilever under growing weight (Fig. 11)", quick=int(args.quick),
                    fem_mesh=label(fem_n), shape_mss=label(shape_n), length=L)
    C.write(ds, args.out, t0)
    print(f"done in {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
