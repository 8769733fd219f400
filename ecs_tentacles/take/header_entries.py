"""The rows of a take header's `creatures`, `bodies` and `suckers` tables, as TypedDicts.

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
