"""Hints where the numbers point to a mistake in the input rather than to the model or solver.

* :func:`check_load_scale`, before a run: a load whose stress is far above the smallest Young's
  modulus (the classic: E given in MPa, loads in Pa) is refused, one line giving the ratio; a
  load above E but within :data:`REFUSE_RATIO` of it is a warning (strains above 1 ahead).  The
  stress of a load (:func:`load_stresses`): a traction's magnitude, a pressure's; gravity's ``rho g L`` with
  ``L`` the extent of the mesh along ``g`` (the weight a column of that height puts on its
  base); a nodal force over the mean cross-section of the mesh across it (volume, or area times
  thickness in 2D, over its extent along the force).  These are the stresses of a bar pulled,
  hung or pushed: bending raises them, so the ratio is a lower bound on what the body sees, and
  a ratio of 10 or more means strains no elastic model of msslib reaches (a stretch of 10).
* :func:`failure_hint`, after Newton failed: where the residual of the failing iterate
  concentrates on a sliver cell, the cell is named (index, nodes, smallest angle, aspect ratio).
"""

from __future__ import annotations

import warnings
from typing import NamedTuple

import numpy as np

from msslib import mesh as _mesh
from msslib.errors import MsslibWarning

__all__ = ["REFUSE_RATIO", "SLIVER_ASPECT", "LoadStress", "load_stresses", "check_load_scale", "failure_hint"]

#: a load stress at least this many times the smallest Young's modulus is refused before the run
REFUSE_RATIO = 10.0
#: a cell whose aspect ratio (:func:`msslib.mesh.hygiene.cell_shapes`) is at least this is a sliver
SLIVER_ASPECT = 100.0


class LoadStress(NamedTuple):
    """The stress scale of load ``index`` of a scene (Pa) and how it was found (for messages)."""

    index: int
    stress: float
    how: str


def load_stresses(mesh, loads, cell_density=None, thickness: float = 1.0, held: bool = True) -> list[LoadStress]:
    """The stress scale of every load of ``loads`` (the scene's list of load mappings, see the
    module docstring); gravity without densities, or on a body nothing holds (it falls freely),
    and a zero load are left out."""
    out = []
    points = np.asarray(mesh.points, dtype=float)
    for i, load in enumerate(loads):
        kind = load.get("type")
        if kind == "traction":
            t = float(np.linalg.norm(np.asarray(load["traction"], dtype=float)))
            out.append(LoadStress(i, t, f"traction |t| = {t:.3g} Pa"))
        elif kind == "pressure":
            p = abs(float(load["pressure"]))
            out.append(LoadStress(i, p, f"pressure |p| = {p:.3g} Pa"))
        elif kind == "gravity":
            g = np.asarray(load["g"], dtype=float)
            gn = float(np.linalg.norm(g))
            if not held or gn == 0 or cell_density is None or not np.isfinite(cell_density).any():
                continue
            rho = float(np.nanmax(cell_density))
            height = float(np.ptp(points @ (g / gn))) if len(points) else 0.0
            out.append(LoadStress(i, rho * gn * height,
                                  f"gravity rho g L = {rho:.3g} kg/m^3 x {gn:.3g} m/s^2 x {height:.3g} m = "
                                  f"{rho * gn * height:.3g} Pa (L the extent of the mesh along g)"))
        elif kind == "nodal_force":
            f = np.asarray(load["total"], dtype=float)
            fn = float(np.linalg.norm(f))
            if fn == 0 or mesh.n_cells == 0:
                continue
            volume = float(np.abs(_mesh.cell_measures(mesh)).sum()) * (thickness if mesh.dim == 2 else 1.0)
            length = float(np.ptp(points @ (f / fn)))
            if length <= 0 or volume <= 0:
                continue
            area = volume / length
            unit = "m^2" if mesh.dim == 3 else "m^2 (area x thickness)"
            out.append(LoadStress(i, fn / area, f"nodal force |F| = {fn:.3g} N over the mean cross-section "
                                                f"{area:.3g} {unit} across it = {fn / area:.3g} Pa"))
    return [s for s in out if s.stress > 0]


def times(ratio: float) -> str:
    """A ratio for a message: ``2.5`` or ``5 x 10^4``."""
    if ratio < 100:
        return f"{ratio:.3g}"
    mantissa, exponent = f"{ratio:.2e}".split("e")
    return f"{float(mantissa):g} x 10^{int(exponent)}"


def check_load_scale(mesh, loads, moduli, cell_density=None, thickness: float = 1.0, held: bool = True,
                     source: str = "scene.loads") -> None:
    """Refuse (ValueError) a load whose stress (:func:`load_stresses`) is :data:`REFUSE_RATIO` or
    more times the smallest Young's modulus of the cells, warn (:class:`MsslibWarning`) above 1.

    ``moduli`` are the materials' Young's moduli (Pa), indexed by ``mesh.material``; the message
    names ``{source}[i]`` (the load) and ``scene.materials[j]`` (the softest material used)."""
    moduli = np.asarray(moduli, dtype=float).reshape(-1)
    if mesh.n_cells == 0 or moduli.size == 0:
        return
    used = np.unique(mesh.material)
    softest = int(used[np.argmin(moduli[used])])
    E = float(moduli[softest])
    if not E > 0:
        return
    stresses = load_stresses(mesh, loads, cell_density, thickness, held)
    if not stresses:
        return
    worst = max(stresses, key=lambda s: s.stress)
    ratio = worst.stress / E
    what = (f"{source}[{worst.index}]: the load is {times(ratio)} E ({worst.how} against the smallest Young's "
            f"modulus E = {E:.6g} Pa, scene.materials[{softest}])")
    units = ("E is in Pa (an E given in MPa is 1e6 times larger in Pa, in GPa 1e9 times), tractions and pressures in Pa, "
             "forces in N, lengths in m")
    if ratio >= REFUSE_RATIO:
        raise ValueError(f"{what}: strains of order {times(ratio)}, far beyond any elastic model; {units}; "
                         f"allowed: loads below {REFUSE_RATIO:g} E")
    if ratio > 1.0:
        warnings.warn(f"{what}: strains above 1 ahead; {units}", MsslibWarning, stacklevel=2)


def failure_hint(problem, x, residual=None, free=None) -> str:
    """A clause for the message of a failed Newton solve, or ``""``.

    ``problem`` is the solver's problem (a :class:`msslib.system.Model`: its ``mesh``), ``x`` the
    failing iterate (positions, ``n_dof``), ``residual`` the free-dof residual there (computed
    from ``problem.force`` at load 1 when None).  When the node with the largest residual is a
    corner of a sliver (aspect ratio at least :data:`SLIVER_ASPECT`), the worst such cell is named.
    """
    mesh = getattr(problem, "mesh", None)
    if mesh is None or getattr(mesh, "n_cells", 0) == 0:
        return ""
    try:
        dim = mesh.dim
        if free is None:
            free = np.asarray(getattr(problem, "free", np.ones(problem.n_dof, dtype=bool)), dtype=bool)
        r = np.zeros(problem.n_dof)
        if residual is None:
            with np.errstate(all="ignore"):
                residual = np.asarray(problem.force(x, 1.0), dtype=float)[free]
        r[free] = residual
        per_node = np.linalg.norm(r.reshape(-1, dim), axis=1)
        per_node[~np.isfinite(per_node)] = np.inf
        if not per_node.max() > 0:
            return ""
        node = int(np.argmax(per_node))
        around = np.flatnonzero((mesh.cells == node).any(axis=1))
        aspect, angle = _mesh.hygiene.cell_shapes(mesh)
        cell = int(around[np.argmax(aspect[around])]) if len(around) else -1
        if cell < 0 or not aspect[cell] >= SLIVER_ASPECT:
            return ""
    except (AttributeError, TypeError, ValueError, IndexError):  # not a mesh-based problem: no hint
        return ""
    nodes = ", ".join(str(int(i)) for i in mesh.cells[cell])
    smallest = "" if angle is None else f"smallest angle {angle[cell]:.3g} deg, "
    return (f"the residual is largest at node {node}, a corner of {mesh.cell_type} cell {cell} (nodes {nodes}), a "
            f"sliver ({smallest}aspect ratio {aspect[cell]:.3g}) that stalls Newton's method; remesh or remove "
            f"it (allowed: cells of aspect ratio below {SLIVER_ASPECT:g})")
