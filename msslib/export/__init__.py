"""Export a scene's complete mass-spring system without solving it.

:func:`build` reads a scene (:mod:`msslib.scene`), builds its mesh, boundary conditions, loads and
model exactly as ``run`` would, and collects everything that defines the model in an
:class:`MssExport`: the springs (nodes, stiffness, rest length), the volume terms and Baudet's
correction with their constants, the node masses and rest positions, the fixed dofs and prescribed
displacements, the loads and gravity. The writers turn it into

``csv``
    One file per table, a header row with the units (``name [unit]``): ``nodes`` (rest position,
    mass), ``springs``, ``fixed`` (fixed axes and prescribed displacements), ``loads`` (surface
    loads at load factor 1), ``gravity``, and when the model has them ``tet_volume`` (Lloyd),
    ``hex_volume`` (Golec), ``baudet_correction`` (factor and face forces per cell) and
    ``baudet_correction_forces`` (the nodal forces it adds at load factor 1),
    ``baudet_element_correction`` (Baudet's element reading: k_edge, k_diagonal, factor per cube),
    ``delingette_triangle`` (Delingette's six constants and rest squared lengths per triangle),
    ``pressure_I`` and ``pressure_I_forces`` for the pressure load ``loads[I]`` of the scene (its
    outward facets, pressure and reading, and its nodal forces at rest at load factor 1): each
    term gives its own tables (:meth:`msslib.terms.Term.export_tables`). Node indices are
    0-based. Floats are written with ``repr`` (they read back bit for bit): :func:`msslib.export.text.read_csv`.
``json``
    One document with the same tables, a schema name and version (:data:`SCHEMA`,
    :data:`SCHEMA_VERSION`), the units, the energy of every term, the scene text: :func:`msslib.export.text.read_json`.
``vtu``
    The springs as line cells (cell data ``stiffness``, ``rest_length``) on the rest positions,
    with the point data ``mass``, ``fixed``, ``prescribed_displacement``, ``load`` (and
    ``baudet_correction``): for ParaView. The volume terms are in the tables only.
``mjcf``
    A MuJoCo model (:func:`msslib.export.simulators.mjcf_text`): one body per node with a slide joint per free axis (a node
    fixed on every axis has none: it is welded to the world; prescribed displacements move the
    body), its mass as a point mass, a site at the node; one spatial tendon per spring between the
    two sites with ``stiffness`` = k and ``springlength`` = the rest length, i.e. the force
    ``k (|x_j - x_i| - L)`` along the spring, exactly msslib's spring; gravity in ``<option>``;
    surface loads and Baudet's correction (constant at load factor 1) as ``<general>`` actuators
    with a constant affine bias on the joints; mass-proportional damping ``alpha`` as joint damping
    ``alpha m``. Volume terms cannot be expressed: an XML comment and the command say so. MuJoCo
    integrates tendon springs explicitly, so the model steps at most at half their stability limit
    ``2/omega_max`` (a dynamic scene's ``dt`` when below it, else half the limit, with a warning and
    a comment in the file: :func:`msslib.export.simulators.mjcf_time_step`).
``sofa``
    A SOFA scene (:func:`msslib.export.simulators.sofa_text`, ``.scn`` XML) made only of the components and attributes of
    :data:`SOFA_COMPONENTS`: MechanicalObject, DiagonalMass (``vertexMass``), SpringForceField
    (``spring``: ``i j ks kd L`` per spring), Fixed/PartialFixedProjectiveConstraint,
    ConstantForceField, StaticSolver (static scenes) or EulerImplicitSolver (dynamic scenes,
    Rayleigh damping), CGLinearSolver. Volume terms: not carried, said in a comment.
``c``
    The generated C headers (:mod:`derivations.codegen`): ``msslib_mss.h``, which includes one
    header per derivation module (``msslib_<module>.h``: its spring-constant formulas, or the energy,
    gradient and Hessian kernels), all copied beside the outputs (:func:`c_header_paths`).

One entry per format (name, files, writer, what it carries, help) is declared in a module of
:mod:`msslib.export.formats` and read into :func:`msslib.export.formats.table`: a new format is one
module there and its test. Which terms a format carries each term says itself
(:attr:`msslib.terms.Term.export_formats`; a format may also take terms by its own rule), and a
format that leaves one out says so in the file and on the command line, naming the model and the
term.

Pressure loads: a dead pressure is carried by every format (its constant nodal forces at load factor
1, labelled ``pressure_I``, beside the surface loads); a follower pressure, whose forces follow the
deforming surface, only by the CSV and JSON tables: the VTU, MuJoCo and SOFA files say in a comment
that they do not carry it, and the command line says so too for MuJoCo and SOFA.

Units are SI throughout. The writers are in :mod:`msslib.export.text` (CSV, JSON, VTU) and
:mod:`msslib.export.simulators` (MuJoCo, SOFA); :mod:`msslib.export.files` chooses formats and
file names, hands each output its writer and writes them all or none (a folder it creates appears
whole), with a manifest ``STEM.export-manifest.json`` of the files the export owns: the next export
to the same stem removes those it no longer writes, and nothing else; it never overwrites a file
that is not the export's.
"""

from msslib.export.formats import Format
from msslib.export.model import (
    C_HEADER_PATH,
    SCHEMA,
    SCHEMA_VERSION,
    Column,
    MssExport,
    Table,
    build,
    c_header_paths,
    from_setup,
    not_carried,
)

__all__ = ["Format", "SCHEMA", "SCHEMA_VERSION", "C_HEADER_PATH", "c_header_paths", "Column",
           "Table", "MssExport", "build", "from_setup", "not_carried"]
