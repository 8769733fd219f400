"""Keyframed tracks: easing curves and vectorised evaluation, exactly."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.numeric.keyframes import EASING_CODE, TrackSet, channels_from_keys, ease

U = np.linspace(0.0, 1.0, 11)


@pytest.mark.parametrize(
    ("name", "curve"),
    [
        ("linear", U),
        ("ease", 3 * U**2 - 2 * U**3),
        ("slow_out", U**2),
        ("slow_in", 1 - (1 - U) ** 2),
        ("step", (U >= 1).astype(float)),
    ],
)
def test_easing_curves(name: str, curve: np.ndarray) -> None:
    assert_allclose(ease(U, np.full(11, EASING_CODE[name])), curve, atol=1e-15)


def test_ease_is_slow_at_both_ends() -> None:
    code = np.full(3, EASING_CODE["ease"])
    small = ease(np.array([0.0, 1e-3, 1.0]), code)
    assert small[1] < 1e-5 and 1 - ease(np.array([1 - 1e-3]), code[:1])[0] < 1e-5


def test_track_set_evaluates_every_channel_at_once() -> None:
    lift = channels_from_keys(
        0, (3,), [{"time": 1, "value": 0.0, "easing": "linear"}, {"time": 3, "value": 1.0}]
    )
    pos = channels_from_keys(
        2,
        (0, 1, 2),
        [
            {"time": 0, "value": [0, 0, 0], "easing": "ease"},
            {"time": 2, "value": [2, 4, 6], "easing": "step"},
            {"time": 4, "value": [0, 0, 0]},
        ],
    )
    single = channels_from_keys(5, (6,), [{"time": 10, "value": 0.25}])
    tracks = TrackSet([*lift, *pos, *single])
    assert list(tracks.rows) == [0, 2, 2, 2, 5] and list(tracks.columns) == [3, 0, 1, 2, 6]
    for t, expected in [
        (0.0, [0.0, 0, 0, 0, 0.25]),
        (2.0, [0.5, 2, 4, 6, 0.25]),
        (1.0, [0.0, 1, 2, 3, 0.25]),  # ease at u = 1/2 is 1/2
        (0.5, [0.0, 2 * 0.15625, 4 * 0.15625, 6 * 0.15625, 0.25]),
        (3.0, [1.0, 2, 4, 6, 0.25]),  # step holds
        (4.0, [1.0, 0, 0, 0, 0.25]),
        (99.0, [1.0, 0, 0, 0, 0.25]),
    ]:
        assert_allclose(tracks.evaluate(t), expected, atol=1e-12, err_msg=f"t={t}")


def test_empty_track_set() -> None:
    assert len(TrackSet([])) == 0 and TrackSet([]).evaluate(1.0).shape == (0,)


def test_keys_a_few_ulps_apart_evaluate_quietly_to_their_values() -> None:
    later = float(np.nextafter(1e-300, 1.0))
    keys = [{"time": 1e-300, "value": 2.0, "easing": "linear"}, {"time": later, "value": 5.0}]
    tracks = TrackSet(channels_from_keys(0, (0,), keys))
    with np.errstate(all="raise"):  # no overflow warning for a time far past the gap
        assert tracks.evaluate(1.0).tolist() == [5.0]
        assert tracks.evaluate(1e-300).tolist() == [2.0]
