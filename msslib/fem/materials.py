"""Materials of the FEM references: Lame constants, per-cell moduli and the finite-strain laws
(St Venant-Kirchhoff, compressible neo-Hookean; 2D plane strain or exact plane stress)."""

from __future__ import annotations

import numpy as np

from msslib.mesh import Mesh


def lame(E, nu, plane: str | None = None):
    """Lame constants ``(lambda, mu)``; with ``plane="stress"`` the 2D plane-stress ``lambda*``."""
    E = np.asarray(E, dtype=float)
    nu = np.asarray(nu, dtype=float)
    lam = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))
    mu = E / (2.0 * (1.0 + nu))
    if plane == "stress":
        lam = 2.0 * lam * mu / (lam + 2.0 * mu)
    return lam, mu


def _per_material(value, name: str, n_mat: int) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(max(n_mat, 1), float(arr))
    if arr.ndim != 1:
        raise ValueError(f"{name} must be a scalar or a 1D sequence indexed by material, got shape {arr.shape}")
    if arr.size < n_mat:
        raise ValueError(f"{name} has {arr.size} values but the mesh uses material indices up to {n_mat - 1}")
    return arr


def _cell_materials(mesh: Mesh, E, nu) -> tuple[np.ndarray, np.ndarray]:
    """Validated per-cell ``(E, nu)`` arrays."""
    if mesh.material.size and mesh.material.min() < 0:
        raise ValueError("material indices must be non-negative")
    n_mat = int(mesh.material.max()) + 1 if mesh.material.size else 1
    E_m = _per_material(E, "E", n_mat)
    nu_m = _per_material(nu, "nu", n_mat)
    for k, e in enumerate(E_m):
        if not (np.isfinite(e) and e > 0):
            raise ValueError(f"Young's modulus E={float(e)!r} of material {k} must be > 0")
    for k, v in enumerate(nu_m):
        if not (np.isfinite(v) and -1.0 < v < 0.5):
            raise ValueError(f"Poisson's ratio nu={float(v)!r} of material {k} must satisfy -1 < nu < 0.5")
    return E_m[mesh.material], nu_m[mesh.material]


def _check_plane(plane: str, dim: int) -> None:
    if plane not in ("stress", "strain"):
        raise ValueError(f"plane must be 'stress' or 'strain', got {plane!r}")


def _det1m(H):
    """``det(I + H) - 1`` for ``(3, 3, ...)`` arrays without cancellation for small ``H``."""
    i1 = np.einsum("ii...->...", H)
    i2 = 0.5 * (i1**2 - np.einsum("ij...,ji...->...", H, H))
    i3 = np.linalg.det(np.moveaxis(H, (0, 1), (-2, -1)))
    return i1 + i2 + i3


def _law3d(H, lam, mu, law: str, tangent: bool = True):
    """Response to the displacement gradient ``H = F - I`` of shape ``(3, 3, ...)``.

    Returns the first Piola stress ``P`` (3,3,...), the tangent ``A = dP/dF`` (3,3,3,3,...) or
    ``None``, and the energy density ``W``. Strain measures are formed from ``H`` directly so that
    tiny deformations keep full relative precision (``F^T F - I`` would cancel).
    """
    ex = (1,) * (H.ndim - 2)
    I = np.eye(3).reshape((3, 3) + ex)
    F = H + I
    if law == "svk":
        Eg = 0.5 * (H + np.swapaxes(H, 0, 1) + np.einsum("kI...,kJ...->IJ...", H, H))
        trE = np.einsum("ii...->...", Eg)
        S = lam * trE * I + 2.0 * mu * Eg
        P = np.einsum("iK...,KJ...->iJ...", F, S)
        W = 0.5 * lam * trE**2 + mu * np.einsum("IJ...,IJ...->...", Eg, Eg)
        if not tangent:
            return P, None, W
        b = np.einsum("iK...,kK...->ik...", F, F)
        A = (
            np.einsum("ik,JL...->iJkL...", np.eye(3), S)
            + lam * np.einsum("iJ...,kL...->iJkL...", F, F)
            + mu * np.einsum("ik...,JL->iJkL...", b, np.eye(3))
            + mu * np.einsum("iL...,kJ...->iJkL...", F, F)
        )
        return P, A, W
    if law == "neohookean":
        Jm1 = _det1m(H)
        if np.any(~(Jm1 > -1.0)):
            raise FloatingPointError("non-positive Jacobian det F")
        lnJ = np.log1p(Jm1)
        Finv = np.moveaxis(np.linalg.inv(np.moveaxis(F, (0, 1), (-2, -1))), (-2, -1), (0, 1))
        FinvT = np.swapaxes(Finv, 0, 1)
        # F - F^-T = (F F^T - I) F^-T with F F^T - I = H + H^T + H H^T
        bm1 = H + np.swapaxes(H, 0, 1) + np.einsum("iK...,kK...->ik...", H, H)
        P = mu * np.einsum("ik...,kJ...->iJ...", bm1, FinvT) + lam * lnJ * FinvT
        trC_3 = 2.0 * np.einsum("ii...->...", H) + np.einsum("iJ...,iJ...->...", H, H)
        W = 0.5 * mu * trC_3 - mu * lnJ + 0.5 * lam * lnJ**2
        if not tangent:
            return P, None, W
        A = (
            mu * np.einsum("ik,JL->iJkL", np.eye(3), np.eye(3)).reshape((3, 3, 3, 3) + ex)
            + (mu - lam * lnJ) * np.einsum("Li...,Jk...->iJkL...", Finv, Finv)
            + lam * np.einsum("Ji...,Lk...->iJkL...", Finv, Finv)
        )
        return P, A, W
    raise ValueError(f"law must be 'svk' or 'neohookean', got {law!r}")


def _law(H, lam, mu, law: str, plane: str | None, tangent: bool = True):
    """Material response for ``H = F - I`` of shape ``(d, d, ...)``; 2D: plane strain or exact plane stress."""
    d = H.shape[0]
    if d == 3:
        return _law3d(H, lam, mu, law, tangent)
    H3 = np.zeros((3, 3) + H.shape[2:])
    H3[:2, :2] = H
    if plane == "stress":
        if law == "svk":
            # S33 = lam tr(E) + 2 mu E33 = 0 is linear in E33 = h33 + h33^2 / 2
            E2 = 0.5 * (H + np.swapaxes(H, 0, 1) + np.einsum("kI...,kJ...->IJ...", H, H))
            E33 = -lam * (E2[0, 0] + E2[1, 1]) / (lam + 2.0 * mu)
            if np.any(~(1.0 + 2.0 * E33 > 0)):
                raise FloatingPointError("plane-stress SVK: out-of-plane stretch not real")
            H3[2, 2] = 2.0 * E33 / (1.0 + np.sqrt(1.0 + 2.0 * E33))  # sqrt(1 + 2 E33) - 1
        else:
            h = np.zeros(H.shape[2:])
            for _ in range(60):
                H3[2, 2] = h
                P, A, _ = _law3d(H3, lam, mu, law, True)
                dh = -P[2, 2] / A[2, 2, 2, 2]
                h = h + dh
                if np.any(~(h > -1.0)):
                    raise FloatingPointError("plane-stress: out-of-plane stretch not positive")
                if np.max(np.abs(dh), initial=0.0) < 1e-15:
                    break
            H3[2, 2] = h
    P, A, W = _law3d(H3, lam, mu, law, tangent or plane == "stress")
    P2 = P[:2, :2]
    if not tangent:
        return P2, None, W
    A2 = A[:2, :2, :2, :2]
    if plane == "stress":
        A2 = A2 - np.einsum("ij...,kl...->ijkl...", A[:2, :2, 2, 2], A[2, 2, :2, :2]) / A[2, 2, 2, 2]
    return P2, A2, W

