"""Couple ropesim to another program: it moves the coupled points and bodies, ropesim returns their lines' forces.

A scene's points and bodies of kind ``coupled`` are moved by the caller (a hydrodynamics code, a controller, a
wave-energy model), as MoorDyn's coupled points and bodies are. At every coupling step the caller gives each
coupled object's position and velocity at the step's start, time t; ropesim moves it on the straight line
x(t + tau) = x + V tau for the whole step (MoorDyn's rule, ``Body::updateFairlead``), takes its own internal
steps of the scene's integrator inside the step, and returns the forces and moments on the coupled objects at
the step's end: from the integrator's last force evaluation when it is at the step's end time (rk4's last stage,
as MoorDyn reports its last evaluation's), from an evaluation at the end state otherwise. A coupled body moves its points rigidly, as a driven body does (:mod:`ropesim.model.motion`):
its pose is its reference point and its angles about x, then y, then z (R = Rz Ry Rx), and the caller gives the
angles' rates with its velocity.

Degrees of freedom, in the scene's own frame (y up, or z up for a scene with ``up = "z"``, as MoorDyn's) and in
the scene's order of ``[[bodies]]`` then ``[[points]]`` (MoorDyn too lists coupled bodies before coupled points):
a coupled body has 6 in 3-D (x, y, z [m], then the angles about x, y, z [rad], R = Rz Ry Rx in the scene's axes)
and 3 in 2-D (x, y, the angle about z); a coupled point has one per axis. The forces come in the same layout: a
body's force [N] on its reference point and the moment [N m] about it (world axes), a point's force [N]. A z-up
scene computes in its y-up twin (:mod:`ropesim.scene.frame`): each call turns the positions and velocities into
the twin, (x, y, z) -> (x, z, -y), a body's angles through its rotation, P R P^T, and their rates through the
angular velocity they give (w = c' e_z + b' u2 + a' u3, turned by P, then the twin's rates), and the forces and
moments back; every turn is exact up to round-off, so a z-up scene and its y-up twin coupled with the same motion
give the same forces up to the axis permutation.

The force on a coupled point is the net force on its line ends' nodes without their inertia, what MoorDyn
reports for a coupled point (``Point::getFnet``): the lines' pull and the weight, buoyancy, drag and seabed push
on the half segments the point carries. A body's is the sum of its points', and their moments. The caller's
model adds its own mass, buoyancy and drag (a coupled body has none in ropesim).

The internal step is the scene's ``integrator.dt``; the first coupling step shrinks it, as MoorDyn shrinks dtM,
to dt / ceil(dt / integrator.dt) when dt is not a whole number of it, and every later coupling step must be a
whole number of internal steps. Time starts at 0 at :meth:`Coupling.init`.

**Water kinematics from outside** (MoorDyn's external wave kinematics, ``WaveKin = 1``): a scene with a ``[sea]``
may take the waves from the coupled program. It asks where they are wanted, :meth:`Coupling.wave_points` (every
node, now), and gives the water's velocity and acceleration there (and, if it has one, the surface's elevation),
:meth:`Coupling.set_waves`; every force evaluation uses them, held, until it gives them again (MoorDyn's rule too).
They replace the scene's own ``[waves]`` from then on; a ``[flow]`` current is added on top. Held over a coupling
step, they lag the waves they sample by up to a step: the run differs from one with the same waves inside ropesim
at first order in the coupling step.

With a ``folder`` the run is recorded as an ordinary run folder (frames every ``output.interval``, checkpoints
by :meth:`Coupling.checkpoint`, finished by :meth:`Coupling.close`), which every command reads; a coupling
stopped after a checkpoint continues bit for bit with :meth:`Coupling.resume`. Without one,
:meth:`Coupling.state` and :meth:`Coupling.restore` hand its complete state over in memory.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .integrate.grid import TimeGrid
from .integrate.base import SCHEDULE_AT, Schedule
from .integrate.health import E0, OK
from .model.build import Model, build
from .model.jit import Direct
from .scene.frame import P, frame_of

BODY_ROWS = {3: (0, 1, 2, 3, 4, 5), 2: (0, 1, 5)}   # a body's degrees of freedom among a driven body's six rows
STEP_TOLERANCE = 1e-9                              # relative: a coupling step is a whole number of internal steps
UNBOUNDED_STEPS = 2 ** 62                          # a coupling has no t_end: its grid never reaches its last step


class CouplingError(ValueError):
    """A coupling call that cannot be honoured; ``str()`` is one line for the user."""


@dataclass(frozen=True)
class CoupledObject:
    """One coupled point or body: its id, ``kind`` ("point" or "body"), its degrees of freedom and where they
    sit in the coupling's arrays (``first``), its held rows (a point's line-end nodes) or its index among the
    bodies that move their points rigidly (a body)."""

    id: str
    kind: str
    dofs: int
    first: int
    rows: tuple = ()
    body: int = -1

    @property
    def part(self) -> slice:
        return slice(self.first, self.first + self.dofs)


def coupled_objects(model: Model) -> tuple[CoupledObject, ...]:
    """The scene's coupled bodies then coupled points, each with its degrees of freedom and held rows."""
    from .model.build import RIGID_MOTION_KINDS
    from .model.layout import point_ends

    scene, dim = model.scene, model.dim
    row = {int(node): j for j, node in enumerate(model.held_idx)}
    out, first = [], 0
    rigid = [b for b in scene.rigid_bodies if b.kind in RIGID_MOTION_KINDS]
    for body in scene.rigid_bodies:
        if body.kind == "coupled":
            b = rigid.index(body)
            rows = tuple(int(j) for j in np.flatnonzero(np.asarray(model.motion.rigid) == b))
            out.append(CoupledObject(body.id, "body", len(BODY_ROWS[dim]), first, rows, b))
            first += len(BODY_ROWS[dim])
    ends = point_ends(scene, model.lines)
    for point in scene.points:
        if point.kind == "coupled":
            out.append(CoupledObject(point.id, "point", dim, first, tuple(row[i] for i in ends[point.id])))
            first += dim
    return tuple(out)


def objects_bundle(objects: tuple[CoupledObject, ...], dim: int):
    """The coupled objects as the compiled ends of a step take them (:class:`ropesim.model.coupled.Objects`)."""
    from .model.coupled import BODY, POINT, Objects

    starts = np.cumsum([0] + [len(o.rows) for o in objects])
    return Objects(np.array([POINT if o.kind == "point" else BODY for o in objects], dtype=np.int64),
                   np.array([o.first for o in objects], dtype=np.int64),
                   np.array([o.body for o in objects], dtype=np.int64), starts.astype(np.int64),
                   np.array([j for o in objects for j in o.rows], dtype=np.int64),
                   np.array(BODY_ROWS[dim], dtype=np.int64))


def rotation_of(angles) -> np.ndarray:
    """The rotation R = Rz(c) Ry(b) Rx(a) of angles (a, b, c) [rad] about x, then y, then z."""
    a, b, c = (float(q) for q in angles)
    ca, sa, cb, sb, cc, sc = math.cos(a), math.sin(a), math.cos(b), math.sin(b), math.cos(c), math.sin(c)
    return np.array([[cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa],
                     [sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa],
                     [-sb, cb * sa, cb * ca]])


def angles_of(R: np.ndarray) -> np.ndarray:
    """The angles (a, b, c) [rad] of rotation matrix R = Rz(c) Ry(b) Rx(a), b in [-pi/2, pi/2]."""
    b = -math.asin(max(-1.0, min(1.0, R[2, 0])))
    return np.array([math.atan2(R[2, 1], R[2, 2]), b, math.atan2(R[1, 0], R[0, 0])])


def _rate_axes(angles) -> np.ndarray:
    """The columns u3 = Rz(c) Ry(b) e_x, u2 = Rz(c) e_y, e_z: w = (u3 u2 e_z) (a', b', c')."""
    _, b, c = angles
    return np.array([[math.cos(c) * math.cos(b), -math.sin(c), 0.0],
                     [math.sin(c) * math.cos(b), math.cos(c), 0.0],
                     [-math.sin(b), 0.0, 1.0]])


def angular_velocity(angles, rates) -> np.ndarray:
    """The angular velocity (world axes) [rad/s] of a body whose angles (a, b, c) change at ``rates``
    (:func:`ropesim.model.motion.rigid_state`)."""
    return _rate_axes(angles) @ np.asarray(rates, dtype=float)


def angle_rates(angles, w) -> np.ndarray:
    """The rates of the angles (a, b, c) that turn a body at angular velocity w (world axes); the inverse of
    :func:`angular_velocity` (singular at b = +-pi/2)."""
    return np.linalg.solve(_rate_axes(angles), np.asarray(w, dtype=float))


class Coupling:
    """A system advanced one coupling step at a time by another program (see the module doc).

        coupling = ropesim.Coupling("spar.toml")
        # the static solve with the coupled objects held; their forces at t = 0:
        f = coupling.init()
        for k in range(steps):
            # x, v: the coupled objects' positions and velocities at t = k dt
            f = coupling.step(k * dt, dt, x, v)
        coupling.close()

    ``scene``: a :class:`~ropesim.Scene` or a scene file with at least one point or body of kind ``coupled``;
    ``folder``: where to record the run as a run folder (None: nothing is written).
    """

    def __init__(self, scene, folder: str | Path | None = None):
        from .scene.loader import load_scene

        if isinstance(scene, (str, Path)):
            scene = load_scene(scene)
        if not scene.is_system:
            raise CouplingError(f"{scene.name}: a coupling moves a system's coupled points and bodies; this scene "
                                f"is one rope ([rope]): give it [[lines]] between [[points]]")
        self.scene = scene
        self.model = build(scene, solve=False)
        self.objects = coupled_objects(self.model)
        if not self.objects:
            raise CouplingError(f"{scene.name}: no point or body has kind = 'coupled', so there is nothing for the "
                                f"coupled program to move; give the points or bodies it moves kind = 'coupled'")
        self.dofs = sum(o.dofs for o in self.objects)
        self.frame = frame_of(scene)     # the caller's frame; the model computes in the y-up twin
        self.folder = None if folder is None else Path(folder)
        self.integrator = None
        self.writer = None
        self._rows = None
        self._begin_step = self._end = self._held = self._quiet = None
        self._objects = objects_bundle(self.objects, self.model.dim)
        self._acc = np.zeros((self.model.dim, self.model.nodes))
        self._last_acc = self._acc       # the accelerations the last forces came from
        self._loop_acc = None            # the loop's last evaluation, when it is at the step's end time
        self._step_dt = self._step_n = None
        self.wall_time = 0.0

    # -- what the caller asks ------------------------------------------------------------------------------

    @property
    def t(self) -> float:
        """The coupling's time [s]: 0 at :meth:`init`, the end of the last coupling step since."""
        return 0.0 if self.integrator is None else self.integrator.t

    @property
    def dt(self) -> float:
        """The internal step [s]."""
        return self.scene.integrator.dt if self.integrator is None else self.integrator.grid.dt

    def positions(self) -> np.ndarray:
        """The coupled objects' positions as the scene places them (the layout of :meth:`step`'s arrays, the
        scene's own frame)."""
        out = np.zeros(self.dofs)
        points = {p.id: p for p in self.scene.points}
        bodies = {b.id: b for b in self.scene.rigid_bodies}
        given = dict(zip((b.id for b in self.scene.rigid_bodies), self.scene.given_orientations))
        dim, frame = self.model.dim, self.frame
        for o in self.objects:
            if o.kind == "point":
                out[o.part] = frame.out(np.array(points[o.id].position))
            else:
                body = bodies[o.id]
                out[o.first:o.first + dim] = frame.out(np.array(body.position))
                angles = given.get(o.id) if frame.turned else None
                if angles is None and frame.turned:
                    angles = np.degrees(angles_of(P.T @ rotation_of(np.radians(body.orientation)) @ P))
                out[o.first + dim:o.first + o.dofs] = np.radians(body.orientation if angles is None else angles)
        return out

    def init(self, positions=None, velocities=None, *, statics: bool = True) -> np.ndarray:
        """Start at t = 0 with the coupled objects at ``positions`` moving at ``velocities`` (default: where the
        scene puts them, at rest), after the static solve with them held there (``statics``; the scene's own
        start shape otherwise). Returns the forces on the coupled objects at t = 0."""
        if self.integrator is not None:
            raise CouplingError(f"{self.scene.name}: init() was called already; make a new Coupling to start again")
        x = self._checked(self.positions() if positions is None else positions, "positions")
        v = self._checked(np.zeros(self.dofs) if velocities is None else velocities, "velocities")
        x, v = self._into(x, v)
        from .model.motion import Held

        model = self.model
        motion = model.motion._replace(accel=model.motion.accel.copy())
        self._begin(0.0, x, v, Held(model.held_idx, model.held_x0, model.held_v, motion), model.x0, model.v0)
        if statics:
            self._solve_statics()
        self._start(self.scene.integrator.dt)
        return self._out(self._end_forces())

    def step(self, t: float, dt: float, positions, velocities) -> np.ndarray:
        """One coupling step from time ``t`` (the coupling's own time, :attr:`t`) to t + ``dt``, with the coupled
        objects at ``positions`` moving at ``velocities`` at t (arrays of :attr:`dofs` numbers); returns the forces
        and moments on them at t + dt (:attr:`dofs` numbers, the same layout)."""
        if self.integrator is None:
            raise CouplingError(f"{self.scene.name}: step() before init(); call init() first (it solves the "
                                f"static shape and starts the clock at t = 0)")
        if dt != self._step_dt:     # a coupling step checked once, with its number of internal steps, until it changes
            if not (isinstance(dt, (int, float, np.floating)) and math.isfinite(dt) and dt > 0):
                raise CouplingError(f"{self.scene.name}: step: dt = {dt!r}; give a positive, finite coupling step [s]")
            self._step_n = self._internal_steps(float(dt))
            self._step_dt = dt
        i = self.integrator
        now = i.step * i.grid.dt
        try:
            on_time = abs(t - now) <= 1e-9 * max(abs(now), dt)     # False for a NaN
        except TypeError:
            on_time = False
        if not on_time:
            raise CouplingError(f"{self.scene.name}: step: t = {t!r} s, but the coupling stands at t = {now!r} s; "
                                f"each step starts where the last one ended (the first at t = 0)")
        x, v = self._checked(positions, "positions"), self._checked(velocities, "velocities")
        if self.frame.turned:
            x, v = self._into(x, v)
            return self._out(self._advance(self._step_n, x, v))
        return self._advance(self._step_n, x, v)

    def mass(self) -> np.ndarray:
        """The mass matrix (dofs, dofs) [kg, kg m, kg m^2] of what the coupled objects carry now: their line ends'
        lumped masses m_i and added masses a_n (I - q q^T) + a_t q q^T (q the node's tangent), a body's about its
        reference point in world axes. The forces :meth:`step` returns leave this inertia out (MoorDyn's report);
        a caller's model adds it to its own mass, as a free body inside ropesim carries its attachments'."""
        model, i = self.model, self.integrator
        if i is None:
            raise CouplingError(f"{self.scene.name}: mass() before init()")
        dim, x = model.dim, i.x
        added = np.asarray(model.params.added_mass)
        around = np.asarray(model.params.neighbours)
        out = np.zeros((self.dofs, self.dofs))
        for o in self.objects:
            block = np.zeros((6, 6))
            if o.kind == "body":
                m = model.motion.bodies
                ref = m.accel[:dim, o.body] + m.base[:dim, o.body] * i.t
            for j in o.rows:
                node = model.held_idx[j]
                mi = model.mass[node] * np.eye(3)
                if added.size:
                    q = np.zeros(3)
                    q[:dim] = x[:, around[1, node]] - x[:, around[0, node]]
                    norm = np.linalg.norm(q)
                    q = q / norm if norm > 0 else q
                    a_n, a_t = added[0, node], added[1, node]
                    mi = mi + a_n * (np.eye(3) - np.outer(q, q)) + a_t * np.outer(q, q)
                arm = np.zeros(3)
                if o.kind == "body":
                    arm[:dim] = x[:, node] - ref
                cross = np.array([[0, -arm[2], arm[1]], [arm[2], 0, -arm[0]], [-arm[1], arm[0], 0]])
                block[:3, :3] += mi
                block[:3, 3:] -= mi @ cross
                block[3:, :3] += cross @ mi
                block[3:, 3:] -= cross @ mi @ cross
            if self.frame.turned:     # the twin's block in the scene's frame: T^T M T, T = diag(P, P)
                turn = np.kron(np.eye(2), P)
                block = turn.T @ block @ turn
            keep = list(range(dim)) + ([3, 4, 5] if dim == 3 else [5]) if o.kind == "body" else list(range(dim))
            out[o.part, o.part] = block[np.ix_(keep, keep)]
        return out

    # -- water kinematics from outside ---------------------------------------------------------------------

    def _has_sea(self) -> bool:
        return self.model.params.sea.nodes.shape[1] > 0

    def wave_points(self) -> np.ndarray:
        """Where :meth:`set_waves` wants the water's kinematics: every node's position now (N, D) [m], in the
        scene's frame and the model's node order (each line's nodes from its start to its end, the lines in the
        scene's order)."""
        self._need_sea("wave_points")
        x = self.model.x0 if self.integrator is None else self.integrator.x
        return np.array(self.frame.out(x.T))

    def set_waves(self, velocity, acceleration, elevation=None) -> None:
        """The waves' water velocity [m/s] and acceleration [m/s^2] at :meth:`wave_points` (N, D each, the scene's
        frame; a [flow] current is added on top) and the surface's elevation above the sea's level [m] there (N;
        default 0, the mean level), used by every force evaluation until the next call, in place of the scene's own
        ``[waves]`` (module doc)."""
        from .model.forces.sea import GIVEN, GIVEN_WAVES, STATE_VALID

        self._need_sea("set_waves")
        if self.model.params.bodies is not None:
            raise CouplingError(f"{self.scene.name}: set_waves: a free rigid body takes the water at its reference "
                                f"point, which the wave points (the lines' nodes) do not give; its waves come from "
                                f"the scene's [waves]")
        n, dim = self.model.nodes, self.model.dim
        u = self._node_values(velocity, (n, dim), "velocity")
        a = self._node_values(acceleration, (n, dim), "acceleration")
        eta = np.zeros(n) if elevation is None else self._node_values(elevation, (n,), "elevation")
        sea = self.model.params.sea
        given = sea.nodes[GIVEN:GIVEN + 7]
        given[0] = eta
        given[1:1 + dim] = self.frame.into(u).T
        given[4:4 + dim] = self.frame.into(a).T
        sea.scalars[GIVEN_WAVES] = 1.0
        sea.scalars[STATE_VALID] = 0.0     # the water's state of the last evaluation is stale

    def _need_sea(self, call: str) -> None:
        if not self._has_sea():
            raise CouplingError(f"{self.scene.name}: {call}: the scene has no [sea], so there is no water whose "
                                f"kinematics could be given; add [sea] (its level is the mean surface)")

    def _node_values(self, values, shape: tuple, what: str) -> np.ndarray:
        """``values`` as a float array of ``shape`` (or as many numbers flat, MoorDyn's layout), every one finite."""
        try:
            a = np.array(values, dtype=np.float64)
        except (TypeError, ValueError):
            raise CouplingError(f"{self.scene.name}: set_waves: {what}: not an array of numbers") from None
        if a.size != math.prod(shape):
            raise CouplingError(f"{self.scene.name}: set_waves: {what}: {a.size} numbers of shape {a.shape}; give "
                                f"{' x '.join(map(str, shape))} (one per node of wave_points())")
        a = a.reshape(shape)
        bad = np.flatnonzero(~np.isfinite(a.ravel()))
        if bad.size:
            k = int(bad[0]) // (shape[1] if len(shape) > 1 else 1)
            value = float(a.ravel()[bad[0]])
            raise CouplingError(f"{self.scene.name}: set_waves: {what} at node {k} is {value!r}; every value must be a "
                                f"finite number")
        return a

    # -- state ---------------------------------------------------------------------------------------------

    COUPLING_STATE = ("coupling_held_x0", "coupling_held_v", "coupling_base", "coupling_body_pose0",
                      "coupling_body_base", "coupling_dt", "coupling_waves", "coupling_waves_given")

    def state(self) -> dict[str, np.ndarray]:
        """The complete state (copies): the integrator's and the coupled objects' motion of the last step."""
        if self.integrator is None:
            raise CouplingError(f"{self.scene.name}: state() before init(): there is no state yet")
        m = self.model.motion
        out = self.integrator.state()
        out.update(coupling_held_x0=self.model.held_x0.copy(), coupling_held_v=self.integrator.held.v.copy(),
                   coupling_base=m.base.copy(), coupling_dt=np.array(self.integrator.grid.dt))
        if self._has_sea():
            from .model.forces.sea import GIVEN, GIVEN_WAVES

            sea = self.model.params.sea
            out.update(coupling_waves=sea.nodes[GIVEN:GIVEN + 7].copy(),
                       coupling_waves_given=np.array(sea.scalars[GIVEN_WAVES]))
        if m.bodies is not None:
            out.update(coupling_body_pose0=m.bodies.accel.copy(), coupling_body_base=m.bodies.base.copy())
        return out

    def restore(self, state: dict[str, np.ndarray]) -> None:
        """Continue from ``state`` (from :meth:`state` of a coupling of the same scene): the next step gives, bit
        for bit, what the coupling that saved it would have given."""
        if self.integrator is None or self.integrator.grid.dt != float(state["coupling_dt"]):
            self._start(float(state["coupling_dt"]), record_first=False)
        m = self.model.motion
        np.copyto(self.model.held_x0, state["coupling_held_x0"])
        np.copyto(self.integrator.held.v, state["coupling_held_v"])
        np.copyto(m.base, state["coupling_base"])
        if m.bodies is not None:
            np.copyto(m.bodies.accel, state["coupling_body_pose0"])
            np.copyto(m.bodies.base, state["coupling_body_base"])
        if self._has_sea() and "coupling_waves" in state:
            from .model.forces.sea import GIVEN, GIVEN_WAVES, STATE_VALID

            sea = self.model.params.sea
            np.copyto(sea.nodes[GIVEN:GIVEN + 7], state["coupling_waves"])
            sea.scalars[GIVEN_WAVES] = float(state["coupling_waves_given"])
            sea.scalars[STATE_VALID] = 0.0
        self.integrator.restore({k: v for k, v in state.items() if k not in self.COUPLING_STATE})

    def checkpoint(self) -> None:
        """Commit the recorded frames and the complete state to the run folder: :meth:`resume` continues from
        here."""
        if self.writer is None:
            raise CouplingError(f"{self.scene.name}: checkpoint() needs a run folder; give Coupling(scene, folder)")
        self.writer.checkpoint(self.state(), self.integrator.step, self.t, extra={"wall_time_s": self.wall_time})

    @classmethod
    def resume(cls, folder: str | Path) -> "Coupling":
        """The coupling recorded in ``folder``, at its last checkpoint (frames after it are dropped), recording
        on into the same folder."""
        from .io.runfolder import SCENE, RunFolderError, RunWriter, scene_hash
        from .run import frame_specs
        from .scene.loader import SceneError, scene_from_toml

        folder = Path(folder)
        writer = RunWriter.reopen(folder)
        try:
            text = (folder / SCENE).read_text(encoding="utf-8")
            if scene_hash(text) != writer.manifest.get("scene_sha256"):
                raise RunFolderError(f"{folder / SCENE}: changed since the coupling began; it cannot continue")
            try:
                scene = scene_from_toml(text, source=str(folder / SCENE))
            except SceneError as exc:
                raise RunFolderError(f"{folder / SCENE}: cannot be read ({exc})") from None
            self = cls(scene)
            state, _ = writer.load_checkpoint(frame_specs(self.model))
            self.folder, self.writer = folder, writer
            self.restore(state)
            self.wall_time = float((writer.manifest.get("checkpoint") or {}).get("wall_time_s", 0.0))
            return self
        except BaseException:
            writer.close()
            raise

    def close(self) -> None:
        """Finish the recorded run folder (its last state saved as a frame, trajectory.npz, ledger.npz and the
        summary written, scene.toml's t_end and dt those the coupling reached): every command reads it."""
        if self.writer is None:
            return
        try:
            self._finish()
        finally:
            self.writer.close()
            self.writer = None

    def __enter__(self) -> "Coupling":
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    # -- inside --------------------------------------------------------------------------------------------

    def _checked(self, values, what: str) -> np.ndarray:
        """``values`` as a fresh C-ordered float64 array (the compiled calls take no other; copying a few numbers
        costs less than asking an array whether it is one), of the right shape; :meth:`_begin` checks that every
        value is finite."""
        try:
            a = np.array(values, dtype=np.float64)
        except (TypeError, ValueError):
            raise CouplingError(f"{self.scene.name}: {what}: not an array of numbers ({type(values).__name__}); "
                                f"give {self.dofs} numbers ({self.layout()})") from None
        if a.shape != (self.dofs,):
            raise CouplingError(f"{self.scene.name}: {what}: {a.size} numbers of shape {a.shape}; the coupled "
                                f"objects have {self.dofs} degrees of freedom ({self.layout()})")
        return a

    def _into(self, x: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions and velocities of the coupled objects in the scene's frame -> the y-up twin's (see the module
        doc); the arrays themselves for a y-up scene."""
        if not self.frame.turned:
            return x, v
        bad = np.flatnonzero(~np.isfinite(np.concatenate([x, v])))
        if bad.size:     # refused before turning (a NaN angle would not survive the rotation's clamp)
            self._refuse(int(bad[0]), x, v)
        tx, tv = np.empty_like(x), np.empty_like(v)
        for o in self.objects:
            s = o.first
            tx[s:s + 3], tv[s:s + 3] = P @ x[s:s + 3], P @ v[s:s + 3]
            if o.kind == "body":
                angles = angles_of(P @ rotation_of(x[s + 3:s + 6]) @ P.T)
                tx[s + 3:s + 6] = angles
                tv[s + 3:s + 6] = angle_rates(angles, P @ angular_velocity(x[s + 3:s + 6], v[s + 3:s + 6]))
        return tx, tv

    def _out(self, forces: np.ndarray) -> np.ndarray:
        """Forces and moments on the coupled objects in the twin -> the scene's frame (in place)."""
        if self.frame.turned:
            for start in range(0, self.dofs, 3):     # 3-D: every object's DOF come in threes
                forces[start:start + 3] = P.T @ forces[start:start + 3]
        return forces

    def _refuse(self, bad: int, x: np.ndarray, v: np.ndarray):
        what, a, k = ("positions", x, bad) if bad < self.dofs else ("velocities", v, bad - self.dofs)
        raise CouplingError(f"{self.scene.name}: {what}[{k}] = {float(a[k])!r} ({self._dof_name(k)}); every value "
                            f"must be a finite number")

    def layout(self) -> str:
        """The arrays' layout in words: 'spar: x y z rx ry rz, fairlead1: x y z'."""
        return ", ".join(f"{o.id}: {' '.join(self._names(o))}" for o in self.objects)

    def _names(self, o: CoupledObject) -> tuple[str, ...]:
        axes = ("x", "y", "z")[: self.model.dim]
        if o.kind == "point":
            return axes
        return axes + (("rx", "ry", "rz") if self.model.dim == 3 else ("rz",))

    def _dof_name(self, k: int) -> str:
        for o in self.objects:
            if o.first <= k < o.first + o.dofs:
                return f"{o.id} {self._names(o)[k - o.first]}"
        return "?"

    def _internal_steps(self, dt: float) -> int:
        h = self.integrator.grid.dt
        n = round(dt / h)
        if n >= 1 and abs(n * h - dt) <= STEP_TOLERANCE * dt:
            return n
        if self.integrator.step == 0:      # MoorDyn's rule: the internal step shrinks to fit the coupling step
            n = math.ceil(dt / h * (1 - 1e-12))
            self._start(dt / n, record_first=False)
            return n
        raise CouplingError(f"{self.scene.name}: step: dt = {dt!r} s is not a whole number of internal steps of "
                            f"{h!r} s (set by the first coupling step); give a multiple of it")

    def _begin(self, t0: float, x: np.ndarray, v: np.ndarray, held, state_x: np.ndarray,
               state_v: np.ndarray) -> None:
        """Move every coupled object on x + v (t - t0) from time t0 (the loops' own time) and place the held
        nodes of ``state_x``, ``state_v`` there at t0 (:func:`ropesim.model.coupled.begin_step`)."""
        if self._begin_step is None:
            from .model.coupled import begin_step

            self._begin_step = Direct(self.model.kernel(begin_step))
        elif type(self._begin_step) is Direct and self._begin_step.entry is not None:
            self._begin_step = self._begin_step.entry      # its compiled copy itself from now on
        bad = self._begin_step(float(t0), x, v, self._objects, held, state_x, state_v)
        if bad >= 0:     # nothing was moved
            self._refuse(bad, x, v)

    def _solve_statics(self) -> None:
        from .model.build import EquilibriumError
        from .model.statics import solve_equilibrium

        result = solve_equilibrium(self.model)
        if not result.converged:
            raise EquilibriumError(f"{self.scene.name}: the static solve with the coupled objects held did not "
                                   f"converge (largest residual force {result.residual:.3g} N after "
                                   f"{result.iterations} iterations); init(statics=False) starts from the scene's "
                                   f"shape")
        self.model.x0[:] = result.x

    def _start(self, h: float, record_first: bool = True) -> None:
        """The integrator from the model's state at t = 0 with internal step h; the first frame recorded."""
        from .integrate.methods import make_integrator
        from .run import frame_specs

        scene = self.scene
        if self.integrator is not None:   # the first coupling step chose another internal step: same state at t = 0
            self.model.x0[:] = self.integrator.x
            self.model.v0[:] = self.integrator.v
            self.model.held_v[:] = self.integrator.held.v
        save_every = max(1, round(scene.output.interval / h))
        grid = TimeGrid(dt=h, steps=UNBOUNDED_STEPS, save_every=save_every, requested_dt=scene.integrator.dt)
        self.integrator = make_integrator(self.model, grid)
        self._quiet = None
        self.integrator.warm_up()
        self.integrator.loop = Direct(self.integrator.loop)   # its arguments keep their types: no dispatch
        self._loop_acc = self.integrator.last_accelerations
        held = self.integrator.held       # what held_forces reads of it: the held nodes, a body's pose and rates
        m = held.motion
        self._held_args = (held.idx, *((m.bodies.accel, m.bodies.base) if m.bodies is not None else (m.base, m.base)))
        self._step_dt = None             # the coupling step is checked again against the new internal step
        if self.folder is not None and self.writer is None:
            from .io.runfolder import RunWriter
            from .run import _manifest_info
            from .scene.schema import scene_to_toml

            self.writer = RunWriter.create(self.folder, scene_to_toml(scene), frame_specs(self.model),
                                           _manifest_info(scene, grid))
        if self.writer is not None:
            from .io.trajectory import FrameStore
            from .model.tension import frame_arrays
            from .scene.frame import frame_of

            model = self.model
            self._rows = FrameStore(0, model.nodes, model.dim,
                                    derive=lambda t, x, v, body: frame_arrays(model, t, x, v, body),
                                    frame=frame_of(model.scene)).rows
            if record_first and self.writer.count == 0:
                self._record_now()

    def _record_now(self) -> None:
        from .integrate.health import LEDGER_COLUMNS

        i = self.integrator
        ledger = np.zeros((1, len(LEDGER_COLUMNS))) if i.step == 0 else i.ledger[None, :len(LEDGER_COLUMNS)].copy()
        self.writer.append(self._rows(np.array([i.t]), i.x[None].copy(), i.v[None].copy(), ledger,
                                      i.body_rows()[None]))

    def _advance(self, n: int, x: np.ndarray, v: np.ndarray) -> np.ndarray:
        i = self.integrator
        tick = time.perf_counter()
        self._begin(i.step * i.grid.dt, x, v, i.held, i.x, i.v)
        save_every = i.grid.save_every      # a coupling's grid has no end: frames are due at multiples of it
        if (i.step + n) // save_every != i.step // save_every:
            frames = i.new_frames(n)
            done, written, status, node = i._run(n, frames)     # Integrator.advance, without its bundling
        else:    # most coupling steps save no frame: the loop's arguments are kept, but for the Schedule
            quiet = self._quiet
            if quiet is None or quiet[2] != n:
                args = list(i.loop_args(n, i.new_frames(0)))
                quiet = self._quiet = (args, tuple(args[SCHEDULE_AT])[2:], n)
            args, rest, _ = quiet
            args[SCHEDULE_AT] = Schedule(i.step, n, *rest)
            done, written, status, node = i.loop(*args)
        if type(i.loop) is Direct:          # after its first call the loop is its compiled copy itself
            i.loop = i.loop.fast
        i.step += done
        if self.writer is not None and written:
            self.writer.append(self._rows(frames.t[:written], frames.x[:written], frames.v[:written],
                                          frames.ledger[:written], frames.body[:written]))
        if status != OK:
            from .run import _blow_up_message

            _, message = _blow_up_message(self.model, i, status, node)
            raise CouplingError(f"{self.scene.name}: {message}")
        if self._loop_acc is None:
            forces = self._end_forces()
        else:
            forces = self._loop_forces()
        self.wall_time += time.perf_counter() - tick
        return forces

    def _end_forces(self) -> np.ndarray:
        """The forces and moments on the coupled objects now, from an evaluation at the state now (see the module
        doc; :func:`ropesim.model.coupled.end_forces`)."""
        model, i = self.model, self.integrator
        if self._end is None:
            from .model.coupled import end_forces

            self._end = Direct(model.kernel(end_forces))
        out = np.zeros(self.dofs)
        self._end(i.x, i.v, self._acc, model.params, float(i.t), model.mass, self._objects, i.held, out)
        self._last_acc = self._acc
        return out

    def _loop_forces(self) -> np.ndarray:
        """The forces and moments on the coupled objects at the end of the loop's last step, from its last force
        evaluation (:attr:`ropesim.integrate.base.Integrator.last_accelerations`;
        :func:`ropesim.model.coupled.held_forces`)."""
        i = self.integrator
        if self._held is None:
            from .model.coupled import held_forces

            self._held = Direct(self.model.kernel(held_forces))
        elif type(self._held) is Direct and self._held.entry is not None:
            self._held = self._held.entry
        out = np.zeros(self.dofs)
        self._held(i.x, self._loop_acc, i.step * i.grid.dt, self.model.mass, self._objects, *self._held_args,
                        out)
        self._last_acc = self._loop_acc
        return out

    def node_accelerations(self) -> np.ndarray:
        """The accelerations (D, N) of the evaluation the last forces came from (m a is each node's net force), in
        the frame the model computes in (a z-up scene's y-up twin)."""
        return self._last_acc

    def _finish(self) -> None:
        from .analysis.ledger import ledger_arrays
        from .analysis.summary import summarize
        from .io.atomic import write_text_atomic
        from .io.runfolder import COMPLETED, LEDGER, SCENE, TRAJECTORY, scene_hash
        from .run import COMPLETED as DONE, RunOutcome, _manifest_info
        from .scene.schema import scene_to_toml

        i, writer = self.integrator, self.writer
        if i.step % i.grid.save_every:     # an ordinary run's frames end with its last step
            self._record_now()
        scene = replace(self.scene, integrator=replace(self.scene.integrator, t_end=i.t, dt=i.grid.dt))
        text = scene_to_toml(scene)
        write_text_atomic(writer.folder / SCENE, text)
        grid = TimeGrid(dt=i.grid.dt, steps=i.step, save_every=i.grid.save_every, requested_dt=i.grid.dt)
        writer.manifest.update(_manifest_info(scene, grid), scene_sha256=scene_hash(text))
        arrays = writer.arrays()
        outcome = RunOutcome(status=DONE, steps=i.step, t_reached=i.t, wall_time=self.wall_time, compile_time=0.0,
                             grid=grid, ledger=arrays["ledger"], energy0=float(i.ledger[E0]),
                             force_evaluations=i.force_evaluations, integrator=i)
        summary = summarize(self.model, outcome, arrays["t"], arrays["x"], arrays["v"], arrays["tension"], arrays)
        summary["coupled"] = [o.id for o in self.objects]
        files = {TRAJECTORY: {k: a for k, a in arrays.items() if k != "ledger"},
                 LEDGER: ledger_arrays(arrays["t"], arrays["ledger"], outcome.energy0)}
        writer.finish(COMPLETED, self.state(), files, summary)
