"""What a sweep prints while it runs: one line per finished run on stderr, and a rich progress bar on a terminal."""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

from rich.console import Console
from rich.markup import escape
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn


PLANNING_SHOWN = 500   # combinations from which resolving them shows a bar (10^4 take about ten seconds)


@contextmanager
def planning(total: int, quiet: bool = False):
    """While a sweep resolves its combinations: a transient bar on a terminal for large sweeps; yields the
    ``on_point(i, n)`` callback for :func:`ropesim.sweep.plan.plan`."""
    console = Console(stderr=True, highlight=False)
    if quiet or total < PLANNING_SHOWN or not console.is_terminal:
        yield None
        return
    progress = Progress(TextColumn("[bold]planning"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                        console=console, transient=True)
    task = progress.add_task("planning", total=total)
    with progress:
        yield lambda i, n: progress.update(task, completed=i) if i % 100 == 0 or i == n else None


class SweepProgress:
    """Context manager: ``skipped(n, root)`` once, then ``finished(point, summary, error)`` per run."""

    def __init__(self, total: int, quiet: bool = False):
        self.total, self.quiet, self.count = total, quiet, 0
        self.console = Console(stderr=True, highlight=False)
        self.progress = Progress(TextColumn("[bold]sweep"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
                                 console=self.console, transient=True,
                                 disable=quiet or not self.console.is_terminal)
        self.task = self.progress.add_task("sweep", total=total)

    def __enter__(self) -> "SweepProgress":
        self.progress.start()
        return self

    def __exit__(self, *exc) -> None:
        self.progress.stop()

    def _print(self, text: str) -> None:
        if not self.quiet:
            self.console.print(text, soft_wrap=True)

    def skipped(self, n: int, root: Path) -> None:
        self.count += n
        self.progress.update(self.task, completed=self.count)
        if n:
            self._print(f"{n} of {self.total} runs already finished in {escape(str(root))}/: kept")

    def finished(self, point, summary: dict | None, error: str) -> None:
        self.count += 1
        self.progress.update(self.task, completed=self.count)
        if summary is None:
            what = f"[red]error[/]: {escape(error)}"
        elif summary["status"] != "completed":
            what = f"[red]{summary['status']}[/]: {escape(summary.get('message', ''))}"
        else:
            what = f"completed in {summary['wall_time_s']:.3g} s"
        self._print(f"{escape(f'[{self.count}/{self.total}]')} {escape(point.name)}: {what}")
