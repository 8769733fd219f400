"""A game mode from a plugin file beside its level (the docs' `sprint.py`,
docs/extending/game-modes.md): it registers, its keys are checked, and it ends `run`
(`tests/data/sprint/`, the page's two files as the page shows them)."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

from ecs_tentacles.cli import main

SPRINT = Path(__file__).resolve().parents[1] / "data" / "sprint"
PAGE = Path(__file__).resolve().parents[2] / "docs" / "extending" / "game-modes.md"


def test_the_files_are_the_page_s() -> None:
    blocks = re.findall(r"<!-- file: (\S+) -->\n```\w+\n(.*?)```", PAGE.read_text(), flags=re.S)
    files = ("sprint.py", "sprint.json")
    assert dict(blocks) == {name: (SPRINT / name).read_text() for name in files}


def test_a_mode_from_a_file_ends_the_run_and_reports_its_result(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    folder = shutil.copytree(SPRINT, tmp_path / "sprint")
    level = str(folder / "sprint.json")
    argv = ["run", level, "--allow-systems", "--frames", "1800", "--json", "--quiet"]
    assert main([*argv, "--threads", "1"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["game"]["mode"] == "sprint" and report["game"]["outcome"] == "won"
    assert report["game"]["first"] == "octopus" and report["frames"] < 1800


def test_a_misspelt_mode_or_key_is_one_line(tmp_path: Path, capsys) -> None:  # type: ignore[no-untyped-def]
    folder = shutil.copytree(SPRINT, tmp_path / "sprint")
    scene = json.loads((folder / "sprint.json").read_text())
    for change, says in [
        (
            {"mode": "sprnt"},
            "game.mode: 'sprnt' is not a registered game mode (registered: sprint)",
        ),
        ({"finsh": 1}, "game.finsh: unknown key (allowed: finish, mode, radius, seconds)"),
    ]:
        (folder / "bad.json").write_text(json.dumps({**scene, "game": {**scene["game"], **change}}))
        assert main(["run", str(folder / "bad.json"), "--allow-systems", "--quiet"]) == 2
        lines = capsys.readouterr().err.strip().splitlines()
        assert lines == [f"error: {folder / 'bad.json'}: {says}"]
