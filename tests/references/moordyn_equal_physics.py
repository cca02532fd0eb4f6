"""One line, run in MoorDyn and in ropesim on equal physics: the cases of ``scripts/compare_moordyn.py`` and
``tests/test_moordyn_equal_physics.py``.

Equal physics means the same lumped-mass line in both codes (MOORDYN_CONVENTIONS.md): the same segments and node
masses (half a segment at each end), EA in tension only, axial damping BA in tension and compression, Morison drag
on the velocity relative to the current (Cd across on d l, CdAx along on pi d l, split by the chord through the
neighbours), buoyancy on the unstretched volume, added mass Ca across and CaAx along the same tangent, the same g and
water density; a clump at a free end is a MoorDyn ``Free`` point and a ropesim ``[[bodies]]`` entry with the same
mass, volume, CdA and Ca. No seabed: it is 200 m down, far below every node. The top node stays at z = -5 m or
deeper, so no segment pierces the surface (MoorDyn would count a partly submerged segment's buoyancy and drag by
its wetted fraction; ropesim has no free surface).

Both codes start from the same state, at rest, handed to ropesim as ``[initial] shape = "points"``:

- a hanging line: MoorDyn's initial-condition (IC) state in still water (MoorDyn ignores currents in its IC), from
  its legacy dynamic relaxation run tight (:data:`TIGHT_IC`): converged to 1e-11 m whatever dtM or the scheme, its
  nodes left moving at 1e-8 m/s at most. MoorDyn's default IC solver would not do: it stops 0.5 N (3e-4) short of
  the static top tension at a state that depends on dtM, so a step-halving check would compare different starts;
- the catenary: MoorDyn's initial shape without the IC (``Init_NoIC``), its elastic catenary for the end points,
  with 13 of its 30 segments slightly slack: the line snaps taut in the first 0.1 s and rings for a few seconds, a
  hard test of the tension-only segments. The tight IC would leave its nodes swaying at up to 0.9 mm/s (a start
  ropesim's ``[initial]``, one velocity for every node, cannot take), and a tighter one costs minutes; the IC
  appears only in the static comparison.

A current is on from t = 0 in both (MoorDyn: a steady current
profile; ropesim: ``[flow]`` with no ramp, since a ramp is a time-varying flow whose acceleration MoorDyn would turn
into a Froude-Krylov force); a moved top end moves at a constant velocity from t = 0 in both (MoorDyn: a coupled
point on the straight path, see ``moordyn_harness.run_input_file``; ropesim: ``[[driven]]``).

Frames: MoorDyn's (x, y, z) with z up; ropesim's y is up, so a MoorDyn point (x, y, z) is ropesim's (x, z, y)
(:func:`to_ropesim`). Node i is node i in both: node 0 at end A (the bottom: the clump or the anchor), node N at the
top. Tensions: MoorDyn's ``GetLineFairTen`` (the top segment's |T + Td|) against ropesim's ``tension[:, -1]``, and
``GetLineNodeTen(0)`` against ``tension[:, 0]``: the axial force of the end segment, spring plus damping, in both.
MoorDyn reports its magnitude, ropesim its signed value (negative while a slack segment shortens: its damping
pushes), so the comparison takes ropesim's magnitude (:meth:`Series.of_ropesim`). Units: SI.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .moordyn_harness import MOORDYN_DEFAULT_G, MoorDynRun, current_profile_text, run_input_file

RHO_W = 1025.0          # sea water, kg/m^3
G = MOORDYN_DEFAULT_G   # 9.80665 m/s^2: MoorDyn's default, given to both codes
DEPTH = 200.0           # m: the seabed, far below every node (no contact)


@dataclass(frozen=True)
class LineType:
    """A MoorDyn line type: volume-equivalent diameter (m), mass per metre (kg/m), EA (N), BA (N s, not a ratio),
    and the four hydrodynamic coefficients."""

    diameter: float
    mass_per_length: float
    EA: float
    BA: float
    Cd: float
    Ca: float
    CdAx: float
    CaAx: float

    @property
    def wet_weight(self) -> float:
        """Submerged weight per metre (N/m)."""
        return (self.mass_per_length - RHO_W * math.pi / 4.0 * self.diameter ** 2) * G


#: A 16 mm studless chain in MoorPy's chain formulas (volume-equivalent diameter 1.8 d, 20.0e3 d^2 kg/m,
#: EA = 0.854e11 d^2 N), with the chain coefficients of MoorDyn's own test inputs (Cd 2.4, Ca 1, CdAx 1.15) and
#: CaAx 0; BA = 5000 N s is 0.47 of a 1-m segment's critical axial damping l sqrt(EA m').
CHAIN = LineType(diameter=0.0288, mass_per_length=5.12, EA=2.186e7, BA=5000.0, Cd=2.4, Ca=1.0, CdAx=1.15,
                 CaAx=0.0)


@dataclass(frozen=True)
class Clump:
    """A point body on the line's free bottom end: mass (kg), volume (m^3), drag CdA (m^2), added mass Ca (-)."""

    mass: float
    volume: float
    cd_area: float
    ca: float


#: 20 kg of steel (its volume 20 / 7850 m^3), CdA of a 0.16 m sphere-like lump.
CLUMP = Clump(mass=20.0, volume=20.0 / 7850.0, cd_area=0.02, ca=1.0)


@dataclass(frozen=True)
class Case:
    """One line, in MoorDyn's frame (z up, m, s).

    bottom: the anchor's position (end A, fixed) when ``clump`` is None; with a clump (a free end A), None: the clump
    starts straight below the top, the line stretched by its mean static strain (:meth:`bottom_start`); top: end B's;
    top_velocity: the top's constant velocity from t = 0 (m/s), None for a fixed top; current: uniform current
    (m/s), on from t = 0. t_end: simulated time (s); dt_out: output and coupling interval (s); dtM: MoorDyn's step
    (s, RK2 unless ``scheme``); method, dt: ropesim's integrator and step (s); steady: the last seconds over which
    the steady values are averaged (0: the case has no steady state).
    """

    name: str
    title: str
    line: LineType
    length: float
    segments: int
    bottom: tuple[float, float, float] | None
    top: tuple[float, float, float]
    clump: Clump | None = None
    top_velocity: tuple[float, float, float] | None = None
    current: tuple[float, float, float] = (0.0, 0.0, 0.0)
    t_end: float = 20.0
    dt_out: float = 0.1
    dtM: float = 2.0e-4
    scheme: str = "RK2"
    method: str = "verlet"
    dt: float = 2.0e-4
    steady: float = 0.0
    ic: bool = False
    ic_options: dict = field(default_factory=lambda: dict(TIGHT_IC))

    def with_(self, **changes) -> Case:
        return replace(self, **changes)

    def bottom_start(self) -> tuple[float, float, float]:
        """End A's start (m): the anchor, or for a hanging line the clump, straight below the top by the length
        stretched by the mean static strain of its segments (segment j, above node j, carries the clump's and
        nodes 0..j's submerged weight)."""
        if self.clump is None:
            return self.bottom
        seg = self.length / self.segments
        c = self.clump
        clump_weight = (c.mass - RHO_W * c.volume) * G
        tension = clump_weight + self.line.wet_weight * seg * (0.5 + np.arange(self.segments))
        stretched = self.length + float(np.sum(tension)) * seg / self.line.EA
        return (self.top[0], self.top[1], self.top[2] - stretched)


TOP = (0.0, 0.0, -5.0)

#: A tight IC: MoorDyn's legacy dynamic relaxation (``ICgenDynamic 1``, drag scaled by 10) until the fairlead
#: tension changes by less than 1e-7 between checks.
TIGHT_IC = {"ICgenDynamic": 1, "threshIC": 1e-7, "TmaxIC": 1200, "CdScaleIC": 10}
#: MoorDyn's own IC defaults (``ICgenDynamic 0``, the stationary solver), for the static comparison.
DEFAULT_IC: dict = {}

#: The cases of the comparison (full size; the tests use smaller ones built with ``Case.with_``).
CASES = {
    "current": Case(
        name="current", title="hanging in a current", line=CHAIN, length=30.0, segments=30,
        bottom=None, top=TOP, clump=CLUMP, current=(1.0, 0.5, 0.0), t_end=150.0, steady=10.0, ic=True),
    "towed": Case(
        name="towed", title="top towed at 1 m/s", line=CHAIN, length=30.0, segments=30,
        bottom=None, top=TOP, clump=CLUMP, top_velocity=(1.0, 0.0, 0.0), t_end=150.0, steady=10.0, ic=True),
    "catenary": Case(
        name="catenary", title="catenary, fairlead moved", line=CHAIN, length=60.0, segments=30,
        bottom=(0.0, 0.0, -50.0), top=(30.0, 0.0, -5.0), top_velocity=(0.3, 0.2, 0.0), t_end=20.0),
}


def to_ropesim(p) -> np.ndarray:
    """MoorDyn positions or vectors (..., 3), z up, as ropesim's (x, y up, z): (x, y, z) -> (x, z, y)."""
    return np.asarray(p, dtype=float)[..., [0, 2, 1]]


# ------------------------------------------------------------------------------------------------ MoorDyn


def moordyn_input(case: Case, dtM: float | None = None, scheme: str | None = None) -> str:
    """MoorDyn's input file for ``case``: point 1 (end A) the free clump or the fixed anchor, point 2 (end B) the
    top, coupled when it moves, else fixed."""
    ln = case.line
    bx, by, bz = case.bottom_start()
    if case.clump is not None:
        c = case.clump
        end_a = f"Free {bx!r} {by!r} {bz!r} {c.mass!r} {c.volume!r} {c.cd_area!r} {c.ca!r}"
    else:
        end_a = f"Fixed {bx!r} {by!r} {bz!r} 0 0 0 0"
    kind = "Coupled" if case.top_velocity is not None else "Fixed"
    current = any(u != 0.0 for u in case.current)
    options = "".join(f"{v} {k}\n" for k, v in case.ic_options.items()) if case.ic else ""
    return f"""ropesim equal-physics case {case.name} (tests/references/moordyn_equal_physics.py)
---------------------- LINE TYPES -----------------------------------
TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx
(name) (m) (kg/m) (N) (N-s/-) (N-m^2) (-) (-) (-) (-)
line {ln.diameter!r} {ln.mass_per_length!r} {ln.EA!r} {ln.BA!r} 0.0 {ln.Cd!r} {ln.Ca!r} {ln.CdAx!r} {ln.CaAx!r}
---------------------- POINTS ---------------------------------------
ID Attachment X Y Z Mass Volume CdA Ca
(#) (word/ID) (m) (m) (m) (kg) (m^3) (m^2) (-)
1 {end_a}
2 {kind} {case.top[0]!r} {case.top[1]!r} {case.top[2]!r} 0 0 0 0
---------------------- LINES ----------------------------------------
ID LineType AttachA AttachB UnstrLen NumSegs LineOutputs
(#) (name) (ID) (ID) (m) (-) (-)
1 line 1 2 {case.length!r} {case.segments:d} -
---------------------- OPTIONS -----------------------------------------
0 writeLog
{dtM if dtM is not None else case.dtM!r} dtM
{scheme or case.scheme} tScheme
{G!r} g
{RHO_W!r} rho
{DEPTH!r} WtrDpth
{1 if current else 0} Currents
{options}1 disableOutput
1 disableOutTime
---------------------- OUTPUTS -----------------------------------------
-------------------------------------------------------------------------
"""


def top_path(case: Case):
    """The top's prescribed path t -> position (m), None for a fixed top."""
    if case.top_velocity is None:
        return None
    x0, v = np.asarray(case.top, dtype=float), np.asarray(case.top_velocity, dtype=float)
    return lambda t: x0 + v * t


def run_moordyn(case: Case, dtM: float | None = None, scheme: str | None = None,
                t_end: float | None = None) -> MoorDynRun:
    """MoorDyn on ``case``: its initial shape (or its IC state, with ``case.ic``), then t_end of dynamics (s);
    dtM (s) and scheme default to the case's."""
    with tempfile.TemporaryDirectory(prefix="ropesim-md-equal-") as tmp:
        folder = Path(tmp)
        path = folder / "line.txt"
        path.write_text(moordyn_input(case, dtM, scheme), encoding="utf-8")
        extra = {}
        if any(u != 0.0 for u in case.current):
            (folder / "current_profile.txt").write_text(current_profile_text(case.current, DEPTH), encoding="utf-8")
            extra["current_profile.txt"] = folder / "current_profile.txt"
        return run_input_file(path, motion=top_path(case), t_end=case.t_end if t_end is None else t_end,
                              dt_out=case.dt_out, extra_files=extra, ic=case.ic)


# ------------------------------------------------------------------------------------------------ ropesim


def ropesim_scene_dict(case: Case, start, method: str | None = None, dt: float | None = None,
                       t_end: float | None = None, **physics) -> dict:
    """ropesim's scene (as a TOML-ready dict) for ``case`` from ``start``: MoorDyn node positions (N+1, 3).

    physics: overrides for checking that the comparison is sensitive (``Cd``, ``CdAx``, ``Ca``, ``CaAx``, ``BA``,
    ``buoyancy`` (bool), ``clump`` (a :class:`Clump`)); by default the case's own values."""
    ln = case.line
    cd, cdax = physics.get("Cd", ln.Cd), physics.get("CdAx", ln.CdAx)
    ca, caax, ba = physics.get("Ca", ln.Ca), physics.get("CaAx", ln.CaAx), physics.get("BA", ln.BA)
    scene = {
        "name": f"moordyn_{case.name}",
        "description": f"MoorDyn equal-physics case: {case.title}",
        "dimension": 3,
        "rope": {"length": case.length, "segments": case.segments, "mass_per_length": ln.mass_per_length,
                 "diameter": ln.diameter, "EA": ln.EA, "axial_damping": ba, "compression": False},
        "initial": {"shape": "points", "points": to_ropesim(start).tolist()},
        "integrator": {"method": method or case.method, "dt": dt or case.dt,
                       "t_end": case.t_end if t_end is None else t_end},
        "output": {"interval": case.dt_out},
        "gravity": {"g": G},
        "fluid": {"density": RHO_W},
        "fluid_drag": {"cd_normal": cd, "cd_tangential": cdax},
        "added_mass": {"ca_normal": ca, "ca_tangential": caax},
    }
    if physics.get("buoyancy", True):
        scene["buoyancy"] = {}
    if any(u != 0.0 for u in case.current):
        scene["flow"] = {"velocity": to_ropesim(case.current).tolist()}
    pinned = [] if case.top_velocity is not None else [-1]
    if case.clump is not None:
        c = physics.get("clump", case.clump)
        scene["bodies"] = [{"node": 0, "mass": c.mass, "volume": c.volume, "cd_area": c.cd_area, "ca": c.ca}]
    else:
        pinned.insert(0, 0)
    if pinned:
        scene["pinned"] = {"nodes": pinned}
    if case.top_velocity is not None:
        scene["driven"] = [{"nodes": [-1], "velocity": to_ropesim(case.top_velocity).tolist()}]
    return scene


def ropesim_scene(case: Case, start, method: str | None = None, dt: float | None = None,
                  t_end: float | None = None, **physics):
    """:func:`ropesim_scene_dict` loaded through ropesim's own TOML reader (a validated Scene)."""
    import tomli_w

    import ropesim

    return ropesim.scene_from_toml(tomli_w.dumps(ropesim_scene_dict(case, start, method, dt, t_end, **physics)))


def run_ropesim(case: Case, start, method: str | None = None, dt: float | None = None,
                t_end: float | None = None, **physics):
    """ropesim's Trajectory for ``case`` from ``start`` (MoorDyn node positions, (N+1, 3))."""
    import ropesim

    return ropesim.simulate(ropesim_scene(case, start, method, dt, t_end, **physics))


# ------------------------------------------------------------------------------------------------ comparing


@dataclass
class Series:
    """One code's run of a case, in ropesim's frame: times (F,) s, positions (F, N+1, 3) m, top and bottom
    segment tensions (F,) N, and the wall time of its time loop (s)."""

    t: np.ndarray
    x: np.ndarray
    top: np.ndarray
    bottom: np.ndarray
    wall: float

    @classmethod
    def of_moordyn(cls, run: MoorDynRun) -> Series:
        return cls(run.t, to_ropesim(run.positions), np.asarray(run.fairlead_tension),
                   np.asarray(run.anchor_tension), float(run.wall_time))

    @classmethod
    def of_ropesim(cls, traj) -> Series:
        """ropesim's run; its end-segment tensions as magnitudes, as MoorDyn reports them (ropesim's are signed:
        a slack segment that shortens carries its axial damping alone, negative)."""
        tension = np.abs(np.asarray(traj.tension))
        return cls(np.asarray(traj.t), np.asarray(traj.x), tension[:, -1], tension[:, 0],
                   float(traj.summary["wall_time_s"]))


def compare(case: Case, a: Series, b: Series) -> dict:
    """How far b is from a (b - a), over frames 1..F-1. Frame 0 is the shared start, but not its tensions: with a
    moving top, MoorDyn's frame 0 has the top still at rest and ropesim's already moving, so the top segment's axial
    damping differs there and only there; without its IC, MoorDyn has computed no tension yet at t = 0 (it reports
    0). Returns, in N, m and fractions:

    top_rms, bottom_rms: RMS tension differences; top_range, bottom_range: a's tension ranges (max - min) over
    those frames; top_rms_rel = top_rms / top_range; top_max, bottom_max: largest differences; pos_rms, pos_max: RMS
    and largest node distance over all nodes and frames; and with ``case.steady`` the steady top and bottom
    tensions (means over the last ``steady`` seconds) of each and their relative difference.
    """
    if a.x.shape != b.x.shape:
        raise ValueError(f"frames differ: {a.x.shape} against {b.x.shape}")
    s = slice(1, None)
    d_top, d_bot = b.top[s] - a.top[s], b.bottom[s] - a.bottom[s]
    dist = np.linalg.norm(b.x[s] - a.x[s], axis=-1)
    out = {
        "top_rms": float(np.sqrt(np.mean(d_top ** 2))),
        "top_max": float(np.max(np.abs(d_top))),
        "top_range": float(np.ptp(a.top[s])),
        "bottom_rms": float(np.sqrt(np.mean(d_bot ** 2))),
        "bottom_max": float(np.max(np.abs(d_bot))),
        "bottom_range": float(np.ptp(a.bottom[s])),
        "pos_rms": float(np.sqrt(np.mean(dist ** 2))),
        "pos_max": float(np.max(dist)),
    }
    out["top_rms_rel"] = out["top_rms"] / out["top_range"]
    if case.steady > 0:
        window = a.t >= a.t[-1] - case.steady - 1e-9
        for key, series in (("top", "top"), ("bottom", "bottom")):
            va, vb = float(np.mean(getattr(a, series)[window])), float(np.mean(getattr(b, series)[window]))
            out[f"steady_{key}_a"], out[f"steady_{key}_b"] = va, vb
            out[f"steady_{key}_rel"] = (vb - va) / va
    return out


def exact_static_line(case: Case) -> tuple[np.ndarray, np.ndarray]:
    """The exact static state of the *discrete* line of a case with both ends fixed (no current), solved
    independently of both codes: node positions (N+1, 3) in MoorDyn's frame (m) and segment tensions (N,) (N).

    The line hangs in the vertical plane through its ends. Segment j's tension vector is (H, V_0 + the submerged
    weight of nodes 1..j) (each inner node carries w l, w the submerged weight per metre, l = L / N); the segment
    points along it and is l (1 + T_j / EA) long. The gap to the top end closes for one (H, V_0), found with scipy
    from the continuous elastic catenary's values."""
    from scipy.optimize import root

    from .catenary_closed_form import suspended_catenary

    if case.clump is not None or any(u != 0.0 for u in case.current):
        raise ValueError("the exact static state is for a line between two fixed points in still water")
    b, t = np.asarray(case.bottom_start(), dtype=float), np.asarray(case.top, dtype=float)
    span, rise = float(np.hypot(*(t - b)[:2])), float((t - b)[2])
    ln, n = case.line, case.segments
    seg = case.length / n
    w = ln.wet_weight
    vertical_steps = np.concatenate([[0.0], np.cumsum(np.full(n - 1, w * seg))])

    def segments(u):
        h, v0 = u
        v = v0 + vertical_steps
        tension = np.hypot(h, v)
        stretch = seg * (1.0 + tension / ln.EA) / tension
        return h * stretch, v * stretch, tension

    def gap(u):
        dx, dz, _ = segments(u)
        return [(np.sum(dx) - span) / case.length, (np.sum(dz) - rise) / case.length]

    guess = suspended_catenary(span, rise, case.length, ln.EA, w)
    sol = root(gap, [guess.H, guess.V_A], method="hybr", options={"xtol": 1e-14})
    if max(abs(r) for r in gap(sol.x)) > 1e-11:
        raise RuntimeError(f"the discrete catenary did not close: {sol.message}")
    dx, dz, tension = segments(sol.x)
    across = (t - b)[:2] / span
    pos = np.zeros((n + 1, 3))
    pos[0] = b
    pos[1:, :2] = b[:2] + np.cumsum(dx)[:, None] * across
    pos[1:, 2] = b[2] + np.cumsum(dz)
    return pos, tension


def exact_static(case: Case) -> tuple[float, float]:
    """(top, bottom) segment tensions (N) of :func:`exact_static_line`."""
    tension = exact_static_line(case)[1]
    return float(tension[-1]), float(tension[0])
