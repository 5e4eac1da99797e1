"""Lloyd et al. Secs. 5.1 and 5.3: the ratio mean/max error under one changed factor at a time."""

from pathlib import Path

import xarray as xr

from experiments import script

ROOT = Path(__file__).resolve().parents[3]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
SHORT = {"baseline": "nothing (the experiment file)", "equal_forces": "equal nodal forces",
         "mss_strain": "load from the MSS strain", "flipped": "mesh upside down",
         "flipped_equal_forces": "mesh upside down, equal forces", "counts_mesh": "mesh with 39 nodes, 92 springs", "cst_slash": "reference CST, diagonals up",
         "cst_backslash": "reference CST, diagonals down", "cst_crossed": "reference CST, both diagonals",
         "q1_one_point": "reference Q1, one-point quadrature"}


def main(argv=None):
    args = script.args(__doc__, argv)
    ds = xr.load_dataset(ROOT / INPUTS[0])
    lines = script.head(
        ("**Lloyd Secs. 5.1 and 5.3: what sets the ratio mean/max error** (one factor changed at a time "
         "from the experiment files' set-up; strains along the load at the top corner node and in the middle "
         "of the top edge; the paper: 11.2-13.6 % at these two points in Fig. 9a; CST: the squares split into "
         "constant-strain triangles along one diagonal, up = lower left to upper right, or both; Q1 one-point: "
         "bilinear quads integrated at their centre, the constant strain rectangle)"),
        ["Sec.", "case", "changed", "load (Pa)", "strain corner / middle, FEM (%)", "ours max (mm)", "ours mean/max",
         "published max (mm)", "published mean/max", "ours - published, mean/max"])
    for r in script.rows(ds, "run"):
        lines.append(script.row(
            r.section.values, r.case.values, SHORT.get(str(r.factor.values), str(r.factor.values)), f"{float(r['load']):.0f}",
            f"{100 * float(r.corner_fem):.1f} / {100 * float(r.middle_fem):.1f}", f"{1e3 * float(r.error_max):.3g}",
            f"{float(r.ratio):.2f}", f"{1e3 * float(r.published_max):.3g}", f"{float(r.published_ratio):.2f}",
            f"{float(r.ratio) - float(r.published_ratio):+.2f}"))
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
