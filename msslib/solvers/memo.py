"""A bounded, process-wide memo of the symbolic plans of sparsity patterns.

The free-dof plans of a solve (free-free index arrays, node-block index arrays, band orderings;
:mod:`msslib.solvers.submatrices`) are pure functions of index arrays -- the pattern of a tangent, a
free mask, the coordinates the geometric band ordering reads -- and of a few settings.  A new
model of a pattern met before (a rebuilt model, the next case of a sweep) finds them here instead
of computing them again; its solver context then keeps its own reference, as before.

An entry is found by a fingerprint of its arrays (dtype, shape and CRC-32 of the elements, or of
an evenly spaced sample of a large array) and taken only when the stored arrays equal the asked
ones, element by element: a fingerprint collision costs a recomputation, never a wrong plan.  The
stored key arrays are read-only copies, so a caller that later changes its arrays in place cannot
change what an entry stands for.  The memo keeps at most :attr:`PatternMemo.size` entries and
:attr:`PatternMemo.max_bytes` bytes (key copies and plan arrays), the least recently used going
first; patterns whose arrays alone exceed a quarter of the byte budget are neither fingerprinted
nor kept (their plans are a small part of their solve).
"""

from __future__ import annotations

import threading
import zlib
from collections import OrderedDict

import numpy as np

MISSING = object()  # what :meth:`PatternMemo.get` returns when no entry matches


SAMPLE = 1 << 15  # elements of an array that its fingerprint reads, at most (evenly spaced)


def _fingerprint(a: np.ndarray):
    """dtype, shape and CRC-32 of (an evenly spaced sample of at most about ``SAMPLE`` elements of)
    ``a``.  Only a bucket: equality of the arrays decides a hit, so a sample costs at worst a
    recomputation, while hashing every element of a large pattern would cost a good part of
    computing its plan."""
    flat = a.reshape(-1)
    if flat.size > SAMPLE:
        flat = np.concatenate((flat[:: flat.size // SAMPLE], flat[-1:]))
    flat = np.ascontiguousarray(flat)
    return a.dtype.str, a.shape, zlib.crc32(flat.view(np.uint8)) if flat.size else 0


def _nbytes(value) -> int:
    """Bytes of the arrays in ``value`` (an array, a dict or tuple of them, or anything else: 0)."""
    if isinstance(value, np.ndarray):
        return value.nbytes
    if isinstance(value, dict):
        return sum(_nbytes(v) for v in value.values())
    if isinstance(value, (tuple, list)):
        return sum(_nbytes(v) for v in value)
    return 0


class PatternMemo:
    """Least-recently-used map from ``(kind, settings, arrays)`` to a plan (see the module
    docstring).  ``kind`` names the function, ``settings`` (hashable) its other inputs."""

    def __init__(self, size: int = 16, max_bytes: int = 128 << 20):
        self.size = size
        self.max_bytes = max_bytes
        self._entries: OrderedDict = OrderedDict()  # key -> (key arrays, value, bytes)
        self._bytes = 0
        self._lock = threading.Lock()

    def __len__(self):
        return len(self._entries)

    @property
    def nbytes(self) -> int:
        return self._bytes

    def clear(self):
        with self._lock:
            self._entries.clear()
            self._bytes = 0

    def _key(self, kind, settings, arrays):
        if sum(a.nbytes for a in arrays) > self.max_bytes // 4:
            return None
        return (kind, settings, tuple(_fingerprint(a) for a in arrays))

    def get(self, kind, arrays, settings=()):
        """The plan stored for these arrays and settings, or :data:`MISSING`."""
        key = self._key(kind, settings, arrays)
        if key is None:
            return MISSING
        with self._lock:
            hit = self._entries.get(key)
            if hit is None:
                return MISSING
            if not all(s.shape == a.shape and np.array_equal(s, a) for s, a in zip(hit[0], arrays)):
                return MISSING  # a fingerprint collision
            self._entries.move_to_end(key)
            return hit[1]

    def put(self, kind, arrays, value, settings=()):
        """Keep ``value`` as the plan of these arrays and settings (when it fits the bounds)."""
        key = self._key(kind, settings, arrays)
        if key is None or self.size < 1:
            return
        copies = tuple(np.array(a, copy=True) for a in arrays)
        for c in copies:
            c.flags.writeable = False
        nbytes = _nbytes(copies) + _nbytes(value)
        if nbytes > self.max_bytes:
            return
        with self._lock:
            old = self._entries.pop(key, None)
            if old is not None:
                self._bytes -= old[2]
            self._entries[key] = (copies, value, nbytes)
            self._bytes += nbytes
            while len(self._entries) > self.size or self._bytes > self.max_bytes:
                self._bytes -= self._entries.popitem(last=False)[1][2]

    def get_or_compute(self, kind, arrays, compute, settings=()):
        """The stored plan, else ``compute()`` (outside the lock), kept and returned."""
        value = self.get(kind, arrays, settings)
        if value is MISSING:
            value = compute()
            self.put(kind, arrays, value, settings)
        return value


PLANS = PatternMemo()  # the memo of msslib.solvers.submatrices
