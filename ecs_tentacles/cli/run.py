"""`ecs-tentacles run SCENE --frames N`: step a scene headless and report the speed.

The report holds timing, sizes, physics health and sucker attaches, and what the
plugins add (`RunSummaries` entries: locomotion's goals reached and left). A level (a
scene with a `game`) stops when its game mode says the game is won or lost
(`ecs_tentacles.game`), and the report's `game` holds the result (`frames`: those run).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Callable, Mapping
from typing import Any

from ecs_tentacles.cli.arguments import add_frames, bounded_int, counted
from ecs_tentacles.cli.registries import RunSummaries, RunSummary
from ecs_tentacles.cli.world_options import CODE, PHYSICS, SEED, parents, world_options
from ecs_tentacles.components import Creature
from ecs_tentacles.game.rules import playing
from ecs_tentacles.output.progress import status, step_frames
from ecs_tentacles.scene.load import resolve_scene_path
from ecs_tentacles.world import World


def positive_int(text: str) -> int:
    """argparse type: a whole number >= 1 (and at most a million: a count, not a size)."""
    return bounded_int(1, 1_000_000)(text)


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "run",
        help="simulate a scene headless and print sim time, wall time and real-time factor",
        description="Simulate a scene headless (no window) for a number of frames.",
        parents=parents(SEED, CODE, PHYSICS),
    )
    parser.add_argument("scene", metavar="SCENE", help="scene file or bundled scene name")
    add_frames(parser, 600)
    parser.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument(
        "--strict",
        action="store_true",
        help="exit 1 if any creature's physics had to be recovered or frozen",
    )
    parser.set_defaults(handler=handle)


def health_line(summary: Mapping[str, object]) -> str:
    """One sentence about recoveries, for the human-readable reports ('' when none)."""
    counted_causes = summary["recovery_causes"]
    if not summary["recoveries"] or not isinstance(counted_causes, dict):  # (`simulate`'s)
        return ""
    causes = ", ".join(f"{k} {v}" for k, v in sorted(counted_causes.items()))
    return (
        f"physics recovered {summary['recoveries']} times ({causes}),"
        f" {summary['frozen']} creatures frozen"
    )


def tier_line(tiers: dict[str, int]) -> str:
    """`full 32  reduced 64  kinematic 928` (creatures per physics tier)."""
    return "  ".join(f"{name} {count}" for name, count in tiers.items())


def handle(args: argparse.Namespace) -> int:
    path = resolve_scene_path(args.scene)
    build_start = time.perf_counter()
    with status(f"run: building {path}", progress=not args.quiet):
        world = World.from_scene(path, world_options(args))
    build_seconds = time.perf_counter() - build_start
    summary = simulate(world, args.frames, progress=not args.quiet)
    texts = [found.text for found in plugin_summaries(world) if found.text]
    summary = {"scene": str(path), **summary, "build_seconds": round(build_seconds, 4)}
    if summary.get("game") is not None:
        texts.append(game_phrase(summary["game"], summary["frames"], args.frames))
    attaches = f"sucker attaches {summary['sucker_attaches']}"
    if args.json:
        print(json.dumps(summary))
    else:
        print(
            f"{path}: {summary['frames']} frames, {summary['sim_seconds']:.2f} s simulated in"
            f" {summary['wall_seconds']:.2f} s wall,"
            f" real-time factor {summary['real_time_factor']:.2f}x"
            f" ({counted(summary['creatures'], 'creature')}, {summary['bodies']} bodies,"
            f" {summary['dofs']} dofs); {'; '.join([*texts, attaches])}"
        )
        if summary["tiers"]["full"] < summary["creatures"]:  # level of detail did something
            print(f"  level of detail at the end: {tier_line(summary['tiers'])}")
    failed = bool(args.strict and summary["recoveries"])
    if health_line(summary) and (failed or not args.json):  # --strict: an error, even with --json
        kind = "error" if failed else "warning"
        print(f"{kind}: {health_line(summary)}", file=sys.stderr)
    world.close()
    return 1 if failed else 0


def simulate(world: World, frames: int, *, progress: bool = True) -> dict[str, Any]:
    """Step `world` for `frames` frames (fewer when its game ends first) and return timing
    and size figures, physics health, the plugins' counts (`RunSummaries`) and the game's
    result (`game`, for a level)."""
    physics = world.physics
    start_time = world.time
    wall_start = time.perf_counter()
    until = game_over(world)
    done = step_frames(world, frames, progress=progress, until=until)
    wall = time.perf_counter() - wall_start
    sim = world.time - start_time
    game = playing(world)
    return {
        "frames": done,
        "seed": world.seed,
        "sim_seconds": round(sim, 6),
        "wall_seconds": round(wall, 4),
        "real_time_factor": round(sim / wall, 3) if wall > 0 else None,
        "creatures": len(list(world.query(Creature))),
        "bodies": physics.bodies,
        "dofs": physics.dofs,
        "models": physics.compiles,
        "threads": physics.threads,
        "recoveries": physics.health.recoveries,
        "recovery_causes": dict(physics.health.causes),
        "frozen": physics.health.frozen,
        "lod": physics.lod.enabled,
        "tiers": physics.lod.counts(),  # at the end
        "promotions": physics.lod.promotions,
        **{k: v for found in plugin_summaries(world) for k, v in found.counts.items()},
        "sucker_attaches": int(world.events.counts["sucker_attached"]),
        **({} if game is None else {"game": game[1].report(game[0])}),
    }


def game_over(world: World) -> Callable[[], bool] | None:
    """For a level: a test that its game is won or lost (the run stops there); None
    for a scene without a game."""
    if playing(world) is None:
        return None

    def over() -> bool:
        found = playing(world)
        return found is not None and found[1].ended

    return over


def game_phrase(game: Mapping[str, object], frames: int, asked: int) -> str:
    """`game won in 41.2 s (1. Open field), stopped at frame 2472 of 3600`."""
    where = f" ({game['level']})" if game.get("level") else ""
    if game["outcome"] == "playing":
        return f"game still playing after {game['seconds']:.1f} s{where}"
    stopped = f", stopped at frame {frames} of {asked}" if frames < asked else ""
    return f"game {game['outcome']} in {game['seconds']:.1f} s{where}{stopped}"


def plugin_summaries(world: World) -> list[RunSummary]:
    """What the world's plugins report after a run (`RunSummaries` entries), plugin order."""
    found = (summary(world) for summary in world.registry(RunSummaries))
    return [summary for summary in found if summary is not None]
