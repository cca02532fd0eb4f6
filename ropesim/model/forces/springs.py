"""Hookean springs between node pairs (i, i + stride): the rope itself (stride 1) and bending (stride 2).

A spring of stiffness k and rest length l0 between nodes i and j stores E = k/2 (|x_j - x_i| - l0)^2 and
pulls both ends along the segment with force k (r - l0) r_hat. On an open line the springs are
(i, i + stride) for i < N - stride; on a closed loop the indices wrap, giving N springs. A rope that cannot
push (``rope.compression = false``, its segments *slack*) has no force and no energy while r < l0.

The rope's axial damping (``rope.axial_damping`` BA) adds c (r_hat . (v_j - v_i)) r_hat along each segment,
c = BA / l0, in tension and compression (MoorDyn's convention): :func:`add_axial_damping`.

The rope's parameters: k [N/m], l0 [m], closed (1 or 0), slack (1: no compression stiffness, or 0).
"""

import numpy as np

from . import Term
from ..layout import line_layouts
from .. import jit

WITH_AXIAL_DAMPING = jit.Switch("axial_damping", "the segments' axial damping")
WITH_BENDING = jit.Switch("bending", "second-neighbour bending springs")


@jit.kernel
def add_pair_springs(x, acc, inv_mass, k, rest, stride, closed):
    """Add the accelerations [m/s^2] of the springs (i, i + stride) to ``acc``."""
    dim, n = x.shape
    count = n if closed else n - stride
    for i in range(count):
        j = i + stride
        if j >= n:
            j -= n
        r2 = 0.0
        for d in range(dim):
            delta = x[d, j] - x[d, i]
            r2 += delta * delta
        if r2 == 0.0:
            continue  # coincident nodes: the spring has no direction, so it exerts no force
        r = np.sqrt(r2)
        f = k * (r - rest) / r
        mi = inv_mass[i]
        mj = inv_mass[j]
        for d in range(dim):
            fd = f * (x[d, j] - x[d, i])
            acc[d, i] += fd * mi
            acc[d, j] -= fd * mj


@jit.kernel
def _spring_scale(k, rest, r2, slack):
    """k (1 - l0 / r) for a spring of squared length r2: times the separation, its force [N]; 0 if r = 0, and
    0 for a ``slack`` (tension-only) spring shorter than l0."""
    c = k * (1.0 - rest / np.sqrt(r2)) if r2 > 0.0 else 0.0
    if slack and c < 0.0:
        return 0.0
    return c


ONE = np.uint64(1)   # the line kernels index with unsigned integers: see set_chain_springs


@jit.kernel
def set_chain_springs(x, acc, inv_mass, k, rest, closed, g, slack, a, b):
    """Overwrite ``acc`` with the accelerations [m/s^2] of the springs (i, i + 1) of the line of nodes a .. b - 1,
    minus ``g`` along y.

    The same forces as ``add_pair_springs(..., stride=1, ...)`` plus gravity, computed so that both loops
    vectorise: first each spring's force F_i (on node i, from spring (i, i + 1)) is written into ``acc[:, i]``,
    then, from the last node down, a_i = (F_i - F_(i-1)) / m_i - g. 2-D and 3-D are written out row by row. The
    node indices are unsigned: a signed index that Numba cannot prove non-negative gets a wrap-around test
    (Python's negative indexing) that stops the loops vectorising, twice as slow from a few hundred nodes.
    """
    dim = x.shape[0]
    first, last = np.uint64(a), np.uint64(b) - ONE
    if dim == 2:
        for i in range(first, last):
            d0 = x[0, i + ONE] - x[0, i]
            d1 = x[1, i + ONE] - x[1, i]
            c = _spring_scale(k, rest, d0 * d0 + d1 * d1, slack)
            acc[0, i] = c * d0
            acc[1, i] = c * d1
        l0 = l1 = 0.0   # the force of the spring closing a loop, (last, first), on node last
        if closed:
            d0 = x[0, first] - x[0, last]
            d1 = x[1, first] - x[1, last]
            c = _spring_scale(k, rest, d0 * d0 + d1 * d1, slack)
            l0, l1 = c * d0, c * d1
        acc[0, last] = l0
        acc[1, last] = l1
        for back in range(last - first):
            i = last - np.uint64(back)
            m = inv_mass[i]
            acc[0, i] = (acc[0, i] - acc[0, i - ONE]) * m
            acc[1, i] = (acc[1, i] - acc[1, i - ONE]) * m - g
        acc[0, first] = (acc[0, first] - l0) * inv_mass[first]
        acc[1, first] = (acc[1, first] - l1) * inv_mass[first] - g
    else:
        for i in range(first, last):
            d0 = x[0, i + ONE] - x[0, i]
            d1 = x[1, i + ONE] - x[1, i]
            d2 = x[2, i + ONE] - x[2, i]
            c = _spring_scale(k, rest, d0 * d0 + d1 * d1 + d2 * d2, slack)
            acc[0, i] = c * d0
            acc[1, i] = c * d1
            acc[2, i] = c * d2
        l0 = l1 = l2 = 0.0
        if closed:
            d0 = x[0, first] - x[0, last]
            d1 = x[1, first] - x[1, last]
            d2 = x[2, first] - x[2, last]
            c = _spring_scale(k, rest, d0 * d0 + d1 * d1 + d2 * d2, slack)
            l0, l1, l2 = c * d0, c * d1, c * d2
        acc[0, last] = l0
        acc[1, last] = l1
        acc[2, last] = l2
        for back in range(last - first):
            i = last - np.uint64(back)
            m = inv_mass[i]
            acc[0, i] = (acc[0, i] - acc[0, i - ONE]) * m
            acc[1, i] = (acc[1, i] - acc[1, i - ONE]) * m - g
            acc[2, i] = (acc[2, i] - acc[2, i - ONE]) * m
        acc[0, first] = (acc[0, first] - l0) * inv_mass[first]
        acc[1, first] = (acc[1, first] - l1) * inv_mass[first] - g
        acc[2, first] = (acc[2, first] - l2) * inv_mass[first]


BLOCK_BYTES = 16 * 2 ** 20   # the NumPy helpers below work on at most this many bytes of positions at a time


def _by_blocks(fn, x: np.ndarray) -> np.ndarray:
    """``fn`` applied to (F, N, D) positions in blocks of frames of at most BLOCK_BYTES, results joined.

    Keeps the temporaries of a trajectory-wide computation small however many frames a (memory-mapped)
    trajectory has; ``fn`` maps (B, N, D) to (B, ...).
    """
    x = np.asarray(x)
    if x.ndim <= 2 or x.nbytes <= BLOCK_BYTES:
        return fn(x)
    frames = x if x.ndim == 3 else x.reshape((-1,) + x.shape[-2:])
    per = max(1, BLOCK_BYTES // max(1, frames[0].nbytes))
    out = np.concatenate([fn(frames[s:s + per]) for s in range(0, len(frames), per)])
    return out.reshape(x.shape[:-2] + out.shape[1:])


def _deltas(x: np.ndarray, stride: int, closed: bool) -> np.ndarray:
    if closed:
        return np.roll(x, -stride, axis=-2) - x
    return x[..., stride:, :] - x[..., :-stride, :]


def pair_spring_energy(x, k, rest, stride, closed, slack=False):
    """Energy [J] stored in the springs (i, i + stride), for positions of shape (..., N, D); a ``slack`` spring
    stores nothing while shorter than its rest length."""
    def energy(b):
        e = np.linalg.norm(_deltas(b, stride, closed), axis=-1) - rest
        return 0.5 * k * np.sum((np.maximum(e, 0.0) if slack else e) ** 2, axis=-1)
    return _by_blocks(energy, x)


def pair_spring_stretch(x, rest, stride, closed):
    """Relative stretch |r| / l0 - 1 of every spring (i, i + stride), for positions (..., N, D)."""
    return _by_blocks(lambda b: np.linalg.norm(_deltas(b, stride, closed), axis=-1) / rest - 1.0, x)


def segment_forces(model, x, v) -> np.ndarray:
    """Each segment's axial force [N] (positive in tension) for frames x, v (..., N, D): the spring's
    k (r - l0) (none while a slack segment is short) plus the axial damping c dr/dt. Line after line (a rope is
    one line); a line's segment j joins its nodes j and j + 1 (its node 0 for a loop's last segment)."""
    x, v = np.asarray(x), np.asarray(v)
    return np.concatenate([_line_forces(line, x[..., line.first:line.end, :], v[..., line.first:line.end, :])
                           for line in model.lines], axis=-1)


def _line_forces(line, x, v) -> np.ndarray:
    """One line's segment forces [N] for its frames x, v (..., n, D) (see :func:`segment_forces`)."""
    k, rest, c = line.stiffness, line.segment_length, line.axial_damping / line.segment_length

    def force(block):
        xb, vb = block[..., :block.shape[-1] // 2], block[..., block.shape[-1] // 2:]
        d = _deltas(xb, 1, line.closed)
        r = np.linalg.norm(d, axis=-1)
        f = k * (r - rest)
        if line.slack:
            f = np.maximum(f, 0.0)
        if c:
            unit = d / np.where(r > 0, r, 1.0)[..., None]
            f = f + c * np.sum(unit * _deltas(vb, 1, line.closed), axis=-1)
        return f
    return _by_blocks(force, np.concatenate([x, v], axis=-1))


def segment_strains(model, x) -> np.ndarray:
    """Each segment's strain r / l0 - 1, line after line, for frames x (..., N, D)."""
    x = np.asarray(x)
    return np.concatenate([pair_spring_stretch(x[..., line.first:line.end, :], line.segment_length, 1, line.closed)
                           for line in model.lines], axis=-1)


@jit.kernel
def add_axial_damping(x, v, acc, inv_mass, c, closed, a, b):
    """Add the axial damping c (r_hat . dv) r_hat [N] / m of the segments of the line of nodes a .. b - 1;
    returns its power [W] (never positive)."""
    dim = x.shape[0]
    first, end = np.uint64(a), np.uint64(b)
    count = end - first if closed else end - first - ONE
    power = 0.0
    for s in range(count):
        i = first + np.uint64(s)
        j = i + ONE if i + ONE < end else first
        r2 = 0.0
        rate = 0.0
        for d in range(dim):
            delta = x[d, j] - x[d, i]
            r2 += delta * delta
            rate += delta * (v[d, j] - v[d, i])
        if r2 == 0.0:
            continue
        f = c * rate / r2   # times the separation: c (r_hat . dv) r_hat
        for d in range(dim):
            fd = f * (x[d, j] - x[d, i])
            acc[d, i] += fd * inv_mass[i]
            acc[d, j] -= fd * inv_mass[j]
        power -= f * rate
    return power


def _rope_params(scene, layout) -> np.ndarray:
    """(L, 4): each line's k [N/m], rest length l [m], closed (1) or open (0), slack (1) or not (0)."""
    return np.array([[line.stiffness, line.segment_length, 1.0 if line.closed else 0.0, 1.0 if line.slack else 0.0]
                     for line in layout.lines])


def _bending_params(scene, mass) -> np.ndarray:
    return np.array([scene.bending.stiffness, 2.0 * scene.rope.segment_length])


def _lines_energy(model, x) -> np.ndarray:
    """Every line's springs' energy [J] for frames x (..., N, D)."""
    x = np.asarray(x)
    return sum(pair_spring_energy(x[..., line.first:line.end, :], line.stiffness, line.segment_length, 1, line.closed,
                                  line.slack) for line in model.lines)


def _axial_rate(model) -> float:
    """The fastest axial damping rate 4 c / m [1/s] on a line's lightest free node, c = BA / l."""
    rates = [4.0 * line.axial_damping / line.segment_length / float(mass.min())
             for line in model.lines if line.axial_damping
             for mass in [model.mass[line.first:line.end][~model.held[line.first:line.end]]] if mass.size]
    return max(rates, default=0.0)


def pairs(first: int, nodes: int, stride: int, closed: bool, k: float) -> tuple:
    """(i, j, k) arrays of the springs (i, i + stride) of a line of ``nodes`` nodes from ``first`` (wrapped round
    a loop), each of stiffness k [N/m]."""
    i = np.arange(nodes if closed else max(nodes - stride, 0))
    j = (i + stride) % nodes
    keep = i != j
    return i[keep] + first, j[keep] + first, np.full(int(keep.sum()), k)


ROPE = Term(
    "rope", None, _rope_params, lambda: np.zeros((1, 4)), energy=_lines_energy,
    springs=lambda model: [pairs(line.first, line.nodes, 1, line.closed, line.stiffness) for line in model.lines],
    label="spring", reach=1)
"""The lines' own springs (i, i + 1): parameters per line, k [N/m], rest length l [m], closed (1) or open (0),
slack (1)."""

AXIAL_DAMPING = Term(
    "rope", WITH_AXIAL_DAMPING,
    lambda scene, layout: np.array([line.axial_damping / line.segment_length for line in layout.lines]),
    lambda: np.zeros(1), active=lambda scene: any(line.axial_damping for line in line_layouts(scene)),
    damping=_axial_rate, ledger="internal", velocity=True)
"""The segments' internal damping: parameter c = BA / l [N s/m] per line (0 on a line without)."""

BENDING = Term(
    "bending", WITH_BENDING, _bending_params, lambda: np.zeros(2),
    energy=lambda model, x: pair_spring_energy(x, model.scene.bending.stiffness, 2 * model.scene.rope.segment_length,
                                               2, model.scene.rope.closed),
    springs=lambda model: [pairs(0, model.nodes, 2, model.scene.rope.closed, model.scene.bending.stiffness)], reach=2)
"""Second-neighbour springs (i, i + 2), the seed's bending stiffness: parameters k2 [N/m], rest length 2 l [m]."""
