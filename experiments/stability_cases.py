"""The hard cases of :mod:`experiments.stability`, one function per case (each returns a record per
model, see :func:`experiments.stability_common._record`)."""

from __future__ import annotations

import time

import numpy as np

from experiments.stability_common import (
    CUBE_MODELS,
    DENSITY,
    E0,
    FEM_MODELS,
    MSS_MODELS,
    TET_EDGES,
    TET_MODELS,
    _record,
    _short,
    clamped_bc,
    cube_meshes,
    mss_terms,
    run_fem,
    run_mss,
    sliding_bc,
)
from msslib.models.common import assemble_springs
from msslib import fem
from msslib import mesh as M
from msslib import system as MD
from msslib import parameters as P
from msslib import solvers as S
from msslib.terms import Gravity, Traction

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
    return float(P.lloyd_tetrahedron(E, l=P.equivalent_edge_length(V), nu=nu).k)


def shape_case(shape, nu=0.3):
    """Per-shape data and the (case, model) records."""
    X = shape_coordinates(shape)
    k_lloyd = lloyd_constant(X, E0, nu)
    k_lsq, resid = elementwise_lsq(X, E0, nu)
    mesh = M.Mesh(X, np.array([[0, 1, 2, 3]]), "tetra")
    neg = np.flatnonzero(k_lsq <= 0)
    try:
        local = {tuple(sorted(e)): i for i, e in enumerate(TET_EDGES.tolist())}
        assemble_springs(mesh, "edges", lambda _c, pairs: k_lsq[[local[tuple(q)] for q in pairs.tolist()]])
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
