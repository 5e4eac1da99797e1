"""FEM reference solves before and after moving them onto msslib.solvers:
``python -m benchmarks.fem_solvers`` (single thread).

A clamped block of n^3 hexahedra (Q1) or 6 n^3 tetrahedra (P1) under gravity: the free-dof
system of linear elasticity solved by SuperLU (the references' solver before, MMD_AT_PLUS_A
ordering) and by the policy of msslib.solvers (what the references use now: banded Cholesky,
SuperLU or AMG-preconditioned CG), and the whole non-linear neo-Hookean solve (assembly, Newton,
linear solves; one load step) with direct solves (before) and with the policy (now).  Times
are the best of three; the linear solve excludes the assembly.
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_v, "1")

import time

import numpy as np


def _best(fn, repeat=3):
    out, best = None, np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def block(cell, n):
    from msslib import fem
    from msslib.fem import space as fem_space
    from msslib import mesh as M

    m = (M.hex_grid if cell == "hexahedron" else M.tet_grid)(0.1, 0.1, 0.1, n, n, n)
    fixed = np.zeros((m.n_nodes, 3), dtype=bool)
    fixed[m.points[:, 2] < 1e-12] = True
    geo = fem_space._Geometry(m)
    lam, mu = fem.lame(np.full(m.n_cells, 1e6), np.full(m.n_cells, 0.3))
    K = fem_space._linear_stiffness(geo, lam, mu)
    f = geo.body_load([0.0, 0.0, -1e4], 1.0).ravel()
    return m, fixed, geo, K, f


def main():
    from msslib import fem
    from msslib.fem.newton import linear_solve

    print("| mesh | free dofs | linear solve: SuperLU (before) | policy (now) | non-linear solve: direct (before) "
          "| policy (now) |")
    print("|---|---|---|---|---|---|")
    for cell, n in (("hexahedron", 8), ("hexahedron", 12), ("hexahedron", 16), ("tetra", 12)):
        m, fixed, geo, K, f = block(cell, n)
        free = ~fixed.ravel()
        Kff = K[free][:, free]
        t_lu, u_lu = _best(lambda: fem.solve_sparse(Kff, f[free]))
        t_new, (u_new, how) = _best(lambda: linear_solve(K, f[free], free, geo.points, 3))
        assert np.abs(u_new - u_lu).max() <= 1e-8 * np.abs(u_lu).max()
        kw = dict(fixed=fixed, body_force=[0.0, 0.0, -1e4], law="neohookean", steps=1)
        t_nd, _ = _best(lambda: fem.solve_nonlinear(m, 1e6, 0.3, linear_solver="direct", **kw), 2)
        t_na, _ = _best(lambda: fem.solve_nonlinear(m, 1e6, 0.3, **kw), 2)
        print(f"| {cell} {n}^3 | {int(free.sum())} | {t_lu:.3g} s | {t_new:.3g} s ({how}) | {t_nd:.3g} s | "
              f"{t_na:.3g} s |", flush=True)


if __name__ == "__main__":
    main()
