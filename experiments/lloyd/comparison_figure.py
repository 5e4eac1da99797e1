"""Shared body of the Lloyd comparison figures (experiments/lloyd/figures/<experiment>.py declare only
their columns and the files they read): for each column (a case and two model variants of one
experiment), top row: the variant's wireframe (red) over the reference coloured by its displacement
magnitude, the rest shape in grey; bottom row: the per-node distance between the two."""

import argparse
from pathlib import Path

from experiments import plotting
from msslib.results import read_result

ROOT = Path(__file__).resolve().parents[2]


def main(doc, columns, inputs, *, plane="xy", panel_width=3.2, argv=None):
    """Draw the figure of ``columns`` = [(title, case, variant, reference), ...] from ``inputs``, the
    figure's INPUTS: the variant's and the reference's result of each column, in that order."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--out", required=True, help="output stem: writes STEM.png and STEM.pdf")
    args = ap.parse_args(argv)
    named = [f"{case}__{m}.nc" for _, case, var, ref in columns for m in (var, ref)]
    if [Path(p).name for p in inputs] != named:
        raise ValueError(f"INPUTS {inputs} do not match the columns {named}")
    results = [read_result(ROOT / p) for p in inputs]
    pairs = {title: (results[2 * k], results[2 * k + 1]) for k, (title, *_) in enumerate(columns)}
    fig = plotting.comparison_figure(pairs, plane=plane, variant_label="MSS", reference_label="FEM",
                                     panel_width=panel_width)
    plotting.save(fig, args.out)
