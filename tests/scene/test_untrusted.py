"""Scenes are untrusted input: odd files, deep nesting, huge arrays and 8.0 integers.

Each case is refused with one line naming the file or JSON path, quickly and without
blocking (a FIFO with no writer, /dev/zero) or recursing (10 000 levels of nesting).
"""

from __future__ import annotations

import copy
import os
import signal
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ecs_tentacles.scene import load as load_module
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.scene.validate import MAX_DEPTH, validate_scene
from ecs_tentacles.world import World

BASE: dict[str, Any] = {"version": 1, "creatures": [{"name": "octo"}]}


@pytest.fixture(autouse=True)
def _no_hang() -> Iterator[None]:
    """A regression that blocks (a FIFO read) fails the test instead of hanging the suite."""

    def stop(signum: int, frame: object) -> None:
        raise TimeoutError("blocked")

    previous = signal.signal(signal.SIGALRM, stop)
    signal.alarm(20)
    yield
    signal.alarm(0)
    signal.signal(signal.SIGALRM, previous)


def problems(source: object) -> list[str]:
    with pytest.raises(SceneError) as caught:
        load_scene(source)  # type: ignore[arg-type]
    return caught.value.problems


def nested(depth: int) -> dict[str, Any]:
    value: Any = 1
    for _ in range(depth):
        value = {"a": value}
    return {**BASE, "extra": value}


def test_a_fifo_without_writer_is_refused_without_blocking(tmp_path: Path) -> None:
    fifo = tmp_path / "scene.json"
    os.mkfifo(fifo)
    assert problems(fifo) == [f"{fifo}: cannot read scene: a FIFO, not a regular file"]


def test_a_device_and_a_folder_are_refused(tmp_path: Path) -> None:
    assert problems(Path("/dev/zero")) == [
        "/dev/zero: cannot read scene: a device or socket, not a regular file"
    ]
    assert problems(tmp_path) == [f"{tmp_path}: cannot read scene: a folder, not a regular file"]


def test_the_size_cap_refuses_big_files_and_can_be_raised(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(load_module, "MAX_SCENE_BYTES", 1024)
    big = tmp_path / "big.json"
    big.write_text('{"version": 1, "creatures": [{"name": "octo"}]}' + " " * 1024)
    assert problems(big) == [
        f"{big}: cannot read scene: larger than 0.000976562 MB (raise the limit with"
        " --max-scene-mb)"
    ]
    monkeypatch.setattr(load_module, "MAX_SCENE_BYTES", 4096)
    assert load_scene(big)["creatures"][0]["name"] == "octo"


@pytest.mark.parametrize("depth", [MAX_DEPTH + 1, 990, 10_000])
def test_deep_nesting_in_a_file_is_one_line(tmp_path: Path, depth: int) -> None:
    path = tmp_path / "deep.json"
    path.write_text('{"version": 1, "creatures": [], "x": ' + "[" * depth + "]" * depth + "}")
    (line,) = problems(path)
    assert line.startswith(f"{path}: ") and "nested" in line


def test_deep_nesting_in_a_dict_never_recurses() -> None:
    (line,) = problems(nested(10_000))
    assert line == "extra" + ".a" * MAX_DEPTH + f": nested deeper than {MAX_DEPTH} levels"
    with pytest.raises(SceneError):
        World.from_scene(nested(10_000))
    assert validate_scene(nested(MAX_DEPTH - 2))[0].startswith("extra: unknown key")


def test_a_million_goals_is_refused_in_well_under_a_second() -> None:
    scene = copy.deepcopy(BASE)
    scene["creatures"][0]["goals"] = [{"position": [1.0, 0.0]}] * 1_050_000
    start = time.perf_counter()
    assert validate_scene(scene) == [
        "creatures[0].goals: must have at most 1024 items, got 1050000"
    ]
    assert time.perf_counter() - start < 5  # was more than 175 s


def test_a_crowd_above_the_creature_limit_is_one_line_before_validating_creatures() -> None:
    crowd = {"version": 1, "creatures": [{"name": "octo", "mantle": "big"}] * 16385}
    assert validate_scene(crowd) == ["creatures: must have at most 16384 items, got 16385"]
    crowd["creatures"] = crowd["creatures"][:10_000]  # 10,000 are allowed: the bad mantles tell
    assert validate_scene(crowd)[0] == 'creatures[0].mantle: must be an object, got "big"'


INTEGERS_AS_FLOATS = [
    ("seed", {"seed": 8.0}),
    ("creatures[0].tentacles.count", {"tentacles": {"count": 8.0}}),
    ("creatures[0].tentacles.links", {"tentacles": {"links": 8.0}}),
    (
        "creatures[0].tentacles.overrides[0].links",
        {"tentacles": {"overrides": [{"index": 0, "links": 8.0}]}},
    ),
    (
        "creatures[0].tentacles.overrides[0].index",
        {"tentacles": {"overrides": [{"index": 1.0}]}},
    ),
    ("creatures[0].fur.groom.count", {"fur": {"preset": "hedgehog", "groom": {"count": 8.0}}}),
    ("creatures[0].fur.groom.points", {"fur": {"preset": "hedgehog", "groom": {"points": 8.0}}}),
    ("creatures[0].fur.groom.seed", {"fur": {"preset": "hedgehog", "groom": {"seed": 7.0}}}),
]


@pytest.mark.parametrize(
    ("where", "change"), INTEGERS_AS_FLOATS, ids=[c[0] for c in INTEGERS_AS_FLOATS]
)
def test_integers_written_as_floats_are_refused_with_their_path(
    where: str, change: dict[str, Any]
) -> None:
    scene = copy.deepcopy(BASE)
    if where == "seed":
        scene.update(change)
    else:
        scene["creatures"][0].update(change)
    got = "8.0" if "8.0" in repr(change) else ("1.0" if "1.0" in repr(change) else "7.0")
    assert validate_scene(scene) == [f"{where}: must be an integer, got {got}"]


@pytest.mark.parametrize("bad", [float("nan"), float("inf")])
def test_a_scene_given_as_data_with_a_value_that_is_not_finite_is_refused(bad: float) -> None:
    """A file cannot hold NaN (the loader refuses the literal), but a dict from Python can."""
    scene = copy.deepcopy(BASE)
    scene["creatures"][0]["position"] = [0.0, bad]
    scene["creatures"][0]["tentacles"] = {"strength": bad}
    shown = "NaN" if bad != bad else "Infinity"
    assert validate_scene(scene) == [
        f"creatures[0].position[1]: must be a finite number, got {shown}",
        f"creatures[0].tentacles.strength: must be a finite number, got {shown}",
    ]
    with pytest.raises(SceneError, match="must be a finite number"):
        World.from_scene(scene)
