"""Skinned creatures in the sandbox: the GPU palette matches the CPU skinning, and the
picture shows one smooth creature where the capsules were."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.render.skinned import SANDBOX_DETAIL, world_skeleton
from ecs_tentacles.skin.mesh import creature_mesh
from tests.skin.cpu_skinning import skin_points


def test_the_palette_puts_the_tubes_on_the_simulated_links(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("octopus")
    sandbox.step(60)
    world, skinned = sandbox.world, sandbox.renderer.skinned
    pos, quat = world.transforms.pos.astype(np.float64), world.transforms.quat.astype(np.float64)
    skeleton = world_skeleton(world, world.creature("octopus"))
    np.testing.assert_array_equal(skinned.rows, skeleton.bodies)
    mesh = creature_mesh(skeleton, SANDBOX_DETAIL)
    palette = np.zeros((len(skinned.rows), 4, 4))
    palette[:, :3] = skinned.palette(pos, quat)
    palette[:, 3, 3] = 1.0
    points = skin_points(mesh, palette)  # what the vertex shader computes
    centres = points[mesh.rings].mean(axis=1)
    rigid = (mesh.weights[mesh.rings[:, 0], 1] == 0) & (mesh.joints[mesh.rings[:, 0], 0] > 0)
    rows = skeleton.bodies[mesh.joints[mesh.rings[rigid, 0], 0]]
    direction = quat_rotate(quat[rows], np.array([1.0, 0.0, 0.0]))
    offset = centres[rigid] - pos[rows]
    along = np.einsum("ij,ij->i", offset, direction)
    off_axis = np.linalg.norm(offset - along[:, None] * direction, axis=1)
    assert rigid.sum() > 100 and off_axis.max() < 1e-3  # on the capsule's axis
    tips = quat_rotate(quat[skeleton.bodies[10::10]], np.array([1.0, 0.0, 0.0]))
    bases = quat_rotate(quat[skeleton.bodies[1::10]], np.array([1.0, 0.0, 0.0]))
    bend = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", tips, bases), -1, 1)))
    assert bend.max() > 10  # the tentacles are bent, not in the bind pose


def _octopus(make_sandbox: Callable[..., Any]) -> Any:
    """The octopus sandbox 30 frames in, the HUD hidden."""
    sandbox = make_sandbox("octopus")
    sandbox.step(30)
    sandbox.hud.visible = False
    return sandbox


def _warm(pixels: np.ndarray, margin: int) -> np.ndarray:
    """Where `pixels` (h, w, 3) are redder than green and blue by `margin`: the creature."""
    return (pixels[..., 0] > pixels[..., 1] + margin) & (pixels[..., 0] > pixels[..., 2] + margin)


def test_skinned_view_draws_one_smooth_creature(make_sandbox: Callable[..., Any]) -> None:
    sandbox = _octopus(make_sandbox)
    sandbox.render()
    skinned = sandbox.renderer.target.read().astype(int)
    sandbox.renderer.toggle_view()
    sandbox.render()
    capsules = sandbox.renderer.target.read().astype(int)
    octo = sandbox.world.creature("octopus")
    creature = sandbox.world.component(octo, Creature)
    top = sandbox.world.component(octo, Transform).pos + [0.0, 0.0, creature.mantle_height / 2]
    x, y = sandbox.renderer.camera.project(top[None])[0]
    for pixels in (skinned, capsules):
        r, g, b = pixels[360 - round(y) + 3, round(x)]
        assert r > g + 60 and r > b + 60  # the warm red creature is there in both views
    warm = _warm(skinned, 60).sum() / _warm(capsules, 60).sum()
    assert 0.5 < warm < 2.0  # the same creature, not a blob
    assert (np.abs(skinned - capsules).sum(axis=2) > 30).sum() > 200  # but drawn differently


def test_creatures_seen_small_are_drawn_coarse_and_look_the_same(
    make_sandbox: Callable[..., Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.render import skinned as module

    sandbox = _octopus(make_sandbox)
    skinned = sandbox.renderer.skinned
    sandbox.render()
    assert skinned.level.tolist() == [0]  # close: the sandbox's detail
    close = skinned.triangles
    sandbox.renderer.camera.distance = 5.0  # the creature about 140 px across
    sandbox.render()
    assert skinned.level.tolist() == [1]
    assert skinned.triangles * 3 < close
    coarse = sandbox.renderer.target.read().astype(int)
    monkeypatch.setattr(module, "COARSE_PIXELS", 0.0)  # the same view in full detail
    sandbox.render()
    assert skinned.level.tolist() == [0]
    fine = sandbox.renderer.target.read().astype(int)
    warm = _warm(fine, 40)
    assert warm.sum() > 300  # the creature is in the picture
    changed = np.abs(coarse - fine).sum(axis=2) > 60
    assert changed.sum() < 0.15 * warm.sum()  # a few edge pixels differ, not the creature


def test_creatures_seen_tiny_have_half_the_coarse_triangles_and_look_the_same(
    make_sandbox: Callable[..., Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.render import skinned as module

    sandbox = _octopus(make_sandbox)
    skinned = sandbox.renderer.skinned
    sandbox.renderer.camera.distance = 5.0  # about 140 px across: coarse
    sandbox.render()
    assert skinned.level.tolist() == [1]
    coarse_triangles = skinned.triangles
    sandbox.renderer.camera.distance = 8.0  # about 90 px across
    sandbox.render()
    assert skinned.level.tolist() == [2]
    assert skinned.triangles < 0.6 * coarse_triangles
    tiny = sandbox.renderer.target.read().astype(int)
    monkeypatch.setattr(module, "TINY_PIXELS", 0.0)  # the same view, coarse
    sandbox.render()
    assert skinned.level.tolist() == [1]
    coarse = sandbox.renderer.target.read().astype(int)
    warm = _warm(coarse, 40)
    assert warm.sum() > 100  # the creature is in the picture
    assert 0.8 < _warm(tiny, 40).sum() / warm.sum() < 1.1  # as big: its tentacles are not lost
    changed = np.abs(tiny - coarse).sum(axis=2) > 60
    assert changed.sum() < 0.2 * warm.sum()  # a few edge pixels differ, not the creature
