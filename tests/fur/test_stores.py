"""Fur stores: the behaviours and track columns are named once and reach the controls."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ecs_tentacles.fur import FurControl
from ecs_tentacles.fur.stores import BEHAVIOURS, COLUMNS, ControlStore, FurData
from ecs_tentacles.world import World


def test_every_behaviour_is_a_control_value_with_its_own_track_column() -> None:
    fields = {field.name for field in ControlStore.fields()}
    assert set(BEHAVIOURS) <= fields
    assert list(COLUMNS) == ["position", *BEHAVIOURS]
    columns = [c for name in COLUMNS for c in COLUMNS[name]]
    assert columns == list(range(3 + len(BEHAVIOURS)))


def test_a_scene_keys_every_attribute_and_each_lands_on_its_control_value(
    make_world: Callable[..., World],
) -> None:
    values = {name: 0.1 * (i + 1) for i, name in enumerate(BEHAVIOURS)}
    tracks = [{"attribute": "position", "keys": [{"time": 0, "value": [0.1, 0.05, 0.2]}]}]
    tracks += [{"attribute": k, "keys": [{"time": 0, "value": v}]} for k, v in values.items()]
    control = {"name": "c", "position": [0, 0, 0.1], "tracks": tracks}
    fur = {"groom": {"count": 20}, "controls": [control]}
    world = make_world(
        {"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 2}, "fur": fur}]}
    )
    world.step(1)
    (made,) = [c for _, c in world.query(FurControl)]
    np.testing.assert_array_equal(made.position, [0.1, 0.05, 0.2])
    assert {name: float(getattr(made, name)) for name in BEHAVIOURS} == values


def test_rest_shapes_added_creature_by_creature_are_joined_in_order() -> None:
    fur = FurData()
    fur.points = 4
    batches = [np.full((k, 4, 3), float(i)) for i, k in enumerate([3, 1, 5])]
    for batch in batches:
        fur.guides.add(len(batch))
        fur.add_shapes(batch)
    np.testing.assert_array_equal(fur.shape, np.concatenate(batches))
    assert fur.curves.shape == (9, 4, 3) and fur.frames.shape == (9, 4, 3)
    fur.curves[0] = 1.0  # the rig's output stays, also when more guides are added
    assert fur.curves[0, 0, 0] == 1.0
    for more in range(2, 40):  # the buffers grow by doubling: earlier rows are kept
        fur.guides.add(more)
        fur.add_shapes(np.full((more, 4, 3), float(more)))
        assert fur.shape.shape == (len(fur.guides), 4, 3) and fur.shape[-1, 0, 0] == more
        assert fur.curves.shape == (len(fur.guides), 4, 3)
        assert fur.curves[0, 0, 0] == 1.0 and not fur.curves[1:].any()  # the new ones zeroed
    np.testing.assert_array_equal(fur.shape[:9], np.concatenate(batches))
