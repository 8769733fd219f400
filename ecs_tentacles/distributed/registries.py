"""What the shard planner of a distributed bake asks the plugins: the distributed
layer's registries (`ecs_tentacles.registry`), filled in plugins' `build(app)`. The
planner builds the scene's plugins without a world (`shards.entries`).

- `ShardReaches`: `entry(creature, seconds)` -> how far `creature` (its scene entry,
  defaults in) may move during a bake of `seconds`, beyond its body (`Reach`;
  locomotion: its crawl), or None. Creatures whose reaches may meet bake in one shard.
- `MeetingReaches`: `entry(scene)` -> per creature, metres beyond its body within which
  it acts on others without touching them (locomotion: its personal space), or None;
  the merge joins shards whose creatures came that near.
- `ShardGroups`: `entry(creatures)` -> lists of creature indices that must bake in one
  shard (fur: threats and the creatures they rouse).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from ecs_tentacles.registry import Registry


@dataclass(frozen=True)
class Reach:
    """How far a creature may get during a bake, beyond its body: a capsule from its
    start along `towards` (x, y metres), widened by `radius` metres."""

    towards: tuple[float, float] = (0.0, 0.0)
    radius: float = 0.0


class ShardReaches(Registry[Callable[[Mapping[str, object], float], Reach | None]]):
    """How far each creature may get during a bake."""


class MeetingReaches(Registry[Callable[[Mapping[str, object]], Sequence[float] | None]]):
    """How far each creature acts on others without touching them."""


class ShardGroups(Registry[Callable[[Sequence[Mapping[str, object]]], list[list[int]]]]):
    """Creatures that must bake in one shard."""
