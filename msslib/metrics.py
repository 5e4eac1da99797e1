"""Metrics: displacement errors against a reference, effective elastic moduli, mesh volumes.

Conventions
-----------
* Positions and displacements are ``(n_nodes, dim)`` arrays in metres (see :mod:`msslib.mesh`);
  ``displaced = rest + displacement``.
* Stresses are Cauchy/engineering stresses in Pa, **positive in tension**. Strains are small
  (engineering) strains, positive in extension.
* Pressure is **positive in compression** (the pressure pushes on the body, its volume shrinks):
  ``p = -trace(sigma) / dim``.

Effective moduli from a box-shaped sample
-----------------------------------------
The mean strain of the sample is measured in one of two ways (argument ``method``):

``"fit"`` (default)
    least-squares fit of an affine field ``u(x) = c + H x`` to the displacements of the nodes
    (all nodes, or those selected by ``mask``); the mean displacement gradient ``H`` gives the
    strains ``H[a, a]`` and, for shear, the slope ``H[load, normal]``. Using every node averages
    out the local fluctuations of an inhomogeneous mass-spring response.
``"extent"``
    the sample's extent measured on the nodes: the strain along axis ``a`` is
    ``(L'_a - L_a) / L_a`` with ``L_a = max - min`` of the rest coordinates and ``L'_a`` the same
    on the displaced nodes; for shear the slope is the difference of the mean load-axis
    displacements of the two faces normal to ``axis_normal`` divided by their distance.

Both are exact for an affine displacement field. In 2D the moduli are the apparent in-plane ones
(for a plane-strain run they are ``E / (1 - nu**2)`` and ``nu / (1 - nu)``; converting is left to the
caller).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from .mesh import Mesh
from .mesh import cells as _cells

__all__ = [
    "DisplacementError",
    "displacement_error",
    "YoungPoisson",
    "mean_displacement_gradient",
    "youngs_modulus_poisson",
    "shear_modulus",
    "bulk_modulus",
    "cell_volumes",
    "mesh_volume",
]


# --------------------------------------------------------------------------------------------------
# displacement errors


@dataclass(frozen=True, eq=False)
class DisplacementError:
    """Statistics of the per-node Euclidean displacement error ``e_i = |u_i - u_ref_i|``.

    ``mean``, ``std`` (population, ``ddof = 0``) and ``max`` are in metres; ``rel_mean``,
    ``rel_std`` and ``rel_max`` are the same statistics of the relative error ``per_node_relative``.
    ``scale`` is the reference length the errors were divided by, or ``None`` for per-node relative
    errors.
    """

    mean: float
    std: float
    max: float
    rel_mean: float
    rel_std: float
    rel_max: float
    scale: float | None
    per_node: np.ndarray
    per_node_relative: np.ndarray


def _as_field(u, name: str) -> np.ndarray:
    u = np.asarray(u, dtype=float)
    if u.ndim == 1:
        u = u[:, None]
    if u.ndim != 2:
        raise ValueError(f"{name} must have shape (n_nodes, dim), got {u.shape}")
    return u


def displacement_error(u, u_ref, *, relative_to=None) -> DisplacementError:
    """Per-node Euclidean error ``|u - u_ref|`` and its statistics.

    ``relative_to`` selects the relative error:

    * ``None`` or ``"max"`` (default, the convention of the papers): errors divided by the largest
      reference displacement magnitude, ``max_i |u_ref_i|``;
    * a positive number: errors divided by that length [m] (e.g. the sample size);
    * ``"node"``: per-node relative errors ``|u_i - u_ref_i| / |u_ref_i|``; nodes with zero reference
      displacement (e.g. fixed nodes) get NaN and are left out of the relative statistics.

    If the scale is zero (the reference does not move) the relative statistics are NaN.
    """
    u, u_ref = _as_field(u, "u"), _as_field(u_ref, "u_ref")
    if u.shape != u_ref.shape:
        raise ValueError(f"u and u_ref differ in shape: {u.shape} vs {u_ref.shape}")
    if len(u) == 0:
        raise ValueError("no nodes")
    err = np.linalg.norm(u - u_ref, axis=1)
    ref = np.linalg.norm(u_ref, axis=1)

    with np.errstate(divide="ignore", invalid="ignore"):
        if isinstance(relative_to, str) and relative_to == "node":
            scale = None
            rel = np.where(ref > 0, err / np.where(ref > 0, ref, 1.0), np.nan)
        else:
            if relative_to is None or (isinstance(relative_to, str) and relative_to == "max"):
                scale = float(ref.max())
            elif isinstance(relative_to, str):
                raise ValueError(f"relative_to must be None, 'max', 'node' or a positive number, got {relative_to!r}")
            else:
                scale = float(relative_to)
                if not scale > 0:
                    raise ValueError(f"relative_to must be positive, got {relative_to!r}")
            rel = err / scale if scale > 0 else np.full_like(err, np.nan)

    if np.isnan(rel).all():
        rel_stats = (np.nan, np.nan, np.nan)
    else:
        rel_stats = (float(np.nanmean(rel)), float(np.nanstd(rel)), float(np.nanmax(rel)))
    return DisplacementError(
        mean=float(err.mean()), std=float(err.std()), max=float(err.max()),
        rel_mean=rel_stats[0], rel_std=rel_stats[1], rel_max=rel_stats[2],
        scale=scale, per_node=err, per_node_relative=rel,
    )


# --------------------------------------------------------------------------------------------------
# effective moduli


class YoungPoisson(NamedTuple):
    """Effective Young's modulus [Pa] and Poisson's ratio; unpacks as ``E, nu``."""

    E: float
    nu: float


def _positions(rest, displaced, mask):
    rest = _as_field(rest, "rest")
    displaced = _as_field(displaced, "displaced")
    if rest.shape != displaced.shape:
        raise ValueError(f"rest and displaced differ in shape: {rest.shape} vs {displaced.shape}")
    if mask is not None:
        mask = np.asarray(mask)
        rest, displaced = rest[mask], displaced[mask]
    if len(rest) <= rest.shape[1]:
        raise ValueError(f"need at least {rest.shape[1] + 1} nodes, got {len(rest)}")
    return rest, displaced


def mean_displacement_gradient(rest, displaced, *, mask=None) -> np.ndarray:
    """``H`` (``(dim, dim)``, ``H[i, j] = du_i / dx_j``) of the least-squares affine fit
    ``u = c + H x`` to the node displacements ``displaced - rest``."""
    rest, displaced = _positions(rest, displaced, mask)
    x = rest - rest.mean(axis=0)
    u = displaced - rest
    u = u - u.mean(axis=0)
    H_T, _, rank, _ = np.linalg.lstsq(x, u, rcond=None)
    if rank < rest.shape[1]:
        raise ValueError("the nodes do not span every axis; cannot fit a displacement gradient")
    return H_T.T


def _check_axis(axis, dim, name):
    axis = int(axis)
    if not 0 <= axis < dim:
        raise ValueError(f"{name} must be in [0, {dim}), got {axis}")
    return axis


def _normal_strains(rest, displaced, method, mask):
    if method == "fit":
        return np.diag(mean_displacement_gradient(rest, displaced, mask=mask)).copy()
    if method == "extent":
        rest, displaced = _positions(rest, displaced, mask)
        L0 = np.ptp(rest, axis=0)
        if np.any(L0 <= 0):
            raise ValueError("the sample has zero extent along an axis")
        return (np.ptp(displaced, axis=0) - L0) / L0
    raise ValueError(f"method must be 'fit' or 'extent', got {method!r}")


def youngs_modulus_poisson(rest, displaced, applied_stress, axis, *, method="fit", mask=None) -> YoungPoisson:
    """Effective ``E`` and ``nu`` of a uniaxial test along ``axis``.

    ``E = sigma / eps_axis`` and ``nu = -mean(eps_lateral) / eps_axis`` where ``sigma`` is
    ``applied_stress`` [Pa] (positive in tension; a compressive test gives negative stress and
    strain, hence positive ``E``), ``eps_axis`` the mean strain along ``axis`` and ``eps_lateral``
    the mean strains along the other axes (averaged over them in 3D). See the module docstring for
    ``method``; ``mask`` selects the nodes used.
    """
    rest_arr = _as_field(rest, "rest")
    dim = rest_arr.shape[1]
    axis = _check_axis(axis, dim, "axis")
    if dim < 2:
        raise ValueError("need at least 2 dimensions for Poisson's ratio")
    eps = _normal_strains(rest_arr, displaced, method, mask)
    eps_axial = eps[axis]
    if eps_axial == 0:
        raise ValueError("zero strain along the load axis")
    eps_lateral = np.delete(eps, axis).mean()
    return YoungPoisson(E=float(applied_stress / eps_axial), nu=float(-eps_lateral / eps_axial))


def shear_modulus(rest, displaced, shear_stress, axis_load, axis_normal, *, small_angle=False,
                  method="fit", mask=None) -> float:
    """Effective shear modulus of a shear test.

    The shear stress ``tau`` [Pa] acts along ``axis_load`` on the faces normal to ``axis_normal``
    (positive when it pushes the face of larger ``axis_normal`` coordinate towards +``axis_load``).
    The shear angle ``theta`` is the rotation of the sample's edges parallel to ``axis_normal``:
    ``tan(theta) = du_load / dx_normal`` (see the module docstring for ``method``).

    Returns ``G = tau / tan(theta)`` (Baudet's definition; exact for simple shear of a linear
    material), or ``G = tau / theta`` with ``small_angle=True``.
    """
    rest_arr = _as_field(rest, "rest")
    dim = rest_arr.shape[1]
    a = _check_axis(axis_load, dim, "axis_load")
    n = _check_axis(axis_normal, dim, "axis_normal")
    if a == n:
        raise ValueError("axis_load and axis_normal must differ")
    if method == "fit":
        slope = mean_displacement_gradient(rest_arr, displaced, mask=mask)[a, n]
    elif method == "extent":
        r, d = _positions(rest_arr, displaced, mask)
        x = r[:, n]
        lo, hi = x.min(), x.max()
        if hi <= lo:
            raise ValueError("the sample has zero extent along axis_normal")
        tol = 1e-9 * (hi - lo)
        u = d[:, a] - r[:, a]
        top, bottom = x >= hi - tol, x <= lo + tol
        slope = (u[top].mean() - u[bottom].mean()) / (hi - lo)
    else:
        raise ValueError(f"method must be 'fit' or 'extent', got {method!r}")
    if slope == 0:
        raise ValueError("zero shear angle")
    return float(shear_stress / (np.arctan(slope) if small_angle else slope))


def bulk_modulus(volume0, volume, pressure):
    """Effective bulk modulus ``B = -p / ((V - V0) / V0)``.

    ``pressure`` [Pa] is positive in compression, so a body that shrinks under a positive pressure
    has ``B > 0``. Works elementwise on arrays; raises ValueError if the volume did not change.
    """
    v0, v, p = np.asarray(volume0, dtype=float), np.asarray(volume, dtype=float), np.asarray(pressure, dtype=float)
    if np.any(v0 == 0):
        raise ValueError("volume0 must be non-zero")
    dv = (v - v0) / v0
    if np.any(dv == 0):
        raise ValueError("volume unchanged; the bulk modulus is undefined")
    B = -p / dv
    return float(B) if np.ndim(B) == 0 else B


# --------------------------------------------------------------------------------------------------
# volumes

def cell_volumes(mesh: Mesh, displacement=None) -> np.ndarray:
    """Signed measure of every cell (area in 2D, volume in 3D) of the (deformed) mesh.

    Positive for cells in the orientation of :mod:`msslib.mesh`, negative for inverted ones.  The
    measure of each cell type is its cell module's (:mod:`msslib.mesh.cells`): exact for every
    type (the determinant formula for simplices, ``det J`` integrated exactly for quads,
    hexahedra and wedges).
    """
    x = mesh.points
    if displacement is not None:
        u = np.asarray(displacement, dtype=float)
        if u.shape != x.shape:
            raise ValueError(f"displacement must have shape {x.shape}, got {u.shape}")
        x = x + u
    return _cells.get(mesh.cell_type).measure(x[mesh.cells])


def mesh_volume(mesh: Mesh, displacement=None) -> float:
    """Volume (area in 2D) of the body, deformed by ``displacement`` if given: the sum of the signed
    cell measures of :func:`cell_volumes`."""
    return float(cell_volumes(mesh, displacement).sum())
