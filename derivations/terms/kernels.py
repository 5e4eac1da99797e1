# ---
# jupyter:
#   jupytext:
#     formats: py:percent
#     text_representation:
#       extension: .py
#       format_name: percent
# ---

# %% [markdown]
# # Energy, force and Hessian kernels for the simulator
#
# The simulator integrates exactly the energies the element derivations linearise
# (:mod:`derivations.mss`): a spring with a rest length, Lloyd's tetrahedron volume energy, and the
# hexahedron volume correction with Golec's averaged volume. Each kernel takes the node coordinates
# as scalars (or equal-length arrays) and returns the energy, its gradient (= minus the force) and
# its Hessian, flattened row-major, node by node.

# %%
from functools import lru_cache

import sympy as sp

from derivations import mss
from derivations.records import Derivation, Formula


def _coords(n, dim):
    names = "xyz"[:dim]
    syms = [sp.Matrix([sp.Symbol(f"{c}{a}", real=True) for c in names]) for a in range(n)]
    return syms, [s for v in syms for s in v]


def _kernel_family(name, n, dim, energy, params, doc):
    P, flat = _coords(n, dim)
    W = energy(P, *params)
    g = [sp.diff(W, s) for s in flat]
    H = [sp.diff(gi, s) for gi in g for s in flat]
    args = tuple(flat) + tuple(params)
    return [
        Formula(f"{name}_energy", args, {"energy": W}, f"{doc} Energy [J]."),
        Formula(f"{name}_gradient", args, {f"g{i}": gi for i, gi in enumerate(g)},
                f"{doc} Gradient dW/dx [N] (the force is minus this), {n * dim} entries, node by node."),
        Formula(f"{name}_hessian", args, {f"h{i}": hi for i, hi in enumerate(H)},
                f"{doc} Hessian [N/m], {n * dim}x{n * dim} row-major."),
    ]


k, L0, k_v, V0, kappa = sp.symbols("k L0 k_v V0 kappa", real=True)


@lru_cache(maxsize=None)
def derive() -> Derivation:
    d = Derivation("kernels", "Energy, gradient and Hessian kernels")
    for dim in (2, 3):
        d.formulas += _kernel_family(f"spring{dim}d", 2, dim, lambda P, k, L0: mss.spring_energy(P[0], P[1], k, L0),
                                     (k, L0), f"Spring k/2 (|x1 - x0| - L0)^2 in {dim}D.")
    d.formulas += _kernel_family("tet_volume", 4, 3, lambda P, k_v, V0: mss.tet_volume_energy(P, k_v, V0),
                                 (k_v, V0), "Tetrahedron volume energy k_v/(2 V0^2) (V - V0)^2 (Lloyd et al. App. C.2).")
    d.formulas += _kernel_family("hex_volume", 8, 3, lambda P, kappa, V0: mss.hex_volume_energy(P, kappa, V0),
                                 (kappa, V0), "Hexahedron volume correction kappa/(2 V0) (V - V0)^2, V from the averaged edge vectors (Golec et al.).")
    P, flat = _coords(4, 3)
    d.formulas.append(Formula("tet_signed_volume", tuple(flat), {"V": mss.tet_volume(*P)}, "Signed tetrahedron volume [m^3]."))
    P, flat = _coords(8, 3)
    d.formulas.append(Formula("hex_averaged_volume", tuple(flat), {"V": mss.hex_averaged_volume(P)},
                              "Golec's averaged-edge-vector volume of a hexahedron in VTK order [m^3]."))
    return d


# %%
if __name__ == "__main__":
    for f in derive().formulas:
        print(f.name, len(f.outputs), "outputs")
