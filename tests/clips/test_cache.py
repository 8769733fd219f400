"""Clip cache: one recording per morphology, whatever the creature's place or heading."""

from __future__ import annotations

import inspect
import typing
from collections.abc import Callable
from typing import Any

import numpy as np

from ecs_tentacles.clips.cache import ClipCache, RecordOptions, morphology_key, recording_input
from ecs_tentacles.clips.clips import GaitClips
from ecs_tentacles.clips.gait_world import one_creature_scene, simulate
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.world import World

SMALL = {"count": 4, "links": 5}
QUICK: dict[str, Any] = {"warmup": 1.0, "seconds": 2.5, "loop": (0.5, 2.0)}  # short ones


def _scene() -> dict[str, Any]:
    """Two creatures of one small morphology (placed and turned apart) and one other."""
    creatures = [
        {"name": "a", "position": [0, 0], "tentacles": SMALL, "goals": [{"position": [0, 2]}]},
        {"name": "b", "position": [4, 0], "heading_deg": 90, "tentacles": SMALL},
        {"name": "c", "position": [8, 0], "tentacles": {"count": 5, "links": 5}},
    ]
    return {"version": 1, "creatures": creatures}


def test_one_recording_per_morphology(make_world: Callable[..., World]) -> None:
    world = make_world(_scene())
    cache = ClipCache(**QUICK)
    a, b, c = (cache.for_creature(world, world.creature(n)) for n in "abc")
    assert a is b and a is not c
    assert len(cache) == 2
    for key, seconds in cache.seconds.items():
        print(f"\nrecording {len(cache.clips[key].bodies)} bodies: {seconds:.2f} s")
        assert seconds > 0
    assert a.crawl.speed > 0 and c.crawl.speed > 0


def test_scene_entries_find_the_same_clips(make_world: Callable[..., World]) -> None:
    scene = load_scene(_scene())
    world = make_world(scene)
    cache = ClipCache(**QUICK)
    first = cache.get(scene["creatures"][0], scene["physics"])
    assert cache.get(scene["creatures"][1], scene["physics"]) is first
    assert cache.for_creature(world, world.creature("b")) is first
    assert morphology_key(scene["creatures"][2], scene["physics"]) != first.key
    assert len(cache) == 1


def test_what_a_world_replays_does_not_depend_on_the_worlds_built_before() -> None:
    # the same morphology, creatures that behave otherwise: each is recorded from itself,
    # so a process that first met the slow one does not replay it for the fast one
    slow = load_scene(_scene())["creatures"][0]
    fast = load_scene(_scene())["creatures"][0]
    fast["locomotion"] = {**fast.get("locomotion", {}), "speed": 1.6}
    cache = ClipCache(**QUICK)
    from_slow, from_fast = cache.get(slow), cache.get(fast)
    assert from_slow.key == from_fast.key  # one morphology
    assert from_slow is not from_fast and len(cache) == 2
    assert from_fast.crawl.speed > from_slow.crawl.speed
    assert cache.get(dict(fast, name="renamed", position=[3.0, 1.0])) is from_fast
    fresh = ClipCache(**QUICK).get(fast)
    assert fresh.crawl.speed == from_fast.crawl.speed  # as in a process that met it first


def test_record_options_are_the_recording_keywords() -> None:
    """`ClipCache`'s keywords are typed by `RecordOptions`: it names exactly the keywords
    `GaitClips.record` takes, so neither can drift."""
    keywords = {
        name
        for name, p in inspect.signature(GaitClips.record).parameters.items()
        if p.kind is inspect.Parameter.KEYWORD_ONLY
    }
    assert set(typing.get_type_hints(RecordOptions)) == keywords


def test_scenes_that_differ_only_in_level_of_detail_share_one_recording() -> None:
    """A recording steps its creature alone at full physics, so the scene's level of
    detail (on or off, budgets, hold, focus) does not move it: stepped with two such
    settings the frames are the same bits, and the cache records it once for both."""
    scene = load_scene(_scene())
    creature, physics = scene["creatures"][0], scene["physics"]
    other = dict(physics)
    other["lod"] = {
        "enabled": not physics["lod"]["enabled"],
        "full": 0,
        "reduced": 1,
        "hold_seconds": 0.0,
        "focus": {"center": [0.0, 0.0], "radius": 1.0},
    }
    recorded = []
    for settings in (physics, other):
        staged = one_creature_scene(creature, None, goal=3.0)
        staged["physics"] = settings  # the level of detail kept in the staged scene
        recorded.append(simulate(staged, warmup=0.2, seconds=0.5))
    first, second = recorded
    assert first.qpos.shape == second.qpos.shape and np.abs(first.qvel).max() > 0
    assert np.array_equal(first.qpos, second.qpos) and np.array_equal(first.qvel, second.qvel)

    cache = ClipCache(**QUICK)
    assert cache.get(creature, other) is cache.get(creature, physics)
    assert len(cache) == 1
    assert recording_input(creature, other) == recording_input(creature, physics)
    moved = dict(physics, substeps=physics["substeps"] + 2)  # a setting that does move it
    assert recording_input(creature, moved) != recording_input(creature, physics)
