"""The sandbox's world, its renderer and director on: every registry entry is owned by
a plugin that is on and is that plugin's code (tests/test_registry.py walks them)."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from tests.test_registry import strangers


def test_the_sandbox_world_with_its_renderer_is_its_owners(
    make_sandbox: Callable[..., Any],
) -> None:
    world = make_sandbox("rocky_shore").world
    assert {"render", "director", "terrain"} <= {plugin.key for plugin in world.plugins}
    assert sum(len(registry) for registry in world.registries.all().values()) >= 20
    assert strangers(world) == []
