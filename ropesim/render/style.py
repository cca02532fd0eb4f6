"""What every picture shares: fonts that can draw any scene name, and legends that never cover data.

Fonts: matplotlib's default font (DejaVu Sans) has no CJK glyphs, and each missing glyph is a warning. Every
picture is drawn with the usual font first, then any installed font that covers CJK, then matplotlib's own
Last Resort font (3.10 and later), which draws a character no font has as a box naming its Unicode block; a
glyph still missing is drawn as an empty box, without a warning.

Legends: a legend inside the axes covers data wherever "best" finds no empty corner, so pictures put their
legends outside the plotting area (beside an axes, or in the figure's margin); tests check it.
"""

from __future__ import annotations

import functools
import logging
import warnings
from contextlib import contextmanager
from typing import Iterator

FALLBACK_FONTS = (
    "Noto Sans CJK JP", "Noto Sans CJK SC", "Noto Sans CJK TC", "Noto Sans CJK KR", "Source Han Sans",
    "WenQuanYi Zen Hei", "WenQuanYi Micro Hei", "Droid Sans Fallback", "Arial Unicode MS",
    "Last Resort High-Efficiency",
)
OUTSIDE_RIGHT = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0}  # ax.legend(**this)


def font_families() -> list[str]:
    """The current font family, then the installed fallback fonts (only installed ones: a missing family
    named in the list would itself be a warning)."""
    from matplotlib import font_manager, rcParams

    installed = {f.name for f in font_manager.fontManager.ttflist}
    return list(rcParams["font.family"]) + [f for f in FALLBACK_FONTS if f in installed]


@contextmanager
def picture_text() -> Iterator[None]:
    """Draw pictures inside this block: any scene name is drawn, and no glyph warning reaches the user."""
    import matplotlib

    fonts = logging.getLogger("matplotlib.font_manager")  # "findfont: Failed to find font weight bold for <a
    level = fonts.level                                    # fallback>": the next font in the list is used
    fonts.setLevel(logging.ERROR)
    try:
        with matplotlib.rc_context({"font.family": font_families()}), warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r"Glyph \d+ .*missing from (current )?font",
                                    category=UserWarning)
            yield
    finally:
        fonts.setLevel(level)


def with_picture_text(fn):
    """Decorator: run ``fn`` (which draws and saves a picture) inside :func:`picture_text`."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with picture_text():
            return fn(*args, **kwargs)
    return wrapper
