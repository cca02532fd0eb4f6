"""ropesim against the tools a user would otherwise pick: MoorDyn (`moordyn`) and PyElastica (`pyelastica`).

The same towed rope in each: the helicopter's uniform rope (scenarios/helicopter_uniform.toml: node spacing
0.5 m, 5 kg per node, axial stiffness k l = 2500 N, gravity 9.81, drag b = 5 kg/s per node), N nodes hanging
straight down from a point towed at 8 m/s, every node starting at 8 m/s, dt = 1 ms, t_end = 3 s, at N = 21
and N = 1000. Each tool is set up once per round (untimed), then its time loop is timed; rounds are
interleaved and the medians reported. A column shows where the rope's free end is at t_end relative to the
towed point, and its longest segment over the rest length: a check that each tool simulated a comparable
rope (the material is very stretchy: at N = 1000 the rope's weight is 20 times its EA, so long segments near
the top are physics, not a fault).

What differs, by construction of each tool:

- MoorDyn (lumped-mass mooring-line model, C++): drag is Morison's quadratic drag only, so its drag
  coefficient is set to match ropesim's linear drag at the tow speed (same force per metre at 8 m/s),
  axially too; no added mass, no internal damping, no bending; its end nodes carry half a segment's mass
  (ropesim's carry a whole node's); it runs in 3-D; the towed point's motion is handed to it every 0.1 s
  (its internal steps interpolate). Time scheme: explicit Euler (1 force evaluation per step, the closest to
  ropesim's symplectic Euler) and its default RK2 (2 evaluations).
- PyElastica (Cosserat rod, NumPy + Numba kernels called from a Python loop): a rod with bending, shear and
  twist, not a chain of springs; radius 1 cm and Young's modulus set so EA = 2500 N (bending stiffness
  0.06 N m^2, negligible), density so the mass per metre is 10 kg/m (end nodes half); linear damping via
  its AnalyticalLinearDamper at gamma = b / m = 1/s, which also damps rotation; position Verlet steps; the
  towed end is a custom constraint x0 + V t. Our set-up of this scene in PyElastica is not stable at this
  dt: after about a second the first segments stretch without bound (hanging without towing it is
  stable); its time per step does not depend on that, so the timing stands, but its shape does not.

If a peer is not installed (`pip install -e ".[bench]"`) or fails here, its row says so.

    python scripts/bench_peers.py [--repeats 5] [--sizes 21,1000]
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import sys
import time

import numpy as np
from rich.console import Console
from rich.table import Table

from benchlib import load_note, median, stepper_for, towed_scene

L0, M, K, B, G, V = 0.5, 5.0, 5000.0, 5.0, 9.81, 8.0
DT, T_END = 0.001, 3.0
STEPS = round(T_END / DT)
RADIUS = 0.01   # PyElastica rod radius [m]


@contextlib.contextmanager
def quiet_fd():
    """Silence a C library's prints to stdout/stderr (MoorDyn reports every line it reads)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    with open(os.devnull, "w") as null:
        os.dup2(null.fileno(), 1)
        os.dup2(null.fileno(), 2)
        try:
            yield
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])


class Ropesim:
    label = "ropesim (symplectic Euler)"
    note = "linear drag exact in each kick; 2-D"

    def __init__(self, n):
        self.n = n

    def setup(self):
        self.stepper = stepper_for(towed_scene(self.n, "symplectic_euler", STEPS))

    def run(self):
        self.stepper.advance(STEPS)

    def shape(self):
        return self.stepper.x.T


class MoorDyn:
    note = "quadratic drag matched at 8 m/s; starts at rest; 3-D"

    def __init__(self, n, scheme):
        self.n, self.scheme = n, scheme
        self.label = f"MoorDyn ({scheme})"
        import moordyn  # noqa: F401  (fails here, not mid-table, when MoorDyn is missing)

    def input_file(self, path):
        segs = self.n - 1
        d = 0.05
        cd = 2 * (B / L0) / (1.225 * d * V)         # 0.5 rho Cd d V^2 = (b / l) V, per metre
        top = -1.0                                  # MoorDyn's points live below its water surface z = 0
        path.write_text(f"""towed rope, ropesim benchmark
---------------------- LINE TYPES -----------------------------------
TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx
(name) (m) (kg/m) (N) (N-s) (N-m^2) (-) (-) (-) (-)
rope {d} {M / L0} {K * L0} 0.0 0.0 {cd} 0.0 {cd / math.pi} 0.0
---------------------- POINTS ---------------------------------------
ID Attachment X Y Z Mass Volume CdA Ca
(#) (word/ID) (m) (m) (m) (kg) (m^3) (m^2) (-)
1 Coupled 0 0 {top} 0 0 0 0
2 Free 0 0 {top - segs * L0} 0 0 0 0
---------------------- LINES ----------------------------------------
ID LineType AttachA AttachB UnstrLen NumSegs LineOutputs
(#) (name) (ID) (ID) (m) (-) (-)
1 rope 2 1 {segs * L0} {segs} -
---------------------- OPTIONS -----------------------------------------
{DT} dtM
{self.scheme} tScheme
{G} g
1.225 rho
100000 WtrDpth
0 writeLog
1 disableOutput
---------------------- OUTPUTS -----------------------------------------
-------------------------------------------------------------------------
""")
        return top

    def setup(self):
        import tempfile
        from pathlib import Path

        import moordyn

        self.md = moordyn
        folder = Path(tempfile.mkdtemp(prefix="ropesim-moordyn-"))
        self.top = self.input_file(folder / "towed.txt")
        with quiet_fd():
            self.system = moordyn.Create(str(folder / "towed.txt"))
            moordyn.Init_NoIC(self.system, [0.0, 0.0, self.top], [V, 0.0, 0.0])
        self.line = moordyn.GetLine(self.system, 1)

    def run(self):
        md, chunk, t = self.md, 0.1, 0.0
        with quiet_fd():
            for _ in range(round(T_END / chunk)):
                md.Step(self.system, [V * (t + chunk), 0.0, self.top], [V, 0.0, 0.0], t, chunk)
                t += chunk

    def shape(self):
        nodes = np.array([self.md.GetLineNodePos(self.line, i) for i in range(self.n)])[::-1]  # towed end first
        with quiet_fd():
            self.md.Close(self.system)
        return nodes[:, [0, 2]]


class PyElastica:
    label = "PyElastica (position Verlet)"
    note = "Cosserat rod; damper also damps rotation; 3-D"

    def __init__(self, n):
        self.n = n
        import elastica  # noqa: F401

    def setup(self):
        import elastica as ea

        class Towed(ea.ConstraintBase):
            def __init__(self, x0, velocity, **kwargs):   # PyElastica passes node 0's position as x0
                super().__init__(**kwargs)
                self.x0, self.velocity = np.array(x0, float).reshape(3), np.asarray(velocity, float)

            def constrain_values(self, system, time):
                system.position_collection[:, 0] = self.x0 + self.velocity * time

            def constrain_rates(self, system, time):
                system.velocity_collection[:, 0] = self.velocity

        class Sim(ea.BaseSystemCollection, ea.Constraints, ea.Forcing, ea.Damping):
            pass

        radius = RADIUS
        area = math.pi * radius ** 2
        sim = Sim()
        rod = ea.CosseratRod.straight_rod(
            self.n - 1, np.zeros(3), np.array([0.0, -1.0, 0.0]), np.array([0.0, 0.0, 1.0]), (self.n - 1) * L0,
            radius, (M / L0) / area, youngs_modulus=K * L0 / area, shear_modulus=K * L0 / area / 3.0)
        rod.velocity_collection[0, :] = V
        sim.append(rod)
        sim.constrain(rod).using(Towed, constrained_position_idx=(0,), velocity=[V, 0.0, 0.0])  # x0: node 0
        sim.add_forcing_to(rod).using(ea.GravityForces, acc_gravity=np.array([0.0, -G, 0.0]))
        sim.dampen(rod).using(ea.AnalyticalLinearDamper, uniform_damping_constant=B / M, time_step=DT)
        sim.finalize()
        self.ea, self.sim, self.rod = ea, sim, rod
        self.stepper = ea.PositionVerlet()

    def run(self):
        self.ea.integrate(self.stepper, self.sim, T_END, STEPS, progress_bar=False)

    def shape(self):
        return self.rod.position_collection[:2].T


def shape_figures(xy: np.ndarray) -> tuple[tuple[float, float], float]:
    """(free end minus towed point (x, up) [m], longest segment / rest length) of nodes (N, 2), towed first."""
    seg = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    return (float(xy[-1, 0] - xy[0, 0]), float(xy[-1, 1] - xy[0, 1])), float(seg.max() / L0)


def contenders(n: int, console: Console) -> list:
    out = [Ropesim(n)]
    for make, name in ((lambda: MoorDyn(n, "Euler"), "MoorDyn"), (lambda: MoorDyn(n, "RK2"), "MoorDyn"),
                       (lambda: PyElastica(n), "PyElastica")):
        try:
            out.append(make())
        except ImportError as exc:
            out.append((name, f"not installed here ({exc.name}); pip install -e \".[bench]\""))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--sizes", default="21,1000")
    args = parser.parse_args()
    console = Console(width=max(150, Console().width))
    table = Table(title=f"Towed rope, dt = {DT * 1e3:g} ms, t_end = {T_END:g} s ({STEPS} steps): time loop only, "
                        f"median of {args.repeats} interleaved rounds")
    for col in ("N", "tool", "time", "node-steps/s", "vs ropesim",
                "t_end: free end - tow point [m]; longest segment / l0",
                "differences"):
        table.add_column(col, justify="left" if col in ("tool", "differences") else "right")
    for n in (int(s) for s in args.sizes.split(",")):
        tools = contenders(n, console)
        live = [t for t in tools if not isinstance(t, tuple)]
        times: dict = {t.label: [] for t in live}
        ends, failed = {}, {}
        for rnd in range(args.repeats + 1):
            for tool in live:
                if tool.label in failed:
                    continue
                try:
                    tool.setup()
                    start = time.perf_counter()
                    tool.run()
                    elapsed = time.perf_counter() - start
                    ends[tool.label] = shape_figures(tool.shape())
                except Exception as exc:  # a peer that cannot run here is reported, not fatal
                    failed[tool.label] = f"failed here: {type(exc).__name__}: {exc}"
                    continue
                if rnd:
                    times[tool.label].append(elapsed)
        base = median(times[live[0].label])
        for tool in tools:
            if isinstance(tool, tuple):
                table.add_row(str(n), tool[0], "-", "-", "-", "-", tool[1])
                continue
            if tool.label in failed:
                table.add_row(str(n), tool.label, "-", "-", "-", "-", failed[tool.label])
                continue
            t = median(times[tool.label])
            (dx, dy), stretch = ends[tool.label]
            ours = ends[live[0].label][1]
            sane = "" if stretch < 2.0 * ours else " (diverged: over twice ropesim's longest segment)"
            table.add_row(str(n), tool.label, f"{t * 1e3:,.1f} ms", f"{n * STEPS / t / 1e6:,.1f} M/s",
                          f"{base / t:.2f}x" if tool is not live[0] else "1",
                          f"({dx:+.2f}, {dy:+.2f}), {stretch:.2f}" + sane, tool.note)
    console.print(table)
    console.print("vs ropesim: ropesim's time / the tool's time (below 1: slower than ropesim). " + load_note())


if __name__ == "__main__":
    main()
