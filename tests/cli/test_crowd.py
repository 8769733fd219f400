"""`ecs-tentacles crowd`: writes a valid scene, same seed same bytes, one-line errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.scene.load import load_scene
from tests.cli.conftest import refused


def test_writes_a_valid_scene_and_says_what_is_in_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "crowd.json"
    assert main(["crowd", "12", "--out", str(out), "--seed", "3", "--idle", "0.25"]) == 0
    scene = load_scene(out)
    furry = sum("fur" in c for c in scene["creatures"])
    idle = sum(not c["goals"] for c in scene["creatures"])
    assert (len(scene["creatures"]), idle) == (12, 3)
    assert capsys.readouterr().out == f"{out}: 12 creatures ({furry} with fur, 3 idle)\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["crowd.json"]  # no temporary left


def test_same_seed_writes_the_same_bytes(tmp_path: Path) -> None:
    files = {name: tmp_path / f"{name}.json" for name in ("a", "b", "c")}
    for name, seed in (("a", "9"), ("b", "9"), ("c", "10")):
        assert main(["crowd", "17", "--out", str(files[name]), "--seed", seed]) == 0
    assert files["a"].read_bytes() == files["b"].read_bytes()
    assert files["a"].read_bytes() != files["c"].read_bytes()
    assert json.loads(files["a"].read_text())["seed"] == 9


def test_spacing_option_places_the_grid(tmp_path: Path) -> None:
    out = tmp_path / "wide.json"
    assert main(["crowd", "2", "--out", str(out), "--spacing", "10"]) == 0
    (x0, y0), (x1, y1) = (c["position"] for c in json.loads(out.read_text())["creatures"])
    assert 8.0 <= x1 - x0 <= 12.0 and abs(y1 - y0) <= 2.0  # jitter <= 0.1 x spacing


def test_too_small_spacing_is_one_line_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "tight.json"
    assert main(["crowd", "4", "--out", str(out), "--spacing", "0.5"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --spacing: must be >= ") and err.endswith(", got 0.5\n")
    assert err.count("\n") == 1 and not out.exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["crowd", "0", "--out", "x.json"], "argument N: must be >= 1, got 0"),
        (["crowd", "20000", "--out", "x.json"], "argument N: must be <= 16384 (the most creatures"),
        (["crowd", "many", "--out", "x.json"], "argument N: must be a whole number, got 'many'"),
        (["crowd", "3", "--out", "x.txt"], "argument --out: must end in .json, got 'x.txt'"),
        (["crowd", "3", "--out", "x.json", "--idle", "2"], "argument --idle: must be in [0, 1]"),
        (["crowd", "3"], "the following arguments are required: --out"),
    ],
)
def test_bad_arguments_are_one_line_exit_2(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    err = refused(argv, capsys)
    assert err.startswith("error: ") and message in err
    assert err.count("\n") == 1
