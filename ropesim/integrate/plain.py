"""The fast path for the plainest scene: a 2-D rope of springs (open or closed) under gravity and linear drag.

A scene with no bending springs, no thrower and no guide circles (the towed ropes) needs only the rope's own
springs, so its splitting steps run in :func:`advance_chain`: one function body whose loops are as plain as a
hand-written loop for this physics alone, and which nonetheless keeps every feature of the general loop
(:func:`ropesim.integrators.advance`): any splitting scheme, held nodes on x0 + V t, per-node masses and
drag, the energy ledger, the blow-up check and saved frames. Its trajectories are bit-identical to the
general loop's.

Three things make it fast:

- *Bulk and exceptions.* Most free nodes share one mass and one drag coefficient. The kick treats every node
  as such a bulk node, with scalar factors that stay in registers, and then redoes the few exceptions (free
  nodes with an overridden mass or drag) from their saved pre-kick state with their own factors. Held nodes
  get their velocity V back and their place x0 + V t after the drift.
- *Spring forces once per spring, differenced in the kick.* The spring pass writes the force F_i of spring
  (i, i + 1) on node i into ``f[:, i + 1]`` (``f[:, 0]`` and ``f[:, N]`` hold the loop-closing spring's, or
  0); the kick takes a_i = (F_i - F_(i-1)) / m_i - g straight from it, so no acceleration array is written.
- *Drag loss booked per node, the kinetic part telescoped.* The energy drag takes out in a kick is the work
  of the forces over the kick minus the kinetic energy gained, D = m a . (gain u + travel a) - dK (see
  :mod:`ropesim.kick`). Between kicks only kicks change a velocity, so the dK terms of successive kicks
  telescope: each node accumulates only its work per unit mass, (u + reach a) . (gain a) with
  reach = travel / gain, in ``lost`` (an element-wise update that vectorises, reusing the gain a of the
  kick), and D = sum_i m_i lost_i - (K - K_0) is formed by :func:`settle_drag` whenever the ledger is read (a
  blow-up check, a saved frame, the end of a call). It is a function of the state alone, so chunking never
  changes it; a scene without drag skips the term altogether.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .health import BOX, DRAG, E0, HELD, OK, SCALE, balance_status, save_frame, verdict
from ..model.terms import BENDING, GRAVITY, GUIDES, THROWER
from .kick import LANES, _lanes

BULK_FIXED = 1        # bulk = [1 / m, then per kick stage: decay, gain, reach]
BULK_PER_STAGE = 3


def applies(model, scheme) -> bool:
    """True when ``model`` stepped by ``scheme`` can run on :func:`advance_chain`."""
    flags = model.forces[1]
    return (scheme.kind == "splitting" and model.dim == 2 and model.nodes >= 2
            and not (flags[BENDING] or flags[THROWER] or flags[GUIDES]))


class ChainState:
    """The fast path's arrays for one model and scheme: bulk factors, exceptions, forces and per-node work.

    ``decay``, ``gain`` and ``travel`` (kick stages, N) are the kick factors of
    :func:`ropesim.integrators.kick_factors`; ``reach`` = travel / gain turns the work of a kick into
    (u + reach a) . (gain a) per unit mass.
    """

    def __init__(self, model, decay: np.ndarray, gain: np.ndarray, travel: np.ndarray):
        free = ~model.held
        mass, drag = model.mass, model.drag
        if free.any():   # the bulk is the commonest (mass, drag) pair among free nodes
            pairs, counts = np.unique(np.stack([mass[free], drag[free]]), axis=1, return_counts=True)
            m_bulk, b_bulk = pairs[:, np.argmax(counts)]
        else:
            m_bulk, b_bulk = mass[0], drag[0]
        bulk_node = free & (mass == m_bulk) & (drag == b_bulk)
        like = int(np.flatnonzero(bulk_node)[0]) if bulk_node.any() else 0
        with np.errstate(invalid="ignore"):   # inf / inf where a forced run's backward kick overflowed
            reach = travel / np.where(gain != 0.0, gain, 1.0)   # gain is 0 only at held nodes, which book no work
        stages = decay.shape[0]
        self.bulk = np.empty(BULK_FIXED + BULK_PER_STAGE * stages)
        self.bulk[0] = model.forces[0][like]
        for k in range(stages):
            self.bulk[BULK_FIXED + BULK_PER_STAGE * k:BULK_FIXED + BULK_PER_STAGE * (k + 1)] = (
                decay[k, like], gain[k, like], reach[k, like])
        self.exceptions = np.flatnonzero(free & ~bulk_node).astype(np.int64)
        e = self.exceptions
        self.exception_factors = np.ascontiguousarray(np.stack([decay[:, e], gain[:, e], reach[:, e]], axis=1))
        self.saved = (np.zeros((2, e.size)), np.zeros((2, e.size)), np.zeros(e.size))   # pre-kick x, v, lost
        self.spring_forces = np.zeros((2, model.nodes + 1))   # see advance_chain's f
        self.lost = np.zeros(model.nodes)
        self.free_mass = np.where(free, mass, 0.0)
        self.scratch = (np.zeros(model.nodes), np.zeros(model.nodes))   # spring lengths, per-node terms
        self.kinetic0 = -settle(np.zeros(model.nodes), model.v0, self.free_mass, 0.0, self.scratch[1])   # K(0) [J]
        self.has_drag = bool(np.any(drag[free] > 0.0))


@njit(cache=True, error_model="numpy", inline="always")
def settle(lost, v, free_mass, kinetic0, terms):
    """sum_i m_i (lost_i - |v_i|^2 / 2) + kinetic0 over the free nodes (m_i = 0 at held ones), in a fixed order.

    With ``lost`` the work per unit mass booked since the start and ``kinetic0`` the free nodes' kinetic energy
    then, this is the energy drag has taken out [J]. ``terms`` (N,) is scratch.
    """
    for i in range(v.shape[1]):
        terms[i] = free_mass[i] * (lost[i] - 0.5 * (v[0, i] * v[0, i] + v[1, i] * v[1, i]))
    return _lanes(terms) + kinetic0


@njit(cache=True, error_model="numpy", inline="always")
def chain_energy(x, v, mass, k, rest, closed, g, lengths, terms):
    """(mechanical energy [J], largest spring length / rest length, that spring's first node) of the rope.

    The quantities of :func:`ropesim.kernel.mechanical_energy` for a 2-D rope with only its springs and
    gravity, in passes that vectorise and sums in a fixed order (``lengths`` and ``terms``, (N,), are
    scratch). A non-finite state gives a non-finite energy.
    """
    n = x.shape[1]
    springs = n if closed else n - 1
    for i in range(n - 1):
        d0 = x[0, i + 1] - x[0, i]
        d1 = x[1, i + 1] - x[1, i]
        lengths[i] = np.sqrt(d0 * d0 + d1 * d1)
    if closed:
        d0 = x[0, 0] - x[0, n - 1]
        d1 = x[1, 0] - x[1, n - 1]
        lengths[n - 1] = np.sqrt(d0 * d0 + d1 * d1)
    for i in range(n):
        terms[i] = 0.5 * mass[i] * (v[0, i] * v[0, i] + v[1, i] * v[1, i]) + mass[i] * g * x[1, i]
    for i in range(springs):
        e = lengths[i] - rest
        terms[i] += 0.5 * k * e * e
    m0 = m1 = m2 = m3 = 0.0
    whole = springs - springs % LANES
    for i in range(0, whole, LANES):
        m0 = max(m0, lengths[i])
        m1 = max(m1, lengths[i + 1])
        m2 = max(m2, lengths[i + 2])
        m3 = max(m3, lengths[i + 3])
    for i in range(whole, springs):
        m0 = max(m0, lengths[i])
    worst = max(max(m0, m1), max(m2, m3))
    node = -1
    for i in range(springs):
        if lengths[i] == worst:
            node = i
            break
    return _lanes(terms), worst / rest, node


@njit(cache=True, error_model="numpy", inline="always")
def settle_drag(ledger, lost, v, free_mass, kinetic0, has_drag, held_idx, terms):
    """Set ``ledger[DRAG]`` from the work booked in ``lost`` and the kinetic energy the free nodes gained [J].

    The held nodes' entries of ``lost`` hold whatever their bulk kick booked, and are cleared first.
    """
    if has_drag:
        for j in range(held_idx.shape[0]):
            lost[held_idx[j]] = 0.0
        ledger[DRAG] = settle(lost, v, free_mass, kinetic0, terms)


@njit(cache=True, error_model="numpy")
def advance_chain(x, v, f, lost, ledger, have_acc, step0, n_steps, total_steps, h, drift, kick, bulk, exceptions,
                  exception_factors, saved, reuse_force, held, mass, forces, free_mass, kinetic0, has_drag, scratch,
                  limits, save_every, frames, check_every):
    """Advance ``n_steps`` splitting steps of a 2-D spring rope in place; the contract of ``integrators.advance``.

    ``f`` (2, N + 1) holds the spring forces [N] (kept between calls when the last kick's forces are reused),
    ``lost`` (N,) each node's accumulated work per unit mass [J/kg], ``bulk`` and ``exception_factors`` the
    kick factors (see :class:`ChainState`), ``saved`` the exceptions' scratch and ``scratch`` the blow-up
    check's. Returns (steps done, frames written, status, node).
    """
    n = x.shape[1]
    px, py, vx, vy, fx, fy = x[0], x[1], v[0], v[1], f[0], f[1]
    held_idx, held_x0, held_v = held
    inv_mass, flags, spring, bending, gravity, thrower, guides = forces
    saved_x, saved_v, saved_lost = saved
    lengths, terms = scratch
    frames_t, frames_x, frames_v, frames_ledger = frames
    k, rest, closed = spring[0], spring[1], spring[2] != 0.0
    g = gravity[0] if flags[GRAVITY] else 0.0
    stages = kick.shape[0]
    n_held = held_idx.shape[0]
    n_exc = exceptions.shape[0]
    inv_m = bulk[0]
    if not closed:
        fx[0] = fx[n] = fy[0] = fy[n] = 0.0
    held_work = ledger[HELD]   # kept in a register, stored whenever the ledger is read
    max_stretch, of_scale, of_flows = limits[0], limits[1], limits[2]
    frame = 0
    next_check = step0 + check_every - step0 % check_every   # counted, not divided, per step
    next_save = step0 + save_every - step0 % save_every
    for s in range(n_steps):
        step = step0 + s
        t = step * h
        if drift[0] != 0.0:
            ch = drift[0] * h
            for i in range(n):
                px[i] += ch * vx[i]
                py[i] += ch * vy[i]
            t += ch
            for j in range(n_held):   # health.place_held, written out: the call cost 2.5 % at N = 21
                i = held_idx[j]
                px[i] = held_x0[0, j] + held_v[0, j] * t
                py[i] = held_x0[1, j] + held_v[1, j] * t
        for st in range(stages):
            if not (st == 0 and reuse_force and have_acc[0]):
                for i in range(n - 1):
                    d0 = px[i + 1] - px[i]
                    d1 = py[i + 1] - py[i]
                    r2 = d0 * d0 + d1 * d1
                    c = k * (1.0 - rest / np.sqrt(r2)) if r2 > 0.0 else 0.0   # no direction, no force
                    fx[i + 1] = c * d0
                    fy[i + 1] = c * d1
                if closed:   # an open line's f[:, 0] and f[:, N] stay 0
                    d0 = px[0] - px[n - 1]
                    d1 = py[0] - py[n - 1]
                    r2 = d0 * d0 + d1 * d1
                    c = k * (1.0 - rest / np.sqrt(r2)) if r2 > 0.0 else 0.0
                    fx[0] = fx[n] = c * d0
                    fy[0] = fy[n] = c * d1
            ch = drift[st + 1] * h
            b = BULK_FIXED + BULK_PER_STAGE * st
            decay, gain, reach = bulk[b], bulk[b + 1], bulk[b + 2]
            for j in range(n_exc):
                i = exceptions[j]
                saved_x[0, j] = px[i]
                saved_x[1, j] = py[i]
                saved_v[0, j] = vx[i]
                saved_v[1, j] = vy[i]
                saved_lost[j] = lost[i]
            # the kick (drag exact) and the drift after it, every node as a bulk node; the two copies differ
            # only in booking the work, since a flag tested inside the loop would stop it vectorising
            if has_drag:
                for i in range(n):
                    ax = (fx[i + 1] - fx[i]) * inv_m
                    ay = (fy[i + 1] - fy[i]) * inv_m - g
                    ux = vx[i]
                    uy = vy[i]
                    gx = gain * ax
                    gy = gain * ay
                    wx = decay * ux + gx
                    wy = decay * uy + gy
                    lost[i] += (ux + reach * ax) * gx + (uy + reach * ay) * gy
                    vx[i] = wx
                    vy[i] = wy
                    px[i] += ch * wx
                    py[i] += ch * wy
            else:
                for i in range(n):
                    ax = (fx[i + 1] - fx[i]) * inv_m
                    ay = (fy[i + 1] - fy[i]) * inv_m - g
                    wx = decay * vx[i] + gain * ax
                    wy = decay * vy[i] + gain * ay
                    vx[i] = wx
                    vy[i] = wy
                    px[i] += ch * wx
                    py[i] += ch * wy
            for j in range(n_exc):   # the exceptions, redone from their saved state with their own factors
                i = exceptions[j]
                e_decay, e_gain = exception_factors[st, 0, j], exception_factors[st, 1, j]
                e_reach = exception_factors[st, 2, j]
                ax = (fx[i + 1] - fx[i]) * inv_mass[i]
                ay = (fy[i + 1] - fy[i]) * inv_mass[i] - g
                ux = saved_v[0, j]
                uy = saved_v[1, j]
                gx = e_gain * ax
                gy = e_gain * ay
                wx = e_decay * ux + gx
                wy = e_decay * uy + gy
                vx[i] = wx
                vy[i] = wy
                px[i] = saved_x[0, j] + ch * wx
                py[i] = saved_x[1, j] + ch * wy
                lost[i] = saved_lost[j]
                if has_drag:
                    lost[i] += (ux + e_reach * ax) * gx + (uy + e_reach * ay) * gy
            if ch != 0.0:
                t += ch
            p = 0.0   # the supports' power on the rope: a held node does not accelerate, so its support pushes -m a
            for j in range(n_held):
                i = held_idx[j]
                ax = (fx[i + 1] - fx[i]) * inv_mass[i]
                ay = (fy[i + 1] - fy[i]) * inv_mass[i] - g
                p -= mass[i] * ax * held_v[0, j]
                p -= mass[i] * ay * held_v[1, j]
                vx[i] = held_v[0, j]   # undo its bulk kick and drift
                vy[i] = held_v[1, j]
                if ch != 0.0:
                    px[i] = held_x0[0, j] + held_v[0, j] * t
                    py[i] = held_x0[1, j] + held_v[1, j] * t
            held_work += kick[st] * h * p
        have_acc[0] = reuse_force
        done = step + 1
        if done < next_check and done < next_save and done != total_steps:
            continue
        saving = done == next_save or done == total_steps
        if done == next_check:
            next_check += check_every
        if done == next_save:
            next_save += save_every
        ledger[HELD] = held_work
        settle_drag(ledger, lost, v, free_mass, kinetic0, has_drag, held_idx, terms)
        energy, stretch, worst = chain_energy(x, v, mass, k, rest, closed, g, lengths, terms)
        status = balance_status(energy, stretch, held_work, ledger[BOX], ledger[DRAG], ledger[E0], ledger[SCALE],
                                max_stretch, of_scale, of_flows)
        if status != OK or not np.isfinite(energy):   # only now hand the arrays over, to name the culprit
            status, node = verdict(energy, stretch, worst, x, v, ledger, limits)
            if status != OK:
                return s + 1, frame, status, node
        if saving:
            save_frame(frame, done * h, x, v, ledger, frames_t, frames_x, frames_v, frames_ledger)
            frame += 1
    ledger[HELD] = held_work
    settle_drag(ledger, lost, v, free_mass, kinetic0, has_drag, held_idx, terms)
    return n_steps, frame, OK, -1

