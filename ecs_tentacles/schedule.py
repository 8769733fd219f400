"""The frame's system order, resolved once from the names systems declare.

`Schedule.names` is the one place the order can be read (and it is tested). Among the
systems whose constraints are met, the one added earliest runs first.
"""

from __future__ import annotations

from collections.abc import Iterator

from ecs_tentacles.system import System


class ScheduleError(ValueError):
    """A system's declared place cannot be satisfied."""


class Schedule:
    """Systems in frame order."""

    def __init__(self) -> None:
        self._added: list[System] = []
        self._ordered: list[System] = []

    def add(self, *systems: System) -> None:
        """Add systems and re-resolve the order; raises ScheduleError on a bad place.

        Systems added together may name each other in `after` / `before`.
        """
        names = [s.name for s in self._added]
        for system in systems:
            if not system.name:
                raise ScheduleError(f"{type(system).__name__} has no name")
            if system.name in names:
                raise ScheduleError(f"a system named {system.name!r} is already scheduled")
            names.append(system.name)
        self._ordered = _resolve([*self._added, *systems])
        self._added.extend(systems)

    def remove(self, name: str) -> System:
        """Remove a system by name (other systems may not depend on it)."""
        system = self[name]
        rest = [s for s in self._added if s is not system]
        self._ordered = _resolve(rest)
        self._added = rest
        return system

    def __getitem__(self, name: str) -> System:
        for system in self._added:
            if system.name == name:
                return system
        raise KeyError(f"no system named {name!r}; scheduled: {', '.join(self.names)}")

    def __contains__(self, name: object) -> bool:
        return any(s.name == name for s in self._added)

    def __iter__(self) -> Iterator[System]:
        return iter(self._ordered)

    def __len__(self) -> int:
        return len(self._ordered)

    @property
    def names(self) -> list[str]:
        """System names in the order they run each frame."""
        return [s.name for s in self._ordered]

    def substep_systems(self) -> list[System]:
        """Systems with a per-substep hook, in frame order."""
        return [s for s in self._ordered if type(s).has_substep()]


def _resolve(systems: list[System]) -> list[System]:
    """Stable topological sort of `systems` by their `after` / `before` names."""
    by_name = {s.name: s for s in systems}
    preds: dict[str, set[str]] = {s.name: set() for s in systems}
    for s in systems:
        for other in s.after:
            if other not in by_name:
                raise ScheduleError(
                    f"system {s.name!r} runs after {other!r}, which is not scheduled"
                )
            preds[s.name].add(other)
        for other in s.before:
            if other not in by_name:
                raise ScheduleError(
                    f"system {s.name!r} runs before {other!r}, which is not scheduled"
                )
            preds[other].add(s.name)
    ordered: list[System] = []
    placed: set[str] = set()
    while len(ordered) < len(systems):
        ready = [s for s in systems if s.name not in placed and preds[s.name] <= placed]
        if not ready:
            stuck = sorted(n for n in preds if n not in placed)
            raise ScheduleError(f"systems {', '.join(stuck)} wait on each other (a cycle)")
        ordered.append(ready[0])
        placed.add(ready[0].name)
    return ordered
