"""Uniform gravity, acceleration g along -y.

It has no kernel of its own: the rope's spring pass subtracts g as it writes each node's acceleration
(:func:`ropesim.model.forces.springs.set_chain_springs`), which saves a pass over the nodes. Its potential
energy is m g y, zero at y = 0. Parameters: [g] [m/s^2].
"""

from __future__ import annotations

import numpy as np

from . import Term
from ..jit import Switch

WITH_GRAVITY = Switch("gravity", "uniform gravity along -y")


def gravitational_energy(model, x: np.ndarray) -> np.ndarray:
    """m g y summed over the nodes [J], for frames x (..., N, D)."""
    return model.scene.gravity.g * np.einsum("...n,n->...", np.asarray(x)[..., 1], model.mass)


GRAVITY = Term("gravity", WITH_GRAVITY, lambda scene, mass: np.array([scene.gravity.g]), lambda: np.zeros(1),
               energy=gravitational_energy)
