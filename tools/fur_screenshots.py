"""Headless pictures of the fur scenes: the presets side by side (labelled), the hedgehog
octopus before and after the roach arrives (quills lowered, then raised), close-ups of
cat hair and bird feathers as lit strands (these in the clean view: no overlays), and the
fur tool editing the hedgehog (its markers and timeline shown).

    python tools/fur_screenshots.py --out-dir shots/
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ecs_tentacles.render import configure


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=Path("."))
    parser.add_argument("--width", type=int, default=1280)
    parser.add_argument("--height", type=int, default=720)
    args = parser.parse_args()
    args.out_dir.mkdir(parents=True, exist_ok=True)
    configure(headless=True)
    from ecs_tentacles.components import Transform
    from ecs_tentacles.fur.render.furpanel import FurPanel
    from ecs_tentacles.render.sandbox import Sandbox

    size = {"width": args.width, "height": args.height, "headless": True}
    presets = Sandbox("fur_presets", **size, clean=True)  # for showing: no overlays
    presets.hud.visible = False
    presets.hud.name_labels = True
    presets.renderer.camera.shift_x = 0.0
    presets.step(90)
    presets.renderer.camera.pitch = np.radians(30)
    presets.renderer.frame_all()  # every preset whole (the fit is tight: no zoom after it)
    print(presets.screenshot(args.out_dir / "fur_presets.png"))
    camera = presets.renderer.camera
    for name in ("cat", "bird"):  # close-ups: the strands' shading and taper
        entity = presets.world.creature(name)
        camera.target = presets.world.component(entity, Transform).pos * [1, 1, 0] + [0, 0, 0.2]
        camera.distance, camera.pitch, camera.yaw = 1.0, np.radians(22), np.radians(-60)
        print(presets.screenshot(args.out_dir / f"fur_{name}_strands.png"))
    presets.close()

    tool = Sandbox("hedgehog_octopus", **size)  # the editor: its overlays are the point
    tool.step(60)
    tool.paused = True
    fur = tool.panel("Fur")
    assert isinstance(fur, FurPanel)
    tool.hud.fold("Locomotion", "Stats", "Physics")
    tool.hud.unfold("Fur")  # one section open at a time: the fur panel in view
    fur.editor.create("L_cheek", shape="cube", colour=(0.2, 0.7, 1.0), mirror="y")
    fur.editor.set_value("L_cheek", "lift", 0.8)
    fur.editor.set_key("crown", "lift", 1.0, "slow_in")
    fur.sync_view()
    fur.display.colour_by = "control"
    fur.refresh_rig(edit=True)
    camera = tool.renderer.camera
    octo = tool.world.creature("hedgehog")
    camera.target = tool.world.component(octo, Transform).pos * [1, 1, 0] + [0, 0, 0.1]
    camera.distance, camera.pitch = 1.4, np.radians(30)
    print(tool.screenshot(args.out_dir / "fur_tool.png"))
    tool.close()

    hedgehog = Sandbox("hedgehog_octopus", **size, clean=True)
    hedgehog.hud.visible = False
    hedgehog.renderer.camera.shift_x = 0.0
    camera = hedgehog.renderer.camera
    camera.shift_x, camera.distance, camera.pitch = 0.0, 1.6, np.radians(28)
    octo = hedgehog.world.creature("hedgehog")
    for name, seconds in (("before", 1.5), ("after", 4.2)):
        hedgehog.step(round(seconds * hedgehog.world.settings.fps) - hedgehog.world.frame)
        camera.target = hedgehog.world.component(octo, Transform).pos * [1, 1, 0] + [0.15, 0, 0]
        print(hedgehog.screenshot(args.out_dir / f"hedgehog_octopus_{name}.png"))
    hedgehog.close()


if __name__ == "__main__":
    main()
