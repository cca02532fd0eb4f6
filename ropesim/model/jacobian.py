"""Where force terms put their Jacobian blocks: the rope's symmetric block-banded matrix, for the stiff integrator.

The stiff integrator (:mod:`ropesim.integrate.sdirk`) solves with the matrix M (1 + beta gamma) + beta^2 H +
beta C_v, H the force terms' stiffness (minus d force / d x) and C_v their damping (minus d force / d v). A
term couples each node only to nodes at most ``w`` places away along the rope (``Term.reach``; w = 1 for the
rope's springs, 2 with bending), so the matrix, with node-major unknowns (node i, axis d at i * D + d), is a
block band of half-width w blocks. Only its lower triangle is kept, ``band[q, c] = A[c + q, c]``. On a closed
loop the couplings across the wrap (between the first w and the last w nodes) fall outside the band; they go
into ``corner``, the block C^T with C = A[first w D rows, last w D columns], and the solver corrects for them
(a Woodbury update).

:class:`Jacobian` bundles the storage; :func:`add_pair` adds one coupling's blocks, :func:`pair_spring_blocks`
every spring of one stride, and a node-local term adds its D x D block of node i straight into the band at
``band[a - b, i * D + b]`` (a >= b).
"""

from __future__ import annotations

import math
from collections import namedtuple

from . import jit


Jacobian = namedtuple("Jacobian", ["band", "corner", "blk", "w"])
"""band ((w + 1) D, N D), corner (w D, w D), a D x D scratch block, and the half-width w in nodes."""


def band_width(closed: bool, nodes: int, reach: int) -> tuple[int, bool]:
    """(block half-bandwidth w, whether a wrap-around correction is needed) for couplings ``reach`` nodes apart."""
    w = max(1, reach)
    return w, bool(closed and nodes >= w + 2)


@jit.kernel
def slot(n, dim, w, ni, nj, di, dj):
    """Where A[ni*D+di, nj*D+dj] is kept: (0, q, c) for band[q, c], (1, row, c) for the wrap-around's
    corner[row, c], (-1, 0, 0) above the diagonal (only the lower triangle is stored).

    Indices only: a helper that took the arrays would cost an atomic reference-count update per array and
    call; twelve such calls per spring made assembly ten times slower (366 ns per node against 35).
    """
    r = ni * dim + di
    c = nj * dim + dj
    if r < c:
        return -1, 0, 0
    if ni - nj <= w:
        return 0, r - c, c
    return 1, (ni - (n - w)) * dim + di, c


@jit.kernel
def add_pair(jac, n, i, j, free_i, free_j):
    """Add a coupling's block ``jac.blk``: +blk to (i, i) and (j, j), -blk to (i, j) and (j, i)."""
    band, corner, blk, w = jac
    dim = blk.shape[0]
    hi, lo = (i, j) if i > j else (j, i)
    free_hi, free_lo = (free_i, free_j) if i > j else (free_j, free_i)
    for ni, nj, sign, used in ((hi, hi, 1.0, free_hi), (lo, lo, 1.0, free_lo), (hi, lo, -1.0, free_hi and free_lo)):
        if not used:
            continue
        for a in range(dim):
            for b in range(dim):
                where, q, c = slot(n, dim, w, ni, nj, a, b)
                if where == 0:
                    band[q, c] += sign * blk[a, b]
                elif where == 1:
                    corner[q, c] += sign * blk[a, b]


@jit.kernel
def pair_spring_blocks(x, jac, k, rest, stride, closed, scale, free, slack, first, end):
    """Add ``scale`` times the stiffness of every spring (i, i + stride) of constant k [N/m] and rest length [m]
    of the line of nodes ``first`` .. ``end`` - 1.

    A spring's stiffness block is k [(1 - g) u u^T + g I] with g = 1 - l0 / r, u its unit vector;
    compressive (negative) geometric stiffness is left out (g >= 0), so the matrix stays positive definite. A
    ``slack`` (tension-only) spring shorter than its rest length adds nothing.
    """
    dim, n = x.shape
    blk = jac.blk
    count = end - first if closed else end - first - stride
    for i in range(first, first + count):
        j = i + stride
        if j >= end:
            j -= end - first
        if i == j or not (free[i] or free[j]):
            continue
        r2 = 0.0
        for d in range(dim):
            delta = x[d, j] - x[d, i]
            r2 += delta * delta
        if r2 == 0.0:
            continue
        r = math.sqrt(r2)
        if slack and r < rest:
            continue
        geo = max(0.0, 1.0 - rest / r)   # compressive (negative) geometric stiffness left out: SPD
        u = ((x[0, j] - x[0, i]) / r, (x[1, j] - x[1, i]) / r, (x[2, j] - x[2, i]) / r if dim == 3 else 0.0)
        for a in range(dim):
            for b in range(dim):
                blk[a, b] = scale * k * ((1.0 - geo) * u[a] * u[b] + (geo if a == b else 0.0))
        add_pair(jac, n, i, j, free[i], free[j])


@jit.kernel
def pair_damper_blocks(x, jac, c, closed, scale, free, first, end):
    """Add ``scale`` times the damping c u u^T [N s/m] of every segment (i, i + 1) of the line of nodes
    ``first`` .. ``end`` - 1 (the line's axial damping)."""
    dim, n = x.shape
    blk = jac.blk
    count = end - first if closed else end - first - 1
    for i in range(first, first + count):
        j = i + 1 if i + 1 < end else first
        if not (free[i] or free[j]):
            continue
        r2 = 0.0
        for d in range(dim):
            delta = x[d, j] - x[d, i]
            r2 += delta * delta
        if r2 == 0.0:
            continue
        r = math.sqrt(r2)
        u = ((x[0, j] - x[0, i]) / r, (x[1, j] - x[1, i]) / r, (x[2, j] - x[2, i]) / r if dim == 3 else 0.0)
        for a in range(dim):
            for b in range(dim):
                blk[a, b] = scale * c * u[a] * u[b]
        add_pair(jac, n, i, j, free[i], free[j])
