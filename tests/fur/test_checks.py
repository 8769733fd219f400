"""The fur's budget (`fur.checks`): a scene asking for more guides or guide points than a
scene may have is refused in one line naming the fur, before any guide is made."""

from __future__ import annotations

import json
import resource
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from ecs_tentacles.creator.crowd import crowd_scene
from ecs_tentacles.creatures.spawning import SpawnError
from ecs_tentacles.fur import groom
from ecs_tentacles.fur.checks import (
    MAX_SCENE_CHILDREN,
    MAX_SCENE_FUR_POINTS,
    MAX_SCENE_GUIDES,
    budget_problems,
    guide_count,
)
from ecs_tentacles.scene.defaults import with_defaults
from ecs_tentacles.scene.load import bundled_scene, bundled_scene_names, load_scene
from ecs_tentacles.scene.plugins import resolve
from ecs_tentacles.scene.schema import load_schema
from ecs_tentacles.scene.validate import validate_scene
from ecs_tentacles.world import World

MEMORY = 1536 * 1024**2  # bytes of address space the `validate` below may take (it needs 0.4 GB)


def _furry(*grooms: dict[str, Any], **fur: Any) -> dict[str, Any]:
    """A scene of one creature per groom, 3 m apart, each with that fur."""
    creatures = [
        {"name": f"c{i}", "position": [3 * i, 0], "fur": {"groom": g, **fur}}
        for i, g in enumerate(grooms)
    ]
    return {"version": 1, "creatures": creatures}


def _limit_memory() -> None:
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY, MEMORY))


def test_validate_refuses_a_kilobyte_scene_that_asks_for_80_gb_of_fur(tmp_path: Path) -> None:
    """16 creatures of a million guides of 64 points: 1.1 KB of JSON, about 80 GB to build.
    Refused in one line, exit 2, within a memory limit a build would break at once."""
    scene = tmp_path / "furry.json"
    scene.write_text(json.dumps(_furry(*[{"count": 1_000_000, "points": 64}] * 16)))
    assert scene.stat().st_size < 2048
    result = subprocess.run(
        [sys.executable, "-P", "-m", "ecs_tentacles", "validate", str(scene)],
        capture_output=True, text=True, timeout=120, preexec_fn=_limit_memory, cwd=tmp_path,
    )  # fmt: skip
    assert result.returncode == 2, result.stderr
    assert result.stdout == ""
    assert result.stderr.splitlines() == [
        f"error: {scene}: creatures[0].fur.groom.count: the scene's 16,000,000 guides"
        " (1,000,000 here) are over the budget of 500,000 a scene (about 83.1 GB);"
        " groom fewer guides"
    ]


def test_guide_points_count_every_guide_at_the_most_points_a_groom_asks() -> None:
    """Guides of all furs share one point count: 10 guides of 64 points make 400,000
    guides of 2 points cost 64 points each."""
    lines = validate_scene(_furry({"count": 400_000, "points": 2}, {"count": 10, "points": 64}))
    assert lines == [
        "creatures[0].fur.groom.count: the scene's 400,010 guides (400,000 here) of 64 points"
        " each (the most a groom asks: creatures[1].fur.groom.points) are 25,600,640 guide"
        " points, over the budget of 4,000,000 a scene (about 2.1 GB); groom fewer guides or"
        " fewer points per guide"
    ]
    assert validate_scene(_furry({"count": 400_000, "points": 2}, {"count": 10, "points": 10}))


def test_the_budget_holds_up_to_its_limits_and_not_one_guide_more() -> None:
    half = MAX_SCENE_GUIDES // 2
    points = MAX_SCENE_FUR_POINTS // MAX_SCENE_GUIDES
    assert validate_scene(_furry(*[{"count": half, "points": points}] * 2)) == []
    over = validate_scene(_furry({"count": half, "points": points}, {"count": half + 1}))
    assert len(over) == 1 and over[0].startswith("creatures[1].fur.groom.count: the scene's")
    at = {"count": MAX_SCENE_FUR_POINTS // 64, "points": 64}
    assert validate_scene(_furry(at)) == []
    assert len(validate_scene(_furry({**at, "count": at["count"] + 1}))) == 1


def test_density_and_listed_guides_count_as_the_groom_makes_them() -> None:
    listed = [{"points": [[0.1, 0, 0.1], [0.2, 0, 0.2]]}] * 3
    scene = with_defaults(
        _furry({"density": 2000.0, "region": "back"}, guides=listed), resolve(None)
    )
    fur, mantle = scene["creatures"][0]["fur"], scene["creatures"][0]["mantle"]
    made = groom.generate(fur["groom"], mantle["radius"], mantle["height"])
    assert guide_count(fur, mantle) == (len(made.length) + 3, "density")
    assert guide_count({"groom": {"count": 2}, "guides": listed}, mantle) == (5, "guides")
    huge = _furry({"density": 1e6})
    huge["creatures"][0]["mantle"] = {"radius": 1.0, "height": 1.0}
    guides = round(1e6 * groom.region_area("all", 1.0, 1.0))  # 3 pi m^2 of skin
    assert validate_scene(huge) == [
        f"creatures[0].fur.groom.density: the scene's {guides:,} guides (all here) are over"
        " the budget of 500,000 a scene (about 15.2 GB); groom fewer guides"
    ]


def test_the_bundled_scenes_and_the_largest_crowd_are_well_within_the_budget() -> None:
    """The largest crowd `ecs-tentacles crowd` writes (16,384 creatures, a quarter furry)
    has about 132,000 guides of 8 points: a quarter of the budget or less."""
    for name in bundled_scene_names():
        assert budget_problems(load_scene(bundled_scene(name))) == [], name
    crowd = with_defaults(crowd_scene(16_384, 0), resolve(None))
    counts = [guide_count(c["fur"], c["mantle"])[0] for c in crowd["creatures"] if "fur" in c]
    points = max(c["fur"]["groom"]["points"] for c in crowd["creatures"] if "fur" in c)
    assert sum(counts) <= MAX_SCENE_GUIDES / 3
    assert sum(counts) * points <= MAX_SCENE_FUR_POINTS / 3
    children = [
        guide_count(c["fur"], c["mantle"])[0] * c["fur"]["children"]
        for c in crowd["creatures"]
        if "fur" in c
    ]
    assert sum(children) <= MAX_SCENE_CHILDREN / 5  # about 180,000
    assert budget_problems(crowd) == []


def test_a_creature_over_the_budget_is_not_spawned(make_world: Callable[..., World]) -> None:
    world = make_world({"version": 1, "creatures": [{"name": "octo", "position": [0, 0]}]})
    with pytest.raises(SpawnError) as refused:
        world.spawn({"fur": {"groom": {"count": 600_000, "points": 2}}}, position=(3, 0))
    assert refused.value.problems == [
        "creature.fur.groom.count: the scene's 600,000 guides (all here) are over the budget"
        " of 500,000 a scene (about 0.7 GB); groom fewer guides"
    ]
    assert len(world.creatures) == 1


def test_the_schema_publishes_the_budget() -> None:
    text = load_schema()["$defs"]["groom"]["properties"]["count"]["description"]
    assert f"{MAX_SCENE_GUIDES:,} guides and {MAX_SCENE_FUR_POINTS:,} guide points" in text
    text = load_schema()["$defs"]["fur"]["properties"]["children"]["description"]
    assert f"at most {MAX_SCENE_CHILDREN:,} child hairs in all" in text


def test_validate_refuses_more_child_hairs_than_a_scene_may_draw(tmp_path: Path) -> None:
    """Two furs of 200,000 guides with 64 children each ask for 25.6 million child hairs
    (about 17 GB to set up): one line naming the first fur's `children`, exit 2."""
    scene = tmp_path / "hairy.json"
    scene.write_text(json.dumps(_furry(*[{"count": 200_000, "points": 2}] * 2, children=64)))
    result = subprocess.run(
        [sys.executable, "-P", "-m", "ecs_tentacles", "validate", str(scene)],
        capture_output=True, text=True, timeout=120, preexec_fn=_limit_memory, cwd=tmp_path,
    )  # fmt: skip
    assert (result.returncode, result.stdout) == (2, ""), result.stderr
    assert result.stderr.splitlines() == [
        f"error: {scene}: creatures[0].fur.children: the scene's 25,600,000 child hairs"
        " (12,800,000 here: 200,000 guides x 64) are over the budget of 1,000,000 a scene"
        " (about 17.2 GB to set up); fewer children per guide or fewer guides"
    ]


def test_children_are_counted_as_the_sandbox_draws_them_up_to_the_limit() -> None:
    """Each fur's guides times its own `children`; the limit itself is allowed."""
    at = _furry({"count": 250_000, "points": 2}, {"count": 125_000, "points": 2})
    at["creatures"][0]["fur"]["children"] = 3
    at["creatures"][1]["fur"]["children"] = 2
    assert 250_000 * 3 + 125_000 * 2 == MAX_SCENE_CHILDREN
    assert validate_scene(at) == []
    at["creatures"][1]["fur"]["guides"] = [{"points": [[0.1, 0, 0.1], [0.2, 0, 0.2]]}]
    assert validate_scene(at) == [
        "creatures[0].fur.children: the scene's 1,000,002 child hairs (750,000 here: 250,000"
        " guides x 3) are over the budget of 1,000,000 a scene (about 0.7 GB to set up);"
        " fewer children per guide or fewer guides"
    ]
    without = _furry({"count": MAX_SCENE_GUIDES, "points": 2})  # no children: none drawn
    assert validate_scene(without) == []
