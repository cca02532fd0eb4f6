"""Mechanical energy of the rope, term by term [J], for one frame (N, D) or many (F, N, D)."""

from __future__ import annotations

import numpy as np

from .bodies import body_energy_numpy
from .build import Model
from .terms import declared_terms


def energy_terms(model: Model, x: np.ndarray, v: np.ndarray, pose: np.ndarray | None = None,
                 twist: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Kinetic energy, each conservative term's energy (only the scene's own terms), with free rigid bodies their
    kinetic, gravitational and buoyancy energy, and the total; for frames x, v (..., N, D) and the bodies' poses
    (..., 7, B) and twists (..., 6, B) (the model's initial ones when not given).

    Gravitational energy is m g y, zero at y = 0.
    """
    x, v = np.asarray(x), np.asarray(v)
    terms = {"kinetic": 0.5 * np.einsum("...nd,...nd,n->...", v, v, model.mass)}
    for term in declared_terms(model.scene):
        if term.energy is not None:
            terms[term.label or term.name] = term.energy(model, x)
    if model.body_pose0.shape[1]:
        g = model.scene.gravity.g if model.scene.gravity is not None else 0.0
        terms.update(body_energy_numpy(model.params.bodies, model.body_pose0 if pose is None else pose,
                                       model.body_twist0 if twist is None else twist, g))
    terms["total"] = sum(terms.values())
    return terms
