"""What the command line prints: rich tables for a run's summary and a scene's check."""

from __future__ import annotations

import math

from pathlib import Path

from rich import box
from rich.console import Console
from rich.table import Table
from rich.text import Text

from ..scene.schema import Scene


def _console() -> Console:
    return Console(highlight=False)


def print_figures(console: Console, title: str, columns: list[str], rows: list[list[str]], keys: int = 2,
                  left: tuple[int, ...] = (0,)) -> None:
    """A table of figures that stays readable at 80 columns and when piped (rich then assumes 80 columns).

    No vertical rules, one space between columns, headers on two lines ("\\n" in a column name); the columns
    ``left`` (names) on the left, the figures on the right. A figure is never wrapped or cut:
    a table too wide for the terminal is printed in parts, each repeating the first ``keys`` columns. A row
    whose first cell is "" starts no new group; a row with a new first cell is set off by a blank line.
    """
    def width(i: int) -> int:
        return max(len(line) for cell in [columns[i], *(r[i] for r in rows)] for line in cell.splitlines() or [""])

    grouped = any(not row[0] for row in rows)   # some first cells left blank: set the groups apart
    parts, part = [], list(range(keys))
    for i in range(keys, len(columns)):
        if part[keys:] and sum(map(width, part + [i])) + len(part) > console.width:
            parts.append(part)
            part = list(range(keys))
        part.append(i)
    parts.append(part)
    for n, part in enumerate(parts):
        label = title + (f" ({n + 1} of {len(parts)})" if len(parts) > 1 else "")
        table = Table(title=label, title_justify="left", box=box.SIMPLE_HEAD, show_edge=False, padding=(0, 0))
        for i in part:
            table.add_column(Text(columns[i]), justify="left" if i in left else "right", no_wrap=True)
        for k, row in enumerate(rows):
            if k and row[0] and grouped:
                table.add_section()
            table.add_row(*(Text(row[i]) for i in part))
        console.print(table)


def print_compiled(results, cache: str, builtin: bool = True) -> None:
    """What ``ropesim compile`` did, per integrator (and the static solver): time and functions compiled, for the
    built-in scenes (``builtin``) or the scenes given."""
    rows = []
    for r in results:
        if r.functions:
            what = f"compiled {r.functions} function{'s' if r.functions != 1 else ''}"
        elif r.shared_with:
            what = f"shares the loop of {r.shared_with}"
        else:
            what = "in the cache already"
        rows.append([r.name, r.family, f"{r.seconds:.1f}", what])
    console = _console()
    print_figures(console, f"kernels in {cache}", ["kernel", "family", "time [s]", "what happened"], rows, keys=1,
                  left=(0, 1, 3))
    scenes = max((r.scenes for r in results if r.family != "statics"), default=0)
    which = "built-in scene" if builtin else "scene"
    console.print(f"each integrator made ready for {scenes} {which}{'s' if scenes != 1 else ''}: their runs load it "
                  f"from the cache instead of compiling (a scene with other parts compiles its own on its first "
                  f"run; name it to `ropesim compile` to prepare it now)")


def print_summary(summary: dict, folder: Path) -> None:
    """The run summary as a two-column table."""
    table = Table(title=f"{summary['scene']}: {summary['status']}", show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("", overflow="fold")  # words wrap; a word too long for the column folds, never cut
    rows = summary_rows(summary)
    rows.append(("written", written(summary, folder)))
    for key, value in rows:
        table.add_row(key, value)
    _console().print(table)


def summary_rows(summary: dict) -> list[tuple[str, str]]:
    """The run summary (``summary.json``) as (what, figures) rows, as `ropesim run` prints them (and the browser
    viewer shows them); an unfinished run's short summary gives the rows it has."""
    rows = []
    if "steps" in summary and "method" in summary:
        rows.append(("simulated", f"t = 0 .. {summary['t_end']:.6g} s, {summary['steps']} steps of "
                                  f"{summary['dt']:.3g} s ({summary['method']}), {summary['frames']} frames"))
    if "wall_time_s" in summary:
        rows.append(("wall time", f"{summary['wall_time_s']:.3g} s ({summary['steps_per_second'] or 0:,.0f} "
                                  f"steps/s, {summary['node_steps_per_second'] or 0:,.0f} node-steps/s); "
                                  f"compile or cache load {summary['compile_time_s']:.2g} s"))
    if summary.get("dt_requested"):
        rows.append(("time step", f"{summary['dt_requested']:.6g} s shortened to {summary['dt']:.6g} s so "
                                  f"t_end is a whole number of steps"))
    if summary.get("stable_dt_bound"):
        rows.append(("stable dt bound", f"{summary['stable_dt_bound']:.3g} s"))
    energy = summary.get("final_energy_J")
    if energy:
        rows.append(("final energy", ", ".join(f"{k} {v:.6g} J" for k, v in energy.items())))
        rows.append(("largest stretch", f"{100 * summary['max_spring_stretch']:.3g} % of the rest length "
                                        f"(max_spring_stretch {summary['max_spring_stretch']:.3g}; over the saved "
                                        f"frames, at t = {summary['max_spring_stretch_t']:.3g} s)"))
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
        if "mean_centroid_height_m" in shooter:
            rows.append(("loop height", f"centroid {shooter['centroid_height_m']:.3g} m above the thrower's centre "
                                        f"at t_end (mean {shooter['mean_centroid_height_m']:.3g} m)"))
    tension = summary.get("tension")
    if tension:
        rows.append(("tension", f"{tension['start_N']:.4g} N at node 0's end, {tension['end_N']:.4g} N at the "
                                f"other at t_end; largest {tension['max_N']:.4g} N (segment {tension['max_segment']}, "
                                f"t = {tension['max_t_s']:.3g} s)"))
    lines = summary.get("lines") or {}
    if lines:
        from ..analysis.tension import force_unit

        unit, scale = force_unit(max(abs(figures["max_N"]) for figures in lines.values()))
    for line, figures in lines.items():
        rows.append((f"tension, {line}", f"{figures['start_N'] / scale:.4g} {unit} at its start, "
                                         f"{figures['end_N'] / scale:.4g} {unit} at its end at t_end; largest "
                                         f"{figures['max_N'] / scale:.4g} {unit} (its segment "
                                         f"{figures['max_segment']}, t = {figures['max_t_s']:.3g} s)"))
    ledger = summary.get("energy_ledger")
    if ledger:
        flows = [f"{what} {ledger[key]:.4g} J" for what, key in (("drag took", "drag_loss_J"),
                                                                  ("held nodes gave", "held_work_J"),
                                                                  ("thrower and guides gave", "box_work_J"),
                                                                  ("the fluid gave", "fluid_work_J"),
                                                                  ("axial damping gave", "internal_work_J"),
                                                                  ("the seabed gave", "seabed_work_J"))
                 if ledger.get(key, 0.0) != 0.0]
        rows.append(("energy ledger", f"{', '.join(flows) or 'no energy flowed in or out'}; balance off by at "
                                      f"most {ledger['max_residual_J']:.3g} J ({ledger['relative_residual']:.2g} "
                                      f"of the energy that "
                                      f"{'flowed' if ledger['relative_to'] == 'flows' else 'moved'})"))
    if summary.get("message"):
        rows.append(("stopped", summary["message"]))
    return rows


def written(summary: dict, folder: Path) -> str:
    """What the run left in its folder: the finished run's files, an interrupted run's checkpoint, or (a rerun
    stopped before it replaced the earlier run) nothing."""
    if summary.get("kept_earlier_run"):
        return f"nothing: {folder}/ still holds the earlier run"
    if summary["status"] == "interrupted":
        return f"{folder}/ (frames in checkpoint/, scene.toml, summary.json; `ropesim run --resume {folder}` goes on)"
    return f"{folder}/ (trajectory.npz, ledger.npz, scene.toml, summary.json)"


def print_check(scene: Scene, source: Path) -> None:
    """What a scene contains, and its stability bounds, without running it."""
    from ..model.build import build
    from ..integrate.grid import TimeGrid

    from ..scene.frame import scene_out

    model = build(scene)
    grid = TimeGrid.of(scene)
    scene = scene_out(scene)    # shown in its own frame (a z-up scene's keys as its file gives them)
    table = Table(title=f"{source}: valid scene '{scene.name}'", show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("", overflow="fold")  # words wrap; a word too long for the column folds, never cut
    if scene.description:
        table.add_row("description", scene.description)
    for key, value in (system_rows(scene, model) if scene.is_system else rope_rows(scene)):
        table.add_row(key, value)
    if scene.up == "z":
        table.add_row("frame", "z up (up = \"z\"): computed in its y-up twin, (x, y, z) -> (x, z, -y); every output in "
                               "this frame")
    init = scene.initial
    if scene.is_system:
        table.add_row("initial", f"{init.shape}: " + ("every line straight or sagging from its start point to its "
                                                      "end point, at rest" if init.shape == "lines" else
                                                      "the static shape, solved before the run"))
    else:
        moving = ("a velocity per node" if getattr(init, "velocities", None) is not None
                  else f"velocity {list(init.velocity)} m/s")
        table.add_row("initial", f"{init.shape}, {moving}")
    table.add_row("force terms", ", ".join(force_terms(scene, model)))
    held = []
    if scene.pinned:
        clamped = f" (clamped {list(scene.pinned.clamped)})" if scene.pinned.clamped else ""
        held.append(f"pinned {list(scene.pinned.nodes)}{clamped}")
    for d in scene.driven:
        held.append(f"driven {list(d.nodes)} " + _motion_text(d))
    if held:
        table.add_row("held nodes", "; ".join(held))
    for o in scene.overrides:
        parts = [f"mass {o.mass:g} kg" if o.mass is not None else "", f"drag {o.drag:g} kg/s" if o.drag is not None
                 else ""]
        table.add_row(f"node {o.index}", ", ".join(p for p in parts if p))
    tol = getattr(scene.integrator, "tolerance", None)
    if tol is None:
        table.add_row("time", f"{scene.integrator.method}, dt = {grid.dt:.6g} s, t_end = {scene.integrator.t_end:g} "
                              f"s ({grid.steps} steps, {grid.frames} frames)")
    else:   # the scheme chooses its own steps; dt is where x and v are reported (dense output)
        table.add_row("time", f"{scene.integrator.method}, adaptive steps to a tolerance of {tol:g} m; dt = "
                              f"{grid.dt:.6g} s is the reporting grid (x and v read off the steps by dense output), "
                              f"t_end = {scene.integrator.t_end:g} s ({grid.steps} grid points, {grid.frames} "
                              f"frames)")
    for key, value in stability_rows(model, scene.integrator.method, grid.dt):
        table.add_row(key, value)
    _console().print(table)


def rope_rows(scene: Scene) -> list[tuple[str, str]]:
    """The check table's rows of what one rope is made of."""
    rope = scene.rope
    rows = [("rope", f"{rope.nodes} nodes, {'closed loop' if rope.closed else 'open line'}, "
                     f"{scene.dimension}-D; l = {rope.segment_length:g} m, k = {rope.stiffness:g} N/m, "
                     f"m = {rope.mass:g} kg" + (f" (the ends {rope.mass / 2:g} kg)" if rope.physical
                                                  and not rope.closed else "")
                     + ("" if rope.compression else "; slack in compression"))]
    if rope.physical:
        rows.append(("physical form", f"{rope.length:g} m in {rope.segments} segments, {rope.mass_per_length:g} "
                                      f"kg/m, EA = {rope.EA:g} N" + (f", d = {rope.diameter:g} m" if rope.diameter
                                                                     else "")))
    return rows


def system_rows(scene: Scene, model) -> list[tuple[str, str]]:
    """The check table's rows of what a system is made of: its size, then each line, point and rigid body."""
    count = lambda n, what: f"{n} {what}{'s' if n != 1 else ''}"   # noqa: E731
    bodies = len(scene.rigid_bodies)
    rows = [("system", f"{count(len(scene.lines), 'line')}, {count(len(scene.points), 'point')}"
                       + (f", {bodies} rigid bod{'ies' if bodies != 1 else 'y'}" if bodies else "")
                       + f", {scene.dimension}-D; {model.nodes} nodes")]
    for line, layout in zip(scene.lines, model.lines):
        material = [f"{line.mass_per_length:g} kg/m", f"EA = {line.EA:g} N"]
        material += [f"{name} = {value:g} {unit}" for name, value, unit in
                     (("d", line.diameter, "m"), ("BA", line.axial_damping, "N s"), ("EI", line.EI, "N m^2"))
                     if value]
        kind = f"{line.type}: " if line.type else ""
        rows.append((f"line {line.id}", f"{line.start} -> {line.end}, {line.length:g} m in {line.segments} segments "
                                        f"(nodes {layout.first} .. {layout.end - 1}); {kind}{', '.join(material)}"
                                        + ("" if layout.slack else "; pushes back in compression")))
    for point in scene.points:
        rows.append((f"point {point.id}", _point_text(point)))
    for body in scene.rigid_bodies:
        rows.append((f"body {body.id}", _body_text(body, scene)))
    return rows


def _point_text(point) -> str:
    """A system point in a phrase: its kind, where it is, what it carries or how it moves."""
    where = _point(point.position)
    if point.kind == "body":
        return f"on body {point.body}, at {where} m in its frame"
    if point.kind == "free":
        parts = [f"{point.mass:g} kg" if point.mass else "no mass of its own"]
        parts += [f"{name} {value:g}{unit}" for name, value, unit in (("volume", point.volume, " m^3"),
                                                                       ("CdA", point.cd_area, " m^2"),
                                                                       ("Ca", point.ca, "")) if value]
        return f"free, starting at {where} m; {', '.join(parts)}"
    if point.kind == "driven":
        return f"driven from {where} m " + _motion_text(point)
    if point.kind == "coupled":
        return f"coupled at {where} m (held there in a run of the scene alone)"
    return f"fixed at {where} m"


DOF_NAMES = ("x", "y", "z", "rx", "ry", "rz")


def _body_text(body, scene: Scene) -> str:
    """A rigid body in a phrase: its kind, where it starts, its mass and how it moves."""
    dim = scene.dimension
    turned = any(body.orientation or ())
    parts = [f"{body.kind}, reference point at {_point(body.position)} m"
             + (f", turned {_point(body.orientation)} deg" if turned else "")]
    if body.mass:
        parts.append(f"{body.mass:g} kg")
    if body.volume:
        parts.append(f"volume {body.volume:g} m^3")
    on = [p.id for p in scene.points if p.kind == "body" and p.body == body.id]
    parts.append(f"points {', '.join(on)}" if on else "no points")
    text = "; ".join(parts)
    if body.kind == "driven":
        names = DOF_NAMES if dim == 3 else ("x", "y", "rz")
        units = ["m"] * dim + ["deg"] * (len(names) - dim)
        axes = [f"{names[k]} {a:g} {units[k]}, {body.period[k]:g} s" for k, a in enumerate(body.amplitude or ()) if a]
        moves = []
        if any(body.velocity or ()) or any(body.angular_velocity or ()):
            moves.append(f"at {list(body.velocity)} m/s, {list(body.angular_velocity)} deg/s")
        if axes:
            moves.append("sinusoid " + "; ".join(axes))
        if body.path_table is not None:
            moves.append(f"a path of {len(body.path_table)} rows")
        ramp = f", ramped in over {body.ramp_time:g} s" if body.ramp_time and (axes or body.path_table is not None) \
            else ""
        text += "; " + (" + ".join(moves) + ramp if moves else "held still (every amplitude is 0)")
    if body.kind == "coupled":
        text += "; moved through ropesim.Coupling (held where the scene puts it by ropesim run)"
    return text


def force_terms(scene: Scene, model) -> list[str]:
    """Each force term the scene switches on, in a short phrase with its main parameters."""
    terms = ["springs"]
    if any(line.EI for line in model.lines):
        terms.append(f"bending stiffness ({_line_value(model, 'EI', 'EI', 'N m^2')})")
    if scene.bending:
        terms.append(f"bending (k2 = {scene.bending.stiffness:g} N/m)")
    if scene.gravity:
        terms.append(f"gravity (g = {scene.gravity.g:g} m/s^2)")
    if model.has_drag:
        terms.append(f"drag (b = {scene.drag.b if scene.drag else 0:g} kg/s)")
    if scene.thrower:
        angle = f", launch angle {scene.thrower.angle:g} deg" if scene.thrower.angle else ""
        terms.append(f"thrower (v_max = {scene.thrower.v_max:g} m/s{angle})")
    if scene.guides:
        terms.append(f"{len(scene.guides)} guide circle{'s' if len(scene.guides) > 1 else ''}")
    if any(line.axial_damping for line in model.lines):
        terms.append(f"axial damping ({_line_value(model, 'axial_damping', 'BA', 'N s')})")
    if scene.fluid:
        terms.append(f"fluid (rho = {scene.fluid.density:g} kg/m^3)")
    if scene.flow:
        terms.append(f"{scene.flow.profile.replace('_', ' ')} flow"
                     + (f", ramped over {scene.flow.ramp_time:g} s" if scene.flow.ramp_time else ""))
    if scene.fluid_drag:
        terms.append(f"fluid drag (Cd_n = {scene.fluid_drag.cd_normal:g}, Cd_t = {scene.fluid_drag.cd_tangential:g})")
    if scene.viscous_drag:
        terms.append(f"viscous drag (b_n = {scene.viscous_drag.b_normal:g}, b_t = {scene.viscous_drag.b_tangential:g} "
                     f"N s/m^2)")
    if scene.buoyancy:
        terms.append("buoyancy")
    if scene.added_mass:
        terms.append(f"added mass (Ca_n = {scene.added_mass.ca_normal:g}, Ca_t = {scene.added_mass.ca_tangential:g})")
    if scene.bodies:
        terms.append(f"{len(scene.bodies)} bod{'ies' if len(scene.bodies) > 1 else 'y'}")
    if scene.seabed:
        terms.append(_seabed_text(scene.seabed))
    if scene.sea:
        terms.append(_sea_text(scene))
    return terms


def _sea_text(scene) -> str:
    """The sea in one phrase: its level, depth, air and wind, the waves' kind and figures, stretching, ramp."""
    from ..model.waves import DEEP, components_of, water_depth

    sea, waves = scene.sea, scene.waves
    depth = water_depth(scene)
    where = f"level y = {sea.level:g} m, " + ("deep water" if depth == DEEP else f"{depth:g} m deep")
    air = f", air {sea.air_density:g} kg/m^3" + (f", wind {list(sea.wind)} m/s" if sea.wind is not None else "")
    rule = ", MoorDyn's submerged fraction" if sea.fraction == "moordyn" else ""
    text = f"sea ({where}{air}{rule})"
    if waves is None:
        return text + ", still"
    comps = components_of(waves, depth, scene.gravity.g)
    if waves.kind == "regular":
        length = 2.0 * math.pi / comps.k[0]
        what = f"regular waves H = {waves.height:g} m, T = {waves.period:g} s (L = {length:.4g} m)"
    elif waves.kind == "table":
        what = f"{comps.count} wave component{'s' * (comps.count > 1)} from a table"
    else:
        name = "JONSWAP" if waves.kind == "jonswap" else "Pierson-Moskowitz"
        gamma = f", gamma {waves.gamma:.3g}" if waves.kind == "jonswap" else ""
        what = (f"{name} waves Hs = {waves.significant_height:g} m, Tp = {waves.peak_period:g} s{gamma}, "
                f"{comps.count} components, seed {waves.seed}")
    heading = f", heading {waves.direction:g} deg" if waves.direction else ""
    ramp = f", ramped over {waves.ramp_time:g} s" if waves.ramp_time else ""
    return f"{text}, {what}{heading}, {waves.stretching} stretching{ramp}"


def _line_value(model, key: str, name: str, unit: str) -> str:
    """``name = value unit`` when every line that has ``key`` has the same value, else ``name per line``."""
    values = {getattr(line, key) for line in model.lines if getattr(line, key)}
    return f"{name} = {values.pop():g} {unit}" if len(values) == 1 else f"{name} per line"


def _seabed_text(bed) -> str:
    """The seabed in one phrase: where it is, its contact stiffness and damping, its friction."""
    slope = f" + tan({bed.slope:g} deg) x" if bed.slope else ""
    if bed.friction_axial is None or bed.friction_axial == bed.friction:
        friction = f", friction {bed.friction:g}" if bed.friction else ""
    else:
        friction = f", friction {bed.friction:g} across, {bed.friction_axial:g} along"
    return (f"seabed (y = {bed.height:g} m{slope}, kBot = {bed.stiffness:g} N/m^3, cBot = {bed.damping:g} "
            f"N s/m^3{friction})")


def _motion_text(drive) -> str:
    """How a driven node moves: its constant velocity, and its sinusoid and path, ramped in."""
    parts = [f"at {list(drive.velocity)} m/s"] if any(drive.velocity) or not drive.moving else []
    axes = [f"{'xyz'[k]} {a:g} m, {drive.period[k]:g} s" + (f", {drive.phase[k]:g} deg" if drive.phase[k] else "")
            for k, a in enumerate(drive.amplitude or ()) if a]
    if axes:
        parts.append("sinusoid " + "; ".join(axes))
    if drive.path_table is not None:
        parts.append(f"a path of {len(drive.path_table)} rows")
    if not parts:
        return "held still (every amplitude is 0)"
    ramp = f", ramped in over {drive.ramp_time:g} s" if (axes or drive.path_table is not None) and drive.ramp_time else ""
    return " + ".join(parts) + ramp


def stability_rows(model, method: str, dt: float) -> list[tuple[str, str]]:
    """The check table's stability rows: both bounds on omega_max and every method's largest stable dt."""
    from ..analysis.stability import WARN_FRACTION, bounds, drag_rates, explicit_damping

    g, s, rows = bounds(model)
    if g <= 0:
        return [("fastest mode", "no free node: nothing to integrate")]
    out = [("fastest mode", f"omega_max <= {s:.4g} rad/s (largest eigenvalue of the mass-weighted spring "
                            f"stiffness); Gershgorin bound {g:.4g} rad/s")]
    scene = model.scene
    damping = explicit_damping(model)
    if damping > 0:
        from ..model.terms import declared_terms

        rates = {term.name: term.damping(model) for term in declared_terms(scene)}
        names = ", ".join(name for name, rate in rates.items() if rate > 0)
        out.append(("velocity damping", f"up to {damping:.4g} 1/s ({names}); the bounds below include it where "
                                        f"a method evaluates it explicitly"))
    high = drag_rates(model)[1]
    if high > 0:
        out.append(("drag", f"b/m up to {high:.4g} 1/s: exact in the splitting schemes' kicks, explicit in rk4, "
                            f"implicit in sdirk2 and galpha"))
    sharp = [name for name, part in (("thrower", scene.thrower), *(("guides", g) for g in scene.guides))
             if part is not None and part.edge_width == 0]
    if sharp:
        out.append(("accuracy", "the thrower's and guides' forces switch on and off at sharp edges, which stops "
                                "every method converging as dt shrinks; edge_width smooths them (README: Accuracy "
                                "and stability)"))
    for b in rows:
        mark = "  <- this scene" if b.method == method else ""
        if b.dt_spectral == float("inf"):
            kind = "L-stable implicit" if b.method == "sdirk2" else "implicit, high modes damped by rho_inf"
            out.append((f"  {b.method}", f"stable at any dt ({kind}){mark}"))
            continue
        if dt > b.dt_spectral:
            verdict = "UNSTABLE: `ropesim run` refuses it without --force"
        elif dt > WARN_FRACTION * b.dt_spectral:
            verdict = f"above {WARN_FRACTION:.0%} of the bound: `ropesim run` warns"
        else:
            verdict = "stable"
        out.append((f"  {b.method}", f"dt <= {b.dt_spectral:.4g} s (Gershgorin: {b.dt_gershgorin:.4g} s; "
                                     f"h omega <= {b.h_omega:.3f} undamped); dt = {dt:.3g} s is {verdict}{mark}"))
    return out


def print_accuracy(report, folder: Path) -> None:
    """The accuracy table, the reference's convergence check and each method's observed order."""
    from ..analysis.accuracy import REFERENCE_FLOOR

    ref = report.reference
    rows, previous = [], None
    for r in report.rows:
        err = f"{r.error_max:.3e}" + ("*" if r.at_floor else "") if r.status == "completed" else r.status
        rows.append([r.method if r.method != previous else "", f"{r.dt:.4g}", err, f"{r.error_rms:.3e}",
                     f"{r.energy_error:.3e}", f"{r.wall_time:.3g}", f"{r.force_evaluations:,}"])
        previous = r.method
    console = _console()
    print_figures(console, f"{report.scene.name}: error at t = {report.t_end:g} s against {ref.method} at dt = "
                           f"{ref.dt:.3g} s",
                  ["method", "dt [s]", "largest\nerror [m]", "RMS\nerror [m]", "energy\nerror [J]", "wall\ntime [s]",
                   "force\nevals"], rows)
    console.print(f"reference: two refinements differ by {ref.difference:.2e} m; errors below "
                  f"{REFERENCE_FLOOR:g} x that (marked *) are left out of the orders")
    done = [r for r in report.rows if r.status == "completed"]
    if done and sum(r.at_floor for r in done) > len(done) / 2:
        console.print("[bold]warning:[/bold] most errors are within the reference's own uncertainty: the solution "
                      "is not converging (forces that switch on and off, as at sharp thrower or guide edges, do "
                      "this); the orders below are not meaningful")
    for name, (order, used) in report.orders.items():
        text = f"{order:.2f} (from {used} points)" if used >= 2 else "not measurable (fewer than 2 usable points)"
        console.print(f"observed order of {name}: {text}")
    console.print(f"written: {folder}/ (accuracy.csv, accuracy.png)")


def print_stability(result, folder: Path) -> None:
    """Predicted bounds against measured blow-up time steps."""
    rows, previous = [], None
    for b in result.bounds:
        k = f"{b['stiffness']:g}"
        row = [k if k != previous else "", b["method"]]
        previous = k
        if b["predicted_dt_spectral"] == float("inf"):
            measured = "none" if b["measured_blowup_dt"] == float("inf") else f"{b['measured_blowup_dt']:.4g}"
            rows.append(row + ["none", "none", measured, ""])
            continue
        ratio = b["predicted_dt_spectral"] / b["measured_blowup_dt"]
        rows.append(row + [f"{b['predicted_dt_spectral']:.4g}", f"{b['predicted_dt_gershgorin']:.4g}",
                           f"{b['measured_blowup_dt']:.4g}", f"{ratio:.3f}"])
    unstable = [r for r in result.rows if r["method"] == "sdirk2" and not r["stable"]]
    console = _console()
    print_figures(console, "stability: predicted bound against measured blow-up",
                  ["k [N/m]", "method", "bound\n[s]", "Gershgorin\n[s]", "measured\nblow-up [s]", "bound /\nmeasured"],
                  rows, left=(1,))
    if unstable:
        console.print(f"sdirk2 failed {len(unstable)} probes (Newton did not converge or the energy balance broke)")
    console.print(f"written: {folder}/ (stability.csv, bounds.csv, stability.png)")


def print_equilibrium(shape, source: str) -> None:
    """The static shape's figures (:class:`ropesim.analysis.statics.StaticShape`) as one table."""
    import numpy as np

    model, x = shape.model, shape.x
    scene = model.scene
    verdict = (f"static shape found in {shape.iterations} iterations" if shape.converged
               else f"NOT converged after {shape.iterations} iterations")
    table = Table(title=f"{source}: {verdict}", show_header=False, title_justify="left")
    table.add_column("", style="bold")
    table.add_column("", overflow="fold")
    table.add_row("residual", f"largest force left on a free node {shape.residual:.3g} N "
                              f"({shape.residual / shape.scale:.2g} of the largest force a term puts on a node, "
                              f"{shape.scale:.4g} N)")
    axes = "xyz"[:model.dim]
    if scene.is_system:
        _system_equilibrium_rows(table, shape, axes)
        _console().print(table)
        return
    for node, force in zip(shape.held, shape.supports):
        kind = "pinned" if scene.pinned and node in {scene.node(i) for i in scene.pinned.nodes} else "driven"
        parts = ", ".join(f"F{a} = {f:.6g}" for a, f in zip(axes, force))
        table.add_row(f"support, node {node}", f"{kind} at {_point(x[node])} m: {parts} N, "
                                               f"|F| = {float(np.linalg.norm(force)):.6g} N")
    tension = shape.tension
    if tension.size:
        k = int(np.argmax(tension))
        slack = int(np.count_nonzero(tension <= 0.0))
        table.add_row("tension", f"first segment {tension[0]:.6g} N, last segment {tension[-1]:.6g} N, largest "
                                 f"{tension[k]:.6g} N in segment {k}" + (f"; {slack} slack" if slack else ""))
    if scene.seabed is not None:
        if shape.grounded.size:
            where = (f"; touchdown at node {shape.touchdown}, {_point(x[shape.touchdown])} m"
                     if shape.touchdown is not None else "")
            table.add_row("seabed", f"{shape.grounded.size} nodes rest on it, carrying {shape.grounded_length:.6g} "
                                    f"m of rope{where}")
        else:
            table.add_row("seabed", "no node touches it")
    span = x[-1] - x[0]
    table.add_row("ends", f"node 0 at {_point(x[0])} m, the last node "
                          f"{', '.join(f'{a} {d:+.6g}' for a, d in zip(axes, span))} m from it")
    _console().print(table)


def _system_equilibrium_rows(table, shape, axes: str) -> None:
    """A system's rows of :func:`print_equilibrium`: each point (a support's force, a free point's position),
    each line's tensions, and what rests on the seabed."""
    import numpy as np

    for point in shape.points:
        where = f"{point.kind} at {_point(point.position)} m"
        if point.force is not None:
            parts = ", ".join(f"F{a} = {f:.6g}" for a, f in zip(axes, point.force))
            where += f": {parts} N, |F| = {float(np.linalg.norm(point.force)):.6g} N"
        table.add_row(f"point {point.id}", where)
    for line in shape.lines:
        text = (f"tension at its start {line.start_tension:.6g} N, at its end {line.end_tension:.6g} N, largest "
                f"{line.largest:.6g} N in its segment {line.largest_segment}")
        if line.slack:
            text += f"; {line.slack} slack"
        if line.grounded_length:
            text += f"; {line.grounded_length:.6g} m on the seabed"
            if line.touchdown is not None:
                text += f", touchdown at node {line.touchdown}, {_point(shape.x[line.touchdown])} m"
        table.add_row(f"line {line.id}", text)
    turns = "xyz" if len(axes) == 3 else "z"
    for body in shape.bodies:
        angles = ", ".join(f"{a:.6g}" for a in body.angles)
        table.add_row(f"body {body.id}", f"{body.kind} at {_point(body.position)} m, turned ({angles}) deg")
        for line, force in body.line_forces.items():
            parts = ", ".join(f"F{a} = {f:.6g}" for a, f in zip(axes, force))
            turn = ", ".join(f"M{a} = {m:.6g}" for a, m in zip(turns, body.line_moments[line]))
            table.add_row("", f"line {line} on it: {parts} N; {turn} N m about its reference point")
    if shape.model.scene.seabed is not None and not shape.grounded.size:
        table.add_row("seabed", "no node touches it")


def _point(p) -> str:
    return "(" + ", ".join(f"{float(c):.6g}" for c in p) + ")"


def check_data(scene: Scene, source) -> dict:
    """What ``ropesim check --json`` prints: the scene's make-up and every method's stability bound."""
    from ..analysis.stability import bounds
    from ..integrate.grid import TimeGrid
    from ..model.build import build

    from ..scene.frame import scene_out

    model = build(scene)
    grid = TimeGrid.of(scene)
    scene = scene_out(scene)    # in its own frame (a z-up scene's keys as its file gives them)
    omega_gershgorin, omega, rows = bounds(model)
    out = {"source": str(source), "valid": True, "scene": scene.name, "description": scene.description,
           "dimension": scene.dimension, "up": scene.up, "nodes": model.nodes}
    if scene.is_system:
        out.update(system_data(scene, model))
    else:
        rope = scene.rope
        held = []
        if scene.pinned:
            held += [{"kind": "pinned", "nodes": list(scene.pinned.nodes)}]
        held += [{"kind": "driven", "nodes": list(d.nodes), "motion": _motion_text(d)} for d in scene.driven]
        out.update({"closed": rope.closed, "segment_length_m": rope.segment_length,
                    "stiffness_N_per_m": rope.stiffness, "node_mass_kg": rope.mass,
                    "force_terms": force_terms(scene, model), "held": held})
    out.update({
        "method": scene.integrator.method, "dt_s": grid.dt, "t_end_s": scene.integrator.t_end,
        "steps": grid.steps, "frames": grid.frames,
        "dt_is": "grid" if getattr(scene.integrator, "tolerance", None) is not None else "step",
        "omega_max_rad_per_s": omega if omega_gershgorin > 0 else None,
        "stable_dt_s": {b.method: (None if b.dt_spectral == float("inf") else b.dt_spectral) for b in rows},
    })
    return out


def system_data(scene: Scene, model) -> dict:
    """A system's make-up for ``ropesim check --json``: its lines (with their nodes), points and rigid bodies."""
    lines = [{"id": line.id, "start": line.start, "end": line.end, "type": line.type, "length_m": line.length,
              "segments": line.segments, "first_node": layout.first, "nodes": layout.nodes,
              "segment_length_m": layout.segment_length, "stiffness_N_per_m": layout.stiffness,
              "mass_per_length_kg_per_m": line.mass_per_length, "EA_N": line.EA}
             for line, layout in zip(scene.lines, model.lines)]
    points = [{"id": p.id, "kind": p.kind, "position_m": list(p.position), "body": p.body, "text": _point_text(p)}
              for p in scene.points]
    bodies = [{"id": b.id, "kind": b.kind, "position_m": list(b.position), "mass_kg": b.mass,
               "text": _body_text(b, scene)} for b in scene.rigid_bodies]
    return {"lines": lines, "points": points, "bodies": bodies, "force_terms": force_terms(scene, model)}


def equilibrium_data(shape, source: str) -> dict:
    """What ``ropesim equilibrium --json`` prints: the figures of :func:`print_equilibrium`, in SI units."""
    import numpy as np

    model, x = shape.model, shape.x
    scene = model.scene
    pinned = {scene.node(i) for i in scene.pinned.nodes} if scene.pinned else set()
    out = {
        "source": source, "converged": bool(shape.converged), "iterations": int(shape.iterations),
        "residual_N": float(shape.residual), "force_scale_N": float(shape.scale),
        "supports": [{"node": int(node), "kind": "pinned" if node in pinned else "driven",
                      "position_m": [float(c) for c in x[node]], "force_N": [float(f) for f in force],
                      "magnitude_N": float(np.linalg.norm(force))}
                     for node, force in zip(shape.held, shape.supports)] if not scene.is_system else None,
        "tension_N": [float(f) for f in shape.tension],
        "positions_m": [[float(c) for c in row] for row in x],
    }
    if scene.is_system:   # a system's supports are its fixed and driven points
        del out["supports"]
        out["points"] = [{"id": p.id, "kind": p.kind, "position_m": [float(c) for c in p.position]}
                         | ({"force_N": [float(f) for f in p.force], "magnitude_N": float(np.linalg.norm(p.force))}
                            if p.force is not None else {}) for p in shape.points]
        out["lines"] = [{"id": line.id, "start_tension_N": line.start_tension, "end_tension_N": line.end_tension,
                         "largest_tension_N": line.largest, "largest_segment": line.largest_segment,
                         "slack_segments": line.slack, "grounded_length_m": line.grounded_length,
                         "touchdown_node": line.touchdown} for line in shape.lines]
        out["bodies"] = [{"id": body.id, "kind": body.kind, "position_m": [float(c) for c in body.position],
                          "quaternion": [float(c) for c in body.quaternion],
                          "angles_deg": [float(c) for c in body.angles],
                          "lines": [{"id": line, "force_N": [float(f) for f in force],
                                     "moment_Nm": [float(m) for m in body.line_moments[line]]}
                                    for line, force in body.line_forces.items()]} for body in shape.bodies]
    if scene.seabed is not None:
        out["seabed"] = {"grounded_nodes": [int(i) for i in shape.grounded],
                         "grounded_length_m": float(shape.grounded_length),
                         "touchdown_node": None if shape.touchdown is None else int(shape.touchdown)}
    return out


def print_window(figures: dict, folder) -> None:
    """``ropesim summary``: a run's tension and support figures over a window of time, in N or kN."""
    from ..analysis.tension import force_unit

    unit, scale = force_unit(1e3 if figures["unit"] == "kN" else 0.0)
    console = _console()
    console.print(f"{folder}: t = {figures['from_s']:g} .. {figures['to_s']:g} s ({figures['frames']} frames)")

    def row(name, stats):
        return [name, *(f"{stats[k] / scale:.4g}" for k in ("min", "max", "mean", "std"))]

    if "lines" in figures:
        rows = []
        for line, part in figures["lines"].items():
            rows += [row(f"{line}: start", part["start"]), row(f"{line}: end", part["end"])]
        labels = figures.get("support_labels", [])
    else:
        rows = [row("segment 0 (node 0's end)", figures["start"]), row("last segment", figures["end"])]
        labels = [f"support {h}" for h in range(len(figures.get("supports", [])))]
    for label, stats in zip(labels, figures.get("supports", [])):
        rows.append(row(f"{label}: |F|", stats))
    columns = ["", f"min\n[{unit}]", f"max\n[{unit}]", f"mean\n[{unit}]", f"std\n[{unit}]"]
    print_figures(console, "tension and support forces", columns, rows, keys=1)
    for name, part in (figures["lines"] if "lines" in figures else {"": figures}).items():
        console.print(f"largest tension{f' in {name}' if name else ''} {part['max_N'] / scale:.4g} {unit} in "
                      f"{'its ' if name else ''}segment {part['max_segment']} at t = {part['max_t_s']:g} s")
