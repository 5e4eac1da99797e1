"""3-4: static solve scaling and the cantilever under gravity."""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from msslib import mesh as M
from msslib import model as MD
from msslib import solvers as S
from msslib import terms as T

from .common import median_time


def superlu_default(A, b):
    """Baseline linear solver: scipy's splu with its default (COLAMD) ordering."""
    return spla.splu(sp.csc_matrix(A)).solve(np.asarray(b, dtype=float))


def cube_under_gravity(n: int, E: float = 1e4, nu: float = 0.25, rho: float = 1000.0):
    """n^3 Golec cubes of 1 cm (nu = 1/4: springs only, kappa = 0), clamped at z = 0, gravity -z."""
    a = 0.01
    mesh = M.hex_grid(n * a, n * a, n * a, n, n, n)
    springs = MD.golec_cube_springs(mesh, [(E, nu)], 1.0)[0]
    masses = M.lumped_masses(mesh, rho)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    return MD.Model(mesh, [springs, T.Gravity(masses, [0.0, 0.0, -9.81])], fixed=fixed, masses=masses)


def run_scaling(res, quick: bool):
    sizes = [6, 10, 15] if quick else [6, 10, 15, 22, 32, 46]
    lu_sizes = [6, 10] if quick else [6, 10, 15]
    dofs, times, lu_times = [], [], {}
    for n in sizes:
        model = cube_under_gravity(n)
        rep = 3 if n <= 10 else 1
        t = median_time(lambda: S.static_solve(model, model.x0), repeat=rep, warmup=1 if n <= 15 else 0)
        r = S.static_solve(model, model.x0) if n <= 15 else None
        dofs.append(int(model.free.sum()))
        times.append(t)
        if n in lu_sizes:
            lu_times[n] = median_time(lambda: S.static_solve(model, model.x0, linear_solver=superlu_default),
                                      repeat=rep, warmup=0)
        ratio = lu_times[n] / t if n in lu_sizes else None
        res.add(f"static_solve_{dofs[-1]}_dofs", t, "s", ratio, "scipy SuperLU default" if ratio else None,
                f"{n}^3 cubes, auto solver" + (f", Newton its {r.iterations}" if r else ""))
        if n in lu_sizes:
            res.add(f"static_solve_superlu_{dofs[-1]}_dofs", lu_times[n], "s", 1.0, "itself")
    slope = float(np.polyfit(np.log(dofs), np.log(times), 1)[0])
    res.add("static_solve_scaling_exponent", slope, "", None, None,
            f"log-log fit over {dofs[0]}..{dofs[-1]} dofs; target <= 1.2")
    if len(lu_times) >= 2:
        ld = [int(cube_under_gravity(n).free.sum()) for n in lu_times]
        sl = float(np.polyfit(np.log(ld), np.log(list(lu_times.values())), 1)[0])
        res.add("static_solve_superlu_scaling_exponent", sl, "", None, None, f"over {ld[0]}..{ld[-1]} dofs")


def cantilever(kind: str):
    """Baudet's cantilever: 16 x 4 x 4 cubes, 400 x 100 x 100 mm, E = 1000 Pa, nu = 0.3, total
    mass 0.0125 kg, clamped at x = 0, gravity -z."""
    mesh = M.hex_grid(0.4, 0.1, 0.1, 16, 4, 4)
    rho = 0.0125 / (0.4 * 0.1 * 0.1)
    if kind == "baudet":
        terms = MD.baudet_cube_springs(mesh, [(1000.0, 0.3)])
    else:
        terms = MD.golec_cube_springs(mesh, [(1000.0, 0.3)], 1.0)
    masses = M.lumped_masses(mesh, rho)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 0] < 1e-12] = True
    return MD.Model(mesh, terms + [T.Gravity(masses, [0.0, 0.0, -9.81])], fixed=fixed, masses=masses)


def run_cantilever(res, quick: bool):
    for kind in ("baudet", "golec"):
        model = cantilever(kind)
        t = median_time(lambda: S.static_solve(model, model.x0), repeat=5 if quick else 9, warmup=2)
        t_lu = median_time(lambda: S.static_solve(model, model.x0, linear_solver=superlu_default), repeat=3)
        r = S.static_solve(model, model.x0)
        tip = float(-(r.x - model.x0).reshape(-1, 3)[:, 2].min())
        res.add(f"cantilever_static_{kind}", t * 1e3, "ms", t_lu / t, "same with scipy SuperLU default",
                f"Newton its {r.iterations}, tip deflection {tip * 1e3:.1f} mm; target <= 50 ms")
