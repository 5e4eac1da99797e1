"""Baudet Fig. 11 re-made: the cantilever under growing weight, MSS and linear FEM against neo-Hookean FEM."""

import numpy as np
from matplotlib.patches import Polygon, Rectangle

from experiments.baudet import baudet_common as C
from experiments import plotting
from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
COLORS = {"mss_4x1x1": "tab:red", "mss_8x2x2": "tab:orange", "mss_16x4x4": "tab:blue", "mss_32x8x8": "tab:purple",
          "fem_linear": "0.4", "fem_nonlinear": "k"}


def label(m):
    return {"fem_linear": "linear FEM", "fem_nonlinear": "neo-Hookean FEM"}.get(m, "MSS " + m.split("_")[1])


def side(X, u, y0):
    """Edges of the face y = y0 of a box grid, deformed: lines of constant z and of constant x (m)."""
    on = np.isclose(X[:, 1], y0)
    Xs, xs = X[on], X[on] + u[on]
    out = []
    for key, along in ((2, 0), (0, 2)):
        for v in np.unique(np.round(Xs[:, key], 10)):
            sel = np.isclose(Xs[:, key], v)
            order = np.argsort(Xs[sel, along])
            out.append(xs[sel][order])
    return out


def outline(X, u, y0, L, H):
    """The deformed boundary of the face y = y0 (bottom, free end, top reversed, clamp) as a polygon (m)."""
    on = np.isclose(X[:, 1], y0)
    Xs, xs = X[on], X[on] + u[on]
    parts = []
    for key, val, along, rev in ((2, 0.0, 0, False), (0, L, 2, False), (2, H, 0, True), (0, 0.0, 2, True)):
        sel = np.isclose(Xs[:, key], val)
        order = np.argsort(Xs[sel, along])
        parts.append(xs[sel][order[::-1] if rev else order][:, [0, 2]])
    return np.vstack(parts)


def main():
    args = script.args(__doc__)
    ds = C.open_result(INPUTS[0])
    L = float(ds.attrs["length"])
    rho = ds["density"].values
    fig = plotting.figure(figsize=(12.5, 3.9))
    ax1, ax2, ax3 = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1, 1, 1.25]})
    for m in ds.tip_model.values:
        ls = "--" if m == "fem_linear" else "-"
        ax1.plot(rho, 100 * ds["tip_deflection"].sel(tip_model=m) / L, ls, marker="o" if m.startswith("mss") else None,
                 ms=3, color=COLORS.get(str(m)), lw=2.5 if m == "fem_nonlinear" else 1.5, label=label(str(m)))
    for m in ds.model.values:
        ax2.plot(rho, 100 * ds["error"].sel(model=m, reference="nonlinear", stat="max_mean"), marker="o", ms=3,
                 color=COLORS.get(str(m)), ls="--" if m == "fem_linear" else "-", label=label(str(m)) + ", M")
        ax2.plot(rho, 100 * ds["error"].sel(model=m, reference="nonlinear", stat="max_max"), ":", color=COLORS.get(str(m)))
    if "limit_error" in ds:  # the element reading at the largest density only (resolution limit)
        for m, mk in (("mss_8x2x2_element", "s"), ("mss_16x4x4_element", "D"), ("mss_32x8x8_element", "^"),
                      ("mss_32x8x8_element_other_path", "v")):
            if m in ds.limit_model.values:
                ax2.plot([rho[-1]], [100 * float(ds["limit_error"].sel(limit_model=m, reference="nonlinear", stat="max_max"))],
                         mk, ms=6, mfc="none", color=COLORS.get("_".join(m.split("_")[:2]), "k"),
                         label=f"MSS {m.split('_')[1]}, element reading, MAX" + (" (other load path)" if "path" in m else ""))
    for ax in (ax1, ax2):
        for k, txt in (("reading_density", "kg/m³"), ("reading_linear_density", "kg/m"), ("reading_total_mass", "kg")):
            v = float(ds[k])
            ax.axvline(v, color="0.7", lw=0.8)
            # inside the axes, below its top edge, on a white ground: never clipped by the frame nor hidden by a curve
            ax.annotate(f"0.0125 {txt}", (v, 1.0), xycoords=("data", "axes fraction"), xytext=(-1.5, -4),
                        textcoords="offset points", rotation=90, va="top", ha="right", fontsize=7, color="0.3",
                        bbox={"fc": "white", "ec": "none", "alpha": 0.85, "pad": 0.8}, zorder=5, annotation_clip=False)
        ax.set_xscale("log")
        plotting.label_log_axis(ax, "x")
        ax.set_xlabel("density of the beam (kg/m³)")
        ax.grid(alpha=0.3, which="both")
    ax1.set_ylabel("tip deflection / length (%)")
    ax1.set_title("tip deflection")
    ax1.legend(fontsize=7)
    ax2.set_yscale("log")
    plotting.label_log_axis(ax2, "y")
    ax2.set_ylabel("error vs neo-Hookean FEM (%)\nsolid/dashed: mean M, dotted: MAX")
    ax2.set_title("per-node error / largest displacement")
    ax2.legend(fontsize=7)
    if "rest_fem_nonlinear" in ds:
        Xr = ds["rest_fem_nonlinear"].values
        T, Lx, H = Xr[:, 1].max(), Xr[:, 0].max(), Xr[:, 2].max()
        for name, style in (("fem_nonlinear", {"fc": "0.8", "ec": "k", "lw": 1.0, "label": "neo-Hookean FEM"}),
                            ("fem_linear", {"fill": False, "ec": "0.3", "ls": "--", "lw": 1.0, "label": "linear FEM"})):
            ax3.add_patch(Polygon(outline(Xr, ds[f"displacement_{name}"].values, T, Lx, H) * 1e3, closed=True, **style))
        X, u = ds["rest_mss"].values, ds["displacement_mss"].values
        for i, line in enumerate(side(X, u, X[:, 1].max())):
            ax3.plot(line[:, 0] * 1e3, line[:, 2] * 1e3, color="tab:red", lw=1.0,
                     label=f"MSS {ds.attrs['shape_mss']}" if i == 0 else None)
        ax3.add_patch(Rectangle((0, 0), Lx * 1e3, H * 1e3, fill=False, ec="0.6", ls=":", label="rest"))
        ax3.autoscale_view()
        ax3.set_aspect("equal")
        ax3.set_xlabel("x (mm)")
        ax3.set_ylabel("z (mm)")
        ax3.set_title(f"side view at density {float(rho[-1]):g} kg/m³", fontsize=9)
        ax3.legend(fontsize=7, loc="lower left")
        ax3.grid(alpha=0.3)
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
