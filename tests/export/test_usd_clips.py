"""Creatures replaying one gait clip share one SkelAnimation in the skinned USD: the file
validates, every creature's joints evaluate (UsdSkel.Cache) where the take has them, and
a sharer costs its root motion, not its joints."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.skinned_usd import write_skinned_usd
from ecs_tentacles.export.take_chunks import TakeChunks
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.take import Take
from ecs_tentacles.take.stream import open_take

pxr = pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Usd, UsdGeom, UsdSkel  # noqa: E402


def _hinges(take: Path, frames: list[int]) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Every body's pose at `frames`, read from the take as its reader gives them
    (replayed creatures' bodies filled in from their clip)."""
    found = {}
    with open_take(take) as source:
        for first, chunk in source.chunks():
            for frame in frames:
                if first <= frame < first + chunk.frames:
                    found[frame] = (chunk.pos[frame - first], chunk.quat[frame - first])
    return found


def test_replayed_creatures_share_one_clip_animation_and_pose_as_the_take(
    replay_take: Path, tmp_path: Path
) -> None:
    """The 15 of 16 creatures that replay reference one clip animation; through UsdSkel's
    own evaluation (world-space joint transforms) a physical creature's joints are within
    1 mm of the take's hinge points and a sharer's within 1 cm, at the built frame, the
    first replayed one, the middle and the last."""
    usd = tmp_path / "crowd16.usdc"
    assert main(["export", str(replay_take), "--out", str(usd), "--quiet", "--validate"]) == 0
    with open_take(replay_take) as source:
        header, frames = source.header, source.frames
        replays = [len(source.segments(c)) == 1 for c in range(len(header["creatures"]))]
    stage = Usd.Stage.Open(str(usd))
    clips = stage.GetPrimAtPath("/World/clips")
    assert clips.GetSpecifier() == pxr.Sdf.SpecifierClass  # nothing drawn or imported
    assert [c.GetTypeName() for c in clips.GetAllChildren()] == ["SkelAnimation"]
    cache = UsdSkel.Cache()
    lengths = np.array([body["length"] for body in header["bodies"]])
    checked = [0, 1, frames // 2, frames - 1]
    poses = _hinges(replay_take, checked)
    worst = {True: 0.0, False: 0.0}
    for creature, entry in enumerate(header["creatures"]):
        name = entry["name"]
        anim = stage.GetPrimAtPath(f"/World/{name}/{name}_skeleton/{name}_animation")
        sharing = anim.HasAuthoredReferences()
        assert sharing is replays[creature]
        cache.Populate(
            UsdSkel.Root(stage.GetPrimAtPath(f"/World/{name}")), Usd.TraverseInstanceProxies()
        )
        query = cache.GetSkelQuery(
            UsdSkel.Skeleton(stage.GetPrimAtPath(f"/World/{name}/{name}_skeleton"))
        )
        bodies = np.array([entry["mantle"], *(b for chain in entry["tentacles"] for b in chain)])
        offset = np.zeros((len(bodies), 3))
        offset[1:, 0] = -0.5 * lengths[bodies[1:]]  # a link's joint: its base
        for frame in checked:
            world = np.array(query.ComputeJointWorldTransforms(UsdGeom.XformCache(frame)))
            pos, quat = poses[frame]
            turn = quat[bodies].astype(np.float64)
            turn /= np.linalg.norm(turn, axis=1, keepdims=True)
            hinge = pos[bodies] + quat_rotate(turn, offset)
            apart = float(np.linalg.norm(world[:, 3, :3] - hinge, axis=1).max())
            worst[sharing] = max(worst[sharing], apart)
    assert sum(replays) == 15  # the one at full physics keeps its own
    assert worst[False] < 1e-3 and worst[True] < 1e-2, worst


def test_a_sharer_costs_its_root_motion_not_its_joints(replay_take: Path, tmp_path: Path) -> None:
    """The same take with every creature animated alone (a take in memory: no replay
    records) takes each sharer's joint rotations more (81 quaternions a frame), less the
    one animation they share."""
    shared, alone = tmp_path / "shared.usdc", tmp_path / "alone.usdc"
    with open_take(replay_take) as source:
        report = write_skinned_usd(source, shared)
        frames = source.frames
    full = Take.load(replay_take)
    assert write_skinned_usd(TakeChunks(full), alone).sharing == 0
    assert (report.sharing, report.shared, report.creatures) == (15, 1, 16)
    saved = alone.stat().st_size - shared.stat().st_size
    joints = 81 * 16  # bytes of a creature-frame's rotations (quatf)
    assert saved > 0.9 * (report.sharing - report.shared) * frames * joints, (saved, report)
