"""The measured speed/error points and the Pareto front of each scene, as a Markdown table."""

import argparse

import numpy as np

from msslib.io import read_result, write_text
from msslib.planning import pareto

SCENES = ["cantilever", "cylinder", "membrane"]
INPUTS = [f"results/performance/studies/front_{s}.nc" for s in SCENES]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--out", required=True)
    a = p.parse_args()
    lines = []
    for scene, path in zip(SCENES, INPUTS):
        f = read_result(path)
        front = {(m, lv) for m, lv, _, _ in pareto(f)}
        lines += [f"**{scene}** (reference: {f.attrs['reference_model']} at level {f.attrs['reference_level']}; "
                  f"median of {f.attrs['repeats']} runs)", "",
                  "| model | level | dofs | wall time (s) | max error (%) | mean error (%) | on the front | status |",
                  "|---|---|---|---|---|---|---|---|"]
        for m in f.model.values:
            for lv in f.level.values:
                r = f.sel(model=m, level=lv)
                t, e, em = float(r.wall_time), float(r.error_max), float(r.error_mean)
                fmt = lambda v, s=1: "-" if not np.isfinite(v) else f"{v * s:.3g}"  # noqa: E731
                lines.append(f"| {m} | {lv} | {int(r.n_dofs)} | {fmt(t)} | {fmt(e, 100)} | {fmt(em, 100)} | "
                             f"{'yes' if (str(m), int(lv)) in front else ''} | {str(r.status.values)[:80]} |")
        lines.append("")
    write_text(a.out, "\n".join(lines))


if __name__ == "__main__":
    main()
