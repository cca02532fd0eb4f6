"""The run folder on disk: ``trajectory.npz``, ``scene.toml`` and ``summary.json``.

``trajectory.npz`` holds ``t`` (F,) [s], ``x`` (F, N, D) [m] and ``v`` (F, N, D) [m/s], every saved frame from
t = 0. It is an ordinary uncompressed ``.npz`` (``numpy.load`` reads it), written so that each array can also be
memory-mapped: :meth:`Trajectory.open` reads frames lazily, so a trajectory of any size can be analysed.

While the run goes on, frames stream to ``checkpoint/`` in durable checkpoints, and ``manifest.json`` says
what the folder holds (:mod:`ropesim.io.runfolder`); a finished run's ``.npz`` files are assembled beside their
final names and moved into place, so a reader never sees half a file. :meth:`Trajectory.open` reads either,
checking every frame's CRC-32 first.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from .frames import check_run_folder, read_run
from .runfolder import SCENE, TRAJECTORY, RunFolderError

ARRAYS = ("t", "x", "v")
DERIVED = ("tension", "strain", "support", "held_force", "body_x", "body_q", "body_v", "body_w", "submerged",
           "line_submerged", "probe_elevation")
"""Per frame, derived from t, x and v (and the free bodies' states) as they are stored."""
BODY_STATE = ("body_x", "body_v", "body_q", "body_w")   # a system's rigid bodies, in the scene's order


class FrameStore:
    """Where a run's saved frames go in memory (:func:`ropesim.simulate` without a folder; a run folder streams
    them through :class:`ropesim.io.runfolder.RunWriter` instead).

    Named per-frame arrays: ``t``, ``x``, ``v``, ``ledger`` (the energy ledger's flows), and with ``derive`` (a
    function of the frames' t (k,), x and v (k, N, D) and the free bodies' states (k, 13, B) or None, returning
    named (k, ...) arrays, ``shapes`` their per-frame shapes) what it derives: the segments' tension and strain,
    the supports' forces, the rigid bodies' poses (:mod:`ropesim.model.tension`). With ``frame`` (a z-up scene's
    :class:`ropesim.scene.frame.Frame`) the vectors are stored in the scene's own frame.
    """

    def __init__(self, n_frames: int, nodes: int, dim: int, folder: Path | None = None, derive=None,
                 shapes: dict[str, tuple] | None = None, ledger_columns: int | None = None, frame=None):
        from ..integrate.health import LEDGER_COLUMNS

        if folder is not None:
            raise TypeError("FrameStore keeps frames in memory; a run folder is written by ropesim.simulate")
        self.count = 0
        self.derive = derive
        self.frame = frame     # a z-up scene's frames are stored turned out of its y-up twin (ropesim.scene.frame)
        self.specs = {"t": (), "x": (nodes, dim), "v": (nodes, dim), **(shapes or {}),
                      "ledger": (ledger_columns or len(LEDGER_COLUMNS),)}
        self.names = tuple(self.specs)
        self._arrays = {name: np.zeros((n_frames, *s)) for name, s in self.specs.items()}

    def __getattr__(self, name):
        arrays = self.__dict__.get("_arrays", {})
        if name in arrays:
            return arrays[name]
        raise AttributeError(name)

    def rows(self, t: np.ndarray, x_dn: np.ndarray, v_dn: np.ndarray, ledger: np.ndarray | None,
             body: np.ndarray | None = None) -> dict:
        """Frames given in kernel layout (F, D, N) (and the free rigid bodies' states (F, 13, B)), as the named
        per-frame arrays to store."""
        x, v = np.swapaxes(x_dn, 1, 2), np.swapaxes(v_dn, 1, 2)
        out = {"t": np.asarray(t), "x": x, "v": v}
        if self.derive is not None:
            out.update(self.derive(out["t"], x, v, body))
        out["ledger"] = np.zeros((len(t), self.specs["ledger"][0])) if ledger is None else ledger
        return out if self.frame is None else self.frame.arrays_out(out)

    def append(self, t: np.ndarray, x_dn: np.ndarray, v_dn: np.ndarray, ledger: np.ndarray | None = None,
               body: np.ndarray | None = None) -> None:
        """Append frames given in kernel layout (F, D, N) (and their ledger rows and bodies' states)."""
        k = len(t)
        if k == 0:
            return
        end = self.count + k
        for name, values in self.rows(t, x_dn, v_dn, ledger, body).items():
            self._arrays[name][self.count:end] = values
        self.count = end

    def arrays(self) -> dict[str, np.ndarray]:
        return {name: a[:self.count] for name, a in self._arrays.items()}


def scene_nodes(scene) -> int:
    """How many nodes a scene's frames hold: a rope's, or every line's of a system."""
    return scene.rope.nodes if scene.rope is not None else sum(line.nodes for line in scene.lines)


@dataclass
class Trajectory:
    """Saved frames of one run: ``t`` (F,) [s], ``x`` and ``v`` (F, N, D) [m, m/s], each segment's ``tension``
    [N] and ``strain`` (F, S), the force each support exerts on its held node, ``support`` (F, H, D) [N] (None
    without held nodes), the net force on each held node without its inertia, ``held_force`` (F, H, D) [N]
    (MoorDyn's report for a fixed or coupled point: :mod:`ropesim.model.tension`), the energy ledger's flows ``ledger`` (F, C) [J] (columns
    :data:`ropesim.integrate.health.LEDGER_COLUMNS`), with its scene and summary (the derived arrays and
    ``ledger`` are None for a run folder written before ropesim stored them).

    A system's nodes are its lines' nodes, line after line in the scene's order; its rigid bodies' states are
    ``body_x`` (F, B, D) [m], the reference point, ``body_v`` (F, B, D) [m/s] its velocity, ``body_q`` (F, B, 4)
    the orientation quaternion (w, x, y, z), body frame to world frame, and ``body_w`` (F, B, 3) [rad/s] the
    angular velocity in world axes (2-D: about z alone), every body in the scene's order (None without rigid
    bodies). :meth:`line`, :meth:`point` and :meth:`body` give each object's results by its id.

    With a ``[sea]``: ``submerged`` (F, N), each node's fraction below the instantaneous surface,
    ``line_submerged`` (F, L), each line's fraction of its length, and with ``[sea] probes`` the surface's
    elevation above the mean level at each, ``probe_elevation`` (F, P) [m] (:mod:`ropesim.model.sea_frames`).

    Every array is in the scene's own frame: a z-up scene's (``up = "z"``) are z-up, though the model computes
    in its y-up twin (:mod:`ropesim.scene.frame`; :attr:`internal` gives the run in that frame).

    From :func:`ropesim.simulate` the arrays are in memory; from :meth:`open` they are memory-mapped.
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    scene: object
    summary: dict = field(default_factory=dict)
    folder: Path | None = None
    tension: np.ndarray | None = None
    strain: np.ndarray | None = None
    support: np.ndarray | None = None
    held_force: np.ndarray | None = None   # (F, H, D) the net force on each held node without its inertia [N]
    ledger: np.ndarray | None = None   # (F, C) the energy ledger's cumulative flows [J], columns LEDGER_COLUMNS
    body_x: np.ndarray | None = None   # (F, B, D) each rigid body's reference point [m] (None without bodies)
    body_q: np.ndarray | None = None   # (F, B, 4) its orientation, a unit quaternion (w, x, y, z), body to world
    body_v: np.ndarray | None = None   # (F, B, D) its reference point's velocity [m/s]
    body_w: np.ndarray | None = None   # (F, B, 3) its angular velocity in world axes [rad/s]
    submerged: np.ndarray | None = None        # (F, N) each node's submerged fraction (a [sea]; else None)
    line_submerged: np.ndarray | None = None   # (F, L) each line's submerged fraction of its length
    probe_elevation: np.ndarray | None = None  # (F, P) the surface's elevation at each of [sea] probes [m]

    @property
    def frames(self) -> int:
        return len(self.t)

    @property
    def frame(self):
        """The scene's own frame (:class:`ropesim.scene.frame.Frame`): which axis is up. Every array here is in it."""
        from ..scene.frame import frame_of
        return frame_of(self.scene)

    @cached_property
    def internal(self) -> "Trajectory":
        """This run in ropesim's y-up frame, the frame its scene object and model compute in (the trajectory itself
        for a y-up scene; for a z-up one a copy with every vector turned into its y-up twin's frame): what the
        analyses and pictures that use the model's geometry (heights, the seabed) read."""
        frame = self.frame
        if not frame.turned:
            return self
        from dataclasses import replace
        arrays = frame.arrays_into({name: getattr(self, name) for name in ("x", "v", *DERIVED)})
        return replace(self, **arrays)

    @property
    def nodes(self) -> int:
        return self.x.shape[1]

    @classmethod
    def open(cls, folder: str | Path, verify: bool = True) -> "Trajectory":
        """Read a run folder lazily; raises :class:`RunFolderError` with one clear line if it is unusable.

        A finished run is read from ``trajectory.npz``; an unfinished one (interrupted, killed, still running)
        from its last checkpoint. With ``verify`` (the default) every array's CRC-32 is checked first.
        """
        from ..scene.loader import SceneError, load_scene

        folder = Path(folder)
        check_run_folder(folder)
        try:
            scene = load_scene(folder / SCENE)
        except SceneError as exc:
            raise RunFolderError(f"{folder}: its scene.toml is not valid: {exc}") from None
        arrays, ledger, summary = read_run(folder, verify)
        missing = [a for a in ARRAYS if a not in arrays]
        if missing:
            raise RunFolderError(f"{folder / TRAJECTORY}: missing arrays {', '.join(missing)}")
        t, x, v = arrays["t"], arrays["x"], arrays["v"]
        n, d = scene_nodes(scene), scene.dimension
        if t.ndim != 1 or x.shape != (len(t), n, d) or v.shape != x.shape or len(t) == 0:
            raise RunFolderError(f"{folder / TRAJECTORY}: arrays do not match the scene: t {t.shape}, "
                                 f"x {x.shape}, v {v.shape}, expected (F,), (F, {n}, {d})")
        derived = {name: arrays.get(name) for name in DERIVED}
        for name, values in derived.items():
            if values is not None and (values.ndim < 2 or values.shape[0] != len(t)):
                raise RunFolderError(f"{folder / TRAJECTORY}: {name} has shape {values.shape}, not one row per "
                                     f"frame ({len(t)})")
        bodies = len(scene.rigid_bodies)
        for name, width in zip(BODY_STATE, (d, d, 4, 3)):
            values = derived[name]
            if bodies and values is not None and values.shape[1:] != (bodies, width):
                raise RunFolderError(f"{folder / TRAJECTORY}: {name} has shape {values.shape}, expected "
                                     f"({len(t)}, {bodies}, {width}) for the scene's {bodies} rigid bodies")
        if ledger is not None and len(ledger) != len(t):
            ledger = None
        return cls(t=t, x=x, v=v, scene=scene, summary=summary, folder=folder, ledger=ledger, **derived)

    # Each object's results by its id (ropesim.analysis.objects).
    def line(self, id: str):
        """Line ``id``'s results (a rope is the line "rope"): its nodes' positions and velocities, each
        segment's tension and strain, its end tensions and the force each end puts on what it is attached to
        (:class:`ropesim.analysis.objects.LineResults`)."""
        from ..analysis.objects import line_results
        return line_results(self, id)

    def point(self, id: str):
        """Point ``id``'s results: its position and velocity, and the force its lines put on it
        (:class:`ropesim.analysis.objects.PointResults`)."""
        from ..analysis.objects import point_results
        return point_results(self, id)

    def body(self, id: str):
        """Rigid body ``id``'s results: its position, orientation (quaternion, rotation matrix, the scene's
        angles), velocity and angular velocity, and the force and moment its lines put on it
        (:class:`ropesim.analysis.objects.BodyResults`)."""
        from ..analysis.objects import body_results
        return body_results(self, id)

    @property
    def lines(self) -> dict:
        """Every line's results by id, in the scene's order (a rope: {"rope": ...}); see :meth:`line`."""
        from ..analysis.objects import every_line
        return every_line(self)

    @property
    def points(self) -> dict:
        """Every point's results by id, in the scene's order (a rope has none); see :meth:`point`."""
        return {p.id: self.point(p.id) for p in self.scene.points}

    @property
    def bodies(self) -> dict:
        """Every rigid body's results by id, in the scene's order; see :meth:`body`."""
        return {b.id: self.body(b.id) for b in self.scene.rigid_bodies}

    # Other tools and notebooks (ropesim.io.export, ropesim.render.notebook).
    def export(self, to: str, out: str | Path | None = None):
        """Write this run for other tools: ``to`` "vtk" (a ParaView series) or "csv" (see ropesim.io.export)."""
        from .export import export
        return export(self, to, out)

    def animate(self, **options):
        """An animation that plays inline in Jupyter (an MP4 in a <video>); options as `ropesim animate`'s."""
        from ..render.notebook import inline_animation
        return inline_animation(self, **options)

    def view(self, **options):
        """This run in the browser viewer (`ropesim view`'s page; options ``every``, ``start``, ``end`` as
        :func:`ropesim.view`'s): a notebook shows it in a sandboxed iframe, ``.save(path)`` writes it."""
        from ..viewer.page import view
        return view(self, **options)

    def _repr_html_(self) -> str:
        """In Jupyter: the short summary table, and the run in the viewer below it."""
        from ..render.notebook import summary_html
        return summary_html(self) + self.view()._repr_html_()

    def __repr__(self) -> str:
        return (f"Trajectory(scene={self.scene.name!r}, {self.summary.get('status', 'completed')}, "
                f"{self.frames} frames, t = {float(self.t[0]):.6g} .. {float(self.t[-1]):.6g} s, "
                f"{self.nodes} nodes, {self.x.shape[2]}-D, {'in memory' if self.folder is None else self.folder})")
