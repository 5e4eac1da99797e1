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



# --------------------------------------------------------------------------------------------
# the quadratic neo-Hookean reference at 13 k, 100 k and 300 k dofs
# --------------------------------------------------------------------------------------------

#: tet_grid cells per side whose quadratic (P2) elements have about 13 k, 100 k and 300 k dofs
REFERENCE_SIZES = (8, 16, 23)
REFERENCE_TIMEOUT = 240.0  # s per size: a slower case is reported as "> REFERENCE_TIMEOUT s"


def _cube_scene(n, model):
    """A 10 cm cube of 6 n^3 tetrahedra (E = 1 MPa, nu = 1/4, where Lloyd's tetrahedra are exact),
    clamped at z = 0, under a body force of 10^4 N/m^3 (strain about 10^-3: a few Newton
    iterations)."""
    return {"name": "cube", "geometry": {"generator": "tet_grid",
                                         "args": {"lx": 0.1, "ly": 0.1, "lz": 0.1, "nx": n, "ny": n, "nz": n}},
            "materials": [{"E": 1.0e6, "nu": 0.25, "density": 1000.0}], "model": model,
            "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
            "loads": [{"type": "gravity", "g": [0.0, 0.0, -10.0]}],
            "solver": {"type": "static", "load_steps": 1, "tol": 1.0e-8}}


def reference_case(n: int) -> dict:
    """One size: the quadratic neo-Hookean reference (:func:`msslib.planning.reference.solve_setup`,
    one load step) on 6 n^3 tetrahedra, its Newton iterations' linear solves timed one by one
    (the first: one Newton solve, the tangent factorised or its preconditioner built from
    scratch), the rest (residual and tangent assembly, the convergence test) as assembly; and
    the MSS (Lloyd's tetrahedra, static Newton) on the mesh of 6 (2 n)^3 tetrahedra, whose nodes
    are the reference's dofs (the same number of unknowns).  Warmed up (compiled) on n = 2."""
    import msslib.solvers.statics as statics
    from msslib.planning.reference import solve_setup
    from msslib.scene import load_scene, prepare, run_scene

    solves = []
    real = statics.solve_linear_system

    def timed(*args, **kw):
        t0 = time.perf_counter()
        try:
            return real(*args, **kw)
        finally:
            solves.append(time.perf_counter() - t0)

    statics.solve_linear_system = timed
    for size in (2, n):
        solves.clear()
        setup = prepare(load_scene(_cube_scene(size, "fem_neohookean")))
        t0 = time.perf_counter()
        res = solve_setup(setup, order=2, law="neohookean", steps=1, tol=1e-8)
        wall = time.perf_counter() - t0
    statics.solve_linear_system = real
    out = {"n": n, "dofs": int(res.stats["n_free_dofs"]), "wall_s": wall, "first_solve_s": solves[0],
           "solves_s": sum(solves), "n_solves": len(solves), "assembly_s": wall - sum(solves),
           "iterations": res.stats["iterations"], "messages": res.stats["messages"]}
    for size in (2, 2 * n):
        r = run_scene(load_scene(_cube_scene(size, "lloyd_tetrahedron")), progress=False)
    out["mss_dofs"] = 3 * int(r.sizes.get("node", 0)) if hasattr(r, "sizes") else None
    out["mss_wall_s"] = float(r.attrs["solver_wall_time"])
    return out


def reference_table(sizes=REFERENCE_SIZES, timeout=REFERENCE_TIMEOUT):
    """Each size in its own process (a fresh heap; stopped after ``timeout`` s)."""
    import json
    import subprocess
    import sys

    rows = []
    for n in sizes:
        try:
            p = subprocess.run([sys.executable, "-m", "benchmarks.fem_solvers", "--reference", str(n)],
                               capture_output=True, text=True, timeout=timeout)
            line = [ln for ln in p.stdout.splitlines() if ln.startswith("{")]
            rows.append(json.loads(line[-1]) if line else {"n": n, "error": p.stderr.strip().splitlines()[-1:]})
        except subprocess.TimeoutExpired:
            rows.append({"n": n, "timeout_s": timeout})
    return rows


def print_reference_table(rows):
    print("| tets per side | reference free dofs (P2) | one Newton solve | Newton: solves / assembly and rest / all "
          "| MSS dofs | MSS static solve |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        if "timeout_s" in r:
            print(f"| {r['n']} | | > {r['timeout_s']:.0f} s | > {r['timeout_s']:.0f} s in all | | |")
        elif "error" in r:
            print(f"| {r['n']} | failed: {r['error']} | | | | |")
        else:
            print(f"| {r['n']} | {r['dofs']} | {r['first_solve_s']:.3g} s | {r['solves_s']:.3g} s ({r['n_solves']}) / "
                  f"{r['assembly_s']:.3g} s / {r['wall_s']:.3g} s | {r['mss_dofs']} | {r['mss_wall_s']:.3g} s |",
                  flush=True)


#: the same table measured on the code before the references moved to MKL Pardiso and the compiled
#: tangent assembly (SuperLU fallback, einsum element matrices and a COO sort per iteration); same
#: machine (2 cores, one thread each, the other core busy): size -> (one Newton solve, all linear
#: solves, assembly and the rest, whole reference solve), in s
BEFORE = {8: (0.177, 0.271, 1.49, 1.76), 16: (0.909, 2.18, 26.1, 28.3), 23: (2.75, 8.01, 98.7, 107.0)}


def run_reference(res, quick: bool):
    """``python -m benchmarks --only reference``: the table of :func:`reference_table` as figures,
    with the time before (:data:`BEFORE`) as the baseline."""
    rows = reference_table(REFERENCE_SIZES[:1] if quick else REFERENCE_SIZES)
    print_reference_table(rows)
    for r in rows:
        n = r["n"]
        if "dofs" not in r:
            res.add(f"reference_p2_n{n}_wall", float("nan"), "s", note=f"not measured: {r}")
            continue
        before = BEFORE.get(n)
        tag = f"reference_p2_{r['dofs']}dofs"
        for key, k in (("first_solve_s", 0), ("solves_s", 1), ("assembly_s", 2), ("wall_s", 3)):
            ratio = None if before is None else before[k] / r[key]
            res.add(f"{tag}_{key[:-2]}", r[key], "s", ratio=ratio, baseline=None if before is None else
                    f"before: {before[k]:.3g} s", note="quadratic neo-Hookean reference, one load step")
        res.add(f"mss_lloyd_{r['mss_dofs']}dofs_static_solve", r["mss_wall_s"], "s",
                note="Lloyd's tetrahedra on the mesh whose nodes are the reference's dofs")


if __name__ == "__main__" and "--reference" in __import__("sys").argv:
    import json
    import sys

    print(json.dumps(reference_case(int(sys.argv[sys.argv.index("--reference") + 1])), default=str))
    sys.exit(0)


if __name__ == "__main__":
    main()
