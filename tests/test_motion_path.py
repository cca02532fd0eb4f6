"""A driven node's piecewise-linear path (``path_table``): where it is and how fast it moves at any time, and what a
lookup costs in a long table.

A sea state's fairlead path is long (three hours at 0.1 s is 108 000 rows) and every stage of every step looks its
piece up, for every driven node and axis: the lookup must not walk the table from its first row (it did, and
cost 110 us per call at t = 10 000 s, forty times a whole force evaluation of an 83-node chain).
"""

from __future__ import annotations

import time

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from ropesim.model.motion import Motion, offset


def _motion(times: np.ndarray, rows: np.ndarray) -> Motion:
    """One driven node, one axis moving along the path (times (K,), displacements (K,)), the other still."""
    k = times.size
    z = np.zeros((2, 1))
    return Motion(True, z, z.copy(), z.copy(), z.copy(), np.zeros(1), times, np.vstack([rows, np.zeros(k)]),
                  np.array([[0, k]], dtype=np.int64), z.copy(), None, None, None)


def _linear_walk(times, rows, t):
    """The path's (position, velocity) at t the plain way: walk from the first row to t's piece (the last row at
    or before t, kept inside the table), then interpolate and extrapolate linearly."""
    k = 0
    while k + 2 < times.size and times[k + 1] <= t:
        k += 1
    slope = (rows[k + 1] - rows[k]) / (times[k + 1] - times[k])
    return rows[k] + slope * (t - times[k]), slope


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.01, 2.0), min_size=1, max_size=40), st.data())
def test_the_lookup_finds_the_piece_a_walk_from_the_first_row_finds(gaps, data):
    """Bit for bit the same position and velocity as walking the table, at random times, at every row's own time
    (where the velocity jumps: the piece starting there), before the first row and after the last."""
    times = np.concatenate([[0.0], np.cumsum(gaps)])
    rows = np.asarray(data.draw(st.lists(st.floats(-10, 10), min_size=times.size, max_size=times.size)))
    m = _motion(times, rows)
    probes = list(times) + [-0.5, times[-1] + 0.7] + data.draw(
        st.lists(st.floats(0.0, float(times[-1])), max_size=20))
    for t in probes:
        s, ds, _ = offset(m, 0, 0, float(t), float(t))
        assert (s, ds) == _linear_walk(times, rows, float(t)), t


@njit(cache=True)
def _lookups(m, t, n):
    total = 0.0
    for i in range(n):
        total += offset(m, 0, 0, t + 1e-6 * i, t + 1e-6 * i)[0]
    return total


def test_a_lookup_late_in_a_long_path_costs_no_more_than_an_early_one():
    """10^6 rows (28 hours at 0.1 s): 20 000 lookups at the end take about as long as at the start (a walk from the
    first row took 110 us each at 10^5 rows, so 20 000 of them here would take over 20 s). The bound is 50 times
    the early lookups' time plus 0.1 s, far above a binary search's and far below a walk's."""
    times = 0.1 * np.arange(1_000_000)
    m = _motion(times, np.sin(times))
    _lookups(m, 1.0, 10)

    def timed(t):
        start = time.perf_counter()
        _lookups(m, t, 20_000)
        return time.perf_counter() - start

    early = min(timed(1.0) for _ in range(3))
    late = min(timed(float(times[-2])) for _ in range(3))
    assert late < 50 * early + 0.1, (early, late)


def test_a_stage_keeps_its_steps_piece_past_a_row():
    """A stage of a step takes the piece holding the step's middle, extended beyond its rows: at the row that
    ends the step it keeps the step's velocity (not the next piece's), and past it goes on in a straight line."""
    m = _motion(np.array([0.0, 1.0, 2.0]), np.array([0.0, 2.0, 1.0]))
    assert offset(m, 0, 0, 1.0, 0.95)[:2] == (2.0, 2.0)      # the last stage of the step ending on row 1
    assert offset(m, 0, 0, 1.0, 1.05)[:2] == (2.0, -1.0)     # the first stage of the step starting there
    assert offset(m, 0, 0, 1.0, 1.0)[:2] == (2.0, -1.0)      # a state at the row: on the path, the next piece
    s, ds, _ = offset(m, 0, 0, 1.1, 0.95)                    # a Yoshida drift past the row: the same line
    assert ds == 2.0 and abs(s - 2.2) < 1e-12
