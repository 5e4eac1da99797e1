"""Free-dof submatrices of sparse tangents, by plans computed once per sparsity pattern.

A plan holds the index arrays of the free-free block (CSR) or of the free node blocks (BSR) of a
given pattern and free mask; each new matrix of that pattern then only has its values gathered.
Plans are kept by a :class:`PlanCache`, which a solver context owns
(:class:`msslib.solvers.context.SolverContext`); without one, a plan is computed for the call.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

from .memo import PLANS


class PlanCache:
    """The plans of a few sparsity patterns, most recently used first: free-dof extraction plans
    (CSR and node blocks) and band orderings (:func:`msslib.solvers.direct._band_plan`).

    An entry is reused only for the very same pattern (the same index arrays, or equal ones) and
    free mask; it holds references to the pattern arrays, so their ids cannot be recycled.  A
    solver context owns one; the contexts of one problem share its lists (``share``: plans
    depend on the pattern only).  A pattern new to the cache is looked up in the process-wide
    memo (:data:`msslib.solvers.memo.PLANS`) first, and new plans are kept there too (band
    orderings by :func:`msslib.solvers.direct._band_plan` itself, keyed by all its inputs)."""

    SIZE = 4

    def __init__(self, share: PlanCache | None = None):
        self.entries: list = share.entries if share is not None else []  # submatrix and node-block plans
        self.bands: list = share.bands if share is not None else []  # band orderings

    @staticmethod
    def _push(lst, entry, size):
        lst.insert(0, entry)
        del lst[size:]

    def add(self, entry):
        self._push(self.entries, entry, self.SIZE)

    def add_band(self, entry):
        self._push(self.bands, entry, self.SIZE)


def _plans_of(plans):
    """The :class:`PlanCache` of ``plans`` (a cache, a solver context holding one, or None)."""
    if plans is None or isinstance(plans, PlanCache):
        return plans
    return getattr(plans, "plans", None)



def _same_readonly(a, b):
    """True when ``a`` and ``b`` are the same read-only memory (scipy wraps index arrays passed
    with ``copy=False`` in new views, so ``is`` is not enough).  The cache keeps ``a`` alive, so
    its address cannot be recycled; read-only memory cannot be changed behind our back."""
    return a is b or (not a.flags.writeable and not b.flags.writeable and a.dtype == b.dtype
                      and a.shape == b.shape and a.strides == b.strides
                      and a.__array_interface__["data"][0] == b.__array_interface__["data"][0])


def _pattern_key_matches(entry, K, free):
    if entry["shape"] != K.shape or entry["free_n"] != free.size:
        return False
    if _same_readonly(entry["indptr"], K.indptr) and _same_readonly(entry["indices"], K.indices):
        same = True
    else:
        same = (entry["indptr"].shape == K.indptr.shape and entry["indices"].shape == K.indices.shape
                and np.array_equal(entry["indptr"], K.indptr) and np.array_equal(entry["indices"], K.indices))
        if same:  # remember the new arrays: the next call is then an identity check
            entry["indptr"], entry["indices"] = K.indptr, K.indices
    return same and np.array_equal(entry["free"], free)


@njit(cache=True, nogil=True)
def _plan_count(indptr, indices, free, sub_indptr):
    """Row pointers of the free-free block; returns its number of entries."""
    r = 0
    n = 0
    sub_indptr[0] = 0
    for i in range(indptr.shape[0] - 1):
        if not free[i]:
            continue
        for p in range(indptr[i], indptr[i + 1]):
            if free[indices[p]]:
                n += 1
        r += 1
        sub_indptr[r] = n
    return n


@njit(cache=True, nogil=True)
def _plan_fill(indptr, indices, free, new_index, sub_indices):
    """New column indices of the free-free entries."""
    n = 0
    for i in range(indptr.shape[0] - 1):
        if not free[i]:
            continue
        for p in range(indptr[i], indptr[i + 1]):
            j = indices[p]
            if free[j]:
                sub_indices[n] = new_index[j]
                n += 1


@njit(cache=True, nogil=True)
def _gather_free(indptr, indices, data, free, out):
    """Values of the free-free entries, row by row (walks the pattern with the free mask rather
    than storing their positions: one array fewer to allocate and touch per pattern)."""
    n = 0
    for i in range(indptr.shape[0] - 1):
        if not free[i]:
            continue
        for p in range(indptr[i], indptr[i + 1]):
            if free[indices[p]]:
                out[n] = data[p]
                n += 1


_U = np.uint64  # unsigned indices: numba then skips its wraparound test of negative ones


@njit(cache=True, nogil=True)
def _is_node_blocked(indptr, indices, dim):
    """Whether a CSR pattern (sorted indices) is made of whole ``dim x dim`` node blocks: the
    ``dim`` rows of every node have the same columns, which come in whole nodes."""
    n_nodes = (indptr.shape[0] - 1) // dim
    if n_nodes * dim != indptr.shape[0] - 1:
        return False
    for a in range(n_nodes):
        r0 = indptr[_U(dim * a)]
        L = indptr[_U(dim * a + 1)] - r0
        if L % dim != 0:
            return False
        for i in range(1, dim):
            if indptr[_U(dim * a + i + 1)] - indptr[_U(dim * a + i)] != L or indptr[_U(dim * a + i)] != r0 + i * L:
                return False
        for t in range(0, L, dim):
            c0 = indices[_U(r0 + t)]
            if c0 % dim != 0:
                return False
            for i in range(dim):
                for j in range(dim):
                    if indices[_U(r0 + i * L + t + j)] != c0 + j:
                        return False
    return True


@njit(cache=True, nogil=True)
def _free_blocks(indptr, indices, node_free, dim, new_node, bptr, bind, data, out):
    """Walk the free-free node blocks of a node-blocked CSR in BSR order (block-major) and return
    their number.  What is filled, each when its array is not empty: ``bptr`` the block row
    pointers, ``bind`` (when long enough) the block column indices (``new_node`` numbering),
    ``out`` the blocks' values from ``data``."""
    nb = 0
    r = 0
    rows = bptr.shape[0] > 0
    gather = out.shape[0] > 0
    if rows:
        bptr[0] = 0
    for a in range(node_free.shape[0]):
        if not node_free[a]:
            continue
        r0 = indptr[_U(dim * a)]
        L = indptr[_U(dim * a + 1)] - r0
        for t in range(0, L, dim):
            b = indices[_U(r0 + t)] // dim
            if node_free[_U(b)]:
                if nb < bind.shape[0]:
                    bind[_U(nb)] = new_node[_U(b)]
                if gather:
                    for i in range(dim):
                        q = r0 + i * L + t
                        for j in range(dim):
                            out[_U(nb), _U(i), _U(j)] = data[_U(q + j)]
                nb += 1
        if rows:
            r += 1
            bptr[r] = nb
    return nb


def _no_index(K):
    """An empty index array of the index type of the plans of ``K`` (an argument of
    :func:`_free_blocks` that is not filled)."""
    return np.empty(0, dtype=np.int32 if K.nnz < 2**31 else np.int64)


def _submatrix_bsr(K, node_free, dim, out=None, plans=None):
    """Free-free block of a node-blocked CSR ``K`` (sorted indices, canonical) as a BSR matrix
    of ``dim x dim`` blocks, or None when ``K`` is not node-blocked.

    The block index arrays are computed once per pattern and node mask.  AMG works on the node
    blocks anyway: gathering them straight from ``K`` skips the free-free CSR (values and
    indices) and its conversion to BSR (three arrays of the size of ``K`` fewer to allocate and
    fill per solve).  ``out``: an earlier result for the same pattern and mask, whose values are
    overwritten (and which is returned).  ``plans``: the :class:`PlanCache` (or a context holding
    one) that keeps the plan; without it the plan is computed for this call."""
    if not (sp.issparse(K) and K.format == "csr" and K.has_canonical_format) or K.shape[0] != K.shape[1]:
        return None
    entry = _bsr_entry(K, node_free, dim, plans)
    if entry is None:
        return None
    if not (out is not None and sp.issparse(out) and out.format == "bsr"
            and _same_readonly(out.indices, entry["bind"]) and out.data.shape == (entry["nblocks"], dim, dim)
            and out.data.dtype == K.data.dtype and out.data.flags.writeable):
        out = sp.bsr_matrix((np.empty((entry["nblocks"], dim, dim), dtype=K.data.dtype), entry["bind"],
                             entry["bptr"]), shape=entry["sub_shape"], copy=False)
        out.has_sorted_indices = True
    none = _no_index(K)
    _free_blocks(K.indptr, K.indices, entry["free"], dim, none, none, none, K.data, out.data)
    return out


def _bsr_block_plan(K, node_free, dim):
    """The node-block plan of ``K`` and ``node_free`` (the part of a plan entry that depends on
    them only)."""
    if not _is_node_blocked(K.indptr, K.indices, dim):
        return {"blocked": False}
    none = _no_index(K)
    new_node = (np.cumsum(node_free) - 1).astype(none.dtype)
    n_free = int(node_free.sum())
    bptr = np.empty(n_free + 1, dtype=none.dtype)
    no_values = np.empty((0, dim, dim), dtype=K.data.dtype)
    nb = _free_blocks(K.indptr, K.indices, node_free, dim, new_node, bptr, none, K.data, no_values)
    bind = np.empty(nb, dtype=none.dtype)
    _free_blocks(K.indptr, K.indices, node_free, dim, new_node, bptr, bind, K.data, no_values)
    bptr.flags.writeable = False
    bind.flags.writeable = False
    return {"blocked": True, "bptr": bptr, "bind": bind, "nblocks": nb, "sub_shape": (dim * n_free, dim * n_free)}


def _bsr_entry(K, node_free, dim, plans=None):
    """The cached free-node block plan of ``K`` (see :func:`_submatrix_bsr`), or None."""
    if not (sp.issparse(K) and K.format == "csr" and K.has_canonical_format) or K.shape[0] != K.shape[1]:
        return None
    node_free = np.asarray(node_free, dtype=bool)
    if K.shape[0] != dim * node_free.size:
        return None
    key = ("bsr", dim)
    entry = None
    cache = _plans_of(plans)
    for e in (cache.entries if cache is not None else ()):
        if e.get("kind") == key and _pattern_key_matches(e, K, node_free):
            entry = e
            break
    if entry is None:
        entry = {"kind": key, "shape": K.shape, "free_n": node_free.size, "free": node_free.copy(),
                 "indptr": K.indptr, "indices": K.indices}
        if cache is not None:
            entry.update(PLANS.get_or_compute("bsr", (K.indptr, K.indices, node_free),
                                              lambda: _bsr_block_plan(K, node_free, dim), (dim, K.shape)))
            cache.add(entry)
        else:
            entry.update(_bsr_block_plan(K, node_free, dim))
    return entry if entry["blocked"] else None


@njit(cache=True, nogil=True)
def _eccentricity(ptr, ind):
    """Largest breadth-first distance from node 0 of the graph ``(ptr, ind)``; -1 when some
    node is not reached."""
    n = ptr.shape[0] - 1
    if n == 0:
        return 0
    depth = np.full(n, -1, dtype=np.int64)
    queue = np.empty(n, dtype=np.int64)
    depth[0] = 0
    queue[0] = 0
    head, tail = 0, 1
    while head < tail:
        a = queue[head]
        head += 1
        for p in range(ptr[a], ptr[a + 1]):
            b = ind[p]
            if depth[b] < 0:
                depth[b] = depth[a] + 1
                queue[tail] = b
                tail += 1
    if tail < n:
        return -1
    return depth[queue[tail - 1]]


def _free_plan(K, free):
    """The free-free index arrays of ``K`` and ``free`` (the part of a plan entry that depends on
    them only)."""
    n_free = int(free.sum())
    idx_t = np.int32 if K.nnz < 2**31 else np.int64
    new_index = (np.cumsum(free) - 1).astype(idx_t)  # increasing: sorted rows stay sorted
    sub_indptr = np.empty(n_free + 1, dtype=idx_t)
    n_keep = _plan_count(K.indptr, K.indices, free, sub_indptr)
    sub_indices = np.empty(n_keep, dtype=idx_t)
    _plan_fill(K.indptr, K.indices, free, new_index, sub_indices)
    sub_indptr.flags.writeable = False
    sub_indices.flags.writeable = False
    return {"nnz": n_keep, "sub_indptr": sub_indptr, "sub_indices": sub_indices, "sub_shape": (n_free, n_free)}


def _submatrix_plan(K, free, plans=None):
    cache = _plans_of(plans)
    for i, entry in enumerate(cache.entries if cache is not None else ()):
        if entry.get("kind") is None and _pattern_key_matches(entry, K, free):
            if i:
                cache.entries.insert(0, cache.entries.pop(i))
            return entry
    entry = {"shape": K.shape, "free_n": free.size, "free": free.copy(), "indptr": K.indptr,
             "indices": K.indices}
    if cache is None:
        entry.update(_free_plan(K, free))
    else:
        entry.update(PLANS.get_or_compute("free", (K.indptr, K.indices, free), lambda: _free_plan(K, free),
                                          (K.shape,)))
        cache.add(entry)
    return entry


def submatrix(K, free, out=None, plans=None):
    """Free-free block of ``K`` (CSR, sorted indices).  For a canonical CSR input the index arrays
    of the block are computed once per sparsity pattern and reused (each call only gathers the
    values), and the returned matrices share these (read-only) index arrays.  ``out``: an earlier result
    for the same pattern and mask, whose values are overwritten (and which is returned).  ``plans``:
    the :class:`PlanCache` (or a context holding one) that keeps the plan across calls."""
    if not (sp.issparse(K) and K.format == "csr"):
        K = sp.csr_matrix(K)
    if free.all():
        return K
    if not K.has_canonical_format:
        K = K.copy()
        K.sum_duplicates()
    if K.shape[0] != K.shape[1]:
        idx = np.flatnonzero(free)
        return sp.csr_matrix(K[idx][:, idx])
    plan = _submatrix_plan(K, free, plans)
    if (out is not None and _same_readonly(out.indices, plan["sub_indices"])
            and out.data.shape == (plan["nnz"],) and out.data.dtype == K.data.dtype
            and out.data.flags.writeable):
        _gather_free(K.indptr, K.indices, K.data, free, out.data)
        return out
    vals = np.empty(plan["nnz"], dtype=K.data.dtype)
    _gather_free(K.indptr, K.indices, K.data, free, vals)
    A = sp.csr_matrix((vals, plan["sub_indices"], plan["sub_indptr"]),
                      shape=plan["sub_shape"], copy=False)
    A.has_sorted_indices = True
    A.has_canonical_format = True
    return A
