"""Reading a version 2 take's chunks: which entries it must hold, each checked as read.

`Layout` works out from a checked header which arrays are stored in chunks
(`ecs_tentacles.take.chunks`) and which whole, refuses unknown or missing entries and
a take whose reader would decode more than `max_bytes` at once, and reads single
entries and chunks with their shapes checked against the header. `read_whole` joins
the chunks, fills in replayed creatures' poses (`take.replay`) and checks the numbers:
the whole-take path of `read_take`.
"""

from __future__ import annotations

import zipfile
from typing import Any

import numpy as np

from ecs_tentacles.take import chunks
from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take import replay as take_replay
from ecs_tentacles.take import roster as take_roster
from ecs_tentacles.take.entries import _npy_header, data_problem, read_npy
from ecs_tentacles.take.header import MAX_COORDINATE, TakeError, array_dtypes, expected_shapes
from ecs_tentacles.take.tracks import tracks_of


class Layout:
    """The version 2 layout of an open archive: which entries, their checked shapes."""

    def __init__(self, archive: zipfile.ZipFile, header: dict[str, Any], max_bytes: int):
        self.archive, self.header = archive, header
        frames, per = header["frames"], header.get("chunk_frames")
        if per is None:
            raise TakeError("header.chunk_frames: missing (a version 2 file stores chunks)")
        self.per_chunk = per
        self.count = chunks.chunk_count(frames, per)
        self.chunked = chunks.chunked_names(header)
        self.dtypes = array_dtypes(header)
        self.quantised: dict[str, float] = dict(header.get("quantised") or {})
        self.curves = {t.arrays[0]: t for t in tracks_of(header) if t.kind == "curves"}
        listed = [entry.filename for entry in archive.infolist()]
        names = set(listed)
        single = [n for n in self.dtypes if n not in self.chunked and n != "header"]
        optional = {a for t in self.curves.values() if header[t.key] is None for a in t.arrays}
        for track in self.curves.values():
            for name in track.arrays:
                entry = chunks.entry_name(name, 0) if name in self.chunked else f"{name}.npy"
                if (entry in names) != (header[track.key] is not None):
                    raise TakeError(f"{name}: present only when header.{track.key} is")
        self.singles = [n for n in single if n not in optional]
        known = {"header.npy", *(f"{n}.npy" for n in self.singles)}
        known |= {chunks.entry_name(n, k) for n in self.chunked if n not in optional
                  for k in range(self.count)}  # fmt: skip
        for name in (n for n in listed if n not in known):
            raise TakeError(f"unknown entry {name!r} (not an array of this take)")
        for name in sorted(known - names):
            raise TakeError(f"{name.removesuffix('.npy')}: missing")
        self.points = self._curve_points()
        self.shapes = expected_shapes(header, self.points)
        self.frame_singles = frame_arrays(header) & set(self.singles)
        self.frame_bytes = chunks.frame_bytes(
            {n: self.shapes[n] for n in (*self.chunked, *self.frame_singles)}, self.dtypes
        )
        chunked_frame = chunks.frame_bytes({n: self.shapes[n] for n in self.chunked}, self.dtypes)
        self.still_bytes = sum(
            int(np.prod(self.shapes[n])) * self.dtypes[n].itemsize
            for n in self.singles
            if n not in self.frame_singles
        )
        at_once = (
            min(per, frames) * chunked_frame
            + (self.frame_bytes - chunked_frame) * frames
            + self.still_bytes
        )
        if at_once > max_bytes:
            raise TakeError(
                f"a chunk of {min(per, frames)} frames would decode to {at_once} bytes,"
                f" over the {max_bytes} limit"
            )
        self.items = {n: self.shapes[n][1] for n in self.chunked}

    def _curve_points(self) -> dict[str, int]:
        """Points per curve of each recorded curves track, from its stored shape."""
        points = {}
        for name, track in self.curves.items():
            if self.header[track.key] is None:
                continue
            entry = chunks.entry_name(name, 0) if name in self.chunked else f"{name}.npy"
            with self.archive.open(entry) as handle:
                stored, _, _ = _npy_header(handle, name)
            if len(stored) != 4 or stored[2] < 2 or stored[3] != 3:
                raise TakeError(
                    f"{name}: shape {tuple(stored)}, expected (frames, curves, points >= 2, 3)"
                )
            points[name] = int(stored[2])
        return points

    def single(self, name: str) -> np.ndarray:
        shape = self.shapes[name]

        def check(stored: tuple[int, ...]) -> str | None:
            return None if stored == shape else f"shape {stored}, expected {shape} from the header"

        return read_npy(self.archive, f"{name}.npy", name, self.dtypes[name], check)

    def chunk(self, name: str, k: int, at_least: int) -> np.ndarray:
        """Chunk `k` of `name`, its items between `at_least` and the header's."""
        frames = min(self.per_chunk, self.header["frames"] - k * self.per_chunk)
        full = self.shapes[name]

        def check(stored: tuple[int, ...]) -> str | None:
            if (
                len(stored) != len(full)
                or stored[0] != frames
                or stored[2:] != full[2:]
                or not at_least <= stored[1] <= full[1]
            ):
                return (
                    f"shape {stored}, expected ({frames}, {at_least}..{full[1]},"
                    f" {', '.join(map(str, full[2:]))}) from the header"
                ).replace(", )", ")")
            return None

        label = f"{name} chunk {k}"
        step = self.quantised.get(name)
        dtype = self.dtypes[name] if step is None else chunks.QUANTISED
        value = read_npy(self.archive, chunks.entry_name(name, k), label, dtype, check)
        if step is None:
            return value
        if value.size and np.abs(value).max() > 2 * MAX_COORDINATE / step:  # before summing
            raise TakeError(f"{label}: a step beyond {MAX_COORDINATE:g} m")
        return chunks.dequantise(value, step)


def read_whole(
    archive: zipfile.ZipFile, header: dict[str, Any], max_bytes: int
) -> dict[str, np.ndarray]:
    """Every array of a version 2 archive, chunks joined and replayed poses filled in
    (`read_take`'s version 2 path): at most `max_bytes` decoded in all."""
    layout = Layout(archive, header, max_bytes)
    total = layout.frame_bytes * header["frames"] + layout.still_bytes
    if total > max_bytes:
        raise TakeError(f"header implies {total} bytes of arrays, over the {max_bytes} limit")
    out = {name: layout.single(name) for name in layout.singles}
    clips = {
        i: out[take_replay.clip_array(i)]
        for i in range(len((header.get(take_replay.KEY) or {}).get("clips", [])))
    }
    for name in layout.chunked:
        whole = np.empty(layout.shapes[name], layout.dtypes[name])
        least = 0
        starts = []
        for k in range(layout.count):
            value = layout.chunk(name, k, least)
            least = value.shape[1]
            first = k * layout.per_chunk
            whole[first : first + len(value), : value.shape[1]] = value
            starts.append((first, len(value), value.shape[1]))
        for first, n, have in reversed(starts):  # items not there yet: their first values
            if have < whole.shape[1]:
                whole[first : first + n, have:] = whole[first + n, have:]
        out[name] = whole
    problem = take_replay.values_problem(header, out) or take_ground.index_problem(header, out)
    if problem:
        raise TakeError(problem)
    if header.get(take_replay.KEY) is not None:
        take_replay.fill(header, clips, out, out["pos"], out["quat"])
    tracks = tracks_of(header)
    checked = {n: a for n, a in out.items() if n not in take_replay.PER_FRAME}
    problem = data_problem(checked, tracks)
    if problem:
        raise TakeError(problem)
    return out


def frame_arrays(header: dict[str, object]) -> set[str]:
    """The arrays of a take besides bodies and suckers that have a frames axis: the
    tracks' per-frame arrays, the roster's, the replay records."""
    out = set(take_replay.PER_FRAME) | {take_roster.ARRAY}
    for track in tracks_of(header):
        out |= set(track.arrays) if track.kind == "curves" else {track.arrays[1]}
    return out
