"""Baudet Fig. 5: signed error of Poisson's ratio against the axial strain, with the +-5 % band, under
the boundary and the element reading of the correction force."""

import matplotlib.ticker

from experiments.baudet import baudet_common as C
from experiments import plotting
from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
BAND = 5.0  # %, the tolerance drawn


def main():
    args = script.args(__doc__)
    ds = C.open_result(INPUTS[0])
    panels = C.CUBE_PANELS
    fig = C.curves(ds["nu_error_by_reading"], ds["strain"].values, xlabel="axial strain (%)",
                   ylabel="nu error, (nu_MSS - nu)/nu (%)", panels=panels,
                   dashed={"beam of 4x4x12 cubes": {"geometry": "beam"}})
    fig.set_size_inches(fig.get_size_inches()[0], 4.4)
    lo = min(ax.get_ylim()[0] for ax in fig.axes)
    hi = max(ax.get_ylim()[1] for ax in fig.axes)
    ticks = [t for t in (-200, -100, -50, -20, -10, -5, 0, 5, 10, 20, 50, 100, 200) if lo <= t <= hi]
    for ax in fig.axes:
        # signed log scale: linear within +-5 % (the band is readable), logarithmic beyond
        ax.set_yscale("symlog", linthresh=5.0, linscale=0.6)
        ax.set_ylim(lo, hi)  # one scale for all panels
        ax.set_yticks(ticks, [f"{t:g}" for t in ticks])
        ax.yaxis.set_minor_locator(matplotlib.ticker.NullLocator())
        ax.axhspan(-BAND, BAND, color="0.9", zorder=0)
        ax.axhline(0.0, color="0.4", lw=0.6, zorder=0)
        for sign in (1, -1):
            ax.axhline(sign * BAND, color="k", ls=":", lw=1.0, zorder=1)
            ax.annotate(f"{sign * BAND:+g} %", (0.0, sign * BAND), xycoords=("axes fraction", "data"),
                        xytext=(3, 1 if sign > 0 else -1), textcoords="offset points", ha="left",
                        va="bottom" if sign > 0 else "top", fontsize=8)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
