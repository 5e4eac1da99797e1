"""Lloyd et al., Secs. 5.1-5.8: how precisely the published errors fix the ratio mean/max.

The paper prints its maximum and mean node distances to a few digits (e.g. 0.076 and 0.041 cm). A
printed number stands for every value that rounds to it: 0.041 for [0.0405, 0.0415]. The ratio
mean/max of two printed numbers is therefore known only within an interval, and an agreement of
our ratio with the paper's can be claimed only to within that interval's half-width, not to a
tolerance chosen after the fact. For every published pair of every Lloyd experiment file (the
numbers read as the text the file prints them, so their digits are those of the paper) this study
writes the printed ratio, the smallest and largest ratio the printed digits allow and the
half-width of that interval, labelled like the runs of study ``load_sweep``
(``experiment/case/variant``).

    python -m experiments.lloyd.studies.printed_digits --out results/lloyd/studies/printed_digits.nc [--quick]
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from experiments import script
from msslib.results import write_result

LLOYD = Path(__file__).resolve().parents[1]


def half_unit(text: str) -> float:
    """Half a unit of the last printed digit of a decimal number written as ``text``."""
    digits = len(text.split(".")[1]) if "." in text else 0
    return 0.5 * 10.0 ** (-digits)


def ratio_interval(mean: str, maximum: str):
    """The printed ratio mean/max and the smallest and largest ratio of numbers that print so."""
    m, M = float(mean), float(maximum)
    dm, dM = half_unit(mean), half_unit(maximum)
    return m / M, (m - dm) / (M + dM), (m + dm) / (M - dM)


def published_pairs():
    """(run label, mean text, max text) for every published pair of the Lloyd experiment files."""
    out = []
    for path in sorted(LLOYD.glob("*.yaml")):
        doc = yaml.load(path.read_text(encoding="utf-8"), Loader=yaml.BaseLoader)  # every scalar as its text
        if not isinstance(doc, dict) or "published" not in doc:
            continue
        for case, variants in doc["published"].items():
            for variant, metrics in variants.items():
                if "mean" in metrics and "max" in metrics and metrics["mean"][1] == metrics["max"][1]:
                    out.append((f"{path.stem}/{case}/{variant}", metrics["mean"][0], metrics["max"][0]))
    return out


def main(argv=None):
    args = script.args(__doc__, argv)
    pairs = published_pairs()
    runs = [p[0] for p in pairs]
    rows = np.array([ratio_interval(mean, mx) for _, mean, mx in pairs])
    ds = xr.Dataset(coords={"run": runs})
    ds["published_ratio"] = ("run", rows[:, 0], {"units": "1", "long_name": "printed mean / printed max"})
    ds["ratio_low"] = ("run", rows[:, 1], {"units": "1", "long_name": "smallest ratio the printed digits allow"})
    ds["ratio_high"] = ("run", rows[:, 2], {"units": "1", "long_name": "largest ratio the printed digits allow"})
    ds["tolerance"] = ("run", np.maximum(rows[:, 2] - rows[:, 0], rows[:, 0] - rows[:, 1]),
                       {"units": "1", "long_name": "half-width of that interval about the printed ratio"})
    ds["published_mean_text"] = ("run", [p[1] for p in pairs], {"long_name": "the mean as printed"})
    ds["published_max_text"] = ("run", [p[2] for p in pairs], {"long_name": "the max as printed"})
    ds.attrs.update(study="lloyd_printed_digits", quick=int(args.quick), description=__doc__.strip().splitlines()[0])
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    write_result(args.out, ds)
    for r, (p, lo, hi), tol in zip(runs, rows, ds.tolerance.values):
        print(f"{r}: {p:.3f} in [{lo:.3f}, {hi:.3f}] (+-{tol:.3f})")


if __name__ == "__main__":
    main()
