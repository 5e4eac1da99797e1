"""Speed against error on nested meshes: per scene, every variant's error and time by level, whether
its error decreases under refinement, its place on the Pareto front, and the crossover error budget
(the fastest variant within a budget is FEM below it, an MSS above it). No published values exist
for this comparison: it is ours only."""

import math

import numpy as np

from msslib.results import read_result, write_text
from msslib.planning import pareto
from experiments import script

SCENES = ["cantilever", "cantilever on tetrahedra", "cylinder", "membrane"]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def _g(v, s=1.0, fmt=".3g"):
    return "-" if not np.isfinite(v) else format(v * s, fmt)


def main():
    a = script.args(__doc__)
    lines = [("| scene | reference (level, dofs) | its own error (est.) | observed order | linear vs non-linear "
              "reference | crossover budget | fastest just below it | fastest at it | an MSS fastest up to |"),
             "|---|---|---|---|---|---|---|---|---|"]
    body = []
    for scene, path in zip(SCENES, INPUTS):
        f = read_result(path)
        front = pareto(f)  # by increasing time
        cross = float(f.attrs["crossover_error"])
        below = [q for q in front if q[3] < cross] if math.isfinite(cross) else front
        at = [q for q in front if q[3] == cross]
        name = lambda q: f"{q[0]} level {q[1]} ({_g(q[3], 100)} %, {_g(q[2])} s)"
        upper = float(f.attrs["mss_window_upper"])
        lines.append(
            f"| {scene} | {f.attrs['reference_model']} ({f.attrs['reference_level']}, {f.attrs['reference_dofs']}) | "
            f"{_g(float(f.attrs['reference_error']), 100, '.2g')} % | "
            f"{_g(float(f.attrs['reference_observed_order']), 1, '.2f')} | "
            f"{_g(float(f.attrs['linearisation_gap']), 100, '.3g')} % | "
            f"{_g(cross, 100) + ' %' if math.isfinite(cross) else 'none (' + str(f.attrs['crossover_kind']) + ')'} | "
            f"{name(below[0]) if below else '-'} | {name(at[0]) if at else '-'} | "
            f"{'every larger budget' if upper == math.inf else _g(upper, 100) + ' %'} |")
        on = {(q[0], q[1]) for q in front}
        levels = [int(v) for v in f.level.values]
        body += ["", (f"**{scene}**: max error (%) / best CPU time (s) by level "
                      f"{', '.join(map(str, levels))}; level 0 is the scene's mesh, each level one uniform refinement "
                      f"(reference: {f.attrs['reference_model']} on level {f.attrs['reference_level']}, "
                      f"own error about {_g(float(f.attrs['reference_error']), 100, '.2g')} %)"), "",
                 "| variant | " + " | ".join(f"level {lv}" for lv in levels) + " | decreases | last-step rate | on the front |",
                 "|---|" + "---|" * len(levels) + "---|---|---|"]
        for m in f.model.values:
            r = f.sel(model=m)
            cells = []
            for lv in levels:
                x = r.sel(level=lv)
                e, t = float(x.error_max), float(x.wall_time)
                flag = "" if str(x.status.values) == "ok" else " (" + str(x.status.values)[:40] + ")"
                cells.append(f"{_g(e, 100)} / {_g(t)}{flag}")
            fr = [str(lv) for lv in levels if (str(m), lv) in on]
            body.append(f"| {m} | " + " | ".join(cells) + f" | {'yes' if int(r.decreasing) else 'no'} | "
                        f"{_g(float(r.last_rate), 1, '.2f')} | {', '.join(fr) or '-'} |")
    write_text(a.out, "\n".join(lines + body) + "\n")


if __name__ == "__main__":
    main()
