"""Meshes: node positions, cells of one type, a material index per cell, named groups.

Conventions (shared by every module of msslib):

* ``points`` has shape ``(n_nodes, dim)`` in metres, ``dim`` is 2 or 3.
* ``cells`` has shape ``(n_cells, nodes_per_cell)``; node order is meshio's/VTK's:
  ``triangle`` and ``quad`` counter-clockwise; ``tetra`` positively oriented
  (``det[p1-p0, p2-p0, p3-p0] > 0``); ``hexahedron`` nodes 0-3 the bottom face counter-clockwise
  seen from above, 4-7 the top face, node ``i + 4`` above node ``i``; ``wedge`` nodes 0-2 the
  bottom triangle clockwise seen from above (its normal points out), 3-5 the top triangle, node
  ``i + 3`` above node ``i``.
* ``material`` has shape ``(n_cells,)``: an index into the list of materials of a model.
* ``cell_groups``, ``facet_groups``, ``node_groups``: named groups of cells, boundary facets and
  nodes from a mesh file (see :class:`Mesh` and :func:`read`).

Contents of this package, one concern per module; every name below is importable from ``msslib.mesh``
(all lengths in metres, areas in m^2, volumes in m^3):

* :mod:`msslib.mesh.cells`: the cell types, one module each (``triangle``, ``quad``, ``tetra``,
  ``hexahedron``, ``wedge``), found by :func:`msslib.mesh.cells.registry`: their local numbering
  (edges, faces of each facet type), measure, refinement rule, scikit-fem elements and names;
* :mod:`msslib.mesh.core`: :class:`Mesh`, :data:`CELL_TYPES` (read from the cell registry),
  :data:`COINCIDENT_RTOL`, :data:`COINCIDENT_POLICIES`;
* :mod:`msslib.mesh.structured`, structured generators: :func:`quad_grid`,
  :func:`triangle_grid_right`, :func:`triangle_grid_equilateral` (with :func:`equilateral_rows`),
  :func:`hexagon_equilateral`, :func:`hex_grid`, :func:`tet_grid`, :func:`wedge_grid`, :func:`l_block_hex`;
* :mod:`msslib.mesh.unstructured`, meshes generated with gmsh: :func:`polygon_mesh`,
  :func:`cylinder_mesh`, :func:`cylinder_with_hole_mesh`, :func:`cone_mesh`, :func:`l_block_tet`.
  Element sizes are at most ``h``, refined to about 12 elements per full circle on curved
  boundaries but not below ``h / 8``; gmsh runs single-threaded with a fixed random ``seed``, so
  a call is reproducible; the mesh keeps only the nodes its cells use and its simplices are
  positively oriented;
* :mod:`msslib.mesh.files`, input/output: :func:`read` (every failure one ValueError naming the
  file; keeps the file's physical groups, cell sets and node sets), :func:`write_vtu`,
  :func:`readable_suffixes`, :func:`check_mesh_suffix`; :mod:`msslib.mesh.meshio_output` collects what
  meshio says while it reads, per thread, without replacing ``sys.stdout`` or ``sys.stderr``;
* :mod:`msslib.mesh.groups`, groups and selections: :func:`materials_from_groups` (a material
  index per cell from cell groups), :func:`select_nodes`;
* :mod:`msslib.mesh.topology`: :class:`NodePairs`, :func:`unique_edges`, :func:`face_diagonals`,
  :func:`inner_diagonals`, :func:`boundary_facets`, :func:`boundary_facets_by_type` (of a cell type
  with facets of several types: a wedge has triangles and quads), :func:`facet_cell_counts` (is a
  facet a face of the mesh);
* :mod:`msslib.mesh.geometry`: :func:`cell_measures`, :func:`check_cells`, :func:`orient`,
  :func:`facet_areas`, :func:`lumped_masses`;
* :mod:`msslib.mesh.hygiene`: :func:`coincident_nodes` and :func:`resolve_coincident_nodes`
  (nodes at the same place but with different numbers, which cut a body in two: merged or
  refused), :func:`connected_parts` and :func:`loose_parts` (parts whose fixed dofs leave a
  rigid-body mode free: floating, or free to slide or turn; :class:`LoosePart`).

The modules import one another in one direction: ``cells`` (which imports nothing of the mesh
package; its registry imports the cell modules) <- ``core`` <- ``topology``, ``geometry``,
``groups``; ``geometry`` <- ``structured``, ``unstructured``; ``groups`` <- ``hygiene`` <-
``files`` -> ``meshio_output``.  gmsh and meshio are imported only when a mesh is generated or a file is read or
written.

The L-shaped block (:func:`l_block_hex`, :func:`l_block_tet`) of edge ``size`` ``s`` is the cube
``[0, s]^3`` from which the quadrant ``x > s/2, z > s/2`` is removed: its cross-section in the
x-z plane is an "L" (three squares of side ``s/2``), extruded over ``0 <= y <= s``.
Its volume is ``3 s^3 / 4``.
"""

from __future__ import annotations

from .core import (
    CELL_TYPES,
    COINCIDENT_POLICIES,
    COINCIDENT_RTOL,
    Mesh,
)
from .files import check_mesh_suffix, read, readable_suffixes, write_vtu
from .geometry import cell_measures, check_cells, facet_areas, lumped_masses, orient
from .groups import materials_from_groups, select_nodes
from .hygiene import (
    LoosePart,
    coincident_nodes,
    connected_parts,
    loose_parts,
    resolve_coincident_nodes,
)
from .reorder import reorder_nodes
from .structured import (
    equilateral_rows,
    hex_grid,
    hexagon_equilateral,
    l_block_hex,
    quad_grid,
    tet_grid,
    triangle_grid_equilateral,
    triangle_grid_right,
    wedge_grid,
)
from .topology import (
    NodePairs,
    boundary_facets,
    boundary_facets_by_type,
    face_diagonals,
    facet_cell_counts,
    inner_diagonals,
    unique_edges,
)
from .unstructured import (
    cone_mesh,
    cylinder_mesh,
    cylinder_with_hole_mesh,
    l_block_tet,
    polygon_mesh,
)

__all__ = [
    "CELL_TYPES",
    "Mesh",
    "NodePairs",
    "quad_grid",
    "triangle_grid_right",
    "equilateral_rows",
    "triangle_grid_equilateral",
    "hexagon_equilateral",
    "hex_grid",
    "tet_grid",
    "wedge_grid",
    "l_block_hex",
    "polygon_mesh",
    "cylinder_mesh",
    "cylinder_with_hole_mesh",
    "cone_mesh",
    "l_block_tet",
    "read",
    "reorder_nodes",
    "materials_from_groups",
    "facet_cell_counts",
    "readable_suffixes",
    "check_mesh_suffix",
    "write_vtu",
    "unique_edges",
    "face_diagonals",
    "inner_diagonals",
    "boundary_facets",
    "boundary_facets_by_type",
    "facet_areas",
    "cell_measures",
    "check_cells",
    "orient",
    "select_nodes",
    "lumped_masses",
    "COINCIDENT_RTOL",
    "COINCIDENT_POLICIES",
    "coincident_nodes",
    "resolve_coincident_nodes",
    "connected_parts",
    "LoosePart",
    "loose_parts",
]
