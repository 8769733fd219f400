"""load_scene, bundled_scene, resolve_scene_path and SceneError."""

from __future__ import annotations

import json
import pathlib
import sys

import pytest

from ecs_tentacles.scene import load as load_module
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import (
    bundled_scene,
    bundled_scene_names,
    load_scene,
    resolve_scene_path,
)


def write(path: pathlib.Path, text: str) -> pathlib.Path:
    path.write_text(text, encoding="utf-8")
    return path


def problems_of(source: object) -> list[str]:
    with pytest.raises(SceneError) as info:
        load_scene(source)  # type: ignore[arg-type]
    return info.value.problems


def test_scene_error_str_is_the_lines() -> None:
    err = SceneError(["a: one", "b: two"])
    assert err.problems == ["a: one", "b: two"]
    assert str(err) == "a: one\nb: two"
    assert str(SceneError("just one")) == "just one"


def test_load_from_file_fills_defaults(tmp_path: pathlib.Path) -> None:
    path = write(tmp_path / "s.json", '{"version": 1, "creatures": [{"name": "octo"}]}')
    data = load_scene(path)
    assert data["creatures"][0]["name"] == "octo"
    assert data["creatures"][0]["tentacles"]["end_scale"] == 0.3
    assert data["physics"]["substeps"] == 8
    assert load_scene(str(path)) == data


def test_load_from_dict_does_not_modify_it() -> None:
    source = {"version": 1, "creatures": [{}]}
    data = load_scene(source)
    assert source == {"version": 1, "creatures": [{}]}
    assert data["creatures"][0]["name"] == "creature_0"


def test_dict_problems_have_no_prefix() -> None:
    assert problems_of({"version": 2}) == ["version: must be 1, got 2"]


def test_file_problems_are_prefixed_with_the_path(tmp_path: pathlib.Path) -> None:
    path = write(tmp_path / "bad.json", json.dumps({"physics": {"fps": 0}}))
    assert problems_of(path) == [
        f"{path}: physics.fps: must be in [4, 1000], got 0",
        f"{path}: version: is required",
    ]


def test_json_syntax_error_reports_line_and_column(tmp_path: pathlib.Path) -> None:
    path = write(tmp_path / "broken.json", '{\n  "version": 1,\n  "seed": ,\n}')
    assert problems_of(path) == [f"{path}:3:11: invalid JSON: Expecting value"]


def test_missing_file(tmp_path: pathlib.Path) -> None:
    path = tmp_path / "nope.json"
    assert problems_of(path) == [f"{path}: cannot read scene: No such file or directory"]


def test_directory_is_not_a_scene(tmp_path: pathlib.Path) -> None:
    assert problems_of(tmp_path) == [f"{tmp_path}: cannot read scene: a folder, not a regular file"]


def test_not_utf8(tmp_path: pathlib.Path) -> None:
    path = tmp_path / "latin1.json"
    path.write_bytes(b'{"version": 1, "name": "caf\xe9"}')
    assert problems_of(path) == [
        f"{path}: cannot read scene: not UTF-8 text (invalid continuation byte)"
    ]


def test_top_level_not_an_object(tmp_path: pathlib.Path) -> None:
    path = write(tmp_path / "list.json", "[1, 2]")
    assert problems_of(path) == [f"{path}: scene: must be an object, got [1, 2]"]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('{"version": 1, "seed": NaN}', "NaN is not valid JSON"),
        ('{"version": 1, "physics": {"fps": Infinity}}', "Infinity is not valid JSON"),
        ('{"version": 1, "physics": {"fps": 1e400}}', "number 1e400 is too large"),
    ],
)
def test_non_finite_numbers_are_refused(tmp_path: pathlib.Path, text: str, message: str) -> None:
    path = write(tmp_path / "nan.json", text)
    assert problems_of(path) == [f"{path}: invalid JSON: {message}"]


def test_byte_order_mark_is_accepted(tmp_path: pathlib.Path) -> None:
    path = tmp_path / "bom.json"
    path.write_bytes(b'\xef\xbb\xbf{"version": 1}')
    assert load_scene(path)["seed"] == 0


def test_systems_are_not_imported(tmp_path: pathlib.Path) -> None:
    path = write(tmp_path / "s.json", '{"version": 1, "systems": ["antigravity:Fly"]}')
    assert load_scene(path)["systems"] == ["antigravity:Fly"]
    assert "antigravity" not in sys.modules


@pytest.fixture
def scenes_dir(tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch) -> pathlib.Path:
    folder = tmp_path / "scenes"
    folder.mkdir()
    write(folder / "octopus.json", '{"version": 1}')
    write(folder / "duel.json", '{"version": 1}')
    monkeypatch.setattr(load_module, "_scenes_dir", lambda: folder)
    return folder


def test_bundled_scene_by_name(scenes_dir: pathlib.Path) -> None:
    assert bundled_scene("octopus") == scenes_dir / "octopus.json"
    assert bundled_scene("octopus.json") == scenes_dir / "octopus.json"
    assert bundled_scene_names() == ["duel", "octopus"]


@pytest.mark.parametrize("name", ["squid", "../octopus", "/etc/passwd", ""])
def test_unknown_bundled_scene(scenes_dir: pathlib.Path, name: str) -> None:
    with pytest.raises(SceneError) as info:
        bundled_scene(name)
    assert info.value.problems == [f"{name}: no such bundled scene (available: duel, octopus)"]


@pytest.fixture
def here(tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch) -> pathlib.Path:
    """The test's folder, made the working folder (relative paths resolve in it)."""
    monkeypatch.chdir(tmp_path)
    return tmp_path


def test_resolve_scene_path(scenes_dir: pathlib.Path, here: pathlib.Path) -> None:
    write(here / "mine.json", '{"version": 1}')
    assert resolve_scene_path("mine.json") == pathlib.Path("mine.json")
    assert resolve_scene_path("octopus") == scenes_dir / "octopus.json"
    assert resolve_scene_path("nowhere.json") == pathlib.Path("nowhere.json")
    assert problems_of(resolve_scene_path("nowhere.json")) == [
        "nowhere.json: no such file or bundled scene"
    ]
    assert problems_of(resolve_scene_path("octopuss")) == [
        "octopuss: no such file or bundled scene; did you mean 'octopus'?"
    ]


@pytest.mark.usefixtures("scenes_dir")
def test_existing_path_wins_over_bundled_name(here: pathlib.Path) -> None:
    write(here / "octopus", '{"version": 1}')
    assert resolve_scene_path("octopus") == pathlib.Path("octopus")


@pytest.mark.parametrize("name", bundled_scene_names())
def test_every_bundled_scene_loads(name: str) -> None:
    assert load_scene(bundled_scene(name))["version"] == 1


def test_one_run_reports_the_problems_of_every_stage(tmp_path: pathlib.Path) -> None:
    scene = {
        "version": 1,
        "plugins": {"wobble": True},  # stage 1: no such plugin
        "physics": {"gravity": [0, 0, 9.81]},  # stage 4: gravity points up
        "creatures": [
            {"name": "a", "position": [0, 0], "mantle": {"radius": -1}},  # stage 2: schema
            {"name": "a", "position": [3, 0]},  # stage 3: a duplicate name
            {"name": "b", "position": [0.05, 0]},  # stage 4: overlaps the first
        ],
    }
    path = tmp_path / "nine.json"
    path.write_text(json.dumps(scene))
    with pytest.raises(SceneError) as caught:
        load_scene(path)
    lines = caught.value.problems
    assert len(lines) == len(set(lines))
    wanted = [
        "plugins.wobble: ",
        "creatures[0].mantle.radius: must be ",
        'creatures[1].name: duplicate name "a"',
        "physics.gravity: points up",
    ]
    for start in wanted:
        assert any(line.startswith(f"{path}: {start}") for line in lines), (start, lines)
