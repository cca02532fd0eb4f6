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


@jit.kernel
def set_chain_springs(x, acc, inv_mass, k, rest, closed, g, slack):
    """Overwrite ``acc`` with the accelerations [m/s^2] of the rope's springs (i, i + 1), minus ``g`` along y.

    The same forces as ``add_pair_springs(..., stride=1, ...)`` plus gravity, computed so that both loops
    vectorise: first each spring's force F_i (on node i, from spring (i, i + 1)) is written into ``acc[:, i]``,
    then, from the last node down, a_i = (F_i - F_(i-1)) / m_i - g. 2-D and 3-D are written out row by row.
    """
    dim, n = x.shape
    if dim == 2:
        for i in range(n - 1):
            d0 = x[0, i + 1] - x[0, i]
            d1 = x[1, i + 1] - x[1, i]
            c = _spring_scale(k, rest, d0 * d0 + d1 * d1, slack)
            acc[0, i] = c * d0
            acc[1, i] = c * d1
        l0 = l1 = 0.0   # the force of the spring closing a loop, (n - 1, 0), on node n - 1
        if closed:
            d0 = x[0, 0] - x[0, n - 1]
            d1 = x[1, 0] - x[1, n - 1]
            c = _spring_scale(k, rest, d0 * d0 + d1 * d1, slack)
            l0, l1 = c * d0, c * d1
        acc[0, n - 1] = l0
        acc[1, n - 1] = l1
        for i in range(n - 1, 0, -1):
            m = inv_mass[i]
            acc[0, i] = (acc[0, i] - acc[0, i - 1]) * m
            acc[1, i] = (acc[1, i] - acc[1, i - 1]) * m - g
        acc[0, 0] = (acc[0, 0] - l0) * inv_mass[0]
        acc[1, 0] = (acc[1, 0] - l1) * inv_mass[0] - g
    else:
        for i in range(n - 1):
            d0 = x[0, i + 1] - x[0, i]
            d1 = x[1, i + 1] - x[1, i]
            d2 = x[2, i + 1] - x[2, i]
            c = _spring_scale(k, rest, d0 * d0 + d1 * d1 + d2 * d2, slack)
            acc[0, i] = c * d0
            acc[1, i] = c * d1
            acc[2, i] = c * d2
        l0 = l1 = l2 = 0.0
        if closed:
            d0 = x[0, 0] - x[0, n - 1]
            d1 = x[1, 0] - x[1, n - 1]
            d2 = x[2, 0] - x[2, n - 1]
            c = _spring_scale(k, rest, d0 * d0 + d1 * d1 + d2 * d2, slack)
            l0, l1, l2 = c * d0, c * d1, c * d2
        acc[0, n - 1] = l0
        acc[1, n - 1] = l1
        acc[2, n - 1] = l2
        for i in range(n - 1, 0, -1):
            m = inv_mass[i]
            acc[0, i] = (acc[0, i] - acc[0, i - 1]) * m
            acc[1, i] = (acc[1, i] - acc[1, i - 1]) * m - g
            acc[2, i] = (acc[2, i] - acc[2, i - 1]) * m
        acc[0, 0] = (acc[0, 0] - l0) * inv_mass[0]
        acc[1, 0] = (acc[1, 0] - l1) * inv_mass[0] - g
        acc[2, 0] = (acc[2, 0] - l2) * inv_mass[0]


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
    k (r - l0) (none while a slack segment is short) plus the axial damping c dr/dt. Segment j joins node j
    and node j + 1 (node 0 for a loop's last segment)."""
    rope = model.scene.rope
    k, rest, c = rope.stiffness, rope.segment_length, (rope.axial_damping or 0.0) / rope.segment_length

    def force(block):
        xb, vb = block[..., :block.shape[-1] // 2], block[..., block.shape[-1] // 2:]
        d = _deltas(xb, 1, rope.closed)
        r = np.linalg.norm(d, axis=-1)
        f = k * (r - rest)
        if not rope.compression:
            f = np.maximum(f, 0.0)
        if c:
            unit = d / np.where(r > 0, r, 1.0)[..., None]
            f = f + c * np.sum(unit * _deltas(vb, 1, rope.closed), axis=-1)
        return f
    return _by_blocks(force, np.concatenate([np.asarray(x), np.asarray(v)], axis=-1))


@jit.kernel
def add_axial_damping(x, v, acc, inv_mass, c, closed):
    """Add the segments' axial damping c (r_hat . dv) r_hat [N] / m; returns its power [W] (never positive)."""
    dim, n = x.shape
    count = n if closed else n - 1
    power = 0.0
    for i in range(count):
        j = i + 1 if i + 1 < n else 0
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


def _rope_params(scene, mass) -> np.ndarray:
    rope = scene.rope
    return np.array([rope.stiffness, rope.segment_length, 1.0 if rope.closed else 0.0,
                     0.0 if rope.compression else 1.0])


def _bending_params(scene, mass) -> np.ndarray:
    return np.array([scene.bending.stiffness, 2.0 * scene.rope.segment_length])


ROPE = Term(
    "rope", None, _rope_params, lambda: np.zeros(4),
    energy=lambda model, x: pair_spring_energy(x, model.scene.rope.stiffness, model.scene.rope.segment_length, 1,
                                               model.scene.rope.closed, not model.scene.rope.compression),
    springs=lambda model: [(1, model.scene.rope.stiffness)], label="spring", reach=1)
"""The rope's own springs (i, i + 1): parameters k [N/m], rest length l [m], closed (1) or open (0), slack (1)."""

AXIAL_DAMPING = Term(
    "rope", WITH_AXIAL_DAMPING, lambda scene, mass: np.array([scene.rope.axial_damping / scene.rope.segment_length]),
    lambda: np.zeros(1), active=lambda scene: bool(scene.rope.axial_damping),
    damping=lambda model: 4.0 * model.scene.rope.axial_damping / model.scene.rope.segment_length
    / float(model.mass[~model.held].min()), ledger="internal", velocity=True)
"""The segments' internal damping: parameter c = BA / l [N s/m]."""

BENDING = Term(
    "bending", WITH_BENDING, _bending_params, lambda: np.zeros(2),
    energy=lambda model, x: pair_spring_energy(x, model.scene.bending.stiffness, 2 * model.scene.rope.segment_length,
                                               2, model.scene.rope.closed),
    springs=lambda model: [(2, model.scene.bending.stiffness)], reach=2)
"""Second-neighbour springs (i, i + 2), the seed's bending stiffness: parameters k2 [N/m], rest length 2 l [m]."""
