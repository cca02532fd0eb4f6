"""Stability before running: bounds on the fastest natural frequency and each method's largest stable step.

The linearised rope obeys M x'' = -K x - C x' (plus drag). A spring of stiffness k between nodes i and j
contributes k [u u^T + (1 - l/r) (I - u u^T)] to K: at most k in any direction while it is stretched (r >= l),
so K <= (L (x) I_D) with L the spring graph's Laplacian weighted by k (held nodes removed: they do not move).
The thrower's and guides' centring springs add their omega0^2 to the nodes they can hold. Two bounds on
omega_max, the square root of the largest eigenvalue of M^-1/2 L M^-1/2 (+ omega0^2):

- ``gershgorin``: the largest row sum of |M^-1/2 L M^-1/2|. For a uniform chain 2 sqrt(k/m): its zig-zag mode,
  twice a single spring's sqrt(k/m) (the write-up's dt < 2 sqrt(m/k) is the one-spring limit).
- ``spectral``: that largest eigenvalue itself (dense symmetric eigenvalues up to SPECTRAL_MAX_NODES nodes;
  Gershgorin above). Exact for a straight, stretched rope; never above Gershgorin.

A method's largest stable step is then the h at which its one-step map of the damped oscillator
x'' = -omega^2 x - gamma x' stops being bounded (:func:`ropesim.integrators.stable_step`), with gamma the
explicit velocity damping the method sees: the thrower's drive b_thrower / m and centring damping 2 zeta omega0,
the guides' 2 zeta omega0 (integrated exactly, like drag, by the splitting schemes when the edges are
smoothed), and, for Runge-Kutta (which does not integrate drag exactly), the drag b / m.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model.build import Model
from ..integrate.base import stable_step
from ..integrate.methods import METHODS, get_method
from ..model.terms import declared_terms
from ..render.style import with_picture_text

SPECTRAL_MAX_NODES = 800
WARN_FRACTION = 0.8       # `ropesim run` warns above this fraction of the bound, refuses above the bound


def representatives(model: Model) -> np.ndarray:
    """Each node's representative (N,) int: itself, or for the line ends on a system's free point the point's
    first (they move as one, :mod:`ropesim.model.junctions`)."""
    rep = np.arange(model.nodes)
    if model.params.junctions is None:
        return rep
    start, nodes = model.params.junctions.start, model.params.junctions.nodes
    for j in range(len(start) - 1):
        group = nodes[start[j]:start[j + 1]]
        rep[group] = group[0]
    return rep


def _laplacian_rows(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(i, j, k) of every spring between two free nodes, and the diagonal (N,) of L (every term's springs), the
    nodes that move together counted as one (their representative's row, :func:`representatives`)."""
    rep = representatives(model)
    diag = np.zeros(model.nodes)
    ii, jj, kk = [], [], []
    springs = [pair for term in declared_terms(model.scene) for pair in (term.springs(model) or ())]
    for i, j, k in springs:
        i, j = rep[i], rep[j]
        keep = i != j
        i, j, k = i[keep], j[keep], k[keep]
        np.add.at(diag, i, k)
        np.add.at(diag, j, k)
        both = ~model.held[i] & ~model.held[j]
        ii.append(i[both])
        jj.append(j[both])
        kk.append(k[both])
    return np.concatenate(ii), np.concatenate(jj), np.concatenate(kk), diag


def contact_stiffness(model: Model) -> float:
    """The largest omega^2 [1/s^2] a term adds to a single node (the thrower's and guides' centring springs; 0
    without them)."""
    return max((term.node_stiffness(model) for term in declared_terms(model.scene)), default=0.0)


def explicit_damping(model: Model) -> float:
    """The largest velocity-damping rate [1/s] a term applies that a method may evaluate explicitly (the
    thrower's and guides')."""
    return max((term.damping(model) for term in declared_terms(model.scene)), default=0.0)


def inertial_mass(model: Model) -> np.ndarray:
    """Each node's mass [kg] as its stiffest mode sees it: its own, plus the smaller of its normal and
    tangential added mass (the direction in which the fluid adds least inertia oscillates fastest); nodes that
    move together all on their representative (:func:`representatives`), the others' entries left as theirs."""
    added = model.params.added_mass
    if model.scene.sea is not None:   # a node in air has none (the sea rewrites the coefficients as it runs)
        added = np.zeros_like(added)
    mass = model.mass + added.min(axis=0) if added.size else model.mass
    junctions = model.params.junctions
    if junctions is not None:
        rep = representatives(model)
        together = np.zeros(model.nodes)
        np.add.at(together, rep, mass)
        if model.scene.sea is None:
            np.add.at(together, rep[junctions.nodes], junctions.added.min(axis=0))   # left out of the per-node pass
        mass = np.where(rep == np.arange(model.nodes), together, mass)
    return mass


def gershgorin_frequency(model: Model) -> float:
    """Gershgorin bound [rad/s] on omega_max (see the module doc); 0 when no node is free."""
    free = ~model.held
    if not free.any():
        return 0.0
    i, j, k, diag = _laplacian_rows(model)
    mass = inertial_mass(model)
    inv_sqrt_m = 1.0 / np.sqrt(mass)
    row = diag / mass
    coupling = k * inv_sqrt_m[i] * inv_sqrt_m[j]
    np.add.at(row, i, coupling)
    np.add.at(row, j, coupling)
    return float(math.sqrt(row[free].max() + contact_stiffness(model)))


def spectral_frequency(model: Model) -> float:
    """omega_max [rad/s] of the bound matrix itself (Gershgorin's bound above SPECTRAL_MAX_NODES nodes)."""
    free = np.flatnonzero(~model.held)
    if free.size == 0:
        return 0.0
    if model.nodes > SPECTRAL_MAX_NODES:
        return gershgorin_frequency(model)
    i, j, k, diag = _laplacian_rows(model)
    lap = np.diag(diag)
    np.add.at(lap, (i, j), -k)
    np.add.at(lap, (j, i), -k)
    inv_sqrt_m = 1.0 / np.sqrt(inertial_mass(model))
    sym = lap * inv_sqrt_m[:, None] * inv_sqrt_m[None, :]
    sym = sym[np.ix_(free, free)]
    top = float(np.linalg.eigvalsh(sym)[-1])
    return math.sqrt(max(top, 0.0) + contact_stiffness(model))


def drag_rates(model: Model) -> tuple[float, float]:
    """(smallest, largest) drag rate b / m [1/s] over the free nodes."""
    free = ~model.held
    if not free.any():
        return 0.0, 0.0
    rate = model.drag[free] / model.mass[free]
    return float(rate.min()), float(rate.max())


RK4_REAL_LIMIT = 2.785293563405282   # RK4 is stable on x' = -lambda x while lambda h <= this (the real axis)


def predicted_dt(model: Model, method: str, omega: float | None = None) -> float:
    """Largest stable time step [s] for ``method`` on this scene (inf for the stiff integrator).

    Uses the spectral bound on omega_max unless ``omega`` is given, and the worst of the scene's smallest and
    largest drag rates and of no and the largest explicit damping (every term's ``damping`` hook: the
    thrower's and guides', the fluid drag's at the run's speed scale, the axial damping's). With forces that
    depend on velocity beyond the thrower's and guides', a splitting scheme's kicks are RK4 sub-stages
    (:mod:`ropesim.integrate.velocity_kick`): they must also resolve the fastest damping, drag included,
    (damping + b / m) |c| dt <= 2.785 for the largest kick coefficient |c|.
    """
    scheme = get_method(method)
    omega = spectral_frequency(model) if omega is None else omega
    low, high = drag_rates(model)
    damping = explicit_damping(model)
    velocity_kick = model.velocity_terms and scheme.kick_span > 0
    if scheme.exact_contact_kicks and model.smooth_contacts and not velocity_kick:
        high, damping = high + damping, 0.0  # the contacts' damping is integrated exactly, like drag
    # Damping can widen or narrow a method's interval, and the fastest mode may sit on lightly or heavily
    # damped nodes: take the worst of the extremes.
    bound = min(stable_step(scheme, omega, f, d) for f in {0.0, damping} for d in {low, high})
    if velocity_kick and damping + high > 0:
        bound = min(bound, RK4_REAL_LIMIT / ((damping + high) * scheme.kick_span))
    return bound


@dataclass(frozen=True)
class Bound:
    method: str
    h_omega: float             # the method's stability interval on the undamped oscillator
    dt_gershgorin: float       # largest stable dt with the Gershgorin bound [s]
    dt_spectral: float         # ... with the spectral bound [s]; the one `ropesim run` enforces


def bounds(model: Model, methods=None) -> tuple[float, float, list[Bound]]:
    """(Gershgorin omega_max, spectral omega_max, every method's bounds)."""
    g, s = gershgorin_frequency(model), spectral_frequency(model)
    rows = []
    for name in methods or METHODS:
        scheme = get_method(name)
        rows.append(Bound(name, scheme.stability_limit, predicted_dt(model, name, g), predicted_dt(model, name, s)))
    return g, s, rows


def time_step_verdict(model: Model, method: str, dt: float) -> tuple[str, float]:
    """('ok' | 'warn' | 'refuse', bound [s]): refuse above the bound, warn above WARN_FRACTION of it."""
    bound = predicted_dt(model, method)
    if dt > bound:
        return "refuse", bound
    if dt > WARN_FRACTION * bound:
        return "warn", bound
    return "ok", bound


# ------------------------------------------------------------------------------- measuring blow-ups

PERTURBATION = 1e-6       # seed displacement of every free node, in segment lengths, so every mode is excited
PROBE_STEPS = 4000        # steps a probe run must survive to count as stable
BISECTIONS = 8


def reference_dt(model: Model) -> float:
    """The sweep's unit of time step [s]: 2 / omega_max (spectral), the leapfrog's undamped limit."""
    omega = spectral_frequency(model)
    return 2.0 / omega if omega > 0 else math.inf


def probe(scene, method: str, dt: float, steps: int = PROBE_STEPS) -> bool:
    """True when ``steps`` steps of ``dt`` from a slightly perturbed start stay sane.

    Sane: no blow-up stop (non-finite, overstretched, runaway energy) and, stricter than a run's own check, an
    energy balance residual at the end below the initial energy scale alone (a run's check also allows the
    energy that flowed). That catches instabilities that saturate into bounded nonsense instead of
    overflowing; stable runs of the built-in scenes stay below 0.15 of that scale even at 0.95 of the bound.
    """
    import dataclasses

    from ..integrate.grid import TimeGrid
    from ..integrate.health import E0, OK, SCALE, net_flow
    from ..integrate.methods import make_integrator
    from ..model.build import build
    from ..model.energy import energy_terms
    from ..integrate.base import advance_in_chunks

    integ = dataclasses.replace(scene.integrator, method=method, dt=dt, t_end=steps * dt)
    out = dataclasses.replace(scene.output, interval=steps * dt)
    scene = dataclasses.replace(scene, integrator=integ, output=out)
    model = build(scene)
    rng = np.random.default_rng(12345)
    free = ~model.held
    spacing = min(line.segment_length for line in model.lines)
    model.x0[:, free] += PERTURBATION * spacing * rng.standard_normal((model.dim, free.sum()))
    grid = TimeGrid.of(scene)
    stepper = make_integrator(model, grid, method)
    _, _, status, _ = advance_in_chunks(stepper, grid.steps)   # Ctrl-C is honoured between chunks
    if status != OK:
        return False
    ledger = stepper.ledger
    energy = float(energy_terms(model, stepper.x.T, stepper.v.T)["total"])
    residual = energy - ledger[E0] - net_flow(ledger)
    return abs(residual) <= ledger[SCALE]


def measured_dt(scene, method: str, guess: float, steps: int = PROBE_STEPS) -> tuple[float, float]:
    """(largest stable dt found, smallest unstable dt found) [s], bracketing where ``method`` blows up.

    Starts from ``guess`` (the predicted bound), widens by factors of 2 until it brackets the threshold, then
    bisects BISECTIONS times (resolution about 0.4 %). (inf, inf) when no blow-up is found up to 1000 x guess.
    """
    lo, hi = None, None
    dt = guess
    for _ in range(12):
        if probe(scene, method, dt, steps):
            lo = dt
            if hi is not None:
                break
            dt *= 2.0
        else:
            hi = dt
            if lo is not None:
                break
            dt /= 2.0
        if dt > 1000 * guess:
            return math.inf, math.inf
    if lo is None or hi is None:
        return (lo or 0.0), (hi or math.inf)
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if probe(scene, method, mid, steps) else (lo, mid)
    return lo, hi


@dataclass
class SweepResult:
    rows: list            # dicts: stiffness, method, dt, dt_over_ref, stable
    bounds: list          # dicts: stiffness, method, predicted (spectral, Gershgorin), measured (lo, hi)


def stability_sweep(scene, methods=None, fractions=None, stiffnesses=None, steps: int = PROBE_STEPS,
                    progress=None) -> SweepResult:
    """Map stable and unstable time steps per method (and per stiffness k), against the predicted bounds.

    dt runs over ``fractions`` of the reference step 2 / omega_max (default 0.1 to 2.0); for every explicit
    method the blow-up dt is also measured by bisection. The stiff integrator is probed on the same ladder
    (it should be stable everywhere).
    """
    import dataclasses

    from ..model.build import build

    methods = list(methods or METHODS)
    fractions = fractions or [round(0.1 * i, 2) for i in range(1, 21)]
    if scene.is_system:    # each line has its own k: the scene as it is, labelled by its stiffest line's
        if stiffnesses:
            raise ValueError("--k: a system's lines each have their own stiffness EA / l; sweep one with --set "
                             "(lines.N.EA=..., or line_types.NAME.EA=...)")
        from ..model.layout import line_layouts

        stiffnesses = [max(line.stiffness for line in line_layouts(scene))]
    stiffnesses = stiffnesses or [scene.rope.stiffness]
    rows, bound_rows = [], []
    for k in stiffnesses:
        sc = scene if scene.is_system else dataclasses.replace(scene, rope=dataclasses.replace(scene.rope,
                                                                                             stiffness=k))
        model = build(sc)
        unit = reference_dt(model)
        g, s = gershgorin_frequency(model), spectral_frequency(model)
        for name in methods:
            if progress is not None:
                progress(k, name)
            pred_s, pred_g = predicted_dt(model, name, s), predicted_dt(model, name, g)
            for f in fractions:
                rows.append({"stiffness": k, "method": name, "dt": f * unit, "dt_over_ref": f,
                             "stable": probe(sc, name, f * unit, steps)})
            lo, hi = (math.inf, math.inf) if not math.isfinite(pred_s) else measured_dt(sc, name, pred_s, steps)
            bound_rows.append({"stiffness": k, "method": name, "ref_dt": unit, "omega_gershgorin": g,
                               "omega_spectral": s, "predicted_dt_spectral": pred_s, "predicted_dt_gershgorin": pred_g,
                               "measured_stable_dt": lo, "measured_blowup_dt": hi})
    return SweepResult(rows, bound_rows)


def write_sweep(result: SweepResult, folder) -> tuple:
    """Write stability.csv (every probe) and bounds.csv (predicted against measured) into ``folder``."""
    import csv
    import io
    from pathlib import Path

    from ..io.atomic import write_text_atomic

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, rows in (("stability.csv", result.rows), ("bounds.csv", result.bounds)):
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
        write_text_atomic(folder / name, buf.getvalue())
        paths.append(folder / name)
    return tuple(paths)


def stability_figure(result: SweepResult):
    """One row per method: probes at each dt (and k), the predicted bound (line) and the measured blow-up; the
    legend above the axes, never over a probe."""
    from matplotlib.figure import Figure

    methods = list(dict.fromkeys(r["method"] for r in result.rows))
    ks = sorted({r["stiffness"] for r in result.rows})
    fig = Figure(figsize=(9, 1.4 + 0.55 * len(methods) * len(ks)), layout="constrained")
    ax = fig.subplots()
    labels = []
    y = 0
    for name in methods:
        for k in ks:
            pts = [r for r in result.rows if r["method"] == name and r["stiffness"] == k]
            ok = [r["dt_over_ref"] for r in pts if r["stable"]]
            bad = [r["dt_over_ref"] for r in pts if not r["stable"]]
            ax.plot(ok, [y] * len(ok), "o", color="tab:green", ms=5, label="stable" if y == 0 else None)
            ax.plot(bad, [y] * len(bad), "x", color="tab:red", ms=6, label="blew up" if y == 0 else None)
            b = next(r for r in result.bounds if r["method"] == name and r["stiffness"] == k)
            if math.isfinite(b["predicted_dt_spectral"]):
                ax.plot([b["predicted_dt_spectral"] / b["ref_dt"]] * 2, [y - 0.35, y + 0.35], "-", color="k", lw=2,
                        label="predicted bound" if y == 0 else None)
                ax.plot([b["predicted_dt_gershgorin"] / b["ref_dt"]] * 2, [y - 0.35, y + 0.35], ":", color="k",
                        lw=1.5, label="Gershgorin bound" if y == 0 else None)
            if math.isfinite(b["measured_blowup_dt"]):
                ax.plot([b["measured_blowup_dt"] / b["ref_dt"]], [y], "|", color="tab:blue", ms=16, mew=2,
                        label="measured blow-up" if y == 0 else None)
            labels.append(f"{name}" + (f", k = {k:g}" if len(ks) > 1 else ""))
            y += 1
    ax.set_yticks(range(len(labels)), labels)
    ax.invert_yaxis()
    ax.set_xlabel("time step dt as a multiple of 2 / omega_max (omega_max [rad/s]: the fastest mode)")
    ax.grid(True, axis="x", alpha=0.3)
    fig.legend(*ax.get_legend_handles_labels(), loc="outside upper center", ncol=5, fontsize=8, frameon=False)
    return fig


@with_picture_text
def plot_sweep(result: SweepResult, path) -> None:
    """Write :func:`stability_figure` to the PNG ``path``."""
    from ..render.output import save_png

    save_png(stability_figure(result), path, 110)
