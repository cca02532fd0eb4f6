"""The scene: a validated, frozen description of one simulation.

A scene file is TOML. Each table names one part of the model and a scene names only the parts it uses:
``[rope]`` (always), ``[initial]`` (always), ``[integrator]`` (always), and optionally ``[gravity]``,
``[drag]``, ``[bending]``, ``[thrower]``, ``[[guides]]``, ``[pinned]``, ``[[driven]]``, ``[[overrides]]``
and ``[output]``. Units are SI throughout; x is horizontal and y points up (z is the third axis in 3-D).

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

    kind: "int", "float", "bool", "str", "vector" (one number per dimension), "int_list" or "points"
    (a list of vectors). ``low``/``high`` bound numbers (``open_low`` makes the lower bound strict).
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
    """N point masses joined by springs of stiffness k and rest length l; an open line or a closed loop."""

    nodes: int = spec("int", "number of point masses N", low=2, high=1_000_000)
    segment_length: float = spec("float", "rest length l of each spring", "m", low=0, open_low=True)
    stiffness: float = spec("float", "spring constant k between neighbours", "N/m", low=0, open_low=True)
    mass: float = spec("float", "mass m of each node", "kg", low=0, open_low=True)
    closed: bool = spec("bool", "true for a closed loop (the last node joins the first)", default=False)


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
    """Linear air drag F = -b v on every node (still air)."""

    b: float = spec("float", "drag coefficient of each node", "kg/s", low=0)


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
    """An explicit list of node positions."""

    points: tuple = spec("points", "one position per node", "m")
    velocity: tuple = spec("vector", "initial velocity of every node", "m/s", default=None, required=False)
    shape: str = "points"


INITIAL_SHAPES = {
    "hanging": HangingStart,
    "line": LineStart,
    "square_loop": SquareLoopStart,
    "points": PointsStart,
}
InitialShape = HangingStart | LineStart | SquareLoopStart | PointsStart


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
    """Nodes held fixed at their initial positions."""

    nodes: tuple = spec("int_list", "indices of the pinned nodes (negative counts from the end)")


@dataclass(frozen=True)
class Driven:
    """Nodes moved at a constant velocity: x(t) = x(0) + V t exactly (the helicopter's grip)."""

    nodes: tuple = spec("int_list", "indices of the driven nodes (negative counts from the end)")
    velocity: tuple = spec("vector", "the constant velocity V", "m/s")


# ----------------------------------------------------------------------------- string shooter


@dataclass(frozen=True)
class Thrower:
    """The string shooter's drive box, |x - cx| < L/2 and |y - cy| < W/2 (and |z - cz| < W/2 in 3-D).

    Inside it a node feels F_x = b_thrower (v_max - v_x) along the box, and across it a critically damped
    spring towards the centre line that also cancels gravity: F_y = m g - m omega0^2 (y - cy)
    - 2 zeta m omega0 v_y (likewise in z). omega0 defaults to 2 (2 pi v_max / L).
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
                       choices=("symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4", "sdirk2"))


@dataclass(frozen=True)
class Output:
    """Which frames are saved: every ``interval`` seconds, rounded to a whole number of steps (at least one),
    and always the last step."""

    interval: float = spec("float", "time between saved frames", "s", default=0.01, low=0, open_low=True)


# --------------------------------------------------------------------------------------- scene


@dataclass(frozen=True)
class Scene:
    """One complete, validated simulation: the parts it declares, and nothing else."""

    name: str
    dimension: int
    rope: Rope
    initial: InitialShape
    integrator: Integrator
    output: Output = Output()
    description: str = ""
    gravity: Gravity | None = None
    drag: Drag | None = None
    bending: Bending | None = None
    thrower: Thrower | None = None
    guides: tuple[Guide, ...] = ()
    pinned: Pinned | None = None
    driven: tuple[Driven, ...] = ()
    overrides: tuple[NodeOverride, ...] = ()

    def node(self, index: int) -> int:
        """The non-negative index of ``index`` (negative counts from the end)."""
        return index % self.rope.nodes if index < 0 else index


# Top-level keys and tables, in the order a resolved scene file lists them.
TOP_LEVEL_SCALARS = {
    "name": Spec("str", "scene name (default: the file's stem); runs go to runs/<name>/", required=False),
    "description": Spec("str", "one line saying what the scene shows", required=False),
    "dimension": Spec("int", "2 or 3 spatial dimensions", required=False, choices=(2, 3)),
}
TABLES = {
    "rope": Rope,
    "initial": None,  # a tagged union: initial.shape chooses one of INITIAL_SHAPES
    "gravity": Gravity,
    "drag": Drag,
    "bending": Bending,
    "thrower": Thrower,
    "pinned": Pinned,
    "integrator": Integrator,
    "output": Output,
}
ARRAYS_OF_TABLES = {"guides": Guide, "driven": Driven, "overrides": NodeOverride}
REQUIRED_TABLES = ("rope", "initial", "integrator")


def scene_to_dict(scene: Scene) -> dict:
    """The scene as a TOML-ready dict, every default filled in; undeclared parts stay absent."""
    from dataclasses import fields

    def table(obj) -> dict:
        out = {}
        if hasattr(obj, "shape"):
            out["shape"] = obj.shape
        for f in fields(obj):
            if f.name == "shape":
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
    for key in TABLES:
        part = getattr(scene, key)
        if part is not None:
            out[key] = table(part)
    for key in ARRAYS_OF_TABLES:
        items = getattr(scene, key)
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
