"""FurEditor without a window: deleting, keys on twins, bad input, invalid saves."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest
from numpy.testing import assert_allclose

from ecs_tentacles.fur.editor import FurEditor
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.world import World
from tests.conftest import NO_LOCOMOTION


@pytest.fixture
def editor() -> Any:
    """An editor over the bundled hedgehog, rebuilding worlds as the sandbox would."""
    made: list[World] = []

    def rebuild(scene: dict[str, Any]) -> World:
        made[-1].close()
        made.append(World.from_scene(scene, plugins=NO_LOCOMOTION))
        return made[-1]

    made.append(World.from_scene("hedgehog_octopus", plugins=NO_LOCOMOTION))
    yield FurEditor(made[-1], rebuild)
    made[-1].close()


def test_delete_keeps_one_control_and_removes_twins(editor: FurEditor) -> None:
    editor.create("L_fin", mirror="y")
    assert editor.control_names() == ["crown", "spine", "L_fin", "R_fin"]
    editor.delete("R_fin")  # a twin goes with its original
    assert editor.control_names() == ["crown", "spine"]
    assert len(editor.world.resource(FurData).controls) == 2  # the world was rebuilt without them
    editor.delete("spine")
    with pytest.raises(ValueError, match="at least one control"):
        editor.delete("crown")
    with pytest.raises(ValueError, match="bad control"):
        editor.create("x", shape="blob")
    with pytest.raises(KeyError, match="no control named 'nope'"):
        editor.set_value("nope", "lift", 0.5)


def test_keys_on_a_twin_go_to_its_original_mirrored(editor: FurEditor) -> None:
    editor.create("L_fin", mirror="y")
    editor.set_position("R_fin", [0.02, -0.1, 0.25])
    editor.set_key("R_fin", "position", 1.0, "linear")
    (track,) = editor.source("L_fin")[0]["tracks"]
    assert track["keys"] == [{"time": 1.0, "value": [0.02, 0.1, 0.25], "easing": "linear"}]
    assert editor.keys("R_fin", "position")[0]["value"] == [0.02, -0.1, 0.25]
    editor.set_value("L_fin", "lift", 0.3)
    editor.set_key("L_fin", "lift", 1.0)
    editor.set_value("L_fin", "lift", 0.7)
    editor.set_key("L_fin", "lift", 1.0 + 1e-9)  # the same time: replaces
    assert [k["value"] for k in editor.keys("L_fin", "lift")] == [0.7]
    world = editor.world
    rows = editor.rows()
    world.step(1)
    assert (
        world.resource(FurData).controls.lift[rows["R_fin"]] == 0.7
    )  # the twin plays the same track
    assert_allclose(world.resource(FurData).controls.position[rows["R_fin"]], [0.02, -0.1, 0.25])
    assert not editor.delete_key("L_fin", "lift", 1.5, within=0.1)
    assert editor.delete_key("L_fin", "lift", 1.05, within=0.1)
    assert editor.keys("L_fin", "lift") == []


def test_an_invalid_scene_is_not_saved(editor: FurEditor, tmp_path: Path) -> None:
    scene = copy.deepcopy(editor.scene)
    editor.fur_spec()["controls"][0]["lift"] = 2.0  # out of range: the schema says so
    with pytest.raises(SceneError, match=r"controls\[0\]\.lift"):
        editor.save(tmp_path / "bad.json")
    assert list(tmp_path.iterdir()) == []
    editor.scene = scene
    assert editor.save(tmp_path / "good.json").exists()
