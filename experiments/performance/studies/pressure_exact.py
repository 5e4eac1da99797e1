"""Pressure against exact solutions: every mass-spring model on its cells, linear FEM and the
quadratic reference (reduced volumetric rule), each under an internal pressure on a thick-walled
body whose linear-elastic solution is known in closed form (:mod:`msslib.fem.exact`):

* ``cylinder``: Lame's thick cylinder (radii 1 and 2) in plane stress on a quarter annulus of
  triangles or quads (``n`` cells through the wall, ``2 n`` around), symmetry supports;
* ``sphere``: the thick sphere (radii 1 and 2) on a gmsh octant of tetrahedra of size ``h``.

The quadratic reference runs twice: with straight-sided elements, as on a user's mesh
(``fem_quadratic``), and with the quadratic nodes of both walls on their circle or sphere
(``fem_quadratic_curved``, isoparametric).  Every run is small strain: the mass-spring models by the scene's linear static solve (one solve
with the stiffness at rest) of a dead pressure on the inner wall (the scene's ``pressure`` load on
the mesh's facet group ``inner``), the FEM ones by :func:`msslib.fem.solve_linear` on the same
facets.  The error is the largest nodal displacement error over the largest exact nodal
displacement (``error_max``), the root mean square of the nodal errors over that of the exact
displacements (``error_rms``), both at the mesh's nodes, and the largest nodal difference from the
quadratic reference on the same mesh over its largest displacement (``error_max_vs_fem``); a model that refuses the mesh or does
not converge gets NaN and its reason in ``outcome``.

``python -m experiments.performance.studies.pressure_exact --out F.nc [--quick]`` writes a NetCDF dataset
(dimension ``run``: problem, cells, level, n_nodes, run_model, run_nu, the errors, outcome; and the
finest level's errors and the observed orders per ``case``, ``model`` and ``nu``: :func:`summary`).
"""

from __future__ import annotations

import sys
from dataclasses import replace
from functools import partial

import numpy as np

A, B, P, E = 1.0, 2.0, 1.0e3, 1.0e6
NUS = (0.3, 0.49, 0.4999)
LEVELS = {"cylinder": (4, 8, 16), "sphere": (0.4, 0.2)}
QUICK = {"cylinder": (4, 8), "sphere": (0.4,)}


def problems(quick: bool):
    """``(problem, cells, level, mesh, exact(nu))`` of every run's geometry."""
    from msslib.fem import exact

    levels = QUICK if quick else LEVELS
    for cells in ("triangle", "quad"):
        for n in levels["cylinder"]:
            mesh = exact.quarter_annulus(A, B, n, cells)
            yield "cylinder", cells, float(n), mesh, lambda nu: partial(plane_stress_cylinder, nu=nu)
    for h in levels["sphere"]:
        mesh = exact.sphere_octant(A, B, h)
        yield "sphere", "tetra", float(h), mesh, lambda nu: partial(exact.sphere_displacement, a=A, b=B, p=P, E=E,
                                                                      nu=nu)


def plane_stress_cylinder(X, nu):
    """Lame's cylinder in plane stress: the plane-strain field of ``E* = E (1 + 2 nu) / (1 + nu)^2``,
    ``nu* = nu / (1 + nu)``."""
    from msslib.fem import exact

    return exact.cylinder_displacement(X, A, B, P, E * (1 + 2 * nu) / (1 + nu) ** 2, nu / (1 + nu))


def models_for(cells: str) -> list[str]:
    from msslib import models as registry

    return [name for name in registry.registry() if cells in registry.get(name).cells and not name.startswith("fem_")]


def errors(u, mesh, exact_u) -> tuple[float, float]:
    ue = exact_u(mesh.points)
    return (float(np.abs(u - ue).max() / np.abs(ue).max()),
            float(np.sqrt(np.mean(np.sum((u - ue) ** 2, axis=1)) / np.mean(np.sum(ue**2, axis=1)))))


def mss_run(model: str, mesh, inner, nu: float):
    """The model's nodal displacement under the dead pressure (a scene, linear static solve)."""
    from msslib.scene import run_scene

    axes = "xyz"[: mesh.dim]
    sc = {"name": f"pressure_exact_{model}", "model": model, "geometry": {"mesh": replace(mesh, facet_groups={"inner": inner})},
          "materials": [{"E": E, "nu": nu, "density": 1000.0}],
          "boundary": [{"select": {"plane": [a, 0.0]}, "fix": [a]} for a in axes],
          "loads": [{"type": "pressure", "select": {"group": "inner"}, "pressure": P, "follow": False}],
          "solver": {"type": "static", "linear": True}}
    ds = run_scene(sc, progress=False)
    return np.asarray(ds["displacement"].values).reshape(mesh.n_nodes, mesh.dim)


def fem_run(order: int, mesh, inner, nu: float, curved: bool = False):
    """FEM of ``order`` on the mesh; ``curved``: the quadratic nodes of both walls on their circle or
    sphere (isoparametric), else straight-sided elements as on a user's mesh."""
    from msslib.fem import exact, solve_linear

    r = solve_linear(mesh, E, nu, fixed=exact.symmetry_supports(mesh), order=order, plane="stress",
                     volumetric="reduced" if order == 2 and mesh.dim == 3 else "full", linear_solver="direct",
                     pressures=[(inner, P, False)], curved=exact.curved_walls(mesh, A, B) if curved else ())
    return r.displacement


def study(quick: bool = False, log=print) -> list[dict]:
    from msslib.fem import exact

    rows = []
    for problem, cells, level, mesh, exact_of in problems(quick):
        inner = exact.inner_wall(mesh, A)
        for nu in NUS:
            u_exact = exact_of(nu)
            runs = [("fem_quadratic", partial(fem_run, 2)), ("fem_quadratic_curved", partial(fem_run, 2, curved=True)),
                    ("fem_linear_p1", partial(fem_run, 1))]
            runs += [(m, partial(mss_run, m)) for m in models_for(cells)]
            reference = None
            for name, run in runs:
                outcome = "ok"
                try:
                    u = run(mesh, inner, nu)
                    err_max, err_rms = errors(u, mesh, u_exact)
                    if reference is None:
                        reference = u
                    fem_max = float(np.abs(u - reference).max() / np.abs(reference).max())
                except (ValueError, RuntimeError, np.linalg.LinAlgError) as exc:
                    err_max = err_rms = fem_max = float("nan")
                    outcome = f"{type(exc).__name__}: {' '.join(str(exc).split())}"[:300]
                rows.append({"problem": problem, "cells": cells, "level": level, "model": name, "nu": nu,
                             "n_nodes": mesh.n_nodes, "error_max": err_max, "error_rms": err_rms,
                             "error_max_vs_fem": fem_max, "outcome": outcome})
                log(f"{problem:8s} {cells:8s} {level:5g} nu={nu:<6g} {name:26s} max {err_max:.3e} rms {err_rms:.3e} "
                    f"vs FEM {fem_max:.3e}" + ("" if outcome == "ok" else f"  ({outcome[:120]})"))
    return rows


def summary(rows: list[dict]) -> dict:
    """Per ``case`` (problem and cells), ``model`` and ``nu``: the finest level's ``finest_error_max``
    and ``finest_error_rms``, its ``finest_error_vs_fem`` (against the quadratic reference on the same
    mesh), and the observed order ``rate`` of the root-mean-square error between the two finest levels
    (``log(e_coarse / e_fine) / log(h_coarse / h_fine)``); NaN where a model does not run on a case."""
    cases = sorted({f"{r['problem']}_{r['cells']}" for r in rows})
    models = list(dict.fromkeys(r["model"] for r in rows))
    nus = sorted({r["nu"] for r in rows})
    shape = (len(cases), len(models), len(nus))
    out = {k: np.full(shape, np.nan) for k in ("finest_error_max", "finest_error_rms", "finest_error_vs_fem", "rate")}
    for i, case in enumerate(cases):
        for j, model in enumerate(models):
            for k, nu in enumerate(nus):
                own = [r for r in rows if f"{r['problem']}_{r['cells']}" == case and r["model"] == model
                       and r["nu"] == nu]
                if not own:
                    continue
                # the level is cells through the wall (cylinder: finer is larger) or a size (sphere: finer is smaller)
                own.sort(key=lambda r: r["n_nodes"])
                fine = own[-1]
                out["finest_error_max"][i, j, k] = fine["error_max"]
                out["finest_error_rms"][i, j, k] = fine["error_rms"]
                out["finest_error_vs_fem"][i, j, k] = fine["error_max_vs_fem"]
                if len(own) >= 2:
                    coarse = own[-2]
                    h_ratio = (fine["level"] / coarse["level"] if fine["problem"] == "cylinder"
                               else coarse["level"] / fine["level"])
                    out["rate"][i, j, k] = np.log(coarse["error_rms"] / fine["error_rms"]) / np.log(h_ratio)
    return {"coords": {"case": cases, "model": models, "nu": np.array(nus)},
            "data": {k: (("case", "model", "nu"), v) for k, v in out.items()}}


def write(rows: list[dict], path: str, quick: bool = False) -> None:
    """Write the rows (dimension ``run``) and their :func:`summary` (dimensions ``case``, ``model``,
    ``nu``) as one NetCDF dataset, atomically."""
    import xarray as xr

    from msslib.results import write_result

    # the runs' model and nu are named run_model and run_nu (model and nu are the summary's coordinates)
    data = {(f"run_{key}" if key in ("model", "nu") else key): ("run", np.array([r[key] for r in rows]))
            for key in rows[0]}
    s = summary(rows)
    data.update(s["data"])
    ds = xr.Dataset(data, coords=s["coords"])
    ds.attrs.update(description="nodal displacement errors against the exact thick-cylinder (plane stress) and "
                                "thick-sphere solutions under internal pressure", E=E, pressure=P, inner_radius=A,
                    outer_radius=B)
    if quick:
        ds.attrs["quick"] = 1
    write_result(path, ds)


def main(argv=None) -> int:
    import warnings

    from experiments import script

    a = script.args(__doc__, argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rows = study(a.quick)
    write(rows, a.out, a.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
