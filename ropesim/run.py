"""Run a scene: the compiled kernel in chunks, frames streamed out, progress, Ctrl-C and blow-up stops.

Between chunks (each about a tenth of a second of work) control returns to Python: saved frames go to their
store, the progress bar moves, and an interrupt or a blow-up ends the run cleanly with every frame computed
so far kept. Chunking never changes the numbers: the same scene gives bit-identical frames however it is cut.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from .build import Model, build, stability_frequency
from .integrators import NON_FINITE, advance, get_method, kick_factors
from .scene import Scene

COMPLETED, INTERRUPTED, BLEW_UP = "completed", "interrupted", "blew_up"
CHECK_EVERY = 64  # steps between finiteness checks: a blow-up is caught within this many steps


@dataclass(frozen=True)
class TimeGrid:
    """The run's steps: ``steps`` uniform steps of ``dt`` reaching t_end exactly; a frame every ``save_every``.

    When t_end is not a whole number of the scene's dt, dt shrinks slightly (never grows) to fit.
    """

    dt: float
    steps: int
    save_every: int
    requested_dt: float

    @classmethod
    def of(cls, scene: Scene) -> "TimeGrid":
        dt, t_end = scene.integrator.dt, scene.integrator.t_end
        steps = math.ceil(t_end / dt * (1 - 1e-12)) if t_end > 0 else 0
        h = t_end / steps if steps else dt
        save_every = max(1, round(scene.output.interval / h))
        return cls(dt=h, steps=steps, save_every=save_every, requested_dt=dt)

    @property
    def frames(self) -> int:
        """Saved frames, t = 0 included: every save_every-th step and the last one."""
        return 1 + self.steps // self.save_every + (1 if self.steps % self.save_every else 0)

    @property
    def dt_adjusted(self) -> bool:
        return abs(self.dt - self.requested_dt) > 1e-12 * self.requested_dt


class Stepper:
    """The scene's state and the compiled step loop; ``advance(n)`` moves it n steps forward."""

    def __init__(self, model: Model, method: str, grid: TimeGrid):
        self.model, self.grid = model, grid
        self.scheme = get_method(method)
        self.x = model.x0.copy()
        self.v = model.v0.copy()
        self.acc = np.zeros_like(self.x)
        self.have_acc = np.zeros(1, dtype=np.bool_)
        self.step = 0
        self.reuse_force = self.scheme.reuses_last_force and not model.velocity_dependent
        self.drift = np.array(self.scheme.drift)
        self.kick = np.array(self.scheme.kick)
        self.decay, self.gain = kick_factors(self.scheme, grid.dt, model.drag, model.mass, model.held)

    @property
    def t(self) -> float:
        return self.step * self.grid.dt

    def frames_in(self, n: int) -> int:
        """Frames saved by the next ``n`` steps."""
        e, end = self.grid.save_every, self.step + n
        count = end // e - self.step // e
        if end == self.grid.steps and end % e:
            count += 1
        return count

    def advance(self, n: int, frames: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None):
        """Run ``n`` steps; returns (steps done, frames written, status, node)."""
        if frames is None:
            k = self.frames_in(n)
            dim, nodes = self.x.shape
            frames = (np.zeros(k), np.zeros((k, dim, nodes)), np.zeros((k, dim, nodes)))
        m = self.model
        done, written, status, node = advance(
            self.x, self.v, self.acc, self.have_acc, self.step, n, self.grid.steps, self.grid.dt, self.drift,
            self.kick, self.decay, self.gain, self.reuse_force, m.held_idx, m.held_x0, m.held_v, m.forces,
            self.grid.save_every, frames[0], frames[1], frames[2], CHECK_EVERY)
        self.step += done
        return done, written, status, node

    def warm_up(self) -> float:
        """Compile the kernel (or load it from cache) with a zero-step call; returns the seconds it took."""
        start = time.perf_counter()
        self.advance(0)
        return time.perf_counter() - start


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


@contextmanager
def _interrupt_flag():
    """While inside, Ctrl-C sets the returned flag instead of raising, so a chunk always finishes whole."""
    flag = threading.Event()
    if threading.current_thread() is not threading.main_thread():
        yield flag
        return
    previous = signal.getsignal(signal.SIGINT)
    signal.signal(signal.SIGINT, lambda *_: flag.set())
    try:
        yield flag
    finally:
        signal.signal(signal.SIGINT, previous)


def integrate(model: Model, store, on_progress: Callable[[float, float], None] | None = None,
              target_chunk_seconds: float = 0.1, stop: Callable[[], bool] | None = None) -> RunOutcome:
    """Step ``model`` from t = 0 to t_end, appending saved frames to ``store`` (see :class:`FrameStore`)."""
    scene = model.scene
    grid = TimeGrid.of(scene)
    stepper = Stepper(model, scene.integrator.method, grid)
    compile_time = stepper.warm_up()
    dim, nodes = stepper.x.shape
    store.append(np.zeros(1), stepper.x[None], stepper.v[None])

    status, bad_node, message = "completed", -1, ""
    chunk = max(1, min(grid.steps, 20_000_000 // max(1, nodes * stepper.scheme.evaluations)))
    chunk = _round_to(chunk, grid.save_every)
    start = time.perf_counter()
    with _interrupt_flag() as interrupted:
        while stepper.step < grid.steps:
            if interrupted.is_set() or (stop is not None and stop()):
                status = INTERRUPTED
                message = f"interrupted at t = {stepper.t:.6g} s (step {stepper.step} of {grid.steps})"
                break
            n = min(chunk, grid.steps - stepper.step)
            k = stepper.frames_in(n)
            frames = (np.zeros(k), np.zeros((k, dim, nodes)), np.zeros((k, dim, nodes)))
            tick = time.perf_counter()
            done, written, code, node = stepper.advance(n, frames)
            elapsed = time.perf_counter() - tick
            store.append(frames[0][:written], frames[1][:written], frames[2][:written])
            if code == NON_FINITE:
                status, bad_node = BLEW_UP, node
                break
            if on_progress is not None:
                on_progress(stepper.t, scene.integrator.t_end)
            if elapsed > 0:
                rate = done / elapsed
                chunk = _round_to(max(1, int(rate * target_chunk_seconds)), grid.save_every)
    wall = time.perf_counter() - start

    stable_dt = None
    if status == BLEW_UP:
        omega = stability_frequency(model)
        limit = stepper.scheme.stability_limit
        stable_dt = 0.5 * limit / omega if omega > 0 else None
        hint = f"; a time step of {stable_dt:.3g} s or less would be stable" if stable_dt else ""
        message = (f"blew up at t = {stepper.t:.6g} s (step {stepper.step}): node {bad_node} has a non-finite "
                   f"position or velocity with dt = {grid.dt:.3g} s and method {scene.integrator.method}{hint}")
    return RunOutcome(status=status, steps=stepper.step, t_reached=stepper.t, wall_time=wall,
                      compile_time=compile_time, grid=grid, message=message, bad_node=bad_node, stable_dt=stable_dt)


def _round_to(n: int, multiple: int) -> int:
    """``n`` rounded to a positive multiple of ``multiple`` (so chunks end on saved frames)."""
    return max(multiple, (n // multiple) * multiple)


def simulate(scene: Scene, folder: str | Path | None = None, progress: bool = False):
    """Run ``scene`` and return its :class:`~ropesim.trajectory.Trajectory`.

    With ``folder`` the run also writes ``trajectory.npz``, ``scene.toml`` and ``summary.json`` there, each
    atomically; frames stream to disk as they are computed. A run that blows up or is interrupted stops
    cleanly: the trajectory holds every frame up to that point and ``summary["status"]`` says what happened.
    """
    from .analysis.summary import summarize
    from .scene import scene_to_toml
    from .trajectory import SCENE, SUMMARY, FrameStore, Trajectory, write_json_atomic, write_text_atomic

    model = build(scene)
    grid = TimeGrid.of(scene)
    folder = Path(folder) if folder is not None else None
    store = FrameStore(grid.frames, model.nodes, model.dim, folder)
    try:
        if folder is not None:
            write_text_atomic(folder / SCENE, scene_to_toml(scene))
        with _progress(progress, scene) as on_progress:
            outcome = integrate(model, store, on_progress)
        arrays = store.arrays()
        summary = summarize(model, outcome, arrays["t"], arrays["x"], arrays["v"])
        if folder is not None:
            store.finish()
            write_json_atomic(folder / SUMMARY, summary)
            return Trajectory.open(folder)
        return Trajectory(t=arrays["t"], x=arrays["x"], v=arrays["v"], scene=scene, summary=summary)
    finally:
        store.discard()


@contextmanager
def _progress(enabled: bool, scene: Scene):
    """A rich progress bar that appears only once a run has taken more than a second."""
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
            p.start()
            bar["p"], bar["task"] = p, p.add_task("run", total=t_end)
        bar["p"].update(bar["task"], completed=t)

    try:
        yield update
    finally:
        if "p" in bar:
            bar["p"].stop()
