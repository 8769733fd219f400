"""The bytes a take of a scene will hold, counted from the scene before anything is built.

`take_size(scene, tracks)` -> `TakeSize`, its parts as `TrackSize`s: the bodies (28
bytes a frame each: position and quaternion, float32), the suckers (13 at most: the
attached flag and the anchor; the suckers plugin may be off) and what each plugin says
its tracks will hold (`Plugin.take_sizes`: the fur's guide curves, 16 bytes a point a
frame; the goals, a byte). Once: the header's JSON (the creatures', bodies' and
suckers' entries as the recorder writes them, names, indices and sizes as the scene
builds them; the other fields at their widest) and room for the arrays' `.npy` headers.

`export.bake` checks it against what the reader takes (`take.read`: `MAX_TAKE_BYTES`
in all, `MAX_HEADER_BYTES` of header), so a bake refuses a take nobody could read
before it simulates. What the scene cannot tell (goals a system adds, creatures spawned
during the bake, the terrain's meshes, physics recoveries in the header) is not counted
here: `Take.save` checks the finished take as the reader will.
"""

from __future__ import annotations

import functools
import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from ecs_tentacles.scene.construction import tentacle_params, tentacle_shape
from ecs_tentacles.take.chunks import chunk_frames
from ecs_tentacles.take.tracks import WIDEST_FLOAT, TrackSize

POSE_BYTES = 7 * 4  # a body's position and quaternion in a frame (float32)
SUCKER_BYTES = 1 + 3 * 4  # attached flag and anchor
NPY_HEADERS = 64 * 128  # room for the `.npy` headers of 64 arrays (128 bytes each)


@dataclass(frozen=True)
class TakeSize:
    """A take's bytes by part (`TrackSize`s: bodies, suckers, the plugins' tracks) and
    the header's fields beside them (`base`, with the `.npy` headers)."""

    parts: tuple[TrackSize, ...]
    base: int

    @property
    def frame_bytes(self) -> int:
        """Bytes each frame adds."""
        return sum(part.items * part.frame_bytes for part in self.parts)

    @property
    def fixed_bytes(self) -> int:
        """Bytes whatever the frames (the header at most, arrays that do not grow)."""
        return self.base + sum(part.fixed_bytes for part in self.parts)

    def total(self, frames: int) -> int:
        """Bytes of a take of `frames` frames, at most."""
        return frames * self.frame_bytes + self.fixed_bytes

    @property
    def chunked_frame_bytes(self) -> int:
        """Bytes a frame adds to the arrays stored in chunks (bodies, suckers, and the
        tracks a bake stores in chunks: curves, replay records)."""
        return sum(
            part.items * part.frame_bytes
            for i, part in enumerate(self.parts)
            if i < 2 or part.chunked
        )

    def at_once(self, frames: int) -> int:
        """Bytes a reader decodes at once, at most, for `frames` frames: a chunk of the
        bodies and suckers (`take.chunks`), every frame of the tracks, the fixed part."""
        chunked = self.chunked_frame_bytes
        per_chunk = min(frames, chunk_frames(chunked))
        return per_chunk * chunked + frames * (self.frame_bytes - chunked) + self.fixed_bytes


def _digits_below(n: int) -> int:
    """Digits of the numbers 0 .. n-1 written out, in all."""
    total, width, low = 0, 1, 0
    while low < n:
        high = min(n, 10**width)
        total += (high - low) * width
        low, width = high, width + 1
    return total


def scene_sizes(scene: Mapping[str, Any]) -> tuple[int, int]:
    """(bodies, suckers) a loaded scene's creatures have: mantles and links; suckers at
    most (the suckers plugin may be off)."""
    bodies = suckers = 0
    for creature in scene["creatures"]:
        tentacles = creature["tentacles"]
        for k in range(tentacles["count"]):
            params = tentacle_params(tentacles, k)
            bodies += params["links"]
            suckers += params["links"] if params.get("suckers") == "every_link" else 1
        bodies += 1
    return bodies, suckers


def _entry(value: object) -> int:
    """Bytes of `value` in the header's JSON (compact), with the comma after it."""
    return len(json.dumps(value, separators=(",", ":"))) + 1


def _digits(first: int, end: int) -> int:
    """Digits of the numbers first .. end-1 written out, in all."""
    return _digits_below(end) - _digits_below(first)


@functools.lru_cache(maxsize=4096)
def _link_numbers(
    mantle_radius: float, params: tuple[float, float, int, float]
) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """Characters of each link's length and radius in the header and of its sucker's
    offset (half the length, minus the radius), as `tentacle_shape` makes them."""
    shape = tentacle_shape(mantle_radius, *params)
    return tuple(
        len(repr(float(length))) + len(repr(float(radius)))
        for length, radius in zip(shape.lengths, shape.radii, strict=True)
    ), tuple(
        len(repr(float(0.5 * length))) + len(repr(float(-radius)))
        for length, radius in zip(shape.lengths, shape.radii, strict=True)
    )


def _header_entries(scene: Mapping[str, Any]) -> tuple[int, int]:
    """Header bytes of (the creatures and bodies, the suckers) at most, as the recorder
    writes them: names, indices and every number as built from the scene; bodies and
    suckers once per body plan (`take.compact`), each creature's entry and plan index."""
    body_bytes = sucker_bytes = 0
    first = 0  # the mantle's body index
    plans: set[str] = set()
    for c, creature in enumerate(scene["creatures"]):
        tentacles = creature["tentacles"]
        every = [tentacle_params(tentacles, k) for k in range(tentacles["count"])]
        plan = repr([_shape_of(creature["mantle"], params) for params in every])
        listed, bodies, suckers, first = _creature_entries(c, creature, every, first)
        body_bytes += listed + len(str(len(plans))) + 1
        if plan not in plans:
            plans.add(plan)
            body_bytes, sucker_bytes = body_bytes + bodies, sucker_bytes + suckers
    return body_bytes, sucker_bytes


def _shape_of(mantle: Mapping[str, object], params: Mapping[str, object]) -> tuple[object, ...]:
    """What a tentacle's bodies and suckers in the header are made of (not its motion)."""
    shape = ("links", "link_length", "link_radius", "end_scale", "suckers")
    return (mantle["radius"], mantle["height"], *(params.get(key) for key in shape))


def _creature_entries(
    c: int, creature: Mapping[str, Any], every: Sequence[Mapping[str, Any]], first: int
) -> tuple[int, int, int, int]:
    """(bytes of creature `c`'s entry, of its bodies', of its suckers', the next
    creature's first body), its mantle being body `first`."""
    body_bytes = sucker_bytes = 0
    name, mantle = creature.get("name", f"creature_{c}"), creature["mantle"]
    radius, height = float(mantle["radius"]), float(mantle["height"])
    entry = {"axis": "Z", "creature": c, "length": height, "name": f"{name}/mantle"}
    body_bytes += _entry({**entry, "radius": radius, "shape": "cylinder"})
    listed = _entry({"mantle": 0, "name": name, "tentacles": []}) - 1 + len(str(first))
    body = first + 1
    tentacles = creature["tentacles"]
    for k, params in enumerate(every):
        links, stem = params["links"], f"{name}/tentacles/t{k}/link"
        asked = (params["link_length"], params["link_radius"], links, params["end_scale"])
        numbers, offsets = _link_numbers(radius, asked)
        link = {**entry, "axis": "X", "name": stem, "length": 0, "radius": 0}
        body_bytes += links * (_entry({**link, "shape": "capsule"}) - 2) + sum(numbers)
        body_bytes += _digits_below(links)
        listed += 2 + links + _digits(body, body + links)  # [b,b,...], and a comma
        sucker = {"body": 0, "name": f"{stem}/sucker0", "offset": [0, 0.0, 0]}
        if params.get("suckers") == "every_link":  # one on each link
            sucker_bytes += links * (_entry(sucker) - 3) + sum(offsets)
            sucker_bytes += _digits_below(links) + _digits(body, body + links)
        else:  # one at the tip
            tip = links - 1
            sucker_bytes += _entry(sucker) - 3 + len(str(tip)) + len(str(body + tip))
            sucker_bytes += offsets[tip]
        body += links
    listed -= 1 if tentacles["count"] else 0  # no comma after the last
    return listed, body_bytes, sucker_bytes, body


def _base(scene: Mapping[str, object]) -> int:
    """The header's fields beside the parts, at most, and the `.npy` headers."""
    fields = {
        "format": "ecs_tentacles.take",
        "version": 1,
        "scene": scene.get("name", ""),
        "scene_sha256": 64 * "0",
        "seed": -(2**63),
        "fps": WIDEST_FLOAT,
        "sim_fps": WIDEST_FLOAT,
        "substeps": 10**6,
        "frames": 10**7,
        "health": {"recoveries": 0, "frozen": 0, "events": []},
    }
    return _entry(fields) + 16 * 32 + NPY_HEADERS  # and room for 16 keys of the parts


def take_size(scene: Mapping[str, object], tracks: Iterable[TrackSize] = ()) -> TakeSize:
    """What a take of `scene` (loaded: defaults filled in) holds, from the scene alone:
    the bodies, the suckers and `tracks` (the plugins' `take_sizes` for it)."""
    bodies, suckers = scene_sizes(scene)
    body_header, sucker_header = _header_entries(scene)
    parts: Sequence[TrackSize] = (
        TrackSize("bodies", bodies, POSE_BYTES, body_header),
        TrackSize("suckers", suckers, SUCKER_BYTES, sucker_header),
        *tracks,
    )
    return TakeSize(tuple(parts), _base(scene))
