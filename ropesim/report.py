"""What the command line prints: rich tables for a run's summary and a scene's check."""

from __future__ import annotations

from pathlib import Path

from rich.console import Console
from rich.table import Table

from .scene import Scene


def _console() -> Console:
    return Console(highlight=False)


def print_summary(summary: dict, folder: Path) -> None:
    """The run summary as a two-column table."""
    table = Table(title=f"{summary['scene']}: {summary['status']}", show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("")
    rows = [
        ("simulated", f"t = 0 .. {summary['t_end']:.6g} s, {summary['steps']} steps of {summary['dt']:.3g} s "
                      f"({summary['method']}), {summary['frames']} frames"),
        ("wall time", f"{summary['wall_time_s']:.3g} s ({summary['steps_per_second'] or 0:,.0f} steps/s, "
                      f"{summary['node_steps_per_second'] or 0:,.0f} node-steps/s); "
                      f"compile or cache load {summary['compile_time_s']:.2g} s"),
    ]
    if summary.get("dt_requested"):
        rows.append(("time step", f"{summary['dt_requested']:.6g} s shortened to {summary['dt']:.6g} s so "
                                  f"t_end is a whole number of steps"))
    if summary.get("stable_dt_bound"):
        rows.append(("stable dt bound", f"{summary['stable_dt_bound']:.3g} s"))
    energy = summary.get("final_energy_J")
    if energy:
        rows.append(("final energy", ", ".join(f"{k} {v:.6g} J" for k, v in energy.items())))
        rows.append(("largest stretch", f"{100 * summary['max_spring_stretch']:.3g} % "
                                        f"(at t = {summary['max_spring_stretch_t']:.3g} s)"))
    towed = summary.get("towed")
    if towed:
        rows.append(("rope angle", f"top {towed['top_angle_deg']:.2f} deg, bottom {towed['bottom_angle_deg']:.2f} "
                                   f"deg from vertical: {towed['shape']}"))
        if "steady_top_angle_deg" in towed:
            rows.append(("steady state", f"top {towed['steady_top_angle_deg']:.2f} deg, bottom "
                                         f"{towed['steady_bottom_angle_deg']:.2f} deg: {towed['steady_shape']}; "
                                         f"now {towed['distance_from_steady_state_m']:.3g} m from it"))
    shooter = summary.get("shooter")
    if shooter:
        rows.append(("loop inclination", f"{shooter['loop_inclination_deg']:.1f} deg from vertical at t_end "
                                         f"(mean {shooter['mean_loop_inclination_deg']:.1f} deg over the last "
                                         f"{shooter['averaged_over_s']:.3g} s)"))
    if summary.get("message"):
        rows.append(("stopped", summary["message"]))
    rows.append(("written", f"{folder}/ (trajectory.npz, scene.toml, summary.json)"))
    for key, value in rows:
        table.add_row(key, value)
    _console().print(table)


def print_check(scene: Scene, source: Path) -> None:
    """What a scene contains, and its stability bound, without running it."""
    from .build import build, stability_frequency
    from .integrators import METHODS
    from .run import TimeGrid

    model = build(scene)
    grid = TimeGrid.of(scene)
    rope = scene.rope
    table = Table(title=f"{source}: valid scene '{scene.name}'", show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("")
    if scene.description:
        table.add_row("description", scene.description)
    table.add_row("rope", f"{rope.nodes} nodes, {'closed loop' if rope.closed else 'open line'}, "
                          f"{scene.dimension}-D; l = {rope.segment_length:g} m, k = {rope.stiffness:g} N/m, "
                          f"m = {rope.mass:g} kg")
    table.add_row("initial", f"{scene.initial.shape}, velocity {list(scene.initial.velocity)} m/s")
    terms = ["springs"]
    if scene.bending:
        terms.append(f"bending (k2 = {scene.bending.stiffness:g} N/m)")
    if scene.gravity:
        terms.append(f"gravity (g = {scene.gravity.g:g} m/s^2)")
    if model.has_drag:
        terms.append(f"drag (b = {scene.drag.b if scene.drag else 0:g} kg/s)")
    if scene.thrower:
        terms.append(f"thrower (v_max = {scene.thrower.v_max:g} m/s)")
    if scene.guides:
        terms.append(f"{len(scene.guides)} guide circle{'s' if len(scene.guides) > 1 else ''}")
    table.add_row("force terms", ", ".join(terms))
    held = []
    if scene.pinned:
        held.append(f"pinned {list(scene.pinned.nodes)}")
    for d in scene.driven:
        held.append(f"driven {list(d.nodes)} at {list(d.velocity)} m/s")
    if held:
        table.add_row("held nodes", "; ".join(held))
    for o in scene.overrides:
        parts = [f"mass {o.mass:g} kg" if o.mass is not None else "", f"drag {o.drag:g} kg/s" if o.drag is not None
                 else ""]
        table.add_row(f"node {o.index}", ", ".join(p for p in parts if p))
    table.add_row("time", f"{scene.integrator.method}, dt = {grid.dt:.6g} s, t_end = {scene.integrator.t_end:g} s "
                          f"({grid.steps} steps, {grid.frames} frames)")
    omega = stability_frequency(model)
    if omega > 0:
        table.add_row("fastest mode", f"omega_max <= {omega:.4g} rad/s (Gershgorin bound on the mass-weighted "
                                      f"stiffness)")
        for name, scheme in METHODS.items():
            bound = scheme.stability_limit / omega
            mark = "  <- this scene" if name == scene.integrator.method else ""
            verdict = "stable" if grid.dt <= bound else "UNSTABLE"
            table.add_row(f"  {name}", f"dt <= {bound:.4g} s (h omega <= {scheme.stability_limit:.3f}); "
                                       f"dt = {grid.dt:.3g} s is {verdict}{mark}")
    _console().print(table)
