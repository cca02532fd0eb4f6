"""MoorDyn v2 input files as ropesim scenes: ``ropesim import moordyn FILE`` and ``ropesim run FILE.txt``.

A MoorDyn input file is a list of sections, each opened by a line with ``---`` and the section's name: LINE TYPES
(or LINE DICTIONARY), POINTS (or POINT LIST, POINT PROPERTIES, CONNECTION PROPERTIES, NODE PROPERTIES), LINES,
BODIES, OPTIONS and the ones ropesim cannot take (RODS, ROD TYPES, FAILURE, SYROPE IC, OUTPUTS). A table section
has a row of column names and a row of units under its header; MoorDyn reads its columns by position, whatever
the names say, and so does this reader (``source/MoorDyn2.cpp``).

:func:`read_moordyn` turns the text into a :class:`Translation`: the scene as a TOML-ready dict, the comments that
go with its keys (where ropesim's law differs from MoorDyn's, it says so) and the ``notes``: one line for each
thing MoorDyn's file asks for that the scene does not carry (output channels, logging, the IC solver's settings),
never dropped silently. A steady current profile (``Currents = 1``: ``current_profile.txt`` beside the input file)
becomes ``[flow]``'s table. What would change the physics if left out (rods, wave kinematics, time-varying
currents, VIV, a nonlinear or viscoelastic line, a seabed file, line failure) is refused: :class:`MoorDynError`, one line naming
the file, the line number and what is wrong, as a malformed row, a line end on a missing point, a missing line
type, a section ropesim does not know or units MoorDyn would not read as SI are.

Conventions, mapped exactly (``tests/references/MOORDYN_CONVENTIONS.md`` sets them side by side):

- frame: MoorDyn's z points up. The scene keeps MoorDyn's numbers with ``up = "z"`` (the loader turns it into its
  y-up twin, :mod:`ropesim.scene.frame`, and every output back); with ``y_up`` a point (x, y, z) is written as
  ropesim's (x, z, -y) instead, a proper rotation (:func:`to_y_up`);
- a line type's d, mass per metre, EA, BA (a negative BA is a damping ratio: ``axial_damping_ratio``), EI, Cd, Ca,
  CdAx, CaAx are the line type's diameter, mass_per_length, EA, axial_damping, EI, cd_normal, ca_normal,
  cd_tangential, ca_tangential, with MoorDyn's areas (normal drag on d l, tangential on pi d l) and its lumping
  (half a segment at each end node);
- a body's angles: MoorDyn turns by R = Rx(roll) Ry(pitch) Rz(yaw) (``Euler2Quat``), ropesim's orientation by
  R = Rz Ry Rx; the scene's angles are those of the same rotation. Its weight and buoyancy both act at its centre of
  gravity in MoorDyn (``Body::doRHS``), so the scene's centre of buoyancy is its centre of gravity;
- the seabed: MoorDyn's flat bottom at z = -WtrDpth with kBot and cBot, its damping in both directions
  (``damping_both_ways``); each node's footprint is its line's diameter, as in MoorDyn.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import SceneError

MOORDYN_G = 9.80665            # MoorDyn's default g [m/s^2] (``EnvCond``)
MOORDYN_RHO = 1025.0           # its default water density [kg/m^3]
MOORDYN_KBOT, MOORDYN_CBOT = 3.0e6, 3.0e5   # its default seabed stiffness [Pa/m] and damping [Pa s/m]
MOORDYN_CFL = 0.5              # its default CFL number, which sets the step when dtM is not given
DEFAULT_T_END = 60.0           # MoorDyn's file gives no run time (its caller steps it): the scene's default

SECTIONS = (   # (names MoorDyn accepts, ropesim's name for it); the first that a header contains wins
    (("LINE DICTIONARY", "LINE TYPES"), "line_types"),
    (("ROD DICTIONARY", "ROD TYPES"), "rod_types"),
    (("BODIES", "BODY LIST", "BODY PROPERTIES"), "bodies"),
    (("RODS", "ROD LIST", "ROD PROPERTIES"), "rods"),
    (("POINTS", "POINT LIST", "POINT PROPERTIES", "CONNECTION PROPERTIES", "NODE PROPERTIES"), "points"),
    (("LINES", "LINE LIST", "LINE PROPERTIES"), "lines"),
    (("OPTIONS",), "options"),
    (("OUTPUT",), "outputs"),
    (("FAILURE",), "failure"),
    (("SYROPE IC",), "syrope"),
    (("EXTERNAL",), "external"),
    (("CONTROL",), "control"),
)
NOT_SECTIONS = ("MOORDYN", "NEED THIS LINE", "END")   # the title line and the end markers
TABLE_SECTIONS = ("line_types", "rod_types", "bodies", "rods", "points", "lines")
REFUSED_SECTIONS = {
    "rod_types": "rods (ROD TYPES): ropesim has no rods yet",
    "rods": "rods: ropesim has no rods yet",
    "failure": "line failure (FAILURE): ropesim's lines do not break",
    "syrope": "SYROPE IC: ropesim has no Syrope line model",
    "external": "external loads: ropesim has no constant loads on points or bodies",
    "control": "control (line length changes): ropesim's lines keep their length",
}

POINT_KINDS = {"ANCHOR": "fixed", "FIXED": "fixed", "FIX": "fixed", "FAIRLEAD": "coupled", "VESSEL": "coupled",
               "VES": "coupled", "COUPLED": "coupled", "CPLD": "coupled", "POINT": "free", "CONNECT": "free",
               "CON": "free", "FREE": "free", "BODY": "body"}
BODY_KINDS = {"ANCHOR": "fixed", "FIXED": "fixed", "FIX": "fixed", "VESSEL": "coupled", "VES": "coupled",
              "COUPLED": "coupled", "CPLD": "coupled"}   # any other word: free (as MoorDyn reads it)
PINNED_BODIES = ("VESSELPINNED", "VESPIN", "CPLDPIN", "COUPLEDPINNED")
SCHEMES = {"RK4": "rk4"}   # the others: rk4 too, and a comment saying so

UNIT_COLUMNS = {   # table section: {column position: (what, the unit MoorDyn reads)}
    "line_types": {1: ("Diam", "m"), 2: ("Mass/m", "kg/m"), 3: ("EA", "N"), 5: ("EI", "N-m^2")},
    "points": {2: ("X", "m"), 3: ("Y", "m"), 4: ("Z", "m"), 5: ("Mass", "kg"), 6: ("Volume", "m^3")},
    "lines": {4: ("UnstrLen", "m")},
    "bodies": {2: ("X", "m"), 3: ("Y", "m"), 4: ("Z", "m"), 5: ("Roll", "deg"), 6: ("Pitch", "deg"),
               7: ("Yaw", "deg"), 8: ("Mass", "kg"), 11: ("Volume", "m^3")},
}
SCALED_UNIT = re.compile(r"^(mm|cm|km|in|ft|kn|mn|kip|lb|lbs|lbf|te|t|tonne|kg/mm|t/m|kn-m\^2|knm\^2|kn-m2|"
                         r"mm\^3|cm\^3|l|rad)(\W|$)")


class MoorDynError(SceneError):
    """A MoorDyn input file ropesim cannot read or cannot translate: ``str()`` is one line, ``FILE: line N:
    what``."""

    def __init__(self, source: str, line: int | None, message: str):
        super().__init__(source, f"line {line}" if line else "", message)
        self.line = line


@dataclass
class Translation:
    """A MoorDyn file as a scene: ``scene`` (a TOML-ready dict), ``comments`` {dotted key: comment} to write above
    the keys, and ``notes``: one line for each thing the file asks for that the scene does not carry."""

    scene: dict
    comments: dict[str, str] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)


@dataclass
class _Row:
    number: int          # 1-based line number in the file
    cells: list[str]


@dataclass
class _Section:
    name: str
    header: int          # its header's line number
    rows: list[_Row]
    units: _Row | None = None


def looks_like_moordyn(text: str) -> bool:
    """True for a MoorDyn input file: a ``---`` line naming one of MoorDyn's sections."""
    return any(_section_of(line) is not None for line in text.splitlines() if "---" in line)


def _section_of(header: str) -> str | None:
    upper = header.upper()
    for names, key in SECTIONS:
        if any(name in upper for name in names):
            return key
    return None


def split_sections(text: str, source: str) -> dict[str, _Section]:
    """The file's sections by ropesim's names, their rows split on blanks (a table's names and units rows set
    apart); an unknown section is refused."""
    lines = text.splitlines()
    sections: dict[str, _Section] = {}
    current: _Section | None = None
    skip = 0
    for number, raw in enumerate(lines, start=1):
        line = raw.rstrip()
        if "---" in line:
            key = _section_of(line)
            words = line.replace("-", " ").strip()
            if key is None:
                if words and not any(w in words.upper() for w in NOT_SECTIONS):
                    raise MoorDynError(source, number, f"unknown section '{words}'; MoorDyn's sections are LINE "
                                                       f"TYPES, POINTS, LINES, BODIES, RODS, ROD TYPES, OPTIONS, "
                                                       f"OUTPUTS, FAILURE")
                current = None
                continue
            if key in sections:
                raise MoorDynError(source, number, f"a second {words} section (the first is at line "
                                                   f"{sections[key].header})")
            current = sections[key] = _Section(key, number, [])
            skip = 2 if key in TABLE_SECTIONS else 0
            continue
        if current is None or not line.strip():
            continue
        cells = line.split()
        if skip:
            if skip == 1:
                current.units = _Row(number, cells)
            skip -= 1
            continue
        current.rows.append(_Row(number, cells))
    return sections


def read_moordyn(text: str, source: str = "<moordyn>", base_dir: str | Path | None = None,
                 y_up: bool = False) -> Translation:
    """The scene of a MoorDyn v2 input file (see the module's docstring); raises :class:`MoorDynError`.
    ``y_up``: write the scene in ropesim's y-up frame, (x, y, z) -> (x, z, -y), instead of MoorDyn's own with
    ``up = "z"`` (the default)."""
    sections = split_sections(text, source)
    if not sections:
        raise MoorDynError(source, None, "not a MoorDyn input file: no line of it opens a MoorDyn section (---- "
                                         "LINE TYPES ----, ---- LINES ----, ...)")
    for key, why in REFUSED_SECTIONS.items():
        if key in sections and sections[key].rows:
            raise MoorDynError(source, sections[key].rows[0].number, f"uses {why}")
    for key, what in (("line_types", "LINE TYPES"), ("lines", "LINES")):
        if key not in sections or not sections[key].rows:
            where = sections[key].header if key in sections else None
            raise MoorDynError(source, where, f"has no {what}: ropesim's systems are lines between points and "
                                              f"bodies")
    for key in UNIT_COLUMNS:
        if key in sections:
            _check_units(sections[key], source)
    translation = _Translator(sections, source, y_up, base_dir).translate()
    _fit_time_step(translation, source)
    return translation


def _fit_time_step(translation: Translation, source: str) -> None:
    """MoorDyn's step kept when ropesim's method is stable at it (with a margin: no warning), else divided by the
    smallest whole number that makes it so, with a comment saying why. MoorDyn's RK2 and ropesim's rk4 have
    different stability regions, and ropesim's bound counts every stiff term."""
    from ..analysis.stability import WARN_FRACTION, predicted_dt
    from ..model.build import build
    from .loader import scene_from_dict

    integrator = translation.scene["integrator"]
    scene = scene_from_dict({"name": "moordyn", **translation.scene}, source=f"{source} (imported)")
    bound = predicted_dt(build(scene), integrator["method"])
    dt = integrator["dt"]
    if dt <= WARN_FRACTION * bound:
        return
    parts = math.ceil(dt / (WARN_FRACTION * bound))
    integrator["dt"] = dt / parts
    translation.comments["integrator.dt"] = (f"MoorDyn's step {dt:g} s divided by {parts}: {integrator['method']}'s "
                                             f"stability bound here is {bound:.4g} s")


def _check_units(section: _Section, source: str) -> None:
    """A units row that names a scaled unit (kN, mm, t, ...) where MoorDyn reads SI is refused: MoorDyn would read
    the numbers as SI, so the file's author meant something else."""
    if section.units is None:
        return
    for position, (what, unit) in UNIT_COLUMNS[section.name].items():
        if position >= len(section.units.cells):
            continue
        given = section.units.cells[position].strip("()[]").lower()
        if SCALED_UNIT.match(given) and given != unit.lower():
            raise MoorDynError(source, section.units.number, f"inconsistent units: column {position + 1} ({what}) "
                                                             f"says ({given}), but MoorDyn reads it in {unit}; "
                                                             f"convert the column to {unit}")


def to_y_up(v) -> list[float]:
    """MoorDyn's (x, y, z), z up, as ropesim's y-up (x, z, -y): a rotation of -90 degrees about x."""
    x, y, z = (float(c) for c in v)
    return [x, z, 0.0 if y == 0.0 else -y]


def _number(row: _Row, i: int, what: str, source: str) -> float:
    try:
        value = float(row.cells[i])
    except ValueError:
        raise MoorDynError(source, row.number, f"{what} (column {i + 1}) must be a number, got "
                                               f"'{row.cells[i]}'") from None
    if not math.isfinite(value):
        raise MoorDynError(source, row.number, f"{what} (column {i + 1}) must be finite, got '{row.cells[i]}'")
    return value


def _numbers(row: _Row, i: int, what: str, source: str, counts: tuple[int, ...]) -> list[float]:
    """A cell of numbers joined by '|' (MoorDyn's body columns), of one of ``counts`` lengths."""
    parts = row.cells[i].split("|")
    if len(parts) not in counts:
        raise MoorDynError(source, row.number, f"{what} (column {i + 1}) takes {' or '.join(map(str, counts))} "
                                               f"numbers joined by '|', got '{row.cells[i]}'")
    return [_number(_Row(row.number, parts), k, what, source) for k in range(len(parts))]


def _need(row: _Row, count: int, what: str, source: str) -> None:
    if len(row.cells) < count:
        raise MoorDynError(source, row.number, f"malformed {what} row: {count} columns needed, got "
                                               f"{len(row.cells)} ('{' '.join(row.cells)}')")


def _word_and_number(cell: str) -> tuple[str, str]:
    """'Body2' -> ('BODY', '2'); '3' -> ('', '3') (MoorDyn's ``decomposeString``, its first letters and digits)."""
    match = re.match(r"^([A-Za-z]*)(\d*)", cell)
    return match.group(1).upper(), match.group(2)


class _Translator:
    def __init__(self, sections: dict[str, _Section], source: str, y_up: bool, base_dir: str | Path | None = None):
        self.sections, self.source, self.y_up = sections, source, y_up
        self.base_dir = None if base_dir is None else Path(base_dir)
        self.scene: dict = {}
        self.comments: dict[str, str] = {}
        self.notes: list[str] = []
        self.options = self._options()

    def fail(self, row: _Row | None, message: str):
        raise MoorDynError(self.source, row.number if row else None, message)

    def vector(self, v) -> list[float]:
        return to_y_up(v) if self.y_up else [float(c) for c in v]

    def axes(self, v) -> list[float]:
        """Per-axis magnitudes (drag areas, added masses, moments of inertia) on the scene's axes."""
        return [abs(c) for c in to_y_up(v)] if self.y_up else [float(c) for c in v]

    def option(self, name: str, default=None):
        return self.options.get(name.lower(), (default, None))[0]

    # ------------------------------------------------------------------------------------ options

    def _options(self) -> dict[str, tuple[str, _Row]]:
        out: dict[str, tuple[str, _Row]] = {}
        aliases = {"dt": "dtm", "gravity": "g", "rho": "wtrdnsty", "kb": "kbot", "cb": "cbot", "icdt": "dtic",
                   "ictmax": "tmaxic", "icdfac": "cdscaleic", "icthresh": "threshic", "icfile": "fileic",
                   "icgendynamic": "gendynamicic"}
        section = self.sections.get("options")
        for row in section.rows if section else ():
            if len(row.cells) < 2:
                continue
            name = row.cells[1].lower()
            out[aliases.get(name, name)] = (row.cells[0], row)
        return out

    def _float_option(self, name: str, default: float) -> float:
        if name not in self.options:
            return default
        value, row = self.options[name]
        try:
            number = float(value)
        except ValueError:
            self.fail(row, f"option {row.cells[1]} must be a number, got '{value}'")
        if not math.isfinite(number):
            self.fail(row, f"option {row.cells[1]} must be finite, got '{value}'")
        return number

    # ------------------------------------------------------------------------------------ whole

    def translate(self) -> Translation:
        self._refuse_options()
        self.scene["dimension"] = 3
        if not self.y_up:
            self.scene["up"] = "z"
        self._environment()
        self._currents()
        self._line_types()
        self._bodies()
        self._points()
        self._lines()
        self._run_options()
        self._other_options()
        self._outputs()
        return Translation(self.scene, self.comments, self.notes)

    def _refuse_options(self) -> None:
        for name, why in (("wavekin", "wave kinematics from MoorDyn's wave files or grids (WaveKin = {}): ropesim reads "
                                      "WaveKin = 1 (kinematics given through the coupling calls); its own waves are "
                                      "[waves]"),
                          ("currents", "currents that vary in time or across the sea (Currents = {}): ropesim's "
                                       "[flow] is steady and varies with height only (Currents = 1 is read)")):
            value = self.options.get(name, ("0", None))[0]
            if value in ("0", "0.0") or value in ("1", "1.0"):
                continue
            self.fail(self.options[name][1], f"uses {why.format(value)}")
        if "seafloorfile" in self.options:
            self.fail(self.options["seafloorfile"][1], "uses a 3-D seafloor (SeafloorFile): ropesim's seabed is a "
                                                       "plane")

    def _currents(self) -> None:
        """MoorDyn's Currents = 1: a steady current profile read from current_profile.txt beside the input file
        (WaveGrid.cpp's constructSteadyCurrentGrid: three header lines, then rows z, ux [, uy [, uz]], missing
        components 0), interpolated linearly in z and held at the end rows beyond them, as [flow]'s table is."""
        value, row = self.options.get("currents", ("0", None))
        if value not in ("1", "1.0"):
            return
        if self.base_dir is None:
            self.fail(row, "Currents = 1 reads current_profile.txt beside the input file, but this file's folder is "
                           "not known; import it from its file")
        path = self.base_dir / "current_profile.txt"
        try:
            lines = path.read_text(errors="replace").splitlines()
        except OSError as exc:
            self.fail(row, f"Currents = 1 reads {path}, which cannot be read ({exc.strerror or exc})")
        rows = []
        for number, line in enumerate(lines[3:], start=4):
            cells = line.replace(",", " ").split()
            if not cells:
                continue
            try:
                numbers = [float(c) for c in cells[:4]]
            except ValueError:
                numbers = []
            if len(numbers) < 2:
                raise MoorDynError(str(path), number, "a current profile row is z, ux [, uy [, uz]] in numbers, got "
                                                      f"{line.strip()!r}")
            rows.append((numbers + [0.0, 0.0])[:4])
        if not rows:
            raise MoorDynError(str(path), None, "no rows of z, ux [, uy [, uz]] after its three header lines")
        rows.sort(key=lambda r: r[0])
        heights = [r[0] for r in rows]
        if len(set(heights)) != len(heights):
            raise MoorDynError(str(path), None, "two rows at the same depth z")
        velocities = [self.vector(r[1:]) for r in rows]
        if len(rows) == 1:
            self.scene["flow"] = {"velocity": velocities[0]}
        else:
            self.scene["flow"] = {"profile": "table", "heights": heights, "velocities": velocities}
        self.comments["flow"] = (f"MoorDyn's Currents = 1: the steady current profile of {path.name} ({len(rows)} "
                                 f"depths), interpolated linearly in depth and held beyond its end rows, as MoorDyn's")

    def _environment(self) -> None:
        g = self._float_option("g", MOORDYN_G)
        rho = self._float_option("wtrdnsty", MOORDYN_RHO)
        self.scene["gravity"] = {"g": g}
        self.scene["fluid"] = {"density": rho}
        self.scene["buoyancy"] = {}
        self.comments["fluid"] = ("MoorDyn's WtrDnsty. ropesim has no free surface: a node above z = 0 still feels "
                                  "buoyancy and drag (MoorDyn counts a node's wetted fraction)")
        if self.options.get("wavekin", ("0", None))[0] in ("1", "1.0"):
            self.scene["sea"] = {"level": 0.0}
            self.comments["fluid"] = "MoorDyn's WtrDnsty"
            self.comments["sea"] = ("MoorDyn's WaveKin = 1: the coupled program gives the waves' velocity and "
                                    "acceleration at the nodes (ExternalWaveKinSet; ropesim.Coupling.set_waves), held "
                                    "until it gives them again; still water until then. The surface is flat at "
                                    "z = 0 (MoorDyn's calls give no elevation): each node feels the water on its "
                                    "part below it, as MoorDyn counts a node's wetted fraction")

    # ------------------------------------------------------------------------------------ line types

    def _line_types(self) -> None:
        types: dict[str, dict] = {}
        coefficients: list[tuple[float, float, float, float]] = []
        for row in self.sections["line_types"].rows:
            _need(row, 10, "line type", self.source)
            name = row.cells[0]
            if not re.match(r"^[A-Za-z0-9_-]+$", name):
                self.fail(row, f"line type name '{name}' must be letters, digits, '_' or '-' (ropesim names a "
                               f"[line_types] table by it)")
            if name in types:
                self.fail(row, f"line type '{name}' is given twice")
            if len(row.cells) > 10 and _number(row, 10, "Cl", self.source) != 0:
                self.fail(row, f"line type '{name}' has a lift coefficient Cl (VIV): ropesim has no vortex-induced "
                               f"vibration")
            for i, what in ((3, "EA"), (4, "BA")):
                if "|" in row.cells[i]:
                    self.fail(row, f"line type '{name}' is viscoelastic ({what} '{row.cells[i]}'): ropesim's lines are "
                                   f"linear elastic")
                try:
                    float(row.cells[i])
                except ValueError:
                    self.fail(row, f"line type '{name}' gives {what} as '{row.cells[i]}' (a curve or a file): "
                                   f"ropesim's lines have a constant {what}")
            d, w, EA, BA, EI = (_number(row, i, what, self.source) for i, what in
                                ((1, "Diam"), (2, "Mass/m"), (3, "EA"), (4, "BA"), (5, "EI")))
            cd, ca, cdax, caax = (_number(row, i, what, self.source) for i, what in
                                  ((6, "Cd"), (7, "Ca"), (8, "CdAx"), (9, "CaAx")))
            for value, what in ((d, "Diam"), (w, "Mass/m"), (EA, "EA")):
                if value <= 0:
                    self.fail(row, f"line type '{name}': {what} must be > 0, got {value:g}")
            for value, what in ((EI, "EI"), (cd, "Cd"), (ca, "Ca"), (cdax, "CdAx"), (caax, "CaAx")):
                if value < 0:
                    self.fail(row, f"line type '{name}': {what} must be >= 0, got {value:g}")
            entry = {"diameter": d, "mass_per_length": w, "EA": EA}
            key = f"line_types.{name}"
            if BA < 0:
                entry["axial_damping_ratio"] = -BA
                self.comments[f"{key}.axial_damping_ratio"] = (f"MoorDyn's BA = {BA:g}: a fraction of each "
                                                               f"segment's critical damping")
            elif BA > 0:
                entry["axial_damping"] = BA
            if EI > 0:
                entry["EI"] = EI
                self.comments[f"{key}.EI"] = ("MoorDyn bends a line by the curvature at each node, from the angle "
                                              "between its segments; ropesim stores EI (1 - cos theta) / l at each "
                                              "joint: equal for small angles")
            entry.update(cd_normal=cd, ca_normal=ca, cd_tangential=cdax, ca_tangential=caax)
            types[name] = entry
            coefficients.append((cd, cdax, ca, caax))
        self.scene["line_types"] = types
        self.types = types
        cd, cdax, ca, caax = coefficients[0]
        self.scene["fluid_drag"] = {"cd_normal": cd, "cd_tangential": cdax}
        self.scene["added_mass"] = {"ca_normal": ca, "ca_tangential": caax}
        note = ("each line type gives its own coefficients (MoorDyn's Cd, CdAx, Ca, CaAx); these, the first "
                "type's, apply only where none is given")
        self.comments["fluid_drag"] = ("Morison drag on the velocity relative to the water: normal on d l, "
                                       "tangential on pi d l, as MoorDyn's; " + note)
        self.comments["added_mass"] = ("on the displaced volume pi d^2 / 4 l, normal and tangential, as MoorDyn's; "
                                       + note)

    # ------------------------------------------------------------------------------------ bodies

    def _bodies(self) -> None:
        self.body_ids: list[str] = []
        section = self.sections.get("bodies")
        if section is None or not section.rows:
            return
        from ..model.rotation import quaternion_from_matrix
        from ..analysis.rotation import angles_from_quaternion

        bodies = []
        for n, row in enumerate(section.rows, start=1):
            _need(row, 14, "body", self.source)
            if row.cells[0] != str(n):
                self.fail(row, f"body ID '{row.cells[0]}' out of order: MoorDyn numbers bodies 1, 2, ... (this "
                               f"is body {n})")
            word, _ = _word_and_number(row.cells[1])
            if word in PINNED_BODIES:
                self.fail(row, f"body {n} is '{row.cells[1]}' (coupled in translation, free to turn): ropesim has "
                               f"no pinned coupled bodies yet")
            kind = BODY_KINDS.get(word, "free")
            r6 = [_number(row, i, what, self.source) for i, what in
                  zip(range(2, 8), ("X", "Y", "Z", "Roll", "Pitch", "Yaw"))]
            mass = _number(row, 8, "Mass", self.source)
            cog = _numbers(row, 9, "CG", self.source, (1, 3))
            cog = [0.0, 0.0, cog[0]] if len(cog) == 1 else cog
            inertia = _numbers(row, 10, "I", self.source, (1, 3))
            inertia = inertia * 3 if len(inertia) == 1 else inertia
            volume = _number(row, 11, "Volume", self.source)
            cda = _numbers(row, 12, "CdA", self.source, (1, 2, 3, 6))
            cda = {1: lambda c: c * 6, 2: lambda c: [c[0]] * 3 + [c[1]] * 3, 3: lambda c: c + c,
                   6: lambda c: c}[len(cda)](cda)
            ca = _numbers(row, 13, "Ca", self.source, (1, 3))
            ca = ca * 3 if len(ca) == 1 else ca
            body_id = f"body{n}"
            key = f"bodies.{len(bodies)}"
            roll, pitch, yaw = (math.radians(a) for a in r6[3:])
            turn = _rx(roll) @ _ry(pitch) @ _rz(yaw)          # MoorDyn's Euler2Quat
            if self.y_up:
                frame = np.array([[1.0, 0, 0], [0, 0, 1.0], [0, -1.0, 0]])
                turn = frame @ turn @ frame.T
            angles = [round(float(a), 12) + 0.0 for a in angles_from_quaternion(quaternion_from_matrix(turn))]
            body = {"id": body_id, "kind": kind, "position": self.vector(r6[:3]), "orientation": angles}
            if kind == "free":
                rho = self.scene["fluid"]["density"]
                body.update(mass=mass, center_of_gravity=self.vector(cog), inertia=self.axes(inertia),
                            volume=volume, center_of_buoyancy=self.vector(cog), cd_area=self.axes(cda[:3]),
                            cd_rotation=self.axes(cda[3:]), added_mass=self.axes([rho * volume * c for c in ca]))
                self.comments[f"{key}.center_of_buoyancy"] = ("MoorDyn's buoyancy acts at the centre of gravity "
                                                              "(Body::doRHS)")
                self.comments[f"{key}.added_mass"] = "MoorDyn's Ca: rho V Ca along each body axis, at the reference point"
            elif any(v != 0 for v in (mass, volume, *cda, *ca)) or any(inertia):
                self.notes.append(f"body {n} ({kind}): its mass, volume, drag and added mass act only on a free "
                                  f"body; left out")
            if kind == "coupled":
                self.comments[key] = (f"MoorDyn's {row.cells[1]} body {n}: the program ropesim is coupled to moves "
                                      f"it; `ropesim run` of this scene alone holds it where it starts")
            if any(a != 0 for a in r6[3:]):
                self.comments[f"{key}.orientation"] = (f"MoorDyn's roll, pitch, yaw {r6[3]:g}, {r6[4]:g}, {r6[5]:g} "
                                                       f"deg turn by Rx Ry Rz; ropesim's angles by Rz Ry Rx, so these "
                                                       f"are the same rotation's")
            bodies.append(body)
            self.body_ids.append(body_id)
        self.scene["bodies"] = bodies

    # ------------------------------------------------------------------------------------ points

    def _points(self) -> None:
        section = self.sections.get("points")
        self.point_rows: dict[int, _Row] = {}
        points = []
        for n, row in enumerate(section.rows if section else (), start=1):
            _need(row, 9, "point", self.source)
            if row.cells[0] != str(n):
                self.fail(row, f"point ID '{row.cells[0]}' out of order: MoorDyn numbers points 1, 2, ... (this "
                               f"is point {n})")
            word, number = _word_and_number(row.cells[1])
            if word not in POINT_KINDS:
                self.fail(row, f"unknown point type '{row.cells[1]}': MoorDyn's are Fixed, Vessel (Coupled), Free "
                               f"(Point, Connect) and BodyN")
            kind = POINT_KINDS[word]
            position = [_number(row, i, what, self.source) for i, what in ((2, "X"), (3, "Y"), (4, "Z"))]
            mass, volume = _number(row, 5, "Mass", self.source), _number(row, 6, "Volume", self.source)
            if len(row.cells) >= 12:
                force = [_number(row, i, "F", self.source) for i in (7, 8, 9)]
                if any(force):
                    self.fail(row, f"point {n} carries a constant external force: ropesim has none on points")
                cda, ca = _number(row, 10, "CdA", self.source), _number(row, 11, "Ca", self.source)
            else:
                cda, ca = _number(row, 7, "CdA", self.source), _number(row, 8, "Ca", self.source)
            for value, what in ((mass, "Mass"), (volume, "Volume"), (cda, "CdA"), (ca, "Ca")):
                if value < 0:
                    self.fail(row, f"point {n}: {what} must be >= 0, got {value:g}")
            point = {"id": f"point{n}", "kind": kind, "position": self.vector(position)}
            key = f"points.{len(points)}"
            if kind == "body":
                if not number or int(number) < 1 or int(number) > len(self.body_ids):
                    self.fail(row, f"point {n} sits on '{row.cells[1]}', but the file has "
                                   f"{len(self.body_ids)} bodies")
                point["body"] = self.body_ids[int(number) - 1]
            elif kind == "free":
                point.update(mass=mass, volume=volume, cd_area=cda, ca=ca)
            elif any((mass, volume, cda, ca)):
                self.notes.append(f"point {n} ({row.cells[1]}): its mass, volume, CdA and Ca act only on a free "
                                  f"point; left out")
            if kind == "coupled":
                self.comments[key] = (f"MoorDyn's {row.cells[1]} point {n}: the program ropesim is coupled to moves "
                                      f"it; `ropesim run` of this scene alone holds it where it starts")
            points.append(point)
            self.point_rows[n] = row
        self.scene["points"] = points

    # ------------------------------------------------------------------------------------ lines

    def _lines(self) -> None:
        lines = []
        for n, row in enumerate(self.sections["lines"].rows, start=1):
            _need(row, 7, "line", self.source)
            if row.cells[0] != str(n):
                self.fail(row, f"line ID '{row.cells[0]}' out of order: MoorDyn numbers lines 1, 2, ... (this is "
                               f"line {n})")
            kind = row.cells[1]
            if kind not in self.types:
                self.fail(row, f"line {n} is of type '{kind}', which LINE TYPES does not give (types: "
                               f"{', '.join(self.types) or 'none'})")
            ends = []
            for i, end in ((2, "AttachA"), (3, "AttachB")):
                word, number = _word_and_number(row.cells[i])
                if word in ("R", "ROD"):
                    self.fail(row, f"line {n} ends on rod '{row.cells[i]}': ropesim has no rods yet")
                if word not in ("", "C", "CON", "P", "POINT") or not number:
                    self.fail(row, f"line {n}: {end} '{row.cells[i]}' is not a point (a number, or P followed by "
                                   f"one)")
                if int(number) not in self.point_rows:
                    self.fail(row, f"line {n}: {end} is point {number}, but POINTS gives "
                                   f"{len(self.point_rows)} points")
                ends.append(f"point{int(number)}")
            length = _number(row, 4, "UnstrLen", self.source)
            try:
                segments = int(row.cells[5])
            except ValueError:
                self.fail(row, f"line {n}: NumSegs (column 6) must be a whole number, got '{row.cells[5]}'")
            if length <= 0 or segments < 1:
                self.fail(row, f"line {n}: UnstrLen must be > 0 and NumSegs >= 1, got {length:g} and {segments}")
            lines.append({"id": f"line{n}", "type": kind, "start": ends[0], "end": ends[1], "length": length,
                          "segments": segments})
            outputs = row.cells[6]
            if outputs not in ("-", "0"):
                self.notes.append(f"line {n}'s output channels '{outputs}': ropesim saves every node and segment "
                                  f"in the run folder (ropesim export, ropesim summary)")
        self.scene["lines"] = lines

    # ------------------------------------------------------------------------------------ options

    def _run_options(self) -> None:
        dt = self._time_step()
        scheme = str(self.option("tscheme", "RK2"))
        method = SCHEMES.get(scheme.upper(), "rk4")
        self.scene["integrator"] = {"method": method, "dt": dt, "t_end": DEFAULT_T_END}
        step = ("MoorDyn's dtM" if "dtm" in self.options else
                f"MoorDyn's step for CFL = {self._float_option('cfl', MOORDYN_CFL):g}: the segments' shortest period "
                f"2 pi l sqrt(m' / EA) times CFL")
        self.comments["integrator"] = (f"dt: {step}. Its file gives no run time (its caller steps it), so t_end is "
                                       f"{DEFAULT_T_END:g} s here: change it, or --set integrator.t_end=T")
        if method != scheme.lower():
            self.comments["integrator.method"] = (f"MoorDyn's tScheme {scheme}; ropesim has no such scheme and "
                                                  f"takes rk4")
        depth = self._float_option("wtrdpth", 0.0)
        lowest = max([-p["position"][2] if not self.y_up else -p["position"][1]
                      for p in self.scene["points"] if p["kind"] != "body"] or [0.0])
        if lowest > depth:   # MoorDyn lowers its default (and a too shallow) water depth to the lowest point
            depth = lowest
        kbot = self._float_option("kbot", MOORDYN_KBOT)
        cbot = self._float_option("cbot", MOORDYN_CBOT)
        seabed = {"height": -depth, "stiffness": kbot, "damping": cbot, "damping_both_ways": True}
        mu = self._float_option("frictioncoefficient", 0.0)
        if mu > 0:
            seabed["friction"] = mu
            self.comments["seabed.friction"] = ("MoorDyn's FrictionCoefficient; ropesim's friction is Coulomb's, "
                                                "regularised below friction_speed (MoorDyn's: FricDamp and "
                                                "StatDynFricScale, not translated)")
        self.scene["seabed"] = seabed
        self.comments["seabed"] = ("MoorDyn's WtrDpth, kBot and cBot: the flat bottom, pushing on each node's "
                                   "footprint d l, damped both ways as MoorDyn's")
        self.scene["initial"] = {"shape": "equilibrium"}
        self.comments["initial"] = ("MoorDyn starts from its initial-condition solver (dynamic relaxation: dtIC, "
                                    "TmaxIC, CdScaleIC, threshIC); ropesim solves the statics directly")
        dt_out = self._float_option("dtout", 0.0)
        self.scene["output"] = {"interval": dt_out if dt_out > 0 else max(dt, 0.1)}
        if dt_out <= 0:
            self.comments["output"] = "MoorDyn writes at every call (dtOut 0); ropesim saves a frame every interval"

    def _time_step(self) -> float:
        """MoorDyn's time step: dtM when given, else the CFL number (default 0.5) times the shortest natural period
        of a segment, 2 pi sqrt(m / k) with m = m' l and k = EA / l (``Line::setup``, ``NatFreqCFL``)."""
        if "dtm" in self.options:
            dt = self._float_option("dtm", 0.0)
            if dt <= 0:
                self.fail(self.options["dtm"][1], f"option dtM must be > 0, got {dt:g}")
            return dt
        cfl = self._float_option("cfl", MOORDYN_CFL)
        if cfl <= 0:
            self.fail(self.options["cfl"][1], f"option CFL must be > 0, got {cfl:g}")
        periods = [2.0 * math.pi * line["length"] / line["segments"]
                   * math.sqrt(self.types[line["type"]]["mass_per_length"] / self.types[line["type"]]["EA"])
                   for line in self.scene["lines"]]
        return cfl * min(periods)

    HANDLED = ("dtm", "cfl", "g", "wtrdnsty", "wtrdpth", "kbot", "cbot", "tscheme", "dtout", "frictioncoefficient",
               "wavekin", "currents", "seafloorfile")
    SOLVER = ("dtic", "tmaxic", "cdscaleic", "threshic")
    QUIET = ("writelog", "disableoutput", "disableouttime", "writeunits")

    def _other_options(self) -> None:
        for name, (value, row) in self.options.items():
            if name in self.HANDLED or name in self.SOLVER:
                continue
            original = row.cells[1]
            if name in self.QUIET:
                self.notes.append(f"option {original} = {value}: MoorDyn's own output files and log; ropesim "
                                  f"writes its run folder")
            elif name == "fileic":
                self.notes.append(f"option {original} = {value}: MoorDyn's stored initial state; ropesim solves "
                                  f"the statics itself")
            elif name == "gendynamicic":
                self.notes.append(f"option {original} = {value}: ropesim solves the statics directly")
            elif name in ("fricdamp", "statdynfricscale"):
                self.notes.append(f"option {original} = {value}: MoorDyn's friction law; ropesim's is "
                                  f"regularised Coulomb (seabed.friction_speed)")
            else:
                self.notes.append(f"option {original} = {value}: no counterpart in ropesim")

    def _outputs(self) -> None:
        section = self.sections.get("outputs")
        channels = [c for row in (section.rows if section else ()) for c in row.cells]
        if channels:
            self.notes.append(f"output channels {' '.join(channels)}: ropesim saves every node, segment, point "
                              f"and body in the run folder (ropesim summary, ropesim export)")


def _rx(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[1.0, 0, 0], [0, c, -s], [0, s, c]])


def _ry(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1.0, 0], [-s, 0, c]])


def _rz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


# ---------------------------------------------------------------------------------------- writing


def scene_text(translation: Translation, source: str, name: str) -> str:
    """The translation as a commented scene file: a header saying where it came from and what it leaves out, each
    table and key with MoorDyn's name for it where that helps."""
    scene = {"name": name, "description": f"imported from the MoorDyn input file {Path(source).name}",
             **translation.scene}
    frame = ("MoorDyn's own, z up (up = \"z\")." if scene.get("up") == "z" else
             "ropesim's y points up; a MoorDyn point (x, y, z) is here (x, z, -y), a rotation of -90 degrees about "
             "x (so MoorDyn's roll is about x, its pitch about -z, its yaw about y).")
    head = _comment(f"Imported by `ropesim import moordyn` from {source} (a MoorDyn v2 input file). Frame: {frame} "
                    f"MoorDyn's numbered points, lines and bodies are point1, line1, body1, ... here.")
    if translation.notes:
        head += "# Not translated (the scene does without them):\n"
        head += "".join(_comment(f"  - {note}", indent="      ") for note in translation.notes)
    out = head + "\n"
    comments = translation.comments
    out += "".join(_key(k, v) for k, v in scene.items() if not isinstance(v, (dict, list))) + "\n"
    for key, value in scene.items():
        if isinstance(value, dict) and key == "line_types":
            for type_name, entry in value.items():
                out += _table(f"line_types.{type_name}", entry, comments)
        elif isinstance(value, dict):
            out += _table(key, value, comments)
        elif isinstance(value, list):
            for j, entry in enumerate(value):
                out += _table(key, entry, comments, index=j)
    return out


def _comment(text: str, indent: str = "") -> str:
    import textwrap

    return "".join(f"# {line}\n" for line in textwrap.wrap(text, 110, subsequent_indent=indent))


def _key(key: str, value) -> str:
    """One ``key = value`` line, a list of numbers inline."""
    import tomli_w

    def scalar(v) -> str:
        return tomli_w.dumps({"v": v})[4:].strip()

    if isinstance(value, list):
        return f"{key} = [{', '.join(scalar(v) for v in value)}]\n"
    return f"{key} = {scalar(value)}\n"


def _table(key: str, entry: dict, comments: dict, index: int | None = None) -> str:
    where = f"{key}.{index}" if index is not None else key
    text = _comment(comments[where]) if where in comments else ""
    text += f"[[{key}]]\n" if index is not None else f"[{key}]\n"
    for k, v in entry.items():
        if f"{where}.{k}" in comments:
            text += _comment(comments[f"{where}.{k}"])
        text += _key(k, v)
    return text + "\n"
