"""The frame's system order: public stages, and names ordered inside each stage.

`Schedule.names` is the one place the order can be read (and it is tested). Stages
run in `STAGES` order; inside a stage, `after` / `before` order systems, and among the
systems whose constraints are met the one added earliest runs first. Ordering against
a system that is not scheduled is a no-op, so any system can be removed, replaced or
disabled. Two systems of one stage that write the same field with no order between
them get a `ScheduleWarning` (`Schedule.conflicts` lists them).

    world.schedule.disable("rig")              # stays listed, does not run
    world.schedule.replace("goals", MyGoals())  # takes its name and its place
    print(world.schedule.table())               # stage, system, plugin, reads, writes
"""

from __future__ import annotations

import warnings
from collections.abc import Iterator
from dataclasses import dataclass

from ecs_tentacles.system import DEFAULT_STAGE, STAGES, System


class ScheduleError(ValueError):
    """A system's declared place cannot be satisfied."""


class ScheduleWarning(UserWarning):
    """Two systems of one stage write the same field and nothing orders them."""


@dataclass
class _Slot:
    label: str  # the name others order against (a replacement keeps the replaced name)
    system: System
    enabled: bool = True
    declared: str | None = None  # the stage the system asked for
    stage: str = DEFAULT_STAGE  # the stage it runs in
    after: tuple[str, ...] = ()
    before: tuple[str, ...] = ()
    # what `after` / `before` mean now: set labels replaced by their members (`_resolve`)
    order_after: tuple[str, ...] = ()
    order_before: tuple[str, ...] = ()


class Schedule:
    """Systems in frame order."""

    def __init__(self) -> None:
        self._slots: list[_Slot] = []  # in the order added
        self._ordered: list[_Slot] = []
        self._running: list[System] = []
        self._substep: tuple[System, ...] = ()  # of `_running`, those with a substep hook
        self.conflicts: list[tuple[str, str, str]] = []  # (field, system, system)

    # -- changing ------------------------------------------------------------------------
    def add(self, *systems: System) -> None:
        """Add systems and re-resolve the order; raises ScheduleError on a bad place.

        Systems added together may name each other in `after` / `before`.
        """
        labels = [s.label for s in self._slots]
        slots = []
        for system in systems:
            if not system.name:
                raise ScheduleError(f"{type(system).__name__} has no name")
            if system.name in labels:
                raise ScheduleError(f"a system named {system.name!r} is already scheduled")
            if system.stage is not None and system.stage not in STAGES:
                raise ScheduleError(
                    f"system {system.name!r}: stage must be one of {', '.join(STAGES)},"
                    f" got {system.stage!r}"
                )
            labels.append(system.name)
            slots.append(
                _Slot(
                    system.name,
                    system,
                    True,
                    system.stage,
                    after=system.after,
                    before=system.before,
                )
            )
        self._resolve([*self._slots, *slots])

    def remove(self, name: str) -> System:
        """Take a system out of the frame; systems that ordered against it keep running."""
        slot = self._slot(name)
        self._resolve([s for s in self._slots if s is not slot])
        return slot.system

    def replace(self, name: str, system: System) -> System:
        """Put `system` in the place of the one scheduled as `name`; return the old one.

        The new system is scheduled under `name` (others keep ordering against it) and
        keeps the old stage and `after` / `before` unless it declares its own.
        """
        slot = self._slot(name)
        old = slot.system
        own = system.stage is not None or bool(system.after or system.before)
        new = _Slot(
            name,
            system,
            slot.enabled,
            system.stage if own else slot.declared,
            after=system.after if own else slot.after,
            before=system.before if own else slot.before,
        )
        self._resolve([new if s is slot else s for s in self._slots])
        return old

    def disable(self, name: str) -> None:
        """Stop running a system; it stays scheduled (and listed) until `enable`."""
        self._slot(name).enabled = False
        self._resolve(self._slots)

    def enable(self, name: str) -> None:
        """Run a disabled system again."""
        self._slot(name).enabled = True
        self._resolve(self._slots)

    # -- reading -------------------------------------------------------------------------
    def __getitem__(self, name: str) -> System:
        return self._slot(name).system

    def __contains__(self, name: object) -> bool:
        return any(s.label == name for s in self._slots)

    def __iter__(self) -> Iterator[System]:
        """The enabled systems, in frame order."""
        return iter(self._running)

    def __len__(self) -> int:
        return len(self._running)

    @property
    def names(self) -> list[str]:
        """Names of the systems that run, in the order they run each frame."""
        return [s.label for s in self._ordered if s.enabled]

    def label(self, system: System) -> str:
        """The name `system` is scheduled under."""
        for slot in self._slots:
            if slot.system is system:
                return slot.label
        raise KeyError(f"{system!r} is not scheduled")

    def disabled(self) -> list[str]:
        return [s.label for s in self._slots if not s.enabled]

    def stage_of(self, name: str) -> str:
        return self._slot(name).stage

    def substep_systems(self) -> tuple[System, ...]:
        """Enabled systems with a per-substep hook, in frame order."""
        return self._substep

    def rows(self) -> list[dict[str, str]]:
        """One row per scheduled system in frame order: its data flow, for `table`."""
        return [
            {
                "stage": slot.stage,
                "system": slot.label + ("" if slot.enabled else " (disabled)"),
                "plugin": slot.system.plugin or "-",
                "reads": compact(slot.system.reads)
                + (" + plugins' hook reads" if slot.system.calls_hooks else "")
                or "-",
                "writes": compact(slot.system.writes) or "-",
            }
            for slot in self._ordered
        ]

    def table(self) -> str:
        """The frame as a plain-text table: stage, system, plugin, reads, writes."""
        rows = self.rows()
        heads = ["stage", "system", "plugin", "reads", "writes"]
        widths = [max([len(h)] + [len(r[h]) for r in rows]) for h in heads[:-1]]
        lines = ["  ".join(h.ljust(w) for h, w in zip(heads, [*widths, 0], strict=True))]
        for row in rows:
            cells = [row[h].ljust(w) for h, w in zip(heads[:-1], widths, strict=True)]
            lines.append("  ".join([*cells, row["writes"]]))
        return "\n".join(line.rstrip() for line in lines)

    def _slot(self, name: str) -> _Slot:
        for slot in self._slots:
            if slot.label == name:
                return slot
        labels = ", ".join(s.label for s in self._ordered)
        raise KeyError(f"no system named {name!r}; scheduled: {labels}")

    # -- resolving -----------------------------------------------------------------------
    def _resolve(self, slots: list[_Slot]) -> None:
        by_label = {s.label: s for s in slots}
        _expand_sets(slots, by_label)
        _assign_stages(slots, by_label)
        ordered: list[_Slot] = []
        for stage in STAGES:
            ordered += _order_stage([s for s in slots if s.stage == stage], by_label)
        conflicts = _unordered_writers(ordered, by_label)
        for field, first, second in conflicts:
            if (field, first, second) not in self.conflicts:
                warnings.warn(
                    f"systems {first!r} and {second!r} both write {field!r} in stage"
                    f" {by_label[first].stage!r} and nothing orders them; add after/before",
                    ScheduleWarning,
                    stacklevel=3,
                )
        self._slots, self._ordered, self.conflicts = slots, ordered, conflicts
        self._running = [s.system for s in ordered if s.enabled]
        self._substep = tuple(s for s in self._running if type(s).has_substep())


def _expand_sets(slots: list[_Slot], by_label: dict[str, _Slot]) -> None:
    """Each slot's `after` / `before` with set labels (`System.sets`) replaced by the
    systems in the set (itself aside): a feature orders against the labels others
    export, not against their systems' names. A label is a set or a system, never both."""
    members: dict[str, list[str]] = {}
    for slot in slots:
        for label in slot.system.sets:
            if label in by_label:
                raise ScheduleError(
                    f"system {slot.label!r}: set {label!r} has the name of a system"
                )
            members.setdefault(label, []).append(slot.label)
    for slot in slots:
        slot.order_after = tuple(
            n for name in slot.after for n in members.get(name, [name]) if n != slot.label
        )
        slot.order_before = tuple(
            n for name in slot.before for n in members.get(name, [name]) if n != slot.label
        )


def _assign_stages(slots: list[_Slot], by_label: dict[str, _Slot]) -> None:
    """Declared stages as given; the others from the systems they order against."""
    free = [s for s in slots if s.declared is None]
    for slot in slots:
        if slot.declared is not None:
            slot.stage = slot.declared
    for slot in free:
        slot.stage = ""
    for _ in range(len(free) + 1):  # inferred stages can chain; settles in len(free) rounds
        for slot in free:
            after = [
                by_label[n].stage for n in slot.order_after if n in by_label and by_label[n].stage
            ]
            before = [
                by_label[n].stage for n in slot.order_before if n in by_label and by_label[n].stage
            ]
            if after:
                slot.stage = max(after, key=STAGES.index)
            elif before:
                slot.stage = min(before, key=STAGES.index)
    for slot in free:
        slot.stage = slot.stage or DEFAULT_STAGE


def _order_stage(members: list[_Slot], by_label: dict[str, _Slot]) -> list[_Slot]:
    """Stable topological sort of one stage; ordering across stages must agree with them."""
    rank = STAGES.index
    inside = {s.label for s in members}
    preds: dict[str, set[str]] = {s.label: set() for s in members}
    for slot in members:
        for other, slot_first in [(n, False) for n in slot.order_after] + [
            (n, True) for n in slot.order_before
        ]:
            target = by_label.get(other)
            if target is None:
                continue  # ordering against an absent system is a no-op
            if other in inside:
                (preds[other] if slot_first else preds[slot.label]).add(
                    slot.label if slot_first else other
                )
            elif (rank(target.stage) > rank(slot.stage)) != slot_first:
                word = "before" if slot_first else "after"
                raise ScheduleError(
                    f"system {slot.label!r} (stage {slot.stage}) cannot run {word} {other!r}"
                    f" (stage {target.stage}): stages run in the order {', '.join(STAGES)}"
                )
    ordered: list[_Slot] = []
    placed: set[str] = set()
    while len(ordered) < len(members):
        ready = [s for s in members if s.label not in placed and preds[s.label] <= placed]
        if not ready:
            stuck = sorted(n for n in preds if n not in placed)
            raise ScheduleError(f"systems {', '.join(stuck)} wait on each other (a cycle)")
        ordered.append(ready[0])
        placed.add(ready[0].label)
    return ordered


def _unordered_writers(
    ordered: list[_Slot], by_label: dict[str, _Slot]
) -> list[tuple[str, str, str]]:
    """(field, first, second) for enabled same-stage writers with no path between them."""
    edges: dict[str, set[str]] = {s.label: set() for s in ordered}
    for slot in ordered:
        for other in slot.order_after:
            if other in by_label and by_label[other].stage == slot.stage:
                edges[other].add(slot.label)
        for other in slot.order_before:
            if other in by_label and by_label[other].stage == slot.stage:
                edges[slot.label].add(other)

    def reaches(start: str, end: str) -> bool:
        stack, seen = [start], set()
        while stack:
            here = stack.pop()
            if here == end:
                return True
            if here not in seen:
                seen.add(here)
                stack.extend(edges[here])
        return False

    found = []
    writers = [s for s in ordered if s.enabled and s.system.writes]
    for i, first in enumerate(writers):
        for second in writers[i + 1 :]:
            if first.stage != second.stage:
                continue
            for field in sorted(set(first.system.writes) & set(second.system.writes)):
                if not reaches(first.label, second.label) and not reaches(
                    second.label, first.label
                ):
                    found.append((field, first.label, second.label))
    return found


def compact(names: tuple[str, ...]) -> str:
    """Declared names, columns of one store grouped: `motors.{target, gain}, goals`."""
    groups: dict[str, list[str]] = {}
    for name in names:
        store, dot, field = name.rpartition(".")
        groups.setdefault(store if dot else name, []).append(field if dot else "")
    parts = []
    for store, fields in groups.items():
        if fields == [""]:
            parts.append(store)
        elif len(fields) == 1:
            parts.append(f"{store}.{fields[0]}")
        else:
            parts.append(f"{store}.{{{', '.join(fields)}}}")
    return ", ".join(parts)
