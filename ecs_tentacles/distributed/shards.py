"""Shards: sets of creatures a bake may simulate apart because they can never meet.

Creatures meet through contact proxies (`ecs_tentacles.physics.proxies`): when their
bounding spheres come within `MARGIN`. A shard plan is either the scene's own
`shards` field, or worked out here from where each creature can get to during the
bake: a capsule on the ground around its body's reach plus `SLACK`, stretched and
widened by what the plugins say it may move (`Plugin.shard_reach`; locomotion: its
crawl toward its first goal, or a disc when it has none or may reach it). Creatures
whose capsules come within `MARGIN` are joined (union-find); each connected set is
one island, and islands are packed into at most `tasks` shards of balanced size.
Sets of creatures a plugin says must bake together (`Plugin.shard_groups`; fur:
threats and the emotional creatures they rouse) always share a shard (declared
shards too).

The plan is an estimate; the bake proves it (`ecs_tentacles.distributed.spheres`):
shards whose creatures did come within contact range are baked again together.
"""

from __future__ import annotations

import math
import pathlib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ecs_tentacles.distributed.registries import Reach, ShardGroups, ShardReaches
from ecs_tentacles.physics.proxies import MARGIN
from ecs_tentacles.plugin import Plugin, calling
from ecs_tentacles.registry import App, Registries
from ecs_tentacles.scene.construction import creature_reach
from ecs_tentacles.scene.plugins import resolve

SLACK = 0.15  # metres: settling at the start, sideways drift, tentacles lifting


@dataclass(frozen=True)
class ShardPlan:
    """Creature indices (scene order) per shard, and how the plan was made."""

    shards: list[list[int]]
    islands: int  # sets of creatures that may meet (before packing into shards)
    declared: bool

    def describe(self) -> str:
        """One line for the user."""
        n = len(self.shards)
        if self.declared:
            return f"{n} shard{'s' * (n != 1)} as the scene declares"
        if self.islands == 1:
            return "1 shard: every creature may meet another during the bake"
        return f"{n} shard{'s' * (n != 1)} from {self.islands} sets of creatures that never meet"


def plan_shards(
    scene: dict[str, Any],
    seconds: float,
    tasks: int,
    plugins: Sequence[Plugin] | None = None,
) -> ShardPlan:
    """The shards of `scene` (validated, defaults in) for a bake of `seconds`.

    `plugins`: the scene's plugins (`scene_plugins`, the default, makes them).
    """
    creatures = scene["creatures"]
    if not creatures:
        return ShardPlan([[]], 1, declared=False)
    plugins = scene_plugins(scene) if plugins is None else plugins
    together = [g for groups in entries(plugins).get(ShardGroups) for g in groups(creatures)]
    if "shards" in scene:
        index = {c["name"]: i for i, c in enumerate(creatures)}
        shards = [sorted(index[name] for name in shard) for shard in scene["shards"]]
        shards = _joined_all(shards, together)
        return ShardPlan(sorted(shards), len(shards), declared=True)
    islands = _joined_all(islands_of(creatures, seconds, plugins), together)
    return ShardPlan(pack(islands, creatures, tasks), len(islands), declared=False)


def scene_plugins(
    scene: Mapping[str, Any], folder: str | None = None, *, allow_systems: bool = False
) -> list[Plugin]:
    """The plugins a loaded scene turns on (its `plugins` field), for their shard entries."""
    where = pathlib.Path(folder) if folder else None
    return resolve(scene.get("plugins"), where, allow=allow_systems)


def entries(plugins: Sequence[Plugin]) -> Registries:
    """The registries the scene's `plugins` fill, built without a world; a `build` that
    calls sys.exit is a one-line `HookFailure` naming the plugin, as in a world."""
    registries = Registries()
    for plugin in plugins:
        with calling(plugin, "build"):
            plugin.build(App(registries, plugin))
    return registries


def _joined_all(sets: list[list[int]], groups: list[list[int]]) -> list[list[int]]:
    for group in groups:
        sets = _joined(sets, group)
    return sets


def _joined(sets: list[list[int]], together: list[int]) -> list[list[int]]:
    """`sets` with every set holding one of `together` merged into one."""
    if not together:
        return sets
    wanted = set(together)
    merged = sorted({i for s in sets if wanted & set(s) for i in s})
    return sorted([merged, *(s for s in sets if not wanted & set(s))])


def travel_capsules(
    creatures: list[dict[str, Any]], seconds: float, plugins: Sequence[Plugin] = ()
) -> np.ndarray:
    """(n, 5): start x, y, end x, y and radius of where each creature can get to."""
    out = np.zeros((len(creatures), 5))
    reaches = list(entries(plugins).get(ShardReaches))
    for i, creature in enumerate(creatures):
        start = np.asarray(creature["position"][:2], dtype=np.float64)
        reach = creature_reach(creature) + 0.5 * creature["mantle"]["height"] + SLACK
        moves = [reach(creature, seconds) for reach in reaches]
        towards, extra = _combined([m for m in moves if m is not None])
        out[i] = (*start, *(start + towards), reach + extra)
    return out


def _combined(moves: list[Reach]) -> tuple[np.ndarray, float]:
    """One capsule's stretch and widening holding every plugin's reach (exact when at
    most one stretches: a capsule widened by discs; otherwise a disc around them all)."""
    stretched = [m for m in moves if m.towards != (0.0, 0.0)]
    if len(stretched) <= 1:
        towards = np.asarray(stretched[0].towards if stretched else (0.0, 0.0), np.float64)
        extra = 0.0
        for move in moves:
            extra += move.radius
        return towards, extra
    return np.zeros(2), sum(math.hypot(*m.towards) + m.radius for m in moves)


def islands_of(
    creatures: list[dict[str, object]], seconds: float, plugins: Sequence[Plugin] = ()
) -> list[list[int]]:
    """Sets of creature indices that may meet during the bake (union-find), sorted."""
    capsules = travel_capsules(creatures, seconds, plugins)
    parent = list(range(len(creatures)))

    def find(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for i, j in _near_pairs(capsules):
        a, b = find(i), find(j)
        if a != b:
            parent[max(a, b)] = min(a, b)
    groups: dict[int, list[int]] = {}
    for i in range(len(creatures)):
        groups.setdefault(find(i), []).append(i)
    return sorted(groups.values())


def _near_pairs(capsules: np.ndarray) -> list[tuple[int, int]]:
    """Pairs i < j of capsules closer than MARGIN (bounding circles first, in blocks)."""
    a, b, radius = capsules[:, :2], capsules[:, 2:4], capsules[:, 4]
    mid = 0.5 * (a + b)
    bound = 0.5 * np.linalg.norm(b - a, axis=1) + radius
    pairs: list[tuple[int, int]] = []
    n = len(capsules)
    block = max(1, 2_000_000 // max(n, 1))
    for lo in range(0, n, block):
        hi = min(n, lo + block)
        gap = np.linalg.norm(mid[lo:hi, None] - mid[None], axis=2) - bound[lo:hi, None] - bound
        i, j = np.nonzero(gap < MARGIN)
        i += lo
        keep = i < j
        i, j = i[keep], j[keep]
        if len(i) == 0:
            continue
        distance = segment_distance(a[i], b[i], a[j], b[j])
        near = distance - radius[i] - radius[j] < MARGIN
        pairs += list(zip(i[near].tolist(), j[near].tolist(), strict=True))
    return pairs


def segment_distance(p0: np.ndarray, p1: np.ndarray, q0: np.ndarray, q1: np.ndarray) -> np.ndarray:
    """Distance between 2D segments p0-p1 and q0-q1, row by row (0 where they cross)."""

    def to_segment(x: np.ndarray, s0: np.ndarray, s1: np.ndarray) -> np.ndarray:
        d = s1 - s0
        length2 = np.einsum("ij,ij->i", d, d)
        t = np.clip(np.einsum("ij,ij->i", x - s0, d) / np.where(length2 > 0, length2, 1), 0, 1)
        distance: np.ndarray = np.linalg.norm(x - (s0 + t[:, None] * d), axis=1)
        return distance

    def side(o: np.ndarray, s: np.ndarray, x: np.ndarray) -> np.ndarray:
        u, v = s - o, x - o
        sides: np.ndarray = np.sign(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0])
        return sides

    ends = np.minimum.reduce(
        [
            to_segment(p0, q0, q1),
            to_segment(p1, q0, q1),
            to_segment(q0, p0, p1),
            to_segment(q1, p0, p1),
        ]
    )
    cross = (side(p0, p1, q0) * side(p0, p1, q1) < 0) & (side(q0, q1, p0) * side(q0, q1, p1) < 0)
    return np.where(cross, 0.0, ends)


def pack(islands: list[list[int]], creatures: list[dict[str, Any]], tasks: int) -> list[list[int]]:
    """Islands packed into at most `tasks` shards, balanced by bodies (largest first)."""
    weight = [1 + sum(_links(c)) for c in creatures]
    bins: list[list[int]] = [[] for _ in range(max(1, min(tasks, len(islands))))]
    load = [0] * len(bins)
    for island in sorted(islands, key=lambda s: (-sum(weight[i] for i in s), s)):
        k = min(range(len(bins)), key=lambda b: (load[b], b))
        bins[k] += island
        load[k] += sum(weight[i] for i in island)
    return sorted(sorted(b) for b in bins if b)


def _links(creature: dict[str, Any]) -> list[int]:
    tentacles = creature["tentacles"]
    overrides = {o["index"]: o.get("links") for o in tentacles.get("overrides", [])}
    return [overrides.get(k) or tentacles["links"] for k in range(tentacles["count"])]


def default_tasks(cpus: float) -> int:
    """Shards to aim for on `cpus` workers: a few per worker, so a slow one evens out."""
    return max(1, 4 * math.floor(cpus))
