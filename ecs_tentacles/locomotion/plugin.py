"""The locomotion plugin: goal paths, gait and the action queues that crawl toward goals.

Scene keys: a creature's `goals`, `locomotion`, `navigation` and `avoid`, the scene's
`avoidance` (`locomotion.schema.json` beside this file).
Resources: `LocomotionStores` (per-tentacle and per-creature columns, row for row with
the body's stores; `world.stores` "locomotion.tentacles" / "locomotion.creatures"),
`GoalBook` (goal paths), `Locomotion` (parameters at run time) and `Avoidance` (the
scene's `avoidance` settings), by type: `world.resource(GoalBook)`. Scene keys also
include six tentacle parameters (speed, target angle, waves, writhe; `tentacles` and its
`overrides`).
Systems: goals, avoidance, tentacle_selection (stage decide), action_queue, motor_targets
(act).
Sandbox hooks: goal rings and paths, goals set by clicks (`locomotion.render`), the
Locomotion and Actions sections of the HUD (`locomotion.panel`). Registry entry `MotionWants`
(creatures with a goal stay awake).
Output hooks (`ecs_tentacles.locomotion.outputs`): the goals a take records, how far a
creature may crawl during a distributed bake, goals reached for `ecs-tentacles run`.
"""

from __future__ import annotations

import copy
from collections import deque
from collections.abc import Mapping
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ecs_tentacles.behaviour import Destinations, Travel
from ecs_tentacles.cli.registries import RunSummaries, RunSummary
from ecs_tentacles.components import Creature, Tentacle
from ecs_tentacles.creatures.body import creature_rng
from ecs_tentacles.distributed.registries import MeetingReaches, Reach, ShardReaches
from ecs_tentacles.locomotion.actions import STRENGTH, ActionQueue, Kind
from ecs_tentacles.locomotion.avoidance import Avoidance, bent, turned
from ecs_tentacles.locomotion.components import Goal
from ecs_tentacles.locomotion.formations import FormationChoice
from ecs_tentacles.locomotion.goals import GoalBook
from ecs_tentacles.locomotion.navigation import NavigationState, Navigator
from ecs_tentacles.locomotion.params import Locomotion
from ecs_tentacles.locomotion.stores import LocomotionStores
from ecs_tentacles.physics.registries import MotionWants, TravelTargets
from ecs_tentacles.plugin import Plugin
from ecs_tentacles.render.registries import (
    Clicks,
    FramedPoints,
    OverlayLines,
    Panels,
    UndoState,
    UndoStates,
)
from ecs_tentacles.scene.construction import every_tentacle_params
from ecs_tentacles.scene.parameters import apply_parameters
from ecs_tentacles.scene.schema import plugin_schemas
from ecs_tentacles.scene.spec import as_spec
from ecs_tentacles.system import System
from ecs_tentacles.take.registries import TakeTracks, TrackSource

if TYPE_CHECKING:
    import numpy as np

    from ecs_tentacles.host import Host
    from ecs_tentacles.locomotion.actions import Action
    from ecs_tentacles.locomotion.directing import Directed, DirectedStates
    from ecs_tentacles.registry import App
    from ecs_tentacles.render.registries import Click, Panel, RenderView, SandboxView
    from ecs_tentacles.roster_change import RosterChange
    from ecs_tentacles.store import ArrayStore
    from ecs_tentacles.take.tracks import TrackSize


class LocomotionState(NamedTuple):
    """What a snapshot keeps: each creature's goal path (position, radius), each
    tentacle's pending actions (a tentacle with none is not listed), and the
    navigator's routes."""

    goals: dict[int, list[tuple[np.ndarray, float]]]
    queues: dict[int, deque[Action]]
    navigation: NavigationState


class LocomotionPlugin(Plugin):
    name = "locomotion"
    build_order = 10  # a default plugin: built before suckers (20)
    description = "goal-directed crawling: goal paths, gait, action queues, motor targets"
    creature_schema, tentacle_schema, scene_schema, defs = plugin_schemas(__package__, name)
    # its MotionWants and TravelTargets entries
    hook_reads = (
        "locomotion.creatures.has_goal",
        "locomotion.creatures.goal",
        "locomotion.creatures.steer",
        "locomotion.creatures.avoidance",
        "transforms.pos",
        "creatures.mantle_row",
    )

    _directed: DirectedStates | None = None  # the sandbox's undo mementos (`locomotion.directing`)

    def resources(self, world: Host) -> list[object]:
        return [LocomotionStores(), GoalBook(world), Locomotion(world), Navigator(),
                FormationChoice(), Avoidance()]  # fmt: skip

    def stores(self, world: Host) -> dict[str, ArrayStore]:
        loco = world.resource(LocomotionStores)
        return {"locomotion.tentacles": loco.tentacles, "locomotion.creatures": loco.creatures}

    def build_creature(self, world: Host, creature: int, spec: Mapping[str, object]) -> None:
        entry = as_spec(spec)  # core's keys, typed; this plugin's below (defaults filled)
        locomotion, goals = spec["locomotion"], spec["goals"]
        if not isinstance(locomotion, Mapping) or not isinstance(goals, list):
            raise TypeError(f"{entry['name']}: its locomotion and goals were not filled in")
        loco = world.resource(LocomotionStores)
        body = world.component(creature, Creature)
        row = int(loco.creatures.add()[0])
        if row != body.row:
            raise RuntimeError("locomotion's creature rows must line up with the body's")
        apply_parameters(world, "locomotion", locomotion, {"locomotion.creatures": row})
        loco.creatures.navigate[row] = bool(spec.get("navigation", True))
        loco.creatures.avoid[row] = bool(spec.get("avoid", True))
        rng = creature_rng(world.seed, entry["name"])  # the creature's own stream
        tentacles = entry["tentacles"]
        # one draw a tentacle, in order (an array of draws holds the same values)
        phases = rng.uniform(0.0, 2.0 * np.pi, len(body.tentacles))
        rows = loco.tentacles.add(len(phases), phase=phases, action_strength=STRENGTH[Kind.IDLE])
        for entity, added in zip(body.tentacles, rows.tolist(), strict=True):
            if added != world.component(entity, Tentacle).row:
                raise RuntimeError("locomotion's tentacle rows must line up with the body's")
            world.add_component(entity, ActionQueue())
        # each parameter written once for the tentacles that share their settings
        sharing: dict[int, list[int]] = {}
        every = every_tentacle_params(tentacles)
        for k, params in enumerate(every):
            sharing.setdefault(id(params), []).append(k)
        for ks in sharing.values():
            at = {"locomotion.tentacles": rows[ks]}
            apply_parameters(world, "tentacles", every[ks[0]], at)
        for goal in goals:
            # a 2-d goal is on the ground under it (`GoalBook` puts it there)
            world.resource(GoalBook).append(creature, goal["position"], goal["radius"])

    def build_scene(self, world: Host, scene: Mapping[str, object]) -> None:
        world.resource(Avoidance).configure(scene)

    def despawning(self, world: Host, creature: int) -> None:
        world.resource(GoalBook).forget(creature)

    def roster_changed(self, world: Host, change: RosterChange) -> None:
        world.resource(Navigator).roster_changed(change)

    def systems(self) -> list[System]:
        from ecs_tentacles.locomotion.systems.action_queue import ActionQueueSystem
        from ecs_tentacles.locomotion.systems.avoidance import CrowdAvoidance
        from ecs_tentacles.locomotion.systems.goals import Goals
        from ecs_tentacles.locomotion.systems.motor_targets import MotorTargets
        from ecs_tentacles.locomotion.systems.tentacle_selection import TentacleSelection

        return [Goals(), CrowdAvoidance(), TentacleSelection(), ActionQueueSystem(),
                MotorTargets()]  # fmt: skip

    def _wants_motion(self, world: Host) -> np.ndarray:
        """Creatures with a goal crawl: they never fall asleep."""
        wants: np.ndarray = world.resource(LocomotionStores).creatures.has_goal
        return wants

    def _travel_targets(self, world: Host) -> np.ndarray:
        """Creatures crawl toward their current goal (or the waypoint on the way to it),
        turned by avoidance where a neighbour is near."""
        creatures = world.resource(LocomotionStores).creatures
        term = creatures.avoidance
        if 2 * np.count_nonzero(term[:, 0]) > len(term):  # most turned (a crowd): no gathers
            return self._crowd_travel_targets(world)
        target = creatures.steer[:, :2].copy()
        rows = np.flatnonzero(turned(term))
        if len(rows):  # the others keep their steer point exactly
            mantle = world.transforms.pos[world.creatures.mantle_row[rows], :2]
            target[rows] = mantle + bent(target[rows] - mantle, creatures.avoidance[rows])
        return np.where(creatures.has_goal[:, None], target, np.nan)

    def _crowd_travel_targets(self, world: Host) -> np.ndarray:
        """`_travel_targets` as whole-array math: every creature turned (`bent`'s
        operations, in its order), then those with no avoidance term given back their
        steer point; the same bits without a gather and a scatter of most rows."""
        creatures = world.resource(LocomotionStores).creatures
        steer, term = creatures.steer[:, :2], creatures.avoidance
        mantle = world.transforms.pos[world.creatures.mantle_row, :2]
        with np.errstate(invalid="ignore", over="ignore"):  # (rows not turned: not kept)
            to_goal = steer - mantle
            length = np.hypot(to_goal[:, 0], to_goal[:, 1])
            to_goal += length[:, None] * term
            to_goal += mantle  # (mantle + to_goal: addition commutes bit for bit)
        target = np.where(turned(term)[:, None], to_goal, steer)
        return np.where(creatures.has_goal[:, None], target, np.nan)

    def snapshot(self, world: Host) -> object:
        goals = {
            entity: [
                (world.component(g, Goal).position.copy(), world.component(g, Goal).radius)
                for g in world.resource(GoalBook).path(entity)
            ]
            for entity, _ in world.query(Creature)
        }
        queues = {e: copy.deepcopy(q.pending) for e, q in world.query(ActionQueue) if len(q)}
        return LocomotionState(goals, queues, world.resource(Navigator).state())

    def restore(self, world: Host, state: object) -> None:
        if not isinstance(state, LocomotionState):
            raise TypeError(f"locomotion: a snapshot's state is a LocomotionState, not {state!r}")
        goals, queues, navigation = state
        for entity, path in goals.items():
            world.resource(GoalBook).clear(entity)
            for position, radius in path:
                world.resource(GoalBook).append(entity, position.tolist(), radius)
        for entity, queue in world.query(ActionQueue):  # (an empty queue: not in `queues`)
            queue.pending = copy.deepcopy(queues[entity]) if entity in queues else None
        world.resource(Navigator).set_state(navigation)

    # -- registry entries ---------------------------------------------------------------
    def build(self, app: App) -> None:
        """How far creatures crawl and act in a bake (`distributed.registries`); goals
        reached for `run` (`cli.registries`); the goals track (`take.registries`); paths,
        goal clicks, sliders and undo in the sandbox (`render.registries`); creatures with
        a goal stay awake and head for it (`physics.registries`); behaviours send
        creatures through its goals (`behaviour.Destinations`)."""
        app.add(ShardReaches, self._shard_reach)
        app.add(MeetingReaches, self._meeting_reach)
        app.add(RunSummaries, self._run_summary)
        app.add(TakeTracks, self._take_tracks)
        app.add(OverlayLines, self._lines)  # the editor's: none in the clean view
        app.add(FramedPoints, self._framed_points)
        app.add(Panels, self._panels)
        app.add(Clicks, self._click)
        app.add(UndoStates, UndoState(self._undo_capture, self._undo_restore))
        app.add(MotionWants, self._wants_motion)
        app.add(TravelTargets, self._travel_targets)
        app.add(
            Destinations,
            Travel(
                send=lambda world, creature, point, radius: world.resource(GoalBook).set(
                    creature, point, radius
                ),
                stop=lambda world, creature: world.resource(GoalBook).clear(creature),
                going=lambda world: world.resource(LocomotionStores).creatures.has_goal,
            ),
        )

    def _lines(self, world: Host, view: RenderView) -> list[np.ndarray]:
        from ecs_tentacles.locomotion.render import path_lines

        return path_lines(world, view)

    def _framed_points(self, world: Host) -> np.ndarray:
        from ecs_tentacles.locomotion.render import goal_points

        return goal_points(world)

    def _undo_capture(self, world: Host) -> Directed:
        from ecs_tentacles.locomotion.directing import DirectedStates

        if self._directed is None:
            self._directed = DirectedStates()
        return self._directed.capture(world)

    def _undo_restore(self, world: Host, state: object) -> None:
        from ecs_tentacles.locomotion.directing import Directed, sandbox_restore

        if not isinstance(state, Directed):
            raise TypeError(f"locomotion: an undo state is a Directed, not {state!r}")
        sandbox_restore(world, state)

    def save_creature(self, world: Host, creature: int, entry: dict[str, object]) -> None:
        from ecs_tentacles.locomotion.directing import save_creature

        save_creature(world, creature, entry)

    def _click(self, world: Host, click: Click) -> bool:
        from ecs_tentacles.locomotion.render import click_goal

        return click_goal(world, click)

    def _panels(self, sandbox: SandboxView) -> list[Panel]:
        from ecs_tentacles.locomotion.panel import locomotion_panels

        return locomotion_panels(sandbox)

    # -- outputs (take tracks: build; shard plans, run report: hooks) ----------------
    def _take_tracks(self, world: Host) -> list[TrackSource]:
        from ecs_tentacles.locomotion.outputs import GOAL_TRACK

        return [GOAL_TRACK]

    def take_sizes(self, scene: Mapping[str, object]) -> list[TrackSize]:
        from ecs_tentacles.locomotion.outputs import goal_sizes

        return goal_sizes(scene)

    def _shard_reach(self, creature: Mapping[str, object], seconds: float) -> Reach | None:
        from ecs_tentacles.locomotion.outputs import crawl_reach

        return crawl_reach(creature, seconds)

    def _meeting_reach(self, scene: Mapping[str, object]) -> list[float] | None:
        from ecs_tentacles.locomotion.avoidance import meeting_reach

        return meeting_reach(scene)

    def _run_summary(self, world: Host) -> RunSummary | None:
        from ecs_tentacles.locomotion.outputs import goal_summary

        return goal_summary(world)
