"""The sandbox's undo stack: Ctrl+Z undoes the last edit, Ctrl+Shift+Z does it again.

An edit is an `Edit`: something that can be undone and redone (`undo(world)`,
`redo(world)`), with a label the sandbox prints. Two kinds exist:

* `Memento`: what the plugins keep of the world's directable state (goals, tentacle
  parameters: the plugins' `UndoStates` entries), before and after one
  click or slider drag; `Sandbox.edit` makes them;
* the director's roster edits (spawn, despawn, move: `ecs_tentacles.director.commands`).

The physics is not rewound: creatures stay where they are; the roster, goals and
settings go back. Creatures are named, not numbered, in edits, so an edit still
applies after an undo spawned a creature again (with a new entity). A new edit drops
what was undone. Reads and writes only through the edits.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol

from ecs_tentacles.render.registries import UndoStates

if TYPE_CHECKING:
    from ecs_tentacles.world import World

LIMIT = 200  # edits kept
MERGE_SECONDS = 1.0  # a slider dragged: one edit while it keeps changing this often


class Edit(Protocol):
    label: str

    def undo(self, world: World) -> None: ...
    def redo(self, world: World) -> None: ...


def plugin_state(world: World) -> dict[tuple[str, int], object]:
    """Every plugin's directable state (its `UndoStates` entries), by (plugin key, entry)."""
    found = {}
    for index, (owner, undo) in enumerate(world.registry(UndoStates).items()):
        state = undo.capture(world)
        if state is not None:
            found[(owner, index)] = state
    return found


def restore_plugin_state(world: World, state: dict[tuple[str, int], object]) -> None:
    for index, (owner, undo) in enumerate(world.registry(UndoStates).items()):
        if (owner, index) in state:
            undo.restore(world, state[(owner, index)])


@dataclass
class Memento:
    """The plugins' directable state before and after one edit."""

    label: str
    before: dict[tuple[str, int], object]
    after: dict[tuple[str, int], object]
    at: float = field(default_factory=time.monotonic)

    def undo(self, world: World) -> None:
        restore_plugin_state(world, self.before)

    def redo(self, world: World) -> None:
        restore_plugin_state(world, self.after)


class UndoStack:
    """Edits done (newest last) and undone (redo takes the newest)."""

    def __init__(self) -> None:
        self.done: list[Edit] = []
        self.undone: list[Edit] = []

    def push(self, edit: Edit) -> None:
        """A new edit: it can be undone; what was undone can no longer be redone."""
        self.done.append(edit)
        del self.done[:-LIMIT]
        self.undone.clear()

    def record(self, world: World, label: str, action: Callable[[], object]) -> object:
        """Run `action` (an edit of goals or parameters) and keep the plugins' state
        before and after it as one edit; nothing is kept if nothing changed. A slider
        dragged (the same label again within `MERGE_SECONDS`) stays one edit."""
        before = plugin_state(world)
        result = action()
        after = plugin_state(world)
        if _same(before, after):
            return result
        last = self.done[-1] if self.done else None
        if (
            isinstance(last, Memento)
            and last.label == label
            and time.monotonic() - last.at < MERGE_SECONDS
            and not self.undone
        ):
            last.after, last.at = after, time.monotonic()
            return result
        self.push(Memento(label, before, after))
        return result

    def undo(self, world: World) -> str | None:
        """Undo the newest edit; its label, or None when there is nothing to undo."""
        if not self.done:
            return None
        edit = self.done[-1]
        edit.undo(world)  # an edit that refuses (raises) stays where it was
        self.undone.append(self.done.pop())
        return edit.label

    def redo(self, world: World) -> str | None:
        """Do the newest undone edit again; its label, or None."""
        if not self.undone:
            return None
        edit = self.undone[-1]
        edit.redo(world)
        self.done.append(self.undone.pop())
        return edit.label


def _same(a: object, b: object) -> bool:
    """Deep equality that compares numpy arrays by value."""
    import numpy as np

    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return bool(np.array_equal(np.asarray(a), np.asarray(b)))
    return bool(a == b)
