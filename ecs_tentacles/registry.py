"""Registries: what a layer calls, filled by the plugins in their `build(app)`.

A registry is defined by the layer that calls its entries, in that layer's package
(the renderer's spheres, lines, draws and framing points, the sandbox's panels, clicks
and undo states: `ecs_tentacles.render.registries`); core defines none of them and
names none. A plugin adds entries in `Plugin.build(app)`:

    class Beacon(Plugin):
        name = "beacon"

        def build(self, app):
            from ecs_tentacles.render.registries import Spheres

            app.add(Spheres, beacon_spheres)

and the layer reads every entry, in plugin order: `for spheres in world.registry(Spheres)`.
Each entry remembers the plugin that added it (`items()`), so a plugin swapped by a
reload takes its own entries with it (`drop`) and nothing outlives the plugin it came
from.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import Any, Generic, Protocol, TypeVar

Entry = TypeVar("Entry")
R = TypeVar("R", bound="RegistryLike")


class RegistryLike(Protocol):
    """What `Registries` knows of a registry whatever its entries are (a `Registry[E]` is
    one): it forgets a plugin's entries and lists them with their owners."""

    def drop(self, owner: str) -> None: ...
    def items(self) -> Sequence[tuple[str, object]]: ...
    def __len__(self) -> int: ...


class Registry(Generic[Entry]):
    """Entries of one kind, each with the key of the plugin that added it. Subclass it
    (one class per kind, in the package of the layer that calls the entries)."""

    def __init__(self) -> None:
        self._items: list[tuple[str, Entry]] = []

    def add(self, owner: str, entry: Entry) -> None:
        """`entry`, added by the plugin on as `owner`."""
        self._items.append((owner, entry))

    def drop(self, owner: str) -> None:
        """Forget every entry plugin `owner` added."""
        self._items = [(key, entry) for key, entry in self._items if key != owner]

    def items(self) -> list[tuple[str, Entry]]:
        """(owner plugin key, entry) pairs, in the order they were added."""
        return list(self._items)

    def __iter__(self) -> Iterator[Entry]:
        return iter([entry for _, entry in self._items])

    def __len__(self) -> int:
        return len(self._items)


class Registries:
    """A world's registries, one per kind, made empty when first asked for."""

    def __init__(self) -> None:
        self._kinds: dict[type[RegistryLike], RegistryLike] = {}

    def get(self, kind: type[R]) -> R:
        """The world's `kind` registry."""
        found = self._kinds.get(kind)
        if found is None:
            found = self._kinds[kind] = kind()
        return found  # type: ignore[return-value]  # made as `kind` above

    def drop(self, owner: str) -> None:
        """Forget every entry plugin `owner` added, in every registry."""
        for registry in self._kinds.values():
            registry.drop(owner)

    def all(self) -> dict[type[RegistryLike], RegistryLike]:
        """Every registry made so far, by kind."""
        return dict(self._kinds)


class Owner(Protocol):
    """What an `App` needs of the plugin it builds (`ecs_tentacles.plugin.Plugin`)."""

    key: str
    config: dict[str, object]


class App:
    """What a plugin's `build(app)` registers into: registries (a world's, or a planner's
    that builds plugins without a world), each entry marked as the plugin's own.
    `world`: the world being built, None when there is none (a bake's shard planner)."""

    def __init__(self, registries: Registries, plugin: Owner, world: Any = None) -> None:
        self.registries = registries
        self.plugin = plugin
        self.world = world

    @property
    def config(self) -> dict[str, object]:
        """The plugin's `plugins.<name>` config, defaults filled in."""
        return self.plugin.config

    def add(self, kind: type[Registry[Entry]], entry: Entry) -> None:
        """Add `entry` to the `kind` registry, as this plugin's."""
        self.registries.get(kind).add(self.plugin.key, entry)
