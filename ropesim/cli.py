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


def main() -> None:
    app()


if __name__ == "__main__":  # pragma: no cover
    main()
