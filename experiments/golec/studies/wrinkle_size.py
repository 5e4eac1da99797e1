"""Size of the wrinkle of the beam without face diagonals (Golec Fig. 2 (3)) against its deflection.

Golec et al. write that without face-diagonal springs "the wrinkles at the bottom of a sample change
the shape of the deformation" of the beam under gravity. The study ``wrinkles`` finds the symmetric
equilibrium of that beam unstable and a wrinkled equilibrium near it; this one measures how large
the wrinkle is against the bend, at the beam of ``experiments/golec/beam.yaml`` (variant
``mss_no_face``: 20 x 4 x 4 cubes of 1 cm, E = 400 kPa, nu = 0.3) and at larger deflections
(gravity times 2 and 4: the paper prints neither the beam's size nor its deflection), in two ways:

* *statically*: the symmetric equilibrium (load-stepped Newton), the smallest eigenvalue of its
  tangent on the free dofs, and the energy minimum reached from it perturbed along the unstable
  eigenvector (as in study ``wrinkles``);
* *dynamically*: the beam released from rest under gravity and stepped in time (velocity Verlet,
  mass-proportional damping) until it has come to rest; its final state is compared with the
  symmetric equilibrium.

The wrinkle is the largest node distance between the wrinkled (or the dynamic final) state and the
symmetric equilibrium; the deflection is the largest downward displacement of the symmetric state.

    python -m experiments.golec.studies.wrinkle_size --out results/golec/studies/wrinkle_size.nc [--quick]
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from experiments.golec.studies.wrinkles import min_eigen, wrinkled
from msslib.experiment import load_experiment, scene_of
from msslib.results import write_result
from msslib.scene import load_scene, prepare
from msslib.stepping import Simulator
from msslib.solvers import static_solve

HERE = Path(__file__).resolve().parent.parent
FACTORS = (1.0, 2.0, 4.0)  # gravity times these (density times these: the same load)
DT, DAMPING = 1.0e-4, 8.0  # s, 1/s (mass-proportional)


def setup_of(factor, quick):
    exp = load_experiment(HERE / "beam.yaml")
    sc = scene_of(exp, "default", "mss_no_face", quick=quick)
    sc["materials"] = [dict(m, density=m["density"] * factor) for m in sc["materials"]]
    return prepare(load_scene(sc, base_dir=exp.base_dir))


def main(argv=None):
    args = script.args(__doc__, argv)
    t0 = time.perf_counter()
    factors = FACTORS[:2] if args.quick else FACTORS
    t_end = 0.5 if args.quick else 3.0
    keys = ("deflection", "min_eigenvalue", "wrinkle_static", "wrinkle_dynamic", "dynamic_to_wrinkled",
            "kinetic_energy_end", "energy_drop")
    out = {k: np.full(len(factors), np.nan) for k in keys}
    for i, f in enumerate(factors):
        st = setup_of(f, args.quick)
        model, mesh = st.model, st.mesh
        s = st.scene.solver
        x = static_solve(model, model.x0, load_steps=int(s["load_steps"] * f), tol=s["tol"], max_iter=s["max_iter"]).x
        u = (x - model.x0).reshape(-1, 3)
        lam, vec = min_eigen(model, x)
        out["deflection"][i] = -u[:, 2].min()
        out["min_eigenvalue"][i] = lam
        xw = x
        if lam < 0:
            xw, _ = wrinkled(model, mesh, x, vec)
            out["energy_drop"][i] = model.energy(x, 1.0) - model.energy(xw, 1.0)
        out["wrinkle_static"][i] = np.linalg.norm((xw - x).reshape(-1, 3), axis=1).max()
        print(f"[{time.perf_counter() - t0:6.1f} s] gravity x{f:g}: deflection {out['deflection'][i] * 1e3:.2f} mm, "
              f"smallest eigenvalue {lam:.4g} N/m, static wrinkle {out['wrinkle_static'][i] * 1e3:.3g} mm", flush=True)
        # released from rest under gravity, stepped until at rest
        sim = Simulator(model, dt=DT, method="velocity_verlet", damping=DAMPING)
        sim.step(round(t_end / DT))
        xd = np.asarray(sim.x).reshape(-1)
        out["kinetic_energy_end"][i] = sim.kinetic_energy()
        out["wrinkle_dynamic"][i] = np.linalg.norm((xd - x).reshape(-1, 3), axis=1).max()
        out["dynamic_to_wrinkled"][i] = np.linalg.norm((xd - xw).reshape(-1, 3), axis=1).max()
        print(f"[{time.perf_counter() - t0:6.1f} s] gravity x{f:g}: dynamic final state {out['wrinkle_dynamic'][i] * 1e3:.3g} mm "
              f"from the symmetric one, {out['dynamic_to_wrinkled'][i] * 1e3:.3g} mm from the wrinkled one, "
              f"kinetic energy {out['kinetic_energy_end'][i]:.3g} J", flush=True)
    units = {"deflection": "m", "min_eigenvalue": "N/m", "wrinkle_static": "m", "wrinkle_dynamic": "m",
             "dynamic_to_wrinkled": "m", "kinetic_energy_end": "J", "energy_drop": "J"}
    names = {"deflection": "largest downward displacement of the symmetric equilibrium",
             "min_eigenvalue": "smallest eigenvalue of the tangent (free dofs) at the symmetric equilibrium",
             "wrinkle_static": "largest node distance, wrinkled equilibrium to symmetric equilibrium",
             "wrinkle_dynamic": "largest node distance, dynamic final state to symmetric equilibrium",
             "dynamic_to_wrinkled": "largest node distance, dynamic final state to wrinkled equilibrium",
             "kinetic_energy_end": "kinetic energy at the end of the dynamic run",
             "energy_drop": "energy of the symmetric minus the wrinkled equilibrium"}
    ds = xr.Dataset(coords={"gravity_factor": ("gravity_factor", np.array(factors), {"units": "1"})})
    for k, v in out.items():
        ds[k] = ("gravity_factor", v, {"units": units[k], "long_name": names[k]})
    for k in ("wrinkle_static", "wrinkle_dynamic"):
        ds[f"{k}_relative"] = ds[k] / ds.deflection
        ds[f"{k}_relative"].attrs.update(units="1", long_name=f"{names[k]}, over the deflection")
    ds["relative_wrinkle_max"] = ds[["wrinkle_static_relative", "wrinkle_dynamic_relative"]].to_array().max()
    ds["relative_wrinkle_max"].attrs.update(units="1", long_name="largest wrinkle over deflection, all runs")
    ds.attrs.update(study="golec_wrinkle_size", quick=int(args.quick), wall_time_s=time.perf_counter() - t0,
                    dt=DT, damping=DAMPING, t_end=t_end, description=__doc__.strip().splitlines()[0])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_result(args.out, ds)


if __name__ == "__main__":
    main()
