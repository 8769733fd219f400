"""Writing a scene: validated first, then JSON written through the one atomic writer."""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from ecs_tentacles.atomic import atomic_output
from ecs_tentacles.scene.load import load_scene


def save_scene(scene: dict[str, Any], path: str | os.PathLike[str]) -> Path:
    """Validate `scene` (SceneError listing the problems if not) and write it atomically."""
    load_scene(scene)
    target = Path(path)
    with atomic_output(target) as temporary:
        temporary.write_text(json.dumps(scene, indent=1) + "\n", encoding="utf-8")
    return target
