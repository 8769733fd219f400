"""`ecs-tentacles play SCENE`: the interactive sandbox, or headless screenshots/video.

Headless, a level (a scene with a `game`) stops once its game is won or lost, and the
report holds the game's result (`ecs_tentacles.game`)."""

from __future__ import annotations

import argparse
import json
import sys
from typing import TYPE_CHECKING

from ecs_tentacles.cli.arguments import add_frames, add_switch, output_path, require_display
from ecs_tentacles.cli.world_options import CODE, PHYSICS, SEED, parents, world_options
from ecs_tentacles.scene.load import resolve_scene_path

if TYPE_CHECKING:
    from collections.abc import Mapping

    from ecs_tentacles.host import Host
    from ecs_tentacles.render.camera import CameraChoice

SIZE_RULE = "an even number of pixels in [64, 8192]"


def even_size(text: str) -> int:
    """argparse type: a window or image side, an even number of pixels in [64, 8192]."""
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value % 2 or not 64 <= value <= 8192:
        raise argparse.ArgumentTypeError(f"must be {SIZE_RULE}, got {text!r}")
    return value


def camera_option(text: str) -> CameraChoice:
    """argparse type: `frame-all`, `follow NAME` or `X,Y,Z,TX,TY,TZ` (a `CameraChoice`)."""
    from ecs_tentacles.render.camera import parse_camera

    try:
        return parse_camera(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def ui_scale(text: str) -> float:
    """argparse type: a factor in [0.5, 3]."""
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.5 <= value <= 3.0:
        raise argparse.ArgumentTypeError(f"must be a number in [0.5, 3], got {text!r}")
    return value


def add_parser(commands: argparse._SubParsersAction[argparse.ArgumentParser]) -> None:
    parser = commands.add_parser(
        "play",
        help="open the sandbox: watch, click goals, tune tentacles (or render headless)",
        description=(
            "Open a scene in the sandbox window. Mouse: left-drag select in a rectangle, "
            "right-drag orbit, middle-drag pan, wheel zoom, click a creature to select it, "
            "click the ground to set its goal, shift-click "
            "to append, right-click a goal to remove it. Keys: space pause, . step, r reset, "
            "h HUD, f follow, a frame all, tab next tentacle, F12 screenshot, v video, o the"
            " clean view (the editor's overlays hidden: goal paths, selection rings, sucker"
            " dots, the fur timeline, the metre grid; a game's HUD and banners stay), Ctrl+Q quit"
            " (Ctrl-C in the terminal too)."
        ),
        # without --focus, the focus follows the camera (render.sandbox)
        parents=parents(SEED, CODE, PHYSICS),
    )
    parser.add_argument("scene", metavar="SCENE", help="scene file or bundled scene name")
    parser.add_argument("--headless", action="store_true", help="no window: render off-screen")
    add_frames(parser, 300, "headless: ")
    parser.add_argument("--screenshot", type=output_path(".png"), help="headless: final PNG")
    parser.add_argument("--video", type=output_path(".mp4"), help="headless: record an MP4")
    parser.add_argument("--width", type=even_size, default=1280, help=f"{SIZE_RULE} (default 1280)")
    parser.add_argument("--height", type=even_size, default=720, help=f"{SIZE_RULE} (default 720)")
    parser.add_argument(
        "--camera",
        type=camera_option,
        default=None,
        metavar="VIEW",
        help=(
            "frame-all (every creature and goal in view; headless: kept so while they move),"
            " follow NAME (that creature at the centre) or X,Y,Z,TX,TY,TZ (stand at X,Y,Z,"
            " look at TX,TY,TZ); default: every creature framed at the start"
        ),
    )
    parser.add_argument(
        "--palette",
        choices=("natural", "debug"),
        default=None,
        help="creature colours: natural (muted skin tones, one per species) or debug (a"
        " bright colour per creature); default: the scene's render.palette, else natural",
    )
    parser.add_argument(
        "--ui-scale",
        type=ui_scale,
        default=None,
        metavar="FACTOR",
        help="draw the HUD FACTOR times larger, in [0.5, 3] (default: as the display asks,"
        " its DPI over 96; 1 headless); either way it also grows with the window's height",
    )
    add_switch(
        parser,
        "hud",
        "show the HUD (default: shown, except in a --video: a film has no sliders in it)",
        "start with the HUD hidden (h)",
    )
    add_switch(
        parser,
        "clean",
        "the clean view, a picture for showing: none of the editor's overlays (goal"
        " paths and rings, selection rings and names, sucker dots, tier spheres, the fur"
        " timeline, the metre grid); default: clean in a game (a scene with a `game` key)"
        " and in a --video",
        "draw the editor's overlays, in a game or a --video too (o toggles them)",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    parser.add_argument(
        "--json", action="store_true", help="headless: the summary as JSON (a level's: its game)"
    )
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    if not args.headless and (args.screenshot or args.video):
        print(
            "error: argument --screenshot/--video: needs --headless (in the window: F12, v)",
            file=sys.stderr,
        )
        return 2
    if args.headless and not (args.screenshot or args.video or args.json):
        print(
            "error: play: --headless keeps nothing without --screenshot FILE.png,"
            " --video FILE.mp4 or --json",
            file=sys.stderr,
        )
        return 2
    path = resolve_scene_path(args.scene)
    if not args.headless:
        require_display("play")
    from ecs_tentacles.render import configure

    configure(headless=args.headless)
    from ecs_tentacles.render.gui import set_ui_scale

    set_ui_scale(args.ui_scale)
    from ecs_tentacles.scene.load import load_scene

    load_scene(path, allow_systems=args.allow_systems)  # a bad scene fails before a window opens
    from ecs_tentacles.render.sandbox import Sandbox

    sandbox = Sandbox(
        path,
        world_options(args),
        width=args.width,
        height=args.height,
        headless=args.headless,
        hud=args.hud if args.hud is not None else not args.video,
        palette=args.palette,
        clean=True if args.clean is None and args.video else args.clean,
    )
    try:
        if args.camera is not None:
            try:
                sandbox.aim(args.camera)
            except KeyError as error:
                print(f"error: argument --camera: {error.args[0]}", file=sys.stderr)
                return 2
        if args.headless:
            result = sandbox.run_headless(
                args.frames,
                screenshot=args.screenshot,
                video=args.video,
                progress=not args.quiet,
                until=game_ended,
            )
            report = {"scene": str(path), **result, **game_report(sandbox.world)}
            print(json.dumps(report) if args.json else sentence(report))
        else:
            sandbox.run()
    finally:
        sandbox.close()
    return 0


def game_ended(world: Host) -> bool:
    """True once the world's game (a level's) is won or lost: a headless play stops."""
    from ecs_tentacles.game.rules import playing

    found = playing(world)
    return found is not None and found[1].ended


def game_report(world: Host) -> dict[str, dict[str, object]]:
    """`{"game": ...}`: the level's result as `--json` gives it ({} without a game)."""
    from ecs_tentacles.game.rules import playing

    found = playing(world)
    return {} if found is None else {"game": found[1].report(found[0])}


def sentence(report: Mapping[str, object]) -> str:
    """`octopus.json: 300 frames (5.00 s simulated, physics 4.1 ms a frame: 4.07x real
    time); wrote shot.png, clip.mp4`."""
    written = [str(report[k]) for k in ("screenshot", "video") if k in report]
    text = (
        f"{report['scene']}: {report['frames']} frames ({report['sim_seconds']:.2f} s simulated,"
        f" physics {report['physics_ms']:.1f} ms a frame: {report['realtime_factor']:.2f}x real"
        " time)"
    )
    game = report.get("game")
    if isinstance(game, dict):  # (a level's: `game_report`)
        text += f"; game {game['outcome']} at {game['seconds']:.1f} s"
    return text + (f"; wrote {', '.join(written)}" if written else "")
