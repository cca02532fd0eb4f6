"""The energy ledger: where the rope's energy came from and went, frame by frame.

The mechanical energy E = kinetic + spring + bending + gravitational (:mod:`ropesim.analysis.energy`) changes
only through what flows in or out: the work W_held that held (pinned or driven) nodes' supports do on the rope,
the work W_box of the thrower box and guide circles, and the energy D lost to drag. The run loop books those
flows inside the compiled kernel with the integrator's own quadrature (exactly within each splitting kick),
so the balance

    residual(t) = E(t) - E(0) - (W_held(t) + W_box(t) - D(t))

is the integrator's energy error alone: it shrinks with dt at the method's order, stays bounded for the
symplectic schemes, and grows when a run is going wrong (an early warning of a blow-up). Runs save the flows
in ``ledger.npz`` beside ``trajectory.npz``: ``t`` (F,), ``drag_loss``, ``held_work``, ``box_work`` (F,) [J]
and ``energy0`` [J].
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..io.runfolder import LEDGER
from ..model.build import Model
from ..integrate.health import LEDGER_COLUMNS
from ..model.bodies import free_body_state
from ..model.energy import energy_terms

FRAME_BLOCK = 256


GAINS = ("held_work", "box_work", "fluid_work", "internal_work", "seabed_work")   # work done on the rope [J]
LOSSES = ("drag_loss",)                                                           # energy taken out [J]


def ledger_arrays(t: np.ndarray, flows: np.ndarray, energy0: float) -> dict[str, np.ndarray]:
    """The arrays of ``ledger.npz``: ``t``, one array per column of the cumulative flows (F, C), ``energy0``."""
    arrays = {"t": np.asarray(t)[:len(flows)]}
    arrays.update({name: np.ascontiguousarray(flows[:, c]) for c, name in enumerate(LEDGER_COLUMNS)})
    arrays["energy0"] = np.array(energy0)
    return arrays


def write_ledger(folder: Path, t: np.ndarray, flows: np.ndarray, energy0: float) -> None:
    """Write ``ledger.npz`` atomically: the cumulative flows (F, C) at the saved frames' times."""
    from ..io.runfolder import write_npz_atomic

    write_npz_atomic(Path(folder) / LEDGER, ledger_arrays(t, flows, energy0))


def ledger_series(model: Model, x: np.ndarray, v: np.ndarray, flows: np.ndarray, energy0: float,
                  bodies=None) -> dict:
    """Every term of the ledger per frame [J]: the energy terms, the flows and the residual.

    ``x``, ``v`` are (F, N, D) frames (possibly memory-mapped; read in blocks), ``flows`` (F, C); ``bodies`` what
    holds the rigid bodies' per-frame arrays (a Trajectory or a dict; see
    :func:`ropesim.model.bodies.free_body_state`), needed when the scene has free bodies.
    """
    blocks = [energy_terms(model, x[s:s + FRAME_BLOCK], v[s:s + FRAME_BLOCK],
                           *free_body_state(model, bodies, slice(s, s + FRAME_BLOCK)))
              for s in range(0, len(flows), FRAME_BLOCK)]
    out = {key: np.concatenate([b[key] for b in blocks]) for key in blocks[0]} if blocks else {}
    for c, name in enumerate(LEDGER_COLUMNS):
        out[name] = flows[:, c]
    flowed = sum(out[name] for name in GAINS) - sum(out[name] for name in LOSSES)
    out["residual"] = out["total"] - energy0 - flowed
    return out


def ledger_summary(series: dict, energy0: float) -> dict:
    """The balance at the end: each flow, the residual, and the residual relative to the energy that flowed.

    "Energy that flowed" is the largest D + sum |W| reached or, when larger (as in a closed system,
    where nothing flows), the largest change of any single energy term (the energy that moved between terms),
    so the relative residual is always measured against energy that actually moved. ``residual_growth`` compares the
    largest |residual| in the last and the first half of the run: well above 1 on a run that is going wrong.
    """
    residual = np.abs(series["residual"])
    flowed = sum(series[name] for name in LOSSES) + sum(np.abs(series[name]) for name in GAINS)
    moved = float(flowed.max()) if len(flowed) else 0.0
    terms = [k for k in series if k not in ("total", "residual", *GAINS, *LOSSES)]
    exchanged = max(float(np.ptp(series[k])) for k in terms) if len(residual) else 0.0
    basis = "flows"
    if exchanged > moved:
        basis, moved = "exchange", exchanged
    half = len(residual) // 2
    first = float(residual[:max(half, 1)].max()) if len(residual) else 0.0
    last = float(residual[half:].max()) if len(residual) else 0.0
    return {
        "energy0_J": energy0,
        "energy_J": float(series["total"][-1]),
        "drag_loss_J": float(series["drag_loss"][-1]),
        "held_work_J": float(series["held_work"][-1]),
        "box_work_J": float(series["box_work"][-1]),
        "fluid_work_J": float(series["fluid_work"][-1]),
        "internal_work_J": float(series["internal_work"][-1]),
        "seabed_work_J": float(series["seabed_work"][-1]),
        "residual_J": float(series["residual"][-1]),
        "max_residual_J": float(residual.max()) if len(residual) else 0.0,
        "energy_flowed_J": moved,
        "relative_to": basis,
        "relative_residual": float(residual.max() / moved) if moved > 0 else 0.0,
        "residual_growth": last / first if first > 0 else (0.0 if last == 0 else float("inf")),
    }
