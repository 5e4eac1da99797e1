"""The exported model: :class:`MssExport` and its tables (:class:`Table`, :class:`Column`), built
from a scene by :func:`build` (or from a prepared setup by :func:`from_setup`); see
:mod:`msslib.export` for the formats."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = ["FORMATS", "SPRINGS_ONLY_FORMATS", "SCHEMA", "SCHEMA_VERSION", "C_HEADER_PATH", "c_header_paths", "Column",
           "Table", "MssExport", "build", "from_setup", "not_carried"]

#: every format, in the order outputs are written
FORMATS = ("csv", "json", "vtu", "mjcf", "sofa", "c")
#: formats that cannot express volume terms (they get the springs-only part, with a note)
SPRINGS_ONLY_FORMATS = ("mjcf", "sofa")
SCHEMA = "msslib-mss-export"
SCHEMA_VERSION = 1
#: the umbrella C header; every module's header is beside it (msslib/generated/c/)
C_HEADER_PATH = Path(__file__).resolve().parents[1] / "generated" / "c" / "msslib_mss.h"


def c_header_paths() -> list[Path]:
    """The C headers the ``c`` format copies: :data:`C_HEADER_PATH` and every header beside it
    (the ones it includes), umbrella first."""
    return [C_HEADER_PATH] + sorted(p for p in C_HEADER_PATH.parent.glob("*.h") if p != C_HEADER_PATH)

AXES = "xyz"
UNITS = {"length": "m", "mass": "kg", "force": "N", "stiffness": "N/m", "pressure": "Pa", "energy": "J",
         "volume": "m^3", "acceleration": "m/s^2", "time": "s", "damping_alpha": "1/s", "damping_beta": "s"}



# --------------------------------------------------------------------------------------------
# tables
# --------------------------------------------------------------------------------------------


@dataclass
class Column:
    """One column: ``name``, ``unit`` (None for indices and flags; ``"1"`` for dimensionless
    numbers), ``values`` (1D int or float array) and a description."""

    name: str
    unit: str | None
    values: np.ndarray
    description: str = ""

    @property
    def header(self) -> str:
        return self.name if self.unit is None else f"{self.name} [{self.unit}]"


@dataclass
class Table:
    name: str
    description: str
    columns: list[Column] = field(default_factory=list)

    def __getitem__(self, name: str) -> np.ndarray:
        for c in self.columns:
            if c.name == name:
                return c.values
        raise KeyError(f"table {self.name!r} has no column {name!r}; it has {', '.join(self.names)}")

    @property
    def names(self) -> list[str]:
        return [c.name for c in self.columns]

    @property
    def n_rows(self) -> int:
        return len(self.columns[0].values) if self.columns else 0


def _col(name, unit, values, description="", dtype=float):
    return Column(name, unit, np.ascontiguousarray(values, dtype=dtype), description)


def _cell_columns(conn, solid: str) -> list[Column]:
    """The columns that name each cell of a per-cell table: its index and its nodes ``conn`` (m, k),
    ``solid`` the kind of cell (``"tetrahedron"``, ``"hexahedron"``)."""
    return [_col("cell", None, np.arange(len(conn)), "cell index", int),
            *[_col(f"node_{a}", None, conn[:, a], f"node {a} of the {solid}", int) for a in range(conn.shape[1])]]


# --------------------------------------------------------------------------------------------
# the model
# --------------------------------------------------------------------------------------------


@dataclass
class MssExport:
    """Everything that defines a scene's mass-spring system (SI units, rest configuration).

    ``points`` (n, dim) rest positions (the mesh's); ``masses`` (n,); ``fixed`` (n, dim) bool and
    ``prescribed`` (n, dim) displacements at load factor 1; ``pairs`` (s, 2), ``stiffness`` (s,),
    ``rest_length`` (s,); ``tet_volume`` / ``hex_volume`` / ``correction`` the model's
    :class:`msslib.terms.TetVolume`, :class:`~msslib.terms.HexVolume`,
    :class:`~msslib.terms.BaudetCorrection` (or None); ``loads`` (n, dim) surface loads at load
    factor 1; ``gravity`` (dim,) or None; ``damping`` (alpha, beta) of a dynamic scene.
    """

    scene: object
    setup: object
    model: object
    masses: np.ndarray
    mass_source: str
    fixed: np.ndarray
    prescribed: np.ndarray
    pairs: np.ndarray
    stiffness: np.ndarray
    rest_length: np.ndarray
    tet_volume: object = None
    hex_volume: object = None
    correction: object = None
    loads: np.ndarray | None = None
    gravity: np.ndarray | None = None
    damping: tuple = (0.0, 0.0)
    _tables: dict | None = field(default=None, repr=False)
    _stability_limit: float | None = field(default=None, repr=False)

    @property
    def points(self) -> np.ndarray:
        """Rest positions (n, dim), the mesh's."""
        return self.setup.mesh.points

    @property
    def dim(self) -> int:
        return self.setup.mesh.dim

    @property
    def n_nodes(self) -> int:
        return self.setup.mesh.n_nodes

    @property
    def volume_terms(self) -> list[str]:
        """One phrase per volume term of the model (what MuJoCo and SOFA cannot carry)."""
        out = []
        if self.tet_volume is not None:
            out.append(f"Lloyd's tetrahedron volume energy k_v/(2 V0^2) (V - V0)^2 on {len(self.tet_volume)} "
                       f"cells (table tet_volume)")
        if self.hex_volume is not None:
            out.append(f"Golec's volume energy kappa/(2 V0) (V - V0)^2 on {len(self.hex_volume)} cells "
                       f"(table hex_volume)")
        return out

    def tables(self) -> dict[str, Table]:
        """The tables of the CSV and JSON outputs, by name (built once)."""
        if self._tables is None:
            self._tables = _tables(self)
        return self._tables


def build(scene) -> MssExport:
    """Load (a path, a dict or a :class:`msslib.scene.Scene`), prepare and collect a scene's MSS.

    ValueError for a FEM scene (there is no mass-spring system to export) and for anything
    :func:`msslib.scene.prepare` refuses."""
    from msslib.scene import load_scene, prepare

    scene = load_scene(scene)
    if scene.is_fem:
        raise ValueError(f"scene.model: {scene.model} is a FEM reference; export writes mass-spring models "
                         f"(the models of msslib.scene.MSS_MODELS)")
    return from_setup(prepare(scene))


def from_setup(setup) -> MssExport:
    """Collect the MSS of a prepared scene (:class:`msslib.scene.Setup`); the model's terms are read
    as they are (a term of an unknown kind is an error: nothing is left out silently)."""
    from msslib.terms import BaudetCorrection, Gravity, HexVolume, NodalForces, Springs, TetVolume

    model = setup.model
    if model is None:
        raise ValueError("the scene has no mass-spring model to export")
    springs, tet, hexv, corr = [], None, None, None
    for t in model.terms:
        if isinstance(t, Springs):
            springs.append(t)
        elif isinstance(t, TetVolume):
            tet = t if tet is None else _merge_error("TetVolume")
        elif isinstance(t, HexVolume):
            hexv = t if hexv is None else _merge_error("HexVolume")
        elif isinstance(t, BaudetCorrection):
            corr = t if corr is None else _merge_error("BaudetCorrection")
        elif isinstance(t, (NodalForces, Gravity)):
            pass  # the scene's surface loads and gravity, taken from the setup below
        else:
            raise ValueError(f"cannot export a term of type {type(t).__name__}")
    dim = model.dim
    pairs = np.concatenate([s.pairs for s in springs]) if springs else np.zeros((0, 2), dtype=np.int64)
    k = np.concatenate([s.k for s in springs]) if springs else np.zeros(0)
    rest = np.concatenate([s.rest_length for s in springs]) if springs else np.zeros(0)
    if setup.masses is not None:
        masses, source = np.asarray(setup.masses, dtype=float), "lumped from the scene's densities"
    else:
        masses, source = np.asarray(model.node_masses, dtype=float), \
            "lumped with unit density (the scene gives no density; only dynamics would use them)"
    scene = setup.scene
    damping = (0.0, 0.0)
    if scene.is_dynamic:
        d = scene.solver.get("damping", 0.0)
        damping = (float(d), 0.0) if np.ndim(d) == 0 else (float(d[0]), float(d[1]))
    gravity = None if setup.gravity is None else np.asarray(setup.gravity, dtype=float)
    return MssExport(scene=scene, setup=setup, model=model,
                     masses=masses, mass_source=source, fixed=np.asarray(setup.fixed, dtype=bool).reshape(-1, dim),
                     prescribed=np.asarray(setup.prescribed, dtype=float).reshape(-1, dim), pairs=pairs,
                     stiffness=k, rest_length=rest, tet_volume=tet, hex_volume=hexv, correction=corr,
                     loads=np.asarray(setup.surface_forces, dtype=float).reshape(-1, dim), gravity=gravity,
                     damping=damping)


def _merge_error(kind):
    raise ValueError(f"the model has two {kind} terms; export expects one")


def _tables(exp: MssExport) -> dict[str, Table]:
    from msslib.terms import _HEX_FACES

    dim, n = exp.dim, exp.n_nodes
    axes = AXES[:dim]
    nodes = np.arange(n)
    out = {}
    out["nodes"] = Table("nodes", f"node rest positions and masses ({exp.mass_source})", [
        _col("node", None, nodes, "node index (0-based)", int),
        *[_col(a, "m", exp.points[:, i], f"rest position, {a}") for i, a in enumerate(axes)],
        _col("mass", "kg", exp.masses, "node mass"),
    ])
    out["springs"] = Table("springs", "springs k/2 (|x_j - x_i| - L)^2 between node_i and node_j", [
        _col("spring", None, np.arange(len(exp.pairs)), "spring index", int),
        _col("node_i", None, exp.pairs[:, 0], "first node", int),
        _col("node_j", None, exp.pairs[:, 1], "second node", int),
        _col("stiffness", "N/m", exp.stiffness, "spring constant k, summed over the elements sharing the pair"),
        _col("rest_length", "m", exp.rest_length, "rest length L (differs from the node distance for "
                                                  "prestrained springs)"),
    ])
    held = np.flatnonzero(exp.fixed.any(axis=1))
    out["fixed"] = Table("fixed", "nodes with fixed axes (1 fixed, 0 free) and the displacements prescribed "
                                  "on the fixed axes at load factor 1 (0 on free axes)", [
        _col("node", None, held, "node index", int),
        *[_col(f"fixed_{a}", None, exp.fixed[held, i].astype(int), f"axis {a} fixed", int) for i, a in enumerate(axes)],
        *[_col(f"u_{a}", "m", exp.prescribed[held, i], f"prescribed displacement, {a}") for i, a in enumerate(axes)],
    ])
    loaded = np.flatnonzero(np.any(exp.loads != 0, axis=1))
    out["loads"] = Table("loads", "surface loads (tractions and nodal forces of the scene) on the nodes at load "
                                  "factor 1, dead loads (gravity is in table gravity)", [
        _col("node", None, loaded, "node index", int),
        *[_col(f"f_{a}", "N", exp.loads[loaded, i], f"force, {a}") for i, a in enumerate(axes)],
    ])
    g = np.zeros(dim) if exp.gravity is None else exp.gravity
    out["gravity"] = Table("gravity", "gravitational acceleration (each node carries its mass times it; zero: "
                                      "no gravity)", [_col(f"g_{a}", "m/s^2", [g[i]], f"gravity, {a}")
                                                      for i, a in enumerate(axes)])
    if exp.tet_volume is not None:
        t = exp.tet_volume
        out["tet_volume"] = Table("tet_volume", "Lloyd's tetrahedron volume energy k_v/(2 V0^2) (V - V0)^2, V the "
                                                "signed volume of (node_0, ..., node_3) (C: msslib_tet_signed_volume)", [
            *_cell_columns(t.conn, "tetrahedron"),
            _col("k_v", "J", t.k_v, "volume coefficient k_v (may be negative)"),
            _col("V0", "m^3", t.V0, "rest volume of the cell"),
        ])
    if exp.hex_volume is not None:
        h = exp.hex_volume
        out["hex_volume"] = Table("hex_volume", "Golec's volume energy kappa/(2 V0) (V - V0)^2, V the averaged-edge-"
                                                "vector volume of the hexahedron (node_0, ..., node_7) in VTK order "
                                                "(C: msslib_hex_averaged_volume)", [
            *_cell_columns(h.conn, "hexahedron"),
            _col("kappa", "Pa", h.kappa, "volume coefficient kappa (may be negative)"),
            _col("V0", "m^3", h.V0, "rest (averaged) volume of the cell"),
        ])
    if exp.correction is not None:
        c = exp.correction
        cells = exp.setup.mesh.cells
        faces = "; ".join(f"face {f}: local nodes {' '.join(map(str, nodes_))}" for f, nodes_ in enumerate(_HEX_FACES))
        out["baudet_correction"] = Table("baudet_correction", "Baudet's orthogonal correction per cube: factor c "
                                         "(F_perp = c F_i) and the elongation force of each face at load factor 1 "
                                         f"({faces}; msslib.terms.BaudetCorrection)", [
            *_cell_columns(cells, "hexahedron"),
            _col("factor", "1", c.factor, "correction factor c"),
            *[_col(f"face_force_{f}", "N", c.face_force[:, f], f"elongation force of face {f} (> 0 tension)")
              for f in range(6)],
        ])
        fc = c.nodal
        on = np.flatnonzero(np.any(fc != 0, axis=1))
        out["baudet_correction_forces"] = Table(
            "baudet_correction_forces", "nodal forces of Baudet's correction at load factor 1 (they scale with the "
                                        "load; constant in the reference configuration)", [
                _col("node", None, on, "node index", int),
                *[_col(f"f_{a}", "N", fc[on, i], f"force, {a}") for i, a in enumerate(axes)],
            ])
    return out


# --------------------------------------------------------------------------------------------
# shared by the writers
# --------------------------------------------------------------------------------------------

def not_carried(exp: MssExport, fmt: str) -> list[str]:
    """What of the model ``fmt`` leaves out (an empty list: all of it)."""
    out = []
    if fmt in SPRINGS_ONLY_FORMATS:
        out += exp.volume_terms
        if fmt == "mjcf" and exp.damping[1] != 0.0:
            out.append(f"the stiffness-proportional damping beta = {exp.damping[1]!r} s (only the mass-proportional "
                       f"alpha is carried, as joint damping)")
    elif fmt == "vtu" and (exp.volume_terms or exp.correction is not None):
        out += [v.split(" (table")[0] for v in exp.volume_terms]
        if exp.correction is not None:
            out.append("Baudet's per-cell correction factors (the nodal correction forces are carried)")
    return out


def _safe_name(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") or "scene"


def _version() -> str:
    from msslib import __version__

    return __version__


def _pad3(a):
    a = np.asarray(a)
    if a.ndim == 2 and a.shape[1] < 3:
        a = np.hstack([a, np.zeros((len(a), 3 - a.shape[1]), dtype=a.dtype)])
    return a
