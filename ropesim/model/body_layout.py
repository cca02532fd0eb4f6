"""The free rigid bodies' compiled parameters packed into a few arrays (:class:`Bodies`), and the named columns of
their records: what every body kernel reads (:mod:`ropesim.model.bodies`, :mod:`ropesim.model.body_sea`, the
implicit integrators' body rows).

A compiled call passes a namedtuple of arrays by value, every array a struct of pointers, shape and strides, each
typed and reference-counted at the call: a body described by some thirty arrays made every call that carries it
cost more than its arithmetic. Packed, a call carries four arrays whatever the number of parameters.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

# A free body's record, a row of Bodies.table (B, BODY_COLUMNS): its mass [kg], rho V g [N], whether its mass
# matrix varies (1.0 when its attachments have a_t != a_n), then 3 columns each in body axes for the centre of
# gravity and of buoyancy [m], 1/2 rho CdA [kg/m], 1/2 rho Cd_r [kg m^2], added mass [kg] and inertia [kg m^2],
# the linear spring [N/m] and damper [N s/m] (world axes) and their rest point [m], and 9 for the inertia about the
# centre of gravity [kg m^2] row by row.
MASS, LIFT, VARIES, COG, COB, DRAG, DRAG_ROT, ADDED, ADDED_ROT, SPRING, DAMPER, REST, INERTIA = (
    0, 1, 2, 3, 6, 9, 12, 15, 18, 21, 24, 27, 30)
BODY_COLUMNS = 39
# An attachment's record, a row of Bodies.links (K, LINK_COLUMNS): its arm in the body frame [m], its line's
# added-mass coefficients a_n and a_t [kg], its node's mass [kg]; scratch: the chord d along its line in body axes
# [m] and (a_t - a_n) / |d|^2.
ARM, ADDED_N, ADDED_T, NODE_MASS, CHORD, CHORD_SCALE = 0, 3, 4, 5, 6, 9
LINK_COLUMNS = 10
# Each body's matrices, Bodies.matrices (B, 3, 6, 7): the constant part of its mass matrix in body axes, its
# inverse, and the solve's scratch (a varying body's L D L^T kept there between calls); each on the kept rows
# (the leading n x n: 6 in 3-D, x, y and the turn about z in 2-D), the scratch's last column the right-hand side.
CONSTANT, INVERSE, SCRATCH = range(3)

_VIEWS = {   # the former one-array-per-parameter names, as views of the packed arrays (NumPy code and tests)
    "mass": ("table", MASS, 0), "lift": ("table", LIFT, 0), "varies": ("table", VARIES, 0),
    "cog": ("table", COG, 3), "cob": ("table", COB, 3), "drag": ("table", DRAG, 3),
    "drag_rot": ("table", DRAG_ROT, 3), "added": ("table", ADDED, 3), "added_rot": ("table", ADDED_ROT, 3),
    "spring": ("table", SPRING, 3), "damper": ("table", DAMPER, 3), "rest": ("table", REST, 3),
    "arm": ("links", ARM, 3), "node_added": ("links", ADDED_N, 2), "attached_mass": ("links", NODE_MASS, 0)}


class Bodies(namedtuple("Bodies", ["table", "links", "matrices", "index", "sea"], defaults=(None,))):
    """The free bodies' compiled parameters, packed so that a kernel call passes four arrays (see the module doc):
    ``table`` (B, BODY_COLUMNS) one record per body, ``links`` (K, LINK_COLUMNS) one per attachment,
    ``matrices`` (B, 3, 6, 7), ``index`` (K + B + 1,) int64 the attachments' nodes, then each body's first
    attachment (body b's are k = index[K + b] to index[K + b + 1]); ``sea`` the :class:`~ropesim.model.body_sea.
    BodySea` or None. In NumPy, each parameter by its name: ``mass`` (B,), ``cog`` (3, B), ``arm`` (3, K), ...,
    ``inertia`` (3, 3, B), ``start`` (B + 1,), ``nodes`` (K,)."""

    __slots__ = ()

    def __getattr__(self, name):
        view = _VIEWS.get(name)
        if view is None:
            raise AttributeError(name)
        packed, column, width = view
        array = getattr(self, packed)
        return array[:, column] if width == 0 else array[:, column:column + width].T

    @property
    def inertia(self) -> np.ndarray:
        return self.table[:, INERTIA:INERTIA + 9].reshape(-1, 3, 3).transpose(1, 2, 0)

    @property
    def nodes(self) -> np.ndarray:
        return self.index[:self.links.shape[0]]

    @property
    def start(self) -> np.ndarray:
        return self.index[self.links.shape[0]:]
