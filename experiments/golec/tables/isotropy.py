"""Effective moduli of the Golec lattice at A = 1 (and their spread over A), derived vs printed."""

from experiments import script
from msslib.results import read_result

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script
LABELS = {"derived": "derived (per element)", "published": "printed, used per element",
          "printed_totals": "printed, read as interior totals"}


def main():
    args = script.args(__doc__)
    ds = read_result(INPUTS[0])
    A = ds.A.values
    lines = [f"**Isotropy of the Golec lattice in simulation** ({ds.attrs['sample']}, strain {float(ds.attrs['strain']):g}). "
             f"Values at A = 1; in brackets the range over A = {A.min():g} ... {A.max():g}. An isotropic lattice "
             "with the target moduli has E/E_t = G/G_t = G45/G_t = 1 and nu = nu_t.", "",
             "| target | constants | E / E_t | nu | G / G_t (C44) | G45 / G_t ((C11-C12)/2) | G / G45 |",
             "|---|---|---|---|---|---|---|"]

    def cell(r, k, fmt):
        a1 = float(r[k].sel(A=1.0))
        lo, hi = float(r[k].min()), float(r[k].max())
        return f"{a1:{fmt}} [{lo:{fmt}} ... {hi:{fmt}}]"

    for m in ds.material.values:
        E_t, nu_t = float(ds.E_target.sel(material=m)), float(ds.nu_target.sel(material=m))
        for c in ds.constants.values:
            r = ds.sel(material=m, constants=c)
            lines.append(f"| E = {E_t / 1e3:g} kPa, nu = {nu_t:g} | {LABELS[str(c)]} | {cell(r, 'E_ratio', '.3f')} | "
                         f"{cell(r, 'nu_eff', '.4f')} | {cell(r, 'G_ratio', '.3f')} | {cell(r, 'G45_ratio', '.3f')} | "
                         f"{cell(r, 'anisotropy', '.3f')} |")
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
