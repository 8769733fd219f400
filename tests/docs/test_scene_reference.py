"""The generated scene reference (docs/hooks/scene_keys.py) has a row for every key of the
schema a scene is checked against: the core schema with every built-in plugin's keys, and
every game mode's `game` keys."""

from __future__ import annotations

import importlib.util
import re
from collections.abc import Iterator, Mapping
from pathlib import Path
from types import ModuleType
from typing import Any

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.scene.schema import schema_for

GENERATOR = Path(__file__).resolve().parents[2] / "docs" / "hooks" / "scene_keys.py"


def generator() -> ModuleType:
    spec = importlib.util.spec_from_file_location("scene_keys", GENERATOR)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def keys(node: Mapping[str, Any]) -> Iterator[str]:
    """Every property name under `node`, at any depth (through items and $defs)."""
    for name, child in node.get("properties", {}).items():
        yield name
        yield from keys(child)
        if isinstance(child.get("items"), Mapping):
            yield from keys(child["items"])
    for definition in node.get("$defs", {}).values():
        yield from keys(definition)


def test_every_key_of_every_plugin_is_a_row() -> None:
    scene_keys = generator()
    page = scene_keys.page()
    rows = {
        row.rpartition(".")[2].removesuffix("[]")
        for row in re.findall(r"^\| `([^`]+)`", page, flags=re.M)
    }
    plugins: list[Plugin] = []
    for cls in scene_keys.builtin_plugins().values():
        plugin = cls.__new__(cls)  # the class's schema only: some are made only by their layer
        Plugin.__init__(plugin)
        plugins.append(plugin)
    schema = schema_for(plugins)  # every built-in plugin on at once
    missing = set(keys(schema)) - rows
    assert missing == set(), f"keys the scene reference has no row for: {sorted(missing)}"
    assert "## Game mode `herding`" in page and "## Game mode `race`" in page
    assert "`game.need`" in page and "`game.flag.radius`" in page
