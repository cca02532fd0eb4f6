"""Notebook users: a Trajectory's HTML summary, an animation that plays inline, and docs/notebooks/*.ipynb
executed from the first cell to the last (nbclient), so the quickstart and the moorings notebook cannot rot
(the site executes them again at every build: mkdocs-jupyter)."""

from __future__ import annotations

import base64
import re
from pathlib import Path

import imageio_ffmpeg
import nbformat
import pytest
from nbclient import NotebookClient

import ropesim
from ropesim.render.notebook import InlineAnimation

from conftest import ROOT

NOTEBOOKS = sorted((ROOT / "docs" / "notebooks").glob("*.ipynb"))


@pytest.fixture(scope="module")
def traj(tmp_path_factory):
    scene = ropesim.load_scene("helicopter_parachute", ["integrator.t_end=0.4"])
    return ropesim.simulate(scene, tmp_path_factory.mktemp("nb") / "run")


def test_the_html_summary_says_what_the_run_is(traj):
    page = traj._repr_html_()
    for fragment in ("helicopter_parachute", "completed", "41, t = 0 .. 0.4 s", "21 (open line, 2-D)",
                     "symplectic_euler, dt = 0.001 s", "x and v (41, 21, 2)", str(traj.folder)):
        assert fragment in page, fragment
    assert repr(traj) == (f"Trajectory(scene='helicopter_parachute', completed, 41 frames, t = 0 .. 0.4 s, 21 nodes, "
                          f"2-D, {traj.folder})")   # short, not every array
    scene = ropesim.load_scene("helicopter_parachute", ["integrator.t_end=0.02", "name=<b>&"])
    assert "&lt;b&gt;&amp;" in ropesim.simulate(scene)._repr_html_()   # escaped; in memory
    assert "in memory" in ropesim.simulate(scene)._repr_html_()


def test_animate_returns_a_video_that_plays_inline(traj, tmp_path):
    anim = traj.animate(fps=20, size=200)
    assert isinstance(anim, InlineAnimation) and anim.frames == 9   # t = 0, 0.05, ..., 0.4
    assert repr(anim).startswith("InlineAnimation(frames=9, fps=20")
    page = anim._repr_html_()
    assert page.startswith("<video") and "controls" in page
    data = base64.b64decode(page.split("base64,", 1)[1].split('"', 1)[0])
    assert data == anim.mp4
    saved = anim.save(tmp_path / "a.mp4")
    assert imageio_ffmpeg.count_frames_and_secs(str(saved))[0] == 9


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.name for p in NOTEBOOKS])
def test_the_notebooks_run_without_an_error_or_a_warning(path, tmp_path):
    notebook = nbformat.read(path, as_version=4)
    assert all(not cell.get("outputs") for cell in notebook.cells if cell.cell_type == "code"), \
        f"{path.name} is stored with outputs: clear them"
    NotebookClient(notebook, timeout=600, kernel_name="python3",
                   resources={"metadata": {"path": str(tmp_path)}}).execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    assert not [o for o in outputs if o.output_type == "stream" and o.name == "stderr"], \
        [o.text for o in outputs if o.output_type == "stream"]
    html = [o.data["text/html"] for o in outputs if "text/html" in o.get("data", {})]
    if path.name == "quickstart.ipynb":
        assert any("ropesim.Trajectory" in h and "helicopter_mass" in h for h in html)
        assert any(h.startswith("<video") for h in html)
        viewers = [h for h in html if '<iframe sandbox="allow-scripts" srcdoc=' in h]   # the browser viewer
        assert len(viewers) == 2 and all("ropesim-data" in h for h in viewers)
        assert (tmp_path / "runs" / "helicopter_mass.html").is_file()
    if path.name == "moorings.ipynb":
        assert any("ropesim.Trajectory" in h and "mooring_chain" in h for h in html)
        pictures = [o for o in outputs if "image/png" in o.get("data", {})]
        assert len(pictures) == 3                       # tensions over time, along the chain, peak against surge
        text = "".join(o.text for o in outputs if o.output_type == "stream")
        assert "fairlead load 360 to 1782 kN after the ramp" in text   # as the moorings tutorial says
        peaks = [float(p) for p in re.findall(r"largest fairlead load (\d+) kN", text)]
        assert len(peaks) == 5 and all(b > a for a, b in zip(peaks, peaks[1:]))   # grows with the surge
        assert all((tmp_path / "runs" / name).is_file() for name in ("mooring.csv", "mooring_tension_history.csv",
                                                             "mooring_tension_range.csv"))


def test_there_are_the_notebooks():
    assert [p.name for p in NOTEBOOKS] == ["moorings.ipynb", "quickstart.ipynb"]
