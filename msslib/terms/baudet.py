"""Baudet's orthogonal correction of cubes, in both readings: :class:`BaudetCorrection` (the
body's surface loads drive it) and :class:`ElementBaudetCorrection` (every cube driven by the forces
acting on it from outside).

Baudet's correction force read at element level (paper Sec. 4), next to the boundary reading.

Baudet et al. compute "all the forces applied to each element": internal ones (the element's
springs and its correction forces) and external ones ("gravity or reaction forces due to
neighboring elements"); the elongation force of a face is "the projection on the face normal of
the sum of all the external forces applied to the considered face".  Two readings are built:

``boundary``
    :class:`msslib.terms.BaudetCorrection`: only the body's surface loads drive the correction
    (boundary faces, reference configuration, constant per unit load).  Nothing acts inside a body
    or under gravity.
``element``
    :class:`ElementBaudetCorrection` (this module): every cube ``e`` takes as external force at its
    node ``a`` everything acting at ``a`` except its own springs and its own correction: the
    springs *and* corrections of the neighbouring cubes (their reaction on ``e``), the applied
    loads, gravity and the support reactions, each counted in full at every cube sharing the node
    (no splitting is needed: the neighbours' springs carry their own share, see below).

Free-body identity.  Write ``s_e(a)`` and ``k_e(a)`` for the forces of cube ``e``'s springs and
correction on node ``a`` and ``R(a)`` for the total force on node ``a`` (all cubes, loads,
gravity).  The external force of the element reading is then ``O_e(a) = R(a) - s_e(a) - k_e(a)`` on
free dofs and ``-s_e(a) - k_e(a)`` on constrained ones (the reaction closes the balance).  At rest
(static equilibrium, ``R = 0`` on the free dofs) it is ``O_e(a) = -(s_e(a) + k_e(a))`` at every node:
the outside world holds each cube exactly against its own internal forces.  In a single cube loaded
on a face, ``O`` is the applied load there (and the support reaction on the opposite face), so the
cube gets the correction of eqs. 7-8 with the applied resultant, as in the boundary reading; had a
load at a node shared by several cubes been split among them, the neighbours' springs (which carry
their share of it) would have counted it twice.

Face and pair forces.  With reference outward unit normals ``n_f``, the elongation force of face
``f`` is ``F_f = sum_{a in f} n_f . O_e(a)`` (> 0 tension).  Both faces of a pair get the same value at
rest (springs and correction have zero resultant per cube), and the pair force is their mean
``F_i``.  The correction of pair ``i`` puts ``c F_i n_g / 4`` on every node of each face ``g`` of the two
other pairs (``c`` the per-cube factor of :func:`msslib.parameters.baudet_cube`), as in the boundary
reading.  Since ``k_e`` itself projects on the faces (``sum_{a in f} n_f . k_e(a) = c sum_{j != i} F_j``
for a cube), the pair forces solve, per cube, ``F_i + c sum_{j != i} F_j = g_i`` with
``g_i = -mean_{f in i} sum_{a in f} n_f . s_e(a)``: ``F = A^-1 g``, ``A = (1 - c) I + c J`` (``J`` all ones),
invertible unless ``c = 1`` or ``c = -1/2`` (``nu = -1/4`` or ``nu = 1/2`` with the derived factor).

How it is solved.  :class:`ElementBaudetCorrection` uses the equilibrium form: ``k_e = M_e s_e(x)``
with the constant ``24 x 24`` map ``M_e = Q_e A_e^-1 P_e`` (reference normals), a function of the
positions only, with the exact, non-symmetric, element-block Jacobian ``M_e H_e`` (``H_e`` the
stiffness of the cube's own springs).  Statics: Newton on springs + loads + this term (LU, residual
line search); its fixed points are exactly those of the paper's algorithm.  That algorithm, written
literally (freeze the corrections, solve, recompute them from ``O`` built from the neighbours,
loads and reactions, repeat), is :func:`fixed_point_solve`; it converges geometrically with a ratio
that grows with ``|c|`` and is used to check the equilibrium form.  Dynamics: the term is evaluated
at every step (every force call); during motion it differs from the paper's ``O`` by the net force
on the nodes (inertia and damping, ``R`` above, which vanishes at rest), so dynamic relaxation to
rest gives the static solution.  Directions are those of the reference configuration, as in the boundary reading; the
amplitudes follow the deformation.

:func:`fixed_point_solve` also offers the narrower reading ``neighbour_corrections=False`` (outside
forces from the neighbours' springs, loads, gravity and the support reactions, not the neighbours'
corrections): it coincides with ``element`` for a single cube and differs in composites.
"""

from __future__ import annotations

import numpy as np

from msslib.mesh.core import LOCAL_EDGES
from msslib.mesh.topology import INNER_DIAGONALS
from msslib.terms.assembly import block_pattern
from msslib.terms.base import Table, Term, cell_columns, make_column, _per_element
from msslib.terms.external import sum_external_forces

# local faces of a hexahedron (msslib.mesh order, right-hand normal outward) and the three pairs
# of opposite faces: bottom/top, y-min/y-max, x-max/x-min of a reference cube
_HEX_FACES = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]])
_FACE_PAIRS = np.array([[0, 1], [2, 4], [3, 5]])


class BaudetCorrection(Term):
    """Baudet et al.'s orthogonal correction forces for hexahedral (cube) elements.

    Baudet's cube springs alone give the wrong Poisson contraction; the correction adds, for
    every element with an externally loaded face, forces on the four faces orthogonal to the
    elongation direction.  Construction (all at unit load, in the *reference* configuration):

    1. External forces ``loads`` (n, 3) (an array, or terms whose :class:`ExternalForce` parts are
       summed — pass only surface loads, not gravity) live on the nodes.  Candidate faces are the
       mesh's boundary faces, with outward unit normal ``n_f``.
    2. Sharing rule: the normal component ``f_a . n_f`` of the force of node ``a`` is shared
       equally among the boundary faces containing ``a`` *with the same normal* (coplanar faces
       of neighbouring elements). Faces with other normals get their own normal component, so at
       an edge or corner where loaded faces meet (pressure on a box) every face receives its full
       normal load. The elongation force of face ``f`` is ``F_f = sum_a (f_a . n_f) / m_af``
       (> 0 tension, < 0 compression, ``m_af`` the number of coplanar boundary faces at ``a``);
       for uniform normal tractions with consistent nodal forces it is exactly each face's normal
       resultant. A face is loaded when ``F_f != 0``. Limitation: a load tangential to a face
       (shear) at an edge node also has a normal component on the adjacent side face and is
       counted there.
    3. Per element and per pair of opposite faces the elongation force ``F_i`` is the one of the
       two faces with the larger magnitude (if both are loaded, as in a free cube pulled at both
       ends, the tension is counted once).
    4. The correction amplitude is ``F_perp = c F_i`` with ``c = factor`` per element (from
       :func:`msslib.parameters.baudet_cube` ``.correction_factor``: ``-(4 nu - 1) / 2`` derived
       for resultants per face, ``-(4 nu - 1) / 16`` as printed, see the errata).
       On each of the two other pairs of faces ``(j, j')`` the force ``F_perp d / 4`` is applied to
       each node of ``j`` and ``-F_perp d / 4`` to each node of ``j'``, ``d`` the unit vector from
       the centroid of ``j'`` to the centroid of ``j`` (the outward normal of ``j`` for a cube).
       For nu > 1/4, ``c < 0``: a stretched element is pinched on its sides.

    The two forces of a face pair are equal, opposite and collinear (they act along the line
    through both face centroids), so every element's correction has zero resultant force and zero
    moment, for any hexahedron shape.

    Directions are those of the reference configuration: the correction is a constant nodal force
    vector per unit load, scaled by the load factor.  Its Jacobian is therefore zero (no Hessian
    entries) and the static stiffness stays that of the springs.  It is treated as
    non-conservative (``energy`` returns None; Baudet's force is defined from the applied load,
    not from a potential), so a model containing it reports ``energy = None``.
    """

    conservative = False
    scales_with_load = True
    dim = 3
    kind = "correction"
    export_name = "baudet_correction"
    export_label = "Baudet's correction"
    #: MuJoCo and SOFA carry it as constant forces at load factor 1; VTU only its nodal forces
    export_formats = ("csv", "json", "mjcf", "sofa", "c")
    cell_constants = (("correction_factor", "factor", "1", "Baudet's correction factor c, F_perp = c F_i"),)

    def export_count(self) -> int:
        return int(len(self.factor))

    def export_entry(self) -> dict:
        return {"kind": self.export_name, "count": self.export_count(), "table": self.export_name,
                "forces_table": "baudet_correction_forces", "energy": None, "conservative": self.conservative,
                "scales_with_load": self.scales_with_load}

    def export_note(self, fmt: str) -> str:
        return "Baudet's per-cell correction factors (the nodal correction forces are carried)"

    def export_forces(self):
        return [("baudet_correction", self.nodal, "Baudet's correction forces (N) at load factor 1")]

    def export_tables(self, mesh) -> list[Table]:
        faces = "; ".join(f"face {f}: local nodes {' '.join(map(str, nodes))}" for f, nodes in enumerate(_HEX_FACES))
        fc = self.nodal
        on = np.flatnonzero(np.any(fc != 0, axis=1))
        return [
            Table("baudet_correction", "Baudet's orthogonal correction per cube: factor c (F_perp = c F_i) and the "
                  f"elongation force of each face at load factor 1 ({faces}; msslib.terms.BaudetCorrection)", [
                      *cell_columns(mesh.cells, "hexahedron"),
                      make_column("factor", "1", self.factor, "correction factor c"),
                      *[make_column(f"face_force_{f}", "N", self.face_force[:, f], f"elongation force of face {f} (> 0 "
                                                                            f"tension)") for f in range(6)],
                  ]),
            Table("baudet_correction_forces", "nodal forces of Baudet's correction at load factor 1 (they scale "
                                              "with the load; constant in the reference configuration)", [
                make_column("node", None, on, "node index", int),
                *[make_column(f"f_{a}", "N", fc[on, i], f"force, {a}") for i, a in enumerate("xyz"[:fc.shape[1]])],
            ]),
        ]

    def __init__(self, mesh, loads, factor):
        if mesh.cell_type != "hexahedron":
            raise ValueError(f"BaudetCorrection needs hexahedron cells, got {mesh.cell_type}")
        if not isinstance(loads, np.ndarray) and not np.isscalar(loads):
            try:
                loads = np.asarray(loads, dtype=float)
            except (TypeError, ValueError):
                loads = sum_external_forces(loads, mesh.n_nodes, 3)
        loads = np.asarray(loads, dtype=float)
        if loads.shape != (mesh.n_nodes, 3):
            raise ValueError(f"loads must have shape ({mesh.n_nodes}, 3), got {loads.shape}")
        factor = _per_element("factor", factor, mesh.n_cells)
        if not np.isfinite(factor).all():
            raise ValueError("BaudetCorrection: factor must be finite")
        self.factor = factor
        self.loads = loads
        self.face_force = self._face_elongation(mesh, loads)  # (m, 6)
        nodal = self._correction(mesh, self.face_force, factor)
        self.nodal = nodal
        self.vector = nodal.ravel()

    @staticmethod
    def _face_elongation(mesh, loads):
        m = mesh.n_cells
        faces = mesh.cells[:, _HEX_FACES]  # (m, 6, 4)
        flat = faces.reshape(-1, 4)
        _, inverse, counts = np.unique(np.sort(flat, axis=1), axis=0, return_inverse=True, return_counts=True)
        boundary = counts[inverse.ravel()] == 1
        p = mesh.points[flat]
        normal = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        fid = np.repeat(np.flatnonzero(boundary), 4)
        node = flat[boundary].ravel()
        proj = np.einsum("ij,ij->i", loads[node], normal[fid])
        # number of boundary faces at the node with the same (rounded) normal
        key = np.column_stack([node, np.round(normal[fid] * 1e6).astype(np.int64)])
        _, group, count = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        share = 1.0 / count[group.ravel()]
        face_force = np.bincount(fid, weights=share * proj, minlength=len(flat))
        return face_force.reshape(m, 6)

    @staticmethod
    def _correction(mesh, face_force, factor):
        nodal = np.zeros((mesh.n_nodes, 3))
        centroid = mesh.points[mesh.cells[:, _HEX_FACES]].mean(axis=2)  # (m, 6, 3)
        for i, (f0, f1) in enumerate(_FACE_PAIRS):
            a, b = face_force[:, f0], face_force[:, f1]
            F = np.where(np.abs(a) >= np.abs(b), a, b)
            loaded = F != 0.0
            if not loaded.any():
                continue
            amp = factor[loaded] * F[loaded] / 4.0  # per node
            cells = mesh.cells[loaded]
            for q, (j0, j1) in enumerate(_FACE_PAIRS):
                if q == i:
                    continue
                d = centroid[loaded, j1] - centroid[loaded, j0]
                d /= np.linalg.norm(d, axis=1, keepdims=True)
                fj = amp[:, None] * d
                for face, sign in ((j1, 1.0), (j0, -1.0)):
                    nodes = cells[:, _HEX_FACES[face]]  # (k, 4)
                    for c in range(3):
                        nodal[:, c] += np.bincount(nodes.ravel(), weights=np.repeat(sign * fj[:, c], 4),
                                                   minlength=mesh.n_nodes)
        return nodal

    def max_node(self) -> int:
        return len(self.nodal) - 1

    def energy(self, x):
        return None

    def gradient(self, x) -> np.ndarray:
        """Minus the correction force at unit load (independent of ``x``)."""
        return -self.vector.copy()


# --------------------------------------------------------------------------------------------------
# the element reading
READINGS = ("boundary", "element")
"""Readings of Baudet's correction force (model option ``correction``)."""

_PAIRS = np.vstack([LOCAL_EDGES["hexahedron"], INNER_DIAGONALS])  # 12 edges, 4 inner diagonals
_INCIDENCE = np.zeros((16, 8))
_INCIDENCE[np.arange(16), _PAIRS[:, 0]] = 1.0  # force t u on the first node
_INCIDENCE[np.arange(16), _PAIRS[:, 1]] = -1.0


def _face_normals(points, cells):
    """Outward unit normals ``(m, 6, 3)`` of the local faces of hexahedra at ``points``."""
    p = points[cells[:, _HEX_FACES]]  # (m, 6, 4, 3)
    n = np.cross(p[:, :, 2] - p[:, :, 0], p[:, :, 3] - p[:, :, 1])
    return n / np.linalg.norm(n, axis=2, keepdims=True)


def _maps(normals, factor):
    """``P`` (m, 3, 24), ``Q`` (m, 24, 3) and ``A`` (m, 3, 3) of the module docstring."""
    m = len(normals)
    P = np.zeros((m, 3, 8, 3))
    Q = np.zeros((m, 8, 3, 3))
    for i, pair in enumerate(_FACE_PAIRS):
        for f in pair:
            for a in _HEX_FACES[f]:
                P[:, i, a, :] -= 0.5 * normals[:, f, :]
                for j in range(3):
                    if j != i:  # the correction of pair j acts on the faces of pair i
                        Q[:, a, :, j] += 0.25 * factor[:, None] * normals[:, f, :]
    c = factor[:, None, None]
    A = (1.0 - c) * np.eye(3) + c * np.ones((3, 3))
    return P.reshape(m, 3, 24), Q.reshape(m, 24, 3), A


class ElementBaudetCorrection(Term):
    """Baudet's correction driven by the forces acting on each cube from outside it (the
    ``element`` reading, equilibrium form; see the module docstring).

    ``mesh``: hexahedra (cubes); ``k_edge``, ``k_diagonal``: each cube's own constants (its 12 edges
    and 4 inner diagonals, before summing over neighbours), ``factor``: per-cube ``c``.  Force on the
    nodes ``k(x) = sum_e M_e s_e(x)``; non-conservative (``energy`` is None), not proportional to the
    load (it follows the springs), with the non-symmetric Jacobian ``M_e H_e`` per cube.
    """

    conservative = False
    scales_with_load = False
    symmetric = False
    dim = 3
    kind = "correction"
    export_name = "baudet_element_correction"
    export_label = ("Baudet's element-reading correction (non-conservative nodal forces sum_e M_e s_e(x) from "
                    "each cube's own springs)")
    cell_constants = (("correction_factor", "factor", "1", "Baudet's correction factor c, F_perp = c F_i"),)

    def export_count(self) -> int:
        return int(len(self.cells))

    def export_tables(self, mesh) -> list[Table]:
        return [Table(self.export_name, "Baudet's correction, element reading (msslib.terms.ElementBaudetCorrection): "
                      "per cube its own 12 edge springs (k_edge) and 4 inner diagonals (k_diagonal), rest lengths the "
                      "distances of their nodes at rest, and the factor c; the correction force on the cube's nodes "
                      "is M_e s_e(x), s_e the forces of the cube's own springs, F_perp = c F_i on each face pair, "
                      "equilibrium form (not proportional to the load, no energy)", [
                          *cell_columns(self.cells, "hexahedron"),
                          make_column("k_edge", "N/m", self.k[:, 0], "spring constant of each of the cube's 12 edges"),
                          make_column("k_diagonal", "N/m", self.k[:, 12],
                               "spring constant of each of the cube's 4 inner diagonals"),
                          make_column("factor", "1", self.factor, "correction factor c"),
                      ])]

    def __init__(self, mesh, k_edge, k_diagonal, factor):
        if mesh.cell_type != "hexahedron":
            raise ValueError(f"ElementBaudetCorrection needs hexahedron cells, got {mesh.cell_type}")
        m = mesh.n_cells
        self.cells = self.conn = np.ascontiguousarray(mesh.cells, dtype=np.int64)
        self.n_nodes = mesh.n_nodes
        k_edge = _per_element("k_edge", k_edge, m)
        k_diagonal = _per_element("k_diagonal", k_diagonal, m)
        factor = _per_element("factor", factor, m)
        if not (np.isfinite(k_edge).all() and np.isfinite(k_diagonal).all() and np.isfinite(factor).all()):
            raise ValueError("ElementBaudetCorrection: k_edge, k_diagonal and factor must be finite")
        det = (1.0 - factor) ** 2 * (1.0 + 2.0 * factor)
        bad = np.flatnonzero(np.abs(det) < 1e-9)
        if len(bad):
            raise ValueError(f"element reading undefined for correction factor c = 1 or -1/2 (nu = -1/4 or 1/2 with "
                             f"the derived factor): cells {bad[:5].tolist()}")
        self.factor = factor
        self.k = np.column_stack([np.repeat(k_edge[:, None], 12, axis=1), np.repeat(k_diagonal[:, None], 4, axis=1)])
        X = mesh.points[self.cells]
        self.rest_length = np.linalg.norm(X[:, _PAIRS[:, 1]] - X[:, _PAIRS[:, 0]], axis=2)  # (m, 16)
        self.normals = _face_normals(mesh.points, self.cells)
        P, Q, A = _maps(self.normals, factor)
        self.P, self.Q = P, Q
        self.A_inv = np.linalg.inv(A)
        self.map = Q @ self.A_inv @ P  # (m, 24, 24)

    # ---- per-cube springs ------------------------------------------------------------------

    def _springs(self, x):
        xe = np.asarray(x, dtype=float).reshape(-1, 3)[self.cells]  # (m, 8, 3)
        d = xe[:, _PAIRS[:, 1]] - xe[:, _PAIRS[:, 0]]
        length = np.linalg.norm(d, axis=2)
        u = d / length[..., None]
        t = self.k * (length - self.rest_length)
        return u, t, length

    def element_spring_forces(self, x) -> np.ndarray:
        """Force ``(m, 8, 3)`` of every cube's own springs on its nodes."""
        u, t, _ = self._springs(x)
        return np.einsum("pj,mpd->mjd", _INCIDENCE, t[..., None] * u)

    def element_spring_stiffness(self, x) -> np.ndarray:
        """``H_e = -d s_e / dx`` ``(m, 24, 24)`` of every cube's own springs."""
        u, t, length = self._springs(x)
        uu = u[..., :, None] * u[..., None, :]
        Kp = self.k[..., None, None] * uu + (t / length)[..., None, None] * (np.eye(3) - uu)
        H = np.einsum("pj,pk,mpde->mjdke", _INCIDENCE, _INCIDENCE, Kp)
        return H.reshape(len(self.cells), 24, 24)

    # ---- the correction -----------------------------------------------------------------------

    def pair_forces(self, x) -> np.ndarray:
        """Elongation force ``F_i`` (N) of every cube's three face pairs ``(m, 3)`` (z, y, x order
        of :data:`msslib.terms.baudet._FACE_PAIRS`: bottom/top, y faces, x faces), equilibrium form."""
        s = self.element_spring_forces(x).reshape(len(self.cells), 24)
        return np.einsum("mij,mj->mi", self.A_inv, np.einsum("mij,mj->mi", self.P, s))

    def nodal_from_pair_forces(self, F) -> np.ndarray:
        """Correction nodal forces ``(n_nodes, 3)`` for given pair forces ``F`` ``(m, 3)``."""
        k = np.einsum("mij,mj->mi", self.Q, np.asarray(F, dtype=float)).reshape(-1, 8, 3)
        return self._scatter(k)

    def _scatter(self, ke):
        out = np.zeros((self.n_nodes, 3))
        for d in range(3):
            out[:, d] = np.bincount(self.cells.ravel(), weights=ke[:, :, d].ravel(), minlength=self.n_nodes)
        return out

    def nodal(self, x) -> np.ndarray:
        """Correction force ``(n_nodes, 3)`` at positions ``x``."""
        s = self.element_spring_forces(x).reshape(len(self.cells), 24)
        return self._scatter(np.einsum("mij,mj->mi", self.map, s).reshape(-1, 8, 3))

    # ---- term protocol ----------------------------------------------------------------------

    def max_node(self) -> int:
        return int(self.cells.max()) if self.cells.size else -1

    def energy(self, x):
        return None

    def gradient(self, x) -> np.ndarray:
        return -self.nodal(x).ravel()

    def hessian_pattern(self):
        if getattr(self, "_pattern", None) is None:
            self._pattern = block_pattern(self.cells, 3)
        return self._pattern

    def hessian_values(self, x) -> np.ndarray:
        return (self.map @ self.element_spring_stiffness(x)).ravel()


# --------------------------------------------------------------------------------------------
# the paper's algorithm, literally: outside forces from neighbours, loads and reactions
# --------------------------------------------------------------------------------------------


class FrozenForce(Term):
    """A constant nodal force ``vector`` (n_dof,) at unit load (scaled by the load factor);
    non-conservative, so that a model holding it uses the residual line search."""

    conservative = False
    scales_with_load = True
    dim = 3

    def __init__(self, n_nodes):
        self.vector = np.zeros(3 * n_nodes)

    def energy(self, x):
        return None

    def gradient(self, x) -> np.ndarray:
        return -self.vector.copy()


def outside_pair_forces(term, x, total_force, free, F_frozen, neighbour_corrections=True):
    """Pair forces ``(m, 3)`` from the forces acting on each cube from outside it, built from the
    neighbours (not from the equilibrium identity): ``total_force`` (n_dof,) is the model's force at
    ``x`` (all springs, loads, gravity and the correction of the pair forces ``F_frozen`` (m, 3)),
    ``free`` the free dofs (elsewhere the reaction closes the balance).  With
    ``neighbour_corrections=False`` the corrections at the cube's nodes (its own and its
    neighbours') are left out, the cube's own one being added back as its internal force."""
    free = np.asarray(free, dtype=bool).reshape(-1, 3)
    R = np.where(free, np.asarray(total_force, dtype=float).reshape(-1, 3), 0.0)
    s = term.element_spring_forces(x)  # (m, 8, 3)
    if neighbour_corrections:
        ke = np.einsum("mij,mj->mi", term.Q, F_frozen).reshape(-1, 8, 3)
        O = R[term.cells] - s - ke
    else:
        O = (R - term.nodal_from_pair_forces(F_frozen))[term.cells] - s
    Fface = np.einsum("mfad,mfd->mf", O[:, _HEX_FACES], term.normals)  # (m, 6)
    return 0.5 * (Fface[:, _FACE_PAIRS[:, 0]] + Fface[:, _FACE_PAIRS[:, 1]])


def fixed_point_solve(model, term, *, tol=1e-10, max_outer=200, neighbour_corrections=True, load_steps=1,
                      newton_tol=1e-11, start=None):
    """Static equilibrium of ``model`` (springs and loads, containing one :class:`FrozenForce`)
    with the element correction of ``term`` by the paper's loop: freeze the correction, solve,
    recompute each cube's pair forces from the forces acting on it from outside (neighbours'
    springs and corrections, loads, gravity, reactions), repeat until the pair forces change by
    less than ``tol`` times their largest magnitude.  Returns ``(x, F, history)`` with the relative
    changes per outer iteration; raises RuntimeError without convergence."""
    from msslib.solvers import static_solve

    frozen = next(t for t in model.terms if isinstance(t, FrozenForce))
    m = len(term.cells)
    F = np.zeros((m, 3)) if start is None else np.array(start, dtype=float)
    frozen.vector = term.nodal_from_pair_forces(F).ravel()
    x = static_solve(model, model.x0, load_steps=load_steps, tol=newton_tol).x
    history = []
    for _ in range(max_outer):
        F_new = outside_pair_forces(term, x, model.force(x, 1.0), model.free, F, neighbour_corrections)
        change = float(np.abs(F_new - F).max() / max(np.abs(F_new).max(), 1e-300))
        history.append(change)
        F = F_new
        frozen.vector = term.nodal_from_pair_forces(F).ravel()
        x = static_solve(model, x, load_steps=1, tol=newton_tol).x
        if change < tol:
            return x, F, history
    raise RuntimeError(f"fixed point not converged in {max_outer} iterations (last change {history[-1]:.3e})")
