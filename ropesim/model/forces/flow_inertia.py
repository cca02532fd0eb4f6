"""The force of accelerating water: Morison's inertia term for a flow that ramps in.

While a ``[flow]`` ramps in (``ramp_time`` > 0) the water at a node accelerates at a_f = r'(t) U(y), r the
ramp (see :mod:`ropesim.model.forces.fluid`) and U(y) the flow's full profile: its local acceleration dU/dt.
(The convective part U . grad U is left out, as MoorDyn does; it is zero for a horizontal flow over height.)
The water pushes node i with

    F_i = k_n a_f,n + k_t a_f,t,    k_n = rho V (b + Ca_n),  k_t = rho V (b + Ca_t),

a_f split along the node tangent q like the drag (a_f,t = (a_f . q) q, a_f,n = a_f - a_f,t), V the node's
displaced volume (the rope's share, pi d^2 / 4 times half of each adjacent unstretched segment, plus its
body's). The "1" (b = 1) is the pressure gradient that accelerates the water, rho V a_f (the Froude-Krylov
force, the dynamic side of buoyancy): it comes with ``[buoyancy]``. Ca_n and Ca_t are the added mass's
(``[added_mass]``, and a body's ``ca`` in every direction): with the added mass M_i = m + A_i already on the
node's inertia, they make the added-mass force A_i (a_f - a) that the fluid exerts on a body accelerating
relative to it. MoorDyn's Line.cpp applies the same two parts (its Ap and Aq) whenever the water accelerates.

So a rope as dense as the water, moving with the flow, keeps moving with it exactly: (m + A) a = (rho V + A)
a_f with m = rho V. The term is switched on only while it can act: a ramped flow and buoyancy or added mass.
Its work is the fluid's (the ledger's ``fluid_work``). The stiff integrator's Newton matrix leaves it out: it
depends on the positions only through the tangent and the height. Parameters: (2, N) k_n and k_t [kg] per
node, zero for held nodes.
"""

from __future__ import annotations


import numpy as np

from . import Term
from .added_mass import ADDED_MASS_TERM
from .added_mass import _params as added_mass_params
from .buoyancy import displaced_volume
from .fluid import flow_scaled, node_tangent
from .. import jit
from ..ramp import ramp_rate

WITH_FLOW_INERTIA = jit.Switch("flow_inertia", "the accelerating water's inertia force")


@jit.kernel
def add_flow_inertia(x, v, acc, inv_mass, inertia, flow, t, around):
    """Add the accelerating water's force (see the module doc) at time t [s] as accelerations [m/s^2]; returns
    its power [W] on the nodes moving at ``v``."""
    scalars, table = flow
    rate = ramp_rate(t, scalars[1])
    if rate == 0.0:
        return 0.0
    dim, n = x.shape
    power = 0.0
    for i in range(n):
        k_n, k_t = inertia[0, i], inertia[1, i]
        if k_n == 0.0 and k_t == 0.0:
            continue
        ax, ay, az = flow_scaled(x[1, i], rate, scalars, table)
        qx, qy, qz = node_tangent(x, i, around)
        along = ax * qx + ay * qy + az * qz
        fx = k_n * (ax - along * qx) + k_t * along * qx
        fy = k_n * (ay - along * qy) + k_t * along * qy
        acc[0, i] += fx * inv_mass[i]
        acc[1, i] += fy * inv_mass[i]
        power += fx * v[0, i] + fy * v[1, i]
        if dim == 3:
            fz = k_n * (az - along * qz) + k_t * along * qz
            acc[2, i] += fz * inv_mass[i]
            power += fz * v[2, i]
    return power


def _params(scene, layout) -> np.ndarray:
    k = np.zeros((2, len(layout.mass)))
    if scene.buoyancy is not None:
        k += scene.fluid.density * displaced_volume(scene, layout)
    if ADDED_MASS_TERM.declared(scene):
        k += added_mass_params(scene, layout)
    k[:, layout.held] = 0.0
    return k


def _active(scene) -> bool:
    return (scene.flow is not None and scene.flow.ramp_time > 0.0 and scene.sea is None
            and (scene.buoyancy is not None or ADDED_MASS_TERM.declared(scene)))


FLOW_INERTIA_TERM = Term("flow", WITH_FLOW_INERTIA, _params, lambda: np.zeros((2, 0)), ledger="fluid", velocity=True,
                         active=_active)
"""Morison's inertia term while the flow ramps in (time-dependent, so the splitting schemes integrate it in
their RK4 velocity kicks with the drag)."""
