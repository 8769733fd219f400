"""Replayed stretches share one SkelAnimation per clip in the skinned USD: each stretch is a
skeleton whose animation references the shared one offset in time, shown on its frames;
the file validates, at every frame the skeleton shown poses the creature (UsdSkel.Cache)
where the take has it, and a replayed frame costs its root motion, not its joints."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.export.skinned import Skin
from ecs_tentacles.export.skinned_usd import write_skinned_usd
from ecs_tentacles.export.take_chunks import TakeChunks
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.skin.keys import angle_between
from ecs_tentacles.skin.rig import Keys
from ecs_tentacles.take import Take
from ecs_tentacles.take.stream import open_take

pxr = pytest.importorskip("pxr", reason="USD export needs usd-core (the usd / dev extras)")
from pxr import Sdf, Usd, UsdGeom, UsdSkel  # noqa: E402


def _read(take: Path) -> tuple[dict[str, Any], list[np.ndarray], list[np.ndarray], np.ndarray]:
    """(header, every frame's body positions and rotations as the reader gives them,
    replayed bodies filled in, replay_kind (frames, creatures))."""
    pos, quat = [], []
    with open_take(take) as source:
        for _, chunk in source.chunks():
            pos += list(chunk.pos)
            quat += list(chunk.quat)
        return source.header, pos, quat, source.replay_records()["replay_kind"]


def _round_trip(take: Path, usd: Path) -> tuple[dict[str, float], dict[str, list[str]]]:
    """At every frame of every creature: exactly one of its skeletons is shown; through
    UsdSkel's own evaluation (world-space joint transforms) its joints against the take's
    hinge points. Returns the worst distance on physical and replayed frames, and each
    creature's skeletons in the order they are shown."""
    header, pos, quat, kind = _read(take)
    stage = Usd.Stage.Open(str(usd))
    cache = UsdSkel.Cache()
    lengths = np.array([body["length"] for body in header["bodies"]])
    worst = {"physical": 0.0, "replayed": 0.0}
    shown_order: dict[str, list[str]] = {}
    for creature, entry in enumerate(header["creatures"]):
        name = entry["name"]
        root = stage.GetPrimAtPath(f"/World/{name}")
        cache.Populate(UsdSkel.Root(root), Usd.TraverseInstanceProxies())
        skeletons = [p for p in root.GetChildren() if p.IsA(UsdSkel.Skeleton)]
        bodies = np.array([entry["mantle"], *(b for chain in entry["tentacles"] for b in chain)])
        offset = np.zeros((len(bodies), 3))
        offset[1:, 0] = -0.5 * lengths[bodies[1:]]  # a link's joint: its base
        order: list[str] = []
        for frame in range(len(pos)):
            shown = [
                s
                for s in skeletons
                if UsdGeom.Imageable(s).ComputeVisibility(frame) != UsdGeom.Tokens.invisible
            ]
            assert len(shown) == 1, (name, frame, [s.GetName() for s in shown])
            skin = root.GetChild(shown[0].GetName().replace("_skeleton", "_skin"))
            assert UsdGeom.Imageable(skin).ComputeVisibility(frame) != UsdGeom.Tokens.invisible
            if not order or order[-1] != shown[0].GetName():
                order.append(shown[0].GetName())
            query = cache.GetSkelQuery(UsdSkel.Skeleton(shown[0]))
            world = np.array(query.ComputeJointWorldTransforms(UsdGeom.XformCache(frame)))
            turn = quat[frame][bodies].astype(np.float64)
            turn /= np.linalg.norm(turn, axis=1, keepdims=True)
            hinge = pos[frame][bodies] + quat_rotate(turn, offset)
            apart = float(np.linalg.norm(world[:, 3, :3] - hinge, axis=1).max())
            key = "physical" if kind[frame, creature] < 0 else "replayed"
            worst[key] = max(worst[key], apart)
        shown_order[name] = order
    return worst, shown_order


def test_a_creature_that_switches_shows_a_skeleton_per_stretch_where_the_take_has_it(
    switching_take: Path, tmp_path: Path
) -> None:
    """Creatures that leave physics for the crawl clip and come back, some several times:
    one shared clip animation; a skeleton per replayed stretch, shown on its frames, its
    own skeleton on the physical ones, at every frame within 1 cm (replayed) and 1 mm
    (physical) of the take; the own animation samples only the physical frames and the
    frame after each run of them."""
    usd = tmp_path / "switching.usdc"
    assert main(["export", str(switching_take), "--out", str(usd), "--quiet", "--validate"]) == 0
    with open_take(switching_take) as source:
        segments = [source.segments(c) for c in range(len(source.header["creatures"]))]
        frames = source.frames
    assert max(len(s) for s in segments) >= 3  # the premise: a creature that comes back
    worst, order = _round_trip(switching_take, usd)
    assert worst["physical"] < 1e-3 and worst["replayed"] < 1e-2, worst
    stage = Usd.Stage.Open(str(usd))
    clips = stage.GetPrimAtPath("/World/clips")
    assert clips.GetSpecifier() == Sdf.SpecifierClass  # nothing drawn or imported
    assert [c.GetName() for c in clips.GetAllChildren()] == ["plan0_clip0_crawl"]
    for creature, name in enumerate(order):
        mine = segments[creature]
        physical = np.ones(frames, dtype=bool)
        for segment in mine:
            physical[segment.first : segment.end] = False
        expected = []  # the skeletons as they take over, frame by frame
        for frame in range(frames):
            k = next((k for k, s in enumerate(mine) if s.first <= frame < s.end), None)
            expected.append(f"{name}_skeleton" if k is None else f"{name}_replay{k}_skeleton")
        assert order[name] == [s for i, s in enumerate(expected) if i == 0 or s != expected[i - 1]]
        own = UsdSkel.Animation(
            stage.GetPrimAtPath(f"/World/{name}/{name}_skeleton/{name}_animation")
        )
        needed = physical.copy()
        needed[1:] |= physical[:-1]
        assert own.GetRotationsAttr().GetTimeSamples() == np.flatnonzero(needed).tolist()
        for k, segment in enumerate(mine):
            anim = stage.GetPrimAtPath(
                f"/World/{name}/{name}_replay{k}_skeleton/{name}_replay{k}_animation"
            )
            (reference,) = anim.GetPrimStack()[0].referenceList.GetAddedOrExplicitItems()
            assert reference.primPath == "/World/clips/plan0_clip0_crawl"
            assert reference.layerOffset.scale == pytest.approx(1.0 / segment.rate)


def test_creatures_replaying_from_frame_one_pose_as_the_take(
    replay_take: Path, tmp_path: Path
) -> None:
    """The 15 of 16 creatures that replay from frame 1 to the end: their built frame on
    their own skeleton, the rest on their stretch's; every creature's joints within 1 mm
    (physical) and 1 cm (replayed) of the take at every frame."""
    usd = tmp_path / "crowd16.usdc"
    assert main(["export", str(replay_take), "--out", str(usd), "--quiet", "--validate"]) == 0
    worst, order = _round_trip(replay_take, usd)
    assert worst["physical"] < 1e-3 and worst["replayed"] < 1e-2, worst
    switching = [n for n, skeletons in order.items() if len(skeletons) == 2]
    assert len(switching) == 15  # the one at full physics shows its own throughout
    assert all(order[n] == [f"{n}_skeleton", f"{n}_replay0_skeleton"] for n in switching)


def test_a_replayed_frame_costs_its_root_motion_not_its_joints(
    replay_take: Path, tmp_path: Path
) -> None:
    """The same take with every creature animated alone (a take in memory: no replay
    records) takes each replayed creature-frame's joint rotations more (81 quaternions),
    less the clip frames the shared animation holds."""
    shared, alone = tmp_path / "shared.usdc", tmp_path / "alone.usdc"
    with open_take(replay_take) as source:
        report = write_skinned_usd(source, shared)
        replayed = int((source.replay_records()["replay_kind"] >= 0).sum())
    full = Take.load(replay_take)
    assert write_skinned_usd(TakeChunks(full), alone).sharing == 0
    assert (report.sharing, report.shared, report.stretches, report.creatures) == (15, 1, 15, 16)
    stage = Usd.Stage.Open(str(shared))
    clip = UsdSkel.Animation(stage.GetPrimAtPath("/World/clips/plan0_clip0_crawl"))
    rows = clip.GetRotationsAttr().GetNumTimeSamples()
    saved = alone.stat().st_size - shared.stat().st_size
    joints = 81 * 16  # bytes of a creature-frame's rotations (quatf)
    assert saved > 0.9 * (replayed - rows) * joints, (saved, replayed, rows, report)


def test_reduced_keys_of_a_switching_creature_hold_their_tolerance_where_it_is_shown(
    switching_take: Path, tmp_path: Path
) -> None:
    """With `--keys reduced` a creature's own animation keys only frames its skeleton
    needs, and on every physical frame each joint's rotation as USD interpolates it is
    within the tolerance of the take's (the export of every frame)."""
    every, reduced = tmp_path / "every.usdc", tmp_path / "reduced.usdc"
    with open_take(switching_take) as source:
        write_skinned_usd(source, every)
    with open_take(switching_take) as source:
        report = write_skinned_usd(source, reduced, Skin(keys=Keys("reduced", 0.5)))
        kind = source.replay_records()["replay_kind"]
        names = [c["name"] for c in source.header["creatures"]]
    assert report.after < 0.6 * report.before and report.max_rotation_error_deg <= 0.5
    stages = [Usd.Stage.Open(str(path)) for path in (every, reduced)]
    worst = 0.0
    for creature, name in enumerate(names):
        path = f"/World/{name}/{name}_skeleton/{name}_animation"
        full, kept = (UsdSkel.Animation(s.GetPrimAtPath(path)).GetRotationsAttr() for s in stages)
        assert set(kept.GetTimeSamples()) <= set(full.GetTimeSamples())
        for frame in np.flatnonzero(kind[:, creature] < 0).tolist():
            a, b = (np.array(attr.Get(frame), dtype=np.float64) for attr in (full, kept))
            worst = max(worst, float(angle_between(a, b).max()))
    assert worst < 0.5 + 0.01, worst  # float32 samples
