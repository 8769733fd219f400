"""The measurement tools run and report the fields their docs promise (short runs)."""

from __future__ import annotations

import pytest

from tests.tools.loader import TOOLS, load_tool

pytestmark = pytest.mark.skipif(not TOOLS.is_dir(), reason="needs the source tree")


def test_locomotion_report_row_has_the_issue_fields() -> None:
    report = load_tool("locomotion_report")
    from ecs_tentacles.world import World

    world = World.from_scene(report.case_scene(4, "coordinated", 0.0))
    row = report.run(world, "4_front", 2.0)
    world.close()
    assert {
        "case",
        "tentacles",
        "gait",
        "reached",
        "time_s",
        "speed_radii_per_s",
        "path_efficiency",
        "attaches",
        "max_penetration_m",
    } <= set(row)
    assert (row["case"], row["tentacles"], row["gait"], row["reached"]) == (
        "4_front",
        4,
        "coordinated",
        False,
    )
    assert row["time_s"] == pytest.approx(2.0)
    assert row["finite"] and not row["flipped"] and row["suckers_left_behind"] == 0
    assert row["speed_radii_per_s"] > 0 and row["attaches"] >= 1
    assert len(report.cases(None, None)) == 5 * 3 * 2 + 2 + 1


def test_frame_benchmark_splits_the_frame() -> None:
    bench = load_tool("bench_frame")
    row = bench.bench_scene("three_goals", frames=3, repeats=1)
    ms = row["ms_per_frame"]
    names = {"goals", "avoidance", "tentacle_selection", "action_queue", "motor_targets"}
    names |= {"suckers"}
    names |= {"threats", "emotion", "rig", "lod_replay"}
    assert names | {"physics", "physics_health", "physics_sync", "total", "mj_step"} == set(ms)
    assert ms["total"] >= ms["mj_step"] > 0


def test_scene_corners_builds_or_refuses_every_corner_scene() -> None:
    corners = load_tool("scene_corners")
    result = corners.search(scenes=60, seed=1, frames=10)
    counts = result["counts"]
    assert sum(counts.values()) == 60
    assert counts.get("ok", 0) >= 3  # some corners are accepted and stepped
    assert result["unstable"] == [] and "unstable" not in counts
    assert all(key == "ok" or key.startswith("refused ") for key in counts)
