"""A running world written back as a scene: the roster, goals and settings as they are now.

    save_roster(world, "directed.json")      # atomic; validated before it is written

Every creature there now (spawned ones too, despawned ones not) is written from the
entry it was built from (`world.creature_specs`), at its mantle's current position and
heading, with what each plugin knows of it now (`Plugin.save_creature`: the locomotion
plugin's goals and parameters); the scene's other keys are the world's scene's, and
each plugin adds what it has at the scene level (`Plugin.save_scene`: threats dropped
in the sandbox). Loading the file builds the same roster with the same goals and
settings (creatures rest on the ground where their mantles were; one that crawled
too close to another or to a rock to be built there at rest goes to the nearest spot
where it fits). This module sits
above the world (as `loading`).
"""

from __future__ import annotations

import copy
import logging
import os
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.creatures.spawning import nearest_free
from ecs_tentacles.ground import ground_of
from ecs_tentacles.scene.construction import creature_layout
from ecs_tentacles.scene.overlap import segment_distances
from ecs_tentacles.scene.save import save_scene
from ecs_tentacles.scene.spec import CreatureSpec, as_spec

log = logging.getLogger("ecs_tentacles.creatures.roster_save")

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


def heading_deg(quat: np.ndarray) -> float:
    """The heading (degrees about +z) of a body with orientation `quat` (w, x, y, z)."""
    w, x, y, z = (float(v) for v in quat)
    return float(np.degrees(np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))))


def entry_now(world: Host, entity: int) -> dict[str, object]:
    """Creature `entity`'s scene entry as it is now: where its mantle is, which way it
    heads, and what every plugin knows of it (`Plugin.save_creature`)."""
    name = world.component(entity, Creature).name
    entry: dict[str, object] = copy.deepcopy(
        dict(world.creature_specs.get(entity) or {"name": name})
    )
    pose = world.component(entity, Transform)
    entry["position"] = [round(float(v), 6) for v in pose.pos[:2]]
    entry["heading_deg"] = round(heading_deg(pose.quat), 6)
    for plugin in world.plugins:
        plugin.save_creature(world, entity, entry)
    return entry


def roster_scene(world: Host) -> dict[str, object]:
    """The scene dict of `world` as it is now (module docstring); not yet validated."""
    scene: dict[str, object] = copy.deepcopy(world.scene) if world.scene is not None else {}
    scene.setdefault("version", 1)
    by_row = sorted(world.query(Creature), key=lambda item: item[1].row)
    scene["creatures"] = [entry_now(world, entity) for entity, _ in by_row]
    for plugin in world.plugins:
        plugin.save_scene(world, scene)
    return scene


def fit_at_rest(world: Host, entries: list[dict[str, object]]) -> int:
    """Move entries (in order) whose creature, built at rest where it is, would overlap
    an obstacle or a creature placed before it to the nearest spot where it fits
    (`spawning.nearest_free`); how many moved."""
    ground = ground_of(world)
    starts: list[np.ndarray] = []
    ends: list[np.ndarray] = []
    radii: list[np.ndarray] = []
    centres, reaches = np.zeros((0, 2)), np.zeros(0)
    names: list[str] = []

    def blocked(entry: CreatureSpec) -> str | None:
        if ground.has_obstacles:  # as the terrain checks a scene: resting on the ground
            s, e, r = creature_layout(entry, ground).capsules()
            points = np.concatenate([s, e, 0.5 * (s + e)])
            if (ground.inside_solid(points, np.tile(r, 3)) >= 0).any():
                return "an obstacle"
        layout = creature_layout(entry)  # as the scene's overlap check: on the plane
        s, e, r = layout.capsules()
        points = np.concatenate([s, e])
        centre = layout.origin[:2]
        reach = float(np.max(np.linalg.norm(points[:, :2] - centre, axis=1)) + r.max())
        near = np.flatnonzero(np.linalg.norm(centres - centre, axis=1) < reaches + reach)
        for i in near.tolist():
            gap = segment_distances(s[:, None], e[:, None], starts[i][None], ends[i][None])
            if (gap < r[:, None] + radii[i][None]).any():
                return f"creature {names[i]!r}"
        return None

    moved = 0
    for k, entry in enumerate(entries):
        fitted, blocker = nearest_free(as_spec(entry), blocked)
        if blocker is not None:
            entries[k] = dict(fitted)
            moved += 1
        layout = creature_layout(fitted)
        s, e, r = layout.capsules()
        starts.append(s)
        ends.append(e)
        radii.append(r)
        centre = layout.origin[:2]
        reach = float(np.max(np.linalg.norm(np.concatenate([s, e])[:, :2] - centre, axis=1)))
        centres = np.vstack([centres, centre])
        reaches = np.append(reaches, reach + float(r.max()))
        names.append(fitted["name"])
    return moved


def save_roster(world: Host, path: str | os.PathLike[str]) -> Path:
    """Write `roster_scene(world)` to `path` as JSON, validated and atomically; the path.

    Creatures that crawled close to each other or to a rock would overlap when built
    again at rest (tentacles spread): they are written at the nearest spot where they
    fit (`fit_at_rest`; logged). Raises SceneError (one line per problem) and writes
    nothing when the scene would not load."""
    scene = roster_scene(world)
    creatures = scene["creatures"]  # (the list `roster_scene` wrote)
    moved = fit_at_rest(world, creatures) if isinstance(creatures, list) else 0
    if moved:
        log.info("%s: %d creature(s) moved to where they fit with tentacles spread", path, moved)
    # checked as any scene (SceneError, one line each) by the world's own plugins: none
    # is looked up or imported again, so no file in the current folder is run; saved in
    # another folder, the files the scene names (terrain images, meshes) go along
    return save_scene(scene, path, world.plugins, source_dir=world.scene_dir, indent=2)
