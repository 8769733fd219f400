"""The fur tool driven like a user: synthesized clicks, typing and drags, headless."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.testing import assert_allclose
from pyglet.window import key, mouse

from ecs_tentacles.components import Creature, Transform
from ecs_tentacles.fur.components import FurControl
from ecs_tentacles.fur.controls import nearest_control
from ecs_tentacles.fur.render.furpanel import FurPanel
from ecs_tentacles.fur.stores import FurData
from ecs_tentacles.numeric.quaternions import quat_rotate
from ecs_tentacles.scene.load import load_scene
from ecs_tentacles.world import World
from tests.render.conftest import click_item, event


def tool(make_sandbox: Callable[..., Any]) -> Any:
    """The hedgehog in a tall window, paused after one frame, the Fur section opened (the
    others fold)."""
    sandbox = make_sandbox("hedgehog_octopus", width=1280, height=1440)
    sandbox.step(1)
    sandbox.paused = True
    sandbox.render()
    click_item(sandbox, "Fur")
    assert "speed" not in sandbox.hud.gui.rects
    return sandbox


def fur_panel(sandbox: Any) -> FurPanel:
    """The fur plugin's HUD section (its `Panels` entry made it)."""
    panel = sandbox.panel("Fur")
    assert isinstance(panel, FurPanel)
    return panel


def type_text(sandbox: Any, field: str, text: str) -> None:
    """Click a text field, select what it holds and type `text` over it."""
    click_item(sandbox, field)
    for name, symbol, modifiers in [
        ("on_key_press", key.LCTRL, key.MOD_CTRL),  # ctrl+a, as a keyboard sends it
        ("on_key_press", key.A, key.MOD_CTRL),
        ("on_key_release", key.A, key.MOD_CTRL),
        ("on_key_release", key.LCTRL, 0),
    ]:
        event(sandbox, name, symbol, modifiers)
        sandbox.render()
    event(sandbox, "on_text", text)
    sandbox.render()
    event(sandbox, "on_key_press", key.RETURN, 0)
    sandbox.render()
    event(sandbox, "on_key_release", key.RETURN, 0)
    sandbox.render()


def local_to_pixels(sandbox: Any, local: np.ndarray) -> np.ndarray:
    world = sandbox.world
    row = world.component(world.creature("hedgehog"), Transform).row
    points = world.transforms.pos[row] + quat_rotate(world.transforms.quat[row], local[None])
    return np.asarray(sandbox.renderer.camera.project(points)[0])


def expected_assignment(world: World, editor: Any) -> np.ndarray:
    """Every hedgehog guide's nearest control, computed here from the stores."""
    rows = editor.rows()
    names, control_rows = list(rows), np.array(list(rows.values()))
    g = world.resource(FurData).guides
    mine = g.fur_row == g.fur_row[0]
    nearest = nearest_control(
        g.root[mine], world.resource(FurData).controls.rest_position[control_rows]
    )
    return np.array(names)[nearest]


def test_create_a_mirrored_control_and_drag_it(make_sandbox: Callable[..., Any]) -> None:
    sandbox = tool(make_sandbox)
    editor = fur_panel(sandbox).editor
    assert editor.creature == "hedgehog" and editor.control_names() == ["crown", "spine"]
    click_item(sandbox, "create section")
    type_text(sandbox, "new name", "L_ear")
    click_item(sandbox, "mirror y")
    click_item(sandbox, "shape cube")
    click_item(sandbox, "create")
    assert editor.control_names() == ["crown", "spine", "L_ear", "R_ear"]
    assert editor.control == "L_ear"
    spec = editor.fur_spec()["controls"][-1]
    assert (spec["name"], spec["mirror"], spec["shape"]) == ("L_ear", "y", "cube")
    left, right = editor.value("L_ear", "position"), editor.value("R_ear", "position")
    assert_allclose(right, left * [1, -1, 1])
    assert left[1] > 0.05  # on the left side of the body, its twin on the right
    before = editor.assignment()
    assert (before == expected_assignment(sandbox.world, editor)).all()
    # drag L_ear from where it is to the rear of the back
    start = local_to_pixels(sandbox, left)
    target_local = np.array([-0.12, 0.1, 0.3])
    end = local_to_pixels(sandbox, target_local)
    event(sandbox, "on_mouse_press", round(start[0]), round(start[1]), mouse.LEFT, 0)
    assert fur_panel(sandbox).dragging
    for f in np.linspace(0.2, 1.0, 5):
        x, y = start + f * (end - start)
        event(sandbox, "on_mouse_drag", round(x), round(y), 1, 1, mouse.LEFT, 0)
    event(sandbox, "on_mouse_release", round(end[0]), round(end[1]), mouse.LEFT, 0)
    assert not fur_panel(sandbox).dragging
    moved = editor.value("L_ear", "position")
    assert moved[0] < -0.05 and moved[1] > 0.0  # now at the rear, still on the left
    assert_allclose(editor.value("R_ear", "position"), moved * [1, -1, 1])
    assert_allclose(editor.fur_spec()["controls"][-1]["position"], moved)
    after = editor.assignment()
    assert (after == expected_assignment(sandbox.world, editor)).all()
    assert (after != before).any()
    assert (after == "spine").sum() < (before == "spine").sum()  # the ears took rear guides
    g = sandbox.world.resource(FurData).guides
    roots = g.root[g.fur_row == g.fur_row[0]]
    for name, side in (("L_ear", 1), ("R_ear", -1)):  # at the rear of their own side
        assert roots[before == name, 0].mean() > 0.0 > roots[after == name, 0].mean()
        assert (side * roots[after == name, 1] > 0).all()
    assert (
        sandbox.world.resource(FurData).version > 0
        and sandbox.world.schedule["rig"].bind is not None
    )


def test_two_slow_in_keys_play_back_as_the_tracks_evaluate(
    make_sandbox: Callable[..., Any],
) -> None:
    sandbox = tool(make_sandbox)
    editor, timeline = fur_panel(sandbox).editor, fur_panel(sandbox).timeline
    row = editor.rows()["crown"]
    lift = sandbox.world.resource(FurData).controls.lift
    click_item(sandbox, "easing slow_in")
    assert timeline.easing == 3
    click_item(sandbox, "scrubber", 0.1)
    first_time = timeline.time
    click_item(sandbox, "lift", 0.2)
    first = float(lift[row])
    click_item(sandbox, "set key")
    click_item(sandbox, "scrubber", 0.7)
    second_time = timeline.time
    assert float(lift[row]) == first  # after the only key: its value holds
    click_item(sandbox, "lift", 0.8)
    second = float(lift[row])
    click_item(sandbox, "set key")
    assert 0.1 < first < 0.3 and 0.7 < second < 0.9 and 0.3 < first_time < second_time
    keys = editor.keys("crown", "lift")
    assert [(k["time"], k["value"], k["easing"]) for k in keys] == [
        (round(first_time, 6), first, "slow_in"),
        (round(second_time, 6), second, "slow_in"),
    ]
    assert editor.key_times() == [k["time"] for k in keys]
    click_item(sandbox, "scrubber", 0.4)
    mid = timeline.time
    u = (mid - keys[0]["time"]) / (keys[1]["time"] - keys[0]["time"])
    assert 0.3 < u < 0.7
    slow_in = first + (second - first) * (1 - (1 - u) ** 2)
    assert float(lift[row]) == float(editor.track_value("crown", "lift", mid)[0])
    assert abs(float(lift[row]) - slow_in) < 1e-9
    click_item(sandbox, "delete key")  # nothing within a frame of the current time
    assert len(editor.keys("crown", "lift")) == 2
    click_item(sandbox, "play")
    assert not sandbox.paused and sandbox.world.schedule["rig"].track_time is None


def test_save_reloads_to_the_same_fur(make_sandbox: Callable[..., Any], tmp_path: Path) -> None:
    sandbox = tool(make_sandbox)
    panel = fur_panel(sandbox)
    editor = panel.editor
    editor.create("tuft", count=2, shape="arrow", mirror="x")
    editor.set_value("tuft_0", "lift", 0.6)
    editor.set_position("tuft_1_mirror", [-0.05, 0.02, 0.25])
    editor.set_key("crown", "random", 0.5, "step")
    panel.save_path = str(tmp_path / "edited.json")
    sandbox.render()
    click_item(sandbox, "save")
    assert panel.message == f"saved {tmp_path / 'edited.json'}"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["edited.json"]  # no partial files
    saved = load_scene(tmp_path / "edited.json")
    reference = saved.pop("$schema")  # rewritten to reach the bundled schema from there
    assert (tmp_path / reference).is_file()
    assert saved == {k: v for k, v in editor.scene.items() if k != "$schema"}
    reloaded = World.from_scene(tmp_path / "edited.json")
    try:
        edited = sandbox.world
        for world in (edited, reloaded):
            world.schedule["rig"].play_tracks = True
        by_root = {}
        for world in (edited, reloaded):
            g = world.resource(FurData).guides
            names = {row: name for name, row in _rows(world).items()}
            order = np.lexsort(g.root.T)
            by_root[id(world)] = (g.root[order], [names[int(r)] for r in g.control_row[order]])
            world.step(3)
        assert_allclose(by_root[id(edited)][0], by_root[id(reloaded)][0])
        assert by_root[id(edited)][1] == by_root[id(reloaded)][1]
        for name in ("lift", "position", "rest_position", "random", "emotion"):
            a, b = (
                getattr(edited.resource(FurData).controls, name),
                getattr(reloaded.resource(FurData).controls, name),
            )
            rows_a, rows_b = _rows(edited), _rows(reloaded)
            assert rows_a.keys() == rows_b.keys()
            assert_allclose(a[list(rows_a.values())], b[list(rows_b.values())], atol=1e-12)
    finally:
        reloaded.close()


def _rows(world: World) -> dict[str, int]:
    """Control rows by "creature/control" name."""
    return {
        f"{world.component(c.creature, Creature).name}/{c.name}": c.row
        for _, c in world.query(FurControl)
    }


def test_the_timeline_shows_only_for_a_creature_with_fur(make_sandbox: Callable[..., Any]) -> None:
    import json

    from ecs_tentacles.scene.load import bundled_scene

    scene = json.loads(bundled_scene("hedgehog_octopus").read_text())
    bare = {"name": "bare", "position": [3.0, 0.0]}  # no fur
    scene["creatures"].append(bare)
    sandbox = make_sandbox(scene)
    sandbox.select(sandbox.world.creature("hedgehog"))
    sandbox.render()
    assert "timeline" in sandbox.hud.gui.windows
    sandbox.select(sandbox.world.creature("bare"))
    sandbox.hud.unfold("Fur")
    sandbox.render()
    assert "no fur" in sandbox.hud.gui.rects  # the section says so
    assert "timeline" not in sandbox.hud.gui.windows  # and shows no timeline


def test_only_the_edited_creatures_controls_are_drawn(make_sandbox: Callable[..., Any]) -> None:
    """A crowd's every control drawn was clutter: the markers follow the fur tool."""
    import json

    from ecs_tentacles.fur.render.strands import fur_display, fur_lines
    from ecs_tentacles.scene.load import bundled_scene

    scene = json.loads(bundled_scene("hedgehog_octopus").read_text())
    twin = json.loads(json.dumps(scene["creatures"][0]))
    twin.update(name="twin", position=[3.0, 0.0])
    scene["creatures"].append(twin)
    sandbox = make_sandbox(scene)
    sandbox.step(1)
    world = sandbox.world
    mantle = {n: world.component(world.creature(n), Transform).row for n in ("hedgehog", "twin")}

    def drawn_near() -> set[str]:
        (lines,) = fur_lines(world, sandbox.renderer.render_view)
        assert len(lines)
        centres = world.transforms.pos[list(mantle.values())]
        nearest = np.argmin(
            np.linalg.norm(lines[:, None, :3] - centres[None].astype(np.float32), axis=2), axis=1
        )
        return {list(mantle)[k] for k in set(nearest.tolist())}

    for name in ("hedgehog", "twin"):
        sandbox.select(world.creature(name))
        sandbox.render()
        assert fur_display(sandbox.renderer.state).creature == world.creature(name)
        assert drawn_near() == {name}


def test_the_children_slider_never_offers_more_child_hairs_than_a_scene_may_have() -> None:
    from ecs_tentacles.fur.checks import MAX_SCENE_CHILDREN
    from ecs_tentacles.fur.render.furpanel import children_slider_most

    assert children_slider_most(1_500) == 16  # the bundled furs: the full range
    assert children_slider_most(0) == 16
    for guides in (62_500, 62_501, 100_000, 500_000):
        most = children_slider_most(guides)
        assert guides * most <= MAX_SCENE_CHILDREN < guides * (most + 1) or most == 16
    assert children_slider_most(500_000) == 2  # was 16: 8 million children, about 5 GB
