"""Takes: every frame of a simulation in one compact, reproducible npz file.

A take holds, per frame, the pose of every mantle and link, the state of every
sucker, and the tracks the world's plugins add (`ecs_tentacles.take.tracks`): the
goals still to reach (points, from locomotion) and, when the world has fur, the guide
curves (curves, from fur), plus any track a plugin declares. The header (JSON) names
everything and carries the geometry, so exporters (USD, glTF) need nothing but the take.

The file is a zip of `.npy` arrays (`np.load(path)` opens it), every entry dated
1980-01-01 and deflated, so the same scene and seed give byte-identical files. Version 3
(what is written) stores the header's bodies and suckers once per body plan
(`ecs_tentacles.take.compact`: standard library only, `unpack(header)` lists them; a
crowd of 10,000 creatures of one plan names its 810,000 bodies in 2 MB, not 121 MiB);
otherwise it is version 2, which stores the arrays that grow with the shot in chunks of frames,
written as a bake goes (`ecs_tentacles.take.chunks`: entry `pos.000003.npy` holds frames
3C..4C-1 of `pos`, C = `header["chunk_frames"]`), the others whole:

    pos              float32  (frames, bodies, 3)  body centres, metres, z up   chunked
    quat             float32  (frames, bodies, 4)  body orientations (w, x, y, z) chunked
    sucker_attached  bool     (frames, suckers)                                  chunked
    sucker_anchor    float32  (frames, suckers, 3) world anchor (kept after release) chunked
    replay_*         a replayed creature's clip, phase and root motion per frame  chunked
                     (`ecs_tentacles.take.replay`; its bodies are zeros in pos/quat)
    guide_points     float32  (frames, guides, points, 3)   the standard curves track,
    guide_widths     float32  (frames, guides, points)      only when guides are recorded
                     (chunked when recording when the first chunk was stored:
                     `header["chunked"]` lists every chunked array)
    goal_pos         float32  (goals, 3)                       the standard points track
    goal_active      bool     (frames, goals)      still in its creature's path
    ...              the arrays of the tracks `header.tracks` declares, in its order
    replay_clip_<i>  float64  a gait clip's frames, once per body plan
    ground_*         the terrain's meshes, on terrain (`ecs_tentacles.take.ground`)
    creature_visible bool     (frames, creatures)  only when creatures came or went
                                                   (`ecs_tentacles.take.roster`)
    header           uint8    UTF-8 JSON (see `Take.header`), last

Version 1 (every array one entry, header first, no replay records) and 2 files still read.
Readers decode a chunk at a time (`ecs_tentacles.take.stream.open_take`) or the whole
take (`Take.load`, replayed creatures' poses filled in); `MAX_TAKE_BYTES` caps what is
decoded at once, not the shot.

Frame i is simulated time i / fps; frame 0 is the pose the scene was built in.
Bodies: a mantle is a cylinder along its local +z (`length` = height), a link a
capsule along its local +x (`length` = the spine between the cap centres).
"""

from __future__ import annotations

import io
import os
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, BinaryIO

import numpy as np

from ecs_tentacles.ground import StaticMesh
from ecs_tentacles.take import chunks, compact
from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take import replay as take_replay
from ecs_tentacles.take import roster as take_roster
from ecs_tentacles.take.read import (
    FORMAT,
    MAX_HEADER_BYTES,
    MAX_TAKE_BYTES,
    VERSION,
    TakeError,
    data_problem,
    expected_shapes,
    header_problem,
    read_take,
)
from ecs_tentacles.take.tracks import CORE_ARRAYS, STANDARD, TakeTrack, tracks_of

# every array of a take without declared tracks, in file order
ARRAYS = CORE_ARRAYS + tuple(name for track in STANDARD for name in track.arrays)
__all__ = ["ARRAYS", "FORMAT", "VERSION", "Take", "TakeError", "TakeTrack", "write_npz"]
_EPOCH = (1980, 1, 1, 0, 0, 0)  # the earliest zip date: no wall-clock time in the file


@dataclass
class Take:
    """A recorded simulation: `header` (names, geometry, timing), per-frame body and
    sucker arrays, and `tracks` (every track's arrays by file name: `tracks["goal_pos"]`).

    `header` keys: format, version, scene, scene_sha256, seed, fps, sim_fps, substeps,
    frames, creatures [{name, mantle (body index), tentacles [[body index per link]]}],
    bodies [{name, creature, shape cylinder|capsule, axis, radius, length}],
    suckers [{name, body, offset (in the body's frame)}], health, and one key per track
    (`ecs_tentacles.take.tracks`): goals [{name, creature, radius}], guides (null, or
    {creatures: [creature index per guide]}); `tracks` lists declared tracks, if any;
    `ground` the terrain's and obstacles' meshes on terrain (`ecs_tentacles.take.ground`;
    their arrays are in `tracks` too, by file name: `ground_meshes()` gives them);
    `roster` when creatures came or went during the recording (`ecs_tentacles.take.roster`:
    `visible()` gives which creatures are there at each frame).
    """

    header: dict[str, Any]
    pos: np.ndarray
    quat: np.ndarray
    sucker_attached: np.ndarray
    sucker_anchor: np.ndarray
    tracks: dict[str, np.ndarray] = field(default_factory=dict)

    @classmethod
    def from_arrays(cls, header: dict[str, object], arrays: dict[str, np.ndarray]) -> Take:
        """A take from its header and arrays by file name (as `read_take` returns them);
        what the header says of the file's layout (its chunks) is left out."""
        layout = ("chunk_frames", "chunked", "quantised")
        header = {k: v for k, v in header.items() if k not in layout}
        core = {k: arrays[k] for k in CORE_ARRAYS[1:]}
        rest = {k: v for k, v in arrays.items() if k not in CORE_ARRAYS}
        return cls(header=header, **core, tracks=rest)

    # -- reading -----------------------------------------------------------------------
    @property
    def frames(self) -> int:
        """Number of frames (the first is time 0)."""
        return int(self.pos.shape[0])

    @property
    def fps(self) -> float:
        """Frames per second of the take."""
        return float(self.header["fps"])

    @property
    def times(self) -> np.ndarray:
        """Seconds of each frame."""
        return np.arange(self.frames) / self.fps

    @property
    def body_names(self) -> list[str]:
        """Body names in array order: `<creature>/mantle`, `<creature>/tentacles/t<k>/link<i>`."""
        return [body["name"] for body in self.header["bodies"]]

    def body(self, name: str) -> int:
        """Array index of the body called `name`."""
        try:
            return self.body_names.index(name)
        except ValueError:
            raise KeyError(f"no body named {name!r} in this take") from None

    def ground_meshes(self) -> list[tuple[str, StaticMesh]]:
        """(name, `StaticMesh`) of the ground's meshes (none on the plane)."""
        return take_ground.meshes_of(self.header, self.tracks)

    def ground_colours(self) -> dict[str, tuple[float, float, float]]:
        """Ground mesh name -> its display colour, where the take records one."""
        return take_ground.colours(self.header)

    def visible(self) -> np.ndarray:
        """(frames, creatures) bool: which creatures are there at each frame (all of them
        unless the roster changed while recording; `ecs_tentacles.take.roster`)."""
        return take_roster.visible(self.header, self.tracks)

    def track_list(self) -> list[TakeTrack]:
        """Every track of this take, in file order (`ecs_tentacles.take.tracks`)."""
        return tracks_of(self.header)

    def array(self, name: str) -> np.ndarray | None:
        """A body, sucker or track array by its file name (None: a track not recorded)."""
        if name in CORE_ARRAYS[1:]:
            value: np.ndarray = getattr(self, name)
            return value
        return self.tracks.get(name)

    def arrays(self) -> dict[str, np.ndarray]:
        """The arrays to store, in file order (the header encoded as UTF-8 JSON bytes)."""
        return {name: np.ascontiguousarray(value) for name, value in self._entries().items()}

    def _entries(self) -> dict[str, np.ndarray]:
        """`arrays()` as they are (not made contiguous: nothing copied)."""
        text = compact.header_text(self.header)
        out = {"header": np.frombuffer(text.encode(), dtype=np.uint8)}
        names = [*CORE_ARRAYS[1:], *(a for t in self.track_list() for a in t.arrays)]
        names += list(take_ground.dtypes(self.header))
        names += list(take_roster.dtypes(self.header))
        names += list(take_replay.dtypes(self.header))
        for name in names:
            value = self.array(name)
            if value is not None:
                out[name] = value
        return out

    def size_problem(self) -> str | None:
        """Why `read_take` would refuse this take for its size (one line), or None: the
        file's entries (each array's `.npy` header and data) over `MAX_TAKE_BYTES`, or
        its header over `MAX_HEADER_BYTES`. Counted from shapes: nothing is copied."""
        entries = self._entries()
        header = entries["header"].nbytes
        if header > MAX_HEADER_BYTES:
            return (
                f"header: {header / 1024**2:,.0f} MiB, over the {MAX_HEADER_BYTES / 1024**2:g}"
                " MiB a take's header holds"
            )
        at_once = self.decoded_at_once()
        if at_once > MAX_TAKE_BYTES:
            return (
                f"its {len(entries)} arrays would be {at_once:,} bytes to read at once, over"
                f" the {MAX_TAKE_BYTES:,} ({MAX_TAKE_BYTES / 1024**3:g} GiB) a take's reader"
                " decodes at once"
            )
        return None

    def decoded_at_once(self) -> int:
        """Bytes a reader of the saved file decodes at once (`take.stream`): a chunk of
        the chunked arrays (bodies, suckers, replay records) and every other array whole."""
        entries = self._entries()
        chunked = tuple(n for n in chunks.chunkable(self.header) if n in entries)
        frame = sum(entries[n][:1].nbytes for n in chunked)
        per = min(self.frames, chunks.chunk_frames(frame))
        rest = sum(v.nbytes for n, v in entries.items() if n not in chunked and n != "header")
        return per * frame + rest + entries["header"].nbytes

    def stored_bytes(self) -> int:
        """Bytes of the file's arrays before compression (what `save` tells its
        `progress` of). Counted from shapes: nothing copied."""
        return sum(value.nbytes for value in self._entries().values())

    # -- files -------------------------------------------------------------------------
    def save(
        self, path: str | os.PathLike[str], progress: Callable[[int], object] | None = None
    ) -> None:
        """Write the take to `path` atomically (see `ecs_tentacles.output.atomic`);
        `progress(n)` as n more bytes are stored (of `stored_bytes()`).

        Raises `TakeError` (one line, nothing written) when `Take.load` would refuse the
        result: a plugin that wrote NaN into the poses makes a take nobody can read."""
        problem = self.problem()
        if problem:
            raise TakeError(f"{path}: cannot write this take: {problem}")
        from ecs_tentacles.take.writer import TakeWriter

        entries = self._entries()
        del entries["header"]
        chunked = tuple(n for n in chunks.chunkable(self.header) if n in entries)
        header = {**self.header, "chunked": list(chunked)}
        per = chunks.chunk_frames(sum(entries[n][:1].nbytes for n in chunked))
        quantised = {n: chunks.STEP for n in chunks.curves_points(header) if n in chunked}
        with TakeWriter(path, per, progress, quantised) as writer:
            for first in range(0, self.frames, per):
                part = {n: entries[n][first : first + per] for n in chunked}
                writer.add_frames(take_replay.blanked(header, part))
            writer.finish(header, {n: a for n, a in entries.items() if n not in chunked})

    @classmethod
    def load(cls, path: str | os.PathLike[str], max_bytes: int = MAX_TAKE_BYTES) -> Take:
        """Read a take; raises `TakeError` (one line) when the file is not a sound take.

        Takes are untrusted input: see `ecs_tentacles.take.read` for every check
        (zip-bomb cap `max_bytes` on the uncompressed size, header, dtypes, shapes,
        finite values) made before the exporters see the data.
        """
        header, arrays = read_take(Path(path), max_bytes)
        return cls.from_arrays(header, arrays)

    @staticmethod
    def read_header(path: str | os.PathLike[str]) -> dict[str, Any]:
        """A take file's header alone, checked as `load` checks it (`TakeError`, one
        line), without reading a frame: what an exporter counts before any work."""
        header, _ = read_take(Path(path), header_only=True)
        return header

    def problem(self) -> str | None:
        """The first problem of this (in-memory) take, as `Take.load` would report it."""
        problem = header_problem(self.header) or self.size_problem()
        if problem:
            return problem
        tracks = self.track_list()
        points: dict[str, int] = {}
        for track in tracks:
            first = self.tracks.get(track.arrays[0])
            if track.kind == "curves" and (first is None) != (self.header[track.key] is None):
                return f"{track.arrays[0]}: present only when header.{track.key} is"
            if track.kind == "curves" and first is not None:
                points[track.arrays[0]] = first.shape[2] if first.ndim == 4 else -1
        known = {*CORE_ARRAYS, *(a for t in tracks for a in t.arrays)}
        known |= set(take_ground.dtypes(self.header)) | set(take_roster.dtypes(self.header))
        known |= set(take_replay.dtypes(self.header))
        unknown = sorted(set(self.tracks) - known)
        if unknown:
            return f"{unknown[0]}: not a track of this take"
        for name, shape in expected_shapes(self.header, points).items():
            value = self.array(name)
            if value is None or value.shape != shape:
                got = None if value is None else value.shape
                return f"{name}: shape {got}, expected {shape} from the header"
        arrays = {k: v for k, v in self.arrays().items() if k != "header"}
        return data_problem(arrays, tracks) or take_ground.index_problem(self.header, arrays)

    def check_exportable(self, path: str | os.PathLike[str]) -> None:
        """Raise `TakeError` (one line) unless exporters can write this take to `path`."""
        problem = self.problem()
        if problem:
            raise TakeError(f"{path}: cannot export this take: {problem}")


def _npy_bytes(array: np.ndarray) -> int:
    """Bytes of `array` as a `.npy` file: its header (as `write_array` makes it) and data."""
    fields = np.lib.format.header_data_from_array_1_0(array)
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(buffer, fields)
    return buffer.tell() + array.nbytes


def write_npz(
    path: str | os.PathLike[str] | BinaryIO,
    arrays: dict[str, np.ndarray],
    progress: Callable[[int], object] | None = None,
) -> None:
    """Write `arrays` as an npz readable by `np.load`, byte-reproducibly; `progress(n)`
    as n more bytes are stored (numpy writes an array in pieces of 16 MiB).

    `np.savez` stamps each zip entry with the current time; here every entry gets the
    same fixed date and permissions, in the order of `arrays`.
    """
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED, allowZip64=True) as zf:
        for name, array in arrays.items():
            info = zipfile.ZipInfo(f"{name}.npy", date_time=_EPOCH)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.create_system = 3  # unix, whatever the writing platform
            info.external_attr = 0o644 << 16
            with zf.open(info, "w", force_zip64=True) as out:
                told = out if progress is None else _Told(out, progress)
                np.lib.format.write_array(told, np.asanyarray(array), allow_pickle=False)


class _Told:
    """A file being written that tells `progress(n)` of every n bytes written to it."""

    def __init__(self, out: IO[bytes], progress: Callable[[int], object]) -> None:
        self.out, self.progress = out, progress

    def write(self, data: bytes) -> int:
        written = self.out.write(data)
        self.progress(len(data))
        return written
