"""Take tracks: what plugins add to a take beyond bodies and suckers.

A track is named per-frame data of one of two kinds, each stored as two arrays:

    points   locators that appear, stay where they first appeared and show while live
             header[key]  [{name "<creature>/<folder>/<item><n>", creature, radius}]
             arrays[0]    float32 (items, 3)          position, metres
             arrays[1]    bool    (frames, items)     live (visible) at that frame
    curves   polylines posed every frame (USD: BasisCurves `<c>/<c>_<folder>/<c>_<item>`)
             header[key]  null, or {creatures: [creature index per curve, or -1]}
             arrays[0]    float32 (frames, curves, points, 3)   world metres
             arrays[1]    float32 (frames, curves, points)      widths, metres
             (both arrays are in the file only when header[key] is not null)

Version 1 takes always hold the two tracks of `STANDARD` (`version1.json`, the file
format's data), in that order after the body and sucker arrays: `goals` (points; the
locomotion plugin fills it) and `guides` (curves; the fur plugin's guide curves). A
take recorded without those plugins holds them empty (no goals, `guides` null), so
every version 1 file has the same layout.
Any other track a plugin adds is declared in `header["tracks"]` (absent when there is
none) and stored after them, in the order declared.

`TrackSize` is what a plugin says its tracks will hold for a scene before anything is
built (`Plugin.take_sizes`), so a bake can refuse a take too big to read back.
"""

from __future__ import annotations

import importlib.resources
import json
import re
from dataclasses import dataclass
from typing import Any

from ecs_tentacles.take.header_entries import HeaderTrack

KINDS = ("points", "curves")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class TakeTrack:
    """A named track of a take: header key, kind, its two arrays, where exporters put it."""

    key: str  # the header key holding its entries ("goals")
    kind: str  # "points" or "curves"
    arrays: tuple[str, str]  # file arrays ("goal_pos", "goal_active")
    folder: str  # the group under each creature in USD ("goals", "fur")
    item: str  # points: name stem of each ("goal" -> goal0); curves: the prim ("guides")

    def declaration(self) -> HeaderTrack:
        """This track as `header["tracks"]` lists it."""
        return {"key": self.key, "kind": self.kind, "arrays": list(self.arrays),
                "folder": self.folder, "item": self.item}  # fmt: skip

    def empty_header(self) -> list[object] | None:
        """Its header entry before anything is recorded."""
        return [] if self.kind == "points" else None


def _version1() -> tuple[TakeTrack, ...]:
    """The tracks every version 1 file carries (`version1.json`: part of the file format,
    data beside this module; the plugins that fill them declare the same tracks)."""
    text = importlib.resources.files("ecs_tentacles.take").joinpath("version1.json").read_text()
    return tuple(
        TakeTrack(t["key"], t["kind"], (t["arrays"][0], t["arrays"][1]), t["folder"], t["item"])
        for t in json.loads(text)["tracks"]
    )


STANDARD = _version1()
CORE_KEYS = (
    "format",
    "version",
    "scene",
    "scene_sha256",
    "seed",
    "fps",
    "sim_fps",
    "substeps",
    "frames",
    "creatures",
    "bodies",
    "suckers",
    "health",
    "tracks",
)
CORE_ARRAYS = ("header", "pos", "quat", "sucker_attached", "sucker_anchor")


WIDEST_FLOAT = -2.2250738585072014e-308  # 24 characters in JSON: no float is wider


@dataclass(frozen=True)
class TrackSize:
    """What a track will hold in a take of a scene, from the scene alone: `items` of
    `what` (a plural noun, "goals"; `each` may say more of one, "of 8 points"), each
    `frame_bytes` a frame, and `fixed_bytes` in all once (header entries and arrays that
    do not grow with frames; at most); `chunked` when a bake stores it in chunks of
    frames (curves tracks, replay records). Counted before anything is built."""

    what: str
    items: int
    frame_bytes: int
    fixed_bytes: int = 0
    each: str = ""
    chunked: bool = False  # stored in chunks of frames (a reader holds one chunk of it)


def dtypes(track: TakeTrack) -> tuple[str, str]:
    """The numpy dtypes of a track's two arrays."""
    return ("<f4", "|b1") if track.kind == "points" else ("<f4", "<f4")


def declared_problem(header: dict[str, object]) -> str | None:
    """The first problem of `header["tracks"]` (the declared tracks), or None."""
    declared = header.get("tracks", [])
    if not isinstance(declared, list):
        return "header.tracks: must be a list"
    keys, arrays = {t.key for t in STANDARD}, {a for t in STANDARD for a in t.arrays}
    for i, entry in enumerate(declared):
        where = f"header.tracks[{i}]"
        if not isinstance(entry, dict) or set(entry) != {"key", "kind", "arrays", "folder", "item"}:
            return f"{where}: must be an object with key, kind, arrays, folder and item"
        if entry["kind"] not in KINDS:
            return f"{where}.kind: must be one of {', '.join(KINDS)}, got {entry['kind']!r}"
        names = entry["arrays"]
        if not isinstance(names, list) or len(names) != 2:
            return f"{where}.arrays: must be two array names"
        for field in ("key", "folder", "item", *range(2)):
            value = names[field] if isinstance(field, int) else entry[field]
            if not isinstance(value, str) or not _NAME.fullmatch(value):
                return f"{where}: {value!r} is not an identifier (letters, digits, _)"
        if entry["key"] in keys or entry["key"] in CORE_KEYS:
            return f"{where}.key: {entry['key']!r} is used twice"
        if set(names) & (arrays | set(CORE_ARRAYS)) or names[0] == names[1]:
            return f"{where}.arrays: {names} names an array twice"
        keys.add(entry["key"])
        arrays.update(names)
    return None


def tracks_of(header: dict[str, Any]) -> list[TakeTrack]:
    """Every track of a take with a sound header (`declared_problem` is None), file order."""
    declared = [
        TakeTrack(t["key"], t["kind"], (t["arrays"][0], t["arrays"][1]), t["folder"], t["item"])
        for t in header.get("tracks", [])
    ]
    return [*STANDARD, *declared]
