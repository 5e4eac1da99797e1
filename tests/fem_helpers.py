"""Meshes and reference quantities from the finite-element module shared by the spring-fit tests."""

from __future__ import annotations

import numpy as np

from msslib import fem
from msslib import mesh as M


def fem_stiffness(mesh, E, nu, thickness):
    """The dense global linear FEM stiffness matrix of ``mesh`` (one material), assembled from
    ``fem.element_stiffness`` cell by cell; ``thickness`` is used by 2D cells."""
    n = mesh.n_nodes * mesh.dim
    K = np.zeros((n, n))
    for cell in mesh.cells:
        dofs = (cell[:, None] * mesh.dim + np.arange(mesh.dim)).ravel()
        K[np.ix_(dofs, dofs)] += fem.element_stiffness(mesh.cell_type, mesh.points[cell], E, nu, thickness=thickness)
    return K


def jittered(base, amount, seed=0):
    """``base`` with its interior nodes moved by up to ``amount`` (m) along each axis."""
    rng = np.random.default_rng(seed)
    p = base.points.copy()
    inner = np.all((p > p.min(0) + 1e-9) & (p < p.max(0) - 1e-9), axis=1)
    p[inner] += amount * rng.uniform(-1, 1, (inner.sum(), p.shape[1]))
    return M.Mesh(p, base.cells, base.cell_type)
