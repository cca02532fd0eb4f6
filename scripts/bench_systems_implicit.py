"""The implicit solve of a system of lines against a single line of the same total size: cost per node.

    python scripts/bench_systems_implicit.py [--nodes 60,300,3000] [--repeats 5]

sdirk2 (and the static solver) on four layouts of the same 3-D steel wire (0.4 kg/m, EA 5 MN, in air, the
lines hanging in catenaries and swinging), N nodes in all:

- ``rope``: one rope of N nodes in the course's [rope] form, the one-line fast path (no junctions compiled);
- ``one line``: a system of one line of N nodes from an anchor to a free 200 kg weight (the same fast path: a
  point on one line is a node of it);
- ``spread``: three lines of N / 3 nodes from anchors 120 degrees apart to one free 200 kg point (one group,
  each line with one end on it: half of them factored from their far end);
- ``spread, forward only``: the same, every line factored from its first node (the reverse factorisation off),
  to show what that choice saves;
- ``series``: six lines in a row between two anchors, joined at five free 50 kg points (every inner line has a
  group at both ends, the worst case: one group's columns travel its whole length);
- ``spread, free body``: the spread's three lines to fairleads 1 m from the axis of a free 200 kg rigid body
  instead of the point (its six unknowns, its Newton-Euler equations and their linearisation in the solve).

Each contender runs the same number of steps, interleaved round by round (scripts/benchlib.py); the table gives
the median wall time per node and Newton iteration, and each one's ratio to ``one line`` (median of per-round
ratios). Then the static solver from each layout's straight guess: time per node and iteration.
"""

from __future__ import annotations

import argparse
import math
import time

from benchlib import interleaved, load_note, median, median_ratio

WIRE = "[line_types.wire]\ndiameter = 0.01\nmass_per_length = 0.4\nEA = 5.0e6\ncompression = true\n"
TAIL = '[gravity]\n[integrator]\nmethod = "sdirk2"\ndt = 0.002\nt_end = {t_end}\n[output]\ninterval = {t_end}\n'


def rope_text(n: int, t_end: float, start: list) -> str:
    """One rope of ``n`` nodes, the wire's material in physical units, pinned at node 0 with a 200 kg weight on
    its last node, starting from the node positions ``start`` (those of the one-line system)."""
    points = ", ".join(f"[{x:.17g}, {y:.17g}, {z:.17g}]" for x, y, z in start)
    return (f'name = "rope"\ndimension = 3\n[rope]\nsegments = {n - 1}\nlength = 60.0\nmass_per_length = 0.4\n'
            f"EA = 5.0e6\ndiameter = 0.01\ncompression = true\n"
            f'[initial]\nshape = "points"\npoints = [{points}]\nvelocity = [0.0, 0.0, 0.0]\n'
            f"[pinned]\nnodes = [0]\n[[bodies]]\nnode = {n - 1}\nmass = 200.0\n" + TAIL.format(t_end=t_end))


def points_text(points: list[tuple[str, tuple, float | None]], lines: list[tuple[str, str, float, int]],
                t_end: float) -> str:
    """A system: points (id, position, mass or None for an anchor), lines (start, end, length, segments)."""
    out = ['name = "system"\ndimension = 3\n', WIRE]
    for pid, position, mass in points:
        kind = f'kind = "free"\nmass = {mass}\n' if mass is not None else ""
        out.append(f'[[points]]\nid = "{pid}"\nposition = {list(position)}\n{kind}')
    for i, (start, end, length, segments) in enumerate(lines):
        out.append(f'[[lines]]\nid = "l{i}"\ntype = "wire"\nstart = "{start}"\nend = "{end}"\nlength = {length}\n'
                   f"segments = {segments}\n")
    out.append(TAIL.format(t_end=t_end))
    return "\n".join(out)


def body_text(anchors: list, per: int, t_end: float) -> str:
    """The spread's lines from ``anchors`` to fairleads on a free 200 kg body (inertia 20 kg m^2 about each axis)
    1 m from its axis, each line of ``per`` nodes."""
    out = ['name = "body_spread"\ndimension = 3\n', WIRE,
           '[[bodies]]\nid = "buoy"\nposition = [0.0, -30.0, 0.0]\nmass = 200.0\ninertia = [20.0, 20.0, 20.0]\n']
    for i, (pid, position, _) in enumerate(anchors):
        angle = 2 * math.pi * i / 3
        out.append(f'[[points]]\nid = "{pid}"\nposition = {list(position)}\n')
        out.append(f'[[points]]\nid = "f{i}"\nbody = "buoy"\nposition = [{math.cos(angle)!r}, 0.0, {math.sin(angle)!r}]\n')
        out.append(f'[[lines]]\nid = "l{i}"\ntype = "wire"\nstart = "{pid}"\nend = "f{i}"\nlength = 55.0\n'
                   f"segments = {per - 1}\n")
    out.append(TAIL.format(t_end=t_end))
    return "\n".join(out)


def layouts(n: int, t_end: float) -> dict[str, str]:
    """Each layout's scene text with about ``n`` nodes in all."""
    one = points_text([("a", (0.0, 0.0, 0.0), None), ("w", (40.0, -40.0, 0.0), 200.0)],
                      [("a", "w", 60.0, n - 1)], t_end)
    per = n // 3
    anchors = [(f"a{i}", (40.0 * math.cos(2 * math.pi * i / 3), 0.0, 40.0 * math.sin(2 * math.pi * i / 3)), None)
               for i in range(3)]
    spread = points_text(anchors + [("hub", (0.0, -30.0, 0.0), 200.0)],
                         [(f"a{i}", "hub", 55.0, per - 1) if i % 2 == 0 else ("hub", f"a{i}", 55.0, per - 1)
                          for i in range(3)], t_end)
    per = n // 6
    row = [("a0", (0.0, 0.0, 0.0), None)] + [(f"p{i}", (20.0 * i, -8.0, 0.0), 50.0) for i in range(1, 6)]
    row += [("a1", (120.0, 0.0, 0.0), None)]
    series = points_text(row, [(row[i][0], row[i + 1][0], 22.0, per - 1) for i in range(6)], t_end)
    from ropesim.model.build import build
    from ropesim.scene.loader import scene_from_toml

    start = build(scene_from_toml(one)).x0.T.tolist()
    return {"rope": rope_text(n, t_end, start), "one line": one, "spread": spread, "spread, forward only": spread,
            "series": series, "spread, free body": body_text(anchors, n // 3, t_end)}


def stepper(name: str, text: str):
    from ropesim.integrate.grid import TimeGrid
    from ropesim.integrate.methods import make_integrator
    from ropesim.model.build import build
    from ropesim.scene.loader import scene_from_toml

    scene = scene_from_toml(text)
    model = build(scene)
    it = make_integrator(model, TimeGrid.of(scene))
    if name.endswith("forward only"):
        it.newton.groups.reverse[:] = False
        rows, lines = it.newton.groups.rows, model.lines
        for k, line in enumerate(lines):   # slot 0's columns now reach along the whole line
            rows[k, 0] = (line.first * model.dim, line.end * model.dim)
    it.warm_up()
    return it, model


def dynamics(n: int, steps: int, repeats: int) -> None:
    texts = layouts(n, steps * 0.002)
    made = {name: stepper(name, text) for name, text in texts.items()}
    state = {name: it.state() for name, (it, _) in made.items()}
    iterations = {}

    def run(name):
        it, _ = made[name]
        it.restore(state[name])
        before = it.force_evaluations
        it.advance(steps)
        iterations[name] = it.force_evaluations - before

    times = interleaved({name: (lambda name=name: run(name)) for name in made}, repeats)
    per = {name: [t / (iterations[name] * made[name][1].nodes) for t in times[name]] for name in made}
    print(f"sdirk2, {steps} steps of 2 ms, N = {n} ({load_note()})")
    print(f"  {'layout':22s} {'nodes':>6s} {'Newton its/step':>16s} {'ns per node-iteration':>22s} "
          f"{'/ one line':>11s}")
    for name in made:
        print(f"  {name:22s} {made[name][1].nodes:6d} {iterations[name] / steps:16.2f} "
              f"{median(per[name]) * 1e9:22.1f} {median_ratio(per[name], per['one line']):11.3f}")


def statics(n: int, repeats: int) -> None:
    from ropesim.model.build import build
    from ropesim.model.statics import solve_equilibrium
    from ropesim.scene.loader import scene_from_toml

    texts = layouts(n, 1.0)
    texts.pop("spread, forward only")
    models = {name: build(scene_from_toml(text)) for name, text in texts.items()}
    count, converged = {}, {}

    def solve(name):
        result = solve_equilibrium(models[name])
        count[name], converged[name] = result.iterations, result.converged

    times = interleaved({name: (lambda name=name: solve(name)) for name in models}, repeats)
    per = {name: [t / (count[name] * models[name].nodes) for t in times[name]] for name in models}
    print(f"static solver from the straight guess, N = {n}")
    print(f"  {'layout':22s} {'iterations':>11s} {'us per node-iteration':>22s} {'/ one line':>11s}")
    for name in models:
        print(f"  {name:22s} {count[name]:11d} {median(per[name]) * 1e6:22.3f} "
              f"{median_ratio(per[name], per['one line']):11.3f}" + ("" if converged[name] else "  (not converged)"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", default="60,300,3000", help="total node counts (comma-separated)")
    parser.add_argument("--repeats", type=int, default=5, help="interleaved rounds")
    args = parser.parse_args()
    for n in (int(v) for v in args.nodes.split(",")):
        dynamics(n, max(20, 60000 // n), args.repeats)
        statics(n, max(1, args.repeats // 2))


if __name__ == "__main__":
    start = time.perf_counter()
    main()
    print(f"({time.perf_counter() - start:.0f} s)")
