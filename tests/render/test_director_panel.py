"""The director in the sandbox, driven headless by pyglet events and read back from the world."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from pyglet.window import key, mouse

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.director.grab import MAX_ACCELERATION
from ecs_tentacles.director.state import Director
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.threats.data import ThreatData
from ecs_tentacles.world import World

from .conftest import click_at, click_gui, event, pixel


def _names(world: Any) -> list[str]:
    return sorted(c.name for _, c in world.query(Creature))


def _key(sandbox: Any, symbol: int, modifiers: int = 0) -> None:
    event(sandbox, "on_key_press", symbol, modifiers)
    event(sandbox, "on_key_release", symbol, modifiers)


def test_place_scatter_delete_copy_and_undo_them(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus")
    world = sandbox.world
    panel = sandbox.panel("Director")
    panel.placing = True
    click_at(sandbox, pixel(sandbox, [2.0, 1.5, 0.0]))
    assert _names(world) == ["octopus", "octopus_2"]
    sandbox.render()  # the next frame draws it
    assert world.creature("octopus_2") in sandbox.renderer.creature_entities
    placed = world.component(world.creature("octopus_2"), Transform).pos
    assert np.hypot(placed[0] - 2.0, placed[1] - 1.5) < 0.05
    panel.placing = False
    # S + drag: the brush scatters
    panel.radius, panel.density, panel.count = 3.0, 4.0, 8
    event(sandbox, "on_key_press", key.S, 0)
    start = pixel(sandbox, [-4.0, 3.0, 0.0])
    event(sandbox, "on_mouse_press", *start, mouse.LEFT, 0)
    assert world.resource(Director).brush is not None  # the brush ring is drawn
    event(sandbox, "on_mouse_drag", start[0] + 10, start[1], 10, 0, mouse.LEFT, 0)
    event(sandbox, "on_mouse_release", start[0] + 10, start[1], mouse.LEFT, 0)
    event(sandbox, "on_key_release", key.S, 0)
    assert len(_names(world)) == 2 + 8
    assert world.resource(Director).brush is None
    sandbox.step(5)
    sandbox.render()
    # select two, Ctrl+D copies them (and selects the copies), Delete removes those
    sandbox.select_many([world.creature("octopus"), world.creature("octopus_2")])
    _key(sandbox, key.D, key.MOD_CTRL)
    assert len(_names(world)) == 12 and len(sandbox.selection) == 2
    copies = sorted(world.creature_name(e) for e in sandbox.selection.entities)
    _key(sandbox, key.DELETE)
    assert len(_names(world)) == 10 and not set(copies) & set(_names(world))
    # undo: the copies come back; undo twice more: no copies, no scatter
    _key(sandbox, key.Z, key.MOD_CTRL)
    assert set(copies) <= set(_names(world))
    _key(sandbox, key.Z, key.MOD_CTRL)
    _key(sandbox, key.Z, key.MOD_CTRL)
    assert _names(world) == ["octopus", "octopus_2"]
    _key(sandbox, key.Z, key.MOD_CTRL | key.MOD_SHIFT)  # redo the scatter
    assert len(_names(world)) == 10
    sandbox.step(10)
    assert world.physics.health.recoveries == 0


def test_goal_and_slider_edits_undo_and_redo(make_sandbox: Callable[..., Any]) -> None:
    sandbox = make_sandbox("octopus")
    world = sandbox.world
    octo = world.creature("octopus")
    book = world.resource(GoalBook)
    before = book.positions(octo).copy()
    click_at(sandbox, pixel(sandbox, [1.0, -1.0, 0.0]))
    assert not np.array_equal(book.positions(octo), before)
    sandbox.render()
    x0, y0, x1, y1 = sandbox.hud.gui.rects["speed"]
    click_gui(sandbox, x0 + 0.9 * (x1 - x0), (y0 + y1) / 2)
    fast = world.resource(Locomotion).get(octo, 0)["creature_speed"]
    assert fast != 1.0
    _key(sandbox, key.Z, key.MOD_CTRL)  # the speed
    assert world.resource(Locomotion).get(octo, 0)["creature_speed"] == 1.0
    _key(sandbox, key.Z, key.MOD_CTRL)  # the goal
    assert np.array_equal(book.positions(octo), before)
    _key(sandbox, key.Z, key.MOD_CTRL | key.MOD_SHIFT)
    _key(sandbox, key.Z, key.MOD_CTRL | key.MOD_SHIFT)
    assert world.resource(Locomotion).get(octo, 0)["creature_speed"] == fast
    assert np.allclose(book.positions(octo)[0, :2], [1.0, -1.0], atol=0.01)


@pytest.mark.parametrize("offset", [0, -2, 4])  # px beside the mantle's centre: other throws
def test_ctrl_drag_lifts_and_throws_a_creature_with_a_bounded_force(
    make_sandbox: Callable[..., Any], offset: int
) -> None:
    sandbox = make_sandbox("octopus")
    world = sandbox.world
    octo = world.creature("octopus")
    sandbox.step(120)  # it crawls: a sucker holds the ground
    assert world.suckers.attached.any()
    start = world.component(octo, Transform).pos.copy()
    x, y = pixel(sandbox, start)
    x += offset
    event(sandbox, "on_mouse_press", x, y, mouse.LEFT, key.MOD_CTRL)
    grab = world.resource(Director).grab
    assert grab is not None and grab.creature == octo
    view = world.physics.view_of(world.component(octo, Creature))
    limit = float(view.model.body_subtreemass[view.body_ids[0]]) * MAX_ACCELERATION
    forces = []
    for i in range(60):  # up the screen: up in the world
        event(sandbox, "on_mouse_drag", x, y + 2 * i, 0, 2, mouse.LEFT, key.MOD_CTRL)
        sandbox.step(1)
        forces.append(float(np.linalg.norm(grab.force)))
    lifted = world.component(octo, Transform).pos[2] - start[2]
    assert lifted > 0.3
    assert max(forces) <= limit * (1 + 1e-9)
    assert not world.suckers.attached.any()  # stretched: the suckers let go
    for i in range(10):  # a fast sweep sideways, then let go: a throw
        event(sandbox, "on_mouse_drag", x + 15 * i, y + 120, 15, 0, mouse.LEFT, key.MOD_CTRL)
        sandbox.step(1)
    speed = float(np.linalg.norm(view.data.qvel[:3]))
    event(sandbox, "on_mouse_release", x + 150, y + 120, mouse.LEFT, key.MOD_CTRL)
    assert world.resource(Director).grab is None and speed > 1.0
    sandbox.step(240)
    landed = world.component(octo, Transform).pos
    assert landed[2] < 0.2 and np.hypot(*(landed[:2] - start[:2])) > 0.5
    assert world.physics.health.recoveries == 0
    assert not view.batch.applied  # no force left behind
    _key(sandbox, key.Z, key.MOD_CTRL)  # the move: back where it was grabbed
    assert np.hypot(*(world.component(octo, Transform).pos[:2] - start[:2])) < 0.05


def test_removing_the_creature_being_dragged_ends_the_grab(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("thesis_four_by_six")
    world = sandbox.world
    held, other = sorted(c.name for _, c in world.query(Creature))[:2]
    position = world.component(world.creature(held), Transform).pos.copy()
    x, y = pixel(sandbox, position)
    event(sandbox, "on_mouse_press", x, y, mouse.LEFT, key.MOD_CTRL)
    event(sandbox, "on_mouse_drag", x, y + 20, 0, 20, mouse.LEFT, key.MOD_CTRL)
    sandbox.step(2)
    sandbox.select_many([world.creature(held)])
    _key(sandbox, key.DELETE)  # still dragging
    assert world.resource(Director).grab is None
    event(sandbox, "on_mouse_drag", x, y + 40, 0, 20, mouse.LEFT, key.MOD_CTRL)
    before = world.frame
    sandbox.step(3)  # the physics steps on (it raised for the creature gone, switched off)
    event(sandbox, "on_mouse_release", x, y + 40, mouse.LEFT, key.MOD_CTRL)
    sandbox.render()
    assert world.frame == before + 3 and held not in _names(world)
    assert not world.schedule.disabled()  # no system failed and was switched off
    assert world.physics.health.recoveries == 0
    assert not any(batch.applied for batch in world.physics.batches)
    other_view = world.physics.view_of(world.component(world.creature(other), Creature))
    moved = world.transforms.pos[other_view.body_rows[0]]
    assert np.isfinite(moved).all()
    _key(sandbox, key.Z, key.MOD_CTRL)  # the removal undone: it is back
    assert held in _names(world)


def test_ctrl_s_saves_a_scene_that_reloads_to_the_same_setup(
    make_sandbox: Callable[..., Any], tmp_path: Path
) -> None:
    sandbox = make_sandbox("flee")
    world = sandbox.world
    panel = sandbox.panel("Director")
    panel.placing = True
    click_at(sandbox, pixel(sandbox, [0.0, 3.0, 0.0]))  # a new octopus
    panel.chosen = len(panel.presets) - 1  # the roach
    click_at(sandbox, pixel(sandbox, [2.0, -2.0, 0.0]))
    panel.placing = False
    assert len(world.resource(ThreatData).positions(world)) == 2
    newcomer = world.creature("octopus")  # the palette's first creature
    sandbox.select(newcomer)
    click_at(sandbox, pixel(sandbox, [-1.0, 4.0, 0.0]))  # its goal
    world.resource(Locomotion).set(newcomer, gait="cyclic", speed=1.3)
    world.resource(Locomotion).set(newcomer, tentacle=2, wave_frequency=0.9)
    world.despawn(world.creature("east"))
    sandbox.step(3)
    saved = sandbox.save_roster(tmp_path / "directed.json")
    assert saved is not None and json.loads(saved.read_text())["creatures"]
    with World.from_scene(saved, allow_systems=True) as again:
        assert _names(again) == _names(world) == ["octopus", "west"]
        for name in ("octopus", "west"):
            here, there = world.creature(name), again.creature(name)
            assert np.allclose(
                again.resource(GoalBook).positions(there)[:, :2],
                world.resource(GoalBook).positions(here)[:, :2],
            )
            for k in range(8):
                a = world.resource(Locomotion).get(here, k)
                b = again.resource(Locomotion).get(there, k)
                assert a.keys() == b.keys()
                for name_, value in a.items():
                    assert value == b[name_] or np.isclose(value, b[name_]), (name, k, name_)
            mantle = world.component(here, Transform).pos[:2]
            assert np.allclose(again.component(there, Transform).pos[:2], mantle, atol=1e-5)
        assert set(again.resource(ThreatData).positions(again)) == set(
            world.resource(ThreatData).positions(world)
        )


def test_f9_goes_back_past_a_spawn_and_refuses_past_a_removal(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = make_sandbox("octopus")
    world = sandbox.world
    _key(sandbox, key.F5)
    newcomer = world.spawn({"name": "late"}, position=(4.0, 0.0))
    sandbox.select(newcomer)
    sandbox.step(5)
    _key(sandbox, key.F9)  # back to before it came: it goes again
    assert _names(world) == ["octopus"] and sandbox.renderer.selected is None
    sandbox.render()
    _key(sandbox, key.F5)
    sandbox.step(3)
    world.despawn(world.creature("octopus"))
    _key(sandbox, key.F9)  # it cannot come back with its old entity: said, nothing changes
    assert _names(world) == [] and sandbox.world.frame == 3
    assert any("despawned since" in line for _, line in sandbox.scripts.notes)


def test_undoing_a_removal_puts_the_creature_beside_whatever_took_its_place(
    make_sandbox: Callable[..., Any],
) -> None:
    """Delete `a`, a script spawns a creature on its spot, Ctrl+Z: `a` came back inside the newcomer
    and both blew up within 2 s (QACC NaN, 6 recoveries)."""
    sandbox = make_sandbox("thesis_four_by_six")
    world = sandbox.world
    gone = sorted(c.name for _, c in world.query(Creature))[0]
    spot = world.component(world.creature(gone), Transform).pos.copy()
    sandbox.select_many([world.creature(gone)])
    _key(sandbox, key.DELETE)
    entry = {"name": "newcomer", "tentacles": {"count": 6, "links": 4}}
    newcomer = world.creature_name(world.spawn(entry, position=spot[:2]))  # a script's
    _key(sandbox, key.Z, key.MOD_CTRL)
    assert gone in _names(world) and newcomer in _names(world)
    back = world.component(world.creature(gone), Transform).pos
    there = world.component(world.creature(newcomer), Transform).pos
    assert np.hypot(*(back - there)[:2]) > 0.5  # beside it, not inside
    sandbox.step(120)
    assert world.physics.health.recoveries == 0
    assert not world.schedule.disabled()


def test_an_edit_that_refuses_stays_on_the_undo_stack() -> None:
    from ecs_tentacles.creatures.spawning import SpawnError
    from ecs_tentacles.render.undo import UndoStack

    class NoRoom:
        label = "remove 1"
        tries = 0

        def undo(self, world: Any) -> None:
            self.tries += 1
            if self.tries == 1:
                raise SpawnError(["creature 'a': no free spot within 3.0 m of (0, 0)"])

        def redo(self, world: Any) -> None:
            pass

    stack, edit = UndoStack(), NoRoom()
    stack.push(edit)
    with pytest.raises(SpawnError):
        stack.undo(None)
    assert stack.done == [edit] and not stack.undone
    assert stack.undo(None) == "remove 1" and stack.undone == [edit]
