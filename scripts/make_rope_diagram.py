"""The physics page's diagram of ropesim's conventions (docs/images/rope_conventions.svg), drawn with matplotlib:
nodes 0 .. N - 1 at x_0 .. x_(N-1); segment i joins node i and node i + 1, its length r (the rest length l
when unstretched); the node tangent q_i is the unit vector along the chord from
node i - 1 to node i + 1; x horizontal, y up, z out of the page in 3-D; gravity along -y.

    python scripts/make_rope_diagram.py          # writes docs/images/rope_conventions.svg (deterministic)
"""

from __future__ import annotations

import argparse
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "images" / "rope_conventions.svg"
INK, ACCENT, GREY, TANGENT = "#222222", "#00796b", "#9e9e9e", "#e64a19"


def rope() -> np.ndarray:
    """A hanging rope's 7 nodes, (7, 2): segments 3 long, sloping from -45 to +45 degrees (a schematic sag)."""
    angles = np.radians([-45.0, -28.0, -10.0, 10.0, 28.0, 45.0])
    steps = 3.0 * np.column_stack([np.cos(angles), np.sin(angles)])
    return np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)])


def label(ax, xy, text, offset, color=INK, size=13, **kw):
    ax.annotate(text, xy, xytext=offset, textcoords="offset points", ha="center", va="center", color=color,
                fontsize=size, **kw)


def arrow(ax, start, end, color, lw=1.5, scale=14, zorder=4):
    ax.annotate("", end, start, arrowprops=dict(arrowstyle="-|>", color=color, lw=lw, shrinkA=0, shrinkB=0,
                                                mutation_scale=scale), zorder=zorder)


def draw(out: Path) -> None:
    plt.rcParams.update({"svg.fonttype": "path", "svg.hashsalt": "ropesim", "mathtext.fontset": "dejavusans"})
    nodes = rope()
    i = 4                                          # the node the labels are about
    prev, node, nxt = nodes[i - 1], nodes[i], nodes[i + 1]
    fig, ax = plt.subplots(figsize=(9.0, 4.2))
    ax.set_aspect("equal")
    ax.axis("off")

    ax.plot(nodes[:, 0], nodes[:, 1], color=GREY, lw=2, zorder=1)
    for j in (i - 1, i):                           # segment i - 1 and segment i in colour
        ax.plot(nodes[j:j + 2, 0], nodes[j:j + 2, 1], color=ACCENT, lw=3.5, zorder=2)
    ax.scatter(nodes[:, 0], nodes[:, 1], s=50, color=INK, zorder=3)
    label(ax, nodes[0], r"node $0$", (0, 14), size=11)
    label(ax, nodes[-1], r"node $N-1$", (0, 14), size=11)

    # the three nodes around node i, and the two segments between them (their names above the rope)
    label(ax, prev, r"node $i-1$", (0, -18), size=12)
    label(ax, node, "node $i$\nat $\\mathbf{x}_i$", (-8, -30), size=12)
    label(ax, nxt, r"node $i+1$", (46, -4), size=12)
    for a, b, text in ((prev, node, r"segment $i-1$"), (node, nxt, r"segment $i$")):
        mid, d = (a + b) / 2, (b - a) / np.linalg.norm(b - a)
        normal = np.array([-d[1], d[0]])           # above the rope
        ax.annotate(text, mid, xytext=tuple(15 * normal), textcoords="offset points", ha="center",
                    va="center", color=ACCENT, fontsize=12, rotation=np.degrees(np.arctan2(d[1], d[0])),
                    rotation_mode="anchor")

    # the rest length l of segment i, as a dimension line below it
    d = (nxt - node) / np.linalg.norm(nxt - node)
    below = np.array([d[1], -d[0]])
    a, b = node + 1.0 * below, nxt + 1.0 * below
    ax.annotate("", b, a, arrowprops=dict(arrowstyle="<->", color=INK, lw=1, shrinkA=0, shrinkB=0))
    for p, q in ((node, a), (nxt, b)):
        ax.plot(*np.column_stack([p + 0.25 * below, q + 0.15 * below]), color=INK, lw=0.6)
    ax.annotate(r"length $r$ ($l$ at rest)", (a + b) / 2, xytext=tuple(12 * below), textcoords="offset points",
                ha="left", va="top", fontsize=12, color=INK, rotation=np.degrees(np.arctan2(d[1], d[0])),
                rotation_mode="anchor")

    # the node tangent: along the chord from node i - 1 to node i + 1, drawn at node i
    ax.plot(*np.column_stack([prev, nxt]), color=TANGENT, lw=1, ls=(0, (4, 3)), zorder=1)
    q = (nxt - prev) / np.linalg.norm(nxt - prev)
    arrow(ax, node, node + 2.0 * q, TANGENT, lw=2.2, scale=18)
    label(ax, node + 2.0 * q, r"$\mathbf{q}_i$", (14, -10), color=TANGENT, size=15)
    ax.annotate(r"$\mathbf{q}_i = \dfrac{\mathbf{x}_{i+1} - \mathbf{x}_{i-1}}{|\mathbf{x}_{i+1} - \mathbf{x}_{i-1}|}$",
                (2.6, 2.5), ha="left", va="center", color=TANGENT, fontsize=13)
    ax.annotate("the node tangent: along the chord\nthrough node $i$'s two neighbours (dashed)",
                (2.6, 1.2), ha="left", va="center", color=TANGENT, fontsize=11, linespacing=1.4)

    # the axes: x horizontal, y up, z out of the page (3-D), and gravity along -y
    origin = np.array([-1.8, -4.6])
    arrow(ax, origin, origin + (1.6, 0.0), INK)
    arrow(ax, origin, origin + (0.0, 1.6), INK)
    label(ax, origin + (1.6, 0.0), r"$x$", (10, 0))
    label(ax, origin + (0.0, 1.6), r"$y$", (0, 10))
    ax.scatter(*origin, s=120, facecolor="white", edgecolor=INK, lw=1.5, zorder=5)
    ax.scatter(*origin, s=10, color=INK, zorder=6)
    ax.annotate(r"$z$: out of the page (3-D)", origin, xytext=(-8, -18), textcoords="offset points", ha="left",
                va="center", fontsize=10, color=INK)
    arrow(ax, (4.2, -3.6), (4.2, -5.0), GREY)
    label(ax, (4.2, -4.3), r"$g$", (10, 0), color=GREY, size=12)

    ax.set_xlim(-2.6, 16.4)
    ax.set_ylim(-5.8, 3.4)
    fig.tight_layout(pad=0.2)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, format="svg", metadata={"Date": None, "Creator": "scripts/make_rope_diagram.py"})
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    draw(args.out)
    print(f"{args.out}: {args.out.stat().st_size / 1e3:.0f} kB")


if __name__ == "__main__":
    main()
