"""MoorDyn's Python API (the ``moordyn`` package, v2) served by ropesim: a script written for MoorDyn runs on
ropesim by changing its import::

    import ropesim.compat.moordyn as moordyn      # instead of: import moordyn

    system = moordyn.Create("spar.toml")
    moordyn.Init(system, x, xd)                    # the static solve with the coupled objects held at x
    for k in range(steps):
        f = moordyn.Step(system, x, xd, t, dt)     # forces on the coupled degrees of freedom
    moordyn.Close(system)

Every array is in MoorDyn's frame and units: z up, SI, angles in radians. The scene is read by
:func:`ropesim.load_scene`: a ropesim scene, or a MoorDyn v2 input file as ``ropesim run`` reads it; its coupled
points and bodies (``kind = "coupled"``, MoorDyn's Coupled and Vessel objects) are the coupled degrees of
freedom, bodies first, then points, each in the scene's order, as MoorDyn orders them. A MoorDyn file reads
as a z-up scene (``up = "z"``), whose frame is MoorDyn's: nothing is turned here. A y-up scene's coordinates are
turned: MoorDyn's (x, y, z) is the scene's (x, z, -y). Calls run through :class:`ropesim.Coupling`, whose
documentation says what a coupling step does.

A coupled body's angles are MoorDyn's (roll, pitch, yaw, R = Rx Ry Rz, ``Euler2Quat``) and its angular
velocity the world-axes one MoorDyn moves its points with; both are turned into the scene's angles (R = Rz Ry
Rx) and their rates at every step; the scene's angles then move linearly over the step where MoorDyn's own
angles do, two paths that agree to second order in the rotation over one coupling step.

Not supported, one line each (a call raises :class:`NotImplementedError` saying so):

- rods (``GetRod`` and every rod getter): ropesim has no rods;
- ``GetWaves`` (MoorDyn's wave object): the waves are given (``ExternalWaveKinSet``) or the scene's own ``[waves]``;
- a surface elevation with external wave kinematics (MoorDyn's calls give none: the surface stays at the sea's level), and a point's own entry (its line ends' are used);
- ``GetSeafloor`` (a bathymetry file): ropesim's seabed is flat;
- ``Log`` and ``SetVerbosity`` are accepted and do nothing: ropesim writes no log file;
- ``Serialize`` / ``Deserialize`` (bytes in MoorDyn's format): use ``SaveState`` / ``LoadState`` (ropesim's own file, a NumPy .npz);
- the inertia term of a coupled body (MoorDyn subtracts M (v - v_prev) / dt of its points' masses): not subtracted;
- a coupled body's own mass, buoyancy and drag: not added to its force (give them to the caller's model);
- a coupled pinned body or rod (``CoupledPinned``): only fully coupled bodies and points;
- ``GetBodyForce`` of a body that is not coupled, ``GetLineNodeCurv``, ``GetLineNodeForce`` of a node that is not an end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..coupling import Coupling, CouplingError, angle_rates, angles_of
from ..scene.frame import P, frame_of

__all__ = ["Create", "NCoupledDOF", "Init", "Init_NoIC", "Step", "Close", "GetNumberLines", "GetNumberPoints",
           "GetNumberBodies", "GetLine", "GetPoint", "GetBody", "GetLineID", "GetPointID", "GetBodyID",
           "GetLineN", "GetLineNumberNodes", "GetLineUnstretchedLength", "GetLineNodePos", "GetLineNodeTen",
           "GetLineFairTen", "GetFASTtens", "GetPointPos", "GetPointVel", "GetPointForce", "GetPointNAttached",
           "GetBodyState", "GetBodyForce", "SaveState", "LoadState", "Log", "SetVerbosity", "ExternalWaveKinInit",
           "ExternalWaveKinGetN", "ExternalWaveKinGetCoordinates", "GetWaveKinCoordinates", "ExternalWaveKinSet",
           "SetWaveKin", "MoorDynError"]

MoorDynError = CouplingError


class System:
    """What :func:`Create` returns: the coupling, and the turn between MoorDyn's frame and the scene's."""

    def __init__(self, scene):
        if scene.dimension != 3:
            raise CouplingError(f"{scene.name}: MoorDyn's calls move 3-D systems; this scene is 2-D")
        self.coupling = Coupling(scene)
        self.scene = scene
        # turn: MoorDyn's coordinates -> the scene's, whose frame the coupling takes: nothing for a z-up scene
        # (up = "z", as a MoorDyn file reads), P: (x, y, z) -> (x, z, -y) for a y-up one. inside: MoorDyn's ->
        # the model's own arrays, always its y-up twin's (the getters read them)
        self.turn = np.eye(3) if frame_of(scene).turned else P
        self.inside = P
        self.last_x = self.last_v = None
        self.forces = None

    @property
    def model(self):
        return self.coupling.model

    # -- frames ---------------------------------------------------------------------------------------------

    def to_scene(self, x, v) -> tuple[np.ndarray, np.ndarray]:
        """MoorDyn's positions and velocities of the coupled DOF -> the coupling's (scene frame, scene angles)."""
        x = np.asarray(x, dtype=float)
        v = np.asarray(v, dtype=float)
        c = self.coupling
        if x.shape != (c.dofs,) or v.shape != (c.dofs,):
            raise CouplingError(f"{self.scene.name}: x and xd need {c.dofs} numbers each (NCoupledDOF), got "
                                f"{x.size} and {v.size}")
        out_x, out_v = np.empty(c.dofs), np.empty(c.dofs)
        turn = self.turn
        for o in c.objects:
            s = o.first
            out_x[s:s + 3], out_v[s:s + 3] = turn @ x[s:s + 3], turn @ v[s:s + 3]
            if o.kind == "body":
                angles = angles_of(turn @ moordyn_rotation(*x[s + 3:s + 6]) @ turn.T)
                out_x[s + 3:s + 6] = angles
                out_v[s + 3:s + 6] = angle_rates(angles, turn @ v[s + 3:s + 6])
        return out_x, out_v

    def to_moordyn(self, forces: np.ndarray) -> list[float]:
        """The coupling's forces and moments (scene frame) -> MoorDyn's frame."""
        out = np.empty_like(forces)
        back = self.turn.T
        for o in self.coupling.objects:
            for start in range(o.first, o.first + o.dofs, 3):
                out[start:start + 3] = back @ forces[start:start + 3]
        return out.tolist()

    def vector(self, inside_vector) -> list[float]:
        """A vector of the model's own arrays (the y-up twin's) in MoorDyn's frame."""
        return (self.inside.T @ np.asarray(inside_vector, dtype=float)).tolist()

    # -- state now ------------------------------------------------------------------------------------------

    def state(self):
        i = self.coupling.integrator
        if i is None:
            raise CouplingError(f"{self.scene.name}: call Init first")
        return i.x, i.v

    def node_forces(self) -> np.ndarray:
        """Every node's net force (D, N) [N], m acc, of the evaluation the coupling's last forces came from."""
        self.state()
        return self.model.mass * self.coupling.node_accelerations()


def moordyn_rotation(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """MoorDyn's orientation of a body from its three angles: R = Rx(roll) Ry(pitch) Rz(yaw) (Euler2Quat)."""
    cr, sr, cp, sp, cy, sy = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch), math.cos(yaw), \
        math.sin(yaw)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rx @ ry @ rz


@dataclass(frozen=True)
class Handle:
    """A line, point or body of a system (MoorDyn's MoorDynLine, MoorDynPoint, MoorDynBody), numbered from 1."""

    system: System
    number: int
    item: object


# -- the system ---------------------------------------------------------------------------------------------


def Create(filepath: str = "") -> System:
    """The system of scene file ``filepath``: a ropesim scene or a MoorDyn v2 input file (MoorDyn's default
    "Mooring/lines.txt" if empty)."""
    from ..scene.loader import load_scene

    return System(load_scene(filepath or str(Path("Mooring") / "lines.txt")))


def NCoupledDOF(instance: System) -> int:
    """The number of coupled degrees of freedom: 6 per coupled body, 3 per coupled point."""
    return instance.coupling.dofs


def Init(instance: System, x, v) -> int:
    """Place the coupled objects at x moving at v and solve the static shape with them held there; 0."""
    sx, sv = instance.to_scene(x, v)
    instance.forces = instance.coupling.init(sx, sv)
    instance.last_x, instance.last_v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
    return 0


def Init_NoIC(instance: System, x, v) -> int:
    """:func:`Init` without the static solve: the scene's own start shape."""
    sx, sv = instance.to_scene(x, v)
    instance.forces = instance.coupling.init(sx, sv, statics=False)
    instance.last_x, instance.last_v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
    return 0


def Step(instance: System, x, v, t: float, dt: float) -> list[float]:
    """One coupling step of dt from the system's time (MoorDyn too steps from its own time, whatever t says)
    with the coupled objects at x moving at v; the forces on the coupled degrees of freedom at its end."""
    c = instance.coupling
    sx, sv = instance.to_scene(x, v)
    if dt <= 0:          # MoorDyn: nothing to do, the forces as they are
        return instance.to_moordyn(instance.forces)
    instance.forces = c.step(c.t, dt, sx, sv)
    instance.last_x, instance.last_v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
    return instance.to_moordyn(instance.forces)


def Close(instance: System) -> int:
    instance.coupling.close()
    return 0


def SaveState(instance: System, filepath: str) -> None:
    """The system's complete state into ``filepath`` (a NumPy .npz, written whole or not at all)."""
    from ..io.atomic import atomic_output

    with atomic_output(Path(filepath)) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **instance.coupling.state())


def LoadState(instance: System, filepath: str) -> None:
    """Continue from the state :func:`SaveState` wrote (of the same scene): bit for bit."""
    with np.load(filepath, allow_pickle=False) as npz:
        state = {name: npz[name] for name in npz.files}
    instance.coupling.restore(state)


def Log(instance: System, level: int, msg: str) -> int:
    return 0


def SetVerbosity(instance: System, verbosity: int) -> int:
    return 0


def _unsupported(name: str, why: str):
    def call(*args, **kwargs):
        raise NotImplementedError(f"moordyn.{name}: {why}")
    call.__name__ = name
    return call


GetRod = _unsupported("GetRod", "ropesim has no rods")
GetNumberRods = lambda instance: 0  # noqa: E731  (a system without rods)
GetWaves = _unsupported("GetWaves", "the waves are given (ExternalWaveKinSet) or the scene's own [waves]")
GetSeafloor = _unsupported("GetSeafloor", "ropesim's seabed is flat (no bathymetry file)")
Serialize = _unsupported("Serialize", "use SaveState (ropesim's own .npz file)")
Deserialize = _unsupported("Deserialize", "use LoadState (ropesim's own .npz file)")
GetLineNodeCurv = _unsupported("GetLineNodeCurv", "ropesim does not report curvature")


# -- external wave kinematics (MoorDyn's WaveKin = 1) ---------------------------------------------------------


def _wave_nodes(instance: System) -> np.ndarray:
    """The model's node of each of MoorDyn's wave points: every line's nodes from its start (node 0) to its end,
    line by line, then each point's first line end (MoorDyn's Waves::getWaveKinematicsPoints order)."""
    from ..model.layout import point_ends

    nodes = [node for layout in instance.model.lines for node in range(layout.first, layout.end)]
    ends = point_ends(instance.scene, instance.model.lines)
    return np.array(nodes + [ends[p.id][0] for p in instance.scene.points], dtype=np.int64)


def ExternalWaveKinInit(instance: System) -> int:
    """The number of points where the waves' kinematics are wanted (call after :func:`Init`); the scene needs a
    ``[sea]`` (a MoorDyn file with WaveKin = 1 imports with one)."""
    instance.coupling.wave_points()       # refuses a scene without a sea in one line
    instance.wave_nodes = _wave_nodes(instance)
    return len(instance.wave_nodes)


def ExternalWaveKinGetN(instance: System) -> int:
    return len(getattr(instance, "wave_nodes", ()))


def ExternalWaveKinGetCoordinates(instance: System) -> list[list[float]]:
    """The points (n, 3) where :func:`ExternalWaveKinSet` wants the waves, now (MoorDyn's frame)."""
    x, _ = instance.state()
    nodes = _need_wave_init(instance, "ExternalWaveKinGetCoordinates")
    return (instance.inside.T @ x[:, nodes]).T.tolist()


GetWaveKinCoordinates = ExternalWaveKinGetCoordinates


def ExternalWaveKinSet(instance: System, u, a, t: float = 0.0) -> int:
    """The waves' velocity ``u`` and acceleration ``a`` (n, 3 each, MoorDyn's frame) at the points of
    :func:`ExternalWaveKinGetCoordinates`, used until they are set again (t is not read, as MoorDyn does not);
    0."""
    nodes = _need_wave_init(instance, "ExternalWaveKinSet")
    n = len(nodes)
    on_lines = nodes[:n - len(instance.scene.points)]
    values = []
    for what, given in (("u", u), ("a", a)):
        try:
            array = np.array(given, dtype=float).reshape(n, 3)
        except (TypeError, ValueError):
            raise CouplingError(f"{instance.scene.name}: ExternalWaveKinSet: {what} needs {n} x 3 numbers (one row "
                                f"per point of ExternalWaveKinGetCoordinates), got {np.size(given)}") from None
        per_node = np.zeros((instance.model.nodes, 3))
        per_node[on_lines] = array[:len(on_lines)] @ instance.turn.T     # the scene's frame
        values.append(per_node)
    instance.coupling.set_waves(*values)
    return 0


SetWaveKin = ExternalWaveKinSet


def _need_wave_init(instance: System, call: str) -> np.ndarray:
    nodes = getattr(instance, "wave_nodes", None)
    if nodes is None:
        raise CouplingError(f"{instance.scene.name}: {call} before ExternalWaveKinInit; call it once after Init")
    return nodes


# -- lines, points, bodies ----------------------------------------------------------------------------------


def GetNumberLines(instance: System) -> int:
    return len(instance.scene.lines)


def GetNumberPoints(instance: System) -> int:
    return len(instance.scene.points)


def GetNumberBodies(instance: System) -> int:
    return len(instance.scene.rigid_bodies)


def _get(instance: System, items, number: int, what: str) -> Handle:
    if not 1 <= int(number) <= len(items):
        raise CouplingError(f"{instance.scene.name}: no {what} {number}; {what}s are numbered 1 to {len(items)}")
    return Handle(instance, int(number), items[int(number) - 1])


def GetLine(instance: System, line: int) -> Handle:
    return _get(instance, instance.scene.lines, line, "line")


def GetPoint(instance: System, point: int) -> Handle:
    return _get(instance, instance.scene.points, point, "point")


def GetBody(instance: System, body: int) -> Handle:
    return _get(instance, instance.scene.rigid_bodies, body, "body")


def GetLineID(instance: Handle) -> int:
    return instance.number


GetPointID = GetBodyID = GetLineID


def _layout(line: Handle):
    return line.system.model.lines[line.number - 1]


def GetLineN(instance: Handle) -> int:
    """The line's number of segments."""
    return instance.item.segments


def GetLineNumberNodes(instance: Handle) -> int:
    return instance.item.segments + 1


def GetLineUnstretchedLength(instance: Handle) -> float:
    return instance.item.length


def GetLineNodePos(instance: Handle, i: int) -> list[float]:
    """Node i's position (0: the line's start, anchor side; N: its end)."""
    x, _ = instance.system.state()
    return instance.system.vector(x[:, _layout(instance).first + int(i)])


def _segment_tensions(line: Handle) -> tuple[np.ndarray, np.ndarray]:
    """(the line's segment forces [N] (S,), its nodes (n, D)) now."""
    from ..model.forces.springs import segment_forces

    x, v = line.system.state()
    part = _layout(line)
    nodes = slice(part.first, part.end)
    forces = segment_forces(line.system.model, x.T[None], v.T[None])[0]
    first = sum(layout.segments for layout in line.system.model.lines[:line.number - 1])
    return forces[first:first + part.segments], x[:, nodes].T


def GetLineNodeTen(instance: Handle, i: int) -> list[float]:
    """The tension vector at node i: its segment's at an end, the mean of its two segments' inside (MoorDyn's
    Line::getNodeTen), along each segment's direction."""
    tension, x = _segment_tensions(instance)
    i, n = int(i), len(tension)
    vectors = []
    for j in {max(i - 1, 0), min(i, n - 1)}:
        d = x[j + 1] - x[j]
        vectors.append(tension[j] * d / np.linalg.norm(d))
    return instance.system.vector(sum(vectors) / len(vectors))


def GetLineFairTen(instance: Handle) -> float:
    """The tension at the line's end (node N, MoorDyn's fairlead end)."""
    tension, _ = _segment_tensions(instance)
    return float(tension[-1])


def GetLineNodeForce(instance: Handle, i: int) -> list[float]:
    """The net force on an end node now (its line's pull, weight, buoyancy, drag, seabed push)."""
    i = int(i)
    if i not in (0, instance.item.segments):
        raise NotImplementedError("moordyn.GetLineNodeForce: ropesim reports the net force of a line's end nodes only")
    return instance.system.vector(instance.system.node_forces()[:, _layout(instance).first + i])


def GetFASTtens(instance: System, n_lines: int):
    """(fairlead horizontal, fairlead vertical, anchor horizontal, anchor vertical) tension of the first n_lines
    lines [N]: the net force on each line's end (node N) and start (node 0) nodes, as MoorDyn's getFASTtens."""
    forces = instance.node_forces()
    out = ([], [], [], [])
    for layout in instance.model.lines[:int(n_lines)]:
        for k, node in ((0, layout.end - 1), (2, layout.first)):
            f = instance.inside.T @ forces[:, node]
            out[k].append(float(math.hypot(f[0], f[1])))
            out[k + 1].append(float(f[2]))
    return out


def _point_nodes(point: Handle) -> list[int]:
    from ..model.layout import point_ends

    return point_ends(point.system.scene, point.system.model.lines)[point.item.id]


def GetPointPos(instance: Handle) -> list[float]:
    x, _ = instance.system.state()
    return instance.system.vector(x[:, _point_nodes(instance)[0]])


def GetPointVel(instance: Handle) -> list[float]:
    _, v = instance.system.state()
    return instance.system.vector(v[:, _point_nodes(instance)[0]])


def GetPointForce(instance: Handle) -> list[float]:
    """The net force on the point's line-end nodes without their inertia (MoorDyn's Point::getFnet)."""
    forces = instance.system.node_forces()
    return instance.system.vector(forces[:, _point_nodes(instance)].sum(axis=1))


def GetPointNAttached(instance: Handle) -> int:
    return len(_point_nodes(instance))


def _coupled(body: Handle):
    for o in body.system.coupling.objects:
        if o.kind == "body" and o.id == body.item.id:
            return o
    raise NotImplementedError(f"moordyn.GetBodyForce/GetBodyState: body '{body.item.id}' is not coupled; ropesim "
                              f"reports these for coupled bodies")


def GetBodyState(instance: Handle):
    """(position and angles (6), velocity and angular velocity (6)) as the caller last gave them."""
    o = _coupled(instance)
    s = instance.system
    return s.last_x[o.part].tolist(), s.last_v[o.part].tolist()


def GetBodyForce(instance: Handle) -> list[float]:
    """The force and moment on a coupled body (its points' net forces; MoorDyn's frame)."""
    o = _coupled(instance)
    return instance.system.to_moordyn(instance.system.forces)[o.first:o.first + 6]
