"""The assembled mass-spring system: a mesh, force terms and boundary conditions behind the solver
protocol (the model families that build the terms are :mod:`msslib.models`).

:class:`Model` sums the terms of :mod:`msslib.terms` and implements the problem protocol of
:mod:`msslib.solvers` (``n_dof``, ``force``, ``stiffness``, ``energy``, ``free``, ``mass``,
``symmetric``, ``apply_prescribed``, ``damping``, ``dim``), plus ``x0`` and :meth:`Model.reaction`.

The builders that turn a mesh and its materials into terms live with their models in
:mod:`msslib.models`, one module per model family (``msslib.models.lloyd.lloyd_tet_springs``,
``msslib.models.golec.golec_cube_springs``, ...); a :class:`Model` knows no family.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from msslib import mesh as _mesh
from msslib.terms import ExternalForce, Springs, Term
from msslib.terms.base import ElementTerm
from msslib.terms.assembly import (
    block_scatter_bsr,
    block_scatter_csr,
    expand_block_pattern,
    scatter_add,
    spring3d_hessian_bsr,
    spring3d_hessian_csr,
)

__all__ = ["Model", "frozen_mesh"]


# --------------------------------------------------------------------------------------------
# frozen copies
# --------------------------------------------------------------------------------------------


def _read_only(a: np.ndarray) -> np.ndarray:
    a = np.array(a, copy=True)
    a.flags.writeable = False
    return a


def frozen_mesh(mesh):
    """A copy of ``mesh`` (a :class:`msslib.mesh.Mesh`) with read-only arrays of its own: node
    positions, cells, materials and groups.  What a built model keeps, so that editing the mesh it
    was built from (``mesh.points[...] = ...``) changes neither the model nor its solutions."""
    import dataclasses

    groups = {kind: {name: _read_only(a) for name, a in (getattr(mesh, kind) or {}).items()}
              for kind in ("cell_groups", "facet_groups", "node_groups")}
    frozen = dataclasses.replace(mesh, points=np.array(mesh.points, dtype=float), cells=np.array(mesh.cells),
                                 material=np.array(mesh.material), **groups)
    for name in ("points", "cells", "material"):
        getattr(frozen, name).flags.writeable = False
    for kind in groups:
        for a in getattr(frozen, kind).values():
            a.flags.writeable = False
    return frozen


def _mesh_arrays(mesh) -> list[np.ndarray]:
    arrays = [mesh.points, mesh.cells, mesh.material]
    for kind in ("cell_groups", "facet_groups", "node_groups"):
        arrays += list((getattr(mesh, kind, None) or {}).values())
    return [a for a in arrays if isinstance(a, np.ndarray)]


def _detach(terms, arrays) -> None:
    """Give every array attribute of ``terms`` that shares memory with one of ``arrays`` (the
    caller's mesh) a copy of its own; arrays that were one object stay one object."""
    copies: dict[int, np.ndarray] = {}

    def own(value):
        if isinstance(value, np.ndarray) and any(np.may_share_memory(value, a) for a in arrays):
            if id(value) not in copies:
                copies[id(value)] = value.copy()
            return copies[id(value)]
        if type(value) is tuple:  # e.g. a cached layout of arrays
            items = tuple(own(v) for v in value)
            return items if any(a is not b for a, b in zip(items, value)) else value
        return value

    for term in terms:
        for name, value in list(getattr(term, "__dict__", {}).items()):
            new = own(value)
            if new is not value:
                setattr(term, name, new)


# --------------------------------------------------------------------------------------------
# the model
# --------------------------------------------------------------------------------------------


class Model:
    """A mass-spring system on ``mesh`` made of ``terms`` (see :mod:`msslib.terms`).

    Parameters
    ----------
    mesh : :class:`msslib.mesh.Mesh`; its points are the rest positions ``x0``.
    terms : iterable of terms (internal ones, external loads, corrections).
    fixed : bool ``(n_nodes, dim)`` (or ``(n_dof,)``) mask of the constrained dofs; default none.
    prescribed : ``(n_nodes, dim)`` displacements (m) imposed on the fixed dofs at load 1; at
        load factor ``load`` the fixed dofs sit at ``x0 + load * prescribed``.  Default zero.
    masses : ``(n_nodes,)`` node masses (kg); default the lumped masses of unit density (and unit
        thickness in 2D), :func:`msslib.mesh.lumped_masses`.
    damping : default damping of :func:`msslib.stepping.integrate` (scalar alpha or (alpha, beta)).

    Force convention: ``force(x, load) = -sum_t s_t grad_t(x)`` with ``s_t = load`` for the terms
    that scale with the load (external loads, Baudet's correction) and 1 otherwise;
    ``stiffness = -d force / dx = sum_t s_t H_t`` assembled in a CSR matrix whose sparsity
    pattern (union of the terms' patterns, all dofs) is built once: each call only refills its data.
    """

    def __init__(self, mesh, terms, *, fixed=None, prescribed=None, masses=None, damping=0.0):
        # frozen: the model keeps its own read-only copy of the mesh, and its terms no array of
        # the mesh given, so that editing that mesh afterwards changes nothing here
        self.mesh = frozen_mesh(mesh)
        self.dim = mesh.dim
        self.n_nodes = mesh.n_nodes
        self.n_dof = mesh.n_nodes * mesh.dim
        self.x0 = mesh.points.ravel().copy()
        self.terms = [t for t in terms]
        _detach(self.terms, _mesh_arrays(mesh))
        for t in self.terms:
            if not isinstance(t, Term):
                raise TypeError(f"not a term: {t!r}")
            if t.max_node() >= self.n_nodes:
                raise ValueError(f"{type(t).__name__} refers to node {t.max_node()}, the mesh has {self.n_nodes}")
            if t.dim != self.dim and (isinstance(t, ExternalForce) or t.max_node() >= 0):
                raise ValueError(f"{type(t).__name__} is {t.dim}D, the mesh {self.dim}D")
        self.conservative = all(t.conservative for t in self.terms)
        self.symmetric = all(t.symmetric for t in self.terms)
        self.damping = damping

        if fixed is None:
            fixed = np.zeros(self.n_dof, dtype=bool)
        fixed = np.asarray(fixed, dtype=bool)
        if fixed.size != self.n_dof:
            raise ValueError(f"fixed must have shape ({self.n_nodes}, {self.dim}), got {fixed.shape}")
        self.fixed = fixed.ravel().copy()
        self.free = ~self.fixed
        if prescribed is None:
            prescribed = np.zeros(self.n_dof)
        prescribed = np.asarray(prescribed, dtype=float)
        if prescribed.size != self.n_dof:
            raise ValueError(f"prescribed must have shape ({self.n_nodes}, {self.dim}), got {prescribed.shape}")
        prescribed = prescribed.ravel().copy()
        if np.any(prescribed[self.free] != 0):
            raise ValueError("prescribed displacements given on free dofs; mark them in `fixed`")
        self.prescribed = prescribed

        if masses is None:
            masses = _mesh.lumped_masses(mesh, 1.0)
        masses = np.array(masses, dtype=float)  # a copy: the caller's array may change
        if masses.shape != (self.n_nodes,):
            raise ValueError(f"masses must have shape ({self.n_nodes},), got {masses.shape}")
        self.node_masses = masses
        self.mass = np.repeat(masses, self.dim)

        self._build_pattern()

    # ---- sparsity pattern ------------------------------------------------------------------

    def _build_pattern(self):
        parts = [(t, *t.hessian_pattern()) for t in self.terms]
        self._hessian_terms = [(t, r, c) for t, r, c in parts if len(r)]
        # Fast path: every term with Hessian entries is an element term with dense node blocks
        # (all dofs of its nodes).  The pattern is then built at node level (a node pair stands
        # for a dim x dim block) and the values are added directly into the CSR data by numba
        # loops at precomputed positions; otherwise the generic dof-level path below is used.
        # (Only when every node belongs to some element, so that the pattern is exactly the one
        # of the generic path: the union of the element blocks and the diagonal.)
        if self._hessian_terms and all(_is_block_term(t, self.dim) for t, _, _ in self._hessian_terms):
            covered = np.zeros(self.n_nodes, dtype=bool)
            for t, _, _ in self._hessian_terms:
                covered[t.conn.ravel()] = True
            if covered.all():
                self._build_block_pattern()
                return
        self._block = None
        n = self.n_dof
        if self._hessian_terms:
            rows = np.concatenate([r for _, r, _ in self._hessian_terms])
            cols = np.concatenate([c for _, _, c in self._hessian_terms])
        else:
            rows = cols = np.zeros(0, dtype=np.int64)
        # the diagonal is always present, so that constrained rows can be edited without changing
        # the pattern
        diag = np.arange(n, dtype=np.int64)
        keys = np.concatenate([rows * n + cols, diag * n + diag])
        unique, inverse = np.unique(keys, return_inverse=True)
        self._indices = (unique % n).astype(np.int32 if n < 2**31 else np.int64)
        urows = unique // n
        self._indptr = np.zeros(n + 1, dtype=self._indices.dtype)
        np.cumsum(np.bincount(urows, minlength=n), out=self._indptr[1:])
        self._nnz = len(unique)
        self._scatter = []
        start = 0
        for t, r, _ in self._hessian_terms:
            self._scatter.append(inverse[start:start + len(r)])
            start += len(r)

    def _build_block_pattern(self):
        """Node-level pattern: node pairs of every element (and every node with itself)."""
        nn, dim = self.n_nodes, self.dim
        keys, owners = [], []
        for t, _, _ in self._hessian_terms:
            conn = t.conn
            if isinstance(t, Springs) and dim == 3:
                order, rowptr, nb, _, _ = t.symmetric_layout()
                a = np.repeat(np.arange(len(rowptr) - 1, dtype=np.int64), np.diff(rowptr))
                k = a * nn + nb
            else:
                k = (conn[:, :, None] * nn + conn[:, None, :]).ravel()
            keys.append(k)
            owners.append(len(k))
        diag = np.arange(nn, dtype=np.int64)
        keys.append(diag * nn + diag)
        unique, inverse = np.unique(np.concatenate(keys), return_inverse=True)
        inverse = inverse.ravel()
        urow = unique // nn
        ucol = unique % nn
        nptr = np.zeros(nn + 1, dtype=np.int64)
        np.cumsum(np.bincount(urow, minlength=nn), out=nptr[1:])
        pos_all = inverse - nptr[np.concatenate([k // nn for k in keys])]  # position in node row
        n = self.n_dof
        idx_t = np.int32 if n < 2**31 else np.int64
        self._nnz = dim * dim * len(unique)
        self._indices = np.empty(self._nnz, dtype=idx_t)
        self._indptr = np.empty(n + 1, dtype=idx_t)
        expand_block_pattern(nptr, ucol, dim, self._indices, self._indptr)
        diag_pos = pos_all[-nn:].astype(np.int32)
        fills = []
        start = 0
        for (t, _, _), size, k in zip(self._hessian_terms, owners, keys):
            pos = pos_all[start:start + size].astype(np.int32)
            start += size
            if isinstance(t, Springs) and dim == 3:
                # "exact": these springs alone write every block of the pattern exactly once
                # (every node row, no repeated pair, no block of another term), so a refill may
                # overwrite instead of zeroing and adding
                rows_covered = len(t.symmetric_layout()[1]) - 1 == nn
                exact = rows_covered and size + nn == len(unique) and len(np.unique(k)) == size
                fills.append(("springs", pos, exact))
            else:
                nv = t.conn.shape[1]
                fills.append(("blocks", pos.reshape(-1, nv, nv), None))
        self._block = (nptr, diag_pos, fills)
        self._block_cols = ucol.astype(idx_t)  # node column of every node block, row by row
        self._block_plans = []
        self._scatter = None
    @property
    def nnz(self) -> int:
        """Number of stored entries of the stiffness pattern."""
        return self._nnz

    # ---- protocol ------------------------------------------------------------------------

    def _scale(self, term, load):
        return load if term.scales_with_load else 1.0

    def force(self, x, load: float = 1.0) -> np.ndarray:
        """Total nodal force ``(n_dof,)``: internal plus ``load`` times the external forces."""
        x = np.asarray(x, dtype=float).ravel()
        g = np.zeros(self.n_dof)
        for t in self.terms:
            s = self._scale(t, load)
            if s != 0.0:
                g += s * t.gradient(x)
        return -g

    def internal_force(self, x) -> np.ndarray:
        """Force of the terms that do not scale with the load (springs, volume terms)."""
        return self.force(x, 0.0)

    def external_force(self, load: float = 1.0) -> np.ndarray:
        """Load-proportional force at ``x0`` (dead loads plus load-dependent corrections)."""
        return self.force(self.x0, load) - self.force(self.x0, 0.0)

    def stiffness(self, x, load: float = 1.0, out: sp.csr_matrix | None = None) -> sp.csr_matrix:
        """Tangent stiffness ``-d force / dx`` (CSR, fixed pattern incl. the full diagonal).

        ``out``: a matrix returned by an earlier call of this model's ``stiffness``, whose
        values are overwritten in place and which is returned (no allocation: for Newton loops
        that no longer need the previous tangent)."""
        x = np.asarray(x, dtype=float).ravel()
        if out is not None:
            if (out.data.shape != (self._nnz,) or out.indices.shape != self._indices.shape
                    or not np.may_share_memory(out.indices, self._indices)):
                raise ValueError("out must be a matrix returned by this model's stiffness()")
            data = out.data
        else:
            data = None
        if self._block is not None:
            nptr, diag_pos, _ = self._block
            exact, steps = self._fill_steps(load)
            if not exact:
                if data is None:
                    data = np.zeros(self._nnz)
                else:
                    data[:] = 0.0
            elif data is None:
                data = np.empty(self._nnz)  # every entry is written by the exact spring term
            xc = np.ascontiguousarray(x)
            for t, kind, p, s, assign in steps:
                if kind == "springs":
                    _, rowptr, nb, k, L0 = t.symmetric_layout()
                    spring3d_hessian_csr(xc, rowptr, nb, k, L0, p, nptr, diag_pos, s, assign, data)
                else:
                    vals = t.hessian_values(x).reshape(len(t.conn), -1)
                    block_scatter_csr(vals, t.conn, p, nptr, self.dim, s, data)
        else:
            if data is None:
                data = np.zeros(self._nnz)
            else:
                data[:] = 0.0
            for (t, _, _), scatter in zip(self._hessian_terms, self._scatter):
                s = float(self._scale(t, load))
                if s != 0.0:
                    scatter_add(data, scatter, t.hessian_values(x), s)
        # the pattern arrays are shared, not copied (54 MB for a 30^3 lattice): they are read-only,
        # so an operation that would change a returned matrix's structure in place fails loudly
        if out is not None:
            return out
        K = sp.csr_matrix((data, self._indices_ro, self._indptr_ro), shape=(self.n_dof, self.n_dof), copy=False)
        K.has_sorted_indices = True
        K.has_canonical_format = True
        return K

    def stiffness_blocks(self, x, load: float = 1.0, out: sp.bsr_matrix | None = None,
                         node_free=None) -> sp.bsr_matrix | None:
        """Tangent stiffness restricted to the nodes ``node_free`` (rows and columns), as a BSR
        matrix of ``dim x dim`` node blocks: the free-free block of :meth:`stiffness`, filled
        directly (the full matrix is neither formed nor copied), for block solvers (AMG).

        ``node_free``: bool ``(n_nodes,)``; default the nodes whose dofs are all free.  ``out``:
        a matrix returned by an earlier call with the same mask, refilled in place.  Returns None
        when the model has no node-block pattern (a term without dense node blocks)."""
        if self._block is None:
            return None
        if node_free is None:
            f = self.free.reshape(-1, self.dim)
            if not np.array_equal(f.all(axis=1), f.any(axis=1)):
                return None
            node_free = f.all(axis=1)
        node_free = np.asarray(node_free, dtype=bool)
        if node_free.shape != (self.n_nodes,):
            raise ValueError(f"node_free must have shape ({self.n_nodes},), got {node_free.shape}")
        plan = self._block_plan(node_free)
        bmap, bind, bptr, shape = plan
        dim = self.dim
        x = np.ascontiguousarray(np.asarray(x, dtype=float).ravel())
        if (out is not None and sp.issparse(out) and out.format == "bsr" and out.shape == shape
                and out.data.shape == (len(bind), dim, dim) and np.may_share_memory(out.indices, bind)):
            data = out.data
        else:
            out = None
            data = None
        nptr, diag_pos, _ = self._block
        exact, steps = self._fill_steps(load)
        if data is None:
            data = np.empty((len(bind), dim, dim)) if exact else np.zeros((len(bind), dim, dim))
        elif not exact:
            data[:] = 0.0
        for t, kind, p, s, assign in steps:
            if kind == "springs":
                _, rowptr, nb, k, L0 = t.symmetric_layout()
                spring3d_hessian_bsr(x, rowptr, nb, k, L0, p, nptr, diag_pos, bmap, s, assign, data)
            else:
                vals = t.hessian_values(x).reshape(len(t.conn), -1)
                block_scatter_bsr(vals, t.conn, p, nptr, bmap, s, data)
        if out is not None:
            return out
        K = sp.bsr_matrix((data, bind, bptr), shape=shape, copy=False)
        K.has_sorted_indices = True
        return K

    def _fill_steps(self, load):
        """How the node-block fills run at ``load``: ``(exact, steps)``, ``steps`` the terms to
        add as ``(term, kind, positions, scale, assign)``, an exact spring term first (it
        overwrites every entry: ``exact``, no zeroing needed), terms of zero scale left out."""
        fills = self._block[2]
        scales = [float(self._scale(t, load)) for t, _, _ in self._hessian_terms]
        first = next((i for i, (f, s) in enumerate(zip(fills, scales)) if f[0] == "springs" and f[2] and s != 0.0),
                     None)
        order = ([first] if first is not None else []) + [i for i in range(len(fills)) if i != first]
        steps = [(self._hessian_terms[i][0], fills[i][0], fills[i][1], scales[i], i == first)
                 for i in order if scales[i] != 0.0]
        return first is not None, steps

    def _block_plan(self, node_free):
        """Kept node blocks for a node mask: ``bmap`` (position of every block of the node
        pattern in the restricted matrix, -1 if dropped) and the BSR index arrays; cached."""
        for entry in self._block_plans:
            if np.array_equal(entry[0], node_free):
                return entry[1]
        nptr = self._block[0]
        idx_t = self._block_cols.dtype
        rows = np.repeat(np.arange(self.n_nodes, dtype=idx_t), np.diff(nptr))
        keep = node_free[rows] & node_free[self._block_cols]
        bmap = np.full(len(keep), -1, dtype=np.int64 if len(keep) >= 2**31 else np.int32)
        bmap[keep] = np.arange(int(keep.sum()), dtype=bmap.dtype)
        new_node = (np.cumsum(node_free) - 1).astype(idx_t)
        bind = new_node[self._block_cols[keep]]  # increasing in every row: sorted blocks
        bptr = np.zeros(int(node_free.sum()) + 1, dtype=idx_t)
        np.cumsum(np.bincount(new_node[rows[keep]], minlength=len(bptr) - 1), out=bptr[1:])
        for a in (bind, bptr):
            a.flags.writeable = False
        nf = self.dim * (len(bptr) - 1)
        plan = (bmap, bind, bptr, (nf, nf))
        self._block_plans.insert(0, (node_free.copy(), plan))
        del self._block_plans[2:]
        return plan

    @property
    def _indices_ro(self):
        if self._indices.flags.writeable:
            self._indices.flags.writeable = False
        return self._indices

    @property
    def _indptr_ro(self):
        if self._indptr.flags.writeable:
            self._indptr.flags.writeable = False
        return self._indptr

    def energy(self, x, load: float = 1.0):
        """Total potential energy (J), or None when a term is non-conservative."""
        if not self.conservative:
            return None
        x = np.asarray(x, dtype=float).ravel()
        return float(sum(self._scale(t, load) * t.energy(x) for t in self.terms))

    def apply_prescribed(self, x, load: float = 1.0) -> np.ndarray:
        """Copy of ``x`` with the fixed dofs at ``x0 + load * prescribed``."""
        x = np.array(x, dtype=float).ravel()
        x[self.fixed] = self.x0[self.fixed] + load * self.prescribed[self.fixed]
        return x

    def stiffness_row_bound(self, x, load: float, isq: np.ndarray) -> np.ndarray:
        """Row sums of ``|D K D|`` at ``x`` with ``D = diag(isq)`` (``isq`` = ``1/sqrt(m)`` on the
        free dofs, 0 on the fixed ones), a bound of each row's sum over the terms (Gershgorin;
        :mod:`msslib.terms.bounds`): from the terms themselves when each can, else from the
        assembled stiffness."""
        from msslib.terms.bounds import csr_abs_rows

        x = np.asarray(x, dtype=float).ravel()
        isq = np.ascontiguousarray(isq, dtype=float)
        out = np.zeros(self.n_dof)
        for t in self.terms:
            s = self._scale(t, load)
            if s != 0.0 and not t.abs_row_sums(x, s, isq, out):
                K = self.stiffness(x, load)
                out[:] = 0.0
                csr_abs_rows(K.indptr, K.indices, K.data, isq, out)
                break
        return out

    def reaction(self, x, load: float = 1.0) -> np.ndarray:
        """Support reactions ``(n_nodes, dim)`` (N), zero on free dofs.

        On a fixed dof the reaction is minus the total force the terms apply there (internal force
        plus any load on that node), i.e. what the support must supply.  At equilibrium
        (free residual zero) the reactions plus the applied loads sum to zero.
        """
        r = np.where(self.fixed, -self.force(x, load), 0.0)
        return r.reshape(self.n_nodes, self.dim)


def _is_block_term(term, dim) -> bool:
    """True for element terms whose Hessian pattern is the dense block of all dofs of their nodes
    (the default :meth:`msslib.terms.base.ElementTerm.hessian_pattern`)."""
    return (isinstance(term, ElementTerm) and type(term).hessian_pattern is ElementTerm.hessian_pattern
            and type(term).hessian_values is ElementTerm.hessian_values and term.dim == dim)
