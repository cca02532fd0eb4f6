"""The stiff integrator: a two-stage, L-stable, singly diagonally implicit Runge-Kutta method (SDIRK2).

Alexander (1977): gamma = 1 - 1/sqrt(2), c = (gamma, 1), A = [[gamma, 0], [1 - gamma, gamma]], b = A's last row
(stiffly accurate). Second order; L-stable, so it is stable at any time step and damps modes far faster than
1/h (the stiff springs' stretching vibrations) instead of ringing them. For y = (x, v) and
y' = F = (v, a(x, v) - gamma_drag v), each stage solves Y = Yhat + beta F(t_s, Y) with beta = gamma h; drag is
inside F, so it is implicit too and strong drag never destabilises a step. Eliminating the stage velocity
V = (X - Xhat) / beta leaves, for the positions X of the free nodes,

    R(X) = M (1 + beta gamma_drag) (X - Xhat) - beta M Vhat - beta^2 M a(X, V(X)) = 0,

solved by Newton's method. Its Jacobian, M (1 + beta gamma_drag) + beta^2 H + beta C_v (H the springs',
bending springs', box's and guides' stiffness, C_v their velocity damping), couples each node only to its
neighbours and second neighbours: a block banded matrix, factored by a banded Cholesky in O(N) per
iteration. On a closed loop the wrap-around couples the first and last nodes; a Woodbury correction of rank
w D (w = 1, or 2 with bending) handles it, still O(N). Negative (compressive) geometric stiffness is left out
of the Jacobian so the matrix stays symmetric positive definite: Newton then converges a little more slowly
where springs are compressed, but to the same exact stage solution. Held nodes sit at x0 + V (t + c_s h) in
every stage.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numba import njit

from ..model.forces.thrower import box_of, smooth_step, weight_at
from .health import BOX, DRAG, HELD, NEWTON_FAILED, OK, end_step, held_power, place_held, power
from ..model.terms import BENDING, GUIDES, THROWER, accelerations, box_accelerations

GAMMA = 1.0 - 1.0 / math.sqrt(2.0)
NEWTON_TOL = 1e-11      # Newton stops when no free node's position changes by more than this times l
NEWTON_MAX_ITER = 40


@dataclass(frozen=True)
class Sdirk:
    """The stiff integrator's description; the loop is :func:`advance_sdirk`."""

    name: str
    order: int
    doc: str
    kind: str = "implicit"
    unconditionally_stable: bool = True

    @property
    def evaluations(self) -> int:
        """Nominal force evaluations per step: two stages of about two Newton iterations (counted exactly in
        the accuracy report)."""
        return 4

    @property
    def reuses_last_force(self) -> bool:
        return False

    @property
    def stability_limit(self) -> float:
        return math.inf

    def amplification(self, h: float, omega: float, gamma_force: float = 0.0, gamma_drag: float = 0.0):
        lin = np.array([[0.0, 1.0], [-omega * omega, -(gamma_force + gamma_drag)]]) * h
        solve = np.linalg.inv(np.eye(2) - GAMMA * lin)
        k1 = solve @ lin
        k2 = solve @ lin @ (np.eye(2) + (1 - GAMMA) * k1)
        return np.eye(2) + (1 - GAMMA) * k1 + GAMMA * k2


SDIRK2 = Sdirk("sdirk2", 2,
               "The stiff integrator: L-stable two-stage SDIRK (Alexander 1977), second order, stable at any "
               "time step; each stage a Newton solve with the rope's banded Jacobian (O(N)), drag implicit.")


def band_width(closed: bool, nodes: int, bending: bool) -> tuple[int, bool]:
    """(block half-bandwidth w, whether a wrap-around correction is needed)."""
    w = 2 if bending else 1
    return w, bool(closed and nodes >= w + 2)


def scratch(dim: int, nodes: int, bending: bool, closed: bool) -> tuple:
    """Work arrays for :func:`advance_sdirk`, allocated once per run."""
    w, _ = band_width(closed, nodes, bending)
    nt = dim * nodes
    p = (w + 1) * dim - 1
    m = w * dim
    f = np.zeros
    # band, W, Z, A00, G, S, corner, small, rhs, tmp, X, V, Xhat, Vhat, spring block
    return (f((p + 1, nt)), f((nt, m)), f((nt, m)), f((m, m)), f((m, m)), f((m, m)), f((m, m)), f((m, m + 1)),
            f(nt), f(m), f((dim, nodes)), f((dim, nodes)), f((dim, nodes)), f((dim, nodes)), f((dim, dim)))


# ----------------------------------------------------------------------------------- linear algebra


@njit(cache=True, error_model="numpy")
def _band_cholesky(band, p):
    """In-place Cholesky of a symmetric positive definite band matrix stored as band[q, j] = A[j + q, j]."""
    nt = band.shape[1]
    for j in range(nt):
        s = band[0, j]
        for k in range(max(0, j - p), j):
            lk = band[j - k, k]
            s -= lk * lk
        if not s > 0.0:
            return False
        djj = math.sqrt(s)
        band[0, j] = djj
        for i in range(j + 1, min(nt, j + p + 1)):
            s = band[i - j, j]
            for k in range(max(0, i - p), j):
                s -= band[i - k, k] * band[j - k, k]
            band[i - j, j] = s / djj
    return True


@njit(cache=True, error_model="numpy")
def _band_solve(band, p, r):
    """Solve L L^T z = r in place (``band`` holds L from :func:`_band_cholesky`)."""
    nt = band.shape[1]
    for i in range(nt):
        s = r[i]
        for k in range(max(0, i - p), i):
            s -= band[i - k, k] * r[k]
        r[i] = s / band[0, i]
    for i in range(nt - 1, -1, -1):
        s = r[i]
        for k in range(i + 1, min(nt, i + p + 1)):
            s -= band[k - i, i] * r[k]
        r[i] = s / band[0, i]


@njit(cache=True, error_model="numpy")
def _band_solve_columns(band, p, z):
    """Solve L L^T Z = z in place for every column of ``z`` (nt, m) at once: the same operations, in the same
    order, as :func:`_band_solve` on each column, with each entry of L loaded once for all columns."""
    nt, m = z.shape
    for i in range(nt):
        for k in range(max(0, i - p), i):
            lik = band[i - k, k]
            for c in range(m):
                z[i, c] -= lik * z[k, c]
        for c in range(m):
            z[i, c] /= band[0, i]
    for i in range(nt - 1, -1, -1):
        for k in range(i + 1, min(nt, i + p + 1)):
            lki = band[k - i, i]
            for c in range(m):
                z[i, c] -= lki * z[k, c]
        for c in range(m):
            z[i, c] /= band[0, i]


@njit(cache=True, error_model="numpy")
def _dense_solve(a, rhs, work):
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


# ------------------------------------------------------------------------------------------ Jacobian


@njit(cache=True, error_model="numpy")
def _slot(n, dim, w, ni, nj, di, dj):
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


@njit(cache=True, error_model="numpy")
def _add_pair(band, corner, n, dim, w, i, j, blk, free_i, free_j):
    """Add a spring's stiffness block: +blk to (i, i) and (j, j), -blk to (i, j) and (j, i)."""
    hi, lo = (i, j) if i > j else (j, i)
    free_hi, free_lo = (free_i, free_j) if i > j else (free_j, free_i)
    for ni, nj, sign, used in ((hi, hi, 1.0, free_hi), (lo, lo, 1.0, free_lo), (hi, lo, -1.0, free_hi and free_lo)):
        if not used:
            continue
        for a in range(dim):
            for b in range(dim):
                where, q, c = _slot(n, dim, w, ni, nj, a, b)
                if where == 0:
                    band[q, c] += sign * blk[a, b]
                elif where == 1:
                    corner[q, c] += sign * blk[a, b]


@njit(cache=True, error_model="numpy")
def _spring_blocks(x, band, corner, n, dim, w, k, rest, stride, closed, scale, free, blk):
    count = n if closed else n - stride
    for i in range(count):
        j = i + stride
        if j >= n:
            j -= n
        if i == j or not (free[i] or free[j]):
            continue
        r2 = 0.0
        for d in range(dim):
            delta = x[d, j] - x[d, i]
            r2 += delta * delta
        if r2 == 0.0:
            continue
        r = math.sqrt(r2)
        geo = max(0.0, 1.0 - rest / r)   # compressive (negative) geometric stiffness left out: SPD
        u = ((x[0, j] - x[0, i]) / r, (x[1, j] - x[1, i]) / r, (x[2, j] - x[2, i]) / r if dim == 3 else 0.0)
        for a in range(dim):
            for b in range(dim):
                blk[a, b] = scale * k * ((1.0 - geo) * u[a] * u[b] + (geo if a == b else 0.0))
        _add_pair(band, corner, n, dim, w, i, j, blk, free[i], free[j])


@njit(cache=True, error_model="numpy")
def _assemble(x, v, band, corner, beta, mass, drag, free, forces, w, blk):
    """The Newton matrix M (1 + beta gamma) + beta^2 H + beta C_v into ``band`` (and ``corner``)."""
    inv_mass, flags, spring, bending, gravity, thrower, guides = forces
    dim, n = x.shape
    box = box_of(thrower)
    band[:] = 0.0
    corner[:] = 0.0
    closed = spring[2] != 0.0
    b2 = beta * beta
    _spring_blocks(x, band, corner, n, dim, w, spring[0], spring[1], 1, closed, b2, free, blk)
    if flags[BENDING]:
        _spring_blocks(x, band, corner, n, dim, w, bending[0], bending[1], 2, closed, b2, free, blk)
    for i in range(n):
        if not free[i]:
            for d in range(dim):
                band[0, i * dim + d] = 1.0
                for e in range(d + 1, dim):
                    band[e - d, i * dim + d] = 0.0
            continue
        m = mass[i]
        diag = m + beta * drag[i]
        for d in range(dim):
            band[0, i * dim + d] += diag
        outside = 1.0
        if flags[THROWER]:
            sb = weight_at(x[0, i], x[1, i], x[2, i] if dim == 3 else 0.0, dim == 3, box)
            outside = 1.0 - sb
            if sb > 0.0:
                band[0, i * dim] += sb * beta * thrower[6]
                for d in range(1, dim):
                    band[0, i * dim + d] += sb * m * (b2 * thrower[7] + beta * thrower[8])
        if flags[GUIDES] and outside > 0.0:
            for c in range(guides.shape[0]):
                dx = x[0, i] - guides[c, 0]
                dy = x[1, i] - guides[c, 1]
                r = math.sqrt(dx * dx + dy * dy)
                radius = guides[c, 2]
                weight = outside * smooth_step(radius - r, guides[c, 6])
                if weight == 0.0 or r == 0.0:
                    continue
                ux, uy = dx / r, dy / r
                vr = v[0, i] * ux + v[1, i] * uy
                if guides[c, 5] != 0.0:
                    if guides[c, 6] == 0.0:
                        if vr > 0.0:
                            continue
                    else:
                        weight *= smooth_step(-vr, guides[c, 6] * math.sqrt(guides[c, 3]))
                ar = -guides[c, 3] * (r - radius) - guides[c, 4] * vr
                radial = weight * (b2 * guides[c, 3] + beta * guides[c, 4])
                tangential = weight * b2 * max(0.0, -ar / r)
                u = (ux, uy)
                for a in range(2):
                    for b in range(a + 1):
                        val = m * (radial * u[a] * u[b] + tangential * ((1.0 if a == b else 0.0) - u[a] * u[b]))
                        band[a - b, i * dim + b] += val


@njit(cache=True, error_model="numpy")
def _factor(band, corner, cyclic, p, work):
    """Factor the Newton matrix; with a wrap-around, prepare the Woodbury correction (see the module doc).

    With C = A[first m rows, last m columns] (``corner`` holds C^T) and Gamma = -A00 (the top-left m x m
    block): A = B + W Gamma W^T with W = [I; 0; X], X = -(A00^-1 C)^T, and B banded (its top-left block is
    2 A00 and its bottom-right gains C^T A00^-1 C, both still positive definite). Then
    A^-1 r = B^-1 r - Z S^-1 W^T B^-1 r with Z = B^-1 W and S = -A00^-1 + W^T Z.
    """
    wmat, zmat, a00, g, s, small = work[1], work[2], work[3], work[4], work[5], work[7]
    nt = band.shape[1]
    m = a00.shape[0]
    if cyclic:
        for a in range(m):
            for b in range(m):
                r, c = (a, b) if a >= b else (b, a)
                a00[a, b] = band[r - c, c]
                g[a, b] = corner[b, a]
        _dense_solve(a00, g, small)              # G = A00^-1 C
        for a in range(m):
            for b in range(a + 1):
                band[a - b, b] += a00[a, b]
                val = 0.0
                for q in range(m):
                    val += corner[a, q] * g[q, b]
                band[a - b, nt - m + b] += val
    if not _band_cholesky(band, p):
        return False
    if cyclic:
        wmat[:] = 0.0
        for a in range(m):
            wmat[a, a] = 1.0
            for b in range(m):
                wmat[nt - m + a, b] = -g[b, a]
        zmat[:] = wmat
        _band_solve_columns(band, p, zmat)
        for b in range(m):
            for a in range(m):
                s[a, b] = 0.0
            s[b, b] = -1.0
        _dense_solve(a00, s, small)              # S = -A00^-1 ...
        for a in range(m):
            for b in range(m):
                val = 0.0
                for r in range(nt):
                    val += wmat[r, a] * zmat[r, b]
                s[a, b] += val                   # ... + W^T Z
    return True


@njit(cache=True, error_model="numpy")
def _solve(band, cyclic, p, rhs, work):
    """Solve the factored Newton system in place into ``rhs`` (flat, node-major)."""
    wmat, zmat, s, corner, small, tmp = work[1], work[2], work[5], work[6], work[7], work[9]
    nt = band.shape[1]
    _band_solve(band, p, rhs)
    if cyclic:
        m = s.shape[0]
        for a in range(m):
            val = 0.0
            for r in range(nt):
                val += wmat[r, a] * rhs[r]
            corner[a, 0] = val                   # corner is free once factored: W^T y, then S^-1 W^T y
            for b in range(1, m):
                corner[a, b] = 0.0
        _dense_solve(s, corner, small)
        for a in range(m):
            tmp[a] = corner[a, 0]
        for r in range(nt):
            val = 0.0
            for a in range(m):
                val += zmat[r, a] * tmp[a]
            rhs[r] -= val


@njit(cache=True, error_model="numpy")
def _solve_stage(xh, vh, X, V, acc, beta, t_stage, held, free, mass, drag, forces, w, cyclic, tol, work, blk):
    """Newton solve of one stage: X = xh + beta V, V = vh + beta (a(X, V) - gamma V). Returns
    (iterations, node): iterations < 0 when it failed, naming the node that moved most in the last one."""
    held_idx, held_x0, held_v = held
    band, corner, rhs = work[0], work[6], work[8]
    dim, n = X.shape
    p = band.shape[0] - 1
    for d in range(dim):
        for i in range(n):
            X[d, i] = xh[d, i] + beta * vh[d, i]
    place_held(X, held_idx, held_x0, held_v, t_stage)
    worst_node = -1
    for it in range(NEWTON_MAX_ITER):
        for d in range(dim):
            for i in range(n):
                V[d, i] = (X[d, i] - xh[d, i]) / beta
        for j in range(held_idx.shape[0]):
            for d in range(dim):
                V[d, held_idx[j]] = held_v[d, j]
        accelerations(X, V, acc, forces)
        for i in range(n):
            for d in range(dim):
                u = i * dim + d
                if free[i]:
                    m = mass[i]
                    rhs[u] = -((m + beta * drag[i]) * (X[d, i] - xh[d, i]) - beta * m * vh[d, i]
                               - beta * beta * m * acc[d, i])
                else:
                    rhs[u] = 0.0
        _assemble(X, V, band, corner, beta, mass, drag, free, forces, w, blk)
        if not _factor(band, corner, cyclic, p, work):
            return -1, 0
        _solve(band, cyclic, p, rhs, work)
        worst = 0.0
        for i in range(n):
            for d in range(dim):
                dx = rhs[i * dim + d]
                X[d, i] += dx
                if not abs(dx) <= worst:
                    worst = abs(dx)
                    worst_node = i
        if worst <= tol:
            for d in range(dim):
                for i in range(n):
                    if free[i]:
                        V[d, i] = (X[d, i] - xh[d, i]) / beta
            return it + 1, -1
    return -1, worst_node


@njit(cache=True, error_model="numpy")
def advance_sdirk(x, v, acc, acc_box, ledger, stats, step0, n_steps, total_steps, h, w, cyclic, tol, held, free,
                  mass, drag, forces, limits, save_every, frames, check_every, work):
    """Advance ``n_steps`` SDIRK2 steps in place; arguments and result as for
    :func:`ropesim.integrators.advance`. ``stats[0]`` counts Newton iterations (force evaluations)."""
    dim, n = x.shape
    held_idx, held_x0, held_v = held
    flags = forces[1]
    has_box = flags[THROWER] != 0 or flags[GUIDES] != 0
    X, V, xh, vh = work[10], work[11], work[12], work[13]
    blk = work[14]
    beta = GAMMA * h
    frame = 0
    for s in range(n_steps):
        step = step0 + s
        t = step * h
        for d in range(dim):
            for i in range(n):
                xh[d, i] = x[d, i]
                vh[d, i] = v[d, i]
        for stage in range(2):
            t_stage = t + (GAMMA if stage == 0 else 1.0) * h
            its, node = _solve_stage(xh, vh, X, V, acc, beta, t_stage, held, free, mass, drag, forces, w, cyclic,
                                     tol, work, blk)
            if its < 0:
                return s, frame, NEWTON_FAILED, node
            stats[0] += its
            weight = (1.0 - GAMMA if stage == 0 else GAMMA) * h
            lost = 0.0
            for d in range(dim):
                for i in range(n):
                    lost += drag[i] * V[d, i] * V[d, i]
            ledger[DRAG] += weight * lost
            ledger[HELD] += weight * held_power(acc, mass, held_idx, held_v)
            if has_box:
                box_accelerations(X, V, acc_box, forces)
                ledger[BOX] += weight * power(acc_box, V, mass)
            if stage == 0:
                ratio = (1.0 - GAMMA) / GAMMA
                for d in range(dim):
                    for i in range(n):
                        xh[d, i] = x[d, i] + (1.0 - GAMMA) * h * V[d, i]
                        vh[d, i] = v[d, i] + ratio * (V[d, i] - v[d, i])
        for d in range(dim):
            for i in range(n):
                x[d, i] = X[d, i]
                v[d, i] = V[d, i]
        place_held(x, held_idx, held_x0, held_v, (step + 1) * h)
        done = step + 1
        if done % check_every and done % save_every and done != total_steps:
            continue  # nothing due: skip the call, whose array arguments cost more than a small rope's step
        status, node, frame = end_step(done, total_steps, save_every, check_every, h, x, v, mass, forces, ledger,
                                       limits, frames, frame)
        if status != OK:
            return s + 1, frame, status, node
    return n_steps, frame, OK, -1
