"""What the command line prints stays readable in a narrow terminal and when piped: figures are never cut."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from ropesim.cli.report import print_accuracy, print_stability

METHODS = ("symplectic_euler", "verlet", "sdirk2")


def accuracy_report():
    rows = [SimpleNamespace(method=m, dt=dt, status="completed", error_max=1.923456e-3 * dt / (k + 1),
                            at_floor=dt < 0.0002, error_rms=-7.1e-11 * dt, energy_error=-2.471e-3 * (k + 1),
                            wall_time=1.43e-5 * (k + 1), force_evaluations=int(1.2e6 * (k + 1) * 1e-3 / dt))
            for k, m in enumerate(METHODS) for dt in (0.004, 0.001, 0.000125)]
    rows[1].status = "blew_up"
    return SimpleNamespace(rows=rows, reference=SimpleNamespace(method="pefrl", dt=3.9e-6, difference=3.66e-12),
                           scene=SimpleNamespace(name="helicopter_uniform"), t_end=0.3,
                           orders={m: (2.0, 3) for m in METHODS})


def figures(report) -> list[str]:
    """Every figure of the accuracy table, as printed."""
    out = []
    for r in report.rows:
        out += [f"{r.dt:.4g}", f"{r.error_rms:.3e}", f"{r.energy_error:.3e}", f"{r.wall_time:.3g}",
                f"{r.force_evaluations:,}"]
        if r.status == "completed":
            out.append(f"{r.error_max:.3e}" + ("*" if r.at_floor else ""))
    return out


@pytest.mark.parametrize("columns", [200, 80, 60, 40])
def test_the_accuracy_table_never_cuts_a_figure(columns, monkeypatch, capsys):
    monkeypatch.setenv("COLUMNS", str(columns))
    report = accuracy_report()
    print_accuracy(report, Path("runs/acc"))
    out = capsys.readouterr().out
    assert "…" not in out and "[s]" in out and "[m]" in out   # units are text, not rich markup ([s] strikes)
    assert max(map(len, out.splitlines())) <= columns
    words = out.split()
    for figure in figures(report):
        assert figure in words, (figure, columns)
    for method in METHODS:
        assert method in words
    assert ("(1 of" in " ".join(words)) == (columns < 80)   # 80 columns hold the whole table; fewer, it comes in parts


def test_the_stability_table_never_cuts_a_figure(monkeypatch, capsys):
    bounds = [{"stiffness": k, "method": m, "predicted_dt_spectral": 0.0123456 / k ** 0.5,
               "predicted_dt_gershgorin": 0.00987654 / k ** 0.5, "measured_blowup_dt": 0.0125 / k ** 0.5}
              for k in (5000.0, 50000.0) for m in ("symplectic_euler", "verlet", "rk4")]
    monkeypatch.setenv("COLUMNS", "80")
    print_stability(SimpleNamespace(bounds=bounds, rows=[]), Path("runs/st"))
    out = capsys.readouterr().out
    assert "…" not in out and max(map(len, out.splitlines())) <= 80
    for b in bounds:
        assert f"{b['predicted_dt_gershgorin']:.4g}" in out.split()
        assert f"{b['predicted_dt_spectral'] / b['measured_blowup_dt']:.3f}" in out.split()
