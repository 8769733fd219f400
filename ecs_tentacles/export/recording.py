"""Recording a live World into a `Take`, one frame at a time.

`TakeRecorder(world)` fixes the layout once (which store rows are which bodies,
suckers, goals) and `capture()` copies the current frame with one gather per array;
the `record` system (`ecs_tentacles.systems.record.record`) calls it after physics_sync.
Goals are discovered as they appear (scripts may add some); fur guides are read
through the plugins' export hook (`plugin_curves`: the fur plugin's guides).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.components import Creature, Link, Tentacle, Transform
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.plugin import GuideFrame
from ecs_tentacles.take import FORMAT, VERSION, Take

if TYPE_CHECKING:
    from ecs_tentacles.world import World


GuideSource = Callable[["World"], GuideFrame | None]


def plugin_curves(world: World) -> GuideFrame | None:
    """The curves the world's plugins export (`Plugin.export_curves`: the fur guides)."""
    for plugin in world.plugins:
        found = plugin.export_curves(world)
        if found is not None:
            return found
    return None


def pose_fur_at_build(world: World) -> None:
    """Pose fur guides before the first frame, so a take's frame 0 has them.

    The rig system poses guides during a frame; at the built pose nothing has run. A
    fresh rig (its own dynamics state, thrown away) poses them once; it writes only
    the rig's output buffers, which the real rig rewrites every frame.
    """
    fur = world.get_resource(FurData)
    if world.frame == 0 and fur is not None and len(fur.guides) and "rig" in world.schedule:
        type(world.schedule["rig"])().process(world, 0.0)


def scene_sha256(scene: dict[str, Any] | None) -> str:
    """SHA-256 of a scene's canonical JSON (sorted keys, no spaces); '' without a scene."""
    if scene is None:
        return ""
    text = json.dumps(scene, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


class TakeRecorder:
    """Copies a world's frames into growing float32 arrays; `take()` returns the Take.

    `fps` is the take's frame rate (the world's by default; a bake recording every
    k-th frame passes world fps / k). `scene_sha256` defaults to the hash of
    `world.scene`.
    """

    def __init__(
        self,
        world: World,
        *,
        fps: float | None = None,
        scene_sha256: str | None = None,
        capacity: int = 64,
        guides: GuideSource = plugin_curves,
    ):
        self.world = world
        self.guides = guides
        self._layout(world)
        self.header: dict[str, Any] = {
            "format": FORMAT,
            "version": VERSION,
            "scene": world.name,
            "scene_sha256": _sha(world) if scene_sha256 is None else scene_sha256,
            "seed": int(world.seed),
            "fps": float(fps if fps is not None else world.settings.fps),
            "sim_fps": float(world.settings.fps),
            "substeps": int(world.settings.substeps),
            "frames": 0,
            "creatures": self._creatures,
            "bodies": self._bodies,
            "suckers": self._suckers,
            "goals": [],
            "guides": None,
        }
        bodies, suckers = len(self._rows), len(self._suckers)
        capacity = max(1, capacity)
        self._pos = np.empty((capacity, bodies, 3), np.float32)
        self._quat = np.empty((capacity, bodies, 4), np.float32)
        self._attached = np.empty((capacity, suckers), np.bool_)
        self._anchor = np.empty((capacity, suckers, 3), np.float32)
        self._goal_columns: dict[int, int] = {}  # goal entity -> column
        self._goal_pos: list[np.ndarray] = []
        self._goals_alive: list[list[int]] = []  # per frame, the live columns
        self._points: list[np.ndarray] = []
        self._widths: list[np.ndarray] = []
        self.count = 0
        # physics recoveries, marked on the take frame that follows them
        self._health: list[dict[str, Any]] = []
        world.events.on("creature_recovered", self._on_health("recovered"))
        world.events.on("creature_frozen", self._on_health("frozen"))

    def _on_health(self, what: str) -> Any:
        def handler(*, creature: int, cause: str, **_: Any) -> None:
            index = self._creature_index[creature]
            entry = {"frame": self.count, "creature": index, "event": what, "cause": cause}
            self._health.append(entry)

        return handler

    def _layout(self, world: World) -> None:
        """Body and sucker tables in take order: creature by creature, mantle then links."""
        self._creatures: list[dict[str, Any]] = []
        self._bodies: list[dict[str, Any]] = []
        rows: list[int] = []
        by_entity = sorted(world.query(Creature), key=lambda item: item[1].row)
        self._creature_index = {entity: i for i, (entity, _) in enumerate(by_entity)}
        for index, (entity, creature) in enumerate(by_entity):
            name = creature.name
            entry: dict[str, Any] = {"name": name, "mantle": len(rows), "tentacles": []}
            rows.append(world.component(entity, Transform).row)
            self._bodies.append(_body(f"{name}/mantle", index, "cylinder", "Z", creature))
            for tentacle_entity in creature.tentacles:
                tentacle = world.component(tentacle_entity, Tentacle)
                chain = []
                for link_entity in tentacle.links:
                    link = world.component(link_entity, Link)
                    chain.append(len(rows))
                    rows.append(world.component(link_entity, Transform).row)
                    body = f"{name}/tentacles/t{tentacle.index}/link{link.index}"
                    self._bodies.append(_body(body, index, "capsule", "X", link))
                entry["tentacles"].append(chain)
            self._creatures.append(entry)
        self._rows = np.asarray(rows, dtype=np.int64)
        body_of_row = {row: i for i, row in enumerate(rows)}
        self._suckers: list[dict[str, Any]] = []
        seen: dict[int, int] = {}
        suckers = world.suckers
        for link_row, offset in zip(
            suckers.link_row.tolist(), suckers.offset.tolist(), strict=True
        ):
            carrier = body_of_row[link_row]
            n = seen[carrier] = seen.get(carrier, -1) + 1
            name = f"{self._bodies[carrier]['name']}/sucker{n}"
            self._suckers.append({"name": name, "body": carrier, "offset": offset})

    def capture(self) -> None:
        """Append the world's current frame."""
        world, i = self.world, self.count
        if i == len(self._pos):
            self._grow()
        transforms = world.transforms
        self._pos[i] = transforms.pos[self._rows]
        self._quat[i] = transforms.quat[self._rows]
        self._attached[i] = world.suckers.attached
        self._anchor[i] = world.suckers.anchor
        goals = list(world.query(Goal))
        new = [(e, g) for e, g in goals if e not in self._goal_columns]
        # new goals in creature, then path order: never in entity-id order, which
        # depends on which other creatures the world holds (a shard of a bake)
        for entity, goal in sorted(
            new, key=lambda eg: (self._creature_index[eg[1].owner], eg[1].order)
        ):
            self._add_goal(entity, goal)
        alive = sorted(self._goal_columns[entity] for entity, _ in goals)
        self._goals_alive.append(alive)
        guides = self.guides(world)
        if guides is not None:
            self._add_guides(guides)
        elif self._points:
            raise ValueError("fur guides disappeared during the recording")
        self.count += 1

    def _add_goal(self, entity: int, goal: Goal) -> int:
        column = self._goal_columns[entity] = len(self._goal_pos)
        creature = self._creature_index[goal.owner]
        number = sum(g["creature"] == creature for g in self.header["goals"])
        name = f"{self._creatures[creature]['name']}/goals/goal{number}"
        self.header["goals"].append({"name": name, "creature": creature, "radius": goal.radius})
        self._goal_pos.append(np.asarray(goal.position, dtype=np.float64))
        return column

    def _add_guides(self, guides: GuideFrame) -> None:
        points = np.asarray(guides.points, dtype=np.float32)
        widths = np.broadcast_to(np.asarray(guides.widths, dtype=np.float32), points.shape[:2])
        if points.ndim != 3 or points.shape[2] != 3:
            raise ValueError(f"fur guide points must be (guides, points, 3), got {points.shape}")
        if self._points and points.shape != self._points[0].shape:
            raise ValueError(f"fur guides changed shape: {self._points[0].shape} -> {points.shape}")
        if not self._points:
            owners = [self._creature_index.get(int(e), -1) for e in guides.creatures]
            self.header["guides"] = {"creatures": owners}
        self._points.append(points)
        self._widths.append(np.array(widths))

    def _grow(self) -> None:
        for name in ("_pos", "_quat", "_attached", "_anchor"):
            old = getattr(self, name)
            grown = np.empty((2 * len(old), *old.shape[1:]), old.dtype)
            grown[: len(old)] = old
            setattr(self, name, grown)

    def take(self) -> Take:
        """The frames captured so far as a Take (copies; recording may go on)."""
        n = self.count
        goals = len(self._goal_pos)
        active = np.zeros((n, goals), np.bool_)
        for frame, alive in enumerate(self._goals_alive):
            active[frame, alive] = True
        header = json.loads(json.dumps(self.header))  # a deep copy
        header["frames"] = n
        events = [e for e in self._health if e["frame"] < n]
        header["health"] = {
            "recoveries": sum(e["event"] == "recovered" for e in events),
            "frozen": sum(e["event"] == "frozen" for e in events),
            "events": events,
        }
        return Take(
            header=header,
            pos=self._pos[:n].copy(),
            quat=self._quat[:n].copy(),
            sucker_attached=self._attached[:n].copy(),
            sucker_anchor=self._anchor[:n].copy(),
            goal_pos=np.array(self._goal_pos, np.float32).reshape(goals, 3),
            goal_active=active,
            guide_points=np.stack(self._points) if self._points else None,
            guide_widths=np.stack(self._widths) if self._widths else None,
        )


def _body(name: str, creature: int, shape: str, axis: str, part: Any) -> dict[str, Any]:
    if isinstance(part, Creature):
        radius, length = part.mantle_radius, part.mantle_height
    else:
        radius, length = part.radius, part.length
    return {
        "name": name,
        "creature": creature,
        "shape": shape,
        "axis": axis,
        "radius": float(radius),
        "length": float(length),
    }


def _sha(world: World) -> str:
    return scene_sha256(world.scene)
