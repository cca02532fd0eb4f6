"""Every picture's legends and text: a legend never covers data (it lies outside every plotting area and inside
the picture), every axis says its unit, and no warning reaches the user (a CJK scene name, a plot with nothing
to label)."""

from __future__ import annotations

import logging
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from matplotlib.figure import Figure

import ropesim
from ropesim.analysis.accuracy import work_precision_figure
from ropesim.analysis.stability import SweepResult, stability_figure
from ropesim.model.build import build
from ropesim.render.animate import FrameRenderer, animate
from ropesim.render.frames import frame_sheet
from ropesim.render.framing import projection
from ropesim.render import style
from ropesim.render.plots import plot_run, run_figure
from ropesim.sweep.plan import Axis
from ropesim.sweep.plot import figure_label, key_label, sweep_figure

from conftest import SCENARIOS

METHODS = ("symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4", "sdirk2")


def legends(fig: Figure) -> list:
    return list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]


def assert_legends_clear_of_data(fig: Figure) -> None:
    """Each legend lies inside the picture and outside every plotting area, so it covers no data point,
    line or label of any axes; the data's own points are checked too."""
    if fig.canvas is None or not hasattr(fig.canvas, "get_renderer"):
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig)
    fig.canvas.draw()
    found = legends(fig)
    assert found, "the picture has no legend to check"
    renderer = fig.canvas.get_renderer()
    for legend in found:
        box = legend.get_window_extent(renderer)
        # the legend and every handle's marker (which may be larger than its box) lie inside the picture
        for part in [box] + [h.get_window_extent(renderer) for h in legend.legend_handles]:
            assert part.x0 >= -0.5 and part.y0 >= -0.5 and part.x1 <= fig.bbox.x1 + 0.5 \
                and part.y1 <= fig.bbox.y1 + 0.5, (part, fig.bbox)
        for ax in fig.axes:
            if not ax.get_visible():
                continue
            area = ax.get_window_extent(renderer)
            assert not box.overlaps(area), (legend.get_texts()[0].get_text(), box, area)
            for line in ax.get_lines():
                xy = line.get_transform().transform(np.column_stack(line.get_data()).astype(float))
                xy = xy[np.isfinite(xy).all(axis=1)]
                inside = ((xy[:, 0] > box.x0) & (xy[:, 0] < box.x1) & (xy[:, 1] > box.y0) & (xy[:, 1] < box.y1))
                assert not inside.any(), line.get_label()


def accuracy_report(completed: bool = True):
    rows = [SimpleNamespace(method=m, dt=dt, status="completed" if completed else "blew_up",
                            error_max=(k + 1) * 1e-3 * (dt / 0.004) ** 2, at_floor=False, error_rms=1e-4,
                            energy_error=1e-3, wall_time=1e-5 * (k + 1) * 0.004 / dt,
                            force_evaluations=int(4 / dt)) for k, m in enumerate(METHODS)
            for dt in (0.004, 0.002, 0.001, 0.0005)]
    return SimpleNamespace(rows=rows, reference=SimpleNamespace(method="pefrl", dt=4e-6, difference=1e-12),
                           scene=SimpleNamespace(name="helicopter_uniform"), t_end=0.3,
                           orders={m: (2.0, 4) for m in METHODS})


def stability_result() -> SweepResult:
    fractions = np.round(np.arange(0.1, 2.01, 0.1), 2)
    rows = [{"stiffness": 5000.0, "method": m, "dt_over_ref": f, "stable": m == "sdirk2" or f < 1.0}
            for m in METHODS for f in fractions]
    bounds = [{"stiffness": 5000.0, "method": m, "ref_dt": 0.01,
               "predicted_dt_spectral": np.inf if m == "sdirk2" else 0.00995,
               "predicted_dt_gershgorin": np.inf if m == "sdirk2" else 0.0099,
               "measured_blowup_dt": np.inf if m == "sdirk2" else 0.01} for m in METHODS]
    return SweepResult(rows=rows, bounds=bounds)


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, ropesim.Trajectory]:
    base = tmp_path_factory.mktemp("legend-runs")
    out = {}
    for name in ("shooter_low", "helicopter_mass", "helicopter_parachute"):
        scene = ropesim.load_scene(SCENARIOS / f"{name}.toml", ["integrator.t_end=0.2"])
        ropesim.simulate(scene, base / name)
        out[name] = ropesim.Trajectory.open(base / name)
    return out


def test_the_accuracy_legend_is_below_the_panels():
    assert_legends_clear_of_data(work_precision_figure(accuracy_report()))


def test_the_stability_legend_is_above_the_rows():
    fig = stability_figure(stability_result())
    assert_legends_clear_of_data(fig)
    assert "[rad/s]" in fig.axes[0].get_xlabel()


@pytest.mark.parametrize("name", ["shooter_low", "helicopter_parachute"])
def test_run_plot_legends_are_beside_their_panels(runs, name):
    fig, panels = run_figure(runs[name])
    assert "ledger" in panels
    assert_legends_clear_of_data(fig)
    for ax in fig.axes:
        assert "[" in ax.get_ylabel() and "[" in ax.get_xlabel(), (ax.get_title(), ax.get_xlabel())


@pytest.mark.parametrize("name", ["helicopter_mass", "helicopter_parachute"])
def test_the_animation_legend_is_whole_and_above_the_view(runs, name):
    traj = runs[name]
    model = build(traj.scene)
    renderer = FrameRenderer(traj, model, projection(None, 2), None, 320)
    renderer.render(traj.frames - 1)
    assert_legends_clear_of_data(renderer.canvas.figure)


def _saved_figures(monkeypatch) -> list[Figure]:
    saved = []
    original = Figure.savefig

    def savefig(self, *args, **kwargs):
        saved.append(self)
        return original(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", savefig)
    return saved


def test_frame_sheet_legends_are_outside_the_views(runs, tmp_path, monkeypatch):
    saved = _saved_figures(monkeypatch)
    frame_sheet(runs["shooter_low"], tmp_path / "over.png", count=5, overlay=True)
    frame_sheet(runs["helicopter_mass"], tmp_path / "sheet.png")
    assert len(saved) == 2
    for fig in saved:
        assert_legends_clear_of_data(fig)


def test_the_sweep_plot_has_units_from_the_schema_and_its_legend_beside_it():
    rows = [{"drag.b": b, "rope.nodes": n, "status": "completed", "shooter.mean_loop_inclination_deg": b * n}
            for b in (0.1, 0.4, 0.7, 1.0) for n in (40, 60, 80)]
    fig = sweep_figure(rows, [Axis("drag.b", (0.1, 0.4, 0.7, 1.0)), Axis("rope.nodes", (40, 60, 80))],
                       "shooter.mean_loop_inclination_deg", "shooter_low")
    ax = fig.axes[0]
    assert ax.get_xlabel() == "drag coefficient of each node, drag.b [kg/s]"
    assert ax.get_ylabel() == "shooter.mean_loop_inclination_deg [deg]"
    assert_legends_clear_of_data(fig)
    assert figure_label("final_energy_J.kinetic") == "final_energy_J.kinetic [J]"
    assert figure_label("shooter.circulation_speed_m_s") == "shooter.circulation_speed_m_s [m/s]"
    assert figure_label("max_spring_stretch_t") == "max_spring_stretch_t [s]"
    assert figure_label("integrator.dt") == "time step, integrator.dt [s]"
    assert key_label("rope.nodes") == "number of point masses N, rope.nodes"


def _no_warnings(make, caplog, capfd):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with caplog.at_level(logging.DEBUG, logger="matplotlib"):
            make()
    assert not [r for r in caplog.records if r.levelno >= logging.WARNING], caplog.records
    err = capfd.readouterr().err
    assert err == "", err


def _cjk_run(tmp_path):
    text = (SCENARIOS / "helicopter_parachute.toml").read_text().replace(
        'name = "helicopter_parachute"', 'name = "直升机绳子"')
    (tmp_path / "s.toml").write_text(text)
    scene = ropesim.load_scene(tmp_path / "s.toml", ["integrator.t_end=0.05"])
    assert scene.name == "直升机绳子"
    return ropesim.simulate(scene, tmp_path / "run")


def test_a_cjk_scene_name_draws_without_a_warning_where_a_font_has_it(tmp_path, caplog, capfd, monkeypatch):
    """With a font that covers the name (as on a machine with fonts-noto-cjk), titles keep it as written."""
    covered = style._drawn_by_installed_fonts() | frozenset(map(ord, "直升机绳子"))
    monkeypatch.setattr(style, "_drawn_by_installed_fonts", lambda: covered)
    monkeypatch.setattr(style, "_noted", set())
    traj = _cjk_run(tmp_path)
    _no_warnings(lambda: plot_run(traj, tmp_path / "p.png"), caplog, capfd)
    _no_warnings(lambda: frame_sheet(traj, tmp_path / "f.png"), caplog, capfd)
    _no_warnings(lambda: animate(traj, tmp_path / "a.gif", size=160), caplog, capfd)
    assert all((tmp_path / f).stat().st_size > 1000 for f in ("p.png", "f.png", "a.gif"))
    fig, _ = run_figure(traj)
    assert fig.get_suptitle().startswith("直升机绳子")


def test_a_cjk_scene_name_no_font_draws_shows_code_points_and_one_note(tmp_path, caplog, capfd, monkeypatch):
    """Without such a font, titles show the characters' code points (never empty boxes) and one note line names
    the font package to install, once for all the pictures; no warning."""
    covered = frozenset(c for c in style._drawn_by_installed_fonts() if not 0x2E80 <= c <= 0x9FFF)   # no CJK
    monkeypatch.setattr(style, "_drawn_by_installed_fonts", lambda: covered)
    monkeypatch.setattr(style, "_noted", set())
    traj = _cjk_run(tmp_path)
    capfd.readouterr()
    with caplog.at_level(logging.WARNING), warnings.catch_warnings():
        warnings.simplefilter("error")
        plot_run(traj, tmp_path / "p.png")
        frame_sheet(traj, tmp_path / "f.png")
        animate(traj, tmp_path / "a.gif", size=160)
    out, err = capfd.readouterr()
    assert not caplog.records and out == ""
    assert err.count("\n") == 1 and err.startswith("note: no installed font draws 直升机绳子") and "fonts-noto-cjk" in err
    fig, _ = run_figure(traj)
    assert fig.get_suptitle().startswith("U+76F4 U+5347 U+673A U+7EF3 U+5B50")
    assert style.title_text("rope 直升机 2") == "rope U+76F4 U+5347 U+673A 2"
    assert style.title_text("Übung δ") == "Übung δ"   # DejaVu Sans draws these
    assert capfd.readouterr().err == ""               # its characters were noted already


def test_an_accuracy_plot_with_no_completed_run_has_no_legend_and_no_warning(tmp_path, caplog, capfd):
    from ropesim.analysis.accuracy import plot

    _no_warnings(lambda: plot(accuracy_report(completed=False), tmp_path / "a.png"), caplog, capfd)
    assert legends(work_precision_figure(accuracy_report(completed=False))) == []
