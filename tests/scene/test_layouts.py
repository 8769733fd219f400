"""A creature's layout is worked out once per load and reused by everyone who needs it."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.ground import ground_of
from ecs_tentacles.scene import construction, layouts, physical
from ecs_tentacles.scene.construction import creature_layout
from ecs_tentacles.scene.layouts import Layouts
from ecs_tentacles.scene.load import bundled_scene, load_scene
from ecs_tentacles.scene.spec import creature_specs
from ecs_tentacles.terrain import plugin as terrain_plugin
from ecs_tentacles.world import World


def _counting(monkeypatch: pytest.MonkeyPatch) -> list[Any]:
    """Every `creature_layout` call, wherever it is made from."""
    calls: list[Any] = []
    real = construction.creature_layout

    def counted(spec: Any, *args: Any) -> Any:
        calls.append(spec["name"])
        return real(spec, *args)

    from ecs_tentacles.creatures import body, spawning

    for module in (construction, layouts, physical, body, spawning, terrain_plugin):
        monkeypatch.setattr(module, "creature_layout", counted, raising=False)
    return calls


@pytest.mark.parametrize("scene", ["three_goals", "ramp", "rocky_shore"])
def test_a_load_works_each_layout_out_once(scene: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The physical checks, the terrain's check and the build each worked it out again."""
    calls = _counting(monkeypatch)
    with World.from_scene(scene, threads=1) as world:
        names = [c.name for _, c in world.query(Creature)]
        assert sorted(calls) == sorted(names)
        assert len(world.layouts) == 0  # built: forgotten


def test_the_built_creature_stands_where_its_layout_says() -> None:
    """On shaped ground the build's layout is the plane layout raised onto it."""
    with World.from_scene("rocky_shore", threads=1) as world:
        raised = 0
        for spec in creature_specs(world.scene or {}):
            expected = creature_layout(spec, ground_of(world))
            raised += bool(expected.origin[2] > creature_layout(spec).origin[2] + 0.1)
            mantle = world.component(world.creature(spec["name"]), Transform).pos
            height = spec["mantle"]["height"]
            np.testing.assert_array_equal(mantle, expected.origin + [0.0, 0.0, 0.5 * height])
        assert raised  # some stand on rocks


def test_a_moved_entry_is_worked_out_again() -> None:
    scene = load_scene(bundled_scene("three_goals"))
    spec = creature_specs(scene)[0]
    book = Layouts()
    first = book.on_plane(spec)
    assert book.on_plane(spec) is first
    spec["position"] = [spec["position"][0] + 1.0, *spec["position"][1:]]
    moved = book.on_plane(spec)
    assert moved is not first
    np.testing.assert_allclose(moved.origin - first.origin, [1.0, 0.0, 0.0])
    assert book.worked_out == 2


def test_tentacles_without_overrides_share_their_settings() -> None:
    scene = load_scene(bundled_scene("asymmetric"))
    for spec in creature_specs(scene):
        layout = creature_layout(spec)
        overridden = {o["index"] for o in spec["tentacles"]["overrides"]}
        for k, params in enumerate(layout.params):
            assert params == construction.tentacle_params(spec["tentacles"], k)
        plain = [id(p) for k, p in enumerate(layout.params) if k not in overridden]
        assert len(set(plain)) <= 1
