"""The hard cases as scenes: :func:`scene` turns an entry of ``cases.yaml`` into the scene (the dict
form of :mod:`msslib.scene`) of one model on the case's mesh; :func:`msslib.scene.run_scene` runs it.

Meshes are the scene generators ``hex_grid`` and ``tet_grid`` (Kuhn's six tetrahedra per cube);
the inverted input hands the scene its mesh as an in-memory object with one cell mirrored."""

from __future__ import annotations

from pathlib import Path

import yaml

from msslib import mesh as M

CASES_FILE = Path(__file__).with_name("cases.yaml")
GRIDS = {"hexahedron": "hex_grid", "tetra": "tet_grid"}
FLIP = {"tetra": [0, 2, 1, 3], "hexahedron": [4, 5, 6, 7, 0, 1, 2, 3]}


def model_type(spec) -> str:
    """The registry name of a column's scene model (``{type: ...}`` or a bare name)."""
    model = spec["model"]
    return model if isinstance(model, str) else model["type"]


def reading(spec) -> str:
    """The reading of Baudet's correction force a column runs (its ``correction`` option, else the
    model's default), or "" for a model without that option."""
    from msslib import models as registry

    options = {o.name: o.default for o in registry.get(model_type(spec)).options}
    if "correction" not in options:
        return ""
    model = spec["model"]
    return str(model.get("correction", options["correction"]) if isinstance(model, dict) else options["correction"])


def registry_columns(columns: dict) -> dict:
    """``columns`` with a column for every mass-spring model of the registry on tetrahedra or
    hexahedra that no column runs, named after it and placed before the first FEM column."""
    from msslib import models as registry

    ran = {model_type(spec) for spec in columns.values()}
    extra = {name: {"cells": cells, "model": name} for cells in GRIDS
             for name in registry.for_cells(cells, "mss") if name not in ran}
    extra = {name: spec for name, spec in extra.items() if spec["cells"] == registry.get(name).cells[0]}
    fem = [name for name, spec in columns.items() if registry.get(model_type(spec)).kind == "fem"]
    at = list(columns).index(fem[0]) if fem else len(columns)
    items = list(columns.items())
    return dict(items[:at] + list(extra.items()) + items[at:])


def load_cases(path=CASES_FILE) -> dict:
    """``cases.yaml``: ``E``, ``density``, ``models`` (column -> cells and scene model; with
    :func:`registry_columns`), ``cases``."""
    data = yaml.safe_load(Path(path).read_text())
    kinds = {"sliding", "clamped", "inverted", "shape", "contrast", "explicit", "implicit", "unloaded", "beam"}
    for name, case in data["cases"].items():
        if case.get("kind") not in kinds:
            raise ValueError(f"{path}: case {name}: kind {case.get('kind')!r}; allowed: {', '.join(sorted(kinds))}")
    data["models"] = registry_columns(data["models"])
    return data


def pick(value, quick: bool):
    """A case value, or its ``quick``/``full`` variant."""
    if isinstance(value, dict) and set(value) == {"quick", "full"}:
        return value["quick" if quick else "full"]
    return value


def _grid(cells, lx, ly, lz, n):
    nx, ny, nz = (n, n, n) if isinstance(n, int) else n
    return {"generator": GRIDS[cells], "args": {"lx": lx, "ly": ly, "lz": lz, "nx": nx, "ny": ny, "nz": nz}}


def _plane(axis, value, fix, displacement=None):
    entry = {"select": {"plane": [axis, float(value)]}, "fix": fix}
    if displacement is not None:
        entry["displacement"] = displacement
    return entry


def _sliding(size, strain, top_free=False):
    """Symmetry planes x = y = z = 0 and the top moved down by ``strain * size`` (or left free)."""
    bc = [_plane("x", 0.0, ["x"]), _plane("y", 0.0, ["y"]), _plane("z", 0.0, ["z"])]
    if not top_free:
        bc.append(_plane("z", size, ["z"], [None, None, -strain * size]))
    return bc


def _static(steps=1):
    return {"type": "static", "load_steps": int(steps)}


def flipped_mesh(cells: str, size: float, n: int, cell: int) -> M.Mesh:
    """The cube mesh of ``cells`` with cell ``cell`` mirrored (its node order reversed in one axis)."""
    g = _grid(cells, size, size, size, n)
    base = getattr(M, g["generator"])(**g["args"])
    conn = base.cells.copy()
    conn[cell] = conn[cell][FLIP[cells]]
    return M.Mesh(base.points, conn, base.cell_type, base.material)


def scene(name: str, case: dict, cells: str, model, data: dict, quick: bool, **extra) -> dict:
    """The scene of model ``model`` (a scene ``model`` value) on the ``cells`` mesh of case ``name``.

    ``extra``: ``traction`` (force control of the sliding cube: the top traction, Pa), ``flip``
    (inverted input: False for the consistently numbered mesh), ``dt`` and
    ``t_end``, ``method``, ``allow_unstable`` (dynamic cases), ``static`` (a dynamic case's static
    solve)."""
    kind = case["kind"]
    E = float(case.get("E", data["E"]))
    nu = float(case.get("nu", 0.3))
    material = {"E": E, "nu": nu, "density": float(data["density"])}
    sc = {"name": f"{name}_{cells}", "model": model, "materials": [material], "loads": [], "solver": _static()}
    if kind in ("sliding", "clamped", "unloaded", "inverted"):
        size, n = float(case["size"]), pick(case["n"], quick)
        sc["geometry"] = _grid(cells, size, size, size, n)
    if kind == "sliding":
        traction = extra.get("traction")
        sc["boundary"] = _sliding(size, case["strain"], top_free=traction is not None)
        if traction is not None:
            sc["loads"] = [{"type": "traction", "select": {"plane": ["z", size]}, "traction": [0.0, 0.0, traction]}]
        sc["solver"] = _static(case["load_steps"])
    elif kind == "inverted":
        if extra.get("flip", True):  # else the same mesh numbered consistently: the reference
            sc["geometry"] = {"mesh": flipped_mesh(cells, size, n, int(case["cell"]))}
        sc["boundary"] = _sliding(size, case["strain"])
    elif kind == "clamped":
        sc["boundary"] = [_plane("z", 0.0, "all"),
                          _plane("z", size, "all", [0.0, 0.0, -case["strain"] * size])]
        sc["solver"] = _static(case["load_steps"])
    elif kind == "unloaded":
        sc["boundary"] = [_plane("x", 0.0, "all")]
    elif kind == "contrast":
        sc["geometry"] = _grid(cells, 0.4, 0.1, 0.1, pick(case["n"], quick))
        sc["materials"] = [material, dict(material, E=case["contrast"] * E)]
        sc["regions"] = [{"box": [[0.2, None, None], [None, None, None]], "material": 1}]
        sc["boundary"] = [_plane("x", 0.0, "all")]
        sc["loads"] = [{"type": "traction", "select": {"plane": ["x", 0.4]}, "traction": [case["strain"] * E, 0.0, 0.0]}]
        sc["solver"] = _static(2 if str(model).startswith("fem_") else 1)
    elif kind == "beam":
        length, width, nyz = case["length"], case["width"], pick(case["nyz"], quick)
        sc["geometry"] = _grid(cells, length, width, width, (round(length / width * nyz), nyz, nyz))
        sc["boundary"] = [_plane("x", 0.0, "all")]
        sc["loads"] = [{"type": "gravity", "g": [0.0, 0.0, -9.81]}]
    elif kind in ("explicit", "implicit"):
        length, width = case["length"], case["width"]
        sc["geometry"] = _grid(cells, length, width, width, case["n"])
        sc["boundary"] = [_plane("x", 0.0, "all")]
        sc["loads"] = [{"type": "gravity", "g": [0.0, 0.0, -9.81]}]
        if not extra.get("static"):
            sc["solver"] = {"type": "dynamic", "method": extra.get("method", "symplectic_euler"), "dt": extra["dt"],
                            "t_end": extra["t_end"], "damping": 0.0, "allow_unstable": extra.get("allow_unstable", False)}
            sc["output"] = {"history": False}
    else:
        raise ValueError(f"case {name}: kind {kind!r} is not a scene")
    return sc
