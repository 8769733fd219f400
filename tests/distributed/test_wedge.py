"""Wedges: `--wedge PATH=VALUES` parsing, names, and refusals before anything runs."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.distributed.wedge import WedgeAxis, WedgeError, parse_parameter, variant_name
from tests.export.conftest import SMALL_SCENE


def test_parameters_parse_ranges_lists_and_json_paths() -> None:
    assert parse_parameter("seed=1..3") == WedgeAxis(("seed",), (1, 2, 3))
    strength = parse_parameter("creatures[0].tentacles.strength=20,25.5")
    assert strength == WedgeAxis(("creatures", 0, "tentacles", "strength"), (20, 25.5))
    assert strength.text == "creatures[0].tentacles.strength"
    gait = parse_parameter('creatures[1].locomotion.gait=cyclic,"coordinated"')
    assert gait.values == ("cyclic", "coordinated")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("seed", "argument --wedge: expected PATH=VALUES, got 'seed'"),
        ("seed=3..1", "argument --wedge: seed: empty range 3..1"),
        ("seed=0..99999999999", "argument --wedge: seed: 100000000000 values, more than 10000"),
        ("creatures[x]=1", "argument --wedge: 'creatures[x]' is not a JSON path like a.b[0].c"),
    ],
)
def test_bad_parameters_get_one_line(text: str, message: str) -> None:
    with pytest.raises(WedgeError, match=None) as caught:
        parse_parameter(text)
    assert str(caught.value) == message


def test_names_are_file_safe_and_say_every_value() -> None:
    values = {"seed": 3, "creatures[0].name": "a/b c", "physics.gravity": [0, 0, -9.8]}
    name = variant_name(values)
    assert name == "seed-3_creatures0.name-a_b_c_physics.gravity-_0__0__-9.8_"


@pytest.mark.parametrize(
    ("wedge", "message"),
    [
        (
            "creatures[0].tentacles.strenght=1,2",
            "error: {scene}: creatures[0].tentacles.strenght: unknown key",
        ),
        (
            "creatures[3].tentacles.strength=1",
            "error: argument --wedge: creatures[3]: no such item",
        ),
        ("seed=0,-1", "error: {scene}: seed: must be >= 0, got -1 (wedge seed=-1)"),
    ],
)
def test_a_bad_path_or_value_is_refused_before_any_bake(
    wedge: str, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "small.json"
    scene.write_text(json.dumps(SMALL_SCENE))
    out = str(tmp_path / "{name}.npz")
    code = main(["bake", str(scene), "--seconds", "0.1", "--out", out, "--wedge", wedge])
    assert code == 2
    assert capsys.readouterr().err.startswith(message.format(scene=scene))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.json"]


def test_a_local_wedge_without_ray(tmp_path: Path) -> None:
    scene = tmp_path / "small.json"
    scene.write_text(json.dumps(SMALL_SCENE))
    out = str(tmp_path / "w_{name}.npz")
    argv = ["bake", str(scene), "--seconds", "0.1", "--out", out, "--quiet"]
    assert main([*argv, "--wedge", "seed=5..6"]) == 0
    index = json.loads((tmp_path / "wedge.json").read_text())
    assert [row["file"] for row in index["outputs"]] == ["w_seed-5.npz", "w_seed-6.npz"]
    assert index["parameters"] == ["seed"]
    variant = tmp_path / "six.json"
    variant.write_text(json.dumps({**SMALL_SCENE, "seed": 6}))
    one = tmp_path / "one.npz"
    assert main(["bake", str(variant), "--seconds", "0.1", "--out", str(one), "--quiet"]) == 0
    assert one.read_bytes() == (tmp_path / "w_seed-6.npz").read_bytes()


def test_a_wedge_whose_file_names_are_too_long_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "small.json"
    scene.write_text(json.dumps(SMALL_SCENE))
    out = str(tmp_path / ("x" * 200 + "_{name}.npz"))
    argv = ["bake", str(scene), "--seconds", "0.1", "--out", out, "--quiet"]
    assert main([*argv, "--wedge", "seed=1,2", "--wedge", "description=" + "d" * 60]) == 2
    err = capsys.readouterr().err
    assert (
        err.startswith("error: argument --out: the file name of variant ") and err.count("\n") == 1
    )
    assert "more than the 255 a file name may have" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small.json"]


PLUGIN = """
from ecs_tentacles.system import System


class Still(System):
    name = "still"
    stage = "act"

    def process(self, world, dt):
        pass
"""


def test_a_wedge_of_a_scene_with_a_plugin_file_needs_and_honours_allow_systems(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "still.py").write_text(PLUGIN)
    scene = tmp_path / "small.json"
    scene.write_text(json.dumps({**SMALL_SCENE, "plugins": {"still": {"from": "still.py"}}}))
    out = str(tmp_path / "w_{name}.npz")
    argv = ["bake", str(scene), "--seconds", "0.1", "--out", out, "--quiet", "--wedge", "seed=1,2"]
    assert main(argv) == 2  # plugin code runs only when asked
    assert "--allow-systems" in capsys.readouterr().err
    assert main([*argv, "--allow-systems"]) == 0
    assert capsys.readouterr().err.splitlines() == [f"wedge: 2 variants -> {tmp_path}"]
    index = json.loads((tmp_path / "wedge.json").read_text())
    assert [row["file"] for row in index["outputs"]] == ["w_seed-1.npz", "w_seed-2.npz"]
    assert main([*argv, "--allow-systems"]) == 0  # again: says it replaces the index
    assert capsys.readouterr().err.splitlines() == [
        f"note: {tmp_path / 'wedge.json'} exists: this wedge replaces it",
        f"wedge: 2 variants -> {tmp_path}",
    ]
