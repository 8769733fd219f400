"""The README's "Play the herding game" pictures: level 1 played in a headless sandbox by
the bot, its every aim given as the mouse press a player makes on the ground.

    python tools/herding_screenshots.py                     # into assets/screenshots/
    python tools/herding_screenshots.py --out-dir shots/ --level herding_2_shore

Writes `herding_sequence.png` (2 x 2: the start; the predator behind the flock; the
first creature penned; the win banner) and `herding.gif` (the game, a frame every
`GIF_SECONDS` simulated seconds, small). The best time goes to a scratch data folder,
not the user's.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

from ecs_tentacles.render import configure

sys.path.insert(0, str(Path(__file__).resolve().parent))
from picture_sequence import save_sequence

DEFAULT_DIR = Path(__file__).resolve().parents[1] / "assets" / "screenshots"
SIZE = (800, 450)
GIF_WIDTH = 400
GIF_SECONDS = 1.0


def run(out_dir: Path, level: str) -> None:
    from PIL import Image
    from pyglet.event import EventDispatcher
    from pyglet.window import mouse

    from ecs_tentacles.herding.game import HerdingGame
    from ecs_tentacles.herding.play import Bot
    from ecs_tentacles.render.sandbox import Sandbox
    from ecs_tentacles.scene.load import resolve_scene_path

    sandbox = Sandbox(resolve_scene_path(level), width=SIZE[0], height=SIZE[1], headless=True)
    sandbox.select(None)
    sandbox.renderer.frame_all()
    game = sandbox.world.resource(HerdingGame)
    bot = Bot()
    scratch = Path(tempfile.mkdtemp())

    def shot() -> Image.Image:
        path = sandbox.screenshot(scratch / "shot.png")
        return Image.open(path).convert("RGB")

    def press(point: Any) -> None:
        at = sandbox.renderer.camera.project(np.array([[point[0], point[1], 0.0]]))[0]
        x, y = round(float(at[0])), round(float(at[1]))
        EventDispatcher.dispatch_event(sandbox.window, "on_mouse_press", x, y, mouse.LEFT, 0)
        EventDispatcher.dispatch_event(sandbox.window, "on_mouse_release", x, y, mouse.LEFT, 0)

    fps = sandbox.world.settings.fps
    block = round(0.25 * fps)
    frames = [shot()]
    moments = {"start": frames[0]}
    next_gif = GIF_SECONDS
    while game.outcome == "playing":
        aim = bot.decide(sandbox.world, game)
        if aim is not None:
            press(aim)
        sandbox.step(block)
        sandbox.keep_framed()
        if "behind" not in moments and sandbox.world.time >= 10.0:
            moments["behind"] = shot()
        if "penned" not in moments and game.penned >= 1:
            moments["penned"] = shot()
        if sandbox.world.time >= next_gif:
            frames.append(shot())
            next_gif += GIF_SECONDS
    sandbox.step(block)
    moments["end"] = shot()
    frames += [moments["end"]] * 4  # the banner stays a moment
    print(f"{game.level}: {game.outcome} in {game.elapsed:.1f} s", file=sys.stderr)
    sandbox.close()
    order = ("start", "behind", "penned", "end")
    pictures = [moments.get(name, moments["end"]) for name in order]
    png, gif = save_sequence(out_dir, "herding", pictures, frames, GIF_WIDTH, 150)
    print(f"{png}, {gif}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=DEFAULT_DIR)
    parser.add_argument("--level", default="herding_1_field", help="bundled name or file")
    args = parser.parse_args(argv)
    args.out_dir.mkdir(parents=True, exist_ok=True)
    os.environ.setdefault("ECS_TENTACLES_DATA", tempfile.mkdtemp())  # not the user's times
    configure(headless=True)
    run(args.out_dir, args.level)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
