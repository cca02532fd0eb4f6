"""Encode RGBA frames (H, W, 4) uint8 (opaque, as the Agg canvas renders them) as a GIF (Pillow) or an MP4 (H.264 through imageio-ffmpeg's own ffmpeg).

GIF: one palette for the whole animation, from the most frequent colours of a few sample frames (so the
background, the rope and the geometry keep their exact colours; anti-aliased edges take the nearest), no
dithering; Pillow stores only the changed rectangle of each frame. Frame delays are whole hundredths of a
second, so a GIF's rate is 100 / n frames per second (see :func:`gif_fps`).

MP4: H.264, yuv420p, bit-exact flags so the same frames give the same bytes; the picture size is a multiple
of 16 (see :mod:`ropesim.render.framing`) so ffmpeg never rescales.
"""

from __future__ import annotations

import errno
import shutil
from pathlib import Path
from typing import Iterable

import numpy as np

from ..io.guard import SOFTWARE

ANIMATION_TYPES = (".gif", ".mp4")
GIF_MAX_FPS = 50.0  # viewers slow down GIFs with delays under 2/100 s
PALETTE_SEPARATION = 9  # see gif_palette
PALETTE_PIXELS = 1 << 20  # pixels of a sample frame the palette counts (a large frame's every k-th)
MP4_QUALITY = 6     # imageio-ffmpeg's 0..10 scale (6 is x264's crf 20); thin lines need more than its default 5
MP4_PRESET = "veryfast"  # x264 speed preset: at these sizes twice as fast as "medium", about as small


def gif_fps(fps: float) -> float:
    """The GIF rate nearest to ``fps``: 100 / n frames per second, at most GIF_MAX_FPS."""
    return 100.0 / max(round(100.0 / GIF_MAX_FPS), round(100.0 / fps))


def gif_palette(samples: list[np.ndarray]):
    """A "P" image holding up to 256 colours of ``samples``, the most frequent first (ties by colour value),
    each at least PALETTE_SEPARATION from the ones before it in some channel.

    Pillow maps a pixel to the palette entry nearest to the corner of its 4 x 4 x 4 colour cell, up to 3 per
    channel away from the pixel; with entries 9 apart no other entry is nearer to that corner than a
    pixel's own colour (its distance is at most sqrt(27), any other's at least 6), so the frequent colours
    (background, rope, geometry) come out exact; anti-aliased edges take the nearest kept shade.
    """
    from PIL import Image

    pixels = np.concatenate([s[..., :3].reshape(-1, 3) for s in samples]).astype(np.uint32)
    packed = (pixels[:, 0] << 16) | (pixels[:, 1] << 8) | pixels[:, 2]
    colours, counts = np.unique(packed, return_counts=True)
    ranked = colours[np.argsort(-counts, kind="stable")]
    candidates = np.stack([(ranked >> 16) & 255, (ranked >> 8) & 255, ranked & 255], axis=1).astype(int)
    kept = np.empty((256, 3), dtype=int)
    n = 0
    for colour in candidates:
        if n == 0 or np.abs(kept[:n] - colour).max(axis=1).min() >= PALETTE_SEPARATION:
            kept[n] = colour
            n += 1
            if n == 256:
                break
    rgb = np.concatenate([kept[:n], np.repeat(kept[:1], 256 - n, axis=0)]).astype(np.uint8)
    palette = Image.new("P", (1, 1))
    palette.putpalette(rgb.ravel().tolist())
    return palette


def write_gif(frames: Iterable[np.ndarray], path: Path, fps: float, samples: list[np.ndarray]) -> None:
    """Write ``frames`` to ``path`` as a looping GIF at ``gif_fps(fps)``; ``samples`` choose the palette."""
    from PIL import Image

    palette = gif_palette(samples)
    images = (Image.fromarray(f).convert("RGB").quantize(palette=palette, dither=Image.Dither.NONE)
              for f in frames)
    first = next(images)
    # optimize=False: Pillow's per-frame palette trimming halves the writing speed for files 15 % smaller
    first.save(path, format="GIF", save_all=True, append_images=images, loop=0, optimize=False,
               duration=10 * round(100.0 / gif_fps(fps)), comment=SOFTWARE)


def write_mp4(frames: Iterable[np.ndarray], path: Path, fps: float, size: tuple[int, int]) -> None:
    """Write ``frames`` (each ``size`` = (width, height) px) to ``path`` as an H.264 MP4 at ``fps``."""
    import imageio_ffmpeg

    writer = imageio_ffmpeg.write_frames(
        str(path), size, fps=fps, codec="libx264", pix_fmt_in="rgba", pix_fmt_out="yuv420p", quality=MP4_QUALITY,
        macro_block_size=16, ffmpeg_log_level="error",
        output_params=["-preset", MP4_PRESET, "-fflags", "+bitexact", "-flags:v", "+bitexact", "-map_metadata", "-1",
                       "-metadata", f"comment={SOFTWARE}"])
    try:
        writer.send(None)
        try:
            for frame in frames:
                writer.send(np.ascontiguousarray(frame))
        finally:
            writer.close()
    except (OSError, RuntimeError) as exc:
        raise _ffmpeg_failure(exc, path) from None


FULL_DISK_BYTES = 1 << 20   # less than this free where ffmpeg failed: the disk filled up


def _ffmpeg_failure(exc: BaseException, path: Path) -> OSError:
    """ffmpeg's failure as one OSError: a full disk as ENOSPC, else the last line ffmpeg said (imageio-ffmpeg
    hands over its whole command line and log, a dozen lines)."""
    try:
        full = shutil.disk_usage(Path(path).parent).free < FULL_DISK_BYTES
    except OSError:
        full = False
    if full or getattr(exc, "errno", None) in (errno.ENOSPC, errno.EDQUOT):
        return OSError(errno.ENOSPC, "No space left on device")
    said = [line.strip() for line in str(exc).splitlines() if line.strip() and not line.startswith("FFMPEG")]
    return OSError(errno.EIO, f"ffmpeg failed: {said[-1] if said else type(exc).__name__}")
