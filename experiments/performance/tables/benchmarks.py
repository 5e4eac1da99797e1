"""The benchmark figures with their baselines, threads and load, as a Markdown table."""

import json
from pathlib import Path

from msslib.results import write_text
from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def _md(text):
    """Text for a Markdown table cell (a bare pipe would split the cell)."""
    return str(text).replace("|", "\\|")


def main():
    a = script.args(__doc__)
    data = json.loads(Path(INPUTS[0]).read_text())
    m = data["meta"]
    lines = [f"`python -m benchmarks{' --quick' if m['quick'] else ''}`: BLAS and numba pinned to "
             f"{m['threads_blas']}/{m['threads_numba']} thread(s) ({m['thread_pools']}); {m['cpu_count']} cores, "
             f"load average {m['load_average']:.1f} at the start; numpy {m['numpy']}, numba {m['numba']}, "
             f"pyamg {m['pyamg']}; {m['wall_s']:.0f} s in all." + (" Reduced sizes." if m["quick"] else ""), "",
             "| figure | value | unit | ratio to baseline | baseline | target | met | note |",
             "|---|---|---|---|---|---|---|---|"]
    for name, f in data["figures"].items():
        r = "-" if f["ratio_to_baseline"] is None else f"{f['ratio_to_baseline']:.3g}"
        met = {None: "-", True: "yes", False: "**no**"}[f.get("met")]
        lines.append(f"| {name} | {f['value']:.4g} | {f['unit']} | {r} | {f['baseline'] or '-'} | "
                     f"{f.get('target') or '-'} | {met} | {_md(f['note'])} |")
    write_text(a.out, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
