"""tools/readme_screenshots.py: the README's sandbox pictures come from one script."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parents[2]


def _tool():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location(
        "readme_screenshots", ROOT / "tools" / "readme_screenshots.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_every_picture_the_script_makes_is_in_the_readme_and_it_makes_one(tmp_path: Path) -> None:
    tool = _tool()
    readme = (ROOT / "README.md").read_text()
    shown = set(re.findall(r"assets/screenshots/(\w+)\.png", readme))
    assert {*tool.SHOTS, "skinned_sandbox"} <= shown
    assert tool.main(["--out-dir", str(tmp_path), "--only", "hud_640x360"]) == 0
    with Image.open(tmp_path / "hud_640x360.png") as image:
        pixels = np.asarray(image.convert("RGB"))
    assert pixels.shape == (360, 640, 3)
    panel, view = pixels[:, :150].reshape(-1, 3), pixels[:, 300:].reshape(-1, 3)
    assert (panel.mean(axis=1) > 200).mean() > 0.5  # the HUD's light panel on the left
    assert (view.mean(axis=1) > 200).mean() < 0.1  # the ground on the right
