"""MoorDyn's own system cases (lines joined at points and rigid bodies), built as ropesim scenes on equal
physics: the cases of ``scripts/compare_moordyn_systems.py`` and ``tests/test_moordyn_systems.py``.

The cases are MoorDyn's input files copied to ``tests/data/moordyn/cases/`` (their README says where from). Each
ropesim scene is read from the same file (:func:`read_moordyn_file`, :func:`system_scene_dict`), so both codes run
one description:

- **lines** (``lines.txt``, with its saved state ``lines.txt.ic``): OC3-Hywind's three chains (902.2 m, 20
  segments each) from anchors on the seabed 320 m down to fairleads on the spar 70 m down. MoorDyn's fairleads are
  three coupled ("Vessel") points; ropesim's are points of a driven body ``vessel`` at the origin, as in
  ``tests/data/systems/oc3_hywind.toml``. The vessel surges (:data:`LINES_SURGE`).
- **rotatingBody** (``body_tests/rotatingBody.txt``): a free rigid body (10 kg, inertia 5 kg m^2 about every
  axis) held at its centre by six short taut springs to fixed points, turned by a seventh line from a point on it
  1 m off its centre to a coupled point dragged round three quarter circles (MoorDyn's own test,
  ``tests/bodies.cpp``, "Rotating body"): the body turns -90 degrees about y, then about x, then about z. No
  gravity, and everything sits 4 to 6 m above the water (z > 0), so no fluid acts.
- **lifting** (``lifting.txt``): a 1000 kg free point on a 100.5 m, 20-segment line as dense as the water, hung
  100 m below a fixed point. MoorDyn's own test winds the line in (``SetLineUnstretchedLengthVel``); ropesim has no
  winch (a line's length is fixed), so here the mass drops the 0.5 m of slack its file starts with and bounces on
  the stiff line (EA = 1e9 N): a snap load, every segment slack at the start.
- **spar** (``spar_free.txt``, not MoorDyn's: the speed benchmark's case): lines.txt's chains on a free body, a
  spar of OC3-Hywind's mass and inertia, its centre of gravity 78 m down and 0.5 m off its axis, translational and
  rotational drag, no added mass (MoorDyn would put it in the centripetal force: :func:`moordyn_centripetal_excess`),
  10 % too buoyant for its lines; released from their static shape with the body held (:func:`run_system_from`).

Equal physics, item by item (MOORDYN_CONVENTIONS.md has MoorDyn's side, with its source lines):

- frame: MoorDyn's z is up, ropesim's y; a MoorDyn vector (x, y, z) is ropesim's (x, z, -y) (:data:`P`, a
  proper rotation, so the sense of every rotation is kept); a body's frame maps the same way;
- a line type's columns are read by position, as MoorDyn reads them (``readLineProps``): Diam, Mass/m, EA,
  BA/-zeta, EI, then Cd, Ca, CdAx, CaAx (the file's own header names may say otherwise: rotatingBody's "tbd Can
  Cat Cdn Cdt" are read as Cd, Ca, CdAx, CaAx and a lift coefficient);
- a negative BA is a damping ratio: BA = zeta (L/N) sqrt(EA m'), per line (it depends on the segment length);
- a free rigid body: its mass, its centre of gravity (one number is its z), its inertia about the centre of
  gravity on its axes, its volume with the centre of buoyancy *at the centre of gravity* (where MoorDyn puts
  buoyancy), CdA per axis (translational drag on the reference point's velocity; rotational in m^5), added mass
  rho V Ca on the reference point, none on the rotation; MoorDyn's orientation angles (r, p, y) mean
  R = Rx(r) Ry(p) Rz(y) (``Euler2Quat``), converted to ropesim's R = Rz Ry Rx of its own angles;
- MoorDyn's body lacks the gyroscopic moment w x (I w) and the moment of its points' centripetal forces; on these
  cases they are negligible (measured by :func:`gyroscopic_share`);
- water: WtrDnsty, g, kBot and cBot on the footprint d l_i both ways (``seabed.damping_both_ways``), no friction
  (the files set none); nothing pierces the surface in any case (MoorDyn counts a partly wet segment by its
  wetted part; ropesim's fluid fills all space), and a case entirely above it has no fluid at all.

What is compared: each line's fairlead tension (the end-B segment's |T + Td|, ``GetLineFairTen``), computed for
both codes from the state at the frame with the coupled end's velocity over the coupling interval ending at the
frame (MoorDyn's definition: :func:`segment_tension`); body pose; free point and node positions. Units: SI.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .moordyn_harness import MOORDYN_DEFAULT_G
from .moordyn_own_cases import moordyn_ba, set_line_state

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
CASES_DIR = DATA / "cases"
STORED = DATA / "own_systems"          # .npz and .json
SYSTEMS = ("lines", "rotatingBody", "lifting", "spar")
FILES = {"lines": "lines.txt", "rotatingBody": "rotatingBody.txt", "lifting": "lifting.txt",
         "spar": "spar_free.txt"}   # spar: not MoorDyn's, the speed benchmark's (scripts/bench_systems_moordyn.py)
EXTRA_FILES = {"lines": ("lines.txt.ic",)}

#: MoorDyn's frame to ropesim's: (x, y, z) -> (x, z, -y), a rotation by -90 degrees about x.
P = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


def to_ropesim(v) -> np.ndarray:
    """MoorDyn vectors (..., 3) in ropesim's frame."""
    return np.asarray(v, dtype=float) @ P.T


def from_ropesim(v) -> np.ndarray:
    """ropesim vectors (..., 3) in MoorDyn's frame."""
    return np.asarray(v, dtype=float) @ P


# ------------------------------------------------------------------------------------------------ MoorDyn's file


@dataclass(frozen=True)
class MoorDynFile:
    """A MoorDyn v2 input file as MoorDyn reads it: each table a list of rows (lists of words, the two header rows
    skipped), the options (lower-case name -> value string)."""

    line_types: list[list[str]]
    bodies: list[list[str]]
    rods: list[list[str]]
    points: list[list[str]]
    lines: list[list[str]]
    options: dict[str, str]

    def option(self, *names: str, default: float) -> float:
        """The first of ``names`` the file sets, as a float, else ``default``."""
        return next((float(self.options[n]) for n in names if n in self.options), default)

    @property
    def g(self) -> float:
        return self.option("g", "gravity", default=MOORDYN_DEFAULT_G)

    @property
    def rho_w(self) -> float:
        return self.option("wtrdnsty", "rho", default=1025.0)

    @property
    def depth(self) -> float:
        return self.option("wtrdpth", default=0.0)

    @property
    def dtM(self) -> float:
        return self.option("dtm", default=0.0)

    @property
    def scheme(self) -> str:
        return self.options.get("tscheme", "RK2").upper()


_SECTION_NAMES = {"line types": "line_types", "line dictionary": "line_types", "bodies": "bodies",
                  "body list": "bodies", "body properties": "bodies", "rod types": None, "rod dictionary": None,
                  "rods": "rods", "rod list": "rods", "rod properties": "rods", "points": "points",
                  "point properties": "points", "point list": "points", "connection properties": "points",
                  "node properties": "points", "lines": "lines", "line list": "lines", "line properties": "lines",
                  "options": "options", "solver options": "options", "outputs": None}


def read_moordyn_file(path: str | Path) -> MoorDynFile:
    """Read a MoorDyn input file's tables and options: a ``---- NAME ----`` header, for a table two rows of column
    names and units, then one row per item; options as ``value name [comment]``."""
    tables: dict[str, list] = {k: [] for k in ("line_types", "bodies", "rods", "points", "lines")}
    options: dict[str, str] = {}
    section, skip = None, 0
    for raw in Path(path).read_text(encoding="utf-8").splitlines():
        line = raw.strip()
        if line.startswith("---"):
            title = line.strip("- ").lower()
            key = next((k for k in _SECTION_NAMES if title == k or title.startswith(k + " ")), None)
            section, skip = (_SECTION_NAMES[key] if key else None), 2
            continue
        if section is None or not line:
            continue
        words = line.split()
        if section == "options":
            if len(words) >= 2:
                options[words[1].lower()] = words[0]
        elif skip:
            skip -= 1
        else:
            tables[section].append(words)
    return MoorDynFile(options=options, **tables)


@dataclass(frozen=True)
class LineType:
    """A MoorDyn line type, its columns by position (``readLineProps``): d (m), m' (kg/m), EA (N), BA/-zeta
    (N s, or minus a damping ratio), EI (N m^2), Cd, Ca, CdAx, CaAx (-)."""

    name: str
    d: float
    w: float
    EA: float
    BA: float
    EI: float
    Cd: float
    Ca: float
    CdAx: float
    CaAx: float

    @classmethod
    def of(cls, row: list[str]) -> LineType:
        return cls(row[0], *(float(v) for v in row[1:10]))


def _split(word: str) -> list[float]:
    return [float(v) for v in word.split("|")]


@dataclass(frozen=True)
class Body:
    """A MoorDyn body row (``readBody``), MoorDyn's frame: kind (free, fixed, coupled), position (m), angles
    (deg, R = Rx Ry Rz), mass (kg), CG (m, body frame), inertia (kg m^2 about the CG, body axes), volume (m^3),
    CdA (6: translational m^2, rotational m^5, MoorDyn's own parsing kept), Ca (3)."""

    number: int
    kind: str
    position: tuple
    angles: tuple
    mass: float
    cg: tuple
    inertia: tuple
    volume: float
    cda: tuple
    ca: tuple

    @classmethod
    def of(cls, row: list[str]) -> Body:
        kind = row[1].lower()
        kind = ("fixed" if kind in ("fixed", "fix", "anchor") else
                "coupled" if kind in ("vessel", "ves", "coupled", "cpld") else
                "pinned" if kind in ("vesselpinned", "vespin", "cpldpin", "coupledpinned") else "free")
        cg = _split(row[9])
        cg = (0.0, 0.0, cg[0]) if len(cg) == 1 else tuple(cg)
        inertia = _split(row[10])
        inertia = tuple(inertia * 3) if len(inertia) == 1 else tuple(inertia)
        c = _split(row[12])
        # MoorDyn 2.7.2 reads 1, 2, 3 or 6 CdA values; with 3 or 6 its loop starts at index 1, so CdA_x stays 0.
        cda = ([c[0]] * 6 if len(c) == 1 else [c[0]] * 3 + [c[1]] * 3 if len(c) == 2 else
               [0.0, c[1], c[2], 0.0, c[1], c[2]] if len(c) == 3 else [0.0, *c[1:6]])
        ca = _split(row[13])
        ca = tuple(ca * 3) if len(ca) == 1 else tuple(ca)
        return cls(int(row[0]), kind, tuple(float(v) for v in row[2:5]), tuple(float(v) for v in row[5:8]),
                   float(row[8]), cg, inertia, float(row[11]), tuple(cda), ca)


@dataclass(frozen=True)
class Point:
    """A MoorDyn point row: number, kind (fixed, free, coupled, body), body number (for kind body), position
    (m, world or body frame), mass (kg), volume (m^3), CdA (m^2), Ca (-)."""

    number: int
    kind: str
    body: int | None
    position: tuple
    mass: float
    volume: float
    cda: float
    ca: float

    @classmethod
    def of(cls, row: list[str]) -> Point:
        word = row[1].lower()
        body = None
        if word.startswith("body"):
            kind, body = "body", int(word[4:])
        elif word in ("fixed", "fix", "anchor"):
            kind = "fixed"
        elif word in ("vessel", "ves", "coupled", "cpld"):
            kind = "coupled"
        elif word in ("free", "connect", "con"):
            kind = "free"
        else:
            raise ValueError(f"point {row[0]}: attachment {row[1]!r} is not one ropesim maps")
        return cls(int(row[0]), kind, body, tuple(float(v) for v in row[2:5]), *(float(v) for v in row[5:9]))


@dataclass(frozen=True)
class Line:
    """A MoorDyn line row: number, type name, end A and end B point numbers, unstretched length (m), segments."""

    number: int
    type: str
    a: int
    b: int
    length: float
    segments: int

    @classmethod
    def of(cls, row: list[str]) -> Line:
        return cls(int(row[0]), row[1], int(row[2]), int(row[3]), float(row[4]), int(row[5]))


@dataclass(frozen=True)
class System:
    """A MoorDyn file's system, typed: line types by name, bodies, points and lines in the file's order."""

    file: MoorDynFile
    types: dict
    bodies: tuple
    points: tuple
    lines: tuple

    def point(self, number: int) -> Point:
        return next(p for p in self.points if p.number == number)

    def ba(self, line: Line) -> float:
        """The line's axial damping BA (N s), a damping ratio resolved for its segment length."""
        t = self.types[line.type]
        return moordyn_ba(t.BA, line.length, line.segments, t.EA, t.w)

    @property
    def coupled(self) -> list[int]:
        """The coupled points' numbers, in the file's order (MoorDyn's coupled degrees of freedom, 3 each)."""
        return [p.number for p in self.points if p.kind == "coupled"]

    @property
    def node_count(self) -> int:
        return sum(line.segments + 1 for line in self.lines)

    def first_nodes(self) -> list[int]:
        """Each line's first node in the concatenated node list (line after line, as ropesim lays them)."""
        out, first = [], 0
        for line in self.lines:
            out.append(first)
            first += line.segments + 1
        return out


def read_system(name: str) -> System:
    """A case's MoorDyn file, read and typed."""
    md = read_moordyn_file(CASES_DIR / FILES[name])
    if md.rods:
        raise ValueError(f"{name}: rods are not modelled in ropesim")
    return System(md, {r[0]: LineType.of(r) for r in md.line_types}, tuple(Body.of(r) for r in md.bodies),
                  tuple(Point.of(r) for r in md.points), tuple(Line.of(r) for r in md.lines))


def moordyn_rotation(angles_deg) -> np.ndarray:
    """MoorDyn's orientation matrix (3, 3) of its angles (deg): R = Rx(r) Ry(p) Rz(y) (``Euler2Quat``)."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler("XYZ", np.asarray(angles_deg, dtype=float), degrees=True).as_matrix()


def ropesim_angles(rotation_md: np.ndarray) -> list[float]:
    """ropesim's orientation angles (deg; R = Rz(c) Ry(b) Rx(a)) of a MoorDyn orientation matrix."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(P @ rotation_md @ P.T).as_euler("xyz", degrees=True).tolist()


# ------------------------------------------------------------------------------------------------ ropesim's scene


@dataclass(frozen=True)
class Drive:
    """How the coupled points move: ``path(t)`` (s -> (C, 3) MoorDyn positions of the coupled points, in the file's
    order), handed to MoorDyn at every coupling instant k dt_out as the position and the secant velocity (it moves
    each point linearly between instants) and to ropesim as a ``path_table`` through the same points. vessel: the
    coupled points are ropesim points of a driven body of that name at the origin (its path a translation, the
    same for every point); else each is a driven point."""

    path: Callable[[float], np.ndarray]
    dt_out: float
    t_end: float
    vessel: str | None = None

    def times(self) -> np.ndarray:
        return self.dt_out * np.arange(round(self.t_end / self.dt_out) + 1)


def path_rows(drive: Drive, j: int) -> list[list[float]]:
    """ropesim's ``path_table`` for coupled point j: rows [t, dx, dy, dz] (s, m; ropesim's frame)."""
    x0 = drive.path(0.0)[j]
    return [[float(t), *to_ropesim(drive.path(float(t))[j] - x0).tolist()] for t in drive.times()]


def _in_water(system: System) -> bool:
    """True when everything is under (or at) the still water surface z = 0; False when everything is above it; a system
    that crosses it is refused (ropesim's fluid fills all space)."""
    z = [p.position[2] for p in system.points if p.kind != "body"] + [b.position[2] for b in system.bodies]
    if max(z) <= 0.0:   # a node at z = 0 with its segment below counts as wet in MoorDyn (calcSubSeg)
        return True
    if min(z) > 0.0:
        return False
    raise ValueError("the system crosses the water surface, which ropesim does not model")


def system_scene_dict(name: str, drive: Drive | None, start: str = "lines", method: str = "rk4",
                      dt: float | None = None, t_end: float | None = None, interval: float | None = None,
                      seabed: bool | None = None, changes: dict | None = None) -> dict:
    """ropesim's scene (a TOML-ready dict) for a case, every number from MoorDyn's file.

    drive: the coupled points' motion (None: held where the file puts them); start: the system's initial shape
    (``lines`` or ``equilibrium``); method, dt (default the file's dtM), t_end (default the drive's), interval
    (default the drive's dt_out); seabed: declare the seabed (default: when a point sits within 1 m of it);
    changes: {section: {key: value}} merged into the scene last (for deliberately wrong coefficients in tests)."""
    s = read_system(name)
    md = s.file
    water = _in_water(s)
    depth = md.depth
    if seabed is None:
        seabed = any(p.kind != "body" and p.position[2] < -depth + 1.0 for p in s.points)
    scene: dict = {"name": f"moordyn_{name.lower()}",
                   "description": f"MoorDyn's {FILES[name]} on equal physics (tests/references/moordyn_systems.py)",
                   "dimension": 3}
    drag = water and any(t.Cd or t.CdAx for t in s.types.values())
    added = water and any(t.Ca or t.CaAx for t in s.types.values())
    scene["line_types"] = {t.name: {"diameter": t.d, "mass_per_length": t.w, "EA": t.EA, "compression": False,
                                    **({"EI": t.EI} if t.EI else {}),
                                    **({"cd_normal": t.Cd, "cd_tangential": t.CdAx} if drag else {}),
                                    **({"ca_normal": t.Ca, "ca_tangential": t.CaAx} if added else {})}
                           for t in s.types.values()}
    bodies = []
    for b in s.bodies:
        if b.kind != "free":
            raise ValueError(f"{name}: body {b.number} is {b.kind}; only free bodies are mapped")
        entry = {"id": f"body{b.number}", "position": to_ropesim(b.position).tolist(),
                 "orientation": ropesim_angles(moordyn_rotation(b.angles)), "mass": b.mass,
                 "center_of_gravity": to_ropesim(b.cg).tolist(),
                 "inertia": [b.inertia[0], b.inertia[2], b.inertia[1]]}   # body axes x, z, -y
        if water and b.volume:
            entry |= {"volume": b.volume, "center_of_buoyancy": to_ropesim(b.cg).tolist()}
        if water and any(b.cda):
            entry["cd_area"] = [b.cda[0], b.cda[2], b.cda[1]]
            entry["cd_rotation"] = [b.cda[3], b.cda[5], b.cda[4]]
        if water and b.volume and any(b.ca):
            entry["added_mass"] = [md.rho_w * b.volume * c for c in (b.ca[0], b.ca[2], b.ca[1])]
        bodies.append(entry)
    coupled = s.coupled
    points = []
    for p in s.points:
        entry = {"id": f"point{p.number}"}
        if p.kind == "body":
            entry |= {"body": f"body{p.body}", "position": to_ropesim(p.position).tolist()}
        elif p.kind == "fixed":
            entry |= {"kind": "fixed", "position": to_ropesim(p.position).tolist()}
        elif p.kind == "free":
            entry |= {"kind": "free", "position": to_ropesim(p.position).tolist(), "mass": p.mass}
            if water:
                entry |= {"volume": p.volume, "cd_area": p.cda, "ca": p.ca}
        elif drive is not None and drive.vessel:
            entry |= {"body": drive.vessel, "position": to_ropesim(p.position).tolist()}
        else:
            entry |= {"kind": "driven", "position": to_ropesim(p.position).tolist()}
            if drive is not None:
                entry |= {"path_table": path_rows(drive, coupled.index(p.number)), "ramp_time": 0.0}
            else:
                entry["kind"] = "fixed"
        points.append(entry)
    if drive is not None and drive.vessel:
        rows = [[*row, 0.0, 0.0, 0.0] for row in path_rows(drive, 0)]   # a translation: every point's path
        bodies.insert(0, {"id": drive.vessel, "kind": "driven", "position": [0.0, 0.0, 0.0], "path_table": rows,
                          "ramp_time": 0.0})
    scene["points"] = points
    if bodies:
        scene["bodies"] = bodies
    scene["lines"] = [{"id": f"line{line.number}", "type": line.type, "start": f"point{line.a}",
                       "end": f"point{line.b}", "length": line.length, "segments": line.segments,
                       "axial_damping": s.ba(line)} for line in s.lines]
    scene["initial"] = {"shape": start}
    if md.g:
        scene["gravity"] = {"g": md.g}
    if water:
        scene["fluid"] = {"density": md.rho_w}
        scene["buoyancy"] = {}
        first = next(iter(s.types.values()))   # the tables need values; every line type gives its own
        if drag:
            scene["fluid_drag"] = {"cd_normal": first.Cd, "cd_tangential": first.CdAx}
        if added:
            scene["added_mass"] = {"ca_normal": first.Ca, "ca_tangential": first.CaAx}
    if seabed:
        scene["seabed"] = {"height": -depth, "stiffness": md.option("kbot", "kb", default=3.0e6),
                           "damping": md.option("cbot", "cb", default=3.0e5), "damping_both_ways": True}
    t_end = t_end if t_end is not None else (drive.t_end if drive is not None else 0.0)
    scene["integrator"] = {"method": method, "dt": dt or md.dtM, "t_end": t_end}
    scene["output"] = {"interval": interval or (drive.dt_out if drive is not None else max(t_end, md.dtM))}
    for section, values in (changes or {}).items():
        if isinstance(scene.get(section), dict) and isinstance(values, dict):
            scene[section] = {**scene[section], **values}
        else:
            scene[section] = values
    return scene


def system_scene(name: str, drive: Drive | None, **kw):
    """:func:`system_scene_dict` through ropesim's own TOML reader (a validated Scene)."""
    import tomli_w

    import ropesim

    return ropesim.scene_from_toml(tomli_w.dumps(system_scene_dict(name, drive, **kw)))


def run_system(name: str, drive: Drive | None, **kw):
    """ropesim's Trajectory of a case (arguments as :func:`system_scene_dict`)."""
    import ropesim

    return ropesim.simulate(system_scene(name, drive, **kw))


def run_system_from(name: str, x, **kw):
    """ropesim's Trajectory of a case started from the node positions x (nodes, 3; MoorDyn's frame, line after line),
    at rest, its bodies where the file puts them (a system's scene starts only from its ``lines`` or ``equilibrium``
    shape, so the built model's start is replaced); arguments as :func:`system_scene_dict`."""
    from ropesim.integrate.grid import TimeGrid
    from ropesim.model.build import build
    from ropesim.run import _run_in_memory

    scene = system_scene(name, None, **kw)
    model = build(scene)
    model.x0[:] = to_ropesim(x).T
    return _run_in_memory(model, TimeGrid.of(scene), False, None)


def static_positions(name: str, **kw) -> np.ndarray:
    """ropesim's static shape of a case (``initial.shape = "equilibrium"``), every node (nodes, 3) in MoorDyn's
    frame, line after line."""
    from ropesim.model.build import build

    return from_ropesim(build(system_scene(name, None, start="equilibrium", t_end=0.0, **kw)).x0.T)


def start_positions(name: str) -> np.ndarray:
    """ropesim's ``lines`` start of a case (nodes, 3), MoorDyn's frame."""
    from ropesim.model.build import build

    return from_ropesim(build(system_scene(name, None, t_end=0.0)).x0.T)


# ------------------------------------------------------------------------------------------------ the drives


def smootherstep(s: float) -> float:
    """6 s^5 - 15 s^4 + 10 s^3 on [0, 1], 0 below, 1 above."""
    s = min(max(s, 0.0), 1.0)
    return s * s * s * (s * (6.0 * s - 15.0) + 10.0)


#: lines.txt's vessel surge: amplitude (m), period (s), ramped in over the first period; run length (s).
LINES_SURGE = {"amplitude": 5.0, "period": 20.0, "t_end": 80.0, "dt_out": 0.1}


def lines_drive(t_end: float | None = None) -> Drive:
    """lines.txt's fairleads surging together, x = f(t) A sin(2 pi t / T) (f: smootherstep over one period)."""
    s = read_system("lines")
    rest = np.array([s.point(n).position for n in s.coupled])
    a, period = LINES_SURGE["amplitude"], LINES_SURGE["period"]

    def path(t: float) -> np.ndarray:
        out = rest.copy()
        out[:, 0] += smootherstep(t / period) * a * math.sin(2.0 * math.pi * t / period)
        return out

    return Drive(path, LINES_SURGE["dt_out"], t_end or LINES_SURGE["t_end"], vessel="vessel")


#: rotatingBody's drive, after MoorDyn's tests/bodies.cpp: the coupled point starts 2 m from the body's centre
#: on x, is held 0.1 s, then goes a quarter circle in each of three planes at pi/4 rad/s, each followed by 0.5 s
#: held (MoorDyn's test nudges the point 5 cm outwards while it holds; a path cannot jump, so it is held on the
#: circle here). Centre (m), radius (m).
ROTATING_CENTRE, ROTATING_RADIUS, ROTATING_DT_OUT = np.array([0.0, 0.0, 5.0]), 2.0, 0.1


def rotating_point(t: float) -> np.ndarray:
    """The coupled point's position (3,) at t (s), MoorDyn's frame."""
    c, r = ROTATING_CENTRE, ROTATING_RADIUS
    arcs = (lambda a: c + r * np.array([math.cos(a), 0.0, math.sin(a)]),   # x-z: -90 deg about y
            lambda a: c + r * np.array([0.0, math.sin(a), math.cos(a)]),   # y-z: about x
            lambda a: c + r * np.array([math.sin(a), math.cos(a), 0.0]))   # x-y: about z
    t0 = 0.1
    if t <= t0:
        return arcs[0](0.0)
    for arc in arcs:
        if t <= t0 + 2.0:
            return arc(0.25 * math.pi * (t - t0))
        t0 += 2.0
        if t <= t0 + 0.5:
            return arc(0.5 * math.pi)
        t0 += 0.5
    return arcs[-1](0.5 * math.pi)


def rotating_drive(t_end: float = 7.6) -> Drive:
    return Drive(lambda t: rotating_point(t)[None, :], ROTATING_DT_OUT, t_end)


def drive_of(name: str, t_end: float | None = None) -> Drive | None:
    """The stored run's drive of a case (None for lifting, where nothing is driven)."""
    if name == "lines":
        return lines_drive(t_end)
    if name == "rotatingBody":
        return rotating_drive(7.6 if t_end is None else t_end)
    return None


#: lifting's stored drop: its length (s) and output interval (s).
LIFTING_RUN = {"t_end": 3.0, "dt_out": 0.01}

#: spar's stored release: its length (s), output interval (s), and the body's Ca of the run that shows MoorDyn's
#: added mass in its centripetal force (:func:`moordyn_centripetal_excess`; the file's own Ca is 0).
SPAR_RUN = {"t_end": 30.0, "dt_out": 0.1, "ca": 1.0}


def with_body_ca(text: str, ca: float) -> str:
    """A MoorDyn file's text with its (one) body's Ca, the last column of its row, set to ``ca``."""
    rows = text.splitlines(keepends=True)
    i = next(k for k, row in enumerate(rows) if row.split()[1:2] == ["free"])
    words = rows[i].split()
    rows[i] = " ".join([*words[:-1], repr(ca)]) + "\n"
    return "".join(rows)


def spar_changes(ca: float) -> dict:
    """ropesim's scene change giving the spar's body MoorDyn's added mass rho V Ca on every axis."""
    body = system_scene_dict("spar", None)["bodies"][0]
    return {"bodies": [{**body, "added_mass": [1025.0 * body["volume"] * ca] * 3}]}


def moordyn_centripetal_excess(traj, ca: float) -> np.ndarray:
    """What MoorDyn's body adds to ropesim's physics on the spar, from ropesim's run: its centripetal force of the
    offset centre of gravity is M_t w x (w x c) with M_t its whole translational mass, added mass included
    (``Body::doRHS``), where the rigid body's is m w x (w x c) (the added mass acts at the reference point). The
    excess, -rho V Ca w x (w x c), integrated twice over the heave's mass m + rho V Ca (the lines' restoring
    force and the drag left out over a short window): MoorDyn's heave minus ropesim's (F,), m."""
    from ropesim.model.rotation import rotation_matrix

    s = read_system("spar")
    (body,) = s.bodies
    t = np.asarray(traj.t)
    w = np.asarray(traj.body_w)[:, 0]
    c = np.einsum("fij,j->fi", rotation_matrix(np.asarray(traj.body_q)[:, 0]), to_ropesim(body.cg))
    added = s.file.rho_w * body.volume * ca
    excess = from_ropesim(-added * np.cross(w, np.cross(w, c)))[:, 2] / (body.mass + added)

    def integral(f):
        return np.concatenate([[0.0], np.cumsum(0.5 * (f[1:] + f[:-1]) * np.diff(t))])

    return integral(integral(excess))


# ------------------------------------------------------------------------------------------------ MoorDyn, live


@dataclass
class MoorDynSystemRun:
    """A MoorDyn run of a case, MoorDyn's frame, SI units, F frames: t (F,); positions, velocities (F, nodes, 3),
    every line's nodes line after line; fairlead (F, L): ``GetLineFairTen`` (from its last force evaluation);
    fairlead_state (F, L): the end-B segment's |T + Td| from the state at the frame, the coupled end's velocity
    the secant of the interval ending there (:func:`segment_tension`); anchor (F, L): ``|GetLineNodeTen(0)|``
    (from its last force evaluation too); anchor_state (F, L): the end-A segment's |T + Td| from the state;
    body_r6, body_v6 (F, B, 6): position and angles (rad, R = Rx Ry Rz), velocity and angular velocity;
    points (F, P, 3); wall: the Step calls' wall time (s); dtM (s), scheme; init_wall (s)."""

    t: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    fairlead: np.ndarray
    fairlead_state: np.ndarray
    anchor: np.ndarray
    anchor_state: np.ndarray
    body_r6: np.ndarray
    body_v6: np.ndarray
    points: np.ndarray
    wall: float
    dtM: float
    scheme: str
    init_wall: float = 0.0
    extra: dict = field(default_factory=dict)


def moordyn_text(name: str, options: dict | None = None, ic_file: bool = True, body_ca: float | None = None) -> str:
    """The case's MoorDyn file with the harness's quiet options and ``options`` set; without ``ic_file``, its
    ``fileIC`` option left out (MoorDyn loads that saved state into its integrator even with ``Init_NoIC``, so a
    start set by :func:`set_line_state`, which edits the state the lines report, would not be the one it steps);
    with ``body_ca``, its body's Ca set to that (:func:`with_body_ca`)."""
    from .moordyn_harness import QUIET_OPTIONS, set_options

    text = set_options((CASES_DIR / FILES[name]).read_text(encoding="utf-8"), {**QUIET_OPTIONS, **(options or {})})
    if body_ca is not None:
        text = with_body_ca(text, body_ca)
    if not ic_file:
        text = "".join(row for row in text.splitlines(keepends=True)
                       if not (len(row.split()) >= 2 and row.split()[1].lower() in ("fileic", "icfile")))
    return text


def _extra_files(name: str) -> dict:
    return {f: (CASES_DIR / f).read_bytes() for f in EXTRA_FILES.get(name, ())}


def run_moordyn_system(name: str, drive: Drive | None, t_end: float, dt_out: float, ic: bool = False,
                       start: np.ndarray | None = None, options: dict | None = None,
                       every: int = 1, ic_file: bool = True, body_ca: float | None = None) -> MoorDynSystemRun:
    """MoorDyn on a case: its IC (``ic``) or its initial layout (``Init_NoIC``), then, with ``start`` (nodes, 3),
    every line's nodes set there at rest (:func:`set_line_state`); then ``t_end`` seconds coupled every ``dt_out``
    (the coupled points at ``drive.path`` with the secant velocity, as the harness does), recording every
    ``every``-th coupling instant. options: MoorDyn options (``dtM``, ``tScheme``, ``threshIC``, ...); ic_file:
    keep the file's ``fileIC`` (left out anyway with ``start``)."""
    import shutil
    import tempfile
    import time

    import cmoordyn
    import moordyn as md

    from .moordyn_harness import quiet_fd

    s = read_system(name)
    folder = Path(tempfile.mkdtemp(prefix="ropesim-moordyn-"))
    system = None
    try:
        path = folder / FILES[name]
        path.write_text(moordyn_text(name, options, ic_file=ic_file and start is None, body_ca=body_ca),
                        encoding="utf-8")
        for f, data in _extra_files(name).items():
            (folder / f).write_bytes(data)
        n_coupled = len(s.coupled)
        x_at = (lambda t: drive.path(t).ravel()) if drive is not None else (
            lambda t: np.array([s.point(n).position for n in s.coupled]).ravel())
        with quiet_fd():
            system = md.Create(str(path))
        if not system:
            raise RuntimeError(f"MoorDyn could not read {FILES[name]}")
        tic = time.perf_counter()
        with quiet_fd():
            err = (md.Init if ic else md.Init_NoIC)(system, list(x_at(0.0)), [0.0] * (3 * n_coupled))
        init_wall = time.perf_counter() - tic
        if err != md.ERRCODE_SUCCESS:
            raise RuntimeError(f"MoorDyn Init failed with error {err}")
        lines = [md.GetLine(system, line.number) for line in s.lines]
        bodies = [md.GetBody(system, b.number) for b in s.bodies]
        points = [md.GetPoint(system, p.number) for p in s.points]
        if start is not None:
            first = s.first_nodes()
            for line, handle, f in zip(s.lines, lines, first):
                set_line_state(md, system, handle, start[f:f + line.segments + 1])
        coupled_end = {i: s.coupled.index(line.b) for i, line in enumerate(s.lines) if line.b in s.coupled}
        rec: dict[str, list] = {k: [] for k in ("pos", "vel", "fair", "fstate", "anchor", "astate", "r6", "v6",
                                                  "pts")}

        def record(v_coupled: np.ndarray):
            pos = [np.array([md.GetLineNodePos(h, i) for i in range(line.segments + 1)])
                   for line, h in zip(s.lines, lines)]
            vel = [np.array([md.GetLineNodeVel(h, i) for i in range(line.segments + 1)])
                   for line, h in zip(s.lines, lines)]
            rec["pos"].append(np.concatenate(pos))
            rec["vel"].append(np.concatenate(vel))
            rec["fair"].append([md.GetLineFairTen(h) for h in lines])
            rec["anchor"].append([float(np.linalg.norm(md.GetLineNodeTen(h, 0))) for h in lines])
            fstate = []
            for i, line in enumerate(s.lines):
                v_end = v_coupled.reshape(-1, 3)[coupled_end[i]] if i in coupled_end else vel[i][-1]
                fstate.append(abs(segment_tension(s, i, pos[i], vel[i], v_end)))
            rec["fstate"].append(fstate)
            rec["astate"].append([abs(segment_tension(s, i, pos[i], vel[i], segment=0)) for i in range(len(s.lines))])
            states = [md.GetBodyState(b) for b in bodies]
            rec["r6"].append([st[0] for st in states])
            rec["v6"].append([st[1] for st in states])
            rec["pts"].append([md.GetPointPos(p) for p in points])

        steps = round(t_end / dt_out)
        times = dt_out * np.arange(steps + 1)
        record(np.zeros(3 * n_coupled))
        wall = 0.0
        with quiet_fd():
            for k in range(steps):
                xa, xb = x_at(times[k]), x_at(times[k + 1])
                v = (xb - xa) / dt_out
                tic = time.perf_counter()
                md.Step(system, list(xa), list(v), float(times[k]), dt_out)
                wall += time.perf_counter() - tic
                if (k + 1) % every == 0:
                    record(v)
        dtm, scheme = cmoordyn.get_dt(system), cmoordyn.get_tscheme(system)
    finally:
        if system is not None:
            with quiet_fd():
                md.Close(system)
        shutil.rmtree(folder, ignore_errors=True)
    a = {k: np.array(v) for k, v in rec.items()}
    nb = len(s.bodies)
    return MoorDynSystemRun(times[::every], a["pos"], a["vel"], a["fair"], a["fstate"], a["anchor"], a["astate"],
                            a["r6"].reshape(len(a["pos"]), nb, 6), a["v6"].reshape(len(a["pos"]), nb, 6), a["pts"], wall, dtm, scheme,
                            init_wall)


def moordyn_ic(name: str, options: dict | None = None, ic_file: bool = True) -> dict:
    """MoorDyn's initial-condition (IC) state of a case as its file sets it up (with ``options`` changed; without
    its saved ``.ic`` state unless ``ic_file``): every node (nodes, 3), each line's fairlead and anchor tensions
    (L,) from that state at rest, the points (P, 3), and Init's wall time (s)."""
    run = run_moordyn_system(name, drive_of(name, 0.0), 0.0, 0.1, ic=True, options=options, ic_file=ic_file)
    return {"positions": run.positions[0], "fairlead": run.fairlead_state[0], "anchor": run.anchor_state[0],
            "points": run.points[0], "init_wall": run.init_wall}


def static_tensions(name: str, x) -> tuple[np.ndarray, np.ndarray]:
    """Each line's (fairlead, anchor) segment tensions (L,) each, N, of a static shape x (nodes, 3), at rest."""
    s = read_system(name)
    x = np.asarray(x, dtype=float)
    fair, anchor = [], []
    for i, (line, f) in enumerate(zip(s.lines, s.first_nodes())):
        xi = x[f:f + line.segments + 1]
        fair.append(float(segment_tension(s, i, xi, np.zeros_like(xi))))
        anchor.append(float(segment_tension(s, i, xi, np.zeros_like(xi), segment=0)))
    return np.array(fair), np.array(anchor)


def lifting_closed_form() -> dict:
    """lifting.txt's static state, solved by hand: the line hangs straight down from the fixed point, each segment
    carrying the free point's weight and the wet weight lumped on the nodes below it (a half segment on each end
    node), stretched by T l / EA. Returns {"point_z": the free point's height (m), "tension_a", "tension_b": the
    top segment's and the bottom one's (next to the mass) (N), "segment_tensions": (N,) from the top}."""
    s = read_system("lifting")
    (line,), t = s.lines, s.types[s.lines[0].type]
    g, rho = s.file.g, s.file.rho_w
    l0 = line.length / line.segments
    wet = (t.w - rho * math.pi / 4.0 * t.d ** 2) * g * l0      # N per segment
    mass = next(p for p in s.points if p.kind == "free").mass
    # segment j (0 = top) carries the point, the bottom node's half segment and the inner nodes j+1 .. N-1
    tensions = mass * g + 0.5 * wet + wet * (line.segments - 1 - np.arange(line.segments))
    stretched = l0 * (1.0 + tensions / t.EA)
    top = s.point(line.a).position[2]
    return {"point_z": float(top - stretched.sum()), "tension_a": float(tensions[0]), "tension_b": float(tensions[-1]),
            "segment_tensions": tensions}


EULER_CHECK = {"angles_deg": (30.0, 20.0, 10.0), "point": (1.0, 2.0, 3.0)}


def moordyn_euler_check() -> list[float]:
    """Where MoorDyn puts a point fixed at ``EULER_CHECK["point"]`` on a fixed body turned by
    ``EULER_CHECK["angles_deg"]`` (m, MoorDyn frame): the body's orientation convention as MoorDyn runs it."""
    import shutil
    import tempfile

    import moordyn as md

    from .moordyn_harness import quiet_fd

    r, p, y = EULER_CHECK["angles_deg"]
    px, py, pz = EULER_CHECK["point"]
    text = f"""euler angle check (tests/references/moordyn_systems.py)
---------------------- LINE TYPES -----------------------------------
TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx
(name) (m) (kg/m) (N) (N-s/-) (N-m^2) (-) (-) (-) (-)
rope 0.1 10.0 1.0e6 0.0 0.0 0.0 0.0 0.0 0.0
---------------------- BODIES ---------------------------------------
ID Attachment X0 Y0 Z0 r0 p0 y0 Mass CG* I* Volume CdA* Ca
(#) (-) (m) (m) (m) (deg) (deg) (deg) (kg) (m) (kg-m^2) (m^3) (m^2) (-)
1 fixed 0 0 0 {r!r} {p!r} {y!r} 0 0 0 0 0 0
---------------------- POINTS ---------------------------------------
ID Attachment X Y Z Mass Volume CdA Ca
(#) (-) (m) (m) (m) (kg) (m^3) (m^2) (-)
1 Body1 {px!r} {py!r} {pz!r} 0 0 0 0
2 Fixed 10 0 -5 0 0 0 0
---------------------- LINES ----------------------------------------
ID LineType AttachA AttachB UnstrLen NumSegs LineOutputs
(#) (name) (#) (#) (m) (-) (-)
1 rope 1 2 20 2 -
---------------------- OPTIONS -----------------------------------------
0 writeLog
1 disableOutput
0 g
0.001 dtM
---------------------------------------------------------------------
"""
    folder = Path(tempfile.mkdtemp(prefix="ropesim-moordyn-"))
    system = None
    try:
        (folder / "euler.txt").write_text(text, encoding="utf-8")
        with quiet_fd():
            system = md.Create(str(folder / "euler.txt"))
            md.Init_NoIC(system, [], [])
            md.Step(system, [], [], 0.0, 0.001)
        return list(md.GetPointPos(md.GetPoint(system, 1)))
    finally:
        if system is not None:
            with quiet_fd():
                md.Close(system)
        shutil.rmtree(folder, ignore_errors=True)


# ------------------------------------------------------------------------------------------------ comparing


def segment_tension(s: System, i: int, x, v, v_end=None, segment: int = -1):
    """Line i's segment tension (N), spring plus damping, from its nodes' positions x (..., N+1, 3) and velocities
    v: EA (l_s - l)/l when stretched, plus BA (dl_s/dt)/l (MoorDyn's ``T + Td``, ropesim's ``tension``).
    segment: which segment (-1: the one at end B); v_end: the velocity (..., 3) to use for that segment's upper
    node instead of v's (a coupled fairlead's, see the module docstring). Frame-independent."""
    line = s.lines[i]
    t = s.types[line.type]
    x, v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
    j = segment % line.segments
    seg = x[..., j + 1, :] - x[..., j, :]
    ls = np.linalg.norm(seg, axis=-1)
    upper = v[..., j + 1, :] if v_end is None else np.asarray(v_end, dtype=float)
    rate = np.einsum("...d,...d->...", seg / ls[..., None], upper - v[..., j, :])
    l0 = line.length / line.segments
    return t.EA * np.maximum(ls - l0, 0.0) / l0 + s.ba(line) * rate / l0


def coupled_velocity_before(drive: Drive, t) -> np.ndarray:
    """The coupled points' velocities (F, C, 3) over the coupling interval ending at each time t (F,), MoorDyn's
    frame; zero at t = 0 (MoorDyn's coupled points rest during its Init)."""
    t = np.asarray(t, dtype=float)
    k = np.rint(t / drive.dt_out).astype(int)
    if np.abs(k * drive.dt_out - t).max() > 1e-9:
        raise ValueError("the frames must fall on the coupling instants")
    out = np.zeros((t.size, *drive.path(0.0).shape))
    for f, kf in enumerate(k):
        if kf > 0:
            out[f] = (drive.path(drive.dt_out * kf) - drive.path(drive.dt_out * (kf - 1))) / drive.dt_out
    return out


def ropesim_fairlead_tensions(name: str, traj, drive: Drive | None) -> np.ndarray:
    """ropesim's fairlead tension (F, L) of every line as MoorDyn reports it: |T + Td| of the end-B segment, with
    a coupled end's velocity over the coupling interval ending at the frame."""
    s = read_system(name)
    x, v = from_ropesim(traj.x), from_ropesim(traj.v)
    before = coupled_velocity_before(drive, traj.t) if drive is not None else None
    out = []
    for i, (line, f) in enumerate(zip(s.lines, s.first_nodes())):
        nodes = slice(f, f + line.segments + 1)
        v_end = before[:, s.coupled.index(line.b)] if (drive is not None and line.b in s.coupled) else None
        out.append(np.abs(segment_tension(s, i, x[:, nodes], v[:, nodes], v_end)))
    return np.stack(out, axis=1)


def ropesim_anchor_state(name: str, traj) -> np.ndarray:
    """ropesim's end-A segment |T + Td| (F, L) of every line, from its frames (as MoorDyn's is computed from its
    state: :func:`segment_tension` of each line's first segment)."""
    s = read_system(name)
    x, v = from_ropesim(np.asarray(traj.x)), from_ropesim(np.asarray(traj.v))
    return np.stack([np.abs(segment_tension(s, i, x[:, f:f + line.segments + 1], v[:, f:f + line.segments + 1],
                                            segment=0)) for i, (line, f) in enumerate(zip(s.lines, s.first_nodes()))],
                    axis=1)


def body_rotations_moordyn(r6) -> np.ndarray:
    """MoorDyn bodies' orientations (..., 3, 3) in ropesim's frame, from their angles (rad, R = Rx Ry Rz)."""
    from scipy.spatial.transform import Rotation

    r6 = np.asarray(r6, dtype=float)
    shape = r6.shape[:-1]
    rot = Rotation.from_euler("XYZ", r6.reshape(-1, 6)[:, 3:]).as_matrix()
    return (P @ rot @ P.T).reshape(*shape, 3, 3)


def rotation_angle_between(a, b) -> np.ndarray:
    """The angle (rad) of the rotation taking orientation a to b, (..., 3, 3) each."""
    rel = np.einsum("...ji,...jk->...ik", a, b)
    c = 0.5 * (np.trace(rel, axis1=-2, axis2=-1) - 1.0)
    s = 0.5 * np.linalg.norm(np.stack([rel[..., 2, 1] - rel[..., 1, 2], rel[..., 0, 2] - rel[..., 2, 0],
                                       rel[..., 1, 0] - rel[..., 0, 1]], axis=-1), axis=-1)
    return np.arctan2(s, c)


def gyroscopic_share(name: str, traj) -> dict:
    """What MoorDyn's body leaves out, on ropesim's run of a case (bodies' frames; N m): the gyroscopic moment
    w x (I w) of the body with its line ends' masses about its reference point (I_ref = I_cg + m(|c|^2 - c c^T) plus
    each attached node's m_k(|r_k|^2 - r_k r_k^T)), its largest value and RMS, against the RMS of the moment the
    lines put on the body (I_ref dw/dt + w x I_ref w, from the frames)."""
    from ropesim.model.build import build
    from ropesim.model.rotation import rotation_matrix

    scene = traj.scene
    model = build(scene)
    out = {}
    for j, body in enumerate(b for b in scene.rigid_bodies if b.kind == "free"):
        r = rotation_matrix(np.asarray(traj.body_q)[:, j])
        w = np.asarray(traj.body_w)[:, j]
        inertia_b = np.diag(body.inertia) if len(np.shape(body.inertia)) == 1 else np.asarray(body.inertia)
        c = np.asarray(body.center_of_gravity or (0.0, 0.0, 0.0))
        i_ref = inertia_b + body.mass * (c @ c * np.eye(3) - np.outer(c, c))
        x = np.asarray(traj.x)
        ref = np.asarray(traj.body_x)[:, j]
        attached = [p.id for p in scene.points if p.body == body.id]
        nodes = _nodes_on(scene, attached)
        for k in nodes:
            arm = np.einsum("fji,fj->fi", r, x[:, k] - ref)[0]   # body frame, fixed
            i_ref = i_ref + model.mass[k] * (arm @ arm * np.eye(3) - np.outer(arm, arm))
        world = np.einsum("fij,jk,flk->fil", r, i_ref, r)
        gyro = np.cross(w, np.einsum("fij,fj->fi", world, w))
        wdot = np.gradient(w, traj.t, axis=0)
        moment = np.einsum("fij,fj->fi", world, wdot) + gyro
        out[body.id] = {"gyroscopic_max_Nm": float(np.linalg.norm(gyro, axis=1).max()),
                        "gyroscopic_rms_Nm": float(np.sqrt(np.mean(np.sum(gyro ** 2, axis=1)))),
                        "moment_rms_Nm": float(np.sqrt(np.mean(np.sum(moment ** 2, axis=1))))}
    return out


def _nodes_on(scene, point_ids) -> list[int]:
    """The node indices of the line ends on the given points (a system laid out line after line)."""
    out, first = [], 0
    for line in scene.lines:
        n = line.segments + 1
        if line.start in point_ids:
            out.append(first)
        if line.end in point_ids:
            out.append(first + n - 1)
        first += n
    return out


def differences(a, b, skip_first: bool = True) -> dict:
    """How far signal b is from a (b - a), both (F,), over frames 1..F-1: rms, max, a's range and RMS, and the
    fractions rms / range, rms / a's RMS, max / range."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    s = slice(1, None) if skip_first else slice(None)
    d = b[s] - a[s]
    out = {"rms": float(np.sqrt(np.mean(d ** 2))), "max": float(np.max(np.abs(d))),
           "range": float(np.ptp(a[s])), "signal_rms": float(np.sqrt(np.mean(a[s] ** 2)))}
    out["rms_of_range"] = out["rms"] / out["range"] if out["range"] else math.inf
    out["rms_of_rms"] = out["rms"] / out["signal_rms"] if out["signal_rms"] else math.inf
    out["max_of_range"] = out["max"] / out["range"] if out["range"] else math.inf
    return out


def load_stored() -> tuple[dict, dict]:
    """The stored MoorDyn runs: (arrays of ``own_systems.npz``, the ``own_systems.json`` record)."""
    with np.load(STORED.with_suffix(".npz")) as npz:
        arrays = {k: npz[k] for k in npz.files}
    return arrays, json.loads(STORED.with_suffix(".json").read_text(encoding="utf-8"))
