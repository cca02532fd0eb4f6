"""Hookean springs between node pairs (i, i + stride): the rope itself (stride 1) and bending (stride 2).

A spring of stiffness k and rest length l0 between nodes i and j stores E = k/2 (|x_j - x_i| - l0)^2 and
pulls both ends along the segment with force k (r - l0) r_hat. On an open line the springs are
(i, i + stride) for i < N - stride; on a closed loop the indices wrap, giving N springs.
"""

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
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


def pair_spring_energy(x, k, rest, stride, closed):
    """Energy [J] stored in the springs (i, i + stride), for positions of shape (..., N, D)."""
    return _by_blocks(lambda b: 0.5 * k * np.sum((np.linalg.norm(_deltas(b, stride, closed), axis=-1) - rest) ** 2,
                                                 axis=-1), x)


def pair_spring_stretch(x, rest, stride, closed):
    """Relative stretch |r| / l0 - 1 of every spring (i, i + stride), for positions (..., N, D)."""
    return _by_blocks(lambda b: np.linalg.norm(_deltas(b, stride, closed), axis=-1) / rest - 1.0, x)
