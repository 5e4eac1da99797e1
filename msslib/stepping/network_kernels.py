"""Explicit steps of a general 3D spring network (any mesh): symplectic Euler with the spring
forces and the position update fused in one pass over the nodes.

Layout: every spring is stored once, under its lower node ``a`` (``a < b``), the springs sorted by
``a`` then ``b`` (``rowptr`` offsets by node, ``ia`` and ``ib`` the two ends, ``kl`` the constants
and rest lengths interleaved).  A pass visits the nodes in order, in blocks of :data:`BLOCK`; the
force on node ``a`` is complete once the rows of its block are done, because every spring
``(c, a)`` with ``c < a`` was visited in that block or an earlier one and scattered into ``a``'s
accumulator.  The block's nodes are then advanced at once (``v = damp v + w F``, ``x += h v``)
while they are in cache: later rows only read nodes ``b > a``, which are not advanced yet, so the
pass computes the forces of one state and advances it, exactly as the two-pass scheme (forces of
every spring, then every node).  One pass reads each spring's 24 bytes once and each node's
state once.

Each node's position and force accumulator are one record of six numbers (``R[:, :3]`` the
positions, ``R[:, 3:]`` the accumulator): the other end of a spring is read and written in one
cache line instead of two, which doubles the speed when the mesh's numbering scatters the springs
(a gmsh mesh of 5 10^5 springs: 48 to 99 M spring-steps/s); the positions are the view
``R[:, :3]``.

The scheme is that of :func:`msslib.stepping.integrate` with ``method="symplectic_euler"`` and
mass-proportional damping: ``v+ = v + h M^-1 (F(x) - alpha M v)``, ``x+ = x + h v+``, written as
``v+ = damp v + w F`` with ``damp = 1 - h alpha`` on free dofs and ``w = h / m`` (0 on fixed dofs,
which keep their position: prescribed motion sets them between steps).

Each force pass also writes what the divergence detector of :mod:`msslib.stepping.generic` needs
for the step whose end state it evaluates (``v.v``, ``F.M^-1 F_prev``, ``v.(F - F_prev)``,
``F.M^-1 F`` over the free dofs and ``max |x - x_ref|``), and the support reactions ``-F`` on the
fixed dofs, so that the state, the force and the reaction are current after every call.

Node numbering matters for large networks: :func:`cache_order` picks reverse Cuthill-McKee for a
large network whose numbering scatters its springs, and :class:`msslib.stepping.network.NetworkStepper`
steps in that numbering internally (the state comes back in the model's).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from msslib.terms.jit import UINT

# fast-math without nnan/ninf: the monitor must see a non-finite state
_FAST = {"nsz", "arcp", "contract", "afn"}

BLOCK = 64  # nodes advanced together after their springs (see fused_pass)

__all__ = ["network_terms", "network_layout", "records", "network_steps", "network_forces", "N_MONITOR",
           "cache_order"]

N_MONITOR = 5  # columns of a monitor row: q, pf, ku, r, dmax


def network_terms(model):
    """``(springs, others, why)``: the 3D spring terms (which the kernel runs), the other
    internal terms (their forces are added before each pass), or ``why`` the model cannot run on
    the network kernels (None when it can).  Dead external loads (no stiffness) go into the
    constant external force."""
    if getattr(model, "dim", None) != 3:
        return [], [], "the network engine is 3D"
    springs, others = [], []
    for t in model.terms:
        if t.kind == "springs" and getattr(t, "dim", 3) == 3 and hasattr(t, "rest_length"):
            springs.append(t)
        elif t.kind == "external" and t.abs_row_sums(np.zeros(0), 1.0, np.zeros(0), np.zeros(0)):
            continue  # dead loads: in the external force
        elif t.scales_with_load:
            return [], [], f"{type(t).__name__} scales with the load and is not a dead load"
        else:
            others.append(t)
    if not springs:
        return [], [], "the model has no springs"
    return springs, others, None


def network_layout(conn, k, rest_length, n_nodes: int):
    """``(rowptr, ia, ib, kl)`` of springs ``conn`` (s, 2) with constants ``k`` and rest lengths:
    each spring under its lower node ``ia``, sorted by lower then upper node ``ib`` (see the module
    docstring)."""
    conn = np.asarray(conn, dtype=np.int64).reshape(-1, 2)
    a = np.minimum(conn[:, 0], conn[:, 1])
    b = np.maximum(conn[:, 0], conn[:, 1])
    if len(conn) and (np.any(a == b) or a.min() < 0 or b.max() >= n_nodes):
        raise ValueError("springs must join two different nodes of the network")
    order = np.lexsort((b, a))
    rowptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(a, minlength=n_nodes), out=rowptr[1:])
    kl = np.empty(2 * len(conn))
    kl[0::2] = np.asarray(k, dtype=float)[order]
    kl[1::2] = np.asarray(rest_length, dtype=float)[order]
    idx_t = np.int32 if n_nodes < 2**31 else np.int64
    return (rowptr, np.ascontiguousarray(a[order], dtype=idx_t), np.ascontiguousarray(b[order], dtype=idx_t), kl)


# below this many nodes the records, velocities and forces of a network fit in a core's cache:
# no renumbering pays
REORDER_MIN_NODES = 8192
# the factor by which reverse Cuthill-McKee must shorten the springs' mean index span to be used
REORDER_GAIN = 1.5


def cache_order(conn, n_nodes: int):
    """A renumbering of the nodes for the pass's locality, or None to keep theirs: ``order`` with
    internal node ``i`` = given node ``order[i]`` (reverse Cuthill-McKee on the springs' graph),
    when the network is large enough (:data:`REORDER_MIN_NODES`) and the springs' mean index span
    ``|a - b|`` is at least :data:`REORDER_GAIN` times smaller in that order (a numbering already banded is kept)."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import reverse_cuthill_mckee

    conn = np.asarray(conn, dtype=np.int64).reshape(-1, 2)
    if n_nodes < REORDER_MIN_NODES or not len(conn):
        return None
    g = csr_matrix((np.ones(2 * len(conn), dtype=np.int8), (conn.ravel(), conn[:, ::-1].ravel())),
                   shape=(n_nodes, n_nodes))
    order = reverse_cuthill_mckee(g, symmetric_mode=True).astype(np.int64)
    new = np.empty(n_nodes, dtype=np.int64)
    new[order] = np.arange(n_nodes)
    span = float(np.abs(conn[:, 0] - conn[:, 1]).mean())
    span_new = float(np.abs(new[conn[:, 0]] - new[conn[:, 1]]).mean())
    return order if REORDER_GAIN * span_new <= span else None


@njit(cache=True, nogil=True)
def gather_state(R, v, x, vu, order):
    """The node records' positions and the velocities in the pass's numbering from the given
    numbering's ``x`` (n, 3) and ``vu`` (flat): internal node ``i`` is node ``order[i]``."""
    for i in range(order.shape[0]):
        o = order[i]
        for c in range(3):
            R[i, c] = x[o, c]
            v[3 * i + c] = vu[3 * o + c]


@njit(cache=True, nogil=True)
def scatter_state(R, v, F, react, x, vu, Fu, ru, order):
    """The state of the pass's numbering (positions, velocities, forces, reactions) written into
    the given numbering's arrays (the inverse of :func:`gather_state`)."""
    for i in range(order.shape[0]):
        o = order[i]
        for c in range(3):
            x[o, c] = R[i, c]
            vu[3 * o + c] = v[3 * i + c]
            Fu[3 * o + c] = F[3 * i + c]
            ru[3 * o + c] = react[3 * i + c]


def records(x) -> np.ndarray:
    """The node records ``(n_nodes, 6)`` of flat positions ``x`` (accumulators zero)."""
    x = np.asarray(x, dtype=float).reshape(-1, 3)
    R = np.zeros((len(x), 6))
    R[:, :3] = x
    return R


@njit(cache=True, nogil=True, error_model="numpy", fastmath=_FAST, inline="always")
def fused_pass(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, row, advance, exact):
    """One pass: the force ``F`` at the positions ``R[:, :3]`` (springs + the accumulators
    ``R[:, 3:]``, which hold the other forces and are zeroed, + ``fext``), the monitor row
    ``mon[row]`` (over the free dofs, ``w != 0``; the masses are ``h / w``; its first column is
    ``v.v``, whose finiteness is checked), the reactions; then, if
    ``advance``, the symplectic Euler update of each node as soon as its force is complete.
    ``exact``: the monitor's ``max |x - x_ref|`` is computed (else its column is -1: the caller
    bounds it, see :func:`fused_steps_lean`).

    The nodes go in blocks of :data:`BLOCK`: one loop over the springs of a block's rows adds
    each spring's force into both ends' accumulators, then the block's nodes are advanced (their
    forces are complete: the springs that reach them from lower rows are done).  A loop over
    the springs of one row at a time would end at an unpredictable count every few springs.  The
    sums are those of a row-by-row pass, in the same order (bitwise the same forces)."""
    q = 0.0
    pf = 0.0
    ku = 0.0
    r = 0.0
    dmax = 0.0
    hinv = 1.0 / h
    n = rowptr.shape[0] - 1
    for a0 in range(0, n, BLOCK):
        a1 = min(a0 + BLOCK, n)
        for s in range(rowptr[a0], rowptr[a1]):
            na = UINT(ia[UINT(s)])
            b = UINT(ib[UINT(s)])
            d0 = R[b, 0] - R[na, 0]
            d1 = R[b, 1] - R[na, 1]
            d2 = R[b, 2] - R[na, 2]
            l = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
            c = kl[2 * s] * (l - kl[2 * s + 1]) / l
            f0 = d0 * c
            f1 = d1 * c
            f2 = d2 * c
            R[na, 3] += f0
            R[na, 4] += f1
            R[na, 5] += f2
            R[b, 3] -= f0
            R[b, 4] -= f1
            R[b, 5] -= f2
        for na in range(a0, a1):
            a = 3 * na
            ga0 = R[na, 3]
            ga1 = R[na, 4]
            ga2 = R[na, 5]
            R[na, 3] = 0.0
            R[na, 4] = 0.0
            R[na, 5] = 0.0
            for i in range(3):
                j = a + i
                fj = (ga0 if i == 0 else (ga1 if i == 1 else ga2)) + fext[j]
                fo = F[j]
                F[j] = fj
                vj = v[j]
                if exact:
                    dj = abs(R[na, i] - x_ref[j])
                    if not dj <= dmax:  # larger, or not a number
                        dmax = dj if dmax == dmax else dmax
                wj = w[j]
                if wj != 0.0:
                    g = fj * wj  # h F / m: the sums over the masses are h times theirs
                    q += vj * vj  # only its finiteness is checked: no mass needed
                    pf += g * fo
                    ku += vj * (fj - fo)
                    r += g * fj
                    if advance:
                        vj = damp * vj + wj * fj
                        v[j] = vj
                        R[na, i] += h * vj
                else:
                    react[j] = -fj
    mon[row, 0] = q
    mon[row, 1] = pf * hinv
    mon[row, 2] = ku
    mon[row, 3] = r * hinv
    mon[row, 4] = dmax if exact else -1.0


@njit(cache=True, nogil=True, error_model="numpy", fastmath=_FAST)
def fused_advance(R, v, F, w, damp, h):
    """The update of every node from the current force ``F`` (no force evaluation)."""
    for j in range(v.shape[0]):
        if w[j] != 0.0:
            vj = damp * v[j] + w[j] * F[j]
            v[j] = vj
            R[j // 3, j % 3] += h * vj


@njit(cache=True, nogil=True, error_model="numpy", fastmath=_FAST)
def fused_steps(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, n_steps):
    """``n_steps >= 1`` steps (the callers check: an early return here for ``n_steps < 1`` makes
    the compiled steps 4-5 % slower, measured at 122 k springs)."""
    fused_advance(R, v, F, w, damp, h)
    # the pass is inlined twice with a constant ``advance``: the loop over the nodes carries no
    # test of it
    for p in range(n_steps - 1):
        fused_pass(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, p, True, True)
    fused_pass(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, n_steps - 1, False, True)


@njit(cache=True, nogil=True, error_model="numpy", fastmath=_FAST)
def fused_steps_lean(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, n_steps):
    """:func:`fused_steps` without the monitor's ``max |x - x_ref|`` (4-5 % of a step at 122 k
    springs), for steps in which only the update moves nodes (no drive): there
    ``|x_{p+1} - x_ref| <= |x_p - x_ref| + h max|v_{p+1}|`` and ``max|v| <= sqrt(v.v)``, the
    monitor's first column, so the caller bounds it from the state before the call
    (:meth:`msslib.stepping.network.NetworkStepper._steps`)."""
    fused_advance(R, v, F, w, damp, h)
    for p in range(n_steps - 1):
        fused_pass(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, p, True, False)
    fused_pass(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, n_steps - 1, False, False)


def network_forces(state, layout, mon, row: int = 0):
    """Evaluate the force at the current positions (no update): ``state`` = ``(R, v, F, w, damp,
    h, fext, x_ref, react)`` (``R`` from :func:`records`, ``w = h / m`` on the free dofs, 0 on the
    fixed ones); ``F`` becomes the force."""
    R, v, F, w, damp, h, fext, x_ref, react = state
    rowptr, ia, ib, kl = layout
    fused_pass(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, row, False, True)


def network_steps(state, layout, mon, n_steps: int):
    """``n_steps`` symplectic Euler steps from a state whose force ``F`` is current; the force,
    the reactions and ``mon[0:n_steps]`` (the monitor of each step's end state) are current
    after the call.  The accumulators must be zero (spring-only networks)."""
    if int(n_steps) < 1:
        return
    R, v, F, w, damp, h, fext, x_ref, react = state
    rowptr, ia, ib, kl = layout
    fused_steps(R, v, F, rowptr, ia, ib, kl, w, damp, h, fext, x_ref, react, mon, int(n_steps))
