"""The page's data: runs' contents packed small, with every quantisation bound stated.

**Positions** are quantised to a grid of step 2 e per axis, so every coordinate the page shows is within
e = max(0.1 mm, 1e-5 of the run's size) of the saved one (the size is the largest side of the box holding every
position the page shows); as 16-bit integers from the box's corner (the size is at most 50 000 steps, so
they fit; 65535 marks a coordinate that is not finite). Then they are delta-coded: each frame minus the frame
before it, and that difference minus the one of the node before it along the line, modulo 2^16 (a smooth
motion leaves mostly small numbers; decoding adds them back exactly, with no drift). **Fields** to colour by
(tension, strain, speed) are stored to 1/254 of their range over the runs shown (one range for every run, so
that their colours compare) (8 bits: the colour map has 256
colours), delta-coded along the line; 255 marks a value that is not finite. **Times and series** are stored as
float64 and float32. Rigid bodies' poses are float32 (1e-7 relative: far below a pixel).

All arrays go into one buffer, compressed with zlib (the browser inflates it with its DecompressionStream) and
base64-coded into the page; a JSON description says where each array is and how to decode it.

A page that would pass ``budget`` bytes (50 MB: about what a browser opens in a few seconds) keeps every k-th
frame (the smallest k that fits, from the compressed size of a sample of frames); --every N and --from/--to
choose instead.
"""

from __future__ import annotations

import json
import math
import zlib
from dataclasses import dataclass

import numpy as np

from . import ViewError
from .content import RunContent

FORMAT = "ropesim view 1"
POSITION_FLOOR = 1e-4       # [m] the quantisation bound is at least this,
POSITION_RELATIVE = 1e-5    # or this fraction of the run's size, whichever is larger
Q16_NOT_FINITE, Q8_NOT_FINITE = 65535, 255
FIELD_LEVELS = 254          # a field's range is split into this many steps (0 .. 254)
PAGE_BUDGET = 50_000_000    # [bytes] a larger page is thinned in time
RAW_BUDGET = 600_000_000    # [bytes] and so is one whose decoded arrays would take more memory in the browser
SAMPLE_FRAMES = 48          # frames compressed to estimate a page's size
DESCRIPTION_BYTES = 3000    # [bytes] about what a run's description takes beside its summary
ZLIB_LEVEL = 4              # 4: 3 % larger than 6 on a rope, and six times faster to write
BLOCK = 256                 # frames read and encoded at a time
RUN_COLORS = ("#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#7f7f7f")


def position_bound(size: float) -> float:
    """The largest error [m] of a stored coordinate, for a run of ``size`` [m]: max(0.1 mm, 1e-5 size)."""
    return max(POSITION_FLOOR, POSITION_RELATIVE * size)


@dataclass(frozen=True)
class Selection:
    """Which saved frames of each run the page holds, and why (``note``: a thinning message, or None)."""

    frames: list[np.ndarray]   # per run: indices of its saved frames
    every: int
    note: str | None = None


def select_frames(contents: list[RunContent], every: int | None = None, start: float | None = None,
                  end: float | None = None, budget: int = PAGE_BUDGET, overhead: int = 0,
                  at_least: int = 1) -> Selection:
    """The frames to show: those from ``start`` to ``end`` [s] (default: all), every ``every``-th of them; with
    ``every`` None, every frame, or every k-th for the smallest k (from ``at_least`` on) that keeps the page
    within ``budget`` bytes (``overhead``: the bytes of the page without its data)."""
    if every is not None and every < 1:
        raise ViewError(f"--every {every}: must be a whole number of frames, at least 1")
    spans = []
    for c in contents:
        slack = 1e-9 * max(1.0, abs(float(c.t[-1])))     # requested times may miss saved ones by rounding
        lo = -math.inf if start is None else start - slack
        hi = math.inf if end is None else end + slack
        spans.append(np.flatnonzero((c.t >= lo) & (c.t <= hi)))
    if start is not None and end is not None and end < start:
        raise ViewError(f"--to {end:g} is before --from {start:g}")
    if not any(len(s) for s in spans):
        first = min(float(c.t[0]) for c in contents)
        last = max(float(c.t[-1]) for c in contents)
        raise ViewError(f"--from/--to: no saved frame between {start if start is not None else first:g} and "
                        f"{end if end is not None else last:g} s (the run{'s' if len(contents) > 1 else ''}: "
                        f"t = {first:g} .. {last:g} s)")
    if every is not None:
        return Selection([_strided(s, every) for s in spans], every)
    longest = max(len(s) for s in spans)
    full, full_raw = estimate_bytes(contents, spans, 1, overhead)
    if at_least == 1 and full <= budget and full_raw <= RAW_BUDGET:
        return Selection(spans, 1)
    room = max(budget - overhead, 1)
    k = min(max(2, at_least, math.ceil(max((full - overhead) / room, full_raw / RAW_BUDGET))), max(longest - 1, 1))
    while True:
        size, raw = estimate_bytes(contents, spans, k, overhead)
        if (size <= budget and raw <= RAW_BUDGET) or k >= longest - 1:
            break
        k = min(max(k + 1, math.ceil(k * min((size - overhead) / room, 2.0)), math.ceil(k * raw / RAW_BUDGET)),
                longest - 1)
    kept = sum(len(_strided(s, k)) for s in spans)
    total = sum(len(s) for s in spans)
    why = (f"about {_mb(full)}" if full > budget else f"{_mb(full_raw)} of arrays in the browser's memory")
    note = (f"{total:,} frames would make a page of {why}: showing every {_ordinal(k)} frame ({kept:,} frames, "
            f"a page of about {_mb(size)}); --every 1 keeps every frame, --from/--to a shorter stretch at the "
            f"full rate")
    return Selection([_strided(s, k) for s in spans], k, note)


def _strided(indices: np.ndarray, every: int) -> np.ndarray:
    """Every ``every``-th of ``indices``, and always the last (the run's end is worth seeing)."""
    kept = indices[::every]
    if len(indices) and kept[-1] != indices[-1]:
        kept = np.append(kept, indices[-1])
    return kept


def _mb(nbytes: float) -> str:
    return f"{nbytes / 1e6:,.0f} MB" if nbytes >= 10e6 else f"{nbytes / 1e6:.1f} MB"


def _ordinal(k: int) -> str:
    suffix = "th" if 10 <= k % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(k % 10, "th")
    return f"{k}{suffix}"


def estimate_bytes(contents: list[RunContent], spans: list[np.ndarray], every: int,
                   overhead: int = 0) -> tuple[float, float]:
    """(page bytes, decoded bytes in the browser) for ``spans`` thinned to every ``every``-th frame, from a
    sample of SAMPLE_FRAMES frames of each run, compressed as the page would be."""
    page, raw = float(overhead), 0.0
    for content, span in zip(contents, spans):
        kept = _strided(span, every)
        if not len(kept):
            continue
        middle = max(0, len(kept) // 2 - SAMPLE_FRAMES // 2)
        sample = kept[middle:middle + SAMPLE_FRAMES]
        frame_bytes = _frame_raw_bytes(content)
        blob = _encode_run_arrays(content, sample, _extent(content, sample))
        compressed = len(zlib.compress(blob, ZLIB_LEVEL)) / len(sample)
        per_frame = compressed + 8 + 4 * len(content.series)          # with its time and series values
        page += 4 / 3 * per_frame * len(kept) + DESCRIPTION_BYTES + len(json.dumps(content.summary))
        raw += frame_bytes * len(kept)
    return page, raw


def _frame_raw_bytes(content: RunContent) -> int:
    """Bytes one frame of ``content`` takes decoded in the browser."""
    n = 0
    for line in content.lines:
        n += 2 * line.nodes * content.dimension + sum(f.values.shape[1] for f in line.fields)
    for p in content.points:
        if p.positions is not None:
            n += 2 * p.positions.shape[1] * content.dimension
    return n + 8 + 4 * len(content.series)


# ------------------------------------------------------------------------------------------ encoding


@dataclass
class Extent:
    """A run's box over the frames shown (the quantisation's origin and step) and its fields' ranges."""

    origin: np.ndarray      # (D,) [m]
    size: float             # [m] the box's largest side
    ranges: dict            # (line index, field name) -> (low, high)

    @property
    def bound(self) -> float:
        return position_bound(self.size)

    @property
    def step(self) -> float:
        return 2.0 * self.bound


def _blocks(indices: np.ndarray):
    for s in range(0, len(indices), BLOCK):
        yield s, indices[s:s + BLOCK]


def _moving_positions(content: RunContent) -> list:
    """Every per-frame position array of the run: its lines', its free points', its moving bodies'."""
    arrays = [line.positions for line in content.lines]
    arrays += [p.positions for p in content.points if p.positions is not None]
    arrays += [b.position for b in content.bodies if np.ndim(b.position) == 2]
    return arrays


def _extent(content: RunContent, frames: np.ndarray) -> Extent:
    """The box of every finite position in ``frames`` (and of the fixed bodies) and each field's range."""
    d = content.dimension
    lo, hi = np.full(d, np.inf), np.full(d, -np.inf)
    for array in _moving_positions(content):
        for _, idx in _blocks(frames):
            block = np.asarray(array[idx], dtype=float).reshape(len(idx), -1, d)
            low, high = block.min(axis=(0, 1)), block.max(axis=(0, 1))
            if not (np.all(np.isfinite(low)) and np.all(np.isfinite(high))):     # a blow-up: the finite ones
                finite = block[np.isfinite(block).all(axis=-1)]
                if not len(finite):
                    continue
                low, high = finite.min(axis=0), finite.max(axis=0)
            lo, hi = np.minimum(lo, low), np.maximum(hi, high)
    if not np.all(np.isfinite(lo)):
        raise ViewError(f"{content.name}: no finite position in the frames shown")
    ranges = {}
    for i, line in enumerate(content.lines):
        for f in line.fields:
            low, high = math.inf, -math.inf
            for _, idx in _blocks(frames):
                block = np.asarray(f.values[idx], dtype=float)
                b_low, b_high = float(block.min()), float(block.max())
                if not (math.isfinite(b_low) and math.isfinite(b_high)):
                    finite = block[np.isfinite(block)]
                    if not len(finite):
                        continue
                    b_low, b_high = float(finite.min()), float(finite.max())
                low, high = min(low, b_low), max(high, b_high)
            ranges[(i, f.name)] = (low, high) if low <= high else (0.0, 0.0)
    return Extent(origin=lo, size=float(np.max(hi - lo)), ranges=ranges)


def quantise_positions(array, frames: np.ndarray, extent: Extent) -> np.ndarray:
    """Positions (F, K, D) at ``frames`` as delta-coded 16-bit integers (k, D, K) (see the module)."""
    d = extent.origin.shape[0]
    k = array.shape[1]
    out = np.empty((len(frames), d, k), dtype=np.uint16)
    previous = np.zeros((d, k), dtype=np.int32)
    for s, idx in _blocks(frames):
        block = np.asarray(array[idx], dtype=float).reshape(len(idx), k, d)
        with np.errstate(invalid="ignore"):
            q = np.rint((block - extent.origin) / extent.step)
        q = np.where(np.isfinite(q), q, Q16_NOT_FINITE).astype(np.int32).transpose(0, 2, 1)   # (b, D, K)
        in_time = np.diff(q, axis=0, prepend=previous[None])
        previous = q[-1]
        out[s:s + len(idx)] = np.diff(in_time, axis=2, prepend=0) & 0xFFFF   # modulo 2^16
    return out


def quantise_field(values, frames: np.ndarray, low: float, high: float) -> np.ndarray:
    """A field (F, S) at ``frames`` as 8-bit levels over [low, high], delta-coded along axis 1 (k, S)."""
    scale = FIELD_LEVELS / (high - low) if high > low else 0.0
    out = np.empty((len(frames), values.shape[1]), dtype=np.uint8)
    for s, idx in _blocks(frames):
        block = np.asarray(values[idx], dtype=float)
        with np.errstate(invalid="ignore"):
            q = np.rint((block - low) * scale)
        q = np.where(np.isfinite(q), np.clip(q, 0, FIELD_LEVELS), Q8_NOT_FINITE).astype(np.int16)
        out[s:s + len(idx)] = np.diff(q, axis=1, prepend=0) & 0xFF   # modulo 2^8
    return out


def _encode_run_arrays(content: RunContent, frames: np.ndarray, extent: Extent) -> bytes:
    """The bulk of a run's data (positions and fields), as the page stores it: for size estimates."""
    parts = [quantise_positions(line.positions, frames, extent).tobytes() for line in content.lines]
    for i, line in enumerate(content.lines):
        for f in line.fields:
            parts.append(quantise_field(f.values, frames, *extent.ranges[(i, f.name)]).tobytes())
    return b"".join(parts)


class Buffer:
    """Arrays laid one after another (each at a multiple of 8 bytes), described by reference dicts."""

    def __init__(self):
        self.parts: list[bytes] = []
        self.size = 0

    def add(self, array: np.ndarray, coding: str = "raw") -> dict:
        array = np.ascontiguousarray(array)
        dtype = {np.dtype(np.uint16): "u16", np.dtype(np.uint8): "u8", np.dtype(np.float32): "f32",
                 np.dtype(np.float64): "f64"}[array.dtype]
        ref = {"offset": self.size, "dtype": dtype, "shape": list(array.shape), "coding": coding}
        data = array.astype(array.dtype.newbyteorder("<"), copy=False).tobytes()
        pad = -len(data) % 8
        self.parts.append(data + b"\0" * pad)
        self.size += len(data) + pad
        return ref

    def compressed(self) -> bytes:
        compressor = zlib.compressobj(ZLIB_LEVEL)
        return b"".join([*(compressor.compress(p) for p in self.parts), compressor.flush()])


def _pose_array(values, frames: np.ndarray, width: int) -> np.ndarray | list:
    """A body's position or orientation: a list for a fixed one, float32 (k, width) for a moving one."""
    if np.ndim(values) == 1:
        return [float(v) for v in values]
    return np.asarray(values[frames], dtype=np.float32).reshape(len(frames), width)


def pack(contents: list[RunContent], selection: Selection, colormap: bytes) -> tuple[dict, bytes]:
    """The page's description (JSON-ready) and its compressed data for ``contents`` at ``selection``'s frames;
    ``colormap``: 256 RGB triplets, the colours of a field from its low to its high end."""
    buffer = Buffer()
    for c, frames in zip(contents, selection.frames):
        if not len(frames):
            raise ViewError(f"{c.name}: no frame in the time range shown")
    extents = [_extent(c, frames) for c, frames in zip(contents, selection.frames)]
    shared: dict[str, tuple[float, float]] = {}     # a field has one range over every run: colours compare
    for extent in extents:
        for (_, name), (low, high) in extent.ranges.items():
            old = shared.get(name, (math.inf, -math.inf))
            shared[name] = (min(old[0], low), max(old[1], high))
    for extent in extents:
        extent.ranges = {(i, name): shared[name] for (i, name) in extent.ranges}
    runs = [_pack_run(c, frames, extent, buffer, RUN_COLORS[i % len(RUN_COLORS)])
            for i, (c, frames, extent) in enumerate(zip(contents, selection.frames, extents))]
    description = {"format": FORMAT, "runs": runs, "colormap": colormap.hex(), "note": selection.note,
                   "every": selection.every, "bytes": buffer.size}
    return description, buffer.compressed()


def _pack_run(content: RunContent, frames: np.ndarray, extent: Extent, buffer: Buffer, color: str) -> dict:
    d = content.dimension
    lines = []
    for i, line in enumerate(content.lines):
        fields = []
        for f in line.fields:
            low, high = extent.ranges[(i, f.name)]
            fields.append({"name": f.name, "unit": f.unit, "per": f.per, "low": low, "high": high,
                           "values": buffer.add(quantise_field(f.values, frames, low, high), "delta-along")})
        lines.append({"name": line.name, "nodes": line.nodes, "closed": line.closed, "fields": fields,
                      "positions": buffer.add(quantise_positions(line.positions, frames, extent), "delta-time-along")})
    points = []
    for p in content.points:
        entry = {"name": p.name, "kind": p.kind, "color": p.color, "size": p.size}
        if p.positions is not None:
            entry["positions"] = buffer.add(quantise_positions(p.positions, frames, extent), "delta-time-along")
        else:
            entry.update(line=p.line, nodes=list(p.nodes))
        points.append(entry)
    bodies = []
    for b in content.bodies:
        entry = {"name": b.name, "size": list(b.size), "fixed": b.fixed, "color": b.color}
        for key, values, width in (("position", b.position, d), ("orientation", b.orientation, 4)):
            pose = _pose_array(values, frames, width)
            entry[key] = pose if isinstance(pose, list) else buffer.add(pose)
        bodies.append(entry)
    return {
        "name": content.name, "description": content.description, "where": content.where, "color": color,
        "dimension": d, "axes": list(content.axes), "frames": len(frames), "saved_frames": content.frames,
        "time": buffer.add(np.asarray(content.t[frames], dtype=np.float64)),
        "quantisation": {"origin": extent.origin.tolist(), "step": extent.step, "bound": extent.bound,
                         "size": extent.size},
        "lines": lines, "points": points, "bodies": bodies,
        "shapes": [{"name": s.name, "kind": s.kind, "center": list(s.center), "radius": s.radius,
                    "axis": list(s.axis), "dashed": s.dashed} for s in content.shapes],
        "water": _surface(content.water, frames, buffer),
        "seabed": _surface(content.seabed, frames, buffer),
        "series": [{"name": s.name, "unit": s.unit,
                    "values": buffer.add(np.asarray(s.values, dtype=np.float32)[frames])} for s in content.series],
        "summary": [[k, v] for k, v in content.summary],
    }


def _surface(surface, frames: np.ndarray, buffer: Buffer) -> dict | None:
    if surface is None:
        return None
    out = {"height": surface.height, "slope_deg": surface.slope_deg}
    if surface.heights is not None:
        heights = np.asarray(surface.heights[frames] if np.ndim(surface.heights) == 3 else surface.heights,
                             dtype=np.float32)
        out.update(x=[float(v) for v in surface.x], z=[float(v) for v in surface.z], heights=buffer.add(heights))
    return out


def description_json(description: dict) -> str:
    """The description as JSON safe inside a <script> element (no "</" can close it)."""
    return json.dumps(description, allow_nan=False, separators=(",", ":")).replace("</", "<\\/")
