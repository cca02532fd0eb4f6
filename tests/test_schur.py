"""The system Newton solve (ropesim/model/schur.py) against a dense solve of the same constrained system.

Random symmetric positive definite block-banded matrices on random lines, joined at random groups (points:
G = I; bodies: G = [I, -[rho]x] with random arms and own blocks), some nodes held: the Schur complement's
answer must equal numpy's dense solve of P^T J P + O with P the map from the free nodes' and the groups'
unknowns to every node's displacement.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from ropesim.model.layout import LineLayout
from ropesim.model.schur import (band_cholesky_range, band_cholesky_reverse, groups_of, schur_factor, schur_solve,
                                 substitute_down, substitute_up)


def lever_matrix(arm: np.ndarray, dim: int, dof: int) -> np.ndarray:
    """G for one constrained node, written out: identity, then the rotation's columns (d theta x rho)."""
    g = np.zeros((dim, dof))
    g[:, :dim] = np.eye(dim)
    if dof == 3 and dim == 2:
        g[:, 2] = [-arm[1], arm[0]]
    elif dof == 6:
        for r in range(3):
            e = np.zeros(3)
            e[r] = 1.0
            g[:, 3 + r] = np.cross(e, arm)
    return g


def random_system(rng: np.random.Generator, dim: int, w: int, sizes: list[int], n_groups: int, bodies: bool):
    """Lines of ``sizes`` nodes, their ends joined at random into groups, a random SPD banded J and a residual."""
    lines, first = [], 0
    for n in sizes:
        lines.append(LineLayout(f"l{len(lines)}", first, n, False, 1.0, 1.0, False))
        first += n
    total = first
    ends = [e for line in lines for e in (line.first, line.end - 1)]
    rng.shuffle(ends)
    members, used = [], set()
    for g in range(n_groups):
        take = [e for e in ends[2 * g:2 * g + 2 + g % 2] if e not in used]
        if not take:
            continue
        used.update(take)
        body = bodies and g % 2 == 1
        dof = (6 if dim == 3 else 3) if body else dim
        arms = rng.normal(size=(3, len(take))) if body else None
        if arms is not None and dim == 2:
            arms[2] = 0.0
        members.append((dof, take, arms))
    held = [i for i in range(total) if i not in used and rng.random() < 0.15]
    nt = total * dim
    jac = np.zeros((nt, nt))
    for line in lines:
        for i in range(line.first, line.end):
            blk = rng.normal(size=(dim, dim))
            jac[i * dim:(i + 1) * dim, i * dim:(i + 1) * dim] += blk @ blk.T + 0.1 * np.eye(dim)
            for j in range(i + 1, min(i + w + 1, line.end)):
                blk = rng.normal(size=(dim, dim))
                k = blk @ blk.T
                a, b = slice(i * dim, (i + 1) * dim), slice(j * dim, (j + 1) * dim)
                jac[a, a] += k
                jac[b, b] += k
                jac[a, b] -= k
                jac[b, a] -= k
    for i in held:
        jac[i * dim:(i + 1) * dim, :] = 0.0
        jac[:, i * dim:(i + 1) * dim] = 0.0
        jac[i * dim:(i + 1) * dim, i * dim:(i + 1) * dim] = np.eye(dim)
    rhs = rng.normal(size=nt)
    for i in held:
        rhs[i * dim:(i + 1) * dim] = 0.0
    return lines, members, held, jac, rhs


def dense_reference(jac, rhs, members, own, own_rhs, dim, total):
    """Solve the constrained system densely: unknowns (free nodes' displacements, the groups' unknowns)."""
    constrained = {i for _, nodes, _ in members for i in nodes}
    free = [i for i in range(total) if i not in constrained]
    m = sum(dof for dof, _, _ in members)
    nt = total * dim
    p = np.zeros((nt, len(free) * dim + m))
    for col, i in enumerate(free):
        p[i * dim:(i + 1) * dim, col * dim:(col + 1) * dim] = np.eye(dim)
    offset = len(free) * dim
    for dof, nodes, arms in members:
        for k, i in enumerate(nodes):
            arm = arms[:, k] if arms is not None else np.zeros(3)
            p[i * dim:(i + 1) * dim, offset:offset + dof] = lever_matrix(arm, dim, dof)
        offset += dof
    reduced = p.T @ jac @ p
    reduced[len(free) * dim:, len(free) * dim:] += own
    right = p.T @ rhs
    right[len(free) * dim:] += own_rhs
    return p @ np.linalg.solve(reduced, right)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), dim=st.sampled_from([2, 3]), w=st.sampled_from([1, 2]),
       sizes=st.lists(st.integers(2, 9), min_size=1, max_size=5), n_groups=st.integers(0, 4),
       bodies=st.booleans())
def test_schur_solve_equals_the_dense_solve(seed, dim, w, sizes, n_groups, bodies):
    rng = np.random.default_rng(seed)
    lines, members, held, jac, rhs = random_system(rng, dim, w, sizes, n_groups, bodies)
    total = lines[-1].end
    groups = groups_of(lines, members, dim, w, total)
    m = groups.s.shape[0]
    own = np.zeros((m, m))
    for g, (dof, _, arms) in enumerate(members):
        if arms is not None:   # a body's own blocks: positive definite, and not symmetric (gyroscopic-like)
            blk = rng.normal(size=(dof, dof))
            skew = rng.normal(size=(dof, dof))
            own[groups.offset[g]:groups.offset[g + 1], groups.offset[g]:groups.offset[g + 1]] = (
                blk @ blk.T + np.eye(dof) + 0.3 * (skew - skew.T))
    own_rhs = rng.normal(size=m) * np.repeat([arms is not None for _, _, arms in members],
                                             [dof for dof, _, _ in members]) if m else np.zeros(0)
    groups.own[:] = own
    groups.own_rhs[:] = own_rhs
    expected = dense_reference(jac, rhs, members, own, own_rhs, dim, total)

    nt = total * dim
    p = (w + 1) * dim - 1
    band = np.zeros((p + 1, nt))
    for q in range(p + 1):
        band[q, :max(nt - q, 0)] = np.diagonal(jac, -q)
    table = np.array([[line.first, line.end] for line in lines], dtype=np.int64)
    assert schur_factor(band, w, table, groups)
    got = rhs.copy()
    schur_solve(band, w, table, groups, got)
    scale = np.abs(expected).max()
    assert np.allclose(got, expected, rtol=1e-8, atol=1e-9 * scale)
    for _, nodes, arms in members:   # a point's nodes move as one, to the last bit
        if arms is None:
            first = got[nodes[0] * dim:(nodes[0] + 1) * dim]
            for i in nodes[1:]:
                assert np.array_equal(got[i * dim:(i + 1) * dim], first)


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 30), p=st.integers(1, 7))
def test_both_band_factorisations_solve_the_banded_system(seed, n, p):
    """L L^T from the top and U U^T from the bottom, each with its two substitutions, against numpy."""
    rng = np.random.default_rng(seed)
    a = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - p), i + 1):
            a[i, j] = a[j, i] = rng.normal()
    a += np.eye(n) * (np.abs(a).sum(axis=1).max() + 1.0)
    r = rng.normal(size=n)
    expected = np.linalg.solve(a, r)
    for factor, first, second in ((band_cholesky_range, substitute_down, substitute_up),
                                  (band_cholesky_reverse, substitute_up, substitute_down)):
        band = np.zeros((p + 1, n + 3))             # padded: the range is columns 1 .. n
        for q in range(p + 1):
            band[q, 1:1 + max(n - q, 0)] = np.diagonal(a, -q)
        assert factor(band, p, 1, n + 1)
        z = np.concatenate([[0.0], r, [0.0, 0.0]])
        ends = (1, n + 1)
        first(band, p, z, 1, n + 1, ends[0] if first is substitute_down else ends[1])
        second(band, p, z, 1, n + 1, ends[0] if second is substitute_down else ends[1])
        assert np.allclose(z[1:n + 1], expected, rtol=1e-10, atol=1e-12 * np.abs(expected).max())
