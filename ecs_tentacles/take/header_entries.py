"""A take's header and the rows of its `creatures`, `bodies` and `suckers` tables, as
TypedDicts (`TakeHeader`: every key the format names; a plugin's own track adds a key
of its own, which no TypedDict mypy accepts can name, so `Take.header` stays a dict).

The recorder (`ecs_tentacles.export.recording`) writes them; `take.header` checks a
file's against the same fields (names, indices, shapes, sizes) before anything reads
them. Types only: reads and writes nothing, costs nothing at run time (the rows stay the
plain dicts `json` writes).
"""

from __future__ import annotations

from typing import Literal, TypedDict


class HeaderCreature(TypedDict):
    """A creature: its name, its mantle's body index and each tentacle's link bodies."""

    name: str
    mantle: int
    tentacles: list[list[int]]


class HeaderBody(TypedDict):
    """A body: `<creature>/mantle` (a cylinder along Z) or
    `<creature>/tentacles/t<k>/link<i>` (a capsule along X), metres."""

    name: str
    creature: int
    shape: Literal["cylinder", "capsule"]
    axis: Literal["X", "Y", "Z"]
    radius: float
    length: float


class HeaderSucker(TypedDict):
    """A sucker: `<body>/sucker<n>`, on body `body` at `offset` in the body's frame."""

    name: str
    body: int
    offset: list[float]


class HeaderPoint(TypedDict):
    """An item of a points track (`goals`): `<creature>/<folder>/<item><n>`."""

    name: str
    creature: int
    radius: float


class HeaderCurves(TypedDict):
    """A curves track (`guides`) with curves: the creature owning each (-1: none)."""

    creatures: list[int]


class HeaderTrack(TypedDict):
    """A declared track (`tracks`, `ecs_tentacles.take.tracks.TakeTrack.declaration`)."""

    key: str
    kind: str
    arrays: list[str]
    folder: str
    item: str


class HeaderHealth(TypedDict):
    """Physics recoveries while recording: counts and each event's frame and cause."""

    recoveries: int
    frozen: int
    events: list[HealthEvent]


class HealthEvent(TypedDict):
    """A creature recovered or frozen on take frame `frame`."""

    frame: int
    creature: int
    event: str
    cause: str


class _MeshColour(TypedDict, total=False):
    rgb: list[float]  # absent in takes written before meshes carried it


class GroundMeshEntry(_MeshColour):
    """A ground mesh (`ecs_tentacles.take.ground`): its name and sizes, its colour."""

    name: str
    vertices: int
    triangles: int


class HeaderGround(TypedDict):
    """The ground's static meshes, on terrain."""

    digest: str
    meshes: list[GroundMeshEntry]


class ReplayClip(TypedDict):
    """A gait clip replayed creatures share (`ecs_tentacles.take.replay`)."""

    bodies: int
    dt: float
    frames: list[int]


class HeaderReplay(TypedDict):
    """The clips replayed and each creature's clip (-1: none)."""

    clips: list[ReplayClip]
    creatures: list[int]


class HeaderRoster(TypedDict):
    """Spawns and despawns while recording (`ecs_tentacles.take.roster`)."""

    changes: int


class _OptionalKeys(TypedDict, total=False):
    """The keys a take header holds only in some takes (a class of their own, total=False:
    the runtime's `__required_keys__` then says which are required, as mypy does)."""

    replay: HeaderReplay | None  # version 2 on, when the crowd replays clips
    tracks: list[HeaderTrack]  # the plugins' own tracks, when there are any
    ground: HeaderGround  # on terrain
    roster: HeaderRoster  # when creatures came or went
    chunk_frames: int  # in a file (version 2 on): frames a chunk holds
    chunked: list[str]  # in a file: the arrays stored in chunks
    quantised: dict[str, float]  # in a file: arrays stored quantised -> their step


class TakeHeader(_OptionalKeys):
    """A take's header as the recorder and the writer give it (`ecs_tentacles.take.format`
    describes each key), but its tracks' keys: each track (the standard ones of
    `ecs_tentacles.take.tracks.STANDARD`, and those `tracks` declares) adds its own key
    beside these, holding `HeaderPoint`s (points) or a `HeaderCurves` (curves, or null)."""

    format: str
    version: int
    scene: str
    scene_sha256: str
    seed: int
    fps: float
    sim_fps: float
    substeps: int
    frames: int
    creatures: list[HeaderCreature]
    bodies: list[HeaderBody]
    suckers: list[HeaderSucker]
    health: HeaderHealth
