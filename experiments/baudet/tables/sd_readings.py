"""Baudet's SD under one reading for all three experiments (sheared beam, cantilever, L-block): the
published SD / M (SD a standard deviation, as printed) and sqrt(SD) / M (SD a variance of the errors
as fractions, printed in %), beside our SD / M (population standard deviation of the per-node errors
over their mean, both readings of the correction). A reading of SD is consistent when it gives one
relation between spread and mean in all three experiments."""

import numpy as np

from experiments import script
from experiments.baudet import baudet_common as C

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
EXPERIMENTS = (("sheared beam (Fig. 7)", "shear", ("mss_2x2x6", "mss_4x4x12", "mss_8x8x24")),
               ("cantilever (Fig. 10)", "gravity", ("mss_4x1x1", "mss_8x2x2", "mss_16x4x4")),
               ("L-block (Fig. 13)", "lateral", ("mss_n2", "mss_n4", "mss_n8")))


def readings(ds, case, variant):
    """(published M, SD, SD / M, sqrt(SD) / M, ours SD / M boundary, ours SD / M element); NaN where
    a value is missing (a variant the build did not run)."""
    def get(name, v):
        return float(ds[name].sel(case=case, variant=v)) if v in ds["variant"].values else np.nan

    m, sd = get("published_relative_mean", variant), get("published_relative_std", variant)
    ours = [get("relative_error_std", v) / get("relative_error_mean", v) for v in (variant, f"{variant}_element")]
    return (m, sd, sd / m, np.sqrt(sd) / m, *ours)


def main():
    args = script.args(__doc__)
    rows, printed, variance, ours = [], [], [], []
    for (title, case, variants), path in zip(EXPERIMENTS, INPUTS):
        ds = C.open_result(path)
        for v in variants:
            m, sd, r1, r2, o1, o2 = readings(ds, case, v)
            printed.append(r1)
            variance.append(r2)
            ours += [o1, o2]
            f = lambda x: "-" if not np.isfinite(x) else f"{x:.2f}"
            rows.append(f"| {title} | {v.removeprefix('mss_')} | {100 * m:g} | {f(100 * sd)} | {f(r1)} | {f(r2)} | "
                        f"{f(o1)} | {f(o2)} |")
            title = ""
    span = lambda a: f"{np.nanmin(a):.2f} to {np.nanmax(a):.2f}"
    lines = ["**Baudet's SD read one way for all three experiments** (published M and SD in %; SD / M: SD a standard "
             "deviation, as printed; sqrt(SD) / M: SD a variance of the errors as fractions; ours: our per-node "
             "standard deviation over our mean, boundary and element reading). "
             f"Ranges over the levels with a published SD: published SD / M {span(printed)}, sqrt(SD) / M {span(variance)}, "
             f"ours {span(ours)}.", "",
             "| experiment | resolution | M | SD | SD / M | sqrt(SD) / M | ours, boundary | ours, element |",
             "|---|---|---|---|---|---|---|---|"]
    script.write_table(args.out, lines + rows)


if __name__ == "__main__":
    main()
