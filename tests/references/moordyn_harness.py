"""Run MoorDyn v2 (through its Python bindings, ``pip install moordyn``) on one mooring line, or on an existing
MoorDyn input file, with a prescribed fairlead motion, and return what a second implementation must match.

Units are SI throughout: metres, seconds, kilograms, newtons. MoorDyn's frame: z up, the still water surface at
z = 0, a flat seabed at z = -depth (a MoorDyn ``WtrDpth`` is a positive depth).

What is returned (:class:`MoorDynRun`), per output frame (one frame per coupling step ``dt_out``; frame 0 is the
state after MoorDyn's initial-condition solve):

- ``positions`` (F, N+1, 3): node positions, node 0 at the line's end A (the anchor), node N at end B;
- ``fairlead_tension`` (F,): |T + Td| of the last segment, what ``GetLineFairTen`` reports (axial stiffness plus
  internal damping, no weight): the tension *in the line* next to the fairlead;
- ``anchor_tension`` (F,): the same for the first segment (``GetLineNodeTen(line, 0)``);
- ``fairlead_force``, ``anchor_force`` (F, 3): the net force MoorDyn puts on the end nodes
  (``GetLineNodeForce``, its ``TenB``/``TenA`` output channels): segment tension plus the end node's half-segment
  weight, buoyancy, drag and seabed force. A coupled fairlead point receives exactly ``fairlead_force``.

How the fairlead is driven (see MOORDYN_CONVENTIONS.md, "Prescribed motion"): MoorDyn moves a coupled point
linearly inside each coupling step, ``r(t_n + s) = x_n + v_n s``. This harness passes ``x_n = motion(t_n)`` and
the secant velocity ``v_n = (motion(t_n+1) - motion(t_n)) / dt_out``, so the fairlead is exactly on the
prescribed path at every output instant and piecewise linear in between.

Everything MoorDyn prints goes to /dev/null (it writes to the C streams directly); the input file, its log and
its output files live in a temporary folder that is removed afterwards.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import shutil
import sys
import tempfile
import time
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, field
from importlib import metadata
from pathlib import Path

import numpy as np

Motion = Callable[[float], "np.ndarray | tuple[float, float, float]"]

#: MoorDyn's own default gravity (m/s^2). Its documentation says 9.81, but the v2.7.2 binary uses 9.80665
#: (checked by tests/test_references_moordyn.py::test_weight_and_gravity_convention).
MOORDYN_DEFAULT_G = 9.80665


@dataclass(frozen=True)
class LineProps:
    """One MoorDyn line type and its length, exactly MoorDyn's ``LINE TYPES`` columns.

    length: unstretched length (m); n_segments: number of segments N (N + 1 nodes); diameter: volume-equivalent
    diameter d (m), used for buoyancy (pi d^2 / 4 per metre), drag and seabed contact; mass_per_length: mass in air
    (kg/m); EA: axial stiffness (N); BA: internal axial damping (N s), or a negative number -zeta meaning a damping
    ratio (MoorDyn sets BA = zeta (L/N) sqrt(EA w)); EI: bending stiffness (N m^2); Cd, Ca: transverse drag and
    added-mass coefficients (-); CdAx, CaAx: tangential ones (-); MoorDyn's tangential drag area is pi d per metre.
    """

    length: float
    n_segments: int
    diameter: float
    mass_per_length: float
    EA: float
    BA: float = 0.0
    EI: float = 0.0
    Cd: float = 1.2
    Ca: float = 1.0
    CdAx: float = 0.0
    CaAx: float = 0.0


@dataclass(frozen=True)
class Environment:
    """Water, gravity and seabed.

    depth: water depth (m), seabed at z = -depth; g (m/s^2); rho_w: water density (kg/m^3); kbot: seabed
    stiffness (Pa/m = N/m^3, per metre of penetration per unit of d x contact length); cbot: seabed damping
    (Pa s/m); friction: MoorDyn ``FrictionCoefficient`` (-); fric_damp: ``FricDamp`` (N s/m per node, whatever its
    length or load: see MOORDYN_CONVENTIONS.md);
    stat_dyn_fric_scale: ``StatDynFricScale`` (-); current: uniform current velocity (m/s), given to MoorDyn as a
    steady current profile (``Currents 1``). MoorDyn ignores currents during its initial-condition solve.
    """

    depth: float
    g: float = MOORDYN_DEFAULT_G
    rho_w: float = 1025.0
    kbot: float = 3.0e6
    cbot: float = 3.0e5
    friction: float = 0.0
    fric_damp: float = 200.0
    stat_dyn_fric_scale: float = 1.0
    current: tuple[float, float, float] = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Solver:
    """MoorDyn's integrator and initial-condition (IC) options.

    dtM: internal time step (s); scheme: ``tScheme`` (RK2 is MoorDyn's default, the explicit midpoint rule);
    ic: run MoorDyn's IC solve at ``Init`` (False: start from the initial catenary/straight profile,
    ``Init_NoIC``); ic_dynamic: ``ICgenDynamic`` (0 = the stationary solver, MoorDyn-C's default; 1 = the legacy
    drag-boosted dynamic relaxation); dtIC (s), TmaxIC (s), CdScaleIC (-), threshIC (-): as in MoorDyn.
    """

    dtM: float = 1.0e-3
    scheme: str = "RK2"
    ic: bool = True
    ic_dynamic: bool = False
    dtIC: float = 1.0
    TmaxIC: float = 120.0
    CdScaleIC: float = 5.0
    threshIC: float = 1.0e-3


@dataclass
class MoorDynRun:
    """Time series from one MoorDyn run (see the module docstring for what each quantity is).

    t (F,) s; positions (F, N+1, 3) m; fairlead_tension, anchor_tension (F,) N; fairlead_force, anchor_force
    (F, 3) N; fairlead_path (F, 3) m, the prescribed fairlead position; wall_time: wall-clock seconds of the time
    loop (Step calls only); init_wall_time: wall-clock seconds of ``Init`` (the IC solve); dtM: MoorDyn's internal
    step (s); scheme: its integrator's name; version: the moordyn package version; input_text: the input file run.
    """

    t: np.ndarray
    positions: np.ndarray
    fairlead_tension: np.ndarray
    anchor_tension: np.ndarray
    fairlead_force: np.ndarray
    anchor_force: np.ndarray
    fairlead_path: np.ndarray
    wall_time: float
    init_wall_time: float
    dtM: float
    scheme: str
    version: str
    input_text: str = field(repr=False)


def moordyn_version() -> str:
    """The installed ``moordyn`` package version (a string such as '2.7.2')."""
    return metadata.version("moordyn")


@contextlib.contextmanager
def quiet_fd():
    """Send the C library's prints on file descriptors 1 and 2 to /dev/null for the duration (no units)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = os.dup(1), os.dup(2)
    null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 1)
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, null):
            os.close(fd)


def sinusoidal_motion(
    x0, amplitude: float, period: float, axis: int = 0, ramp_periods: float = 1.0
) -> Callable[[float], np.ndarray]:
    """Fairlead path x0 + f(t) A sin(2 pi t / T) e_axis (m), t in s.

    x0: rest position (m, 3 values); amplitude A (m); period T (s); axis: 0 surge (x), 1 sway (y), 2 heave (z);
    ramp_periods: the amplitude grows over this many periods with the smootherstep f = 6s^5 - 15s^4 + 10s^3,
    s = t / (ramp_periods T) (zero velocity and acceleration at both ends; MoorDyn's own lowe_and_langley_2006 test
    ramps the same way); 0 for no ramp.
    """
    x0 = np.asarray(x0, dtype=float)
    t_ramp = ramp_periods * period

    def path(t: float) -> np.ndarray:
        s = 1.0 if t_ramp <= 0.0 or t >= t_ramp else max(t, 0.0) / t_ramp
        f = s * s * s * (s * (6.0 * s - 15.0) + 10.0)
        x = x0.copy()
        x[axis] += f * amplitude * math.sin(2.0 * math.pi * t / period)
        return x

    return path


def line_input_text(
    line: LineProps,
    env: Environment,
    anchor,
    fairlead,
    solver: Solver = Solver(),
    fairlead_coupled: bool = True,
) -> str:
    """A MoorDyn v2 input file (text) for one line from a fixed anchor (point 1, end A) to the fairlead (point 2,
    end B), coupled (driven by the caller) or fixed. anchor, fairlead: (x, y, z) positions (m)."""
    ax, ay, az = (float(v) for v in anchor)
    fx, fy, fz = (float(v) for v in fairlead)
    current = any(c != 0.0 for c in env.current)
    return f"""ropesim reference run (tests/references/moordyn_harness.py)
---------------------- LINE TYPES -----------------------------------
TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx
(name) (m) (kg/m) (N) (N-s/-) (N-m^2) (-) (-) (-) (-)
rope {line.diameter!r} {line.mass_per_length!r} {line.EA!r} {line.BA!r} {line.EI!r} \
{line.Cd!r} {line.Ca!r} {line.CdAx!r} {line.CaAx!r}
---------------------- POINTS ---------------------------------------
ID Attachment X Y Z Mass Volume CdA Ca
(#) (word/ID) (m) (m) (m) (kg) (m^3) (m^2) (-)
1 Fixed {ax!r} {ay!r} {az!r} 0 0 0 0
2 {"Coupled" if fairlead_coupled else "Fixed"} {fx!r} {fy!r} {fz!r} 0 0 0 0
---------------------- LINES ----------------------------------------
ID LineType AttachA AttachB UnstrLen NumSegs LineOutputs
(#) (name) (ID) (ID) (m) (-) (-)
1 rope 1 2 {line.length!r} {line.n_segments:d} -
---------------------- OPTIONS -----------------------------------------
0 writeLog
{solver.dtM!r} dtM
{solver.scheme} tScheme
{env.g!r} g
{env.rho_w!r} rho
{env.depth!r} WtrDpth
{env.kbot!r} kBot
{env.cbot!r} cBot
{env.friction!r} FrictionCoefficient
{env.fric_damp!r} FricDamp
{env.stat_dyn_fric_scale!r} StatDynFricScale
{solver.dtIC!r} dtIC
{solver.TmaxIC!r} TmaxIC
{solver.CdScaleIC!r} CdScaleIC
{solver.threshIC!r} threshIC
{int(solver.ic_dynamic)} ICgenDynamic
{1 if current else 0} Currents
1 disableOutput
1 disableOutTime
---------------------- OUTPUTS -----------------------------------------
-------------------------------------------------------------------------
"""


def current_profile_text(current, depth: float) -> str:
    """MoorDyn's steady current file (``Currents 1`` reads ``current_profile.txt`` next to the input file):
    a uniform current (m/s, 3 values) tabulated from below the seabed (z = -depth - 1 m) to above the surface."""
    ux, uy, uz = (float(v) for v in current)
    rows = "".join(f"{z!r} {ux!r} {uy!r} {uz!r}\n" for z in (-depth - 1.0, 0.0, 10.0))
    return f"--------------------- MoorDyn steady currents ---------------\nuniform current\nz ux uy uz\n{rows}"


_OPTIONS_HEADER = re.compile(r"^-+.*OPTIONS", re.IGNORECASE)


def set_options(text: str, options: Mapping[str, object]) -> str:
    """Return the input file text with the given MoorDyn options set (name -> value, value written with str()).

    A row ``<value> <name> ...`` of the OPTIONS section whose name matches (case-insensitively) gets the new
    value; an option not present is added right after the OPTIONS header."""
    rows = text.splitlines(keepends=True)
    start = next((i for i, r in enumerate(rows) if _OPTIONS_HEADER.match(r)), None)
    if start is None:
        raise ValueError("the input file has no OPTIONS section")
    end = next((i for i in range(start + 1, len(rows)) if rows[i].lstrip().startswith("---")), len(rows))
    remaining = {k.lower(): (k, v) for k, v in options.items()}
    for i in range(start + 1, end):
        words = rows[i].split()
        if len(words) >= 2 and words[1].lower() in remaining:
            name, value = remaining.pop(words[1].lower())
            rows[i] = f"{value} {words[1]}\n"
    added = [f"{value} {name}\n" for name, value in remaining.values()]
    return "".join(rows[: start + 1] + added + rows[start + 1 :])


#: Options every run gets: no log file, no output files, no per-step time print (none changes the physics).
QUIET_OPTIONS = {"writeLog": 0, "disableOutput": 1, "disableOutTime": 1}


def _vec(x) -> np.ndarray:
    """Any 3 numbers as a float array of shape (3,), units unchanged."""
    return np.asarray(x, dtype=float).reshape(3)


def _run(
    input_path: Path,
    motion: Motion | None,
    t_end: float,
    dt_out: float,
    line_number: int,
    fairlead_point: int | None,
    ic: bool,
) -> MoorDynRun:
    import cmoordyn
    import moordyn

    with quiet_fd():
        system = moordyn.Create(str(input_path))
    if not system:
        raise RuntimeError(f"MoorDyn could not read {input_path}")
    try:
        n_dof = moordyn.NCoupledDOF(system)
        points = [moordyn.GetPoint(system, i) for i in range(1, moordyn.GetNumberPoints(system) + 1)]
        coupled = [i + 1 for i, p in enumerate(points) if moordyn.GetPointType(p) == moordyn.POINT_TYPE_COUPLED]
        if n_dof != 3 * len(coupled):
            raise ValueError(f"only coupled points are driven here; the file has {n_dof} coupled DOFs")
        if fairlead_point is None and len(coupled) > 1:
            raise ValueError(f"several coupled points {coupled}: say which one is the fairlead")
        if len(coupled) > 1:
            raise ValueError("one coupled point at most (the fairlead)")
        if fairlead_point is not None and fairlead_point not in coupled:
            raise ValueError(f"point {fairlead_point} is not a coupled point (coupled: {coupled})")
        x_rest = _vec(moordyn.GetPointPos(points[coupled[0] - 1])) if coupled else None
        if motion is not None and not coupled:
            raise ValueError("a motion was given but the file has no coupled point")
        path = motion if motion is not None else (lambda t: x_rest)

        line = moordyn.GetLine(system, line_number)
        n = moordyn.GetLineN(line)

        def frame():
            pos = np.array([moordyn.GetLineNodePos(line, i) for i in range(n + 1)])
            return (
                pos,
                moordyn.GetLineFairTen(line),
                float(np.linalg.norm(moordyn.GetLineNodeTen(line, 0))),
                _vec(moordyn.GetLineNodeForce(line, n)),
                _vec(moordyn.GetLineNodeForce(line, 0)),
            )

        # The coupled point rests at path(0) with zero velocity during the IC solve: a velocity given to Init
        # would move it while MoorDyn relaxes the line (r = x + v s over the IC's pseudo-time).
        x0 = _vec(path(0.0)) if coupled else None
        init = moordyn.Init if ic else moordyn.Init_NoIC
        tic = time.perf_counter()
        with quiet_fd():
            err = init(system, list(x0) if coupled else [], [0.0, 0.0, 0.0] if coupled else [])
        init_wall = time.perf_counter() - tic
        if err != moordyn.ERRCODE_SUCCESS:
            raise RuntimeError(f"MoorDyn Init failed with error {err}")

        steps = int(round(t_end / dt_out))
        times = dt_out * np.arange(steps + 1)
        frames = [frame()]
        fair_path = [x0 if coupled else np.full(3, np.nan)]
        wall = 0.0
        with quiet_fd():
            for k in range(steps):
                if coupled:
                    xa, xb = _vec(path(times[k])), _vec(path(times[k + 1]))
                    x, v = list(xa), list((xb - xa) / dt_out)
                else:
                    x = v = []
                tic = time.perf_counter()
                moordyn.Step(system, x, v, float(times[k]), dt_out)
                wall += time.perf_counter() - tic
                frames.append(frame())
                fair_path.append(xb if coupled else np.full(3, np.nan))
        dtm = cmoordyn.get_dt(system)
        scheme = cmoordyn.get_tscheme(system)
    finally:
        with quiet_fd():
            moordyn.Close(system)

    pos, ften, aten, fforce, aforce = (np.array(a) for a in zip(*frames))
    return MoorDynRun(
        t=times,
        positions=pos,
        fairlead_tension=ften,
        anchor_tension=aten,
        fairlead_force=fforce,
        anchor_force=aforce,
        fairlead_path=np.array(fair_path),
        wall_time=wall,
        init_wall_time=init_wall,
        dtM=dtm,
        scheme=scheme,
        version=moordyn_version(),
        input_text=input_path.read_text(encoding="utf-8"),
    )


def run_line(
    line: LineProps,
    env: Environment,
    anchor,
    fairlead,
    motion: Motion | None = None,
    t_end: float = 0.0,
    dt_out: float = 0.1,
    solver: Solver = Solver(),
) -> MoorDynRun:
    """Run one line in MoorDyn: anchor fixed at ``anchor`` (m), fairlead coupled and following ``motion``.

    motion: t (s) -> fairlead position (m); None holds the fairlead at ``fairlead``. The motion at t = 0 is where
    the fairlead sits during the IC solve, so it should equal ``fairlead``. t_end: simulated time after the IC (s),
    0 for the static state only; dt_out: coupling step and output interval (s), a multiple of ``solver.dtM``.
    """
    folder = Path(tempfile.mkdtemp(prefix="ropesim-moordyn-"))
    try:
        path = folder / "line.txt"
        path.write_text(line_input_text(line, env, anchor, fairlead, solver), encoding="utf-8")
        if any(c != 0.0 for c in env.current):
            (folder / "current_profile.txt").write_text(current_profile_text(env.current, env.depth))
        return _run(path, motion, t_end, dt_out, 1, None, solver.ic)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def run_input_file(
    input_file: str | os.PathLike,
    motion: Motion | None = None,
    t_end: float = 0.0,
    dt_out: float = 0.1,
    line_number: int = 1,
    fairlead_point: int | None = None,
    options: Mapping[str, object] | None = None,
    ic: bool = True,
    extra_files: Mapping[str, str | os.PathLike] | None = None,
) -> MoorDynRun:
    """Run an existing MoorDyn input file with its (single) coupled point following ``motion``.

    The file is copied to a temporary folder with ``QUIET_OPTIONS`` and then ``options`` (name -> value) set, so the
    original is never touched and MoorDyn writes nothing beside it. motion: t (s) -> fairlead position (m); None
    holds the coupled point where the file puts it. t_end (s), dt_out (s): as in :func:`run_line`. line_number: the
    line (1-based) whose nodes and tensions are recorded. fairlead_point: the coupled point's ID (checked; found
    automatically when there is one). ic: run the IC solve. extra_files: name in the run folder -> file to copy
    there (a current profile, a seabed file).
    """
    folder = Path(tempfile.mkdtemp(prefix="ropesim-moordyn-"))
    try:
        text = Path(input_file).read_text(encoding="utf-8")
        path = folder / Path(input_file).name
        path.write_text(set_options(text, {**QUIET_OPTIONS, **(options or {})}), encoding="utf-8")
        for name, src in (extra_files or {}).items():
            shutil.copy(src, folder / name)
        return _run(path, motion, t_end, dt_out, line_number, fairlead_point, ic)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def moordyn_system(
    input_text: str, coupled_position=None, ic: bool = True, extra_files: Mapping[str, str] | None = None
):
    """MoorDyn created from ``input_text`` (written, with ``extra_files`` (name -> text) beside it, into a temporary
    folder) and initialised, for callers that query MoorDyn's API themselves.

    coupled_position: where the (single) coupled point is, m (None when the file has no coupled point); it gets zero
    velocity. ic: run the IC solve (``Init``) or not (``Init_NoIC``). Yields ``(moordyn, system)``: the bindings
    module and the system. Closes MoorDyn and removes the folder afterwards."""
    import moordyn

    folder = Path(tempfile.mkdtemp(prefix="ropesim-moordyn-"))
    system = None
    try:
        path = folder / "input.txt"
        path.write_text(input_text, encoding="utf-8")
        for name, text in (extra_files or {}).items():
            (folder / name).write_text(text, encoding="utf-8")
        x = [] if coupled_position is None else [float(v) for v in coupled_position]
        with quiet_fd():
            system = moordyn.Create(str(path))
            err = (moordyn.Init if ic else moordyn.Init_NoIC)(system, x, [0.0] * len(x))
        if err != moordyn.ERRCODE_SUCCESS:
            raise RuntimeError(f"MoorDyn Init failed with error {err}")
        yield moordyn, system
    finally:
        if system is not None:
            with quiet_fd():
                moordyn.Close(system)
        shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def line_system(line: LineProps, env: Environment, anchor, fairlead, solver: Solver = Solver()):
    """:func:`moordyn_system` for the one-line set-up of :func:`run_line` (anchor, fairlead: m; the fairlead is the
    coupled point 2, at rest at ``fairlead``). Yields ``(moordyn, system, line)`` with the line's handle."""
    extra = {}
    if any(c != 0.0 for c in env.current):
        extra["current_profile.txt"] = current_profile_text(env.current, env.depth)
    text = line_input_text(line, env, anchor, fairlead, solver)
    with moordyn_system(text, fairlead, solver.ic, extra) as (moordyn, system):
        yield moordyn, system, moordyn.GetLine(system, 1)


def as_dict(obj) -> dict:
    """A dataclass instance (LineProps, Environment, Solver) as a plain dict, for JSON (no units change)."""
    return asdict(obj)
