"""Level of detail: which creature runs at which tier (`physics.tiers`), decided each frame.

    world.lod.promote(creature)           # full physics until released
    world.lod.release(creature)
    world.lod.focus((2.0, -1.0), 3.0)     # creatures within 3 m of (2, -1) run full
    world.lod.counts()                    # {"full": 0, "reduced": 128, "kinematic": 896}

Reads: every creature's reach sphere (the contact proxies' geometry over the Transform
store), who is asleep or frozen, the scene's `physics.lod` budgets, and what scripts,
the sandbox or a bake asked for (`promote`, `select`, `focus`). Writes: the roster's
`tier`; a creature leaving KINEMATIC starts from the joint state of the pose it was
shown in (`Replay.joint_state`, then `PhysicsBackend.place_joints`: no pop); a
creature entering KINEMATIC is handed to the replay (`Replay.start`).

The rules, whole-array work every frame before the step:

1. Lod off: everyone is FULL, always (`--lod off`, `lod=False`).
2. Heroes must be FULL: forced ones (`promote`: scripts, a grabbed creature; `select`:
   the sandbox's selection), those inside the focus region, and whatever has a body
   within `contact_margin` of a hero's (the bodies' bounding spheres; it stays full
   until it is `CLEAR` times that far).
3. Contact must be physical, never replayed: creatures with a body within
   `contact_margin` of another creature's, or whose reach comes within it of an
   obstacle (`Ground.touches_obstacle`), run at least REDUCED, whatever the budgets (promoted
   before they touch; one simulated stays so until it is `CLEAR` times that far).
4. The other awake creatures (those of rule 3 too) are ranked: nearest the focus first
   (without one, all equal), then the tier they hold (hysteresis), then creature
   order, so a bake's decisions depend on nothing but the scene. With a focus region
   they fill what rule 2 left of the `full` budget (it counts the heroes: it caps what
   full physics costs unless more than `full` are heroes); without one, or with
   `focus(..., fill=False)` as the sandbox asks, only heroes run full (creature order
   is no reason for full physics: a 1,024 crowd's eight arbitrary full creatures cost
   it a sixth of its frame). Then what rule 3 left of the `reduced` budget runs
   REDUCED, the rest KINEMATIC (REDUCED while no replay is registered).
5. Asleep creatures keep their tier and use no budget.
6. Demotion waits until a creature has held its tier `hold_seconds`; promotion never
   waits.

A crowd within the full budget therefore runs exactly as with lod off.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Protocol

import numpy as np

from ecs_tentacles.ground import ground_of
from ecs_tentacles.physics.pairs import nearest_gap
from ecs_tentacles.physics.proxies import ContactProxies
from ecs_tentacles.physics.tiers import FULL, KINEMATIC, NAMES, REDUCED

if TYPE_CHECKING:
    from ecs_tentacles.physics.host import PhysicsHost
    from ecs_tentacles.physics.roster import Roster
    from ecs_tentacles.settings import LodSettings


CLEAR = 2.0  # a full creature near another stays full until this many margins away


class Replay(Protocol):
    """What moves KINEMATIC creatures (registered by the `lod` plugin: gait clips)."""

    def start(self, indices: np.ndarray) -> None:
        """Creatures `indices` (roster order) leave the physics: replay from where they are."""

    def joint_state(self, index: int) -> tuple[np.ndarray, np.ndarray]:
        """The MuJoCo qpos and qvel of the pose creature `index` is shown in now."""
        ...


class LevelOfDetail:
    """Tier decisions and the requests that steer them (`world.lod`)."""

    def __init__(
        self,
        roster: Roster,
        proxies: ContactProxies,
        settings: LodSettings,
        fps: float,
        place: Callable[[int, np.ndarray, np.ndarray], None],
    ):
        self.roster = roster
        self.proxies = proxies
        self.settings = settings
        self.enabled = settings.enabled
        self.hold_frames = round(settings.hold_seconds * fps)
        self._place = place
        self.replay: Replay | None = None
        count = len(roster)
        self.scripted = np.zeros(count, dtype=bool)  # promote() / release()
        self.selected = np.zeros(count, dtype=bool)  # the sandbox's selection
        self.focus_region: tuple[np.ndarray, float] | None = None
        self.fill = True  # with a focus: non-heroes may take what heroes leave of `full`
        if settings.focus is not None:
            self.focus(settings.focus[:2], settings.focus[2])
        # frames at the current tier; at the start nobody is held: first tiers come at once
        self.held = np.full(count, self.hold_frames, dtype=np.int64)
        self.promotions = 0
        self.demotions = 0

    # -- requests --------------------------------------------------------------------
    def index(self, creature: int) -> int:
        """The roster index of creature entity `creature`."""
        i = int(np.searchsorted(self.roster.entity, creature))
        if i >= len(self.roster) or self.roster.entity[i] != creature:
            raise KeyError(f"entity {creature} is not a creature of this physics")
        return i

    def promote(self, creature: int) -> None:
        """Run `creature` (an entity) at full physics from the next frame until `release`."""
        self.scripted[self.index(creature)] = True

    def release(self, creature: int) -> None:
        """Undo `promote`: `creature` competes for the budgets again."""
        self.scripted[self.index(creature)] = False

    def select(self, creatures: Iterable[int]) -> None:
        """The sandbox's selection (entities): they run full while selected."""
        self.selected[:] = False
        for creature in creatures:
            self.selected[self.index(creature)] = True

    def focus(
        self,
        centre: tuple[float, float] | np.ndarray | None,
        radius: float = 0.0,
        fill: bool = True,
    ) -> None:
        """Creatures whose mantle is within `radius` m of `centre` (x, y) run full and the
        rest are ranked by distance to it; None: no focus (creature order decides).
        `fill=False`: what the heroes leave of the full budget stays unused (the sandbox:
        a creature far from what the camera looks at gains nothing visible from full
        physics, and the frame time it would take is what keeps the crowd real time)."""
        self.fill = fill
        if centre is None:
            self.focus_region = None
            return
        if not radius >= 0:
            raise ValueError(f"focus radius: must be >= 0, got {radius}")
        self.focus_region = (np.asarray(centre, dtype=np.float64)[:2].copy(), float(radius))

    def tier_of(self, creature: int) -> str:
        """`"full"`, `"reduced"` or `"kinematic"`."""
        return NAMES[int(self.roster.tier[self.index(creature)])]

    def counts(self) -> dict[str, int]:
        """Creatures per tier, by name."""
        counts = np.bincount(self.roster.tier, minlength=len(NAMES))
        return {name: int(n) for name, n in zip(NAMES, counts, strict=True)}

    # -- roster changes --------------------------------------------------------------
    def grow(self) -> None:
        """A creature was appended: not scripted, not selected, free to change tier."""
        self.scripted = np.append(self.scripted, False)
        self.selected = np.append(self.selected, False)
        self.held = np.append(self.held, self.hold_frames)

    def remove(self, index: int) -> None:
        """Creature `index` was taken out."""
        for name in ("scripted", "selected", "held"):
            setattr(self, name, np.delete(getattr(self, name), index))

    # -- state -----------------------------------------------------------------------
    def state(self) -> tuple[np.ndarray, ...]:
        """What decides the next frame's tiers, for snapshots (tiers are the roster's)."""
        return self.scripted.copy(), self.selected.copy(), self.held.copy()

    def set_state(self, state: tuple[np.ndarray, ...]) -> None:
        self.scripted[:], self.selected[:], self.held[:] = state

    # -- per frame -------------------------------------------------------------------
    def update(self, world: PhysicsHost) -> None:
        """Decide every creature's tier for this frame's step (rules in the module doc)."""
        roster = self.roster
        if not len(roster):
            return
        fits = len(roster) <= self.settings.full  # everyone fits the full budget
        if not self.enabled or fits:  # everyone full (at once, if that just became so)
            self._move(world, np.full(len(roster), FULL, dtype=np.int8))
            return
        count = len(roster)
        pos, _, centre, radius = self.proxies.sense(world.transforms, world.frame)
        margin = self.settings.contact_margin
        pairs = self.proxies.pair_gaps(pos, centre, radius, CLEAR * margin)
        tier = roster.tier
        hero = self.scripted | self.selected
        distance = np.zeros(count)
        if self.focus_region is not None:
            point, reach = self.focus_region
            distance = np.linalg.norm(centre[:, :2] - point, axis=1)
            hero |= distance <= reach
        to_hero = nearest_gap(count, *pairs, among=hero)
        must = hero | (to_hero < margin) | ((to_hero < CLEAR * margin) & (tier == FULL))
        gap = nearest_gap(count, *pairs)
        simulated = tier != KINEMATIC  # stays so until clear (CLEAR margins away)
        clear = np.where(simulated, CLEAR * margin, margin)
        contact = (gap < clear) | _near_obstacles(world, centre, radius + clear)
        contact &= ~must
        want = np.full(count, KINEMATIC if self.replay is not None else REDUCED, np.int8)
        want[must] = FULL
        want[contact] = REDUCED
        awake = ~(roster.sleeping | roster.frozen)
        ranked = np.flatnonzero(awake & ~must)
        order = ranked[np.lexsort((ranked, tier[ranked], distance[ranked]))]
        fill = self.fill and self.focus_region is not None  # ranked by nothing: heroes only
        full = max(0, self.settings.full - int(must.sum())) if fill else 0  # heroes count
        want[order[:full]] = FULL
        rest = order[full:]
        rest = rest[~contact[rest]]  # in contact: REDUCED already, and counted below
        reduced = max(0, self.settings.reduced - int(contact[order[full:]].sum()))
        want[rest[:reduced]] = REDUCED
        keep = ~awake & ~must & ~(contact & (tier == KINEMATIC))  # asleep: keeps its tier
        keep |= (want > tier) & (self.held < self.hold_frames)  # demotion waits
        want[keep] = tier[keep]
        self._move(world, want)

    def _move(self, world: PhysicsHost, want: np.ndarray) -> None:
        roster = self.roster
        tier = roster.tier
        changed = want != tier
        self.held += 1
        if not changed.any():
            return
        self.held[changed] = 0
        self.promotions += int((changed & (want < tier)).sum())
        self.demotions += int((changed & (want > tier)).sum())
        leaving = np.flatnonzero(changed & (tier == KINEMATIC))
        entering = np.flatnonzero(changed & (want == KINEMATIC))
        for index in leaving.tolist():  # an event: only the creatures promoted this frame
            if self.replay is None:
                raise RuntimeError("a kinematic creature with no replay to take its pose from")
            qpos, qvel = self.replay.joint_state(index)
            self._place(index, qpos, qvel)
        tier[:] = want
        if len(entering) and self.replay is not None:
            self.replay.start(entering)


def _near_obstacles(world: PhysicsHost, centre: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """(creatures,) whose reach sphere (`centre`, `reach`) meets an obstacle: about to
    touch it. Bounding spheres cull, then each obstacle's signed distance decides."""
    return np.asarray(ground_of(world).touches_obstacle(centre, reach), dtype=bool)
