"""Golec Fig. 2 (1-2): the 5 cm cube compressed by 10 % (clamped faces), side view (xz plane)."""

import numpy as np

from experiments import script
from experiments.golec.wrinkle_states import study_state
from experiments import plotting
from msslib.results import read_result

R = "results/golec/compression"
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def main():
    args = script.args(__doc__)
    w = read_result(INPUTS[-1])
    wr = w.sel(experiment="compression")
    panels = [
        (study_state(w, "compression", "wrinkled"), "mss_no_face", "classical MSS, no face diagonals\n(wrinkled equilibrium)"),
        (read_result(INPUTS[0]), "mss_classical", "classical MSS (printed springs,\nno correction)"),
        (read_result(INPUTS[1]), "golec", "Golec MSS, derived constants\nwith correction forces"),
        (read_result(INPUTS[2]), "golec_published", "Golec MSS, printed constants\nwith correction forces"),
        (read_result(INPUTS[3]), "fem", "neo-Hookean FEM (hex8, locks)"),
    ]
    fig = plotting.figure(figsize=(15, 3.6))
    axes = fig.subplots(1, len(panels), sharey=True)
    for ax, (ds, var, title) in zip(axes, panels):
        plotting.deformed_mesh(ax, ds, deformed=False, color="0.75", plane="xz", linewidth=0.5, label="rest")
        plotting.deformed_mesh(ax, ds, color="tab:red" if var != "fem" else "k", plane="xz", label="deformed")
        r = wr.sel(variant=var)
        vol = float(r.volume_wrinkled if var == "mss_no_face" and np.isfinite(r.volume_wrinkled) else r.volume_symmetric)
        ax.set_title(f"{title}\nV = {vol * 1e6:.2f} cm$^3$", fontsize=9)
        ax.set_aspect("equal")
    axes[0].legend(loc="lower left", fontsize=7)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
