"""Generalized-alpha with adaptive steps: a local error estimate, step-size control and dense output.

With ``integrator.tolerance`` (tol, metres) the steps are the scheme's own choice; the run's time grid (steps of
``integrator.dt``) becomes the grid on which x and v are reported. The saved frames are step ends: a step that
would pass a frame's time is cut to land on it (:func:`land`; the step after it is the controller's own again),
because a stiff line's tension is EA times its strain, and positions interpolated between two solved steps are
not in force balance (on WD0050 a frame read off by interpolation from 30 ms steps carried a fairlead tension
error of 6 % of its range, the frames at step ends 0.2 %). The other grid points are read off the step that
covers them by dense output, a cubic Hermite interpolant of the step's ends (x, v): its error, O(H^4) in x and
O(H^3) in v, is below the scheme's own second-order error.

**The error estimate** is the scheme's own truncation term (Zienkiewicz & Xie 1991 for Newmark, carried over
to generalized-alpha): the displacement's local error is h^3 x''' (beta - 1/6 + (am - af) / 2) + O(h^4) (the
acceleration a_n is the true one shifted by (am - af) h), and x''' h ~ a_(n+1) - a_n, so

    e = h^2 |beta - 1/6 + (am - af) / 2| (a_(n+1) - a_n),

filtered through the step's own (factored) Newton matrix J = M + c2 K + ...: e <- J^-1 M e, as Radau5 and
other stiff solvers filter theirs (Hairer & Wanner IV.8). A resolved mode keeps its estimate; an unresolved
stiff one (the axial waves, the seabed's contact and friction at large steps), whose a_(n+1) - a_n is
omega^2 times its tiny displacement, is divided by 1 + c2 omega^2 down to that displacement. Without the
filter, mooring_chain's steps stayed near 10 ms at a 0.1 m tolerance.

**The tolerance is the run's.** A step of h gets the share h / t_end of it (error per unit step): it is
accepted when max_i e_i / ((h / t_end) (tol + rtol max(|x_n|_i, |x_(n+1)|_i))) <= 1 (rtol:
``integrator.relative_tolerance``, relative to the nodes' coordinates, whose origin is the scene's), so that the
local errors of the whole run add up to at most tol: what a user asks for is the error at the end, and a
local-error control lets an oscillating line's phase error add up over the run (measured on the helicopter:
true error 20 to 200 times a per-step tolerance). summary.json reports that sum ("estimated_error_m"). The
next step is 0.9 h / ratio^(1/2) (the ratio grows as h^2), within 0.2 and 2 times h; a step within 20 % of the last is not changed, so
that the factored matrix stays valid (modified Newton). A rejected step, or one whose Newton solve fails, is
retried at the smaller step. Newton's tolerance becomes a hundredth of tol, but at most a strain of 1e-6 of the
shortest segment (NEWTON_STRAIN in :mod:`ropesim.integrate.galpha`): an unconverged Newton solve is not a
smooth position error but an error in the force balance, EA times it in each segment (at tol = 1 m the
hundredth alone, 1 cm, left WD0050's fairlead tension 5 % off).

The energy ledger is booked per step and read off at each grid point on the line between the step's ends.
Everything the loop keeps between calls (the step's ends, the step, counts and estimates) is state, so a run
cut into calls or resumed gives the same numbers.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from ..model import jit
from .health import NEWTON_FAILED, OK, due, end_step, place

WITH_ADAPTIVE = jit.Switch("adaptive_steps", "generalized-alpha's error-controlled steps and dense output")

NEWTON_FRACTION = 1e-2   # Newton's tolerance, as a fraction of the error tolerance
SAFETY, SHRINK_MOST, GROW_MOST, KEEP_WITHIN = 0.9, 0.2, 2.0, 0.2
NEWTON_SHRINK = 0.25     # the step after a failed Newton solve, as a fraction of the failed one
ORDER = 2.0            # the error ratio's power of h: a local error h^3 against an allowance h tol / t_end
SMALLEST = 1e-12         # a step below this times t_end: the run stops (the solve fails at every step size)

# clock: the last step's start and end [s], the next step [s], tol [m], rtol, the largest estimated local error
# [m], their sum [m], the smallest and largest step taken [s], the node whose error set the last step
T0, T1, H_NEXT, TOL, RTOL, EST_MAX, EST_SUM, H_MIN, H_MAX, LIMITING = range(10)
CLOCK_SIZE = 10
ACCEPTED, REJECTED = 0, 1

Adapt = namedtuple("Adapt", ["x0", "v0", "x1", "v1", "ledger0", "ledger1", "clock", "counts"])
"""The last step's ends (x0, v0 at clock[T0]; x1, v1 at clock[T1]; (D, N)), the ledger at both, the clock and
the counts of steps taken and rejected."""


def new_adapt(x, v, ledger, dt: float, tol: float, rtol: float) -> Adapt:
    clock = np.zeros(CLOCK_SIZE)
    clock[H_NEXT], clock[TOL], clock[RTOL], clock[H_MIN] = dt, tol, rtol, math.inf
    return Adapt(x.copy(), v.copy(), x.copy(), v.copy(), ledger.copy(), ledger.copy(), clock,
                 np.zeros(2, dtype=np.int64))


@jit.kernel
def raw_error(work, an, co, h, nodes, out):
    """M e into ``out`` (flat, node-major, as the Newton matrix's unknowns): e = h^2 |beta - 1/6 + (am - af)/2|
    (a_(n+1) - a_n) per free node, zero at held nodes."""
    am, af, gam, beta = co[0], co[1], co[2], co[3]
    weight = h * h * abs(beta - 1.0 / 6.0 + 0.5 * (am - af))
    scale = 1.0 / ((1.0 - af) * beta * h * h)
    free, mass = nodes.free, nodes.mass
    dim, n = work.X.shape
    for i in range(n):
        for d in range(dim):
            if free[i]:
                a1 = (work.X[d, i] - work.Xk[d, i]) * scale
                out[i * dim + d] = mass[i] * weight * (a1 - an[d, i])
            else:
                out[i * dim + d] = 0.0


@jit.kernel
def error_ratio(error, x, X, af, tol, rtol, free, share):
    """The step's filtered error ``error`` (flat) over its allowance (``share`` of the tolerance), largest over the
    free nodes, that error [m] and its node."""
    dim, n = x.shape
    worst = 0.0
    worst_error = 0.0
    worst_node = -1
    for i in range(n):
        if not free[i]:
            continue
        e2 = 0.0
        size = 0.0
        for d in range(dim):
            e = error[i * dim + d]
            e2 += e * e
            x1 = x[d, i] + (X[d, i] - x[d, i]) / (1.0 - af)
            size = max(size, abs(x[d, i]), abs(x1))
        e = math.sqrt(e2)
        ratio = e / (share * (tol + rtol * size))
        if ratio > worst:
            worst = ratio
            worst_error = e
            worst_node = i
    return worst, worst_error, worst_node


@jit.kernel
def dense_output(adapt, t, x, v, ledger):
    """x, v and the ledger at time t inside the last step: the cubic Hermite interpolant of its ends (x, v), the
    ledger on the line between them."""
    clock = adapt.clock
    span = clock[T1] - clock[T0]
    th = (t - clock[T0]) / span if span > 0.0 else 1.0
    t2 = th * th
    t3 = t2 * th
    h00, h10, h01, h11 = 2.0 * t3 - 3.0 * t2 + 1.0, t3 - 2.0 * t2 + th, 3.0 * t2 - 2.0 * t3, t3 - t2
    d00, d10, d01, d11 = 6.0 * t2 - 6.0 * th, 3.0 * t2 - 4.0 * th + 1.0, 6.0 * th - 6.0 * t2, 3.0 * t2 - 2.0 * th
    x0, v0, x1, v1 = adapt.x0, adapt.v0, adapt.x1, adapt.v1
    dim, n = x.shape
    for d in range(dim):
        for i in range(n):
            x[d, i] = h00 * x0[d, i] + h10 * span * v0[d, i] + h01 * x1[d, i] + h11 * span * v1[d, i]
            if span > 0.0:
                v[d, i] = (d00 * x0[d, i] + d01 * x1[d, i]) / span + d10 * v0[d, i] + d11 * v1[d, i]
            else:
                v[d, i] = v1[d, i]
    for k in range(ledger.shape[0]):
        ledger[k] = adapt.ledger0[k] + th * (adapt.ledger1[k] - adapt.ledger0[k])


@jit.kernel
def land(h, left):
    """The step that lands on a frame ``left`` seconds ahead: all of it when the planned step ``h`` reaches it,
    half of it when two steps of ``h`` would (no sliver of a step after a full one), else ``h``."""
    if left <= h * (1.0 + 1e-9):
        return left
    if left < 2.0 * h:
        return 0.5 * left
    return h


@jit.kernel
def next_step(h, ratio):
    """The step after one of ``h`` whose error ratio was ``ratio``: 0.9 h / ratio^(1/2) within [0.2, 2] h, and h
    itself when that is within 20 % of it (the factored matrix stays valid)."""
    grow = GROW_MOST if ratio <= 0.0 else min(GROW_MOST, max(SHRINK_MOST, SAFETY * ratio ** (-1.0 / ORDER)))
    if 1.0 <= grow <= 1.0 + KEEP_WITHIN:
        return h
    return h * grow
