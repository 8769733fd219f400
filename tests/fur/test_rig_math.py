"""The rig's math on synthetic guides: each behaviour exactly, and no flips (hypothesis)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from ecs_tentacles.fur.rig import (
    F32,
    Bind,
    ControlValues,
    local_frames,
    pose,
    world_frames,
)
from ecs_tentacles.fur.synthetic import synthetic_rig
from ecs_tentacles.fur.vectors import clamp_to_cap, dot, normalize

N = 500


def only(controls: int = 16, **set_values: float | np.ndarray) -> ControlValues:
    """Control values with every behaviour off except the ones given."""
    zero = np.zeros(controls, dtype=F32)
    fields = {"lift": zero, "aim": zero, "direction": zero, "twist": zero}
    fields |= {k: np.broadcast_to(np.asarray(v, F32), (controls,)) for k, v in set_values.items()}
    return ControlValues(
        position=np.zeros((3, controls), F32), offset=np.zeros((3, controls), F32), **fields
    )


def azimuth(v: np.ndarray, ref: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Signed angle from `ref` to `v` about `normal` (both projected on the tangent plane)."""
    a = v - dot(v, normal) * normal
    b = ref - dot(ref, normal) * normal
    crossed = np.cross(b.T, a.T).T
    return np.asarray(np.arctan2(dot(crossed, normal), dot(a, b)))


def frames(bind: Bind, values: ControlValues) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Body-local axis, up and side (3, n) of every guide."""
    local = local_frames(bind, values)
    assert_allclose(local[3], bind.root)
    return local[0], local[1], local[2]


def test_all_off_is_the_rest_pose() -> None:
    bind, _ = synthetic_rig(N)
    axis, up, side = frames(bind, only())
    assert_allclose(axis, bind.rest, atol=1e-6)
    assert_allclose(side, bind.side, atol=1e-6)
    assert_allclose(up, np.cross(bind.rest.T, bind.side.T).T, atol=1e-6)
    assert np.all(dot(up, bind.normal) > 0.9)  # up is the skin's outward side


def test_lift_one_gives_the_surface_normal_whatever_else_is_on() -> None:
    bind, values = synthetic_rig(N)
    values.lift[:] = 1.0
    axis, _, _ = frames(bind, values)
    assert_allclose(axis, bind.normal, atol=1e-6)


def test_half_lift_turns_half_the_angle_toward_the_normal() -> None:
    bind, _ = synthetic_rig(N)
    axis, _, _ = frames(bind, only(lift=0.5))
    rest_angle = np.arccos(dot(bind.rest, bind.normal))
    assert_allclose(np.arccos(np.clip(dot(axis, bind.normal), -1, 1)), rest_angle / 2, atol=2e-6)
    assert_allclose(azimuth(axis, bind.rest, bind.normal), 0.0, atol=1e-5)


def test_aim_one_points_at_the_control() -> None:
    bind, values = synthetic_rig(N, controls=4)
    values = only(4, aim=1.0)
    values.position[:] = np.array([[0.5, -0.5, 0.0, 0.0], [0.0, 0.0, 0.5, 0.0], [0, 0, 0, 0.6]])
    axis, _, _ = frames(bind, values)
    wanted = normalize(values.position[:, bind.control] - bind.root)
    inside = dot(wanted, bind.normal) >= bind.tan_min  # above the guide's horizon
    assert inside.sum() > 50
    assert_allclose(axis[:, inside], wanted[:, inside], atol=1e-6)
    # below its horizon a guide points as close as it may: same azimuth, lowest elevation
    clamped = clamp_to_cap(wanted[:, ~inside], bind.normal[:, ~inside], bind.tan_min[~inside])
    assert_allclose(axis[:, ~inside], clamped, atol=1e-6)
    low = dot(axis[:, ~inside], bind.normal[:, ~inside])
    assert np.all(low >= np.sin(np.arctan(bind.tan_min[~inside])) - 1e-6)


def test_direction_follows_the_controls_move() -> None:
    bind, _ = synthetic_rig(N, controls=1)
    values = only(1, direction=1.0)
    values.offset[:, 0] = (0.0, 0.0, 1.0)  # moved up by one reach
    axis, _, _ = frames(bind, values)
    expected = clamp_to_cap(normalize(bind.rest + values.offset[:, [0]]), bind.normal, bind.tan_min)
    assert_allclose(axis, expected, atol=2e-5)  # float32; clamped ones amplify rounding
    assert np.all(axis[2] >= bind.rest[2] - 1e-6)  # every guide turned toward +z
    assert np.mean(axis[2] - bind.rest[2]) > 0.2


def test_twist_angles_follow_the_per_guide_multipliers() -> None:
    bind, _ = synthetic_rig(N)
    top = np.pi / 4
    axis, _, side = frames(bind, only(twist=top))
    turned = azimuth(axis, bind.rest, bind.normal)
    assert_allclose(turned, bind.multiplier * top, atol=2e-6)
    assert_allclose(azimuth(side, bind.side, bind.normal), bind.multiplier * top, atol=2e-6)
    assert_allclose(dot(axis, bind.normal), dot(bind.rest, bind.normal), atol=1e-6)


def test_world_frames_and_pose_follow_the_body() -> None:
    bind, values = synthetic_rig(N)
    angle = 0.7
    rotation = np.array(
        [[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]]
    )
    position = np.array([1.5, -2.0, 0.25])
    out = np.zeros((N, 4, 3), np.float32)
    local = local_frames(bind, values)
    world_frames(bind, local, rotation[None], position[None], out=out)
    assert_allclose(out[:, 3], (rotation @ bind.root.astype(float)).T + position, atol=1e-6)
    for slot in range(3):
        assert_allclose(out[:, slot], (rotation @ local[slot].astype(float)).T, atol=1e-6)
    curves = pose(bind.shape_h, out, out=np.zeros((N, 8, 3), np.float32))
    assert_allclose(curves[:, 0], out[:, 3], atol=1e-6)
    tip = out[:, 3] + 0.05 * out[:, 0]  # straight guides of 5 cm
    assert_allclose(curves[:, -1], tip, atol=1e-6)


unit = st.floats(0.0, 1.0, allow_nan=False)
coordinate = st.floats(-0.7, 0.7, allow_nan=False)


@st.composite
def controls(draw: st.DrawFn, count: int = 4) -> ControlValues:
    """Arbitrary control values: weights in [0, 1], twist up to 180 degrees, anywhere."""

    def arr(strategy: st.SearchStrategy[float], shape: tuple[int, ...]) -> np.ndarray:
        size = int(np.prod(shape))
        return np.array(draw(st.lists(strategy, min_size=size, max_size=size)), F32).reshape(shape)

    return ControlValues(
        lift=arr(unit, (count,)),
        aim=arr(unit, (count,)),
        direction=arr(unit, (count,)),
        twist=arr(st.floats(0.0, np.pi), (count,)),
        position=arr(coordinate, (3, count)),
        offset=arr(st.floats(-5.0, 5.0), (3, count)),
    )


BENT, _ = synthetic_rig(300, controls=4, bend_deg=40.0, seed=3)


@settings(max_examples=100, deadline=None)
@given(controls())
def test_every_guide_and_every_point_stays_outside_the_skin(values: ControlValues) -> None:
    local = local_frames(BENT, values)
    assert np.all(dot(local[0], BENT.normal) >= np.sin(np.radians(3.0)) - 1e-6)
    out = np.zeros((300, 4, 3), np.float32)
    world_frames(BENT, local, np.eye(3)[None], np.zeros((1, 3)), out=out)
    curves = pose(BENT.shape_h, out, out=np.zeros((300, 8, 3), np.float32))
    height = np.einsum("npk,kn->np", curves - out[:, 3:4], BENT.normal)
    assert height.min() >= -1e-6


def _angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return np.asarray(np.arccos(np.clip(dot(a.astype(float), b.astype(float)), -1.0, 1.0)))


@settings(max_examples=100, deadline=None)
@given(controls(), st.integers(0, 2**31 - 1))
def test_a_small_control_change_gives_a_small_direction_change(
    values: ControlValues, seed: int
) -> None:
    bind = BENT
    rng = np.random.default_rng(seed)
    # keep controls off the roots (an aim target inside a root has no direction)
    far = np.linalg.norm(values.position, axis=0) < 0.35
    values.position[:, far] *= 0.35 / np.maximum(
        np.linalg.norm(values.position[:, far], axis=0), 1e-3
    )
    step = 1e-5
    nudged = ControlValues(
        lift=np.clip(values.lift + rng.uniform(-step, step, 4), 0, 1).astype(F32),
        aim=np.clip(values.aim + rng.uniform(-step, step, 4), 0, 1).astype(F32),
        direction=np.clip(values.direction + rng.uniform(-step, step, 4), 0, 1).astype(F32),
        twist=(values.twist + rng.uniform(-step, step, 4)).astype(F32),
        position=(values.position + rng.uniform(-step, step, (3, 4))).astype(F32),
        offset=(values.offset + rng.uniform(-step, step, (3, 4))).astype(F32),
    )
    before, after = local_frames(bind, values), local_frames(bind, nudged)
    for slot in range(3):  # axis, up, side: a flip would be ~1 radian
        assert _angles(before[slot], after[slot]).max() < 0.02


def test_controls_crossing_each_other_move_guides_smoothly() -> None:
    bind, _ = synthetic_rig(400, controls=2, seed=5)
    values = only(2, aim=0.8, direction=0.5, lift=0.2)
    previous = None
    for t in np.linspace(0.0, 1.0, 801):  # the two controls swap places through each other
        a = (1 - t) * np.array([-0.5, 0.1, 0.3]) + t * np.array([0.5, -0.1, 0.3])
        values.position[:, 0] = a
        values.position[:, 1] = a * np.array([-1, -1, 1])
        values.offset[:, 0] = a - (-0.5, 0.1, 0.3)
        values.offset[:, 1] = values.position[:, 1] - (0.5, -0.1, 0.3)
        axis, _, _ = frames(bind, values)
        if previous is not None:
            assert _angles(previous, axis).max() < 0.05  # steps of 1.25 mm: no jumps
        previous = axis
