"""Buoyancy: the fluid's upward push rho V g on each node, V its displaced volume.

V is the node's share of the rope's unstretched volume, pi d^2 / 4 times half of each adjacent segment
(MoorDyn's lumping), plus the volume of a body it carries. The force is constant, so it is conservative: its
potential energy is -rho V g y. Parameters: (N,) the upward acceleration rho V g / m of each node [m/s^2].
"""

from __future__ import annotations

import math

import numpy as np

from . import Term
from ..layout import line_volumes, lumped_bodies
from .. import jit

WITH_BUOYANCY = jit.Switch("buoyancy", "buoyancy")


@jit.kernel
def add_buoyancy(acc, up):
    """Add each node's upward acceleration ``up`` [m/s^2] (along +y)."""
    for i in range(up.shape[0]):
        acc[1, i] += up[i]


def displaced_volume(scene, layout) -> np.ndarray:
    """Each node's displaced volume [m^3]: its share of its line's and its body's."""
    volume = line_volumes(layout.lines, layout.node_length)
    for body in lumped_bodies(scene, layout.lines):
        volume[body.node] += body.volume
    return volume


def _params(scene, layout) -> np.ndarray:
    return scene.fluid.density * displaced_volume(scene, layout) * scene.gravity.g / layout.mass


def buoyancy_energy(model, x: np.ndarray) -> np.ndarray:
    """-rho V g y summed over the nodes [J], for frames x (..., N, D)."""
    return -np.einsum("...n,n->...", np.asarray(x)[..., 1], model.mass * model.params.buoyancy)


BUOYANCY_TERM = Term("buoyancy", WITH_BUOYANCY, _params, lambda: np.zeros(0), energy=buoyancy_energy)
