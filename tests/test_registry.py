"""Registries: every entry in a built world belongs to a plugin that is on, and its code
is that plugin's own (its feature's package, its systems included); a plugin turned off
or swapped leaves no entry behind."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from ecs_tentacles.cli.migrate import migrate
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.registry import App, Registries, Registry
from ecs_tentacles.scene.plugins import shipped
from ecs_tentacles.world import World

SCENES = Path(__file__).resolve().parent.parent / "assets" / "scenes"
# render needs a sandbox's renderer: tests/render/test_registries.py turns it on; a level
# plays one game mode (herding here): tests/race/ walks the race mode's world
EVERY = [key for key in shipped() if key not in ("render", "race")]


def _code(entry: Any) -> Iterator[Any]:
    """The callables an entry carries: itself, or a dataclass entry's callable fields."""
    if dataclasses.is_dataclass(entry) and not isinstance(entry, type):
        for field in dataclasses.fields(entry):
            value = getattr(entry, field.name)
            if callable(value):
                yield value
    elif callable(entry):
        yield entry


def _home(plugin: Plugin) -> tuple[str, ...]:
    """Module prefixes of a plugin's own code: its feature's package (its systems in
    `<feature>.systems`), or an example's own module."""
    module = type(plugin).__module__
    if module.startswith("ecs_tentacles_examples."):
        return (module,)
    return (module.rsplit(".", 1)[0] + ".",)


def strangers(world: Any) -> list[str]:
    """Every registry entry whose owner is not on, or whose code is not its owner's."""
    on = {plugin.key: plugin for plugin in world.plugins}
    problems = []
    for kind, registry in world.registries.all().items():
        for owner, entry in registry.items():
            plugin = on.get(owner)
            if plugin is None:
                problems.append(f"{kind.__name__}: {entry!r} owned by {owner!r}, not on")
                continue
            for code in _code(entry):
                bound = getattr(code, "__self__", None)
                if bound is not None and not isinstance(bound, type):
                    if bound is not plugin:
                        problems.append(f"{kind.__name__}: {code!r} is bound to another object")
                    continue
                module = getattr(code, "__module__", "") or ""
                if not module.startswith(_home(plugin)):
                    problems.append(f"{kind.__name__}: {code!r} ({module}) is not {owner}'s")
    return problems


@pytest.fixture(scope="module")
def everything_on() -> World:
    scene = json.loads((SCENES / "rocky_shore.json").read_text())
    scene["plugins"] = {key: {} for key in EVERY}
    scene["game"] = {"mode": "herding", "pen": {"centre": [9, 9], "radius": 1}, "need": 1,
                     "seconds": 30}  # fmt: skip
    with pytest.warns(Warning):  # the examples all steer goals, unordered among themselves
        return World.from_scene(scene)


def test_every_entry_of_a_world_with_every_plugin_on_is_its_owners(everything_on: World) -> None:
    kinds = everything_on.registries.all()
    assert len(kinds) >= 15, sorted(kind.__name__ for kind in kinds)  # the walk saw them
    assert sum(len(registry) for registry in kinds.values()) >= 20
    assert strangers(everything_on) == []


@pytest.mark.parametrize("off", ["locomotion", "fur", "threats", "terrain", "director"])
def test_a_plugin_turned_off_has_no_entry(off: str) -> None:
    scene = json.loads((SCENES / "rocky_shore.json").read_text())
    keys = [key for key in ("locomotion", "suckers", "threats", "fur", "clips", "terrain",
                            "director") if key != off]  # fmt: skip
    scene["plugins"] = {key: (key in keys and {}) for key in [*keys, off]}
    if off == "locomotion":
        scene["plugins"]["suckers"] = False  # suckers need locomotion
    world = World.from_scene(migrate(scene)[0])  # the keys of the plugin off dropped
    owners = {
        owner for registry in world.registries.all().values() for owner, _ in registry.items()
    }
    assert off not in owners
    assert strangers(world) == []


class Mine(Registry[str]):
    pass


class Owned(Plugin):
    name = "owned"

    def build(self, app: App) -> None:
        app.add(Mine, "an entry")


def test_dropping_a_plugin_takes_its_entries_and_no_others() -> None:
    registries = Registries()
    first, second = Owned(), Owned()
    first.key, second.key = "first", "second"
    Owned.build(first, App(registries, first))
    Owned.build(second, App(registries, second))
    assert [owner for owner, _ in registries.get(Mine).items()] == ["first", "second"]
    registries.drop("first")
    assert registries.get(Mine).items() == [("second", "an entry")]


def test_the_walk_finds_an_entry_of_a_plugin_not_on_and_one_of_another_features_code(
    everything_on: World,
) -> None:
    from ecs_tentacles.render.registries import Lines

    lines = everything_on.registry(Lines)
    fur = next(plugin for plugin in everything_on.plugins if plugin.key == "fur")
    lines.add("ghost", lambda world: [])  # a plugin that is not on
    lines.add("terrain", fur.build)  # terrain's entry, fur's code
    try:
        found = strangers(everything_on)
    finally:
        lines.drop("ghost")
        lines._items.pop()  # the last: terrain's borrowed entry
    assert len(found) == 2 and "'ghost', not on" in found[0] and "another object" in found[1]
    assert strangers(everything_on) == []
