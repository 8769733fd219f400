"""JSON a file may lie in: parsed as `json` does, or refused in one line naming where."""

from __future__ import annotations

import json

import pytest

from ecs_tentacles.untrusted.bounded_json import JsonLimit, loads

SOUND = {"fps": 30.0, "seed": 2**63 - 1, "bodies": [{"radius": 0.05, "tip": [1, -2.5e-3]}]}


def test_sound_json_reads_as_json_reads_it() -> None:
    text = json.dumps(SOUND)
    assert loads(text, "header", max_bytes=len(text)) == json.loads(text) == SOUND
    assert loads(b"[1.5, -7]", "x", max_bytes=9) == [1.5, -7]


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ('{"fps": 1' + "0" * 400 + "}", "header.fps: a number of 401 characters, at most 100"),
        (
            '{"b": [{"r": -1e' + "0" * 120 + "}]}",
            "header.b[0].r: a number of 123 characters, at most 100",
        ),
        ('{"a b": 0.' + "5" * 200 + "}", 'header["a b"]: a number of 202 characters, at most 100'),
        ("9" * 101, "header: a number of 101 characters, at most 100"),
        ("[" * 65 + "]" * 65, "header: nested deeper than 64 levels"),
        ('{"x": ' + "[" * 50_000 + "]" * 50_000 + "}", "header: nested deeper than 64 levels"),
    ],
)
def test_a_long_number_or_deep_nesting_is_refused_naming_where(text: str, said: str) -> None:
    with pytest.raises(JsonLimit) as refused:
        loads(text, "header", max_bytes=1 << 20)
    assert str(refused.value) == said


def test_the_limits_are_inclusive_and_size_is_checked_first() -> None:
    deepest = "[" * 64 + "]" * 64
    assert loads(deepest, "h", max_bytes=128) == json.loads(deepest)
    assert loads("9" * 100, "h", max_bytes=100) == int("9" * 100)
    with pytest.raises(JsonLimit, match=r"^h: larger than 99 bytes$"):
        loads("9" * 100, "h", max_bytes=99)


def test_malformed_json_stays_a_decode_error() -> None:
    with pytest.raises(json.JSONDecodeError):
        loads('{"fps": }', "header", max_bytes=100)
