"""Run a scene: an integrator in chunks, frames streamed out, progress, Ctrl-C and blow-up stops.

Between chunks (each about a tenth of a second of wall time, measured, whatever a step costs) control returns to Python: saved frames go to their
store, the progress bar moves, and an interrupt or a blow-up ends the run cleanly with every frame computed
so far kept. Chunking never changes the numbers: the same scene gives bit-identical frames however it is cut.
The integrator comes from one table by the scene's method name (:mod:`ropesim.integrate.methods`); this
module knows the integrator contract (:mod:`ropesim.integrate.base`), not the families.
"""

from __future__ import annotations

import signal
import threading
import time
from contextlib import contextmanager, nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from .integrate.grid import TimeGrid
from .integrate.health import E0, LEDGER_COLUMNS, NEWTON_FAILED, NON_FINITE, OK, OVERSTRETCH, RUNAWAY_ENERGY
from .integrate.health import RUNAWAY_FLOW_FRACTION
from .integrate.base import ChunkSizer, Integrator
from .integrate.methods import make_integrator
from .model.build import Model, build
from .scene.schema import Scene

COMPLETED, INTERRUPTED, BLEW_UP = "completed", "interrupted", "blew_up"
FRAME_BUFFER_BYTES = 16 * 2 ** 20  # at most this many bytes of saved frames are held in memory between chunks


@dataclass
class RunOutcome:
    """How a run ended. ``message`` is one line for the user when it did not complete."""

    status: str
    steps: int
    t_reached: float
    wall_time: float
    compile_time: float
    grid: TimeGrid
    message: str = ""
    bad_node: int = -1
    stable_dt: float | None = None
    ledger: np.ndarray | None = None       # (F, C) cumulative flows [J] per frame (LEDGER_COLUMNS)
    energy0: float = 0.0                   # mechanical energy at t = 0 [J]
    force_evaluations: int = 0
    signal: str = ""                       # the signal that interrupted the run (SIGINT, SIGTERM, SIGHUP)
    integrator: Integrator | None = None


STOP_SIGNALS = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))
EXIT_CODES = {"SIGINT": 130, "SIGTERM": 143, "SIGHUP": 129}   # 128 + the signal's number, as shells report


class StopFlag:
    """Set by a stop signal (or by hand); remembers which signal came first."""

    def __init__(self):
        self._event = threading.Event()
        self.signal = ""

    def set(self, name: str = "SIGINT") -> None:
        if not self._event.is_set():
            self.signal = name
        self._event.set()

    def is_set(self) -> bool:
        return self._event.is_set()


@contextmanager
def stop_signals(flag: StopFlag | None = None):
    """While inside, Ctrl-C (SIGINT), SIGTERM and SIGHUP set the returned flag instead of ending the process, so
    a chunk always finishes whole and the run stops cleanly at the next one. Only the main thread can handle
    signals; elsewhere (and after the block: a notebook keeps its own handlers) nothing is installed."""
    flag = flag if flag is not None else StopFlag()
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return
    previous = {}
    try:
        for sig in STOP_SIGNALS:
            previous[sig] = signal.signal(sig, lambda signum, _frame: flag.set(signal.Signals(signum).name))
        yield flag
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


_interrupt_flag = stop_signals  # the former name


def integrate(model: Model, store, on_progress: Callable[[float, float], None] | None = None,
              target_chunk_seconds: float = 0.1, stop: Callable[[], bool] | None = None,
              integrator: Integrator | None = None, interrupted: StopFlag | None = None,
              on_chunk: Callable[[Integrator, float], None] | None = None) -> RunOutcome:
    """Step ``model`` to t_end, appending saved frames to ``store`` (see :class:`FrameStore`).

    From t = 0, or from where ``integrator`` (restored from a checkpoint) stands. ``on_chunk(integrator,
    seconds)`` is called after the first frame and after every chunk (a run folder commits checkpoints there).
    """
    scene = model.scene
    grid = TimeGrid.of(scene) if integrator is None else integrator.grid
    with (nullcontext(interrupted) if interrupted is not None else stop_signals()) as flag:
        if integrator is None:
            integrator = make_integrator(model, grid)
        if integrator.step == 0 and store.count == 0:
            store.append(np.zeros(1), integrator.x[None], integrator.v[None], np.zeros((1, len(LEDGER_COLUMNS))),
                         integrator.body_rows()[None])
            if on_chunk is not None:
                on_chunk(integrator, 0.0)
        status, bad_node, message, code = "completed", -1, "", OK
        chunks = ChunkSizer(target_chunk_seconds, grid.save_every)
        frame_cap = grid.save_every * max(1, FRAME_BUFFER_BYTES // (2 * 8 * model.nodes * model.dim))
        compile_time = integrator.warm_up()
        start = time.perf_counter()
        while integrator.step < grid.steps:
            if flag.is_set() or (stop is not None and stop()):
                status = INTERRUPTED
                message = f"interrupted at t = {integrator.t:.6g} s (step {integrator.step} of {grid.steps})"
                break
            n = min(chunks.steps, frame_cap, grid.steps - integrator.step)
            frames = integrator.new_frames(n)
            tick = time.perf_counter()
            done, written, code, node = integrator.advance(n, frames)
            chunks.measured(done, time.perf_counter() - tick)
            store.append(frames.t[:written], frames.x[:written], frames.v[:written], frames.ledger[:written],
                         frames.body[:written])
            if code != OK:
                status, bad_node = BLEW_UP, node
                break
            if on_chunk is not None:
                on_chunk(integrator, time.perf_counter() - start)
            if on_progress is not None:
                on_progress(integrator.t, scene.integrator.t_end)
        if hasattr(store, "drain"):
            store.drain()       # the frames still being written count in the run's wall time
    wall = time.perf_counter() - start

    stable_dt = None
    if status == BLEW_UP:
        stable_dt, message = _blow_up_message(model, integrator, code, bad_node)

    return RunOutcome(status=status, steps=integrator.step, t_reached=integrator.t, wall_time=wall,
                      compile_time=compile_time, grid=grid, message=message, bad_node=bad_node, stable_dt=stable_dt,
                      ledger=store.arrays()["ledger"], energy0=float(integrator.ledger[E0]),
                      force_evaluations=integrator.force_evaluations,
                      signal=flag.signal if status == INTERRUPTED and flag.is_set() else "", integrator=integrator)


def _sharp_contacts(scene: Scene) -> bool:
    """True when the scene has a thrower box or guide circles whose edges switch sharply."""
    return (scene.thrower is not None and scene.thrower.edge_width == 0) or any(g.edge_width == 0
                                                                                  for g in scene.guides)


def _blow_up_message(model: Model, integrator: Integrator, code: int, node: int) -> tuple[float | None, str]:
    """(a time step that would be stable, one line saying when, where and how the run blew up)."""
    from .analysis.stability import predicted_dt

    scene, grid = model.scene, integrator.grid
    method = scene.integrator.method
    what = {
        NON_FINITE: f"node {node} has a non-finite position or velocity",
        OVERSTRETCH: f"the spring after node {node} is stretched beyond {integrator.limits[0]:.3g} times its rest "
                     f"length",
        RUNAWAY_ENERGY: f"runaway energy (the energy balance is off by more than the initial energy scale plus "
                        f"{RUNAWAY_FLOW_FRACTION:.0%} of the energy that flowed; node {node} is the fastest)",
        NEWTON_FAILED: f"the implicit stage's Newton solve did not converge in node {node}'s neighbourhood"
                       + (" (the thrower's and guides' sharp edges switch forces on and off; smooth them with "
                          "thrower.edge_width and guides edge_width)" if _sharp_contacts(scene) else ""),
    }[code]
    bound = predicted_dt(model, method)
    start = (f"blew up at t = {integrator.t:.6g} s (step {integrator.step}): {what}, with dt = {grid.dt:.3g} s and "
             f"method {method}; ")
    if code != NEWTON_FAILED and np.isfinite(bound) and bound > 0 and grid.dt > 0.5 * bound:
        stable_dt = 0.5 * bound     # the spectral bound says so
        return stable_dt, start + f"a time step of {stable_dt:.3g} s or less would be stable"
    # Below the bound, or an implicit method: no bound to quote, only a smaller step to try.
    stable_dt = 0.25 * grid.dt
    adaptive = " or adaptive steps (integrator.tolerance)" if method == "galpha" else ""
    return stable_dt, start + f"try a time step of {stable_dt:.3g} s (a quarter of this one){adaptive}"


# Measured cost of the kernel per node and step [ns] (helicopter_mass at 21 and 201 nodes, the larger of the
# two), and of deriving and writing a saved frame per node [ns]. galpha's (fixed steps) from its ratio to rk4's
# in one run of scripts/bench_node_step.py (rk4 38 and 49, sdirk2 392 and 390, galpha 85 and 119 ns at 201 and
# 21 nodes: 2.2 rk4's, 0.22 sdirk2's; scaled by rk4's, the larger of the two scalings).
NS_PER_NODE_STEP = {"symplectic_euler": 4.2, "verlet": 6.2, "yoshida4": 19.0, "pefrl": 20.0, "rk4": 180.0,
                    "sdirk2": 1100.0, "galpha": 400.0}
NS_PER_NODE_FRAME = 150.0
# What a [sea] adds per node and force evaluation [ns]: the surface, fractions and split drag, then each wave
# component, advanced by a multiplication for a spectrum, evaluated directly for a table or a regular wave
# (scripts/bench_waves.py), times the evaluations a step makes (sdirk2's measured on the mooring chain in a sea:
# 4 to 5; the splitting schemes' velocity kicks take four sub-stages).
NS_PER_NODE_SEA = 100.0
NS_PER_NODE_COMPONENT = {"recurrence": 2.0, "direct": 36.0}
SEA_EVALUATIONS_PER_STEP = {"sdirk2": 5.0}
WARN_BYTES = 2 * 10 ** 9        # `run` and `check` warn above this much output
WARN_SECONDS = 15 * 60          # ... or this long a run


@dataclass
class Estimate:
    """What a run will take before it starts: its frames, their bytes (the run folder's finished size; while
    it finishes, the checkpoint streams and trajectory.npz exist together: ``peak_bytes``) and its run time."""

    frames: int
    bytes: int
    peak_bytes: int
    seconds: float


def estimate(scene: Scene, model: Model | None = None) -> Estimate:
    """The output size and run time of ``scene``, from its time grid and the method's measured cost."""
    model = model if model is not None else build(scene)
    grid = TimeGrid.of(scene)
    row = 8 * sum(int(np.prod(s, dtype=np.int64)) for s in frame_specs(model).values())
    total = grid.frames * row
    cost = NS_PER_NODE_STEP.get(scene.integrator.method, max(NS_PER_NODE_STEP.values())) + _sea_cost(scene)
    seconds = 1e-9 * model.nodes * (grid.steps * cost + grid.frames * NS_PER_NODE_FRAME)
    return Estimate(frames=grid.frames, bytes=total, peak_bytes=2 * total, seconds=seconds)


def _sea_cost(scene: Scene) -> float:
    """What a scene's [sea] and [waves] add to a step's cost per node [ns] (see NS_PER_NODE_SEA)."""
    if scene.sea is None:
        return 0.0
    per_evaluation = NS_PER_NODE_SEA
    if scene.waves is not None:
        from .model.waves import components_of, water_depth

        comps = components_of(scene.waves, water_depth(scene), scene.gravity.g)
        way = "recurrence" if comps.spacing is not None else "direct"
        per_evaluation += comps.count * NS_PER_NODE_COMPONENT[way]
    return SEA_EVALUATIONS_PER_STEP.get(scene.integrator.method, 4.0) * per_evaluation


CHECKPOINT_SECONDS = 5.0   # a run folder commits a checkpoint at most this often (and at every stop)
LOW_DISK_BYTES = 64 * 2 ** 20   # below this much free space, every chunk is a checkpoint


def frame_specs(model: Model) -> dict[str, tuple]:
    """The named per-frame arrays a run stores and their per-frame shapes: t, x, v, what
    :func:`ropesim.model.tension.frame_arrays` derives (tension, strain, support forces), and the ledger's
    flows."""
    from .model.tension import frame_shapes

    return {"t": (), "x": (model.nodes, model.dim), "v": (model.nodes, model.dim), **frame_shapes(model),
            "ledger": (len(LEDGER_COLUMNS),)}


def simulate(scene: Scene, folder: str | Path | None = None, progress: bool = False, *,
             stop: Callable[[], bool] | None = None, checkpoint_seconds: float = CHECKPOINT_SECONDS,
             before_bar: Callable[[], None] | None = None):
    """Run ``scene`` and return its :class:`~ropesim.trajectory.Trajectory`.

    With ``folder`` the run is written there as a transaction (:mod:`ropesim.io.runfolder`): frames stream to
    disk in durable checkpoints, and at the end ``trajectory.npz``, ``ledger.npz`` and ``summary.json`` are
    written and committed by ``manifest.json``. An earlier run in the folder is replaced whole; a folder
    another process is writing is refused (:class:`~ropesim.io.runfolder.RunFolderBusy`). A run that blows up
    or is interrupted (Ctrl-C, SIGTERM, SIGHUP, or ``stop()`` returning True) stops cleanly: the trajectory
    holds every frame up to that point and ``summary["status"]`` says what happened; an interrupted run
    continues with :func:`resume`. ``before_bar()`` is called just before the progress bar appears (the
    command line's start-up spinner makes way for it).
    """
    from .io.runfolder import RunWriter
    from .scene.schema import scene_to_toml

    model = build(scene)
    grid = TimeGrid.of(scene)
    if folder is None:
        return _run_in_memory(model, grid, progress, stop, before_bar)
    writer = RunWriter.create(Path(folder), scene_to_toml(scene), frame_specs(model), _manifest_info(scene, grid))
    return _run_in_folder(model, grid, writer, None, {}, progress, stop, checkpoint_seconds, before_bar)


def resume(folder: str | Path, t_end: float | None = None, progress: bool = False, *,
           stop: Callable[[], bool] | None = None, checkpoint_seconds: float = CHECKPOINT_SECONDS,
           before_bar: Callable[[], None] | None = None):
    """Continue the run in ``folder`` from its last checkpoint; with ``t_end``, extend it (a finished run too).

    The result is bit for bit the run that was never stopped: frames, ledger, tension and summary (but for
    wall times). Refused in one line (:class:`~ropesim.io.runfolder.RunFolderError`) when there is nothing to
    continue, when scene.toml was edited since, or when the new t_end would change the time grid.
    """
    from .io.atomic import write_text_atomic
    from .io.runfolder import SCENE, RunFolderError, RunWriter, scene_hash
    from .scene.schema import scene_to_toml

    folder = Path(folder)
    writer = RunWriter.reopen(folder)
    try:
        scene, old_t_end = _scene_to_continue(folder, writer.manifest, t_end)
        reached = (writer.manifest.get("checkpoint") or {}).get("t")
        if t_end is not None and reached is not None and t_end < reached:
            raise RunFolderError(f"{folder}: integrator.t_end = {t_end:g} s lies before the run's last checkpoint "
                                 f"(t = {reached:.6g} s), where it goes on from; give a t_end of at least "
                                 f"{reached:.6g} s")
        model = build(scene)
        grid = TimeGrid.of(scene)
        old = writer.manifest.get("grid", {})
        if (grid.dt, grid.save_every) != (old.get("dt"), old.get("save_every")):
            raise RunFolderError(
                f"{folder}: integrator.t_end = {scene.integrator.t_end:g} s changes the run's time grid (dt "
                f"{old.get('dt')!r} -> {grid.dt!r} s, a frame every {old.get('save_every')} -> {grid.save_every} "
                f"steps), so the result could not equal one uninterrupted run; choose t_end a whole number of "
                f"dt = {old.get('dt')!r} s")
        state, cp = writer.load_checkpoint(frame_specs(model))
        _align_frames(folder, writer, grid, int(state["step"]), cp)
        if scene.integrator.t_end != old_t_end:
            new_text = scene_to_toml(scene)
            write_text_atomic(folder / SCENE, new_text)
            writer.manifest.update(_manifest_info(scene, grid), scene_sha256=scene_hash(new_text))
        integrator = make_integrator(model, grid)
        integrator.restore(state)
        return _run_in_folder(model, grid, writer, integrator, cp, progress, stop, checkpoint_seconds, before_bar)
    except BaseException:
        writer.close()
        raise


def _scene_to_continue(folder: Path, manifest: dict, t_end: float | None) -> tuple[Scene, float]:
    """(the run's scene, with ``t_end`` if given; its t_end before) if the run in ``folder`` can go on."""
    from dataclasses import replace

    from .io.runfolder import BLEW_UP, COMPLETED, SCENE, RunFolderError, scene_hash
    from .scene.loader import SceneError, scene_from_toml

    try:
        text = (folder / SCENE).read_text(encoding="utf-8")
        scene = scene_from_toml(text, source=str(folder / SCENE))
    except (OSError, SceneError) as exc:
        raise RunFolderError(f"{folder / SCENE}: cannot be read ({exc}); run the scene again") from None
    if scene_hash(text) != manifest.get("scene_sha256"):
        raise RunFolderError(f"{folder / SCENE}: changed since the run began, so the run cannot continue bit "
                             f"for bit; run the scene again (only --set integrator.t_end=... may change with "
                             f"--resume)")
    old_t_end = scene.integrator.t_end
    if t_end is not None and t_end != old_t_end:
        scene = replace(scene, integrator=replace(scene.integrator, t_end=float(t_end)))
    if manifest["status"] == BLEW_UP:
        raise RunFolderError(f"{folder}: blew up ({manifest.get('message', '')}); it cannot continue; run it again "
                             f"with a smaller integrator.dt")
    if manifest["status"] == COMPLETED and scene.integrator.t_end <= old_t_end:
        raise RunFolderError(f"{folder}: already completed to t = {old_t_end:g} s; to extend it give "
                             f"--set integrator.t_end=T with T > {old_t_end:g}")
    return scene, old_t_end


def _align_frames(folder: Path, writer, grid: TimeGrid, step: int, cp: dict) -> None:
    """Make the checkpoint's frames those an uninterrupted run on ``grid`` holds after ``step``: an extended
    run drops the shorter run's own last frame, which lies off its grid."""
    from .io.runfolder import RunFolderError

    if step > grid.steps:
        raise RunFolderError(f"{folder}: its last checkpoint is at t = {cp['t']:.6g} s, past the new t_end")
    on_grid = 1 + step // grid.save_every + (1 if step == grid.steps and step % grid.save_every else 0)
    if writer.count > on_grid:
        writer.drop_last_frames(on_grid)
    elif writer.count != on_grid:
        raise RunFolderError(f"{folder}: its checkpoint holds {writer.count} frames for step {step}, expected "
                             f"{on_grid}; run the scene again")


def _manifest_info(scene: Scene, grid: TimeGrid) -> dict:
    return {"scene": scene.name, "grid": {"dt": grid.dt, "steps": grid.steps, "save_every": grid.save_every,
                                          "frames": grid.frames, "t_end": scene.integrator.t_end}}


def _run_in_memory(model: Model, grid: TimeGrid, progress: bool, stop, before_bar=None) -> "Trajectory":
    from .io.trajectory import FrameStore
    from .model.tension import frame_arrays
    from .scene.frame import frame_of

    specs = frame_specs(model)
    store = FrameStore(grid.frames, model.nodes, model.dim, derive=lambda t, x, v, body: frame_arrays(model, t, x, v, body),
                       shapes={k: s for k, s in specs.items() if k not in ("t", "x", "v", "ledger")},
                       frame=frame_of(model.scene))
    with _progress(progress, model.scene, before_bar) as on_progress:
        outcome = integrate(model, store, on_progress, stop=stop)
    return _in_memory(model, store.arrays(), outcome)


def _in_memory(model: Model, arrays: dict, outcome: RunOutcome, **more) -> "Trajectory":
    """A trajectory held in memory from the run's frame arrays, with its summary (and ``more`` in it)."""
    from .analysis.summary import summarize
    from .io.trajectory import DERIVED, Trajectory

    summary = summarize(model, outcome, arrays["t"], arrays["x"], arrays["v"], arrays["tension"], arrays)
    _stopped_by(summary, outcome)
    summary.update(more)
    extra = {k: v for k, v in arrays.items() if k in (*DERIVED, "ledger")}
    return Trajectory(t=arrays["t"], x=arrays["x"], v=arrays["v"], scene=model.scene, summary=summary, **extra)


def _stopped_by(summary: dict, outcome: RunOutcome) -> None:
    if outcome.signal:
        summary["stopped_by"] = outcome.signal


class _DiskStore:
    """The integration loop's frame store for a run folder. Frames are derived (tension, strain) and written
    by a background thread while the kernel computes the next chunk; a checkpoint waits for it, then commits
    (at most every ``seconds`` of wall time, and at every stop)."""

    DEPTH = 2   # chunks waiting to be written at most (each at most FRAME_BUFFER_BYTES of frames)

    def __init__(self, writer, model: Model, seconds: float, previous: dict):
        import queue

        from .io.trajectory import FrameStore
        from .model.tension import frame_arrays
        from .scene.frame import frame_of

        self.writer, self.seconds = writer, seconds
        self.rows = FrameStore(0, model.nodes, model.dim, derive=lambda t, x, v, body: frame_arrays(model, t, x, v, body),
                               frame=frame_of(model.scene)).rows
        self.last = -float("inf")
        self.wall0 = float(previous.get("wall_time_s", 0.0))
        self.compile0 = float(previous.get("compile_time_s", 0.0))
        self.compile_time = 0.0
        self.error: BaseException | None = None
        self.queue: queue.Queue = queue.Queue(maxsize=self.DEPTH)
        self.thread = threading.Thread(target=self._work, name="ropesim-frame-writer", daemon=True)
        self.thread.start()

    def _work(self) -> None:
        while True:
            item = self.queue.get()
            try:
                if item is None:
                    return
                if self.error is None:
                    self.writer.append(self.rows(*item))
            except BaseException as exc:   # handed to the main thread at its next append or checkpoint
                self.error = exc
            finally:
                self.queue.task_done()

    def _raise(self) -> None:
        if self.error is not None:
            error, self.error = self.error, None
            raise error

    def append(self, t, x_dn, v_dn, ledger=None, body=None) -> None:
        self._raise()
        if len(t):
            self.queue.put((t, x_dn, v_dn, ledger, body))

    def drain(self) -> None:
        self.queue.join()
        self._raise()

    def close(self) -> None:
        if self.thread.is_alive():
            self.queue.put(None)
            self.thread.join()

    @property
    def count(self) -> int:
        self.drain()
        return self.writer.count

    def arrays(self) -> dict:
        self.drain()
        return self.writer.arrays()

    def on_chunk(self, integrator: Integrator, wall: float) -> None:
        self._raise()
        if time.monotonic() - self.last >= self.seconds or self._disk_nearly_full():
            self.checkpoint(integrator, wall)

    def _disk_nearly_full(self) -> bool:
        """True when the run folder's disk has less than LOW_DISK_BYTES free: then every chunk is a checkpoint,
        so a disk that fills up loses at most the last chunk (the frames of the others stay)."""
        from .io.runfolder import free_bytes

        try:
            return free_bytes(self.writer.folder) < LOW_DISK_BYTES
        except OSError:
            return False

    def checkpoint(self, integrator: Integrator, wall: float) -> None:
        self.drain()
        self.writer.checkpoint(integrator.state(), integrator.step, integrator.t,
                               extra={"wall_time_s": self.wall0 + wall,
                                      "compile_time_s": self.compile0 + self.compile_time})
        self.last = time.monotonic()


def _run_in_folder(model: Model, grid: TimeGrid, writer, integrator: Integrator | None, previous: dict,
                   progress: bool, stop, checkpoint_seconds: float, before_bar=None):
    from .analysis.ledger import ledger_arrays
    from .analysis.summary import summarize
    from .io.runfolder import LEDGER, TRAJECTORY
    from .io.trajectory import Trajectory

    writer.expected_frames = grid.frames
    store = _DiskStore(writer, model, checkpoint_seconds, previous)
    with stop_signals() as flag:   # until the folder is closed: a signal after the last chunk cannot tear that
        try:
            with _progress(progress, model.scene, before_bar) as on_progress:
                outcome = integrate(model, store, on_progress, stop=stop, integrator=integrator, interrupted=flag,
                                    on_chunk=store.on_chunk)
            store.compile_time = outcome.compile_time
            if outcome.status == INTERRUPTED and writer.pending:
                return _not_replaced(model, writer, store, outcome)
            store.checkpoint(outcome.integrator, outcome.wall_time)     # every stop is a checkpoint
            outcome.wall_time += store.wall0
            outcome.compile_time += store.compile0
            arrays = writer.arrays()
            summary = summarize(model, outcome, arrays["t"], arrays["x"], arrays["v"], arrays["tension"], arrays)
            _stopped_by(summary, outcome)
            if outcome.status == INTERRUPTED:
                writer.mark(INTERRUPTED, outcome.message, summary)
            else:
                files = {TRAJECTORY: {k: a for k, a in arrays.items() if k != "ledger"},
                         LEDGER: ledger_arrays(arrays["t"], arrays["ledger"], outcome.energy0)}
                writer.finish(outcome.status, outcome.integrator.state(), files, summary, outcome.message)
        finally:
            store.close()
            writer.close()
    return Trajectory.open(writer.folder, verify=False)


def _not_replaced(model: Model, writer, store, outcome: RunOutcome):
    """A rerun stopped before its first checkpoint past t = 0: it is dropped and the earlier run in its folder
    stays as it was; returns the stopped run's frames, in memory, its summary saying so."""
    store.drain()
    arrays = {name: np.array(a) for name, a in writer.arrays().items()}
    folder = writer.discard()
    outcome.message += f" before it replaced the earlier run in {folder}, which is kept as it was"
    return _in_memory(model, arrays, outcome, kept_earlier_run=str(folder))


@contextmanager
def _progress(enabled: bool, scene: Scene, before: Callable[[], None] | None = None):
    """A rich progress bar that appears only once a run has taken more than a second; ``before()`` is called
    just before it appears."""
    if not enabled:
        yield None
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    started = time.perf_counter()
    bar: dict = {}

    def update(t: float, t_end: float) -> None:
        if "p" not in bar:
            if time.perf_counter() - started < 1.0:
                return
            p = Progress(TextColumn(f"[bold]{scene.name}"), BarColumn(), TextColumn("t = {task.completed:.3g} s"),
                         TimeRemainingColumn(), transient=True)
            if before is not None:
                before()
            p.start()
            bar["p"], bar["task"] = p, p.add_task("run", total=t_end)
        bar["p"].update(bar["task"], completed=t)

    try:
        yield update
    finally:
        if "p" in bar:
            bar["p"].stop()
