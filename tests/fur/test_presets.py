"""Presets behave as their rows of the thesis's table (Figure 3.1) say."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.fur.presets import preset, preset_names, resolve
from ecs_tentacles.fur.rig import pose
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.scene.validate import validate_scene
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION


def fur_world(make: Callable[..., World], fur: dict[str, Any]) -> World:
    creature = {"name": "c", "tentacles": {"count": 3, "links": 2}, "fur": fur}
    world = make({"version": 1, "creatures": [creature]}, plugins=NO_LOCOMOTION)
    world.step(2)
    return world


def evaluate(world: World) -> tuple[np.ndarray, np.ndarray]:
    """Run the rig once more this frame; its curves and frames."""
    world.schedule["rig"].process(world, world.settings.dt)
    return world.resource(FurData).curves.copy(), world.resource(FurData).frames.copy()


def test_the_three_presets_exist_and_are_valid() -> None:
    assert preset_names() == ["bird", "cat", "hedgehog"]
    for name in preset_names():
        scene = {"version": 1, "creatures": [{"fur": {"preset": name}}]}
        assert validate_scene(scene) == []
    with pytest.raises(KeyError, match="no fur preset 'dog'; known: bird, cat, hedgehog"):
        preset("dog")


def test_table_rows() -> None:
    hedgehog, cat, bird = preset("hedgehog"), preset("cat"), preset("bird")
    assert "dynamic" not in hedgehog["behaviours"] and "random" in hedgehog["behaviours"]
    assert hedgehog["groom"]["region"] == "back" and hedgehog["piloerection"]["random"] > 0.5
    assert "dynamic" in cat["behaviours"] and cat["groom"]["length_jitter"] > 0
    assert {c["name"] for c in cat["controls"]} >= {"neck", "back", "tail"}
    assert all(c["dynamic"] > 0 for c in cat["controls"])
    assert bird["behaviours"] == ["lift"] and bird["piloerection"]["random"] == 0


def test_a_scene_overrides_any_preset_field() -> None:
    fur = resolve({"preset": "cat", "groom": {"count": 10}, "width": 0.01})
    assert fur["groom"]["count"] == 10 and fur["width"] == 0.01
    assert fur["groom"]["length"] == 0.045 and fur["groom"]["length_jitter"] == 0.6
    assert fur["twist_max_deg"] == 25 and fur["dynamics"]["stiffness"] == 8  # schema default
    assert resolve({"preset": "none"})["groom"]["count"] == 200


def test_bird_feathers_only_lift(make_world: Callable[..., World]) -> None:
    world = fur_world(make_world, {"preset": "bird", "groom": {"count": 120}})
    c = world.resource(FurData).controls
    rest_curves, rest_frames = evaluate(world)
    c.lift[:] = 0.6
    lifted, lifted_frames = evaluate(world)
    assert np.abs(lifted - rest_curves).max() > 0.01  # lift changes them
    assert_allclose(lifted_frames[:, 2], rest_frames[:, 2], atol=1e-6)  # no twist: same side
    c.aim[:], c.direction[:], c.random[:], c.dynamic[:] = 1.0, 1.0, 1.0, 1.0
    c.position += (0.1, -0.2, 0.3)
    everything, _ = evaluate(world)
    assert_array_equal(everything, lifted)  # nothing but lift has any effect
    c.lift[:] = 1.0
    _, frames = evaluate(world)
    g, body = world.resource(FurData).guides, world.resource(FurData).guides.body_row
    normals = quat_rotate(world.transforms.quat[body], g.normal)
    assert_allclose(frames[:, 0], normals, atol=1e-6)


def test_hedgehog_quills_lift_and_interlock_without_dynamics(
    make_world: Callable[..., World],
) -> None:
    world = fur_world(make_world, {"preset": "hedgehog", "groom": {"count": 200}})
    rig = world.schedule["rig"]
    assert rig.strands is None  # no dynamics at all
    c = world.resource(FurData).controls
    c.lift[:], c.random[:] = 0.5, 1.0
    world.transforms.pos[world.resource(FurData).guides.body_row[0]] += (
        0.3,
        0.0,
        0.0,
    )  # a sudden move
    curves, frames = evaluate(world)
    assert_array_equal(curves, pose(rig.bind.shape_h, frames, out=np.empty_like(curves)))
    m = world.resource(FurData).guides.multiplier
    assert (m < -0.3).sum() > 40 and (m > 0.3).sum() > 40  # twisted both ways: interlocking
    c.random[:] = 0.0
    _, untwisted = evaluate(world)
    n = quat_rotate(
        world.transforms.quat[world.resource(FurData).guides.body_row],
        world.resource(FurData).guides.normal,
    )
    turned = np.arctan2(
        np.sum(np.cross(untwisted[:, 0], frames[:, 0]) * n, axis=1),
        np.sum(untwisted[:, 0] * frames[:, 0], axis=1)
        - np.sum(untwisted[:, 0] * n, axis=1) * np.sum(frames[:, 0] * n, axis=1),
    )
    assert_allclose(turned, m * np.radians(35), atol=1e-5)


def test_cat_hair_blends_to_a_strand_simulation(make_world: Callable[..., World]) -> None:
    world = fur_world(make_world, {"preset": "cat", "groom": {"count": 150}})
    rig = world.schedule["rig"]
    assert rig.strands is not None and len(rig.strands.guides) == 150
    body = world.resource(FurData).guides.body_row[0]
    for _ in range(5):  # the body jerks sideways: tips lag behind, roots follow
        world.transforms.pos[body] += (0.0, 0.02, 0.0)
        curves, frames = evaluate(world)
    rigid = pose(rig.bind.shape_h, frames, out=np.empty_like(curves))
    assert_allclose(curves[:, 0], rigid[:, 0], atol=1e-6)
    lag = curves[:, -1, 1] - rigid[:, -1, 1]
    assert lag.mean() < -1e-3  # tips trail the motion
    world.resource(FurData).controls.dynamic[:] = 0.0
    curves, frames = evaluate(world)
    assert_array_equal(curves, pose(rig.bind.shape_h, frames, out=np.empty_like(curves)))


def test_cat_emotion_lifts_neck_back_and_tail_most(make_world: Callable[..., World]) -> None:
    world = fur_world(make_world, {"preset": "cat", "groom": {"count": 20}})
    from ecs_tentacles.fur import FurControl

    emotion = {c.name: c.emotion for _, c in world.query(FurControl)}
    assert emotion == {"neck": 1.0, "back": 1.0, "tail": 1.0, "L_flank": 0.3, "R_flank": 0.3}
