"""Every README picture of the sandbox, made headless with the current HUD: the
four-creature sandbox, the HUD at 640 x 360, the skinned octopus, the three terrain
scenes (rocky shore, ramp, maze; HUD hidden; the shore and the ramp in the clean view,
the maze with the path navigation planned) and, through `tools/fur_screenshots.py`
(`--only fur`), the fur pictures and, through `tools/director_screenshots.py` (`--only
director`), the crowd director's sequence. (The plots are the benchmarks': `tools/crowd_scaling.py`,
`tools/slope_climb.py`.)

    python tools/readme_screenshots.py                       # into assets/screenshots/
    python tools/readme_screenshots.py --out-dir shots/ --only hud_640x360
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

from ecs_tentacles.cli import main as cli

# name -> (scene, frames, width, height, HUD shown, camera or None): what each README
# picture shows (camera: `play --camera`; None frames the creatures at the start)
SHOTS = {
    "sandbox": ("thesis_four_by_six", 240, 1280, 720, True, None),  # four round a square
    "hud_640x360": ("octopus", 60, 640, 360, True, None),  # the HUD in a small window
    # terrain: six crossing the rocks, seen low from the shore, the sky behind
    "rocky_shore": ("rocky_shore", 900, 960, 540, False, "-6.2,-7.0,2.7,0.4,0.6,0.2"),
    # terrain: cresting the ramp, the goal's platform beyond (framing the start cut it off)
    "ramp": ("ramp", 2700, 960, 540, False, "0.3,-3.6,2.4,2.2,0.0,0.4"),
    # terrain: the path navigation planned, the maze whole (framing the start cut it off)
    "maze": ("maze", 600, 960, 540, False, "3.5,-7.5,5.5,0.0,-0.3,0.0"),
}
# pictures for showing (`play --clean`: none of the editor's overlays); the sandbox and HUD
# pictures show the editor, the maze the path navigation planned
CLEAN = {"rocky_shore", "ramp"}
CLOSE_UP = ("octopus", 120, 960, 540)  # skinned_sandbox: the skinned octopus, no HUD, near
DEFAULT_DIR = Path(__file__).resolve().parents[1] / "assets" / "screenshots"


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=DEFAULT_DIR)
    names = sorted([*SHOTS, "skinned_sandbox", "fur", "director"])
    parser.add_argument("--only", choices=names, action="append", help="one picture")
    args = parser.parse_args(argv)
    args.out_dir.mkdir(parents=True, exist_ok=True)
    for name in args.only or names:
        if name in ("fur", "director"):  # their own scripts, each in a process of its own
            script = Path(__file__).with_name(f"{name}_screenshots.py")
            done = subprocess.run([sys.executable, str(script), "--out-dir", str(args.out_dir)])
            if done.returncode:
                return done.returncode
            continue
        if name == "skinned_sandbox":
            _close_up(args.out_dir / f"{name}.png")
            continue
        scene, frames, width, height, hud, camera = SHOTS[name]
        out = args.out_dir / f"{name}.png"
        argv_play = ["play", scene, "--headless", "--frames", str(frames), "--quiet"]
        argv_play += ["--hud"] if hud else ["--no-hud"]
        argv_play += ["--clean"] if name in CLEAN else []
        argv_play += ["--width", str(width), "--height", str(height), "--screenshot", str(out)]
        argv_play += [f"--camera={camera}"] if camera else []
        code = cli(argv_play)
        if code:
            return code
        print(f"{out}: {scene} after {frames} frames, {width} x {height}", file=sys.stderr)
    return 0


def _close_up(out: Path) -> None:
    """The octopus after `CLOSE_UP` frames, framed close, HUD hidden, in the clean view
    (through the API: nearer than any `--camera` choice frames it)."""
    from ecs_tentacles.render import configure

    configure(headless=True)
    from ecs_tentacles.render.sandbox import Sandbox

    scene, frames, width, height = CLOSE_UP
    sandbox = Sandbox(scene, width=width, height=height, headless=True, hud=False, clean=True)
    sandbox.step(frames)
    # on the octopus alone (`frame_all` also takes in its far goal), its ring inside
    sandbox.renderer.follow(sandbox.renderer.creature_entities[0], span=1.5)
    sandbox.screenshot(out)
    print(f"{out}: {scene} after {frames} frames, {width} x {height}, close up", file=sys.stderr)


if __name__ == "__main__":
    raise SystemExit(main())
