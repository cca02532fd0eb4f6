"""Solves with a system's Newton matrix: each line banded, the points' and bodies' few unknowns by a Schur
complement. O(N) per factorisation and per solve.

A system's lines are runs of consecutive nodes (:mod:`ropesim.model.layout`), and a force term couples a node
only to nodes of its own line at most ``w`` places away (:mod:`ropesim.model.jacobian`). So the node-ordered
Newton matrix J (its lower triangle in the band, as for a rope) is block diagonal over the lines, each block
banded. The lines meet at *groups*: a free point where two or more lines end, whose line-end nodes move as one
(:mod:`ropesim.model.junctions`), and a free rigid body, whose line-end nodes move with it. A group g has a
few unknowns u_g (a point: its D displacements; a body: 6 in 3-D, 3 in 2-D) and each of its constrained
nodes c (a line end on it) follows them through a linearised map

    dx_c = G_c du_g,   G_c = I (a point),   G_c = [I, -[rho_c]x] (a body: rho_c the node's arm from the body's
                                                                 reference point, the rotation a small rotation
                                                                 vector; in 2-D the columns (1, 0), (0, 1) and
                                                                 (-rho_y, rho_x)).

Substituting x = P (x_f, u), with P the identity on the other nodes and G_c on each constrained node, into the
Newton system J dx = r and taking P^T of its rows (a group's equation is the sum over its nodes of G_c^T times
the node's row, as :func:`~ropesim.model.junctions.move_junctions` sums a point's forces) gives

    [ A    B ] [dx_f]   [r_f]
    [ B^T  C ] [du  ] = [r_u],     r_u = o_u + sum_c G_c^T r_c,

- A: J with every constrained node's rows and columns replaced by the identity (and a zero right-hand side):
  still block diagonal over the lines, each block banded and, like J, symmetric positive definite;
- B: the couplings J[j, c] G_c between a constrained node c and its line neighbours j (|j - c| <= w), nonzero
  only in the w nodes next to each line end on a group;
- C = O + sum_(c, c') G_c^T J[c, c'] G_c' over pairs of constrained nodes of one line at most w apart (each
  node's own block, and two ends of a short line), plus the group's own blocks O (a body's mass, its added
  mass, the Jacobian of its own forces; zero for a point, whose own mass is lumped at its first node), and
  o_u the group's own part of the residual (a body's; zero for a point).

Eliminating dx_f leaves the small dense Schur complement

    S du = r_u - B^T A^-1 r_f,   S = C - B^T A^-1 B,   then   dx_f = A^-1 (r_f - B du),   dx_c = G_c du.

**Cost.** Each line's block is factored on its own, A_l = L L^T from its first node (the banded Cholesky of
:mod:`ropesim.model.banded`), or A_l = U U^T from its last node (U upper banded) when its start is on a group
and its end is not. Then A^-1 B = F^-T W with W = F^-1 B (F = L or U), and B^T A^-1 B = W^T W. Because F^-1
substitutes from the factor's first row, W is nonzero only from B's first nonzero row onwards: a line end on a
group that the factor reaches last costs O(w) rows, not the line's length. Only a line with groups at both
ends carries one group's columns along its whole length (the coupling between its two ends travels through
it). A solve is one forward and one backward substitution per line, with the small solve for du between:

    f = F^-1 r_f,   du = S^-1 (r_u - W^T f),   dx_f = F^-T (f - W du).

Per Newton iteration: the lines' banded factorisations O(N w^2 D^3), the group columns O(w D^2 k) per line end
on a group (O(n_l w D^2 k) on a line with groups at both ends), S O(k^2) per line end, its LU factorisation
O(m^3) for the m group unknowns (m = D per point, 6 per body): linear in the nodes.

The Schur complement S is symmetric positive definite where J is (P^T J P with P of full rank); a body's
gyroscopic and rotational geometric terms make O, and so S, non-symmetric, so S is factored by LU with partial
pivoting (:func:`lu_factor`).

Storage (:class:`Groups`): the groups' constrained nodes (members), their arms and groups; per line the member
on each end ("slot" 0 for its first node, 1 for its last) and the direction its block is factored in; W, one
column per slot's unknown (N D, 2 k_max), k_max a group's largest number of unknowns; S, its pivots, O and o_u.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import jit
from .banded import (band_cholesky_range, band_cholesky_reverse, substitute_columns_down, substitute_columns_up,
                     substitute_down, substitute_up)

Groups = namedtuple("Groups", ["start", "nodes", "arm", "group", "member", "offset", "slots", "reverse", "rows",
                               "w", "s", "piv", "own", "own_rhs", "du"])
"""A system's groups (see the module doc), for the compiled code. Members: start (G + 1,) int64, group g's
members ``start[g]:start[g + 1]``; nodes (K,) int64, each member's node; arm (3, K) [m], each member's arm
rho_c from its body's reference point (zero on a point; kept up to date by the integrator); group (K,) int64,
each member's group; member (N,) int64, each node's member or -1. offset (G + 1,) int64: group g's unknowns
are u[offset[g]:offset[g + 1]]. Lines: slots (L, 2) int64, the member on each line's first and last node or
-1; reverse (L,) bool, the line's block factored from its last node; rows (L, 2, 2) int64, the rows [lo, hi)
of the matrix where each slot's columns of W may be nonzero. Scratch: w (N D, 2 k_max), s (m, m), piv (m,)
int64, du (m,). Filled by the integrator: own (m, m), the groups' own blocks O; own_rhs (m,), their own
residual o_u (both zero for points). Slot s's columns of W are ``w[:, s k_max:(s + 1) k_max]``."""


def groups_of(lines, members: list[tuple[int, list[int], np.ndarray | None]], dim: int, w: int,
              nodes: int) -> Groups:
    """The compiled description of ``members``, one (unknowns, line-end nodes, arms (3, K) or None for zero)
    per group, on the model's ``lines`` (:class:`~ropesim.model.layout.LineLayout`) with a Newton matrix of
    block half-width ``w``."""
    start = np.zeros(len(members) + 1, dtype=np.int64)
    offset = np.zeros(len(members) + 1, dtype=np.int64)
    for g, (dof, group_nodes, _) in enumerate(members):
        start[g + 1] = start[g] + len(group_nodes)
        offset[g + 1] = offset[g] + dof
    node_of = np.array([i for _, group_nodes, _ in members for i in group_nodes], dtype=np.int64)
    arm = np.zeros((3, node_of.size))
    for g, (_, _, arms) in enumerate(members):
        if arms is not None:
            arm[:, start[g]:start[g + 1]] = arms
    group = np.repeat(np.arange(len(members), dtype=np.int64), np.diff(start))
    member = np.full(nodes, -1, dtype=np.int64)
    member[node_of] = np.arange(node_of.size)
    slots = np.full((len(lines), 2), -1, dtype=np.int64)
    reverse = np.zeros(len(lines), dtype=np.bool_)
    rows = np.zeros((len(lines), 2, 2), dtype=np.int64)
    for l, line in enumerate(lines):
        slots[l] = member[line.first], member[line.end - 1]
        reverse[l] = slots[l, 0] >= 0 and slots[l, 1] < 0
        near_start = (line.first * dim, min(line.first + w + 1, line.end) * dim)
        near_end = (max(line.end - 1 - w, line.first) * dim, line.end * dim)
        whole = (line.first * dim, line.end * dim)
        rows[l, 0] = near_start if reverse[l] else whole
        rows[l, 1] = near_end
    k_max = max((dof for dof, _, _ in members), default=0)
    m = int(offset[-1])
    return Groups(start, node_of, arm, group, member, offset, slots, reverse, rows,
                  np.zeros((nodes * dim, 2 * k_max)), np.zeros((m, m)), np.zeros(m, dtype=np.int64),
                  np.zeros((m, m)), np.zeros(m), np.zeros(m))


def no_groups(dim: int) -> Groups:
    """The empty bundle (a rope, or a system whose lines meet at no free point or body)."""
    return groups_of((), [], dim, 1, 0)


# ------------------------------------------------------------------------------------ the small pieces
# lever and entry are compiled once each and linked, not inlined by Numba at each of their eight call sites
# (Numba types an inlined body again at every site: 0.9 s more of a system's first run); LLVM still inlines
# them into the loops, at the same speed.


@jit.kernel
def lever(arm, k, dim, dof, b, col):
    """G_k[b, col] for member k (see the module doc): the identity on the translations, -[rho]x on a 3-D
    rotation vector, (-rho_y, rho_x) on a 2-D rotation."""
    if col < dim:
        return 1.0 if b == col else 0.0
    if dim == 2:
        return -arm[1, k] if b == 0 else arm[0, k]
    r = col - 3
    if b == r:
        return 0.0
    sign = 1.0 if (r - b) % 3 == 1 else -1.0     # -[rho]x[b, r] = +-rho of the third axis
    return sign * arm[3 - b - r, k]


@jit.kernel
def entry(band, row, col):
    """J[row, col] of the symmetric matrix whose lower triangle ``band`` holds."""
    return band[row - col, col] if row >= col else band[col - row, row]


@jit.kernel
def lu_factor(a, piv):
    """LU factorisation with partial pivoting of the square ``a`` in place (L unit lower, U upper), the row
    swaps in ``piv``; False when a pivot is zero (a singular matrix)."""
    m = a.shape[0]
    for col in range(m):
        best = col
        for i in range(col + 1, m):
            if abs(a[i, col]) > abs(a[best, col]):
                best = i
        piv[col] = best
        if not a[best, col] != 0.0:
            return False
        if best != col:
            for j in range(m):
                a[col, j], a[best, j] = a[best, j], a[col, j]
        for i in range(col + 1, m):
            f = a[i, col] / a[col, col]
            a[i, col] = f
            for j in range(col + 1, m):
                a[i, j] -= f * a[col, j]
    return True


@jit.kernel
def lu_solve(a, piv, b):
    """Solve with :func:`lu_factor`'s factors, in place into ``b``."""
    m = a.shape[0]
    for col in range(m):
        best = piv[col]
        if best != col:
            b[col], b[best] = b[best], b[col]
    for i in range(m):
        s = b[i]
        for j in range(i):
            s -= a[i, j] * b[j]
        b[i] = s
    for i in range(m - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, m):
            s -= a[i, j] * b[j]
        b[i] = s / a[i, i]


# ------------------------------------------------------------------------------------ factor and solve


@jit.kernel
def schur_factor(band, w, lines, groups):
    """Factor the Newton matrix whose lower triangle ``band`` holds (every constrained node assembled as a free
    node; block half-width ``w`` nodes) for :func:`schur_solve`: take out B and C, replace the constrained
    nodes' rows by the identity, factor each line's block, form W and S = O + C - W^T W and factor S (see the
    module doc). False when a line's block or S is singular."""
    start, nodes, arm, group, member, offset = (groups.start, groups.nodes, groups.arm, groups.group,
                                                groups.member, groups.offset)
    slots, reverse, rows, wmat, s, piv = groups.slots, groups.reverse, groups.rows, groups.w, groups.s, groups.piv
    own = groups.own
    p = band.shape[0] - 1
    dim = (p + 1) // (w + 1)
    m = s.shape[0]
    k_max = wmat.shape[1] // 2
    for a in range(m):
        for b in range(m):
            s[a, b] = own[a, b]
    for line in range(lines.shape[0]):
        first, end = lines[line, 0], lines[line, 1]
        for slot in range(2):
            k = slots[line, slot]
            if k < 0:
                continue
            c = first if slot == 0 else end - 1
            g = group[k]
            dof = offset[g + 1] - offset[g]
            lo, hi = rows[line, slot, 0], rows[line, slot, 1]
            for r in range(lo, hi):
                for col in range(slot * k_max, slot * k_max + dof):
                    wmat[r, col] = 0.0
            for j in range(max(first, c - w), min(end, c + w + 1)):
                other = member[j]
                if other < 0:        # a line node: its coupling to the group, B[j, :] = J[j, c] G_c
                    for a in range(dim):
                        for col in range(dof):
                            val = 0.0
                            for b in range(dim):
                                val += entry(band, j * dim + a, c * dim + b) * lever(arm, k, dim, dof, b, col)
                            wmat[j * dim + a, slot * k_max + col] = val
                    continue
                g2 = group[other]     # another constrained node (or c itself): G_c^T J[c, j] G_j into C
                dof2 = offset[g2 + 1] - offset[g2]
                for col in range(dof):
                    for col2 in range(dof2):
                        val = 0.0
                        for a in range(dim):
                            ga = lever(arm, k, dim, dof, a, col)
                            if ga == 0.0:
                                continue
                            for b in range(dim):
                                val += ga * entry(band, c * dim + a, j * dim + b) * lever(arm, other, dim, dof2, b,
                                                                                          col2)
                        s[offset[g] + col, offset[g2] + col2] += val
    for k in range(nodes.shape[0]):      # the constrained rows and columns become the identity
        c = nodes[k]
        for b in range(dim):
            col = c * dim + b
            for q in range(p + 1):
                if col + q < band.shape[1]:
                    band[q, col] = 0.0
                if col - q >= 0 and q > 0:
                    band[q, col - q] = 0.0
            band[0, col] = 1.0
    for line in range(lines.shape[0]):
        r0, r1 = lines[line, 0] * dim, lines[line, 1] * dim
        if reverse[line]:
            ok = band_cholesky_reverse(band, p, r0, r1)
        else:
            ok = band_cholesky_range(band, p, r0, r1)
        if not ok:
            return False
        for slot in range(2):
            k = slots[line, slot]
            if k < 0:
                continue
            dof = offset[group[k] + 1] - offset[group[k]]
            lo, hi = rows[line, slot, 0], rows[line, slot, 1]
            if reverse[line]:
                substitute_columns_up(band, p, wmat, r0, r1, hi, slot * k_max, slot * k_max + dof)
            else:
                substitute_columns_down(band, p, wmat, r0, r1, lo, slot * k_max, slot * k_max + dof)
        for slot in range(2):             # S -= W_slot^T W_slot2 over the rows where both may be nonzero
            k = slots[line, slot]
            if k < 0:
                continue
            g = group[k]
            for slot2 in range(2):
                k2 = slots[line, slot2]
                if k2 < 0:
                    continue
                g2 = group[k2]
                lo = max(rows[line, slot, 0], rows[line, slot2, 0])
                hi = min(rows[line, slot, 1], rows[line, slot2, 1])
                dof, dof2 = offset[g + 1] - offset[g], offset[g2 + 1] - offset[g2]
                for r in range(lo, hi):
                    for col in range(dof):
                        wr = wmat[r, slot * k_max + col]
                        for col2 in range(dof2):
                            s[offset[g] + col, offset[g2] + col2] -= wr * wmat[r, slot2 * k_max + col2]
    return lu_factor(s, piv)


@jit.kernel
def schur_solve(band, w, lines, groups, rhs):
    """Solve the system :func:`schur_factor` factored, in place into ``rhs`` (flat, node-major, as the
    Newton matrix's unknowns): a constrained node's entries are its share of its group's equation on entry
    (the group's is the sum of G_c^T times them, plus ``own_rhs``), its displacement G_c du on return."""
    nodes, arm, group, offset = groups.nodes, groups.arm, groups.group, groups.offset
    slots, reverse, rows, wmat, s, piv, du = (groups.slots, groups.reverse, groups.rows, groups.w, groups.s,
                                              groups.piv, groups.du)
    p = band.shape[0] - 1
    dim = (p + 1) // (w + 1)
    k_max = wmat.shape[1] // 2
    for a in range(du.shape[0]):
        du[a] = groups.own_rhs[a]
    for k in range(nodes.shape[0]):
        g, c = group[k], nodes[k]
        dof = offset[g + 1] - offset[g]
        for col in range(dof):
            val = 0.0
            for b in range(dim):
                val += lever(arm, k, dim, dof, b, col) * rhs[c * dim + b]
            du[offset[g] + col] += val
        for b in range(dim):
            rhs[c * dim + b] = 0.0
    for line in range(lines.shape[0]):    # f = F^-1 r, then r_u - W^T f
        r0, r1 = lines[line, 0] * dim, lines[line, 1] * dim
        if reverse[line]:
            substitute_up(band, p, rhs, r0, r1, r1)
        else:
            substitute_down(band, p, rhs, r0, r1, r0)
        for slot in range(2):
            k = slots[line, slot]
            if k < 0:
                continue
            g = group[k]
            first, dof = offset[g], offset[g + 1] - offset[g]
            for r in range(rows[line, slot, 0], rows[line, slot, 1]):
                f = rhs[r]
                for col in range(dof):
                    du[first + col] -= wmat[r, slot * k_max + col] * f
    lu_solve(s, piv, du)
    for line in range(lines.shape[0]):    # dx_f = F^-T (f - W du)
        r0, r1 = lines[line, 0] * dim, lines[line, 1] * dim
        for slot in range(2):
            k = slots[line, slot]
            if k < 0:
                continue
            g = group[k]
            first, dof = offset[g], offset[g + 1] - offset[g]
            for r in range(rows[line, slot, 0], rows[line, slot, 1]):
                val = 0.0
                for col in range(dof):
                    val += wmat[r, slot * k_max + col] * du[first + col]
                rhs[r] -= val
        if reverse[line]:
            substitute_down(band, p, rhs, r0, r1, r0)
        else:
            substitute_up(band, p, rhs, r0, r1, r1)
    for k in range(nodes.shape[0]):
        g, c = group[k], nodes[k]
        dof = offset[g + 1] - offset[g]
        for b in range(dim):
            val = 0.0
            for col in range(dof):
                val += lever(arm, k, dim, dof, b, col) * du[offset[g] + col]
            rhs[c * dim + b] = val


def model_groups(model, w: int, bodies: bool = True, arms: bool = True) -> Groups:
    """The groups of ``model``'s Newton matrix (block half-width ``w``): its free points where lines meet
    (:class:`~ropesim.model.junctions.Junctions`), then (with ``bodies``) its free rigid bodies, their arms at their
    initial poses (:mod:`ropesim.model.body_groups`; with ``arms`` False left zero for the caller to place: the
    static solver of an explicit method, which compiles no :func:`set_body_arms`); the empty bundle for a
    rope."""
    from .body_groups import body_unknowns, set_body_arms

    junctions, free = model.params.junctions, model.params.bodies if bodies else None
    members = []
    if junctions is not None:
        members += [(model.dim, [int(i) for i in junctions.nodes[a:b]], None)
                    for a, b in zip(junctions.start[:-1], junctions.start[1:])]
    first = sum(len(nodes) for _, nodes, _ in members)
    if free is not None:
        members += [(body_unknowns(model.dim), [int(i) for i in free.nodes[a:b]], None)
                    for a, b in zip(free.start[:-1], free.start[1:])]
    if not members:
        return no_groups(model.dim)
    groups = groups_of(model.lines, members, model.dim, w, model.nodes)
    if free is not None and arms:
        set_body_arms(groups.arm, first, free, model.body_pose0)
    return groups
