"""Golec Fig. 2 (3-4): cantilever beam under gravity, side view (xz), and the wrinkle of the
classical MSS without face diagonals near the clamp (difference to its symmetric equilibrium)."""

import argparse
import sys
from pathlib import Path

import numpy as np

from msslib import plotting
from msslib.io import read_result

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from wrinkle_states import positions_dataset, study_state  # noqa: E402,F401

R = "results/golec/beam"
INPUTS = ["results/golec/beam/default__fem.nc", "results/golec/beam/default__golec.nc",
          "results/golec/beam/default__mss_classical.nc", "results/golec/beam/default__golec_published.nc",
          "results/golec/studies/wrinkles.nc"]
AMPLIFY = 20.0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    fem, golec, classical, published = (read_result(p) for p in INPUTS[:4])
    w = read_result(INPUTS[-1])
    wrinkled = study_state(w, "beam", "wrinkled")
    fig = plotting.figure(figsize=(13, 4.2))
    ax1, ax2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.4, 1]})
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
    amp_mm = float(w.wrinkle_amplitude.sel(experiment="beam", variant="mss_no_face")) * 1e3
    ax2.set_title(f"No face diagonals, first 8 cm: wrinkle amplitude {amp_mm:.2g} mm")
    ax2.set_aspect("equal")
    ax2.legend(loc="lower left", fontsize=7)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
