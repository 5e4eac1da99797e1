"""Hard cases of the mass-spring models: where each model breaks, and how.

    python experiments/stability.py --out results/stability.nc [--quick]

Runs every case for every model it applies to and records, per (case, model): whether it ran,
whether the solver converged, the error against the neo-Hookean FEM reference on the same mesh
where that is meaningful, the volume ratio V/V0, the smallest element volume ratio, the number of
inverted elements and a one-line text of the outcome (how it broke).  The result is an xarray
Dataset written atomically (:func:`msslib.io.write_result`).

Models (dimension ``model``):

* ``lloyd_tetrahedron`` / ``lloyd_tetrahedron_volume``: Lloyd's springs (with the derived eq. 14
  volume term) on a Kuhn tetrahedral mesh;
* ``baudet_cube``: Baudet's cube springs plus the orthogonal correction (the correction is built
  from external loads, so it only acts in force-controlled cases);
* ``golec_derived`` / ``golec_published`` / ``golec_springs_only``: Golec's cube with the derived
  constants, the printed ones, and the derived springs without the volume term;
* ``fem_linear``, ``fem_svk``, ``fem_neohookean``: scikit-fem references on the cube mesh.

Cases (dimension ``case``):

* ``nu_0.45`` ... ``nu_0.4999``: unit cube, 10 % compression by a prescribed top displacement,
  frictionless symmetry planes (the exact solution is homogeneous, so linear elements represent it
  exactly and the FEM reference does not lock).  Baudet's cube is loaded instead by the FEM
  reactions (force control) so that its correction is active.
* ``compress_10/30/50``: 0.1 m cube clamped at top and bottom (barrelling), nu = 0.3, prescribed
  top displacement.  The static solver gets ``force_scale = ||K(x0) u_prescribed||`` (see the note
  on the default F_ref in the outcome texts).
* ``inverted_input``: the same meshes with one cell flipped: every model must refuse it.
* ``sliver``, ``cap``, ``spindle``, ``wedge``: one badly shaped tetrahedron.  Lloyd's constant
  (equivalent regular tetrahedron of the same volume) against the exact element-wise least squares
  of the element's FEM stiffness by its six spring matrices (variables on the ``shape`` x ``edge``
  dimensions).
* ``contrast_1`` / ``contrast_1000``: bar of two materials (E and 1000 E) in series, clamped at
  one end, pulled by a traction at the other (1 % strain in the soft half).
* ``explicit_1.05x`` / ``explicit_1.2x`` / ``explicit_1.5x`` / ``explicit_2x`` / ``implicit_1.5x``:
  cantilever under gravity released from rest, symplectic Euler at that multiple of
  ``explicit_stability_limit``: refused by default (StabilityError, both numbers in the
  message), then run with ``allow_unstable=True`` until the divergence detector stops it
  (DivergenceError; ``stop_step``, ``stop_displacement`` = max |u| when stopped / static max |u|,
  and error = distance of the last state before the stop from a stable run to the same time /
  static max |u| record how early); implicit Euler at 1.5 x (must stay finite; error = max |u| /
  static max |u|).
* ``unloaded``: 0.1 m cube clamped on one face, no load: every static solver must return at once
  (``iterations`` 0, at the round-off floor; error = max |u| / edge length).
* ``slender_beam``: 1 m x 2 cm x 2 cm beam, E = 1 GPa, clamped, under its own weight, default
  tolerance 1e-8 (below the round-off of the spring forces: converged at the round-off floor);
  error = tip deflection / Euler-Bernoulli ``q L^4 / (8 E I)`` - 1 (4 cubes across; 2 in quick
  mode, where bending locking makes every model stiffer).
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from msslib import fem
from msslib import mesh as M
from msslib import model as MD
from msslib import parameters as P
from msslib import solvers as S
from msslib.io import write_result
from msslib.terms import Gravity, NodalForces, Traction

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
        return MD.lloyd_tet_springs(mesh, materials)
    if name == "lloyd_tetrahedron_volume":
        return MD.lloyd_tet_springs(mesh, materials, volume=True)
    if name == "baudet_cube":
        terms = MD.baudet_cube_springs(mesh, materials)
        if loads is not None and np.any(loads != 0):
            terms.append(MD.baudet_correction(mesh, materials, loads))
        return terms
    if name == "golec_derived":
        return MD.golec_cube_springs(mesh, materials, 1.0)
    if name == "golec_published":
        return MD.golec_cube_springs(mesh, materials, 1.0, published=True)
    if name == "golec_springs_only":
        return MD.golec_cube_springs(mesh, materials, 1.0)[:1]
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


# --------------------------------------------------------------------------------------------
# cases
# --------------------------------------------------------------------------------------------


def nu_case(nu, n=3):
    """Unit cube, 10 % compression on symmetry planes; error vs neo-Hookean FEM."""
    hexm, tetm = cube_meshes(1.0, n)
    mats = [(E0, nu)]
    out = {}
    refs = {}
    for mesh in (hexm, tetm):
        fixed, presc, top = sliding_bc(mesh, 0.1)
        rec, r = run_fem("neohookean", mesh, E0, nu, fixed, presc, steps=2)
        refs[mesh.cell_type] = (rec, r, fixed, presc, top)
    rec_h, r_h, fixed, presc, top = refs["hexahedron"]
    for law, name in ((None, "fem_linear"), ("svk", "fem_svk")):
        out[name] = run_fem(law, hexm, E0, nu, fixed, presc, ref_u=r_h.displacement, steps=2)[0]
    out["fem_neohookean"] = run_fem("neohookean", hexm, E0, nu, fixed, presc, ref_u=r_h.displacement, steps=2)[0]
    for name in CUBE_MODELS:
        if name == "baudet_cube":  # force control with the FEM reactions, so that the correction acts
            forces = np.where(top[:, None], r_h.reaction, 0.0)
            fx = fixed.copy()
            fx[top, 2] = False
            rec, _ = run_mss(name, hexm, mats, fx, forces=forces, ref_u=r_h.displacement, load_steps=2,
                             displacement_control=False)
            rec["outcome"] += "; force control (FEM reactions on top), correction active"
            out[name] = rec
        else:
            out[name] = run_mss(name, hexm, mats, fixed, presc, ref_u=r_h.displacement, load_steps=2)[0]
    _, r_t, fixed_t, presc_t, _ = refs["tetra"]
    for name in TET_MODELS:
        out[name] = run_mss(name, tetm, mats, fixed_t, presc_t, ref_u=r_t.displacement, load_steps=2)[0]
    return out


def compression_case(strain, n=4, nu=0.3):
    """0.1 m cube clamped top and bottom, compressed by ``strain``; error vs neo-Hookean FEM."""
    hexm, tetm = cube_meshes(0.1, n)
    mats = [(E0, nu)]
    steps = 10 if strain > 0.2 else 4
    out = {}
    ref = {}
    for mesh in (hexm, tetm):
        fixed, presc, _ = clamped_bc(mesh, strain)
        rec, r = run_fem("neohookean", mesh, E0, nu, fixed, presc, steps=steps)
        ref[mesh.cell_type] = (rec, None if r is None else r.displacement, fixed, presc)
    rec, ru, fixed, presc = ref["hexahedron"]
    out["fem_neohookean"] = dict(rec, error=0.0 if rec["converged"] else np.nan)
    out["fem_linear"] = run_fem(None, hexm, E0, nu, fixed, presc, ref_u=ru)[0]
    out["fem_svk"] = run_fem("svk", hexm, E0, nu, fixed, presc, ref_u=ru, steps=steps)[0]
    for name in CUBE_MODELS:
        rec = run_mss(name, hexm, mats, fixed, presc, ref_u=ru, load_steps=steps)[0]
        if name == "baudet_cube":
            rec["outcome"] += "; displacement control: no external load, correction inactive"
        out[name] = rec
    _, ru_t, fixed_t, presc_t = ref["tetra"]
    for name in TET_MODELS:
        out[name] = run_mss(name, tetm, mats, fixed_t, presc_t, ref_u=ru_t, load_steps=steps)[0]
    return out


def flip_one(mesh, cell=1):
    """Copy of ``mesh`` with cell ``cell`` inverted (node order mirrored)."""
    flip = {"tetra": [0, 2, 1, 3], "hexahedron": [4, 5, 6, 7, 0, 1, 2, 3]}[mesh.cell_type]
    cells = mesh.cells.copy()
    cells[cell] = cells[cell][flip]
    return M.Mesh(mesh.points, cells, mesh.cell_type, mesh.material)


def inverted_case(n=2):
    hexm, tetm = cube_meshes(0.1, n)
    out = {}
    for mesh, names in ((flip_one(hexm), CUBE_MODELS + FEM_MODELS), (flip_one(tetm), TET_MODELS)):
        fixed, presc, _ = sliding_bc(mesh, 0.1)
        for name in names:
            try:
                if name in FEM_MODELS:
                    law = {"fem_linear": None, "fem_svk": "svk", "fem_neohookean": "neohookean"}[name]
                    if law is None:
                        fem.solve_linear(mesh, E0, 0.3, fixed=fixed, prescribed=presc)
                    else:
                        fem.solve_nonlinear(mesh, E0, 0.3, fixed=fixed, prescribed=presc, law=law, steps=1)
                else:
                    MD.Model(mesh, mss_terms(name, mesh, [(E0, 0.3)]), fixed=fixed, prescribed=presc)
                out[name] = _record(ran=True, outcome="NOT DETECTED: the inverted cell was accepted")
            except ValueError as exc:
                out[name] = _record(outcome=f"detected: {_short(exc)}")
    return out


def shape_coordinates(shape):
    """Node coordinates (4, 3) of a test tetrahedron, positively oriented."""
    s = np.sqrt(2.0)
    h = 0.05
    X = {
        "regular": [[1, 0, -1 / s], [-1, 0, -1 / s], [0, 1, 1 / s], [0, -1, 1 / s]],
        # four nearly coplanar, well separated vertices (a flattened regular tetrahedron)
        "sliver": [[1, 0, -h], [-1, 0, -h], [0, 1, h], [0, -1, h]],
        # one vertex just above the centroid of the opposite face
        "cap": [[1, 0, 0], [-0.5, np.sqrt(3) / 2, 0], [-0.5, -np.sqrt(3) / 2, 0], [0, 0, h]],
        # a small base triangle and a far apex (needle)
        "spindle": [[h, 0, 0], [-h / 2, h * np.sqrt(3) / 2, 0], [-h / 2, -h * np.sqrt(3) / 2, 0], [0, 0, 1]],
        # a long edge with the other two vertices close to its middle
        "wedge": [[0, 0, 0], [1, 0, 0], [0.5, h, 0], [0.5, 0.4 * h, h]],
    }[shape]
    X = np.asarray(X, float)
    if np.linalg.det(X[1:] - X[0]) < 0:
        X = X[[0, 2, 1, 3]]
    return X


def spring_matrices(X):
    """(6, 12, 12) stiffness matrices at rest of unit springs on the 6 edges of tetrahedron X."""
    out = np.zeros((6, 12, 12))
    for i, (a, b) in enumerate(TET_EDGES):
        e = (X[b] - X[a]) / np.linalg.norm(X[b] - X[a])
        g = np.zeros(12)
        g[3 * a:3 * a + 3], g[3 * b:3 * b + 3] = -e, e
        out[i] = np.outer(g, g)
    return out


def elementwise_lsq(X, E, nu):
    """Spring constants (6,) minimising ``||K_fem - sum_i k_i S_i||_F`` and the relative residual."""
    K = fem.element_stiffness("tetra", X, E, nu)
    Sm = spring_matrices(X)
    k, *_ = np.linalg.lstsq(Sm.reshape(6, -1).T, K.ravel(), rcond=None)
    resid = np.linalg.norm(K - np.einsum("i,ijk->jk", k, Sm)) / np.linalg.norm(K)
    return k, float(resid)


def lloyd_constant(X, E, nu):
    """Lloyd's per-element constant: the regular-tetrahedron optimum for the element's volume."""
    V = np.linalg.det(X[1:] - X[0]) / 6.0
    return float(P.lloyd_tetrahedron(E, P.equivalent_edge_length(V), nu=nu).k)


def shape_case(shape, nu=0.3):
    """Per-shape data and the (case, model) records."""
    X = shape_coordinates(shape)
    k_lloyd = lloyd_constant(X, E0, nu)
    k_lsq, resid = elementwise_lsq(X, E0, nu)
    mesh = M.Mesh(X, np.array([[0, 1, 2, 3]]), "tetra")
    neg = np.flatnonzero(k_lsq <= 0)
    try:
        local = {tuple(sorted(e)): i for i, e in enumerate(TET_EDGES.tolist())}
        MD.assemble_springs(mesh, "edges", lambda _c, pairs: k_lsq[[local[tuple(q)] for q in pairs.tolist()]])
        springs = "accepted by Springs"
    except ValueError as exc:
        springs = f"Springs rejects them: {_short(exc)}"
    lloyd = _record(ran=True, converged=True, outcome=f"Lloyd k = {k_lloyd:.4g} N/m > 0 on all 6 edges; element-wise "
                    f"least squares: {len(neg)} negative of 6 (min {k_lsq.min():.4g} N/m, fit residual {resid:.2f}); "
                    + (springs if len(neg) else "all positive"))
    data = {"k_lloyd": k_lloyd, "k_lsq": k_lsq, "lsq_residual": resid}
    return {"lloyd_tetrahedron": lloyd}, data


def two_material_bar(cell, contrast, n=(8, 2, 2), nu=0.3, strain=0.01):
    """Bar [0, 0.4] x [0, 0.1]^2, E0 for x < 0.2 and contrast * E0 beyond, clamped at x = 0,
    pulled by a traction ``strain * E0`` on x = 0.4.  Returns mesh, materials, fixed, nodal forces."""
    base = M.hex_grid(0.4, 0.1, 0.1, *n) if cell == "hexahedron" else M.tet_grid(0.4, 0.1, 0.1, *n)
    material = (base.points[base.cells].mean(axis=1)[:, 0] > 0.2).astype(int)
    mesh = M.Mesh(base.points, base.cells, base.cell_type, material)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    facets = M.boundary_facets(mesh)
    end = np.isclose(mesh.points[facets][:, :, 0], 0.4).all(axis=1)
    forces = Traction(mesh, facets[end], [strain * E0, 0.0, 0.0]).nodal
    return mesh, [(E0, nu), (contrast * E0, nu)], fixed, forces


def contrast_case(contrast, n=(8, 2, 2)):
    out = {}
    for cell, names in (("hexahedron", CUBE_MODELS + FEM_MODELS), ("tetra", TET_MODELS)):
        mesh, mats, fixed, forces = two_material_bar(cell, contrast, n)
        E, nu = [m[0] for m in mats], [m[1] for m in mats]
        rec, ref = run_fem("neohookean", mesh, E, nu, fixed, forces=forces, steps=2)
        for name in names:
            if name == "fem_neohookean":
                out[name] = dict(rec, error=0.0)
            elif name in FEM_MODELS:
                law = None if name == "fem_linear" else "svk"
                out[name] = run_fem(law, mesh, E, nu, fixed, forces=forces, ref_u=ref.displacement, steps=2)[0]
            else:
                out[name] = run_mss(name, mesh, mats, fixed, forces=forces, ref_u=ref.displacement, load_steps=1,
                                    displacement_control=False)[0]
    return out


def cantilever(name, n=4):
    """Cantilever [0, 0.2] x [0, 0.05]^2 clamped at x = 0 under gravity: the MSS model."""
    mesh = (M.tet_grid if name in TET_MODELS else M.hex_grid)(0.2, 0.05, 0.05, n, 1, 1)
    fixed = np.zeros((mesh.n_nodes, 3), bool)
    fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
    masses = M.lumped_masses(mesh, DENSITY)
    terms = mss_terms(name, mesh, [(E0, 0.3)]) + [Gravity(masses, [0.0, 0.0, -9.81])]
    return MD.Model(mesh, terms, fixed=fixed, masses=masses)


def explicit_run(model, factor, n_steps):
    """Symplectic Euler at ``factor`` x the stability limit: first as a user would run it (refused
    up front), then with ``allow_unstable`` (stopped by the divergence detector); one record."""
    from msslib.errors import StabilityError

    limit = S.explicit_stability_limit(model, model.x0)
    dt = factor * limit
    v0 = np.zeros(model.n_dof)
    kw = dict(dt=dt, t_end=n_steps * dt, method="symplectic_euler", damping=0.0)
    try:
        S.integrate(model, model.x0, v0, **kw)
        refused, detail = f"NOT REFUSED at {factor:g} x the limit {limit:.4g} s", ""
    except StabilityError as exc:
        refused, detail = "refused", f"; {_short(exc)[:120]}"
    u_static = np.abs(S.static_solve(model, model.x0).x - model.x0).max()
    try:
        S.integrate(model, model.x0, v0, allow_unstable=True, **kw)
        return _record(True, True, outcome=f"{refused}; NOT DETECTED: no divergence in {n_steps} steps with "
                       f"allow_unstable{detail}")
    except S.DivergenceError as exc:
        moved = exc.max_displacement / u_static
        ok = np.isfinite(exc.x_last).all()
        # how wrong the body was: the last state against a stable run (half the limit) to the same time
        t_last = (exc.step - 1) * dt
        if t_last > 0:
            ref = S.integrate(model, model.x0, v0, dt=0.5 * limit, t_end=t_last, method="symplectic_euler",
                              damping=0.0, save_every=10**9)
            wrong = float(np.abs(exc.x_last - ref.x_final).max()) / u_static
        else:
            wrong = float(np.abs(exc.x_last - model.x0).max()) / u_static
        return _record(ran=True, error=wrong, stop_step=exc.step, stop_displacement=moved,
                       outcome=f"{refused}; allow_unstable: stopped at step {exc.step}, off a stable run by "
                       f"{wrong:.2g} x static (max |u| {moved:.3g} x static, {exc.quantity}, last state "
                       f"{'finite' if ok else 'NON-FINITE'}){detail}")


def dynamics_case(factor=1.5, n_steps=200):
    """Symplectic Euler (refused; then with allow_unstable) and implicit Euler at ``factor`` times
    the explicit stability limit."""
    explicit, implicit = {}, {}
    for name in MSS_MODELS:
        model = cantilever(name)
        explicit[name] = explicit_run(model, factor, n_steps)
        limit = S.explicit_stability_limit(model, model.x0)
        dt = factor * limit
        v0 = np.zeros(model.n_dof)
        static = S.static_solve(model, model.x0)
        u_static = np.abs(static.x - model.x0).max()
        try:
            r = S.integrate(model, model.x0, v0, dt=dt, t_end=n_steps * dt / 2, method="implicit_euler", damping=0.0)
            umax = np.abs(r.x - model.x0).max()
            implicit[name] = _record(True, bool(np.isfinite(r.x).all()), error=umax / u_static,
                                     outcome=f"stable: max |u| = {umax / u_static:.3f} x static max |u| over "
                                     f"{n_steps // 2} steps (numerical damping)")
        except (S.DivergenceError, S.ConvergenceError) as exc:
            implicit[name] = _record(ran=True, outcome=_short(exc))
    return explicit, implicit


def explicit_case(factor, n_steps=200):
    """Symplectic Euler at ``factor`` x the limit, every MSS model (see :func:`explicit_run`)."""
    return {name: explicit_run(cantilever(name), factor, n_steps) for name in MSS_MODELS}


def _static_record(res, t0, error, extra=""):
    floor = (f"; at the round-off floor {res.roundoff_floor:.2e} N (tol x F_ref {1e-8 * res.force_scale:.2e} N)"
             if res.roundoff_steps else "")
    return _record(True, True, error=error, iterations=res.total_iterations,
                   outcome=f"converged ({res.total_iterations} Newton iterations, {time.perf_counter() - t0:.2f} s)"
                   f"{floor}{extra}")


def unloaded_case(n=3):
    """0.1 m cube clamped on x = 0, no load: every static solve must return at once."""
    hexm, tetm = cube_meshes(0.1, n)
    out = {}
    for mesh, names in ((hexm, CUBE_MODELS + FEM_MODELS), (tetm, TET_MODELS)):
        fixed = np.zeros((mesh.n_nodes, 3), bool)
        fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
        for name in names:
            t0 = time.perf_counter()
            if name in FEM_MODELS:
                law = {"fem_linear": None, "fem_svk": "svk", "fem_neohookean": "neohookean"}[name]
                rec, r = run_fem(law, mesh, E0, 0.3, fixed, steps=1)
                if r is not None:
                    its = sum(r.stats["iterations"]) if law else 0
                    rec.update(error=float(np.abs(r.displacement).max()) / 0.1, iterations=its)
                    rec["outcome"] += f"; {its} Newton iterations" if law else "; linear solve"
                out[name] = rec
                continue
            model = MD.Model(mesh, mss_terms(name, mesh, [(E0, 0.3)]), fixed=fixed)
            try:
                res = S.static_solve(model, model.x0)
            except S.ConvergenceError as exc:
                out[name] = _record(ran=True, outcome=f"no convergence: {_short(exc)}")
                continue
            out[name] = _static_record(res, t0, np.abs(res.x - model.x0).max() / 0.1)
    return out


def slender_beam_case(nyz=4, length=1.0, width=0.02, E=1.0e9):
    """``length`` x ``width``^2 beam of ``nyz``^2 cubes across, clamped at x = 0, under its own
    weight, default tolerance; error = tip deflection / Euler-Bernoulli - 1."""
    nx = int(round(length / width * nyz))
    hexm = M.hex_grid(length, width, width, nx, nyz, nyz)
    tetm = M.tet_grid(length, width, width, nx, nyz, nyz, scheme=6)
    q, inertia = DENSITY * 9.81 * width**2, width**4 / 12.0
    w_eb = q * length**4 / (8.0 * E * inertia)
    out = {}
    for mesh, names in ((hexm, CUBE_MODELS + FEM_MODELS), (tetm, TET_MODELS)):
        fixed = np.zeros((mesh.n_nodes, 3), bool)
        fixed[np.isclose(mesh.points[:, 0], 0.0)] = True
        masses = M.lumped_masses(mesh, DENSITY)
        for name in names:
            t0 = time.perf_counter()
            if name in FEM_MODELS:
                law = {"fem_linear": None, "fem_svk": "svk", "fem_neohookean": "neohookean"}[name]
                body = [0.0, 0.0, -DENSITY * 9.81]
                try:
                    if law is None:
                        r = fem.solve_linear(mesh, E, 0.3, fixed=fixed, body_force=body)
                    else:
                        r = fem.solve_nonlinear(mesh, E, 0.3, fixed=fixed, body_force=body, law=law, steps=1)
                except RuntimeError as exc:
                    out[name] = _record(ran=True, outcome=f"no convergence: {_short(exc)}")
                    continue
                w = -float(r.displacement[:, 2].min())
                its = sum(r.stats["iterations"]) if law else 0
                out[name] = _record(True, True, error=w / w_eb - 1.0, iterations=its if law else -1,
                                    outcome=f"converged ({time.perf_counter() - t0:.2f} s); tip {1e3 * w:.3f} mm, "
                                    f"Euler-Bernoulli {1e3 * w_eb:.3f} mm")
                continue
            terms = mss_terms(name, mesh, [(E, 0.3)]) + [Gravity(masses, [0.0, 0.0, -9.81])]
            model = MD.Model(mesh, terms, fixed=fixed, masses=masses)
            try:
                res = S.static_solve(model, model.x0)
            except S.ConvergenceError as exc:
                out[name] = _record(ran=True, outcome=f"no convergence: {_short(exc)}")
                continue
            w = -float((res.x - model.x0).reshape(-1, 3)[:, 2].min())
            out[name] = _static_record(res, t0, w / w_eb - 1.0,
                                       f"; tip {1e3 * w:.3f} mm, Euler-Bernoulli {1e3 * w_eb:.3f} mm")
    return out


# --------------------------------------------------------------------------------------------
# driver and output
# --------------------------------------------------------------------------------------------


def run_all(quick=False, log=print):
    n_nu, n_comp = (2, 3) if quick else (4, 4)
    bar_n = (4, 1, 1) if quick else (8, 2, 2)
    cases = {}
    for nu in NU_VALUES:
        log(f"nu = {nu}")
        cases[f"nu_{nu}"] = nu_case(nu, n_nu)
    for c in COMPRESSIONS:
        log(f"compression {c:.0%}")
        cases[f"compress_{round(100 * c)}"] = compression_case(c, n_comp)
    log("inverted input")
    cases["inverted_input"] = inverted_case()
    shape_data = {}
    for shape in SHAPES[1:]:
        cases[shape], shape_data[shape] = shape_case(shape)
    _, shape_data["regular"] = shape_case("regular")
    for contrast in (1, 1000):
        log(f"contrast {contrast}")
        cases[f"contrast_{contrast}"] = contrast_case(float(contrast), bar_n)
    log("dynamics")
    n_steps = 100 if quick else 200
    for factor in (1.05, 1.2):
        cases[f"explicit_{factor:g}x"] = explicit_case(factor, n_steps)
    cases["explicit_1.5x"], cases["implicit_1.5x"] = dynamics_case(n_steps=n_steps)
    cases["explicit_2x"] = explicit_case(2.0, n_steps)
    log("unloaded")
    cases["unloaded"] = unloaded_case()
    log("slender beam")
    cases["slender_beam"] = slender_beam_case(nyz=2 if quick else 4)
    return cases, shape_data


def to_dataset(cases, shape_data, quick):
    names = list(cases)
    table = {f: [[(cases[c].get(m) or _record(outcome="n/a"))[f] for m in MODELS] for c in names] for f in FIELDS}
    meta = {
        "ran": ("1", "model ran (mesh and constants accepted, solver called)"),
        "converged": ("1", "solver converged (static) / integration completed (dynamic)"),
        "error": ("1", "max nodal |u - u_ref| / max |u_ref|, u_ref neo-Hookean FEM on the same mesh "
                       "(implicit_1.5x: max |u| / static max |u|; explicit_*: max nodal distance of the last state "
                       "before the stop from a stable run (half the limit) to the same time / static max |u|; "
                       "unloaded: max |u| / edge length; slender_beam: "
                       "tip deflection / Euler-Bernoulli - 1); NaN where not meaningful"),
        "volume_ratio": ("1", "total volume / rest volume of the final state"),
        "min_volume_ratio": ("1", "smallest element volume / its rest volume (negative: inverted)"),
        "n_inverted": ("1", "number of elements with non-positive volume in the final state (-1: not run)"),
        "iterations": ("1", "Newton iterations of a static solve, all load steps (-1: not recorded)"),
        "stop_step": ("1", "explicit run with allow_unstable: the step at which the divergence detector stopped it "
                           "(-1: n/a)"),
        "stop_displacement": ("1", "explicit run with allow_unstable: max |u| when stopped / static max |u| "
                                   "(NaN: n/a)"),
        "outcome": ("1", "how the run ended or broke (one line)"),
    }
    data = {}
    for f in FIELDS:
        values = np.array(table[f], dtype=object if f == "outcome" else None)
        if f in ("ran", "converged"):
            values = values.astype(np.int8)
        elif f in ("n_inverted", "iterations", "stop_step"):
            values = values.astype(np.int64)
        elif f == "outcome":
            values = values.astype(str)
        units, long_name = meta[f]
        data[f] = (("case", "model"), values, {"units": units, "long_name": long_name})
    shapes = list(SHAPES)
    data["k_lloyd"] = (("shape",), np.array([shape_data[s]["k_lloyd"] for s in shapes]),
                       {"units": "N/m", "long_name": "Lloyd per-element constant (regular tetrahedron of equal volume)"})
    data["k_lsq"] = (("shape", "edge"), np.array([shape_data[s]["k_lsq"] for s in shapes]),
                     {"units": "N/m", "long_name": "element-wise least-squares spring constants vs the FEM element stiffness"})
    data["lsq_residual"] = (("shape",), np.array([shape_data[s]["lsq_residual"] for s in shapes]),
                            {"units": "1", "long_name": "relative Frobenius residual of the element-wise least squares"})
    coords = {
        "case": ("case", np.array(names), {"units": "1", "long_name": "hard case"}),
        "model": ("model", np.array(MODELS), {"units": "1", "long_name": "model"}),
        "shape": ("shape", np.array(shapes), {"units": "1", "long_name": "tetrahedron shape"}),
        "edge": ("edge", np.array([f"{a}-{b}" for a, b in TET_EDGES]), {"units": "1", "long_name": "local edge (nodes)"}),
    }
    return xr.Dataset(data, coords=coords, attrs={
        "title": "msslib stability and hard cases", "E": E0, "quick": int(quick),
        "description": (__doc__ or "").strip().split("\n\n")[0]})


def summary(ds) -> str:
    lines = []
    for c in ds["case"].values:
        lines.append(str(c))
        for m in ds["model"].values:
            text = str(ds["outcome"].sel(case=c, model=m).values)
            if text == "n/a":
                continue
            err = float(ds["error"].sel(case=c, model=m))
            vr = float(ds["volume_ratio"].sel(case=c, model=m))
            lines.append(f"  {m:26s} err {err:8.4f}  V/V0 {vr:7.4f}  {text[:150]}")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", required=True, help="result file (NetCDF)")
    parser.add_argument("--quick", action="store_true", help="smaller meshes (under a minute)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    if not out.parent.is_dir():
        print(f"stability: error: directory {str(out.parent)!r} does not exist", file=sys.stderr)
        return 1
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        cases, shape_data = run_all(args.quick, log=lambda s: print(f"[{time.perf_counter() - t0:6.1f} s] {s}", file=sys.stderr))
    ds = to_dataset(cases, shape_data, args.quick)
    ds.attrs["wall_time_s"] = time.perf_counter() - t0
    write_result(out, ds)
    print(summary(ds))
    print(f"-> {out} ({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
