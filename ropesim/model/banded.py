"""Solves with the rope's Newton matrix (the stiff integrator's and the static solver's): banded Cholesky, and
a Woodbury correction for a loop; the banded pieces a system's solve takes line by line (:mod:`ropesim.model.schur`):
the Cholesky factorisation of a range of rows from either end, and its substitutions.

The matrix is symmetric positive definite and block banded (see :mod:`ropesim.model.jacobian` for its
storage); :func:`factor` factors it in place in O(N) and :func:`solve` solves with the factors. On a closed
loop the wrap-around couplings in ``corner`` are handled by a Woodbury correction of rank w D (:func:`factor`).
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import jit

WITH_WRAP_AROUND = jit.Switch("wrap_around", "a closed loop: the Woodbury correction of the Newton matrix's "
                                             "wrap-around corner")

Woodbury = namedtuple("Woodbury", ["wmat", "zmat", "a00", "g", "s", "small", "tmp"])
"""The wrap-around correction's arrays, m = w D: W and Z (N D, m), A00, G and S (m, m), dense-solve scratch
(m, m + 1), a vector (m,). See :func:`factor`."""


def woodbury(nt: int, m: int) -> Woodbury:
    """Zeroed Woodbury arrays for a matrix of order ``nt`` and a correction of rank ``m``."""
    f = np.zeros
    return Woodbury(f((nt, m)), f((nt, m)), f((m, m)), f((m, m)), f((m, m)), f((m, m + 1)), f(m))


@jit.kernel
def band_cholesky(band, p):
    """In-place Cholesky of a symmetric positive definite band matrix stored as band[q, j] = A[j + q, j]."""
    return band_cholesky_range(band, p, 0, band.shape[1])


@jit.kernel
def band_solve(band, p, r):
    """Solve L L^T z = r in place (``band`` holds L from :func:`band_cholesky`)."""
    nt = band.shape[1]
    substitute_down(band, p, r, 0, nt, 0)
    substitute_up(band, p, r, 0, nt, nt)


@jit.kernel(inline="always")   # compiled into its callers: a rope compiles no more functions
def band_cholesky_range(band, p, r0, r1):
    """Cholesky L L^T of rows and columns r0 .. r1 - 1 of the band matrix (``band[q, j] = A[j + q, j]``, L in
    its place), taken on their own (a system's line: :mod:`ropesim.model.schur`)."""
    for j in range(r0, r1):
        s = band[0, j]
        for k in range(max(r0, j - p), j):
            lk = band[j - k, k]
            s -= lk * lk
        if not s > 0.0:
            return False
        djj = math.sqrt(s)
        band[0, j] = djj
        for i in range(j + 1, min(r1, j + p + 1)):
            s = band[i - j, j]
            for k in range(max(r0, i - p), j):
                s -= band[i - k, k] * band[j - k, k]
            band[i - j, j] = s / djj
    return True


@jit.kernel
def band_cholesky_reverse(band, p, r0, r1):
    """The factorisation U U^T (U upper banded) of rows and columns r0 .. r1 - 1, from the last row up: U[i, j]
    (i <= j) takes A[j, i]'s place, ``band[j - i, i]``. The Cholesky factorisation of the rows in reverse
    order."""
    for j in range(r1 - 1, r0 - 1, -1):
        s = band[0, j]
        for k in range(j + 1, min(r1, j + p + 1)):
            uk = band[k - j, j]
            s -= uk * uk
        if not s > 0.0:
            return False
        djj = math.sqrt(s)
        band[0, j] = djj
        for i in range(j - 1, max(r0, j - p) - 1, -1):
            s = band[j - i, i]
            for k in range(j + 1, min(r1, i + p + 1)):
                s -= band[k - i, i] * band[k - j, j]
            band[j - i, i] = s / djj
    return True


@jit.kernel(inline="always")   # compiled into its callers: a rope compiles no more functions
def substitute_down(band, p, z, r0, r1, lo):
    """z[i] <- (z[i] - sum_(k<i) band[i - k, k] z[k]) / band[0, i] for i = lo .. r1 - 1, rows r0 .. lo - 1 of z
    being zero: L^-1 z after :func:`band_cholesky_range`, U^-T z after :func:`band_cholesky_reverse`."""
    for i in range(lo, r1):
        s = z[i]
        for k in range(max(lo, r0, i - p), i):
            s -= band[i - k, k] * z[k]
        z[i] = s / band[0, i]


@jit.kernel(inline="always")   # compiled into its callers: a rope compiles no more functions
def substitute_up(band, p, z, r0, r1, hi):
    """z[i] <- (z[i] - sum_(k>i) band[k - i, i] z[k]) / band[0, i] for i = hi - 1 down to r0, rows hi .. r1 - 1
    of z being zero: L^-T z after :func:`band_cholesky_range`, U^-1 z after :func:`band_cholesky_reverse`."""
    for i in range(hi - 1, r0 - 1, -1):
        s = z[i]
        for k in range(i + 1, min(hi, r1, i + p + 1)):
            s -= band[k - i, i] * z[k]
        z[i] = s / band[0, i]


@jit.kernel
def band_solve_columns(band, p, z):
    """Solve L L^T Z = z in place for every column of ``z`` (nt, m) at once: the same operations, in the same
    order, as :func:`band_solve` on each column, with each entry of L loaded once for all columns."""
    nt, m = z.shape
    substitute_columns_down(band, p, z, 0, nt, 0, 0, m)
    substitute_columns_up(band, p, z, 0, nt, nt, 0, m)


@jit.kernel(inline="always")   # compiled into its callers: a rope compiles no more functions
def substitute_columns_down(band, p, z, r0, r1, lo, c0, c1):
    """:func:`substitute_down` on columns c0 .. c1 - 1 of ``z`` (rows, columns) at once, each entry of the
    factor loaded once for all of them."""
    for i in range(lo, r1):
        for k in range(max(lo, r0, i - p), i):
            lik = band[i - k, k]
            for c in range(c0, c1):
                z[i, c] -= lik * z[k, c]
        for c in range(c0, c1):
            z[i, c] /= band[0, i]


@jit.kernel(inline="always")   # compiled into its callers: a rope compiles no more functions
def substitute_columns_up(band, p, z, r0, r1, hi, c0, c1):
    """:func:`substitute_up` on columns c0 .. c1 - 1 of ``z`` (rows, columns) at once."""
    for i in range(hi - 1, r0 - 1, -1):
        for k in range(i + 1, min(hi, r1, i + p + 1)):
            lki = band[k - i, i]
            for c in range(c0, c1):
                z[i, c] -= lki * z[k, c]
        for c in range(c0, c1):
            z[i, c] /= band[0, i]


@jit.kernel
def dense_solve(a, rhs, work):
    """Solve a z = rhs (m x m, m x k) in place into ``rhs`` by Gaussian elimination with partial pivoting;
    ``a`` is kept (``work`` is m x m+... scratch of at least m x m)."""
    m = a.shape[0]
    k = rhs.shape[1]
    lu = work
    for i in range(m):
        for j in range(m):
            lu[i, j] = a[i, j]
    for col in range(m):
        piv = col
        for i in range(col + 1, m):
            if abs(lu[i, col]) > abs(lu[piv, col]):
                piv = i
        if piv != col:
            for j in range(m):
                lu[col, j], lu[piv, j] = lu[piv, j], lu[col, j]
            for j in range(k):
                rhs[col, j], rhs[piv, j] = rhs[piv, j], rhs[col, j]
        for i in range(col + 1, m):
            f = lu[i, col] / lu[col, col]
            for j in range(col, m):
                lu[i, j] -= f * lu[col, j]
            for j in range(k):
                rhs[i, j] -= f * rhs[col, j]
    for col in range(m - 1, -1, -1):
        for j in range(k):
            s = rhs[col, j]
            for i in range(col + 1, m):
                s -= lu[col, i] * rhs[i, j]
            rhs[col, j] = s / lu[col, col]


@jit.kernel
def factor(band, corner, cyclic, p, wood):
    """Factor the Newton matrix; with a wrap-around, prepare the Woodbury correction (see the module doc).

    With C = A[first m rows, last m columns] (``corner`` holds C^T) and Gamma = -A00 (the top-left m x m
    block): A = B + W Gamma W^T with W = [I; 0; X], X = -(A00^-1 C)^T, and B banded (its top-left block is
    2 A00 and its bottom-right gains C^T A00^-1 C, both still positive definite). Then
    A^-1 r = B^-1 r - Z S^-1 W^T B^-1 r with Z = B^-1 W and S = -A00^-1 + W^T Z.
    """
    wmat, zmat, a00, g, s, small = wood.wmat, wood.zmat, wood.a00, wood.g, wood.s, wood.small
    nt = band.shape[1]
    m = a00.shape[0]
    if WITH_WRAP_AROUND and cyclic:
        for a in range(m):
            for b in range(m):
                r, c = (a, b) if a >= b else (b, a)
                a00[a, b] = band[r - c, c]
                g[a, b] = corner[b, a]
        dense_solve(a00, g, small)              # G = A00^-1 C
        for a in range(m):
            for b in range(a + 1):
                band[a - b, b] += a00[a, b]
                val = 0.0
                for q in range(m):
                    val += corner[a, q] * g[q, b]
                band[a - b, nt - m + b] += val
    if not band_cholesky(band, p):
        return False
    if WITH_WRAP_AROUND and cyclic:
        wmat[:] = 0.0
        for a in range(m):
            wmat[a, a] = 1.0
            for b in range(m):
                wmat[nt - m + a, b] = -g[b, a]
        for r in range(nt):
            for b in range(m):
                zmat[r, b] = wmat[r, b]
        band_solve_columns(band, p, zmat)
        for b in range(m):
            for a in range(m):
                s[a, b] = 0.0
            s[b, b] = -1.0
        dense_solve(a00, s, small)              # S = -A00^-1 ...
        for a in range(m):
            for b in range(m):
                val = 0.0
                for r in range(nt):
                    val += wmat[r, a] * zmat[r, b]
                s[a, b] += val                   # ... + W^T Z
    return True


@jit.kernel
def solve(band, corner, cyclic, p, rhs, wood):
    """Solve the factored Newton system in place into ``rhs`` (flat, node-major)."""
    wmat, zmat, s, small, tmp = wood.wmat, wood.zmat, wood.s, wood.small, wood.tmp
    nt = band.shape[1]
    band_solve(band, p, rhs)
    if WITH_WRAP_AROUND and cyclic:
        m = s.shape[0]
        for a in range(m):
            val = 0.0
            for r in range(nt):
                val += wmat[r, a] * rhs[r]
            corner[a, 0] = val                   # corner is free once factored: W^T y, then S^-1 W^T y
            for b in range(1, m):
                corner[a, b] = 0.0
        dense_solve(s, corner, small)
        for a in range(m):
            tmp[a] = corner[a, 0]
        for r in range(nt):
            val = 0.0
            for a in range(m):
                val += zmat[r, a] * tmp[a]
            rhs[r] -= val
