"""tools/lod_fidelity.py: the overlap probe sees two creatures pushed into each other, and a
short comparison reports what its doc promises."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from ecs_tentacles.components import Transform
from ecs_tentacles.world import World
from tests.tools.loader import TOOLS, load_tool

TOOL = TOOLS / "lod_fidelity.py"


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_the_overlap_probe_measures_capsules_pushed_into_each_other() -> None:
    tool = load_tool("lod_fidelity")
    octo = {"tentacles": {"count": 4, "links": 3}}
    scene = {
        "version": 1,
        "creatures": [{**octo, "name": "a"}, {**octo, "name": "b", "position": [3, 0]}],
    }
    with World.from_scene(scene) as world:
        rows, half, radius = tool._capsules(world)
        assert tool.deepest_overlap(world, rows, half, radius) == 0.0  # 3 m apart
        b = world.creature("b")
        moved = world.transforms.pos[rows[1]] - [3.0 - 0.02, 0.0, 0.0]  # b's links onto a's
        world.transforms.pos[rows[1]] = moved
        world.transforms.pos[world.component(b, Transform).row, 0] -= 2.98
        assert tool.deepest_overlap(world, rows, half, radius) > 0.01


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_short_comparison_reports_progress_goals_overlap_and_recoveries() -> None:
    tool = load_tool("lod_fidelity")
    on, off = (tool.run(4, 0.2, lod, 5, 0, None) for lod in (True, False))
    result = tool.compare(on, off)
    assert set(on["progress"]) == set(off["progress"]) and len(on["progress"]) == 4
    assert np.isfinite(result["progress_ratio"])
    assert result["recoveries"] == {"lod": 0, "off": 0}
    assert result["deepest_mm"]["lod"] >= 0.0 and result["reached"]["both"] >= 0


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_goals_brought_near_keep_their_direction_and_are_reached_in_both_runs() -> None:
    from ecs_tentacles.creator.crowd import crowd_scene

    tool = load_tool("lod_fidelity")
    far = crowd_scene(4, seed=0)
    near = tool.goals_within(crowd_scene(4, seed=0), 0.3)
    for old, new in zip(far["creatures"], near["creatures"], strict=True):
        start = np.asarray(old["position"][:2])
        was, now = (np.asarray(c["goals"][0]["position"][:2]) - start for c in (old, new))
        assert np.linalg.norm(now) == pytest.approx(min(0.3, np.linalg.norm(was)))
        assert np.dot(was, now) > 0.999 * np.linalg.norm(was) * np.linalg.norm(now)
    on, off = (tool.run(4, 4.0, lod, 50, 0, 0.3) for lod in (True, False))
    result = tool.compare(on, off)
    assert result["reached"] == {"lod": 4, "off": 4, "both": 4}
    assert result["arrival_apart_s_max"] < 2.0
    assert result["arrivals_within_2s"] == 4 and result["arrival_apart_s"] == {}
    assert 0.0 <= result["arrival_apart_s_median"] <= result["arrival_apart_s_max"]


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_nudged_run_starts_every_creature_moved() -> None:
    tool = load_tool("lod_fidelity")
    plain, moved = (tool.run(2, 0.05, False, 5, 0, None, nudge) for nudge in (0.0, 0.25))
    # the goals stay: moved along x, each creature's distance to its goal changed
    assert plain["progress"].keys() == moved["progress"].keys()
    assert plain["progress"] != moved["progress"]
    with pytest.raises(SystemExit):
        tool.main(["--nudge", "0"])


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_run_where_nobody_arrives_says_no_arrival_times_were_compared(
    capsys: pytest.CaptureFixture[str],
) -> None:
    tool = load_tool("lod_fidelity")
    assert tool.main(["--creatures", "2", "--seconds", "0.1"]) == 0
    out = capsys.readouterr().out
    assert "none in either run, so no arrival times to compare" in out
    assert "--goals-within" in out and "at most 0.00 s apart" not in out


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_bad_reduced_model_is_refused_naming_the_key(capsys: pytest.CaptureFixture[str]) -> None:
    tool = load_tool("lod_fidelity")
    with pytest.raises(SystemExit):
        tool.main(["--model", "rate=0"])
    assert "--model: rate: must be an integer >= 1, got 0" in capsys.readouterr().err


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_reduced_budget_reaches_the_scene_and_a_negative_one_is_refused(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    tool = load_tool("lod_fidelity")
    built = []

    class Built(Exception):
        pass

    def capture(scene: dict[str, Any], **options: Any) -> World:
        built.append((scene, options))
        raise Built

    monkeypatch.setattr(tool.World, "from_scene", capture)
    for reduced in (None, 5):
        with pytest.raises(Built):
            tool.run(12, 0.1, True, 5, 0, None, reduced=reduced)
    (default, _), (smaller, options) = built
    assert "lod" not in default.get("physics", {})  # the scene's own budget
    assert smaller["physics"]["lod"]["reduced"] == 5 and options == {"lod": True}
    with pytest.raises(SystemExit):
        tool.main(["--reduced", "-1"])
    assert "--reduced: must be >= 0 creatures, got -1" in capsys.readouterr().err
