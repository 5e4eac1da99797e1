"""Memory estimates made before anything large is allocated.

A typo such as ``nx: 10000`` or ``dt: 1.0e-12`` should fail at once with a message that names the
estimate and the limit, not end in a ``MemoryError`` traceback after minutes of swapping.  The
estimates here are deliberately simple and on the generous side:

* the size of a generated mesh from its generator's arguments (exact for the structured
  generators; for the gmsh generators from the volume or area and the element size ``h``);
* the memory of a run: a fixed part (the imported libraries) plus a cost per node, measured on
  whole runs (``python -m msslib run`` peak resident memory of Golec cube lattices from
  1 331 to 68 921 nodes: about 29 KB per node for the MSS statics and 90 KB per node for the
  non-linear FEM, whose direct solver fills in), plus the stored history of a dynamic run
  (positions and velocities of every saved state, held about four times over on the way to the
  result file).

The limit is the memory the operating system reports as available (``MemAvailable``), or the
scene's ``checks: {max_memory_gb: ...}``.
"""

from __future__ import annotations

import math
import os

from msslib.errors import ResourceError

__all__ = ["available_memory", "generated_mesh_size", "refined_mesh_size", "run_memory", "check_memory",
           "history_memory"]

#: resident memory of a process that has imported msslib, numpy, scipy, numba and scikit-fem and
#: compiled its kernels (B): compiling with a cold numba cache adds about 170 MB to a warm run, and
#: the first run in a freshly installed environment peaked at 905 MB on a 9 261-node lattice (of
#: which about 300 MB its nodes); with the pressure and cell-type kernels, a run right after the
#: kernels' sources changed (a cold cache) peaked at 997 MB on that lattice, so the fixed part is taken
#: as 800 MB
BASE_BYTES = 800e6
#: bytes per node of a whole run, by (kind, dimension); see the module docstring
PER_NODE_BYTES = {("mss", 3): 32e3, ("mss", 2): 10e3, ("fem", 3): 100e3, ("fem", 2): 30e3}
#: copies of the history held between the integrator and the result file
HISTORY_COPIES = 4
_REGULAR_TET = 1.0 / (6.0 * math.sqrt(2.0))  # volume of a regular tetrahedron of unit edge
_REGULAR_TRIANGLE = math.sqrt(3.0) / 4.0


def available_memory() -> float | None:
    """Memory available to a new allocation (bytes), or None when the system does not say."""
    try:
        with open("/proc/meminfo", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return float(line.split()[1]) * 1024.0
    except (OSError, ValueError, IndexError):
        pass
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES")) * float(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):
        return None


def _polygon_area(vertices) -> float:
    pts = [tuple(float(c) for c in v) for v in vertices]
    return 0.5 * abs(sum(x0 * y1 - x1 * y0 for (x0, y0), (x1, y1) in zip(pts, pts[1:] + pts[:1])))


def generated_mesh_size(generator: str, args: dict) -> tuple[float, float, int]:
    """``(n_nodes, n_cells, dim)`` of ``msslib.mesh.<generator>(**args)``, without building it.

    Exact for the structured generators, an estimate (from the volume or area over the volume of
    a regular simplex of edge ``h``, calibrated on gmsh's output) for the gmsh generators.
    Returns NaN counts for arguments it cannot read (the generator then reports them itself).
    """
    a = dict(args)
    nan = float("nan")
    try:
        if generator in ("quad_grid", "triangle_grid_right"):
            nx, ny = float(a["nx"]), float(a["ny"])
            return (nx + 1) * (ny + 1), nx * ny * (1 if generator == "quad_grid" else 2), 2
        if generator == "triangle_grid_equilateral":
            n = float(a["n"])
            rows = n * float(a["height"]) / float(a["width"]) / (math.sqrt(3.0) / 2.0)
            return (n + 1) * (rows + 1), 2 * n * rows, 2
        if generator == "hexagon_equilateral":
            r = float(a["n_rings"])
            return 3 * r * (r + 1) + 1, 6 * r * r, 2
        if generator in ("hex_grid", "tet_grid", "wedge_grid"):
            nx, ny, nz = float(a["nx"]), float(a["ny"]), float(a["nz"])
            per_cube = {"hex_grid": 1, "wedge_grid": 2}.get(generator) or float(a.get("scheme", 6))
            return (nx + 1) * (ny + 1) * (nz + 1), per_cube * nx * ny * nz, 3
        if generator == "l_block_hex":
            n = float(a["n"])
            return 0.75 * (n + 1) ** 3 + (n + 1) ** 2, 0.75 * n ** 3, 3
        h = float(a["h"])
        if generator == "polygon_mesh":
            n = _polygon_area(a["vertices"]) / (_REGULAR_TRIANGLE * h * h)
            return 0.6 * n + 10, 1.1 * n + 10, 2
        if generator == "cylinder_mesh":
            volume = math.pi * float(a["radius"]) ** 2 * float(a["height"])
        elif generator == "cylinder_with_hole_mesh":
            volume = math.pi * (float(a["radius"]) ** 2 - float(a["hole_radius"]) ** 2) * float(a["height"])
        elif generator == "cone_mesh":
            r0, r1 = float(a["r_bottom"]), float(a["r_top"])
            volume = math.pi * float(a["height"]) * (r0 * r0 + r0 * r1 + r1 * r1) / 3.0
        elif generator == "l_block_tet":
            volume = 0.75 * float(a["size"]) ** 3
        else:
            return nan, nan, 3
        n = abs(volume) / (_REGULAR_TET * h ** 3)
        return 0.3 * n + 50, 1.1 * n + 50, 3
    except (KeyError, TypeError, ValueError, ZeroDivisionError, OverflowError):
        return nan, nan, 3


def refined_mesh_size(n_nodes: float, n_cells: float, dim: int, times: int) -> tuple[float, float]:
    """``(nodes, cells)`` of a mesh of ``n_nodes`` nodes and ``n_cells`` cells after ``times``
    uniform refinements (:func:`msslib.mesh.refine.uniform`), known before refining: the cells
    exactly (each has ``2**dim`` children), the nodes about (each refinement multiplies them by
    about ``2**dim``: exact for a fine grid of squares or cubes, an upper bound for simplices,
    whose new nodes are their edges' midpoints)."""
    times = int(times)
    factor = float(2 ** dim) ** times
    return float(n_nodes) * factor, float(n_cells) * factor


def history_memory(n_saved: float, n_dof: float) -> float:
    """Bytes of a dynamic run's stored history: positions and velocities of ``n_saved`` states."""
    return HISTORY_COPIES * 2.0 * 8.0 * float(n_saved) * float(n_dof)


def run_memory(n_nodes: float, dim: int, *, fem: bool = False, n_saved: float = 0.0) -> float:
    """Estimated peak memory (bytes) of a run on ``n_nodes`` nodes (see the module docstring)."""
    per_node = PER_NODE_BYTES[("fem" if fem else "mss", 3 if dim == 3 else 2)]
    return BASE_BYTES + per_node * float(n_nodes) + history_memory(n_saved, float(n_nodes) * dim)


def _gb(value: float) -> str:
    return f"{value / 1e9:.3g} GB"


def check_memory(estimate: float, what: str, hint: str, limit_gb: float | None = None) -> None:
    """Raise :class:`msslib.errors.ResourceError` when ``estimate`` (bytes) exceeds the limit.

    The limit is ``limit_gb`` (GB) if given, else the memory available now; without either
    nothing is checked.
    """
    if limit_gb is not None:
        limit, source = float(limit_gb) * 1e9, f"checks.max_memory_gb = {limit_gb:g}"
    else:
        limit, source = available_memory(), "the memory available on this machine"
        if limit is None:
            return
    if not math.isfinite(estimate) or estimate > limit:
        shown = "more than can be counted" if not math.isfinite(estimate) else f"about {_gb(estimate)}"
        raise ResourceError(f"{what} would need {shown}, over the limit of {_gb(limit)} ({source}); {hint}")
