"""The run summary (``summary.json``): how the run went, its energy, and the scene's own figures."""

from __future__ import annotations

import numpy as np

from .. import __version__
from ..model.build import Model
from ..model.forces.springs import segment_strains
from ..model.tension import line_segments
from ..model.bodies import free_body_state
from ..model.energy import energy_terms
from .ledger import ledger_series, ledger_summary
from .stability import predicted_dt
from .tension import tension_figures
from .towed import towed_end, towed_figures

FRAME_BLOCK = 256  # frames per block when scanning a (possibly memory-mapped) trajectory
BLOCK_BYTES = 16 * 2 ** 20  # and at most this many bytes of one array per block: a big rope's frames are big


def block_frames(frame_nbytes: int, block: int | None = None) -> int:
    """Frames per block: ``block`` (default FRAME_BLOCK), fewer when that many frames exceed BLOCK_BYTES."""
    return max(1, min(block or FRAME_BLOCK, BLOCK_BYTES // max(1, frame_nbytes)))


def clean_time(t: float) -> float:
    """A frame time [s] without the float noise of k * interval (20.900000000000002 -> 20.9): 12 digits."""
    return float(f"{float(t):.12g}")


def largest_stretch(model: Model, x: np.ndarray) -> tuple[float, float]:
    """The largest relative spring stretch |r| / l - 1 over all saved frames (a peak between two frames is not
    seen), and the frame index where it occurs."""
    best, where = -np.inf, 0
    block = block_frames(x[0].nbytes)
    for start in range(0, len(x), block):
        stretch = segment_strains(model, x[start:start + block])
        per_frame = stretch.max(axis=1)
        k = int(np.argmax(per_frame))
        if per_frame[k] > best:
            best, where = float(per_frame[k]), start + k
    return best, where


def summarize(model: Model, outcome, t: np.ndarray, x: np.ndarray, v: np.ndarray,
              tension: np.ndarray | None = None, bodies: dict | None = None) -> dict:
    """Everything a user wants to know about a finished (or stopped) run, as JSON-ready values; with the frames'
    ``tension`` (F, S) also the tension at both ends and the largest (see :mod:`ropesim.analysis.tension`);
    ``bodies`` the rigid bodies' per-frame arrays (body_x, ...), for the energy ledger. The arrays are stored in
    the scene's own frame (:mod:`ropesim.scene.frame`); the figures are computed in the model's y-up one."""
    from ..scene.frame import frame_of

    scene = model.scene
    frame = frame_of(scene)
    x, v, bodies = frame.into(x), frame.into(v), None if bodies is None else frame.arrays_into(bodies)
    grid = outcome.grid
    node_steps = outcome.steps * model.nodes
    summary: dict = {
        "scene": scene.name,
        "ropesim_version": __version__,
        "status": outcome.status,
        "t_end": clean_time(t[-1]),
        "t_end_requested": scene.integrator.t_end,
        "method": scene.integrator.method,
        "dt": grid.dt,
        "steps": outcome.steps,
        "frames": int(len(t)),
        "nodes": model.nodes,
        "wall_time_s": round(outcome.wall_time, 6),
        "compile_time_s": round(outcome.compile_time, 6),
        "steps_per_second": round(outcome.steps / outcome.wall_time, 1) if outcome.wall_time > 0 else None,
        "node_steps_per_second": round(node_steps / outcome.wall_time, 1) if outcome.wall_time > 0 else None,
        "stable_dt_bound": _finite_or_none(predicted_dt(model, scene.integrator.method)),
        "force_evaluations": outcome.force_evaluations,
    }
    report = getattr(getattr(outcome, "integrator", None), "step_report", None)
    adaptive = report() if report is not None else None
    if adaptive is not None:   # galpha with a tolerance: its own steps, and its error estimate
        summary["adaptive_steps"] = adaptive
    if outcome.message:
        summary["message"] = outcome.message
    if grid.dt_adjusted:
        summary["dt_requested"] = grid.requested_dt
    finite = bool(np.all(np.isfinite(x[-1])) and np.all(np.isfinite(v[-1])))
    if finite:
        with np.errstate(over="ignore", invalid="ignore"):  # a run stopped by a blow-up may end huge
            summary.update(_physics_figures(model, t, x, v, bodies))
            summary["energy_ledger"] = ledger_summary(ledger_series(model, x, v, outcome.ledger, outcome.energy0,
                                                                    bodies), outcome.energy0)
            if tension is not None and len(tension):
                block = block_frames(tension[0].nbytes)
                if scene.is_system:
                    summary["lines"] = {line.id: tension_figures(t, tension[:, part], block)
                                        for line, part in zip(model.lines, line_segments(model))}
                else:
                    summary["tension"] = tension_figures(t, tension, block)
    return summary


def _finite_or_none(value: float) -> float | None:
    """JSON has no infinity: an unconditionally stable method has no bound (None)."""
    return float(value) if np.isfinite(value) else None


def _physics_figures(model: Model, t: np.ndarray, x: np.ndarray, v: np.ndarray, bodies: dict | None = None) -> dict:
    """Energy at the last frame (the free bodies' too, from ``bodies``' per-frame arrays), largest stretch, and the
    figures of the parts the scene declares (towed rope, shooter loop)."""
    scene = model.scene
    pose = twist = None
    if bodies is not None:
        last = slice(len(t) - 1, len(t))
        pose, twist = free_body_state(model, bodies, last)
        pose, twist = (None, None) if pose is None else (pose[0], twist[0])
    energy = energy_terms(model, x[-1], v[-1], pose, twist)
    stretch, at = largest_stretch(model, x)
    out: dict = {
        "final_energy_J": {k: float(val) for k, val in energy.items()},
        "max_spring_stretch": stretch,        # a fraction of the rest length (0.01 is 1 %), over the saved frames
        "max_spring_stretch_t": clean_time(t[at]),
    }
    if towed_end(scene) is not None:
        out["towed"] = towed_figures(model, x[-1])
    if scene.thrower is not None and scene.rope is not None and scene.rope.closed:
        from .shooter import shooter_figures

        out["shooter"] = shooter_figures(model, t, x, v)
    return out
