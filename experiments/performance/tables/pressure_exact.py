"""Pressure table: each model's nodal error against the exact thick-cylinder and thick-sphere solutions under an
internal pressure, on the finest mesh, at three Poisson's ratios, with the observed order of convergence."""

import numpy as np

from experiments import script
from msslib.results import read_result, write_text

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script

CASES = {"cylinder_triangle": "cylinder, triangles", "cylinder_quad": "cylinder, quads",
         "sphere_tetra": "sphere, tetrahedra"}


def _cell(e, rate):
    if not np.isfinite(e):
        return "-"
    text = f"{100 * e:.2g} %" if 100 * e < 10 else f"{100 * e:.0f} %"
    return text + (f" ({rate:.2g})" if np.isfinite(rate) else "")


def main():
    a = script.args(__doc__)
    d = read_result(INPUTS[0])
    nus = [float(v) for v in d.nu.values]
    lines = [(f"Internal pressure {d.attrs['pressure']:g} Pa on thick-walled bodies of radii {d.attrs['inner_radius']:g} "
             f"and {d.attrs['outer_radius']:g} m (E = {d.attrs['E']:g} Pa; the cylinder in plane stress), small strain: "
             "the largest nodal displacement error against the exact linear-elastic solution, relative to the largest "
             "exact displacement, on the finest mesh of each case; in brackets the observed order of the root-mean-square "
             "error between the two finest meshes. *fem_quadratic*: the project's quadratic reference (reduced "
             "volumetric rule in 3D), straight-sided as on a user's mesh; *fem_quadratic_curved*: the same with the "
             "quadratic nodes of both walls on their circle or sphere; *fem_linear_p1*: linear FEM. A dash: the model does not run on those cells."), "",
             "| case | model | " + " | ".join(f"nu = {nu:g}" for nu in nus) + " |", "|---|---" + "|---" * len(nus) + "|"]
    for case in d.case.values:
        for model in d.model.values:
            row = [_cell(float(d.finest_error_max.sel(case=case, model=model, nu=nu)),
                         float(d.rate.sel(case=case, model=model, nu=nu))) for nu in d.nu.values]
            if all(c == "-" for c in row):
                continue
            lines.append(f"| {CASES.get(str(case), str(case))} | {model} | " + " | ".join(row) + " |")
    refused = {}  # the first refusal of each model (the others repeat it on the other meshes)
    for m, o in zip(d.run_model.values, d.outcome.values):
        if str(o) != "ok":
            refused.setdefault(str(m), " ".join(str(o).split())[:120])
    if refused:
        lines += ["", "Models that gave no result:", ""] + [f"- {m}: {o}" for m, o in refused.items()]
    write_text(a.out, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
