"""The FEM solves: linear elasticity, the finite-strain references, one element's stiffness."""

from __future__ import annotations

import copy
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from msslib.fem.materials import _cell_materials, _check_plane, _law, lame
from msslib.fem.space import _boundary, _Geometry, _linear_stiffness, _skfem_linear_stiffness
from msslib.errors import MsslibWarning
from msslib.mesh import CELL_TYPES, Mesh
from msslib.mesh.cells import RegistryView
from msslib.models.references import warn_locking
from msslib.solvers.policy import method_for_material


@dataclass(frozen=True)
class FemResult:
    """Result of an FEM solve.

    ``displacement`` and ``reaction`` are ``(n_nodes, dim)``; ``reaction`` is ``K u - f`` (linear) or
    ``f_int(u) - f_ext`` (non-linear) on the constrained dofs and zero elsewhere. ``strain_energy``
    in J (per unit thickness times ``thickness`` in 2D). ``stats`` holds at least ``n_dofs``,
    ``wall_time`` and ``solver``.
    """

    displacement: np.ndarray
    reaction: np.ndarray
    strain_energy: float
    stats: dict = field(default_factory=dict)
    #: the location ``(n_scalar, dim)`` and displacement of every scalar dof: the nodes first (as
    #: ``displacement``), then, with quadratic elements, the edge, face and cell dofs
    dof_points: np.ndarray | None = None
    dof_displacement: np.ndarray | None = None


def solve_sparse(K: sp.spmatrix, rhs: np.ndarray) -> np.ndarray:
    """``K^-1 rhs`` for a symmetric stiffness ``K`` (all its dofs free) by the solver layer of
    :mod:`msslib.solvers` (:func:`msslib.fem.newton.linear_solve`: the policy that takes every
    solve of the library, without the dofs' locations, so no AMG near-null space). Raises
    :class:`numpy.linalg.LinAlgError` for a singular matrix."""
    from msslib.fem.newton import linear_solve

    K = sp.csr_matrix(K)
    n = K.shape[0]
    x, _ = linear_solve(K, np.asarray(rhs, dtype=float), np.ones(n, dtype=bool), np.zeros((n, 1)), 1)
    return np.atleast_1d(x)


# --------------------------------------------------------------------------------------------
# linear elasticity
# --------------------------------------------------------------------------------------------


def solve_linear(
    mesh: Mesh,
    E,
    nu,
    *,
    fixed,
    prescribed=None,
    nodal_forces=None,
    body_force=None,
    thickness: float = 1.0,
    plane: str = "stress",
    assembly: str = "fast",
    order: int = 1,
    tractions=(),
    linear_solver="auto",
    volumetric: str = "full",
    quadrature: str = "full",
    pressures=(),
    curved=(),
) -> FemResult:
    """Small-strain isotropic linear elasticity on ``mesh``.

    ``E``, ``nu``: scalars or sequences indexed by ``mesh.material``. ``fixed`` (n_nodes, dim) bool
    marks constrained dofs, ``prescribed`` their displacements (default 0). ``nodal_forces`` in N,
    ``body_force`` in N/m^3, shape ``(dim,)`` or ``(n_cells, dim)``. In 2D the stiffness and the body
    load are multiplied by ``thickness`` and ``plane`` selects plane stress (default) or strain.
    ``assembly="fast"`` (default) assembles the stiffness with vectorised element matrices built from
    scikit-fem's scalar basis; ``"skfem"`` uses a scikit-fem ``BilinearForm`` on ``ElementVector``
    (same matrix, several times slower on large meshes).

    ``order``: 1 (linear elements, default) or 2 (quadratic: ``ElementTriP2``, ``ElementTetP2``,
    ``ElementQuad2``, ``ElementHex2``; locking-free enough near nu = 1/2 for a reference, see
    :mod:`msslib.fem`); ``displacement`` and ``reaction`` are then given at the mesh's nodes (the
    reaction of the edge, face and cell dofs carried to them by the linear interpolant's
    transpose, which keeps the total). ``tractions``: pairs ``(facets, traction)`` of boundary
    facets (node indices, ``(k, nodes per facet)``) and a traction (Pa), integrated with the
    element's shape functions. ``linear_solver``: ``"auto"`` (the policy of
    :mod:`msslib.solvers`: banded Cholesky, SuperLU or AMG-preconditioned CG), ``"direct"`` or
    ``"cg"``.

    ``quadrature``: ``"full"`` (default) or ``"one_point"``, bilinear quads (order 1) integrated at
    their centre only: the element whose strain is the constant one at its centre. Its stiffness
    does not resist the two hourglass modes of each quad; a system they leave singular raises
    :class:`numpy.linalg.LinAlgError` naming them, and ``stats["hourglass_energy_fraction"]`` is
    the share of the solution's full-quadrature (bilinear) energy that the one-point element does
    not see, with a :class:`~msslib.errors.MsslibWarning` above :data:`HOURGLASS_WARN`.

    ``pressures``: tuples ``(facets, pressure, follow)`` of outward boundary facets (node indices,
    ``(k, nodes per facet)``, as :func:`msslib.mesh.boundary_facets` gives them), a pressure (Pa,
    positive pushes into the body: traction ``-p n``) and ``follow``; integrated on the element's
    facets (quadratic ones with order 2, see :mod:`msslib.fem.pressure`). In small strain the
    current surface is the reference one, so ``follow`` has no effect here.

    ``curved``: pairs ``(facets, project)`` of boundary facets (node ids, as for ``pressures``) that
    lie on a known curved surface and a function ``project`` mapping points ``(k, dim)`` onto it;
    with ``order=2`` the quadratic nodes of those facets are placed at ``project`` of their
    straight-sided places (isoparametric elements, :func:`msslib.fem.space.curved_mesh`), so that
    the body's curved walls are represented to ``O(h^3)`` and the quadratic element converges at
    its order on it (3 in L2, checked on the thick-walled cylinder and sphere of
    :mod:`msslib.fem.exact`, whose :func:`~msslib.fem.exact.curved_walls` gives the pairs). Default:
    none, every side straight (the mesh alone does not say which surface its facets approximate).
    ``dof_points`` and the pressures then lie on the curved sides. ValueError for ``order=1``.
    """
    from msslib.fem.newton import SOLVER
    from msslib.fem.pressure import check_pressures, facet_pressures

    t0 = time.perf_counter()
    _check_plane(plane, mesh.dim)
    if thickness <= 0:
        raise ValueError(f"thickness={thickness!r} must be > 0")
    pressures = check_pressures(pressures, mesh)
    E_c, nu_c = _cell_materials(mesh, E, nu)
    if order == 1:
        warn_locking(mesh, nu_c, plane)
    linear_solver = method_for_material(linear_solver, nu_c)  # nearly incompressible: direct
    lam_c, mu_c = lame(E_c, nu_c, plane if mesh.dim == 2 else None)
    geo = _Geometry(mesh, order, curved=curved)
    w = thickness if mesh.dim == 2 else 1.0
    if assembly == "skfem" and (order != 1 or volumetric != "full"):
        raise ValueError("assembly='skfem' is for linear elements (order=1) with volumetric='full'")
    if quadrature not in QUADRATURES:
        raise ValueError(f"quadrature must be one of {QUADRATURES}, got {quadrature!r}")
    if quadrature == "one_point" and (mesh.cell_type != "quad" or order != 1 or volumetric != "full" or assembly != "fast"):
        raise ValueError("quadrature='one_point' is for bilinear quads (cell type quad, order=1, volumetric='full', "
                         f"assembly='fast'), got {mesh.cell_type} cells, order={order}, volumetric={volumetric!r}, "
                         f"assembly={assembly!r}")
    if quadrature == "one_point":
        K = _linear_stiffness(_Geometry(mesh, 1, quadrature=ONE_POINT_QUAD), lam_c, mu_c) * w
    elif assembly == "fast":
        K = sum(_linear_stiffness(g, lam_q[:, 0], mu_q[:, 0])
                for g, lam_q, mu_q in _parts(mesh, geo, lam_c, mu_c, volumetric, plane if mesh.dim == 2 else None)) * w
    elif assembly == "skfem":
        K = _skfem_linear_stiffness(geo, lam_c, mu_c) * w
    else:
        raise ValueError(f"assembly must be 'fast' or 'skfem', got {assembly!r}")
    cons, presc, f = _boundary(mesh, fixed, prescribed, nodal_forces, body_force, geo, thickness, tractions)
    for load in facet_pressures(geo, pressures, thickness):
        f = f + load.forces()
    t1 = time.perf_counter()

    u = presc.copy()
    free = ~cons
    how = "none (no free dof)"
    if free.any():
        rhs = f[free] - K[free][:, cons] @ presc[cons]
        u[free], how = _solve_free(K, rhs, free, geo, linear_solver, quadrature)
    t2 = time.perf_counter()

    Ku = K @ u
    reaction = np.where(cons, Ku - f, 0.0)
    d = mesh.dim
    stats = {
        "n_dofs": int(u.size),
        "n_free_dofs": int(free.sum()),
        "assembly_time": t1 - t0,
        "solve_time": t2 - t1,
        "wall_time": time.perf_counter() - t0,
        "solver": f"{SOLVER}: {how}",
        "assembly": assembly,
        "plane": plane if d == 2 else None,
        "order": order,
        "quadrature": quadrature,
    }
    if quadrature == "one_point":
        stats["hourglass_energy_fraction"] = _hourglass_fraction(geo, lam_c, mu_c, w, u, float(u @ Ku))
    return _result(geo, u, reaction, float(0.5 * u @ Ku), stats)


#: the quadrature options of :func:`solve_linear`; one point: the centre of scikit-fem's reference
#: square [0, 1]^2, weight 1 (its area)
QUADRATURES = ("full", "one_point")
ONE_POINT_QUAD = (np.array([[0.5], [0.5]]), np.array([1.0]))
#: above this share of the bilinear energy in hourglass modes a one-point solve warns
HOURGLASS_WARN = 0.01


def _solve_free(K, rhs, free, geo, linear_solver, quadrature):
    """The free dofs' solution; a singular one-point system is named by its hourglass modes."""
    from msslib.fem.newton import linear_solve

    if quadrature != "one_point":
        return linear_solve(K, rhs, free, geo.points, geo.dim, linear_solver)
    A = K.tocsr()[free][:, free]
    # one-point quads can be singular with every rigid-body mode constrained; a pivoting solver
    # may still return a finite vector, so the smallest eigenvalue decides
    lo = spla.eigsh(A, k=1, sigma=-1e-6 * abs(A.diagonal()).max(), which="LM", return_eigenvectors=False)[0] \
        if A.shape[0] > 2 else np.linalg.eigvalsh(A.toarray())[0]
    if lo <= 1e-10 * abs(A.diagonal()).max():
        raise np.linalg.LinAlgError("singular stiffness with quadrature='one_point': the supports leave an hourglass "
                                    "mode of the quads free (zero energy at the element centres); constrain more "
                                    "nodes or use quadrature='full'")
    return linear_solve(K, rhs, free, geo.points, geo.dim, linear_solver)


def _hourglass_fraction(geo, lam_c, mu_c, w, u, one_point_energy) -> float:
    """Share of the solution's full-quadrature energy ``u K_full u`` that one-point quadrature
    does not see (``(u K_full u - u K_1 u) / u K_full u``), with a warning above HOURGLASS_WARN."""
    full = float(u @ (_linear_stiffness(geo, lam_c, mu_c) * w @ u))
    share = (full - one_point_energy) / full if full > 0 else 0.0
    if share > HOURGLASS_WARN:
        warnings.warn(MsslibWarning(
            f"quadrature='one_point': {100 * share:.2g} % of the solution's bilinear (full-quadrature) energy lies in "
            "hourglass modes, which the one-point quads do not resist; compare with quadrature='full'"), stacklevel=3)
    return share


#: quadrature of the volumetric term with volumetric="reduced": one point on P2 simplices (the
#: volumetric strain's cell mean: the penalty form of the inf-sup stable P2-P0 pair), 2x2(x2) Gauss
#: on Q2 (selective reduced integration)
#: (each cell type's quadratic element says it: msslib.mesh.cells)
_REDUCED_INTORDER = RegistryView(lambda c: c.quadratic.reduced_intorder, "cell type -> reduced quadrature order",
                                 only=lambda c: c.quadratic is not None)
VOLUMETRIC = ("full", "reduced")


def _reduced_geometry(mesh, curved=()):
    """The quadratic space at the reduced rule of the volumetric term. Where that rule is of degree
    1 (P2 simplices): one point per cell carrying the cell's mean shape-function gradients and its
    measure, so that the volumetric term sees the cell mean of the displacement gradient (the
    penalty form of P2-P0). On a straight-sided simplex the gradients are linear and their mean is
    their value at the centroid, i.e. the one-point rule; on a curved one (``curved``) the mean is
    integrated exactly, which a one-point rule would not do. (scikit-fem's triangle rules have 3
    points at every degree below 3, so an ``intorder`` of 1 would leave P2 triangles fully
    integrated, and locking.) Else scikit-fem's rule of that degree (2x2(x2) Gauss on Q2)."""
    k = _REDUCED_INTORDER[mesh.cell_type]
    if k > 1:
        return _Geometry(mesh, 2, intorder=k, curved=curved)
    full = _Geometry(mesh, 2, curved=curved)
    mean = copy.copy(full)
    volume = full.dx.sum(axis=1, keepdims=True)  # (m, 1)
    mean.dx = volume
    mean.dphi = np.einsum("aJmq,mq->aJm", full.dphi, full.dx)[..., None] / volume
    mean.phi = np.einsum("amq,mq->am", full.phi, full.dx)[..., None] / volume
    return mean


def _parts(mesh, geo, lam_c, mu_c, volumetric, plane):
    """``(geometry, lam_q, mu_q)`` of the terms of the energy: the whole law at full quadrature,
    or with ``volumetric="reduced"`` the shear part (``lam = 0``) at full quadrature and the
    volumetric part (``mu = 0``) at the reduced one."""
    if volumetric not in VOLUMETRIC:
        raise ValueError(f"volumetric must be 'full' or 'reduced', got {volumetric!r}")

    def q(g, v):
        return np.repeat(np.asarray(v, dtype=float)[:, None], g.dx.shape[1], axis=1)

    if volumetric == "full":
        return [(geo, q(geo, lam_c), q(geo, mu_c))]
    if geo.order != 2:
        raise ValueError("volumetric='reduced' needs quadratic elements (order=2): with linear ones it does not "
                         "stop the locking of simplices")
    if plane == "stress":
        raise ValueError("volumetric='reduced' is for 3D and plane strain: plane stress does not lock")
    red = _reduced_geometry(mesh, geo.curved)
    zero = np.zeros_like(np.asarray(lam_c, dtype=float))
    return [(geo, q(geo, zero), q(geo, mu_c)), (red, q(red, lam_c), q(red, zero))]


def _min_jacobian(geometries, u_dofs) -> tuple[float, int, int]:
    """``(det F, cell, n_cells)``: the smallest ``det F = det(I + grad u)`` over the quadrature points
    of every geometry in ``geometries`` (2D: of the in-plane gradient, whose sign is that of the 3D
    ``det F`` as ``F33 > 0``) at the dof displacements ``u_dofs`` ``(n_scalar, dim)``, the cell
    where it lies and how many cells have a quadrature point with ``det F <= 0``."""
    worst, cell, bad = np.inf, -1, None
    for g in geometries:
        H = g.displacement_gradient(u_dofs)
        F = np.moveaxis(H, (0, 1), (-2, -1)) + np.eye(g.dim)
        J = np.linalg.det(F).reshape(F.shape[0], -1)  # (m, q)
        Jmin = np.where(np.isnan(J), -np.inf, J).min(axis=1)
        bad = Jmin <= 0.0 if bad is None else bad | (Jmin <= 0.0)
        k = int(np.argmin(Jmin))
        if Jmin[k] < worst:
            worst, cell = float(Jmin[k]), k
    return worst, cell, int(bad.sum())


def _check_inversion(parts, u_dofs, load, reached, law) -> None:
    """Raise :class:`msslib.errors.UnphysicalStateError` in one line when the equilibrium found at
    load factor ``load`` has ``det F <= 0`` at a quadrature point of any part of the energy."""
    from msslib.errors import UnphysicalStateError

    J, cell, n_bad = _min_jacobian([g for g, _, _ in parts], u_dofs)
    if J > 0.0:
        return
    why = ("the St Venant-Kirchhoff law has no inversion barrier: a smaller load, more supports or "
           "law='neohookean'") if law == "svk" else "a smaller load or more supports"
    exc = UnphysicalStateError(
        f"msslib.fem.solve_nonlinear: the equilibrium found at load factor {float(load):.6g} inverts element {cell} "
        f"(det F = {J:.4g} at a quadrature point; {n_bad} element(s) with det F <= 0); det F > 0 is required at every "
        f"quadrature point ({why}); load factor reached with every det F > 0: {float(reached):.6g}")
    exc.load, exc.load_reached, exc.cell, exc.det_F = float(load), float(reached), cell, J
    raise exc


def _result(geo, u, reaction, energy, stats) -> FemResult:
    """The result at the mesh's nodes (reactions of higher-order dofs carried to them)."""
    d, n = geo.dim, geo.mesh.n_nodes
    U, R = u.reshape(-1, d), reaction.reshape(-1, d)
    return FemResult(displacement=U[:n].copy(), reaction=np.asarray(geo.interp.T @ R), strain_energy=energy,
                     stats=stats, dof_points=geo.points, dof_displacement=U)


def element_stiffness(cell_type: str, coords, E: float, nu: float, thickness: float = 1.0, plane: str = "stress") -> np.ndarray:
    """Stiffness matrix of a single element with node coordinates ``coords`` (VTK order).

    Dofs are interleaved by node: ``(node0_x, node0_y, [node0_z], node1_x, ...)``.
    """
    if cell_type not in CELL_TYPES:
        raise ValueError(f"unknown cell_type {cell_type!r}")
    dim, nv = CELL_TYPES[cell_type]
    coords = np.asarray(coords, dtype=float)
    if coords.shape != (nv, dim):
        raise ValueError(f"coords must have shape ({nv}, {dim}) for {cell_type}, got {coords.shape}")
    _check_plane(plane, dim)
    mesh = Mesh(coords, np.arange(nv)[None, :], cell_type)
    E_c, nu_c = _cell_materials(mesh, E, nu)
    lam_c, mu_c = lame(E_c, nu_c, plane if dim == 2 else None)
    geo = _Geometry(mesh)
    w = thickness if dim == 2 else 1.0
    return (_skfem_linear_stiffness(geo, lam_c, mu_c) * w).toarray()


def solve_nonlinear(
    mesh: Mesh,
    E,
    nu,
    *,
    fixed,
    prescribed=None,
    nodal_forces=None,
    body_force=None,
    law: str = "svk",
    steps: int = 10,
    tol: float = 1e-8,
    max_iter: int = 30,
    thickness: float = 1.0,
    plane: str = "stress",
    progress: Callable[[int, int], None] | None = None,
    max_halvings: int = 8,
    order: int = 1,
    tractions=(),
    linear_solver="auto",
    volumetric: str = "full",
    initial=None,
    pressures=(),
    curved=(),
) -> FemResult:
    """Geometrically non-linear (total Lagrangian) reference solution with dead loads and pressures.

    ``law``: ``"svk"`` (St Venant-Kirchhoff, Green-Lagrange strain) or ``"neohookean"``
    (``W = mu/2 (I1 - 3) - mu ln J + lam/2 (ln J)^2``). Loads and prescribed displacements are
    applied in ``steps`` equal load-factor increments, solved by the Newton iteration of the
    mass-spring models (:func:`msslib.solvers.static_solve` through
    :mod:`msslib.solvers.displacement`; no line search, direct linear solves): converged when the
    residual force norm on the free dofs is at most ``max(tol * F_ref, floor)``
    (:func:`msslib.solvers.convergence_threshold`), ``F_ref`` the norm of the external load on the
    free dofs (for pure displacement control, of the linear reaction of the prescribed motion),
    ``floor`` the round-off floor :func:`msslib.solvers.roundoff_floor` of
    ``|| |K| |u| + sum_e |f_e| + |load| ||`` on the free dofs at the current iterate (the size of
    what the internal force sums: the displacement gradient differences nodal displacements,
    each element force sums stresses), so that a problem whose ``tol * F_ref`` lies below the
    round-off converges at the floor instead of iterating on it (an increment accepted there is
    listed in ``stats``). A failed increment (no convergence in ``max_iter`` iterations, or an
    inverted element) is halved, at most ``max_halvings`` times in a row and never below
    ``1 / (steps * 2**max_halvings)``; then :class:`msslib.errors.ConvergenceError` (a
    RuntimeError) names the step and the residual. Every converged increment's solution is
    checked for inversion, for every law: ``det F > 0`` at every quadrature point (of each
    quadrature rule of the energy), else :class:`msslib.errors.UnphysicalStateError` (a
    RuntimeError) says in one line the load factor of that solution, the element, its ``det F``
    and the last load factor reached without inversion (attributes ``load``, ``load_reached``,
    ``cell``, ``det_F``): St Venant-Kirchhoff, whose energy depends on ``F^T F`` only, has
    equilibria with inverted elements under strong compression, which are no answer.
    ``initial``: None, or a displacement ``(n_nodes, dim)`` at the mesh's nodes (a guess of the
    solution, e.g. a coarser mesh's at these nodes) from whose linear interpolant at every dof
    Newton starts, with ``steps = 1`` only (ValueError otherwise).
    2D: ``plane="stress"`` (default, as in :func:`solve_linear`; exact plane stress of the 3D law, see
    the module docstring) or ``"strain"`` (``F33 = 1``). ``progress(step, n_steps)`` is called after every converged nominal step.

    ``stats``: ``iterations`` (Newton iterations per converged increment), ``residuals`` (residual
    history per increment, relative to ``F_ref``; ``force_scale`` is ``F_ref``), ``load_factors`` (after each converged increment), ``n_halvings``,
    ``n_dofs``, ``wall_time``, ``solver``, ``tol``, ``roundoff_floor`` and ``threshold`` (of the
    last converged increment, absolute), ``roundoff_steps`` (increments accepted at the floor,
    1-based) and ``messages``.

    ``pressures``: tuples ``(facets, pressure, follow)`` as in :func:`solve_linear`, scaled by the
    load factor. ``follow=False``: dead, normal to the reference surface (added to the external
    forces). ``follow=True``: normal to the current surface (:mod:`msslib.fem.pressure`); its
    force enters the residual and its load stiffness the tangent, which is then not symmetric
    (solved by LU, never by Cholesky or CG). ``strain_energy`` is the internal energy; ``reaction``
    includes the pressure forces at the solution. ``curved``: curved boundary facets of quadratic
    elements, as in :func:`solve_linear`.
    """
    from msslib.fem.newton import NEWTON, newton_solve
    from msslib.fem.pressure import check_pressures, facet_pressures

    t0 = time.perf_counter()
    d = mesh.dim
    if d == 2:
        _check_plane(plane, d)
    if law not in ("svk", "neohookean"):
        raise ValueError(f"law must be 'svk' or 'neohookean', got {law!r}")
    if steps < 1:
        raise ValueError(f"steps={steps!r} must be >= 1")
    if thickness <= 0:
        raise ValueError(f"thickness={thickness!r} must be > 0")
    pressures = check_pressures(pressures, mesh)
    E_c, nu_c = _cell_materials(mesh, E, nu)
    if order == 1:
        warn_locking(mesh, nu_c, plane)
    linear_solver = method_for_material(linear_solver, nu_c)  # nearly incompressible: direct
    lam_c, mu_c = lame(E_c, nu_c)  # 3D constants; plane stress handled inside the law
    geo = _Geometry(mesh, order, curved=curved)
    w = thickness if d == 2 else 1.0
    x0 = None
    if initial is not None:
        guess = np.asarray(initial, dtype=float)
        if guess.shape != (mesh.n_nodes, d) or not np.all(np.isfinite(guess)):
            raise ValueError(f"initial must be None or finite displacements of shape ({mesh.n_nodes}, {d}) (one per "
                             f"node), got shape {guess.shape}" + ("" if guess.shape != (mesh.n_nodes, d) else
                                                                    " with non-finite values"))
        if steps != 1:
            raise ValueError(f"initial is a guess of the solution: it needs steps=1, got steps={steps!r}")
        x0 = np.asarray(geo.interp @ guess).ravel()
    cons, presc, f_ext = _boundary(mesh, fixed, prescribed, nodal_forces, body_force, geo, thickness, tractions)
    loads = facet_pressures(geo, pressures, thickness)
    for load in loads:
        if not load.follow:
            f_ext = f_ext + load.forces()
    followers = [load for load in loads if load.follow]
    free = ~cons
    pl = plane if d == 2 else None
    parts = _parts(mesh, geo, lam_c, mu_c, volumetric, pl)

    pattern = []  # the tangent's CSR pattern, computed once (msslib.fem.kernels)

    def internal(u, tangent=True):
        from msslib.fem.kernels import add_tangent, dof_pattern

        fint, energy, K, fabs, data = 0.0, 0.0, None, 0.0, None
        for g, lam_q, mu_q in parts:
            m, nb = g.dphi.shape[2], g.dphi.shape[0]
            H = g.displacement_gradient(u.reshape(-1, d))
            with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # divergence is detected by the caller
                P, A, W = _law(H, lam_q, mu_q, law, pl, tangent)
            fe = np.einsum("iJmq,aJmq,mq->mai", P, g.dphi, g.dx).reshape(m, nb * d) * w
            fint = fint + g.assemble_vector(fe)
            energy += float(np.sum(W * g.dx) * w)
            if tangent:
                fabs = fabs + g.assemble_vector(np.abs(fe))  # the size of what fint sums: its round-off scale
                if not pattern:
                    pattern.append(dof_pattern(g.nodes, g.n_scalar, d))
                indptr, indices = pattern[0]
                if data is None:
                    data = np.zeros(indices.size)
                # every part has the same dofs: its element matrices are added into the same values
                add_tangent(np.ascontiguousarray(g.dphi), np.ascontiguousarray(A), np.ascontiguousarray(g.dx), float(w),
                            np.ascontiguousarray(g.nodes), d, indptr, indices, data)
        if tangent:
            indptr, indices = pattern[0]
            K = sp.csr_matrix((data, indices, indptr), shape=(geo.n_dofs, geo.n_dofs))
        return fint, K, energy, (fabs if tangent else None)

    reached = [0.0]  # the last load factor whose solution inverts no element

    def admissible(u, load):
        _check_inversion(parts, u.reshape(-1, d), load, reached[0], law)
        reached[0] = load

    u, newton = newton_solve(internal, f_ext, cons, presc, geo.points, steps=steps, tol=tol, max_iter=max_iter,
                             max_halvings=max_halvings, progress=progress, linear_solver=linear_solver,
                             initial=x0, followers=followers, check=admissible)
    fint, _, energy, _ = internal(u, tangent=False)
    r = fint - f_ext - sum((load.forces(u) for load in followers), np.zeros_like(f_ext))
    reaction = np.where(cons, r, 0.0)
    stats = {"n_dofs": int(u.size), "n_free_dofs": int(free.sum()), **newton, "law": law, "plane": pl,
             "wall_time": time.perf_counter() - t0, "solver": NEWTON, "order": order, "volumetric": volumetric}
    return _result(geo, u, reaction, energy, stats)
