"""Lloyd et al., Figs. 5, 7 and 8: the zero patterns of K_MSS and K_FEM of one element.

The paper draws the patterns of the linearised element stiffness matrices (zeros white, non-zeros
black) and argues from them: the square MSS without prestrain is sparse where the bilinear FEM
element "in general contains no zeros" (Fig. 5, left), the prestrained springs fill the remaining
entries (Fig. 5, right); the tetrahedral MSS has many zeros, the FEM only few (Fig. 7), and the
volume-preserving term brings the two patterns closer, "still not a perfect match" (Fig. 8).

Each element is placed as in the derivations (``derivations/elements/square.py``, ``tetrahedron.py``:
the square axis-aligned, the regular tetrahedron with node 0 at the origin, node 1 on the x axis and
node 2 in the xy plane) and its matrices are counted twice:

* structurally, from the symbolic matrices of the derivation engine: an entry is a structural zero
  when it is identically zero for every Poisson's ratio (FEM) or for independent constants (and
  rest-length factors) of every spring and of the volume term (MSS);
* numerically, from the simulator (``msslib.fem.element_stiffness``; the tangent of an
  ``msslib.system.Model`` holding the builder's terms on a one-element mesh) with the paper's
  values: nu = 1/3 and eqs. 10-11 for the square, nu = 1/4 and eqs. 12 and 14 for the tetrahedron;
  an entry is zero when ``|K_ij| <= 1e-12 max |K|``.

The symbolic matrices, evaluated at the same values, must equal the simulator's (the largest
relative difference is written, ``engine_mismatch``).  The same counts in a generic orientation (the
element turned by a fixed rotation) show which zeros belong to the orientation.

    python -m experiments.lloyd.studies.sparsity --out results/lloyd/studies/sparsity.nc [--quick]
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import sympy as sp
import xarray as xr

from derivations import element_stiffness as sfem
from derivations import mss as smss
from derivations.elasticity import E as E_sym
from derivations.elasticity import nu as nu_sym
from derivations.elasticity import t as t_sym
from experiments import script
from msslib import fem
from msslib import mesh as M
from msslib.system import Model
from msslib.models.common import assemble_springs
from msslib.models.lloyd import lloyd_square, lloyd_square_springs, lloyd_tet_springs
from msslib.results import write_result

E, THICKNESS = 14630.0, 0.01
SIDE = 0.01            # the square of the 5 x 5 mesh of Sec. 5.3 (m)
EDGE = 0.01            # edge of the regular tetrahedron (m)
ZERO = 1e-12           # numerical zero, relative to the largest entry
#: matrix -> (element, figure, what)
MATRICES = {
    "square_mss_plain": ("square", "Fig. 5 left", "MSS, 4 edge + 2 diagonal springs, no prestrain"),
    "square_mss_prestrain": ("square", "Fig. 5 right", "MSS, prestrained springs (eqs. 10-11)"),
    "square_fem": ("square", "Figs. 5 (text)", "FEM, bilinear quad, plane stress, nu = 1/3"),
    "tet_mss": ("tet", "Fig. 7 left", "MSS, 6 springs (eq. 12)"),
    "tet_mss_volume": ("tet", "Fig. 8 left", "MSS, 6 springs and volume term (eq. 14)"),
    "tet_fem": ("tet", "Figs. 7-8 right", "FEM, linear tetrahedron, nu = 1/4"),
}
SQ_EDGES, SQ_DIAGONALS = [(0, 1), (1, 2), (2, 3), (3, 0)], [(0, 2), (1, 3)]
TET_PAIRS = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]


def square_coords(a):
    return [(0, 0), (a, 0), (a, a), (0, a)]


def tet_coords(l):
    r3 = sp.sqrt(3) if isinstance(l, sp.Basic) else np.sqrt(3.0)
    r23 = sp.sqrt(sp.Rational(2, 3)) if isinstance(l, sp.Basic) else np.sqrt(2.0 / 3.0)
    return [(0, 0, 0), (l, 0, 0), (l / 2, r3 * l / 2, 0), (l / 2, r3 * l / 6, r23 * l)]


def rotation(dim):
    """A fixed rotation with no zero entry (generic orientation)."""
    if dim == 2:
        c, s = np.cos(0.3), np.sin(0.3)
        return np.array([[c, -s], [s, c]])
    q, _ = np.linalg.qr(np.array([[0.9, -0.3, 0.2], [0.4, 0.8, -0.5], [-0.1, 0.6, 0.7]]))
    return q


# ------------------------------------------------------------------------------------------------
# structural patterns: symbolic, every constant independent
# ------------------------------------------------------------------------------------------------


def symbolic(name):
    """The symbolic matrix of ``name`` with independent constants."""
    a, l = sp.Symbol("a", positive=True), sp.Symbol("l", positive=True)
    if name == "square_fem":
        return sfem.element_stiffness("quad", square_coords(a), "plane_stress")
    if name == "tet_fem":
        return sfem.element_stiffness("tetra", tet_coords(l), "3d")
    if name.startswith("square"):
        pairs = SQ_EDGES + SQ_DIAGONALS
        ks = sp.symbols(f"k_0:{len(pairs)}", positive=True)
        cs = sp.symbols(f"c_0:{len(pairs)}", positive=True) if name.endswith("prestrain") else [1] * len(pairs)
        return smss.stiffness_at_rest([smss.spring(i, j, k, c) for (i, j), k, c in zip(pairs, ks, cs)], square_coords(a))
    ks = sp.symbols("k_0:6", positive=True)
    terms = [smss.spring(i, j, k) for (i, j), k in zip(TET_PAIRS, ks)]
    if name == "tet_mss_volume":
        terms.append(smss.tet_volume_term(range(4), sp.Symbol("k_V", positive=True)))
    return smss.stiffness_at_rest(terms, tet_coords(l))


def structural_mask(K):
    return np.array([[sp.simplify(e) != 0 for e in K.row(i)] for i in range(K.rows)], dtype=bool)


def symbolic_at_values(name):
    """The derivation engine's matrix at the paper's values (for the check against the simulator)."""
    a, l = sp.Symbol("a", positive=True), sp.Symbol("l", positive=True)
    if name == "square_fem":
        K = sfem.element_stiffness("quad", square_coords(a), "plane_stress")
        return K.subs({nu_sym: sp.Rational(1, 3), E_sym: E, t_sym: THICKNESS, a: SIDE})
    if name == "tet_fem":
        return sfem.element_stiffness("tetra", tet_coords(l), "3d").subs({nu_sym: sp.Rational(1, 4), E_sym: E, l: EDGE})
    if name.startswith("square"):
        p = lloyd_square(E, t=THICKNESS)
        ce, cd = (p.rest_factor_edge, p.rest_factor_diagonal) if name.endswith("prestrain") else (1, 1)
        terms = ([smss.spring(i, j, p.k_edge, ce) for i, j in SQ_EDGES]
                 + [smss.spring(i, j, p.k_diagonal, cd) for i, j in SQ_DIAGONALS])
        return smss.stiffness_at_rest(terms, square_coords(sp.Float(SIDE)))
    # tetrahedron: eq. 12 k = 2 sqrt(2)/25 l E; eq. 14 k = 2 sqrt(2)/21 l E 4/5, k_V = sqrt(2)/84 l^3 E 2/5
    r2 = np.sqrt(2.0)
    if name == "tet_mss":
        terms = [smss.spring(i, j, 2 * r2 / 25 * EDGE * E) for i, j in TET_PAIRS]
    else:
        terms = ([smss.spring(i, j, 2 * r2 / 21 * EDGE * E * 0.8) for i, j in TET_PAIRS]
                 + [smss.tet_volume_term(range(4), r2 / 84 * EDGE**3 * E * 0.4)])
    return smss.stiffness_at_rest(terms, [tuple(sp.Float(c) for c in p) for p in tet_coords(EDGE)])


# ------------------------------------------------------------------------------------------------
# numerical matrices: the simulator's
# ------------------------------------------------------------------------------------------------


def simulator(name, R=None):
    """The simulator's matrix of ``name`` at the paper's values, the element turned by ``R``."""
    square = name.startswith("square")
    X = np.array(square_coords(SIDE) if square else tet_coords(EDGE), dtype=float)
    if R is not None:
        X = X @ R.T
    if name == "square_fem":
        return fem.element_stiffness("quad", X, E, 1.0 / 3.0, thickness=THICKNESS)
    if name == "tet_fem":
        return fem.element_stiffness("tetra", X, E, 0.25)
    mesh = M.Mesh(X, np.arange(len(X))[None, :], "quad" if square else "tetra")
    if name == "square_mss_prestrain":
        terms = lloyd_square_springs(mesh, [(E, 1.0 / 3.0)], THICKNESS)
    elif name == "square_mss_plain":
        p = lloyd_square(E, t=THICKNESS)
        terms = [assemble_springs(mesh, "edges", lambda c, _p: np.full(len(c), p.k_edge)),
                 assemble_springs(mesh, "face_diagonals", lambda c, _p: np.full(len(c), p.k_diagonal))]
    else:
        terms = lloyd_tet_springs(mesh, [(E, 0.25)], volume=name == "tet_mss_volume")
    model = Model(mesh, terms)
    return model.stiffness(model.x0).toarray()


def numerical_mask(K):
    return np.abs(K) > ZERO * np.abs(K).max()


def study():
    rows = {}
    for name in MATRICES:
        K = simulator(name)
        Ks = symbolic(name)
        Kv = np.array(symbolic_at_values(name).evalf(), dtype=float)
        Kr = simulator(name, rotation(2 if name.startswith("square") else 3))
        rows[name] = dict(K=K, structural=structural_mask(Ks), numerical=numerical_mask(K),
                          rotated=numerical_mask(Kr),
                          mismatch=float(np.abs(Kv - K).max() / np.abs(K).max()))
        r = rows[name]
        print(f"{name:22s}: {K.shape[0]}x{K.shape[1]}, non-zeros structural {r['structural'].sum():3d}, "
              f"numerical {r['numerical'].sum():3d}, turned {r['rotated'].sum():3d}; engine mismatch {r['mismatch']:.1e}",
              flush=True)
    return rows


def dataset(rows, quick):
    names = list(MATRICES)
    ds = xr.Dataset(coords={"matrix": ("matrix", names, {"units": "1", "long_name": "element matrix"})})
    ds["element"] = ("matrix", np.array([MATRICES[n][0] for n in names], dtype=str), {"units": "1", "long_name": "element"})
    ds["figure"] = ("matrix", np.array([MATRICES[n][1] for n in names], dtype=str), {"units": "1", "long_name": "figure of the paper"})
    ds["what"] = ("matrix", np.array([MATRICES[n][2] for n in names], dtype=str), {"units": "1", "long_name": "matrix"})
    ds["size"] = ("matrix", np.array([rows[n]["K"].size for n in names], dtype=float), {"units": "1", "long_name": "entries"})
    for key, long in (("structural", "structural non-zeros (independent constants, any nu)"),
                      ("numerical", "numerical non-zeros at the paper's values"),
                      ("rotated", "numerical non-zeros, element in a generic orientation")):
        ds[f"nnz_{key}"] = ("matrix", np.array([rows[n][key].sum() for n in names], dtype=float), {"units": "1", "long_name": long})
    ds["engine_mismatch"] = ("matrix", np.array([rows[n]["mismatch"] for n in names]),
                             {"units": "1", "long_name": "max |K_symbolic - K_simulator| / max |K_simulator| at the paper's values"})
    # pairs MSS -> FEM of the same element: entries where the numerical patterns differ
    for mss, ref in (("square_mss_plain", "square_fem"), ("square_mss_prestrain", "square_fem"),
                     ("tet_mss", "tet_fem"), ("tet_mss_volume", "tet_fem")):
        a, b = rows[mss]["numerical"], rows[ref]["numerical"]
        ds.attrs[f"{mss}_zero_where_fem_not"] = int((~a & b).sum())
        ds.attrs[f"{mss}_nonzero_where_fem_zero"] = int((a & ~b).sum())
        ds.attrs[f"{mss}_relative_difference"] = float(np.linalg.norm(rows[mss]["K"] - rows[ref]["K"]) / np.linalg.norm(rows[ref]["K"]))
    # Sec. 4.1: the zeros of K_FEM at nu = 1/3 lie "in the main diagonal and the side-diagonals with
    # index sum i + j = 5 and i + j = 13" (1-based), read as the anti-diagonals i + j = 5, 9, 13
    fem_zero = ~rows["square_fem"]["numerical"]
    i, j = np.nonzero(fem_zero)
    ds.attrs["square_fem_zeros"] = int(fem_zero.sum())
    ds.attrs["square_fem_zeros_off_5_9_13"] = int((~np.isin(i + j + 2, (5, 9, 13))).sum())
    for element, n in (("square", 8), ("tet", 12)):
        dof = f"{element}_dof"
        ds = ds.assign_coords({dof: (dof, np.arange(n), {"units": "1", "long_name": "dof (node-major: x, y[, z])"})})
        members = [m for m in names if MATRICES[m][0] == element]
        ds[f"{element}_matrix"] = (f"{element}_member", np.array(members, dtype=str), {"units": "1", "long_name": "matrix"})
        for key in ("K", "structural", "numerical"):
            arr = np.stack([np.asarray(rows[m][key], dtype=float) for m in members])
            unit = "N/m" if key == "K" else "1"
            long = {"K": "element stiffness at the paper's values", "structural": "1 where structurally non-zero",
                    "numerical": "1 where numerically non-zero"}[key]
            ds[f"{element}_{key}"] = ((f"{element}_member", dof, f"{dof}_col"), arr, {"units": unit, "long_name": long})
    ds.attrs.update(title="Lloyd et al. Figs. 5, 7, 8: zero patterns of the element stiffness matrices", E=E,
                    thickness=THICKNESS, square_side=SIDE, tet_edge=EDGE, zero_tolerance=ZERO, quick=int(quick))
    return ds


def main(argv=None):
    args = script.args(__doc__, argv)
    ds = dataset(study(), args.quick)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_result(out, ds)


if __name__ == "__main__":
    main()
