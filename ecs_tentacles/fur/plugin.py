"""The fur plugin: fur and feathers on the mantle, and the emotion that raises them.

Scene keys: a creature's `fur` and `emotion` (`ecs_tentacles/fur/fur.schema.json`).
Resources: `world.resource(FurData)` (`ecs_tentacles.fur.stores.FurData`). Systems: emotion, rig
(stage animate). Export hook: the posed guide curves a take records.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from ecs_tentacles.fur.build import build_emotion, build_fur
from ecs_tentacles.fur.checks import fur_problems
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.plugin import GuideFrame, Plugin
from ecs_tentacles.scene.validate import fragment
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.store import ArrayStore

_FRAGMENT = fragment("ecs_tentacles.fur", "fur")
STORES = ("guides", "controls", "sets", "emotions")


class FurPlugin(Plugin):
    name = "fur"
    description = "fur and feathers (lift, aim, direction, random, dynamic blend) and emotion"
    creature_schema = _FRAGMENT["creature"]
    defs = _FRAGMENT["$defs"]

    def problems(self, scene: Mapping[str, Any]) -> list[tuple[tuple[str | int, ...], str]]:
        return fur_problems(scene)

    def resources(self, world: Host) -> list[object]:
        return [FurData()]

    def build_creature(self, world: Host, creature: int, spec: Mapping[str, Any]) -> None:
        if "fur" in spec:
            build_fur(world, creature, dict(spec["fur"]))
        if "emotion" in spec:
            build_emotion(world, creature, dict(spec["emotion"]))

    def systems(self) -> list[System]:
        from ecs_tentacles.systems.fur.emotion import EmotionSystem
        from ecs_tentacles.systems.fur.rig import Rig

        return [EmotionSystem(), Rig()]

    def stores(self, world: Host) -> dict[str, ArrayStore]:
        fur = world.resource(FurData)
        return {f"fur.{name}": getattr(fur, name) for name in STORES}

    def snapshot(self, world: Host) -> Any:
        fur = world.resource(FurData)  # its stores are copied with every store
        return fur.curves.copy(), fur.frames.copy()

    def restore(self, world: Host, state: Any) -> None:
        curves, frames = state
        fur = world.resource(FurData)
        fur.curves[...] = curves
        fur.frames[...] = frames

    def export_curves(self, world: Host) -> GuideFrame | None:
        from ecs_tentacles.fur.hooks import take_guides

        return take_guides(world)
