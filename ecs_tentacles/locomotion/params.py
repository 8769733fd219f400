"""Locomotion parameters, read and changed at run time (the HUD and scripts use this).

    world.locomotion.set(octo, speed=1.5)                    # the creature's speed
    world.locomotion.set(octo, tentacle=2, strength=12.0)    # one tentacle's servo kp
    world.locomotion.set(octo, wave_amplitude=0.2)           # every tentacle
    world.locomotion.set(octo, gait="cyclic")
    world.locomotion.actions(octo)                           # what each tentacle is doing

Angles are radians here (scenes use degrees). Values are checked against the scene
schema's ranges (`ecs_tentacles.scene.ranges`), and a strength against its damping
(`damping >= strength x physics step`, as in scenes); a bad one raises ValueError
naming the parameter. Changes reach the servos on the next physics step.
"""

from __future__ import annotations

import numbers
from typing import TYPE_CHECKING, Any

import numpy as np

from ecs_tentacles.components import Creature, Tentacle
from ecs_tentacles.locomotion.actions import ActionQueue, Kind
from ecs_tentacles.scene.ranges import Range, damping_floor, field_range

if TYPE_CHECKING:
    from ecs_tentacles.world import World

GAITS = ("cyclic", "coordinated")
DEGREE = float(np.radians(1.0))
# API name -> its range: the scene schema's, in radians where the scene says degrees
TENTACLE_RANGES: dict[str, Range] = {
    "speed": field_range("tentacles", "speed"),
    "target_angle": field_range("tentacles", "target_angle_deg").scaled(DEGREE),
    "strength": field_range("tentacles", "strength"),
    "damping": field_range("tentacles", "damping"),
    "wave_amplitude": field_range("tentacles", "wave_amplitude_deg").scaled(DEGREE),
    "wave_frequency": field_range("tentacles", "wave_frequency"),
    "wavelength": field_range("tentacles", "wavelength"),
    "writhe": field_range("tentacles", "writhe"),
}
CREATURE_ONLY = ("gait", "drivers")


class Locomotion:
    """Per-creature and per-tentacle locomotion settings of a world."""

    def __init__(self, world: World):
        self._world = world

    def _tentacles(self, creature: int, tentacle: int | None) -> list[Tentacle]:
        entities = self._world.component(creature, Creature).tentacles
        if tentacle is None:
            return [self._world.component(e, Tentacle) for e in entities]
        if not 0 <= tentacle < len(entities):
            raise ValueError(f"tentacle: must be in [0, {len(entities) - 1}], got {tentacle}")
        return [self._world.component(entities[tentacle], Tentacle)]

    def set(self, creature: int, tentacle: int | None = None, **params: Any) -> None:
        """Change parameters of a creature's tentacles (all, or the one at index `tentacle`).

        `speed` without `tentacle` is the creature's speed; `gait` and `drivers` are
        creature-wide. Everything is checked before anything changes.
        """
        world = self._world
        row = world.component(creature, Creature).row
        targets = self._tentacles(creature, tentacle)
        unknown = set(params) - set(TENTACLE_RANGES) - set(CREATURE_ONLY)
        if unknown:
            allowed = ", ".join(sorted([*TENTACLE_RANGES, *CREATURE_ONLY]))
            raise ValueError(f"{sorted(unknown)[0]}: unknown parameter (allowed: {allowed})")
        if tentacle is not None and set(params) & set(CREATURE_ONLY):
            raise ValueError(f"{sorted(set(params) & set(CREATURE_ONLY))[0]}: is set per creature")
        checked = {
            k: TENTACLE_RANGES[k].check(k, v) for k, v in params.items() if k in TENTACLE_RANGES
        }
        if "strength" in checked or "damping" in checked:
            self._check_servos(targets, checked)
        if "gait" in params and params["gait"] not in GAITS:
            raise ValueError(f"gait: must be one of {', '.join(GAITS)}, got {params['gait']!r}")
        if "drivers" in params:
            count = int(world.creatures.tentacles[row])
            drivers = params["drivers"]
            whole = isinstance(drivers, numbers.Integral) and not isinstance(drivers, bool)
            if not whole or not 1 <= drivers <= count:
                raise ValueError(
                    f"drivers: must be a whole number in [1, {count}], got {drivers!r}"
                )
            world.creatures.drivers[row] = int(drivers)
        if "gait" in params:
            world.creatures.gait[row] = GAITS.index(params["gait"])
        rows = np.array([t.row for t in targets])
        for name, value in checked.items():
            if name == "speed" and tentacle is None:
                world.creatures.speed[row] = value
            elif name in ("strength", "damping"):
                links = self._link_rows(rows)
                getattr(world.motors, name)[links] = value * world.motors.scale[links]
            else:
                getattr(world.tentacles, name)[rows] = value

    def _servo(self, tentacle: Tentacle) -> tuple[float, float]:
        """(strength, damping) of a tentacle's base link, before its links' taper."""
        motors = self._world.motors
        first = int(self._world.tentacles.first_link[tentacle.row])
        scale = motors.scale[first]
        return float(motors.strength[first] / scale), float(motors.damping[first] / scale)

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

    def strength_limit(self, creature: int, tentacle: int | None = None) -> float:
        """The highest strength `set` accepts now: the schema's, or what the damping holds."""
        step = self._world.settings.substep_dt
        dampings = [self._servo(t)[1] for t in self._tentacles(creature, tentacle)]
        return min(TENTACLE_RANGES["strength"].high, min(dampings) / step)

    def get(self, creature: int, tentacle: int = 0) -> dict[str, Any]:
        """The parameters of one tentacle plus its creature's gait, speed and drivers."""
        world = self._world
        row = world.component(creature, Creature).row
        target = self._tentacles(creature, tentacle)[0]
        t = target.row
        values: dict[str, Any] = {
            name: float(getattr(world.tentacles, name)[t])
            for name in TENTACLE_RANGES
            if name not in ("strength", "damping")
        }
        values["strength"], values["damping"] = self._servo(target)
        values["gait"] = GAITS[int(world.creatures.gait[row])]
        values["creature_speed"] = float(world.creatures.speed[row])
        values["drivers"] = int(world.creatures.drivers[row])
        return values

    def actions(self, creature: int) -> list[str]:
        """The current action of each of the creature's tentacles, by index."""
        kinds = self._world.tentacles.action[[t.row for t in self._tentacles(creature, None)]]
        return [Kind(int(k)).name.lower() for k in kinds]

    def queue(self, creature: int, tentacle: int) -> list[str]:
        """The current action followed by the pending ones, for one tentacle."""
        target = self._tentacles(creature, tentacle)[0]
        entity = self._world.component(creature, Creature).tentacles[tentacle]
        pending = self._world.component(entity, ActionQueue).kinds()
        current = Kind(int(self._world.tentacles.action[target.row])).name.lower()
        return [current, *pending]

    def _link_rows(self, tentacle_rows: np.ndarray) -> np.ndarray:
        first = self._world.tentacles.first_link[tentacle_rows]
        count = self._world.tentacles.links[tentacle_rows]
        return np.concatenate([np.arange(f, f + n) for f, n in zip(first, count, strict=True)])
