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

from .model.build import Model, build
from .integrate.health import NEWTON_FAILED, NON_FINITE, OK, OVERSTRETCH, RUNAWAY_ENERGY
from .integrate.splitting import advance, get_method, kick_factors
from .scene.schema import Scene

COMPLETED, INTERRUPTED, BLEW_UP = "completed", "interrupted", "blew_up"
CHECK_EVERY = 64  # steps between finiteness checks: a blow-up is caught within this many steps
FRAME_BUFFER_BYTES = 16 * 2 ** 20  # at most this many bytes of saved frames are held in memory between chunks


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
        # at most every step count: an interval past t_end saves t = 0 and t_end alone (and never overflows)
        save_every = max(1, round(min(scene.output.interval / h, max(steps, 1))))
        return cls(dt=h, steps=steps, save_every=save_every, requested_dt=dt)

    @property
    def frames(self) -> int:
        """Saved frames, t = 0 included: every save_every-th step and the last one."""
        return 1 + self.steps // self.save_every + (1 if self.steps % self.save_every else 0)

    @property
    def dt_adjusted(self) -> bool:
        return abs(self.dt - self.requested_dt) > 1e-12 * self.requested_dt


class Stepper:
    """The scene's state and the compiled step loop of its method; ``advance(n)`` moves it n steps forward.

    A splitting scheme on a plain 2-D spring rope runs on the fast path of :mod:`ropesim.chain` (``chain`` holds
    its arrays; None otherwise).

    Besides x and v it carries the energy ledger (``ledger``: drag loss, work of held nodes, work of the box
    and guides, initial energy, energy scale; see :mod:`ropesim.health`) and, for the stiff integrator, the
    Newton iterations so far (``stats``).
    """

    def __init__(self, model: Model, method: str, grid: TimeGrid, specialise: bool = True):
        """``specialise=False`` keeps a plain spring rope off the fast path of :mod:`ropesim.chain` (for tests)."""
        from .analysis.energy import energy_terms
        from .integrate.health import E0, LEDGER_SIZE, SCALE

        self.model, self.grid = model, grid
        self.scheme = get_method(method)
        self.x = model.x0.copy()
        self.v = model.v0.copy()
        self.acc = np.zeros_like(self.x)
        self.acc_box = np.zeros_like(self.x)
        self.have_acc = np.zeros(1, dtype=np.bool_)
        self.stats = np.zeros(1, dtype=np.int64)
        self.step = 0
        self.ledger = np.zeros(LEDGER_SIZE)
        self.ledger[E0] = float(energy_terms(model, self.x.T, self.v.T)["total"])
        self.ledger[SCALE] = energy_scale(model)
        self.limits = np.array([stretch_limit(model), RUNAWAY_FACTOR, RUNAWAY_FLOW_FRACTION])
        self.held = (model.held_idx, model.held_x0, model.held_v)
        kind = self.scheme.kind
        self.chain = None
        if kind == "splitting":
            self.reuse_force = self.scheme.reuses_last_force and not model.velocity_dependent
            self.drift = np.array(self.scheme.drift)
            self.kick = np.array(self.scheme.kick)
            self.decay, self.gain, self.travel = kick_factors(self.scheme, grid.dt, model.drag, model.mass,
                                                              model.held)
            from .analysis.stability import smooth_contacts

            self.exact_contacts = smooth_contacts(model)  # exact kicks for nodes touching the box or a circle
            self.contact_scratch = (np.ascontiguousarray(~model.held), np.where(model.held, 0.0, model.drag / model.mass),
                                    np.zeros_like(self.x), np.zeros(model.nodes, dtype=np.int64))
            from .integrate import chain

            self.chain = (chain.ChainState(model, self.decay, self.gain, self.travel)
                          if specialise and chain.applies(model, self.scheme) else None)
        elif kind == "rk":
            self.tables = self.scheme.tables()
            stages = len(self.scheme.b)
            self.xs, self.vs = np.zeros_like(self.x), np.zeros_like(self.x)
            self.kx = np.zeros((stages,) + self.x.shape)
            self.kv = np.zeros((stages,) + self.x.shape)
            self.gamma = np.where(model.held, 0.0, model.drag / model.mass)
        else:
            from .integrate.sdirk import NEWTON_TOL, band_width, scratch

            scene = model.scene
            bending = scene.bending is not None
            self.band_w, self.cyclic = band_width(scene.rope.closed, model.nodes, bending)
            self.work = scratch(model.dim, model.nodes, bending, scene.rope.closed)
            self.free = ~model.held
            self.newton_tol = NEWTON_TOL * scene.rope.segment_length
            self.drag = np.where(model.held, 0.0, model.drag)

    @property
    def t(self) -> float:
        return self.step * self.grid.dt

    @property
    def force_evaluations(self) -> int:
        """Force evaluations so far (for the stiff integrator, its Newton iterations)."""
        if self.scheme.kind == "implicit":
            return int(self.stats[0])
        if self.scheme.kind == "splitting":  # velocity-dependent forces rule out reusing the last kick's forces
            return self.step * (len(self.scheme.kick) - (1 if self.reuse_force else 0))
        return self.step * self.scheme.evaluations

    def frames_in(self, n: int) -> int:
        """Frames saved by the next ``n`` steps."""
        e, end = self.grid.save_every, self.step + n
        count = end // e - self.step // e
        if end == self.grid.steps and end % e:
            count += 1
        return count

    def new_frames(self, n: int) -> tuple:
        """Empty frame buffers (t, x, v, ledger) for the next ``n`` steps."""
        from .integrate.health import LEDGER_COLUMNS

        k = self.frames_in(n)
        dim, nodes = self.x.shape
        return (np.zeros(k), np.zeros((k, dim, nodes)), np.zeros((k, dim, nodes)), np.zeros((k, len(LEDGER_COLUMNS))))

    def advance(self, n: int, frames: tuple | None = None):
        """Run ``n`` steps; returns (steps done, frames written, status, node)."""
        if frames is None:
            frames = self.new_frames(n)
        m, g = self.model, self.grid
        kind = self.scheme.kind
        if kind == "splitting" and self.chain is not None:
            from .integrate.chain import advance_chain

            c = self.chain
            done, written, status, node = advance_chain(
                self.x, self.v, c.spring_forces, c.lost, self.ledger, self.have_acc, self.step, n, g.steps, g.dt, self.drift,
                self.kick, c.bulk, c.exceptions, c.exception_factors, c.saved, self.reuse_force, self.held, m.mass,
                m.forces, c.free_mass, c.kinetic0, c.has_drag, c.scratch, self.limits, g.save_every, frames,
                CHECK_EVERY)
        elif kind == "splitting":
            done, written, status, node = advance(
                self.x, self.v, self.acc, self.acc_box, self.have_acc, self.ledger, self.step, n, g.steps, g.dt,
                self.drift, self.kick, self.decay, self.gain, self.travel, self.reuse_force, self.held, m.mass,
                m.forces, self.limits, g.save_every, frames, CHECK_EVERY, (self.exact_contacts, *self.contact_scratch))
        elif kind == "rk":
            from .integrate.rk import advance_rk

            a, b, c = self.tables
            done, written, status, node = advance_rk(
                self.x, self.v, self.xs, self.vs, self.kx, self.kv, self.acc, self.acc_box, self.ledger, self.step,
                n, g.steps, g.dt, a, b, c, self.gamma, self.held, m.mass, m.forces, self.limits, g.save_every,
                frames, CHECK_EVERY)
        else:
            from .integrate.sdirk import advance_sdirk

            done, written, status, node = advance_sdirk(
                self.x, self.v, self.acc, self.acc_box, self.ledger, self.stats, self.step, n, g.steps, g.dt,
                self.band_w, self.cyclic, self.newton_tol, self.held, self.free, m.mass, self.drag, m.forces,
                self.limits, g.save_every, frames, CHECK_EVERY, self.work)
        self.step += done
        return done, written, status, node

    def warm_up(self) -> float:
        """Compile the kernel (or load it from cache) with a zero-step call; returns the seconds it took."""
        start = time.perf_counter()
        self.advance(0)
        return time.perf_counter() - start


RUNAWAY_FACTOR = 1.0      # a blow-up: energy balance off by this times the initial energy scale ...
RUNAWAY_FLOW_FRACTION = 0.2  # ... plus this fraction of the energy that flowed in and out
STRETCH_SANITY = 4.0      # a spring longer than this many rest lengths (or 4x its static strain) is a blow-up


def energy_scale(model: Model) -> float:
    """The energy scale [J] a blow-up is measured against (before the flows are added, see health.py).

    Initial kinetic and elastic energy, plus the rope's weight times its length (what gravity can convert),
    plus every spring stretched by 1 % (so a rope at rest in zero gravity still has a scale).
    """
    from .analysis.energy import energy_terms

    scene, rope = model.scene, model.scene.rope
    g = scene.gravity.g if scene.gravity is not None else 0.0
    terms = energy_terms(model, model.x0.T, model.v0.T)
    moving = float(terms["total"] - terms.get("gravity", 0.0))
    length = rope.nodes * rope.segment_length
    springs = rope.nodes
    return abs(moving) + float(model.mass.sum()) * g * length + springs * 0.5 * rope.stiffness * (
        0.01 * rope.segment_length) ** 2


def stretch_limit(model: Model) -> float:
    """Largest sane spring length / rest length [-].

    STRETCH_SANITY, or 1 + STRETCH_SANITY times the strain the rope's whole static load would cause (its
    weight, drag at the held nodes' speed, the thrower's full drive on the nodes its box can hold), or twice
    the longest spring at t = 0, whichever is largest. Stable runs of the built-in scenes stay below 1.7; an
    unstable one that saturates instead of overflowing (bounded garbage) goes past it within a few steps.
    """
    from .model.forces.springs import pair_spring_stretch

    scene, rope = model.scene, model.scene.rope
    g = scene.gravity.g if scene.gravity is not None else 0.0
    load = float(model.mass.sum()) * g
    if model.held_v.size:
        load += float(model.drag.sum()) * float(np.abs(model.held_v).max())
    if scene.thrower is not None:
        in_box = min(rope.nodes, scene.thrower.length / rope.segment_length + 1)
        load += in_box * scene.thrower.b_thrower * abs(scene.thrower.v_max)
    initial = float(np.max(pair_spring_stretch(model.x0.T, rope.segment_length, 1, rope.closed), initial=0.0)) + 1.0
    return max(STRETCH_SANITY, 1.0 + STRETCH_SANITY * load / (rope.stiffness * rope.segment_length), 2.0 * initial)


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
        stepper = Stepper(model, scene.integrator.method, grid)
        store.append(np.zeros(1), stepper.x[None], stepper.v[None])
        ledger = [np.zeros((1, 3))]
        status, bad_node, message, code = "completed", -1, "", OK
        chunk = max(1, min(grid.steps, 20_000_000 // max(1, model.nodes * stepper.scheme.evaluations)))
        chunk = _round_to(chunk, grid.save_every)
        frame_cap = grid.save_every * max(1, FRAME_BUFFER_BYTES // (2 * 8 * model.nodes * model.dim))
        compile_time = stepper.warm_up()
        start = time.perf_counter()
        while stepper.step < grid.steps:
            if interrupted.is_set() or (stop is not None and stop()):
                status = INTERRUPTED
                message = f"interrupted at t = {stepper.t:.6g} s (step {stepper.step} of {grid.steps})"
                break
            n = min(chunk, frame_cap, grid.steps - stepper.step)
            frames = stepper.new_frames(n)
            tick = time.perf_counter()
            done, written, code, node = stepper.advance(n, frames)
            elapsed = time.perf_counter() - tick
            store.append(frames[0][:written], frames[1][:written], frames[2][:written])
            ledger.append(frames[3][:written])
            if code != OK:
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
        stable_dt, message = _blow_up_message(model, stepper, code, bad_node)
    from .integrate.health import E0

    return RunOutcome(status=status, steps=stepper.step, t_reached=stepper.t, wall_time=wall,
                      compile_time=compile_time, grid=grid, message=message, bad_node=bad_node, stable_dt=stable_dt,
                      ledger=np.concatenate(ledger), energy0=float(stepper.ledger[E0]),
                      force_evaluations=stepper.force_evaluations)


def _sharp_contacts(scene: Scene) -> bool:
    """True when the scene has a thrower box or guide circles whose edges switch sharply."""
    return (scene.thrower is not None and scene.thrower.edge_width == 0) or any(g.edge_width == 0
                                                                                  for g in scene.guides)


def _blow_up_message(model: Model, stepper: Stepper, code: int, node: int) -> tuple[float | None, str]:
    """(a time step that would be stable, one line saying when, where and how the run blew up)."""
    from .analysis.stability import predicted_dt

    scene, grid = model.scene, stepper.grid
    method = scene.integrator.method
    what = {
        NON_FINITE: f"node {node} has a non-finite position or velocity",
        OVERSTRETCH: f"the spring after node {node} is stretched beyond {stepper.limits[0]:.3g} times its rest "
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
    return stable_dt, (f"blew up at t = {stepper.t:.6g} s (step {stepper.step}): {what}, with dt = {grid.dt:.3g} s and "
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
    store = FrameStore(grid.frames, model.nodes, model.dim, folder)
    try:
        if folder is not None:
            write_text_atomic(folder / SCENE, scene_to_toml(scene))
        with _progress(progress, scene) as on_progress:
            outcome = integrate(model, store, on_progress)
        arrays = store.arrays()
        summary = summarize(model, outcome, arrays["t"], arrays["x"], arrays["v"])
        if folder is not None:
            write_ledger(folder, arrays["t"], outcome.ledger, outcome.energy0)
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
