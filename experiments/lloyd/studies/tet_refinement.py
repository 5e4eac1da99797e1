"""Lloyd's tetrahedral MSS (eqs. 12-13) under mesh refinement and along large-deformation load paths.

Four parts, one NetCDF:

1. *Mesh and fit* per refinement level of the cylinder of the speed-against-error scene (radius
   1 cm, height 2 cm, gmsh size h = 6, 3, 2 mm, E = 15 kPa, nu = 1/4): element quality (radius
   ratio, smallest dihedral angle) and how far each tetrahedron's six springs are from its linear
   FEM stiffness (relative Frobenius norm of K_mss - K_fem per element: eq. 12 with the equivalent
   edge of eq. 13, the best single constant for that shape, and the best six independent constants).
2. *Linear regime*: the MSS linearised at rest (its tangent at x0, i.e. the load -> 0 limit) against
   linear FEM on the same mesh and against linear FEM on a fine mesh (h = 1 mm), shear and stretch.
3. *Large deformation*: the full shear traction of the scene (5 % of E on the top face, along y)
   for the non-linear MSS against neo-Hookean FEM on the same mesh and on the reference mesh of the
   speed-against-error study (h = 1.5 mm), and the MSS error against neo-Hookean FEM on the same
   mesh along the load path (continuation in the load factor).
4. *Load paths* of the two experiments with trouble: the cylinder with a hole under the full
   compressive traction (1800 Pa) and the cone under its shear (2000 Pa): largest displacement,
   smallest relative Jacobian, inverted cells (msslib.mesh.quality) and the smallest eigenvalue of the
   free tangent stiffness (divided by the mean of its diagonal) at every converged load factor.

    python -m experiments.lloyd.studies.tet_refinement --out results/lloyd/studies/tet_refinement.nc [--quick]
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np
import scipy.sparse as sps
import scipy.sparse.linalg as spl
import xarray as xr
import yaml
from scipy.stats import spearmanr

from experiments import script
from experiments.script import LoadSegment
from msslib.compare import interpolate
from msslib.fem import solve_sparse
from msslib.results import mesh_from_result, write_result
from msslib.mesh.quality import relative_jacobians
from msslib.scene import load_scene, prepare, run_scene
from msslib.solvers import ConvergenceError, static_solve

HERE = Path(__file__).resolve().parent
E, NU, RADIUS, HEIGHT = 15000.0, 0.25, 0.01, 0.02
TRACTION = {"shear": (0.0, 0.05 * E, 0.0), "stretch": (0.0, 0.0, 0.12 * E)}
EDGES = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])
K12 = 2.0 * np.sqrt(2.0) / 25.0  # eq. 12: k = K12 E l per element
SLIVER_DEG = 20.0  # a tetrahedron with a dihedral angle below this counts as poorly shaped


# ------------------------------------------------------------------------------------------
# per-element quantities (vectorised over tetrahedra X of shape (m, 4, 3))
# ------------------------------------------------------------------------------------------


def gradients(X):
    """Shape-function gradients (m, 4, 3) and signed volumes (m,) of linear tetrahedra."""
    J = np.stack([X[:, 1] - X[:, 0], X[:, 2] - X[:, 0], X[:, 3] - X[:, 0]], axis=2)
    Ji = np.linalg.inv(J)
    g = np.empty((len(X), 4, 3))
    g[:, 1:] = Ji
    g[:, 0] = -Ji.sum(axis=1)
    return g, np.linalg.det(J) / 6.0


def fem_stiffness(X, E=E, nu=NU):
    """Linear FEM stiffness (m, 12, 12) of each tetrahedron, dofs interleaved by node."""
    g, V = gradients(X)
    lam, mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    K = (lam * np.einsum("mai,mbk->maibk", g, g) + mu * np.einsum("mak,mbi->maibk", g, g)
         + mu * np.einsum("maj,mbj->mab", g, g)[:, :, None, :, None] * np.eye(3)[None, None, :, None, :])
    return (np.abs(V)[:, None, None, None, None] * K).reshape(-1, 12, 12)


def spring_basis(X):
    """Stiffness at rest (m, 6, 12, 12) of a unit spring (1 N/m) on each of the six edges."""
    S = np.zeros((len(X), 6, 4, 3, 4, 3))
    for e, (a, b) in enumerate(EDGES):
        d = X[:, b] - X[:, a]
        n = d / np.linalg.norm(d, axis=1)[:, None]
        A = np.einsum("mi,mk->mik", n, n)
        S[:, e, a, :, a, :] += A
        S[:, e, b, :, b, :] += A
        S[:, e, a, :, b, :] -= A
        S[:, e, b, :, a, :] -= A
    return S.reshape(len(X), 6, 12, 12)


def equivalent_edge(V):
    """Eq. 13: edge of the regular tetrahedron of volume V."""
    return np.cbrt(6.0 * np.sqrt(2.0) * np.abs(V))


def fit_residuals(X, E=E, nu=NU):
    """Relative Frobenius residuals ||K_mss - K_fem|| / ||K_fem|| per element for eq. 12-13, for the
    best single constant (all six springs equal) and for the best six independent constants, and
    whether that six-constant optimum has a negative spring."""
    Kf = fem_stiffness(X, E, nu)
    S = spring_basis(X)
    _, V = gradients(X)
    nf = np.linalg.norm(Kf, axis=(1, 2))
    S1 = S.sum(axis=1)
    k_lloyd = K12 * E * equivalent_edge(V)
    r_lloyd = np.linalg.norm(k_lloyd[:, None, None] * S1 - Kf, axis=(1, 2)) / nf
    k1 = np.einsum("mij,mij->m", S1, Kf) / np.einsum("mij,mij->m", S1, S1)
    r1 = np.linalg.norm(k1[:, None, None] * S1 - Kf, axis=(1, 2)) / nf
    G = np.einsum("maij,mbij->mab", S, S)
    k6 = np.linalg.solve(G, np.einsum("maij,mij->ma", S, Kf)[..., None])[..., 0]
    r6 = np.linalg.norm(np.einsum("ma,maij->mij", k6, S) - Kf, axis=(1, 2)) / nf
    return {"lloyd": r_lloyd, "best1": r1, "best6": r6, "k1_over_lloyd": k1 / k_lloyd, "negative6": (k6 < 0).any(axis=1)}


def quality(X):
    """Radius ratio 3 r_in / r_circ (1 for the regular tetrahedron) and smallest dihedral angle (deg)."""
    g, V = gradients(X)
    areas = np.linalg.norm(g, axis=2) * 3.0 * np.abs(V)[:, None]
    r_in = 3.0 * np.abs(V) / areas.sum(axis=1)
    P = X[:, 1:] - X[:, :1]
    centre = np.linalg.solve(P, 0.5 * np.sum(P * P, axis=2)[..., None])[..., 0]
    n = g / np.linalg.norm(g, axis=2)[..., None]
    cos = np.stack([-np.sum(n[:, a] * n[:, b], axis=1) for a, b in EDGES], axis=1)
    dihedral = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    return 3.0 * r_in / np.linalg.norm(centre, axis=1), dihedral.min(axis=1)


def element_strain(X, u_cells):
    """Small strain (m, 3, 3) of each tetrahedron from its node displacements (m, 4, 3)."""
    g, _ = gradients(X)
    H = np.einsum("mai,maj->mij", u_cells, g)
    return 0.5 * (H + np.swapaxes(H, 1, 2))


# ------------------------------------------------------------------------------------------
# scenes, linear solves, continuation
# ------------------------------------------------------------------------------------------


def cylinder_scene(h, model, case, scale=1.0):
    return {"name": f"cylinder_{case}_{h * 1e3:g}mm_{model}",
            "geometry": {"generator": "cylinder_mesh", "args": {"radius": RADIUS, "height": HEIGHT, "h": h}},
            "materials": [{"E": E, "nu": NU}], "model": model,
            "boundary": [{"select": {"plane": ["z", 0.0]}, "fix": "all"}],
            "loads": [{"type": "traction", "select": {"plane": ["z", HEIGHT]},
                       "traction": [scale * t for t in TRACTION[case]]}],
            "solver": {"type": "static", "load_steps": 4, "tol": 1e-8}}


def assemble(mesh, Ke):
    dofs = (3 * mesh.cells[:, :, None] + np.arange(3)).reshape(-1, 12)
    n = 3 * mesh.n_nodes
    return sps.csr_matrix((Ke.ravel(), (np.repeat(dofs, 12, axis=1).ravel(), np.tile(dofs, 12).ravel())), shape=(n, n))


def linear_solve(K, forces, fixed):
    free = ~fixed.ravel()
    u = np.zeros(K.shape[0])
    u[free] = solve_sparse(K[free][:, free], forces.ravel()[free])  # the library's solver layer
    return u.reshape(-1, 3)


def lowest_eigenvalue(model, x, load):
    """Smallest eigenvalue of the free tangent at (x, load), divided by the mean of its diagonal."""
    Kf = model.stiffness(x, load)[model.free][:, model.free].tocsc()
    d = float(np.abs(Kf.diagonal()).mean())
    val = spl.eigsh(Kf / d, k=1, sigma=-1e-3, which="LM", return_eigenvectors=False)
    return float(val[0])


def continuation(setup, loads, tol=1e-9, eig=True):
    """Follow the MSS of ``setup`` through the load factors ``loads`` (increasing); stops at the first
    that Newton (6 halvings) cannot reach. Rows (load, x, lowest eigenvalue); and the failed load or None."""
    model = setup.model
    f_ref = float(np.linalg.norm((model.force(model.x0, 1.0) - model.force(model.x0, 0.0))[model.free]))
    x, a, rows = model.x0.copy(), 0.0, []
    for b in loads:
        try:
            x = static_solve(LoadSegment(model, a, b), x, load_steps=1, tol=tol, force_scale=f_ref, max_cuts=6).x
        except ConvergenceError:
            return rows, float(b)
        a = float(b)
        rows.append((a, x.copy(), lowest_eigenvalue(model, x, a) if eig else np.nan))
    return rows, None


def errors(u, u_ref):
    """Max and mean node distance relative to the largest reference displacement."""
    d = np.linalg.norm(u - u_ref, axis=1)
    s = float(np.linalg.norm(u_ref, axis=1).max())
    return float(d.max() / s), float(d.mean() / s)


# ------------------------------------------------------------------------------------------
# the parts
# ------------------------------------------------------------------------------------------


def part_mesh_and_linear(levels, h_lin_ref, progress):
    out = {k: [] for k in ("n_nodes", "n_cells", "rho_min", "rho_median", "dihedral_min", "dihedral_median",
                           "poor_fraction", "fit_lloyd_median", "fit_lloyd_p90", "fit_best1_median", "fit_best6_median",
                           "negative6_fraction", "k1_ratio_median", "spearman_fit_rho", "spearman_strain_rho")}
    lin = {k: np.full((len(TRACTION), len(levels)), np.nan) for k in
           ("lin_same_max", "lin_same_mean", "lin_ref_max", "lin_ref_mean", "lin_fem_ref_max", "lin_fem_ref_mean")}
    elem = {k: [] for k in ("element_level", "element_rho", "element_dihedral_min", "element_fit_lloyd",
                            "element_fit_best6", "element_strain_error")}
    refs = {}
    for c, case in enumerate(TRACTION):
        st = prepare(load_scene(cylinder_scene(h_lin_ref, "fem_linear", case)))
        X = st.mesh.points[st.mesh.cells]
        refs[case] = (st.mesh, linear_solve(assemble(st.mesh, fem_stiffness(X)), st.surface_forces, st.fixed))
    progress(f"linear references at h = {h_lin_ref * 1e3:g} mm: {refs['shear'][0].n_nodes} nodes")
    for j, h in enumerate(levels):
        for c, case in enumerate(TRACTION):
            st = prepare(load_scene(cylinder_scene(h, "lloyd_tetrahedron", case)))
            mesh = st.mesh
            X = mesh.points[mesh.cells]
            u_fem = linear_solve(assemble(mesh, fem_stiffness(X)), st.surface_forces, st.fixed)
            u_mss = linear_solve(st.model.stiffness(st.model.x0), st.surface_forces, st.fixed)
            u_ref = interpolate(refs[case][0], refs[case][1], mesh)  # checked both ways: one body
            lin["lin_same_max"][c, j], lin["lin_same_mean"][c, j] = errors(u_mss, u_fem)
            lin["lin_ref_max"][c, j], lin["lin_ref_mean"][c, j] = errors(u_mss, u_ref)
            lin["lin_fem_ref_max"][c, j], lin["lin_fem_ref_mean"][c, j] = errors(u_fem, u_ref)
            if case != "shear":
                continue
            rho, dmin = quality(X)
            fit = fit_residuals(X)
            eps_f = element_strain(X, u_fem[mesh.cells])
            eps_m = element_strain(X, u_mss[mesh.cells])
            strain_err = np.linalg.norm(eps_m - eps_f, axis=(1, 2)) / np.sqrt(np.mean(np.sum(eps_f**2, axis=(1, 2))))
            for k, v in (("n_nodes", mesh.n_nodes), ("n_cells", mesh.n_cells), ("rho_min", rho.min()),
                         ("rho_median", np.median(rho)), ("dihedral_min", dmin.min()), ("dihedral_median", np.median(dmin)),
                         ("poor_fraction", np.mean(dmin < SLIVER_DEG)), ("fit_lloyd_median", np.median(fit["lloyd"])),
                         ("fit_lloyd_p90", np.percentile(fit["lloyd"], 90)), ("fit_best1_median", np.median(fit["best1"])),
                         ("fit_best6_median", np.median(fit["best6"])), ("negative6_fraction", fit["negative6"].mean()),
                         ("k1_ratio_median", np.median(fit["k1_over_lloyd"])),
                         ("spearman_fit_rho", spearmanr(rho, fit["lloyd"])[0]),
                         ("spearman_strain_rho", spearmanr(rho, strain_err)[0])):
                out[k].append(float(v))
            for k, v in (("element_level", np.full(mesh.n_cells, j)), ("element_rho", rho), ("element_dihedral_min", dmin),
                         ("element_fit_lloyd", fit["lloyd"]), ("element_fit_best6", fit["best6"]),
                         ("element_strain_error", strain_err)):
                elem[k].append(v)
        progress(f"h = {h * 1e3:g} mm: {out['n_nodes'][-1]:.0f} nodes, linear shear error vs same-mesh FEM "
                 f"{100 * lin['lin_same_max'][0, j]:.3g} % (max), fit residual median {out['fit_lloyd_median'][-1]:.3f}")
    return out, lin, {k: np.concatenate(v) for k, v in elem.items()}


def _run(sc):
    ds = run_scene(sc, progress=False)
    return mesh_from_result(ds), ds["displacement"].transpose("node", "axis").values, ds


def part_large(levels, h_nl_ref, sweep, progress):
    ref_mesh, u_ref, _ = _run(cylinder_scene(h_nl_ref, "fem_neohookean", "shear"))
    progress(f"neo-Hookean reference at h = {h_nl_ref * 1e3:g} mm: {ref_mesh.n_nodes} nodes")
    s_ref = float(np.linalg.norm(u_ref, axis=1).max())
    names = ("nl_mss_same_max", "nl_mss_same_mean", "nl_mss_ref_max", "nl_mss_ref_mean", "nl_nh_ref_max",
             "nl_nh_ref_mean", "nl_lin_ref_max", "nl_mss_min_jacobian", "nl_mss_inverted")
    out = {k: np.full(len(levels), np.nan) for k in names}
    path_same = np.full((len(levels), len(sweep)), np.nan)
    path_inverted = np.full((len(levels), len(sweep)), np.nan)
    worst = np.full((len(levels), 2), np.nan)  # (y, z) of the most compressed cell at the full load
    for j, h in enumerate(levels):
        mesh, u_nh, _ = _run(cylinder_scene(h, "fem_neohookean", "shear"))
        _, u_lin, _ = _run(cylinder_scene(h, "fem_linear", "shear"))
        st = prepare(load_scene(cylinder_scene(h, "lloyd_tetrahedron", "shear")))
        rows, failed = continuation(st, sweep, tol=1e-8, eig=False)
        for i, (load, x, _) in enumerate(rows):
            u = (x - st.model.x0).reshape(-1, 3)
            _, u_nh_l, _ = (None, u_nh, None) if load == 1.0 else _run(cylinder_scene(h, "fem_neohookean", "shear", load))
            path_same[j, i] = errors(u, u_nh_l)[0]
            path_inverted[j, i] = (relative_jacobians(mesh, x.reshape(-1, 3)) < 0).sum()
        if failed is not None or rows[-1][0] != 1.0:
            progress(f"h = {h * 1e3:g} mm: the MSS stopped at load factor {failed}")
            continue
        u_mss = (rows[-1][1] - st.model.x0).reshape(-1, 3)
        ui = interpolate(ref_mesh, u_ref, mesh)

        def d(u, ui=ui):
            return np.linalg.norm(u - ui, axis=1) / s_ref

        rj = relative_jacobians(mesh, rows[-1][1].reshape(-1, 3))
        out["nl_mss_same_max"][j], out["nl_mss_same_mean"][j] = errors(u_mss, u_nh)
        out["nl_mss_ref_max"][j], out["nl_mss_ref_mean"][j] = d(u_mss).max(), d(u_mss).mean()
        out["nl_nh_ref_max"][j], out["nl_nh_ref_mean"][j] = d(u_nh).max(), d(u_nh).mean()
        out["nl_lin_ref_max"][j] = d(u_lin).max()
        out["nl_mss_min_jacobian"][j], out["nl_mss_inverted"][j] = rj.min(), (rj < 0).sum()
        worst[j] = mesh.points[mesh.cells[int(np.argmin(rj))]].mean(axis=0)[1:]
        progress(f"h = {h * 1e3:g} mm, full shear: MSS vs same-mesh neo-Hookean {100 * out['nl_mss_same_max'][j]:.3g} %, "
                 f"vs reference {100 * out['nl_mss_ref_max'][j]:.3g} %, neo-Hookean vs reference {100 * out['nl_nh_ref_max'][j]:.3g} %")
    return out, (path_same, path_inverted, worst), s_ref


def _experiment(name):
    return yaml.safe_load((HERE.parent / f"{name}.yaml").read_text())


def experiment_scene(name, case, h=None, loads_from=None):
    """The MSS scene of an experiment's case (``loads_from``: take the loads of that experiment's case)."""
    exp = _experiment(name)
    loads = _experiment(loads_from or name)["cases"][case]["loads"]
    sc = dict(exp["scene"], name=f"{name}_{case}", model="lloyd_tetrahedron", loads=loads)
    if h is not None:
        sc["geometry"] = dict(sc["geometry"], args=dict(sc["geometry"]["args"], h=h))
    return sc


def part_path(sc, loads, progress, label):
    st = prepare(load_scene(sc))
    rows, failed = continuation(st, loads)
    n = len(loads)
    res = {k: np.full(n, np.nan) for k in ("umax", "min_jacobian", "inverted", "eig")}
    where = {"z": np.nan, "r": np.nan}
    for i, (load, x, lam) in enumerate(rows):
        rj = relative_jacobians(st.mesh, x.reshape(-1, 3))
        res["umax"][i] = np.linalg.norm((x - st.model.x0).reshape(-1, 3), axis=1).max()
        res["min_jacobian"][i], res["inverted"][i], res["eig"][i] = rj.min(), (rj < 0).sum(), lam
        if i == len(rows) - 1:  # where the most compressed (or inverted) cell of the last state is
            c = st.mesh.points[st.mesh.cells[int(np.argmin(rj))]].mean(axis=0)
            where = {"z": float(c[2]), "r": float(np.hypot(c[0], c[1]))}
    # neo-Hookean FEM on the same mesh at the full load, for comparison
    _, u_nh, ds_nh = _run(dict(sc, model="fem_neohookean"))
    res["nh_umax"] = float(np.linalg.norm(u_nh, axis=1).max())
    res["nh_min_jacobian"] = float(ds_nh.attrs["min_relative_jacobian"])
    last = rows[-1][0] if rows else 0.0
    progress(f"{label}: {st.mesh.n_nodes} nodes, last converged load factor {last:g}"
             + (f", failed at {failed:g}" if failed is not None else "")
             + f", inverted cells at the end {int(res['inverted'][len(rows) - 1]) if rows else 0}")
    return res, last, (np.nan if failed is None else failed), where, st.mesh.n_nodes


def main(argv=None):
    args = script.args(__doc__, argv)
    t0 = time.perf_counter()

    def progress(text):
        print(f"[{time.perf_counter() - t0:6.1f} s] {text}", flush=True)

    if args.quick:
        levels, h_lin, h_nl, sweep = (0.006,), 0.003, 0.003, (0.25, 1.0)
        hole_h, cone_h = 0.004, 0.004
        hole_loads = np.array([0.5])
        cone_loads = np.array([1.0])
    else:
        levels, h_lin, h_nl, sweep = (0.006, 0.003, 0.002), 0.001, 0.0015, (0.05, 0.25, 0.5, 0.75, 0.9, 0.95, 1.0)
        hole_h, cone_h = None, None
        hole_loads = np.round(np.concatenate([np.arange(0.1, 0.61, 0.1), np.arange(0.62, 0.801, 0.01)]), 3)
        cone_loads = np.round(np.concatenate([np.arange(0.2, 0.81, 0.2), np.arange(0.85, 1.001, 0.05)]), 3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # inverted-cell warnings of the MSS runs are recorded as data here
        mesh_stats, lin, elem = part_mesh_and_linear(levels, h_lin, progress)
        large, (path_same, path_inverted, worst), s_ref = part_large(levels, h_nl, sweep, progress)
        # the hole cylinder under the compressive traction of the full cylinder (its experiment uses less)
        hole, hole_last, hole_failed, hole_where, hole_nodes = part_path(
            experiment_scene("cylinder_hole", "compression", hole_h, loads_from="cylinder"), hole_loads, progress,
            "hole cylinder, 1800 Pa compression")
        cone, cone_last, cone_failed, cone_where, cone_nodes = part_path(
            experiment_scene("cone", "shear", cone_h), cone_loads, progress, "cone, 2000 Pa shear")

    h_mm = np.array(levels) * 1e3
    L, C = ("level",), ("case", "level")
    rel = "node distance / largest reference displacement"
    data = {
        "n_nodes": (L, np.array(mesh_stats["n_nodes"]), {"units": "1", "long_name": "nodes"}),
        "n_cells": (L, np.array(mesh_stats["n_cells"]), {"units": "1", "long_name": "tetrahedra"}),
        "rho_min": (L, mesh_stats["rho_min"], {"units": "1", "long_name": "smallest radius ratio 3 r_in / r_circ"}),
        "rho_median": (L, mesh_stats["rho_median"], {"units": "1", "long_name": "median radius ratio"}),
        "dihedral_min": (L, mesh_stats["dihedral_min"], {"units": "degree", "long_name": "smallest dihedral angle"}),
        "dihedral_median": (L, mesh_stats["dihedral_median"], {"units": "degree", "long_name": "median of the smallest dihedral angle per element"}),
        "poor_fraction": (L, mesh_stats["poor_fraction"], {"units": "1", "long_name": f"fraction of elements with a dihedral angle below {SLIVER_DEG:g} degrees"}),
        "fit_lloyd_median": (L, mesh_stats["fit_lloyd_median"], {"units": "1", "long_name": "median ||K_mss - K_fem||_F / ||K_fem||_F per element, eq. 12-13"}),
        "fit_lloyd_p90": (L, mesh_stats["fit_lloyd_p90"], {"units": "1", "long_name": "90th percentile of the eq. 12-13 residual"}),
        "fit_best1_median": (L, mesh_stats["fit_best1_median"], {"units": "1", "long_name": "median residual of the best single constant per element"}),
        "fit_best6_median": (L, mesh_stats["fit_best6_median"], {"units": "1", "long_name": "median residual of the best six constants per element"}),
        "negative6_fraction": (L, mesh_stats["negative6_fraction"], {"units": "1", "long_name": "fraction of elements whose best six constants include a negative one"}),
        "k1_ratio_median": (L, mesh_stats["k1_ratio_median"], {"units": "1", "long_name": "median best single constant / eq. 12-13 constant"}),
        "spearman_fit_rho": (L, mesh_stats["spearman_fit_rho"], {"units": "1", "long_name": "rank correlation of fit residual with radius ratio"}),
        "spearman_strain_rho": (L, mesh_stats["spearman_strain_rho"], {"units": "1", "long_name": "rank correlation of the element strain error (linear shear) with radius ratio"}),
        **{k: (C, v, {"units": "1", "long_name": f"{k.split('_')[-1]} {rel}; " + {
            "lin_same": "linearised MSS vs linear FEM on the same mesh",
            "lin_ref": f"linearised MSS vs linear FEM at h = {h_lin * 1e3:g} mm",
            "lin_fem_ref": f"linear FEM vs linear FEM at h = {h_lin * 1e3:g} mm"}[k.rsplit('_', 1)[0]]})
           for k, v in lin.items()},
        **{k: (L, v, {"units": "1", "long_name": {
            "nl_mss_same_max": "max " + rel + "; MSS vs neo-Hookean FEM on the same mesh, full shear",
            "nl_mss_same_mean": "mean " + rel + "; MSS vs neo-Hookean FEM on the same mesh, full shear",
            "nl_mss_ref_max": "max " + rel + f"; MSS vs neo-Hookean FEM at h = {h_nl * 1e3:g} mm, full shear",
            "nl_mss_ref_mean": "mean " + rel + f"; MSS vs neo-Hookean FEM at h = {h_nl * 1e3:g} mm, full shear",
            "nl_nh_ref_max": "max " + rel + f"; neo-Hookean FEM vs the same at h = {h_nl * 1e3:g} mm",
            "nl_nh_ref_mean": "mean " + rel + f"; neo-Hookean FEM vs the same at h = {h_nl * 1e3:g} mm",
            "nl_lin_ref_max": "max " + rel + f"; linear FEM vs neo-Hookean FEM at h = {h_nl * 1e3:g} mm",
            "nl_mss_min_jacobian": "smallest relative Jacobian of the MSS, full shear",
            "nl_mss_inverted": "inverted cells of the MSS, full shear"}[k]}) for k, v in large.items()},
        "path_mss_inverted": (("level", "load"), path_inverted, {"units": "1", "long_name": "inverted cells of the MSS along the shear load"}),
        "nl_worst_y": (L, worst[:, 0], {"units": "m", "long_name": "y of the most compressed MSS cell, full shear (load along +y)"}),
        "nl_worst_z": (L, worst[:, 1], {"units": "m", "long_name": "height of the most compressed MSS cell, full shear"}),
        "path_mss_same_max": (("level", "load"), path_same, {"units": "1", "long_name": "max " + rel + "; MSS vs neo-Hookean FEM on the same mesh, shear"}),
        **{f"element_{k.split('_', 1)[1]}": (("element",), v, {"units": "degree" if "dihedral" in k else "1"})
           for k, v in elem.items()},
    }
    for name, res, last, failed, where, nodes, loads in (
            ("hole", hole, hole_last, hole_failed, hole_where, hole_nodes, hole_loads),
            ("cone", cone, cone_last, cone_failed, cone_where, cone_nodes, cone_loads)):
        dim = f"{name}_load"
        data[f"{name}_umax"] = (dim, res["umax"], {"units": "m", "long_name": "largest MSS displacement"})
        data[f"{name}_min_jacobian"] = (dim, res["min_jacobian"], {"units": "1", "long_name": "smallest relative Jacobian"})
        data[f"{name}_inverted"] = (dim, res["inverted"], {"units": "1", "long_name": "inverted cells"})
        data[f"{name}_eig"] = (dim, res["eig"], {"units": "1", "long_name": "smallest eigenvalue of the free tangent / mean diagonal"})
        data[f"{name}_last_load"] = ((), last, {"units": "1", "long_name": "last converged load factor"})
        data[f"{name}_failed_load"] = ((), failed, {"units": "1", "long_name": "first load factor Newton could not reach (NaN: none)"})
        data[f"{name}_worst_z"] = ((), where["z"], {"units": "m", "long_name": "height of the most compressed cell, last state"})
        data[f"{name}_worst_r"] = ((), where["r"], {"units": "m", "long_name": "distance from the axis of the most compressed cell, last state"})
        data[f"{name}_nodes"] = ((), nodes, {"units": "1", "long_name": "nodes"})
        ok = np.flatnonzero(np.isfinite(res["umax"]))
        inv = np.flatnonzero(res["inverted"] > 0)
        for key, idx, what in (("eig", 0, "first"), ("eig", -1, "last"), ("min_jacobian", -1, "last"),
                               ("inverted", -1, "last"), ("umax", -1, "last")):
            v = res[key][ok[idx]] if len(ok) else np.nan
            data[f"{name}_{key}_{what}"] = ((), v, {**data[f"{name}_{key}"][2], "long_name": data[f"{name}_{key}"][2]["long_name"]
                                                    + f", {what} converged load factor"})
        data[f"{name}_first_inverted_load"] = ((), loads[inv[0]] if len(inv) else np.nan,
                                               {"units": "1", "long_name": "first load factor with an inverted cell (NaN: none)"})
        data[f"{name}_before_inverted_load"] = ((), loads[inv[0] - 1] if len(inv) and inv[0] > 0 else np.nan,
                                                {"units": "1", "long_name": "last load factor before the first inverted cell"})
        data[f"{name}_nh_umax"] = ((), res["nh_umax"], {"units": "m", "long_name": "largest displacement, neo-Hookean FEM, full load"})
        data[f"{name}_nh_min_jacobian"] = ((), res["nh_min_jacobian"], {"units": "1", "long_name": "smallest relative Jacobian, neo-Hookean FEM, full load"})
    # the coarsest and the finest level as scalars (the same label exists in the quick and the full run)
    for name in [k for k, v in data.items() if "level" in v[0] and k not in ("n_nodes", "n_cells")]:
        dims, values, attrs = data[name]
        ax = dims.index("level")
        rest = tuple(d for d in dims if d != "level")
        for end, idx in (("coarse", 0), ("fine", -1)):
            data[f"{name}_{end}"] = (rest, np.take(np.asarray(values), idx, axis=ax),
                                     {**attrs, "long_name": f"{attrs['long_name']} ({end}st level)"})
    # the load sweep at the finest level, first load and full load
    data["path_fine_first"] = ((), path_same[-1, 0], {"units": "1", "long_name": f"max {rel}; MSS vs neo-Hookean, same mesh, finest level, load factor {sweep[0]:g}"})
    clean = np.flatnonzero(path_inverted[-1] == 0)
    data["path_fine_clean_load"] = ((), sweep[clean[-1]] if len(clean) else np.nan,
                                    {"units": "1", "long_name": "largest swept load factor without an inverted cell, finest level"})
    data["path_fine_clean_max"] = ((), path_same[-1, clean[-1]] if len(clean) else np.nan,
                                   {"units": "1", "long_name": f"max {rel}; MSS vs neo-Hookean, same mesh, finest level, at that load"})
    coords = {
        "level": ("level", np.arange(len(levels)), {"units": "1", "long_name": "refinement level"}),
        "h": ("level", h_mm, {"units": "mm", "long_name": "gmsh element size"}),
        "case": ("case", list(TRACTION), {"units": "1", "long_name": "load case"}),
        "load": ("load", np.array(sweep), {"units": "1", "long_name": "load factor of the shear traction"}),
        "hole_load": ("hole_load", hole_loads, {"units": "1", "long_name": "load factor of 1800 Pa compression"}),
        "cone_load": ("cone_load", cone_loads, {"units": "1", "long_name": "load factor of 2000 Pa shear"}),
    }
    ds = xr.Dataset(data, coords=coords, attrs={
        "title": "Lloyd's tetrahedral MSS under refinement and along large-deformation load paths",
        "E": E, "nu": NU, "shear_traction": TRACTION["shear"][1], "stretch_traction": TRACTION["stretch"][2],
        "h_linear_reference_mm": h_lin * 1e3, "h_nonlinear_reference_mm": h_nl * 1e3,
        "reference_max_displacement": s_ref, "quick": int(args.quick)})
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_result(out, ds)
    progress(f"wrote {out}")


if __name__ == "__main__":
    main()
