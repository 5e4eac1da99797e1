"""Cost per step of the exact edge-based tetrahedron (``kikuuwe_tetrahedron``) against the St
Venant-Kirchhoff FEM (``fem_svk``, the same element in another basis) and Lloyd's springs
(``lloyd_tetrahedron``) on the same meshes: the cylinder scene of the fronts
(``scenes/cylinder.yaml``, its traction scaled by ``LOAD_SCALE``) on levels 0-2 (its mesh refined
uniformly 0-2 times, as in the front).

Each model's static solve is run once (by :func:`msslib.scene.run_scene`); at its solution the
study times, single-threaded, with ``REPEATS`` repeats each (median, smallest and largest CPU time
of the repeats; every part is called once untimed first):

* ``force``: one evaluation of the internal forces, the cost of an explicit step (the integrator
  adds a few vector operations of the number of dofs);
* ``tangent``: one evaluation of the tangent stiffness matrix (the MSS's ``Model.stiffness``;
  FEM: forces, energy and tangent, the one call its Newton iteration makes);
* ``solve``: one solve with that tangent on the free dofs by the solver layer both use
  (:func:`msslib.fem.newton.linear_solve`, the policy of :mod:`msslib.solvers`), the load as
  right-hand side;
* ``newton_step``: the three for an MSS, tangent and solve for FEM (whose tangent call returns
  its forces too);
* ``element_loop`` and ``assembly``: the tangent split into the per-element work and the scatter
  into the sparse matrix. Kikuuwe's tetrahedron: the term's element Hessians (``hessian_values``)
  and the rest of ``Model.stiffness`` (scatter); FEM: the material law, stresses and forces at the
  quadrature points, and the compiled kernel that forms the element matrices and adds them into
  the matrix (``msslib.fem.kernels.add_tangent``); Lloyd's springs fill the matrix in one kernel
  (NaN).

``equal_to_fem_svk``: the largest node distance between the Kikuuwe and the FEM solution relative
to the largest displacement (the same element: round-off). ``diagonal_over_lloyd``: on the regular
tetrahedron, the diagonal of Kikuuwe's quadratic form taken as a linear spring (``2 k_e l^2``, the
Hessian at rest of ``k_e D^2 / 4``) over Lloyd's eq. 12 constant ``2 sqrt(2) E l / 25``, for the
values of ``nu`` of the coordinate ``nu``; the derivation gives 55/48 at ``nu = 1/4``.
"""

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_v, "1")  # single thread, before numpy is imported

import time
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from experiments import script

HERE = Path(__file__).resolve().parents[1]
SCENE = HERE / "scenes" / "cylinder.yaml"
MODELS = ("kikuuwe_tetrahedron", "fem_svk", "lloyd_tetrahedron")
PARTS = ("force", "tangent", "solve", "newton_step", "element_loop", "assembly")
REPEATS = 9
#: the cylinder's traction scaled: at the full 5 % of E the St Venant-Kirchhoff element (Kikuuwe's and
#: FEM's alike) inverts cells on level 1 and does not converge on level 2 (the fronts); a step costs
#: the same in any state, so the parts are timed at the solution under a tenth of the load
LOAD_SCALE = 0.1
NU = (0.0, 0.25, 0.3, 0.45)


def _times(fn, repeats):
    """``(median, min, max)`` CPU time of ``repeats`` calls of ``fn`` after one untimed call."""
    fn()
    out = []
    for _ in range(repeats):
        c0 = time.process_time()
        fn()
        out.append(time.process_time() - c0)
    return float(np.median(out)), float(min(out)), float(max(out))


def _stat(samples):
    return float(np.median(samples)), float(min(samples)), float(max(samples))


def _fem_parts(sc, base_dir):
    """The FEM solve, and a function timing its parts at the solution (``repeats`` -> parts):
    the Newton iteration's ``internal(u, tangent)`` is taken from the solve itself
    (``newton_solve`` wrapped)."""
    import msslib.fem.newton as newton
    from msslib.scene import load_scene, run_scene

    seen, original = {}, newton.newton_solve

    def capture(internal, f_ext, constrained, prescribed, points, **kw):
        seen.update(internal=internal, f_ext=f_ext, free=~np.asarray(constrained), points=points)
        u, stats = original(internal, f_ext, constrained, prescribed, points, **kw)
        seen["u"] = u
        return u, stats

    newton.newton_solve = capture
    try:
        ds = run_scene(load_scene(sc, base_dir=base_dir), progress=False)
    finally:
        newton.newton_solve = original
    internal, u, free, points = seen["internal"], seen["u"], seen["free"], seen["points"]
    return ds, lambda repeats: _fem_timing(internal, u, free, points, seen["f_ext"], repeats)


def _fem_timing(internal, u, free, points, f_ext, repeats):
    import msslib.fem.kernels as kernels
    import msslib.fem.newton as newton

    spent, original_add = [0.0], kernels.add_tangent

    def timed_add(*a):
        c0 = time.process_time()
        original_add(*a)
        spent[0] += time.process_time() - c0

    kernels.add_tangent = timed_add
    try:
        internal(u, tangent=True)
        total, scatter = [], []
        for _ in range(repeats):
            spent[0] = 0.0
            c0 = time.process_time()
            internal(u, tangent=True)
            total.append(time.process_time() - c0)
            scatter.append(spent[0])
    finally:
        kernels.add_tangent = original_add
    fint, K, _, _ = internal(u, tangent=True)
    rhs = np.asarray(f_ext)[free]  # the load: the same right-hand side as the MSS's
    return {"force": _times(lambda: internal(u, tangent=False), repeats), "tangent": _stat(total),
           "solve": _times(lambda: newton.linear_solve(K, rhs, free, points, 3), repeats),
           "element_loop": _stat(np.subtract(total, scatter)), "assembly": _stat(scatter)}


def _mss_parts(sc, base_dir):
    """The MSS solve, and a function timing its parts at the solution (``repeats`` -> parts)."""
    from msslib.scene import load_scene, prepare, run_scene

    ds = run_scene(load_scene(sc, base_dir=base_dir), progress=False)
    model = prepare(load_scene(sc, base_dir=base_dir)).model
    x = model.x0 + ds["displacement"].values.ravel()
    return ds, lambda repeats: _mss_timing(model, x, repeats)


def _mss_timing(model, x, repeats):
    from msslib.fem.newton import linear_solve
    from msslib.terms.edges import EdgeQuadraticEnergy

    K = model.stiffness(x)
    rhs = model.external_force()[model.free]  # the load (at the solution the residual is round-off)
    points = model.x0.reshape(-1, 3)
    out = {"force": _times(lambda: model.force(x), repeats), "tangent": _times(lambda: model.stiffness(x), repeats),
           "solve": _times(lambda: linear_solve(K, rhs, model.free, points, 3), repeats)}
    edge = [t for t in model.terms if isinstance(t, EdgeQuadraticEnergy)]
    if edge:  # the element Hessians alone; the rest of stiffness() is the scatter into the matrix
        loop = _times(lambda: [t.hessian_values(x) for t in edge], repeats)
        out["element_loop"] = loop
        out["assembly"] = tuple(max(out["tangent"][0] - loop[0], 0.0) for _ in range(3))
    return out


def diagonal_over_lloyd(nu):
    """Kikuuwe's diagonal on the regular tetrahedron of edge 1 as a linear spring, over Lloyd's eq. 12."""
    from msslib.models.kikuuwe import kikuuwe_tetrahedron
    from msslib.models.lloyd import lloyd_tetrahedron

    c = kikuuwe_tetrahedron(1.0, nu=nu, a=1.0, x2=0.5, y2=3 ** 0.5 / 2, x3=0.5, y3=3 ** 0.5 / 6, z3=(2 / 3) ** 0.5)
    diag = [float(c[f"k_{e}"]) for e in ("01", "02", "03", "12", "13", "23")]
    assert np.ptp(diag) < 1e-12 * max(diag)  # every edge of the regular tetrahedron alike
    return 2.0 * diag[0] / float(lloyd_tetrahedron(1.0, l=1.0).k)


def measure(levels, repeats, progress=print):
    from msslib.planning.front import at_level

    raw = yaml.safe_load(SCENE.read_text())
    for load in raw["loads"]:
        load["traction"] = [LOAD_SCALE * float(v) for v in load["traction"]]
    shape = (len(MODELS), len(levels), len(PARTS))
    med, lo, hi = (np.full(shape, np.nan) for _ in range(3))
    dofs, cells, equal = [], [], []
    for j, level in enumerate(levels):
        u, timers = {}, {}
        for model in MODELS:  # every solve first, so that every part is timed in the same state
            sc = at_level(raw, level + 1, model)
            ds, timers[model] = (_fem_parts if model.startswith("fem_") else _mss_parts)(sc, SCENE.parent)
            u[model] = ds["displacement"].values
        for i, model in enumerate(MODELS):
            parts = timers[model](repeats)
            step = ("tangent", "solve") if model.startswith("fem_") else ("force", "tangent", "solve")
            parts["newton_step"] = tuple(sum(parts[p][k] for p in step) for k in range(3))
            for k, part in enumerate(PARTS):
                if part in parts:
                    med[i, j, k], lo[i, j, k], hi[i, j, k] = parts[part]
            progress(f"level {level} {model}: " + ", ".join(f"{p} {1e3 * parts[p][0]:.3g} ms" for p in parts))
        dofs.append(u[MODELS[0]].size)
        cells.append(int(ds["cells"].shape[0]))
        scale = np.abs(u["fem_svk"]).max()
        equal.append(float(np.linalg.norm(u["kikuuwe_tetrahedron"] - u["fem_svk"], axis=1).max() / scale))
    kind = "CPU time"
    coords = {"model": list(MODELS), "level": list(levels), "part": list(PARTS), "nu": list(NU)}
    ds = xr.Dataset({
        "time_median": (("model", "level", "part"), med, {"units": "s", "long_name": f"median {kind} of the repeats"}),
        "time_min": (("model", "level", "part"), lo, {"units": "s", "long_name": f"smallest {kind} of the repeats"}),
        "time_max": (("model", "level", "part"), hi, {"units": "s", "long_name": f"largest {kind} of the repeats"}),
        "n_dofs": (("level",), np.array(dofs), {"units": "1", "long_name": "degrees of freedom"}),
        "n_cells": (("level",), np.array(cells), {"units": "1", "long_name": "tetrahedra"}),
        "equal_to_fem_svk": (("level",), np.array(equal), {
            "units": "1", "long_name": "max node distance of the kikuuwe_tetrahedron and fem_svk solutions / max displacement"}),
        "diagonal_over_lloyd": (("nu",), np.array([diagonal_over_lloyd(nu) for nu in NU]), {
            "units": "1", "long_name": "Kikuuwe's diagonal on the regular tetrahedron as a linear spring (2 k_e l^2) "
                                       "over Lloyd's eq. 12 constant"}),
    }, coords=coords, attrs={"title": "cost per step: kikuuwe_tetrahedron, fem_svk, lloyd_tetrahedron",
                             "description": (__doc__ or "").strip().split("\n\n")[0], "repeats": int(repeats),
                             "scene_file": "experiments/performance/scenes/cylinder.yaml", "load_scale": LOAD_SCALE,
                             "timing": "cpu",
                             "threads": os.environ.get("OMP_NUM_THREADS", "default")})
    for k, part in enumerate(PARTS):  # the ratios the paper quotes, at the finest level
        for other in ("fem_svk", "lloyd_tetrahedron"):
            ds.attrs[f"{part}_{other}_over_kikuuwe"] = float(med[MODELS.index(other), -1, k] / med[0, -1, k])
    return ds


def main():
    from msslib.results import write_result

    a = script.args("cost per step of the exact edge-based tetrahedron")
    t0 = time.perf_counter()
    ds = measure((0, 1) if a.quick else (0, 1, 2), 3 if a.quick else REPEATS, progress=lambda s: print(s, flush=True))
    ds.attrs["wall_time_s"] = time.perf_counter() - t0
    if a.quick:
        ds.attrs["quick"] = 1
    write_result(a.out, ds)


if __name__ == "__main__":
    main()
