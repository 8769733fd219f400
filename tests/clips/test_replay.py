"""Replay: the clip frame a creature starts from (the kernel is numpy's), poses into the store."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.clips import replay
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


def test_poses_written_into_the_store_by_the_replay_are_the_syncs(
    make_world: Callable[..., World], monkeypatch: pytest.MonkeyPatch
) -> None:
    """On the plane a uniform crowd's replayed poses go into the Transform store in the
    replay's own pass (the sync then copies the stepped rows only): the same poses,
    bit for bit, in the store and in the batch, as when the sync copied them all."""
    from ecs_tentacles.creator.crowd import crowd_scene

    scene = crowd_scene(6, seed=2, uniform=True)
    scene.setdefault("physics", {})["lod"] = {"full": 0, "reduced": 2, "hold_seconds": 0.1}
    from ecs_tentacles.physics.batch import Batch

    synced, sync = [], Batch.sync

    def noting(batch: Batch, transforms: Any) -> None:
        synced.append(0 if batch.shown is None else int(batch.shown.sum()))
        sync(batch, transforms)

    monkeypatch.setattr(Batch, "sync", noting)
    runs = []
    for direct in (True, False):
        synced.clear()
        monkeypatch.setattr(replay, "DIRECT", direct)
        world = make_world(scene)
        (batch,) = world.physics.batches
        assert batch.body_span() is not None  # one morphology, its bodies in a row
        poses = []
        for _ in range(30):
            world.step(1)
            poses.append(
                (world.transforms.pos.copy(), world.transforms.quat.copy(), batch.xpos.copy())
            )
        assert world.lod.counts()["kinematic"] >= 3
        assert (max(synced) >= 3) if direct else (max(synced) == 0)  # rows the sync left
        runs.append(poses)
    for (pos, quat, xpos), (pos0, quat0, xpos0) in zip(*runs, strict=True):
        assert_array_equal(pos, pos0)
        assert_array_equal(quat, quat0)
        assert_array_equal(xpos, xpos0)
