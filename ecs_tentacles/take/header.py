"""A take's header checked as untrusted input, and the arrays it implies.

`header_problem(header)` gives the first problem of a header as one line
(`header.<path>: <what>`): the format and version, the timing, creatures, bodies,
suckers and every track with the names, indices and numbers the exporters need, the
ground's meshes and the roster; `expected_shapes` and `array_dtypes` give the shape and
dtype of every array a take with a sound header holds. Reads nothing from disk: the
archive is `ecs_tentacles.take.read`'s.
"""

from __future__ import annotations

import math
import re
import sys
from typing import Any, cast

import numpy as np

from ecs_tentacles.take import ground as take_ground
from ecs_tentacles.take import replay as take_replay
from ecs_tentacles.take import roster as take_roster
from ecs_tentacles.take.tracks import TakeTrack, declared_problem, dtypes, tracks_of

MAX_TAKE_BYTES = 2 * 1024**3  # uncompressed; a 10 s bake of 4 creatures is ~30 MB
MAX_HEADER_BYTES = 64 * 1024**2
MAX_FPS = 1000  # the scene schema's and `bake --fps`'s highest rate
MAX_COORDINATE = 1e6  # metres: a position farther out is a blow-up, not a creature
MAX_FRAMES = 1_000_000  # 4.6 hours at 60 fps: frames are bounded even with no bodies
MAX_BODIES = 16384 * 1025  # the schema's most creatures x the bodies of its largest one
FORMAT = "ecs_tentacles.take"
VERSION = 3  # what is written: version 2 with bodies stored per body plan (`take.compact`)
VERSIONS = (1, 2, 3)  # version 1: no chunks, no replay records; both still read
CORE_DTYPES: dict[str, np.dtype[np.generic]] = {
    "header": np.dtype(np.uint8),
    "pos": np.dtype("<f4"),
    "quat": np.dtype("<f4"),
    "sucker_attached": np.dtype(np.bool_),
    "sucker_anchor": np.dtype("<f4"),
}
AXES = ("X", "Y", "Z")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class TakeError(ValueError):
    """A take file cannot be read; the message is one line naming the file and the problem."""

    def __init__(self, message: str) -> None:
        super().__init__(" ".join(message.split()))  # one line, whatever a library said


def _is_int(value: object) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _is_number(value: object) -> bool:
    """A finite number a float can hold (an int too large for one is not)."""
    if isinstance(value, float):
        return math.isfinite(value)
    return _is_int(value) and abs(cast(int, value)) <= sys.float_info.max


def _index(value: object, size: int) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and 0 <= value < size


def _list_of_dicts(header: dict[str, object], key: str) -> str | None:
    value = header.get(key)
    if not isinstance(value, list):
        return f"header.{key}: missing or not a list"
    for i, item in enumerate(value):
        if not isinstance(item, dict):
            return f"header.{key}[{i}]: not an object"
    return None


def _creature_problem(creatures: list[dict[str, object]], bodies: int) -> str | None:
    used: set[int] = set()
    names: set[str] = set()
    for c, creature in enumerate(creatures):
        where = f"header.creatures[{c}]"
        name = creature.get("name")
        if not isinstance(name, str) or not _NAME.fullmatch(name) or name in names:
            return f"{where}.name: must be a unique identifier (letters, digits, _), got {name!r}"
        names.add(name)
        chains = creature.get("tentacles")
        if not isinstance(chains, list) or not all(isinstance(k, list) for k in chains):
            return f"{where}.tentacles: must be a list of lists of body indices"
        if not chains:  # the exporters' skeletons need a tentacle of a link at least
            return f"{where}.tentacles: a creature needs at least one tentacle, got 0"
        empty = next((k for k, chain in enumerate(chains) if not chain), None)
        if empty is not None:
            return f"{where}.tentacles[{empty}]: a tentacle needs at least one link, got 0"
        for index in [creature.get("mantle"), *(i for chain in chains for i in chain)]:
            if not _index(index, bodies) or index in used:
                return f"{where}: body index {index!r} is out of range or used twice"
            used.add(index)
    return None


def _body_problem(header: dict[str, Any]) -> str | None:
    creatures = header["creatures"]
    for b, body in enumerate(header["bodies"]):
        where = f"header.bodies[{b}]"
        owner = body.get("creature")
        if not _index(owner, len(creatures)):
            return f"{where}.creature: must be a creature index, got {owner!r}"
        pattern = rf"^{creatures[owner]['name']}/(mantle|tentacles/t\d+/link\d+)$"
        if not isinstance(body.get("name"), str) or not re.fullmatch(pattern, body["name"]):
            return f"{where}.name: must be <creature>/mantle or .../tentacles/t<k>/link<i>"
        if body.get("shape") not in ("cylinder", "capsule") or body.get("axis") not in AXES:
            return f"{where}: shape must be cylinder or capsule, axis X, Y or Z"
        if not all(_is_number(body.get(k)) and 0 < body[k] <= 1e4 for k in ("radius", "length")):
            return f"{where}: radius and length must be numbers in (0, 10000] m"
    names = [body["name"] for body in header["bodies"]]
    if len(set(names)) != len(names):
        return "header.bodies: two bodies have the same name"
    return None


def _parts_problem(header: dict[str, Any]) -> str | None:
    bodies = header["bodies"]
    for s, sucker in enumerate(header["suckers"]):
        where = f"header.suckers[{s}]"
        if not _index(sucker.get("body"), len(bodies)):
            return f"{where}.body: must be a body index, got {sucker.get('body')!r}"
        pattern = rf"^{re.escape(bodies[sucker['body']]['name'])}/sucker\d+$"
        if not isinstance(sucker.get("name"), str) or not re.fullmatch(pattern, sucker["name"]):
            return f"{where}.name: must be <body>/sucker<n>"
        offset = sucker.get("offset")
        if not isinstance(offset, list) or len(offset) != 3 or not all(map(_is_number, offset)):
            return f"{where}.offset: must be 3 finite numbers"
    names = [item["name"] for item in header["suckers"]]
    if len(set(names)) != len(names):
        return "header.suckers: two have the same name"
    for track in tracks_of(header):
        problem = _track_problem(header, track)
        if problem:
            return problem
    return None


def _track_problem(header: dict[str, Any], track: TakeTrack) -> str | None:
    """The first problem of a track's header entry (`take_tracks` describes both kinds)."""
    creatures, key = header["creatures"], track.key
    if track.kind == "curves":
        curves = header.get(key)
        if curves is None:
            return None
        owners = curves.get("creatures") if isinstance(curves, dict) else None
        if not isinstance(owners, list) or not all(
            _is_int(o) and -1 <= o < len(creatures) for o in owners
        ):
            return f"header.{key}.creatures: must be a list of creature indices (or -1)"
        return None
    problem = _list_of_dicts(header, key)
    if problem:
        return problem
    for i, item in enumerate(header[key]):
        where = f"header.{key}[{i}]"
        if not _index(item.get("creature"), len(creatures)):
            return f"{where}.creature: must be a creature index, got {item.get('creature')!r}"
        stem = f"{track.folder}/{track.item}"
        pattern = rf"^{creatures[item['creature']]['name']}/{stem}\d+$"
        if not isinstance(item.get("name"), str) or not re.fullmatch(pattern, item["name"]):
            return f"{where}.name: must be <creature>/{stem}<n>"
        if not _is_number(item.get("radius")) or not 0 <= item["radius"] <= MAX_COORDINATE:
            return f"{where}.radius: must be a number in [0, {MAX_COORDINATE:g}] m"
    names = [item["name"] for item in header[key]]
    if len(set(names)) != len(names):
        return f"header.{key}: two have the same name"
    return None


def header_problem(header: object) -> str | None:
    """The first problem of a take header as a one-line `header.<path>: <what>`, or None."""
    if not isinstance(header, dict) or header.get("format") != FORMAT:
        return f"header.format: expected {FORMAT!r}"
    version = header.get("version")
    from ecs_tentacles.take import chunks  # imports the tracks, as this module does

    if isinstance(version, bool) or version not in VERSIONS:
        return f"header.version: this reader knows versions 1 to 3, got {version!r}"
    fps = header.get("fps")
    if not _is_number(fps) or not isinstance(fps, int | float) or not 0 < fps <= MAX_FPS:
        return f"header.fps: must be a number in (0, {MAX_FPS}], got {fps!r}"
    if not _is_int(header.get("frames")) or header["frames"] < 1:
        return f"header.frames: must be a whole number >= 1, got {header.get('frames')!r}"
    if header["frames"] > MAX_FRAMES:
        return f"header.frames: at most {MAX_FRAMES} in a take, got {header['frames']}"
    if version >= 2:  # absent in memory: the file's writer sets it
        chunk = header.get("chunk_frames", 1)
        if not _is_int(chunk) or not 1 <= chunk <= MAX_FRAMES:
            return (
                f"header.chunk_frames: must be a whole number in [1, {MAX_FRAMES}], got {chunk!r}"
            )
    elif header.get(take_replay.KEY) is not None:
        return f"header.{take_replay.KEY}: version 1 takes record no replayed creatures"
    for key, check in (("scene", str), ("scene_sha256", str)):
        if not isinstance(header.get(key), check):
            return f"header.{key}: missing or not a string"
    if not _is_int(header.get("seed")):
        return "header.seed: missing or not a whole number"
    for key in ("creatures", "bodies", "suckers"):
        problem = _list_of_dicts(header, key)
        if problem:
            return problem
        if len(header[key]) > MAX_BODIES:
            return f"header.{key}: at most {MAX_BODIES} in a take, got {len(header[key])}"
    return (
        declared_problem(header)
        or _creature_problem(header["creatures"], len(header["bodies"]))
        or _body_problem(header)
        or _parts_problem(header)
        or take_ground.problem(header)
        or take_roster.problem(header)
        or take_replay.problem(header)
        or (chunks.chunked_problem(header) if version >= 2 else None)
        or (chunks.quantised_problem(header) if version >= 2 else None)
    )


def expected_shapes(
    header: dict[str, Any], points: dict[str, int] | None = None
) -> dict[str, tuple[int, ...]]:
    """Array name -> shape implied by a sound header (curves' points per curve: from
    `points`, by the curves' first array name; curves not in it are left out)."""
    frames, bodies, suckers = header["frames"], len(header["bodies"]), len(header["suckers"])
    shapes: dict[str, tuple[int, ...]] = {
        "pos": (frames, bodies, 3),
        "quat": (frames, bodies, 4),
        "sucker_attached": (frames, suckers),
        "sucker_anchor": (frames, suckers, 3),
    }
    points = points or {}
    for track in tracks_of(header):
        first, second = track.arrays
        if track.kind == "points":
            items = len(header[track.key])
            shapes[first], shapes[second] = (items, 3), (frames, items)
        elif header.get(track.key) is not None and first in points:
            curves = len(header[track.key]["creatures"])
            shapes[first] = (frames, curves, points[first], 3)
            shapes[second] = (frames, curves, points[first])
    shapes.update(take_ground.shapes(header))
    shapes.update(take_roster.shapes(header))
    shapes.update(take_replay.shapes(header))
    return shapes


def array_dtypes(header: dict[str, object]) -> dict[str, np.dtype[np.generic]]:
    """Every array a take with this (sound) header may hold -> its dtype, in file order."""
    out = dict(CORE_DTYPES)
    for track in tracks_of(header):
        for name, dtype in zip(track.arrays, dtypes(track), strict=True):
            out[name] = np.dtype(dtype)
    out.update(take_ground.dtypes(header))
    out.update(take_roster.dtypes(header))
    out.update(take_replay.dtypes(header))
    return out
