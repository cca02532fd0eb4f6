"""Pictures of a run folder: animations (GIF/MP4), sheets of selected frames, and analysis plots.

Pictures never re-run a scene: they read a run folder's saved frames (lazily, through
:class:`ropesim.trajectory.Trajectory`) and the scene saved with them.

    from ..io.trajectory import Trajectory
    from .animate import animate
    animate(Trajectory.open("runs/shooter_medium"), "shooter.gif", fps=25)

Modules: ``timeline`` picks the saved frames to show, ``framing`` the projection and the fixed view limits,
``scene_artist`` draws the scene (static geometry once, the rope per frame), ``encode`` writes GIF/MP4,
``output`` writes any file atomically, and ``animate``, ``frames`` and ``plots`` are the three pictures.
matplotlib, Pillow and imageio-ffmpeg load only inside those modules.
"""


SIZE_RANGE = (320, 8192)   # an animation's longer side [px]: no side is drawn shorter (framing.MIN_SIDE)


class RenderError(ValueError):
    """A picture that cannot be made as asked; ``str()`` is one line naming the option and what is allowed."""
