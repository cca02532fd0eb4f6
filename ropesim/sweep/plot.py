"""``ropesim sweep --plot FIGURE``: one summary figure against a swept parameter, drawn from the table.

The x axis is the first swept key with numeric values, labelled with its meaning and unit from the scene
schema; the y axis is the figure, with its unit (summary figures name it in their last word: ``_deg``,
``_J``, ``_m_s``, ...). Every combination of the other swept keys is one line, and the legend naming them
sits beside the axes. Runs that did not complete, or lack the figure, leave a gap. Drawn from the rows only:
never re-runs.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..io.guard import output_file
from ..render.output import save_png
from ..render.style import OUTSIDE_RIGHT, title_text, with_picture_text
from .plan import Axis, SweepError, _is_number, _label, _numeric_axis, key_spec, toml_value

# Summary figures whose name does not end in their unit.
SUMMARY_UNITS = {
    "t_end": "s", "t_end_requested": "s", "dt": "s", "dt_requested": "s", "stable_dt_bound": "s",
    "max_spring_stretch_t": "s", "steps_per_second": "1/s", "node_steps_per_second": "1/s",
    "max_spring_stretch": "fraction of l", "steps": "count", "frames": "count", "nodes": "count",
    "force_evaluations": "count", "nodes_in_thrower": "count", "relative_residual": "fraction",
    "residual_growth": "ratio",
}
SUFFIX_UNITS = (("_m_s", "m/s"), ("_deg", "deg"), ("_J", "J"), ("_kg", "kg"), ("_s", "s"), ("_m", "m"))


def summary_unit(column: str) -> str:
    """The unit of a results.csv summary column (e.g. "deg" for shooter.mean_loop_inclination_deg), or ""."""
    parts = column.split(".")
    if parts[-1] in SUMMARY_UNITS:
        return SUMMARY_UNITS[parts[-1]]
    for part in reversed(parts):   # final_energy_J.kinetic: the unit is in the group's name
        for suffix, unit in SUFFIX_UNITS:
            if part.endswith(suffix):
                return unit
    return ""


def key_label(key: str) -> str:
    """An axis label for a swept scene key: its meaning and unit from the schema, and the key itself."""
    spec = key_spec(key)
    if spec is None:
        return key
    return f"{spec.doc}, {key}" + (f" [{spec.unit}]" if spec.unit else "")


def figure_label(column: str) -> str:
    """An axis label for a results.csv column: a scene key's (see :func:`key_label`) or a summary figure's."""
    if key_spec(column) is not None:
        return key_label(column)
    unit = summary_unit(column)
    return f"{column} [{unit}]" if unit else column


def sweep_figure(rows: list[dict], axes: list[Axis], figure: str, title: str = ""):
    """The figure of :func:`plot_figure` (a matplotlib Figure); raises :class:`SweepError` for an unknown column."""
    from matplotlib.figure import Figure

    swept = [a for a in axes if a.swept]
    x_axis = next(a for a in swept if _numeric_axis(a))
    others = [a for a in swept if a is not x_axis]
    fig = Figure(figsize=(8, 4.5), layout="constrained")
    ax = fig.subplots()
    groups: dict[str, list[dict]] = {}
    for row in rows:
        label = ", ".join(f"{a.key} = {_shown(row[a.key])}" for a in others)
        groups.setdefault(label, []).append(row)
    for label, members in groups.items():
        points = sorted((r[x_axis.key], r[figure]) for r in members
                        if r["status"] == "completed" and _is_number(r.get(figure)))
        ax.plot([p[0] for p in points], [p[1] for p in points], marker="o", markersize=4, label=label or None)
    failed = sum(r["status"] != "completed" for r in rows)
    ax.set_xlabel(key_label(x_axis.key))
    ax.set_ylabel(figure_label(figure))
    ax.set_title(title_text(f"{title}: {figure} against {x_axis.key}" + (f" ({failed} runs failed)" if failed else "")),
                 fontsize=10)
    ax.grid(True, alpha=0.3)
    if others:
        ax.legend(fontsize=8, **OUTSIDE_RIGHT)
    return fig


@with_picture_text
def plot_figure(rows: list[dict], axes: list[Axis], figure: str, folder: Path, title: str = "") -> Path:
    """Write ``<figure>_vs_<key>.png`` into ``folder`` and return its path; raises :class:`SweepError`."""
    swept = [a for a in axes if a.swept]
    x_axis = next(a for a in swept if _numeric_axis(a))
    check_figure(rows, axes, figure, folder)
    fig = sweep_figure(rows, axes, figure, title)
    path = folder / re.sub(r"[^A-Za-z0-9._=+-]", "-", f"{figure}_vs_{x_axis.key}.png")
    save_png(fig, output_file(path, option="--plot"), 120)
    return path


def check_figure(rows: list[dict], axes: list[Axis], figure: str, folder: Path) -> None:
    """Refuse (:class:`SweepError`) a ``figure`` that is not a numeric summary column of ``rows``."""
    swept = {a.key for a in axes if a.swept}
    numeric = sorted({k for r in rows for k, v in r.items() if _is_number(v) and k not in swept})
    if figure not in numeric:
        raise SweepError(f"--plot {figure}: not a numeric column of {folder / 'results.csv'}; "
                         f"allowed: {', '.join(numeric) or '(no run completed)'}")


def _shown(value) -> str:
    return toml_value(value) if isinstance(value, (list, tuple)) else _label(value, False)
