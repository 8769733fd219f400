"""Scene data -> fur entities: guides, controls, the creature's Fur and Emotion.

Called by the fur plugin's build hook (`ecs_tentacles.fur.plugin`) for a creature with
`fur` or `emotion`. Guides attach to the mantle body (its Transform row); their roots
live in the mantle's local frame.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import esper
import numpy as np

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.fur import groom as grooming
from ecs_tentacles.fur.components import Emotion, Fur, FurControl, FurGuide
from ecs_tentacles.fur.controls import expand_mirrors, nearest_control
from ecs_tentacles.fur.stores import BEHAVIOURS, COLUMNS, FurData
from ecs_tentacles.numeric.keyframes import channels_from_keys

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


def _points_per_guide(world: Host, spec: dict[str, Any]) -> int:
    """The world's shared point count: the largest any fur of the scene asks for."""
    if world.resource(FurData).points:
        return world.resource(FurData).points
    asked = [spec["groom"]["points"]]
    if world.scene is not None:
        asked += [c["fur"]["groom"]["points"] for c in world.scene["creatures"] if "fur" in c]
    return int(max(asked))


def build_fur(world: Host, creature: int, spec: dict[str, Any]) -> int:
    """Controls and guides of `creature` from a defaults-filled `fur` spec; the Fur row."""
    fur = world.resource(FurData)
    info = world.component(creature, Creature)
    body = world.component(creature, Transform).row
    fur.points = _points_per_guide(world, spec)
    dynamics, erect = spec["dynamics"], spec["piloerection"]
    row = int(
        fur.sets.add(
            creature=creature,
            body_row=body,
            enabled=[float(b in spec["behaviours"]) for b in BEHAVIOURS],
            twist_max=np.radians(spec["twist_max_deg"]),
            reach=spec["direction_reach"],
            min_elevation=np.radians(spec["min_elevation_deg"]),
            stiffness=dynamics["stiffness"],
            damping=dynamics["damping"],
            gravity_scale=dynamics["gravity_scale"],
            erect_lift=erect["lift"],
            erect_random=erect["random"],
            colour=spec["colour"],
            width=spec["width"],
            children=spec["children"],
        )[0]
    )
    controls = _build_controls(world, creature, row, spec["controls"])
    guides = _build_guides(world, creature, row, body, info, spec, controls)
    component = Fur(fur.sets, row, spec["preset"], guides, [e for e, _ in controls.values()])
    world.activate()
    esper.add_component(creature, component)
    return row


def _build_controls(
    world: Host, creature: int, fur_row: int, specs: list[dict[str, object]]
) -> dict[str, tuple[int, int]]:
    """Control entities (mirrored twins included): name -> (entity, control row)."""
    store = world.resource(FurData).controls
    made: dict[str, tuple[int, int]] = {}
    for spec in expand_mirrors(specs):
        values = {k: spec[k] for k in BEHAVIOURS}
        row = int(
            store.add(
                fur_row=fur_row,
                position=spec["position"],
                rest_position=spec["position"],
                emotion=spec["emotion"],
                colour=spec["colour"],
                size=spec["size"],
                **values,
            )[0]
        )
        control = FurControl(store, row, spec["name"], spec["shape"], creature)
        entity = world.create_entity(control)
        store.entity[row] = entity
        made[spec["name"]] = (entity, row)
        for track in spec["tracks"]:
            columns = COLUMNS[track["attribute"]]
            world.resource(FurData).tracks += channels_from_keys(row, columns, track["keys"])
    return made


def _build_guides(
    world: Host,
    creature: int,
    fur_row: int,
    body: int,
    info: Creature,
    spec: dict[str, Any],
    controls: dict[str, tuple[int, int]],
) -> list[int]:
    fur = world.resource(FurData)
    radius, height = info.mantle_radius, info.mantle_height
    groom = dict(spec["groom"], points=fur.points)
    parts = [grooming.generate(groom, radius, height)]
    listed = spec["guides"]
    if listed:
        extra = grooming.explicit(listed, fur.points, radius, height)
        rng = np.random.default_rng([groom["seed"], 1])
        drawn = rng.uniform(-1.0, 1.0, len(listed))
        extra.multiplier = np.array(
            [g.get("multiplier", d) for g, d in zip(listed, drawn, strict=True)], dtype=np.float64
        )
        parts.append(extra)
    fields = ("root", "normal", "rest", "side", "length", "multiplier", "shape")
    data = {f: np.concatenate([getattr(p, f) for p in parts]) for f in fields}
    names = list(controls)
    rows = np.array([controls[n][1] for n in names])
    rests = fur.controls.rest_position[rows]
    assigned = rows[nearest_control(data["root"], rests)]
    first_listed = len(data["root"]) - len(listed)
    for i, guide in enumerate(listed):
        if "control" in guide:
            assigned[first_listed + i] = controls[guide["control"]][1]
    order = np.argsort(assigned, kind="stable")  # grouped by control: the rig's runs
    assigned = assigned[order]
    data = {k: v[order] for k, v in data.items()}
    shape = data.pop("shape")
    new = fur.guides.add(
        len(assigned), body_row=body, fur_row=fur_row, control_row=assigned, **data
    )
    fur.add_shapes(shape)
    entities = []
    for row in new:
        entity = world.create_entity(FurGuide(fur.guides, int(row), fur, creature))
        entities.append(entity)
    fur.guides.entity[new] = entities
    return entities


def build_emotion(world: Host, creature: int, spec: dict[str, Any]) -> int:
    """The creature's Emotion (its controls get driven by it); returns the emotion row."""
    store = world.resource(FurData).emotions
    row = int(
        store.add(
            creature=creature,
            body_row=world.component(creature, Transform).row,
            radius=spec["radius"],
            rise=spec["rise_s"],
            decay=spec["decay_s"],
            anticipation=spec["anticipation"],
        )[0]
    )
    world.activate()
    esper.add_component(creature, Emotion(store, row, spec["kind"]))
    fur = world.try_component(creature, Fur)
    if fur is not None:
        rows = [world.component(e, FurControl).row for e in fur.controls]
        world.resource(FurData).controls.emotion_row[rows] = row
    return row
