"""What every picture shares: fonts that can draw any scene name, and legends that never cover data.

Fonts: matplotlib's default font (DejaVu Sans) has no CJK glyphs, and each missing glyph is a warning. Every
picture is drawn with the usual font first, then any installed font that covers CJK, then matplotlib's own
Last Resort font (3.10 and later), which draws a character no font has as a box naming its Unicode block; a
glyph still missing is drawn as an empty box, without a warning. A title (the scene's name) with characters no
installed font draws shows them as their code points instead (U+76F4), so the title still tells scenes apart,
and one note line on stderr says which font package draws them (:func:`title_text`).

Legends: a legend inside the axes covers data wherever "best" finds no empty corner, so pictures put their
legends outside the plotting area (beside an axes, or in the figure's margin); tests check it.
"""

from __future__ import annotations

import functools
import logging
import re
import sys
import warnings
from contextlib import contextmanager
from typing import Iterator

LAST_RESORT = "Last Resort High-Efficiency"
CJK_FONT_HINT = "fonts-noto-cjk (apt), google-noto-sans-cjk-fonts (dnf) or any Noto Sans CJK font"
FALLBACK_FONTS = (
    "Noto Sans CJK JP", "Noto Sans CJK SC", "Noto Sans CJK TC", "Noto Sans CJK KR", "Source Han Sans",
    "WenQuanYi Zen Hei", "WenQuanYi Micro Hei", "Droid Sans Fallback", "Arial Unicode MS",
    LAST_RESORT,
)
OUTSIDE_RIGHT = {"loc": "upper left", "bbox_to_anchor": (1.01, 1.0), "borderaxespad": 0.0}  # ax.legend(**this)


def font_families() -> list[str]:
    """The current font family, then the installed fallback fonts (only installed ones: a missing family
    named in the list would itself be a warning)."""
    from matplotlib import font_manager, rcParams

    installed = {f.name for f in font_manager.fontManager.ttflist}
    return list(rcParams["font.family"]) + [f for f in FALLBACK_FONTS if f in installed]


@functools.lru_cache(maxsize=None)
def _drawn_by_installed_fonts() -> frozenset[int]:
    """The code points some font in :func:`font_families` draws (the Last Resort font's boxes excepted)."""
    from matplotlib import font_manager
    from matplotlib.ft2font import FT2Font

    covered: set[int] = set()
    for family in font_families():
        if family == LAST_RESORT:
            continue
        path = font_manager.findfont(font_manager.FontProperties(family=[family]), fallback_to_default=False)
        covered.update(FT2Font(path).get_charmap())
    return frozenset(covered)


_noted: set[str] = set()   # the characters a note has named already (one note per new character)


def title_text(text: str) -> str:
    """``text`` as a picture's title draws it: each character no installed font has is written as its code point
    (U+76F4), and a note on stderr (once for each character) names a font package that draws it."""
    if text.isascii():
        return text
    drawn = _drawn_by_installed_fonts()
    missing = [c for c in text if not c.isascii() and not c.isspace() and ord(c) not in drawn]
    if not missing:
        return text
    pieces: list[str] = []
    for c in text:   # each run of missing characters becomes "U+76F4 U+5347", spaced from its neighbours
        if c in missing:
            pieces.append(("" if not pieces or pieces[-1].endswith(" ") else " ") + f"U+{ord(c):04X} ")
        else:
            pieces.append(c)
    shown = re.sub(r" +", " ", "".join(pieces)).strip()
    unique = "".join(dict.fromkeys(missing))
    if not set(unique) <= _noted:
        _noted.update(unique)
        print(f"note: no installed font draws {unique} in picture titles, so they show code points; "
              f"install {CJK_FONT_HINT} to draw them", file=sys.stderr)
    return shown


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
