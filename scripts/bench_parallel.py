"""Would both cores pay for a big rope? Serial against parallel (numba prange) versions of the step's loops.

The step's per-node work is the spring pass and the kick and drift. Here both are written twice, once as
plain loops (as in ropesim's kernel) and once with `prange` over nodes, for the towed rope's 2-D state;
every node's arithmetic is the same in both, so the results are bit-identical (checked). The parallel
pass writes each spring's force into a buffer, because ropesim's in-place second pass (which reads the
neighbour below before overwriting it) is not safe to split between threads. Each version runs the same
steps interleaved with the other; the table shows the median time per step and the speed-up, and the
threading layer Numba used. On a 2-core machine shared with other work the speed-up is what both cores
give when the other processes leave one free.

    python scripts/bench_parallel.py [--repeats 5] [--sizes 10000,100000,1000000]
"""

from __future__ import annotations

import argparse
import math

import numba
import numpy as np
from numba import njit, prange
from rich.console import Console
from rich.table import Table

from benchlib import interleaved, load_note, median, median_ratio

L0, K, M, B, G, H = 0.5, 5000.0, 5.0, 5.0, 9.81, 0.001


@njit(error_model="numpy")
def steps_serial(x, v, f, n_steps, decay, gain):
    n = x.shape[1]
    for _ in range(n_steps):
        for i in range(n - 1):
            d0 = x[0, i + 1] - x[0, i]
            d1 = x[1, i + 1] - x[1, i]
            c = K * (1.0 - L0 / np.sqrt(d0 * d0 + d1 * d1))
            f[0, i + 1] = c * d0
            f[1, i + 1] = c * d1
        for i in range(1, n):
            a0 = (f[0, i + 1] - f[0, i]) / M
            a1 = (f[1, i + 1] - f[1, i]) / M - G
            v[0, i] = decay * v[0, i] + gain * a0
            v[1, i] = decay * v[1, i] + gain * a1
            x[0, i] += H * v[0, i]
            x[1, i] += H * v[1, i]


@njit(error_model="numpy", parallel=True)
def steps_parallel(x, v, f, n_steps, decay, gain):
    n = x.shape[1]
    for _ in range(n_steps):
        for i in prange(n - 1):
            d0 = x[0, i + 1] - x[0, i]
            d1 = x[1, i + 1] - x[1, i]
            c = K * (1.0 - L0 / np.sqrt(d0 * d0 + d1 * d1))
            f[0, i + 1] = c * d0
            f[1, i + 1] = c * d1
        for i in prange(1, n):
            a0 = (f[0, i + 1] - f[0, i]) / M
            a1 = (f[1, i + 1] - f[1, i]) / M - G
            v[0, i] = decay * v[0, i] + gain * a0
            v[1, i] = decay * v[1, i] + gain * a1
            x[0, i] += H * v[0, i]
            x[1, i] += H * v[1, i]


def state(n: int):
    x = np.zeros((2, n))
    x[1] = -L0 * 1.01 * np.arange(n)
    v = np.zeros((2, n))
    v[0] = 8.0
    return x, v, np.zeros((2, n + 1))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--sizes", default="1000,10000,100000,1000000")
    args = parser.parse_args()
    decay, gain = math.exp(-B / M * H), -math.expm1(-B / M * H) / (B / M)
    table = Table(title=f"Serial vs parallel step loops, {numba.get_num_threads()} threads "
                        f"(median of {args.repeats} interleaved rounds)")
    for col in ("N", "serial / step", "parallel / step", "speed-up", "identical"):
        table.add_column(col, justify="right")
    for n in (int(s) for s in args.sizes.split(",")):
        steps = max(5, int(2e7 / n))
        a, b = state(n), state(n)
        steps_serial(*a, 1, decay, gain)
        steps_parallel(*b, 1, decay, gain)
        same = all(np.array_equal(p, q) for p, q in zip(a, b))
        t = interleaved({"serial": lambda: steps_serial(*a, steps, decay, gain),
                         "parallel": lambda: steps_parallel(*b, steps, decay, gain)}, args.repeats)
        same = same and all(np.array_equal(p, q) for p, q in zip(a, b))
        table.add_row(f"{n:,}", f"{median(t['serial']) / steps * 1e6:,.1f} us",
                      f"{median(t['parallel']) / steps * 1e6:,.1f} us",
                      f"{median_ratio(t['serial'], t['parallel']):.2f}x", "yes" if same else "NO")
    Console().print(table)
    Console().print(f"threading layer: {numba.threading_layer()}; " + load_note())


if __name__ == "__main__":
    main()
