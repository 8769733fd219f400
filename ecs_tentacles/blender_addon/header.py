"""A take's header checked for what the add-on reads of it (numpy and the standard
library only): the format and version, the timing, the creatures and the bodies' sizes,
and version 2's chunks and replay clips (`ecs_tentacles.take.format`; TAKE2's
`header.replay`). `check(header)` returns a `Header` or raises `TakeFileError` with one
line naming the field (`header.creatures[3].name: ...`).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import TypeGuard

import numpy as np

FORMAT = "ecs_tentacles.take"
VERSIONS = (1, 2, 3)
MAX_FRAMES = 1_000_000
MAX_BODIES = 16384 * 1025
MAX_FPS = 1000
KINDS = 2  # replay kinds: 0 idle, 1 crawl
# a version 2 take's arrays stored in chunks when its header does not list them
CHUNKED = ("pos", "quat", "sucker_attached", "sucker_anchor")
REPLAYED = ("replay_kind", "replay_phase", "replay_xy", "replay_heading")
NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")  # a creature's name, as the project checks it


class TakeFileError(ValueError):
    """A take cannot be imported; the message is one line naming the file and the field."""

    def __init__(self, message: str) -> None:
        super().__init__(" ".join(message.split()))


@dataclass(frozen=True)
class Creature:
    """One creature as the header lists it: `bodies` its take body indices, mantle first
    then the links tentacle by tentacle (the joints' order), `links` per tentacle."""

    name: str
    bodies: np.ndarray
    links: tuple[int, ...]


@dataclass(frozen=True)
class Clip:
    """A replay clip (`header.replay.clips[i]`): `bodies` per pose, seconds per clip frame,
    frames of each kind (idle, crawl)."""

    bodies: int
    dt: float
    frames: tuple[int, int]


@dataclass(frozen=True)
class Header:
    """What the import reads of a sound header. `chunk_frames`: frames an entry of a
    version 2 take holds (version 1: all of them); `replayed`: each creature's clip
    index (-1: never replayed); `roster`: creatures come and go (`creature_visible`);
    `chunked`: the arrays stored in chunks (version 1: none)."""

    version: int
    fps: float
    frames: int
    chunk_frames: int
    bodies: int
    creatures: list[Creature]
    clips: list[Clip]
    replayed: np.ndarray
    roster: bool
    chunked: tuple[str, ...]


def _number(value: object) -> TypeGuard[int | float]:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return False
    return math.isfinite(value) and abs(value) < 1e300


def _whole(value: object) -> TypeGuard[int]:
    return isinstance(value, int) and not isinstance(value, bool)


def check(header: object) -> Header:
    """The checked header (see the module); `TakeFileError` (one line) if it is unsound."""
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        raise TakeFileError(f"header.format: expected {FORMAT!r}")
    version = header.get("version")
    if version not in VERSIONS:
        raise TakeFileError(f"header.version: this add-on reads versions 1 to 3, got {version!r}")
    fps = header.get("fps")
    if not _number(fps) or not 0 < fps <= MAX_FPS:
        raise TakeFileError(f"header.fps: must be a number in (0, {MAX_FPS}], got {fps!r}")
    frames = header.get("frames")
    if not _whole(frames) or not 1 <= frames <= MAX_FRAMES:
        raise TakeFileError(
            f"header.frames: must be a whole number in [1, {MAX_FRAMES}], got {frames!r}"
        )
    chunk_frames = frames
    if version >= 2:
        chunk = header.get("chunk_frames")
        if not _whole(chunk) or chunk < 1:
            raise TakeFileError(f"header.chunk_frames: must be a whole number >= 1, got {chunk!r}")
        chunk_frames = chunk
    bodies = header.get("bodies")
    if not isinstance(bodies, list) or len(bodies) > MAX_BODIES:
        raise TakeFileError(f"header.bodies: must be a list of at most {MAX_BODIES}")
    for b, body in enumerate(bodies):
        if not isinstance(body, dict) or not all(
            _number(body.get(k)) and 0 < body[k] <= 1e4 for k in ("radius", "length")
        ):
            raise TakeFileError(
                f"header.bodies[{b}]: radius and length must be numbers in (0, 10000] m"
            )
    creatures = _creatures(header.get("creatures"), len(bodies))
    replay = header.get("replay") if version >= 2 else None
    clips, replayed = _replay(replay, creatures)
    roster = header.get("roster") is not None
    chunked = _chunked(header.get("chunked"), replay is not None) if version >= 2 else ()
    return Header(int(version), float(fps), frames, chunk_frames, len(bodies), creatures, clips,
                  replayed, roster, chunked)  # fmt: skip


def _chunked(listed: object, replay: bool) -> tuple[str, ...]:
    """The arrays a version 2 take stores in chunks: `header.chunked`, or without it the
    bodies, suckers and (with replayed creatures) the replay records."""
    if listed is None:
        return CHUNKED + (REPLAYED if replay else ())
    if not isinstance(listed, list) or not all(isinstance(n, str) for n in listed):
        raise TakeFileError("header.chunked: must be a list of array names")
    if not set(CHUNKED[:2]) <= set(listed):
        raise TakeFileError("header.chunked: must hold pos and quat")
    return tuple(listed)


def _creatures(creatures: object, bodies: int) -> list[Creature]:
    if not isinstance(creatures, list) or not creatures:
        raise TakeFileError("header.creatures: must be a non-empty list")
    used: set[int] = set()
    names: set[str] = set()
    out = []
    for c, entry in enumerate(creatures):
        where = f"header.creatures[{c}]"
        if not isinstance(entry, dict):
            raise TakeFileError(f"{where}: not an object")
        name = entry.get("name")
        if not isinstance(name, str) or not NAME.fullmatch(name) or name in names:
            raise TakeFileError(f"{where}.name: must be a unique identifier, got {name!r}")
        names.add(name)
        chains = entry.get("tentacles")
        if not isinstance(chains, list) or not chains or not all(
            isinstance(k, list) and k for k in chains
        ):  # fmt: skip
            raise TakeFileError(f"{where}.tentacles: must be a non-empty list of non-empty lists")
        indices = [entry.get("mantle"), *(i for chain in chains for i in chain)]
        for index in indices:
            if not _whole(index) or not 0 <= index < bodies or index in used:
                raise TakeFileError(f"{where}: body index {index!r} is out of range or used twice")
            used.add(index)
        out.append(Creature(name, np.array(indices, np.int64), tuple(len(k) for k in chains)))
    return out


def _replay(replay: object, creatures: list[Creature]) -> tuple[list[Clip], np.ndarray]:
    """The clips and each creature's clip index (-1: never replayed)."""
    if replay is None:
        return [], np.full(len(creatures), -1, np.int64)
    if not isinstance(replay, dict):
        raise TakeFileError("header.replay: must be null or an object")
    clips = replay.get("clips")
    if not isinstance(clips, list):
        raise TakeFileError("header.replay.clips: must be a list")
    out = []
    for i, clip in enumerate(clips):
        where = f"header.replay.clips[{i}]"
        if not isinstance(clip, dict):
            raise TakeFileError(f"{where}: not an object")
        bodies, dt, frames = clip.get("bodies"), clip.get("dt"), clip.get("frames")
        if not _whole(bodies) or not 1 <= bodies <= MAX_BODIES:
            raise TakeFileError(f"{where}.bodies: must be a whole number >= 1, got {bodies!r}")
        if not _number(dt) or not dt > 0:
            raise TakeFileError(f"{where}.dt: must be a number > 0, got {dt!r}")
        if not isinstance(frames, list) or len(frames) != KINDS or not all(
            _whole(f) and 1 <= f <= MAX_FRAMES for f in frames
        ):  # fmt: skip
            raise TakeFileError(f"{where}.frames: must be [idle, crawl] frame counts >= 1")
        out.append(Clip(bodies, float(dt), (frames[0], frames[1])))
    owners = replay.get("creatures")
    if not isinstance(owners, list) or len(owners) != len(creatures):
        raise TakeFileError("header.replay.creatures: must hold a clip index per creature")
    for c, clip in enumerate(owners):
        where = f"header.replay.creatures[{c}]"
        if not _whole(clip) or not -1 <= clip < len(out):
            raise TakeFileError(f"{where}: must be a clip index or -1, got {clip!r}")
        if clip >= 0 and out[clip].bodies != len(creatures[c].bodies):
            raise TakeFileError(
                f"{where}: clip {clip} poses {out[clip].bodies} bodies, the creature has"
                f" {len(creatures[c].bodies)}"
            )
    return out, np.array(owners, np.int64)
