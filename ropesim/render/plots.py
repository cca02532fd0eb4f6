"""`ropesim plot`: the figures a user wants from a run, one panel each, stacked in one PNG.

Every run: the mechanical energy term by term [J], the energy ledger, and the largest relative spring stretch
|r| / l - 1 [%], over time; the tension at the rope's ends over time, and along the rope. A system of lines:
its shape at the last frame (every line drawn and labelled, over its start), the tension at every line end over
time and along each line, and its rigid bodies' motions (their reference points from where they start, and
their angles) over time. A towed rope (the helicopter scenes): the angle from vertical of every segment along
the rope at the last frame, against the exact discrete steady state. A string shooter: the loop's inclination
over time.
Per-frame series are computed in blocks of frames, so a memory-mapped run of any length can be plotted.
``start``/``stop`` (``--from``/``--to``) plot a window of the run, its ranges and extremes over that window;
forces are in kN where they reach kilonewtons.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..analysis.summary import block_frames
from ..model.bodies import free_body_state
from ..model.energy import energy_terms
from ..analysis.towed import exact_steady_state, segment_angles, shape_verdict, towed_end
from ..model.build import Model, build
from ..model.forces.springs import segment_strains
from ..io.trajectory import Trajectory
from .framing import figure_inches, frame_blocks
from .output import output_path, save_png
from .scene_artist import legend_handles, line_color
from .style import OUTSIDE_RIGHT, title_text, with_picture_text

DPI = 100
WIDTH = 860          # [px] the panels, and their legends beside them
PANEL_HEIGHT = 250   # [px] per panel
HEADER = 40          # [px] the title


def per_frame(traj: Trajectory, fn: Callable[..., np.ndarray | dict], with_frames: bool = False):
    """``fn(x, v)`` over blocks of frames ((B, N, D) each), joined along the frame axis (arrays or dicts); with
    ``with_frames``, ``fn(x, v, block)``, ``block`` the block's slice of the frames."""
    blocks = frame_blocks(traj.frames, frame_nbytes=traj.x[0].nbytes)
    parts = [fn(np.asarray(traj.x[sl]), np.asarray(traj.v[sl]), *((sl,) if with_frames else ())) for sl in blocks]
    if isinstance(parts[0], dict):
        return {key: np.concatenate([p[key] for p in parts]) for key in parts[0]}
    return np.concatenate(parts)


def largest_stretch_series(traj: Trajectory, model: Model) -> np.ndarray:
    """The largest relative stretch |r| / l - 1 of the springs of every line in each frame."""
    return per_frame(traj, lambda x, v: segment_strains(model, x).max(axis=1))


def last_finite_frame(traj: Trajectory) -> int:
    """Index of the last frame whose positions are all finite (the last one, unless the run blew up)."""
    for i in range(traj.frames - 1, -1, -1):
        if np.all(np.isfinite(traj.x[i])):
            return i
    return 0


# ------------------------------------------------------------------------------------------ panels


def draw_energy(ax, traj: Trajectory, model: Model) -> None:
    terms = per_frame(traj, lambda x, v, block: energy_terms(model, x, v, *free_body_state(model, traj, block)),
                      with_frames=True)
    for name, values in terms.items():
        if name == "total":
            ax.plot(traj.t, values, color="black", linewidth=1.8, label="total")
        else:
            ax.plot(traj.t, values, linewidth=1.1, label=name)
    ax.set_ylabel("energy [J]")
    up = "z" if model.scene.up == "z" else "y"
    ax.set_title(f"Mechanical energy (gravity: m g {up}, zero at {up} = 0)")
    ax.legend(fontsize=7, **OUTSIDE_RIGHT)


def draw_ledger(ax, traj: Trajectory, model: Model) -> None:
    """The energy ledger: E(t) - E(0), the flows in and out, and the balance's residual (see analysis.ledger)."""
    from ..analysis.ledger import ledger_series, ledger_summary
    from ..io.frames import read_flows

    stored = read_flows(traj.folder) if traj.folder is not None else None
    if stored is None:
        ax.text(0.5, 0.5, "no ledger.npz in this run folder (made by an older ropesim)", ha="center",
                transform=ax.transAxes)
        ax.set_title("Energy ledger")
        return
    flows, energy0 = stored
    if traj.ledger is not None:   # the frames' own flows (a window of the run has only its own)
        flows = traj.ledger
    n = min(len(flows), traj.frames)
    series = ledger_series(model, traj.x, traj.v, flows[:n], energy0, traj)
    t = traj.t[:n]
    ax.plot(t, series["total"] - energy0, color="black", linewidth=1.6, label="E(t) - E(0)")
    ax.plot(t, series["held_work"], linewidth=1.1, label="work by held nodes")
    for name, label in (("box_work", "work by thrower and guides"), ("fluid_work", "work by the fluid"),
                        ("internal_work", "work by axial damping"), ("seabed_work", "work by the seabed")):
        if np.any(series[name]):
            ax.plot(t, series[name], linewidth=1.1, label=label)
    if np.any(series["drag_loss"]):
        ax.plot(t, -series["drag_loss"], linewidth=1.1, label="- loss to drag")
    ax.plot(t, series["residual"], color="#d62728", linewidth=1.4, label="residual (integration error)")
    ax.axhline(0, color="0.6", linewidth=0.8)
    summary = ledger_summary(series, energy0)
    ax.set_ylabel("energy [J]")
    ax.set_title(f"Energy ledger: largest residual {summary['max_residual_J']:.3g} J = "
                 f"{summary['relative_residual']:.2g} of the energy that "
                 f"{'flowed' if summary['relative_to'] == 'flows' else 'moved'}")
    ax.legend(fontsize=7, **OUTSIDE_RIGHT)


def draw_stretch(ax, traj: Trajectory, model: Model) -> None:
    stretch = 100 * largest_stretch_series(traj, model)
    ax.plot(traj.t, stretch, color="#9467bd")
    k = int(np.nanargmax(stretch))
    ax.plot(traj.t[k], stretch[k], "o", color="#9467bd")
    ax.axhline(0, color="0.6", linewidth=0.8)
    ax.set_ylabel("largest stretch [%]")
    ax.set_title(f"Largest spring stretch |r| / l - 1: {stretch[k]:.3g} % at t = {traj.t[k]:.3g} s")


def draw_towed(ax, traj: Trajectory, model: Model) -> None:
    """Segment angles from vertical, from the held end down, at the last frame and in the exact steady state."""
    i = last_finite_frame(traj)
    angles = segment_angles(model, np.asarray(traj.x[i]))
    along = (np.arange(len(angles)) + 0.5) * model.scene.rope.segment_length
    ax.plot(along, angles, "o-", markersize=3, label=f"simulated, t = {traj.t[i]:.3g} s")
    title = f"Rope angle at t = {traj.t[i]:.3g} s: {shape_verdict(angles)}"
    steady = exact_steady_state(model)
    if steady is not None:
        in_scene_order = steady if towed_end(model.scene) == 0 else steady[::-1]
        exact = segment_angles(model, in_scene_order)
        ax.plot(along, exact, "--", color="black", label="exact steady state")
        title += f" (steady state: {shape_verdict(exact)})"
    ax.set_xlabel("distance along the rope from the held end (at rest) [m]")
    ax.set_ylabel("angle from vertical [deg]")
    ax.set_title(title)
    ax.legend(fontsize=7, **OUTSIDE_RIGHT)


def draw_inclination(ax, traj: Trajectory, model: Model) -> None:
    from ..analysis.shooter import loop_inclination, shooter_figures

    inclination = per_frame(traj, lambda x, v: loop_inclination(model, x))
    ax.plot(traj.t, inclination, color="#2ca02c")
    figures = shooter_figures(model, traj.t, traj.x, traj.v)
    t_end, window = float(traj.t[-1]), figures["averaged_over_s"]
    ax.plot([t_end - window, t_end], [figures["mean_loop_inclination_deg"]] * 2, "--", color="black",
            label=f"mean, last {window:.3g} s: {figures['mean_loop_inclination_deg']:.1f} deg")
    ax.axhline(0, color="0.6", linewidth=0.8)
    ax.set_ylabel("inclination [deg]")
    ax.set_title("Loop inclination: 0 = hanging below the thrower, 90 = straight out in front")
    ax.legend(fontsize=7, **OUTSIDE_RIGHT)


def draw_end_tensions(ax, traj: Trajectory, model: Model) -> None:
    """The tension in the first and last segment of every line (a rope's two ends) over time."""
    from ..analysis.tension import end_columns, force_unit

    labels = end_columns(model)
    ends = np.asarray(traj.tension[:, [column for _, column in labels]])
    unit, scale = force_unit(float(np.nanmax(np.abs(ends), initial=0.0)))
    system = model.scene.is_system
    for k, (label, _) in enumerate(labels):
        style = {"color": line_color(k // 2), "linestyle": "-" if k % 2 == 0 else "--"} if system else {}
        ax.plot(traj.t, ends[:, k] / scale, linewidth=1.1, label=label, **style)
    ax.axhline(0, color="0.6", linewidth=0.8)
    ax.set_ylabel(f"tension [{unit}]")
    ax.set_title("Tension at every line end" if system else "Tension at the rope's ends")
    ax.legend(fontsize=7, **OUTSIDE_RIGHT)


def draw_tension_profile(ax, traj: Trajectory, model: Model) -> None:
    """Tension along each line (a rope) at the last frame, and its range over the run."""
    from ..analysis.tension import force_unit
    from ..model.tension import line_segments

    tension = traj.tension
    i = last_finite_frame(traj)
    low, high = np.full(tension.shape[1], np.inf), np.full(tension.shape[1], -np.inf)
    step = block_frames(tension[0].nbytes)
    for s in range(0, len(traj.t), step):
        block = np.asarray(tension[s:s + step])
        low, high = np.minimum(low, np.nanmin(block, axis=0)), np.maximum(high, np.nanmax(block, axis=0))
    unit, scale = force_unit(float(np.nanmax(np.abs(high), initial=0.0)))
    span = f"t = {traj.t[0]:.3g} .. {traj.t[-1]:.3g} s"
    system = model.scene.is_system
    for k, (line, part) in enumerate(zip(model.lines, line_segments(model))):
        along = (np.arange(line.segments) + 0.5) * line.segment_length
        color = line_color(k) if system else "#1f77b4"
        ax.fill_between(along, low[part] / scale, high[part] / scale, color=color, alpha=0.2, linewidth=0,
                        label=f"range, {span}" if k == 0 else None)
        ax.plot(along, np.asarray(tension[i, part]) / scale, "o-", markersize=3, color=color,
                label=f"{line.id}, t = {traj.t[i]:.3g} s" if system else f"t = {traj.t[i]:.3g} s")
    ax.axhline(0, color="0.6", linewidth=0.8)
    ax.set_xlabel("distance along each line from its start (at rest) [m]" if system
                  else "distance along the rope from node 0 (at rest) [m]")
    ax.set_ylabel(f"tension [{unit}]")
    ax.set_title("Tension along each line (shaded: its range)" if system else "Tension along the rope")
    ax.legend(fontsize=7, **OUTSIDE_RIGHT)


def draw_shape(ax, traj: Trajectory, model: Model) -> None:
    """A system's shape at the last frame, every line in its colour and labelled at its middle, the points and
    bodies marked; its start in light grey below (a 3-D scene seen from the side, x across and y up)."""
    from .framing import projection, view_box
    from .scene_artist import Geometry, RopeArtist, body_state

    i = last_finite_frame(traj)
    if ax.name == "3d":
        _draw_shape_3d(ax, traj, model, i)
        return
    from ..scene.frame import frame_of

    proj = projection(None, model.dim, frame_of(model.scene))
    Geometry(ax, model, proj)
    RopeArtist(ax, model, proj, color="0.82").show(np.asarray(traj.x[0]), None, body_state(traj, 0))
    shown = RopeArtist(ax, model, proj)
    x = np.asarray(traj.x[i])
    shown.show(x, None, body_state(traj, i))
    for line in model.lines:
        middle = x[line.first + line.nodes // 2, list(proj.axes)]
        ax.annotate(line.id, middle, xytext=(4, 4), textcoords="offset points", fontsize=7, zorder=7,
                    bbox={"boxstyle": "round,pad=0.15", "facecolor": "white", "edgecolor": "none", "alpha": 0.8})
    box = view_box(model, traj.x, proj, None, traj.body_x)
    ax.set_xlim(*box[0])
    ax.set_ylim(*box[1])
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(f"{proj.names[0]} [m]")
    ax.set_ylabel(f"{proj.names[1]} [m]")
    ax.legend(handles=legend_handles(model), fontsize=7, **OUTSIDE_RIGHT)
    ax.set_title(f"Shape at t = {traj.t[i]:.3g} s (grey: t = {traj.t[0]:.3g} s)"
                 + (", seen from the side" if model.dim == 3 else ""))


def _draw_shape_3d(ax, traj: Trajectory, model: Model, i: int) -> None:
    """:func:`draw_shape` in the 3-D view (:func:`shape_axes` made ``ax``)."""
    from .scene_artist import body_state
    from .view3d import Geometry3D, State3D, plotted

    Geometry3D(ax, model, ax.scene_box)
    State3D(ax, model, color="0.82").show(np.asarray(traj.x[0]), None, body_state(traj, 0))
    x = np.asarray(traj.x[i])
    State3D(ax, model).show(x, None, body_state(traj, i))
    for line in model.lines:
        ax.text(*plotted(x[line.first + line.nodes // 2]), f" {line.id}", fontsize=7, zorder=7)
    ax.legend(handles=legend_handles(model), fontsize=7, **OUTSIDE_RIGHT)
    ax.set_title(f"Shape at t = {traj.t[i]:.3g} s (grey: t = {traj.t[0]:.3g} s)")


def shape_axes(fig, spec, traj: Trajectory, model: Model):
    """The shape panel's axes: a 3-D view for a 3-D scene (:mod:`ropesim.render.view3d`), else a plain one."""
    if model.dim != 3:
        return fig.add_subplot(spec)
    from .view3d import axes_3d, azimuth, run_box

    box = run_box(traj.x, None, traj.body_x)
    ax = axes_3d(fig, spec, box, False, azim=azimuth(model, np.asarray(traj.x[0])), up=model.scene.up)
    ax.scene_box = box
    return ax


BODY_STYLES = ("-", "--", ":", "-.")   # a system's rigid bodies, in turn


def draw_body_motion(ax, traj: Trajectory, model: Model) -> None:
    """Each rigid body's reference point over time, from where it starts (x red, y green, z blue)."""
    from .scene_artist import AXIS_COLORS

    for b, body in enumerate(model.scene.rigid_bodies):
        position = np.asarray(traj.body(body.id).position)
        for k in range(model.dim):
            ax.plot(traj.t, position[:, k] - position[0, k], color=AXIS_COLORS[k], linewidth=1.1,
                    linestyle=BODY_STYLES[b % len(BODY_STYLES)], label=f"{body.id}: Δ{'xyz'[k]}")
    ax.axhline(0, color="0.6", linewidth=0.8)
    ax.set_ylabel("displacement [m]")
    ax.set_title("Rigid bodies: their reference points from where they start")
    ax.legend(fontsize=7, **OUTSIDE_RIGHT)


def draw_body_rotation(ax, traj: Trajectory, model: Model) -> None:
    """Each rigid body's orientation over time, as the scene's angles (about x, then y, then z)."""
    from .scene_artist import AXIS_COLORS

    axes = "xyz" if model.dim == 3 else "z"
    for b, body in enumerate(model.scene.rigid_bodies):
        angles = traj.body(body.id).angles
        for k, name in enumerate(axes):
            ax.plot(traj.t, angles[:, k], color=AXIS_COLORS["xyz".index(name)], linewidth=1.1,
                    linestyle=BODY_STYLES[b % len(BODY_STYLES)], label=f"{body.id}: about {name}")
    ax.axhline(0, color="0.6", linewidth=0.8)
    ax.set_ylabel("angle [deg]")
    ax.set_title("Rigid bodies: orientation, as the scene's angles (about x, then y, then z)"
                 if model.dim == 3 else "Rigid bodies: orientation, the angle about z")
    ax.legend(fontsize=7, **OUTSIDE_RIGHT)


@dataclass(frozen=True)
class Panel:
    """One figure of the plot: its name, which scenes it is for, and how it is drawn."""

    name: str
    applies: Callable[[Model], bool]
    draw: Callable  # (ax, traj, model) -> None
    time_axis: bool = True
    needs_tension: bool = False   # only for run folders that store tension (ropesim 0.2 on)
    needs_bodies: bool = False    # only for runs that store rigid bodies' states
    axes: Callable | None = None  # (fig, subplot spec, traj, model) -> its axes; None: a plain one
    rows: Callable[[Model], int] = lambda model: 1   # its height, in panels


PANELS = (
    Panel("shape", lambda model: model.scene.is_system, draw_shape, time_axis=False, axes=shape_axes,
          rows=lambda model: 2 if model.dim == 3 else 1),
    Panel("energy", lambda model: True, draw_energy),
    Panel("ledger", lambda model: True, draw_ledger),
    Panel("stretch", lambda model: True, draw_stretch),
    Panel("end tensions", lambda model: True, draw_end_tensions, needs_tension=True),
    Panel("tension profile", lambda model: True, draw_tension_profile, time_axis=False, needs_tension=True),
    Panel("body motion", lambda model: bool(model.scene.rigid_bodies), draw_body_motion, needs_bodies=True),
    Panel("body rotation", lambda model: bool(model.scene.rigid_bodies), draw_body_rotation, needs_bodies=True),
    Panel("towed", lambda model: towed_end(model.scene) is not None, draw_towed, time_axis=False),
    Panel("shooter", lambda model: model.scene.thrower is not None and model.lines[0].closed, draw_inclination),
)


@dataclass(frozen=True)
class Plot:
    """What :func:`plot_run` wrote."""

    path: Path
    panels: tuple[str, ...]
    size: tuple[int, int]  # (width, height) [px]


def windowed(traj: Trajectory, start: float | None, stop: float | None) -> Trajectory:
    """``traj`` cut to the frames with start <= t <= stop (views, nothing copied); ValueError when none is left."""
    from dataclasses import replace

    from ..analysis.tension import frame_window

    if start is None and stop is None:
        return traj
    sl = frame_window(traj.t, start, stop)
    cut = {name: getattr(traj, name)[sl] for name in ("t", "x", "v", "tension", "strain", "support", "ledger",
                                                      "body_x", "body_v", "body_q", "body_w")
           if getattr(traj, name) is not None}
    return replace(traj, **cut)


def run_figure(traj: Trajectory, start: float | None = None, stop: float | None = None):
    """The figure of :func:`plot_run` and the names of its panels (every :data:`PANELS` entry that applies)."""
    from matplotlib.figure import Figure

    from . import RenderError

    try:
        traj = windowed(traj, start, stop)
    except ValueError as exc:
        raise RenderError(str(exc)) from None
    model = build(traj.scene, solve=False)   # the frames hold the shape: no static solve
    own = traj             # the body panels plot the run in the scene's own frame; the others in the model's
    traj = traj.internal
    panels = [p for p in PANELS if p.applies(model) and (traj.tension is not None or not p.needs_tension)
              and (traj.body_x is not None or not p.needs_bodies)]
    rows = [panel.rows(model) for panel in panels]
    height = HEADER + PANEL_HEIGHT * sum(rows)
    fig = Figure(figsize=figure_inches(WIDTH, height, DPI), dpi=DPI, layout="constrained")
    grid = fig.add_gridspec(len(panels), 1, height_ratios=rows)
    for k, panel in enumerate(panels):
        ax = (panel.axes or (lambda fig, spec, traj, model: fig.add_subplot(spec)))(fig, grid[k, 0], traj, model)
        panel.draw(ax, own if panel.needs_bodies else traj, model)
        if panel.time_axis:
            ax.set_xlabel("t [s]")
            if traj.t[-1] > traj.t[0]:
                ax.set_xlim(traj.t[0], traj.t[-1])
        ax.grid(True, linewidth=0.4, alpha=0.5)
        ax.title.set_fontsize(9)
        ax.tick_params(labelsize=8)
        ax.xaxis.label.set_fontsize(8)
        ax.yaxis.label.set_fontsize(8)
    title = traj.scene.name + (f": {traj.scene.description}" if traj.scene.description else "")
    fig.suptitle(title_text(title), x=0.01, ha="left", fontsize=10, fontweight="bold", wrap=True)
    return fig, tuple(p.name for p in panels)


@with_picture_text
def plot_run(traj: Trajectory, out: str | Path, start: float | None = None, stop: float | None = None) -> Plot:
    """Write the run's figures (every :data:`PANELS` entry that applies to its scene) to the PNG ``out``; with
    ``start``/``stop`` [s], of that window of the run alone."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    out = Path(out)
    real, _ = output_path(out, (".png",))
    fig, panels = run_figure(traj, start, stop)
    FigureCanvasAgg(fig)
    save_png(fig, real, DPI)
    width, height = (round(v) for v in fig.bbox.size)
    return Plot(path=out, panels=panels, size=(width, height))
