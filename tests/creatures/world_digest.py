"""A digest of everything a built world holds before its first frame: every entity
with its components' values, every store's rows (handles included) and the physics
(each batch's morphology key, store rows, state and poses). Two worlds with the same
digest were built the same, bit for bit (`test_build_digest.py`)."""

from __future__ import annotations

import dataclasses
import hashlib
from typing import Any

import esper
import numpy as np

from ecs_tentacles.store import ArrayStore
from ecs_tentacles.world import World

PHYSICS_ROWS = ("body_ids", "body_rows", "actuator_motor_rows", "actuator_target_index",
                "sucker_rows")  # fmt: skip


def _value(value: Any) -> Any:
    """A value as plain data a digest can take (objects by their type, arrays by bytes)."""
    if isinstance(value, np.ndarray):
        return ("array", str(value.dtype), value.shape, hashlib.sha256(value.tobytes()).hexdigest())
    if isinstance(value, (np.generic,)):
        return _value(np.asarray(value))
    if isinstance(value, (bool, int, float, str, type(None))):
        return repr(value)
    if isinstance(value, (list, tuple)):
        return [_value(v) for v in value]
    if isinstance(value, dict):
        return sorted((repr(k), _value(v)) for k, v in value.items())
    if isinstance(value, ArrayStore):
        return ("store", type(value).__name__)
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return _component(value)
    return ("object", type(value).__name__)


def _component(component: Any) -> Any:
    names = [f.name for f in dataclasses.fields(component)]
    return (type(component).__name__, [(n, _value(getattr(component, n))) for n in names])


def world_parts(world: World) -> dict[str, Any]:
    """The world's entities, stores and physics as plain data, by part."""
    world.activate()
    entities, entity = [], 1  # a fresh esper context numbers its entities from 1
    while esper.entity_exists(entity):
        components = esper.components_for_entity(entity)
        entities.append((entity, sorted((type(c).__name__, _component(c)) for c in components)))
        entity += 1
    stores = {}
    for name, store in sorted(world.stores.items()):
        count = store.count
        arrays = {key: _value(np.ascontiguousarray(a[:count])) for key, a in store._arrays.items()}
        handles = store._row_of_handle[: store._handles]
        stores[name] = (count, sorted(arrays.items()), _value(np.ascontiguousarray(handles)))
    physics = world.physics
    batches = []
    for batch in physics.batches:
        # a crowd's rows the build only showed (`physics.placing`), placed as they would be
        batch.place_pending(np.arange(len(batch)))
        batches.append(
            (
                repr(batch.key),
                [_value(np.ascontiguousarray(a)) for a in (batch.state, batch.xpos, batch.xquat)],
                [_value(np.ascontiguousarray(getattr(batch, name))) for name in PHYSICS_ROWS],
            )
        )
    roster = [_value(a) for a in (physics.creature_entity, physics.creature_row, physics.batch_of,
                                  physics.row_of)]  # fmt: skip
    specs = sorted(world.creature_specs)
    return {"entities": entities, "stores": stores, "physics": (batches, roster), "specs": specs}


def digest(parts: Any) -> str:
    return hashlib.sha256(repr(parts).encode()).hexdigest()
