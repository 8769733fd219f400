"""A name used again during a bake: the take names each creature once, so a creature
spawned under the name of one despawned earlier gets a suffix when it is spawned (the
whole bake used to run, then the take could not be written: exit 1 at the very end)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from ecs_tentacles.cli import main
from ecs_tentacles.components import Creature
from ecs_tentacles.creatures.spawning import SpawnError
from ecs_tentacles.take import Take
from ecs_tentacles.world import World

COMEBACK = '''
from ecs_tentacles.system import System


class Comeback(System):
    """Despawns 'early' at frame 20, spawns a new 'early' at frame 40."""

    name = "comeback"
    stage = "decide"

    def process(self, world, dt):
        if world.frame == 20:
            self.entry = dict(world.creature_specs[world.creature("early")])
            world.despawn(world.creature("early"))
        elif world.frame == 40:
            world.spawn(self.entry)
'''


def test_a_bake_that_spawns_a_name_used_before_writes_its_take(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "comeback.py").write_text(COMEBACK)
    scene = {
        "version": 1,
        "systems": ["comeback:Comeback"],
        "creatures": [
            {"name": "early", "tentacles": {"count": 3, "links": 2}},
            {"name": "late", "position": [4, 0], "tentacles": {"count": 3, "links": 2}},
        ],
    }
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "take.npz"
    args = ["bake", "scene.json", "--seconds", "1", "--out", str(out), "--allow-systems"]
    assert main([*args, "--quiet"]) == 0, capsys.readouterr().err
    take = Take.load(out)
    names = [c["name"] for c in take.header["creatures"]]
    assert names == ["early", "late", "early_2"]
    visible = take.visible()
    assert visible[:20, 0].all() and not visible[25:, 0].any()
    assert not visible[:40, 2].any() and visible[45:, 2].all()


def test_a_placed_entry_whose_name_a_recording_kept_is_refused_when_it_happens() -> None:
    from ecs_tentacles.creatures.spawning import place
    from ecs_tentacles.record.systems.record import Record

    scene = {"version": 1, "creatures": [{"name": "a", "tentacles": {"count": 3, "links": 2}}]}
    with World.from_scene(scene) as world:
        world.add_system(Record())
        world.step(2)
        entry = dict(world.creature_specs[world.creature("a")])
        world.despawn(world.creature("a"))
        with pytest.raises(SpawnError, match=r"^creature.name: 'a' is taken"):
            place(world, entry)  # as an undone removal would
        assert [c.name for _, c in world.query(Creature)] == []
        assert world.creature_name(world.spawn(entry)) == "a_2"
        world.step(2)
        assert np.isfinite(world.transforms.pos).all()
