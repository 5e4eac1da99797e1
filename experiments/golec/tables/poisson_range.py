"""Golec's hybrid MSS at nu = 0.1, 0.2 (kappa < 0) and 0.3: moduli, stability, beam error, by variant."""

from experiments import script
from msslib.results import read_result

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
LABELS = {"golec": "hybrid MSS (A = 1, correction)", "golec_no_face": "no face diagonals (A = 1e4), correction",
          "springs": "springs only (A = 1)", "springs_no_face": "springs only, no face diagonals (A = 1e4)"}


def eig(v):
    return script.number(v, ".3g") + (" (unstable)" if float(v) < 0 else "")


def main():
    args = script.args(__doc__)
    ds = read_result(INPUTS[0])
    lines = script.head(
        "**Golec's model below and above nu = 1/4** (E = 400 kPa, derived constants). Sample: 4 x 4 x 4 cubes of "
        "1 cm, uniaxial stress at 0.1 %. Compression: the 5 cm cube clamped and compressed by 10 %, volume against "
        "neo-Hookean FEM (Q1). Beam: the 20 x 4 x 4 cm cantilever under gravity, mean / max displacement error "
        "divided by the reference's largest displacement, against neo-Hookean FEM on the same hexahedra, trilinear "
        "(Q1) and triquadratic (Q2). Eigenvalues: the smallest of the tangent stiffness at the equilibrium "
        "(negative: the equilibrium is unstable, the lattice wrinkles).",
        ["nu", "kappa / E", "variant", "E / E_t", "nu_eff", "compression: eigenvalue (N/m)", "dV vs FEM (%)",
         "beam: eigenvalue (N/m)", "beam tip (cm)", "error vs Q1, mean / max (%)", "error vs Q2, mean / max (%)"])
    for nu in ds.nu.values:
        r = ds.sel(nu=nu)
        for v in ds.variant.values:
            x = r.sel(variant=v)
            e1, e2 = x.sel(reference="fem_q1"), x.sel(reference="fem_q2")
            lines.append(script.row(
                f"{nu:g}", f"{float(r.kappa_over_E):+.3f}", LABELS[str(v)], f"{float(x.E_ratio):.4f}", f"{float(x.nu_eff):.4f}",
                eig(x.compression_min_eigenvalue), f"{100 * float(x.compression_volume_error):+.2f}",
                eig(x.beam_min_eigenvalue), f"{100 * float(x.beam_tip_deflection):.3f}",
                f"{100 * float(e1.beam_error_mean):.2f} / {100 * float(e1.beam_error_max):.2f}",
                f"{100 * float(e2.beam_error_mean):.2f} / {100 * float(e2.beam_error_max):.2f}"))
        q1, q2 = (100 * float(t) for t in r.beam_reference_tip.values)
        lines.append(script.row(f"{nu:g}", "", "neo-Hookean FEM: Q1 / Q2", "", "", "", "", "", f"{q1:.3f} / {q2:.3f}", "", ""))
    comp = ", ".join(f"{100 * c:g} %" for c in ds.compression.values)
    lines += ["", f"Smallest tangent eigenvalue of the hybrid MSS sample under uniaxial compression ({comp}): "
              + "; ".join(f"nu = {nu:g}: " + ", ".join(f"{float(v):.3g}" for v in ds.sample_compression_min_eigenvalue.sel(nu=nu).values)
                          for nu in ds.nu.values) + " N/m."]
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
