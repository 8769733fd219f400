"""The command line: validate, run, exit codes, one-line errors, no tracebacks."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.scene.load import bundled_scene, bundled_scene_names
from tests.cli.conftest import refused
from tests.scene.bad_scenes import BAD_SCENES

BUNDLED = {
    "asymmetric": "1 creature, 5 tentacles",
    "octopus": "1 creature, 8 tentacles",
    "thesis_four_by_six": "4 creatures, 24 tentacles",
    "three_goals": "1 creature, 6 tentacles",
}


def test_the_issue_scenes_are_bundled() -> None:
    assert set(BUNDLED) <= set(bundled_scene_names())


@pytest.mark.parametrize("name", sorted(BUNDLED))
def test_validate_accepts_every_bundled_scene(
    name: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["validate", name]) == 0
    assert capsys.readouterr().out == f"{bundled_scene(name)}: ok ({BUNDLED[name]})\n"


def test_validate_reports_each_problem_and_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "bad.json"
    scene.write_text(json.dumps({"version": 1, "creatures": [{"tentacles": {"end_scale": 1.7}}]}))
    assert main(["validate", str(scene), str(bundled_scene("octopus"))]) == 2
    captured = capsys.readouterr()
    assert (
        captured.err
        == f"error: {scene}: creatures[0].tentacles.end_scale: must be in (0, 1], got 1.7\n"
    )
    assert "octopus.json: ok (1 creature, 8 tentacles)" in captured.out


def test_run_prints_one_json_summary(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "octopus", "--frames", "12", "--json", "--quiet", "--seed", "7"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["frames"] == 12 and summary["seed"] == 7
    assert summary["sim_seconds"] == pytest.approx(0.2)
    assert summary["real_time_factor"] == pytest.approx(
        summary["sim_seconds"] / summary["wall_seconds"], rel=0.01
    )
    assert (summary["creatures"], summary["bodies"], summary["recoveries"]) == (1, 81, 0)
    assert (summary["goals_reached"], summary["goals_left"]) == (0, 1)  # 0.2 s is not enough


def test_run_human_summary(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", "three_goals", "--frames", "6", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "6 frames, 0.10 s simulated in" in out and "real-time factor" in out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["run", "octopus", "--frames", "0"], "argument --frames: must be >= 1, got 0"),
        (
            ["run", "octopus", "--frames", "ten"],
            "argument --frames: must be a whole number, got 'ten'",
        ),
        (["run", "octopus", "--seed", "-1"], "argument --seed: must be >= 0, got -1"),
    ],
)
def test_bad_arguments_exit_2(
    argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    assert message in refused(argv, capsys)


def test_bad_scene_in_a_real_process_has_no_traceback(tmp_path: Path) -> None:
    scene = tmp_path / "bad.json"
    scene.write_text('{"version": 1, "creatures": [{"tentacles": {"links": 0}}], "colour": 1}')
    result = subprocess.run(
        [sys.executable, "-m", "ecs_tentacles.cli", "run", str(scene), "--frames", "5"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 2
    assert result.stdout == ""
    assert result.stderr.splitlines() == [
        f"error: {scene}: colour: unknown key (allowed: $schema, avoidance, creatures,"
        " description, name, physics, plugins, render, seed, shards, systems, terrain, threats,"
        " version)",
        f"error: {scene}: creatures[0].tentacles.links: must be in [1, 64], got 0",
    ]
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize(
    ("data", "expected"),
    [pytest.param(data, expected, id=name) for name, data, expected in BAD_SCENES],
)
def test_every_bad_scene_exits_2_with_its_json_path(
    data: object, expected: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "bad.json"
    scene.write_text(json.dumps(data))
    assert main(["run", str(scene), "--frames", "1", "--quiet"]) == 2
    captured = capsys.readouterr()
    assert captured.err == f"error: {scene}: {expected}\n"
    assert captured.out == ""


def test_validate_names_the_systems_a_scene_asks_for(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "systems.json"
    scene.write_text(
        json.dumps({"version": 1, "systems": ["mine.wiggle:Wiggle"], "creatures": [{}]})
    )
    assert main(["validate", str(scene)]) == 0
    assert capsys.readouterr().out == (
        f"{scene}: ok (1 creature, 8 tentacles); asks to run systems mine.wiggle:Wiggle"
        " (run, bake and play need --allow-systems)\n"
    )
    assert main(["validate", "--json", str(scene)]) == 0
    assert json.loads(capsys.readouterr().out) == {
        "scene": str(scene),
        "ok": True,
        "creatures": 1,
        "tentacles": 8,
        "systems": ["mine.wiggle:Wiggle"],
        "plugins": ["locomotion", "suckers", "threats", "fur", "clips", "terrain"],
    }


def test_the_scene_size_cap_has_an_override(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "padded.json"
    scene.write_text(json.dumps({"version": 1, "creatures": [{}]}) + " " * (17 << 20))
    assert main(["validate", str(scene)]) == 2
    assert capsys.readouterr().err == (
        f"error: {scene}: cannot read scene: larger than 16 MB (raise the limit with"
        " --max-scene-mb)\n"
    )
    assert main(["--max-scene-mb", "18", "validate", str(scene)]) == 0


def test_every_reporting_command_has_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    take, glb, scene = tmp_path / "t.npz", tmp_path / "t.glb", tmp_path / "c.json"
    base = ["three_goals", "--seconds", "0.05", "--out", str(take), "--quiet"]
    assert main(["bake", *base, "--json"]) == 0
    baked = json.loads(capsys.readouterr().out)
    assert (baked["out"], baked["frames"], baked["creatures"]) == (str(take), 4, 1)
    assert main(["export", str(take), "--out", str(glb), "--quiet", "--json"]) == 0
    exported = json.loads(capsys.readouterr().out)
    assert exported["out"] == str(glb) and exported["frames"] == 4
    assert len(exported["sha256"]) == 64
    assert main(["create", "--tentacles", "3", "--out", str(scene), "--json"]) == 0
    created = json.loads(capsys.readouterr().out)
    assert (created["scene"], created["tentacles"]) == (str(scene), 3)
    assert main(["run", str(scene), "--frames", "2", "--quiet", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["frames"] == 2


def test_the_module_docstring_names_every_command() -> None:
    import ecs_tentacles.cli as cli

    parser = cli.build_parser()
    (commands,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    first_line = " ".join((cli.__doc__ or "").split("\n\n")[0].split())
    named = first_line.split(":", 1)[1].strip(" .").split(", ")
    assert named == list(commands.choices)


def test_validate_json_reports_a_bad_scene_as_json_too(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "bad.json"
    scene.write_text(json.dumps({"version": 1, "creatures": [{"mantle": {"radius": -1}}]}))
    assert main(["validate", "--json", str(scene), "octopus"]) == 2
    captured = capsys.readouterr()
    first, second = (json.loads(line) for line in captured.out.splitlines())
    assert first["ok"] is False and first["scene"] == str(scene)
    assert first["problems"] == [line.removeprefix("error: ") for line in captured.err.splitlines()]
    assert first["problems"] and second["ok"] is True and second["creatures"] == 1


def test_shared_options_work_after_the_command_and_on_every_simulating_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["validate", "octopus", "--debug", "--max-scene-mb", "1"]) == 0
    capsys.readouterr()
    hashes = []
    for threads in ("1", "2"):
        out = tmp_path / f"t{threads}.npz"
        argv = ["bake", "three_goals", "--seconds", "0.1", "--out", str(out), "--quiet"]
        assert main([*argv, "--threads", threads, "--json"]) == 0
        hashes.append(json.loads(capsys.readouterr().out)["sha256"])
    assert hashes[0] == hashes[1]  # results do not depend on the thread count
    shot = tmp_path / "shot.png"
    argv = ["play", "three_goals", "--headless", "--frames", "2", "--quiet", "--threads", "1"]
    assert main([*argv, "--width", "320", "--height", "180", "--screenshot", str(shot)]) == 0
    assert shot.is_file()
