"""Error against run time: every integrator over a ladder of time steps, against a far more accurate reference.

For each method and dt the scene runs to t_end and the final node positions are compared with a reference
solution: the largest and the RMS distance of a node from its reference position [m], and the energy error,
which is the energy ledger's residual at t_end (E(t_end) - E(0) minus the energy that flowed in and out; in
a closed system simply E(t_end) - E(0), see :mod:`ropesim.analysis.ledger`). The kernel's wall time is the
median of ``repeats`` runs after a warm-up (compilation excluded); force evaluations (Newton iterations for
the stiff integrator) give a machine-independent cost axis.

The reference is PEFRL, the most accurate method per unit work, at dt_ref = dt_min / 16 (no larger than half
PEFRL's stability bound), and it is checked: a second reference at dt_ref / 2 gives the difference
|ref(dt_ref) - ref(dt_ref / 2)|, an upper estimate of the reference's own error (for an order-p method the
error is that difference over 2^p - 1). Errors within REFERENCE_FLOOR times that difference are marked as
"at the reference floor" and left out of the order fits.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from ..model.build import build
from ..integrate.health import E0, OK, STATUS_NAMES
from ..integrate.methods import METHODS, get_method
from ..scene.schema import Scene
from ..render.style import title_text, with_picture_text
from .stability import predicted_dt

REFERENCE_METHOD = "pefrl"
REFERENCE_REFINEMENT = 16
REFERENCE_FLOOR = 10.0
CSV_COLUMNS = ("method", "dt", "steps", "status", "error_max_m", "error_rms_m", "energy_error_J", "wall_time_s",
               "force_evaluations", "at_reference_floor")


@dataclass
class RunResult:
    x: np.ndarray              # final positions (D, N) [m]
    v: np.ndarray
    status: str
    energy_error: float        # the ledger's residual at t_end [J]
    wall_times: list
    force_evaluations: int
    steps: int


@dataclass
class Row:
    method: str
    dt: float
    steps: int
    status: str
    error_max: float
    error_rms: float
    energy_error: float
    wall_time: float
    force_evaluations: int
    at_floor: bool


@dataclass
class Reference:
    method: str
    dt: float
    x: np.ndarray
    difference: float          # max node distance between the two refinements [m]
    wall_time: float


@dataclass
class Report:
    scene: Scene
    t_end: float
    rows: list
    reference: Reference
    orders: dict               # method -> (observed order or nan, points used)


def single_frame(scene: Scene, dt: float, method: str) -> Scene:
    """``scene`` with ``method`` and ``dt``, saving only the last frame."""
    integ = dataclasses.replace(scene.integrator, method=method, dt=dt)
    out = dataclasses.replace(scene.output, interval=max(scene.integrator.t_end, dt))
    return dataclasses.replace(scene, integrator=integ, output=out)


def run_once(scene: Scene, method: str, dt: float, repeats: int = 1, exact_contacts: bool | None = None) -> RunResult:
    """Run ``scene`` to t_end with ``method`` at ``dt`` ``repeats`` times (timing only the kernel).

    ``exact_contacts`` overrides whether a method that can kicks nodes touching the box or a circle exactly
    (see :mod:`ropesim.integrate.contact`; by default it does when their edges are smoothed).
    """
    from ..integrate.grid import TimeGrid
    from ..integrate.health import net_flow
    from ..integrate.methods import make_integrator
    from ..model.energy import energy_terms
    from ..integrate.base import advance_in_chunks

    scene = single_frame(scene, dt, method)
    model = build(scene)
    grid = TimeGrid.of(scene)
    times, stepper, status = [], None, OK
    for _ in range(max(1, repeats)):
        stepper = make_integrator(model, grid, method)
        if exact_contacts is not None and get_method(method).exact_contact_kicks:
            stepper.set_exact_contacts(exact_contacts)
        stepper.warm_up()
        start = time.perf_counter()
        _, _, status, _ = advance_in_chunks(stepper, grid.steps)   # Ctrl-C is honoured between chunks
        times.append(time.perf_counter() - start)
        if status != OK:
            break
    ledger = stepper.ledger
    finite = bool(np.all(np.isfinite(stepper.x)) and np.all(np.isfinite(stepper.v)))
    energy_error = math.nan
    if finite and status == OK:
        energy = float(energy_terms(model, stepper.x.T, stepper.v.T)["total"])
        energy_error = energy - ledger[E0] - net_flow(ledger)
    return RunResult(stepper.x.copy(), stepper.v.copy(), "completed" if status == OK else STATUS_NAMES[status],
                     energy_error, times, stepper.force_evaluations, stepper.step)


def make_reference(scene: Scene, dt_min: float) -> Reference:
    """The reference solution and its convergence check (see the module doc)."""
    model = build(scene)
    dt = min(dt_min / REFERENCE_REFINEMENT, 0.5 * predicted_dt(model, REFERENCE_METHOD))
    fine = run_once(scene, REFERENCE_METHOD, dt)
    finer = run_once(scene, REFERENCE_METHOD, dt / 2)
    difference = float(np.max(np.linalg.norm(fine.x - finer.x, axis=0)))
    return Reference(REFERENCE_METHOD, dt / 2, finer.x, difference, finer.wall_times[0])


def observed_order(dts, errors, usable) -> tuple[float, int]:
    """Least-squares slope of log(error) against log(dt) over the usable points (the smallest-dt ones, at most
    four); nan with fewer than two."""
    pts = [(dt, e) for dt, e, ok in zip(dts, errors, usable) if ok and e > 0 and math.isfinite(e)]
    pts = sorted(pts)[:4]
    if len(pts) < 2:
        return math.nan, len(pts)
    d, e = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(d, e, 1)[0]), len(pts)


def accuracy_report(scene: Scene, methods=None, dts=None, repeats: int = 3, progress=None) -> Report:
    """Run every method over the dt ladder (default: the scene's dt times 4, 2, 1, 1/2, 1/4, 1/8)."""
    methods = list(methods or METHODS)
    for name in methods:
        get_method(name)
    base = scene.integrator.dt
    dts = sorted(dts or [base * f for f in (4, 2, 1, 0.5, 0.25, 0.125)], reverse=True)
    reference = make_reference(scene, min(dts))
    floor = REFERENCE_FLOOR * reference.difference
    rows = []
    for name in methods:
        for dt in dts:
            if progress is not None:
                progress(name, dt)
            r = run_once(scene, name, dt, repeats)
            if r.status == "completed":
                dist = np.linalg.norm(r.x - reference.x, axis=0)
                emax, erms = float(dist.max()), float(np.sqrt(np.mean(dist ** 2)))
            else:
                emax = erms = math.nan
            rows.append(Row(name, dt, r.steps, r.status, emax, erms, r.energy_error, float(np.median(r.wall_times)),
                            r.force_evaluations, bool(emax <= floor)))
    orders = {}
    for name in methods:
        mine = [r for r in rows if r.method == name]
        orders[name] = observed_order([r.dt for r in mine], [r.error_max for r in mine],
                                      [r.status == "completed" and not r.at_floor for r in mine])
    return Report(scene, scene.integrator.t_end, rows, reference, orders)


def write_csv(report: Report, path) -> None:
    import csv
    import io

    from ..io.atomic import write_text_atomic

    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(CSV_COLUMNS)
    for r in report.rows:
        w.writerow([r.method, f"{r.dt:.9g}", r.steps, r.status, f"{r.error_max:.6e}", f"{r.error_rms:.6e}",
                    f"{r.energy_error:.6e}", f"{r.wall_time:.6e}", r.force_evaluations, int(r.at_floor)])
    write_text_atomic(path, buf.getvalue())


def work_precision_figure(report: Report):
    """Work-precision figure: largest position error against kernel wall time and against force evaluations.

    One legend for both panels, below them (never over a point); none if no method completed.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(11, 4.8), layout="constrained")
    axes = fig.subplots(1, 2)
    for name in dict.fromkeys(r.method for r in report.rows):
        ok = [r for r in report.rows if r.method == name and r.status == "completed" and r.error_max > 0]
        if not ok:
            continue
        order = report.orders[name][0]
        label = f"{name} (order {order:.2f})" if math.isfinite(order) else name
        for ax, key in zip(axes, ("wall_time", "force_evaluations")):
            ax.loglog([getattr(r, key) for r in ok], [r.error_max for r in ok], "o-", label=label)
    floor = REFERENCE_FLOOR * report.reference.difference
    for ax, xlabel in zip(axes, ("kernel wall time [s] (median)", "force evaluations")):
        if floor > 0:
            ax.axhline(floor, color="grey", ls=":", lw=1)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("largest node position error at t_end [m]")
        ax.grid(True, which="both", alpha=0.3)
    handles, labels = axes[0].get_legend_handles_labels()
    if handles:
        fig.legend(handles, labels, loc="outside lower center", ncol=min(len(handles), 3), fontsize=8,
                   frameon=False)
    else:
        for ax in axes:
            ax.text(0.5, 0.5, "no run completed", ha="center", va="center", transform=ax.transAxes)
    fig.suptitle(title_text(f"{report.scene.name}: work-precision to t = {report.t_end:g} s (dotted: reference floor)"))
    return fig


@with_picture_text
def plot(report: Report, path) -> None:
    """Write :func:`work_precision_figure` to the PNG ``path``."""
    from ..render.output import save_png

    save_png(work_precision_figure(report), path, 110)
