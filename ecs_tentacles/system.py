"""The `System` base class, shared by built-in and user systems.

A system has a unique `name` and declares its place in the frame by name:
`after = ("physics",)`, `before = ("render",)`. The `Schedule` turns those into
one explicit order (see `World.schedule.names`); esper's processor priorities are
not used, because `esper.add_processor` silently overwrites a priority attribute.

    class Wobble(System):
        '''Reads Motor.target; writes Motor.target (adds a wobble).'''
        name = "wobble"
        after = ("motor_targets",)
        before = ("physics",)

        def process(self, world, dt):
            world.motors.target[:, 0] += 0.1 * np.sin(world.time)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, ClassVar

if TYPE_CHECKING:
    from ecs_tentacles.world import World


class System:
    """One job per frame. Override `process`; optionally `substep` and `setup`."""

    name: ClassVar[str] = ""
    after: ClassVar[tuple[str, ...]] = ()
    before: ClassVar[tuple[str, ...]] = ()
    # attributes that carry simulation state from frame to frame (copied by snapshots)
    state_attributes: ClassVar[tuple[str, ...]] = ()

    def setup(self, world: World) -> None:
        """Called once when the system joins a world (after physics is built)."""

    def process(self, world: World, dt: float) -> None:
        """Called once per frame, in schedule order; `dt` is the frame duration."""

    def substep(self, world: World, index: int, dt: float) -> None:
        """Called before each physics substep `index` when overridden; `dt` per substep."""

    @classmethod
    def has_substep(cls) -> bool:
        return cls.substep is not System.substep

    def __repr__(self) -> str:
        return f"<system {self.name}>"
