"""The `System` base class, shared by built-in and user systems.

A system has a unique `name`, runs in one of the frame's public stages and may order
itself inside its stage by name. It declares the store fields it reads and writes, so
the schedule can print the frame's data flow and warn about two unordered writers:

    class Wobble(System):
        '''Reads Motor.target; writes Motor.target (adds a wobble).'''
        name = "wobble"
        stage = "act"
        after = ("motor_targets",)      # a no-op when motor_targets is not scheduled
        reads = ("motors.target",)
        writes = ("motors.target",)

        def process(self, world, dt):
            world.motors.target[:, 0] += 0.1 * np.sin(world.time)

Stages, in frame order (`STAGES`): `decide` (goals, who drives), `act` (actions, motor
targets, suckers), `physics` (stepping), `sync` (poses back, health), `animate` (fur,
emotion) and `output` (record, render). A system without a `stage` joins the stage of
the last system it runs `after`, else of the first it runs `before`, else `act`.
esper's processor priorities are not used: `esper.add_processor` silently overwrites
a priority attribute.
"""

from __future__ import annotations

import traceback
from typing import TYPE_CHECKING, ClassVar

if TYPE_CHECKING:
    from ecs_tentacles.host import Host
    from ecs_tentacles.roster_change import RosterChange

STAGES = ("decide", "act", "physics", "sync", "animate", "output")
DEFAULT_STAGE = "act"


class System:
    """One job per frame. Override `process`; optionally `substep` and `setup`."""

    name: ClassVar[str] = ""
    stage: ClassVar[str | None] = None  # one of STAGES; None: inferred from after/before
    after: ClassVar[tuple[str, ...]] = ()  # systems or sets this one runs after
    before: ClassVar[tuple[str, ...]] = ()
    # labels this system belongs to, that others order against (`after = ("arrivals",)`):
    # a feature exports its sets (core's behaviour labels: `ecs_tentacles.behaviour`)
    sets: ClassVar[tuple[str, ...]] = ()
    reads: ClassVar[tuple[str, ...]] = ()  # "store.field" names, e.g. "motors.target"
    writes: ClassVar[tuple[str, ...]] = ()
    # a generic system that calls plugins' hooks or registry entries (physics: MotionWants;
    # record; render)
    # also reads what those hooks declare (`Plugin.hook_reads`)
    calls_hooks: ClassVar[bool] = False
    # attributes that carry simulation state from frame to frame (copied by snapshots)
    state_attributes: ClassVar[tuple[str, ...]] = ()
    plugin: str = ""  # the plugin that added this system ("" when added directly)

    def setup(self, world: Host) -> None:
        """Called once when the system joins a world (after physics is built)."""

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        """A creature was spawned or despawned (`ecs_tentacles.roster_change`): rebuild
        whatever `setup` made per row or per creature. Default: nothing."""

    def process(self, world: Host, dt: float) -> None:
        """Called once per frame, in schedule order; `dt` is the frame duration."""

    def substep(self, world: Host, index: int, dt: float) -> None:
        """Called before each physics substep `index` when overridden; `dt` per substep."""

    @classmethod
    def has_substep(cls) -> bool:
        return cls.substep is not System.substep

    def __repr__(self) -> str:
        return f"<system {self.name}>"


class SystemFailure(RuntimeError):
    """A system raised while processing a frame; the original exception is `__cause__`."""

    def __init__(self, system: System, label: str, frame: int, error: BaseException):
        self.system = system
        self.label = label  # the name it is scheduled under
        self.frame = frame
        self.error = error
        self.traceback_text: str | None = None
        owner = f" (plugin {system.plugin!r})" if system.plugin else ""
        first = str(error).splitlines()[0] if str(error) else ""
        super().__init__(
            f"system {label!r}{owner} failed at frame {frame}: {type(error).__name__}"
            + (f": {first}" if first else "")
        )

    def __reduce__(self) -> tuple[object, tuple[str, str, int, str]]:
        """Pickled (a Ray worker's failure reaching the driver) as its message and traceback."""
        return _unpickled_failure, (str(self), self.label, self.frame, self.user_traceback())

    def user_traceback(self) -> str:
        """The original exception's traceback, from the system's own code down.

        The frame that caught it (`World.step`, which called the system) is left out,
        so the first frame shown is the system's `process` (or `substep`).
        """
        if getattr(self, "traceback_text", None) is not None:  # came through pickle
            return str(self.traceback_text)
        error = self.error
        tb = error.__traceback__.tb_next if error.__traceback__ is not None else None
        return "".join(traceback.format_exception(type(error), error, tb))


def _unpickled_failure(message: str, label: str, frame: int, text: str) -> SystemFailure:
    """A SystemFailure rebuilt from its message and traceback text (no system object)."""
    failure = SystemFailure.__new__(SystemFailure)
    RuntimeError.__init__(failure, message)
    failure.system, failure.label, failure.frame = None, label, frame  # type: ignore[assignment]
    failure.error = RuntimeError(message)
    failure.traceback_text = text
    return failure
