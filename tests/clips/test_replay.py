"""Replay: the clip frame a creature starts from (the kernel is numpy's), poses written once
into the store (read back from the batches, kept by snapshots)."""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.clips import replay
from ecs_tentacles.physics.tiers import KINEMATIC
from ecs_tentacles.world import World


def test_the_nearest_frame_kernel_picks_numpys_frames(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = np.random.default_rng(5)
    shapes = rng.normal(0.0, 0.3, (40, 21, 3))
    shapes[17] = shapes[6]  # a tie: numpy's argmin takes the first
    shapes[30] = shapes[2] + 1e-12  # all but a tie
    picked = rng.integers(0, 40, 50)
    shape = shapes[picked] + rng.normal(0.0, 0.02, (50, 21, 3))
    shape[:5] = shapes[[6, 17, 2, 30, 0]]  # exactly a frame
    shape[5:10] = rng.normal(0.0, 1.0, (5, 21, 3))  # like none of them
    assert replay.KERNELS.get() is not None  # numba comes with the dev extra
    found = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(replay.KERNELS, "backend", backend)
        found.append(replay._nearest_frame(shapes, shape, chunk=16))
    assert_array_equal(found[0], found[1])
    assert list(found[0][:5]) == [6, 6, 2, 30, 0]
    assert (found[0][10:] == picked[10:]).mean() > 0.9  # a small nudge keeps its frame


BODY_PLAN = ("mantle", "tentacles", "locomotion", "fur")  # a varied crowd's creature's keys
HILLS = {"size": [40, 40], "resolution": 64, "height": 0.3, "noise": {"seed": 3, "scale": 6.0}}


def _replayed_run(world: World, frames: int) -> list[tuple[np.ndarray, ...]]:
    """Per frame: the Transform store's poses, every batch's poses as shown (what a
    snapshot keeps) and each replayed creature's poses read back from its batch."""
    run = []
    for _ in range(frames):
        world.step(1)
        shown = [np.concatenate([p.ravel() for p in b.all_poses()]) for b in world.physics.batches]
        each = []
        for index in np.flatnonzero(world.physics.tier == KINEMATIC).tolist():
            batch, row = world.physics.roster.locate(index)
            each.extend(batch.poses(row))
        run.append((world.transforms.pos.copy(), world.transforms.quat.copy(), *shown, *each))
    return run


@pytest.mark.parametrize("crowd", ["uniform", "varied", "terrain"])
def test_replayed_poses_written_once_are_the_poses_the_sync_copied(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch, crowd: str
) -> None:
    """A replayed creature's poses are written into the Transform store only, not into
    its batch's pose rows for the sync to copy: the store holds the same bits every
    frame as before, whether a batch's store rows are consecutive (a uniform crowd) or
    not (several morphologies, a creature spawned and one despawned), on the plane or
    draped over terrain; read back from the batch (`Batch.poses`, `Batch.all_poses`)
    they are the poses the batch held."""
    from ecs_tentacles.creator.crowd import crowd_scene

    scene = crowd_scene(6, seed=2, uniform=crowd != "varied")
    if crowd == "varied":  # two body plans, alternating: each batch's rows interleaved
        plans = [{k: v for k, v in c.items() if k in BODY_PLAN} for c in scene["creatures"][:2]]
        for i, creature in enumerate(scene["creatures"]):  # (two gait clips to record)
            for key in BODY_PLAN:
                creature.pop(key, None)
            creature.update(copy.deepcopy(plans[i % 2]))
    scene.setdefault("physics", {})["lod"] = {"full": 0, "reduced": 2, "hold_seconds": 0.1}
    if crowd == "terrain":
        scene["terrain"] = {"heightfield": HILLS}
    runs = []
    for direct in (False, True):  # the old path first: poses into the batches, synced
        monkeypatch.setattr(replay, "DIRECT", direct)
        world = make_world(scene)
        if crowd == "varied":  # one more of the first morphology: its rows after the others'
            late = {**scene["creatures"][0], "name": "late", "goals": []}
            world.spawn(late, position=(12.0, 12.0))
        consecutive = [b.body_span() is not None for b in world.physics.batches]
        assert all(consecutive) if crowd != "varied" else not all(consecutive)
        run = _replayed_run(world, 30)
        if crowd == "varied":  # a replayed creature leaves: the rows after it move up
            replayed = np.flatnonzero(world.physics.tier == KINEMATIC)
            world.despawn(int(world.physics.roster.entity[replayed[0]]))
            run += _replayed_run(world, 10)
        runs.append(run)
        assert world.lod.counts()["kinematic"] >= 3
        shown = [b.shown for b in world.physics.batches if b.shown is not None]
        assert (sum(int(s.sum()) for s in shown) >= 3) if direct else not shown
        if direct and crowd == "varied":  # replayed rows scattered through the store too
            assert any(b.shown is not None and b.shown.any() for b in world.physics.batches
                       if b.body_span() is None)  # fmt: skip
    for old, new in zip(*runs, strict=True):
        assert len(old) == len(new)
        for a, b in zip(old, new, strict=True):
            assert_array_equal(a, b)


def test_a_snapshot_keeps_the_replayed_poses_as_shown(make_world: Callable[..., World]) -> None:
    """The batches' pose rows of replayed creatures are not written each frame; a
    snapshot keeps the poses shown and, restored, the world steps on bit for bit."""
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.snapshot import restore, take

    scene = crowd_scene(6, seed=2, uniform=True)
    scene.setdefault("physics", {})["lod"] = {"full": 0, "reduced": 2, "hold_seconds": 0.1}
    world = make_world(scene)
    world.step(20)
    (batch,) = world.physics.batches
    saved = take(world)
    kept = saved.physics.batches[0].poses
    rows = np.flatnonzero(world.physics.tier[batch.members] == KINEMATIC)
    assert len(rows) >= 3
    assert_array_equal(kept[0][rows], world.transforms.pos[batch.body_rows[rows]])
    assert_array_equal(kept[1][rows], world.transforms.quat[batch.body_rows[rows]])
    ahead = _replayed_run(world, 10)
    restore(world, saved)
    assert batch.shown is None  # every row's poses are the batch's again, as saved
    assert_array_equal(batch.all_poses()[0], kept[0])  # (never placed ones: as shown)
    for first, again in zip(ahead, _replayed_run(world, 10), strict=True):
        for a, b in zip(first, again, strict=True):
            assert_array_equal(a, b)


def test_replayed_reach_spheres_found_as_written_are_the_stores(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A replayed creature's reach sphere (the contact proxies' and the level of detail's)
    is found as the replay writes its poses, not read back from the Transform store by
    the next frame: every frame's spheres are the store's bit for bit as the frame starts
    (`ContactProxies.spheres`), also as one is promoted and demoted and on the frame
    after a snapshot is restored, and the crowd's tiers and poses are those of the path
    that reads them back."""
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.physics.proxies import ContactProxies, Sensed
    from ecs_tentacles.snapshot import restore, take
    from ecs_tentacles.store import TransformStore

    scene = crowd_scene(8, seed=2, species=2)  # two body plans: two batches of four rows
    scene.setdefault("physics", {})["lod"] = {"full": 0, "reduced": 2, "hold_seconds": 0.1}
    sensed: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    sense = ContactProxies.sense

    def recorded(
        self: ContactProxies, transforms: TransformStore, frame: int | None = None
    ) -> Sensed:
        out = sense(self, transforms, frame)
        if frame is not None and (not sensed or sensed[-1][0] is not out[2]):
            sensed.append((out[2], out[2].copy(), out[3].copy()))  # the frame's first ask
        return out

    monkeypatch.setattr(ContactProxies, "sense", recorded)
    runs = []
    for found in (False, True):  # the old path first: spheres read back from the store
        monkeypatch.setattr(replay, "SPHERES", found)
        world = make_world(scene)
        proxies = world.physics.proxies
        tiers, poses, came = [], [], 0
        saved, chosen = None, -1
        for frame in range(40):
            if frame == 5:  # a replayed creature promoted, and later demoted again
                chosen = int(world.physics.roster.entity[np.argmax(world.physics.tier)])
                world.lod.promote(chosen)
            if frame == 12:
                world.lod.release(chosen)
            if frame == 15:
                saved = take(world)
            if frame == 30 and saved is not None:  # back to 15: the replay's spheres are stale
                restore(world, saved)
            pos = world.transforms.pos[proxies.rows]
            centre, radius = proxies.spheres(pos)
            came += int(proxies.posed_spheres().known.sum())
            count = len(sensed)
            world.step(1)
            assert len(sensed) == count + 1
            _, got_centre, got_radius = sensed[-1]
            assert_array_equal(got_centre, centre, err_msg=f"frame {frame}")
            assert_array_equal(got_radius, radius, err_msg=f"frame {frame}")
            tiers.append(world.physics.tier.copy())
            poses.append(world.transforms.pos.copy())
        kinematic = np.array(tiers) == KINEMATIC
        assert kinematic.sum(axis=1).max() >= 4 and (kinematic != kinematic[0]).any()
        assert (came > 100) if found else came == 0  # most replayed ones came from the replay
        runs.append((tiers, poses))
    for old, new in zip(*runs, strict=True):
        for a, b in zip(old, new, strict=True):
            assert_array_equal(a, b)


def test_replayed_poses_shared_by_the_stepping_threads_are_one_threads(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """A large crowd's replayed poses are written in chunks on the stepping threads
    (`PhysicsBackend.share`; here from 1 creature a chunk, not `SHARE_LEAST`): every
    frame's store and batch poses are those of one thread, bit for bit. (Store rows
    scattered or not: `test_clips.py`'s kernel test, shared the same way.)"""
    from ecs_tentacles.creator.crowd import crowd_scene
    from ecs_tentacles.physics import stepping

    scene = crowd_scene(6, seed=2, uniform=True)
    scene.setdefault("physics", {})["lod"] = {"full": 0, "reduced": 2, "hold_seconds": 0.1}
    monkeypatch.setattr(stepping, "SHARE_LEAST", 1)
    chunked = [0]  # the chunks of the last shared call
    share = stepping.share

    def counted(pool: Any, threads: int, count: int, work: Any, least: int) -> None:
        chunked.append(0)

        def chunk(start: int, stop: int) -> None:
            chunked[-1] += 1
            work(start, stop)

        share(pool, threads, count, chunk, least)

    monkeypatch.setattr(stepping, "share", counted)
    runs = [_replayed_run(make_world(scene, threads=threads), 20) for threads in (1, 2)]
    assert max(chunked) >= 4  # the two-thread world's replay went in chunks
    for one, two in zip(*runs, strict=True):
        for a, b in zip(one, two, strict=True):
            assert_array_equal(a, b)


def test_the_steering_kernel_turns_and_moves_creatures_as_numpy_does(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Replayed creatures turned toward their targets and moved a frame on: the kernel's
    headings, places, phases and clip kinds are numpy's (within float64 rounding: numba's
    and numpy's sin, cos and atan2 may round differently on another CPU), at every kind
    of way: far targets all round (turns past the limit, both ways, across +-pi), near
    ones (a turn within the limit), arrived (idle), none (nan: idle), in two batches
    crawling at different speeds."""
    from ecs_tentacles.clips.clips import CRAWL, IDLE

    rng = np.random.default_rng(11)
    count, dt = 400, 1.0 / 60.0
    xy = rng.uniform(-5.0, 5.0, (count, 2))
    heading = rng.uniform(-4.0, 4.0, count)  # (not wrapped: replay never wraps them)
    moving = np.flatnonzero(rng.random(count) < 0.8)
    way = rng.uniform(-np.pi, np.pi, len(moving))
    far = rng.choice([10.0, 0.3, 0.04, np.nan], len(moving), p=[0.5, 0.2, 0.2, 0.1])
    targets = xy[moving] + far[:, None] * np.stack([np.cos(way), np.sin(way)], axis=1)
    far[:3] = 3.0, 3.0, 0.0  # behind, across +-pi one way and the other; where it stands
    targets[:3] = xy[moving[:3]] + [[-3.0, 1e-9], [-3.0, -1e-9], [0.0, 0.0]]
    heading[moving[:3]] = 0.0
    batch_of = rng.integers(0, 2, len(moving))
    speed, advance = np.array([0.21, 0.35]), np.array([0.5, 1.0])
    results = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(replay.KERNELS, "backend", backend)
        steered = replay.ClipReplay.__new__(replay.ClipReplay)
        steered.xy, steered.heading = xy.copy(), heading.copy()
        steered.phase, steered.kind = np.zeros(count), np.full(count, IDLE, dtype=np.int64)
        for _ in range(3):
            steered._steer(moving, targets, batch_of, speed, advance, dt)
        results.append(steered)
    assert replay.KERNELS.get() is None  # (the numpy run was numpy's)
    kernel, numpy = results
    assert_array_equal(kernel.kind, numpy.kind)
    assert_array_equal(kernel.phase, numpy.phase)
    np.testing.assert_allclose(kernel.heading, numpy.heading, rtol=0.0, atol=1e-12)
    np.testing.assert_allclose(kernel.xy, numpy.xy, rtol=0.0, atol=1e-12)
    crawled = np.isin(np.arange(count), moving[np.isfinite(far) & (far > replay.ARRIVED)])
    assert (kernel.kind[crawled] == CRAWL).all() and (kernel.kind[~crawled] == IDLE).all()
    limit = 3 * replay.TURN_RATE * dt
    turned = np.abs(kernel.heading - heading)
    assert np.isclose(turned[moving[:2]], limit).all()  # +-pi: the limit, one way or the other
    assert (turned[~crawled] == 0.0).all() and (turned <= limit + 1e-12).all()
    assert_array_equal(kernel.phase[moving], 3 * advance[batch_of])
    moved = np.hypot(*(kernel.xy - xy).T)
    assert (moved[~crawled] == 0.0).all()
    assert np.isclose(moved[crawled].max(), 3 * speed[1] * dt)
