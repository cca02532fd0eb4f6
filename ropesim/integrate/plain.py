"""The splitting loop's specialisation for the plainest scene: a 2-D rope of springs under gravity and linear drag.

A scene with no term but the rope's springs and gravity (the towed ropes) takes, inside the one splitting
loop (:func:`ropesim.integrate.splitting.advance_splitting`), a stage written for that physics alone, as
plain as a hand-written loop for it, while keeping every feature of the general stage: any splitting scheme,
held nodes on x0 + V t, per-node masses and drag, the energy ledger, the blow-up check and saved frames. Its
trajectories are bit-identical to the general stage's. This module holds its data (:class:`Plain`, built by
:func:`plain_bundle`) and its helpers.

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
  :mod:`ropesim.integrate.kick`). Between kicks only kicks change a velocity, so the dK terms of successive
  kicks telescope: each node accumulates only its work per unit mass, (u + reach a) . (gain a) with
  reach = travel / gain, in ``lost`` (an element-wise update that vectorises, reusing the gain a of the
  kick), and D = sum_i m_i lost_i - (K - K_0) is formed by :func:`settle_drag` whenever the ledger is read (a
  blow-up check, a saved frame, the end of a call). It is a function of the state alone, so chunking never
  changes it; a scene without drag skips the term altogether.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from ..model.banded import WITH_WRAP_AROUND
from ..model.terms import WITH_GRAVITY
from .health import DRAG
from .kick import LANES, _lanes
from ..model import jit

WITH_PLAIN_STAGE = jit.Switch("plain_stage", "the splitting loop's stage for a 2-D rope of springs and gravity")
BULK_FIXED = 1        # bulk = [1 / m, then per kick stage: decay, gain, reach]
BULK_PER_STAGE = 3

Plain = namedtuple("Plain", ["bulk", "exceptions", "exception_factors", "saved_x", "saved_v", "saved_lost",
                             "free_mass", "kinetic0", "has_drag", "lengths", "terms"])
"""The plain stage's data: the bulk factors, the exceptions' indices (E,), factors
(stages, 3, E) and saved pre-kick x, v (2, E) and work (E,), the free nodes' masses (N,) (0 at held ones),
their kinetic energy at t = 0 [J], whether any free node has drag, and the check's scratch rows (N,)."""


def applies(model, scheme) -> bool:
    """True when ``model`` stepped by the splitting ``scheme`` can take the plain stage: a 2-D rope whose only
    force terms are its springs (that push as well as pull) and gravity."""
    return (model.dim == 2 and model.nodes >= 2 and model.switches <= {WITH_GRAVITY.name, WITH_WRAP_AROUND.name}
            and model.scene.rope.compression)


def plain_bundle(model, decay: np.ndarray, gain: np.ndarray, travel: np.ndarray) -> Plain:
    """The plain stage's data for ``model`` with the kick factors of :func:`ropesim.integrate.splitting.kick_factors`.

    ``reach`` = travel / gain turns the work of a kick into (u + reach a) . (gain a) per unit mass.
    """
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
    bulk = np.empty(BULK_FIXED + BULK_PER_STAGE * stages)
    bulk[0] = model.params.inv_mass[like]
    for k in range(stages):
        bulk[BULK_FIXED + BULK_PER_STAGE * k:BULK_FIXED + BULK_PER_STAGE * (k + 1)] = (
            decay[k, like], gain[k, like], reach[k, like])
    e = np.flatnonzero(free & ~bulk_node).astype(np.int64)
    factors = np.ascontiguousarray(np.stack([decay[:, e], gain[:, e], reach[:, e]], axis=1))
    free_mass = np.where(free, mass, 0.0)
    terms = np.zeros(model.nodes)
    kinetic0 = -settle(np.zeros(model.nodes), model.v0, free_mass, 0.0, terms)   # K(0) [J]
    return Plain(bulk, e, factors, np.zeros((2, e.size)), np.zeros((2, e.size)), np.zeros(e.size), free_mass,
                 kinetic0, bool(np.any(drag[free] > 0.0)), np.zeros(model.nodes), terms)


def inactive_bundle(stages: int) -> Plain:
    """A Plain of the same types that the general stage carries unused (one argument layout for both)."""
    return Plain(np.zeros(BULK_FIXED + BULK_PER_STAGE * stages), np.zeros(0, dtype=np.int64),
                 np.zeros((stages, 3, 0)), np.zeros((2, 0)), np.zeros((2, 0)), np.zeros(0), np.zeros(0), 0.0, False,
                 np.zeros(0), np.zeros(0))


@jit.kernel(inline="always")
def settle(lost, v, free_mass, kinetic0, terms):
    """sum_i m_i (lost_i - |v_i|^2 / 2) + kinetic0 over the free nodes (m_i = 0 at held ones), in a fixed order.

    With ``lost`` the work per unit mass booked since the start and ``kinetic0`` the free nodes' kinetic energy
    then, this is the energy drag has taken out [J]. ``terms`` (N,) is scratch.
    """
    for i in range(v.shape[1]):
        terms[i] = free_mass[i] * (lost[i] - 0.5 * (v[0, i] * v[0, i] + v[1, i] * v[1, i]))
    return _lanes(terms) + kinetic0


@jit.kernel(inline="always")
def chain_energy(x, v, mass, k, rest, closed, g, lengths, terms):
    """(mechanical energy [J], largest spring length / rest length, that spring's first node) of the rope.

    The quantities of :func:`ropesim.model.terms.mechanical_energy` for a 2-D rope with only its springs and
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


@jit.kernel(inline="always")
def settle_drag(ledger, lost, v, free_mass, kinetic0, has_drag, held_idx, terms):
    """Set ``ledger[DRAG]`` from the work booked in ``lost`` and the kinetic energy the free nodes gained [J].

    The held nodes' entries of ``lost`` hold whatever their bulk kick booked, and are cleared first.
    """
    if has_drag:
        for j in range(held_idx.shape[0]):
            lost[held_idx[j]] = 0.0
        ledger[DRAG] = settle(lost, v, free_mass, kinetic0, terms)
