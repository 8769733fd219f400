"""Shards baked apart (here, without Ray) merge into the local bake's take, byte for byte."""

from __future__ import annotations

import io

import numpy as np

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.distributed.merge import merge_takes
from ecs_tentacles.distributed.registries import MeetingReaches
from ecs_tentacles.distributed.shards import entries
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


def test_shards_that_would_have_steered_each_other_are_found_to_have_met() -> None:
    """Avoidance acts without contact: two creatures of different shards whose personal
    circles come within its range steer each other in the local bake only; the meetings
    check must say they met (the driver then bakes their shards again as one), or the
    sharded bake silently differs from the local one."""
    from ecs_tentacles.locomotion.plugin import LocomotionPlugin

    def octopus(name: str, x: float) -> dict:
        entry = {"name": name, "position": [x, 0.0], "tentacles": {"count": 6, "links": 4}}
        return {**entry, "goals": [{"position": [x, 3.0]}]}

    # side by side, personal circles (0.33 m) 0.3 m apart: close enough to steer, not to
    # touch (their contact spheres stay further apart than the proxies' margin)
    scene = {"version": 1, "creatures": [octopus("a", -0.48), octopus("b", 0.48)]}
    plan = BakePlan.make(scene, seconds=1.0, fps=30)
    results = [bake_shard(plan, [k]) for k in (0, 1)]
    merged = merge_takes([(r.members, r.take) for r in results])
    local = bake(plan, progress=False)
    assert data(merged) != data(local)  # they steered each other locally
    spheres = np.zeros((plan.steps + 1, 2, 4))
    for r in results:
        spheres[:, r.members] = r.spheres
    shard_of = np.array([0, 1])
    assert meetings(spheres, shard_of) == []  # contact alone misses it
    (meeting,) = entries([LocomotionPlugin()]).get(MeetingReaches)
    reach = meeting(plan.scene)
    assert reach is not None and len(reach) == 2
    assert meetings(spheres, shard_of, np.asarray(reach))  # the widened check finds it
    quiet = {**plan.scene, "avoidance": {"enabled": False}}
    assert meeting(quiet) is None
