"""Baudet's orthogonal correction (non-conservative, load dependent) from the surface loads of a
mesh of cubes; the element reading is in :mod:`msslib.baudet_correction`."""

from __future__ import annotations

import numpy as np

from .base import Term, _per_element
from .external import sum_external_forces

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
