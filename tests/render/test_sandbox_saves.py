"""The sandbox's saves (Ctrl+S, the terrain section's "Save scene"): where the files go."""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from pyglet.window import key

from ecs_tentacles.terrain.panel import TerrainPanel

from .conftest import event

SAFE = re.compile(r"^[\w][\w.-]*$")


def _files(folder: Path) -> list[Path]:
    return sorted(p for p in folder.rglob("*") if p.is_file())


@pytest.mark.parametrize(
    "name",
    ["../escaped", "ABSOLUTE", "two\nlines \x1b[31mred\x1b[0m", "nul\x00name", "..", "/", ""],
)
def test_a_scene_name_never_chooses_the_folder_or_odd_characters_of_a_save(
    make_sandbox: Callable[..., Any],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    name: str,
) -> None:
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    if name == "ABSOLUTE":
        name = str(tmp_path / "elsewhere" / "abs")
        (tmp_path / "elsewhere").mkdir()
    scene = {"version": 1, "name": name, "creatures": [{"name": "a", "position": [0, 0]}]}
    sandbox = make_sandbox(scene)
    event(sandbox, "on_key_press", key.S, key.MOD_CTRL)  # Ctrl+S
    event(sandbox, "on_key_release", key.S, key.MOD_CTRL)
    panel = TerrainPanel(sandbox)  # as the HUD makes it: its save box filled in
    assert SAFE.fullmatch(panel.save_path), panel.save_path
    panel.save()
    assert panel.message.startswith("saved "), panel.message
    written = _files(tmp_path)
    assert [p.parent for p in written] == [work, work], written  # both in the working folder
    for path in written:
        assert SAFE.fullmatch(path.name), path.name  # one plain name: no separators, controls
    expected = {"../escaped": "escaped", "nul\x00name": "nul_name"}.get(name, "scene")
    if name.endswith("abs"):
        expected = "abs"
    elif name.startswith("two"):
        expected = "two_lines_red"
    assert sorted(p.name for p in written) == [
        f"{expected}_directed.json",
        f"{expected}_terrain.json",
    ]
