"""Lloyd's tetrahedral MSS under refinement and along large-deformation load paths.

a) maximum error against the number of nodes: the MSS linearised at rest against linear FEM on the
same mesh (falls), and the full-load MSS against neo-Hookean FEM on the same mesh (flat) and on the
reference mesh (rises: the coarse-mesh error of the reference cancels part of the MSS's own);
b) per-element fit residual and radius ratio against refinement (flat: the meshes do not get worse);
c) fit residual per element against its radius ratio; d) the element strain error of the linearised MSS
against the radius ratio; e) error against the load factor in shear, circles mark MSS states with
inverted (folded) cells; f) the hole cylinder under 1800 Pa compression and g) the cone under 2000 Pa
shear along the load.

    python -m experiments.lloyd.figures.tet_refinement --out paper/figures/lloyd_tet_refinement
"""

from pathlib import Path

import numpy as np
import xarray as xr

from experiments import script
from experiments import plotting

ROOT = Path(__file__).resolve().parents[3]
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
LEVEL_COLORS = ["tab:blue", "tab:orange", "tab:green", "tab:purple"]


def main(argv=None):
    args = script.args(__doc__, argv)
    ds = xr.load_dataset(ROOT / INPUTS[0])
    n = ds.n_nodes.values
    fig = plotting.figure(figsize=(17.5, 7.6))
    ax = fig.subplots(2, 4).ravel()
    ax[7].set_axis_off()

    a = ax[0]
    a.plot(n, 100 * ds.lin_same_max.sel(case="shear"), "o-", color="tab:blue", label="linearised MSS vs linear FEM, same mesh (shear)")
    a.plot(n, 100 * ds.lin_same_max.sel(case="stretch"), "s-", color="tab:cyan", label="linearised MSS vs linear FEM, same mesh (stretch)")
    a.plot(n, 100 * ds.nl_mss_same_max, "o-", color="tab:red", label="MSS vs neo-Hookean, same mesh (full shear)")
    a.plot(n, 100 * ds.nl_mss_ref_max, "o--", color="darkred",
           label=f"MSS vs neo-Hookean, h = {ds.attrs['h_nonlinear_reference_mm']:g} mm (full shear)")
    a.plot(n, 100 * ds.nl_nh_ref_max, "^:", color="k",
           label=f"neo-Hookean vs the same, h = {ds.attrs['h_nonlinear_reference_mm']:g} mm")
    a.set_xscale("log")
    plotting.label_log_axis(a, "x")
    a.set_xlabel("nodes of the cylinder mesh")
    a.set_ylabel("max node error / max reference displacement (%)")
    a.set_ylim(bottom=0)
    a.set_title("a) error against refinement")
    a.legend(fontsize=6.5)

    b = ax[1]
    b.plot(n, ds.fit_lloyd_median, "o-", color="tab:red", label="eq. 12-13, median")
    b.plot(n, ds.fit_lloyd_p90, "o--", color="tab:red", label="eq. 12-13, 90th percentile")
    b.plot(n, ds.fit_best6_median, "s-", color="tab:green", label="best six constants per element, median")
    b.plot(n, ds.rho_median, "^-", color="k", label="radius ratio, median")
    b.plot(n, ds.rho_min, "v:", color="k", label="radius ratio, smallest")
    b.set_xscale("log")
    plotting.label_log_axis(b, "x")
    b.set_xlabel("nodes of the cylinder mesh")
    b.set_ylabel(r"$\|K_{MSS} - K_{FEM}\|_F / \|K_{FEM}\|_F$ per element; radius ratio")
    b.set_ylim(0, 1.05)
    b.set_title("b) per-element fit and mesh quality")
    b.legend(fontsize=6.5)

    c = ax[2]
    lev = ds.element_level.values.astype(int)
    for j in np.unique(lev)[::-1]:
        m = lev == j
        c.scatter(ds.element_rho.values[m], ds.element_fit_lloyd.values[m], s=3, alpha=0.35, color=LEVEL_COLORS[j % 4],
                  label=f"h = {float(ds.h[j]):g} mm ({int(ds.n_cells[j])} tetrahedra)")
    c.axhline(0.2, color="k", ls=":", lw=1, label="regular tetrahedron (0.2)")
    c.set_xlabel("radius ratio 3 r_in / r_circ (1 = regular)")
    c.set_ylabel(r"$\|K_{MSS} - K_{FEM}\|_F / \|K_{FEM}\|_F$ (eq. 12-13)")
    c.set_title("c) fit residual against element quality")
    c.legend(fontsize=6.5, markerscale=3)

    g = ax[3]
    for j in np.unique(lev)[::-1]:
        m = lev == j
        g.scatter(ds.element_rho.values[m], ds.element_strain_error.values[m], s=3, alpha=0.35, color=LEVEL_COLORS[j % 4],
                  label=f"h = {float(ds.h[j]):g} mm, rank correlation {float(ds.spearman_strain_rho[j]):.2f}")
    g.set_yscale("log")
    plotting.label_log_axis(g, "y")
    g.set_xlabel("radius ratio 3 r_in / r_circ (1 = regular)")
    g.set_ylabel("element strain error / RMS FEM strain")
    g.set_title("d) local error (linearised, shear) vs quality")
    g.legend(fontsize=6.5, markerscale=3)

    d = ax[4]
    for j in range(ds.sizes["level"]):
        d.plot(ds["load"].values, 100 * ds.path_mss_same_max.isel(level=j), "o-", color=LEVEL_COLORS[j % 4],
               label=f"h = {float(ds.h[j]):g} mm ({int(n[j])} nodes)")
    for j in range(ds.sizes["level"]):
        d.plot([0.0], [100 * float(ds.lin_same_max.sel(case="shear").isel(level=j))], "x", color=LEVEL_COLORS[j % 4], ms=8)
        inv = ds.path_mss_inverted.isel(level=j).values > 0
        d.plot(ds["load"].values[inv], 100 * ds.path_mss_same_max.isel(level=j).values[inv], "o", mfc="none", mec="k",
               ms=11, label="MSS state with inverted cells")
    plotting.unique_legend(d, fontsize=7)
    d.set_xlabel(f"load factor (1 = shear traction {ds.attrs['shear_traction']:g} Pa)")
    d.set_ylabel("max error MSS vs neo-Hookean, same mesh (%)")
    d.set_ylim(bottom=0)
    d.set_title("e) error along the shear load (x: linearised MSS)")

    for axis, name, title in ((ax[5], "hole", "f) hole cylinder, 1800 Pa compression"),
                              (ax[6], "cone", "g) cone, 2000 Pa shear")):
        load = ds[f"{name}_load"].values
        axis.plot(load, ds[f"{name}_min_jacobian"], "o-", color="tab:blue", label="smallest relative Jacobian")
        axis.plot(load, 1e3 * ds[f"{name}_eig"], "s-", color="tab:red", label=r"smallest tangent eigenvalue / mean diagonal ($\times 10^3$)")
        axis.axhline(0.0, color="k", lw=0.8)
        failed = float(ds[f"{name}_failed_load"])
        if np.isfinite(failed):
            axis.axvline(failed, color="k", ls="--", lw=1, label=f"Newton fails at {failed:g}")
        tw = axis.twinx()
        tw.plot(load, ds[f"{name}_inverted"], "^:", color="tab:green", label="inverted cells (right axis)")
        tw.set_ylabel("inverted cells", color="tab:green")
        tw.set_ylim(bottom=0, top=max(1.0, float(np.nanmax(ds[f"{name}_inverted"]))) * 1.15)
        axis.set_xlabel("load factor")
        axis.set_ylabel("relative Jacobian; eigenvalue ratio")
        axis.set_title(title)
        (h1, l1), (h2, l2) = axis.get_legend_handles_labels(), tw.get_legend_handles_labels()
        plotting.unique_legend(axis, [*h1, *h2], [*l1, *l2], fontsize=6.5, loc="lower left")
    plotting.save(fig, args.out)


if __name__ == "__main__":
    main()
