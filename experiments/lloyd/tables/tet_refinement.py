"""Lloyd's tetrahedral MSS under refinement (per level) and along the load paths of the hole
cylinder and the cone."""

import numpy as np

from experiments import script
from msslib.results import read_result

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def _pct(v):
    return script.number(v, ".1f", 100, "n/a")


def main():
    args = script.args(__doc__)
    ds = read_result(INPUTS[0])
    h_nl, h_lin = ds.attrs["h_nonlinear_reference_mm"], ds.attrs["h_linear_reference_mm"]
    caption = (
        f"**The cylinder under refinement** (radius 1 cm, height 2 cm, E = {ds.attrs['E'] / 1e3:g} kPa, nu = {ds.attrs['nu']:g}; "
        f"shear {ds.attrs['shear_traction']:g} Pa, stretch {ds.attrs['stretch_traction']:g} Pa on the top face). Errors are the "
        "largest node distance over the largest reference displacement, in %. *Linearised*: the MSS tangent at rest against "
        f"linear FEM on the same mesh (and on h = {h_lin:g} mm). *Full shear*: the non-linear MSS against neo-Hookean FEM on "
        f"the same mesh and on h = {h_nl:g} mm, and that FEM's own discretisation error. Fit: median over elements of "
        "||K_mss - K_fem||_F / ||K_fem||_F (0.2 for a regular tetrahedron).")
    lines = script.head(caption, [
        "h (mm)", "nodes", "tetrahedra", "radius ratio median (min)", "smallest dihedral (deg)",
        "fit eq. 12-13 (best 6 springs)", "linearised shear / stretch, same mesh", "linearised shear vs fine",
        "full shear, same mesh", "full shear vs reference", "neo-Hookean vs reference"])
    for r in script.rows(ds, "level"):
        lines.append(script.row(
            f"{float(r.h):g}", int(r.n_nodes), int(r.n_cells), f"{float(r.rho_median):.2f} ({float(r.rho_min):.2f})",
            f"{float(r.dihedral_min):.1f}", f"{float(r.fit_lloyd_median):.2f} ({float(r.fit_best6_median):.2f})",
            f"{_pct(r.lin_same_max.sel(case='shear'))} / {_pct(r.lin_same_max.sel(case='stretch'))}",
            _pct(r.lin_ref_max.sel(case='shear')), _pct(r.nl_mss_same_max), _pct(r.nl_mss_ref_max),
            _pct(r.nl_nh_ref_max)))
    published_note = ("Published (Lloyd et al., Sec. 5.6, Fig. 15): one mesh of 91 nodes, no refinement study; maximum errors "
                      "0.039, 0.111 and 0.088 cm against linear FEM in stretch, compression and shear (loads not printed).")
    paths = ("**Load paths** (continuation in the load factor; eigenvalue: smallest eigenvalue of the free tangent "
             "stiffness divided by the mean of its diagonal).")
    lines += ["", published_note, ""] + script.head(paths, [
        "experiment", "nodes", "last converged load factor", "Newton fails at", "smallest relative Jacobian (last state)",
        "smallest eigenvalue (last state)", "inverted cells (last state)", "first load factor with an inverted cell",
        "published"])
    published = {"hole": "Fig. 16b: max error 0.065 cm vs linear FEM (load not printed)", "cone": "Fig. 17: no numbers printed"}
    for name, label in (("hole", "cylinder with hole, 1800 Pa compression"), ("cone", "cone, 2000 Pa shear")):
        load = ds[f"{name}_load"].values
        ok = np.isfinite(ds[f"{name}_umax"].values)
        i = int(np.flatnonzero(ok)[-1]) if ok.any() else None
        inv = ds[f"{name}_inverted"].values
        first = load[np.flatnonzero(inv > 0)[0]] if (inv > 0).any() else np.nan
        jac = "n/a" if i is None else f"{float(ds[name + '_min_jacobian'][i]):.2f}"
        eig = "n/a" if i is None else f"{float(ds[name + '_eig'][i]):.2e}"
        n_inv = "n/a" if i is None else str(int(inv[i]))
        lines.append(script.row(label, int(ds[name + '_nodes']), f"{float(ds[name + '_last_load']):g}",
                                script.number(ds[f"{name}_failed_load"], "g", missing="none"), jac, eig, n_inv,
                                script.number(first, "g", missing="none"), published[name]))
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
