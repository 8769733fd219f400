"""Threats: marked things that frighten creatures (the `threats` plugin's data).

A threat is either a scene `threats` entry, a point that follows a keyframed path, or a
creature marked `"threat": true`, whose mantle is the threat. `world.resource(ThreatData)` holds
them; the `threats` system moves path threats, and the fur plugin's `emotion` system
reads `world.resource(ThreatData).sources()` to rouse creatures nearby.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import esper
import numpy as np

from ecs_tentacles.components import RowComponent, RowField, Transform
from ecs_tentacles.ground import ground_of
from ecs_tentacles.numeric.keyframes import Channel, channels_from_keys
from ecs_tentacles.plugin import Problem
from ecs_tentacles.store import ArrayStore, Field

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


class ThreatStore(ArrayStore):
    """Path threats: their entity and world position (from a keyframed path)."""

    entity = Field(dtype=np.int64)
    pos = Field((3,))


@dataclass(eq=False, repr=False)
class Threat(RowComponent):
    """A marked entity that frightens creatures: world `pos` (follows its keyframed path)."""

    store: ThreatStore
    name: str
    pos = RowField()


class ThreatData:
    """`world.resource(ThreatData)`: path threats (a store and their paths) and threat creatures."""

    provided_by = "threats"  # the plugin that makes it (named by `world.resource` errors)

    def __init__(self) -> None:
        self.store = ThreatStore()
        self.paths: list[Channel] = []  # positions (columns 0, 1, 2) by store row
        self.bodies = np.zeros(0, dtype=np.int64)  # mantle transform rows of threat creatures
        self.creatures = np.zeros(0, dtype=np.int64)  # their creature entities
        self.version = 0  # bumped when a path threat is dropped or removed at run time

    def __len__(self) -> int:
        return len(self.store) + len(self.bodies)

    def sources(self, world: Host) -> tuple[np.ndarray, np.ndarray]:
        """Every threat's world position (n, 3) and owner creature entity (-1: none)."""
        pos = np.concatenate([self.store.pos, world.transforms.pos[self.bodies]])
        owners = np.concatenate([np.full(len(self.store), -1), self.creatures])
        return pos, owners

    def drop(self, world: Host, position: Sequence[float], name: str = "roach") -> int:
        """A path threat standing at `position` (x, y[, z]; on the ground when 2-d) from
        now on, named `name` (made unique); its entity. Creatures react as to any threat."""
        point = [float(v) for v in position]
        if len(point) == 2:
            point.append(float(ground_of(world).surface(np.array(point))[0]))
        taken = set(self.positions(world))
        unique, n = name, 2
        while unique in taken:
            unique, n = f"{name}_{n}", n + 1
        path = [{"time": 0.0, "position": point}]
        (entity,) = build_threats(world, [{"name": unique, "path": path}])
        self.version += 1
        return entity

    def remove(self, world: Host, threat: int) -> None:
        """Take path threat `threat` (an entity) away."""
        row = world.component(threat, Threat).row
        moved = self.store.remove(np.array([row]))
        self.paths = [replace(c, row=int(moved[c.row])) for c in self.paths if moved[c.row] >= 0]
        world.activate()
        esper.delete_entity(threat, immediate=True)
        self.version += 1

    def entities(self, world: Host) -> dict[int, str]:
        """Every path threat's name, by entity."""
        return {entity: threat.name for entity, threat in world.query(Threat)}

    def positions(self, world: Host) -> dict[str, np.ndarray]:
        """World position of every path threat, by name."""
        return {threat.name: threat.pos.copy() for _, threat in world.query(Threat)}


def mark_creature(world: Host, creature: int) -> None:
    """Make a creature's mantle a threat to the others."""
    threats: ThreatData = world.resource(ThreatData)
    row = world.component(creature, Transform).row
    threats.bodies = np.append(threats.bodies, row)
    threats.creatures = np.append(threats.creatures, creature)


def scene_threats(scene: Mapping[str, object]) -> list[Mapping[str, object]]:
    """The scene's `threats` (defaults filled in: [] when it names none)."""
    found = scene.get("threats", [])
    if not isinstance(found, list) or not all(isinstance(t, Mapping) for t in found):
        raise TypeError(f"threats: a list of objects, not {found!r}")
    return found


def build_threats(world: Host, specs: Sequence[Mapping[str, object]]) -> list[int]:
    """Threat entities that follow keyframed paths; returns their entities."""
    threats: ThreatData = world.resource(ThreatData)
    entities = []
    for i, spec in enumerate(specs):
        path = spec["path"]
        if not isinstance(path, list):
            raise TypeError(f"threats[{i}].path: a list of keys, not {path!r}")
        row = int(threats.store.add(pos=path[0]["position"])[0])
        name = str(spec.get("name", f"threat_{i}"))
        entity = world.create_entity(Threat(threats.store, row, name))
        threats.store.entity[row] = entity
        threats.paths += channels_from_keys(row, (0, 1, 2), path, "position")
        entities.append(entity)
    return entities


def threat_problems(scene: Mapping[str, object]) -> list[Problem]:
    """Threat names are unique and path keys come in time order."""
    problems: list[Problem] = []
    seen: dict[str, int] = {}
    threats = scene.get("threats", [])
    if not isinstance(threats, list):
        raise TypeError(f"threats: a list, not {threats!r}")
    for i, threat in enumerate(threats):
        name = threat.get("name", f"threat_{i}")
        if name in seen:
            problems.append(
                (("threats", i, "name"), f'duplicate name "{name}" (also threats[{seen[name]}])')
            )
        seen.setdefault(name, i)
        for k, key in enumerate(threat["path"]):
            if k and key["time"] <= threat["path"][k - 1]["time"]:
                previous = threat["path"][k - 1]["time"]
                problems.append(
                    (
                        ("threats", i, "path", k, "time"),
                        f"must be > {previous} (the previous key's), got {key['time']}",
                    )
                )
    return problems
