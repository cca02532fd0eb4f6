"""The one error a scene refusal raises, shared by the loader and the built-in scene finder."""

from __future__ import annotations


class SceneError(ValueError):
    """A scene that cannot be used; ``str()`` is the one line to show the user."""

    def __init__(self, source: str, key: str, message: str):
        self.source, self.key, self.message = source, key, message
        where = f"{source}: {key}: " if key else f"{source}: "
        super().__init__(" ".join(f"{where}{message}".split()))

    def __reduce__(self):   # picklable, so a sweep's worker process hands the real message back
        return SceneError, (self.source, self.key, self.message)
