"""Hot reload: a changed plugin file is swapped in; the world (ids, poses, frame) stays."""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from ecs_tentacles.reload import Reloader
from ecs_tentacles.world import World

PLUGIN = '''
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.system import System


class Mark(System):
    """Reads the frame; writes Marks (frame, value) and counts its calls."""

    name = "mark"
    stage = "output"
    state_attributes = ("calls",)

    def __init__(self, value):
        self.value = value
        self.calls = 0

    def process(self, world, dt):
        self.calls += 1
        world.resource(Marks).append((world.frame, self.value))
{extra}

class Marks(list):
    """(frame, value) of every mark, in order."""


class MarkPlugin(Plugin):
    name = "mark"
    config_schema = {{
        "type": "object",
        "additionalProperties": False,
        "properties": {{"scale": {{"type": "number", "default": 1.0}}}},
    }}

    def resources(self, world):
        return [Marks()]

    def systems(self):
        return [{systems}]
'''
TICK = '''

class Tick(System):
    """Reads nothing; writes Marks (frame, "tick")."""

    name = "tick"
    stage = "act"

    def process(self, world, dt):
        world.resource(Marks).append((world.frame, "tick"))
'''


def _marks(world: World) -> list:
    """The plugin's Marks resource (its class lives in the user's file)."""
    return next(r for r in world.resources if type(r).__name__ == "Marks")


def _write(path: Path, systems: str, extra: str = "", stamp: int = 0) -> None:
    path.write_text(PLUGIN.format(systems=systems, extra=extra))
    os.utime(path, ns=(stamp, 1_000_000_000 * (1000 + stamp)))  # a new mtime, however fast


@pytest.fixture
def world(tmp_path: Path, make_world: Callable[..., World]) -> World:
    """A crawling octopus with the `mark` plugin from tmp_path/mark.py (scale 10)."""
    _write(tmp_path / "mark.py", 'Mark(1.0 * self.config["scale"])')
    scene = {
        "version": 1,
        "plugins": {"mark": {"from": "mark.py", "scale": 10}},
        "creatures": [
            {
                "name": "octo",
                "tentacles": {"count": 4, "links": 3},
                "goals": [{"position": [1.0, 0.0]}],
            }
        ],
    }
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    return make_world(tmp_path / "scene.json", allow_systems=True)


def _values(world: World, frames: range) -> list[object]:
    return [value for frame, value in _marks(world) if frame in frames]


def test_a_changed_file_swaps_behaviour_and_keeps_the_world(world: World, tmp_path: Path) -> None:
    reloader = Reloader(world)
    assert list(reloader.watched) == ["mark"]
    world.step(12)
    octo, marks = world.creature("octo"), _marks(world)
    pos = world.transforms.pos.copy()
    assert reloader.check() == []  # nothing changed yet
    _write(tmp_path / "mark.py", 'Mark(2.0 * self.config["scale"])', stamp=1)
    [done] = reloader.check()
    assert (done.message, done.swapped) == ("reloaded mark.py (mark)", ["mark"])
    assert world.creature("octo") == octo  # the same entity
    assert_array_equal(world.transforms.pos, pos)  # not moved by the swap
    assert world.frame == 12 and _marks(world) is marks  # the clock and the plugin's data go on
    world.step(3)
    assert _values(world, range(0, 12)) == [10.0] * 12  # old code, config scale 10
    assert _values(world, range(12, 15)) == [20.0] * 3  # new code, same config
    assert world.schedule["mark"].calls == 15  # type: ignore[attr-defined]  # state kept
    assert world.plugin("mark").config == {"scale": 10}
    assert not np.allclose(world.transforms.pos, pos)  # and the creature crawls on


def test_a_broken_file_keeps_the_old_code_running(world: World, tmp_path: Path) -> None:
    reloader = Reloader(world)
    world.step(2)
    (tmp_path / "mark.py").write_text("class Mark(:\n")
    os.utime(tmp_path / "mark.py", ns=(1, 2_000_000_000_000))
    [done] = reloader.check()
    assert done.error is not None and done.error.startswith("SyntaxError: ")
    assert done.message.startswith("mark.py: not reloaded, old code keeps running: SyntaxError")
    _write(tmp_path / "mark.py", "Mark(1 / 0)", stamp=2)  # imports, but cannot be made
    [done] = reloader.check()
    assert done.message == (
        "mark.py: not reloaded, old code keeps running: ZeroDivisionError: division by zero"
    )
    world.step(2)
    assert _values(world, range(0, 4)) == [10.0] * 4


def test_a_fixed_file_runs_the_failed_system_again_and_adds_new_ones(
    world: World, tmp_path: Path
) -> None:
    reloader = Reloader(world)
    world.schedule.disable("mark")  # as the sandbox does when it fails
    world.step(1)
    _write(tmp_path / "mark.py", "Mark(3.0), Tick()", extra=TICK, stamp=3)
    [done] = reloader.check()
    assert (done.swapped, done.added, done.removed) == (["mark"], ["tick"], [])
    assert done.message == "reloaded mark.py (mark, +tick)"
    assert world.schedule.disabled() == []
    world.step(1)
    assert _marks(world) == [(1, "tick"), (1, 3.0)]  # tick acts, mark outputs
    _write(tmp_path / "mark.py", "Tick()", extra=TICK, stamp=4)
    assert reloader.check()[0].removed == ["mark"]
    assert "mark" not in world.schedule


def test_poll_looks_at_most_every_interval_and_skips_a_missing_file(
    world: World, tmp_path: Path
) -> None:
    reloader = Reloader(world, interval=0.5)
    start = reloader._last
    _write(tmp_path / "mark.py", "Mark(4.0)", stamp=5)
    assert reloader.poll(start + 0.2) == []  # too soon: no look
    assert [r.swapped for r in reloader.poll(start + 0.6)] == [["mark"]]
    (tmp_path / "mark.py").unlink()  # an editor between delete and write
    assert reloader.poll(start + 1.2) == []


@pytest.mark.parametrize(
    ("code", "error"),
    [
        ("import sys\nsys.exit(0)\n", "SystemExit: 0"),
        ("raise KeyboardInterrupt\n", "KeyboardInterrupt"),
        ("while True:\n    pass\n", "TimeoutError: took longer than 0.5 s"),
    ],
)
def test_a_file_that_exits_or_hangs_is_not_reloaded(
    world: World, tmp_path: Path, code: str, error: str
) -> None:
    reloader = Reloader(world, import_seconds=0.5)
    world.step(2)
    (tmp_path / "mark.py").write_text(code)
    os.utime(tmp_path / "mark.py", ns=(1, 3_000_000_000_000))
    [done] = reloader.check()
    assert done.message == f"mark.py: not reloaded, old code keeps running: {error}"
    world.step(2)
    assert _values(world, range(0, 4)) == [10.0] * 4


def test_a_file_replaced_by_a_symlink_out_of_the_folder_is_not_run(
    world: World, tmp_path: Path, tmp_path_factory: pytest.TempPathFactory
) -> None:
    reloader = Reloader(world)
    world.step(2)
    outside = tmp_path_factory.mktemp("elsewhere") / "evil.py"
    outside.write_text("raise RuntimeError('outside code ran')\n")
    (tmp_path / "mark.py").unlink()
    (tmp_path / "mark.py").symlink_to(outside)
    [done] = reloader.check()
    assert done.error is not None and "leaves the scene's folder" in done.error
    assert "outside code ran" not in done.message
    world.step(2)
    assert _values(world, range(0, 4)) == [10.0] * 4
