"""The reference of a speed-against-error front: quadratic-element FEM on nested meshes, with an
estimate of its own discretisation error, locking-free near nu = 1/2.

:func:`solve_setup` solves a prepared scene (:class:`msslib.scene.Setup`) with
:func:`msslib.fem.solve_linear` / :func:`msslib.fem.solve_nonlinear` at element ``order`` 2: the
scene's supports and prescribed displacements, its tractions integrated over the loaded facets
with the quadratic shape functions (not lumped at the nodes: a lumped load on quadratic elements
is a set of point loads), nodal forces at the nodes, gravity over the cells.

:func:`reference` solves it on the finest measured level and up to two coarser ones.  Each level
is one uniform refinement of the one below (:func:`msslib.mesh.refine.uniform`), so every node of a
coarser level is a node of the finer ones, and the quadratic dofs of level ``L`` sit exactly at
the nodes of level ``L + 1``: every measured model is compared with the reference at its own
nodes, without interpolation.  Error estimate: ``c = max |u_L - u_{L-1}|`` at the nodes of level
``L`` (the change of the last refinement, relative to the largest reference displacement); with
three levels the observed order ``p = log2(c_1 / c_2)`` of the two changes at the coarsest
nodes gives Richardson's ``c / (2^p - 1)`` for what is left after the last refinement, else
(``p`` not positive, or two levels only) ``c`` itself.  One level only: no estimate (NaN).

Locking: at nu >= :data:`msslib.models.references.LOCKING_NU` (3D or plane strain), even quadratic
displacement elements keep some volumetric locking (a few per cent at nu = 0.4999 on a clamped
cube, shrinking slowly under refinement); the reference then integrates the volumetric term with
the reduced rule (``volumetric="reduced"`` of :mod:`msslib.fem`: P2-P0 on simplices, selective
reduced integration on Q2), whose change under refinement is below 0.3 % there, and solves its
systems directly (conjugate gradients converge slowly as lambda / mu grows).
"""

from __future__ import annotations

import math
import time

import numpy as np


def nearly_incompressible(setup) -> float | None:
    """The largest nu of the scene when its linear or quadratic displacement elements would lock
    (nu >= LOCKING_NU in 3D or plane strain), else None."""
    from msslib.models.references import LOCKING_NU

    nu = max(m.nu for m in setup.scene.materials)
    plane = setup.scene.model_options.get("plane", "stress") if setup.mesh.dim == 2 else None
    return float(nu) if nu >= LOCKING_NU and plane != "stress" else None


def _loads(setup):
    """``(nodal_forces, tractions, body_force)`` of the scene's loads (its pressures: ``setup.pressures``)."""
    from msslib.mesh.selection import loaded_facets, select_nodes

    mesh, dim = setup.mesh, setup.mesh.dim
    size = float(np.linalg.norm(np.ptp(mesh.points, axis=0))) if mesh.n_nodes else 1.0
    tol = max(1e-8 * size, 1e-15)
    nodal = np.zeros((mesh.n_nodes, dim))
    tractions, cache = [], {}
    for i, load in enumerate(setup.scene.loads):
        path = f"scene.loads[{i}]"
        if load["type"] == "nodal_force":
            nodes = select_nodes(f"{path}.select", mesh, load["select"], tol)
            nodal[nodes] += np.asarray(load["total"], dtype=float) / len(nodes)
        elif load["type"] == "traction":
            facets = loaded_facets(f"{path}.select", mesh, load["select"], tol, cache)
            tractions.append((facets, np.asarray(load["traction"], dtype=float)))
    body = None if setup.gravity is None else setup.cell_density[:, None] * setup.gravity[None, :]
    return nodal, tractions, body


def solve_setup(setup, *, order: int = 2, law: str | None = None, volumetric: str = "full", steps: int = 1,
                tol: float = 1e-10, max_iter: int = 30, linear_solver="auto", initial=None):
    """The FEM solution of a prepared scene with elements of ``order`` (a
    :class:`msslib.fem.FemResult`; ``dof_points`` / ``dof_displacement`` hold every dof).
    ``law``: None (linear elasticity) or a law of :func:`msslib.fem.solve_nonlinear`, solved in
    ``steps`` load steps to a relative residual ``tol``; ``initial``: a guess of the non-linear
    solution at the mesh's nodes (:func:`msslib.fem.solve_nonlinear`)."""
    from msslib import fem

    scene, mesh = setup.scene, setup.mesh
    nodal, tractions, body = _loads(setup)
    E = [m.E for m in scene.materials]
    nu = [m.nu for m in scene.materials]
    kw = dict(fixed=setup.fixed, prescribed=setup.prescribed, nodal_forces=nodal, body_force=body, order=order,
              tractions=tractions, volumetric=volumetric, linear_solver=linear_solver)
    if mesh.dim == 2:
        kw.update(thickness=setup.thickness, plane=scene.model_options.get("plane", "stress"))
    from msslib.scene.run import pressure_keywords

    if law is None:
        return fem.solve_linear(mesh, E, nu, **kw, **pressure_keywords(setup, fem.solve_linear))
    return fem.solve_nonlinear(mesh, E, nu, law=law, steps=steps, tol=tol, max_iter=max_iter, initial=initial, **kw,
                               **pressure_keywords(setup, fem.solve_nonlinear))


def at_points(result, points, rtol: float = 1e-9):
    """The dof displacements of ``result`` at ``points`` that coincide with its dofs (ValueError
    naming the distance if one does not)."""
    from scipy.spatial import cKDTree

    x = result.dof_points
    dist, idx = cKDTree(x).query(np.asarray(points, dtype=float))
    size = float(np.linalg.norm(np.ptp(x, axis=0)))
    if dist.max(initial=0.0) > rtol * size:
        raise ValueError(f"a node of the compared mesh is no dof of the reference (nearest dof {dist.max():.3g} m "
                         f"away): the levels are not nested")
    return result.dof_displacement[idx]


def reference(prepare_level, top: int, law: str | None, progress=None, lowest: int = 1):
    """Quadratic reference on level ``top`` and up to two coarser levels (not below ``lowest``);
    ``prepare_level(level)`` gives the prepared scene of a level.  Returns a dict: ``result``
    (the :class:`msslib.fem.FemResult` on ``top``), ``scale`` (its largest displacement),
    ``error_estimate``, ``step_change``, ``observed_order``, ``levels``, ``n_dofs``,
    ``wall_time``, ``locking`` (the nu that made it reduce its volumetric term, or None) and
    ``formulation`` (in words)."""
    used = [lv for lv in (top - 2, top - 1, top) if lv >= lowest]
    setups = {lv: prepare_level(lv) for lv in used}
    nu = nearly_incompressible(setups[top])
    volumetric, solver = ("reduced", "direct") if nu is not None else ("full", "auto")
    results, wall = {}, 0.0
    for lv in used:
        t0 = time.perf_counter()
        # Newton starts on each finer level from the coarser level's solution at its nodes (they are
        # that level's quadratic dofs): a few iterations where a start from rest takes many.  Not
        # under prescribed displacements, whose convergence scale is the force of the motion from
        # the start
        guess = None
        if law is not None and lv - 1 in results and not np.any(setups[lv].prescribed):
            guess = at_points(results[lv - 1], setups[lv].mesh.points)
        results[lv] = solve_setup(setups[lv], order=2, law=law, volumetric=volumetric, linear_solver=solver,
                                  initial=guess)
        wall += time.perf_counter() - t0
        if progress:
            progress(f"reference (quadratic elements, {law or 'linear'}) level {lv}: "
                     f"{results[lv].stats['n_dofs']} dofs, {time.perf_counter() - t0:.2f} s")
    u_top = results[top].dof_displacement
    scale = float(np.linalg.norm(u_top, axis=1).max())
    step = p = math.nan
    if scale > 0 and len(used) >= 2:
        a, b = used[-2], used[-1]
        nb = setups[b].mesh.n_nodes
        step = float(np.linalg.norm(results[b].displacement - at_points(results[a], setups[b].mesh.points[:nb]),
                                    axis=1).max()) / scale
        if len(used) == 3:
            x0 = setups[used[0]].mesh.points
            v = [at_points(results[lv], x0) for lv in used]
            c1, c2 = (float(np.linalg.norm(v[k + 1] - v[k], axis=1).max()) for k in (0, 1))
            p = math.log2(c1 / c2) if c1 > 0 and c2 > 0 else math.nan
    estimate = step / (2.0**p - 1.0) if math.isfinite(p) and p > 0 else step
    what = ("quadratic elements, volumetric term with the reduced rule (P2-P0 / Q2 selective reduced integration: "
            f"locking-free at nu = {nu:.6g})" if nu is not None else "quadratic elements")
    return {"result": results[top], "scale": scale, "error_estimate": estimate, "step_change": step,
            "observed_order": p, "levels": used, "n_dofs": results[top].stats["n_dofs"], "wall_time": wall,
            "locking": nu, "formulation": what}


# --------------------------------------------------------------------------------------------
# what a plan will cost, before it runs
# --------------------------------------------------------------------------------------------

#: the reference's time grows like (dofs)^TIME_EXPONENT: measured on the 10 x 2 x 2 cm bar of
#: tetrahedra (neo-Hookean, large deflection), each level from rest: 13,491 dofs 8.2 s, 95,619
#: dofs 76 s (2 cores); started from the coarser level's solution, as the reference now is, the
#: finest took 51 s: the estimate errs on the long side
TIME_EXPONENT = 1.2
#: seconds per dofs^TIME_EXPONENT of that measurement: the least the estimate assumes (a machine
#: or a scene that solves faster is measured by the calibration solve instead)
TIME_RATE = 8.0e-5
#: the runs of every model at a level, one repeat, as a share of the reference's time there
#: (the same bar: 13.7 s for the five tetrahedron models at level 3 against 76 s)
MODEL_SHARE = 0.25
#: memory of the reference per dof: its tangent (about 80 entries a row, values and indices) and
#: a direct factorisation with about ten times the fill
BYTES_PER_DOF = 12e3


def level_sizes(mesh, levels):
    """``{level: n_nodes}`` of the mesh refined ``level - 1`` times, for every level in ``levels``
    and the one above each (whose nodes are the quadratic dofs of the level below): counted on
    refined meshes up to about 10^6 nodes, beyond that scaled by ``2^dim`` per level."""
    from msslib.mesh.refine import uniform

    top = max(levels) + 1
    sizes, m = {1: mesh.n_nodes}, mesh
    for lv in range(2, top + 1):
        if m is not None and m.n_nodes * 2**mesh.dim <= 1_000_000:
            m = uniform(m, 1)
            sizes[lv] = m.n_nodes
        else:
            m = None
            sizes[lv] = sizes[lv - 1] * 2**mesh.dim
    return sizes


def estimate(setup, levels, *, repeats: int = 1, n_models: int = 5, calibration: float | None = None):
    """Estimated cost of a plan on ``levels`` of a prepared level-1 scene ``setup``: a dict per
    level (``dofs`` of the models, ``reference_dofs``, ``reference_s``, ``models_s``,
    ``memory_bytes`` of the reference) and ``total_s``: the reference on the top level and up to
    two below it, every model on every level ``repeats`` times (plus a warm-up).
    ``calibration``: seconds per dofs^TIME_EXPONENT measured on this machine and scene (a small
    reference solve); the larger of it and :data:`TIME_RATE` is used."""
    d = setup.mesh.dim
    sizes = level_sizes(setup.mesh, levels)
    rate = max(TIME_RATE, calibration or 0.0)
    out = {}
    for lv in sorted(set(levels) | {lv for top in levels for lv in range(max(1, top - 2), top + 1)}):
        ref_dofs = d * sizes[lv + 1]
        t_ref = rate * ref_dofs**TIME_EXPONENT
        out[lv] = {"dofs": d * sizes[lv], "reference_dofs": ref_dofs, "reference_s": t_ref,
                   "models_s": MODEL_SHARE * t_ref * n_models / 5.0, "memory_bytes": BYTES_PER_DOF * ref_dofs}
    top = max(levels)
    ref_levels = [lv for lv in (top - 2, top - 1, top) if lv >= 1]
    total = sum(out[lv]["reference_s"] for lv in ref_levels)
    total += (int(repeats) + 1) * sum(out[lv]["models_s"] for lv in levels)
    return {"levels": out, "total_s": total, "rate": rate}


def calibrate(setup, law) -> float:
    """Seconds per dofs^TIME_EXPONENT of the quadratic reference of the prepared level-1 scene on
    this machine: its solve timed once after a first (compiling) solve."""
    solve_setup(setup, order=2, law=law)
    t0 = time.perf_counter()
    res = solve_setup(setup, order=2, law=law)
    return (time.perf_counter() - t0) / max(res.stats["n_dofs"], 1) ** TIME_EXPONENT
