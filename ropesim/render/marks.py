"""The nodes every picture marks apart from the rope, and how: one list for the matplotlib pictures
(:mod:`ropesim.render.scene_artist`) and the browser viewer (:mod:`ropesim.viewer.content`), so both show the
same things under the same names.

A mark is a set of nodes, a legend label and a kind: ``pinned`` (a black square), ``driven`` (a red triangle
pointing down), ``heavy`` (a dark disc, the end mass or a body with mass, larger as the square root of its mass
ratio), ``parachute`` (an orange canopy: extra drag without extra mass), ``point`` (a small dark disc). In a
system the points are marked by kind: fixed points as pinned nodes, driven ones as driven nodes, a free point
with mass as a heavy node, one without as a point (each at the first of its line ends, which move as one); the
points on rigid bodies are drawn with their body. No matplotlib here: it loads only with the pictures that draw.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model.build import Model
from ..scene.schema import STILL_KINDS

NODE_SIZE = 2.6          # [pt] marker of an ordinary node in the pictures
HEAVY_MIN_SCALE, HEAVY_MAX_SCALE = 1.5, 4.0   # a heavy node's marker grows as sqrt(mass ratio), within these
KIND_COLORS = {"pinned": "black", "driven": "#d62728", "heavy": "0.15", "parachute": "#ff7f0e",   # matplotlib's
               "point": "0.15"}
KIND_CSS = {"pinned": "#000000", "driven": "#d62728", "heavy": "#262626", "parachute": "#ff7f0e",     # the same
            "point": "#262626"}
KIND_SIZES = {"pinned": 6.0, "driven": 8.0, "parachute": 13.0, "point": 5.0}   # [pt]; heavy: heavy_size(scale)


@dataclass(frozen=True)
class Mark:
    """Nodes drawn apart from the rope: their legend ``label``, indices ``nodes`` and ``kind`` (see the module);
    ``scale`` is a heavy node's size relative to an ordinary node's marker times 1.2."""

    label: str
    nodes: np.ndarray
    kind: str
    scale: float = 1.0

    @property
    def color(self) -> str:
        """Its colour as matplotlib takes it."""
        return KIND_COLORS[self.kind]

    @property
    def css_color(self) -> str:
        """The same colour as a web page takes it (#rrggbb)."""
        return KIND_CSS[self.kind]

    @property
    def size(self) -> float:
        """The marker's size [pt] in the pictures."""
        return 1.2 * NODE_SIZE * self.scale if self.kind == "heavy" else KIND_SIZES[self.kind]


def heavy_scale(ratio: float) -> float:
    """A heavy node's marker scale for a mass ``ratio`` to an ordinary node."""
    return float(min(max(np.sqrt(ratio), HEAVY_MIN_SCALE), HEAVY_MAX_SCALE))


def moving_marks(model: Model) -> list[Mark]:
    """The marks that move with the rope, in drawing order: heavy nodes and parachutes (``[[overrides]]``),
    bodies, then the driven nodes; in a system its free points, then its driven points."""
    if model.scene.is_system:
        return _system_marks(model)
    scene, rope = model.scene, model.scene.rope
    out = []
    base_drag = scene.drag.b if scene.drag is not None else 0.0
    for o in scene.overrides:
        i = scene.node(o.index)
        ends = i in (0, rope.nodes - 1) and not rope.closed
        if o.mass is not None and o.mass > rope.mass:
            name = "end mass" if ends else f"node {i}"
            out.append(Mark(f"{name} {o.mass:g} kg", np.array([i]), "heavy", heavy_scale(o.mass / rope.mass)))
        if o.drag is not None and o.drag > base_drag:
            out.append(Mark(f"parachute, b = {o.drag:g} kg/s", np.array([i]), "parachute"))
    for body in scene.bodies:   # a body with mass is drawn as a heavy node, one with drag alone as a canopy
        i = scene.node(body.node)
        if body.mass > 0:
            what = "body" if rope.closed or i not in (0, rope.nodes - 1) else "end body"
            out.append(Mark(f"{what} {body.mass:g} kg" + (f", CdA {body.cd_area:g} m^2" if body.cd_area else ""),
                            np.array([i]), "heavy", heavy_scale(model.mass[i] / rope.mass)))
        elif body.cd_area > 0:
            out.append(Mark(f"drag body, CdA {body.cd_area:g} m^2", np.array([i]), "parachute"))
    driven = sorted({scene.node(i) for d in scene.driven for i in d.nodes})
    if driven:
        if any(d.moving for d in scene.driven):   # a sinusoid or a path: no one speed to quote
            out.append(Mark("driven node", np.array(driven), "driven"))
        else:
            speeds = ", ".join(f"{np.linalg.norm(d.velocity):g}" for d in scene.driven)
            out.append(Mark(f"driven node ({speeds} m/s)", np.array(driven), "driven"))
    return out


def pinned_mark(model: Model) -> Mark | None:
    """The pinned nodes, a system's fixed points (they stay where the scene starts them), or None."""
    if model.scene.is_system:
        fixed = _point_nodes(model, *STILL_KINDS)
        return Mark("fixed point", fixed, "pinned") if fixed.size else None
    pinned = model.scene.pinned
    if pinned is None:
        return None
    return Mark("pinned node", np.array([model.scene.node(i) for i in pinned.nodes]), "pinned")


def _point_nodes(model: Model, *kinds: str) -> np.ndarray:
    """The first line end's node of each of a system's points of these ``kinds`` (points without lines left
    out)."""
    from ..model.layout import point_ends

    ends = point_ends(model.scene, model.lines)
    return np.array([ends[p.id][0] for p in model.scene.points if p.kind in kinds and ends[p.id]], dtype=np.int64)


def _system_marks(model: Model) -> list[Mark]:
    """A system's free points (a heavy disc with its mass, a small disc without), then its driven points."""
    from ..model.layout import point_ends

    scene = model.scene
    ends = point_ends(scene, model.lines)
    typical = float(np.median(model.mass)) if model.nodes else 1.0
    out = []
    for p in scene.points:
        if p.kind != "free" or not ends[p.id]:
            continue
        node = np.array([ends[p.id][0]])
        if p.mass:
            out.append(Mark(f"{p.id} {p.mass:g} kg", node, "heavy", heavy_scale(model.mass[node[0]] / typical)))
        else:
            out.append(Mark(f"{p.id} (free point)", node, "point"))
    driven = _point_nodes(model, "driven")
    if driven.size:
        out.append(Mark("driven point", driven, "driven"))
    return out
