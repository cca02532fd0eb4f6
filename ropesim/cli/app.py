"""The command line. Each command parses its options and calls one function elsewhere.

Bad input (a scene file, a --set, a run folder) prints one line naming the file, the key and what is
allowed, and exits with code 2; a run that blows up exits 3; a run folder that cannot be written (a full
disk) exits 4; a run stopped by Ctrl-C, SIGTERM or SIGHUP exits 130, 143 or 129. All keep what they computed.
"""

from __future__ import annotations

import inspect
import sys
from enum import Enum
from pathlib import Path
from typing import Annotated, Optional

import typer
from typer.core import TyperCommand, TyperGroup

from .. import __version__


class _CleanHelp:
    """Help as a person reads it: no type shown for a flag (typer 0.29 labels every flag <bool>, as if it took
    a value: `--help -h <bool>`), a docstring's paragraphs wrapped to the terminal rather than broken where the
    source lines end, and brackets shown as written ("[s]" is a unit, not rich's strike-through markup)."""

    def __init__(self, *args, **kwargs):
        from rich.markup import escape

        super().__init__(*args, **kwargs)
        if self.help:
            self.help = escape("\n\n".join(" ".join(p.split()) for p in inspect.cleandoc(self.help).split("\n\n")))
        for param in self.params:
            if getattr(param, "help", None):
                param.help = escape(param.help)

    def get_params(self, ctx):
        params = super().get_params(ctx)
        for param in params:
            if getattr(param, "is_flag", False) and param.metavar is None:
                param.metavar = ""
        return params


class Command(_CleanHelp, TyperCommand):
    def invoke(self, ctx):
        """A scene whose ``equilibrium`` start cannot be solved stops any command that builds it: one line,
        exit 1 (the scene is valid; its static shape could not be found)."""
        from ..model.build import EquilibriumError

        try:
            return super().invoke(ctx)
        except EquilibriumError as exc:
            typer.echo(f"ropesim: {exc}", err=True)
            raise typer.Exit(1) from None


class Group(_CleanHelp, TyperGroup):
    """Ctrl-C before a command's own clean stop (while it parses, loads, compiles or checks) is one line and
    exit 130; Typer's own handling would exit 130 without a word."""

    def make_context(self, *args, **kwargs):
        with _interrupt_in_one_line():
            return super().make_context(*args, **kwargs)

    def invoke(self, ctx):
        with _interrupt_in_one_line():
            return super().invoke(ctx)


class _interrupt_in_one_line:
    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if kind is KeyboardInterrupt:
            from .status import close_early

            close_early()
            typer.echo("ropesim: interrupted", err=True)
            raise typer.Exit(130) from None
        return False


app = typer.Typer(
    name="ropesim",
    cls=Group,
    help="Simulate ropes: point masses joined by stiff springs, under gravity and air drag.\n\n"
         "A scene is a TOML file or the name of a built-in scene (`ropesim scenarios` lists them). Start with:\n\n"
         "  ropesim run helicopter_mass",
    no_args_is_help=True,
    add_completion=True,    # --install-completion / --show-completion for bash, zsh, fish and PowerShell
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)
EXIT_BAD_INPUT, EXIT_BLEW_UP, EXIT_WRITE, EXIT_INTERRUPTED = 2, 3, 4, 130
SIGNAL_EXIT = {"SIGINT": 130, "SIGTERM": 143, "SIGHUP": 129}   # 128 + the signal's number, as a shell reports


from ..stop import Stopped, quiet_interrupts_while_loading, started_as_the_command_line  # noqa: E402


def exit_code(exc: BaseException | None = None, name: str = "") -> int:
    """The exit code of a stop: by the signal's name, or the Stopped exception that carries one."""
    if isinstance(exc, Stopped):
        name = exc.name
    return SIGNAL_EXIT.get(name, EXIT_INTERRUPTED)

RUNNING, SCENES, PICTURES, STUDIES = "Run and check", "Scenes and set-up", "Pictures and exports", "Studies"
"""The help panels the commands are grouped in (`ropesim --help`)."""

JsonOpt = Annotated[bool, typer.Option("--json", help="Print the result as one JSON object on stdout (for "
                                                       "scripts), instead of the table.")]
FromOpt = Annotated[Optional[float], typer.Option("--from", metavar="T", help="Leave out the frames before T "
                                                  "seconds (a ramp-in, a transient).", show_default=False)]
ToTimeOpt = Annotated[Optional[float], typer.Option("--to", metavar="T", help="Leave out the frames after T "
                                                    "seconds.", show_default=False)]


def _echo_json(data: dict) -> None:
    import json

    typer.echo(json.dumps(data, indent=2, allow_nan=False, default=float))


SceneArg = Annotated[str, typer.Argument(
    metavar="SCENE", help="A scene file (TOML), or the name of a built-in scene such as helicopter_mass "
                          "(`ropesim scenarios` lists them).", show_default=False)]
SetOpt = Annotated[Optional[list[str]], typer.Option(
    "--set", "-s", metavar="KEY=VALUE",
    help="Override a scene key by its dotted TOML path, typed and validated like the file; repeatable. "
         "E.g. --set integrator.dt=0.002 --set rope.nodes=61 --set overrides.0.mass=50.")]


def _compiling(enabled: bool = True):
    """On a terminal, a spinner while Numba compiles, saying what compiles (see :mod:`ropesim.cli.status`)."""
    from .status import Startup

    return Startup(enabled and sys.stderr.isatty()).watch()


def fail(message: str, code: int = EXIT_BAD_INPUT) -> None:
    """Print one line to stderr and exit with ``code``."""
    typer.echo(f"ropesim: {message}", err=True)
    raise typer.Exit(code)


def _version(value: bool) -> None:
    if value:
        typer.echo(f"ropesim {__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    version: Annotated[bool, typer.Option("--version", "-V", callback=_version, is_eager=True,
                                          help="Print ropesim's version and exit.")] = False,
) -> None:
    pass  # the app's options only (its help is the Typer's help above)


def _source(scene: str):
    """The scene file a SCENE argument means (a path, or a built-in's name); one line and exit 2 if none."""
    from ..scene.builtin import resolve
    from ..scene.loader import SceneError

    try:
        return resolve(scene)
    except SceneError as exc:
        fail(str(exc))


def _load(scene: str, sets: list[str] | None, quiet: bool = False):
    """The scene a SCENE argument means, validated, with ``--set`` applied, and how to name it in messages (a
    MoorDyn input file's untranslated parts said on stderr unless ``quiet``)."""
    from ..scene.loader import SceneError, load_scene

    source = _source(scene)
    try:
        loaded = load_scene(scene, sets or []), source.label
    except SceneError as exc:
        fail(str(exc))
    if not quiet:
        _say_what_moordyn_loses(source.path)
    return loaded


def _say_what_moordyn_loses(path: Path) -> None:
    """A MoorDyn input file run directly: what its scene does without, one line each on stderr."""
    if path.suffix.lower() == ".toml":
        return
    from ..scene.moordyn import looks_like_moordyn, read_moordyn

    text = path.read_text(encoding="utf-8", errors="replace")
    if looks_like_moordyn(text):
        for note in read_moordyn(text, str(path), path.resolve().parent).notes:
            typer.echo(f"ropesim: {path}: not translated: {note}", err=True)


@app.command(cls=Command, rich_help_panel=RUNNING)
def run(
    scene_file: Annotated[Optional[str], typer.Argument(
        metavar="SCENE", help="A scene file (TOML), or the name of a built-in scene such as helicopter_mass "
                              "(`ropesim scenarios` lists them); not with --resume.", show_default=False)] = None,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="Run folder (default runs/<scene name>/). An "
                                                "earlier run there is replaced whole, pictures included.",
                                                show_default=False)] = None,
    sets: SetOpt = None,
    resume: Annotated[Optional[Path], typer.Option(
        "--resume", metavar="RUN_DIR", help="Continue the interrupted or killed run in RUN_DIR from its last "
                                            "checkpoint, bit for bit as if it had never stopped; with --set "
                                            "integrator.t_end=T, extend it (a finished run too).",
        show_default=False)] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
    animate_: Annotated[bool, typer.Option("--animate", help="Then animate the run into RUN_FOLDER/animation.gif "
                                                             "(more choices: `ropesim animate`).")] = False,
    fps: FpsOpt = 25.0,
    force: Annotated[bool, typer.Option("--force", help="Run even when dt is above the method's stability bound "
                                                        "(see `ropesim check`) or the disk looks too small for "
                                                        "the frames.")] = False,
) -> None:
    """Run a scene and write trajectory.npz, ledger.npz, scene.toml and summary.json into its run folder.

    Frames stream to the folder in checkpoints; Ctrl-C, SIGTERM or SIGHUP stop the run at its next chunk and
    keep them, and `ropesim run --resume RUN_DIR` continues it.
    """
    progress = not quiet and sys.stderr.isatty()
    from .status import Startup, take_early

    # On a terminal a spinner shows at once (before numpy and Numba load; from main() on, before Typer parsed
    # the command line) and says what compiles, if anything.
    status = take_early() or Startup(progress)
    if not progress:
        status.close()
    status.update(f"Preparing {scene_file if resume is None else resume}")
    with status:
        traj, folder, where = _run_command(scene_file, out, sets, resume, quiet, force, progress, status)
    from .report import print_summary
    from ..run import BLEW_UP, INTERRUPTED

    summary = traj.summary
    if not quiet:
        print_summary(summary, folder)
    if summary["status"] == BLEW_UP:
        fail(f"{where}: {summary['message']}; frames up to then are in {folder}", EXIT_BLEW_UP)
    if summary["status"] == INTERRUPTED:
        by = summary.get("stopped_by", "SIGINT")
        kept = summary.get("kept_earlier_run")
        fail(f"{where}: {summary['message']}" + (f" by {by}" if by != "SIGINT" else "")
             + ("" if kept else f"; frames up to then are in {folder}; `ropesim run --resume {folder}` continues it"),
             exit_code(name=by))
    if animate_:
        _animate(folder, None, quiet, fps=fps)


def _run_command(scene_file, out, sets, resume, quiet, force, progress, status):
    """`ropesim run`'s work up to the finished run: (trajectory, run folder, how to name it in messages)."""
    from ..io.guard import output_folder
    from ..io.runfolder import DiskFull, RunFolderError
    from ..run import simulate

    if resume is not None:
        if scene_file is not None or out is not None:
            fail("--resume RUN_DIR continues the run in RUN_DIR: give no SCENE and no --out with it")
        folder, where = resume, str(resume)
        t_end = _resume_t_end(sets)
        status.update(f"Resuming {folder}")
        status.watch()
        run_it = (lambda: _resume(folder, t_end, progress, status.stop))
    else:
        if scene_file is None:
            fail("missing SCENE: a scene file or a built-in scene's name (or --resume RUN_DIR)")
        scene, where = _load(scene_file, sets, quiet)
        status.update(f"Preparing {scene.name}", kernel=f"the {scene.integrator.method} kernel")
        status.watch()   # imports Numba, which the checks below need anyway
        _check_time_step(scene, where, force, quiet)
        folder = out if out is not None else Path("runs") / scene.name
        _may_write(lambda: output_folder(folder, "run"))     # at once, not after the kernel compiled
        _check_size(scene, where, folder, force, quiet)
        _say_what_replacing_costs(folder, quiet)
        status.update(f"Running {scene.name}")
        run_it = (lambda: simulate(scene, folder, progress=progress, before_bar=status.stop))
    try:
        traj = run_it()
    except DiskFull as exc:
        fail(str(exc), EXIT_WRITE)
    except RunFolderError as exc:
        fail(str(exc))
    except OSError as exc:
        fail(f"{folder}: cannot write the run folder ({exc.strerror or exc})", EXIT_WRITE)
    return traj, folder, where


def _may_write(check):
    """``check()`` (a :mod:`ropesim.io.guard` check); its refusal is one line and exit 2."""
    from ..io.guard import WriteRefused

    try:
        return check()
    except WriteRefused as exc:
        fail(str(exc))


def _say_what_replacing_costs(folder: Path, quiet: bool) -> None:
    """Before a run replaces a finished run: one line saying so, and until when Ctrl-C keeps the earlier run."""
    from ..io.runfolder import FINISHED, RunFolderError, read_manifest
    from ..run import CHECKPOINT_SECONDS

    try:
        manifest = read_manifest(folder) if folder.is_dir() else None
    except RunFolderError:
        manifest = None
    if quiet or not manifest or manifest.get("status") not in FINISHED:
        return
    t_end = (manifest.get("grid") or {}).get("t_end")
    typer.echo(f"ropesim: replacing the {manifest['status'].replace('_', ' ')} run in {folder}"
               + (f" (t = 0 .. {t_end:g} s)" if isinstance(t_end, (int, float)) else "")
               + f": it is deleted at the new run's first checkpoint, {CHECKPOINT_SECONDS:g} s in; Ctrl-C "
               f"before then keeps it", err=True)


def _resume_t_end(sets: list[str] | None) -> float | None:
    """The new t_end of ``--resume --set integrator.t_end=T``; any other --set is refused."""
    t_end = None
    for item in sets or []:
        key, _, value = item.partition("=")
        if key.strip() != "integrator.t_end":
            fail(f"--set {item}: with --resume only integrator.t_end may change (the rest of the scene is the "
                 f"run's own scene.toml)")
        try:
            t_end = float(value)
        except ValueError:
            t_end = float("nan")
        if not (t_end >= 0 and t_end < float("inf")):
            fail(f"--set {item}: integrator.t_end must be a number of seconds >= 0")
    return t_end


def _resume(folder: Path, t_end: float | None, progress: bool, before_bar=None):
    from ..run import resume

    return resume(folder, t_end, progress=progress, before_bar=before_bar)


def _check_size(scene, where: str, folder: Path, force: bool, quiet: bool) -> None:
    """Warn when the output or the run time is large; refuse (exit 2) unless --force when the disk cannot
    hold the frames."""
    from ..io.runfolder import free_bytes, human
    from ..run import WARN_BYTES, WARN_SECONDS, estimate

    est = estimate(scene)
    free = free_bytes(folder)
    if est.peak_bytes > free and not force:
        fail(f"{where}: the run would write about {human(est.bytes)} of frames ({est.frames:,} frames; "
             f"{human(est.peak_bytes)} while it finishes) and {folder} has {human(free)} free; raise "
             f"output.interval, shorten integrator.t_end, choose another --out, or --force to run anyway")
    if not quiet and (est.bytes > WARN_BYTES or est.seconds > WARN_SECONDS):
        typer.echo(f"ropesim: warning: {where}: a large run: about {human(est.bytes)} of frames ({est.frames:,} "
                   f"frames) and about {_duration(est.seconds)} of computing; Ctrl-C stops it cleanly and "
                   f"`ropesim run --resume` continues it", err=True)


def _duration(seconds: float) -> str:
    if seconds < 1:
        return "under a second"
    if seconds < 120:
        return f"{seconds:.0f} s"
    if seconds < 7200:
        return f"{seconds / 60:.0f} min"
    if seconds < 2 * 86400:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 86400:.0f} days"


def _check_time_step(scene, where: str, force: bool, quiet: bool) -> None:
    """Refuse a dt above the stability bound (exit 2) unless --force; warn above 80 % of it."""
    from ..analysis.stability import WARN_FRACTION, time_step_verdict
    from ..model.build import build
    from ..integrate.grid import TimeGrid

    method, dt = scene.integrator.method, TimeGrid.of(scene).dt
    verdict, bound = time_step_verdict(build(scene), method, dt)
    where = f"{where}: integrator.dt = {dt:.4g} s"
    if verdict == "refuse" and not force:
        fail(f"{where} is above {method}'s stability bound {bound:.4g} s; use a smaller dt, method = \"sdirk2\" "
             f"(stable at any dt), or --force to run anyway")
    if verdict != "ok" and not quiet:
        typer.echo(f"ropesim: warning: {where} is {dt / bound:.0%} of {method}'s stability bound {bound:.4g} s "
                   f"(warning above {WARN_FRACTION:.0%})", err=True)


@app.command(cls=Command, rich_help_panel=RUNNING)
def check(scene_file: SceneArg, sets: SetOpt = None, as_json: JsonOpt = False) -> None:
    """Validate a scene and show what it contains and its stability bound, without running it."""
    from .report import check_data, print_check

    from ..io.runfolder import free_bytes, human
    from ..run import WARN_BYTES, WARN_SECONDS, estimate

    scene, where = _load(scene_file, sets)
    est, folder = estimate(scene), Path("runs") / scene.name
    free = free_bytes(folder)
    if as_json:
        from ..kernels import loop_cached

        _echo_json({**check_data(scene, where), "output": {
            "frames": est.frames, "bytes": est.bytes, "peak_bytes": est.peak_bytes, "free_bytes": free,
            "folder": str(folder), "run_seconds": est.seconds,
            "kernel_cached": loop_cached(scene)}})
        return
    print_check(scene, where)
    typer.echo(f"output: about {human(est.bytes)} in {est.frames:,} frames ({human(est.peak_bytes)} while the "
               f"run finishes; {human(free)} free at {folder}); run time {'about ' * (est.seconds >= 1)}"
               f"{_duration(est.seconds)}"
               f"{_compile_note(scene)}")
    if est.peak_bytes > free:
        typer.echo(f"ropesim: warning: {where}: the disk at {folder} cannot hold the frames; `ropesim run` "
                   f"refuses it without --force", err=True)
    elif est.bytes > WARN_BYTES or est.seconds > WARN_SECONDS:
        typer.echo(f"ropesim: warning: {where}: a large run (about {human(est.bytes)}, {_duration(est.seconds)})",
                   err=True)


def _compile_note(scene) -> str:
    """What a first run adds to the run time: compiling the method's loop, unless Numba's cache has it."""
    from ..kernels import FIRST_COMPILE_SECONDS, loop_cached

    method = scene.integrator.method
    cached = loop_cached(scene)
    if cached:
        return f" ({method}'s kernel is in the cache: no compiling)"
    low, high = FIRST_COMPILE_SECONDS
    return (f", after compiling {method}'s kernel{' once' if cached is False else ', if not in the cache'} "
            f"({low} to {high} s; `ropesim compile` does it ahead)")


@app.command(cls=Command, rich_help_panel=RUNNING)
def summary(
    run_dir: Annotated[Path, typer.Argument(metavar="RUN_DIR", help="Run folder written by `ropesim run`, e.g. "
                                                                    "runs/mooring_chain.", show_default=False)],
    start: FromOpt = None,
    stop: ToTimeOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """A run's tensions and support forces over a window of time: min, max, mean and std of the tension at both
    ends and of each support's force, and the largest tension anywhere, in kN where forces reach kilonewtons.

    --from leaves out a ramp-in or a start-up transient; summary.json keeps the whole run's figures.
    """
    from .report import print_window
    from ..analysis.tension import windowed_figures

    traj = _open_run(run_dir, "summary")
    if traj.tension is None:
        fail(f"{run_dir}: stores no tensions (written by an older ropesim); run it again")
    try:
        figures = windowed_figures(traj, start, stop)
    except ValueError as exc:
        fail(str(exc))
    if as_json:
        _echo_json({"run": str(run_dir), **figures})
    else:
        print_window(figures, run_dir)


@app.command(cls=Command, rich_help_panel=SCENES, name="compile")
def compile_(
    scene_files: Annotated[Optional[list[str]], typer.Argument(
        metavar="[SCENE]...", help="Compile for these scenes (built-in names or scene files; default: every "
                                   "built-in scene).", show_default=False)] = None,
    sets: SetOpt = None,
    methods: Annotated[Optional[list[str]], typer.Option(
        "--method", "-m", metavar="NAME", help="Compile only this integrator's kernels; repeatable or "
                                               "comma-separated (default: every integrator, and the static "
                                               "solver).", show_default=False)] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
) -> None:
    """Compile every kernel into Numba's cache now, so that later runs start at once: for container images and CI.

    A scene compiles only the parts it uses, the first time it runs (a few seconds, once; then it loads from
    the cache in a fraction of a second). This compiles the loop of every integrator for every built-in scene
    (or the scenes given), the tension and support forces of a saved frame, and the static solver of
    `ropesim equilibrium`, then prints what it compiled and how long each took. A scene of your own with parts
    no built-in scene combines compiles its own copy: name it here to prepare it too. The cache is the folder
    ropesim chose for this installation (or NUMBA_CACHE_DIR): run it as the user who will run ropesim, on the
    same kind of CPU.
    """
    from .report import print_compiled
    from .status import Startup, cache_dir
    from ..kernels import STATIC_SOLVER, compile_all

    names = _methods(",".join(methods), "--method") if methods else None
    scenes = [_load(name, sets)[0] for name in scene_files] if scene_files else None
    with Startup(not quiet and sys.stderr.isatty(), "ropesim compile") as status:
        status.watch()

        def starting(name: str, i: int, n: int) -> None:
            what = "the static solver" if name == STATIC_SOLVER else f"the {name} kernel"
            status.update(f"Loading {what} ({i + 1} of {n})", kernel=what)

        results = compile_all(names, scenes, static_solver=names is None, on_start=starting)
    if not quiet:
        print_compiled(results, cache_dir(), builtin=scenes is None)


@app.command(cls=Command, rich_help_panel=RUNNING)
def equilibrium(
    scene_file: SceneArg,
    sets: SetOpt = None,
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", metavar="FILE.toml", help="Also write the scene with its static shape as a 'points' start "
                                                  "(every node at rest), to run or to edit.",
        show_default=False)] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace FILE.toml if it exists.")] = False,
    as_json: JsonOpt = False,
) -> None:
    """Find a scene's static shape: every force balanced at every free node, the held nodes where the scene holds
    them; print the support forces, the tensions and what rests on the seabed.

    The solve starts from the scene's initial shape (an 'equilibrium' start from its sagging guess) and balances
    weight, buoyancy, the springs, bending, the seabed's contact and drag in the flow at its full strength. A
    system's free points and free rigid bodies are balanced too (a body in position and orientation, from where
    the scene puts it): each body's pose and each line's force and moment on it are printed. A scene with
    initial.shape = "equilibrium" starts its runs from this shape. Exit 1 if it does not converge.
    """
    from .report import equilibrium_data, print_equilibrium
    from ..analysis.statics import as_points_scene, equilibrium as solve
    from ..io.atomic import write_text_atomic
    from ..scene.schema import scene_to_toml

    from ..io.guard import output_file

    scene, where = _load(scene_file, sets)
    if out is not None:
        if out.suffix != ".toml":
            fail(f"--out {out}: must name a .toml file")
        if scene.is_system:
            fail(f"--out {out}: a system of lines has no 'points' start to write; give its [initial] "
                 f"shape = \"equilibrium\" to start its runs from the static shape")
        target = _may_write(lambda: output_file(out, replace=force, force_hint=True))
    with _compiling():   # the static solver compiles on its first use
        shape = solve(scene)
    if as_json:
        _echo_json(equilibrium_data(shape.in_scene_frame(), where))
    else:
        print_equilibrium(shape.in_scene_frame(), where)
    if not shape.converged:
        fail(f"{where}: the static solve did not converge (largest residual force {shape.residual:.3g} N after "
             f"{shape.iterations} iterations); check that the rope can hang where the scene holds it", 1)
    if out is not None:
        try:
            write_text_atomic(target, scene_to_toml(as_points_scene(shape)))
        except OSError as exc:
            fail(_write_failure(exc, out), EXIT_WRITE)
        typer.echo(f"written: {out} (run it with `ropesim run {out}`)", err=as_json)


@app.command(cls=Command, rich_help_panel=SCENES)
def scenarios() -> None:
    """List the built-in scenes, one a line: the name to give `ropesim run` and what the scene shows."""
    from ..scene.builtin import builtin_names, builtin_path, describe

    names = builtin_names()
    width = max(map(len, names))
    for name in names:
        typer.echo(f"{name:<{width}}  {describe(builtin_path(name))}")


class ImportFormat(str, Enum):
    """The input files `ropesim import` reads."""

    moordyn = "moordyn"


@app.command(cls=Command, rich_help_panel=SCENES, name="import")
def import_(
    format_: Annotated[ImportFormat, typer.Argument(metavar="FORMAT", help="The program whose input file FILE is: "
                                                    "moordyn (MoorDyn v2).", show_default=False)],
    file: Annotated[Path, typer.Argument(metavar="FILE", help="The input file (a MoorDyn v2 file: lines.txt, ...).",
                                         show_default=False)],
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="The scene file to write (default: FILE's "
                                                "name with .toml, in the current folder).",
                                                show_default=False)] = None,
    force: Annotated[bool, typer.Option("--force", help="Replace the scene file if it exists.")] = False,
) -> None:
    """Write a commented scene file from another program's input file: `ropesim import moordyn lines.txt` turns a
    MoorDyn v2 file's line types, points, lines, bodies and options into ropesim's keys, MoorDyn's conventions
    mapped exactly.

    Where ropesim's law differs from MoorDyn's, the scene says so in a comment; what it does not translate (output
    channels, the IC solver's settings) is listed at its top and here, one line each. A file that needs what
    ropesim lacks (rods, waves, currents, VIV, nonlinear lines) is refused in one line. `ropesim run FILE` runs a
    MoorDyn file directly.
    """
    from ..io.atomic import write_text_atomic
    from ..io.guard import output_file
    from ..scene.loader import SceneError, scene_from_dict
    from ..scene.moordyn import read_moordyn, scene_text

    label = str(file)
    try:
        text = file.read_text(encoding="utf-8", errors="replace")
    except FileNotFoundError:
        fail(f"{label}: no such file")
    except OSError as exc:
        fail(f"{label}: cannot be read ({exc.strerror or exc.__class__.__name__})")
    target = out if out is not None else Path(f"{file.stem}.toml")
    name = target.stem
    try:
        translation = read_moordyn(text, label, file.resolve().parent)
        scene_from_dict({"name": name, **translation.scene}, source=f"{label} (imported)",
                        base_dir=file.resolve().parent)
    except SceneError as exc:
        fail(str(exc))
    real = _may_write(lambda: output_file(target, replace=force, force_hint=True))
    try:
        write_text_atomic(real, scene_text(translation, label, name))
    except OSError as exc:
        fail(_write_failure(exc, target), EXIT_WRITE)
    for note in translation.notes:
        typer.echo(f"ropesim: {label}: not translated: {note}", err=True)
    typer.echo(f"{target}: MoorDyn's {label} as a scene ({len(translation.notes)} things not translated, listed "
               f"at its top); then `ropesim run {target}`")


@app.command(cls=Command, rich_help_panel=SCENES)
def new(
    name: Annotated[str, typer.Argument(metavar="NAME", help="The new scene's name; it is written to NAME.toml "
                                                             "(or give a path ending in .toml).",
                                        show_default=False)],
    from_: Annotated[str, typer.Option("--from", "-f", metavar="SCENE",
                                       help="The built-in scene (or scene file) to start from.")] = "helicopter_mass",
    force: Annotated[bool, typer.Option("--force", help="Replace NAME.toml if it exists.")] = False,
) -> None:
    """Write a scene file to edit: a copy of a built-in scene, every key explained by a comment.

    The copy keeps the original's comments, puts each key's meaning and unit above it, and lists the optional
    keys it leaves out, commented out at their defaults. Then: ropesim check NAME.toml; ropesim run NAME.toml.
    """
    from ..io.atomic import write_text_atomic
    from ..io.guard import output_file
    from ..scene.builtin import NAME, annotated_copy

    target = Path(name) if name.endswith(".toml") else Path(f"{name}.toml")
    stem = target.stem
    if not NAME.match(stem):
        fail(f"NAME {name}: use letters, digits, '_', '-' or '.', starting with a letter or digit "
             f"(it names the file and the run folder runs/{stem}/)")
    real = _may_write(lambda: output_file(target, replace=force, option="NAME", force_hint=True))
    source = _source(from_)
    _load(from_, None)  # the source must itself be a valid scene
    try:
        write_text_atomic(real, annotated_copy(source.path, stem, source.label))
    except OSError as exc:
        fail(_write_failure(exc, target), EXIT_WRITE)
    typer.echo(f"{target}: a copy of {source.label} to edit; then `ropesim check {target}` and "
               f"`ropesim run {target}`")


@app.command(cls=Command, rich_help_panel=STUDIES)
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
                                               "instead of local processes; needs the dask extra "
                                               "(dask.distributed).")] = None,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
    yes: Annotated[bool, typer.Option("--yes", "-y", help=f"Start a sweep of more than {LARGE_SWEEP:,} runs "
                                                          f"without asking (needed where nobody can answer: "
                                                          f"no terminal).")] = False,
) -> None:
    """Run a scene for every combination of --set values, in parallel; rerun, it resumes.

    Exits 3 if any run did not complete (each is recorded with its error in results.csv); 130, 143 or 129
    if stopped by Ctrl-C, SIGTERM or SIGHUP: no new run starts, the running ones stop at their next chunk and
    keep their frames, results.csv is written, and a rerun continues the unfinished runs from their checkpoints.
    """
    from ..sweep.core import run_sweep
    from ..sweep.plan import SweepError

    try:
        with _compiling(not quiet):   # the sweep compiles each method's kernels once before its workers start
            result = run_sweep(_source(scene_file).path, sets or [], out=out, jobs=jobs, scheduler=scheduler,
                               plots=plots or [], quiet=quiet, before=lambda n, root: _sweep_start(n, root, quiet, yes))
    except SweepError as exc:
        fail(str(exc))
    except OSError as exc:
        fail(_write_failure(exc), EXIT_WRITE)
    if not quiet:
        not_run = f", {result.not_run} not started" if result.not_run else ""
        typer.echo(f"{result.csv_path}: {len(result.rows)} runs ({result.ran} run now, {result.skipped} kept"
                   f"{not_run})" + "".join(f"\n{path}" for path in result.plots))
    if result.interrupted:
        fail(f"sweep interrupted{'' if result.stopped_by == 'SIGINT' else f' by {result.stopped_by}'}; rerun the "
             f"same command to finish it (unfinished runs continue from their checkpoints) ({result.csv_path})",
             exit_code(name=result.stopped_by))
    if result.failed:
        fail(f"{len(result.failed)} of {len(result.rows)} runs did not complete; see the error column of "
             f"{result.csv_path}", EXIT_BLEW_UP)


LARGE_SWEEP = 1000   # runs from which a sweep asks before it starts (--yes: without asking)


def _sweep_start(count: int, root: Path, quiet: bool, yes: bool) -> None:
    """Say how many runs go where, at once; before a sweep of more than LARGE_SWEEP runs, ask (on a terminal)
    or, where nobody can answer, refuse without --yes (exit 2)."""
    if count > LARGE_SWEEP and not yes:
        if not sys.stdin.isatty():
            fail(f"sweep: {count:,} runs into {root}/; a sweep of more than {LARGE_SWEEP:,} runs starts with --yes "
                 f"(or answer on a terminal)")
        if not typer.confirm(f"ropesim: sweep: {count:,} runs into {root}/; start?", default=False, err=True):
            fail("sweep: not started", 1)
    elif not quiet:
        typer.echo(f"ropesim: sweep: {count:,} run{'s' if count != 1 else ''} into {root}/", err=True)


# ------------------------------------------------------------------------- pictures (ropesim.render)

RunDirArg = Annotated[Path, typer.Argument(metavar="RUN_DIR", help="Run folder written by `ropesim run`, e.g. "
                                                                   "runs/helicopter_mass.", show_default=False)]
FollowOpt = Annotated[bool, typer.Option("--follow", help="View from the driven node (the helicopter; a "
                                                          "system's driven points and bodies): positions "
                                                          "relative to it.")]
ViewOpt = Annotated[Optional[str], typer.Option(
    "--view", help="3-D scenes: the axes shown across and up: xy (side view, the default for one rope), xz "
                   "(from above), zy (from the front); or 3d, a view in 3-D axes (the default for a system "
                   "of lines).", show_default=False)]


def _check_fps(fps: float) -> float:
    if not 0 < fps <= MAX_FPS:
        fail(f"--fps {fps:g}: must be a positive number of frames per second, at most {MAX_FPS}")
    return fps


from ..render import SIZE_RANGE  # noqa: E402

MAX_FPS, WIDTH_RANGE, COLUMNS_RANGE, COUNT_RANGE = 1000, (100, 16384), (1, 64), (1, 1000)


def _bounded(option: str, low: int, high: int, what: str):
    """A callback that refuses an integer option outside [low, high] in one line (exit 2)."""
    def check(value):
        if value is not None and not low <= value <= high:
            fail(f"{option} {value}: must be {what} from {low} to {high}")
        return value
    return check


def _check_speed(speed: float) -> float:
    if not (0 < speed < float("inf")):
        fail(f"--speed {speed:g}: must be a positive number of simulated seconds per second of video")
    return speed


FpsOpt = Annotated[float, typer.Option(
    "--fps", callback=_check_fps, help="Video frames per second, taken from the run's saved frames; a GIF "
                                       "plays at the nearest 100/n (50, 33.3, 25, 20, ...).")]
QuietOpt = Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")]


def _open_run(run_dir: Path, command: str):
    """The run folder ``run_dir``, opened lazily; a scene (a file, or a built-in's name) given where a run folder
    belongs is told apart from a missing folder, in one line that says what to run (exit 2)."""
    from ..io.runfolder import TRAJECTORY, RunFolderError
    from ..io.trajectory import Trajectory
    from ..scene.builtin import builtin_path, looks_like_a_name

    scene = run_dir if run_dir.is_file() else None
    if scene is None and not run_dir.exists() and looks_like_a_name(str(run_dir)):
        scene = builtin_path(str(run_dir))
    if scene is not None:
        import tomllib

        try:
            name = str(tomllib.loads(scene.read_text(encoding="utf-8")).get("name", scene.stem))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
            fail(f"{run_dir}: is a file, not a run folder (a folder written by `ropesim run`)")
        what = "a scene file" if scene == run_dir else "a built-in scene"
        made = Path("runs") / name
        if (made / TRAJECTORY).is_file():
            fail(f"{run_dir}: is {what}, not a run folder; its run is in {made}: `ropesim {command} {made}`")
        fail(f"{run_dir}: is {what}, not a run folder; run it first: `ropesim run {run_dir}` writes {made}, "
             f"then `ropesim {command} {made}`")
    try:
        return Trajectory.open(run_dir)
    except RunFolderError as exc:
        fail(str(exc))


def _formats(incomplete: str) -> list[str]:
    """``--to``'s fixed choices, for shell completion; any other value is refused by the command in one line that
    says why (NetCDF is not offered, and what to use instead)."""
    from ..io.export import FORMATS

    return [f for f in FORMATS if f.startswith(incomplete.lower())]


def _picture(make, what: str = "picture"):
    """Call ``make()``: an unusable run folder or request, or an output that is not ropesim's to replace, prints
    one line and exits 2; an output that cannot be written (a full disk, a read-only folder) one line naming it,
    exit 4."""
    from ..io.guard import WriteRefused
    from ..render import RenderError
    from ..io.runfolder import RunFolderError

    try:
        return make()
    except (RunFolderError, RenderError, WriteRefused) as exc:
        fail(str(exc))
    except OSError as exc:
        fail(_write_failure(exc), EXIT_WRITE)
    except (KeyboardInterrupt, Stopped) as exc:
        fail(f"interrupted; no {what} written", exit_code(exc))


def _write_failure(exc: OSError, default: Path | str = "output") -> str:
    """One line for a failed write, naming the file asked for (never a temporary one)."""
    from ..io.atomic import WriteFailed

    if isinstance(exc, WriteFailed):
        return str(exc)
    return f"{exc.filename or default}: cannot write it ({exc.strerror or exc})"


def _animate(run_dir: Path, out: Optional[Path], quiet: bool, **options) -> None:
    from ..render.animate import animate as make
    traj = _open_run(run_dir, "animate")
    target = out if out is not None else run_dir / "animation.gif"
    note = (lambda message: typer.echo(f"ropesim: {message}", err=True))
    result = _picture(lambda: make(traj, target, progress=not quiet and sys.stderr.isatty(),
                                   note=note, **options))
    if not quiet:
        typer.echo(f"{result.path}: {result.frames} frames at {result.fps:.3g} fps, "
                   f"{result.size[0]}x{result.size[1]} px")


@app.command(cls=Command, rich_help_panel=PICTURES)
def animate(
    run_dir: RunDirArg,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="Output file, .gif or .mp4 (default "
                                                "RUN_DIR/animation.gif).", show_default=False)] = None,
    fps: FpsOpt = 25.0,
    speed: Annotated[float, typer.Option("--speed", callback=_check_speed,
                                         help="Simulated seconds per second of video.")] = 1.0,
    start: Annotated[Optional[float], typer.Option("--start", help="First time shown, in seconds (default: 0).",
                                                   show_default=False)] = None,
    end: Annotated[Optional[float], typer.Option("--end", help="Last time shown, in seconds (default: the run's end).",
                                                 show_default=False)] = None,
    follow: FollowOpt = False,
    view: ViewOpt = None,
    size: Annotated[int, typer.Option("--size", callback=_bounded("--size", *SIZE_RANGE, "a number of pixels"),
                                      help=f"The picture's longer side, in pixels ({SIZE_RANGE[0]} to "
                                           f"{SIZE_RANGE[1]}).")] = 640,
    quiet: QuietOpt = False,
) -> None:
    """Animate a run folder as a GIF or an MP4 (by --out's extension), with the scene's geometry drawn."""
    _animate(run_dir, out, quiet, fps=fps, speed=speed, start=start, end=end, follow=follow, view=view, size=size)


@app.command(cls=Command, rich_help_panel=PICTURES)
def frames(
    run_dir: RunDirArg,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="Output PNG (default RUN_DIR/frames.png).",
                                                show_default=False)] = None,
    times: Annotated[Optional[str], typer.Option("--times", help="Times to show in seconds, comma-separated, e.g. "
                                                 "0,0.5,1,2,3 (the nearest saved frames).",
                                                 show_default=False)] = None,
    count: Annotated[Optional[int], typer.Option("--count", callback=_bounded("--count", *COUNT_RANGE,
                                                                              "a number of frames"),
                                                 help="Or this many frames evenly spaced from start "
                                                 "to end (default 6; a run with fewer saved frames shows them "
                                                 "all; at most 1000).", show_default=False)] = None,
    overlay: Annotated[bool, typer.Option("--overlay", help="All frames on one view, fading from the first to "
                                                            "the last, instead of side by side.")] = False,
    follow: FollowOpt = False,
    view: ViewOpt = None,
    columns: Annotated[Optional[int], typer.Option("--columns", callback=_bounded("--columns", *COLUMNS_RANGE,
                                                                                  "a number of panels"),
                                                   help="Panels per row (1 to 64).", show_default=False)] = None,
    width: Annotated[Optional[int], typer.Option("--width", callback=_bounded("--width", *WIDTH_RANGE,
                                                                              "a number of pixels"),
                                                 help="Picture width in pixels (100 to 16384).",
                                                 show_default=False)] = None,
    quiet: QuietOpt = False,
) -> None:
    """One PNG of selected frames of a run, side by side or overlaid."""
    from ..render.frames import frame_sheet
    from ..render.timeline import parse_times
    traj = _open_run(run_dir, "frames")
    target = out if out is not None else run_dir / "frames.png"
    result = _picture(lambda: frame_sheet(
        traj, target, times=None if times is None else parse_times(times), count=count,
        overlay=overlay, follow=follow, view=view, columns=columns, width=width))
    if not quiet:
        typer.echo(f"{result.path}: t = {', '.join(f'{t:.3g}' for t in result.times)} s, "
                   f"{result.size[0]}x{result.size[1]} px")


@app.command(cls=Command, rich_help_panel=PICTURES)
def plot(
    run_dir: RunDirArg,
    out: Annotated[Optional[Path], typer.Option("--out", "-o", help="Output PNG (default RUN_DIR/plots.png).",
                                                show_default=False)] = None,
    start: FromOpt = None,
    stop: ToTimeOpt = None,
    quiet: QuietOpt = False,
) -> None:
    """Plot a run: energy and largest spring stretch over time, and the towed rope's angle or the shooter's loop.

    A towed rope's angle is plotted along its length at the end, against the exact steady state; a string
    shooter's loop inclination over time.
    """
    from ..render.plots import plot_run
    traj = _open_run(run_dir, "plot")
    target = out if out is not None else run_dir / "plots.png"
    result = _picture(lambda: plot_run(traj, target, start=start, stop=stop))
    if not quiet:
        typer.echo(f"{result.path}: {', '.join(result.panels)}")


@app.command(cls=Command, rich_help_panel=PICTURES)
def view(
    run_dirs: Annotated[list[Path], typer.Argument(
        metavar="RUN_DIR...", help="Run folders written by `ropesim run` (finished, interrupted or still "
                                   "running); several are overlaid in one view, each in its own colour.",
        show_default=False)],
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="Output HTML file (default RUN_DIR/view.html; for several runs the first one's "
                            "overlay.html). A file ropesim did not write is never replaced.",
        show_default=False)] = None,
    every: Annotated[Optional[int], typer.Option(
        "--every", metavar="N", callback=_bounded("--every", 1, 10 ** 9, "a number of saved frames"),
        help="Keep one saved frame in N (default: every frame, or as few as keep the page under 50 MB, "
             "with a message saying so).", show_default=False)] = None,
    start: Annotated[Optional[float], typer.Option("--from", "--start", metavar="T",
                                                   help="First time shown, in seconds (default: the start).",
                                                   show_default=False)] = None,
    end: Annotated[Optional[float], typer.Option("--to", "--end", metavar="T",
                                                 help="Last time shown, in seconds (default: the end).",
                                                 show_default=False)] = None,
    no_open: Annotated[bool, typer.Option("--no-open", help="Write the page without opening it in a browser.")]
        = False,
    quiet: QuietOpt = False,
) -> None:
    """See runs in the browser: one self-contained HTML page with an interactive 3-D viewer, offline.

    The page plays the run (space; arrows step a frame), turns, zooms and pans the view (a 2-D scene is shown
    flat), colours the line by tension, strain or speed with a colour bar in the run's units, marks the supports,
    driven nodes, bodies, the thrower box and guide circles as `ropesim animate` does, and shows the end
    tensions (or the shooter's loop inclination) over time beside the run's summary. It needs no network and no
    server: mail it, or drop it into a report folder. Positions are stored within 0.1 mm or 1e-5 of the scene's
    size, whichever is larger. It opens in the default browser where there is one.
    """
    from ..viewer import ViewError
    from ..viewer.page import check_target, write_page

    runs = [_open_run(run_dir, "view") for run_dir in run_dirs]
    target = out if out is not None else run_dirs[0] / ("view.html" if len(run_dirs) == 1 else "overlay.html")
    try:
        check_target(target, "--out" if out is not None else None)
    except ViewError as exc:
        fail(str(exc))
    try:
        page = _picture(lambda: write_page(runs, target, "--out" if out is not None else None, every=every,
                                           start=start, end=end))
    except ViewError as exc:
        fail(str(exc))
    if page.note and not quiet:
        typer.echo(f"ropesim: {target}: {page.note}", err=True)
    if not quiet:
        shown = ", ".join(f"{name} ({frames:,} frames)" for name, frames in zip(page.runs, page.frames))
        typer.echo(f"{target}: {shown}, {page.nbytes / 1e6:.1f} MB")
    if not no_open:
        said = _open_in_browser(target)
        if said and not quiet:
            typer.echo(said, err=True)


def _open_in_browser(path: Path) -> str | None:
    """Open ``path`` in the default browser where there is one (a desktop session: never a text browser in the
    terminal); None when it opened, else a line saying why not."""
    import os
    import webbrowser

    if sys.platform.startswith(("linux", "freebsd", "openbsd")) and not (os.environ.get("DISPLAY")
                                                                       or os.environ.get("WAYLAND_DISPLAY")):
        return f"ropesim: no display here to open a browser on; open {path} in one"
    try:
        opened = webbrowser.open(path.resolve().as_uri())
    except webbrowser.Error:
        opened = False
    return None if opened else f"ropesim: found no browser to open; open {path} in one"


@app.command(cls=Command, rich_help_panel=PICTURES)
def export(
    run_dir: RunDirArg,
    to: Annotated[str, typer.Option("--to", "-t", metavar="[vtk|csv]", autocompletion=_formats,
                                    help="vtk: a series for ParaView (a .pvd and a .vtu per frame; needs the export "
                                         "extra); csv: tables for spreadsheets.", show_default=False)],
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="Output: a folder for vtk, a file for csv (default RUN_DIR/vtk/ or "
                            "RUN_DIR/trajectory.csv).", show_default=False)] = None,
    start: FromOpt = None,
    stop: Annotated[Optional[float], typer.Option("--until", metavar="T", help="Leave out the frames after T "
                                                  "seconds (--to names the format here).", show_default=False)] = None,
    quiet: QuietOpt = False,
) -> None:
    """Export a run for the tools engineers use: a VTK series for ParaView, or CSV for spreadsheets.

    vtk: one .vtu per saved frame (the nodes joined by line cells, with velocity and speed per node) and a .pvd
    that lists them with their times: open the .pvd in ParaView and press play. Written with meshio (the export
    extra: pip install 'pyropesim[export]', or pip install -e '.[export]' in a checkout): 2 MB of pure Python that writes VTK's compressed XML correctly; pyvista would
    bring all of VTK.

    vtk also carries each segment's tension [N] and strain as cell data, and the supports as a point set with
    their forces [N] (part 1 of each time step).

    csv: long format, one row per node per frame, a header naming each column with its unit (t [s], node,
    x [m], y [m], vx [m/s], vy [m/s]); full precision, so it reads back exactly. Beside it
    STEM_tension_history.csv (per frame: the end tensions and every support's force) and
    STEM_tension_range.csv (per segment: min, max, mean and std of its tension), in kN where forces reach
    kilonewtons; --from/--until keep a window (leave the ramp-in out).

    A system of lines: in VTK each line is a block of its own, named by its id, and rigid bodies are glyphs (their
    axes and spokes to their points, with the force and moment of their lines); in CSV each row names its line,
    the force tables go by line end and support point, and STEM_bodies.csv holds each body's pose, velocities,
    force and moment per frame.

    With a [sea]: a submerged column (each node's fraction below the surface) and STEM_sea.csv (per frame: each
    line's submerged fraction and the surface's elevation at each of [sea] probes); VTK point data submerged.

    NetCDF is not offered: xarray with h5py would add about 120 MB to hold the three arrays trajectory.npz
    already holds (numpy.load reads it; xarray wraps it in one call).
    """
    from ..io.export import ExportError, export as write

    traj = _open_run(run_dir, "export")
    try:
        result = _picture(lambda: write(traj, to.strip().lower(), out, start=start, stop=stop), "export")
    except ExportError as exc:
        fail(str(exc))
    if not quiet:
        typer.echo(f"{result.path}: {result.frames} frames of {traj.nodes} nodes, {result.files} "
                   f"file{'s' if result.files > 1 else ''}, {result.bytes / 1e3:,.0f} kB")


MethodsOpt = Annotated[Optional[str], typer.Option(
    "--methods", "-m", metavar="NAMES", help="Comma-separated integrators (default: all of "
                                              "symplectic_euler, verlet, yoshida4, pefrl, rk4, sdirk2).",
    show_default=False)]


METHOD_NAMES = ("symplectic_euler", "verlet", "yoshida4", "pefrl", "rk4", "sdirk2")
LADDER_WARN_STEPS = 1e9


def _warn_ladder(scene, steps: dict[str, float], command: str) -> None:
    """Warn (one line) before a ladder of a billion steps or more, with its estimated run time."""
    from ..run import NS_PER_NODE_STEP

    total = sum(steps.values())
    if total >= LADDER_WARN_STEPS:
        from ..io.trajectory import scene_nodes

        seconds = 1e-9 * scene_nodes(scene) * sum(n * NS_PER_NODE_STEP.get(m, 1000.0) for m, n in steps.items())
        typer.echo(f"ropesim: warning: {command}: about {total:.2g} steps in all, about {_duration(seconds)} of "
                   f"computing; Ctrl-C stops it", err=True)


def _methods(text: str | None, option: str = "--methods") -> list[str] | None:
    from ..integrate.methods import METHODS

    if not text:
        return None
    names = list(dict.fromkeys(n.strip() for n in text.split(",") if n.strip()))
    bad = [n for n in names if n not in METHODS]
    if bad or not names:
        fail(f"{option} {text}: unknown integrator {', '.join(bad) or '(none)'}; allowed {', '.join(METHODS)}")
    return names


def _numbers(text: str | None, option: str) -> list[float] | None:
    if not text:
        return None
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        values = []
    if not values or not all(v > 0 and v < float("inf") for v in values):
        fail(f"{option} {text}: must be a comma-separated list of positive numbers")
    return values


@app.command(cls=Command, rich_help_panel=STUDIES)
def accuracy(
    scene_file: SceneArg,
    methods: MethodsOpt = None,
    dts: Annotated[Optional[str], typer.Option(
        "--dts", metavar="DT,DT,...", help="Time steps in seconds (default: the scene's dt times 4, 2, 1, 1/2, 1/4, 1/8).",
        show_default=False)] = None,
    repeats: Annotated[int, typer.Option("--repeats", min=1, help="Timed runs per point (the median is kept).")] = 3,
    sets: SetOpt = None,
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="Folder for accuracy.csv and accuracy.png (default runs/accuracy-<scene name>/).",
        show_default=False)] = None,
) -> None:
    """Error against run time: every integrator over a ladder of time steps, against a converged reference.

    Prints the table and each method's observed order of convergence; writes accuracy.csv and a
    work-precision plot (error against kernel wall time and against force evaluations).
    """
    from ..analysis.accuracy import accuracy_report, plot, write_csv
    from .report import print_accuracy

    scene, _ = _load(scene_file, sets)
    names, ladder = _methods(methods), _numbers(dts, "--dts")
    folder = out if out is not None else Path("runs") / f"accuracy-{scene.name}"
    files = _may_write(lambda: _analysis_files(folder, "accuracy.csv", "accuracy.png"))
    base = scene.integrator.dt
    rungs = ladder or [base * f for f in (4, 2, 1, 0.5, 0.25, 0.125)]
    t_end = scene.integrator.t_end
    steps = {m: sum(t_end / dt for dt in rungs) * repeats for m in (names or METHOD_NAMES)}
    steps["pefrl"] = steps.get("pefrl", 0) + 1.5 * t_end / (min(rungs) / 16)     # the reference
    _warn_ladder(scene, steps, "accuracy")
    try:
        with _compiling():
            report = accuracy_report(scene, names, ladder, repeats)
    except (KeyboardInterrupt, Stopped) as exc:
        fail("accuracy interrupted; nothing written", exit_code(exc))
    try:
        write_csv(report, files[0])
        plot(report, files[1])
    except OSError as exc:
        fail(_write_failure(exc, folder), EXIT_WRITE)
    print_accuracy(report, folder)


def _analysis_files(folder: Path, *names: str) -> list[Path]:
    """The files an analysis writes into ``folder``, each checked by the write guard (links followed; a file
    ropesim did not write is refused)."""
    from ..io.guard import WriteRefused, follow, output_file

    real = follow(folder)
    if real.exists() and not real.is_dir():
        raise WriteRefused(f"--out {folder}: exists and is not a folder")
    return [output_file(real / name, option="--out") for name in names]


@app.command(cls=Command, rich_help_panel=STUDIES)
def stability(
    scene_file: SceneArg,
    methods: MethodsOpt = None,
    fractions: Annotated[Optional[str], typer.Option(
        "--fractions", metavar="F,F,...", help="Time steps to probe, as fractions of 2 / omega_max (default 0.1, "
                                              "0.2, ..., 2.0).", show_default=False)] = None,
    stiffness: Annotated[Optional[str], typer.Option(
        "--k", metavar="K,K,...", help="Also sweep the spring constant rope.stiffness, in N/m.",
        show_default=False)] = None,
    steps: Annotated[int, typer.Option("--steps", min=10, help="Steps a probe run must survive.")] = 4000,
    sets: SetOpt = None,
    out: Annotated[Optional[Path], typer.Option(
        "--out", "-o", help="Folder for stability.csv, bounds.csv and stability.png (default "
                            "runs/stability-<scene name>/).", show_default=False)] = None,
) -> None:
    """Map where each method stays stable as dt (and k) vary, against the predicted bounds.

    Each probe runs the scene from a slightly perturbed start; the blow-up dt of every explicit method is also
    measured by bisection and printed beside its predicted bound.
    """
    from ..analysis.stability import plot_sweep, stability_sweep, write_sweep
    from .report import print_stability

    scene, _ = _load(scene_file, sets)
    names, ladder = _methods(methods), _numbers(fractions, "--fractions")
    ks = _numbers(stiffness, "--k")
    folder = out if out is not None else Path("runs") / f"stability-{scene.name}"
    files = _may_write(lambda: _analysis_files(folder, "stability.csv", "bounds.csv", "stability.png"))
    probes = (len(ladder or range(20)) + 20) * len(ks or [0])       # the ladder and about 20 bisection probes
    _warn_ladder(scene, {m: probes * steps for m in (names or METHOD_NAMES)}, "stability")
    try:
        with _compiling():
            result = stability_sweep(scene, names, ladder, ks, steps)
    except (KeyboardInterrupt, Stopped) as exc:
        fail("stability interrupted; nothing written", exit_code(exc))
    except ValueError as exc:
        fail(str(exc))
    try:
        write_sweep(result, files[0].parent)
        plot_sweep(result, files[2])
    except OSError as exc:
        fail(_write_failure(exc, folder), EXIT_WRITE)
    print_stability(result, folder)


def _raise_stopped(signum, _frame) -> None:
    import signal

    raise Stopped(signal.Signals(signum).name)


def main() -> None:
    """Entry point. SIGTERM and SIGHUP end a command as Ctrl-C does (a run stops cleanly at its next chunk and
    keeps its frames); outside a run's own clean stop (say, while Python imports) they are one line too."""
    import signal

    from .status import close_early, start_early

    for name in ("SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), _raise_stopped)
    try:
        if started_as_the_command_line():   # Ctrl-C while modules loaded ended at once (ropesim.stop); from
            quiet_interrupts_while_loading(False)   # here on it is a KeyboardInterrupt, handled below
        start_early(sys.argv[1:])   # `ropesim run` on a terminal: its spinner, before Typer parses (0.15 s)
        app()
    except (KeyboardInterrupt, Stopped) as exc:
        close_early()
        name = exc.name if isinstance(exc, Stopped) else "SIGINT"
        typer.echo(f"ropesim: {'interrupted' if name == 'SIGINT' else f'stopped by {name}'}", err=True)
        sys.exit(exit_code(exc))
    finally:
        close_early()   # Typer refused the command line before `run` took the spinner
        _exit_without_collecting()


def _exit_without_collecting() -> None:
    """Spare the interpreter's shutdown its garbage collections: they traverse every object Numba's typing
    and cached kernels made (about 0.2 s of CPU after a warm `ropesim run helicopter_uniform`, a fifth of
    the whole process; scripts/bench_first_run.py --warm-only). Frozen objects are still freed by reference
    counting; only cyclic garbage is left to the operating system, and every file a command writes is closed
    (and fsynced) before it returns. The command line's exit only: the Python API collects as usual."""
    import gc

    gc.freeze()


if __name__ == "__main__":  # pragma: no cover
    main()
