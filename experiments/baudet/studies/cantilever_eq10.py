"""Baudet eq. 10: Euler-Bernoulli deflection of the cantilever under its own weight.

y(x) = rho_l g / (24 E I) (6 L^2 x^2 - 4 L x^3 + x^4), rho_l = density x T H the linear density,
I = T H^3 / 12, with the parameters of experiments/baudet/cantilever.yaml (read from it, so the two
stay consistent). Also the Timoshenko shear term rho_l g (L x - x^2/2) / (kappa G A), kappa = 5/6,
which eq. 10 (nu = 0, slender beam) leaves out.
"""

import time
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from experiments.baudet import baudet_common as C

EXP = Path(__file__).resolve().parents[1] / "cantilever.yaml"


def main():
    args = C.parse(__doc__)
    t0 = time.perf_counter()
    raw = yaml.safe_load(EXP.read_text())
    geo = raw["scene"]["geometry"]["args"]
    mat = raw["scene"]["materials"][0]
    g = -float(raw["scene"]["loads"][0]["g"][2])
    L, T, H = float(geo["lx"]), float(geo["ly"]), float(geo["lz"])
    E, nu, rho = float(mat["E"]), float(mat["nu"]), float(mat["density"])
    I = T * H**3 / 12
    rho_l = rho * T * H
    x = np.linspace(0.0, L, 201 if not args.quick else 41)
    y = rho_l * g / (24 * E * I) * (6 * L**2 * x**2 - 4 * L * x**3 + x**4)
    G = E / (2 * (1 + nu))
    y_s = rho_l * g * (L * x - x**2 / 2) / (5 / 6 * G * T * H)
    ds = xr.Dataset(coords={"x": x})
    ds["x"].attrs = {"units": "m", "long_name": "distance from the clamped end"}
    ds["deflection_eq10"] = ("x", y, {"units": "m", "long_name": "Euler-Bernoulli deflection (eq. 10), downwards"})
    ds["deflection_timoshenko"] = ("x", y + y_s, {"units": "m", "long_name": "eq. 10 plus the Timoshenko shear term"})
    ds["tip_eq10"] = ((), y[-1], {"units": "m", "long_name": "tip deflection, eq. 10"})
    ds["tip_timoshenko"] = ((), y[-1] + y_s[-1], {"units": "m", "long_name": "tip deflection, eq. 10 + shear"})
    ds["tip_ratio"] = ((), y[-1] / L, {"units": "1", "long_name": "tip deflection / length (eq. 10)"})
    ds["linear_density"] = ((), rho_l, {"units": "kg/m", "long_name": "linear density rho T H"})
    ds["total_mass"] = ((), rho * L * T * H, {"units": "kg", "long_name": "mass of the beam"})
    for name, rl in (("tip_ratio_if_linear_density", 0.0125), ("tip_ratio_if_total_mass", 0.0125 / L)):
        ds[name] = ((), rl * g * L**4 / (8 * E * I) / L,
                    {"units": "1", "long_name": f"tip deflection / length, reading 0.0125 as {name.split('_if_')[1].replace('_', ' ')}"})
    ds.attrs.update(title="Baudet eq. 10: cantilever deflection", quick=int(args.quick))
    C.write(ds, args.out, t0)
    print(f"tip {y[-1]:.4g} m (eq. 10), {y[-1] + y_s[-1]:.4g} m (with shear)")


if __name__ == "__main__":
    main()
