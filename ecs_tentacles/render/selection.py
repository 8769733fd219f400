"""The sandbox's selection: one or many creatures, the last picked first among them.

    selection.only(octo)          # a click on a creature
    selection.toggle(squid)       # shift-click: in or out
    selection.replace(entities)   # a rectangle, Ctrl+A (every creature), Esc (none)
    selection.primary             # the HUD's creature (sliders, labels), or None

The HUD's locomotion sliders apply to every selected creature, a goal click sends
them all (in formation, `ecs_tentacles.locomotion.formations`), the level of detail
runs them all at full physics. Creatures that are despawned leave the selection.
Reads and writes nothing of the world.
"""

from __future__ import annotations

from collections.abc import Iterable


class Selection:
    """Selected creature entities in the order they were picked."""

    def __init__(self) -> None:
        self._entities: list[int] = []

    @property
    def entities(self) -> tuple[int, ...]:
        return tuple(self._entities)

    @property
    def primary(self) -> int | None:
        """The creature picked last (the HUD shows its values), or None."""
        return self._entities[-1] if self._entities else None

    def only(self, creature: int | None) -> None:
        """Select just `creature` (None: nothing)."""
        self._entities = [] if creature is None else [creature]

    def replace(self, creatures: Iterable[int]) -> None:
        """Select `creatures` (in that order; repeats dropped)."""
        self._entities = list(dict.fromkeys(creatures))

    def toggle(self, creature: int) -> None:
        """Add `creature` (as the primary), or take it out if it is selected."""
        if creature in self._entities:
            self._entities.remove(creature)
        else:
            self._entities.append(creature)

    def discard(self, creature: int) -> None:
        """Take `creature` out if it is selected (it was despawned)."""
        if creature in self._entities:
            self._entities.remove(creature)

    def __contains__(self, creature: object) -> bool:
        return creature in self._entities

    def __len__(self) -> int:
        return len(self._entities)
