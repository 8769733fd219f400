"""How a version 2 take stores its big per-frame arrays: in chunks of frames.

The arrays that grow with bodies and frames (`CHUNKED`: poses, suckers, the replay
records) are stored as entries `<name>.<k>.npy` (k = 000000, 000001, ...), chunk k
holding frames [k * C, (k + 1) * C) where C is `header["chunk_frames"]`, so a bake
writes them as it goes and a reader decodes a chunk at a time. Every other array (the
tracks, the ground, the clips) is one entry `<name>.npy`, as in version 1.

A creature spawned while a bake streamed its take is missing from the chunks written
before it came: a chunk may hold fewer items (bodies, suckers, creatures) than the
header lists, never more than a later chunk. Readers give the missing items the value
they have at the first frame that holds them.
"""

from __future__ import annotations

import io
import math
import re
import zipfile
from collections.abc import Mapping

import numpy as np

from ecs_tentacles.take import replay as take_replay
from ecs_tentacles.take.tracks import tracks_of

CORE = ("pos", "quat", "sucker_attached", "sucker_anchor")
CHUNK_BYTES = 32 * 1024**2  # a chunk of every chunked array decodes to about this much
MAX_CHUNK_FRAMES = 256
_EPOCH = (1980, 1, 1, 0, 0, 0)  # the earliest zip date: no wall-clock time in the file
LEVEL = 1  # deflate level: the poses barely shrink past it; zeros shrink at any level
ENTRY = re.compile(r"^(?P<name>[a-z_]+)\.(?P<chunk>[0-9]{6})\.npy$")


def chunked_names(header: dict[str, object]) -> tuple[str, ...]:
    """The arrays a version 2 take stores in chunks: `header["chunked"]` (bodies,
    suckers, replay records, and the curves tracks being recorded when the first chunk
    was stored), or without it the bodies, suckers and replay records."""
    listed = header.get("chunked")
    if isinstance(listed, list):  # else absent (a sound header's is a list: chunked_problem)
        return tuple(listed)
    replay = take_replay.PER_FRAME if header.get(take_replay.KEY) is not None else ()
    return (*CORE, *replay)


def chunkable(header: dict[str, object]) -> tuple[str, ...]:
    """Every array of this take that may be stored in chunks, in file order."""
    replay = take_replay.PER_FRAME if header.get(take_replay.KEY) is not None else ()
    curves = [a for t in tracks_of(header) if t.kind == "curves" for a in t.arrays]
    return (*CORE, *replay, *curves)


def chunked_problem(header: dict[str, object]) -> str | None:
    """The first problem of `header["chunked"]`, or None."""
    listed = header.get("chunked")
    if listed is None:
        return None
    allowed = chunkable(header)
    if not isinstance(listed, list) or not all(isinstance(n, str) for n in listed):
        return "header.chunked: must be a list of array names"
    if len(set(listed)) != len(listed) or not set(listed) <= set(allowed):
        return f"header.chunked: names arrays of this take stored in chunks, of {list(allowed)}"
    must = set(
        allowed[
            : len(CORE)
            + (len(take_replay.PER_FRAME) if header.get(take_replay.KEY) is not None else 0)
        ]
    )
    if not must <= set(listed):
        return f"header.chunked: must hold {sorted(must)}"
    for track in tracks_of(header):
        if track.kind == "curves" and (track.arrays[0] in listed) != (track.arrays[1] in listed):
            return f"header.chunked: {track.arrays[0]} and {track.arrays[1]} go together"
        if track.kind == "curves" and track.arrays[0] in listed and header.get(track.key) is None:
            return f"header.chunked: {track.arrays[0]} is not recorded (header.{track.key} null)"
    return None


STEP = 1e-4  # m: the step curves' points are stored in (`quantise`): at most 0.05 mm off
QUANTISED = np.dtype("<i8")


def quantised_names(header: dict[str, object]) -> tuple[str, ...]:
    """The chunked arrays stored quantised (`header["quantised"]`: name -> step)."""
    quantised = header.get("quantised")
    return tuple(quantised) if isinstance(quantised, dict) else ()  # sound: a dict or absent


def curves_points(header: dict[str, object]) -> list[str]:
    """The points arrays of the take's curves tracks (world metres, every frame)."""
    return [t.arrays[0] for t in tracks_of(header) if t.kind == "curves"]


def quantise(values: np.ndarray, step: float) -> np.ndarray:
    """Positions (frames, ...) as whole steps, each frame after the first as its change
    from the frame before (small numbers: they deflate to a quarter of the floats)."""
    steps = np.rint(np.asarray(values, dtype=np.float64) / step).astype(QUANTISED)
    steps[1:] -= steps[:-1].copy()
    return steps


def dequantise(steps: np.ndarray, step: float) -> np.ndarray:
    """`quantise`'s positions back (float32), within half a step."""
    return (np.cumsum(steps, axis=0) * step).astype(np.float32)


def quantised_problem(header: dict[str, object]) -> str | None:
    """The first problem of `header["quantised"]`, or None."""
    listed = header.get("quantised")
    if listed is None:
        return None
    allowed = set(curves_points(header)) & set(chunked_names(header))
    if not isinstance(listed, dict) or not set(listed) <= allowed:
        return (
            f"header.quantised: names the chunked curves' points of this take, of {sorted(allowed)}"
        )
    for name, step in listed.items():
        if isinstance(step, bool) or not isinstance(step, float) or not 1e-7 <= step <= 1e-3:
            return f"header.quantised.{name}: a step in metres in [1e-07, 0.001], got {step!r}"
    return None


def chunk_frames(frame_bytes: int) -> int:
    """Frames per chunk when a frame of the chunked arrays is `frame_bytes`."""
    return max(1, min(MAX_CHUNK_FRAMES, CHUNK_BYTES // max(frame_bytes, 1)))


def chunk_count(frames: int, per_chunk: int) -> int:
    """How many chunks hold `frames` frames."""
    return math.ceil(frames / per_chunk)


def entry_name(name: str, chunk: int) -> str:
    """The zip entry of chunk `chunk` of array `name`."""
    return f"{name}.{chunk:06d}.npy"


def npy_bytes(array: np.ndarray) -> bytes:
    """`array` as the bytes of a `.npy` file."""
    buffer = io.BytesIO()
    np.lib.format.write_array(buffer, np.ascontiguousarray(array), allow_pickle=False)
    return buffer.getvalue()


def add_entry(archive: zipfile.ZipFile, name: str, data: bytes) -> None:
    """Store `data` as entry `name`, deflated, dated 1980-01-01, mode 0644 (so equal
    takes are equal bytes)."""
    info = zipfile.ZipInfo(name, date_time=_EPOCH)
    info.compress_type = zipfile.ZIP_DEFLATED
    info.create_system = 3  # unix, whatever the writing platform
    info.external_attr = 0o644 << 16
    archive.writestr(info, data, compress_type=zipfile.ZIP_DEFLATED, compresslevel=LEVEL)


def pad_items(chunk: np.ndarray, items: int, later: np.ndarray | None) -> np.ndarray:
    """`chunk` (frames, some items, ...) widened to `items`, the missing ones holding
    `later` (their values at the first frame that holds them: (missing, ...))."""
    have = chunk.shape[1]
    if have == items:
        return chunk
    out = np.empty((chunk.shape[0], items, *chunk.shape[2:]), chunk.dtype)
    out[:, :have] = chunk
    out[:, have:] = later if later is not None else 0
    return out


def frame_bytes(
    shapes: dict[str, tuple[int, ...]], dtypes: Mapping[str, np.dtype[np.generic]]
) -> int:
    """Bytes of one frame of the chunked arrays among `shapes`."""
    return sum(
        math.prod(shape[1:]) * np.dtype(dtypes[name]).itemsize
        for name, shape in shapes.items()
        if name in dtypes
    )
