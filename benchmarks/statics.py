"""3-4: static solve scaling and the cantilever under gravity."""

from __future__ import annotations

import subprocess
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from msslib.models.baudet import baudet_cube_springs
from msslib.models.golec import golec_cube_springs
from msslib import mesh as M
from msslib import system as MD
from msslib import solvers as S
from msslib import terms as T

from .common import median_time


def superlu_default(A, b):
    """Baseline linear solver: scipy's splu with its default (COLAMD) ordering."""
    return spla.splu(sp.csc_matrix(A)).solve(np.asarray(b, dtype=float))


def cube_under_gravity(n: int, E: float = 1e4, nu: float = 0.25, rho: float = 1000.0, side: float = 0.1):
    """A cube of ``side`` (m) made of n^3 Golec cubes (nu = 1/4: springs only, kappa = 0), clamped
    at z = 0, gravity -z.

    The body is the same at every n (mesh refinement), so the nonlinearity (bottom strain about
    rho g side / E ~ 0.1) and hence the Newton iteration count do not change with the size.  (With
    cells of fixed 1 cm, the earlier set-up, the body grows with n: from n ~ 30 on the self-weight
    exceeds the collapse load of the lattice -- load stepping at n = 32 converges up to load factor
    0.75 and then finds no equilibrium -- so the large sizes had no solution to time.)"""
    a = side / n
    mesh = M.hex_grid(n * a, n * a, n * a, n, n, n)
    springs = golec_cube_springs(mesh, [(E, nu)], 1.0)[0]
    masses = M.lumped_masses(mesh, rho)
    fixed = np.zeros((mesh.n_nodes, 3), dtype=bool)
    fixed[mesh.points[:, 2] < 1e-12] = True
    return MD.Model(mesh, [springs, T.Gravity(masses, [0.0, 0.0, -9.81])], fixed=fixed, masses=masses)


def run_scaling(res, quick: bool):
    """Whole static solves (auto linear solver) from ~10^3 to 3 x 10^5 free dofs (quick: up to
    ~10^4), with the log-log exponent of time vs dofs; scipy's default SuperLU as the baseline on
    the small sizes, with its own exponent.

    Two times per size, each fitted on its own: *cold*, the first solve on a freshly built model
    (the free-dof extraction plan, the band ordering and the AMG set-up included), and *warm*,
    a repeated solve of the same model (those plans cached, as in load stepping, time stepping
    and parameter sweeps).  Building the model (its sparsity pattern) is not timed."""
    # 7^3 cubes: 1,344 free dofs, the smallest size at or above 10^3; 46^3: 304,842
    sizes = [7, 10, 15] if quick else [7, 10, 15, 22, 32, 46]
    lu_sizes = [7, 10] if quick else [7, 10, 15]
    dofs, cold, warm, lu_dofs, lu_times, cg_sizes = [], [], [], [], [], []
    for n in sizes:
        rep = 9 if n <= 10 else (3 if n <= 15 else 1)  # cheap sizes: more repeats (their spread moves the fit)
        colds = []
        for _ in range(rep):  # cold: a new model each time
            model = cube_under_gravity(n)
            t0 = time.perf_counter()
            S.static_solve(model, model.x0)
            colds.append(time.perf_counter() - t0)
        runs = []

        def solve(model=model, runs=runs):
            runs.append(S.static_solve(model, model.x0))

        t = median_time(solve, repeat=max(rep, 3), warmup=0)  # warm: at least 3 (shared hosts)
        r = runs[-1]
        nd = int(model.free.sum())
        dofs.append(nd)
        warm.append(t)
        cold.append(float(np.median(colds)))
        if r.cg_iterations:
            cg_sizes.append(len(dofs) - 1)
        ratio = None
        if n in lu_sizes:
            t_lu = median_time(lambda model=model: S.static_solve(model, model.x0, linear_solver=superlu_default),
                               repeat=3 if n <= 10 else 1, warmup=0)
            lu_dofs.append(nd)
            lu_times.append(t_lu)
            ratio = t_lu / t
        res.add(f"static_solve_{nd}_dofs", t, "s", ratio, "scipy SuperLU default" if ratio else None,
                f"warm; {n}^3 cubes, {nd} dofs, auto solver, Newton its {r.total_iterations}, "
                f"CG its {r.cg_iterations}, final residual {r.residuals[-1][-1] / r.force_scale:.1e} F_ref; "
                f"cold (first solve of a new model) {cold[-1]:.3g} s")
        if n in lu_sizes:
            res.add(f"static_solve_superlu_{nd}_dofs", lu_times[-1], "s", 1.0, "itself")
        del model, runs, solve  # free this size's model before the next
    big = "" if quick else f" ({dofs[-1]} dofs)"
    for label, times in (("warm", warm), ("cold", cold)):
        slope = float(np.polyfit(np.log(dofs), np.log(times), 1)[0])
        res.add(f"static_solve_scaling_exponent_{label}", slope, "", None, None,
                f"{label} solves, log-log fit over {dofs[0]}..{dofs[-1]} dofs ({len(dofs)} sizes)",
                target=("<=", 1.2, "value"))
        if not quick:
            res.add(f"static_solve_largest_{label}", times[-1], "s", None, None, f"{label} solve{big}",
                    target=("<=", 20.0, "value"))
    # what "cold" pays beyond "warm" at large sizes is mostly memory touched for the first time:
    # measure the cost of a page on first touch in a fresh process and once memory is recycled
    code = ("import numpy as np, time\n"
            "for _ in range(2):\n"
            "    t = time.perf_counter(); a = np.ones(1 << 25); dt = time.perf_counter() - t\n"
            "    print(dt / (a.nbytes / 4096) * 1e6); del a\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    first, again = float(out[0]), float(out[1])
    res.add("page_first_touch_cost", first, "us per 4 KiB page", None, None,
            f"256 MB of new memory in a fresh process; {again:.2f} us per page for the same allocation "
            f"repeated in that process ({first / again:.0f}x less): cold solves at large sizes pay the first")
    if len(cg_sizes) >= 2:  # the sizes where "auto" chose AMG-preconditioned CG
        d = [dofs[i] for i in cg_sizes]
        ci = float(np.polyfit(np.log(d), np.log([warm[i] for i in cg_sizes]), 1)[0])
        res.add("static_solve_scaling_exponent_cg_sizes", ci, "", None, None,
                f"warm, log-log fit over the AMG-CG sizes {d[0]}..{d[-1]} dofs (smaller ones: banded Cholesky)")
    if len(lu_times) >= 2:
        sl = float(np.polyfit(np.log(lu_dofs), np.log(lu_times), 1)[0])
        res.add("static_solve_superlu_scaling_exponent", sl, "", None, None,
                f"over {lu_dofs[0]}..{lu_dofs[-1]} dofs")


def cantilever(kind: str):
    """Baudet's cantilever: 16 x 4 x 4 cubes, 400 x 100 x 100 mm, E = 1000 Pa, nu = 0.3, total
    mass 0.0125 kg, clamped at x = 0, gravity -z."""
    mesh = M.hex_grid(0.4, 0.1, 0.1, 16, 4, 4)
    rho = 0.0125 / (0.4 * 0.1 * 0.1)
    if kind == "baudet":
        terms = baudet_cube_springs(mesh, [(1000.0, 0.3)])
    else:
        terms = golec_cube_springs(mesh, [(1000.0, 0.3)], 1.0)
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
                f"Newton its {r.iterations}, tip deflection {tip * 1e3:.1f} mm, after warm-up",
                target=("<=", 50, "value"))
