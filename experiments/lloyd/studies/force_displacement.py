"""Lloyd et al., Fig. 1: force-displacement non-linearity of a triangle and a square MSS.

An equilateral triangle and a square, both of edge 1 m, bottom edge fixed; a vertical force F on
the top node (triangle) or on each of the two top nodes (square), from compression (F < 0) to
stretch (F > 0).  Springs from Lloyd's formulas (eq. 8 for the triangle, the prestrained eq. 10-11
for the square) for a membrane of E = 14630 Pa, nu = 1/3, thickness 1 cm.  For every F the
equilibrium is solved with msslib.solvers.static_solve; the linear FEM response of the same
element (plane stress) is stored beside it.  Straight lines fitted to the MSS points of each side,
displacement = slope * F, give the slopes of compression and of stretch (the paper: a factor of
about two between them).

    python -m experiments.lloyd.studies.force_displacement --out results/lloyd/studies/force_displacement.nc [--quick]
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from msslib.models.lloyd import lloyd_square_springs, lloyd_triangle_springs
from msslib import fem
from msslib import mesh as M
from msslib.results import write_result
from msslib.system import Model
from msslib.solvers import static_solve
from msslib.terms import NodalForces

E, NU, THICKNESS, EDGE = 14630.0, 1.0 / 3.0, 0.01, 1.0
F_MAX = 27.0  # N per loaded node; both elements snap through at about 28.5 N of compression


def element(shape):
    """Mesh, spring terms and loaded nodes of the single element."""
    if shape == "triangle":
        mesh = M.triangle_grid_equilateral(EDGE, EDGE * np.sqrt(3.0) / 2.0, 1)
        terms = lloyd_triangle_springs(mesh, [(E, NU)], THICKNESS)
    else:
        mesh = M.quad_grid(EDGE, EDGE, 1, 1)
        terms = lloyd_square_springs(mesh, [(E, NU)], THICKNESS)
    y = mesh.points[:, 1]
    bottom = np.isclose(y, y.min())
    top = np.isclose(y, y.max())
    return mesh, terms, bottom, top


def sweep(shape, forces):
    """Mean vertical displacement (m) of the loaded nodes: MSS and linear FEM, for every force."""
    mesh, springs, bottom, top = element(shape)
    fixed = np.zeros((mesh.n_nodes, 2), dtype=bool)
    fixed[bottom] = True
    mss = np.empty(len(forces))
    lin = np.empty(len(forces))
    for i, F in enumerate(forces):
        f = np.zeros((mesh.n_nodes, 2))
        f[top, 1] = F
        if F == 0.0:
            mss[i] = lin[i] = 0.0
            continue
        model = Model(mesh, springs + [NodalForces(f)], fixed=fixed)
        res = static_solve(model, model.x0, load_steps=10, tol=1e-10)
        u = (res.x - model.x0).reshape(-1, 2)
        mss[i] = u[top, 1].mean()
        lin[i] = fem.solve_linear(mesh, E, NU, fixed=fixed, nodal_forces=f, thickness=THICKNESS).displacement[top, 1].mean()
    return mss, lin


#: fractions of F_MAX over which the lines are fitted as well (the paper gives no force range)
RANGES = (0.25, 0.5, 0.75, 1.0)


def slope(forces, disp, side, limit=np.inf):
    """Least-squares slope (m/N) of a line through the origin fitted to one side's points with
    ``|F| <= limit``."""
    sel = (forces <= 0 if side == "compression" else forces >= 0) & (np.abs(forces) <= limit * (1 + 1e-12))
    F, d = forces[sel], disp[sel]
    return float(F @ d / (F @ F))


def main(argv=None):
    args = script.args(__doc__, argv)
    n = 9 if args.quick else 41
    forces = np.linspace(-F_MAX, F_MAX, n)
    shapes = ["triangle", "square"]
    disp = np.empty((2, n))
    lin = np.empty((2, n))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for j, s in enumerate(shapes):
            disp[j], lin[j] = sweep(s, forces)
    sc = np.array([slope(forces, disp[j], "compression") for j in range(2)])
    ss = np.array([slope(forces, disp[j], "stretch") for j in range(2)])
    ds = xr.Dataset(
        {
            "displacement": (("shape", "force"), disp, {"units": "m", "long_name": "vertical displacement of the loaded node(s), MSS"}),
            "fem_displacement": (("shape", "force"), lin, {"units": "m", "long_name": "vertical displacement of the loaded node(s), linear FEM"}),
            "slope_compression": (("shape",), sc, {"units": "m/N", "long_name": "slope of the line fitted to the compression points (F <= 0)"}),
            "slope_stretch": (("shape",), ss, {"units": "m/N", "long_name": "slope of the line fitted to the stretch points (F >= 0)"}),
            "slope_ratio": (("shape",), sc / ss, {"units": "1", "long_name": "compression slope over stretch slope"}),
            "slope_ratio_range": (("shape", "force_range"),
                                  np.array([[slope(forces, disp[j], "compression", r * F_MAX) / slope(forces, disp[j], "stretch", r * F_MAX)
                                             for r in RANGES] for j in range(2)]),
                                  {"units": "1", "long_name": "compression slope over stretch slope, fitted up to |F| = force_range F_MAX"}),
            "fem_slope": (("shape",), np.array([slope(forces, lin[j], "stretch") for j in range(2)]),
                          {"units": "m/N", "long_name": "slope of the linear FEM response"}),
        },
        coords={
            "shape": ("shape", shapes, {"units": "1", "long_name": "element shape"}),
            "force": ("force", forces, {"units": "N", "long_name": "vertical force on each top node"}),
            "force_range": ("force_range", np.array(RANGES), {"units": "1", "long_name": "largest |force| of the fit over F_MAX"}),
        },
        attrs={"title": "Lloyd et al. Fig. 1: force-displacement non-linearity", "E": E, "nu": NU,
               "thickness": THICKNESS, "edge_length": EDGE, "force_max": F_MAX, "quick": int(args.quick)},
    )
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_result(out, ds)
    for j, s in enumerate(shapes):
        print(f"{s}: slope compression {sc[j]:.4g} m/N, stretch {ss[j]:.4g} m/N, ratio {sc[j] / ss[j]:.3f}")


if __name__ == "__main__":
    main()
