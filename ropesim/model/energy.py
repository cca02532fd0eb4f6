"""Mechanical energy of the rope, term by term [J], for one frame (N, D) or many (F, N, D)."""

from __future__ import annotations

import numpy as np

from .build import Model
from .terms import declared_terms


def energy_terms(model: Model, x: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
    """Kinetic energy, each conservative term's energy (only the scene's own terms) and their total.

    Gravitational energy is m g y, zero at y = 0.
    """
    x, v = np.asarray(x), np.asarray(v)
    terms = {"kinetic": 0.5 * np.einsum("...nd,...nd,n->...", v, v, model.mass)}
    for term in declared_terms(model.scene):
        if term.energy is not None:
            terms[term.label or term.name] = term.energy(model, x)
    terms["total"] = sum(terms.values())
    return terms
