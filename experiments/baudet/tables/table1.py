"""Baudet's Table 1 (unknown spring constants and equations of the configurations M1-M3), counted by
the derivation engine (derivations/analyses/baudet_table1.py), beside the published counts."""

import sympy as sp

from experiments import script

INPUTS = script.inputs(__file__)  # the list in inputs.yaml beside this script

# Baudet et al. (2007), Sec. 4 "Our 3D Model", Table 1 "Number of equations and unknowns according to the
# geometry chosen" (M1: face diagonals, M2: inner diagonals, M3: both); elongation unknowns are printed
# as "edges + (diagonals)".
PUBLISHED = {
    "M1": {"unknowns_shear": 3, "unknowns_elongation": (3, 3), "unknowns_total": 6,
           "equations_elongation": 9, "equations_shear": 6, "equations_total": 15},
    "M2": {"unknowns_shear": 1, "unknowns_elongation": (3, 1), "unknowns_total": 4,
           "equations_elongation": 9, "equations_shear": 3, "equations_total": 12},
    "M3": {"unknowns_shear": 4, "unknowns_elongation": (3, 4), "unknowns_total": 7,
           "equations_elongation": 9, "equations_shear": 6, "equations_total": 15},
}
CONFS = ("M1", "M2", "M3")


def _nu(values):
    return ", ".join(str(sp.nsimplify(v)) for v in values) or "none"


def main():
    args = script.args(__doc__)
    from derivations.analyses import baudet_table1 as T

    t = T.table()
    P = PUBLISHED

    def row(label, paper, ours):
        cells = " | ".join(f"{paper(c)} | {ours(c)}" for c in CONFS)
        return f"| {label} | {cells} |"

    def dash(c):  # the paper does not give this count
        return "-"
    lines = [
        "**Baudet et al., Table 1: unknown spring constants and equations per configuration**, published "
        "and counted by the derivation engine (parallelepiped x0 x y0 x z0; M1: edges and face diagonals, "
        "M2: edges and inner diagonals, M3: all).", "",
        "| | M1 paper | M1 engine | M2 paper | M2 engine | M3 paper | M3 engine |",
        "|---|---|---|---|---|---|---|",
        row("unknown stiffness constants in shearing", lambda c: P[c]["unknowns_shear"], lambda c: t[c]["unknowns_shear"]),
        row("unknown stiffness constants in elongation (edges + (diagonals))",
            lambda c: "{}+({})".format(*P[c]["unknowns_elongation"]),
            lambda c: f"{t[c]['unknowns_edge']}+({t[c]['unknowns_diagonal_elongation']})"),
        row("total unknown stiffness constants", lambda c: P[c]["unknowns_total"], lambda c: t[c]["unknowns_total"]),
        row("independent combinations of them the experiments see (rank A)", dash, lambda c: t[c]["rank_A_box"]),
        row("equations in elongation: one per experiment and quantity / independent",
            lambda c: P[c]["equations_elongation"],
            lambda c: f"{t[c]['equations_elongation']} / {t[c]['equations_elongation_independent']}"),
        row("equations in shearing: one per experiment / independent", lambda c: P[c]["equations_shear"],
            lambda c: f"{t[c]['equations_shear']} / {t[c]['equations_shear_independent']}"),
        row("total equations (inflation dependent) / independent", lambda c: P[c]["equations_total"],
            lambda c: f"{t[c]['equations_total']} / {t[c]['equations_total_independent']}"),
        row("rank [A b] (generic nu; solvable where it equals rank A)", dash, lambda c: t[c]["rank_Ab_box"]),
        row("solvable for nu = (any parallelepiped)", lambda c: "over-constrained",
            lambda c: _nu(t[c]["solvable_nu_box"]) + ("" if t[c]["solvable_nu_box"] else " (cube only)")),
        row("solvable for nu = (cube)", dash, lambda c: _nu(t[c]["solvable_nu_cube"])),
        row("Lloyd's criterion, cube: distinct equations of K_MSS = K_FEM (24 x 24)", dash,
            lambda c: t[c]["stiffness_equations"]),
        row("Lloyd's criterion, cube: rank A / rank [A b]", dash,
            lambda c: f"{t[c]['stiffness_rank_A']} / {t[c]['stiffness_rank_Ab']}"),
        row("Lloyd's criterion, cube: solvable for nu =", dash, lambda c: _nu(t[c]["stiffness_solvable_nu"])),
        "",
    ]
    sols = []
    for c in CONFS:
        for v, sol in t[c]["solutions_cube"]:
            sols.append(f"{c} at nu = {sp.nsimplify(v)}: " + ", ".join(f"{k} = {sp.sstr(val)}" for k, val in sol.items()))
    lines.append("Equations are counted as the paper counts them (elongation: E and the two Poisson's ratios of each of "
                 "three experiments; shear: G of six experiments, a face and a direction each) and as independent "
                 "conditions on the element's response (rank of their Jacobian with respect to its compliance entries). "
                 "A is the linear map from the spring constants to the element's 9 orthotropic elastic constants, b "
                 "the isotropic target. Solutions on the cube (edge a): " + "; ".join(sols) + ".")
    script.write_table(args.out, lines)


if __name__ == "__main__":
    main()
