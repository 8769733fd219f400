"""The creator window, driven by synthesised clicks: build, pick, edit, export."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from pyglet.event import EventDispatcher
from pyglet.window import mouse

from ecs_tentacles.components import Creature, Link, Tentacle
from ecs_tentacles.creator import CreatureDesign
from ecs_tentacles.scene.validate import validate_scene
from ecs_tentacles.world import World


@pytest.fixture
def creator(tmp_path: Path) -> Iterator[Any]:
    from ecs_tentacles.creator.window import Creator

    window = Creator(
        CreatureDesign(name="squid"), tmp_path / "squid.json", width=960, height=600, headless=True
    )
    yield window
    window.close()


def _press(creator: Any, widget: Any, fraction: float = 0.5) -> None:
    """Click a widget (a slider at `fraction` of its track)."""
    edge = getattr(widget, "_edge", 0)
    x = widget.x + edge + fraction * (widget.width - 2 * edge)
    y = widget.y + widget.height / 2
    for event in ("on_mouse_press", "on_mouse_release"):
        EventDispatcher.dispatch_event(creator.window, event, round(x), round(y), mouse.LEFT, 0)


def _button(creator: Any, text: str) -> Any:
    """The push button whose caption is `text`."""
    labels = [label for label in creator._keep if label.text == text]
    assert len(labels) == 1
    label = labels[0]
    for widget in creator.buttons:
        inside_x = widget.x <= label.x <= widget.x + widget.width
        if inside_x and widget.y <= label.y <= widget.y + widget.height:
            return widget
    raise AssertionError(f"no button {text!r}")


def test_creator_builds_edits_and_exports_what_it_shows(creator: Any) -> None:
    _press(creator, creator.uniform["count"][0], 5 / 15)  # about 6 tentacles
    _press(creator, creator.uniform["links"][0], 7 / 29)  # about 8 links
    count, links = int(creator.slider_value("count")), int(creator.slider_value("links"))
    assert 5 <= count <= 7 and 7 <= links <= 9  # moved from the defaults (8, 10)
    _press(creator, _button(creator, "Build creature"))
    design = creator.design
    assert (len(design.tentacles), design.uniform.links) == (count, links)
    _press(creator, _button(creator, ">"))
    _press(creator, _button(creator, ">"))  # tentacle 1
    assert design.selected == 1
    _press(creator, _button(creator, "+ link"))
    _press(creator, _button(creator, "+ link"))
    _press(creator, creator.per_tentacle["end_scale"][0], 0.9)
    end_scale = creator.slider_value("end_scale", "tentacle")
    assert 0.8 < end_scale < 1.0
    assert design.tentacles[1].links == links + 2
    assert design.tentacles[1].end_scale == pytest.approx(end_scale, abs=1e-12)
    assert creator.selection.text == f"tentacle 1 ({links + 2} links)"
    # the preview is the exported creature, with tentacle 1 drawn in yellow
    shown = creator.renderer.link_instances
    assert (shown[:, 11:14] == np.float32([1.0, 0.85, 0.2])).all(axis=1).sum() == links + 2
    _press(creator, _button(creator, "Export"))
    scene = json.loads(creator.out.read_text())
    assert validate_scene(scene) == [] and scene == design.scene()
    world = World.from_scene(scene)
    creature = world.component(world.creature("squid"), Creature)
    links_built = [len(world.component(t, Tentacle).links) for t in creature.tentacles]
    assert links_built == [links, links + 2] + [links] * (count - 2)
    tip = world.component(world.component(creature.tentacles[1], Tentacle).links[-1], Link)
    assert tip.scale == pytest.approx(end_scale, abs=1e-12)
    world.close()
    assert creator.status.text == f"exported {creator.out}"


def test_refused_value_shows_its_message(creator: Any) -> None:
    _press(creator, _button(creator, "+ link"))  # nothing selected
    assert creator.status.text == "tentacle: no tentacle selected"
