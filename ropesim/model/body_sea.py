"""Free rigid bodies in a sea (``[sea]``, :mod:`ropesim.model.forces.sea`): the body's own loads under a free
surface and waves, in the place of the drag of :func:`ropesim.model.bodies.own_load`.

**Where the water is, for a body.** The surface height is level + eta, eta the waves' elevation at the
horizontal position of the body's reference point r. The body's displaced volume V is taken as a
**vertical-walled** body of ``height`` h centred on its centre of buoyancy c_B (the world's vertical, whatever
the body's tilt): its waterplane area is A_wp = V / h, and its submerged fraction

    f = clamp((level + eta - y_B) / h + 1/2, 0, 1),    y_B = (r + R c_B)_y,

is linear in the body's heave while the surface cuts its walls: a floating body has the heave stiffness
rho g A_wp = lift / h (lift = rho V g) and rests at Archimedes' draught, f = m / (rho V) for a body that carries
no lines. The buoyancy f rho V g acts upwards at c_B; a vertical force acts along its vertical line, so this is
the buoyancy of the submerged prism at its own centroid (which lies on that line below c_B) as well.

**What acts on the body** (all about the reference point, from one evaluation of the water's kinematics at r:
the waves' velocity u_w and local acceleration a_w, Wheeler-stretched (:func:`ropesim.model.waves.water_at`),
plus a ``[flow]`` current and its ramp's acceleration):

- buoyancy f rho V g at c_B: the body's full rho V g (its potential energy, :func:`~ropesim.model.bodies.
  body_energy`) less the part above the surface, -(1 - f) rho V g, whose work is booked as the fluid's (as the
  nodes' lost buoyancy is);
- drag: the water's on the velocity of the reference point relative to the water, u = U + u_w - v, times f,
  and the air's on the velocity relative to the ``wind``, times (1 - f) rho_air / rho_water, each
  1/2 rho R diag(CdA) R^T |u| u in body axes; the rotational drag times f + (1 - f) rho_air / rho_water (the
  water does not turn);
- the water's inertia force at the reference point, Froude-Krylov plus added mass: (f rho V + R diag(a) R^T)
  a_w, a the body's ``added_mass`` on its axes. The added mass and added inertia in the body's mass matrix stay
  whole: they are the user's for the body as it floats (or as it is submerged), as MoorDyn's body's are.

``[sea] fraction = "moordyn"`` gives MoorDyn's body instead, to compare on equal physics (``Body::doRHS``):
f = 1 whatever the surface (full buoyancy, water drag on the waves' velocity at the reference point) and no
force from the water's acceleration; ``height`` is then not needed.

:func:`water_at_body` is the one evaluation; :func:`sea_loads` the loads from it (explicit methods, the stiff
integrator's residual and the static solver: through :func:`~ropesim.model.bodies.own_load`);
:func:`sea_rates` what the stiff integrator's Newton matrix takes of them (the heave stiffness lift / h while
the surface cuts the walls, the drag's damping on both parts). Compiled behind :data:`WITH_BODY_SEA`: a scene
without free bodies in a sea compiles none of it.

Compiled bundle :class:`BodySea` (the ``sea`` field of :class:`~ropesim.model.bodies.Bodies`): the sea's scalars
and wave components (the same arrays as the nodes' :class:`~ropesim.model.forces.sea.Sea`, so the time factors
are shared), and per body the rows ``HEIGHT`` h [m] and ``DISPLACED`` rho V [kg].
"""

from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from . import jit
from .body_layout import ADDED, COB, DRAG, DRAG_ROT, LIFT
from .forces.fluid import WITH_FLOW, flow_at, flow_scaled
from .forces.sea import AIR_RATIO, FRACTION_RULE, MOORDYN_RULE, WIND_X, WIND_Y, WIND_Z, WITH_WAVES
from .ramp import ramp_rate
from .rotation import cross, rotate_back, rotation_matrix
from .waves import LEVEL, wave_field, water_at

WITH_BODY_SEA = jit.Switch("body_sea", "free rigid bodies under a sea's free surface")

BodySea = namedtuple("BodySea", ["scalars", "comps", "rows"])
HEIGHT, DISPLACED = range(2)   # rows of BodySea.rows (2, B)


def body_sea_bundle(scene, free, sea) -> BodySea:
    """The free bodies' :class:`BodySea` (``free`` the scene's free bodies, ``sea`` the nodes' compiled
    :class:`~ropesim.model.forces.sea.Sea`, whose scalars and components it shares)."""
    rho = scene.fluid.density
    rows = np.zeros((2, len(free)))
    for b, body in enumerate(free):
        rows[HEIGHT, b] = body.height if body.height is not None else math.inf
        rows[DISPLACED, b] = rho * body.volume
    return BodySea(sea.scalars, sea.comps, rows)


def submerged_fraction(y_cob, surface, height):
    """The submerged fraction f of a vertical-walled body of ``height`` [m] centred at height ``y_cob`` [m] under
    a surface at ``surface`` [m] (module doc), as :func:`water_at_body` computes it; NumPy, for tests and
    outputs."""
    return np.clip((np.asarray(surface) - np.asarray(y_cob)) / height + 0.5, 0.0, 1.0)


def _fraction(scene, t, x, quaternion, cob, height) -> np.ndarray:
    """(K,) f of bodies with reference points ``x`` (K, 3) [m], orientations ``quaternion`` (K, 4), centres of
    buoyancy ``cob`` (K, 3) [m] in their frames and ``height`` [m] (K,), at times ``t`` [s] (K,) or one (y-up):
    the surface's height, waves and ramp included, over each reference point against its centre of buoyancy."""
    field = wave_field(scene)
    eta = field.elevation(x[:, 0], t, x[:, 2]) if field is not None else 0.0
    y_cob = x[:, 1] + np.einsum("kj,kj->k", rotation_matrix(quaternion)[:, 1, :], cob)
    return submerged_fraction(y_cob, scene.sea.level + eta, height)


def body_fraction(scene, body, t, position, quaternion) -> np.ndarray:
    """(F,) the submerged fraction of the free rigid ``body`` (one of ``scene.rigid_bodies``) at the saved frames:
    times ``t`` (F,) [s], its reference point ``position`` (F, D) [m] and orientation ``quaternion`` (F, 4), all in
    the y-up frame the model computes in. The f its loads take (module doc); 1 under MoorDyn's rule. NumPy, for
    outputs (:class:`ropesim.analysis.objects.BodyResults`)."""
    t = np.asarray(t, dtype=float)
    if scene.sea.fraction == "moordyn":
        return np.ones(len(t))
    dim = scene.dimension
    x, cob = np.zeros((len(t), 3)), np.zeros((len(t), 3))
    x[:, :dim] = np.asarray(position, dtype=float)[:, :dim]
    cob[:, :dim] = np.asarray(body.center_of_buoyancy, dtype=float)[:dim]
    return _fraction(scene, t, x, np.asarray(quaternion, dtype=float), cob, body.height)


def heave_stiffness(model, pose: np.ndarray, t: float) -> np.ndarray:
    """Each free body's heave stiffness [N/m] at ``pose`` (7, B) and time t [s]: rho g A_wp = lift / h while the
    surface cuts its walls, else 0 (and 0 everywhere without a sea or under MoorDyn's rule), as
    :func:`water_at_body` has it; NumPy, for the static solver's step matrix."""
    bundle, scene = model.params.bodies, model.scene
    if bundle is None or bundle.sea is None or scene.sea.fraction == "moordyn":
        return np.zeros(pose.shape[1])
    height = bundle.sea.rows[HEIGHT]
    f = _fraction(scene, t, pose[:3].T, pose[3:7].T, bundle.cob.T, height)
    return np.where((f > 0.0) & (f < 1.0), bundle.lift / height, 0.0)


# ------------------------------------------------------------------------------------------ compiled


@jit.kernel(inline="always")
def water_at_body(flow, bodies, pose, b, t, r):
    """Body b's water at time t [s], ``r`` R's nine entries: (f, heave stiffness [N/m], the water's velocity
    (3) [m/s] and local acceleration (3) [m/s^2] at the reference point, world axes). f and the stiffness
    lift / h (0 where the surface misses the walls) as the module doc says; f = 1 and no acceleration under
    MoorDyn's rule."""
    sea = bodies.sea
    scalars = sea.scalars
    px, py, pz = pose[0, b], pose[1, b], pose[2, b]
    eta = u0 = u1 = u2 = a0 = a1 = a2 = 0.0
    if WITH_WAVES:
        eta, u0, u1, u2, a0, a1, a2 = water_at(px, py, pz, t, scalars, sea.comps)
    if WITH_FLOW:
        U0, U1, U2 = flow_at(py, t, flow[0], flow[1])
        u0, u1, u2 = u0 + U0, u1 + U1, u2 + U2
        rate = ramp_rate(t, flow[0][1])
        if rate != 0.0:
            A0, A1, A2 = flow_scaled(py, rate, flow[0], flow[1])
            a0, a1, a2 = a0 + A0, a1 + A1, a2 + A2
    if scalars[FRACTION_RULE] == MOORDYN_RULE:
        return 1.0, 0.0, u0, u1, u2, 0.0, 0.0, 0.0
    height = sea.rows[HEIGHT, b]
    body = bodies.table[b]
    y_cob = py + r[3] * body[COB] + r[4] * body[COB + 1] + r[5] * body[COB + 2]
    f = (scalars[LEVEL] + eta - y_cob) / height + 0.5
    stiffness = body[LIFT] / height
    if f <= 0.0:
        f, stiffness = 0.0, 0.0
    elif f >= 1.0:
        f, stiffness = 1.0, 0.0
    return f, stiffness, u0, u1, u2, a0, a1, a2


@jit.kernel(inline="always")
def sea_loads(flow, bodies, pose, twist, b, t, r):
    """Body b's loads from the sea (module doc), in its axes about its reference point: the buoyancy lost above
    the surface, the drag of water and air, the rotational drag and the water's inertia force, as
    (f0, f1, f2, m0, m1, m2, power), ``power`` [W] theirs (the fluid's work)."""
    scalars = bodies.sea.scalars
    f, _, u0, u1, u2, a0, a1, a2 = water_at_body(flow, bodies, pose, b, t, r)
    vb0, vb1, vb2 = rotate_back(r, twist[0, b], twist[1, b], twist[2, b])
    wb0, wb1, wb2 = rotate_back(r, twist[3, b], twist[4, b], twist[5, b])
    body = bodies.table[b]
    c0, c1, c2 = body[COB], body[COB + 1], body[COB + 2]
    lost = (1.0 - f) * body[LIFT]   # the buoyancy above the surface, taken away at the centre of buoyancy
    f0, f1, f2 = -lost * r[3], -lost * r[4], -lost * r[5]
    m0, m1, m2 = cross(c0, c1, c2, f0, f1, f2)
    e0, e1, e2 = cross(wb0, wb1, wb2, c0, c1, c2)
    power = f0 * (vb0 + e0) + f1 * (vb1 + e1) + f2 * (vb2 + e2)
    ratio = scalars[AIR_RATIO]
    for part in range(2):   # the water's drag on the wet part, the air's on the dry part
        if part == 0:
            share, w0, w1, w2 = f, u0, u1, u2
        else:
            share, w0, w1, w2 = ratio * (1.0 - f), scalars[WIND_X], scalars[WIND_Y], scalars[WIND_Z]
        if share > 0.0:
            ub0, ub1, ub2 = rotate_back(r, w0 - twist[0, b], w1 - twist[1, b], w2 - twist[2, b])
            speed = share * math.sqrt(ub0 * ub0 + ub1 * ub1 + ub2 * ub2)
            d0, d1, d2 = body[DRAG] * speed * ub0, body[DRAG + 1] * speed * ub1, body[DRAG + 2] * speed * ub2
            power += d0 * vb0 + d1 * vb1 + d2 * vb2
            f0, f1, f2 = f0 + d0, f1 + d1, f2 + d2
    spin = (f + ratio * (1.0 - f)) * math.sqrt(wb0 * wb0 + wb1 * wb1 + wb2 * wb2)
    s0 = -body[DRAG_ROT] * spin * wb0
    s1 = -body[DRAG_ROT + 1] * spin * wb1
    s2 = -body[DRAG_ROT + 2] * spin * wb2
    power += s0 * wb0 + s1 * wb1 + s2 * wb2
    m0, m1, m2 = m0 + s0, m1 + s1, m2 + s2
    if a0 != 0.0 or a1 != 0.0 or a2 != 0.0:   # Froude-Krylov and added mass: (f rho V + A) a_w
        ab0, ab1, ab2 = rotate_back(r, a0, a1, a2)
        fk = f * bodies.sea.rows[DISPLACED, b]
        h0 = (fk + body[ADDED]) * ab0
        h1 = (fk + body[ADDED + 1]) * ab1
        h2 = (fk + body[ADDED + 2]) * ab2
        power += h0 * vb0 + h1 * vb1 + h2 * vb2
        f0, f1, f2 = f0 + h0, f1 + h1, f2 + h2
    return f0, f1, f2, m0, m1, m2, power


@jit.kernel(inline="always")
def sea_rates(flow, bodies, pose, twist, b, t, r):
    """What the stiff integrator's Newton matrix takes of body b's sea loads: (heave stiffness [N/m], the
    water's share f and the air's (1 - f) rho_air / rho_water of the drag, the water's velocity (3) [m/s]
    relative to the reference point and the wind's, world axes)."""
    scalars = bodies.sea.scalars
    f, stiffness, u0, u1, u2, _, _, _ = water_at_body(flow, bodies, pose, b, t, r)
    air = scalars[AIR_RATIO] * (1.0 - f)
    return (stiffness, f, air, u0 - twist[0, b], u1 - twist[1, b], u2 - twist[2, b],
            scalars[WIND_X] - twist[0, b], scalars[WIND_Y] - twist[1, b], scalars[WIND_Z] - twist[2, b])
