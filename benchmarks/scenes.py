"""6: the static scenes of the performance study, mass-spring models against linear FEM.

Each scene of ``experiments/performance/scenes`` (the tetrahedral cylinder sheared by a top
traction of 5 % of E, the hexahedral cantilever under its weight) is run as ``msslib run`` runs
it (:func:`msslib.scene.run_scene`: mesh, model, load-stepped Newton, checks), at the resolution
levels of the study (``msslib.planning.refine``), with every mass-spring model of its cells and
with linear FEM on the same mesh.  The time is the run's ``wall_time_s`` (mesh, model and solve;
the result dataset is not written), the best of 3 runs (quick: 2) after one warm-up run in this
process (the warm-up pays numba's one-off start, ~0.5-1 s per process).  The ratio is FEM time / MSS time.

Also: the banded Cholesky of one Newton matrix of the cylinder (level 2, bandwidth 242) with the
BLAS pool at two threads against one (the solver now always factorises bands on one thread:
``msslib.solvers.blas_threads``).  The two-thread time depends on what else runs on the cores: on an
idle machine the two are close; on busy cores two threads took up to 2.4 s against 1.7 ms.
"""

from __future__ import annotations

import copy
import os
import time
import warnings
from pathlib import Path

import numpy as np
import yaml

SCENES = Path(__file__).resolve().parents[1] / "experiments" / "performance" / "scenes"
CASES = {  # scene: (levels, quick levels, mass-spring models)
    "cylinder": ((1, 2, 3), (1, 3), ("lloyd_tetrahedron", "lloyd_tetrahedron_volume")),  # 3: AMG-CG
    "cantilever": ((1, 2, 4), (1, 2), ("baudet_cube", "golec_cube")),
}


def _scene(name, level, model):
    from msslib.planning import refine

    raw = yaml.safe_load((SCENES / f"{name}.yaml").read_text())
    out = refine(copy.deepcopy(raw), level)
    out["model"] = model
    return out


def _best_run(raw, repeat=3):
    from msslib.scene import load_scene, run_scene

    scene = load_scene(raw, base_dir=SCENES)
    best, ds = np.inf, None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a flagged (inverted) state is recorded in the dataset
        for _ in range(repeat + 1):  # the first one warms up (numba start, gmsh)
            ds = run_scene(scene, progress=False)
            best = min(best, float(ds.attrs["wall_time_s"]))
    return best, ds


def _newton_counts(raw):
    """Newton iterations per load step and CG iterations of the scene's static solve."""
    from msslib.scene import load_scene, prepare
    from msslib.solvers import static_solve

    scene = load_scene(raw, base_dir=SCENES)
    model, s = prepare(scene).model, scene.solver
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = static_solve(model, model.x0, load_steps=s["load_steps"], tol=s["tol"], max_iter=s["max_iter"])
    return list(r.iterations), r.cg_iterations, int(model.free.sum())


def run(res, quick: bool):
    repeat = 2 if quick else 3
    for name, (levels, quick_levels, models) in CASES.items():
        for level in quick_levels if quick else levels:
            t_fem, _ = _best_run(_scene(name, level, "fem_linear"), repeat)
            res.add(f"scene_{name}_L{level}_fem_linear", t_fem * 1e3, "ms", 1.0, "itself",
                    "linear FEM, the same mesh and loads: one sparse solve")
            for model in models:
                raw = _scene(name, level, model)
                t, ds = _best_run(raw, repeat)
                its, cg, n_free = _newton_counts(raw)
                solver = f"AMG-CG ({cg} CG its)" if cg else "direct (banded Cholesky or sparse LU)"
                bad = int(ds.attrs.get("inverted_cells", 0))
                res.add(f"scene_{name}_L{level}_{model}", t * 1e3, "ms", t_fem / t, "linear FEM of the same mesh",
                        f"{n_free} free dofs, Newton its per load step {its}, {solver}, best of {repeat} after a warm-up"
                        + (f"; final state has {bad} inverted cells" if bad else ""))
    _band_threads(res)


def _band_threads(res):
    """The banded Cholesky of the cylinder's level-2 stiffness at rest with two BLAS threads and
    with one (median of 7 each, interleaved)."""
    import scipy.sparse as sp
    from scipy.linalg import cholesky_banded
    from threadpoolctl import ThreadpoolController

    from msslib import solvers as S
    from msslib.scene import load_scene, prepare

    raw = _scene("cylinder", 2, "lloyd_tetrahedron")
    model = prepare(load_scene(raw, base_dir=SCENES)).model
    ctx = S.context.linear_solve_context(model, model.x0, model.free)
    A = sp.csr_matrix(S.submatrices.submatrix(model.stiffness(model.x0, 0.0), model.free))
    A.sort_indices()
    plan = S.direct._band_plan(A, ctx)
    n, bw = A.shape[0], plan["bw"]
    ab = np.zeros((bw + 1, n), order="F")
    ab.reshape(-1, order="F")[plan["dst"]] = A.data[plan["src"]]
    ctl = ThreadpoolController()
    times = {1: [], 2: []}
    for _ in range(7):
        for threads in (2, 1):
            with ctl.limit(limits=threads, user_api="blas"):
                t = time.perf_counter()
                cholesky_banded(ab, lower=True, check_finite=False)
                times[threads].append(time.perf_counter() - t)
    one, two = float(np.median(times[1])), float(np.median(times[2]))
    res.add("banded_cholesky_one_blas_thread", one * 1e3, "ms", two / one, "two BLAS threads",
            f"cylinder level 2, {n} dofs, bandwidth {bw}; two threads: median {two * 1e3:.3g} ms, "
            f"max {max(times[2]) * 1e3:.3g} ms; load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
