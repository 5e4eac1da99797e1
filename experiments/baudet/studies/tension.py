"""Baudet et al. Figs. 4-5: Young's modulus and Poisson's ratio errors in quasi-static tension.

A cube (one element) and a beam of 4 x 4 x 12 cubes (one eighth modelled, symmetry planes
x = y = z = 0) pulled along z by a dead traction P on the free z face, up to 20 % axial strain,
for nu in {0.1, 0.2, 0.25, 0.3, 0.4, 0.499} (0.25: where the paper places the sign change of the
Poisson error and where the correction vanishes), with the derived correction factor -(4 nu - 1)/2 and the
printed -(4 nu - 1)/16 (resultants per face), each under the two readings of the correction force
(dimension ``reading``): ``boundary`` (driven by the loads on the body's loaded faces) and ``element``
(every cube driven by the forces acting on it from outside, msslib.terms.baudet). E = P / eps_z
and nu = -eps_lat / eps_z (eqs. 1-2, nominal stress and engineering strains from the least-squares
mean displacement gradient of all nodes, exact for the cube's affine deformation). Errors are
signed, relative to the input values. Every variable ``V_by_reading`` has the ``reading`` dimension;
``V`` (without it) is its ``boundary`` slice.
"""

import time

import numpy as np
import xarray as xr

from experiments.baudet import baudet_common as C
from msslib.metrics import mean_displacement_gradient

GEOMETRIES = {"cube": (1, 1, 1), "beam": (2, 2, 6)}
LEVELS = {"eps05": 0.05, "eps10": 0.10, "eps14": 0.14, "eps15": 0.15, "eps20": 0.20}
# the shared nu values and 1/4, where Baudet place the sign change of the Poisson error (Sec. 5)
NUS = tuple(sorted(C.NUS + (0.25,)))
NU_LABELS = tuple(f"{v:g}" for v in NUS)


def run(n, nu, published, strains, reading="boundary"):
    lz = C.A0 * n[2]
    mesh, model = C.block(n, nu, published=published, tractions=[("z", lz, [0.0, 0.0, 1.0])], reading=reading)
    X = mesh.points

    def grad(x):
        return mean_displacement_gradient(X, x.reshape(-1, 3))

    target = strains[-1] * 1.02
    loads, states = C.follow(model, lambda x: grad(x)[2, 2], target, first_step=C.E0 * target / 40)
    H = np.array([grad(x) for x in states])
    eps = H[:, 2, 2]
    E = loads / eps
    nu_m = -(H[:, 0, 0] + H[:, 1, 1]) / 2 / eps
    # small-strain limit by the first level (linear extrapolation of the secant values)
    E_i = np.interp(strains, eps, E)
    nu_i = np.interp(strains, eps, nu_m)
    return E_i, nu_i, (E[0], nu_m[0]), len(loads)


def main():
    args = C.parse(__doc__)
    t0 = time.perf_counter()
    strains = np.round(np.arange(0.005, 0.2001, 0.005 if not args.quick else 0.01), 6)
    shape = (len(C.READINGS), len(GEOMETRIES), len(C.FACTORS), len(NUS), len(strains))
    E = np.full(shape, np.nan)
    NU = np.full(shape, np.nan)
    E_lin = np.full(shape[:4], np.nan)
    NU_lin = np.full(shape[:4], np.nan)
    for r, reading in enumerate(C.READINGS):
        for g, n in enumerate(GEOMETRIES.values()):
            for f, fac in enumerate(C.FACTORS):
                for k, nu in enumerate(NUS):
                    E_i, nu_i, (e1, n1), nl = run(n, nu, fac == "printed", strains, reading)
                    E[r, g, f, k], NU[r, g, f, k] = E_i, nu_i
                    E_lin[r, g, f, k], NU_lin[r, g, f, k] = e1, n1
                    print(f"{reading} {list(GEOMETRIES)[g]} {fac} nu={nu}: {nl} load levels, E(eps->0)={e1:.4g}, "
                          f"nu={n1:.4g}", flush=True)
    nu_in = np.array(NUS)[None, None, None, :, None]
    coords = {"reading": list(C.READINGS), "geometry": list(GEOMETRIES), "factor": list(C.FACTORS),
              "nu": list(NU_LABELS), "strain": strains}
    ds = xr.Dataset(coords=coords)
    ds["strain"].attrs = {"units": "1", "long_name": "axial engineering strain"}
    ds["nu"].attrs = {"units": "1", "long_name": "input Poisson's ratio (label)"}
    ds["geometry"].attrs = {"long_name": "cube: one element; beam: 4 x 4 x 12 cubes"}
    ds["factor"].attrs = {"long_name": "correction factor: derived -(4nu-1)/2 or printed -(4nu-1)/16"}
    ds["reading"].attrs = {"long_name": "correction force driven by the loaded boundary faces or, per cube, by the "
                                        "forces from outside it"}
    ds["nu_value"] = ("nu", np.array(NUS), {"units": "1", "long_name": "input Poisson's ratio"})
    dims = ("reading", "geometry", "factor", "nu", "strain")
    ds["youngs_modulus"] = (dims, E, {"units": "Pa", "long_name": "measured Young's modulus P/eps (secant)"})
    ds["poisson_ratio"] = (dims, NU, {"units": "1", "long_name": "measured Poisson's ratio -eps_lat/eps"})
    ds["E_error"] = (dims, E / C.E0 - 1.0, {"units": "1", "long_name": "relative error of E (signed)"})
    ds["nu_error"] = (dims, NU / nu_in - 1.0, {"units": "1", "long_name": "relative error of nu (signed)"})
    ds["nu_abs_error"] = (dims, NU - nu_in, {"units": "1", "long_name": "error of nu (measured - input)"})
    d3 = ("reading", "geometry", "factor", "nu")
    ds["E_small_strain"] = (d3, E_lin, {"units": "Pa", "long_name": "E at the first load level"})
    ds["nu_small_strain"] = (d3, NU_lin, {"units": "1", "long_name": "nu at the first load level"})
    # values at the strains the paper quotes, on a string coordinate (for the paper's placeholders)
    lv = list(LEVELS)
    ds = ds.assign_coords(level=lv)
    ds["level"].attrs = {"long_name": "quoted axial strain (eps10 = 10 %)"}
    ds["level_strain"] = ("level", np.array(list(LEVELS.values())), {"units": "1", "long_name": "axial strain of the level"})
    for name in ("E_error", "nu_error", "nu_abs_error"):
        vals = np.stack([ds[name].interp(strain=v).values for v in LEVELS.values()], axis=-1)
        ds[f"{name}_at"] = (("reading", "geometry", "factor", "nu", "level"), vals,
                            {"units": "1", "long_name": ds[name].attrs["long_name"] + " at the quoted strains"})
    ds = C.split_readings(ds)
    for name in ("E", "nu"):  # "a composite equals one element": largest |beam - cube| over strains and nu
        v = ds[f"{name}_error_by_reading"]
        d = abs(v.sel(geometry="beam") - v.sel(geometry="cube")).max(("nu", "strain"))
        d.attrs = {"units": "1", "long_name": f"largest |{name} error (beam) - {name} error (cube)| over strains and nu"}
        ds[f"{name}_beam_cube_max_difference"] = d
    # the sign of the Poisson error over the strain range (Baudet: thinning overestimated for nu >= 1/4,
    # underestimated below) and the strain at which |nu error| first exceeds 5 % (Fig. 5's bound)
    v = ds["nu_error_by_reading"]
    for name, red in (("min", v.min("strain", skipna=True)), ("max", v.max("strain", skipna=True))):
        red.attrs = {"units": "1", "long_name": f"{name}imum over the strains of the signed relative nu error"}
        ds[f"nu_error_{name}_by_reading"] = red
    strain = ds["strain"].values
    over = np.abs(v.values) > 0.05
    first = np.where(over.any(-1), strain[np.argmax(over, axis=-1)], np.nan)
    ds["nu_error_5pc_strain_by_reading"] = (v.dims[:-1], first, {
        "units": "1", "long_name": "first sampled axial strain with |nu error| > 5 % (NaN: never up to 20 %)"})
    for name in ("nu_error_min", "nu_error_max", "nu_error_5pc_strain"):  # the boundary slice, as split_readings
        ds[name] = ds[f"{name}_by_reading"].sel(reading="boundary", drop=True)
        ds[name].attrs = {**ds[f"{name}_by_reading"].attrs, "reading": "boundary"}
    ds["E_input"] = ((), C.E0, {"units": "Pa", "long_name": "input Young's modulus"})
    ds["lattice_nu"] = ("nu", 1.0 / (4 * np.array(NUS) + 3),
                        {"units": "1", "long_name": "Poisson's ratio of the uncorrected lattice, 1/(4 nu + 3)"})
    ds.attrs.update(title="Baudet Figs. 4-5: E and nu errors in tension", quick=int(args.quick),
                    cube_edge_m=C.A0)
    C.write(ds, args.out, t0)
    print(f"wrote {args.out} in {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
