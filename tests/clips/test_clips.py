"""Gait clips: recorded with the real physics, looping without a visible jump, replayed
rigidly for many creatures, and promoting a creature back to the physics without a pop."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import mujoco
import numpy as np
import pytest

from ecs_tentacles.clips.clips import CRAWL, IDLE, GaitClips
from ecs_tentacles.clips.gait_world import one_creature_scene, simulate
from ecs_tentacles.numeric.quaternions import quat_about_z, quat_multiply, quat_rotate
from ecs_tentacles.scene.load import load_scene, resolve_scene_path
from ecs_tentacles.world import World

PROMOTION_TOLERANCE = 0.02  # m: the largest body jump allowed when physics takes over


@pytest.fixture(scope="module")
def octopus() -> dict[str, Any]:
    return load_scene(resolve_scene_path("octopus"))


@pytest.fixture(scope="module")
def clips(octopus: dict[str, Any]) -> GaitClips:
    """The bundled octopus's clips, recorded once for the module."""
    clips = GaitClips.record(octopus["creatures"][0], octopus["physics"])
    print(f"\nrecording both clips of the octopus: {clips.seconds:.2f} s")
    return clips


def _world_poses(
    clips: GaitClips, kind: np.ndarray, phase: np.ndarray, xy: np.ndarray, heading: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    pos = np.empty((len(kind), len(clips.bodies), 3))
    quat = np.empty((len(kind), len(clips.bodies), 4))
    clips.evaluate(kind, phase, xy, heading, pos, quat)
    return pos, quat


def test_loops_wrap_without_a_jump(clips: GaitClips) -> None:
    for clip in (clips.idle, clips.crawl):
        steps = clip.steps()
        print(
            f"\n{clip.kind}: {clip.frames} frames ({clip.duration:.2f} s), recorded end-start"
            f" mismatch {100 * clip.mismatch:.2f} cm; wrap step {1000 * steps[-1]:.1f} mm,"
            f" ordinary steps median {1000 * np.median(steps[:-1]):.1f} mm,"
            f" largest {1000 * steps[:-1].max():.1f} mm"
        )
        assert clip.mismatch < 0.05  # the recording did hold a loop
        assert steps[-1] <= steps[:-1].max()  # the wrap moves no body more than a frame does
        assert clip.frames * clip.dt >= 1.0


def test_crawl_speed_matches_the_full_simulation(clips: GaitClips, octopus: dict[str, Any]) -> None:
    rec = simulate(one_creature_scene(octopus["creatures"][0], octopus["physics"], 30.0), 2.0, 8.0)
    mantle = rec.pos[:, 0, :2]
    full = float(np.linalg.norm(mantle[-1] - mantle[0])) / ((len(mantle) - 1) * rec.dt)
    print(f"\ncrawl speed: clip {clips.crawl.speed:.3f} m/s, full sim over 8 s {full:.3f} m/s")
    assert clips.crawl.speed > 0.02
    assert abs(clips.crawl.speed - full) < 0.3 * full
    assert clips.idle.speed == 0.0
    # the crawl went straight ahead: the clip's mantle stays near its origin
    assert np.abs(clips.crawl.pos[:, 0, :2]).max() < 0.1


def test_evaluate_is_the_clip_at_integer_phases(clips: GaitClips) -> None:
    n = clips.crawl.frames
    phase = np.arange(n, dtype=np.float64)
    pos, quat = _world_poses(clips, np.full(n, CRAWL), phase, np.zeros((n, 2)), np.zeros(n))
    np.testing.assert_allclose(pos, clips.crawl.pos, atol=1e-12)
    np.testing.assert_allclose(quat, clips.crawl.quat, atol=1e-12)
    # phases wrap: n + 3 is frame 3, -1 is the last frame
    pos, _ = _world_poses(
        clips, np.array([IDLE, IDLE]), np.array([clips.idle.frames + 3.0, -1.0]),
        np.zeros((2, 2)), np.zeros(2),
    )  # fmt: skip
    np.testing.assert_allclose(pos, clips.idle.pos[[3, -1]], atol=1e-12)


def test_evaluate_moves_the_clip_rigidly(clips: GaitClips) -> None:
    rng = np.random.default_rng(3)
    k = 64
    kind = rng.integers(0, 2, k)
    frame = np.array([rng.integers(0, clips.clip(c).frames) for c in kind])
    xy = rng.uniform(-20, 20, (k, 2))
    heading = rng.uniform(-np.pi, np.pi, k)
    pos, quat = _world_poses(clips, kind, frame.astype(np.float64), xy, heading)
    local_pos = np.stack([clips.clip(c).pos[f] for c, f in zip(kind, frame, strict=True)])
    local_quat = np.stack([clips.clip(c).quat[f] for c, f in zip(kind, frame, strict=True)])
    turn = quat_about_z(heading)[:, None, :]
    expected = quat_rotate(turn, local_pos)
    expected[..., :2] += xy[:, None, :]
    np.testing.assert_allclose(pos, expected, atol=1e-12)
    np.testing.assert_allclose(quat, quat_multiply(turn, local_quat), atol=1e-12)
    # and the nearest frame without interpolation is the same at integer phases
    near_pos = np.empty_like(pos)
    near_quat = np.empty_like(quat)
    clips.evaluate(kind, frame + 0.2, xy, heading, near_pos, near_quat, interpolate=False)
    np.testing.assert_allclose(near_pos, expected, atol=1e-12)


def test_fractional_phases_lie_between_frames(clips: GaitClips) -> None:
    clip = clips.crawl
    kind = np.full(3, CRAWL)
    pos, quat = _world_poses(
        clips, kind, np.array([4.25, 4.5, 4.75]), np.zeros((3, 2)), np.zeros(3)
    )
    for i, t in enumerate((0.25, 0.5, 0.75)):
        np.testing.assert_allclose(pos[i], (1 - t) * clip.pos[4] + t * clip.pos[5], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(quat, axis=-1), 1.0, atol=1e-12)


@pytest.fixture(scope="module")
def fresh_world(octopus: dict[str, Any]) -> Iterator[World]:
    """A one-creature world of the octopus, to promote clip poses into."""
    world = World.from_scene(one_creature_scene(octopus["creatures"][0], octopus["physics"]))
    yield world
    world.close()


def _promote(world: World, qpos: np.ndarray, qvel: np.ndarray, bodies: list[str]) -> np.ndarray:
    """Set the creature's joint state in the full model and run forward kinematics; the
    bodies' world positions (B, 3)."""
    group = world.physics.views[0]
    world.physics.place_joints(group.index, qpos, qvel)  # as a promotion does
    world.physics.sync(world.transforms)
    ids = [mujoco.mj_name2id(group.model, mujoco.mjtObj.mjOBJ_BODY, b) for b in bodies]
    return np.array(group.data.xpos[ids])


@pytest.mark.parametrize("interpolate_phase", [False, True])
def test_promotion_reproduces_the_shown_pose(
    clips: GaitClips, fresh_world: World, interpolate_phase: bool
) -> None:
    rng = np.random.default_rng(5)
    worst = 0.0
    for _ in range(12):
        kind = int(rng.integers(0, 2))
        phase = float(rng.integers(0, clips.clip(kind).frames))
        phase += rng.uniform(0, 1) if interpolate_phase else 0.0
        xy = rng.uniform(-10, 10, 2)
        heading = float(rng.uniform(-np.pi, np.pi))
        shown, _ = _world_poses(
            clips, np.array([kind]), np.array([phase]), xy[None], np.array([heading])
        )
        qpos, qvel = clips.joint_state_at(kind, phase, xy, heading)
        promoted = _promote(fresh_world, qpos, qvel, clips.bodies)
        worst = max(worst, float(np.linalg.norm(promoted - shown[0], axis=-1).max()))
    label = "fractional" if interpolate_phase else "integer"
    print(f"\npromotion at {label} phases: largest body jump {1000 * worst:.4f} mm")
    assert worst <= (PROMOTION_TOLERANCE if interpolate_phase else 1e-9)


def test_promoted_creature_steps_on(clips: GaitClips, fresh_world: World) -> None:
    """The promoted state is a state the physics accepts: it steps on without blowing up."""
    qpos, qvel = clips.joint_state_at(CRAWL, 10.0, np.array([1.0, 2.0]), 0.7)
    before = _promote(fresh_world, qpos, qvel, clips.bodies)
    fresh_world.step(30)
    after = np.array(fresh_world.transforms.pos[fresh_world.physics.views[0].body_rows])
    assert np.isfinite(after).all()
    assert np.linalg.norm(after - before, axis=-1).max() < 0.5


def test_thousand_creatures_evaluate_at_once(clips: GaitClips) -> None:
    """No timed assert: the figure is printed (tools/bench_clips.py measures it properly)."""
    import time

    k = 1000
    rng = np.random.default_rng(0)
    kind = rng.integers(0, 2, k)
    phase = rng.uniform(0, 500, k)
    xy = rng.uniform(-50, 50, (k, 2))
    heading = rng.uniform(-np.pi, np.pi, k)
    pos = np.empty((k, len(clips.bodies), 3))
    quat = np.empty((k, len(clips.bodies), 4))
    start = time.perf_counter()
    clips.evaluate(kind, phase, xy, heading, pos, quat)
    per = (time.perf_counter() - start) / k
    print(f"\nevaluate K=1000, {len(clips.bodies)} bodies: {1e6 * per:.1f} us per creature")
    assert np.isfinite(pos).all()
    np.testing.assert_allclose(np.linalg.norm(quat, axis=-1), 1.0, atol=1e-12)


@pytest.mark.parametrize("interpolate", [True, False])
def test_the_replay_kernel_equals_the_numpy_path(
    clips: GaitClips, interpolate: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.clips import clips as module

    assert module.KERNELS.get() is not None  # numba comes with the dev extra
    rng = np.random.default_rng(5)
    count = 300
    kind = rng.integers(0, 2, count)
    phase = rng.uniform(-50.0, 500.0, count)
    xy = rng.uniform(-30.0, 30.0, (count, 2))
    heading = rng.uniform(-7.0, 7.0, count)
    shape = (count, len(clips.bodies))
    results = []
    for backend in ("auto", "numpy"):
        monkeypatch.setattr(module.KERNELS, "backend", backend)
        pos, quat = np.empty((*shape, 3)), np.empty((*shape, 4))
        clips.evaluate(kind, phase, xy, heading, pos, quat, interpolate=interpolate)
        results.append((pos, quat))
    (pos, quat), (pos_np, quat_np) = results
    np.testing.assert_allclose(pos, pos_np, rtol=0, atol=1e-12)
    np.testing.assert_allclose(quat, quat_np, rtol=0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(quat, axis=-1), 1.0, atol=1e-12)


@pytest.mark.parametrize("backend", ["auto", "numpy"])
def test_poses_written_into_rows_of_a_batch_array_are_the_poses_evaluated(
    clips: GaitClips, backend: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    from ecs_tentacles.clips import clips as module

    monkeypatch.setattr(module.KERNELS, "backend", backend)
    rng = np.random.default_rng(6)
    count, bodies = 40, len(clips.bodies)
    kind, phase = rng.integers(0, 2, count), rng.uniform(0.0, 90.0, count)
    xy, heading = rng.uniform(-5.0, 5.0, (count, 2)), rng.uniform(-3.0, 3.0, count)
    pos, quat = np.empty((count, bodies, 3)), np.empty((count, bodies, 4))
    clips.evaluate(kind, phase, xy, heading, pos, quat)
    rows = rng.permutation(100)[:count]  # scattered rows of a 100-row batch
    batch_pos, batch_quat = np.full((100, bodies, 3), 7.0), np.full((100, bodies, 4), 7.0)
    clips.evaluate(kind, phase, xy, heading, batch_pos, batch_quat, rows=rows)
    np.testing.assert_array_equal(batch_pos[rows], pos)
    np.testing.assert_array_equal(batch_quat[rows], quat)
    others = np.setdiff1d(np.arange(100), rows)
    assert (batch_pos[others] == 7.0).all() and (batch_quat[others] == 7.0).all()  # untouched
    # through a batch's store rows (Batch.body_rows), in no order: the store's rows
    body_rows = rng.permutation(100 * bodies).reshape(100, bodies)
    store_pos, store_quat = np.full((100 * bodies, 3), 7.0), np.full((100 * bodies, 4), 7.0)
    clips.evaluate(kind, phase, xy, heading, store_pos, store_quat, rows=rows,
                   body_rows=body_rows)  # fmt: skip
    np.testing.assert_array_equal(store_pos[body_rows[rows]], pos)
    np.testing.assert_array_equal(store_quat[body_rows[rows]], quat)
    assert (store_pos[body_rows[others]] == 7.0).all()


@pytest.mark.parametrize("scattered", [False, True])
def test_poses_shared_by_threads_are_the_same_bits(clips: GaitClips, scattered: bool) -> None:
    """The replay's poses and reach spheres written in parts on the stepping threads
    (`PhysicsBackend.share`) are those of one call, bit for bit."""
    from concurrent.futures import ThreadPoolExecutor

    from ecs_tentacles.physics.posed_spheres import PosedSpheres
    from ecs_tentacles.physics.stepping import share

    rng = np.random.default_rng(7)
    count, bodies, rows_all = 700, len(clips.bodies), 900
    kind, phase = rng.integers(0, 2, count), rng.uniform(-5.0, 90.0, count)
    xy, heading = rng.uniform(-9.0, 9.0, (count, 2)), rng.uniform(-4.0, 4.0, count)
    rows = rng.permutation(rows_all)[:count]
    body_rows = rng.permutation(rows_all * bodies).reshape(rows_all, bodies) if scattered else None
    shape = (rows_all * bodies,) if scattered else (rows_all, bodies)
    of = rng.permutation(count)  # each creature's roster index
    rbound = rng.uniform(0.01, 0.1, count * bodies)
    written = []
    with ThreadPoolExecutor(3) as pool:
        for shared in (None, lambda n, work: share(pool, 3, n, work, least=50)):
            pos, quat = np.full((*shape, 3), 7.0), np.full((*shape, 4), 7.0)
            spheres = PosedSpheres.empty(np.arange(count) * bodies, rbound)
            clips.evaluate(kind, phase, xy, heading, pos, quat, rows=rows, body_rows=body_rows,
                           spheres=(spheres, of), share=shared)  # fmt: skip
            written.append((pos, quat, spheres.centre, spheres.radius, spheres.known))
    for one, parts in zip(*written, strict=True):
        np.testing.assert_array_equal(parts, one)
    assert written[1][4].all()
