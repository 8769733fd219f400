"""The sandbox's saves (Ctrl+S, the terrain section's "Save scene"): where the files go."""

from __future__ import annotations

import os
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from pyglet.window import key

from ecs_tentacles.terrain.panel import TerrainPanel
from ecs_tentacles.world import World

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


def test_the_terrain_section_saves_a_scene_with_its_files_into_another_folder(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    import json

    import numpy as np
    from PIL import Image

    from ecs_tentacles.ground import ground_of
    from ecs_tentacles.world import World

    scenes, other = tmp_path / "scenes", tmp_path / "other"
    scenes.mkdir()
    other.mkdir()
    Image.fromarray(np.tile(np.arange(16, dtype=np.uint8) * 8, (16, 1))).save(scenes / "hill.png")
    (scenes / "rock.obj").write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    )
    scene = {"version": 1, "name": "hill", "terrain": {
        "heightfield": {"size": [8, 8], "image": "hill.png", "height": 0.3},
        "obstacles": [{"shape": "mesh", "file": "rock.obj", "position": [3, 3, 0]}],
    }, "creatures": [{"name": "a", "position": [-2, -2]}]}  # fmt: skip
    (scenes / "hill.json").write_text(json.dumps(scene))
    sandbox = make_sandbox(str(scenes / "hill.json"))
    panel = sandbox.panel("Terrain")
    panel.save_path = str(other / "edited.json")
    panel.save()
    assert panel.message == f"saved {other / 'edited.json'}"
    assert sorted(p.name for p in other.iterdir()) == ["edited.json", "hill.png", "rock.obj"]
    with World.from_scene(other / "edited.json") as again:
        assert ground_of(again).digest() == ground_of(sandbox.world).digest()


@pytest.mark.parametrize("lead", ["", "a", "ab", "abc"], ids=["0", "1", "2", "3"])
def test_a_scene_named_in_many_four_byte_letters_saves_under_a_name_the_disk_takes(
    make_sandbox: Callable[..., Any],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    lead: str,
) -> None:
    # 80 letters of 4 bytes each (U+1D400, MATHEMATICAL BOLD CAPITAL A): 320 bytes, past
    # a file name's 255; `lead` moves where a byte cut falls inside a letter
    name = lead + "\U0001d400" * 80
    monkeypatch.chdir(tmp_path)
    scene = {"version": 1, "name": name, "creatures": [{"name": "a", "position": [0, 0]}]}
    sandbox = make_sandbox(scene)
    event(sandbox, "on_key_press", key.S, key.MOD_CTRL)  # Ctrl+S
    event(sandbox, "on_key_release", key.S, key.MOD_CTRL)
    ok, said = sandbox.scripts.notes[-1]
    assert ok and said.startswith("saved "), said
    panel = TerrainPanel(sandbox)
    panel.save()
    assert panel.message.startswith("saved "), panel.message
    written = sorted(os.listdir(os.fsencode(tmp_path)))  # the bytes the file system holds
    assert len(written) == 2, written
    for raw, suffix in zip(written, (b"_directed.json", b"_terrain.json"), strict=True):
        text = raw.decode("utf-8")  # whole letters only: valid UTF-8
        assert raw.endswith(suffix)
        assert len(raw) + len(b".") + len(b".01234567.partial") <= 255  # its temporary too
        assert text.startswith(lead + "\U0001d400" * 50)
        assert set(text[len(lead) : -len(suffix)]) == {"\U0001d400"}
    with World.from_scene(tmp_path / written[0].decode()) as again:
        assert again.scene is not None and again.scene["name"] == name
