"""A bake of a level records the game: the penned creatures as the take's `game` track,
and `run` reports the outcome."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.take import Take
from tests.herding.levels import level


@pytest.fixture
def penned_at_once(tmp_path: Path) -> Path:
    """A level whose pen holds creature `a` from the start: penned on the first frame."""
    scene = level(pen={"centre": [0.0, 0.0], "radius": 0.3}, need=2, seconds=10)
    path = tmp_path / "level.json"
    path.write_text(json.dumps(scene))
    return path


def test_a_bake_records_the_penned_creatures_into_the_take(
    penned_at_once: Path, tmp_path: Path
) -> None:
    out = tmp_path / "take.npz"
    argv = ["bake", str(penned_at_once), "--seconds", "0.2", "--out", str(out), "--quiet"]
    assert main(argv) == 0
    take = Take.load(out)
    assert [t["key"] for t in take.header["tracks"]] == ["game"]
    assert take.header["game"] == [{"name": "a/game/penned0", "creature": 0, "radius": 0.05}]
    live = take.tracks["game_live"]
    assert live.shape == (take.frames, 1) and live[1:].all()
    mantle = take.pos[1, take.body("a/mantle")]
    np.testing.assert_allclose(take.tracks["game_pos"][0, :2], mantle[:2], atol=0.01)


def test_run_reports_the_game(penned_at_once: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(penned_at_once), "--frames", "30", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["game_penned"] == 1 and report["game_need"] == 2 and report["game_won"] == 0
