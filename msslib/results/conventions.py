"""The NetCDF result schema of msslib (CF-1.11, UGRID-1.0): its description and constants.

Results are built by :func:`msslib.results.netcdf.make_dataset`, written by :func:`msslib.results.netcdf.write_result` and
read by :func:`msslib.results.netcdf.read_result` and :func:`msslib.results.netcdf.mesh_from_result`; this module holds
what they share: the schema below and its names.

Results are :class:`xarray.Dataset` objects built by :func:`msslib.results.netcdf.make_dataset`, written atomically by
:func:`msslib.results.netcdf.write_result` (engine ``netcdf4``) and read back fully into memory by :func:`msslib.results.netcdf.read_result`.
:func:`msslib.results.netcdf.mesh_from_result` rebuilds the :class:`~msslib.mesh.Mesh`. :class:`msslib.results.staging.StagedOutputs` writes
several files as one (all are replaced, or none is); every write goes through it, so temporary
files are removed on any error, on SIGINT and on SIGTERM.

Schema ``msslib-result-2.0``: CF-1.11 and UGRID-1.0
===================================================

A result follows the CF metadata conventions 1.11 and the UGRID conventions 1.0 for unstructured
meshes (global attribute ``Conventions = "CF-1.11 UGRID-1.0"``, :data:`CONVENTIONS`); the global
attribute ``msslib_schema`` (:data:`SCHEMA_VERSION`) tells this schema from the older
``msslib-result-1.0`` (which had ``Conventions = "msslib-result-1.0"``, the material constants as
global attributes and the per-cell material index in a variable ``material``; such files are still
read by :func:`msslib.results.netcdf.mesh_from_result`). ``tests/test_cf.py`` runs the IOOS compliance checker (CF-1.11)
and checks the UGRID rules listed here.

Units are UDUNITS strings (``m``, ``N``, ``N m-1``, ``Pa``, ``kg m-3``, ``J``, ``s``, ``m s-1``;
``1`` for dimensionless quantities). Every variable has a ``long_name``; every physical or
dimensionless quantity has ``units``; connectivity, index, flag and label variables have none (they
are not quantities). CF standard names are used where one exists and fits: none fits Cartesian
coordinates of a body (``projection_x_coordinate`` means map projections), displacements, forces,
spring or material constants, so these have ``long_name`` and ``units`` only. ``time`` has no
``standard_name`` either: CF's ``time`` needs units ``"<unit> since <date>"``, and a simulation's
time is elapsed time with no date.

Mesh topology (UGRID)
---------------------

``mesh`` (a dummy integer, ``cf_role = "mesh_topology"``) describes the mesh of the run:
``topology_dimension`` 2 (triangles, quads: faces) or 3 (tetrahedra, hexahedra: volumes),
``node_coordinates = "node_x node_y"`` (2D) or ``"node_x node_y node_z"`` (3D), and

* 2D: ``face_node_connectivity = "cells"``, ``face_dimension = "cell"``;
* 3D: ``volume_node_connectivity = "cells"``, ``volume_dimension = "cell"``,
  ``volume_shape_type = "cell_shape"`` (UGRID's 3D section: a flag variable with the shape of every
  volume; node order per shape is VTK's, which is :mod:`msslib.mesh`'s).

The springs of a mass-spring system are a second topology, ``spring_network``
(``topology_dimension = 1``, the same ``node_coordinates``, ``edge_node_connectivity = "springs"``,
``edge_dimension = "spring"``): a 1D network on the same nodes. They are not the edges of ``mesh``
because many models have springs along face and cell diagonals. Connectivities are 0-based
(``start_index = 0``); all cells of a mesh have the same number of nodes, so no ``_FillValue`` is
needed. Variables defined on the mesh carry ``mesh`` and ``location``: ``"node"`` (dimension
``node``; with ``coordinates = "node_x node_y (node_z)"``, written by xarray), ``"face"`` (2D) or
``"volume"`` (3D) for dimension ``cell``, and ``mesh = "spring_network"``, ``location = "edge"``
for dimension ``spring``. :func:`msslib.results.netcdf.make_dataset` adds these to every variable with one of these
dimensions (``extra_vars`` included) that does not set them itself.

Dimensions
----------

============== ===============================================================================
dimension      meaning
============== ===============================================================================
``node``       mesh nodes, in the order of ``Mesh.points``
``axis``       spatial axes x, y (2D) and z (3D); the label variable ``axis_name`` names them
               (CF coordinate variables are numeric, so there is no coordinate variable ``axis``)
``cell``       mesh cells, in the order of ``Mesh.cells``
``cell_node``  nodes of one cell (3 triangle, 4 quad, 4 tetra, 8 hexahedron, 6 wedge)
``material``   materials; coordinate variable ``material`` holds ``0, 1, ...``
``spring``     springs of a mass-spring system (optional)
``spring_end`` the two end nodes of a spring (length 2; optional, with ``spring``)
``time``       stored states of a dynamic run; coordinate variable ``time`` [s] (optional)
``step``       stored states of a quasi-static / iterative run when there is no physical time;
               coordinate variable ``step`` [1] (optional; used only if ``time`` is not)
============== ===============================================================================

Variables
---------

====================================================== ======== ========================================
variable                                               units    content
====================================================== ======== ========================================
``mesh``                                               -        UGRID mesh topology (see above)
``node_x(node)``, ``node_y(node)``, ``node_z(node)``   m        node coordinates of the undeformed mesh
                                                                (auxiliary coordinates; ``node_z`` in
                                                                3D only)
``axis_name(axis)``                                    -        ``"x"``, ``"y"`` (, ``"z"``): string
                                                                label (auxiliary coordinate, CF 6.1)
``rest_position(node, axis)``                          m        the same node positions as one array,
                                                                for arithmetic with ``displacement``
``displacement(node, axis)``                           m        displacement of the final state
``cells(cell, cell_node)``                             -        int64 connectivity, 0-based node
                                                                indices, node order of
                                                                :mod:`msslib.mesh`; ``cf_role``
                                                                ``face_node_connectivity`` (2D) or
                                                                ``volume_node_connectivity`` (3D),
                                                                ``start_index = 0``; attribute
                                                                ``cell_type`` (``triangle``,
                                                                ``quad``, ``tetra``, ``hexahedron``,
                                                                ``wedge``: a type of
                                                                :mod:`msslib.mesh.cells`)
``cell_shape(cell)``                                   -        3D only: int8 UGRID volume shape flag
                                                                (``flag_values 0 1 2 3``,
                                                                ``flag_meanings "tetrahedron pyramid
                                                                wedge hexahedron"``)
``material(material)``                                 -        int64 material index (coordinate)
``cell_material(cell)``                                -        int64 material index of the cell
``material_E(material)``                               Pa       Young's modulus
``material_nu(material)``                              1        Poisson's ratio
``material_density(material)``                         kg m-3   density (optional: only when some
                                                                material has one; ``_FillValue``
                                                                9.969209968386869e36, read back as NaN,
                                                                where a material has none)
``material_name(material)``                            -        material names (optional)
``thickness``                                          m        membrane thickness of a 2D (plane
                                                                stress) mesh (optional, scalar)
``spring_network``                                     -        UGRID 1D topology of the springs
                                                                (optional, with ``springs``)
``springs(spring, spring_end)``                        -        int64 end nodes of every spring,
                                                                ``cf_role = "edge_node_connectivity"``,
                                                                ``start_index = 0`` (optional)
``spring_constant(spring)``                            N m-1    spring stiffness (optional)
``rest_length(spring)``                                m        spring rest length (optional)
``reaction_force(node, axis)``                         N        reaction force at the nodes (optional)
``fixed(node, axis)``                                  -        Dirichlet mask: ``bool`` in memory,
                                                                stored as ``int8`` 0/1 with attribute
                                                                ``dtype = "bool"`` (xarray decodes it
                                                                back to ``bool``), ``flag_values 0 1``,
                                                                ``flag_meanings "free prescribed"``
                                                                (optional)
``time(time)``                                         s        simulated time of the stored states,
                                                                from the start of the run (optional)
``step(step)`` or ``step(time)``                       1        iteration / load-step number (optional)
``displacement_history(time|step, node, axis)``        m        displacement of every stored state
                                                                (optional)
``velocity_history(time|step, node, axis)``            m s-1    velocity of every stored state
                                                                (optional)
====================================================== ======== ========================================

Further variables may be added with ``extra_vars``; they need a ``long_name``, and ``units`` unless
they are flags (``flag_values`` and ``flag_meanings``) or text. :func:`msslib.scene.run_scene`
adds ``cell_state(cell)`` (flags, :mod:`msslib.mesh.quality`), ``relative_jacobian(cell)`` [1], the
energies of dynamic runs (``kinetic_energy(time)``, ``potential_energy(time)`` [J]) and the
potential energy of the final state of static mass-spring runs (scalar ``potential_energy`` [J]).

Global attributes
-----------------

==================== ==========================================================================
attribute            content
==================== ==========================================================================
``Conventions``      ``"CF-1.11 UGRID-1.0"`` (:data:`CONVENTIONS`)
``msslib_schema``    ``"msslib-result-2.0"`` (:data:`SCHEMA_VERSION`)
``title``            ``"msslib result: <model>"``
``source``           ``"msslib <version>"``
``history``          ``"<created> created by msslib <version>"``
``model``            model name, e.g. ``"fem_linear"``, ``"lloyd_tetrahedron"``
``scene``            the scene text or name (``""`` if none; a mapping is stored as JSON)
``msslib_version``   :data:`msslib.__version__`
``git_commit``       ``git rev-parse HEAD`` run in the package's directory, with suffix
                     ``"+dirty"`` when tracked files have uncommitted changes (untracked files are
                     ignored, as by ``git describe --dirty``); ``"unknown"`` when unavailable
``created``          creation time, UTC, ISO 8601 (``YYYY-MM-DDTHH:MM:SS+00:00``)
``python_version``   :func:`platform.python_version`
``numpy_version``    :data:`numpy.__version__`
``wall_time_s``      wall time of the run [s]; NaN when not given
``solver_*``         solver statistics, flattened: ``{"newton": {"iterations": 3}}`` becomes
                     ``solver_newton_iterations = 3``
==================== ==========================================================================

Attribute values are restricted to what netCDF stores: strings, numbers and 1-D numeric arrays.
Booleans become the integers 0/1; ``None`` (and the string ``"None"``, which older callers passed for
"no value") drops the attribute; anything else (lists of strings, nested or ragged lists, mappings)
is stored as its JSON text. A length-1 array attribute reads back as a scalar (a netCDF property).
Further global attributes may be added with ``extra_attrs`` (they must not collide with the
attributes above); physical quantities belong in variables, where they carry units.
"""

from __future__ import annotations

from msslib.mesh.cells import RegistryView as _RegistryView

#: value of the global attribute ``Conventions``
CONVENTIONS = "CF-1.11 UGRID-1.0"
#: value of the global attribute ``msslib_schema``
SCHEMA_VERSION = "msslib-result-2.0"
#: the schema before CF/UGRID (its ``Conventions`` attribute); :func:`mesh_from_result` reads it
LEGACY_SCHEMA_VERSION = "msslib-result-1.0"
AXIS_NAMES = ("x", "y", "z")
ENGINE = "netcdf4"
#: Variables that must be finite for :func:`write_result` to accept a dataset.
FINITE_VARIABLES = ("rest_position", "displacement", "displacement_history", "velocity_history")
#: Global attributes set by :func:`make_dataset` (``solver_*`` apart).
SCHEMA_ATTRS = (
    "Conventions", "msslib_schema", "title", "source", "history", "model", "scene", "msslib_version",
    "git_commit", "created", "python_version", "numpy_version", "wall_time_s",
)
#: the UGRID mesh topology variables
MESH, SPRING_NETWORK = "mesh", "spring_network"
#: UGRID volume shapes (flag values of ``cell_shape``) and the msslib cell types they stand for
VOLUME_SHAPES = ("tetrahedron", "pyramid", "wedge", "hexahedron")
_VOLUME_SHAPE_OF = _RegistryView(lambda c: c.volume_shape, "3D cell type -> UGRID volume shape",
                                 only=lambda c: c.dim == 3 and c.volume_shape in VOLUME_SHAPES)
#: the netCDF default fill value of doubles, used where a material has no density
DOUBLE_FILL = 9.969209968386869e36
#: variables stored with a ``_FillValue`` (:data:`DOUBLE_FILL`; NaN in memory)
FILLED_VARIABLES = ("material_density",)
