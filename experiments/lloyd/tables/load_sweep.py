"""Lloyd et al. Sec. 5: published errors beside ours at a small load and at the stated deformation."""

from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script

ROOT = Path(__file__).resolve().parents[3]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def main(argv=None):
    args = script.args(__doc__, argv)
    ds = xr.load_dataset(ROOT / INPUTS[0])
    small = 100 * float(ds.attrs["small_deformation"])

    def pc(a, b):
        return f"{100 * a:.3g}" if np.isclose(a, b) else f"{100 * a:.3g}-{100 * b:.3g}"

    lines = script.head(
        (f"**Lloyd Sec. 5: error against load** (max and mean node distance MSS - reference; ours at "
         f"{small:g} % deformation and at the end of the sweep, the largest deformation the paper states "
         "(where the solvers allow); "
         "deformation: mean top-face displacement along the load over the height, linear FEM; "
         "mean/max does not depend on the load where the error is proportional to a power of it)"),
        ["Sec.", "experiment", "case", "variant", "stated deformation (%)", "published max (mm)", "published mean/max",
         f"ours max at {small:g} % (mm)", f"ours mean/max at {small:g} %", "load at the end (Pa)",
         "ours max at the end (mm)", "ours mean/max at the end", "ours / published max"])
    num = script.number
    for r in script.rows(ds, "run"):
        lo, hi = float(r.stated_low), float(r.stated_high)
        if float(r.end_at_file_load) and not np.isfinite(hi):  # the sweep's end is the file load's deformation: not run
            stated = f"> {100 * lo:.3g}; not run in this build"
        elif float(r.end_at_file_load):  # the sweep ends at the file's load (a solver limit), not at a stated value
            stated = f"> {100 * lo:.3g}; sweep to {100 * hi:.3g}" if lo < hi else f"{100 * lo:.3g}; MSS fails beyond {100 * hi:.3g}"
        else:
            stated = pc(lo, hi)
        lines.append(script.row(
            r.section.values, r.experiment.values, r.case.values, r.variant.values, stated,
            num(r.published_max, ".3g", 1e3), num(r.published_ratio, ".2f"), num(r.error_max_small, ".2g", 1e3),
            num(r.ratio_small, ".2f"), num(r.load_stated, ".0f"), num(r.error_max_stated, ".3g", 1e3),
            num(r.ratio_stated, ".2f"), num(r.max_over_published, ".2f")))
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
