"""Terrain inputs cost a bounded time and memory, and bad ones are refused in one line
naming the field, by `validate` as by `run`: meshes (coordinates, volume, decomposition
budget, one decomposition per distinct file), height images (real PNGs, side caps,
decompression bombs, heights clamped) and big `heights` arrays."""

from __future__ import annotations

import json
import pathlib
import sys
from typing import Any

import numpy as np
import pytest

from ecs_tentacles.cli import main


def scene(terrain: dict[str, Any]) -> dict[str, Any]:
    return {"version": 1, "terrain": terrain, "creatures": [{"name": "c0", "position": [0, 0]}]}


def write_scene(folder: pathlib.Path, terrain: dict[str, Any]) -> pathlib.Path:
    path = folder / "scene.json"
    path.write_text(json.dumps(scene(terrain)))
    return path


class TooManyCalls(Exception):
    pass


def test_a_million_heights_validate_without_a_python_call_per_number(
    tmp_path: pathlib.Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """1024 x 1024 `heights` (the schema's largest) are checked with numpy, not number by
    number (31 s before); a bad one among them is still named by its path."""
    heights = (np.arange(1024 * 1024).reshape(1024, 1024) % 7).tolist()
    path = write_scene(tmp_path, {"heightfield": {"size": [10, 10], "heights": heights}})
    assert main(["validate", str(path)]) == 0  # imports and caches warmed
    capsys.readouterr()
    calls = 0

    def count(frame: object, event: str, arg: object) -> None:
        nonlocal calls
        if event == "call":
            calls += 1
            if calls > 1_000_000:  # one per number: stop there
                raise TooManyCalls

    sys.setprofile(count)
    try:
        code = main(["validate", str(path)])
    finally:
        sys.setprofile(None)
    assert code == 0 and calls < 1_000_000
    assert "ok" in capsys.readouterr().out
    heights[700][300] = 1000.5
    path.write_text(json.dumps(scene({"heightfield": {"size": [10, 10], "heights": heights}})))
    assert main(["validate", str(path)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert lines == [
        f"error: {path}: terrain.heightfield.heights[700][300]: must be in [-1000, 1000],"
        " got 1000.5"
    ]
