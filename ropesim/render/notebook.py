"""A trajectory in Jupyter: a short HTML summary, and an animation that plays inline.

The animation is the one `ropesim animate` makes (the same :func:`ropesim.render.animate.animate`, drawing the
same frames), encoded as an H.264 MP4 and embedded in an HTML5 ``<video>`` element: a few hundred kB where a
JavaScript player of PNG frames (matplotlib's ``to_jshtml``) would be megabytes, and it needs neither IPython
nor a notebook extension, only a browser, so it plays in JupyterLab, Notebook, VS Code and exported HTML.
"""

from __future__ import annotations

import base64
import html
import tempfile
from dataclasses import dataclass, field
from pathlib import Path


@dataclass(frozen=True)
class InlineAnimation:
    """An MP4 animation of a run that Jupyter shows as a playing video; :meth:`save` writes it to a file."""

    mp4: bytes = field(repr=False)
    frames: int
    fps: float
    size: tuple[int, int]  # (width, height) [px]

    def _repr_html_(self) -> str:
        data = base64.b64encode(self.mp4).decode("ascii")
        return (f'<video width="{self.size[0]}" height="{self.size[1]}" controls autoplay loop muted playsinline '
                f'src="data:video/mp4;base64,{data}"></video>')

    def save(self, path: str | Path) -> Path:
        """Write the MP4 to ``path`` and return it."""
        from ..io.atomic import atomic_output

        path = Path(path)
        with atomic_output(path) as tmp:
            tmp.write_bytes(self.mp4)
        return path


def inline_animation(traj, *, fps: float = 25.0, speed: float = 1.0, start: float | None = None,
                     end: float | None = None, follow: bool = False, view: str | None = None,
                     size: int = 480) -> InlineAnimation:
    """Animate ``traj`` as `ropesim animate` does (same options) into an :class:`InlineAnimation`."""
    from .animate import animate

    with tempfile.TemporaryDirectory(prefix="ropesim-inline-") as tmp:
        result = animate(traj, Path(tmp) / "animation.mp4", fps=fps, speed=speed, start=start, end=end,
                         follow=follow, view=view, size=size)
        data = result.path.read_bytes()
    return InlineAnimation(mp4=data, frames=result.frames, fps=result.fps, size=result.size)


def summary_html(traj) -> str:
    """A short HTML table: the scene, its status, frames, time range, nodes, method, a system's objects (the ids
    that traj.line, traj.point and traj.body take) and where it is stored."""
    from ..analysis.objects import line_ids, made_of

    scene, summary = traj.scene, traj.summary
    rows = [
        ("scene", scene.name + (f": {scene.description}" if scene.description else "")),
        ("status", summary.get("status", "completed") + (f" ({summary['message']})" if summary.get("message")
                                                         else "")),
        ("frames", f"{traj.frames}, t = {float(traj.t[0]):.6g} .. {float(traj.t[-1]):.6g} s"),
        ("nodes", f"{traj.nodes} ({made_of(scene)}, {scene.dimension}-D)"),
        ("method", f"{scene.integrator.method}, dt = {summary.get('dt', scene.integrator.dt):.3g} s"),
        ("arrays", f"t {tuple(traj.t.shape)} [s], x and v {tuple(traj.x.shape)} [m, m/s]"),
        ("stored", str(traj.folder) if traj.folder is not None else "in memory"),
    ]
    if scene.is_system:   # where each object's results are
        objects = [f"traj.line(id): {', '.join(line_ids(scene))}", f"traj.point(id): "
                   f"{', '.join(p.id for p in scene.points)}"]
        if scene.rigid_bodies:
            objects.append(f"traj.body(id): {', '.join(b.id for b in scene.rigid_bodies)}")
        rows.insert(-1, ("per object", "; ".join(objects)))
    body = "".join(f"<tr><th style='text-align:left'>{html.escape(k)}</th>"
                   f"<td style='text-align:left'>{html.escape(v)}</td></tr>" for k, v in rows)
    return f"<table><caption style='text-align:left'><b>ropesim.Trajectory</b></caption>{body}</table>"
