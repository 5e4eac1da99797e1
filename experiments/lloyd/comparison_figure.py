"""Shared body of the Lloyd comparison figures: for each column (a case and two model variants of
one experiment), the variant's wireframe (red) over the reference coloured by its displacement
magnitude, the rest shape in grey, and below it the per-node distance between the two."""

import argparse
from pathlib import Path

from msslib import plotting
from msslib.io import read_result

ROOT = Path(__file__).resolve().parents[2]


def inputs(experiment, columns):
    """The result files a figure over ``columns`` = [(title, case, variant, reference), ...] reads."""
    return [f"results/lloyd/{experiment}/{case}__{m}.nc" for _, case, var, ref in columns for m in (var, ref)]


def main(experiment, columns, description, *, plane="xy", panel_width=3.2, argv=None):
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--out", required=True, help="output stem: writes STEM.png and STEM.pdf")
    args = ap.parse_args(argv)

    def load(case, model):
        return read_result(ROOT / "results" / "lloyd" / experiment / f"{case}__{model}.nc")

    pairs = {title: (load(case, var), load(case, ref)) for title, case, var, ref in columns}
    fig = plotting.comparison_figure(pairs, plane=plane, variant_label="MSS", reference_label="FEM",
                                     panel_width=panel_width)
    plotting.save(fig, args.out)
