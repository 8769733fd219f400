"""Gait clips shared by morphology: every creature whose physics model is the same
(`model_layout(...).key`) replays one recording.

A world records each morphology once, from its first creature of that morphology. The
cache keeps a recording under its morphology *and* what it was recorded from (that
creature's entry as `one_creature_scene` stages it, less its name): a world whose first
creature of a morphology behaves otherwise (gait, speed, waves) records its own, so what
a world replays never depends on which worlds this process built before it.

    cache = ClipCache()
    clips = cache.for_creature(world, entity)        # a creature of a built world
    clips = cache.get(scene["creatures"][3], scene["physics"])   # a scene entry
    cache.seconds                                    # recording cost per key

Reads scene creature entries (from the world's `scene` for `for_creature`); records
with `GaitClips.record` on a miss; keeps the clips and their cost. With `disk=True` (the
cache replay uses) a miss first reads the clips kept on disk by an earlier run, and a
recording is kept there (`ecs_tentacles.clips.disk`: checked as it is read).
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING, TypedDict, Unpack

from ecs_tentacles.clips import disk
from ecs_tentacles.clips.clips import GaitClips
from ecs_tentacles.clips.gait_world import one_creature_scene
from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.creatures.body import build_creature
from ecs_tentacles.physics.model import ModelLayout, model_layout
from ecs_tentacles.scene.scene_spec import PhysicsSpec
from ecs_tentacles.scene.spec import as_spec
from ecs_tentacles.settings import Settings
from ecs_tentacles.world import World

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class RecordOptions(TypedDict, total=False):
    """`GaitClips.record`'s keywords."""

    warmup: float  # s
    seconds: float  # s
    loop: tuple[float, float]  # s


class ClipCache:
    """Clips by morphology key; `record_options` go to `GaitClips.record`. With `disk`,
    recordings are also kept between runs (`ecs_tentacles.clips.disk`) and read back
    (checked) instead of recorded again."""

    def __init__(self, *, disk: bool = False, **record_options: Unpack[RecordOptions]):
        self.record_options = record_options
        self.disk = disk
        self.clips: dict[tuple[object, ...], GaitClips] = {}

    @property
    def seconds(self) -> dict[tuple[object, ...], float]:
        """Wall-clock seconds each morphology's recording took."""
        return {key: clips.seconds for key, clips in self.clips.items()}

    def __len__(self) -> int:
        return len(self.clips)

    def get(self, creature: dict[str, object], physics: PhysicsSpec | None = None) -> GaitClips:
        """The clips of the morphology of `creature` (a scene creature entry, defaults
        filled in as `load_scene` leaves them), recorded on first use."""
        layout = _morphology(creature, physics)
        return self._get(layout, _seconds_per_frame(physics), creature, physics)

    def for_creature(self, world: Host, entity: int) -> GaitClips:
        """The clips of creature `entity` of `world`, from its entry (the scene's, or the
        one it was spawned from: `world.creature_specs`)."""
        creature = world.component(entity, Creature)
        layout = model_layout(world, creature, world.component(entity, Transform))
        entry = world.creature_specs.get(entity)
        if entry is None:
            raise ValueError(f"creature {creature.name!r}: no entry to record its clips from")
        physics = world.scene.get("physics") if world.scene is not None else None
        return self._get(layout, world.settings.dt, dict(entry), physics)

    def _get(
        self,
        layout: ModelLayout,
        dt: float,
        creature: dict[str, object],
        physics: PhysicsSpec | None,
    ) -> GaitClips:
        key, recording = layout.key, recording_input(creature, physics)
        full_key = (key, recording)
        clips = self.clips.get(full_key)
        if clips is None:
            stored = disk.entry_key(recording, self.record_options) if self.disk else ""
            hinges = len(layout.actuators)  # the free joint (7 / 6), then one per hinge
            shape = disk.Shape(list(layout.bodies), 7 + hinges, 6 + hinges, dt)
            clips = disk.read(stored, shape, key) if self.disk else None
            if clips is None:
                clips = GaitClips.record(creature, physics, **self.record_options)
                if clips.key != key:
                    raise RuntimeError(f"creature {creature.get('name')!r}: recorded another key")
                if self.disk:
                    disk.keep(stored, clips)
            self.clips[full_key] = clips
        return clips


def recording_input(creature: dict[str, object], physics: PhysicsSpec | None = None) -> str:
    """What a recording of `creature` is made from (its entry staged alone at the origin,
    without its name), as canonical JSON: equal strings record equal clips."""
    unnamed = {key: value for key, value in creature.items() if key != "name"}
    return json.dumps(one_creature_scene(unnamed, physics), sort_keys=True, default=str)


def morphology_key(
    creature: dict[str, object], physics: PhysicsSpec | None = None
) -> tuple[object, ...]:
    """The physics morphology key of a scene creature entry, compiling nothing."""
    return _morphology(creature, physics).key


def _morphology(creature: dict[str, object], physics: PhysicsSpec | None) -> ModelLayout:
    """The model layout of a scene creature entry (alone in a world), compiling nothing."""
    world = World(_settings(physics), name="clip-key")
    try:
        entity = build_creature(world, as_spec(creature))
        return model_layout(
            world, world.component(entity, Creature), world.component(entity, Transform)
        )
    finally:
        world.close()


def _settings(physics: PhysicsSpec | None) -> Settings:
    return Settings.from_physics(physics) if physics is not None else Settings()


def _seconds_per_frame(physics: PhysicsSpec | None) -> float:
    return _settings(physics).dt
