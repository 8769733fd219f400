"""The README's "Directing a crowd" pictures: a headless sandbox driven by the same mouse
and key events a player makes (no API shortcuts).

    python tools/director_screenshots.py                     # into assets/screenshots/
    python tools/director_screenshots.py --out-dir shots/ --seconds 20

1. one octopus on the sand; 2. S + drag round a point: the brush scatters 50
octopuses (seeded); 3. Ctrl+A and a click at the point: each gets its own goal in a
ring round it (its path drawn); 4. after `--seconds`, the crowd gathered round the point.
Writes `director_sequence.png` (the four, 2 x 2) and `director.gif` (the same run, a
frame every `GIF_SECONDS` simulated seconds, small).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ecs_tentacles.render import configure

sys.path.insert(0, str(Path(__file__).resolve().parent))
from picture_sequence import save_sequence

DEFAULT_DIR = Path(__file__).resolve().parents[1] / "assets" / "screenshots"
SIZE = (800, 450)
GIF_WIDTH = 320
GIF_SECONDS = 2.0
POINT = (0.0, 0.0, 0.0)  # where the crowd is sent
BRUSH_PATH = 7.0  # m: the brush goes round the point at this distance
SCENE = {
    "version": 1,
    "name": "director",
    "physics": {"lod": {"enabled": True}},
    "creatures": [{"name": "octopus", "position": [-BRUSH_PATH, 0.0]}],
}


def _events(sandbox: Any) -> tuple[Any, Any]:
    from pyglet.event import EventDispatcher

    def event(name: str, *args: Any) -> None:
        EventDispatcher.dispatch_event(sandbox.window, name, *args)

    def pixel(point: Any) -> tuple[int, int]:
        x, y = sandbox.renderer.camera.project(np.asarray(point, dtype=float)[None])[0]
        return round(float(x)), round(float(y))

    return event, pixel


def run(out_dir: Path, seconds: float) -> None:
    from PIL import Image
    from pyglet.window import key, mouse

    from ecs_tentacles.director.panel import DirectorPanel
    from ecs_tentacles.render.sandbox import Sandbox

    sandbox = Sandbox(SCENE, width=SIZE[0], height=SIZE[1], headless=True, hud=False)
    camera = sandbox.renderer.camera
    camera.target = np.array([0.0, -3.5, 0.0])  # the crowd in the middle of the picture
    camera.distance, camera.pitch, camera.yaw = 22.0, np.radians(62.0), -np.pi / 2
    event, pixel = _events(sandbox)
    frames: list[Image.Image] = []

    def shot() -> Image.Image:
        sandbox.render()
        return Image.fromarray(sandbox.renderer.target.read())

    first = shot()
    panel = sandbox.panel("Director")
    assert isinstance(panel, DirectorPanel)
    panel.radius, panel.density, panel.count, panel.seed = 3.0, 6.0, 50, 1
    event("on_key_press", key.S, 0)
    turns = np.linspace(np.pi, 3.0 * np.pi, 33)
    path = [(BRUSH_PATH * np.cos(a), BRUSH_PATH * np.sin(a), 0.0) for a in turns]
    event("on_mouse_press", *pixel(path[0]), mouse.LEFT, 0)
    for i, point in enumerate(path[1:]):
        event("on_mouse_drag", *pixel(point), 4, 0, mouse.LEFT, 0)
        if i % 4 == 3:
            frames.append(shot())
    scattered = shot()
    event("on_mouse_release", *pixel(path[-1]), mouse.LEFT, 0)
    event("on_key_release", key.S, 0)
    count = len(sandbox.world.creature_specs)
    print(f"scattered: {count - 1} creatures", file=sys.stderr)
    event("on_key_press", key.A, key.MOD_CTRL)
    event("on_mouse_press", *pixel(POINT), mouse.LEFT, 0)
    event("on_mouse_release", *pixel(POINT), mouse.LEFT, 0)
    sent = shot()
    frames.append(sent)
    fps = sandbox.world.settings.fps
    for step in range(int(seconds / GIF_SECONDS)):
        sandbox.step(int(fps * GIF_SECONDS))
        frames.append(shot())
        print(f"{(step + 1) * GIF_SECONDS:.0f} s of {seconds:g}", file=sys.stderr)
    last = frames[-1]
    sandbox.close()
    pictures = [first, scattered, sent, last]
    png, gif = save_sequence(out_dir, "director", pictures, [first, *frames], GIF_WIDTH, 300)
    print(f"{png}, {gif}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=DEFAULT_DIR)
    parser.add_argument("--seconds", type=float, default=60.0, help="simulated after sending")
    args = parser.parse_args(argv)
    if not 1.0 <= args.seconds <= 600.0:
        parser.error("--seconds must be in [1, 600]")
    args.out_dir.mkdir(parents=True, exist_ok=True)
    configure(headless=True)
    run(args.out_dir, args.seconds)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
