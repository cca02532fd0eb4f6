"""Starting a scene from a saved frame of another run (``initial.shape = "from_run"``): relax, then perturb."""

import shutil

import numpy as np
import pytest

import ropesim
from ropesim.io import frames
from ropesim.integrate.methods import METHODS
from ropesim.model.build import build
from ropesim.scene.loader import SceneError, load_scene
from ropesim.scene.schema import scene_to_toml

# A pinned chain released from a horizontal line: no time-dependent term, so a run continued from any saved
# frame is the same initial-value problem as the uninterrupted run from that frame on.
CHAIN = """
name = "chain"
[rope]
nodes = 12
segment_length = 0.1
stiffness = 400.0
mass = 0.01
[initial]
shape = "line"
start = [0.0, 0.0]
end = [1.1, 0.0]
[pinned]
nodes = [0]
[gravity]
g = 9.81
[drag]
b = 0.002
[integrator]
method = "{method}"
dt = 0.001
t_end = {t_end}
[output]
interval = 0.05
"""


def _write(folder, name, text):
    path = folder / name
    path.write_text(text)
    return path


def _continued(tmp_path, method, start, extra=""):
    """The first run (0 to 1 s) into runs/first, and the scene that starts from its frame at ``start``."""
    first = _write(tmp_path, "first.toml", CHAIN.format(method=method, t_end=1.0))
    ropesim.simulate(load_scene(first), tmp_path / "runs" / "first")
    text = CHAIN.format(method=method, t_end=1.0 - start).replace(
        '[initial]\nshape = "line"\nstart = [0.0, 0.0]\nend = [1.1, 0.0]',
        f'[initial]\nshape = "from_run"\nrun = "runs/first"\ntime = {start}\n{extra}')
    return first, _write(tmp_path, "second.toml", text)


@pytest.mark.parametrize("method", list(METHODS))
def test_a_run_continued_from_a_frame_retraces_the_uninterrupted_run(tmp_path, method):
    """From the frame at t = 0.5 s the second run's frames are the first run's from 0.5 s on: bit for bit (each
    method starts a step from x and v alone), the held node where the first run held it. Generalized-alpha
    also carries an acceleration, which a frame does not hold: the continued run starts from the true one
    instead of the scheme's (they differ by O(h^2)), and with fixed steps its Newton solve stops within a tenth
    of each step's own error, where the two runs' iterates differ; so it retraces the first within a fifth of
    the scheme's own error against PEFRL at half the step (measured: 2.2e-5 m, 0.094 of it, at dt = 1 ms), with
    the held node exact."""
    first, second = _continued(tmp_path, method, 0.5)
    whole = ropesim.Trajectory.open(tmp_path / "runs" / "first")
    rest = ropesim.simulate(load_scene(second))
    k = int(np.flatnonzero(whole.t == 0.5)[0])
    assert rest.frames == whole.frames - k
    if METHODS[method].starts_from_x_and_v:
        np.testing.assert_array_equal(rest.x, whole.x[k:])
        np.testing.assert_array_equal(rest.v, whole.v[k:])
    else:
        reference = _write(tmp_path, "reference.toml", CHAIN.format(method="pefrl", t_end=1.0).replace(
            "dt = 0.001", "dt = 0.0005"))
        own_error = np.abs(whole.x - ropesim.simulate(load_scene(reference)).x).max()
        assert np.abs(rest.x - whole.x[k:]).max() <= 0.2 * own_error
        np.testing.assert_array_equal(rest.x[:, 0], whole.x[k:, 0])


def test_the_last_frame_is_the_default_and_at_rest_drops_the_velocities(tmp_path):
    first = _write(tmp_path, "first.toml", CHAIN.format(method="verlet", t_end=0.3))
    source = ropesim.simulate(load_scene(first), tmp_path / "relaxed")
    text = CHAIN.format(method="verlet", t_end=0.1).replace(
        'shape = "line"\nstart = [0.0, 0.0]\nend = [1.1, 0.0]', 'shape = "from_run"\nrun = "relaxed"')
    moving = build(load_scene(_write(tmp_path, "a.toml", text)))
    np.testing.assert_array_equal(moving.x0.T, source.x[-1])
    np.testing.assert_array_equal(moving.v0[:, 1:].T, source.v[-1][1:])
    still = build(load_scene(tmp_path / "a.toml", ["initial.at_rest=true"]))
    np.testing.assert_array_equal(still.x0.T, source.x[-1])
    assert not still.v0.any()


def test_the_resolved_scene_carries_the_frame_and_runs_without_the_source(tmp_path):
    """The run folder's scene.toml holds the frame as points and velocities: delete the source, rerun it, same
    numbers."""
    _, second = _continued(tmp_path, "verlet", 0.8)
    out = tmp_path / "runs" / "second"
    before = ropesim.simulate(load_scene(second), out)
    resolved = load_scene(out / "scene.toml")
    assert resolved.initial.shape == "points" and resolved.initial.velocities is not None
    assert load_scene(second) == resolved
    shutil.rmtree(tmp_path / "runs" / "first")
    again = ropesim.simulate(resolved)
    np.testing.assert_array_equal(again.x, before.x)
    np.testing.assert_array_equal(again.v, before.v)
    assert "velocities" in scene_to_toml(resolved)


def _refusal(path, *sets) -> SceneError:
    with pytest.raises(SceneError) as info:
        load_scene(path, list(sets))
    assert "\n" not in str(info.value)
    return info.value


def test_refusals_name_the_key_and_what_is_there(tmp_path):
    first, second = _continued(tmp_path, "verlet", 0.5)
    err = _refusal(second, "initial.time=0.52")
    assert err.key == "initial.time" and "saved no frame at t = 0.52 s" in str(err)
    assert "from 0 to 1 s, every 0.05 s" in str(err) and "nearest: 0.5" in str(err)
    err = _refusal(second, "rope.nodes=13")
    assert err.key == "initial.run" and "holds 12 nodes in 2-D, but this rope has 13 nodes in 2-D" in str(err)
    err = _refusal(second, "initial.run=runs/nowhere")
    assert err.key == "initial.run" and "no such run folder" in str(err)
    err = _refusal(second, "initial.at_rest=1")
    assert err.key == "initial.at_rest" and "true or false" in str(err)


def test_a_blown_up_run_starts_from_its_last_finite_frame_and_a_non_finite_frame_is_refused(tmp_path,
                                                                                             monkeypatch):
    """A run that blew up keeps its frames up to the blow-up, all finite: its last one may start a run. A frame
    that is not finite (a folder written by other means) is refused in one line."""
    text = CHAIN.format(method="verlet", t_end=1.0).replace("dt = 0.001", "dt = 0.02")
    source = ropesim.simulate(load_scene(_write(tmp_path, "wild.toml", text)), tmp_path / "wild")
    assert source.summary["status"] == "blew_up"
    second = _write(tmp_path, "next.toml", CHAIN.format(method="verlet", t_end=0.1).replace(
        'shape = "line"\nstart = [0.0, 0.0]\nend = [1.1, 0.0]', 'shape = "from_run"\nrun = "wild"'))
    np.testing.assert_array_equal(build(load_scene(second)).x0.T, source.x[-1])

    read = frames.read_run

    def poisoned(folder, verify=True):
        arrays, ledger, summary = read(folder, verify)
        x = np.array(arrays["x"])
        x[-1, 3, 1] = np.nan
        return {**arrays, "x": x}, ledger, summary

    monkeypatch.setattr(frames, "read_run", poisoned)
    err = _refusal(second)
    assert err.key == "initial.time" and "not finite (the run blew up)" in str(err)


def test_one_velocity_or_one_per_node_not_both(tmp_path):
    text = CHAIN.format(method="verlet", t_end=0.1).replace(
        'shape = "line"\nstart = [0.0, 0.0]\nend = [1.1, 0.0]',
        'shape = "points"\npoints = [' + ", ".join(f"[{0.1 * i:.1f}, 0.0]" for i in range(12)) + "]\n"
        "velocities = [" + ", ".join("[0.0, 1.0]" for _ in range(12)) + "]")
    path = _write(tmp_path, "p.toml", text)
    model = build(load_scene(path))
    np.testing.assert_array_equal(model.v0[:, 1:], np.tile([[0.0], [1.0]], (1, 11)))
    assert model.v0[:, 0].tolist() == [0.0, 0.0]   # the pinned node stays still
    assert _refusal(path, "initial.velocity=[1.0, 0.0]").key == "initial.velocities"
    assert "one per node" in str(_refusal(path, "initial.velocities=[[0.0, 1.0]]"))
