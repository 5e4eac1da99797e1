"""How each erratum changes results: the printed formula against the derived one, in simulation."""

from experiments import script
from msslib.results import read_result

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def pct(v):
    return f"{100 * float(v):+.3g} %"


def main():
    a = script.args(__doc__)
    gi, bt, bb, pe, cv = (read_result(f) for f in INPUTS)
    rows = []
    # Golec: printed constants per element / as interior totals vs derived, at A = 1
    for mat in gi.material.values:
        r = {c: gi.sel(material=mat, constants=c, A=1.0) for c in gi.constants.values}
        rows.append((f"Golec spring constants, {mat}, A = 1",
                     f"printed per element: E x{float(r['published'].E_ratio):.3g}, G x{float(r['published'].G_ratio):.3g}, "
                     f"nu {float(r['published'].nu_eff):.3g}, anisotropy {float(r['published'].anisotropy):.3g}; "
                     f"as interior totals: G x{float(r['printed_totals'].G_ratio):.3g}",
                     f"E x{float(r['derived'].E_ratio):.3g}, G x{float(r['derived'].G_ratio):.3g}, nu {float(r['derived'].nu_eff):.3g}, "
                     f"anisotropy {float(r['derived'].anisotropy):.3g}", "results/golec/studies/isotropy.nc"))
    # Baudet: correction factor printed vs derived (single cube, 10 % strain)
    for nu in ("0.3", "0.499"):
        s = {f: bt.sel(geometry="cube", nu=nu, level="eps10", factor=f) for f in ("printed", "derived")}
        b = {f: bb.sel(geometry="cube", nu=nu, factor=f) for f in ("printed", "derived")}
        rows.append((f"Baudet correction factor, cube, nu = {nu}",
                     f"E {pct(s['printed'].E_error_at)}, nu {pct(s['printed'].nu_error_at)} at 10 % strain; B {pct(b['printed'].B_small)}",
                     f"E {pct(s['derived'].E_error_at)}, nu {pct(s['derived'].nu_error_at)}; B {pct(b['derived'].B_small)}",
                     "results/baudet/studies/tension.nc, bulk.nc"))
    # van Gelder / Lloyd: validity at nu = 0 vs nu = 1/3 (small stretch)
    c = pe.sel(case="small_stretch")
    rows.append(("Triangle springs: valid at nu = 0 (van Gelder) or 1/3 (derived)",
                 f"mean error at nu = 0: {1e6 * float(c.error_mean_zero):.3g} um",
                 f"at nu = 1/3: {1e6 * float(c.error_mean_third):.3g} um; best nu {float(c.best_nu):.3g}",
                 "results/lloyd/studies/poisson_error.nc"))
    # Lloyd eq. 14: printed = derived at nu = 1/4
    if {"printed", "derived"} <= set(cv.variant.values):
        rows.append(("Lloyd eq. 14 (tetrahedron + volume), cylinder, largest error over the load cases",
                     f"{1e3 * float(cv.error_max.sel(variant='printed').max()):.3g} mm",
                     f"{1e3 * float(cv.error_max.sel(variant='derived').max()):.3g} mm (the formulas agree at nu = 1/4; they differ elsewhere)",
                     "results/lloyd/cylinder_volume/comparison.nc"))
    rows.append(("Golec correction force (kappa (V - V0) dV/dP)", "not a force (N m^3 with kappa in Pa): cannot be simulated as printed",
                 "-(kappa/V0)(V - V0) dV/dP: see the volumes of the compression experiment", "results/golec/compression"))
    lines = ["| erratum | with the printed formula | with the derived formula | source |", "|---|---|---|---|"]
    lines += [f"| {a_} | {b_} | {c_} | `{d_}` |" for a_, b_, c_, d_ in rows]
    script.write_table(a.out, lines)


if __name__ == "__main__":
    main()
