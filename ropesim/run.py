"""Run a scene: an integrator in chunks, frames streamed out, progress, Ctrl-C and blow-up stops.

Between chunks (each about a tenth of a second of work) control returns to Python: saved frames go to their
store, the progress bar moves, and an interrupt or a blow-up ends the run cleanly with every frame computed
so far kept. Chunking never changes the numbers: the same scene gives bit-identical frames however it is cut.
The integrator comes from one table by the scene's method name (:mod:`ropesim.integrate.methods`); this
module knows the integrator contract (:mod:`ropesim.integrate.base`), not the families.
"""

from __future__ import annotations

import signal
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from .integrate.grid import TimeGrid
from .integrate.health import E0, LEDGER_COLUMNS, NEWTON_FAILED, NON_FINITE, OK, OVERSTRETCH, RUNAWAY_ENERGY
from .integrate.health import RUNAWAY_FLOW_FRACTION
from .integrate.base import Integrator
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
    ledger: np.ndarray | None = None       # (F, 3) cumulative drag loss, held-node work, box work [J] per frame
    energy0: float = 0.0                   # mechanical energy at t = 0 [J]
    force_evaluations: int = 0


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
    with _interrupt_flag() as interrupted:  # a Ctrl-C while compiling stops the run cleanly at t = 0
        integrator = make_integrator(model, grid)
        store.append(np.zeros(1), integrator.x[None], integrator.v[None])
        ledger = [np.zeros((1, len(LEDGER_COLUMNS)))]
        status, bad_node, message, code = "completed", -1, "", OK
        chunk = max(1, min(grid.steps, 20_000_000 // max(1, model.nodes * integrator.method.evaluations)))
        chunk = _round_to(chunk, grid.save_every)
        frame_cap = grid.save_every * max(1, FRAME_BUFFER_BYTES // (2 * 8 * model.nodes * model.dim))
        compile_time = integrator.warm_up()
        start = time.perf_counter()
        while integrator.step < grid.steps:
            if interrupted.is_set() or (stop is not None and stop()):
                status = INTERRUPTED
                message = f"interrupted at t = {integrator.t:.6g} s (step {integrator.step} of {grid.steps})"
                break
            n = min(chunk, frame_cap, grid.steps - integrator.step)
            frames = integrator.new_frames(n)
            tick = time.perf_counter()
            done, written, code, node = integrator.advance(n, frames)
            elapsed = time.perf_counter() - tick
            store.append(frames[0][:written], frames[1][:written], frames[2][:written])
            ledger.append(frames[3][:written])
            if code != OK:
                status, bad_node = BLEW_UP, node
                break
            if on_progress is not None:
                on_progress(integrator.t, scene.integrator.t_end)
            if elapsed > 0:
                rate = done / elapsed
                chunk = _round_to(max(1, int(rate * target_chunk_seconds)), grid.save_every)
    wall = time.perf_counter() - start

    stable_dt = None
    if status == BLEW_UP:
        stable_dt, message = _blow_up_message(model, integrator, code, bad_node)

    return RunOutcome(status=status, steps=integrator.step, t_reached=integrator.t, wall_time=wall,
                      compile_time=compile_time, grid=grid, message=message, bad_node=bad_node, stable_dt=stable_dt,
                      ledger=np.concatenate(ledger), energy0=float(integrator.ledger[E0]),
                      force_evaluations=integrator.force_evaluations)


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
    if np.isfinite(bound) and bound > 0 and grid.dt > 0.5 * bound:
        stable_dt = 0.5 * bound
    else:
        stable_dt = 0.25 * grid.dt
    return stable_dt, (f"blew up at t = {integrator.t:.6g} s (step {integrator.step}): {what}, with dt = {grid.dt:.3g} s and "
                       f"method {method}; a time step of {stable_dt:.3g} s or less would be stable")


def _round_to(n: int, multiple: int) -> int:
    """``n`` rounded to a positive multiple of ``multiple`` (so chunks end on saved frames)."""
    return max(multiple, (n // multiple) * multiple)


def simulate(scene: Scene, folder: str | Path | None = None, progress: bool = False):
    """Run ``scene`` and return its :class:`~ropesim.trajectory.Trajectory`.

    With ``folder`` the run also writes ``trajectory.npz``, ``scene.toml`` and ``summary.json`` there, each
    atomically; frames stream to disk as they are computed. A run that blows up or is interrupted stops
    cleanly: the trajectory holds every frame up to that point and ``summary["status"]`` says what happened.
    """
    from .analysis.ledger import write_ledger
    from .analysis.summary import summarize
    from .scene.schema import scene_to_toml
    from .io.trajectory import SCENE, SUMMARY, FrameStore, Trajectory, write_json_atomic, write_text_atomic

    model = build(scene)
    grid = TimeGrid.of(scene)
    folder = Path(folder) if folder is not None else None
    from .model.tension import frame_arrays, frame_shapes

    store = FrameStore(grid.frames, model.nodes, model.dim, folder,
                       derive=lambda t, x, v: frame_arrays(model, t, x, v), shapes=frame_shapes(model))
    try:
        if folder is not None:
            write_text_atomic(folder / SCENE, scene_to_toml(scene))
        with _progress(progress, scene) as on_progress:
            outcome = integrate(model, store, on_progress)
        arrays = store.arrays()
        summary = summarize(model, outcome, arrays["t"], arrays["x"], arrays["v"], arrays["tension"])
        if folder is not None:
            write_ledger(folder, arrays["t"], outcome.ledger, outcome.energy0)
            store.finish()
            write_json_atomic(folder / SUMMARY, summary)
            return Trajectory.open(folder)
        return Trajectory(t=arrays["t"], x=arrays["x"], v=arrays["v"], scene=scene, summary=summary,
                          tension=arrays["tension"], strain=arrays["strain"], support=arrays.get("support"))
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
