"""Mechanical energy of the rope, term by term [J], for one frame (N, D) or many (F, N, D)."""

from __future__ import annotations

import numpy as np

from ..model.build import Model
from ..model.forces.springs import pair_spring_energy


def energy_terms(model: Model, x: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
    """Kinetic, spring, bending and gravitational energy and their total; only the scene's own terms.

    Gravitational energy is m g y, zero at y = 0.
    """
    scene = model.scene
    x, v = np.asarray(x), np.asarray(v)
    terms = {"kinetic": 0.5 * np.einsum("...nd,...nd,n->...", v, v, model.mass)}
    rope = scene.rope
    terms["spring"] = pair_spring_energy(x, rope.stiffness, rope.segment_length, 1, rope.closed)
    if scene.bending is not None:
        terms["bending"] = pair_spring_energy(x, scene.bending.stiffness, 2 * rope.segment_length, 2, rope.closed)
    if scene.gravity is not None:
        terms["gravity"] = scene.gravity.g * np.einsum("...n,n->...", x[..., 1], model.mass)
    terms["total"] = sum(terms.values())
    return terms
