"""Skinned export options (`Skin`, from `ecs_tentacles.skin.rig`) and the writer that
picks USD or glTF from the suffix.

Skinned is what `ecs-tentacles export` and `bake` write by default: one mesh per
creature bound to a joint skeleton with rotation keys, which an animator can grab and
adjust in Blender, Maya, Houdini or a game engine. `--rigid` keeps the capsule form
(one transform per body, exact world poses: for checking the physics).
"""

from __future__ import annotations

import os
from collections.abc import Callable

from ecs_tentacles.export.kinds import output_kind
from ecs_tentacles.skin.keys import KeyReport
from ecs_tentacles.skin.rig import Skin as Skin  # where the writers' options are
from ecs_tentacles.take import Take


def write_skinned(
    take: Take,
    path: str | os.PathLike[str],
    skin: Skin,
    locators: bool = False,
    progress: Callable[[int], object] | None = None,
) -> KeyReport:
    """Write `take` with skinned creatures as USD or glTF (by suffix), atomically; with
    `locators`, suckers and goals too; `progress(1)` as each creature is done."""
    kind = output_kind(path)
    if kind == "usd":
        from ecs_tentacles.export.skinned_usd import write_skinned_usd

        return write_skinned_usd(take, path, skin, locators, progress)
    if kind == "gltf":
        from ecs_tentacles.export.skinned_gltf import write_skinned_glb

        return write_skinned_glb(take, path, skin, locators, progress)
    raise ValueError(f"{path}: skinned creatures are written as USD or glTF, not {kind}")
