"""Shards baked apart (here, without Ray) merge into the local bake's take, byte for byte."""

from __future__ import annotations

import io

import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.distributed.merge import merge_takes
from ecs_tentacles.distributed.spheres import meetings
from ecs_tentacles.distributed.task import bake_shard
from ecs_tentacles.export.bake import BakePlan, bake
from ecs_tentacles.take import Take, write_npz


def data(take: Take) -> bytes:
    out = io.BytesIO()
    write_npz(out, take.arrays())
    return out.getvalue()


def test_interleaved_shards_with_different_fur_merge_into_the_local_take() -> None:
    # creatures 0 and 4 wear bird fur, 2 cat fur (their guides have other point counts):
    # the shards hold the furs apart, and list creatures out of the scene's order
    scene = crowd_scene(8, uniform=True)
    # the hand-picked shards split neighbours that would steer around each other
    scene["avoidance"] = {"enabled": False}
    plan = BakePlan.make(scene, seconds=0.1, fps=30)
    local = bake(plan, progress=False)
    shards = [[2, 5, 7], [0, 4], [1, 3, 6]]
    results = [bake_shard(plan, members) for members in shards]
    merged = merge_takes([(r.members, r.take) for r in results])
    assert local.header["guides"] is not None and "guide_points" in local.tracks
    assert data(merged) == data(local)
    # and the contact spheres say the shards never met in this short bake
    spheres = np.zeros((plan.steps + 1, 8, 4))
    shard_of = np.zeros(8, dtype=np.int64)
    for k, r in enumerate(results):
        spheres[:, r.members] = r.spheres
        shard_of[r.members] = k
    assert meetings(spheres, shard_of) == []
    assert (spheres[..., 3] > 0.3).all()
