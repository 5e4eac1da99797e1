"""Golec Fig. 2 (3-4): cantilever beam under gravity, side view (xz), and the wrinkle of the
classical MSS without face diagonals near the clamp (difference to its symmetric equilibrium)."""

import numpy as np

from experiments import script
from experiments.golec.wrinkle_states import positions_dataset, study_state
from experiments import plotting
from msslib.results import read_result

R = "results/golec/beam"
INPUTS = ["results/golec/beam/default__fem.nc", "results/golec/beam/default__golec.nc",
          "results/golec/beam/default__mss_classical.nc", "results/golec/beam/default__golec_published.nc",
          "results/golec/studies/wrinkles.nc"]
AMPLIFY = 20.0


def main():
    args = script.args(__doc__)
    fem, golec, classical, published = (read_result(p) for p in INPUTS[:4])
    w = read_result(INPUTS[-1])
    wrinkled = study_state(w, "beam", "wrinkled")
    fig = plotting.figure(figsize=(13, 7.4))
    grid = fig.add_gridspec(2, 2, width_ratios=[1.4, 1], height_ratios=[1.15, 1])
    ax1, ax2, ax3 = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1]), fig.add_subplot(grid[1, :])
    plotting.deformed_mesh(ax1, fem, deformed=False, color="0.8", plane="xz", linewidth=0.5, label="rest")
    plotting.deformed_mesh(ax1, fem, color="k", plane="xz", linewidth=1.2, label="neo-Hookean FEM")
    plotting.deformed_mesh(ax1, golec, color="tab:red", plane="xz", label="Golec MSS, derived, with correction")
    plotting.deformed_mesh(ax1, wrinkled, color="tab:blue", plane="xz", label="classical MSS without face diagonals (wrinkled)")
    plotting.deformed_mesh(ax1, classical, color="tab:green", plane="xz", label="classical MSS, printed springs")
    plotting.deformed_mesh(ax1, published, color="tab:orange", plane="xz", linewidth=0.6, label="Golec MSS, printed constants")
    ax1.set_aspect("equal")
    ax1.legend(loc="lower left", fontsize=7)
    ax1.set_title("Beam under gravity (deformations to scale)")
    # the wrinkle: wrinkled minus symmetric equilibrium, amplified, on the symmetric shape
    rest = w["beam_rest"].values
    sym, wr = w["beam_symmetric"].values, w["beam_wrinkled"].values
    amp = sym + AMPLIFY * (wr - sym)
    near = rest[:, 0] <= 0.08 + 1e-9
    cells = w["beam_cells"].values
    keep = near[cells].all(axis=1)
    remap = -np.ones(len(rest), dtype=int)
    remap[near] = np.arange(near.sum())
    cells_near = remap[cells[keep]]
    plotting.deformed_mesh(ax2, positions_dataset(rest[near], sym[near], cells_near), color="0.6", plane="xz",
                           label="symmetric equilibrium (unstable)")
    plotting.deformed_mesh(ax2, positions_dataset(rest[near], amp[near], cells_near), color="tab:blue", plane="xz",
                           label=f"wrinkled equilibrium, difference x{AMPLIFY:g}")
    diff = wr - sym
    amp_m = float(w.wrinkle_amplitude.sel(experiment="beam", variant="mss_no_face"))
    if not np.isfinite(amp_m):
        amp_m = float(np.abs(diff).max())
    found = amp_m > 1e-9
    ax2.set_title(f"No face diagonals, first 8 cm, difference x{AMPLIFY:g}", fontsize=10)
    ax2.set_aspect("equal")
    ax2.legend(loc="lower left", fontsize=7)
    # the wrinkle as a profile: wrinkled minus symmetric vertical position along the front edges
    front = np.isclose(rest[:, 1], rest[:, 1].min())
    zs = np.unique(np.round(rest[front, 2], 12))
    for z0, colour, name in ((zs.max(), "tab:blue", "top"), (zs[len(zs) // 2], "tab:purple", "mid-height"),
                             (zs.min(), "tab:cyan", "bottom")):
        line = np.flatnonzero(front & np.isclose(rest[:, 2], z0))
        line = line[np.argsort(rest[line, 0])]
        ax3.plot(rest[line, 0] * 1e2, diff[line, 2] * 1e3, "o-", color=colour, ms=4,
                 label=f"{name} edge, z = {z0 * 1e2:g} cm")
    ax3.axhline(0.0, color="0.5", lw=0.8, label="symmetric equilibrium (no wrinkle)")
    ax3.set_xlabel("x along the beam, from the clamp (cm)")
    ax3.set_ylabel("wrinkled - symmetric\nvertical position (mm)")
    ax3.grid(alpha=0.3)
    ax3.legend(loc="best", fontsize=8)
    ax3.set_title("Wrinkle profile, classical MSS without face diagonals (true scale, front face y = 0): "
                  + (f"largest node difference {amp_m * 1e3:.2g} mm" if found
                     else "no wrinkled equilibrium found in this build (difference 0)"), fontsize=10)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
