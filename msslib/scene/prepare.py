"""From a scene to what a solver needs: :func:`prepare` builds the mesh, boundary conditions, loads
and, for a mass-spring model, the :class:`msslib.system.Model` (its force terms built by the model's
spec in :mod:`msslib.models`)."""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from msslib import mesh as _mesh
from msslib import models as _models
from msslib.scene.schema import Scene
from msslib.mesh.selection import loaded_facets, loaded_facets_by_type, select_nodes
from msslib.scene.selection import _build_mesh, _check_dim
from msslib.scene.validate import AXES, _fail


@dataclass
class Setup:
    """What :func:`prepare` builds from a scene: mesh, boundary conditions, loads and model.

    ``fixed`` (n, dim) bool and ``prescribed`` (n, dim) m; ``surface_forces`` (n, dim) N, the
    traction and nodal-force loads; ``gravity`` (dim,) m/s^2 or None; ``cell_density`` (n_cells,)
    (NaN where not given); ``masses`` (n,) kg lumped node masses (None without densities);
    ``model`` the :class:`msslib.system.Model` of an MSS scene (None for FEM); ``pressures`` one
    ``(facets, pressure, follow)`` per pressure load: facets ``(k, nodes per facet)`` outward
    oriented, the pressure (Pa) at load factor 1, positive into the body, and whether it follows
    the deforming surface.
    """

    scene: Scene
    mesh: _mesh.Mesh
    fixed: np.ndarray
    prescribed: np.ndarray
    surface_forces: np.ndarray
    gravity: np.ndarray | None
    cell_density: np.ndarray
    masses: np.ndarray | None
    model: Any = None
    pressures: tuple = ()

    @property
    def thickness(self) -> float:
        return 1.0 if self.mesh.dim == 3 else float(self.scene.thickness or 1.0)


def _check_held(scene: Scene, mesh, fixed, terms=()) -> None:
    """Before a static solve: every part held against its rigid-body modes by its fixed dofs and by
    the nodes a force term ties to fixed points (:meth:`msslib.terms.Term.held_nodes`)."""
    if scene.is_dynamic:
        return
    held = np.array(fixed, dtype=bool)
    for t in terms:
        held[np.asarray(t.held_nodes(), dtype=np.int64)] = True
    loose = _mesh.loose_parts(mesh, held)
    if loose:
        n_modes = 3 if mesh.dim == 2 else 6
        more = f" (and {len(loose) - 1} more loose part(s))" if len(loose) > 1 else ""
        fix = (f"fix at least {n_modes} dofs of every part that stop its {n_modes} rigid-body modes"
               if loose[0].floating else "fix dofs that stop every rigid-body mode of every part")
        _fail("scene.boundary", f"{loose[0].describe(mesh)}{more}; a static solve needs it held: {fix}, "
              f"or use a dynamic solver (solver: {{type: dynamic, ...}})")


def prepare(scene: Scene) -> Setup:
    """Build the mesh, boundary conditions, loads and (for MSS) the model of a scene.

    Does not solve; :func:`run_scene` calls it, the ``validate`` command too.  Errors that need
    the mesh (a selection matching no node, a vector of the wrong length, a model whose cell type
    does not fit the mesh) are ValueErrors naming the key path.

    Mesh hygiene: coincident nodes are merged with a warning or refused
    (``checks.coincident_nodes``, :func:`msslib.mesh.resolve_coincident_nodes`), for generated
    meshes too; a material no cell uses is an error; before a static solve, a part of the mesh
    whose fixed dofs leave a rigid-body mode free (floating, or free to slide or turn:
    :func:`msslib.mesh.loose_parts`; nodes a force term ties to fixed points count as held) is an
    error naming the part and the mode (dynamic runs may move freely).
    """
    policy = scene.checks.get("coincident_nodes", "merge")
    mesh = _mesh.resolve_coincident_nodes(_build_mesh(scene), policy, source="scene.geometry",
                                          hint=" (checks: {coincident_nodes: merge} merges them)")
    used = np.bincount(mesh.material, minlength=len(scene.materials))
    for i in range(len(scene.materials)):
        if used[i] == 0:
            in_use = ", ".join(str(j) for j in np.flatnonzero(used)) or "none"
            _fail(f"scene.materials[{i}]", f"no cell uses material {i} (cells use materials {in_use}); allowed: "
                  f"materials some cell uses (assigned by scene.regions or the mesh file's cell data 'material')")
    n, dim = mesh.n_nodes, mesh.dim
    size = float(np.linalg.norm(np.ptp(mesh.points, axis=0))) if n else 1.0
    default_tol = max(1e-8 * size, 1e-15)

    fixed = np.zeros((n, dim), dtype=bool)
    prescribed = np.zeros((n, dim))
    owner = np.full((n, dim), -1)
    for i, b in enumerate(scene.boundary):
        p = f"scene.boundary[{i}]"
        nodes = select_nodes(f"{p}.select", mesh, b["select"], default_tol)
        axes = list(range(dim)) if b["fix"] is None else [AXES.index(a) for a in b["fix"]]
        for a in axes:
            if a >= dim:
                _fail(f"{p}.fix", f"axis {AXES[a]!r} does not exist on a {dim}D mesh")
        disp = np.zeros(dim)
        if b["displacement"] is not None:
            if len(b["displacement"]) != dim:
                _fail(f"{p}.displacement", f"expected {dim} values on a {dim}D mesh, got {b['displacement']!r}")
            disp = np.array([0.0 if v is None else v for v in b["displacement"]])
        for a in axes:
            clash = (owner[nodes, a] >= 0) & (prescribed[nodes, a] != disp[a])
            if clash.any():
                j = int(owner[nodes, a][clash][0])
                _fail(f"{p}.displacement", f"node {int(nodes[clash][0])} axis {AXES[a]} is already fixed by "
                      f"scene.boundary[{j}] with displacement {float(prescribed[nodes[clash][0], a]):g}, here {float(disp[a]):g}")
            fixed[nodes, a] = True
            prescribed[nodes, a] = disp[a]
            owner[nodes, a] = i
    thickness = 1.0 if dim == 3 else float(scene.thickness or 1.0)
    dens = np.array([np.nan if m.density is None else m.density for m in scene.materials])
    cell_density = dens[mesh.material]
    masses = None
    if mesh.n_cells and np.all(np.isfinite(cell_density)):
        masses = _mesh.lumped_masses(mesh, cell_density, thickness) if dim == 2 else _mesh.lumped_masses(mesh, cell_density)

    surface = np.zeros((n, dim))
    gravity = None
    facet_cache = {}
    pressures = []
    for i, load in enumerate(scene.loads):
        p = f"scene.loads[{i}]"
        if load["type"] == "gravity":
            g = _check_dim(f"{p}.g", load["g"], dim)
            gravity = g if gravity is None else gravity + g
        elif load["type"] == "nodal_force":
            total = _check_dim(f"{p}.total", load["total"], dim)
            nodes = select_nodes(f"{p}.select", mesh, load["select"], default_tol)
            surface[nodes] += total / len(nodes)
        elif load["type"] == "pressure":
            loaded = loaded_facets(f"{p}.select", mesh, load["select"], default_tol, facet_cache, "pressure")
            pressures.append((_outward(mesh, loaded, facet_cache), float(load["pressure"]), bool(load["follow"])))
        else:
            from msslib.terms import Traction

            traction = _check_dim(f"{p}.traction", load["traction"], dim)
            # per facet type (a wedge mesh's triangles and quads)
            for loaded in loaded_facets_by_type(f"{p}.select", mesh, load["select"], default_tol, facet_cache).values():
                surface += Traction(mesh, loaded, traction, thickness if dim == 2 else 1.0).nodal
    from msslib.hints import check_load_scale  # a load far above E (E in MPa, loads in Pa) is refused

    check_load_scale(mesh, scene.loads, [m.E for m in scene.materials], cell_density, thickness, fixed.any())

    setup = Setup(scene=scene, mesh=mesh, fixed=fixed, prescribed=prescribed, surface_forces=surface,
                  gravity=gravity, cell_density=cell_density, masses=masses, pressures=tuple(pressures))
    if scene.is_fem:
        _check_held(scene, mesh, fixed)
        try:
            _mesh.check_cells(mesh)
        except ValueError as exc:
            _fail("scene.geometry", str(exc))
    else:
        setup.model = _build_model(setup)
        _check_held(scene, mesh, fixed, setup.model.terms)
    return setup


def _outward(mesh, facets, cache) -> np.ndarray:
    """``facets`` turned outward (:func:`msslib.terms.pressure.outward_facets`), the boundary cached."""
    from msslib.terms.pressure import outward_facets

    if "boundary" not in cache:
        cache["boundary"] = _mesh.boundary_facets(mesh, return_cells=True)
    return outward_facets(mesh, facets, cache["boundary"][0])


# --------------------------------------------------------------------------------------------
# MSS model: the terms the model's spec builds, plus the loads
# --------------------------------------------------------------------------------------------


def _build_model(setup: Setup):
    from msslib.system import Model
    from msslib.terms import Gravity, NodalForces

    scene, mesh = setup.scene, setup.mesh
    name, opts = scene.model, scene.model_options
    spec = _models.get(name)
    if mesh.cell_type not in spec.cells:
        _fail("scene.model", f"{name} needs {spec.cell_type} cells, the mesh has {mesh.cell_type} cells")
    from msslib.terms import Pressure

    # the pressure terms (scaled by the load factor), one per load, named by the load's index
    at = [i for i, load in enumerate(scene.loads) if load["type"] == "pressure"]
    pressures = [Pressure(mesh, facets, p, follow=follow, thickness=setup.thickness, name=f"pressure_{i}")
                 for i, (facets, p, follow) in zip(at, setup.pressures)]
    # the surface loads a model's build reads (Baudet's correction): the pressures' forces at rest
    surface = setup.surface_forces + sum((t.nodal for t in pressures), np.zeros_like(setup.surface_forces))
    ctx = _models.BuildContext(mesh=mesh, materials=[(m.E, m.nu) for m in scene.materials], options=opts,
                               thickness=setup.thickness, surface_forces=surface)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            built = spec.build(ctx)
    except ValueError as exc:
        _fail("scene.model", f"{name}: {exc}")
    terms = [t for term in spec.terms if term in opts["terms"] for t in built.get(term, ())]
    if np.any(setup.surface_forces != 0):
        terms.append(NodalForces(setup.surface_forces))
    if setup.gravity is not None:
        terms.append(Gravity(setup.masses, setup.gravity))
    terms += pressures
    damping = scene.solver.get("damping", 0.0) if scene.is_dynamic else 0.0
    return Model(mesh, terms, fixed=setup.fixed, prescribed=setup.prescribed, masses=setup.masses, damping=damping)
