"""Creatures that come and go in a take: visibility in USD (rigid and skinned) and glTF."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.export.gltf import read_glb, write_glb
from ecs_tentacles.export.skinned_gltf import write_skinned_glb
from ecs_tentacles.export.skinned_usd import write_skinned_usd
from ecs_tentacles.export.usd import write_usd
from ecs_tentacles.record.systems.record import Record
from ecs_tentacles.take import Take
from ecs_tentacles.world import World

from .conftest import come_and_go_take, khronos_report, three_by_three


@pytest.fixture(scope="module")
def roster_take() -> Take:
    """`come_and_go_take`: `b` despawned after frame 4, `late` spawned after frame 6."""
    return come_and_go_take()


def test_the_take_knows_who_is_there(roster_take: Take) -> None:
    shown = roster_take.visible()
    assert [c["name"] for c in roster_take.header["creatures"]] == ["a", "b", "late"]
    assert shown[:, 0].all()
    assert shown[:5, 1].all() and not shown[5:, 1].any()
    assert not shown[:7, 2].any() and shown[7:, 2].all()


@pytest.mark.parametrize("skinned", [False, True])
def test_usd_keys_visibility_of_creatures_that_come_and_go(
    roster_take: Take, tmp_path: Path, skinned: bool
) -> None:
    pxr = pytest.importorskip("pxr.Usd")
    path = tmp_path / "roster.usda"
    (write_skinned_usd if skinned else write_usd)(roster_take, path)
    stage = pxr.Stage.Open(str(path))
    from pxr import UsdGeom

    def shown_at(name: str, frame: int) -> bool:
        prim = stage.GetPrimAtPath(f"/World/{name}")
        return UsdGeom.Imageable(prim).ComputeVisibility(frame) != UsdGeom.Tokens.invisible

    assert all(shown_at("a", f) for f in range(12))
    assert [shown_at("b", f) for f in range(12)] == [True] * 5 + [False] * 7
    assert [shown_at("late", f) for f in range(12)] == [False] * 7 + [True] * 5
    attribute = UsdGeom.Imageable(stage.GetPrimAtPath("/World/a")).GetVisibilityAttr()
    assert not attribute.GetTimeSamples()  # nothing keyed for a creature there all along


@pytest.mark.parametrize("skinned", [False, True])
def test_gltf_scales_a_creature_to_zero_while_it_is_away_and_validates(
    roster_take: Take, tmp_path: Path, gltf_validator: tuple[str, Path], skinned: bool
) -> None:
    path = tmp_path / "roster.glb"
    (write_skinned_glb if skinned else write_glb)(roster_take, path)
    report = khronos_report(path, gltf_validator)
    assert report["issues"]["messages"] == []
    document, binary = read_glb(path.read_bytes())
    from ecs_tentacles.export.gltf import accessor_array

    scaled = []
    for animation in document["animations"]:
        for channel in animation["channels"]:
            if channel["target"]["path"] == "scale":
                sampler = animation["samplers"][channel["sampler"]]
                assert sampler["interpolation"] == "STEP"
                times = accessor_array(document, binary, sampler["input"])
                scales = accessor_array(document, binary, sampler["output"])
                frames = np.round(times * roster_take.fps).astype(int).tolist()
                scaled.append((frames, scales[:, 0].tolist()))
    # b hidden from frame 5, late shown from frame 7; a (there all along) has no keys
    assert sorted(scaled) == [([0, 5], [1.0, 0.0]), ([0, 7], [0.0, 1.0])]


def test_fur_that_comes_late_or_goes_away_is_held_in_the_take(tmp_path: Path) -> None:
    with World.from_scene({"version": 1, "creatures": [three_by_three("bare", 0.0)]}) as world:
        record = world.add_system(Record())
        world.step(3)
        cat = world.spawn({"name": "cat", "fur": {"preset": "cat"}}, position=(4.0, 0.0))
        world.step(3)
        world.despawn(cat)  # every curve of the take gone from the world
        world.step(3)
        take = record.take()
    take.save(tmp_path / "fur.npz")
    again = Take.load(tmp_path / "fur.npz")
    assert again.problem() is None
    points = again.tracks["guide_points"]
    assert points.shape[0] == again.frames == 10
    assert set(again.header["guides"]["creatures"]) == {1}  # the cat's, take index 1
    assert np.array_equal(points[0], points[4])  # before it came: its first shape
    assert np.array_equal(points[7], points[9])  # after it went: its last shape
    assert not again.visible()[:4, 1].any() and again.visible()[4:7, 1].all()


@pytest.mark.parametrize("skinned", [False, True])
def test_one_animation_drives_everythree_by_three(
    roster_take: Take, tmp_path: Path, skinned: bool
) -> None:
    """Blender plays only a file's first animation (the others go to muted NLA tracks) and
    engines read an animation as one clip: one animation must move every creature."""
    path = tmp_path / "roster.glb"
    (write_skinned_glb if skinned else write_glb)(roster_take, path)
    document, _ = read_glb(path.read_bytes())
    (animation,) = document["animations"]
    driven = {c["target"]["node"] for c in animation["channels"] if c["target"]["path"] != "scale"}
    if skinned:
        assert animation["name"] == "take"
        joints = {j for skin in document["skins"] for j in skin["joints"]}
        assert len(document["skins"]) == 3 and joints <= driven
    else:  # a node per body, named after its creature
        names = {document["nodes"][n]["name"] for n in driven}
        for creature in ("a", "b", "late"):
            assert any(name.startswith(creature) for name in names), creature
