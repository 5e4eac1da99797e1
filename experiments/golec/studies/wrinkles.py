"""Wrinkle instability of the classical MSS without face diagonals (Golec Fig. 2 (1) and (3)).

For the compression (clamped case) and beam experiments, the MSS variant without face diagonals
(mss_no_face) is solved statically along the symmetric path; the smallest eigenvalue of its
stiffness on the free dofs tells whether that equilibrium is stable. Where it is negative, the
state is perturbed along the unstable eigenvector (amplitude 1 % of a cube edge) and the energy is
minimised (trust-region Newton-Krylov, which handles an indefinite Hessian) to find the wrinkled
equilibrium. The same eigenvalue check is made for the variant with face diagonals (mss_classical)
and Golec's hybrid model (golec), for reference. Writes one NetCDF with, per experiment and
variant, the smallest eigenvalue, the volume and the largest displacement of the symmetric and
the wrinkled states (volume and largest downward displacement also for golec_published and the
FEM reference), and the node positions of both states for the figures.
"""

import time
from pathlib import Path

import numpy as np
import xarray as xr
from scipy.optimize import minimize

from experiments import script
from msslib.experiment import load_experiment, run, scene_of
from msslib.results import mesh_from_result, write_result
from msslib.metrics import mesh_volume
from msslib.scene import load_scene, prepare
from msslib.solvers import static_solve

HERE = Path(__file__).resolve().parent.parent
EXPERIMENTS = {"compression": ("compression.yaml", "clamped"), "beam": ("beam.yaml", "default")}
VARIANTS = ["mss_no_face", "mss_classical", "golec", "golec_published", "fem"]


def min_eigen(model, x):
    K = model.stiffness(x).toarray()[np.ix_(model.free, model.free)]
    w, v = np.linalg.eigh(0.5 * (K + K.T))
    return w[0], v[:, 0]


def relax(model, x_start):
    """Local energy minimum near x_start (free dofs), the fixed dofs held at their load-1 values."""
    free = model.free
    base = model.apply_prescribed(x_start.copy(), 1.0)

    def full(z):
        x = base.copy()
        x[free] = z
        return x

    res = minimize(lambda z: model.energy(full(z), 1.0), base[free], method="trust-krylov",
                   jac=lambda z: -model.force(full(z), 1.0)[free],
                   hessp=lambda z, p: model.stiffness(full(z), 1.0)[free][:, free] @ p,
                   options={"gtol": 1e-10, "maxiter": 500})
    return full(res.x), res


def wrinkled(model, mesh, x, vec):
    """The equilibrium reached from ``x`` pushed along the unstable mode ``vec`` (free dofs) by a
    hundredth of the smallest cell side: ``relax``'s ``(x, result)``."""
    a = np.ptp(mesh.points[mesh.cells[0]], axis=0).min()
    xp = x.copy()
    xp[model.free] += 0.01 * a * vec / np.abs(vec).max()
    return relax(model, xp)


def main():
    args = script.args(__doc__)
    ds = xr.Dataset(coords={"experiment": list(EXPERIMENTS), "variant": VARIANTS})
    shape = (len(EXPERIMENTS), len(VARIANTS))
    out = {k: np.full(shape, np.nan) for k in ("min_eigenvalue", "volume_symmetric", "volume_wrinkled",
                                               "max_displacement_symmetric", "wrinkle_amplitude",
                                               "min_eigenvalue_wrinkled", "energy_drop", "volume_rest",
                                               "tip_deflection")}
    t0 = time.perf_counter()
    for i, (ename, (fname, case)) in enumerate(EXPERIMENTS.items()):
        exp = load_experiment(HERE / fname)
        for j, var in enumerate(VARIANTS):
            if var == "fem":  # the reference: volume and largest displacement only
                r = run(exp, case, var, quick=args.quick)
                u = r["displacement"].transpose("node", "axis").values
                mesh = mesh_from_result(r)
                out["volume_rest"][i, j] = mesh_volume(mesh)
                out["volume_symmetric"][i, j] = mesh_volume(mesh, u)
                out["max_displacement_symmetric"][i, j] = np.linalg.norm(u, axis=1).max()
                out["tip_deflection"][i, j] = -u[:, 2].min()
                continue
            setup = prepare(load_scene(scene_of(exp, case, var, quick=args.quick), base_dir=exp.base_dir))
            model, mesh = setup.model, setup.mesh
            s = setup.scene.solver
            res = static_solve(model, model.x0, load_steps=s["load_steps"], tol=s["tol"], max_iter=s["max_iter"])
            x = res.x
            u = (x - model.x0).reshape(-1, 3)
            lam, vec = min_eigen(model, x)
            out["min_eigenvalue"][i, j] = lam
            out["volume_rest"][i, j] = mesh_volume(mesh)
            out["volume_symmetric"][i, j] = mesh_volume(mesh, u)
            out["max_displacement_symmetric"][i, j] = np.linalg.norm(u, axis=1).max()
            out["tip_deflection"][i, j] = -u[:, 2].min()
            xw = x
            if lam < 0:
                xw, r = wrinkled(model, mesh, x, vec)
                uw = (xw - model.x0).reshape(-1, 3)
                out["volume_wrinkled"][i, j] = mesh_volume(mesh, uw)
                out["wrinkle_amplitude"][i, j] = np.linalg.norm((xw - x).reshape(-1, 3), axis=1).max()
                out["min_eigenvalue_wrinkled"][i, j] = min_eigen(model, xw)[0]
                out["energy_drop"][i, j] = model.energy(x, 1.0) - model.energy(xw, 1.0)
                print(f"{ename} {var}: relaxed ({r.message}), energy drop {out['energy_drop'][i, j]:.3g} J", flush=True)
            print(f"{ename} {var}: min eigenvalue {lam:.4g} N/m", flush=True)
            if var == "mss_no_face":
                n = f"node_{ename}"
                ds[f"{ename}_rest"] = ((n, "axis"), mesh.points, {"units": "m", "long_name": f"{ename}: rest positions"})
                ds[f"{ename}_symmetric"] = ((n, "axis"), x.reshape(-1, 3), {"units": "m", "long_name": f"{ename}: symmetric equilibrium (no face diagonals)"})
                ds[f"{ename}_wrinkled"] = ((n, "axis"), xw.reshape(-1, 3), {"units": "m", "long_name": f"{ename}: wrinkled equilibrium (no face diagonals)"})
                ds[f"{ename}_cells"] = ((f"cell_{ename}", "corner"), mesh.cells, {"long_name": f"{ename}: hexahedra (VTK order)"})
    units = {"min_eigenvalue": "N/m", "min_eigenvalue_wrinkled": "N/m", "energy_drop": "J",
             "volume_symmetric": "m^3", "volume_wrinkled": "m^3", "volume_rest": "m^3",
             "max_displacement_symmetric": "m", "wrinkle_amplitude": "m", "tip_deflection": "m"}
    for k, v in out.items():
        ds[k] = (("experiment", "variant"), v, {"units": units[k], "long_name": k.replace("_", " ")})
    ds["volume_change"] = ds.volume_symmetric / ds.volume_rest - 1.0
    ds["volume_change"].attrs.update(units="1", long_name="relative volume change of the symmetric state")
    ds["volume_change_wrinkled"] = ds.volume_wrinkled / ds.volume_rest - 1.0
    ds["volume_change_wrinkled"].attrs.update(units="1", long_name="relative volume change of the wrinkled state")
    ds.attrs.update(study="golec_wrinkles", quick=int(args.quick), wall_time_s=time.perf_counter() - t0,
                    description=__doc__.strip().splitlines()[0])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_result(args.out, ds)


if __name__ == "__main__":
    main()
