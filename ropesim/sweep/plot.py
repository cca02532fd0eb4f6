"""``ropesim sweep --plot FIGURE``: one summary figure against a swept parameter, drawn from the table.

The x axis is the first swept key with numeric values; every combination of the other swept keys is one
line. Runs that did not complete, or lack the figure, leave a gap. Drawn from the rows only: never re-runs.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..io.atomic import atomic_output
from .plan import Axis, SweepError, _is_number, _label, _numeric_axis, toml_value


def plot_figure(rows: list[dict], axes: list[Axis], figure: str, folder: Path, title: str = "") -> Path:
    """Write ``<figure>_vs_<key>.png`` into ``folder`` and return its path; raises :class:`SweepError`."""
    swept = [a for a in axes if a.swept]
    x_axis = next(a for a in swept if _numeric_axis(a))
    others = [a for a in swept if a is not x_axis]
    numeric = sorted({k for r in rows for k, v in r.items() if _is_number(v) and k not in {a.key for a in swept}})
    if figure not in numeric:
        raise SweepError(f"--plot {figure}: not a numeric column of {folder / 'results.csv'}; "
                         f"allowed: {', '.join(numeric) or '(no run completed)'}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5), layout="constrained")
    groups: dict[str, list[dict]] = {}
    for row in rows:
        label = ", ".join(f"{a.key} = {_shown(row[a.key])}" for a in others)
        groups.setdefault(label, []).append(row)
    for label, members in groups.items():
        points = sorted((r[x_axis.key], r[figure]) for r in members
                        if r["status"] == "completed" and _is_number(r.get(figure)))
        ax.plot([p[0] for p in points], [p[1] for p in points], marker="o", markersize=4, label=label or None)
    failed = sum(r["status"] != "completed" for r in rows)
    ax.set_xlabel(x_axis.key)
    ax.set_ylabel(figure)
    ax.set_title(f"{title}: {figure} against {x_axis.key}" + (f" ({failed} runs failed)" if failed else ""),
                 fontsize=10)
    ax.grid(True, alpha=0.3)
    if others:
        ax.legend(fontsize=8)
    path = folder / re.sub(r"[^A-Za-z0-9._=+-]", "-", f"{figure}_vs_{x_axis.key}.png")
    try:
        with atomic_output(path) as tmp:
            fig.savefig(tmp, format="png", dpi=120)
    finally:
        plt.close(fig)
    return path


def _shown(value) -> str:
    return toml_value(value) if isinstance(value, (list, tuple)) else _label(value, False)
