"""Shared pieces of the hard-case study (:mod:`experiments.stability`): constants, meshes, boundary
conditions and the runners of one MSS or FEM solve with its record."""

from __future__ import annotations

import time

import numpy as np

from msslib.models.baudet import baudet_correction, baudet_cube_springs
from msslib.models.golec import golec_cube_springs
from msslib.models.lloyd import lloyd_tet_springs
from msslib import fem
from msslib import mesh as M
from msslib import system as MD
from msslib import solvers as S
from msslib.terms import NodalForces

E0 = 1.0e6  # Pa
DENSITY = 1000.0  # kg/m^3
TET_MODELS = ("lloyd_tetrahedron", "lloyd_tetrahedron_volume")
CUBE_MODELS = ("baudet_cube", "golec_derived", "golec_published", "golec_springs_only")
MSS_MODELS = TET_MODELS + CUBE_MODELS
FEM_MODELS = ("fem_linear", "fem_svk", "fem_neohookean")
MODELS = MSS_MODELS + FEM_MODELS
NU_VALUES = (0.45, 0.49, 0.499, 0.4999)
COMPRESSIONS = (0.1, 0.3, 0.5)
SHAPES = ("regular", "sliver", "cap", "spindle", "wedge")
TET_EDGES = M._LOCAL_EDGES["tetra"]

FIELDS = ("ran", "converged", "error", "volume_ratio", "min_volume_ratio", "n_inverted", "iterations", "stop_step",
          "stop_displacement", "outcome")


def _record(ran=False, converged=False, error=np.nan, volume_ratio=np.nan, min_volume_ratio=np.nan,
            n_inverted=-1, outcome="", iterations=-1, stop_step=-1, stop_displacement=np.nan):
    return {"ran": bool(ran), "converged": bool(converged), "error": float(error),
            "volume_ratio": float(volume_ratio), "min_volume_ratio": float(min_volume_ratio),
            "n_inverted": int(n_inverted), "iterations": int(iterations), "stop_step": int(stop_step),
            "stop_displacement": float(stop_displacement), "outcome": " ".join(str(outcome).split())[:300]}


def _short(exc: BaseException) -> str:
    return f"{type(exc).__name__}: {' '.join(str(exc).split())}"


# --------------------------------------------------------------------------------------------
# meshes, boundary conditions, models
# --------------------------------------------------------------------------------------------


def cube_meshes(size: float, n: int):
    """(hexahedral mesh, Kuhn tetrahedral mesh) of the cube [0, size]^3 with n cells per edge."""
    return M.hex_grid(size, size, size, n, n, n), M.tet_grid(size, size, size, n, n, n, scheme=6)


def sliding_bc(mesh, strain):
    """Symmetry planes x = 0, y = 0, z = 0 (normal dof fixed) and the top moved down by strain * L."""
    p = mesh.points
    L = p[:, 2].max()
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    presc = np.zeros((mesh.n_nodes, 3))
    for d in range(3):
        fixed[np.isclose(p[:, d], 0.0), d] = True
    top = np.isclose(p[:, 2], L)
    fixed[top, 2] = True
    presc[top, 2] = -strain * L
    return fixed, presc, top


def clamped_bc(mesh, strain):
    """Bottom and top faces clamped (all dofs), top moved down by strain * L."""
    p = mesh.points
    L = p[:, 2].max()
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    presc = np.zeros((mesh.n_nodes, 3))
    top = np.isclose(p[:, 2], L)
    fixed[np.isclose(p[:, 2], 0.0)] = True
    fixed[top] = True
    presc[top, 2] = -strain * L
    return fixed, presc, top


def volumes(mesh, x):
    """Cell volumes of ``mesh`` with node positions ``x`` (flat or (n, 3))."""
    return M.cell_measures(M.Mesh(np.asarray(x, float).reshape(-1, 3), mesh.cells, mesh.cell_type))


def mss_terms(name, mesh, materials, loads=None):
    """Internal terms of MSS model ``name``; ``loads`` (n, 3) feeds Baudet's correction."""
    if name == "lloyd_tetrahedron":
        return lloyd_tet_springs(mesh, materials)
    if name == "lloyd_tetrahedron_volume":
        return lloyd_tet_springs(mesh, materials, volume=True)
    if name == "baudet_cube":
        terms = baudet_cube_springs(mesh, materials)
        if loads is not None and np.any(loads != 0):
            terms.append(baudet_correction(mesh, materials, loads))
        return terms
    if name == "golec_derived":
        return golec_cube_springs(mesh, materials, 1.0)
    if name == "golec_published":
        return golec_cube_springs(mesh, materials, 1.0, published=True)
    if name == "golec_springs_only":
        return golec_cube_springs(mesh, materials, 1.0)[:1]
    raise ValueError(f"unknown MSS model {name!r}")


def displacement_scale(model) -> float:
    """``||K(x0) (x_prescribed - x0)||``: the linearised reaction of a displacement-controlled
    problem, a robust ``force_scale`` for :func:`msslib.solvers.static_solve`."""
    xp = model.apply_prescribed(model.x0, 1.0)
    return float(np.linalg.norm(model.stiffness(model.x0) @ (xp - model.x0)))


def _compare(mesh, u, ref_u):
    V0 = M.cell_measures(mesh)
    V = volumes(mesh, mesh.points + u)
    err = np.nan if ref_u is None else np.abs(u - ref_u).max() / np.abs(ref_u).max()
    return err, V.sum() / V0.sum(), (V / V0).min(), int((V <= 0).sum())


def run_mss(name, mesh, materials, fixed, presc=None, forces=None, ref_u=None, load_steps=4,
            displacement_control=True):
    """Static MSS solve; returns (record, displacement or None)."""
    t0 = time.perf_counter()
    try:
        terms = mss_terms(name, mesh, materials, loads=forces)
        if forces is not None and np.any(forces != 0):
            terms.append(NodalForces(forces))
        model = MD.Model(mesh, terms, fixed=fixed, prescribed=presc)
    except ValueError as exc:
        return _record(outcome=f"refused: {_short(exc)}"), None
    scale = displacement_scale(model) if displacement_control else None
    try:
        res = S.static_solve(model, model.x0, load_steps=load_steps, force_scale=scale)
    except S.ConvergenceError as exc:
        return _record(ran=True, outcome=f"no convergence: {_short(exc)}"), None
    u = (res.x - model.x0).reshape(-1, 3)
    err, vr, vmin, ninv = _compare(mesh, u, ref_u)
    text = f"converged ({res.total_iterations} Newton iterations, {res.n_cuts} cuts, {time.perf_counter() - t0:.2f} s)"
    if ninv:
        text += f"; {ninv} inverted elements (min V/V0 {vmin:.3f}): springs have no inversion barrier"
    return _record(True, True, err, vr, vmin, ninv, text), u


def run_fem(law, mesh, materials_E, materials_nu, fixed, presc=None, forces=None, ref_u=None, steps=4):
    """FEM solve (law None: linear); returns (record, displacement or None)."""
    t0 = time.perf_counter()
    try:
        if law is None:
            r = fem.solve_linear(mesh, materials_E, materials_nu, fixed=fixed, prescribed=presc, nodal_forces=forces)
        else:
            r = fem.solve_nonlinear(mesh, materials_E, materials_nu, fixed=fixed, prescribed=presc, nodal_forces=forces,
                                    law=law, steps=steps, max_halvings=4)
    except ValueError as exc:
        return _record(outcome=f"refused: {_short(exc)}"), None
    except (RuntimeError, np.linalg.LinAlgError) as exc:
        return _record(ran=True, outcome=f"no convergence: {_short(exc)}"), None
    u = r.displacement
    err, vr, vmin, ninv = _compare(mesh, u, ref_u)
    text = f"converged ({time.perf_counter() - t0:.2f} s)"
    if ninv:
        text += f"; {ninv} inverted elements (min V/V0 {vmin:.3f})" + (": SVK has no inversion barrier" if law == "svk" else "")
    return _record(True, True, err, vr, vmin, ninv, text), r
