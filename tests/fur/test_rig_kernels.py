"""The rig's two backends (numba kernels, whole-array numpy) agree; scratch and plans reuse."""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from ecs_tentacles.fur import rig
from ecs_tentacles.fur.rig import (
    ControlValues,
    RigBuffers,
    control_table,
    evaluate,
    local_frames,
    pose,
    world_frames,
)
from ecs_tentacles.fur.synthetic import synthetic_rig

BEHAVIOURS = ("lift", "aim", "direction", "twist")
# every on/off pattern of the four behaviours: each skips different work
PATTERNS = [tuple(bool(m >> i & 1) for i in range(4)) for m in range(16)]


@pytest.fixture
def numpy_only(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    monkeypatch.setattr(rig, "BACKEND", "numpy")
    yield


def with_only(values: ControlValues, on: tuple[bool, ...]) -> ControlValues:
    """The values with the behaviours `on` marks off set to zero for every control."""
    fields = {k: getattr(values, k).copy() for k in (*BEHAVIOURS, "position", "offset")}
    for name, keep in zip(BEHAVIOURS, on, strict=True):
        if not keep:
            fields[name][:] = 0.0
    return ControlValues(**fields)


def turn(angle: float, axis: int) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    i, j = [k for k in range(3) if k != axis]
    m = np.eye(3)
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def two_bodies(n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Poses of two bodies and a body index that alternates in runs."""
    rotation = np.stack([turn(0.7, 2), turn(-1.1, 0) @ turn(0.4, 1)])
    position = np.array([[1.5, -2.0, 0.25], [-0.5, 0.3, 1.0]])
    body = (np.arange(n) // 37) % 2
    return rotation, position, body


def run_numpy(monkeypatch: pytest.MonkeyPatch, func, *args):  # type: ignore[no-untyped-def]
    with monkeypatch.context() as m:
        m.setattr(rig, "BACKEND", "numpy")
        return func(*args)


@pytest.mark.parametrize("on", PATTERNS)
def test_numpy_blocks_equal_one_pass(on: tuple[bool, ...], numpy_only: None) -> None:
    bind, values = synthetic_rig(700, controls=9, seed=11, bend_deg=25.0)
    plan = control_table(with_only(values, on))
    whole = local_frames(bind, plan)
    parts = [local_frames(bind.part(slice(s, s + 256)), plan) for s in (0, 256)]
    parts.append(local_frames(bind.part(slice(512, 700)), plan))
    assert_array_equal(np.concatenate(parts, axis=2), whole)


def test_evaluate_is_local_world_and_pose(numpy_only: None) -> None:
    bind, values = synthetic_rig(400, controls=5, seed=4)
    rotation, position, body = two_bodies(400)
    bind.body[:] = body
    bind.__post_init__()
    frames = np.zeros((400, 4, 3), np.float32)
    curves = np.zeros((400, 8, 3), np.float32)
    evaluate(bind, values, rotation, position, frames, curves)
    expected = np.zeros_like(frames)
    world_frames(bind, local_frames(bind, values), rotation, position, out=expected)
    assert_array_equal(frames, expected)
    assert_array_equal(curves, pose(bind.shape_h, frames, out=np.empty_like(curves)))
    with pytest.raises(IndexError, match="control or a body"):
        evaluate(bind, values, rotation[:1], position[:1], frames, curves)


numba = pytest.importorskip("numba")


@pytest.fixture
def kernels_on(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    monkeypatch.setattr(rig, "BACKEND", "auto")  # whatever ECS_TENTACLES_RIG says
    yield


def test_the_kernels_are_used_when_numba_imports(kernels_on: None) -> None:
    assert rig.kernels() is not None
    assert rig.kernels().__name__ == "ecs_tentacles.fur.kernels"  # type: ignore[union-attr]


@pytest.mark.parametrize("on", PATTERNS)
def test_kernels_match_numpy(
    on: tuple[bool, ...], monkeypatch: pytest.MonkeyPatch, kernels_on: None
) -> None:
    bind, values = synthetic_rig(900, controls=7, seed=sum(on) * 3 + 1, bend_deg=30.0)
    values = with_only(values, on)
    rotation, position, body = two_bodies(900)
    bind.body[:] = body
    bind.__post_init__()
    local = local_frames(bind, values)
    expected_local = run_numpy(monkeypatch, local_frames, bind, values)
    # float32 rounding, amplified where a blend nearly cancels or a target is clamped
    assert_allclose(local, expected_local, atol=5e-5)
    frames = np.zeros((900, 4, 3), np.float32)
    curves = np.zeros((900, 8, 3), np.float32)
    evaluate(bind, values, rotation, position, frames, curves, RigBuffers())
    expected_frames, expected_curves = np.zeros_like(frames), np.zeros_like(curves)
    run_numpy(
        monkeypatch, evaluate, bind, values, rotation, position, expected_frames, expected_curves
    )
    assert_allclose(frames, expected_frames, atol=5e-5)
    assert_allclose(curves, expected_curves, atol=5e-6)  # 5 cm guides
    # the kernels' pose is the one `pose` gives for their frames
    assert_array_equal(curves, pose(bind.shape_h, frames, out=np.empty_like(curves)))
    numpy_curves = run_numpy(monkeypatch, pose, bind.shape_h, frames, np.empty_like(curves))
    assert_allclose(curves, numpy_curves, atol=1e-6)


def test_worlds_on_two_threads_take_turns_in_the_kernels(kernels_on: None) -> None:
    from concurrent.futures import ThreadPoolExecutor

    binds = [synthetic_rig(2000, controls=5, seed=seed) for seed in (1, 2)]
    rotation, position = np.eye(3)[None], np.zeros((1, 3))

    def run(index: int) -> np.ndarray:
        bind, values = binds[index]
        frames = np.zeros((2000, 4, 3), np.float32)
        curves = np.zeros((2000, 8, 3), np.float32)
        scratch = RigBuffers()
        for _ in range(20):
            evaluate(bind, values, rotation, position, frames, curves, scratch)
        return curves

    alone = [run(0), run(1)]
    with ThreadPoolExecutor(2) as pool:
        together = list(pool.map(run, [0, 1, 0, 1]))
    for index, curves in enumerate(together):
        assert_array_equal(curves, alone[index % 2])
