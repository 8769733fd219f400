"""`WorldOptions`: one object carries a run's choices to the world, the same as keywords."""

from __future__ import annotations

from pathlib import Path

import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.options import WorldOptions
from ecs_tentacles.world import World


def test_options_build_the_world_they_describe() -> None:
    options = WorldOptions(seed=11, threads=1, lod=False, focus=(1.0, -2.0, 3.0), only={0, 2})
    with World.from_scene(crowd_scene(3, seed=1), options) as world:
        assert world.seed == 11
        assert world.physics.threads == 1
        assert not world.lod.enabled
        assert world.lod.focus_region is not None
        assert [float(v) for v in world.lod.focus_region[0]] == [1.0, -2.0]
        assert float(world.lod.focus_region[1]) == 3.0
        assert len(world.physics) == 2  # creatures 0 and 2 only
        assert world.options == options


def test_keywords_set_fields_over_the_options() -> None:
    base = WorldOptions(seed=5, threads=2, lod=True)
    with World.from_scene(crowd_scene(1, seed=1), base, threads=1, lod=False) as world:
        assert world.options == WorldOptions(seed=5, threads=1, lod=False)
        assert (world.seed, world.physics.threads, world.lod.enabled) == (5, 1, False)


def test_options_are_frozen_and_normalised(tmp_path: Path) -> None:
    options = WorldOptions(only=[3, 1], scene_dir=str(tmp_path), focus=(1, 2, 3))
    assert options.only == frozenset({1, 3})
    assert options.scene_dir == tmp_path
    assert options.focus == (1.0, 2.0, 3.0)
    with pytest.raises(AttributeError):
        options.seed = 3  # type: ignore[misc]
    changed = options.but(seed=3)
    assert (changed.seed, options.seed) == (3, None)


def test_plugins_given_are_copied() -> None:
    chosen = {"locomotion": False}
    options = WorldOptions(plugins=chosen)
    chosen["suckers"] = False
    assert options.plugins == {"locomotion": False}


def test_scene_with_lod_writes_lod_and_focus_and_leaves_the_scene() -> None:
    scene = {"version": 1, "physics": {"fps": 60, "lod": {"budgets": {"full": 4}}}}
    written = WorldOptions(lod=True, focus=(2.0, -1.0, 3.0)).scene_with_lod(scene)
    assert written["physics"]["lod"] == {
        "budgets": {"full": 4},
        "enabled": True,
        "focus": {"center": [2.0, -1.0], "radius": 3.0},
    }
    assert scene["physics"]["lod"] == {"budgets": {"full": 4}}
    assert WorldOptions().scene_with_lod(scene) == scene


def test_old_keywords_still_work_and_say_so() -> None:
    from ecs_tentacles.export.bake import BakePlan
    from ecs_tentacles.render.session import SandboxSession

    scene = crowd_scene(1, seed=1)
    with pytest.warns(DeprecationWarning, match="BakePlan.make: the keywords seed"):
        plan = BakePlan.make(scene, seconds=0.1, seed=5)
    assert plan.seed == 5
    with pytest.warns(DeprecationWarning, match="SandboxSession: the keywords seed, threads"):
        session = SandboxSession(scene, seed=3, threads=1)
    assert (session.world.seed, session.world.physics.threads) == (3, 1)
    session.world.close()
    with pytest.raises(TypeError), pytest.warns(DeprecationWarning):
        BakePlan.make(scene, seconds=0.1, sede=5)
