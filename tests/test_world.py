"""World: scenes in, entities out; contexts apart; events; scene-named systems."""

from __future__ import annotations

import sys
import textwrap
from collections.abc import Callable
from pathlib import Path

import pytest

from ecs_tentacles.components import Creature
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.system import System
from ecs_tentacles.world import World
from tests.conftest import creature_scene


def test_two_worlds_keep_their_entities_apart(make_world: Callable[..., World]) -> None:
    small = make_world(creature_scene(count=3, links=2))
    large = make_world(creature_scene(count=6, links=2))
    assert len(small.component(small.creature("octo"), Creature).tentacles) == 3
    assert len(large.component(large.creature("octo"), Creature).tentacles) == 6
    small.step(1)
    assert small.frame == 1 and large.frame == 0


def test_step_advances_the_fixed_clock(make_world: Callable[..., World]) -> None:
    scene = creature_scene(count=3, links=2)
    scene["physics"] = {"fps": 50, "substeps": 8}
    world = make_world(scene)
    world.step(25)
    assert world.time == 0.5
    assert world.physics.time == pytest.approx(0.5, abs=1e-12)
    assert world.physics.views[0].model.opt.timestep == 0.0025


def test_goals_become_entities_in_path_order(make_world: Callable[..., World]) -> None:
    scene = creature_scene(count=3, links=2)
    scene["creatures"][0]["goals"] = [
        {"position": [1, 0]},
        {"position": [2, 1, 0.5], "radius": 0.5},
    ]
    world = make_world(scene)
    goals = sorted((g.order, g.position.tolist(), g.radius) for _, g in world.query(Goal))
    assert goals == [(0, [1.0, 0.0, 0.0], 0.3), (1, [2.0, 1.0, 0.5], 0.5)]
    assert {g.owner for _, g in world.query(Goal)} == {world.creature("octo")}


def test_a_built_world_keeps_no_spare_store_rows(make_world: Callable[..., World]) -> None:
    """Stores grow by doubling while creatures are built; loading cuts them to their rows."""
    world = make_world(creature_scene(count=5, links=3))
    for name, store in world.stores.items():
        assert store.capacity == len(store), name
    world.step(2)  # the systems run on the cut stores
    assert len(world.transforms) == 1 + 5 * 3


def test_unknown_creature_name_lists_the_known_ones(make_world: Callable[..., World]) -> None:
    world = make_world(creature_scene(count=3, links=2))
    with pytest.raises(KeyError, match="no creature named 'squid'; this world has: octo"):
        world.creature("squid")


def test_bad_scene_builds_nothing() -> None:
    with pytest.raises(SceneError) as caught:
        World.from_scene({"version": 1, "creatures": [{"tentacles": {"end_scale": 1.7}}]})
    assert caught.value.problems == ["creatures[0].tentacles.end_scale: must be in (0, 1], got 1.7"]


@pytest.fixture
def user_system_module(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> str:
    """A module `my_systems` on sys.path that counts its imports and frames."""
    (tmp_path / "my_systems.py").write_text(
        textwrap.dedent(
            """
            from ecs_tentacles.system import System
            IMPORTS = []
            IMPORTS.append(1)

            class Counter(System):
                name = "counter"
                after = ("physics_sync",)
                frames = 0

                def process(self, world, dt):
                    type(self).frames += 1
            """
        )
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "my_systems", raising=False)
    return "my_systems"


def test_scene_systems_are_not_imported_unless_allowed(
    user_system_module: str, make_world: Callable[..., World]
) -> None:
    scene = creature_scene(count=3, links=2)
    scene["systems"] = [f"{user_system_module}:Counter"]
    with pytest.raises(
        SceneError, match=r"systems\[0\]: the scene asks to run 'my_systems:Counter'"
    ):
        World.from_scene(scene)
    assert user_system_module not in sys.modules
    world = make_world(scene, allow_systems=True)
    assert world.schedule.names[-8:] == [
        "physics",
        "lod_replay",  # after physics: kinematic creatures' poses
        "physics_sync",
        "physics_health",
        "counter",  # after physics_sync: the sync stage
        "threats",
        "emotion",
        "rig",
    ]
    world.step(3)
    assert type(world.schedule["counter"]).frames == 3  # type: ignore[attr-defined]


def test_scene_system_that_is_not_a_system(user_system_module: str) -> None:
    scene = creature_scene(count=3, links=2)
    scene["systems"] = [f"{user_system_module}:IMPORTS", "no_such_module_xyz:Thing"]
    with pytest.raises(SceneError) as caught:
        World.from_scene(scene, allow_systems=True)
    assert caught.value.problems[0] == "systems[0]: 'my_systems:IMPORTS' is not a System subclass"
    assert caught.value.problems[1].startswith(
        "systems[1]: cannot import 'no_such_module_xyz:Thing'"
    )


def test_user_system_base_class_is_the_builtin_one() -> None:
    from ecs_tentacles.physics.systems.physics import Physics
    from ecs_tentacles.physics.systems.physics_sync import PhysicsSync

    assert issubclass(Physics, System) and issubclass(PhysicsSync, System)


def test_settings_defaults_are_the_schemas_physics_defaults() -> None:
    from dataclasses import asdict, fields

    from ecs_tentacles.scene.schema import core_schema
    from ecs_tentacles.settings import BUILD_ONLY, Settings

    physics = core_schema()["properties"]["physics"]["properties"]
    defaults = {key: spec["default"] for key, spec in physics.items() if key not in BUILD_ONLY}
    made = asdict(Settings())
    assert {f.name for f in fields(Settings)} == set(defaults)  # every runtime key, no other
    lod = {**defaults["lod"], "focus": None}  # a focus region is set by a scene or a bake
    assert made == {**defaults, "gravity": tuple(defaults["gravity"]), "lod": lod}
    assert Settings().ground_friction == 0.4  # was 1.0 by hand while the schema said 0.4


def test_a_world_without_a_scene_runs_with_a_default_scenes_settings(
    make_world: Callable[..., World],
) -> None:
    scene = make_world(creature_scene(count=3, links=2))
    with World() as bare:
        assert bare.settings == scene.settings


def test_locomotion_is_an_ordinary_plugin_switch(make_world: Callable[..., World]) -> None:
    off = make_world(
        creature_scene(count=3, links=2), plugins={"locomotion": False, "suckers": False}
    )
    assert not {"goals", "motor_targets", "suckers"} & set(off.schedule.names)
    assert [p.key for p in off.plugins] == ["threats", "fur", "clips", "terrain"]
    scene = {**creature_scene(count=3, links=2)}
    scene["creatures"][0]["goals"] = [{"position": [1, 0]}]
    with pytest.raises(SceneError, match=r"creatures\[0\]\.goals: unknown key"):
        World.from_scene(scene, plugins={"locomotion": False, "suckers": False})
    with pytest.raises(TypeError):
        World.from_scene(creature_scene(count=3, links=2), locomotion=False)  # type: ignore[call-arg]


def test_a_failing_plugin_systems_hook_closes_the_half_built_world(
    tmp_path: Path,
) -> None:
    import esper

    (tmp_path / "broken.py").write_text(
        textwrap.dedent(
            """
            from ecs_tentacles.plugin import Plugin

            class Broken(Plugin):
                name = "broken"

                def systems(self):
                    raise RuntimeError("no systems today")
            """
        )
    )
    scene = creature_scene(count=3, links=2)
    scene["plugins"] = {"broken": {"from": "broken.py"}}
    before = set(esper.list_worlds())
    with pytest.raises(SceneError, match=r"plugins\.broken: systems\(\) raised RuntimeError"):
        World.from_scene(scene, allow_systems=True, scene_dir=tmp_path)
    assert set(esper.list_worlds()) == before  # its esper context is gone
