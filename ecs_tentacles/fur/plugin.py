"""The fur plugin: fur and feathers on the mantle, and the emotion that raises them.

Scene keys: a creature's `fur` and `emotion` (`ecs_tentacles/fur/fur.schema.json`).
Resources: `world.resource(FurData)` (`ecs_tentacles.fur.stores.FurData`). Systems: emotion, rig
(stage animate). Output hooks (`ecs_tentacles.fur.outputs`): the posed guide curves a
take records (posed at the built pose before a recording starts), and threats with
the emotional creatures they rouse baked in one shard. Sandbox hooks
(`ecs_tentacles.fur.render`): strands as ribbons, the controls' markers, the fur panel.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ecs_tentacles.distributed.registries import ShardGroups
from ecs_tentacles.fur.build import build_emotion, build_fur
from ecs_tentacles.fur.checks import fur_problems
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.plugin import Plugin, Problem
from ecs_tentacles.render.registries import Draws, Lines, Panels
from ecs_tentacles.scene.schema import plugin_schemas
from ecs_tentacles.system import System
from ecs_tentacles.take.registries import RecordingStarts, TakeTracks, TrackSource

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App
    from ecs_tentacles.render.registries import Panel, RenderView, SandboxView
    from ecs_tentacles.roster_change import RosterChange
    from ecs_tentacles.store import ArrayStore
    from ecs_tentacles.take.tracks import TrackSize

STORES = ("guides", "controls", "sets", "emotions")


class FurState(NamedTuple):
    """What a snapshot keeps: the posed curves and frames the rig last wrote."""

    curves: np.ndarray
    frames: np.ndarray


class FurPlugin(Plugin):
    name = "fur"
    build_order = 40  # a default plugin: built after threats (30), before clips (50)
    description = "fur and feathers (lift, aim, direction, random, dynamic blend) and emotion"
    creature_schema, tentacle_schema, scene_schema, defs = plugin_schemas(__package__, name)
    # the take's guide curves and the sandbox's strands and markers
    hook_reads = ("fur.guides", "fur.sets", "fur.controls")

    def problems(self, scene: Mapping[str, object]) -> list[Problem]:
        return fur_problems(scene)

    def resources(self, world: Host) -> list[object]:
        return [FurData()]

    def build_creature(self, world: Host, creature: int, spec: Mapping[str, object]) -> None:
        fur, emotion = spec.get("fur"), spec.get("emotion")
        if fur is not None and not isinstance(fur, Mapping):
            raise TypeError(f"{spec.get('name')}: its fur is an object, not {fur!r}")
        if emotion is not None and not isinstance(emotion, Mapping):
            raise TypeError(f"{spec.get('name')}: its emotion is an object, not {emotion!r}")
        if fur is not None:
            build_fur(world, creature, dict(fur))
        if emotion is not None:
            build_emotion(world, creature, dict(emotion))

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        if not change.spawned:  # a spawn's fur was added by `build_creature`
            world.resource(FurData).drop(change.moved)

    def systems(self) -> list[System]:
        from ecs_tentacles.fur.systems.emotion import EmotionSystem
        from ecs_tentacles.fur.systems.rig import Rig

        return [EmotionSystem(), Rig()]

    def stores(self, world: Host) -> dict[str, ArrayStore]:
        fur = world.resource(FurData)
        return {f"fur.{name}": getattr(fur, name) for name in STORES}

    def snapshot(self, world: Host) -> object:
        fur = world.resource(FurData)  # its stores are copied with every store
        return FurState(fur.curves.copy(), fur.frames.copy())

    def restore(self, world: Host, state: object) -> None:
        if not isinstance(state, FurState):
            raise TypeError(f"fur: a snapshot's state is a FurState, not {state!r}")
        curves, frames = state
        fur = world.resource(FurData)
        fur.discard()  # the snapshot's outputs replace whatever the rig deferred
        fur.curves[...] = curves
        fur.frames[...] = frames

    # -- outputs (take tracks: build; shard plans, run report: hooks) ----------------
    def _take_tracks(self, world: Host) -> list[TrackSource]:
        from ecs_tentacles.fur.outputs import GUIDE_TRACK

        return [GUIDE_TRACK]

    def take_sizes(self, scene: Mapping[str, object]) -> list[TrackSize]:
        from ecs_tentacles.fur.outputs import guide_sizes

        return guide_sizes(scene)

    def _before_recording(self, world: Host) -> None:
        from ecs_tentacles.fur.outputs import pose_fur_at_build

        pose_fur_at_build(world)

    def _shard_groups(self, creatures: Sequence[Mapping[str, object]]) -> list[list[int]]:
        from ecs_tentacles.fur.outputs import roused

        together = roused(creatures)
        return [together] if together else []

    # -- registry entries (GL and ImGui are imported only when a sandbox calls them) ------
    def build(self, app: App) -> None:
        """Threats and who they rouse bake together (`distributed.registries`); the guides
        in every take (`take.registries`); strands, markers and the Fur section in the
        sandbox (`render.registries`)."""
        app.add(ShardGroups, self._shard_groups)
        app.add(TakeTracks, self._take_tracks)
        app.add(RecordingStarts, self._before_recording)
        app.add(Lines, self._lines)
        app.add(Draws, self._draw)
        app.add(Panels, self._panels)

    def _lines(self, world: Host, view: RenderView) -> list[np.ndarray]:
        from ecs_tentacles.fur.render.strands import fur_lines

        return fur_lines(world, view)

    def _draw(self, world: Host, view: RenderView) -> int:
        from ecs_tentacles.fur.render.strands import draw_fur

        return draw_fur(world, view)

    def _panels(self, sandbox: SandboxView) -> list[Panel]:
        from ecs_tentacles.fur.render.furpanel import fur_panels

        return fur_panels(sandbox)
