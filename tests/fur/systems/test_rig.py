"""The rig system: guides follow their creature, tracks drive controls, re-binding, no fur."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.fur import FurControl, FurGuide
from ecs_tentacles.fur import blocks as blocks_module
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.fur.systems import rig as rig_module
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.physics.tiers import KINEMATIC
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION


def creature(name: str, x: float, fur: dict[str, Any], **extra: Any) -> dict[str, Any]:
    return {
        "name": name,
        "position": [x, 0],
        "tentacles": {"count": 4, "links": 3},
        "fur": fur,
    } | extra


def roots_in_world(world: World) -> np.ndarray:
    g = world.resource(FurData).guides
    return world.transforms.pos[g.body_row] + quat_rotate(world.transforms.quat[g.body_row], g.root)


def test_a_world_without_fur_does_no_rig_work(make_world: Callable[..., World]) -> None:
    world = make_world({"version": 1, "creatures": [{"tentacles": {"count": 3, "links": 2}}]})
    world.step(3)
    rig = world.schedule["rig"]
    assert (
        rig.bind is None and rig.version == -1 and world.resource(FurData).curves.shape == (0, 0, 3)
    )


def test_guides_follow_a_moving_creature(make_world: Callable[..., World]) -> None:
    fur = {"groom": {"count": 150, "bend_deg": 30, "rest_angle_deg": 20}}
    fur["controls"] = [{"name": "m", "lift": 0.3, "random": 0.5, "aim": 0.2}]
    scene = {
        "version": 1,
        "creatures": [
            creature("a", 0.0, fur, goals=[{"position": [1.0, 0.5]}]),
            creature("b", 2.0, {"groom": {"count": 60}}, heading_deg=90),
        ],
    }
    world = make_world(scene)
    start = world.transforms.pos[world.resource(FurData).sets.body_row].copy()
    world.step(90)
    moved = np.linalg.norm(
        world.transforms.pos[world.resource(FurData).sets.body_row] - start, axis=1
    )
    assert moved[0] > 0.02  # it crawled
    frames, curves = world.resource(FurData).frames, world.resource(FurData).curves
    assert_allclose(frames[:, 3], roots_in_world(world), atol=2e-6)
    assert_allclose(curves[:, 0], roots_in_world(world), atol=2e-6)
    guide = world.component(int(world.resource(FurData).guides.entity[7]), FurGuide)
    assert_allclose(guide.points, curves[7]) and guide.creature == world.creature("a")


def test_tracks_drive_control_attributes(make_world: Callable[..., World]) -> None:
    tracks = [
        {
            "attribute": "lift",
            "keys": [{"time": 0, "value": 0}, {"time": 1, "value": 1, "easing": "linear"}],
        },
        {
            "attribute": "position",
            "keys": [{"time": 0, "value": [0, 0, 0.3]}, {"time": 2, "value": [0.2, 0, 0.3]}],
        },
    ]
    tracks[0]["keys"][0]["easing"] = "linear"
    fur = {"groom": {"count": 30}, "controls": [{"name": "m", "tracks": tracks}]}
    world = make_world({"version": 1, "creatures": [creature("a", 0, fur)]}, plugins=NO_LOCOMOTION)
    control = world.component(world.resource(FurData).controls.entity[0], FurControl)
    world.step(31)  # the last frame ran at t = 0.5
    assert control.lift == 0.5
    assert_allclose(control.position, [0.2 * 0.15625, 0, 0.3])  # ease at u = 1/4
    world.step(60)
    assert control.lift == 1.0
    g = world.resource(FurData).guides
    normals = quat_rotate(world.transforms.quat[g.body_row], g.normal)
    assert_allclose(world.resource(FurData).frames[:, 0], normals, atol=1e-6)


def test_a_scripted_control_move_turns_its_guides(make_world: Callable[..., World]) -> None:
    fur = {"groom": {"count": 80, "region": "top"}, "controls": [{"name": "m", "direction": 1.0}]}
    world = make_world({"version": 1, "creatures": [creature("a", 0, fur)]}, plugins=NO_LOCOMOTION)
    world.step(1)
    before = world.resource(FurData).frames[:, 0].copy()
    control = world.component(world.resource(FurData).controls.entity[0], FurControl)
    control.position = control.rest_position + (0.0, 0.1, 0.0)  # one reach toward +y
    world.step(1)
    turned = world.resource(FurData).frames[:, 0] - before
    y_world = quat_rotate(
        world.transforms.quat[world.resource(FurData).sets.body_row[0]], np.array([0, 1.0, 0])
    )
    assert np.all(turned @ y_world > 0.05)


def test_writing_a_guide_rebinds(make_world: Callable[..., World]) -> None:
    fur = {"groom": {"count": 10}}
    world = make_world({"version": 1, "creatures": [creature("a", 0, fur)]}, plugins=NO_LOCOMOTION)
    world.step(1)
    version = world.resource(FurData).version
    guide = world.component(int(world.resource(FurData).guides.entity[3]), FurGuide)
    guide.root = (0.0, 0.0, 0.1)
    guide.normal = (0.0, 0.0, 1.0)
    assert world.resource(FurData).version == version + 2
    world.step(1)
    assert world.schedule["rig"].version == world.resource(FurData).version
    assert_allclose(world.resource(FurData).frames[3, 3], roots_in_world(world)[3], atol=1e-6)
    assert "FurGuide(row=3, root=" in repr(guide)


def test_blocks_give_the_same_result_as_one_pass(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    scene = {
        "version": 1,
        "creatures": [
            creature("bird", 0.0, {"preset": "bird", "groom": {"count": 50}}),
            creature("cat", 2.0, {"preset": "cat", "groom": {"count": 70}}),
        ],
    }
    results = []
    for block, strands in [(10_000, 10_000), (16, 7)]:
        monkeypatch.setattr(blocks_module, "BLOCK", block)
        monkeypatch.setattr(rig_module, "STRAND_BLOCK", strands)
        world = make_world(scene, plugins=NO_LOCOMOTION)
        world.resource(FurData).controls.lift[:] = 0.4
        world.resource(FurData).controls.random[:] = 0.6
        world.step(20)
        results.append(
            (world.resource(FurData).frames.copy(), world.resource(FurData).curves.copy())
        )
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1], results[1][1])


def test_kernels_serial_or_parallel_and_numpy_give_the_same_fur(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    pytest.importorskip("numba")
    from ecs_tentacles.fur import rig as rig_math

    scene = {
        "version": 1,
        "creatures": [
            creature("cat", 0.0, {"preset": "cat", "groom": {"count": 700}}),
            creature("bird", 2.0, {"preset": "bird", "groom": {"count": 90}}),
        ],
    }
    scene["creatures"][0]["goals"] = [{"position": [1.0, 0.5]}]
    results = {}
    for backend, parallel_from in [("numpy", 0), ("auto", 1 << 40), ("auto", 0)]:
        monkeypatch.setattr(rig_math, "BACKEND", backend)
        monkeypatch.setattr(rig_math, "PARALLEL_GUIDES", parallel_from)
        world = make_world(scene)
        world.resource(FurData).controls.lift[:] = 0.4
        world.resource(FurData).controls.random[:] = 0.6
        world.step(40)
        rig = world.schedule["rig"]
        assert rig.strands is not None and len(rig.strands.guides) == 700  # the cat's
        assert rig.parallel == (parallel_from == 0)
        results[backend, parallel_from] = world.resource(FurData).curves.copy()
    serial, parallel = results["auto", 1 << 40], results["auto", 0]
    np.testing.assert_array_equal(serial, parallel)  # the same float32 operations
    # the rig's own float32 rounding (see tests/fur/test_rig_kernels.py), carried by the strands
    assert_allclose(serial, results["numpy", 0], atol=1e-5)
    assert not rig_math.use_parallel(rig_math.PARALLEL_GUIDES - 1)
    # the strands' normals reach the kernels in one layout (C), whether the fur's guides
    # hang from one body or many: each kernel compiled once (a layout more: 2-7 s more)
    from ecs_tentacles.fur import kernels

    for kernel in (kernels.strands, kernels.strands_serial):
        assert {signature[6].layout for signature in kernel.signatures} == {"C"}


@pytest.mark.parametrize("parallel_from", [1 << 40, 0])
def test_fur_nobody_reads_is_posed_when_read_with_the_same_bits(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch, parallel_from: int
) -> None:
    from ecs_tentacles.fur import rig as rig_math

    monkeypatch.setattr(rig_math, "PARALLEL_GUIDES", parallel_from)
    monkeypatch.setattr(blocks_module, "BLOCK", 64)  # strands' guides among other guides
    scene = {
        "version": 1,
        "creatures": [
            creature("bird", 0.0, {"preset": "bird", "groom": {"count": 50}}),
            creature("cat", 2.0, {"preset": "cat", "groom": {"count": 70}}),
            creature("hog", 4.0, {"preset": "hedgehog", "groom": {"count": 40}}),
        ],
    }
    scene["creatures"][1]["goals"] = [{"position": [3.0, 1.0]}]
    every, seldom = make_world(scene), make_world(scene)
    read_every = []
    for frame in range(1, 25):  # one world's fur read every frame, as a recorder reads it
        every.step(1)
        fur = every.resource(FurData)
        read_every.append((frame, fur.frames.copy(), fur.curves.copy()))
    fur = seldom.resource(FurData)
    cat = fur.guides.fur_row == 1  # the dynamic fur's guides
    unread = 0
    for frame, frames, curves in read_every:
        before = fur.outputs()[1].copy()
        seldom.step(1)
        written = np.any(fur.outputs()[1] != before, axis=(1, 2))
        assert written[cat].all()  # the dynamic fur is posed every frame (strands carry state)
        if frame > 1 and (frame - 1) % 5:  # nobody read it since the last frame
            assert not written[~cat].any()  # the rest is posed when read
            unread += 1
        if frame % 5 == 0 or frame == 24:  # read now and then: exactly what was read above
            np.testing.assert_array_equal(fur.curves, curves)
            np.testing.assert_array_equal(fur.frames, frames)
    assert unread == 19


def _replayed_cats(dynamic: bool = True) -> dict[str, Any]:
    """Six small cats (dynamic fur) crawling apart, four of them replayed from the start
    (the level of detail's budgets: 2 reduced, none full); `dynamic` False: the same
    fur without its strands (what the rig alone poses)."""
    behaviours = ["lift", "aim", "direction", "random", *(["dynamic"] if dynamic else [])]
    fur = {"preset": "cat", "behaviours": behaviours, "groom": {"count": 60}}
    creatures = [
        creature(f"cat{i}", 3.0 * i, fur, goals=[{"position": [3.0 * i, 2.0]}]) for i in range(6)
    ]
    physics = {"lod": {"full": 0, "reduced": 2, "hold_seconds": 0.0}}
    return {"version": 1, "physics": physics, "creatures": creatures}


def _cats_world(make_world: Callable[..., World], dynamic: bool = True) -> World:
    """`_replayed_cats` built, every strand blended in whole (`dynamic` 1)."""
    world = make_world(_replayed_cats(dynamic))
    world.resource(FurData).controls.dynamic[:] = 1.0
    return world


def _strand_rows(world: World) -> tuple[np.ndarray, np.ndarray]:
    """The strands of replayed creatures and of stepped ones (indices into the strands)."""
    rig = world.schedule["rig"]
    replayed = world.physics.kinematic_creatures(len(world.creatures))
    mantles = world.creatures.mantle_row
    body = rig.binds.bodies[rig.strand_body]  # each strand's mantle row
    resting = replayed[np.searchsorted(mantles, body)]
    return np.flatnonzero(resting), np.flatnonzero(~resting)


def test_strands_of_replayed_creatures_rest_while_nobody_reads_the_fur(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Nobody reading the fur (`UNREAD_SECONDS`), a replayed creature's strands are not
    stepped: the rest step as they did (the same bits as a world that steps every
    strand), a read then shows the replayed ones' guides as the rig poses them, and from
    then on, read every frame, every strand steps again, the replayed ones from the
    rig's pose."""
    monkeypatch.setattr(rig_module, "UNREAD_SECONDS", 0.05)  # 3 frames (else a second)
    monkeypatch.setattr(rig_module, "SKIP_UNREAD_REPLAYED", False)
    every, plain = _cats_world(make_world), _cats_world(make_world, dynamic=False)
    monkeypatch.setattr(rig_module, "SKIP_UNREAD_REPLAYED", True)
    resting = _cats_world(make_world)
    for world in (every, plain, resting):
        world.step(12)  # nobody reads any of them
    rig, before = resting.schedule["rig"], every.schedule["rig"]
    replayed, stepped = _strand_rows(resting)
    assert len(replayed) and len(stepped)  # both kinds
    assert np.array_equal(_strand_rows(every)[0], replayed)  # the same tiers in both
    assert rig.strands.fresh[replayed].all() and not rig.strands.fresh[stepped].any()
    for state in ("pos", "prev"):
        np.testing.assert_array_equal(
            getattr(rig.strands, state)[..., stepped], getattr(before.strands, state)[..., stepped]
        )
    shown, full, rigged = (w.resource(FurData) for w in (resting, every, plain))
    np.testing.assert_array_equal(shown.frames, full.frames)  # strands move no frame
    guides = rig.strands.guides
    np.testing.assert_array_equal(shown.curves[guides[stepped]], full.curves[guides[stepped]])
    np.testing.assert_array_equal(shown.curves[guides[replayed]], rigged.curves[guides[replayed]])
    assert not np.array_equal(full.curves[guides[replayed]], rigged.curves[guides[replayed]])
    for _ in range(6):  # read every frame from now on: every strand steps
        for world in (every, resting):
            world.step(1)
            world.resource(FurData).curves  # noqa: B018 (a read, as a renderer's)
        assert not rig.strands.fresh.any()
        assert np.isfinite(shown.curves).all()
        np.testing.assert_array_equal(shown.curves[guides[stepped]], full.curves[guides[stepped]])


@pytest.mark.parametrize("every", [1, 2, 5])
def test_fur_read_now_and_then_steps_every_strand_as_before(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch, every: int
) -> None:
    """A renderer reads the fur every frame, a 30 fps recorder of a 60 Hz world every
    other frame, a script now and then (within `UNREAD_SECONDS`, here 0.1 s): the
    replayed creatures' strands step as they always did, the same bits at every read
    with the rest on or off."""
    monkeypatch.setattr(rig_module, "UNREAD_SECONDS", 0.1)
    worlds = []
    for skip in (False, True):
        monkeypatch.setattr(rig_module, "SKIP_UNREAD_REPLAYED", skip)
        worlds.append(_cats_world(make_world))
    old, new = (w.resource(FurData) for w in worlds)
    for frame in range(1, 25):
        for world in worlds:
            world.step(1)
        if frame % every == 0:
            np.testing.assert_array_equal(old.curves, new.curves)
            np.testing.assert_array_equal(old.frames, new.frames)
    assert len(_strand_rows(worlds[1])[0])  # some creatures are replayed
    assert not worlds[1].schedule["rig"].strands.fresh.any()


def test_a_replayed_creature_promoted_while_nobody_reads_steps_its_strands_again(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Creatures that meet are promoted: a cat promoted from replay while nobody reads
    the fur has its strands stepped again from the next frame (from the rig's pose),
    the other replayed cats' still resting, every strand finite."""
    monkeypatch.setattr(rig_module, "UNREAD_SECONDS", 0.05)
    world = _cats_world(make_world)
    world.step(12)
    strands = world.schedule["rig"].strands
    replayed, _ = _strand_rows(world)
    hero = int(world.physics.roster.entity[np.flatnonzero(world.physics.tier == KINEMATIC)[0]])
    world.lod.promote(hero)
    world.step(3)
    still, _ = _strand_rows(world)
    assert 0 < len(still) < len(replayed)  # the hero's strands left the resting ones
    assert strands.fresh[still].all() and not np.delete(strands.fresh, still).any()
    assert np.isfinite(strands.pos).all() and np.isfinite(world.resource(FurData).curves).all()
