"""The README's "Directing a crowd" pictures: a headless sandbox driven by the same mouse
and key events a player makes (no API shortcuts).

    python tools/director_screenshots.py                     # into assets/screenshots/
    python tools/director_screenshots.py --out-dir shots/ --seconds 20

1. one octopus on the sand; 2. S + drag: the brush scatters 50 octopuses (seeded);
3. Ctrl+A and a click at a point: each gets its own goal in a ring round it; 4. after
`--seconds`, the crowd gathering round the point. Writes `director_sequence.png` (the
four, 2 x 2) and `director.gif` (the same run, a frame every half second, smaller).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ecs_tentacles.render import configure

DEFAULT_DIR = Path(__file__).resolve().parents[1] / "assets" / "screenshots"
SIZE = (960, 540)
GIF_WIDTH = 480
POINT = (6.0, 0.0, 0.0)  # where the crowd is sent
SCENE = {
    "version": 1,
    "name": "director",
    "physics": {"lod": {"enabled": True}},
    "creatures": [{"name": "octopus", "position": [-6.0, 0.0]}],
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
    camera.target = np.array([0.0, 0.0, 0.0])
    camera.distance, camera.pitch, camera.yaw = 21.0, np.radians(55.0), -np.pi / 2
    event, pixel = _events(sandbox)
    frames: list[Image.Image] = []

    def shot() -> Image.Image:
        pixels = sandbox.render()
        assert pixels is not None
        return Image.fromarray(pixels)

    first = shot()
    panel = sandbox.panel("Director")
    assert isinstance(panel, DirectorPanel)
    panel.radius, panel.density, panel.count, panel.seed = 3.0, 6.0, 50, 1
    event("on_key_press", key.S, 0)
    path = [(-9.0 + 0.5 * i, 3.5 * np.sin(0.35 * i), 0.0) for i in range(25)]
    event("on_mouse_press", *pixel(path[0]), mouse.LEFT, 0)
    for point in path[1:]:
        event("on_mouse_drag", *pixel(point), 4, 0, mouse.LEFT, 0)
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
    fps = sandbox.world.settings.fps
    for half in range(int(2 * seconds)):
        sandbox.step(int(fps / 2))
        frames.append(shot())
        print(f"{(half + 1) / 2:.1f} s of {seconds:g}", file=sys.stderr)
    last = frames[-1]
    sandbox.close()
    w, h = SIZE
    sheet = Image.new("RGB", (2 * w, 2 * h))
    for i, picture in enumerate((first, scattered, sent, last)):
        sheet.paste(picture, ((i % 2) * w, (i // 2) * h))
    sheet.save(out_dir / "director_sequence.png", optimize=True)
    small = [f.resize((GIF_WIDTH, GIF_WIDTH * h // w)) for f in [first, *frames]]
    small[0].save(
        out_dir / "director.gif", save_all=True, append_images=small[1:], duration=250, loop=0
    )
    print(f"{out_dir / 'director_sequence.png'}, {out_dir / 'director.gif'}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=DEFAULT_DIR)
    parser.add_argument("--seconds", type=float, default=30.0, help="simulated after sending")
    args = parser.parse_args(argv)
    if not 1.0 <= args.seconds <= 600.0:
        parser.error("--seconds must be in [1, 600]")
    args.out_dir.mkdir(parents=True, exist_ok=True)
    configure(headless=True)
    run(args.out_dir, args.seconds)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
