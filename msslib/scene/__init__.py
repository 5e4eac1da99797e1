"""Declarative scenes: a YAML file that describes one simulation, from the mesh to the output.

:func:`load_scene` reads and validates a scene (a YAML file or an equivalent ``dict``) into a
:class:`Scene`; :func:`prepare` builds its mesh, boundary conditions, loads and model;
:func:`run_scene` solves it and returns an :class:`xarray.Dataset` in the schema of
:mod:`msslib.results.netcdf`.  The command line (``python -m msslib run SCENE.yaml --out OUT.nc``) wraps them.

Syntax reference
================

Units are SI throughout: metres, pascals, newtons, kilograms, seconds.  Numbers may be written
``1.0e6`` or ``1e6`` (plain YAML reads the latter as a string; scenes accept both).  Every mapping
is checked for unknown keys: a typo is an error naming its full path, e.g.
``scene.loads[1].tractoin: unknown key; expected one of select, traction, type``.

.. code-block:: yaml

    name: golec_compression            # optional; default: the file name without suffix
    description: Golec cube, 10 % compression          # optional, free text
    geometry:                          # exactly one of `generator` or `file`
      generator: hex_grid              # a generator of msslib.mesh
      args: {lx: 0.1, ly: 0.1, lz: 0.1, nx: 4, ny: 4, nz: 4}
      # file: meshes/part.vtu          # or any file meshio reads, relative to the scene file
    materials:                         # material i applies to the cells with material index i
      - {E: 1.0e6, nu: 0.3, density: 1000.0}
      # or keyed by the cell groups of a mesh file: {soft: {E: ..., nu: ...}, stiff: {...}}
    regions:                           # optional; later entries win
      - {box: [[0.05, null, null], [null, null, null]], material: 1}
    thickness: 0.01                    # 2D meshes only (default 1.0)
    model: golec_cube                  # or a mapping, see "model" below
    boundary:
      - {select: {plane: [z, 0.0]}, fix: [z]}
      - {select: {plane: [z, 0.1]}, fix: [z], displacement: [null, null, -0.01]}
    loads:
      - {type: gravity, g: [0.0, 0.0, -9.81]}
    solver: {type: static, load_steps: 5, tol: 1.0e-8}
    output: {vtu: true}

``geometry``
    ``generator`` names one of :data:`GENERATORS` (``quad_grid``, ``triangle_grid_equilateral``,
    ``hexagon_equilateral``, ``triangle_grid_right``, ``hex_grid``, ``tet_grid``,
    ``l_block_hex``, ``polygon_mesh``, ``cylinder_mesh``, ``cylinder_with_hole_mesh``,
    ``cone_mesh``, ``l_block_tet``, ``wedge_grid``: the generators the cell types declare, read
    from :mod:`msslib.mesh.cells`) and ``args`` its keyword arguments (see :mod:`msslib.mesh`;
    unknown or missing arguments are errors).  ``file`` is a mesh file read by
    :func:`msslib.mesh.read`, relative to the directory of the scene file (or of ``base_dir`` for a
    scene given as a dict); an integer cell data array ``material`` becomes the material index.
    The file's groups are kept (gmsh physical groups, cell sets, node sets; see
    :func:`msslib.mesh.read`): groups of its cells for ``materials``, groups of boundary facets
    (gmsh physical surfaces of a 3D mesh, curves of a 2D mesh) and nodes for ``select``.  A group
    is known by its name, a gmsh physical group without a name by its number (``3`` or ``"3"``).
    ``refine: k`` (optional) refines the mesh uniformly ``k`` times (:func:`msslib.mesh.refine.uniform`:
    nested meshes of one domain, the coarse nodes keeping their numbers).
``materials``
    A non-empty list (every material used by some cell) of ``{E, nu, density}``: Young's modulus ``E > 0`` (Pa), Poisson's ratio
    ``-1 < nu < 0.5`` and the density (kg/m^3, > 0).  ``density`` may be omitted unless the scene
    has gravity or is dynamic.  Note that the triangle and square MSS models are exact only for
    ``nu = 1/3``, Lloyd's tetrahedron without volume term for ``nu = 1/4``.

    Or a mapping from the cell groups of a mesh file to their materials, which assigns each
    group's cells its material (the file's ``material`` cell data is then not used); every cell
    must be in exactly one of the groups named (cells in none or in two are an error counting
    them, with an example cell), and a group the mesh lacks is an error naming the groups it has.
    Material ``i`` is the ``i``-th entry as written; the result names them (``material_name``)::

        geometry: {file: meshes/two_materials.msh}   # physical volumes soft, stiff; surfaces base, top
        materials:
          soft: {E: 1.0e6, nu: 0.45, density: 1100.0}
          stiff: {E: 2.0e8, nu: 0.3, density: 7800.0}
        boundary:
          - {select: {group: base}}
        loads:
          - {type: traction, select: {group: top}, traction: [0.0, 0.0, -1.0e4]}

    With the list form, material ``i`` applies to the cells of material index ``i`` (cell data
    ``material``, ``regions``); a mesh file with cell groups but no material index (every cell 0)
    and a list of several materials is an error asking for the mapping form (or ``regions``), and
    one material for the whole mesh is fine.
``regions``
    Optional list of ``{box: [[xmin, ymin(, zmin)], [xmax, ymax(, zmax)]], material: i}``: cells
    whose centroid lies in the box (``null`` bounds are unbounded) get material ``i`` (with
    materials keyed by group, ``material`` names one of the keys), after the groups.
``thickness``
    Membrane thickness (m) of a 2D mesh (plane stress); an error for 3D meshes.
``model``
    A name, or a mapping ``{type: NAME, ...options}``; the models are those of the registry of
    :mod:`msslib.models` (one module per family; :data:`MODELS` lists them).  FEM references
    (scikit-fem): ``fem_linear`` (small strain), ``fem_svk`` (St Venant-Kirchhoff),
    ``fem_neohookean``; option ``plane: stress | strain`` for 2D (default ``stress``).  Mass-spring
    models with their mesh:

    ============================ ============ =========================================
    model                        cells        terms (default: all of them)
    ============================ ============ =========================================
    ``lloyd_triangle``           triangle     ``springs``
    ``van_gelder``               triangle     ``springs``
    ``lloyd_square``             quad         ``springs``
    ``lloyd_rectangle``          quad         ``springs``
    ``lloyd_tetrahedron``        tetra        ``springs``
    ``lloyd_tetrahedron_volume`` tetra        ``springs``, ``volume``
    ``baudet_cube``              hexahedron   ``springs``, ``correction``
    ``golec_cube``               hexahedron   ``springs``, ``volume``
    ``delingette_triangle``      triangle     ``springs``
    ``lsq_triangle``             triangle     ``springs``
    ``lsq_tetrahedron``          tetra        ``springs``
    ``kikuuwe_tetrahedron``      tetra        ``springs``
    ============================ ============ =========================================

    (every MSS model of the registry, a test checks; the documentation's model table, generated
    from the registry, adds each model's family, options and where it is exact.)

    Options: ``published: true`` uses the formulas as printed in the papers (see
    :mod:`msslib.parameters`; models without a separate printed variant ignore it), ``terms`` the
    list of internal force terms to build (only those listed are built, e.g.
    ``{type: golec_cube, terms: [springs]}`` is a classical MSS without Golec's volume term), and
    each model's own options (its spec's ``options``): ``A`` (``golec_cube``, default 1.0) the
    ratio ``k_inner / k_face``; ``fit: equilibrium | least_squares`` (``lloyd_rectangle``, on quads
    that are rectangles of any aspect ratio ``r``, each quad its own: the least-squares springs
    among elements in equilibrium at rest, the default, or the free least-squares optimum for the
    material's nu, which does not stay at rest without load for r != 1 and has positive springs
    only for 0.49 < r < 2.03 at nu = 1/3); ``correction: boundary | element`` (``baudet_cube``).
    Baudet's ``correction`` is computed from the traction and nodal-force loads (not gravity); it
    is non-conservative, so the static solver's line search works on the residual norm.  Its
    reading ``boundary`` (the default, as just said) or ``element``, each cube's correction from
    the forces acting on it from outside (neighbours, loads, gravity, supports), see
    :mod:`msslib.terms.baudet`.
``boundary``
    List of ``{select: SELECTION, fix: [x, y(, z)] | all, displacement: [...]}``, e.g.
    ``{select: {group: base}, fix: all}`` for a gmsh physical surface ``base``.  ``fix``
    (default ``all``) lists the constrained axes of the selected nodes; ``displacement`` (optional)
    gives one value per axis (m), ``null`` or 0 for the axes not fixed.  A dof fixed twice with two
    different displacements is an error.  Static solves ramp prescribed displacements with the
    load factor; dynamic runs apply them at ``t = 0`` and hold them.  A static scene must hold
    every part of its mesh: a floating part or a free rigid-body mode (a translation or rotation
    the fixed dofs do not stop) is an error naming the part and the mode.
``SELECTION``
    ``all``, or a mapping with ``plane: [axis, value]`` (axis ``x``, ``y`` or ``z``),
    ``box: [[xmin, ...], [xmax, ...]]`` (``null`` = unbounded, either corner may be ``null``)
    and/or ``group: NAME`` (a group of the mesh file: the nodes of its facets, or its nodes, or
    for a group of cells the nodes of those cells; a name that is a group of more than one kind,
    such as a gmsh physical surface and a physical volume both called ``body``, selects its
    facets, else its nodes, with a warning, while ``materials`` keyed by it take its cells); with
    several, the intersection, e.g.
    ``{group: top, box: [[0.0, null, null], [0.05, null, null]]}``.  ``tol`` (m) widens the
    bounds; default ``1e-8`` times the diagonal of the mesh's bounding box.  Selecting no node is
    an error, and so is a group the mesh lacks (naming the groups it has).
``loads``
    List of load entries, all proportional to the load factor of the static solver:

    * ``{type: gravity, g: [0, 0, -9.81]}`` — weight of the lumped node masses (m/s^2);
    * ``{type: traction, select: SELECTION, traction: [tx, ty(, tz)]}`` — a dead traction (Pa) on
      the boundary facets whose nodes are all selected (consistent nodal forces; in 2D per unit
      area of the edge times ``thickness``); with ``group``, on the facets of that facet group
      (each must be a boundary facet) or the boundary facets of the cells of that cell group,
      those all of whose nodes lie in ``plane``/``box`` when given;
    * ``{type: nodal_force, select: SELECTION, total: [Fx, Fy(, Fz)]}`` — a total force (N) split
      equally over the selected nodes;
    * ``{type: pressure, select: SELECTION, pressure: p, follow: true}`` — a pressure (Pa,
      positive pushing into the body: the force per area is ``-p n``, ``n`` the outward normal) on
      the boundary facets chosen as for ``traction`` (a facet group's facets are re-oriented
      outward from their cell), consistent nodal forces (:class:`msslib.terms.Pressure`; in 2D
      times ``thickness``).  ``follow: true`` (default): normal to the current surface, with its
      load stiffness in Newton's tangent (non-symmetric in general: no Cholesky or CG on it);
      ``follow: false``: dead, normal to the reference surface.  The FEM references take it too.
``solver``
    ``{type: static, load_steps: 1, tol: 1.0e-8, max_iter: 50}`` (default; load-stepped Newton
    of :func:`msslib.solvers.static_solve` for MSS, :func:`msslib.fem.solve_nonlinear` for the
    non-linear FEM; ``fem_linear`` ignores them; ``linear: true`` makes one solve with the
    stiffness at rest instead: the MSS model's Hessian, or linear FEM), or ``{type: dynamic, method:
    symplectic_euler | velocity_verlet | implicit_euler, dt: 1.0e-4, t_end: 0.1, damping: 0.0,
    save_every: 1, allow_unstable: false, load_curve: [[0, 0], [0.05, 1]]}`` (MSS only, stepped from
    rest by :class:`msslib.stepping.Simulator`; ``damping`` is a mass-proportional ``alpha``
    (1/s) or a Rayleigh pair ``[alpha, beta]``; ``load_curve``, optional, the load factor of every
    load and prescribed displacement against time, piecewise linear through the rows
    ``[t (s), factor]`` and held after the last: a ramp, a pulse, a cycle).  An
    explicit step above the stability limit of the model at rest is refused with both numbers
    unless ``allow_unstable: true``.
``output``
    ``{vtu: false, history: true}``: ``vtu: true`` also writes a VTU file next to the NetCDF result
    (same name, suffix ``.vtu``), a string names that file (relative to the result's directory);
    ``history: false`` drops the stored states of a dynamic run.
``checks``
    ``{inverted: warn, coincident_nodes: merge, max_memory_gb: null}``: ``inverted: error`` turns
    inverted or collapsed cells in the final (or a saved) state from a warning recorded in the
    result into an error; ``coincident_nodes: error`` refuses a mesh with coincident nodes instead
    of merging them (with a message naming them); ``max_memory_gb`` caps the memory a run may plan
    to use (default: the memory available on the machine).

Result
------
:func:`run_scene` returns :func:`msslib.results.netcdf.make_dataset`'s dataset (CF-1.11 and UGRID-1.0, see
:mod:`msslib.results.netcdf`): rest positions, final displacement, reactions, fixed mask, the materials as
variables (``material_E``, ``material_nu``, ``material_density``, ``material_name`` when they are
keyed by group), ``thickness`` (2D), springs with constants and rest lengths (MSS), the history
(time, displacement, velocity, kinetic energy) of dynamic runs, the cell check of
:mod:`msslib.mesh.quality`, solver statistics (``solver_*``), wall time, the scene text, the model name,
plus the attributes ``scene_name`` and ``scene_description``.
"""

from __future__ import annotations

import time  # noqa: F401 - tests patch msslib.scene.time.perf_counter

from msslib.scene.prepare import Setup, prepare
from msslib.scene.progress import TextProgress
from msslib.scene.run import run_scene
from msslib.scene.schema import (
    CHECK_CHOICES,
    FEM_MODELS,
    GENERATORS,
    LOAD_TYPES,
    MAX_LOAD_STEPS,
    MAX_NEWTON_ITERATIONS,
    MAX_TIME_STEPS,
    METHODS,
    MODELS,
    MSS_MODELS,
    SOLVER_TYPES,
    Material,
    Scene,
    load_scene,
)
from msslib.scene.validate import AXES

__all__ = [
    "AXES",
    "CHECK_CHOICES",
    "LOAD_TYPES",
    "MAX_LOAD_STEPS",
    "MAX_NEWTON_ITERATIONS",
    "MAX_TIME_STEPS",
    "METHODS",
    "SOLVER_TYPES",
    "GENERATORS",
    "MSS_MODELS",
    "FEM_MODELS",
    "MODELS",
    "Material",
    "Scene",
    "Setup",
    "TextProgress",
    "load_scene",
    "prepare",
    "run_scene",
]
