"""Volumes after 10 % compression (Golec Fig. 2 (1-2)) beside the printed ones, and stability."""

import numpy as np

from experiments import script
from msslib.results import mesh_from_result, read_result
from msslib.metrics import mesh_volume

R = "results/golec/compression"
VARIANTS = {
    "mss_no_face": "classical MSS without face diagonals (A = 1e4), no correction",
    "mss_classical": "classical MSS: printed springs, no correction",
    "mss_springs": "derived springs, no correction",
    "golec": "Golec MSS: derived springs + correction forces",
    "golec_published": "Golec MSS: printed springs + correction forces",
    "fem": "neo-Hookean FEM, trilinear hexahedra (locks)",
}
PUBLISHED = {"mss_classical": "115.196 (Fig. 2 (1), classical MSS with wrinkles)",
             "mss_no_face": "115.196 (Fig. 2 (1), classical MSS with wrinkles)",
             "golec_published": "124.959 (Fig. 2 (2), with correction forces)"}
INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script


def volume(path):
    ds = read_result(path)
    mesh = mesh_from_result(ds)
    u = ds["displacement"].transpose("node", "axis").values
    return mesh_volume(mesh, u), mesh_volume(mesh)


def main():
    args = script.args(__doc__)
    w = read_result(INPUTS[-1]).sel(experiment="compression")
    lines = ["**Golec Fig. 2 (1-2): volume of the 5 cm cube (V0 = 125 cm^3) after 10 % compression, bottom and top clamped.** "
             "Symmetric static equilibria; the smallest eigenvalue of the stiffness (clamped case, free dofs) "
             "is negative where that equilibrium is unstable, and the wrinkled equilibrium found from it is "
             "given in its own row. The paper's volumes are in its (unstated) units, read here as cm^3.", "",
             "| variant | model | V (cm^3) | dV (%) | "
             "smallest eigenvalue (N/m) | published V |",
             "|---|---|---|---|---|---|"]
    for v, text in VARIANTS.items():
        Vc, V0 = volume(f"{R}/clamped__{v}.nc")
        lam = float(w.min_eigenvalue.sel(variant=v)) if v in w.variant.values else np.nan
        lam_s = "-" if not np.isfinite(lam) else f"{lam:.3g}" + (" (unstable)" if lam < 0 else "")
        lines.append(f"| {v} | {text} | {Vc * 1e6:.3f} | {100 * (Vc / V0 - 1):+.2f} | {lam_s} | {PUBLISHED.get(v, '-')} |")
        if v == "mss_no_face" and np.isfinite(float(w.volume_wrinkled.sel(variant=v))):
            Vw = float(w.volume_wrinkled.sel(variant=v))
            amp = float(w.wrinkle_amplitude.sel(variant=v)) * 1e3
            lam_w = float(w.min_eigenvalue_wrinkled.sel(variant=v))
            lines.append(f"| {v} (wrinkled) | same, wrinkled equilibrium (amplitude {amp:.2g} mm) | {Vw * 1e6:.3f} | "
                         f"{100 * (Vw / V0 - 1):+.2f} | {lam_w:.3g} | {PUBLISHED[v]} |")
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
