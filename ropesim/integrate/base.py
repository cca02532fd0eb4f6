"""The integrator contract: what a method and its family provide, and the bundles their compiled loops take.

A *method* is one name in :data:`ropesim.integrate.methods.METHODS` (``symplectic_euler``, ``rk4``, ...): a
:class:`Method` record, the same name in TOML (``integrator.method``), on the command line and in code. A
*family* is the :class:`Integrator` subclass that runs a kind of method (splitting schemes, explicit
Runge-Kutta, the stiff SDIRK), one module each. ``ropesim.run`` looks the name up, builds
``method.family(model, grid, method)`` and calls :meth:`Integrator.advance` chunk after chunk; it never asks
which family it holds.

To add a method of an existing family, give its coefficients (a splitting scheme's drift and kick
coefficients, a Runge-Kutta method's Butcher table), its order and a line of documentation, and list it in
``METHODS``. To add a family, write one module with:

1. A :class:`Method` subclass: ``name``, ``order``, ``doc``, ``kind`` (a word for people, e.g. "splitting";
   nothing branches on it), ``evaluations`` (force evaluations per step), :meth:`Method.amplification` (one
   step's 2x2 map of the damped oscillator x'' = -omega^2 x - gamma x', from which :func:`stable_step` finds
   the stability bound) and ``family`` (the class below). Flags say what the stability bound must know:
   ``drag_explicit`` (the method integrates linear drag explicitly, so it limits the step),
   ``exact_contact_kicks`` (the thrower's and guides' damping is integrated exactly) and
   ``unconditionally_stable``.
2. An :class:`Integrator` subclass whose ``__init__(model, grid, method)`` calls ``super().__init__`` (which
   sets x, v, the ledger, the health limits, the held nodes, the step counter and the compile-time switches)
   and builds the family's own state and scratch arrays from the :class:`~ropesim.model.build.Model`, and
   which provides:

   - :meth:`Integrator.template`: its compiled loop (a template, see :func:`ropesim.model.jit.specialise`),
     and, if the family adds compile-time switches of its own to the model's (its terms, prescribed motion),
     :meth:`Integrator.switches_for` (the splitting family's plain stage). ``super().__init__`` sets
     ``self.loop``, the loop's copy for this run's switches;
   - :meth:`Integrator._run` ``(n, frames)``: call ``self.loop`` for ``n`` steps from ``self.step``, returning
     ``(steps done, frames written, status, node)``;
   - :attr:`Integrator.force_evaluations`: force evaluations so far (Newton iterations for an implicit
     method);
   - ``STATE``: the names of its attributes (arrays, updated in place) that, with x, v, the ledger and the
     step, make up its *complete* state: restoring them continues a run bit for bit (resume needs this).

3. Its compiled loop, which must, for global steps step0 + 1 ... step0 + n (time = step * h):

   - advance x and v (D, N) in place by uniform steps h, every force evaluated through the term list
     (:func:`ropesim.model.terms.accelerations`) unless the family has a proved specialisation;
   - keep every held node exactly on x0 + V t at every stage time t, with velocity V;
   - treat linear drag (per-node b, ``Model.drag``) so that the method keeps its declared order;
   - book the energy ledger (:mod:`ropesim.integrate.health`): drag loss, held-node work, the applied
     terms' work (:func:`ropesim.model.terms.applied_accelerations`), each with a quadrature of the
     method's own order, so that E(t) - E(0) - flows is the integration error alone;
   - check the state's health every ``check_every`` global steps and at every saved frame, and stop at the
     first problem, returning its status and node (:func:`ropesim.integrate.health.verdict`);
   - save a frame after every global step s with s % save_every == 0 or s == total_steps;
   - give the same numbers however the run is cut into calls (the schedule is global, the state complete).

Bundles: compiled loops take a handful of namedtuples (Numba compiles them as structs) instead of long
argument lists: :class:`Schedule` (scalars), :class:`Frames` and :class:`Held` (arrays), the model's
:class:`~ropesim.model.terms.ModelParams`, and the family's own state and scratch bundles. A bundle is handed
over once per call; inside the loop, per-node helpers take scalars, since every array handed to a compiled
helper that is not inlined costs an atomic reference-count update.

What a new *force term* must provide (its file in ``model/forces/``, its line in ``model/terms.py``) is
listed in :class:`ropesim.model.forces.Term`; the families reach every term through the term list and the
hooks, never by name.
"""

from __future__ import annotations

import math
import time
from collections import namedtuple
from functools import lru_cache

import numpy as np

from ..model.bodies import STATE_ROWS, place_attachments
from ..model.jit import specialise
from ..model.motion import Held, place_moving
from .health import LEDGER_COLUMNS, OK, initial_ledger, limits

CHECK_EVERY = 64   # steps between blow-up checks: a blow-up is caught within this many steps

Schedule = namedtuple("Schedule", ["step0", "n_steps", "total_steps", "h", "save_every", "check_every"])
SCHEDULE_AT = -3     # where the Schedule sits among a loop's arguments (Integrator.loop_args)
"""Which steps a call runs: from global step ``step0``, ``n_steps`` steps of ``h`` [s] out of ``total_steps``;
a frame every ``save_every`` steps and at the last, a health check every ``check_every``."""

Frames = namedtuple("Frames", ["t", "x", "v", "ledger", "body"])
"""Frame buffers of one call: t (F,) [s], x and v (F, D, N) [m, m/s], the ledger's flows (F, C) [J], the free
rigid bodies' pose and twist (F, 13, B) (:mod:`ropesim.model.bodies`)."""

BodyState = namedtuple("BodyState", ["pose", "twist"])
"""The free rigid bodies' state: pose (7, B) (reference point, orientation quaternion), twist (6, B) (velocity,
angular velocity in world axes); see :mod:`ropesim.model.bodies`."""


Advance = namedtuple("Advance", ["done", "written", "status", "node"])
"""What a call did: steps done, frames written, health status (:mod:`ropesim.integrate.health`), its node."""


class Method:
    """One integration method: its name, order and documentation, its stability, and the family that runs it."""

    name: str
    order: int
    doc: str
    kind: str
    drag_explicit = False          # linear drag evaluated explicitly (it then limits the stable step)
    exact_contact_kicks = False    # the thrower's and guides' damping integrated exactly when their edges are smooth
    unconditionally_stable = False
    starts_from_x_and_v = True     # a step needs x and v alone (generalized-alpha also carries an acceleration)

    @property
    def family(self) -> type:
        """The :class:`Integrator` subclass that runs this method."""
        raise NotImplementedError

    @property
    def evaluations(self) -> int:
        """Force evaluations per step."""
        raise NotImplementedError

    @property
    def backward_kicks(self) -> bool:
        """True when a step contains a kick backwards in time (it amplifies by drag; see stable_step)."""
        return False

    @property
    def kick_span(self) -> float:
        """The largest |kick coefficient| of a splitting scheme (its longest velocity kick, in steps); 0 for a
        method without kicks."""
        return 0.0

    def amplification(self, h: float, omega: float, gamma_force: float = 0.0, gamma_drag: float = 0.0):
        """One step's 2x2 map of (x, v) for x'' = -omega^2 x - gamma_force x' - gamma_drag x'."""
        raise NotImplementedError

    @property
    def stability_limit(self) -> float:
        """Largest h omega for which the method stays bounded on a harmonic oscillator x'' = -omega^2 x."""
        return stable_step(self, 1.0)


def spectral_radius(m) -> float:
    """The largest |eigenvalue| of a real 2x2 matrix, from its trace and determinant (NaN if not finite)."""
    (a, b), (c, d) = m
    half, det = 0.5 * (a + d), a * d - b * c
    disc = half * half - det
    if disc >= 0.0:
        root = math.sqrt(disc)
        return max(abs(half + root), abs(half - root))
    return math.sqrt(det) if det >= 0.0 else math.nan   # a complex pair: |lambda|^2 = det (NaN: not finite)


def _stable(method: Method, h: float, omega: float, gamma_force: float, gamma_drag: float) -> bool:
    try:
        m = method.amplification(h, omega, gamma_force, gamma_drag)
    except OverflowError:   # a backward kick's e^(gamma |c| h) beyond the float range: the kernel's factor is inf
        return False
    return spectral_radius(m.tolist()) <= 1.0 + 1e-9   # False for inf and NaN entries


@lru_cache(maxsize=4096)
def stable_step(method: Method, omega: float, gamma_force: float = 0.0, gamma_drag: float = 0.0) -> float:
    """Largest step h [s] for which ``method`` stays bounded on x'' = -omega^2 x - (gamma_force + gamma_drag) x'.

    ``gamma_force`` [1/s] is damping the method evaluates explicitly (the thrower's and guides'), ``gamma_drag``
    [1/s] the scene's linear drag (exact inside the splitting schemes' kicks, explicit in Runge-Kutta).
    Infinite for an unconditionally stable method or when nothing oscillates or damps.
    """
    if method.unconditionally_stable:
        return math.inf
    rate = max(omega, gamma_force + (gamma_drag if method.drag_explicit else 0.0))
    if rate <= 0.0:
        return math.inf
    h, factor = 1e-3 / max(rate, gamma_drag if method.backward_kicks else 0.0), 1.01
    while h * rate < 20.0 and _stable(method, h * factor, omega, gamma_force, gamma_drag):
        h *= factor
    lo, hi = h, h * factor
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if _stable(method, mid, omega, gamma_force, gamma_drag) else (lo, mid)
    return lo


class Integrator:
    """A family's integrator for one model, method and time grid: its complete state and its compiled loop.

    ``advance(n)`` moves it n steps forward (see the module doc for what a family provides). Besides x and v
    it carries the energy ledger (``ledger``: drag loss, work of held nodes, work of the box and guides,
    initial energy, energy scale; see :mod:`ropesim.integrate.health`) and the step counter.
    """

    STATE: tuple[str, ...] = ()

    def __init__(self, model, grid, method: Method):
        self.model, self.grid, self.method = model, grid, method
        self.x = model.x0.copy()
        self.v = model.v0.copy()
        self.step = 0
        motion = model.motion._replace(accel=model.motion.accel.copy())
        self.held = Held(model.held_idx, model.held_x0, model.held_v.copy(), motion)
        if motion.moving:
            model.kernel(place_moving)(self.x, self.v, self.held, 0.0, 0.0)   # a sinusoid starts with its own velocity
        self.pose = model.body_pose0.copy()
        self.twist = model.body_twist0.copy()
        # None without free bodies: the loops read it only behind WITH_BODIES, and compile nothing of it
        self.bodies = BodyState(self.pose, self.twist) if self.pose.shape[1] else None
        if self.pose.shape[1]:
            place_attachments(self.x, self.v, model.params.bodies, self.pose, self.twist)
        self.ledger = initial_ledger(model, self.x, self.v, self.pose, self.twist)
        self.limits = limits(model)
        self.switches = self.switches_for(model, method)
        self.loop = self.kernel(self.template())

    def kernel(self, function):
        """``function`` (a compiled template) specialised on this run's switches."""
        return specialise(function, self.switches)

    @classmethod
    def compiled_loop(cls, model, method: Method):
        """The copy of the family's loop a run of ``method`` on ``model`` calls (without building the run)."""
        return specialise(cls.template(), cls.switches_for(model, method))

    # -- what a family provides --------------------------------------------------------------------------

    @staticmethod
    def template():
        """The family's compiled loop, a template (see :func:`ropesim.model.jit.specialise`)."""
        raise NotImplementedError

    @classmethod
    def switches_for(cls, model, method: Method) -> frozenset:
        """The compile-time switches of a run of ``method`` on ``model``: the model's, and the family's own."""
        return model.switches

    def _run(self, n: int, frames: Frames) -> tuple:
        """Run the compiled loop for ``n`` steps from ``self.step``; (steps done, frames written, status, node)."""
        return self.loop(*self.loop_args(n, frames))

    def loop_args(self, n: int, frames: Frames) -> tuple:
        """The compiled loop's arguments for ``n`` steps from ``self.step``: the integrator's own arrays and
        bundles (the same objects for its whole life: :meth:`restore` copies into them), the :class:`Schedule` at
        index :data:`SCHEDULE_AT`, then ``frames`` and the bodies' bundle."""
        raise NotImplementedError

    @property
    def force_evaluations(self) -> int:
        """Force evaluations so far."""
        raise NotImplementedError

    # -- shared ----------------------------------------------------------------------------------------------

    @property
    def last_accelerations(self) -> np.ndarray | None:
        """The accelerations (D, N) of the loop's last force evaluation, when the family's last evaluation of a step
        is at the step's end time with every held node where its motion puts it then, so that its held columns are
        the held nodes' net force per unit mass at the end of the last step (:mod:`ropesim.coupling` reports
        them); None when it is not."""
        return None

    @property
    def t(self) -> float:
        return self.step * self.grid.dt

    def schedule(self, n: int) -> Schedule:
        g = self.grid
        return Schedule(self.step, n, g.steps, g.dt, g.save_every, CHECK_EVERY)

    def frames_in(self, n: int) -> int:
        """Frames saved by the next ``n`` steps."""
        e, end = self.grid.save_every, self.step + n
        count = end // e - self.step // e
        if end == self.grid.steps and end % e:
            count += 1
        return count

    def new_frames(self, n: int) -> Frames:
        """Empty frame buffers for the next ``n`` steps."""
        k = self.frames_in(n)
        dim, nodes = self.x.shape
        return Frames(np.zeros(k), np.zeros((k, dim, nodes)), np.zeros((k, dim, nodes)),
                      np.zeros((k, len(LEDGER_COLUMNS))), np.zeros((k, STATE_ROWS, self.pose.shape[1])))

    def advance(self, n: int, frames: Frames | None = None) -> Advance:
        """Run ``n`` steps (fewer if the state goes bad), saving the frames due into ``frames``."""
        if frames is None:
            frames = self.new_frames(n)
        result = Advance(*self._run(n, Frames(*frames)))
        self.step += result.done
        return result

    def warm_up(self) -> float:
        """Compile the loop (or load it from Numba's cache) with a zero-step call; returns the seconds it took."""
        start = time.perf_counter()
        self.advance(0)
        return time.perf_counter() - start

    @property
    def _state_names(self) -> tuple[str, ...]:
        return ("x", "v", "ledger", *(("pose", "twist") if self.pose.shape[1] else ()), *self.STATE)

    def body_rows(self) -> np.ndarray:
        """The free rigid bodies' state now (13, B): pose, then twist (a saved frame's body rows)."""
        return np.concatenate([self.pose, self.twist])

    def state(self) -> dict[str, np.ndarray]:
        """The complete state, as named arrays (copies): restoring it continues the run bit for bit."""
        out = {"step": np.array(self.step, dtype=np.int64)}
        for name in self._state_names:
            out[name] = np.array(getattr(self, name), copy=True)
        return out

    def restore(self, state: dict[str, np.ndarray]) -> None:
        """Continue from ``state`` (from :meth:`state`, of the same model, method and grid).

        Arrays are copied into place, so the bundles the compiled loop holds keep pointing at them.
        """
        for name in self._state_names:
            mine = getattr(self, name)
            if name not in state:
                raise ValueError(f"saved state has no {name!r}")
            theirs = np.asarray(state[name])
            if theirs.shape != mine.shape or theirs.dtype != mine.dtype:
                raise ValueError(f"saved state {name!r} has shape {theirs.shape} ({theirs.dtype}); this run needs "
                                 f"{mine.shape} ({mine.dtype})")
            np.copyto(mine, theirs)
        self.step = int(state["step"])


PROBE_STEPS = 16   # the first chunk: its wall time measures the rate (a scene's cost per step is not known
                   # before: contact and fluid terms make some scenes 100 times dearer per node than others)


class ChunkSizer:
    """Chunk lengths bounded in wall time: control comes back to Python (signals, checkpoints, progress) about
    every ``seconds``, whatever a step costs. The first chunk is a short probe; each next one is the measured
    rate times ``seconds``, grown at most GROWTH times per chunk (a rate measured on a short chunk may be off),
    rounded down to whole saved frames when it covers one or more. The numbers never depend on the cuts."""

    GROWTH = 4

    def __init__(self, seconds: float, save_every: int = 1, first: int = PROBE_STEPS):
        self.seconds, self.save_every, self.steps = seconds, save_every, max(1, first)

    def measured(self, done: int, elapsed: float) -> None:
        if done <= 0:
            return
        wanted = done * self.seconds / elapsed if elapsed > 0 else done * self.GROWTH
        n = max(1, min(int(wanted), done * self.GROWTH))
        self.steps = n - n % self.save_every if n >= self.save_every else n


def advance_in_chunks(integrator: Integrator, steps: int, target_chunk_seconds: float = 0.1):
    """``integrator.advance(steps)`` cut into chunks of about ``target_chunk_seconds`` of wall time (see
    :class:`ChunkSizer`; the numbers are the same however it is cut), so that Ctrl-C or SIGTERM are honoured
    within a chunk instead of after the whole run. Returns the last chunk's Advance with ``done`` summed; stops
    at the first bad status."""
    done, result = 0, None
    chunks = ChunkSizer(target_chunk_seconds)
    while done < steps or result is None:
        n = min(chunks.steps, steps - done)
        tick = time.perf_counter()
        result = integrator.advance(n)
        chunks.measured(result.done, time.perf_counter() - tick)
        done += result.done
        if result.status != OK or n == 0:
            break
    return result._replace(done=done)
