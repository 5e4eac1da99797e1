"""The cell types of msslib, one module per type, found by scanning this package.

Each cell module (``triangle``, ``quad``, ``tetra``, ``hexahedron``, ``wedge``) declares a
module-level ``CELL``, a :class:`CellType` that says all the rest of msslib needs to know of the
type: its dimension and reference nodes (meshio's/VTK's node order), its edges, its faces (each
face with its own number of nodes: a wedge has two triangles and three quads), outward oriented
for a positively oriented cell, how to flip a cell, its signed measure, the shape-function
gradients and the sample points of the quality check, its uniform refinement, its scikit-fem
elements (linear, and quadratic where scikit-fem has one) with their quadrature, and its VTK,
meshio and UGRID names.  :func:`registry` imports every module of the package and collects the
types, ordered by the modules' ``RANK`` then by name: adding a cell type is adding a module.
:mod:`msslib.mesh` (``CELL_TYPES``, topology, geometry, refinement, quality, files),
:mod:`msslib.fem` and the result writer read the registry.

The facets of a cell are its faces (3D) or its edges (2D).  A facet's type follows from its
number of nodes and the dimension: ``line`` in 2D, ``triangle`` (3 nodes) or ``quad`` (4 nodes)
in 3D; a facet type that is also a cell type (triangle, quad) is refined by that type's rule.
"""

from __future__ import annotations

import importlib
import itertools
import pkgutil
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cache, lru_cache
from types import ModuleType

import numpy as np

__all__ = ["CellType", "FemElement", "Refinement", "RegistryView", "LINE", "registry", "get", "names", "facet_type",
           "refinement_of", "generators", "GeneratorView", "lattice_refinement", "simplex_gradients", "tensor_gradients", "measure_by_quadrature"]


@dataclass(frozen=True)
class Refinement:
    """Uniform refinement of a cell into children of half its size.

    ``virtual``: the nodes of the refined cell, each a tuple of parent corners (local numbers) whose
    mean it is (a corner is a tuple of one); nodes of the same corner set are shared between cells.
    ``children``: ``(n_children, nodes)`` indices into ``virtual``, each child in the parent's
    local node order; or, with ``diagonals``, a tuple of such tables (variants), of which each cell
    takes the one whose diagonal (a pair of virtual nodes, row ``k`` of ``diagonals`` for variant
    ``k``) is the shortest.  ``reorient``: for simplices, the permutation applied to a child whose
    orientation differs from its parent's (None for cells whose children keep it by construction).
    """

    virtual: tuple
    children: object
    diagonals: np.ndarray | None = None
    reorient: tuple | None = None

    @property
    def n_children(self) -> int:
        table = self.children[0] if self.diagonals is not None else self.children
        return len(table)


@dataclass(frozen=True)
class FemElement:
    """A scikit-fem element of a cell type: ``mesh`` and ``element`` name scikit-fem classes,
    ``vtk_to_skfem`` permutes a VTK-ordered cell into scikit-fem's local order (None: the same
    order), ``intorder`` is the quadrature order scikit-fem chooses a rule by, ``rule`` an explicit
    rule ``(points (dim, q), weights (q,))`` on scikit-fem's reference cell that replaces it (for
    a cell type whose scikit-fem rule is wrong or missing), ``title`` says what it is in words."""

    mesh: str
    element: str
    title: str
    intorder: int | None = None
    rule: tuple | None = None
    vtk_to_skfem: tuple | None = None
    reduced_intorder: int | None = None


@dataclass(frozen=True)
class CellType:
    """Everything msslib knows of one cell type (see the module docstring).

    ``measure(x)``: signed area or volume of cells ``x`` ``(m, nodes, dim)``, positive for the
    conventional orientation.  ``gradients(points)``: the shape-function gradients with respect to
    the reference coordinates at reference ``points`` ``(p, dim)``, shape ``(p, nodes, dim)``.
    ``sample_points``: where the relative Jacobian of :mod:`msslib.mesh.quality` is sampled (enough
    points to bound ``det J`` of the type from below).  ``face_diagonals``: node pairs across the
    quadrilateral faces (of the cell itself for a 2D quad); ``inner_diagonals``: pairs across the
    cell (both None where there are none).  ``vtk_id``: the VTK cell type number; ``meshio``: the
    name meshio gives it; ``volume_shape``: the UGRID volume shape of a 3D type; ``sofa``: the
    list of SOFA's ``MeshTopology`` that holds cells of the type (None: the SOFA export lists none).
    ``example``: a small mesh of the type for tests and examples, ``(generator, arguments)``: a
    generator of :mod:`msslib.mesh` (its name) or a function of the cell module returning a
    :class:`~msslib.mesh.Mesh`, and its keyword arguments (lengths in metres, as floats, about 1
    m; the registry-wide tests build it, scaled where they need another size).
    ``generators``: further mesh generators of the type, each a name in :mod:`msslib.mesh` or a
    function of the cell module; with the example's generator they are :attr:`mesh_generators`,
    which a scene may name (``geometry: {generator: ..., args: ...}``).
    """

    name: str
    dim: int
    plural: str
    reference: np.ndarray
    edges: np.ndarray
    faces: tuple
    flip: tuple
    measure: Callable
    gradients: Callable
    sample_points: np.ndarray
    refinement: Refinement
    linear: FemElement
    quadratic: FemElement | None = None
    vtk_id: int = 0
    meshio: str = ""
    volume_shape: str | None = None
    simplex: bool = False
    face_diagonals: np.ndarray | None = None
    inner_diagonals: np.ndarray | None = None
    description: str = field(default="")
    example: tuple = ()
    sofa: str | None = None
    generators: tuple = ()

    def __post_init__(self):
        reference = np.asarray(self.reference, dtype=float)
        object.__setattr__(self, "reference", reference)
        object.__setattr__(self, "edges", np.asarray(self.edges, dtype=np.int64).reshape(-1, 2))
        object.__setattr__(self, "faces", tuple(tuple(int(a) for a in f) for f in self.faces))
        object.__setattr__(self, "sample_points", np.asarray(self.sample_points, dtype=float))
        for name in ("face_diagonals", "inner_diagonals"):
            if getattr(self, name) is not None:
                object.__setattr__(self, name, np.asarray(getattr(self, name), dtype=np.int64).reshape(-1, 2))
        if reference.shape[1] != self.dim:
            raise ValueError(f"cell type {self.name!r}: reference nodes of dimension {reference.shape[1]}, "
                             f"expected {self.dim}")
        if sorted(self.flip) != list(range(self.nodes)):
            raise ValueError(f"cell type {self.name!r}: flip {self.flip} is no permutation of its "
                             f"{self.nodes} nodes")

    @property
    def nodes(self) -> int:
        return len(self.reference)

    @property
    def facet_types(self) -> tuple[str, ...]:
        """The type of each face, in face order."""
        return tuple(facet_type(len(f), self.dim) for f in self.faces)

    def facets(self, kind: str | None = None) -> np.ndarray:
        """The faces of type ``kind`` (all faces when the type has one facet type and ``kind`` is
        None) as a ``(faces, nodes per facet)`` array of local node numbers, in face order."""
        kinds = self.facet_types
        if kind is None:
            if len(set(kinds)) != 1:
                raise ValueError(f"{self.name} cells have facets of several types ({', '.join(sorted(set(kinds)))})"
                                 f"; name one")
            kind = kinds[0]
        rows = [f for f, k in zip(self.faces, kinds) if k == kind]
        return np.array(rows, dtype=np.int64).reshape(len(rows), -1)

    def facets_by_type(self) -> dict[str, np.ndarray]:
        """Facet type -> :meth:`facets` of that type, in the order of the first face of each."""
        return {k: self.facets(k) for k in dict.fromkeys(self.facet_types)}

    @property
    def mesh_generators(self) -> dict[str, Callable]:
        """Generator name -> function of the mesh generators of the type: the example's generator
        and :attr:`generators`, a name resolved in :mod:`msslib.mesh`, a function named by its
        ``__name__``."""
        out = {}
        for g in (*self.example[:1], *self.generators):
            if callable(g):
                out[g.__name__] = g
            else:
                out[str(g)] = getattr(importlib.import_module("msslib.mesh"), str(g))
        return out

    @property
    def single_facet_type(self) -> str | None:
        """The type of every facet, or None for a cell with facets of several types."""
        kinds = set(self.facet_types)
        return kinds.pop() if len(kinds) == 1 else None


# --------------------------------------------------------------------------------------------
# helpers of the cell modules
# --------------------------------------------------------------------------------------------

_FACET_OF = {(2, 2): "line", (3, 3): "triangle", (3, 4): "quad"}


def facet_type(nodes: int, dim: int) -> str:
    """The type of a facet of ``nodes`` nodes of a ``dim``-dimensional cell."""
    try:
        return _FACET_OF[(dim, nodes)]
    except KeyError:
        raise ValueError(f"no facet type of {nodes} nodes in {dim}D; allowed: 2 nodes in 2D, 3 or 4 in 3D") from None


def simplex_gradients(dim: int) -> Callable:
    """The (constant) gradients of the linear shape functions of the unit ``dim``-simplex,
    ``N = (1 - sum xi, xi_1, ..., xi_dim)``."""
    grad = np.vstack([-np.ones((1, dim)), np.eye(dim)])

    def gradients(points):
        return np.broadcast_to(grad, (len(points), dim + 1, dim)).copy()

    return gradients


def tensor_gradients(corners) -> Callable:
    """The gradients of the multilinear shape functions ``N_a = prod_d (1 + xi_d s_ad) / 2^dim`` of
    the cell ``[-1, 1]^dim`` with corners ``s`` (node order)."""
    nodes = np.asarray(corners, dtype=float)
    dim = nodes.shape[1]

    def gradients(points):
        points = np.asarray(points, dtype=float)
        f = 1.0 + points[:, None, :] * nodes[None, :, :]  # (points, nodes, dim)
        grad = np.empty((len(points), len(nodes), dim))
        for d in range(dim):
            others = np.prod(np.delete(f, d, axis=2), axis=2)
            grad[..., d] = nodes[:, d] * others
        return grad / 2.0**dim

    return gradients


def measure_by_quadrature(gradients: Callable, points, weights) -> Callable:
    """A signed measure ``x (m, nodes, dim) -> (m,)``: ``det J`` integrated with the rule
    ``points``, ``weights`` on the reference cell (exact where ``det J`` is a polynomial the rule
    integrates exactly)."""
    grad = gradients(np.asarray(points, dtype=float))  # (q, nodes, dim)
    weights = np.asarray(weights, dtype=float)

    def measure(x):
        jac = np.einsum("cai,gad->cgid", x, grad)  # (cells, q, dim, dim)
        return np.linalg.det(jac) @ weights

    return measure


def lattice_refinement(corners01) -> Refinement:
    """The refinement of a tensor-product cell with corners ``corners01`` (in ``{0, 1}^dim``, node
    order): its nodes are the points of the 3^dim lattice of half steps (each the mean of the parent
    corners around it), a child's corners are lattice points in the parent's local corner order."""
    corners01 = np.rint(np.asarray(corners01, dtype=float)).astype(np.int64)
    d = corners01.shape[1]
    index = {tuple(c): i for i, c in enumerate(corners01.tolist())}
    virtual, where = [], {}
    for p in itertools.product(range(3), repeat=d):
        choices = [(0,) if c == 0 else (1,) if c == 2 else (0, 1) for c in p]
        virtual.append(tuple(sorted(index[q] for q in itertools.product(*choices))))
        where[p] = len(virtual) - 1
    children = [[where[tuple(int(a + b) for a, b in zip(child, o))] for o in corners01.tolist()]
                for child in itertools.product(range(2), repeat=d)]
    return Refinement(tuple(virtual), np.array(children))


#: the refinement of a line (the facets of 2D cells): its midpoint
LINE = Refinement(((0,), (1,), (0, 1)), np.array([[0, 2], [2, 1]]))


# --------------------------------------------------------------------------------------------
# the registry
# --------------------------------------------------------------------------------------------


@cache
def modules() -> tuple[ModuleType, ...]:
    """The cell modules of this package (those declaring ``CELL``), ordered by their ``RANK``, then
    by name."""
    found = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_") or info.ispkg:
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        if hasattr(module, "CELL"):
            found.append(module)
    return tuple(sorted(found, key=lambda m: (getattr(m, "RANK", 100), m.__name__)))


@cache
def _registry() -> tuple[tuple[str, CellType], ...]:
    out: dict[str, CellType] = {}
    for module in modules():
        cell = module.CELL
        if not isinstance(cell, CellType):
            raise TypeError(f"{module.__name__}.CELL is {cell!r}, not a CellType")
        if cell.name in out:
            raise ValueError(f"cell type {cell.name!r} declared twice")
        out[cell.name] = cell
    return tuple(out.items())


def clear_cache() -> None:
    """Forget the modules found (after a module is added to or removed from the package path)."""
    modules.cache_clear()
    _registry.cache_clear()


def registry() -> dict[str, CellType]:
    """Cell type name -> :class:`CellType`, every cell type of the package."""
    return dict(_registry())


def names() -> tuple[str, ...]:
    return tuple(name for name, _ in _registry())


def get(name: str) -> CellType:
    """The :class:`CellType` named ``name``; ValueError naming the known ones."""
    for key, cell in _registry():
        if key == name:
            return cell
    raise ValueError(f"unknown cell_type {name!r}; expected one of {sorted(names())}")


class RegistryView(Mapping):
    """A read-only mapping over the cell registry (:mod:`msslib.mesh.cells`), read at each access,
    so a cell type added to the registry is seen everywhere: ``name -> value(cell type)``."""

    def __init__(self, value, doc: str, only=None, extra=None):
        self._value, self._only, self.__doc__, self._extra = value, only, doc, dict(extra or {})

    def _names(self):
        return [n for n, c in _registry() if self._only is None or self._only(c)] + list(self._extra)

    def __getitem__(self, name):
        for n, c in _registry():
            if n == name and (self._only is None or self._only(c)):
                return self._value(c)
        if name in self._extra:
            return self._extra[name]
        raise KeyError(name)

    def __iter__(self):
        return iter(self._names())

    def __len__(self):
        return len(self._names())

    def __repr__(self):
        return repr(dict(self))


def generators() -> dict[str, tuple[Callable, int]]:
    """Mesh generator name -> ``(function, dimension)`` of the generators declared by the cell
    types (:attr:`CellType.mesh_generators`), read at each call."""
    out = {}
    for _, cell in _registry():
        for name, function in cell.mesh_generators.items():
            out.setdefault(name, (function, cell.dim))
    return out


class GeneratorView(Mapping):
    """Generator name -> dimension: the generators of ``fixed`` (a name -> dimension mapping of
    :mod:`msslib.mesh`'s generators not tied to one cell module) and those the cell types declare
    (:func:`generators`), read at each access, so a new cell type's generator is seen with no edit."""

    def __init__(self, fixed: Mapping, doc: str = ""):
        self._fixed, self.__doc__ = dict(fixed), doc

    def _table(self) -> dict[str, int]:
        return {**self._fixed, **{name: dim for name, (_, dim) in generators().items() if name not in self._fixed}}

    def __getitem__(self, name):
        return self._table()[name]

    def __iter__(self):
        return iter(self._table())

    def __len__(self):
        return len(self._table())

    def __repr__(self):
        return repr(self._table())

    def function(self, name: str) -> Callable:
        """The generator ``name``: a cell type's, or else the function of :mod:`msslib.mesh`."""
        declared = generators()
        if name in declared:
            return declared[name][0]
        return getattr(importlib.import_module("msslib.mesh"), name)


def refinement_of(kind: str) -> Refinement:
    """The refinement rule of a cell or facet type (``line`` included)."""
    return LINE if kind == "line" else get(kind).refinement
