"""HUD knobs: their sliders span exactly the API's (the schema's) ranges."""

from __future__ import annotations

import pytest

from ecs_tentacles.locomotion.params import TENTACLE_RANGES
from ecs_tentacles.render.hud import KNOBS, Knob


@pytest.mark.parametrize("knob", KNOBS, ids=[k.name for k in KNOBS])
def test_each_slider_spans_the_range_and_round_trips(knob: Knob) -> None:
    allowed = TENTACLE_RANGES[knob.name]
    assert knob.value(100) == allowed.high
    assert knob.value(0) in allowed  # an open lower bound (speed > 0) is never reached
    assert knob.value(0) - allowed.low <= 1e-3 * (allowed.high - allowed.low)
    for position in (0.0, 12.5, 50.0, 99.0, 100.0):
        assert knob.slider(knob.value(position)) == pytest.approx(position, abs=1e-9)


def test_the_strength_slider_gives_the_default_room() -> None:
    (strength,) = [k for k in KNOBS if k.name == "strength"]
    assert 25 < strength.slider(25.0) < 35  # kp 25 (the default) sits a quarter of the way
