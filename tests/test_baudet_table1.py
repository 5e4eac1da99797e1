"""Baudet's Table 1 as counted by derivations/analyses/baudet_table1.py, against counts reasoned independently.

The expected values are not produced by the module: they come from the geometry of the springs
(which springs a homogeneous shear or elongation stretches), from the symmetry of the compliance
(Maxwell-Betti reciprocity, a symmetric stress), from Cauchy's relations of central-force lattices,
from Baudet's printed eqs. 7-8, and from a numpy enumeration of the cube's 48 symmetries acting on
the entries of a 24 x 24 stiffness matrix.
"""

import itertools

import numpy as np
import pytest
import sympy as sp

from derivations.analyses import baudet_table1 as T
from derivations.elasticity import E
from msslib.fem import element_stiffness as fem_element_stiffness

pytestmark = pytest.mark.slow  # symbolic: about a minute in all

CORNERS = np.array(T._REF["hexahedron"], dtype=float)  # VTK order, coordinates +-1


def springs(conf):
    """(i, j, label) of every spring of the configuration, labelled as Baudet does: edges by their
    direction, face diagonals by the normal of their face, inner diagonals alike (typed from the
    definition of M1-M3, not taken from the module)."""
    out = []
    for i, j in itertools.combinations(range(8), 2):
        diff = np.flatnonzero(CORNERS[i] != CORNERS[j])
        if len(diff) == 1:
            out.append((i, j, "k_" + "xyz"[diff[0]]))
        elif len(diff) == 2 and conf in ("M1", "M3"):
            out.append((i, j, "k_f^" + {0: "yz", 1: "xz", 2: "xy"}[3 - diff.sum()]))
        elif len(diff) == 3 and conf in ("M2", "M3"):
            out.append((i, j, "k_d"))
    return out


# --- unknowns per family: which springs a homogeneous deformation stretches at first order -------

@pytest.mark.parametrize("conf", T.CONFIGURATIONS)
def test_unknowns_per_family(conf):
    # a spring of direction n stretches by (n . eps n) L: under a shear of the plane (i, j) only if
    # n_i n_j != 0, under an elongation along i only if n_i != 0
    shear, elong = set(), set()
    for i, j, label in springs(conf):
        n = CORNERS[j] - CORNERS[i]
        if any(n[p] * n[q] != 0 for p, q in ((0, 1), (0, 2), (1, 2))):
            shear.add(label)
        if any(n[p] != 0 for p in range(3)):
            elong.add(label)
    s = T.system(conf, T.BOX, False)
    assert {str(u) for u in s["in_shear"]} == shear
    assert {str(u) for u in s["in_elongation"]} == elong
    assert len(s["unknowns"]) == len({lab for _, _, lab in springs(conf)})
    # the published rows follow: shear 3, 1, 4; elongation 3 + (3), 3 + (1), 3 + (4); totals 6, 4, 7
    assert len(shear) == {"M1": 3, "M2": 1, "M3": 4}[conf]
    assert len(elong) - 3 == {"M1": 3, "M2": 1, "M3": 4}[conf]


# --- equations: counted per experiment, and independent --------------------------------------------

def test_equation_counts():
    c = T.experiment_counts()
    # three elongations, each measuring E and two Poisson's ratios
    assert c["elongation"]["counted"] == 9
    # reciprocity nu_ij / E_i = nu_ji / E_j: the 9 quantities are functions of the symmetric 3 x 3
    # normal block of the compliance, 6 entries, which they determine
    assert c["elongation"]["independent"] == 6
    # six shear experiments (a face and a direction), but the stress is symmetric: face n along t and
    # face t along n load the same plane, so there is one equation per plane
    assert c["shear"]["counted"] == 6
    assert c["shear"]["distinct"] == 3 and c["shear"]["independent"] == 3
    # inflation measures a function of the normal block, already fixed by the elongations
    assert c["total"]["independent"] == c["total"]["independent_without_bulk"] == 9
    assert c["total"]["counted_without_bulk"] == 15


# --- the element's tensor against a central-force formula; Cauchy's relations; ranks -----------------

def numeric_tensor(conf, L, k):
    """C_ijkl = sum k d_i d_j d_k d_l / (|d|^2 V) over the springs (d the rest vector of the spring),
    in Voigt form: the homogenised energy of central springs, written out independently."""
    X = (CORNERS + 1) / 2 * np.asarray(L, float)
    V = float(np.prod(L))
    voigt = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)]
    C = np.zeros((6, 6))
    for i, j, label in springs(conf):
        d = X[j] - X[i]
        for p, (a, b) in enumerate(voigt):
            for q, (c, e) in enumerate(voigt):
                C[p, q] += k[label] * d[a] * d[b] * d[c] * d[e] / (d @ d) / V
    return C


@pytest.mark.parametrize("conf", T.CONFIGURATIONS)
def test_tensor_matches_central_force_formula(conf):
    rng = np.random.default_rng(1)
    L = (1.0, 1.7, 0.6)
    k = {str(u): float(rng.uniform(0.5, 2.0)) for u in T.unknowns(conf)}
    C = T.element_tensor(conf).subs({T.x0: L[0], T.y0: L[1], T.z0: L[2]})
    C = np.array(C.subs({u: k[str(u)] for u in T.unknowns(conf)}).evalf(), dtype=float)
    assert np.allclose(C, numeric_tensor(conf, L, k), rtol=1e-12, atol=1e-12)
    # Cauchy's relations: C_12 = C_66, C_13 = C_55, C_23 = C_44
    assert C[0, 1] == pytest.approx(C[5, 5]) and C[0, 2] == pytest.approx(C[4, 4]) and C[1, 2] == pytest.approx(C[3, 3])


def test_ranks():
    # Cauchy's relations leave at most 6 independent entries of C (3 diagonal normal + 3 shear), so
    # no configuration sees more than 6 combinations of its constants. M1: each face constant alone
    # sets one shear entry, each edge constant one more diagonal entry: 6. M2: the three edges and k_d:
    # 4. M3: 7 constants, but the inner diagonals of a box stretch as a combination of edges and face
    # diagonals do (sum over the 4 inner diagonals of n_i^2 n_j^2 is the same for all i, j): 6.
    expected = {"M1": 6, "M2": 4, "M3": 6}
    for conf, r in expected.items():
        s = T.system(conf, T.BOX, False)
        assert s["rank_A"] == r
        assert s["rank_Ab"] == r + 1  # generic nu: the isotropic target is not reachable


def test_solvable_only_at_a_quarter():
    # lambda = C_12 = C_66 = mu only for nu = 1/4
    for conf in T.CONFIGURATIONS:
        assert T.system(conf, T.CUBE)["solvable_nu"] == [sp.Rational(1, 4)]
    assert T.system("M1", T.BOX, False)["solvable_nu"] == [sp.Rational(1, 4)]
    assert T.system("M3", T.BOX, False)["solvable_nu"] == [sp.Rational(1, 4)]
    # M2: one k_d for three shear planes of a box: only the cube (Baudet, before eq. 7)
    assert T.system("M2", T.BOX, False)["solvable_nu"] == []
    # M2 on the cube at nu = 1/4: Baudet's eq. 7, k_d = 3 E a / (8 (1 + nu)), and eq. 8,
    # k_x = E a (4 nu + 1) / (8 (1 + nu)), as printed
    nu = sp.Rational(1, 4)
    (value, sol), = T.system("M2", T.CUBE)["solutions"]
    assert value == nu
    assert sp.simplify(sol[T.K_INNER] - 3 * E * T.a / (8 * (1 + nu))) == 0
    for k in T.K_EDGE:
        assert sp.simplify(sol[k] - E * T.a * (4 * nu + 1) / (8 * (1 + nu))) == 0


@pytest.mark.parametrize("conf", T.CONFIGURATIONS)
def test_cube_solutions_are_isotropic(conf):
    # the engine's solution put into the independent tensor gives the isotropic D at nu = 1/4
    (_, sol), = T.system(conf, T.CUBE)["solutions"]
    free = {u: sp.Rational(1, 10) for u in T.unknowns(conf) if u not in sol or sol[u] == u}
    k = {str(u): float(sp.sympify(v).subs(free).subs({E: 1, T.a: 1})) for u, v in sol.items()}
    C = numeric_tensor(conf, (1.0, 1.0, 1.0), k)
    lam = mu = 0.4  # E = 1, nu = 1/4
    D = np.zeros((6, 6))
    D[:3, :3] = lam
    D[np.arange(6), np.arange(6)] += [2 * mu] * 3 + [mu] * 3
    assert np.allclose(C, D, atol=1e-12)


# --- Lloyd's criterion: entries of the 24 x 24 matrices --------------------------------------------

def cube_symmetries():
    """The 48 signed permutation matrices (the symmetry group of the cube)."""
    out = []
    for perm in itertools.permutations(range(3)):
        for signs in itertools.product((1, -1), repeat=3):
            g = np.zeros((3, 3))
            for r, (c, s) in enumerate(zip(perm, signs)):
                g[r, c] = s
            out.append(g)
    return out


def entry_orbits():
    """Orbits of the upper-triangle entries ((node, axis), (node, axis)) of a 24 x 24 matrix under the
    cube's symmetries (an entry maps to +- another; the transpose is the same entry)."""
    index = {tuple(c): n for n, c in enumerate(CORNERS.astype(int))}
    dofs = [(n, i) for n in range(8) for i in range(3)]
    seen, orbits = set(), []
    for p, q in itertools.combinations_with_replacement(range(24), 2):
        if (p, q) in seen:
            continue
        orbit = set()
        for g in cube_symmetries():
            (na, ia), (nb, ib) = dofs[p], dofs[q]
            ga = index[tuple((g @ CORNERS[na]).astype(int))]
            gb = index[tuple((g @ CORNERS[nb]).astype(int))]
            ja, jb = int(np.flatnonzero(g[:, ia])[0]), int(np.flatnonzero(g[:, ib])[0])
            r, s = 3 * ga + ja, 3 * gb + jb
            orbit.add((min(r, s), max(r, s)))
        seen |= orbit
        orbits.append(sorted(orbit))
    return orbits


def test_entry_orbits_of_the_cube():
    # by hand: same node (i = j; i != j): 2; edge neighbours (both along the edge; both across, equal;
    # one along one across; both across, different): 4; face diagonal (normal-normal; in-plane equal;
    # in-plane different; normal-in-plane): 4; body diagonal (equal; different axes): 2
    assert len(entry_orbits()) == 12
    assert sum(len(o) for o in entry_orbits()) == 24 * 25 // 2


def mss_matrix(conf, k):
    """24 x 24 stiffness of the springs at rest: k n n^T blocks (written out independently)."""
    X = (CORNERS + 1) / 2
    K = np.zeros((24, 24))
    for i, j, label in springs(conf):
        d = X[j] - X[i]
        B = k[label] * np.outer(d, d) / (d @ d)
        for a, b, s in ((i, i, 1), (j, j, 1), (i, j, -1), (j, i, -1)):
            K[3 * a:3 * a + 3, 3 * b:3 * b + 3] += s * B
    return K


def distinct_equations(rows, tol=1e-9):
    """Rows of values of the equations at several generic points: two equations are the same up to a
    constant factor exactly when their rows are parallel. Counts the classes of non-zero rows."""
    out = []
    for r in rows:
        n = np.linalg.norm(r)
        if n < tol:
            continue
        u = r / n
        if not any(min(np.linalg.norm(u - w), np.linalg.norm(u + w)) < tol for w in out):
            out.append(u)
    return len(out)


@pytest.mark.parametrize("conf", T.CONFIGURATIONS)
@pytest.mark.parametrize("symmetric", [False, True])
def test_stiffness_equation_count(conf, symmetric):
    # at a generic point (random constants, nu = 0.3, E = a = 1) the distinct non-zero values (up to
    # sign) of K_FEM - K_MSS over the upper triangle are the distinct equations
    rng = np.random.default_rng(2)
    labels = sorted({lab for _, _, lab in springs(conf)})
    kind = {lab: lab[:3] if lab.startswith("k_f") else ("k_d" if lab == "k_d" else "k_e") for lab in labels}
    iu = np.triu_indices(24)
    samples = []
    for _ in range(6):  # random constants and nu; E = a = 1 (they scale every entry alike)
        if symmetric:  # one constant per kind: k_e, k_f, k_d
            per_kind = {kd: float(rng.uniform(0.5, 2.0)) for kd in set(kind.values())}
            draw = {lab: per_kind[kind[lab]] for lab in labels}
        else:
            draw = {lab: float(rng.uniform(0.5, 2.0)) for lab in labels}
        nu = float(rng.uniform(0.05, 0.45))
        K = fem_element_stiffness("hexahedron", (CORNERS + 1) / 2, 1.0, nu) - mss_matrix(conf, draw)
        samples.append(K[iu])
    rows = np.array(samples).T  # one row per upper-triangle entry
    expected = distinct_equations(rows)
    m = T.stiffness_matching(conf, symmetric)
    assert m["n_equations"] == expected
    if symmetric:
        # each orbit of the cube's symmetries holds one value up to sign, so at most 12 equations
        orbits = entry_orbits()
        pos = {pq: n for n, pq in enumerate(zip(*iu))}
        assert all(distinct_equations(rows[[pos[pq] for pq in o]]) <= 1 for o in orbits)
        assert expected <= len(orbits)
    # and no spring constants make them all hold, for any nu (checked below by least squares)
    assert m["rank_Ab"] == m["rank_A"] + 1 and m["solvable_nu"] == []


@pytest.mark.parametrize("conf", T.CONFIGURATIONS)
def test_no_spring_constants_match_the_hexahedron(conf):
    # least squares over the spring constants, numerically: the residual of the best fit stays a
    # sizeable fraction of K_FEM for every nu (some entries couple dofs no spring couples)
    labels = sorted({lab for _, _, lab in springs(conf)})
    basis = np.array([mss_matrix(conf, {lab: float(lab == one) for lab in labels}).ravel() for one in labels]).T
    for nu in np.linspace(0.02, 0.48, 24):
        K = fem_element_stiffness("hexahedron", (CORNERS + 1) / 2, 1.0, nu).ravel()
        k, *_ = np.linalg.lstsq(basis, K, rcond=None)
        assert np.linalg.norm(K - basis @ k) > 0.05 * np.linalg.norm(K)
