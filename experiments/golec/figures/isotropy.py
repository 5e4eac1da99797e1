"""Effective Poisson's ratio and shear moduli of the Golec lattice against A (isotropy study)."""

import argparse

from msslib import plotting
from msslib.io import read_result

INPUTS = ["results/golec/studies/isotropy.nc"]
LABELS = {"derived": "derived constants", "published": "printed constants, per element",
          "printed_totals": "printed constants as interior totals"}
COLORS = {"derived": "tab:red", "published": "tab:blue", "printed_totals": "tab:green"}
STYLES = {"nu0.3": "-", "nu0.4999": "--"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    ds = read_result(INPUTS[0])
    fig = plotting.figure(figsize=(13, 4))
    ax1, ax2, ax3 = fig.subplots(1, 3)
    A = ds.A.values
    for m in ds.material.values:
        nu_t = float(ds.nu_target.sel(material=m))
        for c in ds.constants.values:
            r = ds.sel(material=m, constants=c)
            kw = dict(color=COLORS[str(c)], ls=STYLES[str(m)], marker="o", ms=3)
            ax1.plot(A, r.nu_eff, label=f"{LABELS[str(c)]}, target nu = {nu_t:g}", **kw)
            ax2.plot(A, r.G_ratio, **kw)
            ax3.plot(A, r.G45_ratio, **kw)
        ax1.axhline(nu_t, color="0.5", lw=0.8, ls=STYLES[str(m)])
    for ax in (ax2, ax3):
        ax.axhline(1.0, color="0.5", lw=0.8)
    for ax in (ax1, ax2, ax3):
        ax.set_xscale("log", base=2)
        ax.set_xlabel("A = k_inner / k_face (-)")
    ax1.set_ylabel("effective Poisson's ratio (-)")
    ax2.set_ylabel("G = C44 / target G (-)")
    ax3.set_ylabel("G45 = (C11 - C12)/2 / target G (-)")
    ax1.set_title("uniaxial stress")
    ax2.set_title("simple shear along the cube axes")
    ax3.set_title("pure shear along the face diagonals")
    ax1.legend(fontsize=6.5, loc="best")
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
