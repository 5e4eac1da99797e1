"""Results follow CF-1.11 and UGRID-1.0 (schema ``msslib-result-2.0``, :mod:`msslib.results.netcdf`).

Two checkers from PyPI run on real results (static mass-spring systems in 2D and 3D, FEM references in
2D and 3D, a dynamic run with its history, and a quasi-static dataset with step history and a
material without density):

* the IOOS compliance checker, suite ``cf:1.11`` (with cf-units, whose wheels bring UDUNITS-2);
* ``ugrid-checks`` (the UGRID conformance rules Rxxx/Axxx), which covers 1D and 2D meshes only.

The findings these checkers report on every file, and why they are not errors of the files, are
listed in :data:`CF_ACCEPTED` and :data:`UGRID_ACCEPTED`; anything else fails the test. The UGRID
rules msslib implements, 3D volumes included (which no checker covers), are checked here too
(:func:`ugrid_problems`).
"""

import json
import re
import warnings
from pathlib import Path

import netCDF4
import numpy as np
import pytest
import xarray as xr
import yaml

compliance_runner = pytest.importorskip("compliance_checker.runner", reason="needs the test extra")
ugrid_check = pytest.importorskip("ugrid_checks.check", reason="needs the test extra")

from msslib.results import (  # noqa: E402
    CONVENTIONS, SCHEMA_VERSION, make_dataset, mesh_from_result, read_result, write_result,
)
from msslib.results.conventions import DOUBLE_FILL  # noqa: E402
from msslib.mesh import Mesh  # noqa: E402
from msslib.scene import run_scene  # noqa: E402

SCENES = Path(__file__).resolve().parents[1] / "experiments" / "scenes"

#: (pattern, reason): compliance-checker cf:1.11 messages that are not errors of our files
CF_ACCEPTED = [
    (r"^(mesh_topology|edge_node_connectivity|face_node_connectivity|volume_node_connectivity|volume_shape_type)"
     r" is not a valid cf_role value",
     "UGRID-1.0 cf_role values; the checker (§9.5) knows only the discrete-sampling-geometry roles "
     "(it leaves UGRID to other checkers: ioos/compliance-checker#1186)"),
    (r"^There may only be one variable containing the cf_role attribute",
     "same: every UGRID topology and connectivity variable carries a cf_role"),
    (r"^Coordinate variable 'time' should have standard_name='time'",
     "a name-based heuristic of the checker (§5.1): CF's standard name 'time' requires units "
     "'<unit> since <date>', and simulated time has no date, so 'time' has units 's' and no standard_name"),
]
#: ugrid-checks codes that are not errors of our files, with the reason
UGRID_ACCEPTED = {
    "A203": "node coordinates have no standard_name: CF has none for Cartesian coordinates of a body",
    "A104": "the spring network is a second topology on the nodes of the mesh (springs run along "
            "diagonals, so they are not the mesh's edges)",
    "A201": "same: node_x, node_y (, node_z) are the node coordinates of both topologies",
}
#: ugrid-checks failures caused by 3D volumes, which it does not support (UGRID-1.0 has them)
UGRID_VOLUME_FAILURES = [
    r"^\*\*\* FAIL R104 : Mesh variable \"mesh\" has topology_dimension=\"3\"",
    r"^\*\*\* FAIL R504 : Mesh data variable \"\w+\" has location=\"volume\"",
    r"^\*\*\* FAIL R509 : Mesh data variable \"\w+\" has dimensions \('cell',\), of which 0 are mesh dimensions",
    r"^\.\.\. WARN A905 : netcdf variable \"(cells|cell_shape)\" "
    r"has cf_role=\"(volume_node_connectivity|volume_shape_type)\"",
]
NODES_PER_SHAPE = {"tetrahedron": 4, "pyramid": 5, "wedge": 6, "hexahedron": 8}
#: variables without units: topologies, connectivities, flags and labels are found by their
#: attributes or type; these are the index variables
INDEX_VARIABLES = {"cell_material", "material"}


def _example(name: str, **changes) -> dict:
    return {**yaml.safe_load((SCENES / f"{name}.yaml").read_text()), **changes}


def _quasi_static_2d():
    """A quad mesh with two materials (the second without density), names, thickness and a step
    history: the optional parts of the schema that no example scene has."""
    mesh = Mesh(points=[[0, 0], [1, 0], [2, 0], [0, 1], [1, 1], [2, 1]], cells=[[0, 1, 4, 3], [1, 2, 5, 4]],
                cell_type="quad", material=[0, 1])
    u = np.zeros((6, 2))
    u[[1, 4], 0], u[[2, 5], 0] = 1e-3, 2e-3
    return make_dataset(
        mesh, u, model="fem_linear", E=[1e6, 2e6], nu=[0.3, 0.25], density=[1000.0, None],
        material_names=["soft", "stiff"], thickness=0.01, scene="two quads",
        history={"step": [0, 1, 2], "displacement": [0 * u, u / 2, u]}, fixed=[True, False, False, True, False, False],
        reaction=np.zeros((6, 2)), solver_stats={"iterations": [1, 1], "message": None, "converged": True},
        extra_vars={"strain_energy": (("cell",), np.array([0.1, 0.2]), {"units": "J", "long_name": "strain energy"})},
        extra_attrs={"note": "None"})


CASES = {
    "mss_static_2d": lambda: run_scene(_example("membrane_lloyd_stretch"), progress=False),
    "mss_static_tet": lambda: run_scene(_example("cylinder_tet_shear"), progress=False),
    "mss_static_hex": lambda: run_scene(_example("golec_compression"), progress=False),
    "fem_2d": lambda: run_scene(_example("membrane_fem_stretch"), progress=False),
    "fem_hex": lambda: run_scene(_example("baudet_beam_tension", model="fem_linear"), progress=False),
    "mss_dynamic_history": lambda: run_scene(_example("cantilever_gravity_dynamic"), progress=False),
    "quasi_static_2d": _quasi_static_2d,
}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    directory = tmp_path_factory.mktemp("cf")
    out = {}
    for name, make in CASES.items():
        out[name] = write_result(directory / f"{name}.nc", make())
    return out


# --------------------------------------------------------------------------------------------------
# the checkers


def cf_findings(path) -> tuple[list[str], dict]:
    """Messages of every failed cf:1.11 check (all priorities: errors, warnings, suggestions) and
    the checker's own exceptions. (Passed checks may carry informational messages; they are not
    findings.)"""
    suite = compliance_runner.CheckSuite()
    with warnings.catch_warnings():  # deprecation warnings of unrelated suites (ioos_sos) on loading
        warnings.simplefilter("ignore", DeprecationWarning)
        suite.load_all_available_checkers()
    results, exceptions = suite.run_all(suite.load_dataset(str(path)), ["cf:1.11"], skip_checks=[])["cf:1.11"]
    messages = []
    for r in results:
        score, out_of = r.value if isinstance(r.value, tuple) else (int(bool(r.value)), 1)
        if score < out_of:
            messages += [f"[{r.name}] {m}" for m in r.msgs] or [f"[{r.name}] failed without a message"]
    return messages, exceptions


def _accepted_cf(message: str) -> bool:
    text = message.split("] ", 1)[1]
    return any(re.search(pattern, text) for pattern, _ in CF_ACCEPTED)


def ugrid_check_messages(path) -> list[str]:
    checker = ugrid_check.check_dataset(str(path), print_summary=False)
    return [record.msg for record in checker.logger.report_statement_logrecords()]


def ugrid_problems(path) -> list[str]:
    """The UGRID-1.0 rules of the schema, 3D volumes included; an empty list if all hold."""
    problems = []
    with netCDF4.Dataset(path) as nc:
        conventions = nc.getncattr("Conventions").split()
        if "UGRID-1.0" not in conventions or "CF-1.11" not in conventions:
            problems.append(f"Conventions {conventions}")
        meshes = {n: v for n, v in nc.variables.items() if getattr(v, "cf_role", None) == "mesh_topology"}
        if "mesh" not in meshes:
            problems.append("no mesh topology variable 'mesh'")
        locations, node_coordinates = {}, set()
        for name, m in meshes.items():
            if m.dimensions:
                problems.append(f"{name}: a mesh topology variable has no dimensions, got {m.dimensions}")
            tdim = int(m.topology_dimension)
            coords = m.node_coordinates.split()
            node_coordinates.update(coords)
            if not all(c in nc.variables and nc[c].ndim == 1 for c in coords) \
                    or len({nc[c].dimensions for c in coords}) != 1:
                problems.append(f"{name}: node coordinates {coords} are not 1-D variables on one dimension")
                continue
            if any(nc[c].dtype.kind != "f" or nc[c].units != "m" for c in coords):
                problems.append(f"{name}: node coordinates must be floating point with units m")
            node_dim = nc[coords[0]].dimensions[0]
            n_nodes = len(nc.dimensions[node_dim])
            locs = {"node": node_dim}
            required = {1: "edge_node_connectivity", 2: "face_node_connectivity", 3: "volume_node_connectivity"}
            if tdim not in required:
                problems.append(f"{name}: topology_dimension {tdim}")
                continue
            if required[tdim] not in m.ncattrs():
                problems.append(f"{name}: topology_dimension {tdim} needs {required[tdim]}")
            for role in required.values():
                if role not in m.ncattrs():
                    continue
                location = role.split("_")[0]
                var = nc.variables.get(m.getncattr(role))
                if var is None:
                    problems.append(f"{name}:{role} names no variable")
                    continue
                element_dim = m.getncattr(f"{location}_dimension") if f"{location}_dimension" in m.ncattrs() \
                    else var.dimensions[0]
                if getattr(var, "cf_role", None) != role or var.ndim != 2 or var.dimensions[0] != element_dim:
                    problems.append(f"{var.name}: cf_role {role} and dimensions ({element_dim}, n) expected, got "
                                    f"{getattr(var, 'cf_role', None)} {var.dimensions}")
                    continue
                start = int(getattr(var, "start_index", 0))
                data = var[:]
                width = data.shape[1]
                if var.dtype.kind not in "iu" or start not in (0, 1) or np.ma.is_masked(data):
                    problems.append(f"{var.name}: integer indices, start_index 0 or 1, no missing indices expected")
                elif data.size and (data.min() < start or data.max() >= start + n_nodes):
                    problems.append(f"{var.name}: node indices outside [{start}, {start + n_nodes})")
                if not {"edge": width == 2, "face": width >= 3, "volume": 4 <= width <= 8}[location]:
                    problems.append(f"{var.name}: {width} nodes per {location}")
                locs[location] = element_dim
            if tdim == 3 and "volume" in locs:
                shape = nc.variables.get(getattr(m, "volume_shape_type", ""))
                if shape is None or getattr(shape, "cf_role", None) != "volume_shape_type" \
                        or shape.dimensions != (locs["volume"],):
                    problems.append(f"{name}: volume_shape_type must name a flag variable along {locs['volume']}")
                else:
                    meanings = shape.flag_meanings.split()
                    values = np.asarray(shape.flag_values)
                    if not set(meanings) <= set(NODES_PER_SHAPE) or len(meanings) != len(values):
                        problems.append(f"{shape.name}: flag_meanings {meanings}, flag_values {values}")
                    else:
                        width = nc[m.volume_node_connectivity].shape[1]
                        for v in np.unique(shape[:]):
                            if v not in values or NODES_PER_SHAPE[meanings[list(values).index(v)]] != width:
                                problems.append(f"{shape.name}: shape {v} does not have {width} nodes")
            locations[name] = locs
        element_dims = {d for locs in locations.values() for d in locs.values()}
        for vname, var in nc.variables.items():
            attrs = var.ncattrs()
            if "mesh" in attrs:
                locs = locations.get(var.mesh, {})
                on = [d for d in var.dimensions if d in set(locs.values())]
                if var.mesh not in locations or getattr(var, "location", None) not in locs \
                        or on != [locs[var.location]]:
                    problems.append(f"{vname}: mesh {var.mesh!r}, location {getattr(var, 'location', None)!r} do not "
                                    f"match its dimensions {var.dimensions}")
            elif "cf_role" not in attrs and vname not in node_coordinates and set(var.dimensions) & element_dims:
                problems.append(f"{vname} is defined on the mesh {var.dimensions} but has no mesh/location")
    return problems


# --------------------------------------------------------------------------------------------------
# tests


@pytest.mark.parametrize("case", list(CASES))
def test_cf_compliance_checker(results, case):
    messages, exceptions = cf_findings(results[case])
    assert exceptions == {}, f"the checker itself failed: {exceptions}"
    unexpected = [m for m in messages if not _accepted_cf(m)]
    assert unexpected == [], "\n".join(unexpected)
    # the accepted findings are only the UGRID variables' cf_role and the time heuristic
    roles = re.findall(r"have cf_role attributes: \[(.*)\]", "\n".join(messages))
    for listed in roles:
        names = {n.strip(" '") for n in listed.split(",")}
        assert names <= {"mesh", "cells", "cell_shape", "spring_network", "springs"}, names
    if any("'time'" in m for m in messages):
        assert case == "mss_dynamic_history"


@pytest.mark.parametrize("case", list(CASES))
def test_ugrid_rules(results, case):
    assert ugrid_problems(results[case]) == []


@pytest.mark.parametrize("case", list(CASES))
def test_ugrid_checks(results, case):
    messages = ugrid_check_messages(results[case])
    three_d = case in ("mss_static_tet", "mss_static_hex", "fem_hex", "mss_dynamic_history")
    unexpected = []
    for m in messages:
        code = re.search(r"\b([RA]\d{3}) :", m).group(1)
        if code in UGRID_ACCEPTED:
            continue
        if three_d and any(re.search(p, m) for p in UGRID_VOLUME_FAILURES):
            continue
        unexpected.append(m)
    assert unexpected == [], "\n".join(unexpected)
    if not three_d:  # ugrid-checks covers every part of a 2D file: no requirement fails
        assert not [m for m in messages if "FAIL" in m]


@pytest.mark.parametrize("case", list(CASES))
def test_attributes_and_units(results, case):
    """Units on every quantity; no 'None' attributes; list- or dict-like attribute text is JSON."""
    with netCDF4.Dataset(results[case]) as nc:
        assert nc.getncattr("Conventions") == CONVENTIONS
        assert nc.getncattr("msslib_schema") == SCHEMA_VERSION
        for key in ("E", "nu", "density", "thickness"):
            assert key not in nc.ncattrs(), key
        owners = [("global", {a: nc.getncattr(a) for a in nc.ncattrs()})]
        owners += [(n, {a: v.getncattr(a) for a in v.ncattrs()}) for n, v in nc.variables.items()]
        for owner, attrs in owners:
            for key, value in attrs.items():
                if isinstance(value, str):
                    assert value != "None", (owner, key)
                    if value[:1] in "[{":
                        json.loads(value)  # documented JSON, not a Python repr
        for name, var in nc.variables.items():
            attrs = var.ncattrs()
            assert "long_name" in attrs, name
            not_a_quantity = ("cf_role" in attrs or "flag_meanings" in attrs or var.dtype == str
                              or name in INDEX_VARIABLES)
            assert ("units" in attrs) != not_a_quantity, name
        units = {n: nc[n].units for n in ("material_E", "material_nu", "displacement", "rest_position")}
        assert units == {"material_E": "Pa", "material_nu": "1", "displacement": "m", "rest_position": "m"}
        if "spring_constant" in nc.variables:
            assert nc["spring_constant"].units == "N m-1"


@pytest.mark.parametrize("case", list(CASES))
def test_cells_are_ordered_as_ugrid_says(results, case):
    """Faces anticlockwise (2D), volumes in VTK's node order (3D): computed from the file alone."""
    with netCDF4.Dataset(results[case]) as nc:
        coords = nc["mesh"].node_coordinates.split()
        p = np.stack([nc[c][:] for c in coords], axis=1)
        c = nc[nc["mesh"].getncattr("face_node_connectivity" if len(coords) == 2 else "volume_node_connectivity")][:]
    x = p[c]
    if len(coords) == 2:  # shoelace
        x0, y0 = x[:, :, 0], x[:, :, 1]
        area = 0.5 * np.sum(x0 * np.roll(y0, -1, axis=1) - np.roll(x0, -1, axis=1) * y0, axis=1)
        assert (area > 0).all()
    elif c.shape[1] == 4:  # tetrahedron: nodes 0, 1, 2 anticlockwise seen from node 3
        assert (np.linalg.det(x[:, 1:] - x[:, :1]) > 0).all()
    else:  # hexahedron: bottom face 0-3 anticlockwise seen from the top face 4-7
        normal = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])
        up = x[:, 4:].mean(axis=1) - x[:, :4].mean(axis=1)
        assert (np.einsum("ij,ij->i", normal, up) > 0).all()


def test_materials_and_fill_values(results):
    ds = read_result(results["quasi_static_2d"])
    np.testing.assert_array_equal(ds["material"].values, [0, 1])
    np.testing.assert_array_equal(ds["material_E"].values, [1e6, 2e6])
    assert ds["material_density"].values[0] == 1000.0 and np.isnan(ds["material_density"].values[1])
    assert ds["material_name"].values.tolist() == ["soft", "stiff"]
    assert float(ds["thickness"]) == 0.01 and ds["thickness"].attrs["units"] == "m"
    # per-cell constants, the xarray way
    np.testing.assert_array_equal(ds["material_E"].sel(material=ds["cell_material"]).values, [1e6, 2e6])
    assert "note" not in ds.attrs and "solver_message" not in ds.attrs  # "None" and None drop attributes
    with netCDF4.Dataset(results["quasi_static_2d"]) as nc:
        var = nc["material_density"]
        assert var.getncattr("_FillValue") == DOUBLE_FILL
        var.set_auto_mask(False)
        assert var[:].tolist() == [1000.0, DOUBLE_FILL]
        assert "_FillValue" not in nc["displacement"].ncattrs()  # results are complete elsewhere
    # node coordinates and the history coordinate, as CF readers see them
    assert set(ds["displacement"].coords) >= {"node_x", "node_y", "axis_name"}
    assert ds["displacement_history"].dims == ("step", "node", "axis")


def test_dynamic_history_is_cf(results):
    ds = read_result(results["mss_dynamic_history"])
    assert ds["time"].attrs == {"units": "s", "long_name": "simulated time from the start of the run"}
    assert ds["time"].dtype == float and np.all(np.diff(ds["time"].values) > 0)
    assert ds["displacement_history"].attrs["location"] == "node"
    assert ds["velocity_history"].attrs["units"] == "m s-1"
    assert ds["cell_state"].attrs["location"] == "volume" and ds["cell_state"].attrs["mesh"] == "mesh"
    assert ds["spring_constant"].attrs["mesh"] == "spring_network"
    assert ds["spring_constant"].attrs["location"] == "edge"
    assert ds["potential_energy"].dims == ("time",) and ds["potential_energy"].attrs["units"] == "J"


def test_static_mss_energy_is_a_variable(results):
    ds = read_result(results["mss_static_tet"])
    assert "potential_energy" not in ds.attrs
    assert ds["potential_energy"].dims == () and ds["potential_energy"].attrs["units"] == "J"
    assert "thickness" not in ds  # 3D
    assert ds["mesh"].attrs["volume_shape_type"] == "cell_shape"


def test_legacy_results_are_still_read(tmp_path):
    """A ``msslib-result-1.0`` file (material constants as attributes, ``material(cell)``)."""
    points = np.array([[0, 0], [1, 0], [0, 1]], float)
    legacy = xr.Dataset(
        {"rest_position": (("node", "axis"), points, {"units": "m", "long_name": "rest"}),
         "displacement": (("node", "axis"), np.zeros((3, 2)), {"units": "m", "long_name": "u"}),
         "cells": (("cell", "cell_node"), np.array([[0, 1, 2]]), {"units": "1", "long_name": "c",
                                                                 "cell_type": "triangle"}),
         "material": (("cell",), np.array([0]), {"units": "1", "long_name": "m"})},
        coords={"axis": ("axis", np.array(["x", "y"], dtype=object))},
        attrs={"Conventions": "msslib-result-1.0", "E": 1e6, "nu": 0.3, "thickness": "None"})
    legacy.to_netcdf(tmp_path / "old.nc", engine="netcdf4")
    mesh = mesh_from_result(read_result(tmp_path / "old.nc"))
    assert mesh.cell_type == "triangle" and mesh.material.tolist() == [0]
    np.testing.assert_array_equal(mesh.points, points)
