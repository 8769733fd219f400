"""The palette lists bundled creatures, the generator's species, exported creatures, threats."""

from __future__ import annotations

import json
import logging
from pathlib import Path

import pytest

from ecs_tentacles.director.palette import presets
from ecs_tentacles.world import World


def test_the_palette_lists_every_kind_and_each_one_spawns(tmp_path: Path, monkeypatch) -> None:
    folder = tmp_path / "creatures"
    folder.mkdir()
    mine = {"version": 1, "creatures": [{"name": "blob", "tentacles": {"count": 3}}]}
    (folder / "blob.json").write_text(json.dumps(mine))
    monkeypatch.chdir(tmp_path)
    found = presets(tmp_path)
    labels = [p.label for p in found]
    assert labels[0] == "octopus/octopus"
    assert "species 1" in labels and "species 8" in labels
    assert "blob/blob" in labels and labels[-1] == "roach"
    assert labels.count("blob/blob") == 1  # the scene folder and the working folder are one
    assert found[-1].is_threat and not found[0].is_threat
    with World.from_scene({"version": 1, "creatures": [{"name": "x", "position": [90, 90]}]}) as w:
        for i, preset in enumerate(p for p in found if not p.is_threat):
            w.spawn(preset.creature(), position=(12.0 * i, 0.0))  # every one is a valid entry
        w.step(2)


def test_a_file_that_does_not_load_is_skipped_with_one_line(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    folder = tmp_path / "creatures"
    folder.mkdir()
    (folder / "broken.json").write_text("{not json")
    with caplog.at_level(logging.WARNING, logger="ecs_tentacles.director"):
        labels = [p.label for p in presets(tmp_path)]
    assert not any(label.startswith("broken/") for label in labels)
    assert any("broken.json skipped" in r.message for r in caplog.records)
