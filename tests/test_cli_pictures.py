"""The picture commands end to end: `ropesim run --animate`, `animate`, `frames` and `plot` on short runs;
bad input as one line with exit code 2 and nothing written; and one real `python -m ropesim animate`."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from PIL import Image
from typer.testing import CliRunner

from ropesim.cli.app import app

from conftest import ROOT, SCENARIOS

SHORT = "integrator.t_end=0.3"   # 31 saved frames, every 0.01 s
runner = CliRunner()


def invoke(*args):
    return runner.invoke(app, [str(a) for a in args], env={"COLUMNS": "200"})


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> dict[str, Path]:
    """Short runs made by `ropesim run`, the helicopter one with --animate."""
    base = tmp_path_factory.mktemp("picture-runs")
    heli = invoke("run", SCENARIOS / "helicopter_parachute.toml", "--set", SHORT, "--out", base / "heli",
                  "--animate", "--fps", "20", "-q")
    assert heli.exit_code == 0, heli.output
    shooter = invoke("run", SCENARIOS / "shooter_low.toml", "--set", SHORT, "--out", base / "shooter", "-q")
    assert shooter.exit_code == 0, shooter.output
    return {"heli": base / "heli", "shooter": base / "shooter"}


def test_run_animate_writes_the_animation_into_the_run_folder(runs):
    with Image.open(runs["heli"] / "animation.gif") as gif:
        assert gif.n_frames == 7   # t = 0, 0.05, ..., 0.3 at 20 fps
        assert gif.info["duration"] == 50


def test_animate_gif_and_mp4(runs, tmp_path):
    import imageio_ffmpeg

    gif = invoke("animate", runs["shooter"], "--out", tmp_path / "loop.gif", "--size", 320)
    assert gif.exit_code == 0, gif.output
    assert f"{tmp_path / 'loop.gif'}: 8 frames at 25 fps" in gif.stdout
    with Image.open(tmp_path / "loop.gif") as image:
        assert image.n_frames == 8 and max(image.size) <= 336
    mp4 = invoke("animate", runs["heli"], "-o", tmp_path / "heli.mp4", "--follow", "--fps", 50, "--start", 0.1)
    assert mp4.exit_code == 0, mp4.output
    assert imageio_ffmpeg.count_frames_and_secs(str(tmp_path / "heli.mp4"))[0] == 11  # t = 0.1 .. 0.3


def test_too_few_saved_frames_is_said_on_stderr_and_the_saved_ones_are_used(runs, tmp_path):
    result = invoke("animate", runs["heli"], "-o", tmp_path / "a.mp4", "--fps", 400)
    assert result.exit_code == 0
    assert "too few for 400 fps" in result.stderr and len(result.stderr.splitlines()) == 1
    assert "31 frames at 100 fps" in result.stdout


def test_frames_and_plot_write_pngs_in_the_run_folder(runs, tmp_path):
    folder = tmp_path / "run"
    shutil.copytree(runs["heli"], folder)
    result = invoke("frames", folder, "--times", "0,0.1,0.3")
    assert result.exit_code == 0, result.output
    assert "t = 0, 0.1, 0.3 s" in result.stdout
    with Image.open(folder / "frames.png") as png:
        width, height = png.size
        assert f"{width}x{height} px" in result.stdout
    overlay = invoke("frames", folder, "--count", 4, "--overlay", "--width", 500, "-o", folder / "over.png")
    assert overlay.exit_code == 0, overlay.output
    with Image.open(folder / "over.png") as png:
        assert png.size[0] == 500
    plot = invoke("plot", folder)
    assert plot.exit_code == 0 and "energy" in plot.stdout and "towed" in plot.stdout
    assert (folder / "plots.png").is_file()


def test_frames_shows_every_frame_of_a_run_with_fewer_than_asked(runs, tmp_path):
    four = invoke("run", SCENARIOS / "helicopter_mass.toml", "--set", "integrator.t_end=0.03", "-o", tmp_path / "r",
                  "-q")
    assert four.exit_code == 0, four.output
    for extra in ([], ["--count", "10"]):   # the default 6, or more than the 4 saved frames
        result = invoke("frames", tmp_path / "r", *extra)
        assert result.exit_code == 0, result.output
        assert "t = 0, 0.01, 0.02, 0.03 s" in result.stdout


def test_a_scene_where_a_run_folder_belongs_points_to_its_run(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert invoke("run", "helicopter_mass", "--set", "integrator.t_end=0.03", "-q").exit_code == 0
    result = invoke("animate", "helicopter_mass")
    assert result.exit_code == 2 and result.stderr.splitlines() == [
        "ropesim: helicopter_mass: is a built-in scene, not a run folder; its run is in runs/helicopter_mass: "
        "`ropesim animate runs/helicopter_mass`"]


def _corrupt(folder: Path) -> Path:
    (folder / "trajectory.npz").write_bytes(b"PK\x03\x04 not really a zip")
    return folder


BAD = [
    (["animate", "{missing}"], "no such run folder"),
    (["plot", "{corrupt}"], "corrupt or unreadable"),
    (["frames", "{corrupt}"], "corrupt or unreadable"),
    (["animate", "{heli}", "-o", "{out}/a.avi"], "unknown file type ('.avi'); use .gif or .mp4"),
    (["animate", "{heli}", "-o", "{out}/a"], "unknown file type (no extension)"),
    (["frames", "{heli}", "-o", "{out}/a.jpg"], "use .png"),
    (["animate", "{heli}", "-o", "{out}/a.gif", "--fps", "0"], "--fps 0: must be a positive"),
    (["animate", "{heli}", "-o", "{out}/a.gif", "--fps", "-5"], "--fps -5: must be a positive"),
    (["run", str(SCENARIOS / "helicopter_mass.toml"), "-o", "{out}/r", "--animate", "--fps", "0"], "--fps 0"),
    (["animate", "{heli}", "-o", "{out}/a.gif", "--end", "0.5"], "--end 0.5: outside the run (t = 0 .. 0.3 s)"),
    (["animate", "{heli}", "-o", "{out}/a.gif", "--start", "0.2", "--end", "0.1"], "is before --start"),
    (["animate", "{heli}", "-o", "{out}/a.gif", "--speed", "0"], "--speed 0"),
    (["animate", "{shooter}", "-o", "{out}/a.gif", "--follow"], "has no driven node to follow"),
    (["animate", "{heli}", "-o", "{out}/a.gif", "--view", "xz"], "--view xz"),
    (["frames", "{heli}", "-o", "{out}/a.png", "--times", "0,1"], "--times 1: outside the run"),
    (["frames", "{heli}", "-o", "{out}/a.png", "--times", "0,soon"], "'soon' is not a number"),
    (["frames", "{heli}", "-o", "{out}/a.png", "--times", "0", "--count", "3"], "one or the other"),
    (["animate", str(SCENARIOS / "helicopter_parachute.toml"), "-o", "{out}/a.gif"],
     "helicopter_parachute.toml: is a scene file, not a run folder; run it first: `ropesim run "),
    (["frames", "shooter_vacuum", "-o", "{out}/a.png"],
     "shooter_vacuum: is a built-in scene, not a run folder; run it first: `ropesim run shooter_vacuum` writes "
     "runs/shooter_vacuum, then `ropesim frames runs/shooter_vacuum`"),
    (["plot", "{out}/../corrupt/trajectory.npz", "-o", "{out}/a.png"], "is a file, not a run folder"),
]


@pytest.mark.parametrize("args, fragment", BAD, ids=[" ".join(a[:1] + a[-2:]) for a, _ in BAD])
def test_bad_input_is_one_line_exit_2_and_nothing_written(runs, tmp_path, args, fragment):
    out = tmp_path / "out"
    out.mkdir()
    corrupt = tmp_path / "corrupt"
    shutil.copytree(runs["heli"], corrupt)
    _corrupt(corrupt)
    names = {"missing": tmp_path / "nowhere", "corrupt": corrupt, "out": out, **runs}
    before = {p.name for p in runs["heli"].iterdir()}
    result = invoke(*[a.format(**names) for a in args])
    assert result.exit_code == 2, (result.exit_code, result.output, result.exception)
    lines = result.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("ropesim: ") and fragment in lines[0], result.stderr
    assert "Traceback" not in result.output
    assert list(out.iterdir()) == []                            # no output, no temporary file
    assert {p.name for p in runs["heli"].iterdir()} == before   # nor any in the run folder


def test_python_m_ropesim_animate_in_a_real_process(runs, tmp_path):
    result = subprocess.run([sys.executable, "-m", "ropesim", "animate", str(runs["heli"]), "-o",
                             str(tmp_path / "a.mp4"), "-q"], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout == "" and (tmp_path / "a.mp4").stat().st_size > 0
