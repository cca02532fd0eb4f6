"""Shared pieces of every compiled step loop: placing held nodes, the blow-up check, frames and the ledger.

Blow-up check (every ``check_every`` steps and at every saved frame), in this order:

- a non-finite position or velocity (NON_FINITE, naming the first such node);
- a spring stretched beyond ``limits[0]`` times its rest length (OVERSTRETCH, naming its first node);
- runaway energy (RUNAWAY_ENERGY, naming the fastest node): the energy balance residual
  E(t) - E(0) - (W_held + W_box - D_drag) exceeds ``limits[1]`` times the initial energy scale
  ``ledger[SCALE]`` plus ``limits[2]`` times the energy that flowed, |W_held| + |W_box| + D_drag. A stable
  run keeps that residual a small fraction of both (it is the integrator's energy error: at most 0.15 of the
  scale and 0.06 of the flows in the built-in scenes even at 0.95 of the stability bound); an unstable one
  grows it geometrically, or saturates into nonsense whose balance is off by a large fraction of the (itself
  inflated) flows.

The ledger (float64 array of LEDGER_SIZE) holds the cumulative energy lost to drag D [J], the work done by
held (pinned or driven) nodes on the rope W_held [J], the work done by the thrower box and guide circles
W_box [J], and the initial mechanical energy E0 and the energy scale used above.
"""

import numpy as np
from numba import njit

from ..model.terms import mechanical_energy

OK, NON_FINITE, OVERSTRETCH, RUNAWAY_ENERGY, NEWTON_FAILED = 0, 1, 2, 3, 4
STATUS_NAMES = {OK: "ok", NON_FINITE: "non-finite", OVERSTRETCH: "overstretched", RUNAWAY_ENERGY: "runaway energy",
                NEWTON_FAILED: "Newton solve failed"}

DRAG, HELD, BOX, E0, SCALE = 0, 1, 2, 3, 4
LEDGER_SIZE = 5
LEDGER_COLUMNS = ("drag_loss", "held_work", "box_work")  # what each saved frame records, cumulative [J]


@njit(cache=True, error_model="numpy")
def place_held(x, held_idx, held_x0, held_v, t):
    """Put every held node exactly at x0 + V t."""
    dim = x.shape[0]
    for j in range(held_idx.shape[0]):
        i = held_idx[j]
        for d in range(dim):
            x[d, i] = held_x0[d, j] + held_v[d, j] * t


@njit(cache=True, error_model="numpy")
def first_non_finite(x):
    dim, n = x.shape
    for i in range(n):
        for d in range(dim):
            if not np.isfinite(x[d, i]):
                return i
    return -1


@njit(cache=True, error_model="numpy")
def check_health(x, v, mass, forces, ledger, limits):
    """(status, node): OK and -1 when the state is sane, else the first problem found (see the module doc)."""
    energy, stretch, node = mechanical_energy(x, v, mass, forces)
    return verdict(energy, stretch, node, x, v, ledger, limits)


@njit(cache=True, error_model="numpy", inline="always")
def balance_status(energy, stretch, held, box, drag, e0, scale, max_stretch, of_scale, of_flows):
    """OVERSTRETCH, RUNAWAY_ENERGY or OK from the energy [J], worst stretch and ledger entries alone.

    Scalars only, so the compiled loops can call it at every check without handing over arrays (whose
    reference counting costs more than the test). A NaN energy passes; :func:`verdict` looks for its culprit.
    """
    if stretch > max_stretch:
        return OVERSTRETCH
    flowed = held + box - drag
    if abs(energy - e0 - flowed) > of_scale * scale + of_flows * (abs(held) + abs(box) + drag):
        return RUNAWAY_ENERGY
    return OK


@njit(cache=True, error_model="numpy")
def verdict(energy, stretch, node, x, v, ledger, limits):
    """:func:`check_health` given the mechanical energy [J] and the worst stretch (and its node) of the state."""
    if not np.isfinite(energy):   # every position and velocity enters the energy: look for the culprit only now
        bad = first_non_finite(x)
        if bad < 0:
            bad = first_non_finite(v)
        if bad >= 0:
            return NON_FINITE, bad
    status = balance_status(energy, stretch, ledger[HELD], ledger[BOX], ledger[DRAG], ledger[E0], ledger[SCALE],
                            limits[0], limits[1], limits[2])
    if status == OVERSTRETCH:
        return status, node
    if status == RUNAWAY_ENERGY:
        dim, n = v.shape
        fastest, best = 0, -1.0
        for i in range(n):
            v2 = 0.0
            for d in range(dim):
                v2 += v[d, i] * v[d, i]
            if v2 > best:
                best, fastest = v2, i
        return status, fastest
    return OK, -1


@njit(cache=True, error_model="numpy")
def save_frame(frame, t, x, v, ledger, frames_t, frames_x, frames_v, frames_w):
    frames_t[frame] = t
    frames_x[frame] = x
    frames_v[frame] = v
    for c in range(frames_w.shape[1]):
        frames_w[frame, c] = ledger[c]


@njit(cache=True, error_model="numpy")
def held_power(acc, mass, held_idx, held_v):
    """Power [W] of the held nodes' supports on the rope at one instant.

    A held node does not accelerate, so its support pushes it with -m a (a without drag), moving at V.
    """
    dim = acc.shape[0]
    p = 0.0
    for j in range(held_idx.shape[0]):
        i = held_idx[j]
        for d in range(dim):
            p -= mass[i] * acc[d, i] * held_v[d, j]
    return p


@njit(cache=True, error_model="numpy")
def power(acc, v, mass):
    """Power [W] of the accelerations ``acc`` on nodes moving at ``v``: sum of m a . v."""
    dim, n = acc.shape
    p = 0.0
    for d in range(dim):
        for i in range(n):
            p += mass[i] * acc[d, i] * v[d, i]
    return p


@njit(cache=True, error_model="numpy")
def end_step(done, total_steps, save_every, check_every, h, x, v, mass, forces, ledger, limits, frames, frame):
    """After global step ``done`` (1-based): check the state when due and save a frame when due.

    Returns (status, node, frames written so far).
    """
    saving = done % save_every == 0 or done == total_steps
    if saving or done % check_every == 0:
        status, node = check_health(x, v, mass, forces, ledger, limits)
        if status != OK:
            return status, node, frame
    if saving:
        save_frame(frame, done * h, x, v, ledger, frames[0], frames[1], frames[2], frames[3])
        frame += 1
    return OK, -1, frame
