"""Creatures that come and go while a world runs (`World.spawn`, `World.despawn`).

    octo = world.spawn({"name": "octo", "tentacles": {"count": 6}}, position=(2, 0))
    world.step(60)
    world.despawn(octo)

Spawn validates the creature entry as a scene would (one line per problem, its path
starting at `creature`), builds its body and every plugin's part of it (rows appended
to every store: nothing else moves), gives it a row in the physics batch of its
morphology (a model is compiled only for a new morphology) and tells plugins and
systems (`roster_changed`). Other creatures step on bit-identically: each is its own
row of state. A creature asked to spawn overlapping another creature or inside an
obstacle is refused (`SpawnError`), or with `on_overlap="move"` placed at the nearest
free spot (the `creature_spawned` event and the log say where).

Despawn removes the creature's rows from every store (the rows after them move up;
columns that refer to a store's rows follow, `store.Field.refers`), deletes its
entities (its body's, and those a plugin store's going rows name in an `entity`
column: fur guides and controls), takes it out of the physics and tells plugins and
systems. Events:
`creature_spawned(world, creature, creature_name, moved_to)` and
`creature_despawned(world, creature, creature_name)`.

This module sits above the world (as `loading`): `World.spawn` delegates here.
"""

from __future__ import annotations

import copy
import logging
import re
from collections.abc import Callable, Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal

import esper
import numpy as np

from ecs_tentacles.components import Creature, Tentacle
from ecs_tentacles.creatures.body import build_creature
from ecs_tentacles.events import CreatureDespawned, CreatureSpawned, SuckerReleased
from ecs_tentacles.ground import ground_of
from ecs_tentacles.host import PLACEMENT_KEYS
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.plugin import calling
from ecs_tentacles.roster_change import RosterChange
from ecs_tentacles.scene.construction import CreatureLayout, creature_layout
from ecs_tentacles.scene.defaults import with_defaults
from ecs_tentacles.scene.layouts import Layouts
from ecs_tentacles.scene.overlap import segment_distances
from ecs_tentacles.scene.physical import creature_problems
from ecs_tentacles.scene.spec import CreatureSpec, as_spec
from ecs_tentacles.scene.validate import format_path, validated_creature

if TYPE_CHECKING:
    from typing_extensions import Unpack  # (typing's own from Python 3.12)

    from ecs_tentacles.host import Host, Placement  # any world (`ecs_tentacles.world.World`)

log = logging.getLogger("ecs_tentacles.creatures.spawning")

CORE_STORES = ("transforms", "motors", "tentacles", "suckers", "creatures")
OnOverlap = Literal["refuse", "move"]
SEARCH_RINGS = 40  # rings of candidate spots around an occupied one ...
SPOTS_PER_RING = 16  # ... each this many spots, a quarter of the creature's reach apart


class SpawnError(ValueError):
    """A creature that cannot be spawned: one line per problem, nothing built."""

    def __init__(self, problems: Sequence[str]):
        self.problems = list(problems)
        super().__init__("\n".join(self.problems))


# -- the creature entry ------------------------------------------------------------------
def creature_entry(
    world: Host,
    spec: Mapping[str, object],
    position: Sequence[float] | np.ndarray | None = None,
    heading_deg: float | None = None,
    layouts: Layouts | None = None,
) -> CreatureSpec:
    """`spec` validated as a scene's creature entry, defaults filled in, placed at
    `position` / `heading_deg` when given, its name made unique in `world` (`octo` ->
    `octo_2`). Raises SpawnError (one line per problem) when it is not a valid entry.
    Its layout is worked out in `layouts` (a spawn's: it builds from it)."""
    if not isinstance(spec, Mapping):
        raise SpawnError([f"creature: must be an object, got {type(spec).__name__}"])
    entry = copy.deepcopy(dict(spec))
    if position is not None:
        entry["position"] = [float(v) for v in position]
    if heading_deg is not None:
        entry["heading_deg"] = float(heading_deg)
    entry.setdefault("name", "creature")
    entry.setdefault("position", [0.0, 0.0])
    if isinstance(entry["name"], str):
        entry["name"] = unique_name(world, entry["name"])
    scene = _scene_now(world)
    problems, completed = validated_creature(entry, scene, world.plugins)
    if completed is not None and not problems:
        where = ("creature",)  # (one creature: its paths start at `creature`)
        found = creature_problems(where, as_spec(completed), scene["physics"], layouts=layouts)
        problems = [f"{format_path(path)}: {message}" for path, message in found]
    if problems:
        raise SpawnError(problems)
    assert completed is not None
    return as_spec(completed)


def _scene_now(world: Host) -> dict[str, Any]:
    """The world's scene with the creatures it has now (a spawn is checked among them);
    a scene of defaults for a world built by hand."""
    scene = world.scene
    if scene is None:
        scene = with_defaults({"version": 1, "creatures": []}, world.plugins)
    return {**scene, "creatures": list(world.creature_specs.values())}


def unique_name(world: Host, name: str) -> str:
    """`name`, or `name_2`, `name_3`... : the first no creature of `world` has and no
    take being recorded has seen (`World.kept_names`)."""
    taken = taken_names(world)
    if name not in taken:
        return name
    base = re.sub(r"_\d+$", "", name)
    n = 2
    while _suffixed(base, n) in taken:
        n += 1
    return _suffixed(base, n)


def taken_names(world: Host) -> set[str]:
    """Names a new creature may not take: every creature's now and `World.kept_names`."""
    return {c.name for _, c in world.query(Creature)} | world.kept_names


def _suffixed(base: str, n: int, longest: int = 64) -> str:
    """`base_n`, `base` shortened so it stays within the schema's `longest` name."""
    suffix = f"_{n}"
    return base[: longest - len(suffix)] + suffix


# -- overlap with the creatures there and the obstacles ------------------------------------
def obstruction(world: Host, layout: CreatureLayout) -> str | None:
    """What a creature built as `layout` would overlap now: `"creature 'octo'"`, `"an
    obstacle"`, or None when the spot is free."""
    starts, ends, radii = layout.capsules()
    points = np.concatenate([starts, ends, 0.5 * (starts + ends)])
    ground = ground_of(world)
    if ground.has_obstacles and (ground.inside_solid(points, np.tile(radii, 3)) >= 0).any():
        return "an obstacle"
    physics = world.physics
    if not len(physics):
        return None
    proxies = physics.proxies
    pos, quat, centre, reach = proxies.sense(world.transforms)
    middle = layout.origin
    own_reach = float(np.max(np.linalg.norm(points - middle, axis=1)) + radii.max())
    near = np.flatnonzero(np.linalg.norm(centre - middle, axis=1) < reach + own_reach)
    for index in near.tolist():
        body = proxies.start[index] + np.arange(proxies.count[index])
        radius, half = proxies.size[body, 0], proxies.size[body, 1]
        along = np.where(proxies.kind[body, None] == 1, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0])
        axis = quat_rotate(quat[body], along) * half[:, None]
        gap = segment_distances(
            starts[:, None], ends[:, None], (pos[body] - axis)[None], (pos[body] + axis)[None]
        )
        if (gap < radii[:, None] + radius[None]).any():
            name = world.creature_name(int(physics.creature_entity[index]))
            return f"creature {name!r}"
    return None


def free_spot(world: Host, entry: CreatureSpec) -> tuple[CreatureSpec, str | None]:
    """`entry` where it asked to be if free, else moved to the nearest free spot on rings
    around it; and what was in the way (None: not moved). SpawnError if none is free."""
    placed, blocker, _ = free_spot_layout(world, entry)
    return placed, blocker


def free_spot_layout(
    world: Host, entry: CreatureSpec, layouts: Layouts | None = None
) -> tuple[CreatureSpec, str | None, CreatureLayout]:
    """`free_spot`, and the layout on this world's ground of the entry it returns (the
    one it last checked: a spawn builds from it instead of working it out again).
    `layouts`: where `entry`'s layout may be already (a spawn's)."""
    ground = ground_of(world)
    book = Layouts() if layouts is None else layouts
    last: list[tuple[CreatureSpec, CreatureLayout]] = []

    def blocked(candidate: CreatureSpec) -> str | None:
        if candidate is entry:
            layout = book.on(entry, ground)
        else:  # a copy moved to another spot
            layout = creature_layout(candidate, ground)
        last[:] = [(candidate, layout)]
        return obstruction(world, layout)

    placed, blocker = nearest_free(entry, blocked, book.on_plane(entry))
    checked, layout = last[0]
    assert checked is placed  # the last spot checked is the free one returned
    return placed, blocker, layout


def nearest_free(
    entry: CreatureSpec,
    blocked: Callable[[CreatureSpec], str | None],
    flat: CreatureLayout | None = None,
) -> tuple[CreatureSpec, str | None]:
    """`entry` if `blocked` finds nothing in the way of it, else a copy at the nearest
    spot on rings around it (a quarter of its reach apart) where nothing is; and what
    was in the way first (None: not moved). SpawnError if no spot is free. `flat`:
    `entry`'s layout on the plane, when the caller has it."""
    blocker = blocked(entry)
    if blocker is None:
        return entry, None
    layout = creature_layout(entry) if flat is None else flat  # only its reach is wanted
    _, ends, radii = layout.capsules()
    reach = float(np.max(np.linalg.norm(ends[:, :2] - layout.origin[:2], axis=1)) + radii.max())
    x, y = entry["position"][:2]
    for ring in range(1, SEARCH_RINGS + 1):
        distance = ring * 0.25 * reach
        turns = np.arange(SPOTS_PER_RING) * 2.0 * np.pi / SPOTS_PER_RING + 0.5 * ring
        for angle in turns.tolist():
            moved = copy.deepcopy(entry)
            spot = [x + distance * np.cos(angle), y + distance * np.sin(angle)]
            moved["position"] = spot + list(entry["position"][2:])
            if blocked(moved) is None:
                return moved, blocker
    farthest = SEARCH_RINGS * 0.25 * reach
    line = f"creature {entry['name']!r}: no free spot within {farthest:.1f} m of ({x:g}, {y:g})"
    raise SpawnError([f"{line}: it overlaps {blocker}"])


# -- spawn and despawn ---------------------------------------------------------------------
def spawn(world: Host, spec: Mapping[str, object], **placement: Unpack[Placement]) -> int:
    """Build one creature into the running `world`; its entity (module docstring)."""
    unknown = sorted(set(placement) - PLACEMENT_KEYS)
    if unknown:  # (a script without a type checker: a typo is not silently dropped)
        known = ", ".join(sorted(PLACEMENT_KEYS))
        raise TypeError(f"spawn() got an unexpected keyword {unknown[0]!r} (takes {known})")
    position, heading_deg = placement.get("position"), placement.get("heading_deg")
    on_overlap = placement.get("on_overlap", "refuse")
    if on_overlap not in ("refuse", "move"):
        raise ValueError(f"on_overlap: must be 'refuse' or 'move', got {on_overlap!r}")
    world.activate()
    layouts = Layouts()  # its layout: the physical checks', then the spot's and the build's
    entry = creature_entry(world, spec, position, heading_deg, layouts)
    moved_to = None
    if on_overlap == "move":
        placed, blocker, layout = free_spot_layout(world, entry, layouts)
        if blocker is not None:
            moved_to = tuple(placed["position"])
            log.info(
                "spawn %r: (%s) overlaps %s; moved to (%s)",
                entry["name"],
                ", ".join(f"{v:g}" for v in entry["position"]),
                blocker,
                ", ".join(f"{v:.2f}" for v in moved_to),
            )
        entry = placed
    else:
        layout = layouts.on(entry, ground_of(world))
        blocker = obstruction(world, layout)
        if blocker is not None:
            where = ", ".join(f"{v:g}" for v in entry["position"])
            line = f"creature {entry['name']!r} at ({where}): overlaps {blocker}"
            raise SpawnError([f"{line} (pick a free spot, or on_overlap='move')"])
    return place(world, entry, moved_to, layout)


def place(
    world: Host,
    entry: CreatureSpec,
    moved_to: tuple[float, ...] | None = None,
    layout: CreatureLayout | None = None,
) -> int:
    """Build a creature entry `creature_entry` made (checked, defaults in, its name
    unique) where it says, without looking for overlaps: `spawn`'s last step, and how
    `scatter` places many copies of one checked entry at spots it knows are free."""
    world.activate()
    wanted = entry["name"]
    if wanted in taken_names(world):
        raise SpawnError(  # a take would name two creatures alike: unwritable at the end
            [f"creature.name: {wanted!r} is taken (by a creature here or in the take recorded)"]
        )
    before = {name: len(store) for name, store in world.stores.items()}
    entity = build_creature(world, entry, layout)
    for plugin in world.plugins:
        with calling(plugin, "build_creature"):
            plugin.build_creature(world, entity, entry)
    index = world.physics.add_creature(world, entity)
    added = {
        name: np.arange(before.get(name, 0), len(store))
        for name, store in world.stores.items()
        if len(store) > before.get(name, 0)
    }
    world.creature_specs[entity] = entry
    _tell(world, RosterChange(entity, spawned=True, index=index, added=added))
    world.events.emit(CreatureSpawned(world, entity, entry["name"], moved_to))
    return entity


def despawn(world: Host, entity: int) -> None:
    """Remove creature `entity` and everything it owns (module docstring)."""
    world.activate()
    creature = world.try_component(entity, Creature)
    if creature is None:
        raise KeyError(f"entity {entity} is not a creature of this world")
    name = creature.name
    for plugin in world.plugins:
        plugin.despawning(world, entity)
    dead = _owned_rows(world, creature)
    suckers = world.suckers
    for row in dead["suckers"][suckers.attached[dead["suckers"]]].tolist():  # let go first
        suckers.attached[row] = False
        sucker = int(suckers.entity[row])
        world.events.emit(SuckerReleased(world, sucker, "despawn"))
    owned = _row_entities(world, dead)  # read before the rows go
    moved = {key: world.stores[key].remove(rows) for key, rows in dead.items() if len(rows)}
    for store in world.stores.values():
        for key, new in moved.items():
            store.renumber(key, new)
    _delete_entities(world, entity, creature, owned)
    index = world.physics.lod.index(entity)
    world.physics.remove_creature(world, entity, moved)
    world.creature_specs.pop(entity, None)
    _tell(world, RosterChange(entity, spawned=False, index=index, moved=moved))
    world.events.emit(CreatureDespawned(world, entity, name))


def _owned_rows(world: Host, creature: Creature) -> dict[str, np.ndarray]:
    """Every store's rows that belong to `creature`: the body's, then every store whose
    rows line up with a body store's or refer to rows that go (fur guides -> mantle)."""
    c = creature.row
    first, count = int(world.creatures.first_tentacle[c]), int(world.creatures.tentacles[c])
    tentacles = np.arange(first, first + count)
    t = world.tentacles
    links = np.concatenate(
        [
            np.arange(a, a + n)
            for a, n in zip(t.first_link[tentacles], t.links[tentacles], strict=True)
        ]
    )
    bodies = np.concatenate(
        [[world.creatures.mantle_row[c]]]
        + [
            np.arange(a, a + n)
            for a, n in zip(t.base_row[tentacles], t.links[tentacles], strict=True)
        ]
    )
    dead: dict[str, np.ndarray] = {
        "creatures": np.array([c]),
        "tentacles": tentacles,
        "motors": links,
        "suckers": np.flatnonzero(np.isin(world.suckers.tentacle_row, tentacles)),
        "transforms": np.sort(bodies.astype(np.int64)),
    }
    others = [name for name in world.stores if name not in CORE_STORES]
    for _ in range(len(others) + 1):  # until nothing more goes (chains: controls -> sets)
        changed = False
        for name in others:
            store = world.stores[name]
            gone = np.zeros(len(store), dtype=bool)
            partner = type(store).lines_up_with
            if partner is not None and partner in dead:
                gone[dead[partner]] = True
            for field in store.fields():
                if field.refers in dead:  # a gather per row, not a sort (`np.isin`)
                    going = np.zeros(len(world.stores[field.refers]) + 1, dtype=bool)
                    going[dead[field.refers]] = True  # (the last entry, for row -1, stays False)
                    gone |= going[getattr(store, field.name)]
            rows = np.flatnonzero(gone)
            if len(rows) != len(dead.get(name, ())):
                dead[name], changed = rows, True
        if not changed:
            break
    return dead


def _row_entities(world: Host, dead: dict[str, np.ndarray]) -> list[int]:
    """The entities that the going rows of plugin stores with an `entity` column stand
    for (fur guides and controls): they go with their rows."""
    owned: list[int] = []
    for name, rows in dead.items():
        store = world.stores[name]
        if name not in CORE_STORES and any(f.name == "entity" for f in store.fields()):
            owned += store.entity[rows].tolist()  # type: ignore[attr-defined]
    return owned


def _delete_entities(world: Host, entity: int, creature: Creature, rows: list[int]) -> None:
    for row_entity in rows:
        esper.delete_entity(row_entity, immediate=True)
    for tentacle_entity in creature.tentacles:
        tentacle = world.component(tentacle_entity, Tentacle)
        for owned in (*tentacle.links, *tentacle.suckers, tentacle_entity):
            esper.delete_entity(owned, immediate=True)
    esper.delete_entity(entity, immediate=True)


def _tell(world: Host, change: RosterChange) -> None:
    for plugin in world.plugins:
        plugin.roster_changed(world, change)
    for system in world.schedule:
        system.roster_changed(world, change)
