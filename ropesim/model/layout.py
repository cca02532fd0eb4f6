"""The lines of a model: which nodes each line holds and what it is made of.

A scene is one rope or a system of lines (:mod:`ropesim.scene.schema`); the model lays every line out as a run
of consecutive nodes, line after line in the scene's order, each line keeping its own end nodes (a point where
lines meet is not shared: its lines' end nodes move with it). :func:`line_layouts` gives each line's nodes and
material in SI units, the one description of lines that the force terms' parameters, the frames' tensions and
the analyses read, whatever the scene's form; a rope is one line.

Fluid coefficients are resolved per line here (a line's own, else its type's, else the scene's ``[fluid_drag]``
and ``[added_mass]``), and :func:`per_node` spreads a line property over the line's nodes (0 on a node that
is on no line).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class LineLayout:
    """One line of the model: nodes ``first`` .. ``end - 1``, its springs and its material [SI units].

    ``stiffness`` k = EA / l and ``segment_length`` l are per segment; ``slack``: segments do not push when
    shorter than l; ``axial_damping`` BA [N s] and ``EI`` [N m^2] are 0 where the line has none;
    ``diameter`` [m] is None where none is given (the course's per-node rope); the four fluid coefficients
    apply where the scene declares ``[fluid_drag]`` or ``[added_mass]``.
    """

    id: str
    first: int
    nodes: int
    closed: bool
    segment_length: float
    stiffness: float
    slack: bool
    axial_damping: float = 0.0
    EI: float = 0.0
    diameter: float | None = None
    cd_normal: float = 0.0
    cd_tangential: float = 0.0
    ca_normal: float = 0.0
    ca_tangential: float = 0.0

    @property
    def end(self) -> int:
        """One past its last node."""
        return self.first + self.nodes

    @property
    def segments(self) -> int:
        return self.nodes if self.closed else self.nodes - 1


def _fluid_coefficients(scene, own) -> dict:
    """A line's Cd_n, Cd_t, Ca_n and Ca_t: ``own``'s where given (a system's line, already resolved with its
    type), else the scene's tables'; 0 for a term the scene does not declare."""
    drag, added = scene.fluid_drag, scene.added_mass

    def pick(key, table, name):
        value = getattr(own, key, None) if own is not None else None
        if table is None:
            return 0.0
        return value if value is not None else getattr(table, name)

    return {"cd_normal": pick("cd_normal", drag, "cd_normal"), "cd_tangential": pick("cd_tangential", drag,
                                                                                       "cd_tangential"),
            "ca_normal": pick("ca_normal", added, "ca_normal"), "ca_tangential": pick("ca_tangential", added,
                                                                                       "ca_tangential")}


def line_layouts(scene) -> tuple[LineLayout, ...]:
    """Every line of ``scene`` laid out on the model's nodes: a rope is one line from node 0; a system's lines
    follow each other in the scene's order."""
    if scene.rope is not None:
        rope = scene.rope
        return (LineLayout("rope", 0, rope.nodes, rope.closed, rope.segment_length, rope.stiffness,
                           not rope.compression, rope.axial_damping or 0.0, rope.EI or 0.0, rope.diameter,
                           **_fluid_coefficients(scene, None)),)
    out, first = [], 0
    for line in scene.lines:
        l0 = line.length / line.segments
        out.append(LineLayout(line.id, first, line.segments + 1, False, l0, line.EA / l0, not line.compression,
                              line.axial_damping or 0.0, line.EI or 0.0, line.diameter,
                              **_fluid_coefficients(scene, line)))
        first += line.segments + 1
    return tuple(out)


def per_node(lines: tuple[LineLayout, ...], nodes: int, values) -> np.ndarray:
    """(N,) float: ``values[l]`` on every node of line l, 0 on nodes that are on no line."""
    out = np.zeros(nodes)
    for line, value in zip(lines, values):
        out[line.first:line.end] = value
    return out


def node_lengths(lines: tuple[LineLayout, ...], nodes: int) -> np.ndarray:
    """Each node's share of its line's unstretched length [m]: half of each segment it touches (0 off lines)."""
    length = np.zeros(nodes)
    for line in lines:
        length[line.first:line.end] = line.segment_length
        if not line.closed:
            length[[line.first, line.end - 1]] *= 0.5
    return length


def line_table(lines: tuple[LineLayout, ...]) -> np.ndarray:
    """(L, 2) int64: each line's first node and one past its last, for the compiled code."""
    return np.array([[line.first, line.end] for line in lines], dtype=np.int64).reshape(len(lines), 2)


def line_volumes(lines: tuple[LineLayout, ...], node_length: np.ndarray) -> np.ndarray:
    """Each node's share of its line's displaced volume pi d^2 / 4 L [m^3] (0 off the lines, and on a line
    without a diameter)."""
    volume = np.zeros(len(node_length))
    for line in lines:
        if line.diameter is not None:
            part = slice(line.first, line.end)
            volume[part] = math.pi * line.diameter ** 2 / 4.0 * node_length[part]
    return volume


@dataclass(frozen=True)
class Lumped:
    """A body lumped at one node: its mass joins the node's, its volume the node's displaced volume (buoyancy,
    added mass rho Ca V in every direction), its CdA the node's drag. A rope's point body (``[[bodies]]`` with
    ``node``), or a system's free point, lumped at the first line end that sits on it (the point's other line
    ends move with that node: :func:`junctions`)."""

    node: int
    mass: float
    volume: float
    cd_area: float
    ca: float


def point_ends(scene, lines: tuple[LineLayout, ...] | None = None) -> dict[str, list[int]]:
    """A system's line end nodes on each point, by point id, in line order (first the start, then the end of
    each line)."""
    lines = line_layouts(scene) if lines is None else lines
    ends: dict[str, list[int]] = {p.id: [] for p in scene.points}
    for line, layout in zip(scene.lines, lines):
        ends[line.start].append(layout.first)
        ends[line.end].append(layout.end - 1)
    return ends


def lumped_bodies(scene, lines: tuple[LineLayout, ...] | None = None) -> tuple[Lumped, ...]:
    """The bodies lumped at nodes (see :class:`Lumped`): a rope's point bodies, a system's free points."""
    if scene.rope is not None:
        return tuple(Lumped(scene.node(b.node), b.mass, b.volume, b.cd_area, b.ca) for b in scene.bodies)
    ends = point_ends(scene, lines)
    return tuple(Lumped(ends[p.id][0], p.mass, p.volume, p.cd_area, p.ca) for p in scene.points
                 if p.kind == "free" and ends[p.id])


def junctions(scene, lines: tuple[LineLayout, ...] | None = None) -> list[list[int]]:
    """A system's free points as groups of line end nodes that move together: the first (which carries the
    point, :func:`lumped_bodies`), then the others. Empty for a rope and for points with one line."""
    if scene.rope is not None:
        return []
    ends = point_ends(scene, lines)
    return [ends[p.id] for p in scene.points if p.kind == "free" and len(ends[p.id]) > 1]
