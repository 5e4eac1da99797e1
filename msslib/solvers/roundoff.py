"""The shared Newton convergence test and the round-off floor of the residual."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit

from .submatrices import submatrix

EPS = np.finfo(float).eps
ROUNDOFF_FACTOR = 1.0  # the floor is ROUNDOFF_FACTOR * eps * (force magnitude scale)
# Measured (Newton driven to stagnation with tol = 1e-30): the residual stalls at 0.04-0.11 x
# eps * || |K| |x| + |f_ext| || on Golec, Baudet and Lloyd models (slender beam, compression,
# tetrahedra, membranes), and at 0.10-0.14 x eps * || |K| |u| + sum |f_e| + |f_ext| || for the
# FEM references (St Venant-Kirchhoff and neo-Hookean, hexahedra and tetrahedra); the floor is
# about ten times the stall, so a solve reaches it, and nothing far above it is accepted.


def roundoff_floor(magnitude: float) -> float:
    """Smallest residual norm a force evaluation can resolve: ``ROUNDOFF_FACTOR * eps * magnitude``,
    ``magnitude`` the norm of the per-dof size of what the force sums (for models whose forces
    are computed from absolute positions, ``|| |K| |x| + |f_ext| ||`` on the free dofs; for a
    displacement-based FEM, ``|| |K| |u| + sum_e |f_e| + |f_ext| ||``)."""
    return float(ROUNDOFF_FACTOR * EPS * magnitude)


def convergence_threshold(tol: float, force_scale: float, floor: float | None) -> float:
    """The shared Newton convergence test: converged when ``||r|| <= max(tol * F_ref, floor)``."""
    t = float(tol) * float(force_scale)
    return t if floor is None or not np.isfinite(floor) else max(t, float(floor))


def roundoff_note(residual: float, floor: float, target: float) -> str:
    """The message of a solve that stopped at the round-off floor instead of ``tol * F_ref``."""
    return (f"converged to round-off: residual {residual:.3e} at the round-off floor {floor:.3e} "
            f"(tol x F_ref = {target:.3e} is below what double precision resolves for these forces)")


@njit(cache=True, nogil=True)
def _abs_matvec_csr(indptr, indices, data, z, out):
    for i in range(indptr.shape[0] - 1):
        acc = 0.0
        for q in range(indptr[i], indptr[i + 1]):
            acc += abs(data[q]) * z[indices[q]]
        out[i] = acc


@njit(cache=True, nogil=True)
def _abs_matvec_bsr(indptr, indices, data, z, out):
    d = data.shape[1]
    for bi in range(indptr.shape[0] - 1):
        for a in range(d):
            acc = 0.0
            for q in range(indptr[bi], indptr[bi + 1]):
                j = indices[q] * d
                for b in range(d):
                    acc += abs(data[q, a, b]) * z[j + b]
            out[bi * d + a] = acc


@njit(cache=True, nogil=True)
def _abs_matvec_bsr3(indptr, indices, data, z, out):
    for bi in range(indptr.shape[0] - 1):
        a0 = a1 = a2 = 0.0
        for q in range(indptr[bi], indptr[bi + 1]):
            j = 3 * indices[q]
            z0, z1, z2 = z[j], z[j + 1], z[j + 2]
            B = data[q]
            a0 += abs(B[0, 0]) * z0 + abs(B[0, 1]) * z1 + abs(B[0, 2]) * z2
            a1 += abs(B[1, 0]) * z0 + abs(B[1, 1]) * z1 + abs(B[1, 2]) * z2
            a2 += abs(B[2, 0]) * z0 + abs(B[2, 1]) * z1 + abs(B[2, 2]) * z2
        out[3 * bi], out[3 * bi + 1], out[3 * bi + 2] = a0, a1, a2


def _abs_times(K, z):
    """``|K| z`` (entrywise absolute values of ``K``; ``z >= 0``), without copying ``K``."""
    out = np.empty(K.shape[0])
    z = np.ascontiguousarray(z, dtype=float)
    if sp.issparse(K) and K.format == "csr":
        _abs_matvec_csr(K.indptr, K.indices, np.ascontiguousarray(K.data, dtype=float), z, out)
    elif sp.issparse(K) and K.format == "bsr" and K.blocksize[0] == K.blocksize[1]:
        kernel = _abs_matvec_bsr3 if K.blocksize[0] == 3 else _abs_matvec_bsr
        kernel(K.indptr, K.indices, np.ascontiguousarray(K.data, dtype=float), z, out)
    else:
        out[:] = abs(K) @ z
    return out


def force_magnitude_norm(K_free, x_free, load_abs_free) -> float:
    """``|| |K| |x| + |f_ext| ||`` on the free dofs: the size of what a force computed from the
    absolute positions ``x`` sums (rounding ``x`` by eps changes the force by about eps times it)."""
    with np.errstate(all="ignore"):
        s = float(np.linalg.norm(_abs_times(K_free, np.abs(x_free)) + load_abs_free))
    return s if np.isfinite(s) else float("inf")


def _roundoff_floor_at(problem, x, free, load_abs_free, load=1.0) -> float:
    """The round-off floor at state ``x`` (assembles the tangent once)."""
    with np.errstate(all="ignore"):
        K = submatrix(problem.stiffness(x, load), free)
    return roundoff_floor(force_magnitude_norm(K, x[free], load_abs_free))
