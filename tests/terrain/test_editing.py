"""Editing the terrain of a running world: obstacles placed, moved and deleted, the
heightfield sculpted, the scene saved; the physics follows without a rebuild."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

from ecs_tentacles.ground import ground_of
from ecs_tentacles.terrain.editing import TerrainEditError, TerrainEditor
from ecs_tentacles.world import World

HILLS = {"size": [8, 8], "resolution": 33, "height": 0.3, "noise": {"seed": 5}}


def scene(terrain: dict[str, Any]) -> dict[str, Any]:
    creature = {"name": "octo", "position": [0, 0], "goals": [{"position": [1.5, 0]}]}
    return {"version": 1, "terrain": terrain, "creatures": [creature]}


def _ray_down(world: World, x: float, y: float) -> float:
    """Where MuJoCo's own model of the first creature finds the ground under (x, y)."""
    m, d = world.physics.batches[0].standalone(0)
    hit = np.zeros(1, dtype=np.int32)
    body = m.body("mantle").id  # not the creature itself
    distance = mujoco.mj_ray(
        m, d, np.array([x, y, 5.0]), np.array([0, 0, -1.0]), None, 1, body, hit
    )
    return 5.0 - distance


def test_placed_moved_and_deleted_obstacles_reach_the_physics_and_nothing_moves(
    make_world: Callable[..., World],
) -> None:
    world = make_world(scene({"heightfield": HILLS}))
    world.step(10)
    editor = world.resource(TerrainEditor)
    before = world.transforms.pos.copy()
    saved = world.snapshot()
    index = editor.place(world, "box", (2.5, 1.5, 0.0), size=0.6)
    assert index == 0 and len(ground_of(world).solids) == 1
    np.testing.assert_array_equal(world.transforms.pos, before)  # nobody moved
    top = ground_of(world).surface(np.array([[2.5, 1.5]]))[0]
    assert _ray_down(world, 2.5, 1.5) == pytest.approx(top, abs=1e-6)  # in the physics
    assert top > ground_of(world).height(np.array([[2.5, 1.5]]))[0] + 0.2
    editor.move(world, 0, (-2.5, -1.5))
    assert world.scene["terrain"]["obstacles"][0]["position"][:2] == [-2.5, -1.5]  # type: ignore[index]
    assert _ray_down(world, 2.5, 1.5) < top - 0.2  # gone from where it was
    assert editor.delete_at(world, (2.5, 1.5, 0.3)) is None  # nothing there now
    moved_top = ground_of(world).surface(np.array([[-2.5, -1.5]]))[0]
    assert editor.delete_at(world, (-2.5, -1.5, moved_top)) == 0
    assert ground_of(world).solids == ()
    world.step(30)
    assert world.physics.health.recoveries == 0 and editor.edits == 3
    world.restore(saved)  # a snapshot from before the edits still restores
    np.testing.assert_array_equal(
        world.transforms.pos[world.creatures.mantle_row], before[world.creatures.mantle_row]
    )


def test_a_placed_rock_is_a_boulder_in_the_physics_each_its_own_stone(
    make_world: Callable[..., World],
) -> None:
    world = make_world(scene({"heightfield": HILLS}))
    editor = world.resource(TerrainEditor)
    for point in ((2.5, 1.5), (-2.5, 1.5)):
        editor.place(world, "rock", (*point, 0.0), size=0.8)
    one, two = ground_of(world).solids
    assert one.kind == two.kind == "mesh"
    assert one.pieces[0].shape != two.pieces[0].shape or not np.allclose(
        one.pieces[0], two.pieces[0]
    )  # two seeds, two stones
    top = ground_of(world).surface(np.array([[2.5, 1.5]]))[0]
    assert _ray_down(world, 2.5, 1.5) == pytest.approx(top, abs=1e-5)  # in the physics
    assert top > ground_of(world).height(np.array([[2.5, 1.5]]))[0] + 0.2
    world.step(20)
    assert world.physics.health.recoveries == 0


def test_an_obstacle_into_a_creature_is_refused_and_changes_nothing(
    make_world: Callable[..., World],
) -> None:
    world = make_world(scene({}))
    editor = world.resource(TerrainEditor)
    ground = ground_of(world)
    with pytest.raises(
        TerrainEditError, match=r"terrain.obstacles\[0\]: would be inside creature octo"
    ):
        editor.place(world, "sphere", (0.5, 0.0, 0.0), size=0.6)
    assert ground_of(world) is ground and editor.edits == 0
    assert world.scene["terrain"].get("obstacles", []) == []  # type: ignore[index]
    with pytest.raises(TerrainEditError, match=r"terrain.heightfield: this scene has none"):
        editor.brush(world, "raise", (2.0, 2.0), 1.0, 0.1)


def test_the_brush_raises_lowers_and_smooths_what_the_physics_collides_with(
    make_world: Callable[..., World],
) -> None:
    world = make_world(scene({"heightfield": HILLS}))
    editor = world.resource(TerrainEditor)
    centre = np.array([[2.5, -2.5]])
    start = ground_of(world).height(centre)[0]
    editor.brush(world, "raise", centre[0], radius=1.0, amount=0.2)
    raised = ground_of(world).height(centre)[0]
    assert raised == pytest.approx(start + 0.2, abs=0.02)
    assert _ray_down(world, 2.5, -2.5) == pytest.approx(raised, abs=1e-4)
    field = world.scene["terrain"]["heightfield"]  # type: ignore[index]
    assert "noise" not in field and len(field["heights"]) == 33  # explicit heights now
    far = ground_of(world).height(np.array([[-2.5, 2.5]]))[0]
    editor.brush(world, "lower", centre[0], radius=1.0, amount=0.2)
    assert ground_of(world).height(centre)[0] == pytest.approx(start, abs=1e-4)
    assert ground_of(world).height(np.array([[-2.5, 2.5]]))[0] == pytest.approx(far)
    spike = world.scene["terrain"]["heightfield"]["heights"]  # type: ignore[index]
    spread = np.ptp(np.asarray(spike))
    editor.brush(world, "smooth", (0.0, 3.0), radius=3.0, amount=1.0)
    smoothed = np.asarray(world.scene["terrain"]["heightfield"]["heights"])  # type: ignore[index]
    assert np.ptp(smoothed) <= spread + 1e-9


def test_save_writes_the_edits_into_the_scene_file(
    make_world: Callable[..., World], tmp_path: Path
) -> None:
    raw = scene({"heightfield": HILLS})
    world = make_world(raw)
    editor = world.resource(TerrainEditor)
    editor.place(world, "cylinder", (-2.5, 2.5, 0.0))
    editor.brush(world, "raise", (2.5, -2.5), 1.0, 0.1)
    path = editor.save(world, raw, tmp_path / "edited.json")
    again = make_world(json.loads(path.read_text()))
    assert ground_of(again).digest() == ground_of(world).digest()
    assert raw["terrain"] == {"heightfield": HILLS}  # the caller's scene is left alone
