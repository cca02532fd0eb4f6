"""The command line. Each command parses its options and calls one function elsewhere.

Bad input (a scene file, a --set, a run folder) prints one line naming the file, the key and what is
allowed, and exits with code 2; a run that blows up exits 3; an interrupted run exits 130. Both keep what
they computed.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Optional

import typer

app = typer.Typer(
    name="ropesim",
    help="Simulate ropes: point masses joined by stiff springs, under gravity and air drag.\n\n"
         "Scenes are TOML files (see scenarios/ and the README). Start with:\n\n"
         "  ropesim run scenarios/helicopter_mass.toml",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)

EXIT_BAD_INPUT, EXIT_BLEW_UP, EXIT_INTERRUPTED = 2, 3, 130

SceneArg = Annotated[Path, typer.Argument(help="Scene file (TOML), e.g. scenarios/helicopter_mass.toml.",
                                          show_default=False)]
SetOpt = Annotated[Optional[list[str]], typer.Option(
    "--set", "-s", metavar="KEY=VALUE",
    help="Override a scene key by its dotted TOML path, typed and validated like the file; repeatable. "
         "E.g. --set integrator.dt=0.002 --set rope.nodes=61 --set overrides.0.mass=50.")]


def fail(message: str, code: int = EXIT_BAD_INPUT) -> None:
    """Print one line to stderr and exit with ``code``."""
    typer.echo(f"ropesim: {message}", err=True)
    raise typer.Exit(code)


def _load(scene_file: Path, sets: list[str] | None):
    from .loader import SceneError, load_scene

    try:
        return load_scene(scene_file, sets or [])
    except SceneError as exc:
        fail(str(exc))


@app.command()
def run(
    scene_file: SceneArg,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="Run folder (default runs/<scene name>/).",
                                                show_default=False)] = None,
    sets: SetOpt = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
) -> None:
    """Run a scene and write trajectory.npz, scene.toml and summary.json into its run folder."""
    from .report import print_summary
    from .run import BLEW_UP, INTERRUPTED, simulate

    scene = _load(scene_file, sets)
    folder = out if out is not None else Path("runs") / scene.name
    if folder.exists() and not folder.is_dir():
        fail(f"--out {folder}: exists and is not a folder")
    try:
        traj = simulate(scene, folder, progress=not quiet and sys.stderr.isatty())
    except OSError as exc:
        fail(f"{folder}: cannot write the run folder ({exc.strerror or exc})")
    summary = traj.summary
    if not quiet:
        print_summary(summary, folder)
    if summary["status"] == BLEW_UP:
        fail(f"{scene_file}: {summary['message']}; frames up to then are in {folder}", EXIT_BLEW_UP)
    if summary["status"] == INTERRUPTED:
        fail(f"{scene_file}: {summary['message']}; frames up to then are in {folder}", EXIT_INTERRUPTED)


@app.command()
def check(scene_file: SceneArg, sets: SetOpt = None) -> None:
    """Validate a scene and show what it contains and its stability bound, without running it."""
    from .report import print_check

    scene = _load(scene_file, sets)
    print_check(scene, scene_file)


@app.command()
def sweep(
    scene_file: SceneArg,
    sets: Annotated[Optional[list[str]], typer.Option(
        "--set", "-s", metavar="KEY=VALUES",
        help="A scene key and its values: a list 0.1,0.4,1.0, a range start:stop:count (inclusive, evenly "
             "spaced; whole numbers for integer keys) or one value for every run; repeatable. Every "
             "combination runs.")] = None,
    jobs: Annotated[Optional[int], typer.Option("--jobs", "-j", help="Runs at once (default: one per core).",
                                                show_default=False)] = None,
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="Sweep folder: a run folder per combination and results.csv (default "
                            "runs/sweep-<scene name>/).", show_default=False)] = None,
    plots: Annotated[Optional[list[str]], typer.Option(
        "--plot", metavar="FIGURE", help="Plot a results.csv column (e.g. shooter.mean_loop_inclination_deg) "
                                         "against the first swept key, one line per value of the others; "
                                         "repeatable.")] = None,
    scheduler: Annotated[Optional[str], typer.Option(
        "--scheduler", metavar="ADDRESS", help="Send the runs to this Dask scheduler (tcp://host:8786) "
                                               "instead of local processes; needs ropesim[dask].")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
) -> None:
    """Run a scene for every combination of --set values, in parallel; rerun, it resumes.

    Exits 3 if any run did not complete (each is recorded with its error in results.csv), 130 if interrupted.
    """
    from .sweep import SweepError, run_sweep

    try:
        result = run_sweep(scene_file, sets or [], out=out, jobs=jobs, scheduler=scheduler, plots=plots or [],
                           quiet=quiet)
    except SweepError as exc:
        fail(str(exc))
    if not quiet:
        typer.echo(f"{result.csv_path}: {len(result.rows)} runs ({result.ran} run now, {result.skipped} kept)"
                   + "".join(f"\n{path}" for path in result.plots))
    if result.interrupted:
        fail(f"sweep interrupted; rerun the same command to finish it ({result.csv_path})", EXIT_INTERRUPTED)
    if result.failed:
        fail(f"{len(result.failed)} of {len(result.rows)} runs did not complete; see the error column of "
             f"{result.csv_path}", EXIT_BLEW_UP)


def main() -> None:
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
