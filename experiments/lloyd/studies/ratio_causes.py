"""Lloyd et al., Secs. 5.1 and 5.3: what sets the ratio mean error / max error, one factor at a time.

For an MSS that matches the FEM exactly at small strain (eq. 8 on equilateral triangles, eq. 10-11
on squares) the error grows with the square of the load and its shape over the mesh, hence the
ratio mean/max, hardly depends on the load; it depends on how the experiment is set up.  Starting
from the set-up of the experiment files (``membrane_equilateral.yaml``, ``membrane_square.yaml``:
consistent nodal forces for the edge traction, the FEM on the same mesh, the load that gives the
stated deformation in the FEM) one factor is changed at a time:

* ``equal_forces``: the same total force split equally over the loaded nodes (the corner nodes of
  the top edge get a full share instead of half of one);
* ``mss_strain``: the load that gives the stated deformation in the MSS instead of the FEM;
* Sec. 5.1 ``flipped``: the equilateral mesh upside down, so that the top row has 7 nodes with one
  in the middle (the paper measures the strain "at corner or middle node on top boundary"; the
  file's mesh has 39 nodes and 93 springs either way), and, as the one
  combination, ``flipped_equal_forces``;
* Sec. 5.1 ``counts_mesh``: a mesh with the paper's counts (the file's mesh has 39 nodes and 93
  springs, 55 triangles: rows of 7, 6, 7, 6, 7, 6 nodes, edge 1.2 cm; 92 springs with 39 nodes
  means 54 triangles, which rows of equilateral triangles give only as 6, 5, 6, 5, 6, 5, 6 nodes:
  edge 1 cm, 5 cm wide and, with six rows of triangles, the stated 5.2 cm high);
* Sec. 5.3, the reference the paper calls "constant strain rectangle elements": bilinear quads
  (Q1, the file's) or constant-strain triangles, each square split along one diagonal
  (``cst_slash``: lower left to upper right, ``cst_backslash``: the other) or along both with a
  node at its centre (``cst_crossed``); the error is taken at the square mesh's nodes; or the
  literal constant strain rectangle, bilinear quads integrated at their centre only
  (``q1_one_point``: the strain of each element is its centre's, constant; the share of the
  reference's bilinear energy in the hourglass modes that this element does not resist is
  written as ``hourglass_energy_fraction``).

Deformation: Sec. 5.1 stretch and compression, the mean of the vertical strain at the top corner
node and in the middle of the top edge (the paper: 11.2-13.6 % at these two points; we aim at the
middle of that range, 12.4 %; the paper gives it for the stretch only and we use it for the
compression too); Sec. 5.3 stretch and compression, the mean strain of the top edge (12 %); shear,
the mean top displacement over the height (13 %, the end of the paper's general "ten to thirteen
percent").

    python -m experiments.lloyd.studies.ratio_causes --out results/lloyd/studies/ratio_causes.nc [--quick]
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from msslib.models.lloyd import lloyd_square_springs, lloyd_triangle_springs
from msslib import fem
from msslib import mesh as M
from msslib.results import write_result
from msslib.metrics import displacement_error
from msslib.system import Model
from msslib.solvers import static_solve
from msslib.terms import NodalForces, Traction

E, NU, THICKNESS = 14630.0, 1.0 / 3.0, 0.01
#: published max and mean errors (m), Secs. 5.1 and 5.3
PUBLISHED = {
    ("5.1", "stretch"): (0.033e-2, 0.008e-2), ("5.1", "compression"): (0.061e-2, 0.012e-2),
    ("5.1", "shear"): (0.098e-2, 0.034e-2),
    ("5.3", "stretch"): (0.076e-2, 0.041e-2), ("5.3", "compression"): (0.129e-2, 0.0677e-2),
    ("5.3", "shear"): (0.196e-2, 0.066e-2),
}
TARGET = {("5.1", "stretch"): 0.124, ("5.1", "compression"): 0.124, ("5.1", "shear"): 0.13,
          ("5.3", "stretch"): 0.12, ("5.3", "compression"): 0.12, ("5.3", "shear"): 0.13}
DIRECTION = {"stretch": (0.0, 1.0), "compression": (0.0, -1.0), "shear": (1.0, 0.0)}
FACTORS = {"5.1": ["baseline", "equal_forces", "mss_strain", "flipped", "flipped_equal_forces", "counts_mesh"],
           "5.3": ["baseline", "equal_forces", "mss_strain", "cst_slash", "cst_backslash", "cst_crossed", "q1_one_point"]}
FACTOR_TEXT = {
    "baseline": "as the experiment file: consistent forces, reference on the same mesh, load from the FEM strain",
    "equal_forces": "equal nodal forces on the top edge",
    "mss_strain": "load from the strain of the MSS",
    "flipped": "equilateral mesh upside down (7 nodes on the top edge)",
    "flipped_equal_forces": "both: mesh upside down and equal nodal forces",
    "counts_mesh": "equilateral mesh with the paper's counts (39 nodes, 92 springs; edge 1 cm, rows of 6 and 5 nodes)",
    "cst_slash": "reference: constant-strain triangles, squares split lower left - upper right",
    "cst_backslash": "reference: constant-strain triangles, squares split lower right - upper left",
    "cst_crossed": "reference: constant-strain triangles, squares split along both diagonals (centre node)",
    "q1_one_point": "reference: bilinear quads with one-point quadrature (constant strain rectangles)",
}


#: Sec. 5.1 with the paper's counts: 5 edges of 1.0008 cm across, six rows of triangles 5.2 cm high
COUNTS_MESH = (0.05004, 0.0521, 5)


def membrane(section, flipped=False, counts=False):
    """Mesh of the experiment (Sec. 5.1: 39-node equilateral membrane, the file's or with the paper's
    counts; 5.3: 5 x 5 squares)."""
    if section == "5.1":
        mesh = M.triangle_grid_equilateral(*(COUNTS_MESH if counts else (0.0720534, 0.0521, 6)))
        if flipped:
            p = mesh.points.copy()
            p[:, 1] = p[:, 1].max() - p[:, 1]
            mesh = M.Mesh(p, mesh.cells[:, ::-1], "triangle")  # mirrored: reverse the node order
        return mesh
    return M.quad_grid(0.05, 0.05, 5, 5)


def split_squares(mesh, how):
    """Constant-strain triangle mesh of a quad mesh; the quad mesh's nodes keep their numbers."""
    q = mesh.cells
    if how == "cst_slash":
        return M.Mesh(mesh.points, np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]]), "triangle")
    if how == "cst_backslash":
        return M.Mesh(mesh.points, np.concatenate([q[:, [0, 1, 3]], q[:, [1, 2, 3]]]), "triangle")
    centre = mesh.n_nodes + np.arange(len(q))
    points = np.vstack([mesh.points, mesh.points[q].mean(axis=1)])
    cells = np.concatenate([np.column_stack([q[:, k], q[:, (k + 1) % 4], centre]) for k in range(4)])
    return M.Mesh(points, cells, "triangle")


def loads(mesh, case, equal):
    """Nodal forces (N) of a unit traction (1 Pa) along the case's direction on the top edge."""
    y = mesh.points[:, 1]
    top = np.isclose(y, y.max())
    facets = M.boundary_facets(mesh)
    on_top = facets[top[facets].all(axis=1)]
    f = Traction(mesh, on_top, np.asarray(DIRECTION[case]), THICKNESS).nodal
    if equal:
        total = f.sum(axis=0)
        f = np.zeros_like(f)
        f[top] = total / top.sum()
    return f


def corner_middle(mesh, case, u):
    """Displacement along the load over the height at the top corner nodes and in the middle of
    the top edge (the middle node, or the two nodes nearest the middle)."""
    X = mesh.points
    H = np.ptp(X[:, 1])
    top = np.flatnonzero(np.isclose(X[:, 1], X[:, 1].max()))
    x = X[top, 0]
    off = np.abs(x - 0.5 * (x.min() + x.max()))
    corner, mid = top[np.isclose(off, off.max())], top[np.isclose(off, off.min(), atol=1e-9)]
    d = np.asarray(DIRECTION[case])
    return float(np.mean(u[corner] @ d) / H), float(np.mean(u[mid] @ d) / H)


def measure(section, case, mesh, u):
    """The deformation the load is set by (see the module text)."""
    if section == "5.1" and case != "shear":
        return float(np.mean(corner_middle(mesh, case, u)))
    X = mesh.points
    top = np.flatnonzero(np.isclose(X[:, 1], X[:, 1].max()))
    return float(np.mean(u[top] @ np.asarray(DIRECTION[case])) / np.ptp(X[:, 1]))


def run(section, case, factor):
    mesh = membrane(section, flipped=factor.startswith("flipped"), counts=factor == "counts_mesh")
    fixed = np.zeros((mesh.n_nodes, 2), dtype=bool)
    fixed[np.isclose(mesh.points[:, 1], mesh.points[:, 1].min())] = True
    f1 = loads(mesh, case, equal=factor.endswith("equal_forces"))
    springs = (lloyd_triangle_springs if section == "5.1" else lloyd_square_springs)(mesh, [(E, NU)], THICKNESS)

    hourglass = []

    def reference(t):
        if factor.startswith("cst"):
            tri = split_squares(mesh, factor)
            fx = np.zeros((tri.n_nodes, 2), dtype=bool)
            fx[:mesh.n_nodes] = fixed
            ff = np.zeros((tri.n_nodes, 2))
            ff[:mesh.n_nodes] = t * f1
            return fem.solve_linear(tri, E, NU, fixed=fx, nodal_forces=ff, thickness=THICKNESS).displacement[:mesh.n_nodes]
        if factor == "q1_one_point":
            with warnings.catch_warnings():  # the hourglass share is recorded instead of warned
                warnings.simplefilter("ignore")
                res = fem.solve_linear(mesh, E, NU, fixed=fixed, nodal_forces=t * f1, thickness=THICKNESS,
                                       quadrature="one_point")
            hourglass.append(res.stats["hourglass_energy_fraction"])
            return res.displacement
        return fem.solve_linear(mesh, E, NU, fixed=fixed, nodal_forces=t * f1, thickness=THICKNESS).displacement

    def mss(t):
        model = Model(mesh, springs + [NodalForces(t * f1)], fixed=fixed)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = static_solve(model, model.x0, load_steps=4, tol=1e-10)
        return (res.x - model.x0).reshape(-1, 2)

    target = TARGET[(section, case)]
    t = target / measure(section, case, mesh, reference(1.0))   # linear: exact
    if factor == "mss_strain":  # secant iteration on the MSS deformation
        t0, g0 = t, measure(section, case, mesh, mss(t)) - target
        t1 = t * target / (g0 + target)
        for _ in range(20):
            g1 = measure(section, case, mesh, mss(t1)) - target
            if abs(g1) < 1e-8 * target:
                break
            t0, t1, g0 = t1, t1 - g1 * (t1 - t0) / (g1 - g0), g1
        t = t1
    u, ur = mss(t), reference(t)
    e = displacement_error(u, ur)
    c_fem, m_fem = corner_middle(mesh, case, ur)
    c_mss, m_mss = corner_middle(mesh, case, u)
    return {"load": t, "error_max": e.max, "error_mean": e.mean, "ratio": e.mean / e.max,
            "reference_max": float(np.linalg.norm(ur, axis=1).max()),
            "corner_fem": c_fem, "middle_fem": m_fem, "corner_mss": c_mss, "middle_mss": m_mss,
            "hourglass_energy_fraction": hourglass[-1] if hourglass else np.nan,
            "n_nodes": mesh.n_nodes, "n_springs": sum(len(t.k) for t in springs)}


def main(argv=None):
    args = script.args(__doc__, argv)
    rows = []
    for section in ("5.1", "5.3"):
        for case in DIRECTION:
            for factor in FACTORS[section]:
                r = run(section, case, factor)
                pmax, pmean = PUBLISHED[(section, case)]
                rows.append(dict(section=section, case=case, factor=factor, published_max=pmax, published_mean=pmean, **r))
                print(f"{section} {case:11s} {factor:13s}: load {r['load']:7.1f} Pa, max {1e3 * r['error_max']:.3f} mm, "
                      f"ratio {r['ratio']:.3f} (published {pmean / pmax:.3f}); corner / middle strain FEM "
                      f"{100 * r['corner_fem']:.2f} / {100 * r['middle_fem']:.2f} %, MSS {100 * r['corner_mss']:.2f} / "
                      f"{100 * r['middle_mss']:.2f} %", flush=True)
    name = [f"{r['section']}/{r['case']}/{r['factor']}" for r in rows]
    ds = xr.Dataset(coords={"run": ("run", name, {"units": "1", "long_name": "section/case/factor"})})
    for key in ("section", "case", "factor"):
        ds[key] = ("run", np.array([r[key] for r in rows], dtype=str), {"units": "1", "long_name": key})
    ds["factor_text"] = ("run", np.array([FACTOR_TEXT[r["factor"]] for r in rows], dtype=str), {"units": "1", "long_name": "what was changed"})
    meta = {"load": ("Pa", "traction"), "error_max": ("m", "maximum node distance MSS - reference"),
            "error_mean": ("m", "mean node distance MSS - reference"), "ratio": ("1", "mean error / max error"),
            "reference_max": ("m", "largest reference displacement"),
            "corner_fem": ("1", "strain at the top corner node(s), FEM"), "middle_fem": ("1", "strain in the middle of the top edge, FEM"),
            "corner_mss": ("1", "strain at the top corner node(s), MSS"), "middle_mss": ("1", "strain in the middle of the top edge, MSS"),
            "published_max": ("m", "published maximum error"), "published_mean": ("m", "published mean error"),
            "hourglass_energy_fraction": ("1", "share of the reference's bilinear energy in hourglass modes (q1_one_point)")}
    for key, (unit, long) in meta.items():
        ds[key] = ("run", np.array([r[key] for r in rows], dtype=float), {"units": unit, "long_name": long})
    ds["published_ratio"] = ("run", ds.published_mean.values / ds.published_max.values, {"units": "1", "long_name": "published mean / max"})
    base = {(r["section"], r["case"]): r["ratio"] for r in rows if r["factor"] == "baseline"}
    ds["n_nodes"] = ("run", np.array([r["n_nodes"] for r in rows], dtype=float), {"units": "1", "long_name": "nodes of the mesh"})
    ds["n_springs"] = ("run", np.array([r["n_springs"] for r in rows], dtype=float), {"units": "1", "long_name": "springs of the MSS"})
    ds["max_over_published"] = ("run", ds.error_max.values / ds.published_max.values,
                                {"units": "1", "long_name": "maximum error / published maximum error"})
    ds["ratio_change"] = ("run", np.array([r["ratio"] - base[(r["section"], r["case"])] for r in rows]),
                          {"units": "1", "long_name": "ratio minus the baseline ratio of the same section and case"})
    ds.attrs.update(title="Lloyd et al. Secs. 5.1, 5.3: causes of the mean/max error ratio", E=E, nu=NU,
                    thickness=THICKNESS, quick=int(args.quick))
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_result(out, ds)


if __name__ == "__main__":
    main()
