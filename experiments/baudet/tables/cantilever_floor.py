"""Cantilever: MSS, same-mesh linear FEM and the uncorrected lattice's floor at every resolution; the
reference's own discretisation error."""

import numpy as np

from experiments import script
from experiments.baudet import baudet_common as C

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def pc(v, fmt=".3g"):
    return "-" if not np.isfinite(v) else format(100 * float(v), fmt)


def main():
    args = script.args(__doc__)
    ds = C.open_result(INPUTS[0])
    cmp = C.open_result(INPUTS[1])
    lines = [f"**Cantilever: errors against the resolution and the floor of the uncorrected lattice** (per-node error / "
             f"largest reference displacement, %; reference {ds.attrs['reference']}; floor = the lattice's continuum limit "
             f"against the isotropic continuum, both {ds.attrs['continuum']}, at the MSS nodes; tip: relative error of the "
             "tip deflection, %)", "",
             "| resolution | published M / SD / MAX | MSS M / SD / MAX | floor M / MAX | MSS - floor, M | MSS vs its continuum limit, M | "
             "FEM Q1 same mesh M / MAX | MSS vs same-mesh FEM, M | tip: MSS / FEM same mesh / floor |",
             "|---|---|---|---|---|---|---|---|---|"]
    for r in ds.resolution.values:
        v = f"mss_{r}"
        if v in cmp.variant.values:
            c = cmp.sel(case="gravity", variant=v)
            pub = " / ".join(pc(c[f"published_relative_{s}"], "g") for s in ("mean", "std", "max"))
        if v not in cmp.variant.values or not np.isfinite(float(cmp["published_relative_mean"].sel(case="gravity", variant=v))):
            pub = "-"
        e = ds.sel(resolution=r)
        m = "mean"
        lines.append(
            f"| {r} | {pub} | {' / '.join(pc(e['error_mss'].sel(stat=s)) for s in ('mean', 'sd', 'max'))} | "
            f"{pc(e['error_floor'].sel(stat='mean'))} / {pc(e['error_floor'].sel(stat='max'))} | "
            f"{pc(e['error_mss'].sel(stat=m) - e['error_floor'].sel(stat=m))} | {pc(e['error_mss_vs_lattice'].sel(stat=m))} | "
            f"{pc(e['error_fem_same_mesh'].sel(stat='mean'))} / {pc(e['error_fem_same_mesh'].sel(stat='max'))} | "
            f"{pc(e['error_mss_vs_fem_same_mesh'].sel(stat=m))} | "
            f"{pc(e['tip_error_mss'], '+.3g')} / {pc(e['tip_error_fem_same_mesh'], '+.3g')} / {pc(e['tip_error_floor'], '+.3g')} |")
    lines += ["", f"Lattice (derived tensor): C11 = {float(ds['lattice_C11']):.6g} Pa, C12 = {float(ds['lattice_C12']):.6g} Pa, "
              f"C44 = {float(ds['lattice_C44']):.6g} Pa (= G), E along a cube axis = {float(ds['lattice_E_axis']):.6g} Pa "
              f"(material: E = 1000 Pa), Poisson's ratio {float(ds['lattice_nu_axis']):.4g}. Tip-deflection floor by beam theory: "
              f"Euler-Bernoulli {pc(ds['floor_tip_euler_bernoulli'], '+.3g')} %, Timoshenko with the exact G "
              f"{pc(ds['floor_tip_timoshenko'], '+.3g')} %; by the 3D continuum {pc(ds['floor_tip'], '+.3g')} %.", "",
              f"**The reference's own discretisation error** (against {ds.attrs['continuum']} isotropic, at the reference nodes)", "",
              "| FEM | M (%) | MAX (%) | tip (%) |", "|---|---|---|---|"]
    for c in ds.check.values:
        e = ds.sel(check=c)
        name = str(c).replace("_", " ") + (" (the reference)" if str(c) == f"Q1_{ds.attrs['reference'].split()[-1]}" else "")
        lines.append(f"| {name} | {pc(e['reference_error'].sel(stat='mean'))} | {pc(e['reference_error'].sel(stat='max'))} | "
                     f"{pc(e['reference_tip_error'], '+.3g')} |")
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
