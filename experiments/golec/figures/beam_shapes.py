"""Golec Fig. 2 (3-4): cantilever beam under gravity, side view (xz), the deflection of every variant
along the beam and its difference to the FEM's, and the wrinkle of the classical MSS without face
diagonals near the clamp (difference to its symmetric equilibrium, vertical and horizontal)."""

import numpy as np

from experiments import script
from experiments.golec.wrinkle_states import positions_dataset, study_state
from experiments import plotting
from msslib.results import read_result

R = "results/golec/beam"
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
AMPLIFY = 20.0
#: how each variant is drawn in every panel: colour, line style, marker, line width
STYLE = {
    "fem": ("k", "-", "s", 1.6),
    "golec": ("tab:red", "--", "o", 1.2),
    "no_face": ("tab:blue", ":", "^", 1.6),
    "classical": ("tab:green", "-", "D", 1.0),
    "published": ("tab:orange", "-.", "v", 1.0),
}
LABELS = {
    "fem": "neo-Hookean FEM (reference)",
    "golec": "Golec MSS, derived, with correction",
    "no_face": "classical MSS without face diagonals (wrinkled)",
    "classical": "classical MSS, printed springs",
    "published": "Golec MSS, printed constants",
}


def centreline(rest):
    """Nodes on the beam's axis (middle y and z), ordered along x."""
    ys, zs = np.unique(np.round(rest[:, 1], 12)), np.unique(np.round(rest[:, 2], 12))
    line = np.flatnonzero(np.isclose(rest[:, 1], ys[len(ys) // 2]) & np.isclose(rest[:, 2], zs[len(zs) // 2]))
    return line[np.argsort(rest[line, 0])]


def edge_lines(rest):
    """The top, mid-height and bottom edges of the front face y = min, ordered along x."""
    front = np.isclose(rest[:, 1], rest[:, 1].min())
    zs = np.unique(np.round(rest[front, 2], 12))
    out = []
    for z0, colour, name in ((zs.max(), "tab:blue", "top"), (zs[len(zs) // 2], "tab:purple", "mid-height"),
                             (zs.min(), "tab:cyan", "bottom")):
        line = np.flatnonzero(front & np.isclose(rest[:, 2], z0))
        out.append((line[np.argsort(rest[line, 0])], colour, f"{name} edge, z = {z0 * 1e2:g} cm"))
    return out


def main():
    args = script.args(__doc__)
    fem, golec, classical, published = (read_result(p) for p in INPUTS[:4])
    w = read_result(INPUTS[-1])
    wrinkled = study_state(w, "beam", "wrinkled")
    states = {"fem": fem, "golec": golec, "no_face": wrinkled, "classical": classical, "published": published}
    fig = plotting.figure(figsize=(13, 11.5))
    grid = fig.add_gridspec(3, 2, width_ratios=[1.4, 1], height_ratios=[1.15, 0.9, 0.9])
    ax1, ax2 = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[0, 1])
    ax3, ax4 = fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1])
    ax5, ax6 = fig.add_subplot(grid[2, 0]), fig.add_subplot(grid[2, 1])
    # a) the shapes to scale, one line style per variant
    plotting.deformed_mesh(ax1, fem, deformed=False, color="0.8", plane="xz", linewidth=0.5, label="rest")
    for key, ds in states.items():
        colour, ls, _, lw = STYLE[key]
        lc = plotting.deformed_mesh(ax1, ds, color=colour, plane="xz", linewidth=lw, label=LABELS[key])
        lc.set_linestyle(ls)
    ax1.set_aspect("equal")
    ax1.legend(loc="lower left", fontsize=7)
    ax1.set_title("a) Beam under gravity (to scale); FEM, derived and no-face curves overlap: see c, d", fontsize=10)
    # b) the wrinkle: wrinkled minus symmetric equilibrium, amplified, on the symmetric shape
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
    ax2.set_title(f"b) No face diagonals, first 8 cm, difference x{AMPLIFY:g}", fontsize=10)
    ax2.set_aspect("equal")
    ax2.legend(loc="lower left", fontsize=7)
    # c) deflection along the axis, d) its difference to the FEM's (the variants with derived constants)
    w_fem = None
    zoom = ax3.inset_axes([0.07, 0.33, 0.3, 0.27])  # the printed pair near the tip
    for key, ds in states.items():
        X = ds["rest_position"].values
        u = ds["displacement"].transpose(..., "node", "axis").values
        line = centreline(X)
        x_cm, dz = X[line, 0] * 1e2, u[line, 2]
        if key == "fem":
            w_fem = dz
        colour, ls, marker, lw = STYLE[key]
        every = (1, 2) if key in ("no_face", "published") else (0, 2)  # overlapping pairs: markers on alternate nodes
        ax3.plot(x_cm, -dz * 1e2, color=colour, ls=ls, marker=marker, ms=4, lw=lw, markevery=every, label=LABELS[key])
        zoom.plot(x_cm, -dz * 1e2, color=colour, ls=ls, marker=marker, ms=4, lw=lw)
        if key in ("fem", "golec", "no_face"):
            ax4.plot(x_cm, (dz - w_fem) * 1e3, color=colour, ls=ls, marker=marker, ms=4, lw=lw, label=LABELS[key])
    ax3.set_xlabel("x along the beam, from the clamp (cm)")
    ax3.set_ylabel("deflection of the axis (cm)")
    ax3.set_title("c) Deflection of the beam's axis", fontsize=10)
    ax3.grid(alpha=0.3)
    ax3.legend(loc="upper left", fontsize=7)
    zoom.set_xlim(16.5, 20.3)
    zoom.set_ylim(0.85, 1.2)
    zoom.set_title("printed constants, tip", fontsize=7)
    zoom.tick_params(labelsize=7)
    zoom.grid(alpha=0.3)
    ax3.indicate_inset_zoom(zoom, edgecolor="0.5")
    ax4.set_xlabel("x along the beam, from the clamp (cm)")
    ax4.set_ylabel("vertical position minus\nthe FEM's, on the axis (mm)")
    ax4.set_title("d) Difference to the FEM, derived constants", fontsize=10)
    ax4.grid(alpha=0.3)
    ax4.legend(loc="upper left", fontsize=7)
    # e, f) the wrinkle as a profile: wrinkled minus symmetric position along the front edges
    diff = wr - sym
    amp_m = float(w.wrinkle_amplitude.sel(experiment="beam", variant="mss_no_face"))
    if not np.isfinite(amp_m):
        amp_m = float(np.abs(diff).max())
    found = amp_m > 1e-9
    for line, colour, name in edge_lines(rest):
        ax5.plot(rest[line, 0] * 1e2, diff[line, 2] * 1e3, "o-", color=colour, ms=4, label=name)
        ax6.plot(rest[line, 0] * 1e2, diff[line, 0] * 1e3, "o-", color=colour, ms=4, label=name)
    status = (f"largest node difference {amp_m * 1e3:.2g} mm" if found
              else "no wrinkled equilibrium found in this build (difference 0)")
    for ax, comp, tag in ((ax5, "vertical (z)", "e"), (ax6, "horizontal (x)", "f")):
        ax.axhline(0.0, color="0.5", lw=0.8, label="symmetric equilibrium (no wrinkle)")
        ax.set_xlabel("x along the beam, from the clamp (cm)")
        ax.set_ylabel(f"wrinkled - symmetric,\n{comp} (mm)")
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=7)
        ax.set_title(f"{tag}) Wrinkle, {comp} component, front face y = 0 (true scale)", fontsize=10)
    fig.suptitle("Wrinkle of the classical MSS without face diagonals (b, e, f): " + status, fontsize=10)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
