"""Locomotion parameters, read and changed at run time (the HUD and scripts use this).

    world.resource(Locomotion).set(octo, speed=1.5)                    # the creature's speed
    world.resource(Locomotion).set(octo, tentacle=2, strength=12.0)    # one tentacle's servo kp
    world.resource(Locomotion).set(octo, wave_amplitude=0.2)           # every tentacle
    world.resource(Locomotion).set(octo, gait="cyclic")
    world.resource(Locomotion).actions(octo)                           # what each tentacle is doing

Angles are radians here (scenes use degrees). Which names exist, their ranges, units,
taper and which are creature-wide all come from the parameter table
(`ecs_tentacles.scene.parameters`, read from the scene schema): a parameter stored per
creature is set per creature; `speed` names both the creature's (without `tentacle`,
reported by `get` as `creature_speed`) and each tentacle's. A strength is also checked
against its damping (`damping >= strength x physics step`, as in scenes); a bad value
raises ValueError naming the parameter. Changes reach the servos on the next physics step.
"""

from __future__ import annotations

import numbers
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.components import Creature, Tentacle
from ecs_tentacles.locomotion.actions import ActionQueue, Kind
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.scene.parameters import Parameter, parameters
from ecs_tentacles.scene.ranges import damping_floor

if TYPE_CHECKING:
    from ecs_tentacles.host import Host

# the stores whose rows `set` knows, and what one row of each is
ROWS = {
    "locomotion.creatures": "creature",
    "creatures": "creature",
    "locomotion.tentacles": "tentacle",
    "tentacles": "tentacle",
    "motors": "link",
}


def settable() -> tuple[dict[str, Parameter], dict[str, Parameter]]:
    """The run-time parameters by API name: (per tentacle, per creature)."""
    table = [p for p in parameters() if p.runtime and p.store in ROWS]
    per_tentacle = {p.api: p for p in table if ROWS[p.store] != "creature"}
    return per_tentacle, {p.api: p for p in table if ROWS[p.store] == "creature"}


class Locomotion:
    """Per-creature and per-tentacle locomotion settings of a world."""

    provided_by = "locomotion"  # the plugin that makes it (named by `world.resource` errors)

    def __init__(self, world: Host):
        self._world = world

    def _tentacles(self, creature: int, tentacle: int | None) -> list[Tentacle]:
        entities = self._world.component(creature, Creature).tentacles
        if tentacle is None:
            return [self._world.component(e, Tentacle) for e in entities]
        if not 0 <= tentacle < len(entities):
            raise ValueError(f"tentacle: must be in [0, {len(entities) - 1}], got {tentacle}")
        return [self._world.component(entities[tentacle], Tentacle)]

    def set(self, creature: int, tentacle: int | None = None, **params: object) -> None:
        """Change parameters of a creature's tentacles (all, or the one at index `tentacle`).

        `speed` without `tentacle` is the creature's speed; `gait` and `drivers` are
        creature-wide. Everything is checked before anything changes.
        """
        world = self._world
        row = world.component(creature, Creature).row
        targets = self._tentacles(creature, tentacle)
        per_tentacle, per_creature = settable()
        unknown = set(params) - set(per_tentacle) - set(per_creature)
        if unknown:
            allowed = ", ".join(sorted({*per_tentacle, *per_creature}))
            raise ValueError(f"{sorted(unknown)[0]}: unknown parameter (allowed: {allowed})")
        creature_only = set(params) - set(per_tentacle)
        if tentacle is not None and creature_only:
            raise ValueError(f"{sorted(creature_only)[0]}: is set per creature")
        chosen = {
            name: per_creature[name]
            if tentacle is None and name in per_creature
            else per_tentacle[name]
            for name in params
        }
        rows = np.array([t.row for t in targets])
        at = {name: self._rows(p, row, rows) for name, p in chosen.items()}
        checked = {name: self._check(p, params[name], at[name]) for name, p in chosen.items()}
        if "strength" in checked or "damping" in checked:
            self._check_servos(targets, checked)
        for name, p in chosen.items():
            p.write(world, at[name], checked[name])

    def _rows(self, p: Parameter, creature_row: int, tentacle_rows: np.ndarray) -> int | np.ndarray:
        """The rows of `p`'s store that a change of these tentacles (or creature) writes."""
        if ROWS[p.store] == "creature":
            return creature_row
        return self._link_rows(tentacle_rows) if ROWS[p.store] == "link" else tentacle_rows

    def _check(self, p: Parameter, value: Any, rows: Any) -> Any:
        """`value` checked against `p`'s range, capped by its `at_most` column if it has one."""
        if p.at_most is None or p.range is None:
            return p.check(value)
        high = min(p.range.high, np.min(p.cap(self._world)[rows]))
        whole = isinstance(value, numbers.Integral) and not isinstance(value, bool)
        if not whole or not p.range.low <= value <= high:
            raise ValueError(
                f"{p.api}: must be a whole number in [{p.range.low:g}, {high:g}], got {value!r}"
            )
        return int(value)

    def _value(self, p: Parameter, tentacle_row: int) -> Any:
        """One tentacle's value of `p`: its base link's for link parameters, before the taper."""
        store = self._world.stores[p.store]
        at = (
            int(self._world.tentacles.first_link[tentacle_row])
            if ROWS[p.store] == "link"
            else tentacle_row
        )
        value = getattr(store, p.field)[at]
        return p.to_api(value / getattr(store, p.taper)[at] if p.taper else value)

    def _servo(self, tentacle: Tentacle) -> tuple[float, float]:
        """(strength, damping) of a tentacle's base link, before its links' taper."""
        strength, damping = (settable()[0][name] for name in ("strength", "damping"))
        return self._value(strength, tentacle.row), self._value(damping, tentacle.row)

    def _check_servos(self, targets: list[Tentacle], checked: dict[str, float]) -> None:
        """Refuse a strength its damping cannot keep stable at this world's physics step."""
        step = self._world.settings.substep_dt
        for tentacle in targets:
            strength, damping = self._servo(tentacle)
            strength, damping = checked.get("strength", strength), checked.get("damping", damping)
            least = damping_floor(strength, step)
            if damping < least:
                name = "strength" if "strength" in checked else "damping"
                raise ValueError(
                    f"{name}: strength {strength:g} needs damping >= {least:.3g} at this world's"
                    f" physics step ({1e3 * step:.3g} ms), got damping {damping:g}"
                )

    def tentacle_count(self, creature: int) -> int:
        """How many tentacles creature `creature` has."""
        return len(self._world.component(creature, Creature).tentacles)

    def strength_limit(self, creature: int, tentacle: int | None = None) -> float:
        """The highest strength `set` accepts now: the schema's, or what the damping holds."""
        step = self._world.settings.substep_dt
        dampings = [self._servo(t)[1] for t in self._tentacles(creature, tentacle)]
        allowed = settable()[0]["strength"].range
        assert allowed is not None
        return min(allowed.high, min(dampings) / step)

    def get(self, creature: int, tentacle: int = 0) -> dict[str, object]:
        """One tentacle's parameters plus its creature's (`creature_speed`, gait, drivers)."""
        world = self._world
        row = world.component(creature, Creature).row
        t = self._tentacles(creature, tentacle)[0].row
        per_tentacle, per_creature = settable()
        values = {name: self._value(p, t) for name, p in per_tentacle.items()}
        for name, p in per_creature.items():
            shown = f"creature_{name}" if name in per_tentacle else name
            values[shown] = p.to_api(getattr(world.stores[p.store], p.field)[row])
        return values

    def actions(self, creature: int) -> list[str]:
        """The current action of each of the creature's tentacles, by index."""
        action = self._world.resource(LocomotionStores).tentacles.action
        kinds = action[[t.row for t in self._tentacles(creature, None)]]
        return [Kind(int(k)).name.lower() for k in kinds]

    def queue(self, creature: int, tentacle: int) -> list[str]:
        """The current action followed by the pending ones, for one tentacle."""
        target = self._tentacles(creature, tentacle)[0]
        entity = self._world.component(creature, Creature).tentacles[tentacle]
        pending = self._world.component(entity, ActionQueue).kinds()
        action = self._world.resource(LocomotionStores).tentacles.action
        current = Kind(int(action[target.row])).name.lower()
        return [current, *pending]

    def _link_rows(self, tentacle_rows: np.ndarray) -> np.ndarray:
        first = self._world.tentacles.first_link[tentacle_rows]
        count = self._world.tentacles.links[tentacle_rows]
        return np.concatenate([np.arange(f, f + n) for f, n in zip(first, count, strict=True)])
