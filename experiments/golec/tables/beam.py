"""Beam under gravity (Golec Fig. 2 (3-4)): deflection, volume, error against FEM, stability."""

from experiments import script
from msslib.results import read_result

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
VARIANTS = {
    "mss_no_face": "classical MSS without face diagonals (A = 1e4), no correction",
    "mss_classical": "classical MSS: printed springs, no correction",
    "golec": "Golec MSS: derived springs + correction forces",
    "golec_published": "Golec MSS: printed springs + correction forces",
    "fem": "neo-Hookean FEM (reference)",
}


def main():
    args = script.args(__doc__)
    w = read_result(INPUTS[0]).sel(experiment="beam")
    cmp_ = read_result(INPUTS[1]).sel(case="default")
    lines = script.head(
        "**Golec Fig. 2 (3-4): 20 x 4 x 4 cm cantilever under gravity (E = 400 kPa, nu = 0.3).** "
        "Largest downward displacement, volume change, displacement error against the neo-Hookean FEM "
        "(relative to the FEM's largest displacement) and the smallest eigenvalue of the stiffness at "
        "the symmetric equilibrium (negative: unstable, the beam wrinkles). The paper prints no numbers "
        "for this experiment.",
        ["variant", "model", "max deflection (cm)", "dV (%)", "mean error (%)", "max error (%)",
         "smallest eigenvalue (N/m)", "wrinkle amplitude (mm)"])
    for v, text in VARIANTS.items():
        r = w.sel(variant=v)
        if v in cmp_.variant.values:
            c = cmp_.sel(variant=v)
            em, ex = f"{100 * float(c.relative_error_mean):.2g}", f"{100 * float(c.relative_error_max):.2g}"
        else:
            em = ex = "-"
        lam = float(r.min_eigenvalue)
        lines.append(script.row(v, text, f"{100 * float(r.tip_deflection):.3f}", f"{100 * float(r.volume_change):+.3f}",
                                em, ex, script.number(lam, ".3g") + (" (unstable)" if lam < 0 else ""),
                                script.number(r.wrinkle_amplitude, ".2g", 1e3)))
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
