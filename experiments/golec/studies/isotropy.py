"""Isotropy of Golec's cube lattice in simulation: effective E, nu and shear moduli against A.

A 4 cm cube sample of 4 x 4 x 4 Golec cubes (1 cm) with the correction forces, derived constants
(per element, springs scaled with 5E/(4(1+nu))) or the printed ones (used per element), for
nu = 0.3 (E = 400 kPa, the beam) and nu = 0.4999 (E = 20 kPa, the compression sample), small
strain 1e-3, static:

The printed constants are also read as interior totals (``printed_totals``: per element k_e/4,
k_f/2 and k_c, errata 4), which gives an isotropic spring lattice with nu = 1/4 and shear modulus
2E/5 whatever the target nu (errata 5); the correction term then sets the bulk modulus.

* uniaxial stress along z: bottom and top slide (top displaced by +0.1 %), symmetry planes x = 0
  and y = 0 held normally; stress = top reaction / area; E and nu from the fitted mean strains
  (msslib.metrics.youngs_modulus_poisson);
* simple shear u = gamma z e_x on every boundary node (interior free): G = C44 from the stored
  energy, W = G gamma^2 V / 2 (msslib.metrics.shear_modulus on the fitted slope);
* pure shear along the diagonals, u = eps (x, -y, 0) on the boundary: G45 = (C11 - C12)/2 from
  W = 2 G45 eps^2 V. An isotropic lattice has G = G45 = E/(2(1+nu)).
"""

import time
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from msslib.models.common import assemble_springs
from msslib.models.golec import golec_cube_springs
from msslib.results import write_result
from msslib.mesh import hex_grid
from msslib.metrics import mesh_volume, shear_modulus, youngs_modulus_poisson
from msslib.system import Model
from msslib.parameters import golec_cube
from msslib.solvers import static_solve
from msslib.terms import HexVolume, Springs

L, N, STRAIN = 0.04, 4, 1e-3
MATERIALS = {"nu0.3": (4.0e5, 0.3), "nu0.4999": (2.0e4, 0.4999)}


def printed_as_totals(mesh, E, nu, A):
    """The printed constants read as interior totals (errata 4): per element k_e/4 (an edge is
    shared by 4 cubes), k_f/2 (a face diagonal by 2), k_c; the correction term as derived."""
    a = L / N
    c = golec_cube(E, nu=nu, a=a, A=A, published=True)
    springs = Springs(*[np.concatenate(v) for v in zip(*[
        (s.pairs, s.k, s.rest_length) for s in (assemble_springs(mesh, "edges", lambda cells, _p: c.k_edge / 4),
                                                 assemble_springs(mesh, "face_diagonals", lambda cells, _p: c.k_face / 2),
                                                 assemble_springs(mesh, "inner_diagonals", lambda cells, _p: c.k_inner))])], 3)
    return [springs, HexVolume(mesh.cells, np.full(mesh.n_cells, c.kappa), np.full(mesh.n_cells, a**3))]


def solve(mesh, E, nu, A, constants, fixed, prescribed):
    if constants == "printed_totals":
        terms = printed_as_totals(mesh, E, nu, A)
    else:
        terms = golec_cube_springs(mesh, [(E, nu)], A, published=constants == "published")
    model = Model(mesh, terms, fixed=fixed, prescribed=prescribed)
    res = static_solve(model, model.x0, load_steps=1, tol=1e-10)
    return model, res.x


def tension(mesh, E, nu, A, published):
    p = mesh.points
    fixed = np.zeros_like(p, dtype=bool)
    pres = np.zeros_like(p)
    tol = 1e-9
    bottom, top = p[:, 2] < tol, p[:, 2] > L - tol
    fixed[bottom, 2] = fixed[top, 2] = True
    pres[top, 2] = STRAIN * L
    fixed[p[:, 0] < tol, 0] = True
    fixed[p[:, 1] < tol, 1] = True
    model, x = solve(mesh, E, nu, A, published, fixed, pres)
    sigma = model.reaction(x)[top, 2].sum() / L**2
    return youngs_modulus_poisson(p, x.reshape(-1, 3), sigma, axis=2)


def boundary_affine(mesh, H):
    p = mesh.points
    tol = 1e-9
    on = np.any((p < tol) | (p > L - tol), axis=1)
    fixed = np.zeros_like(p, dtype=bool)
    fixed[on] = True
    pres = np.zeros_like(p)
    pres[on] = p[on] @ H.T
    return fixed, pres


def shear(mesh, E, nu, A, published):
    H = np.zeros((3, 3))
    H[0, 2] = STRAIN  # u_x = gamma z
    model, x = solve(mesh, E, nu, A, published, *boundary_affine(mesh, H))
    V = mesh_volume(mesh)
    G = 2.0 * model.energy(x) / (STRAIN**2 * V)
    # the same through msslib.metrics: tau = G gamma, slope fitted from the node displacements
    return shear_modulus(mesh.points, x.reshape(-1, 3), G * STRAIN, axis_load=0, axis_normal=2)


def shear45(mesh, E, nu, A, published):
    H = np.diag([STRAIN, -STRAIN, 0.0])
    model, x = solve(mesh, E, nu, A, published, *boundary_affine(mesh, H))
    return model.energy(x) / (2.0 * STRAIN**2 * mesh_volume(mesh))


def main():
    args = script.args(__doc__)
    A_values = [0.5, 1.0, 4.0] if args.quick else [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0]
    constants = ["derived", "published", "printed_totals"]
    mesh = hex_grid(L, L, L, N, N, N)
    shape = (len(MATERIALS), len(constants), len(A_values))
    out = {k: np.full(shape, np.nan) for k in ("E_eff", "nu_eff", "G_eff", "G45_eff")}
    t0 = time.perf_counter()
    for i, (E, nu) in enumerate(MATERIALS.values()):
        for j, c in enumerate(constants):
            for k, A in enumerate(A_values):
                pub = c
                out["E_eff"][i, j, k], out["nu_eff"][i, j, k] = tension(mesh, E, nu, A, pub)
                out["G_eff"][i, j, k] = shear(mesh, E, nu, A, pub)
                out["G45_eff"][i, j, k] = shear45(mesh, E, nu, A, pub)
                print(f"nu={nu} {c} A={A}: E {out['E_eff'][i, j, k]:.4g} nu {out['nu_eff'][i, j, k]:.4g} "
                      f"G {out['G_eff'][i, j, k]:.4g} G45 {out['G45_eff'][i, j, k]:.4g}", flush=True)
    ds = xr.Dataset(coords={"material": list(MATERIALS), "constants": constants, "A": A_values})
    ds["E_target"] = ("material", [m[0] for m in MATERIALS.values()], {"units": "Pa"})
    ds["nu_target"] = ("material", [m[1] for m in MATERIALS.values()], {"units": "1"})
    ds["G_target"] = ("material", [m[0] / (2 * (1 + m[1])) for m in MATERIALS.values()], {"units": "Pa"})
    units = {"E_eff": "Pa", "nu_eff": "1", "G_eff": "Pa", "G45_eff": "Pa"}
    names = {"E_eff": "effective Young's modulus (uniaxial stress)", "nu_eff": "effective Poisson's ratio",
             "G_eff": "effective shear modulus C44 (simple shear along the cube axes)",
             "G45_eff": "effective shear modulus (C11 - C12)/2 (pure shear along the face diagonals)"}
    for k, v in out.items():
        ds[k] = (("material", "constants", "A"), v, {"units": units[k], "long_name": names[k]})
        if k != "nu_eff":
            tgt = {"E_eff": ds.E_target, "G_eff": ds.G_target, "G45_eff": ds.G_target}[k]
            ds[k.replace("_eff", "_ratio")] = ds[k] / tgt
            ds[k.replace("_eff", "_ratio")].attrs.update(units="1", long_name=f"{names[k]} / target")
    ds["anisotropy"] = ds.G_eff / ds.G45_eff
    ds["anisotropy"].attrs.update(units="1", long_name="C44 / ((C11 - C12)/2), 1 if isotropic")
    ds.attrs.update(study="golec_isotropy", quick=int(args.quick), wall_time_s=time.perf_counter() - t0,
                    sample=f"{L} m cube, {N}^3 Golec cubes", strain=STRAIN)
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_result(args.out, ds)


if __name__ == "__main__":
    main()
