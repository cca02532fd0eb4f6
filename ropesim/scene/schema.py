"""The scene: a validated, frozen description of one simulation.

A scene file is TOML. Each table names one part of the model and a scene names only the parts it uses. A
scene is one rope: ``[rope]``, ``[initial]`` and ``[integrator]`` (always), and optionally ``[gravity]``,
``[drag]``, ``[bending]``, ``[thrower]``, ``[[guides]]``, ``[pinned]``, ``[[driven]]``, ``[[overrides]]``,
``[output]`` and the fluid and seabed tables; or a system: ``[[lines]]`` between ``[[points]]``, rigid
``[[bodies]]``, named ``[line_types.NAME]``, ``[integrator]``, and the same force tables (see "systems"
below). Units are SI throughout; x is horizontal and y points up (z is the third axis in 3-D), unless a 3-D
scene says ``up = "z"`` (MoorDyn's and OrcaFlex's frame; :mod:`ropesim.scene.frame`): then z points up, and what
this schema says of y (heights, the seabed's plane, gravity along -y) is said of z.

The dataclasses below are the schema: every field's ``metadata`` holds a :class:`Spec` saying what the TOML
value may be. :mod:`ropesim.loader` reads a file against them; :func:`scene_to_dict` writes a scene back with
every default filled in.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Spec:
    """What one TOML key may hold.

    kind: "int", "float", "bool", "str", "vector" (one number per dimension), "int_list", "float_list",
    "points" (a list of vectors), "horizontal" (a list of horizontal positions: x in 2-D, two numbers in 3-D)
    or "rows" (a table: rows of a time and one number per dimension); for rigid
    bodies "angles" (one number per axis of rotation: 3 in 3-D, 1 in 2-D), "dofs" (a vector, then its angles:
    6 in 3-D, 3 in 2-D), "dof_rows" (rows of a time and the dofs) and "inertia" (3-D: 3 principal moments or 6,
    Ixx Iyy Izz Ixy Ixz Iyz, the entries of the symmetric tensor [[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz,
    Izz]], which must be positive definite; 2-D: 1). A kind of one number (the angle of a 2-D body) may be
    written bare. ``low``/``high`` bound numbers (``open_low`` makes the lower bound
    strict).
    """

    kind: str
    doc: str
    unit: str = ""
    required: bool = True
    low: float | None = None
    high: float | None = None
    open_low: bool = False
    choices: tuple = ()


def spec(kind: str, doc: str, unit: str = "", default: Any = None, required: bool | None = None, **kw):
    """A dataclass field carrying its :class:`Spec`; a field with a default (even None) is optional."""
    is_required = (default is None and required is None) or bool(required)
    s = Spec(kind, doc, unit, required=is_required, **kw)
    if is_required:
        return field(metadata={"spec": s})
    return field(default=default, metadata={"spec": s})


# --------------------------------------------------------------------------------------------- rope


@dataclass(frozen=True)
class Rope:
    """N point masses joined by springs; an open line or a closed loop. Two ways to give it:

    - per node (the course's form): ``nodes``, ``segment_length`` l, ``stiffness`` k and ``mass`` m of each node;
    - in physical units: ``length``, ``segments`` (or ``nodes``), ``mass_per_length`` (or ``diameter`` and
      material ``density``) and the axial stiffness ``EA``. The loader derives l = length / segments,
      k = EA / l and the node masses, lumped as cable codes do: each node carries half of each segment it
      touches, so an open line's two end nodes carry half a segment (MoorDyn's convention). The resolved
      scene shows both forms.

    ``axial_damping`` (BA) adds a force BA (dl/dt) / l along each segment, in tension and compression; or give
    ``axial_damping_ratio`` zeta, a fraction of each segment's critical damping (MoorDyn's negative BA): BA = zeta
    l sqrt(EA m'), since a segment between two nodes of m' l / 2 stretches with critical damping sqrt(EA m') (per
    node, EA = k l and m' = m / l). The resolved scene shows both.
    ``EI`` gives the rope bending stiffness: each joint between segments stores EI (1 - cos theta) / l_j, theta
    the angle between the two segments and l_j the mean of their rest lengths (EI kappa^2 / 2 per length for
    small angles, kappa = theta / l_j); the forces are that energy's gradient.
    ``compression = false`` makes segments slack when shorter than their rest length (a real rope; the
    default in physical units), ``true`` makes them push back (the course's springs; the per-node default).
    ``diameter`` (either form) is what fluid drag, buoyancy and added mass act on.
    """

    nodes: int | None = spec("int", "number of point masses N", default=None, required=False, low=2,
                             high=1_000_000)
    segment_length: float | None = spec("float", "rest length l of each spring", "m", default=None, required=False,
                                        low=0, open_low=True)
    stiffness: float | None = spec("float", "spring constant k between neighbours", "N/m", default=None,
                                   required=False, low=0, open_low=True)
    mass: float | None = spec("float", "mass m of each node", "kg", default=None, required=False, low=0,
                              open_low=True)
    closed: bool = spec("bool", "true for a closed loop (the last node joins the first)", default=False)
    length: float | None = spec("float", "unstretched length of the whole rope (physical form)", "m", default=None,
                                required=False, low=0, open_low=True)
    segments: int | None = spec("int", "number of segments (physical form)", default=None, required=False, low=1,
                                high=1_000_000)
    mass_per_length: float | None = spec("float", "mass per metre (physical form)", "kg/m", default=None,
                                         required=False, low=0, open_low=True)
    diameter: float | None = spec("float", "diameter d: the area drag, buoyancy and added mass act on", "m",
                                  default=None, required=False, low=0, open_low=True)
    density: float | None = spec("float", "material density; with diameter, the mass per metre rho pi d^2 / 4",
                                 "kg/m^3", default=None, required=False, low=0, open_low=True)
    EA: float | None = spec("float", "axial stiffness EA (physical form)", "N", default=None, required=False, low=0,
                            open_low=True)
    axial_damping: float | None = spec("float", "internal damping BA: force BA (dl/dt) / l along each segment",
                                       "N s", default=None, required=False, low=0)
    axial_damping_ratio: float | None = spec("float", "internal damping as a fraction zeta of each segment's "
                                                      "critical damping (MoorDyn's negative BA): BA = zeta l "
                                                      "sqrt(EA m')", default=None, required=False, low=0)
    EI: float | None = spec("float", "bending stiffness EI: energy EI (1 - cos theta) / l at each joint",
                            "N m^2", default=None, required=False, low=0, open_low=True)
    compression: bool | None = spec("bool", "segments push back when shorter than their rest length (default: "
                                            "true per node, false in physical units)", default=None, required=False)

    @property
    def physical(self) -> bool:
        """True when the rope was given in physical units (its end nodes then carry half a segment)."""
        return self.length is not None

    @property
    def segment_count(self) -> int:
        return self.nodes if self.closed else self.nodes - 1


@dataclass(frozen=True)
class Seabed:
    """A seabed or ground: the plane y = height + tan(slope) x, with the scene's nodes pushed out of it.

    A node that sinks a depth delta below the plane (measured along its normal n) feels k delta A along n,
    A = contact_width x L (its share of unstretched length), plus the damping c |v_n| A while it moves into the
    plane (none while it moves out: the seabed is not sticky), grown in over the first 1e-3 footprint widths
    of depth (``damping_both_ways``: -c (v . n) A in both directions at full strength, as MoorDyn does); the
    contact stiffness k and damping c per unit area are MoorDyn's kBot and cBot (its defaults). For the
    ``galpha`` integrator's Newton solve the damping has no jump or kink: the two-way law grows in over the same
    depth, and the one-way law's switch at rest is smoothed over ``friction_speed`` (the accuracy page). Sliding on it,
    the node feels Coulomb-like friction against its sliding velocity v_s (v minus its normal part), split along
    and across the rope (the node tangent projected on the plane):

        F = -N (mu_axial v_axial + mu v_across) / sqrt(|v_s|^2 + v_reg^2),   N = k delta A,

    which is mu N at speeds well above ``friction_speed`` v_reg and a stiff linear drag below it: the
    regularisation that makes friction smooth. A line on a slope below its critical angle (tan = mu) creeps at
    about v_reg tan(slope) / mu instead of sticking; above it, it slides. The contact's spring energy is
    conservative; its damping and friction are booked as the ledger's ``seabed_work``.
    """

    height: float = spec("float", "height y of the plane at x = 0", "m")
    slope: float = spec("float", "angle of the plane, rising towards +x", "deg", default=0.0, low=-60.0, high=60.0)
    stiffness: float = spec("float", "contact stiffness per unit area kBot", "N/m^3", default=3.0e6, low=0,
                            open_low=True)
    damping: float = spec("float", "contact damping per unit area cBot", "N s/m^3", default=3.0e5, low=0)
    friction: float = spec("float", "friction coefficient mu (across the rope, and along it unless "
                                    "friction_axial is given)", default=0.0, low=0)
    friction_axial: float | None = spec("float", "friction coefficient along the rope", default=None,
                                        required=False, low=0)
    friction_speed: float = spec("float", "regularisation speed v_reg: friction is full above it", "m/s",
                                 default=0.01, low=0, open_low=True)
    contact_width: float | None = spec("float", "width of a node's footprint (default: the rope's diameter)", "m",
                                       default=None, required=False, low=0, open_low=True)
    damping_both_ways: bool = spec("bool", "damp motion out of the plane too, at full strength from first contact "
                                           "(MoorDyn's cBot, a sticky seabed; for comparisons with MoorDyn)",
                                   default=False)


@dataclass(frozen=True)
class Bending:
    """Second-neighbour springs (i, i+2) of rest length 2 l: a simple bending stiffness."""

    stiffness: float = spec("float", "spring constant k2 of the second-neighbour springs", "N/m", low=0,
                            open_low=True)


@dataclass(frozen=True)
class Gravity:
    """Uniform gravity: acceleration g along -y."""

    g: float = spec("float", "gravitational acceleration (along -y)", "m/s^2", default=9.81, low=0)


@dataclass(frozen=True)
class Drag:
    """Linear drag F = -b (v - U) on every node, U the ambient flow ([flow]; still air without one)."""

    b: float = spec("float", "drag coefficient of each node", "kg/s", low=0)


# ------------------------------------------------------------------------------------ fluid and flow


@dataclass(frozen=True)
class Fluid:
    """The fluid the rope moves in (air, water): needed by fluid drag, buoyancy and added mass."""

    density: float = spec("float", "fluid density (air 1.225, sea water 1025)", "kg/m^3", low=0, open_low=True)


@dataclass(frozen=True)
class Flow:
    """The ambient fluid velocity U (wind, current) that drag acts on, a function of height y:

    - ``profile = "uniform"``: U = ``velocity`` everywhere;
    - ``"power_law"``: U = ``velocity`` ((y - datum) / reference_height)^exponent above the datum (ground or
      seabed), 0 below it;
    - ``"table"``: U interpolated linearly between the rows of ``heights`` (y, increasing) and ``velocities``,
      held at the end rows beyond them (the rope must start inside the table).

    With ``ramp_time`` > 0 the flow grows smoothly from 0, times (1 - cos(pi t / ramp_time)) / 2, and is
    whole from t = ramp_time on.
    """

    profile: str = spec("str", "how the flow varies with height", default="uniform",
                        choices=("uniform", "power_law", "table"))
    velocity: tuple | None = spec("vector", "flow velocity (uniform), or at the reference height (power_law)",
                                  "m/s", default=None, required=False)
    reference_height: float | None = spec("float", "power_law: height above the datum where U = velocity", "m",
                                          default=None, required=False, low=0, open_low=True)
    exponent: float | None = spec("float", "power_law: the exponent (wind over open ground ~0.14, tidal current "
                                           "~1/7)", default=None, required=False, low=0)
    datum: float = spec("float", "power_law: the y of the ground or seabed", "m", default=0.0)
    heights: tuple | None = spec("float_list", "table: heights y, increasing", "m", default=None, required=False)
    velocities: tuple | None = spec("points", "table: the flow velocity at each height", "m/s", default=None,
                                    required=False)
    ramp_time: float = spec("float", "time over which the flow ramps up from zero (0: at once)", "s", default=0.0,
                            low=0)


@dataclass(frozen=True)
class FluidDrag:
    """Morison-type quadratic drag on the velocity relative to the flow, u = v - U, per node, split along the
    node's tangent q (the chord through its two neighbours; the end segment at an open line's ends):

        F = -1/2 rho Cd_n d L |u_n| u_n - 1/2 rho Cd_t pi d L |u_t| u_t,

    L the node's share of unstretched length (half of each adjacent segment), d the rope's diameter: the
    normal part on the projected area d L, the tangential part on the skin pi d L (MoorDyn's Cd and CdAx).
    """

    cd_normal: float = spec("float", "normal drag coefficient Cd_n (a cylinder across the flow: about 1.2)",
                            low=0)
    cd_tangential: float = spec("float", "tangential (skin) drag coefficient Cd_t (about 0.01 to 0.02 for a rope "
                                         "in water, up to ~0.1 measured for strings in air)", default=0.0, low=0)


@dataclass(frozen=True)
class ViscousDrag:
    """Linear drag per metre of rope, split along the node tangent: F = -b_n L u_n - b_t L u_t (u = v - U,
    L the node's share of length). For slow, viscous flow or fitted to experiments; b_n = b_t = b / l is the
    isotropic [drag] b of an inner node."""

    b_normal: float = spec("float", "normal drag per metre", "N s/m^2", low=0)
    b_tangential: float = spec("float", "tangential drag per metre", "N s/m^2", low=0)


@dataclass(frozen=True)
class Buoyancy:
    """The fluid's upward push, fluid density times displaced volume (pi d^2 / 4 per metre of unstretched rope,
    plus each body's volume) times g. Needs [fluid], [gravity] and rope.diameter; no keys."""


@dataclass(frozen=True)
class AddedMass:
    """The fluid the rope drags along when it accelerates: per node the mass matrix
    m I + rho V [Ca_n (I - q q^T) + Ca_t q q^T] (V the displaced volume, q the node tangent; MoorDyn's Ca and
    CaAx), so a = M^-1 F."""

    ca_normal: float = spec("float", "normal added-mass coefficient Ca_n (a cylinder: 1)", low=0)
    ca_tangential: float = spec("float", "tangential added-mass coefficient Ca_t (usually 0)", default=0.0, low=0)


@dataclass(frozen=True)
class Sea:
    """A free surface at the mean water level y = ``level``: water (``[fluid]``) below it, air above. Buoyancy,
    drag, added mass and the water's inertia force act on the submerged part of each node alone, its
    fraction below the instantaneous surface: a node's share of its line is two half segments, each a cylinder
    of the line's diameter cut by the surface (a floating line rests at Archimedes' draught); a point body, a
    sphere of its volume. The part in air feels drag with the air's density on its velocity relative to the
    ``wind``, and no buoyancy. A ``[flow]`` is the current in the water. ``[waves]`` move the surface; without
    them the water is still. A free rigid body is a vertical-walled body of its ``height`` about its centre of
    buoyancy, cut by the surface above its reference point; it feels the water's velocity and acceleration there.
    Not combined with a sea: ``[drag]`` and ``[viscous_drag]`` (a linear coefficient has no fluid property to
    carry from water to air)."""

    level: float = spec("float", "height y of the mean water level", "m", default=0.0)
    depth: float | None = spec("float", "water depth the waves feel (default: level - seabed.height; without a "
                                        "seabed, deep water)", "m", default=None, required=False, low=0,
                               open_low=True)
    air_density: float = spec("float", "the air's density above the surface (its drag)", "kg/m^3", default=1.225,
                              low=0)
    wind: tuple | None = spec("vector", "the wind's velocity above the surface (default: still air)", "m/s",
                              default=None, required=False)
    probes: tuple | None = spec("horizontal", "wave probes: where to record the surface's elevation every frame, "
                                          "each a horizontal position (2-D: x; 3-D: x and the other horizontal "
                                          "axis)", "m", default=None, required=False)
    fraction: str = spec("str", "a node's submerged part: cylinders (its half segments cut by the surface at "
                                "the node, exact) or moordyn (MoorDyn 2's rule, for comparing with it; a free "
                                "body then stays wholly submerged and feels no water acceleration, as MoorDyn's)",
                         default="cylinders", choices=("cylinders", "moordyn"))


WAVE_KINDS = ("regular", "jonswap", "pierson_moskowitz", "table")


@dataclass(frozen=True)
class Waves:
    """Linear (Airy) waves on the ``[sea]``, each component satisfying the finite-depth dispersion relation
    w^2 = g k tanh(k d) exactly, their kinematics stretched to the instantaneous surface (Wheeler) and ramped
    in over ``ramp_time``, plus the ``[flow]``'s current:

    - ``kind = "regular"``: an Airy wave of ``height`` H and ``period`` T;
    - ``"jonswap"`` (``significant_height`` Hs, ``peak_period`` Tp, ``gamma``) or ``"pierson_moskowitz"`` (Hs,
      Tp): the spectrum cut into ``components`` waves evenly spaced in wave number over ``frequency_range``,
      each carrying its share of the variance Hs^2 / 16, with random phases from ``seed``;
    - ``"table"``: your own components, rows of amplitude [m], angular frequency [rad/s], phase [deg] and
      direction [deg], inline as ``table`` or from ``table_file``, a CSV file whose header names those columns.

    The surface is eta = sum a cos(k (x cos beta - z sin beta) - w t + phi): ``direction`` beta turns the
    waves about the vertical from +x (MoorDyn's heading); in 2-D they travel along +x (0) or -x (180)."""

    kind: str = spec("str", "regular, jonswap, pierson_moskowitz or table", choices=WAVE_KINDS)
    height: float | None = spec("float", "regular: wave height H, crest to trough", "m", default=None,
                                required=False, low=0, open_low=True)
    period: float | None = spec("float", "regular: wave period T", "s", default=None, required=False, low=0,
                                open_low=True)
    phase: float = spec("float", "regular: phase phi, the surface eta = H/2 cos(k x - w t + phi)", "deg",
                        default=0.0)
    direction: float = spec("float", "the direction the waves travel, about the vertical from +x", "deg",
                            default=0.0, low=-360.0, high=360.0)
    significant_height: float | None = spec("float", "spectra: significant wave height Hs (4 times the surface's "
                                                     "standard deviation)", "m", default=None, required=False,
                                            low=0, open_low=True)
    peak_period: float | None = spec("float", "spectra: peak period Tp", "s", default=None, required=False, low=0,
                                     open_low=True)
    gamma: float | None = spec("float", "jonswap: peak enhancement factor (default: DNV-RP-C205's from Tp / "
                                        "sqrt(Hs))", default=None, required=False, low=1.0, high=20.0)
    components: int | None = spec("int", "spectra: how many waves the spectrum is cut into", default=None,
                                  required=False, low=1, high=5000)
    seed: int = spec("int", "spectra: seed of the random phases", default=0, low=0)
    frequency_range: tuple | None = spec("float_list", "spectra: lowest and highest angular frequency (default: "
                                                       "0.5 and 3 times the peak's)", "rad/s", default=None,
                                         required=False)
    table: tuple | None = spec("wave_rows", "table: rows of amplitude, angular frequency, phase, direction",
                               "m, rad/s, deg, deg", default=None, required=False)
    table_file: str | None = spec("str", "table: CSV file with columns amplitude, frequency, phase, direction "
                                         "(relative to the scene file's folder)", default=None, required=False)
    stretching: str = spec("str", "how the kinematics reach the moving surface: wheeler, or vertical (the mean "
                                  "level's held above it)", default="wheeler", choices=("wheeler", "vertical"))
    ramp_time: float = spec("float", "time over which the waves grow from still water (0: at once)", "s",
                            default=0.0, low=0)


@dataclass(frozen=True)
class Body:
    """A point body carried by one node (an end mass, a hook, a parachute): its mass joins the node's, and it
    adds buoyancy rho V g, quadratic drag -1/2 rho CdA |u| u on the velocity relative to the flow, and added
    mass rho Ca V (the same in every direction)."""

    node: int = spec("int", "the node carrying it; negative counts from the end (-1 is the last node)")
    mass: float = spec("float", "its mass, added to the node's", "kg", default=0.0, low=0)
    volume: float = spec("float", "its displaced volume (buoyancy, added mass)", "m^3", default=0.0, low=0)
    cd_area: float = spec("float", "its drag coefficient times area, CdA", "m^2", default=0.0, low=0)
    ca: float = spec("float", "its added-mass coefficient", default=0.0, low=0)


# ---------------------------------------------------------------------------------------- systems
#
# A system is lines joined at points and rigid bodies, as MoorDyn and OrcaFlex model moorings: every line end
# sits on a point, and a point is fixed, free (it moves under its lines' pull, its own weight, buoyancy and
# drag), driven (a prescribed motion) or fixed on a body (at a position in the body's frame). A scene is either
# one rope ([rope], the course's form) or a system ([[lines]], [[points]] and [[bodies]] with an id).


@dataclass(frozen=True)
class LineType:
    """A line material, named under ``[line_types.NAME]`` and used by ``[[lines]]`` through ``type = "NAME"``:
    the physical form of ``[rope]`` (diameter, mass per metre or density, EA, axial damping BA, EI), and the
    fluid coefficients of lines of this type where they differ from the scene's ``[fluid_drag]`` and
    ``[added_mass]`` (MoorDyn's line types carry Cd, Ca, CdAx and CaAx). ``axial_damping_ratio`` (as ``[rope]``'s)
    gives each line of this type the BA of its own segment length."""

    diameter: float | None = spec("float", "diameter d: the area drag, buoyancy and added mass act on", "m",
                                  default=None, required=False, low=0, open_low=True)
    mass_per_length: float | None = spec("float", "mass per metre", "kg/m", default=None, required=False, low=0,
                                         open_low=True)
    density: float | None = spec("float", "material density; with diameter, the mass per metre rho pi d^2 / 4",
                                 "kg/m^3", default=None, required=False, low=0, open_low=True)
    EA: float | None = spec("float", "axial stiffness EA", "N", default=None, required=False, low=0, open_low=True)
    axial_damping: float | None = spec("float", "internal damping BA: force BA (dl/dt) / l along each segment",
                                       "N s", default=None, required=False, low=0)
    axial_damping_ratio: float | None = spec("float", "internal damping as a fraction zeta of each segment's "
                                                      "critical damping (MoorDyn's negative BA): BA = zeta l "
                                                      "sqrt(EA m')", default=None, required=False, low=0)
    EI: float | None = spec("float", "bending stiffness EI: energy EI (1 - cos theta) / l at each joint",
                            "N m^2", default=None, required=False, low=0, open_low=True)
    compression: bool | None = spec("bool", "segments push back when shorter than their rest length (default "
                                            "false: a rope or chain goes slack)", default=None, required=False)
    cd_normal: float | None = spec("float", "normal drag coefficient Cd_n (default: [fluid_drag]'s)", default=None,
                                   required=False, low=0)
    cd_tangential: float | None = spec("float", "tangential drag coefficient Cd_t (default: [fluid_drag]'s)",
                                       default=None, required=False, low=0)
    ca_normal: float | None = spec("float", "normal added-mass coefficient Ca_n (default: [added_mass]'s)",
                                   default=None, required=False, low=0)
    ca_tangential: float | None = spec("float", "tangential added-mass coefficient Ca_t (default: "
                                                "[added_mass]'s)", default=None, required=False, low=0)


MATERIAL_KEYS = tuple(f for f in LineType.__dataclass_fields__)


@dataclass(frozen=True)
class Line:
    """A line of a system from point ``start`` to point ``end``: ``length`` unstretched, cut into ``segments``
    segments, of material ``type`` (a ``[line_types]`` name) or given by the material keys themselves (a key
    given here overrides the type's). Its N = segments + 1 nodes are lumped as ``[rope]``'s in physical units:
    each node carries half of each segment it touches, so the end nodes carry half a segment, which moves with
    the point they sit on."""

    id: str = spec("str", "the line's name (in outputs, and for a point's or body's lines)")
    start: str = spec("str", "the point its first node sits on")
    end: str = spec("str", "the point its last node sits on")
    length: float = spec("float", "unstretched length", "m", low=0, open_low=True)
    segments: int = spec("int", "number of segments", low=1, high=1_000_000)
    type: str | None = spec("str", "its material, a name in [line_types]", default=None, required=False)
    diameter: float | None = spec("float", "diameter d: the area drag, buoyancy and added mass act on", "m",
                                  default=None, required=False, low=0, open_low=True)
    mass_per_length: float | None = spec("float", "mass per metre", "kg/m", default=None, required=False, low=0,
                                         open_low=True)
    density: float | None = spec("float", "material density; with diameter, the mass per metre rho pi d^2 / 4",
                                 "kg/m^3", default=None, required=False, low=0, open_low=True)
    EA: float | None = spec("float", "axial stiffness EA", "N", default=None, required=False, low=0, open_low=True)
    axial_damping: float | None = spec("float", "internal damping BA: force BA (dl/dt) / l along each segment",
                                       "N s", default=None, required=False, low=0)
    axial_damping_ratio: float | None = spec("float", "internal damping as a fraction zeta of each segment's "
                                                      "critical damping (MoorDyn's negative BA): BA = zeta l "
                                                      "sqrt(EA m')", default=None, required=False, low=0)
    EI: float | None = spec("float", "bending stiffness EI: energy EI (1 - cos theta) / l at each joint",
                            "N m^2", default=None, required=False, low=0, open_low=True)
    compression: bool | None = spec("bool", "segments push back when shorter than their rest length (default "
                                            "false: a rope or chain goes slack)", default=None, required=False)
    cd_normal: float | None = spec("float", "normal drag coefficient Cd_n (default: the type's, or [fluid_drag]'s)",
                                   default=None, required=False, low=0)
    cd_tangential: float | None = spec("float", "tangential drag coefficient Cd_t (default: the type's, or "
                                                "[fluid_drag]'s)", default=None, required=False, low=0)
    ca_normal: float | None = spec("float", "normal added-mass coefficient Ca_n (default: the type's, or "
                                            "[added_mass]'s)", default=None, required=False, low=0)
    ca_tangential: float | None = spec("float", "tangential added-mass coefficient Ca_t (default: the type's, "
                                                "or [added_mass]'s)", default=None, required=False, low=0)

    @property
    def nodes(self) -> int:
        return self.segments + 1

    @property
    def segment_length(self) -> float:
        return self.length / self.segments


POINT_KINDS = ("fixed", "free", "driven", "body", "coupled")
STILL_KINDS = ("fixed", "coupled")
"""The kinds of point and body that stay where the scene puts them in a plain run: ``coupled`` ones are moved by a
program ropesim is coupled to (MoorDyn's Coupled or Vessel points and bodies); a run of the scene alone holds them
still at their initial positions, as fixed ones."""


@dataclass(frozen=True)
class Point:
    """A point of a system, where line ends meet: ``fixed`` (an anchor), ``free`` (a connector, a clump weight,
    a buoy: it moves under the pull of its lines, its weight less buoyancy, its drag -1/2 rho CdA |u| u on the
    velocity u relative to the flow, with added mass rho Ca V, MoorDyn's free point), ``driven`` (moved along a
    prescribed path: the motion keys of ``[[driven]]``, exactly at every stage), ``body`` (fixed on rigid body
    ``body`` at ``position`` in the body's frame, a fairlead) or ``coupled`` (moved by a program ropesim is coupled
    to, MoorDyn's Coupled or Vessel point; a run of the scene alone holds it where it starts, as a fixed one). Every line end on a point moves with it, and its
    node's mass (half a segment) joins the point's."""

    id: str = spec("str", "the point's name, which lines name as their start or end")
    position: tuple = spec("vector", "position (of a body's point: in the body's frame, from its reference "
                                     "point)", "m")
    kind: str | None = spec("str", "fixed, free, driven, body or coupled (default: body when a body is named, "
                                   "else fixed)", default=None, required=False, choices=POINT_KINDS)
    body: str | None = spec("str", "the rigid body it is fixed on (kind = body)", default=None, required=False)
    mass: float | None = spec("float", "free point: its own mass (a clump weight, a connector)", "kg", default=None,
                              required=False, low=0)
    volume: float | None = spec("float", "free point: its displaced volume (buoyancy, added mass)", "m^3",
                                default=None, required=False, low=0)
    cd_area: float | None = spec("float", "free point: drag coefficient times area, CdA", "m^2", default=None,
                                 required=False, low=0)
    ca: float | None = spec("float", "free point: added-mass coefficient (on its volume)", default=None,
                            required=False, low=0)
    velocity: tuple | None = spec("vector", "driven: the constant velocity V", "m/s", default=None, required=False)
    amplitude: tuple | None = spec("vector", "driven: sinusoid amplitude A per axis", "m", default=None,
                                   required=False)
    period: tuple | None = spec("vector", "driven: sinusoid period T per axis (ignored where A = 0)", "s",
                                default=None, required=False)
    phase: tuple | None = spec("vector", "driven: sinusoid phase per axis", "deg", default=None, required=False)
    path: str | None = spec("str", "driven: CSV file of t, dx, dy[, dz] rows (relative to the scene file's folder)",
                            default=None, required=False)
    path_table: tuple | None = spec("rows", "driven: the path inline, rows [t, dx, dy(, dz)]", "s, m",
                                    default=None, required=False)
    ramp_time: float | None = spec("float", "driven: time over which the sinusoid and the path ramp in (0: at once)",
                                   "s", default=None, required=False, low=0)

    @property
    def moving(self) -> bool:
        return self.amplitude is not None or self.path is not None or self.path_table is not None


BODY_KINDS = ("free", "fixed", "driven", "coupled")


@dataclass(frozen=True)
class RigidBody:
    """A rigid body of a system (a spar, a buoy, a container): 6 degrees of freedom in 3-D, 3 in 2-D (x, y and
    the angle about z). Its frame's origin is its reference point ``position`` (the point its motion and forces
    are reported at), turned by ``orientation``: rotations about x, then y, then z (3-D), or the angle about z
    (2-D). With y up, the rotation about y turns the body's heading: MoorDyn's point (x, y, z) is ropesim's
    (x, z, -y), so its roll is about ropesim's x, its pitch about -z and its yaw about y. Its mass sits at
    ``center_of_gravity`` with the inertia ``inertia`` about it in body axes; buoyancy rho V g acts at
    ``center_of_buoyancy``; drag -1/2 rho CdA_i |u| u_i on the velocity u of the reference point relative to
    the flow, in body axes (and -1/2 rho Cd_i |w| w_i on the rotation rate w); added mass and inertia on the
    body's axes at the reference point (MoorDyn's body conventions). Lines attach through points with
    ``body = this id``. ``free``: it moves under every force, by the Newton-Euler equations (the gyroscopic
    moment w x I w included); ``fixed``: it stays; ``driven``: it follows a prescribed motion, a constant
    velocity and rotation rate plus a sinusoid and a path per degree of freedom; ``coupled``: moved by a program
    ropesim is coupled to (MoorDyn's Coupled or Vessel body), held where it starts in a run of the scene alone."""

    id: str = spec("str", "the body's name, which points name to sit on it")
    position: tuple = spec("vector", "its reference point (the origin of its frame) at t = 0", "m")
    kind: str = spec("str", "free, fixed, driven or coupled (held where it starts in a run of the scene alone)",
                     default="free", choices=BODY_KINDS)
    orientation: tuple | None = spec("angles", "its orientation at t = 0: rotations about x, y, z (3-D) or about z "
                                               "(2-D)", "deg", default=None, required=False)
    mass: float = spec("float", "its mass", "kg", default=0.0, low=0)
    center_of_gravity: tuple | None = spec("vector", "its centre of gravity, in its frame", "m", default=None,
                                           required=False)
    inertia: tuple | None = spec("inertia", "its moments of inertia about the centre of gravity, in body axes: "
                                            "Ixx Iyy Izz (3-D, optionally then the tensor's off-diagonal entries "
                                            "Ixy Ixz Iyz, Ixy = -integral of x y dm) or Izz (2-D)",
                                 "kg m^2", default=None, required=False)
    volume: float = spec("float", "its displaced volume (buoyancy)", "m^3", default=0.0, low=0)
    center_of_buoyancy: tuple | None = spec("vector", "the centre of its displaced volume, in its frame", "m",
                                            default=None, required=False)
    height: float | None = spec("float", "free body under a [sea]: the height of its displaced volume, taken as "
                                         "vertical-walled and centred on the centre of buoyancy (waterplane area "
                                         "volume / height, heave stiffness rho g volume / height)", "m",
                                default=None, required=False, low=0, open_low=True)
    cd_area: tuple | None = spec("vector", "drag coefficient times area along each body axis, CdA", "m^2",
                                 default=None, required=False)
    cd_rotation: tuple | None = spec("angles", "rotational drag coefficient about each body axis: moment "
                                               "-1/2 rho Cd |w| w", "m^5", default=None, required=False)
    added_mass: tuple | None = spec("vector", "added mass along each body axis (rho V Ca_i)", "kg", default=None,
                                    required=False)
    added_inertia: tuple | None = spec("angles", "added moment of inertia about each body axis", "kg m^2",
                                       default=None, required=False)
    stiffness: tuple | None = spec("vector", "free body: a linear spring pulling its reference point back to where "
                                             "it starts, along each world axis (a hydrostatic stiffness: rho g A_wp in "
                                             "heave)", "N/m", default=None, required=False)
    damping: tuple | None = spec("vector", "free body: linear damping on its reference point's velocity along each "
                                           "world axis (radiation damping)", "N s/m", default=None, required=False)
    velocity: tuple | None = spec("vector", "driven: constant velocity of the reference point; free: its velocity "
                                            "at t = 0", "m/s", default=None, required=False)
    angular_velocity: tuple | None = spec("angles", "driven: constant rotation rate about x, y, z (world axes); free: "
                                                    "its rotation rate at t = 0", "deg/s", default=None,
                                          required=False)
    amplitude: tuple | None = spec("dofs", "driven: sinusoid amplitude per degree of freedom (translations, then "
                                           "rotations)", "m, deg", default=None, required=False)
    period: tuple | None = spec("dofs", "driven: sinusoid period per degree of freedom (ignored where the "
                                        "amplitude is 0)", "s", default=None, required=False)
    phase: tuple | None = spec("dofs", "driven: sinusoid phase per degree of freedom", "deg", default=None,
                               required=False)
    path: str | None = spec("str", "driven: CSV file of rows t, then the displacement per degree of freedom "
                                   "(m, deg)", default=None, required=False)
    path_table: tuple | None = spec("dof_rows", "driven: the path inline, rows [t, then one value per degree of "
                                                "freedom]", "s, m, deg", default=None, required=False)
    ramp_time: float | None = spec("float", "driven: time over which the sinusoid and the path ramp in (0: at once)",
                                   "s", default=None, required=False, low=0)

    @property
    def moving(self) -> bool:
        return self.amplitude is not None or self.path is not None or self.path_table is not None


@dataclass(frozen=True)
class StraightLinesStart:
    """A system's start: every line from its start point to its end point, straight, or sagging in a parabola
    below the chord when it is longer than the distance between them (over a seabed, lifted onto it); every
    point and body at rest where the scene puts it. The default."""

    shape: str = "lines"


@dataclass(frozen=True)
class SystemEquilibriumStart:
    """A system's static shape, found by ``ropesim equilibrium``'s solver before the run from the ``lines``
    start: every free node, free point and free body in static balance (weight, buoyancy, springs, bending, the
    seabed, drag in a steady flow), the fixed and driven ones where the scene holds them."""

    shape: str = "equilibrium"


SYSTEM_INITIAL_SHAPES = {"lines": StraightLinesStart, "equilibrium": SystemEquilibriumStart}


# -------------------------------------------------------------------------------- initial shapes


@dataclass(frozen=True)
class HangingStart:
    """Straight down from ``top``: node i at top - i l y."""

    top: tuple = spec("vector", "position of node 0", "m", default=None, required=False)
    velocity: tuple = spec("vector", "initial velocity of every node", "m/s", default=None, required=False)
    shape: str = "hanging"


@dataclass(frozen=True)
class LineStart:
    """Nodes evenly spaced on the straight segment from ``start`` to ``end``."""

    start: tuple = spec("vector", "position of node 0", "m")
    end: tuple = spec("vector", "position of the last node", "m")
    velocity: tuple = spec("vector", "initial velocity of every node", "m/s", default=None, required=False)
    shape: str = "line"


@dataclass(frozen=True)
class SquareLoopStart:
    """The string shooter's start: a square of side N l / 4 hanging below its top edge.

    The top edge is centred on ``top_center`` (default: the thrower's centre), so it lies on the thrower's
    centre line; nodes go along the top edge towards +x first, then down, back and up.
    """

    top_center: tuple = spec("vector", "centre of the square's top edge (default: thrower centre)", "m",
                             default=None, required=False)
    velocity: tuple = spec("vector", "initial velocity of every node", "m/s", default=None, required=False)
    shape: str = "square_loop"


@dataclass(frozen=True)
class PointsStart:
    """An explicit list of node positions, and one velocity for every node or one per node."""

    points: tuple = spec("points", "one position per node", "m")
    velocity: tuple = spec("vector", "initial velocity of every node", "m/s", default=None, required=False)
    velocities: tuple | None = spec("points", "initial velocity of each node (instead of velocity)", "m/s",
                                    default=None, required=False)
    shape: str = "points"


@dataclass(frozen=True)
class FromRunStart:
    """A saved frame of another run: relax a rope in one run, then perturb it in the next. The loader reads
    the frame (its positions and, unless ``at_rest``, its velocities) from the run folder into a ``points``
    start, so the resolved scene carries the frame itself and runs without the folder. The rope must have the
    run's number of nodes and dimension."""

    run: str = spec("str", "run folder to start from (relative to the scene file's folder)")
    time: float | None = spec("float", "time of the saved frame to start from", "s", default=None, required=False,
                              low=0)
    at_rest: bool = spec("bool", "start every node at rest instead of with the frame's velocities", default=False)
    shape: str = "from_run"


@dataclass(frozen=True)
class EquilibriumStart:
    """The static shape between ``start`` (node 0) and ``end`` (the last node), found by ``ropesim
    equilibrium``'s solver before the run: every force (weight, buoyancy, springs, bending, a seabed, drag in
    a steady flow at its full strength) balanced at every free node, the held nodes where the scene holds
    them. A rope longer than the distance between its ends starts from a sagging guess. So a dynamic run
    starts without the transient a straight or hanging start would cause."""

    start: tuple = spec("vector", "position of node 0", "m")
    end: tuple = spec("vector", "position of the last node", "m")
    velocity: tuple = spec("vector", "initial velocity of every node", "m/s", default=None, required=False)
    shape: str = "equilibrium"


INITIAL_SHAPES = {
    "hanging": HangingStart,
    "line": LineStart,
    "square_loop": SquareLoopStart,
    "points": PointsStart,
    "equilibrium": EquilibriumStart,
    "from_run": FromRunStart,
}
InitialShape = (HangingStart | LineStart | SquareLoopStart | PointsStart | EquilibriumStart | StraightLinesStart
                | SystemEquilibriumStart)


# ---------------------------------------------------------------------- nodes held or overridden


@dataclass(frozen=True)
class NodeOverride:
    """Give one node its own mass and/or drag coefficient (the helicopter's end mass and parachute)."""

    index: int = spec("int", "node index; negative counts from the end (-1 is the last node)")
    mass: float | None = spec("float", "this node's mass", "kg", default=None, required=False, low=0,
                              open_low=True)
    drag: float | None = spec("float", "this node's drag coefficient b", "kg/s", default=None, required=False,
                              low=0)


@dataclass(frozen=True)
class Pinned:
    """Nodes held fixed at their initial positions. A pinned end of a rope with bending stiffness (``rope.EI``)
    may also be ``clamped``: its end segment then keeps its initial direction, bent against a joint of
    stiffness 2 EI / l at the clamp (a cantilever's fixed end; a joint covering half a segment, as MoorDyn's
    clamped rod end)."""

    nodes: tuple = spec("int_list", "indices of the pinned nodes (negative counts from the end)")
    clamped: tuple | None = spec("int_list", "pinned end nodes (0 or -1) whose end segment keeps its direction",
                                 default=None, required=False)


@dataclass(frozen=True)
class Driven:
    """Nodes moved along a prescribed path (the helicopter's grip, a vessel's fairlead):

        x(t) = x(0) + V t + r(t) [A sin(2 pi t / T + phi) - A sin(phi) + p(t)]

    exactly, at every stage of every method: a constant ``velocity`` V, a sinusoid per axis (``amplitude`` A,
    ``period`` T, ``phase`` phi in degrees; an axis with A = 0 stays still) and a piecewise-linear ``path`` p(t)
    read from a CSV file of rows t, dx, dy[, dz] or given inline as ``path_table`` (displacements, p(0) = 0,
    times increasing and covering the run; the loader reads the file into ``path_table``, so a resolved scene
    carries its path with it), both ramped in by r(t) = 10 s^3 - 15 s^4 + 6 s^5, s = t / ``ramp_time``, until
    ``ramp_time`` (1 from then on, or always when it is 0; its rate and acceleration vanish at both ends, so
    the motion starts and settles without a jolt). The node's velocity and acceleration follow; the force its
    support exerts is reported (``support`` in each saved frame).
    """

    nodes: tuple = spec("int_list", "indices of the driven nodes (negative counts from the end)")
    velocity: tuple | None = spec("vector", "the constant velocity V", "m/s", default=None, required=False)
    amplitude: tuple | None = spec("vector", "sinusoid: amplitude A per axis", "m", default=None, required=False)
    period: tuple | None = spec("vector", "sinusoid: period T per axis (ignored where A = 0)", "s", default=None,
                                required=False)
    phase: tuple | None = spec("vector", "sinusoid: phase phi per axis", "deg", default=None, required=False)
    path: str | None = spec("str", "CSV file of t, dx, dy[, dz] rows (relative to the scene file's folder)",
                            default=None, required=False)
    path_table: tuple | None = spec("rows", "the path inline: rows [t, dx, dy(, dz)] (instead of a CSV file)",
                                    "s, m", default=None, required=False)
    ramp_time: float = spec("float", "time over which the sinusoid and the path ramp in (0: at once)", "s",
                            default=0.0, low=0)

    @property
    def moving(self) -> bool:
        """True when the motion is more than a constant velocity."""
        return self.amplitude is not None or self.path is not None or self.path_table is not None


# ----------------------------------------------------------------------------- string shooter


@dataclass(frozen=True)
class Thrower:
    """The string shooter's drive box, |x - cx| < L/2 and |y - cy| < W/2 (and |z - cz| < W/2 in 3-D).

    Inside it a node feels F_x = b_thrower (v_max - v_x) along the box, and across it a critically damped
    spring towards the centre line that also cancels gravity: F_y = m g - m omega0^2 (y - cy)
    - 2 zeta m omega0 v_y (likewise in z). omega0 defaults to 2 (2 pi v_max / L).

    ``angle`` (the launch angle alpha) turns the box and its drive about its centre in the x-y plane, positive
    upward (counter-clockwise): the drive then acts along (cos alpha, sin alpha) and the centring spring across
    it, while the weight is still cancelled along y. The guide circles are not moved: place them yourself.
    """

    center: tuple = spec("vector", "centre of the box", "m")
    length: float = spec("float", "length L_box along x", "m", low=0, open_low=True)
    width: float = spec("float", "width W_box across the box", "m", low=0, open_low=True)
    v_max: float = spec("float", "speed the drive pushes nodes towards, along +x", "m/s")
    b_thrower: float = spec("float", "drive coefficient: F_x = b_thrower (v_max - v_x)", "kg/s", low=0)
    omega0: float | None = spec("float", "natural frequency of the centring spring (default 4 pi v_max / L)",
                                "rad/s", default=None, required=False, low=0, open_low=True)
    damping_ratio: float = spec("float", "damping ratio zeta of the centring spring (1 = critical)", default=1.0,
                                low=0)
    edge_width: float = spec("float", "width w over which the box's edges switch its forces on (0 = sharp)", "m",
                             default=0.0, low=0)
    angle: float = spec("float", "launch angle: the box and its drive turned about its centre in the x-y plane, "
                                 "positive upward (0 = along +x)", "deg", default=0.0, low=-90, high=90)

    @property
    def direction(self) -> tuple[float, float]:
        """(cos alpha, sin alpha): the drive's direction in the x-y plane ((1.0, 0.0) exactly at angle 0)."""
        alpha = math.radians(self.angle)
        return math.cos(alpha), math.sin(alpha)

    @property
    def resolved_omega0(self) -> float:
        return self.omega0 if self.omega0 is not None else 2.0 * (2.0 * math.pi * abs(self.v_max) / self.length)


@dataclass(frozen=True)
class Guide:
    """A guide circle (a cylinder along z in 3-D) of radius R that the rope wraps around.

    A node inside it and outside the thrower box feels a radial spring-damper pushing it out to the rim,
    F_r = -m omega0^2 (r - R) - 2 zeta m omega0 v_r, plus m g upward. With ``one_sided`` the circle lets go of
    nodes moving outward (v_r > 0): the write-up's remedy for the rope sticking to a circle.
    """

    center: tuple = spec("vector", "centre of the circle", "m")
    radius: float = spec("float", "radius R", "m", low=0, open_low=True)
    omega0: float | None = spec("float", "natural frequency of the radial spring (default: the thrower's)",
                                "rad/s", default=None, required=False, low=0, open_low=True)
    damping_ratio: float = spec("float", "damping ratio zeta of the radial spring", default=1.0, low=0)
    one_sided: bool = spec("bool", "let go of nodes moving outward", default=False)
    edge_width: float = spec("float", "width w over which the rim switches the circle's forces on (0 = sharp)", "m",
                             default=0.0, low=0)


# --------------------------------------------------------------------------- time and output


@dataclass(frozen=True)
class Integrator:
    """Time stepping: method name, step dt and end time t_end (the run covers 0 <= t <= t_end)."""

    dt: float = spec("float", "time step", "s", low=0, open_low=True)
    t_end: float = spec("float", "end time", "s", low=0)
    method: str = spec("str", "integration method", default="symplectic_euler",
                       choices=("symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4", "sdirk2", "galpha"))
    rho_inf: float | None = spec("float", "galpha's spectral radius at infinite step: 1 keeps every mode's "
                                 "energy, 0 damps the highest out in one step (default 0.9)", default=None,
                                 required=False, low=0, high=1)
    tolerance: float | None = spec("float", "galpha's error tolerance: adaptive steps, each step's estimated error "
                                   "at most this; dt is then the grid x and v are reported on", "m", default=None,
                                   required=False, low=0, open_low=True)
    relative_tolerance: float | None = spec("float", "with tolerance: plus this fraction of the nodes' coordinates",
                                            default=None, required=False, low=0)


@dataclass(frozen=True)
class Output:
    """Which frames are saved: every ``interval`` seconds, rounded to a whole number of steps (at least one),
    and always the last step."""

    interval: float = spec("float", "time between saved frames", "s", default=0.01, low=0, open_low=True)


# --------------------------------------------------------------------------------------- scene


@dataclass(frozen=True)
class Scene:
    """One complete, validated simulation: the parts it declares, and nothing else. Either one rope (``rope``,
    with ``pinned``, ``driven``, ``overrides`` and point ``bodies`` on its nodes) or a system (``lines`` between
    ``points``, ``rigid_bodies``, ``line_types``); ``rope`` is None in a system."""

    name: str
    dimension: int
    rope: Rope | None
    initial: InitialShape
    integrator: Integrator
    output: Output = Output()
    description: str = ""
    up: str = "y"
    given_orientations: tuple = field(default=(), compare=False, repr=False)
    """A z-up scene's rigid bodies' orientations as its file gave them (the bodies hold their y-up twins'), written
    back as they were (:mod:`ropesim.scene.frame`)."""
    gravity: Gravity | None = None
    drag: Drag | None = None
    fluid: Fluid | None = None
    flow: Flow | None = None
    fluid_drag: FluidDrag | None = None
    viscous_drag: ViscousDrag | None = None
    buoyancy: Buoyancy | None = None
    added_mass: AddedMass | None = None
    seabed: Seabed | None = None
    sea: Sea | None = None
    waves: Waves | None = None
    bending: Bending | None = None
    thrower: Thrower | None = None
    guides: tuple[Guide, ...] = ()
    pinned: Pinned | None = None
    driven: tuple[Driven, ...] = ()
    overrides: tuple[NodeOverride, ...] = ()
    bodies: tuple[Body, ...] = ()
    line_types: tuple[tuple[str, LineType], ...] = ()
    lines: tuple[Line, ...] = ()
    points: tuple[Point, ...] = ()
    rigid_bodies: tuple[RigidBody, ...] = ()

    @property
    def is_system(self) -> bool:
        """True for lines joined at points and bodies; False for one rope."""
        return bool(self.lines)

    def node(self, index: int) -> int:
        """The non-negative index of ``index`` (negative counts from the end)."""
        return index % self.rope.nodes if index < 0 else index


# Top-level keys and tables, in the order a resolved scene file lists them.
TOP_LEVEL_SCALARS = {
    "name": Spec("str", "scene name (default: the file's stem); runs go to runs/<name>/; a character no installed "
                 "font draws (CJK without fonts-noto-cjk) shows as its code point in picture titles", required=False),
    "description": Spec("str", "one line saying what the scene shows", required=False),
    "dimension": Spec("int", "2 or 3 spatial dimensions", required=False, choices=(2, 3)),
    "up": Spec("str", "the axis that points up, against gravity (3-D): y (ropesim's frame, the default) or z "
               "(MoorDyn's and OrcaFlex's); every key and output is in the scene's own frame", required=False,
               choices=("y", "z")),
}
TABLES = {
    "rope": Rope,
    "initial": None,  # a tagged union: initial.shape chooses one of INITIAL_SHAPES
    "gravity": Gravity,
    "drag": Drag,
    "fluid": Fluid,
    "flow": Flow,
    "fluid_drag": FluidDrag,
    "viscous_drag": ViscousDrag,
    "buoyancy": Buoyancy,
    "added_mass": AddedMass,
    "seabed": Seabed,
    "sea": Sea,
    "waves": Waves,
    "bending": Bending,
    "thrower": Thrower,
    "pinned": Pinned,
    "integrator": Integrator,
    "output": Output,
}
ARRAYS_OF_TABLES = {"guides": Guide, "driven": Driven, "overrides": NodeOverride, "bodies": Body, "lines": Line,
                    "points": Point}
"""``[[bodies]]`` holds a rope's point bodies (an entry with ``node``, :class:`Body`) or a system's rigid bodies
(an entry with ``id``, :class:`RigidBody`, kept in ``Scene.rigid_bodies``)."""
SYSTEM_VARIANTS = {"bodies": RigidBody}
"""Arrays of tables whose entries are of another class in a system: ``[[bodies]]`` are rigid bodies there."""
NAMED_TABLES = {"line_types": LineType}
"""Tables of named tables: ``[line_types.chain]``, ``[line_types.polyester]``, ..."""
REQUIRED_TABLES = ("rope", "initial", "integrator")
SYSTEM_REQUIRED_TABLES = ("lines", "points", "integrator")
ROPE_ONLY_TABLES = ("rope", "pinned", "driven", "overrides", "thrower", "guides", "drag", "bending")
"""What a system has no use for: parts of one rope's nodes, the string shooter, and the per-node linear drag
and second-neighbour springs of the course's form (a system's lines are given in physical units)."""
SYSTEM_ONLY_TABLES = ("points", "line_types")
"""What only a system has (besides its ``[[lines]]``, which make a scene a system, and its rigid bodies)."""


def scene_to_dict(scene: Scene) -> dict:
    """The scene as a TOML-ready dict, every default filled in; undeclared parts stay absent; in the scene's own
    frame (a z-up scene's keys as its file gives them, not its y-up twin's)."""
    from dataclasses import fields

    from .frame import scene_out

    scene = scene_out(scene)

    def table(obj) -> dict:
        out = {}
        if hasattr(obj, "shape"):
            out["shape"] = obj.shape
        for f in fields(obj):
            if f.name == "shape" or "spec" not in f.metadata:   # a value the loader derived, not a key
                continue
            value = getattr(obj, f.name)
            if f.name == "omega0" and value is None:
                continue
            if value is None:
                continue
            out[f.name] = _plain(value)
        return out

    out: dict = {"name": scene.name}
    if scene.description:
        out["description"] = scene.description
    out["dimension"] = scene.dimension
    out["up"] = scene.up
    for key in TABLES:
        part = getattr(scene, key)
        if part is not None:
            out[key] = table(part)
    for key, _ in NAMED_TABLES.items():
        named = getattr(scene, key)
        if named:
            out[key] = {name: table(item) for name, item in named}
    for key in ARRAYS_OF_TABLES:
        items = getattr(scene, key) + (scene.rigid_bodies if key == "bodies" else ())
        if items:
            out[key] = [table(item) for item in items]
    return out


def scene_to_toml(scene: Scene) -> str:
    """The resolved scene as TOML text: load it again and you get the same scene."""
    import tomli_w

    header = "# Resolved by ropesim: every default filled in. Run it again with `ropesim run scene.toml`.\n"
    return header + tomli_w.dumps(scene_to_dict(scene))


def _plain(value):
    if isinstance(value, tuple):
        return [_plain(v) for v in value]
    return value
