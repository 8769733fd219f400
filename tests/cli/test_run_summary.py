"""`run` reports what the scene's plugins count (`RunSummaries` entries), and nothing else."""

from __future__ import annotations

import json
import re
import textwrap
from pathlib import Path

import pytest

from ecs_tentacles.cli import main

CREATURE = {"name": "octo", "position": [0, 0], "tentacles": {"count": 3, "links": 4}}
COUNTER = textwrap.dedent(
    """
    from ecs_tentacles.cli.registries import RunSummaries, RunSummary
    from ecs_tentacles.plugin import Plugin


    class Counter(Plugin):
        name = "counter"

        def build(self, app):
            app.add(RunSummaries, self.count)

        def count(self, world):
            return RunSummary({"frames_seen": world.frame}, f"frames seen {world.frame}")
    """
)


def test_the_line_names_goals_from_the_locomotion_plugin(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["run", "octopus", "--frames", "3", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert re.search(r"dofs\); goals reached 0, left 1; sucker attaches \d+\n$", out), out


def test_without_locomotion_there_are_no_goal_counts_and_a_plugin_adds_its_own(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "counter.py").write_text(COUNTER)
    scene = {
        "version": 1,
        "creatures": [CREATURE],
        "plugins": {"locomotion": False, "suckers": False, "counter": {"from": "counter.py"}},
    }
    path = tmp_path / "still.json"
    path.write_text(json.dumps(scene))
    argv = ["run", str(path), "--frames", "4", "--quiet", "--allow-systems"]
    assert main([*argv, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert "goals_reached" not in summary and "goals_left" not in summary
    assert summary["frames_seen"] == 4 and summary["sucker_attaches"] == 0
    assert main(argv) == 0
    assert capsys.readouterr().out.endswith("dofs); frames seen 4; sucker attaches 0\n")


def test_lod_and_focus_options_decide_the_tiers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from tests.cli.test_measure import lod_crowd

    scene = tmp_path / "crowd.json"
    scene.write_text(json.dumps(lod_crowd()))  # 6 creatures, budgets 1 full and 2 reduced
    argv = ["run", str(scene), "--frames", "3", "--quiet", "--threads", "1"]
    assert main(argv) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == "  level of detail at the end: full 1  reduced 2  kinematic 3"
    runs = {}
    for name, options in (("off", ["--lod", "off"]), ("focus", ["--focus=0,0,1000"])):
        assert main([*argv, "--json", *options]) == 0
        runs[name] = json.loads(capsys.readouterr().out)
    assert runs["off"]["lod"] is False and runs["off"]["promotions"] == 0
    assert (
        runs["off"]["tiers"] == runs["focus"]["tiers"] == {"full": 6, "reduced": 0, "kinematic": 0}
    )
    assert runs["focus"]["lod"] is True
