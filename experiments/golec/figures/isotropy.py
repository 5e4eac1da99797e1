"""Effective Poisson's ratio and shear moduli of the Golec lattice against A (isotropy study)."""

import matplotlib.ticker
from matplotlib.lines import Line2D

from experiments import script
from experiments import plotting
from msslib.results import read_result

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
LABELS = {"derived": "derived constants", "published": "printed constants, per element",
          "printed_totals": "printed constants as interior totals"}
COLORS = {"derived": "tab:red", "published": "tab:blue", "printed_totals": "tab:green"}
STYLES = {"nu0.3": "-", "nu0.4999": "--"}


def main():
    args = script.args(__doc__)
    ds = read_result(INPUTS[0])
    fig = plotting.figure(figsize=(13, 4))
    ax1, ax2, ax3 = fig.subplots(1, 3)
    A = ds.A.values
    for m in ds.material.values:
        nu_t = float(ds.nu_target.sel(material=m))
        for c in ds.constants.values:
            r = ds.sel(material=m, constants=c)
            kw = dict(color=COLORS[str(c)], ls=STYLES[str(m)], marker="o", ms=3)
            ax1.plot(A, r.nu_eff, **kw)
            ax2.plot(A, r.G_ratio, **kw)
            ax3.plot(A, r.G45_ratio, **kw)
        ax1.axhline(nu_t, color="0.5", lw=0.8, ls=STYLES[str(m)])
    for ax in (ax2, ax3):
        ax.axhline(1.0, color="0.5", lw=0.8)
    for ax in (ax1, ax2, ax3):
        ax.set_xscale("log", base=2)
        ax.set_xticks(A, [f"{a:g}" for a in A])  # the sampled values, as plain numbers
        ax.xaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        ax.set_xlabel("A = k_inner / k_face (-)")
    ax1.set_ylabel("effective Poisson's ratio (-)")
    ax2.set_ylabel("G = C44 / target G (-)")
    ax3.set_ylabel("G45 = (C11 - C12)/2 / target G (-)")
    ax1.set_title("uniaxial stress")
    ax2.set_title("simple shear along the cube axes")
    ax3.set_title("pure shear along the face diagonals")
    # one entry per colour (constants) and per line style (material) drawn, and the target lines
    handles = [Line2D([], [], color=COLORS[str(c)], marker="o", ms=3, label=LABELS[str(c)]) for c in ds.constants.values]
    handles += [Line2D([], [], color="k", ls=STYLES[str(m)],
                       label=f"target nu = {float(ds.nu_target.sel(material=m)):g}") for m in ds.material.values]
    handles.append(Line2D([], [], color="0.5", lw=0.8, label="target value (grey)"))
    fig.legend(handles=handles, loc="outside upper center", ncol=len(handles), frameon=False, fontsize=8)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
