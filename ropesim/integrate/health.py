"""Shared pieces of every compiled step loop: placing held nodes, the blow-up check, frames and the ledger.

Blow-up check (every ``check_every`` steps and at every saved frame), in this order:

- a non-finite position or velocity (NON_FINITE, naming the first such node);
- a spring stretched beyond ``limits[0]`` times its rest length (OVERSTRETCH, naming its first node);
- runaway energy (RUNAWAY_ENERGY, naming the fastest node): the energy balance residual
  E(t) - E(0) - (W_held + W_box + W_fluid + W_internal + W_seabed - D_drag) exceeds ``limits[1]`` times the
  initial energy scale ``ledger[SCALE]`` plus ``limits[2]`` times the energy that flowed, the sum of the
  flows' magnitudes (:func:`flows`). A stable
  run keeps that residual a small fraction of both (it is the integrator's energy error: at most 0.15 of the
  scale and 0.06 of the flows in the built-in scenes even at 0.95 of the stability bound); an unstable one
  grows it geometrically, or saturates into nonsense whose balance is off by a large fraction of the (itself
  inflated) flows.

The ledger (float64 array of LEDGER_SIZE) holds, cumulative [J]: the energy lost to the linear [drag] D (in
still air; in a flow, its push + b U is fluid work), the work of held (pinned or driven) nodes' supports on
the rope W_held, the work of the thrower box and guide circles W_box, the work of the fluid W_fluid (drag on
the relative velocity, a flow's push, added mass), the work of the rope's axial damping W_internal (never
positive) and of the seabed W_seabed; then the initial mechanical energy E0 and the energy scale used above.
"""

import numpy as np

from ..model import jit
from ..model.motion import place_moving
from ..model.bodies import WITH_BODIES, save_bodies
from ..model.terms import WITH_MOTION, bodies_energy, mechanical_energy

OK, NON_FINITE, OVERSTRETCH, RUNAWAY_ENERGY, NEWTON_FAILED = 0, 1, 2, 3, 4
STATUS_NAMES = {OK: "ok", NON_FINITE: "non-finite", OVERSTRETCH: "overstretched", RUNAWAY_ENERGY: "runaway energy",
                NEWTON_FAILED: "Newton solve failed"}

DRAG, HELD, BOX, FLUID, INTERNAL, SEABED, E0, SCALE = 0, 1, 2, 3, 4, 5, 6, 7
LEDGER_SIZE = 8
LEDGER_COLUMNS = ("drag_loss", "held_work", "box_work", "fluid_work", "internal_work", "seabed_work")
"""What each saved frame records of the ledger, cumulative [J] (the first LEDGER_COLUMNS entries)."""


@jit.kernel
def place_held(x, held_idx, held_x0, held_v, t):
    """Put every held node exactly at x0 + V t."""
    dim = x.shape[0]
    for j in range(held_idx.shape[0]):
        i = held_idx[j]
        for d in range(dim):
            x[d, i] = held_x0[d, j] + held_v[d, j] * t


@jit.kernel
def first_non_finite(x):
    dim, n = x.shape
    for i in range(n):
        for d in range(dim):
            if not np.isfinite(x[d, i]):
                return i
    return -1


@jit.kernel(inline="always")
def check_health(x, v, mass, params, ledger, limits, bodies):
    """(status, node): OK and -1 when the state is sane, else the first problem found (see the module doc);
    ``bodies`` the free rigid bodies' state (:class:`ropesim.integrate.base.BodyState`)."""
    energy, stretch, node = mechanical_energy(x, v, mass, params)
    if WITH_BODIES:
        energy += bodies_energy(params, bodies.pose, bodies.twist)
    return verdict(energy, stretch, node, x, v, ledger, limits)


@jit.kernel(inline="always")
def flows(ledger):
    """(energy that flowed in, net [J]; the sum of the flows' magnitudes [J]) from the ledger."""
    flowed = ledger[HELD] + ledger[BOX] - ledger[DRAG] + ledger[FLUID] + ledger[INTERNAL] + ledger[SEABED]
    moved = (abs(ledger[HELD]) + abs(ledger[BOX]) + ledger[DRAG] + abs(ledger[FLUID]) + abs(ledger[INTERNAL])
             + abs(ledger[SEABED]))
    return flowed, moved


@jit.kernel(inline="always")
def balance_status(energy, stretch, flowed, moved, e0, scale, max_stretch, of_scale, of_flows):
    """OVERSTRETCH, RUNAWAY_ENERGY or OK from the energy [J], worst stretch and the ledger's flows alone
    (:func:`flows`).

    Scalars only, so the compiled loops can call it at every check without handing over arrays (whose
    reference counting costs more than the test). A NaN energy passes; :func:`verdict` looks for its culprit.
    """
    if stretch > max_stretch:
        return OVERSTRETCH
    if abs(energy - e0 - flowed) > of_scale * scale + of_flows * moved:
        return RUNAWAY_ENERGY
    return OK


@jit.kernel
def verdict(energy, stretch, node, x, v, ledger, limits):
    """:func:`check_health` given the mechanical energy [J] and the worst stretch (and its node) of the state."""
    if not np.isfinite(energy):   # every position and velocity enters the energy: look for the culprit only now
        bad = first_non_finite(x)
        if bad < 0:
            bad = first_non_finite(v)
        if bad >= 0:
            return NON_FINITE, bad
    flowed, moved = flows(ledger)
    status = balance_status(energy, stretch, flowed, moved, ledger[E0], ledger[SCALE], limits[0], limits[1],
                            limits[2])
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


@jit.kernel
def save_frame(frame, t, x, v, ledger, frames_t, frames_x, frames_v, frames_w):
    frames_t[frame] = t
    dim, n = x.shape
    for d in range(dim):   # element by element: a slice assignment may copy its source, which needs an allocation,
        # and compiles Numba's shape-mismatch message (seconds of a first run's compile)
        for i in range(n):
            frames_x[frame, d, i] = x[d, i]
            frames_v[frame, d, i] = v[d, i]
    for c in range(frames_w.shape[1]):
        frames_w[frame, c] = ledger[c]


@jit.kernel
def held_power(acc, mass, held):
    """Power [W] of the held nodes' supports on the rope at one instant.

    A held node follows its prescribed motion, so its support pushes it with m (a_p - a), a the acceleration
    the forces would give it (``acc``, without the linear drag) and a_p the prescribed one (zero for pins and
    constant drives), while it moves at its velocity ``held.v``.
    """
    held_idx, held_v, motion = held.idx, held.v, held.motion
    dim = acc.shape[0]
    p = 0.0
    for j in range(held_idx.shape[0]):
        i = held_idx[j]
        for d in range(dim):
            p -= mass[i] * acc[d, i] * held_v[d, j]
    if WITH_MOTION:
        for j in range(held_idx.shape[0]):
            i = held_idx[j]
            for d in range(dim):
                p += mass[i] * motion.accel[d, j] * held_v[d, j]
    return p


@jit.kernel
def place(x, v, held, t, t_piece):
    """Put every held node where it must be at time t: x0 + V t, or its prescribed motion (which also sets its
    velocity in ``v``; a path on its piece that holds ``t_piece``, see :mod:`ropesim.model.motion`)."""
    if WITH_MOTION:
        place_moving(x, v, held, t, t_piece)
    else:
        place_held(x, held.idx, held.x0, held.v, t)


@jit.kernel
def power(acc, v, mass):
    """Power [W] of the accelerations ``acc`` on nodes moving at ``v``: sum of m a . v."""
    dim, n = acc.shape
    p = 0.0
    for d in range(dim):
        for i in range(n):
            p += mass[i] * acc[d, i] * v[d, i]
    return p


@jit.kernel
def end_step(done, schedule, x, v, mass, params, ledger, limits, frames, frame, bodies):
    """After global step ``done`` (1-based): check the state when due and save a frame when due.

    ``schedule``, ``frames`` and ``bodies`` are the bundles of :mod:`ropesim.integrate.base`. Returns (status,
    node, frames written so far).
    """
    saving = done % schedule.save_every == 0 or done == schedule.total_steps
    if saving or done % schedule.check_every == 0:
        status, node = check_health(x, v, mass, params, ledger, limits, bodies)
        if status != OK:
            return status, node, frame
    if saving:
        save_frame(frame, done * schedule.h, x, v, ledger, frames.t, frames.x, frames.v, frames.ledger)
        if WITH_BODIES:
            save_bodies(frame, bodies.pose, bodies.twist, frames.body)
        frame += 1
    return OK, -1, frame


@jit.kernel(inline="always")
def due(done, schedule):
    """True when global step ``done`` needs the end-of-step work (a check or a frame)."""
    return done % schedule.check_every == 0 or done % schedule.save_every == 0 or done == schedule.total_steps


def net_flow(ledger) -> float:
    """The energy that flowed in, net [J] (:func:`flows` without compiling)."""
    return float(ledger[HELD] + ledger[BOX] - ledger[DRAG] + ledger[FLUID] + ledger[INTERNAL] + ledger[SEABED])


# ------------------------------------------------------------------------- the limits, set up in Python

RUNAWAY_FACTOR = 1.0      # a blow-up: energy balance off by this times the initial energy scale ...
RUNAWAY_FLOW_FRACTION = 0.2  # ... plus this fraction of the energy that flowed in and out
STRETCH_SANITY = 4.0      # a spring longer than this many rest lengths (or 4x its static strain) is a blow-up


def initial_ledger(model, x: np.ndarray, v: np.ndarray, pose: np.ndarray | None = None,
                   twist: np.ndarray | None = None) -> np.ndarray:
    """A new ledger (LEDGER_SIZE,): no flows yet, the mechanical energy of (x, v) (D, N) (and of the free bodies
    at pose (7, B) and twist (6, B)) and the energy scale."""
    from ..model.energy import energy_terms

    ledger = np.zeros(LEDGER_SIZE)
    ledger[E0] = float(energy_terms(model, x.T, v.T, pose, twist)["total"])
    ledger[SCALE] = energy_scale(model)
    return ledger


def limits(model) -> np.ndarray:
    """The blow-up check's limits: largest sane stretch, runaway factor, runaway fraction of the flows."""
    return np.array([stretch_limit(model), RUNAWAY_FACTOR, RUNAWAY_FLOW_FRACTION])


def energy_scale(model) -> float:
    """The energy scale [J] a blow-up is measured against (before the flows are added, see the module doc).

    Initial kinetic and elastic energy, plus the whole weight times the lines' length (what gravity can
    convert), plus every spring stretched by 1 % (so a rope at rest in zero gravity still has a scale).
    """
    from ..model.energy import energy_terms

    scene = model.scene
    g = scene.gravity.g if scene.gravity is not None else 0.0
    terms = energy_terms(model, model.x0.T, model.v0.T)
    moving = float(terms["total"] - terms.get("gravity", 0.0))
    length = sum(line.nodes * line.segment_length for line in model.lines)
    stretched = sum(line.nodes * 0.5 * line.stiffness * (0.01 * line.segment_length) ** 2 for line in model.lines)
    return abs(moving) + total_mass(model) * g * length + stretched


def total_mass(model) -> float:
    """Every node's mass and every free rigid body's [kg]."""
    bodies = model.params.bodies
    return float(model.mass.sum()) + (float(bodies.mass.sum()) if bodies is not None else 0.0)


def stretch_limit(model) -> float:
    """Largest sane spring length / rest length [-].

    STRETCH_SANITY, or 1 + STRETCH_SANITY times the strain the rope's whole static load would cause (its
    weight, drag at the held nodes' speed, the thrower's full drive on the nodes its box can hold), or twice
    the longest spring at t = 0, whichever is largest. Stable runs of the built-in scenes stay below 1.7; an
    unstable one that saturates instead of overflowing (bounded garbage) goes past it within a few steps.
    """
    from ..model.forces.springs import segment_strains

    scene, rope = model.scene, model.scene.rope
    g = scene.gravity.g if scene.gravity is not None else 0.0
    load = total_mass(model) * g
    if model.held_v.size:
        load += float(model.drag.sum()) * float(np.abs(model.held_v).max())
    if scene.thrower is not None:
        in_box = min(rope.nodes, scene.thrower.length / rope.segment_length + 1)
        load += in_box * scene.thrower.b_thrower * abs(scene.thrower.v_max)
    initial = float(np.max(segment_strains(model, model.x0.T), initial=0.0)) + 1.0
    softest = min(line.stiffness * line.segment_length for line in model.lines)   # its strain under the load
    return max(STRETCH_SANITY, 1.0 + STRETCH_SANITY * load / softest, 2.0 * initial)
