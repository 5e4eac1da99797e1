"""Lloyd et al., Sec. 5.1-5.8: error of every MSS experiment against the load, from small strain to the paper's.

The paper prints maximum and mean node distances between MSS and FEM but no load magnitudes; it
states deformations instead ("around ten to thirteen percent" in general, 11.2-13.6 % for Fig. 9,
13.5 % for Figs. 10-11, 12 % for Fig. 12, 15 % for Fig. 16a).  So no single load is compared here:
every case of every Lloyd experiment file (``experiments/lloyd/<name>.yaml``, scenes taken through
:func:`msslib.experiment.scene_of`, only the load magnitude scaled) is run at loads that give a
deformation ``d`` from 0.1 % up to the largest the paper states for it, log-spaced, plus the
smallest stated value.  ``d`` is measured on the linear FEM of the experiment: the mean
displacement of the top face (the loaded face) along the load, divided by the height; for a
stretch it is the mean strain of the top edge, for a shear the mean shear displacement of the top
over the height.  Every MSS variant is compared with the experiment's reference (per-node
Euclidean distance: max, mean, both also relative to the largest reference displacement, and the
ratio mean/max, which does not depend on the load where the error is linear or quadratic in it).

    python -m experiments.lloyd.studies.load_sweep --out results/lloyd/studies/load_sweep.nc [--quick]

``--quick``: the two small membranes (Secs. 5.1, 5.3), 0.1 % and the stated deformation only; the
other experiments are written as rows of NaN (same labels as the full build).
"""

from __future__ import annotations

import dataclasses
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from msslib.experiment import UNITS, compare, load_experiment, scene_of
from msslib.results import write_result
from msslib.scene import load_scene, run_scene

LLOYD = Path(__file__).resolve().parents[1]
GENERAL = (0.10, 0.13, "Sec. 5: deformations of around ten to thirteen percent")
#: experiment -> (section label, {case: (smallest, largest stated deformation, source)}); cases
#: not named take GENERAL; "file": the sweep ends at the experiment file's load (the cone, whose
#: non-linear reference stops converging a little above it, and the compressed cylinder with a
#: hole, whose MSS solver stops converging a little above it)
EXPERIMENTS = {
    "membrane_equilateral": ("5.1", {"stretch": (0.112, 0.136, "Sec. 5.1, Fig. 9: stretched 11.2-13.6 %")}),
    "membrane_arbitrary": ("5.2", {"stretch": (0.135, 0.135, "Figs. 10-11: 13.5 %")}),
    "membrane_square": ("5.3", {"stretch": (0.12, 0.12, "Sec. 5.3, Fig. 12: stretched 12 %"),
                                "compression": (0.12, 0.12, "Sec. 5.3, Fig. 12: compressed 12 %")}),
    "resolutions": ("5.4", {}),
    "two_layer": ("5.5", {}),
    "cylinder": ("5.6", {}),
    "cylinder_hole": ("5.6", {"stretch": (0.15, 0.15, "Sec. 5.6, Fig. 16a: 15 %"),
                              "compression": (0.10, "file", ("Sec. 5: ten to thirteen percent; the MSS solver fails "
                                              "beyond the file's load (about 8 %)"))}),
    "cone": ("5.7", {"shear": (0.10, "file", "Sec. 5.7: large displacements (> 10 %); up to the file's load")}),
    "cylinder_volume": ("5.8", {}),
}
QUICK = ("membrane_equilateral", "membrane_square")
SMALL = 1e-3          # the smallest deformation of every sweep
N_LOG = 7             # log-spaced levels from SMALL to the largest stated deformation
#: variants left out: identical to another one (at nu = 1/4 eq. 14 re-derived = eq. 14 printed)
SKIP = {("cylinder_volume", "derived")}


def scaled(scene: dict, factor: float) -> dict:
    """The scene with every traction / nodal-force load multiplied by ``factor``."""
    out = dict(scene)
    out["loads"] = []
    for load in scene.get("loads", []):
        load = dict(load)
        for key in ("traction", "total"):
            if key in load:
                load[key] = [factor * float(v) for v in load[key]]
        out["loads"].append(load)
    return out


def load_direction(scene: dict) -> np.ndarray:
    """Unit vector of the (first) traction or nodal-force load of a scene."""
    for load in scene.get("loads", []):
        for key in ("traction", "total"):
            if key in load:
                v = np.asarray(load[key], dtype=float)
                return v / np.linalg.norm(v)
    raise ValueError("scene has no traction or nodal-force load")


def top_nodes(X: np.ndarray) -> np.ndarray:
    """Nodes of the top face (largest coordinate along the last axis)."""
    h = X[:, -1]
    return np.flatnonzero(np.isclose(h, h.max(), atol=1e-9 * np.ptp(h)))


def deformation(X: np.ndarray, u: np.ndarray, direction: np.ndarray) -> float:
    """Mean displacement of the top face along ``direction`` over the height (> 0 along the load)."""
    top = top_nodes(X)
    return float(np.mean(u[top] @ direction) / np.ptp(X[:, -1]))


def arrays(ds):
    return ds["rest_position"].transpose("node", "axis").values, ds["displacement"].transpose("node", "axis").values


def solve(exp, case, model, factor, quick):
    """One run at ``factor`` times the experiment's load; None when the solver fails."""
    sc = scaled(scene_of(exp, case, model, quick), factor)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return run_scene(load_scene(sc, base_dir=exp.base_dir), progress=False)
    except RuntimeError as exc:  # ConvergenceError: the curve ends there
        print(f"    {exp.name}/{case}/{model} at x{factor:.4g}: {type(exc).__name__}", flush=True)
        return None


def linear_fem(exp) -> str:
    """The experiment's linear FEM variant (the deformation is measured on it)."""
    for name, spec in exp.models.items():
        m = spec.get("model") if isinstance(spec, dict) else None
        if m == "fem_linear" or (isinstance(m, dict) and m.get("type") == "fem_linear"):
            return name
    raise ValueError(f"{exp.name}: no fem_linear variant")


def levels_of(lo, hi, quick):
    if quick:
        return np.array([SMALL, hi])
    return np.unique(np.append(np.geomspace(SMALL, hi, N_LOG), lo if lo < hi else []))


def sweep(name, quick):
    """Rows (one per case and MSS variant) of the sweep of one experiment."""
    exp = load_experiment(LLOYD / f"{name}.yaml")
    section, stated = EXPERIMENTS[name]
    lin = linear_fem(exp)
    variants = [m for m in exp.models if m != exp.reference and (name, m) not in SKIP]
    rows = []
    for case in exp.cases:
        lo, hi, source = stated.get(case, GENERAL)
        base = scene_of(exp, case, lin, quick)
        direction = load_direction(base)
        nominal = solve(exp, case, lin, 1.0, quick)
        X, u = arrays(nominal)
        d_nominal = deformation(X, u, direction)
        end = d_nominal if hi == "file" else hi
        levels = levels_of(lo, end, quick)
        factors = levels / d_nominal
        out = {v: {k: np.full(len(levels), np.nan) for k in ("error_max", "error_mean", "relative_error_max",
                                                             "relative_error_mean", "reference_max_displacement",
                                                             "mss_deformation")} for v in variants}
        pub = {}
        one = dataclasses.replace(exp, cases={case: exp.cases[case]},
                                  models={m: exp.models[m] for m in [exp.reference] + variants})
        failed = set()  # a variant whose solver failed is not run at larger loads
        for k, f in enumerate(factors):
            t0 = time.perf_counter()
            results = {(case, m): None if m in failed else solve(exp, case, m, f, quick) for m in [exp.reference] + variants}
            failed |= {m for (_, m), ds in results.items() if ds is None}
            ok = {m for (_, m), ds in results.items() if ds is not None}
            if exp.reference in ok:
                cmp = compare(dataclasses.replace(one, models={m: exp.models[m] for m in [exp.reference] + sorted(ok - {exp.reference})}),
                              {key: ds for key, ds in results.items() if ds is not None})
                for v in variants:
                    if v not in ok:
                        continue
                    r = cmp.sel(case=case, variant=v)
                    for key in ("error_max", "error_mean", "relative_error_max", "relative_error_mean"):
                        out[v][key][k] = float(r[key])
                    out[v]["reference_max_displacement"][k] = float(cmp.reference_max_displacement.sel(case=case))
                    Xv, uv = arrays(results[(case, v)])
                    out[v]["mss_deformation"][k] = deformation(Xv, uv, direction)
                    pub[v] = (float(r.published_max), float(r.published_mean))
            print(f"  {name}/{case}: d = {100 * levels[k]:.3g} %, load x{f:.3g} of the file's, "
                  + ", ".join(f"{v} max {1e3 * out[v]['error_max'][k]:.3g} mm" for v in variants)
                  + f" ({time.perf_counter() - t0:.1f} s)", flush=True)
        traction = np.linalg.norm(base["loads"][0].get("traction", base["loads"][0].get("total")))
        for v in variants:
            pmax, pmean = pub.get(v, (np.nan, np.nan))
            rows.append(dict(experiment=name, section=section, case=case, variant=v, reference=exp.reference,
                             source=source, stated_low=lo, stated_high=end, deformation=levels,
                             load=traction * factors, file_load=traction, file_deformation=d_nominal,
                             end_at_file_load=float(hi == "file"),
                             published_max=pmax, published_mean=pmean, **out[v]))
    return rows


def published(exp, case, variant, metric):
    """A published value in metres (NaN if the paper gives none)."""
    value = (exp.published.get(case, {}).get(variant, {}) or {}).get(metric)
    return np.nan if value is None else float(value[0]) * UNITS[value[1]]


def placeholders(name):
    """Rows of NaN for an experiment the quick build does not run (the labels stay the same)."""
    exp = load_experiment(LLOYD / f"{name}.yaml")
    section, stated = EXPERIMENTS[name]
    rows = []
    for case in exp.cases:
        lo, hi, source = stated.get(case, GENERAL)
        end = np.nan if hi == "file" else hi
        nan = np.full(2, np.nan)
        for v in [m for m in exp.models if m != exp.reference and (name, m) not in SKIP]:
            rows.append(dict(experiment=name, section=section, case=case, variant=v, reference=exp.reference,
                             source=source + " (not run in the quick build)", stated_low=lo, stated_high=end,
                             deformation=nan, load=nan, file_load=np.nan, file_deformation=np.nan,
                             end_at_file_load=float(hi == "file"), published_max=published(exp, case, v, "max"),
                             published_mean=published(exp, case, v, "mean"),
                             **{k: nan for k in ("error_max", "error_mean", "relative_error_max", "relative_error_mean",
                                                 "reference_max_displacement", "mss_deformation")}))
    return rows


def crossing(ds, a, b):
    """Deformation at which the max error of run ``a`` falls below that of run ``b`` (log-linear
    interpolation between the levels around the first sign change; NaN if it never does)."""
    runs = list(ds.run.values)
    if a not in runs or b not in runs:
        return np.nan
    d = ds.deformation.sel(run=a).values
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.log(ds.error_max.sel(run=a).values / ds.error_max.sel(run=b).values)
    for k in range(1, len(d)):
        if np.isfinite(r[k - 1]) and np.isfinite(r[k]) and r[k - 1] >= 0 > r[k]:
            t = r[k - 1] / (r[k - 1] - r[k])
            return float(np.exp(np.log(d[k - 1]) + t * (np.log(d[k]) - np.log(d[k - 1]))))
    return np.nan


def dataset(rows, n_level, quick):
    n = len(rows)

    def pad(key):
        a = np.full((n, n_level), np.nan)
        for i, r in enumerate(rows):
            a[i, :len(r[key])] = r[key]
        return a

    run = [f"{r['experiment']}/{r['case']}/{r['variant']}" for r in rows]
    lvl = ("run", "level")
    ds = xr.Dataset(coords={"run": ("run", run, {"units": "1", "long_name": "experiment/case/MSS variant"}),
                            "level": ("level", np.arange(n_level), {"units": "1", "long_name": "load level"})})
    for key in ("experiment", "section", "case", "variant", "reference", "source"):
        ds[key] = ("run", np.array([r[key] for r in rows], dtype=str), {"units": "1", "long_name": key})
    meta = {
        "deformation": ("1", "top-face displacement along the load over the height, linear FEM"),
        "load": ("Pa", "traction magnitude"),
        "error_max": ("m", "maximum node distance MSS - reference"),
        "error_mean": ("m", "mean node distance MSS - reference"),
        "relative_error_max": ("1", "maximum node distance over the largest reference displacement"),
        "relative_error_mean": ("1", "mean node distance over the largest reference displacement"),
        "reference_max_displacement": ("m", "largest reference displacement"),
        "mss_deformation": ("1", "top-face displacement along the load over the height, MSS"),
    }
    for key, (unit, long) in meta.items():
        ds[key] = (lvl, pad(key), {"units": unit, "long_name": long})
    with np.errstate(invalid="ignore", divide="ignore"):
        ds["ratio"] = (lvl, ds.error_mean.values / ds.error_max.values, {"units": "1", "long_name": "mean error / max error"})
    for key, unit, long in (("stated_low", "1", "smallest deformation the paper states"),
                            ("stated_high", "1", "largest deformation the paper states (end of the sweep)"),
                            ("file_load", "Pa", "traction of the experiment file"),
                            ("file_deformation", "1", "deformation under the experiment file's traction, linear FEM"),
                            ("end_at_file_load", "1", "1: the sweep ends at the experiment file's load, not at a stated deformation"),
                            ("published_max", "m", "published maximum error"),
                            ("published_mean", "m", "published mean error")):
        ds[key] = ("run", np.array([r[key] for r in rows], dtype=float), {"units": unit, "long_name": long})
    with np.errstate(invalid="ignore"):
        ds["published_ratio"] = ("run", ds.published_mean.values / ds.published_max.values,
                                 {"units": "1", "long_name": "published mean / max error"})
    # values at the smallest load and at the largest stated deformation (the end of the sweep)
    d = ds.deformation.values

    def at(key, targets):
        """Values of ``key`` at the level whose deformation is ``targets[run]`` (NaN if none is)."""
        v = ds[key].values
        out = np.full(n, np.nan)
        for i, t in enumerate(targets):
            hit = np.flatnonzero(np.isclose(d[i], t, rtol=1e-9))
            if hit.size:
                out[i] = v[i, hit[0]]
        return out

    for key in ("error_max", "error_mean", "relative_error_max", "relative_error_mean", "ratio", "load"):
        unit = ds[key].attrs["units"]
        ds[f"{key}_small"] = ("run", ds[key].values[:, 0], {"units": unit, "long_name": f"{key} at {100 * SMALL:g} % deformation"})
        ds[f"{key}_stated"] = ("run", at(key, ds.stated_high.values),
                               {"units": unit, "long_name": f"{key} at the end of the sweep (largest stated deformation)"})
        ds[f"{key}_stated_low"] = ("run", at(key, ds.stated_low.values),
                                   {"units": unit, "long_name": f"{key} at the smallest stated deformation"})
    with np.errstate(invalid="ignore", divide="ignore"):
        e = ds.error_max.values
        ds["slope_small"] = ("run", np.log(e[:, 1] / e[:, 0]) / np.log(d[:, 1] / d[:, 0]),
                             {"units": "1", "long_name": "d log(max error) / d log(deformation) between the two smallest loads"})
        ds["max_over_published"] = ("run", ds.error_max_stated.values / ds.published_max.values,
                                    {"units": "1", "long_name": "our max error at the stated deformation / published max"})
    ds["cone_crossing"] = ((), crossing(ds, "cone/shear/mss", "cone/shear/fem_linear"),
                           {"units": "1", "long_name": "cone: deformation beyond which the MSS is closer to the "
                                                       "non-linear reference than the linear FEM is (log-interpolated)"})
    ds.attrs.update(title="Lloyd et al. Sec. 5: MSS error against load", small_deformation=SMALL,
                    quick=int(quick))
    return ds


def main(argv=None):
    def extra(p):
        p.add_argument("--only", nargs="*", help="experiments to run (default: all)")

    args = script.parse(__doc__, argv, extra=extra)[1]
    names = args.only or (QUICK if args.quick else list(EXPERIMENTS))
    rows = []
    t0 = time.perf_counter()
    for name in names:
        print(f"{name} ({time.perf_counter() - t0:.0f} s)", flush=True)
        rows += sweep(name, args.quick)
    if args.quick and not args.only:  # the other experiments as NaN rows: the same labels as the full build
        for name in EXPERIMENTS:
            if name not in names:
                rows += placeholders(name)
    ds = dataset(rows, max(len(r["deformation"]) for r in rows), args.quick)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    write_result(out, ds)
    for i, run in enumerate(ds.run.values):
        r = ds.isel(run=i)
        print(f"{run}: ratio small {float(r.ratio_small):.3f}, stated {float(r.ratio_stated):.3f} "
              f"(published {float(r.published_ratio):.3f}); max at stated {1e3 * float(r.error_max_stated):.3g} mm "
              f"(published {1e3 * float(r.published_max):.3g} mm)")
    print(f"done in {time.perf_counter() - t0:.0f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
