"""Plugins: features that bring their own scene keys, stores, systems, checks and hooks.

Core is the World, its Schedule and the physics. Everything else (locomotion,
suckers, fur, threats, recording, the sandbox's drawing, users' behaviours) is a
`Plugin`: a schema fragment (creature-level and scene-level keys, and the schema of
its own `plugins.<name>` config), a per-creature build hook, its stores (world
resources), its systems at a named stage, its validation, its entries in the registries
of the layers above core (`build(app)`, `ecs_tentacles.registry`: the renderer's and
the sandbox's in `ecs_tentacles.render.registries`, the physics' in
`physics.registries`, the recorder's in `take.registries`, the shard planner's in
`distributed.registries`, `run`'s report's in `cli.registries`).
How a scene's `plugins` are found, trusted, imported and made is
`ecs_tentacles.scene.plugins`.

    class Wander(Plugin):
        name = "wander"
        config_schema = {"type": "object", "additionalProperties": False,
                         "properties": {"radius": {"type": "number", "default": 1.0}}}

        def systems(self):
            return [WanderSystem(self.config["radius"])]
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from contextlib import contextmanager
from typing import TYPE_CHECKING, ClassVar

from ecs_tentacles.roster_change import RosterChange
from ecs_tentacles.system import System

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.registry import App
    from ecs_tentacles.store import ArrayStore
    from ecs_tentacles.take.tracks import TrackSize


# a problem a check finds in a scene: the JSON path of what is wrong, and a message
Problem = tuple[tuple[str | int, ...], str]


class HookFailure(RuntimeError):
    """A plugin's hook called `sys.exit` (raised SystemExit): a failure like any other,
    one line naming the plugin and the hook (the command line exits 1), never a quiet
    exit with nothing done."""


@contextmanager
def calling(plugin: Plugin, hook: str) -> Iterator[None]:
    """Around a call of `plugin`'s `hook`: SystemExit becomes `HookFailure`."""
    try:
        yield
    except SystemExit as exc:
        code = "" if exc.code is None else f"({exc.code!r})"
        raise HookFailure(f"plugins.{plugin.key}: its {hook}() hook called sys.exit{code}") from exc


class Plugin:
    """A feature of the engine. Subclass it; every hook is optional."""

    name: ClassVar[str] = ""
    description: ClassVar[str] = ""
    requires: ClassVar[tuple[str, ...]] = ()  # plugins that must be on too
    # where a plugin on by default is built among the other defaults (lower first, then
    # by key); on by default is the entry point's group (`ecs_tentacles.plugins.default`)
    build_order: ClassVar[int] = 0
    # store columns this plugin's hooks read when a generic system calls them
    # (registry entries and take hooks): they count as that system's reads
    hook_reads: ClassVar[tuple[str, ...]] = ()
    # JSON Schema of this plugin's `plugins.<name>` config (defaults are filled in)
    config_schema: ClassVar[dict[str, object]] = {"type": "object", "additionalProperties": False}
    creature_schema: ClassVar[dict[str, object]] = {}  # creature key -> its schema
    scene_schema: ClassVar[dict[str, object]] = {}  # scene key -> its schema
    # keys of a creature's `tentacles` (and its `overrides`, without default) -> schema
    tentacle_schema: ClassVar[dict[str, object]] = {}
    defs: ClassVar[dict[str, object]] = {}  # "$defs" the fragments refer to ("#/$defs/...")

    # hooks of earlier versions, and what replaced them: a plugin that still defines
    # one is refused when its class is made, instead of being silently never called
    RENAMED_HOOKS: ClassVar[dict[str, str]] = {
        "export_curves": (
            "a TakeTracks entry (a TrackSource of kind 'curves'; docs/extending/output-hooks.md)"
        ),
        **{
            hook: f"a {kind} entry added in build(app) (ecs_tentacles.render.registries)"
            for hook, kind in (
                ("render_spheres", "Spheres"),
                ("render_lines", "Lines"),
                ("render_draw", "Draws"),
                ("render_points", "FramedPoints"),
                ("sandbox_panels", "Panels"),
                ("sandbox_click", "Clicks"),
                ("sandbox_state", "UndoStates"),
                ("sandbox_restore", "UndoStates"),
            )
        },
        "wants_motion": "a MotionWants entry added in build(app) (physics.registries)",
        "travel_targets": "a TravelTargets entry added in build(app) (physics.registries)",
        "take_tracks": "a TakeTracks entry added in build(app) (ecs_tentacles.take.registries)",
        "before_recording": "a RecordingStarts entry added in build(app) (take.registries)",
        "shard_reach": "a ShardReaches entry added in build(app) (distributed.registries)",
        "meeting_reach": "a MeetingReaches entry added in build(app) (distributed.registries)",
        "shard_groups": "a ShardGroups entry added in build(app) (distributed.registries)",
        "run_summary": "a RunSummaries entry added in build(app) (cli.registries)",
    }

    def __init_subclass__(cls, **kwargs: object) -> None:
        super().__init_subclass__(**kwargs)
        for old, new in Plugin.RENAMED_HOOKS.items():
            if old in vars(cls):
                raise TypeError(f"{cls.__name__}.{old}: this hook is now {new}")

    def __init__(self, config: Mapping[str, object] | None = None):
        self.config: dict[str, object] = dict(config or {})
        self.key = self.name  # the name a scene turned it on by
        self.source: str | None = None  # the file or module it came from, if not built in

    # -- registries ----------------------------------------------------------------------
    def build(self, app: App) -> None:
        """Add this plugin's entries to the registries of the layers that call them
        (`app.add(kind, entry)`; `ecs_tentacles.registry`): drawing, HUD sections, clicks
        and undo states (`ecs_tentacles.render.registries`). Runs once per world, after
        `resources` and `stores`."""

    # -- scene ---------------------------------------------------------------------------
    def problems(self, scene: Mapping[str, object]) -> list[Problem]:
        """Rules the schema cannot say, on a defaults-filled scene: (json path, message)."""
        return []

    def shapes_ground(self, scene: Mapping[str, object]) -> bool:
        """True when this plugin's keys of `scene` give the ground a shape (a heightfield)
        under the creatures: core's check that no creature starts below the plane z = 0
        is then left to this plugin (`problems` or `build_scene`)."""
        return False

    # -- building ------------------------------------------------------------------------
    def resources(self, world: Host) -> Sequence[object] | Mapping[str, object]:
        """Stores and APIs this plugin owns, reachable by type: `world.resource(MyStore)`.

        One object per type; give its class `provided_by = "<plugin name>"` so a world
        without this plugin says which plugin to turn on. (A mapping's values are taken.)
        """
        return ()

    def stores(self, world: Host) -> Mapping[str, ArrayStore]:
        """This plugin's stores by name (`"fur.guides"`: starting with the plugin's name),
        called after `resources`. Systems declare reads and writes as `<store>.<field>`
        against these names; snapshots copy them."""
        return {}

    def build_creature(self, world: Host, creature: int, spec: Mapping[str, object]) -> None:
        """Called for each creature, after its body is built (spec: its scene entry)."""

    def build_scene(self, world: Host, scene: Mapping[str, object]) -> None:
        """Called once after every creature is built, before physics is compiled."""

    def ready(self, world: Host) -> None:
        """Called once the world is built, its physics compiled and its systems
        scheduled, before its first frame (`World.from_scene`): the state a level starts
        from, for a plugin that keeps it (a game mode restarting from a snapshot)."""

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        """A creature was spawned (after `build_creature` and its physics) or despawned
        (after its rows left every store): follow it in anything kept beside the stores
        (`ecs_tentacles.roster_change`). Before a despawn, `despawning` is called."""

    def despawning(self, world: Host, creature: int) -> None:
        """Creature `creature` is about to be despawned (its rows and entities still
        exist): remove what this plugin made for it outside the stores (goal entities)."""

    def systems(self) -> list[System]:
        """Fresh instances of this plugin's systems (each declares its stage)."""
        return []

    # -- state ---------------------------------------------------------------------------
    def snapshot(self, world: Host) -> object:
        """A copy of this plugin's state between frames (for `world.snapshot()`)."""
        return None

    def restore(self, world: Host, state: object) -> None:
        """Put back what `snapshot` returned."""

    # -- saving --------------------------------------------------------------------------
    def save_creature(self, world: Host, creature: int, entry: dict[str, object]) -> None:
        """Write what this plugin knows of `creature` now into its scene entry `entry`
        (its goals, its parameters), for saving a directed crowd as a scene
        (`ecs_tentacles.creatures.roster_save`)."""

    def save_scene(self, world: Host, scene: dict[str, object]) -> None:
        """Write this plugin's scene-level state into `scene` when a running world is
        saved (`ecs_tentacles.creatures.roster_save`; the threats plugin: threats dropped since)."""

    def scene_files(self, scene: Mapping[str, object]) -> list[Problem]:
        """The files this plugin's keys of `scene` name, each as (its JSON path, the name
        as written, relative to the scene's folder): a save to another folder takes them
        along (`ecs_tentacles.scene.save`; the terrain plugin: height images, meshes)."""
        return []

    # -- output hooks (takes, shard plans, run reports) -------------------------------
    def take_sizes(self, scene: Mapping[str, object]) -> list[TrackSize]:
        """What this plugin's take tracks will hold for `scene` (defaults filled in),
        from the scene alone: a bake counts them with the bodies before anything is
        built, and refuses a take the reader would not read back."""
        return []

    def __repr__(self) -> str:
        return f"<plugin {self.key}>"


class SystemsPlugin(Plugin):
    """A plugin made of bare System classes (a scene's `systems` list, or a file of them)."""

    description = "systems named by import path"

    def __init__(self, factories: list[type[System]], config: Mapping[str, object] | None = None):
        super().__init__(config)
        self.factories = factories

    def systems(self) -> list[System]:
        return [factory() for factory in self.factories]
