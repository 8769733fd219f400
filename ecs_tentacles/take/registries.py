"""What the recorder asks the plugins for a take: the take layer's registries
(`ecs_tentacles.registry`), filled in plugins' `build(app)`, and the data they carry.

- `TakeTracks`: `entry(world)` -> `TrackSource`s: tracks added to every take recorded
  from `world` (locomotion: the goals; fur: the guides; `ecs_tentacles.take.tracks`
  describes the kinds). A track with a standard key (`goals`, `guides`) must be
  declared as the standard one; others are declared in the take's header, so a take
  file describes itself.
- `RecordingStarts`: `entry(world)`, called once when a recording starts, before its
  first frame is captured (the fur plugin poses its guides at the built pose).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ecs_tentacles.registry import Registry
from ecs_tentacles.take.tracks import TakeTrack

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


@dataclass(frozen=True)
class CurvesFrame:
    """A curves track at one frame (`TrackSource.sample`; the fur guides):
    `points` (curves, points, 3) world metres, `widths` (curves, points) metres (or any
    shape that broadcasts to it: (curves, 1) for one width along each curve),
    `creatures` (curves,) owning creature entities. The recorder copies what it keeps:
    they may be views of the plugin's own buffers."""

    points: ArrayLike
    widths: ArrayLike
    creatures: ArrayLike


@dataclass(frozen=True)
class PointsFrame:
    """A points track at one frame (`TrackSource.sample`; the goals): the live locators.

    `keys` identify each across frames (an entity id); `creatures` are their owners'
    entities; `order` sorts locators that appear in the same frame within a creature;
    `positions` (n, 3) and `radii` (n,) are kept from the frame a locator first appears.
    Each is a sequence or a numpy array; a sample that returns the very same `keys` as at
    the last frame costs the recorder one comparison of them.
    """

    keys: Sequence[int] | np.ndarray
    creatures: Sequence[int] | np.ndarray
    order: Sequence[int] | np.ndarray
    positions: Sequence[Sequence[float]] | np.ndarray
    radii: Sequence[float] | np.ndarray


@dataclass(frozen=True)
class TrackSource:
    """A track a plugin adds to takes: its declaration (`ecs_tentacles.take.tracks`) and
    `sample(world)`, called at every recorded frame (a `PointsFrame` or `CurvesFrame`
    as the kind says, or None: nothing this frame)."""

    track: TakeTrack
    sample: Callable[[Host], PointsFrame | CurvesFrame | None]


class TakeTracks(Registry[Callable[["Host"], Sequence[TrackSource]]]):
    """Tracks plugins add to takes."""


class RecordingStarts(Registry[Callable[["Host"], None]]):
    """What plugins do when a recording starts."""
