"""ropesim: a rope simulator. N point masses joined by stiff springs, under gravity and air drag.

    import ropesim
    scene = ropesim.load_scene("scenarios/helicopter_mass.toml", ["integrator.t_end=10"])
    traj = ropesim.simulate(scene)            # in memory; or simulate(scene, "runs/x") to write a run folder
    traj.x[-1]                                # final positions, (N, D) [m]
    ropesim.Trajectory.open("runs/x")         # read a run folder lazily
    ropesim.view(["runs/a", "runs/b"]).save("ab.html")   # the runs overlaid in the browser viewer

Heavy modules (numba, matplotlib) load only when first used, so the command line starts fast.
"""

__version__ = "0.1.0"

from .stop import quiet_interrupts_while_loading, started_as_the_command_line  # noqa: E402

if started_as_the_command_line():
    quiet_interrupts_while_loading()   # until the command line takes Ctrl-C over (ropesim.cli)

from .io.numba_cache import ensure_writable_cache  # noqa: E402

ensure_writable_cache()  # before any kernel is defined: a read-only install caches its kernels elsewhere

__all__ = ["load_scene", "scene_from_toml", "SceneError", "Scene", "simulate", "Trajectory", "RunFolderError",
           "METHODS", "scene_to_toml", "view", "Coupling", "CouplingError"]

_LAZY = {
    "load_scene": "scene.loader", "scene_from_toml": "scene.loader", "SceneError": "scene.loader",
    "Scene": "scene.schema", "scene_to_toml": "scene.schema",
    "simulate": "run",
    "Trajectory": "io.trajectory", "RunFolderError": "io.trajectory",
    "METHODS": "integrate.methods",
    "view": "viewer.page",
    "Coupling": "coupling", "CouplingError": "coupling",
}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
    raise AttributeError(f"module 'ropesim' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
