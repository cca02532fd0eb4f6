"""MoorDyn's own test cases, built as ropesim scenes on equal physics: the cases of
``scripts/compare_moordyn_cases.py`` and ``tests/test_moordyn_own_cases.py``.

The cases are MoorDyn's input files copied to ``tests/data/moordyn/cases/`` (their README says where from), and
MoorDyn 2.7.2's runs of them stored beside (``<case>.npz``, ``<case>.json``, made by
``scripts/moordyn_reference.py``): the state after MoorDyn's initial-condition (IC) solve, and a dynamic run. Each
ropesim scene here is read from the same input file (:func:`read_input`), so both codes run one description:

- **WD0050_Chain, WD0200_Chain, WD0600_Chain**: a studless chain (d = 0.252 m volume-equivalent, 390 kg/m,
  EA = 1.674e9 N, critical axial damping per segment, Cd 1.37, Ca 1, CdAx 0.64, CaAx 0) from an anchor on the
  seabed to a fairlead at the water surface, in 50, 200 and 600 m of water; a seabed spring kBot = 1e5 Pa/m and
  dashpot cBot = 1e4 Pa s/m on each node's footprint d l_i, MoorDyn's friction coefficient 0.5. The stored dynamic
  run drives the fairlead in surge, x = f(t) A sin(2 pi t / T) (f: a smootherstep ramp over the first period),
  handed to MoorDyn every 0.1 s as a position and the secant velocity, so its fairlead moves piecewise linearly;
  ropesim's fairlead follows the same points as a ``path_table`` (:func:`path_rows`): the identical path.
- **BeamCantilevered**: a 10 m beam with EI = 1e7 N m^2, 100 kg/m, in air, clamped to a fixed rod at one end and
  free at the other; the stored dynamic run releases it straight and at rest under gravity.

Equal physics, item by item (MOORDYN_CONVENTIONS.md has MoorDyn's side, with its source lines):

- the line, its lumping, tension-only EA, BA damping in both directions (BA = zeta (L/N) sqrt(EA m') for MoorDyn's
  negative input), Morison drag across and along, buoyancy, the added-mass matrix, g = 9.80665 m/s^2: as in
  ``moordyn_equal_physics.py``;
- the seabed: MoorDyn's is the plane z = -depth; ropesim's ``[seabed]`` the same plane (``height`` = -depth, flat),
  with kBot and cBot per unit of the footprint d l_i, the same on both sides;
- friction: MoorDyn's is mu FricDamp |v_h| against the horizontal velocity v_h, capped at mu |B_z| (|B_z| the
  seabed's normal force). FricDamp = 200 N s/m is per node whatever its load, so the cap is reached only at
  |v_h| = |B_z| / FricDamp: 83, 154 and 166 m/s on the three chains' grounded inner nodes (|B_z| = w l, w the
  submerged weight per metre). In practice MoorDyn's friction is the linear drag mu FricDamp per node. ropesim's
  regularised Coulomb friction mu N v / sqrt(v^2 + v_reg^2), N = k delta A the contact spring's load, is that
  same drag for |v| << v_reg when v_reg = w l / FricDamp (:attr:`ChainCase.friction_speed`); the two differ where a
  node carries less than w l (in the touchdown zone ropesim's friction is weaker there). Both are zero in the
  static state; over the dynamic runs friction moves the fairlead tension by 3e-5 of its range;
- the beam: ropesim's ``rope.EI`` with its end ``pinned.clamped`` along the rod's axis (its clamp joint of
  stiffness 2 EI / l is MoorDyn's curvature over a single segment at a rod end), the far end free; no fluid
  (the beam is 10 m above MoorDyn's water);
- not equal: MoorDyn's fairleads sit at z = 0, the water surface, so its top segment is 96.4 % submerged (the
  fairlead node's buoyancy 3.6 % low, its neighbour's 1.8 %: 45 N on a 1 MN line); ropesim's fluid fills all space.

What is compared (MoorDyn's frame z up; ropesim's y up; the chains and the beam stay in the x-z plane, so they run
in 2-D, (x, z) -> (x, y); :func:`to_ropesim`):

- the fairlead tension, MoorDyn's ``GetLineFairTen``: |T + Td| of the top segment, spring plus axial damping.
  MoorDyn reports it from its last force evaluation, with the fairlead moving at the secant velocity of the
  coupling interval that *ends* at the frame. That velocity jumps at every coupling instant (by A w^2 dt_out =
  0.088 m/s on WD0050), and the top segment's damping force BA/l times the jump is up to 71 kN there, 2.4 % of the
  tension's range. ropesim's frame holds the driven node's velocity on one side or the other of the jump (the
  path's row and the step's time meet to within rounding). So both sides are compared on MoorDyn's definition:
  :func:`fairlead_tension` computes ropesim's top-segment tension from its frame's positions and node N-1's
  velocity with the fairlead's velocity over the interval ending at the frame;
- the anchor tension (``GetLineNodeTen(0)``: the bottom segment's |T + Td|), which the jump does not touch;
- the beam: its tip's height over time, and its static deflection.

Units: SI throughout.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .moordyn_harness import MOORDYN_DEFAULT_G, sinusoidal_motion

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
CASES_DIR = DATA / "cases"
CHAINS = ("WD0050_Chain", "WD0200_Chain", "WD0600_Chain")
BEAM = "BeamCantilevered"


# ------------------------------------------------------------------------------------------------ MoorDyn's file


@dataclass(frozen=True)
class MoorDynInput:
    """The parts of a MoorDyn v2 input file used here, as read: each table a list of rows (dicts keyed by the
    file's own lower-case column names, values as strings), and the options (lower-case name -> value string)."""

    line_types: list[dict]
    rod_types: list[dict]
    rods: list[dict]
    points: list[dict]
    lines: list[dict]
    options: dict[str, str]


_SECTIONS = {"line types": "line_types", "line dictionary": "line_types", "rod types": "rod_types",
             "rod dictionary": "rod_types", "rods": "rods", "rod properties": "rods", "points": "points",
             "point properties": "points", "connection properties": "points", "node properties": "points",
             "lines": "lines", "line properties": "lines", "options": "options"}


def read_input(path: str | Path) -> MoorDynInput:
    """Read a MoorDyn input file's tables and options (MoorDyn's layout: a ``---- NAME ----`` header, for tables
    two rows of column names and units, then one row per item; options as ``value name [comment]``)."""
    tables: dict[str, list] = {k: [] for k in ("line_types", "rod_types", "rods", "points", "lines")}
    options: dict[str, str] = {}
    section, header, skip = None, None, 0
    for raw in Path(path).read_text(encoding="utf-8").splitlines():
        line = raw.strip()
        if line.startswith("---"):
            title = line.strip("- ").lower()
            section = next((v for k, v in _SECTIONS.items() if title == k or title.startswith(k + " ")), None)
            header, skip = None, 2
            continue
        if section is None or not line:
            continue
        words = line.split()
        if section == "options":
            if len(words) >= 2:
                options[words[1].lower()] = words[0]
            continue
        if skip:
            if skip == 2:
                header = [w.lower() for w in words]
            skip -= 1
            continue
        tables[section].append(dict(zip(header, words)))
    return MoorDynInput(options=options, **tables)


def moordyn_ba(ba_input: float, length: float, segments: int, EA: float, mass_per_length: float) -> float:
    """MoorDyn's axial damping BA (N s) from its input: a negative input -zeta is a damping ratio of one segment's
    axial mode, BA = zeta (L/N) sqrt(EA m') (``Line::initialize``); a positive one is BA itself."""
    if ba_input < 0.0:
        return -ba_input * length / segments * math.sqrt(EA * mass_per_length)
    return ba_input


def to_ropesim(p) -> np.ndarray:
    """MoorDyn positions or vectors (..., 3) in the x-z plane as ropesim's 2-D (x, y up): (x, y, z) -> (x, z)."""
    return np.asarray(p, dtype=float)[..., [0, 2]]


def load_reference(name: str) -> tuple[dict, dict]:
    """The stored MoorDyn run of a case: (arrays of ``<name>.npz``, the ``<name>.json`` record)."""
    with np.load(DATA / f"{name}.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    return arrays, json.loads((DATA / f"{name}.json").read_text(encoding="utf-8"))


# ------------------------------------------------------------------------------------------------ the chains


@dataclass(frozen=True)
class ChainCase:
    """One of MoorDyn's chain cases, in MoorDyn's frame (z up, m, s, kg, N).

    anchor: end A (fixed, on the seabed); fairlead: end B at rest; depth: water depth (seabed at z = -depth);
    BA: MoorDyn's resolved axial damping (N s); kbot (Pa/m), cbot (Pa s/m), friction (-), fric_damp (N s/m per
    node): MoorDyn's seabed; rho_w (kg/m^3), g (m/s^2); dtM: MoorDyn's step in the stored run (s). The stored
    motion: surge amplitude (m), period (s), ramp_periods, t_end (s) and the coupling interval dt_out (s)."""

    name: str
    length: float
    segments: int
    diameter: float
    mass_per_length: float
    EA: float
    BA: float
    Cd: float
    Ca: float
    CdAx: float
    CaAx: float
    anchor: tuple[float, float, float]
    fairlead: tuple[float, float, float]
    depth: float
    kbot: float
    cbot: float
    friction: float
    fric_damp: float
    rho_w: float
    g: float
    dtM: float
    amplitude: float
    period: float
    ramp_periods: float
    t_end: float
    dt_out: float

    def with_(self, **changes) -> ChainCase:
        return replace(self, **changes)

    @property
    def segment_length(self) -> float:
        return self.length / self.segments

    @property
    def wet_weight(self) -> float:
        """Submerged weight per metre w (N/m)."""
        return (self.mass_per_length - self.rho_w * math.pi / 4.0 * self.diameter ** 2) * self.g

    @property
    def friction_speed(self) -> float:
        """ropesim's friction_speed v_reg that makes its friction MoorDyn's linear mu FricDamp on a grounded inner
        node: v_reg = w l / FricDamp (m/s; see the module docstring)."""
        return self.wet_weight * self.segment_length / self.fric_damp

    def motion(self):
        """The stored run's fairlead path, t (s) -> MoorDyn position (m): ``moordyn_harness.sinusoidal_motion``."""
        return sinusoidal_motion(self.fairlead, self.amplitude, self.period, 0, self.ramp_periods)


@dataclass(frozen=True)
class Surge:
    """A smooth surge of the fairlead, ropesim's ``[[driven]]`` sinusoid: x(t) = x0 + r(t) A sin(2 pi t / T) along
    x, r(t) ropesim's smootherstep ramp (10 u^3 - 15 u^4 + 6 u^5, u = t / ramp_time) until ramp_time, then 1.
    amplitude A (m), period T (s), ramp_time (s)."""

    amplitude: float
    period: float
    ramp_time: float

    def motion(self, x0):
        """The same path as a function t (s) -> MoorDyn position (m), for MoorDyn's coupled fairlead."""
        x0 = np.asarray(x0, dtype=float)

        def path(t: float) -> np.ndarray:
            if self.ramp_time <= 0.0 or t >= self.ramp_time:
                r = 1.0
            else:
                u = max(t, 0.0) / self.ramp_time
                r = u * u * u * (10.0 + u * (-15.0 + 6.0 * u))
            x = x0.copy()
            x[0] += r * self.amplitude * math.sin(2.0 * math.pi * t / self.period)
            return x

        return path


def chain_case(name: str) -> ChainCase:
    """A chain case read from MoorDyn's input file (line, points, seabed, options, MoorDyn 2.7.2's defaults where
    the file is silent) and the stored run's record (its motion and MoorDyn's step)."""
    md = read_input(CASES_DIR / f"{name}.txt")
    _, record = load_reference(name)
    (lt,), (ln,) = md.line_types, md.lines
    points = {p["id"]: p for p in md.points}
    anchor, fairlead = points[ln["attacha"]], points[ln["attachb"]]
    if anchor["type"].lower() != "fixed" or fairlead["type"].lower() not in ("vessel", "coupled"):
        raise ValueError(f"{name}: expected a fixed anchor (end A) and a coupled fairlead (end B)")
    o = md.options
    length, segments = float(ln["unstrlen"]), int(ln["numsegs"])
    d, w, EA = float(lt["diam"]), float(lt["mass/m"]), float(lt["ea"])
    motion = record["dynamic"]["motion"]
    return ChainCase(
        name=name, length=length, segments=segments, diameter=d, mass_per_length=w, EA=EA,
        BA=moordyn_ba(float(lt["ba/-zeta"]), length, segments, EA, w),
        Cd=float(lt["cd"]), Ca=float(lt["ca"]), CdAx=float(lt["cdax"]), CaAx=float(lt["caax"]),
        anchor=tuple(float(anchor[k]) for k in "xyz"), fairlead=tuple(float(fairlead[k]) for k in "xyz"),
        depth=float(o["wtrdpth"]), kbot=float(o.get("kbot", 3.0e6)), cbot=float(o.get("cbot", 3.0e5)),
        friction=float(o.get("frictioncoefficient", 0.0)), fric_damp=float(o.get("fricdamp", 200.0)),
        rho_w=float(o.get("wtrdnsty", o.get("rho", 1025.0))), g=float(o.get("g", MOORDYN_DEFAULT_G)),
        dtM=float(record["dynamic"]["dtM_s"]), amplitude=float(motion["amplitude_m"]),
        period=float(motion["period_s"]), ramp_periods=float(motion["ramp_periods"]),
        t_end=float(record["dynamic"]["t_end_s"]), dt_out=float(record["dynamic"]["dt_out_s"]))


def fitting_step(dt_out: float, dt_max: float) -> float:
    """The largest step (s) at most dt_max that divides dt_out (s) a whole number of times, so that frames fall
    on the coupling instants (WD0600's MoorDyn step, 3.0327 ms from its CFL, becomes 3.0303 ms)."""
    return dt_out / math.ceil(dt_out / dt_max - 1e-9)


def coupling_times(case: ChainCase, t_end: float | None = None) -> np.ndarray:
    """The coupling instants 0, dt_out, ..., t_end (s), computed as the harness does (dt_out * k)."""
    t_end = case.t_end if t_end is None else t_end
    return case.dt_out * np.arange(int(round(t_end / case.dt_out)) + 1)


def path_rows(case: ChainCase, t_end: float | None = None) -> list[list[float]]:
    """ropesim's ``path_table`` for the fairlead: rows [t, dx, dy] (s, m; ropesim's 2-D frame), the stored
    motion's displacement at every coupling instant, which MoorDyn's fairlead joins by straight lines."""
    path, x0 = case.motion(), np.asarray(case.fairlead, dtype=float)
    return [[float(t), *to_ropesim(path(float(t)) - x0).tolist()] for t in coupling_times(case, t_end)]


def chain_scene_dict(case: ChainCase, start=None, method: str = "rk4", dt: float | None = None,
                     t_end: float | None = None, moving: bool = True, interval: float | None = None,
                     friction: bool = True, dimension: int = 2, surge: Surge | None = None,
                     both_ways: bool = True) -> dict:
    """ropesim's scene (a TOML-ready dict) for a chain case.

    start: MoorDyn node positions (N+1, 3) as an ``initial.shape = "points"`` start at rest, or None for
    ropesim's own static shape (``initial.shape = "equilibrium"``); moving: the fairlead follows the stored path
    (:func:`path_rows`) until t_end, or with ``surge`` that smooth surge (ropesim's own sinusoid, exact at every
    stage), else it is pinned at rest; friction: MoorDyn's (see the module docstring) or none; dimension: 2 (the
    x-z plane) or 3 (MoorDyn's (x, y, z) as ropesim's (x, z, y)); both_ways: the seabed damps as MoorDyn's
    cBot does (``damping_both_ways``), else with ropesim's own one-way law."""
    if dimension == 2:
        conv = to_ropesim
    else:
        def conv(p):
            return np.asarray(p, dtype=float)[..., [0, 2, 1]]
    t_end = case.t_end if t_end is None else t_end
    if start is None:
        initial = {"shape": "equilibrium", "start": conv(case.anchor).tolist(), "end": conv(case.fairlead).tolist()}
    else:
        initial = {"shape": "points", "points": conv(start).tolist()}
    scene = {
        "name": f"moordyn_{case.name.lower()}",
        "description": f"MoorDyn's {case.name} on equal physics (tests/references/moordyn_own_cases.py)",
        "dimension": dimension,
        "rope": {"length": case.length, "segments": case.segments, "mass_per_length": case.mass_per_length,
                 "diameter": case.diameter, "EA": case.EA, "axial_damping": case.BA, "compression": False},
        "initial": initial,
        "integrator": {"method": method, "dt": dt or fitting_step(case.dt_out, case.dtM), "t_end": t_end},
        "output": {"interval": interval or case.dt_out},
        "gravity": {"g": case.g},
        "fluid": {"density": case.rho_w},
        "buoyancy": {},
        "fluid_drag": {"cd_normal": case.Cd, "cd_tangential": case.CdAx},
        "added_mass": {"ca_normal": case.Ca, "ca_tangential": case.CaAx},
        "seabed": {"height": -case.depth, "stiffness": case.kbot, "damping": case.cbot,
                   "friction": case.friction if friction else 0.0, "friction_speed": case.friction_speed,
                   "damping_both_ways": both_ways},
        "pinned": {"nodes": [0] if moving else [0, -1]},
    }
    if moving and surge is not None:
        scene["driven"] = [{"nodes": [-1], "amplitude": [surge.amplitude] + [0.0] * (dimension - 1),
                            "period": [surge.period] * dimension, "ramp_time": surge.ramp_time}]
    elif moving:
        rows = path_rows(case, t_end)
        if dimension == 3:
            rows = [[t, dx, dy, 0.0] for t, dx, dy in rows]
        scene["driven"] = [{"nodes": [-1], "path_table": rows}]
    return scene


def chain_scene(case: ChainCase, start=None, **kw):
    """:func:`chain_scene_dict` through ropesim's own TOML reader (a validated Scene)."""
    import tomli_w

    import ropesim

    return ropesim.scene_from_toml(tomli_w.dumps(chain_scene_dict(case, start, **kw)))


def run_chain(case: ChainCase, start=None, **kw):
    """ropesim's Trajectory of a chain case (arguments as :func:`chain_scene_dict`)."""
    import ropesim

    return ropesim.simulate(chain_scene(case, start, **kw))


def fairlead_velocity_before(case: ChainCase, t) -> np.ndarray:
    """The fairlead's velocity over the coupling interval that ends at each time t (F,) (m/s, ropesim 2-D
    frame): the secant of the stored path; zero at t = 0 (MoorDyn's fairlead is at rest during its IC)."""
    t = np.asarray(t, dtype=float)
    k = np.rint(t / case.dt_out).astype(int)
    if np.abs(k * case.dt_out - t).max() > 1e-9:
        raise ValueError("the frames must fall on the coupling instants")
    path, out = case.motion(), np.zeros((t.size, 2))
    for i, ki in enumerate(k):
        if ki > 0:
            a, b = case.dt_out * (ki - 1), case.dt_out * ki
            out[i] = to_ropesim((path(b) - path(a)) / case.dt_out)
    return out


def segment_tension(case: ChainCase, x, v, j: int, v_end=None) -> np.ndarray:
    """Segment j's axial force (N), spring plus damping, from frames of positions x (F, N+1, D) and velocities v:
    EA (l_s - l)/l only when stretched, plus BA (dl_s/dt)/l (MoorDyn's ``T + Td``; ropesim's ``tension``).
    v_end: the velocity (F, D) to use for segment j's upper node instead of v's (the fairlead's, see
    :func:`fairlead_tension`)."""
    x, v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
    seg = x[:, j + 1] - x[:, j]
    ls = np.linalg.norm(seg, axis=-1)
    q = seg / ls[:, None]
    upper = v[:, j + 1] if v_end is None else np.asarray(v_end, dtype=float)
    rate = np.einsum("fd,fd->f", q, upper - v[:, j])
    l0 = case.segment_length
    return case.EA * np.maximum(ls - l0, 0.0) / l0 + case.BA * rate / l0


def fairlead_tension(case: ChainCase, traj) -> np.ndarray:
    """ropesim's fairlead tension (N, (F,)) as MoorDyn reports it: |T + Td| of the top segment with the
    fairlead's velocity over the coupling interval ending at the frame (see the module docstring)."""
    return np.abs(segment_tension(case, traj.x, traj.v, case.segments - 1,
                                  v_end=fairlead_velocity_before(case, traj.t)))


def anchor_tension(traj) -> np.ndarray:
    """ropesim's anchor tension (N, (F,)): |tension| of the bottom segment (MoorDyn's ``GetLineNodeTen(0)``)."""
    return np.abs(np.asarray(traj.tension)[:, 0])


def static_tensions(case: ChainCase, x) -> tuple[float, float]:
    """(fairlead, anchor) segment tensions (N) of a static shape x (N+1, D), at rest."""
    x = np.asarray(x, dtype=float)[None]
    v = np.zeros_like(x)
    return (float(segment_tension(case, x, v, case.segments - 1)[0]), float(segment_tension(case, x, v, 0)[0]))


def ropesim_static(case: ChainCase) -> tuple[np.ndarray, float, float]:
    """ropesim's static solve (``initial.shape = "equilibrium"``): node positions (N+1, 2) in ropesim's frame and
    the (fairlead, anchor) tensions (N)."""
    from ropesim.model.build import build

    x = build(chain_scene(case, None, moving=False, t_end=0.0)).x0.T.copy()
    return (x, *static_tensions(case, x))


def settle(case: ChainCase, start, t_end: float = 600.0, dt: float = 0.05):
    """A settled dynamic run: from ``start`` (MoorDyn positions (N+1, 3)), the fairlead pinned, sdirk2 (L-stable:
    its large steps damp every mode) for t_end seconds. Returns the Trajectory."""
    return run_chain(case, start, method="sdirk2", dt=dt, t_end=t_end, moving=False, interval=t_end / 20.0)


def catenary_start(case: ChainCase) -> np.ndarray:
    """A start away from equilibrium, for the settled runs: the chain's nodes evenly along a straight line from
    the anchor to the fairlead (the line 6.9 to 85 m shorter than the chain, so every segment starts slack)
    (MoorDyn frame, (N+1, 3))."""
    return np.linspace(case.anchor, case.fairlead, case.segments + 1)


# ------------------------------------------------------------------------------------------------ the beam


@dataclass(frozen=True)
class BeamCase:
    """MoorDyn's BeamCantilevered, in MoorDyn's frame: a line from the fixed rod's end (``clamp``, the line's end
    A) along the rod's axis ``axis`` (unit vector) to a free massless point; L (m), N segments, diameter (m),
    m' (kg/m), EA (N), BA (N s, resolved), EI (N m^2), g (m/s^2), dtM (s) of the stored release, its output
    interval dt_out (s) and length t_end (s)."""

    length: float
    segments: int
    diameter: float
    mass_per_length: float
    EA: float
    BA: float
    EI: float
    clamp: tuple[float, float, float]
    axis: tuple[float, float, float]
    g: float
    dtM: float
    dt_out: float
    t_end: float
    extra: dict = field(default_factory=dict)

    @property
    def segment_length(self) -> float:
        return self.length / self.segments

    @property
    def analytic_tip(self) -> float:
        """Euler-Bernoulli tip deflection of a uniform cantilever under its own weight, w L^4 / (8 EI) (m)."""
        return self.mass_per_length * self.g * self.length ** 4 / (8.0 * self.EI)

    def analytic_frequency(self, mode: int) -> float:
        """Euler-Bernoulli cantilever's mode frequency (Hz), (beta L)^2 / (2 pi L^2) sqrt(EI / m')."""
        beta_l = (1.8751040687, 4.6940911330, 7.8547574382)[mode - 1]
        return beta_l ** 2 / (2.0 * math.pi * self.length ** 2) * math.sqrt(self.EI / self.mass_per_length)


def beam_case() -> BeamCase:
    """BeamCantilevered read from MoorDyn's file: the line ``beam`` from rod 1's end B (clamped: a line end on a
    rod is cantilevered) to the free point; the stored release's step and output interval."""
    md = read_input(CASES_DIR / f"{BEAM}.txt")
    (lt,), (ln,), (rod,) = md.line_types, md.lines, md.rods
    if ln["attacha"].upper() != "R1B" or rod["attachment"].lower() != "fixed":
        raise ValueError("expected the beam's end A on the fixed rod 1's end B")
    a = np.array([float(rod[k]) for k in ("xa", "ya", "za")])
    b = np.array([float(rod[k]) for k in ("xb", "yb", "zb")])
    length, segments = float(ln["unstrlen"]), int(ln["numsegs"])
    w, EA = float(lt["mass/m"]), float(lt["ea"])
    _, record = load_reference(BEAM)
    dyn = record["dynamic"]
    return BeamCase(length=length, segments=segments, diameter=float(lt["diam"]), mass_per_length=w, EA=EA,
                    BA=moordyn_ba(float(lt["ba/-zeta"]), length, segments, EA, w), EI=float(lt["ei"]),
                    clamp=tuple(b), axis=tuple((b - a) / np.linalg.norm(b - a)),
                    g=float(md.options.get("g", MOORDYN_DEFAULT_G)), dtM=float(dyn["dtM_s"]),
                    dt_out=float(dyn["dt_out_s"]), t_end=float(dyn["t_end_s"]))


def beam_scene_dict(case: BeamCase, equilibrium: bool = False, method: str = "rk4", dt: float = 2.0e-5,
                    t_end: float | None = None, interval: float | None = None) -> dict:
    """ropesim's scene for the beam (2-D, the x-z plane): straight along the rod's axis from the clamp, at rest
    (the stored release), or its static shape (``equilibrium``). Node 0 pinned and clamped, the tip free."""
    clamp = to_ropesim(case.clamp)
    tip = clamp + case.length * to_ropesim(case.axis)
    if equilibrium:
        initial = {"shape": "equilibrium", "start": clamp.tolist(), "end": tip.tolist()}
    else:
        initial = {"shape": "line", "start": clamp.tolist(), "end": tip.tolist()}
    return {
        "name": "moordyn_beam_cantilevered",
        "description": "MoorDyn's BeamCantilevered on equal physics (tests/references/moordyn_own_cases.py)",
        "dimension": 2,
        "rope": {"length": case.length, "segments": case.segments, "mass_per_length": case.mass_per_length,
                 "diameter": case.diameter, "EA": case.EA, "axial_damping": case.BA, "EI": case.EI,
                 "compression": False},
        "initial": initial,
        "integrator": {"method": method, "dt": dt, "t_end": case.t_end if t_end is None else t_end},
        "output": {"interval": interval or case.dt_out},
        "gravity": {"g": case.g},
        "pinned": {"nodes": [0], "clamped": [0]},
    }


def run_beam(case: BeamCase, **kw):
    """ropesim's Trajectory of the beam (arguments as :func:`beam_scene_dict`)."""
    import tomli_w

    import ropesim

    return ropesim.simulate(ropesim.scene_from_toml(tomli_w.dumps(beam_scene_dict(case, **kw))))


def beam_static_tip(case: BeamCase) -> float:
    """ropesim's static tip deflection (m, positive down) from its static solve."""
    import tomli_w

    import ropesim
    from ropesim.model.build import build

    scene = ropesim.scene_from_toml(tomli_w.dumps(beam_scene_dict(case, equilibrium=True, t_end=0.0)))
    x = build(scene).x0
    return float(to_ropesim(case.clamp)[1] - x[1, -1])


def fit_oscillation(t, y, modes: int = 3) -> dict:
    """Fit y(t) = s + sum_k (a_k cos w_k t + b_k sin w_k t) over ``modes`` frequencies (least squares, the
    frequencies started from the spectrum's peaks): the static offset s an undamped release oscillates about,
    and the frequencies (Hz). Returns {"offset", "frequencies", "rms_residual"}."""
    from scipy.optimize import least_squares

    t, y = np.asarray(t, dtype=float), np.asarray(y, dtype=float)
    spec = np.abs(np.fft.rfft((y - y.mean()) * np.hanning(y.size)))
    freqs = np.fft.rfftfreq(y.size, t[1] - t[0])
    peaks = [i for i in range(1, spec.size - 1) if spec[i] >= spec[i - 1] and spec[i] >= spec[i + 1]]
    peaks = sorted(sorted(peaks, key=lambda i: -spec[i])[:modes])
    w0 = 2.0 * math.pi * freqs[peaks]

    def design(w):
        return np.column_stack([np.ones_like(t)] + [f(wk * t) for wk in w for f in (np.cos, np.sin)])

    def residual(w):
        a = design(w)
        coef, *_ = np.linalg.lstsq(a, y, rcond=None)
        return a @ coef - y

    sol = least_squares(residual, w0, x_scale=w0)
    a = design(sol.x)
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    return {"offset": float(coef[0]), "frequencies": sorted((sol.x / (2.0 * math.pi)).tolist()),
            "rms_residual": float(np.sqrt(np.mean((a @ coef - y) ** 2)))}


# ------------------------------------------------------------------------------------------------ comparing


def differences(a, b, skip_first: bool = True) -> dict:
    """How far signal b is from a (b - a), both (F,), over frames 1..F-1 (frame 0 is the shared start; MoorDyn
    has computed no damping there). Returns, in a's units and as fractions: rms, max, range (a's max - min),
    signal_rms (a's own RMS), rms_of_range = rms / range, rms_of_rms = rms / signal_rms, max_of_range."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    s = slice(1, None) if skip_first else slice(None)
    d = b[s] - a[s]
    out = {"rms": float(np.sqrt(np.mean(d ** 2))), "max": float(np.max(np.abs(d))),
           "range": float(np.ptp(a[s])), "signal_rms": float(np.sqrt(np.mean(a[s] ** 2)))}
    out["rms_of_range"] = out["rms"] / out["range"]
    out["rms_of_rms"] = out["rms"] / out["signal_rms"]
    out["max_of_range"] = out["max"] / out["range"]
    return out


# ------------------------------------------------------------------------------------------------ MoorDyn, live


@dataclass
class MoorDynChainRun:
    """A live MoorDyn run of a chain case (MoorDyn's frame, SI units): times t (F,); reported: its fairlead
    tension ``GetLineFairTen`` (F,) (from its last force evaluation: for RK2 the midpoint of the last step);
    from_state: the same top-segment |T + Td| computed from the state at the frame (node positions and node N-1's
    velocity) with the fairlead's secant velocity over the interval ending there, ropesim's
    :func:`fairlead_tension`'s definition; anchor (F,): ``GetLineNodeTen(0)``; positions (F, N+1, 3); wall: the
    time loop's wall time (its Step calls only, s); dtM (s), scheme (name)."""

    t: np.ndarray
    reported: np.ndarray
    from_state: np.ndarray
    anchor: np.ndarray
    positions: np.ndarray
    wall: float
    dtM: float
    scheme: str


def moordyn_chain_text(case: ChainCase, options: dict | None = None) -> str:
    """The case's MoorDyn input file with the harness's quiet options and ``options`` (name -> value) set."""
    from .moordyn_harness import QUIET_OPTIONS, set_options

    text = (CASES_DIR / f"{case.name}.txt").read_text(encoding="utf-8")
    return set_options(text, {**QUIET_OPTIONS, **(options or {})})


def run_moordyn_chain(case: ChainCase, options: dict | None = None, t_end: float | None = None,
                      motion=None, dt_out: float | None = None, positions: bool = True) -> MoorDynChainRun:
    """MoorDyn on a chain case: its IC, then the fairlead along ``motion`` (t -> MoorDyn position; default the
    stored run's path), coupled every dt_out (default the case's) as the harness does (the position at the start of
    each Step and the secant velocity). options: MoorDyn options to set (``dtM``, ``tScheme``, ``threshIC``, ...);
    t_end: simulated time (s), 0 for the IC state alone. positions: record every node at every frame."""
    import cmoordyn

    from .moordyn_harness import moordyn_system, quiet_fd

    t_end = case.t_end if t_end is None else t_end
    dt_out = case.dt_out if dt_out is None else dt_out
    path = case.motion() if motion is None else motion
    steps = int(round(t_end / dt_out))
    times = dt_out * np.arange(steps + 1)
    l0, n = case.segment_length, case.segments
    reported, from_state, anchor, pos = [], [], [], []
    with moordyn_system(moordyn_chain_text(case, options), path(0.0), ic=True) as (md, system):
        line = md.GetLine(system, 1)

        def record(fair_v):
            last = np.array([md.GetLineNodePos(line, i) for i in ((n - 1, n) if not positions else range(n + 1))])
            v = np.asarray(md.GetLineNodeVel(line, n - 1))
            seg = last[-1] - last[-2]
            ls = float(np.linalg.norm(seg))
            tension = case.EA * max(ls - l0, 0.0) / l0 + case.BA * float(seg @ (fair_v - v)) / (ls * l0)
            reported.append(md.GetLineFairTen(line))
            from_state.append(abs(tension))
            anchor.append(float(np.linalg.norm(md.GetLineNodeTen(line, 0))))
            if positions:
                pos.append(last)

        record(np.zeros(3))
        wall = 0.0
        with quiet_fd():
            for k in range(steps):
                xa, xb = np.asarray(path(times[k]), dtype=float), np.asarray(path(times[k + 1]), dtype=float)
                v = (xb - xa) / dt_out
                tic = _clock()
                md.Step(system, list(xa), list(v), float(times[k]), dt_out)
                wall += _clock() - tic
                record(v)
        dtm, scheme = cmoordyn.get_dt(system), cmoordyn.get_tscheme(system)
    return MoorDynChainRun(times, np.array(reported), np.array(from_state), np.array(anchor),
                           np.array(pos) if positions else np.zeros((0, n + 1, 3)), wall, dtm, scheme)


def _clock() -> float:
    import time

    return time.perf_counter()


def _find_block(values: np.ndarray, block: np.ndarray) -> int:
    """The one index at which ``block`` sits in ``values`` (exactly); an error if none or several."""
    hits = [i for i in np.flatnonzero(values == block[0]) if i + block.size <= values.size
            and np.array_equal(values[i:i + block.size], block)]
    if len(hits) != 1:
        raise RuntimeError(f"MoorDyn's serialized state holds the block {len(hits)} times, not once: its layout "
                           "is not the one this was written for")
    return int(hits[0])


def set_line_state(md, system, line, positions) -> None:
    """Put a MoorDyn line's nodes at ``positions`` (N+1, 3) (MoorDyn frame, m), at rest, before its first step.

    MoorDyn has no call for it, so its serialized state (``Serialize``) is edited: it holds the inner nodes'
    positions and velocities (the time integrator's state, (r, v) per node) and every node's position (the line's
    own), each found exactly once by value (the line must be at rest, as after ``Init_NoIC``); both are overwritten
    and loaded back (``Deserialize``), and the positions read back to check. The end nodes must already be where
    ``positions`` puts them (they follow their points)."""
    from .moordyn_harness import quiet_fd

    positions = np.asarray(positions, dtype=float)
    n = positions.shape[0] - 1
    now = np.array([md.GetLineNodePos(line, i) for i in range(n + 1)])
    if np.abs(now[[0, -1]] - positions[[0, -1]]).max() > 1e-9:
        raise ValueError("the line's ends are not where the new state puts them")
    state = np.frombuffer(md.Serialize(system), dtype=np.float64).copy()
    inner = np.column_stack([now[1:n], np.zeros((n - 1, 3))]).ravel()   # (r, v) of nodes 1..N-1
    i_inner, i_all = _find_block(state, inner), _find_block(state, now.ravel())
    state[i_inner:i_inner + inner.size] = np.column_stack([positions[1:n], np.zeros((n - 1, 3))]).ravel()
    state[i_all:i_all + now.size] = positions.ravel()
    with quiet_fd():
        md.Deserialize(system, state.tobytes())
    back = np.array([md.GetLineNodePos(line, i) for i in range(n + 1)])
    if np.abs(back - positions).max() > 1e-12:
        raise RuntimeError("MoorDyn did not take the new state")


def run_moordyn_beam_straight(case: BeamCase, t_end: float | None = None, dt_out: float | None = None) -> dict:
    """MoorDyn's BeamCantilevered released straight and at rest, as ropesim's ``initial.shape = "line"`` starts.

    MoorDyn itself starts a line on its catenary between the end points (``Init_NoIC``): here a sag of 6.7 cm, its
    first segment 1.5 degrees off the rod's axis, so the clamp starts bent. ropesim's clamp keeps the end
    segment's *initial* direction, which would be that bent one; so instead MoorDyn's state is set straight before
    its first step (:func:`set_line_state`). Returns {"t" (F,), "positions" (F, N+1, 3), "wall"} (SI units)."""
    from .moordyn_harness import QUIET_OPTIONS, moordyn_system, quiet_fd, set_options

    t_end = case.t_end if t_end is None else t_end
    dt_out = case.dt_out if dt_out is None else dt_out
    text = set_options((CASES_DIR / f"{BEAM}.txt").read_text(encoding="utf-8"), QUIET_OPTIONS)
    n = case.segments
    straight = np.asarray(case.clamp) + np.outer(np.linspace(0.0, case.length, n + 1), case.axis)
    with moordyn_system(text, None, ic=False) as (md, system):
        line = md.GetLine(system, 1)
        set_line_state(md, system, line, straight)
        steps = int(round(t_end / dt_out))
        frames = [np.array([md.GetLineNodePos(line, i) for i in range(n + 1)])]
        wall, t = 0.0, 0.0
        with quiet_fd():
            for k in range(steps):
                tic = _clock()
                md.Step(system, [], [], t, dt_out)
                wall += _clock() - tic
                t = dt_out * (k + 1)
                frames.append(np.array([md.GetLineNodePos(line, i) for i in range(n + 1)]))
    return {"t": dt_out * np.arange(steps + 1), "positions": np.array(frames), "wall": wall}


def moordyn_line_text(case: ChainCase, dtM: float, scheme: str = "RK2") -> str:
    """A MoorDyn input file for a chain case's line as ``moordyn_harness.line_input_text`` writes it (anchor fixed,
    fairlead coupled, the case's line type, seabed, friction, water and g), with the case's own EA and BA (so a
    case changed with ``with_`` runs as changed), no IC options needed (see :func:`run_moordyn_line`)."""
    from .moordyn_harness import Environment, LineProps, Solver, line_input_text

    line = LineProps(case.length, case.segments, case.diameter, case.mass_per_length, case.EA, case.BA, 0.0,
                     case.Cd, case.Ca, case.CdAx, case.CaAx)
    env = Environment(case.depth, case.g, case.rho_w, case.kbot, case.cbot, case.friction, case.fric_damp, 1.0)
    return line_input_text(line, env, case.anchor, case.fairlead, Solver(dtM=dtM, scheme=scheme, ic=False))


def run_moordyn_line(case: ChainCase, start, motion, dtM: float, scheme: str, t_end: float,
                     coupling: float | None = None, dt_out: float = 0.1) -> dict:
    """MoorDyn on a chain case's line from ``start`` (MoorDyn node positions (N+1, 3), at rest; set with
    :func:`set_line_state`, no IC), the fairlead following ``motion`` (t -> MoorDyn position), handed to MoorDyn
    every ``coupling`` seconds (default dtM: one internal step per ``Step``, so its fairlead's piecewise-linear path
    follows the motion as closely as MoorDyn can) as the harness does. Returns {"t" (F,), "fairlead" (F,): its
    reported ``GetLineFairTen`` every dt_out (from its last force evaluation, a fraction of a step before the
    frame), "from_state" (F,): the top segment's |T + Td| from the state at the frame (the fairlead's velocity that
    of the last Step), "wall": the Step calls' wall time (s), "calls", "ok": False if a tension came out
    non-finite}."""
    from .moordyn_harness import moordyn_system, quiet_fd

    coupling = dtM if coupling is None else coupling
    every = int(round(dt_out / coupling))
    steps = int(round(t_end / coupling))
    if abs(every * coupling - dt_out) > 1e-12 or abs(steps * coupling - t_end) > 1e-9:
        raise ValueError("the coupling step must divide dt_out and t_end")
    out, state, wall, ok = [], [], 0.0, True
    n, l0 = case.segments, case.segment_length
    with moordyn_system(moordyn_line_text(case, dtM, scheme), motion(0.0), ic=False) as (md, system):
        line = md.GetLine(system, 1)
        set_line_state(md, system, line, start)

        def from_state(fair_v) -> float:
            seg = np.asarray(md.GetLineNodePos(line, n)) - np.asarray(md.GetLineNodePos(line, n - 1))
            ls = float(np.linalg.norm(seg))
            rate = float(seg @ (fair_v - np.asarray(md.GetLineNodeVel(line, n - 1)))) / ls
            return abs(case.EA * max(ls - l0, 0.0) / l0 + case.BA * rate / l0)

        out.append(md.GetLineFairTen(line))
        state.append(from_state(np.zeros(3)))
        with quiet_fd():
            xa = np.asarray(motion(0.0), dtype=float)
            for k in range(steps):
                xb = np.asarray(motion(coupling * (k + 1)), dtype=float)
                x, v = list(xa), list((xb - xa) / coupling)
                tic = _clock()
                forces = md.Step(system, x, v, coupling * k, coupling)
                wall += _clock() - tic
                xa = xb
                if (k + 1) % every == 0:
                    tension = md.GetLineFairTen(line)
                    out.append(tension)
                    state.append(from_state(np.asarray(v)))
                    if forces is None or not np.all(np.isfinite(forces)) or not tension < 1e12:
                        ok = False
                        break
    return {"t": dt_out * np.arange(len(out)), "fairlead": np.array(out), "from_state": np.array(state), "wall": wall,
            "calls": steps, "ok": ok}
