"""Hard cases of the mass-spring models: where each model breaks, and how.

    python -m experiments.stability --out results/stability.nc [--quick]

Every case of ``experiments/stability/cases.yaml`` is a scene (:mod:`experiments.stability.scenes`)
run by :func:`msslib.scene.run_scene` once per model column; the study
(:mod:`experiments.stability.study`) loops over cases x models and records, per (case, model):
whether it ran, whether the solver converged, the error against the neo-Hookean FEM reference on
the same mesh where that is meaningful, the volume ratio V/V0, the smallest element volume ratio,
the number of inverted elements, the Newton iterations and a one-line text of the outcome (how it
broke).  The result is an xarray Dataset written atomically (:func:`msslib.results.write_result`).

Models (dimension ``model``, the ``models`` of cases.yaml, plus every mass-spring model of the
registry on tetrahedra or hexahedra that no column runs, under its own name): ``lloyd_tetrahedron``
/ ``lloyd_tetrahedron_volume`` on Kuhn tetrahedral meshes; ``baudet_cube`` (springs plus the
correction under the element reading: each cube corrected from the forces it receives from
outside, active under displacement control too) and ``baudet_cube_boundary`` (the correction
built from the loaded surface: it acts in force-controlled cases only; the variable ``reading``
records which reading each column ran); ``golec_derived`` / ``golec_published`` /
``golec_springs_only`` (Golec's cube with the derived constants, the printed ones, and the
derived springs without the volume term); ``lsq_tetrahedron`` and ``kikuuwe_tetrahedron`` (from
the registry); ``fem_linear``, ``fem_svk``, ``fem_neohookean`` (scikit-fem references on the
cube mesh) and ``fem_svk_tetra`` (St Venant-Kirchhoff FEM on the tetrahedral mesh).

Cases (dimension ``case``):

* ``nu_0.45`` ... ``nu_0.4999``: unit cube, 10 % compression by a prescribed top displacement,
  frictionless symmetry planes (the exact solution is homogeneous, so linear elements represent it
  exactly and the FEM reference does not lock).  Baudet's cube under the boundary reading is
  loaded instead by the FEM reaction on top as a traction (force control) so that its correction
  is active.
* ``compress_10/30/50``: 0.1 m cube clamped at top and bottom (barrelling), nu = 0.3, prescribed
  top displacement (the static solver's F_ref is then the linearised reaction of the motion).
* ``inverted_input``: the sliding scene on 2^3 meshes with one cell numbered backwards (an in-memory
  mesh): the scene loader must say so (a warning) when it re-orders it, and the result must equal
  the consistently numbered mesh's (error: max nodal difference / max displacement).
* ``sliver``, ``cap``, ``spindle``, ``wedge``: one badly shaped tetrahedron, an element analysis
  (:mod:`experiments.stability.shapes`), not a run: Lloyd's constant against the exact
  element-wise least squares of the element's FEM stiffness by its six spring matrices (variables
  on the ``shape`` x ``edge`` dimensions).
* ``contrast_1`` / ``contrast_1000``: bar of two materials (E and 1000 E) in series, clamped at
  one end, pulled by a traction at the other (1 % strain in the soft half).
* ``explicit_1.05x`` / ``explicit_1.2x`` / ``explicit_1.5x`` / ``explicit_2x`` / ``implicit_1.5x``:
  cantilever under gravity released from rest, symplectic Euler at that multiple of the explicit
  stability limit of the model at rest: refused by the scene runner (StabilityError, both numbers
  in the message), then run with ``allow_unstable: true`` until the divergence detector stops it
  (DivergenceError; ``stop_step``, ``stop_displacement`` = max |u| when stopped / static max |u|,
  and error = distance of the last state before the stop from a stable run to the same time /
  static max |u| record how early); implicit Euler at 1.5 x (must stay finite; error = the
  largest |u| over the run / static max |u|).
* ``unloaded``: 0.1 m cube clamped on one face, no load: every static solver must return at once
  (``iterations`` 0, at the round-off floor; error = max |u| / edge length).
* ``slender_beam``: 1 m x 2 cm x 2 cm beam, E = 1 GPa, clamped, under its own weight, default
  tolerance 1e-8 (below the round-off of the spring forces: converged at the round-off floor);
  error = tip deflection / Euler-Bernoulli ``q L^4 / (8 E I)`` - 1 (4 cubes across; 2 in quick
  mode, where bending locking makes every model stiffer).
"""

from __future__ import annotations

import sys
import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from experiments.stability.scenes import load_cases, reading
from experiments.stability.shapes import SHAPES, TET_EDGES
from experiments.stability.study import FIELDS, record, run_all
from msslib.results import write_result

__all__ = ["main", "summary", "to_dataset"]

META = {
    "ran": ("1", "model ran (mesh and constants accepted, solver called)"),
    "converged": ("1", "solver converged (static) / integration completed (dynamic)"),
    "error": ("1", ("max nodal |u - u_ref| / max |u_ref|, u_ref neo-Hookean FEM on the same mesh "
                    "(inverted_input: u_ref the consistently numbered mesh's; implicit_1.5x: largest |u| over the run "
                    "/ static max |u|; explicit_*: max nodal distance of the last state before the stop from a stable "
                    "run (half the limit) to the same time / static max |u|; unloaded: max |u| / edge length; "
                    "slender_beam: tip deflection / Euler-Bernoulli - 1); NaN where not meaningful")),
    "volume_ratio": ("1", "total volume / rest volume of the final state"),
    "min_volume_ratio": ("1", "smallest element volume / its rest volume (negative: inverted)"),
    "n_inverted": ("1", "number of elements with non-positive volume in the final state (-1: not run)"),
    "iterations": ("1", "Newton iterations of a static solve, all load steps (-1: not recorded)"),
    "stop_step": ("1", ("explicit run with allow_unstable: the step at which the divergence detector stopped it "
                        "(-1: n/a)")),
    "stop_displacement": ("1", "explicit run with allow_unstable: max |u| when stopped / static max |u| (NaN: n/a)"),
    "dt_limit": ("s", "explicit and implicit cases: the explicit stability limit of the model at rest, the step the "
                      "case multiplies (NaN: n/a)"),
    "outcome": ("1", "how the run ended or broke (one line)"),
}


def to_dataset(cases, shape_data, models, E, quick, readings=None) -> xr.Dataset:
    """The result: per (case, model) the fields of :data:`FIELDS`; per model the Baudet correction
    reading it ran (``readings``, column -> "element", "boundary" or "" for other models)."""
    names = list(cases)
    table = {f: [[(cases[c].get(m) or record(outcome="n/a"))[f] for m in models] for c in names] for f in FIELDS}
    data = {}
    for f in FIELDS:
        values = np.array(table[f], dtype=object if f == "outcome" else None)
        if f in ("ran", "converged"):
            values = values.astype(np.int8)
        elif f in ("n_inverted", "iterations", "stop_step"):
            values = values.astype(np.int64)
        elif f == "outcome":
            values = values.astype(str)
        units, long_name = META[f]
        data[f] = (("case", "model"), values, {"units": units, "long_name": long_name})
    readings = readings or {}
    data["reading"] = (("model",), np.array([str(readings.get(m, "")) for m in models], dtype=str),
                       {"units": "1", "long_name": "reading of Baudet's correction force the column ran (element: each "
                                                   "cube from the forces it receives from outside; boundary: from the "
                                                   "loaded surface); empty for the other models"})
    shapes = list(SHAPES)
    data["k_lloyd"] = (("shape",), np.array([shape_data[s]["k_lloyd"] for s in shapes]),
                       {"units": "N/m", "long_name": "Lloyd per-element constant (regular tetrahedron of equal volume)"})
    data["k_lsq"] = (("shape", "edge"), np.array([shape_data[s]["k_lsq"] for s in shapes]),
                     {"units": "N/m", "long_name": "element-wise least-squares spring constants vs the FEM element stiffness"})
    data["lsq_residual"] = (("shape",), np.array([shape_data[s]["lsq_residual"] for s in shapes]),
                            {"units": "1", "long_name": "relative Frobenius residual of the element-wise least squares"})
    coords = {
        "case": ("case", np.array(names), {"units": "1", "long_name": "hard case"}),
        "model": ("model", np.array(models), {"units": "1", "long_name": "model"}),
        "shape": ("shape", np.array(shapes), {"units": "1", "long_name": "tetrahedron shape"}),
        "edge": ("edge", np.array([f"{a}-{b}" for a, b in TET_EDGES]), {"units": "1", "long_name": "local edge (nodes)"}),
    }
    return xr.Dataset(data, coords=coords, attrs={
        "title": "msslib stability and hard cases", "E": E, "quick": int(quick),
        "description": (__doc__ or "").strip().split("\n\n")[0]})


def summary(ds) -> str:
    lines = []
    for c in ds["case"].values:
        lines.append(str(c))
        for m in ds["model"].values:
            text = str(ds["outcome"].sel(case=c, model=m).values)
            if text == "n/a":
                continue
            err = float(ds["error"].sel(case=c, model=m))
            vr = float(ds["volume_ratio"].sel(case=c, model=m))
            lines.append(f"  {m:26s} err {err:8.4f}  V/V0 {vr:7.4f}  {text[:150]}")
    return "\n".join(lines)


def main(argv=None) -> int:
    _, args = script.parse(__doc__, argv)  # the one command line of experiments/: --out, --quick
    out = Path(args.out)
    if not out.parent.is_dir():
        print(f"stability: error: directory {str(out.parent)!r} does not exist", file=sys.stderr)
        return 1
    t0 = time.perf_counter()
    data = load_cases()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        cases, shape_data = run_all(data, args.quick,
                                    log=lambda s: print(f"[{time.perf_counter() - t0:6.1f} s] {s}", file=sys.stderr))
    ds = to_dataset(cases, shape_data, list(data["models"]), float(data["E"]), args.quick,
                    readings={m: reading(spec) for m, spec in data["models"].items()})
    ds.attrs["wall_time_s"] = time.perf_counter() - t0
    write_result(out, ds)
    print(summary(ds))
    print(f"-> {out} ({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
    return 0
