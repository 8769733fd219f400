"""Exporters: takes (npz), USD and glTF, all written atomically.

    take = bake(BakePlan.make("octopus", seconds=2))     # ecs_tentacles.export.bake
    write(take, "octopus.usda")                          # or .npz, .usd, .usdc, .glb

Modules: `take` (the file format), `recording` (World -> Take), `bake` (headless
runs), `usd`, `gltf` (rigid bodies), `skinned`, `skinned_usd`, `skinned_gltf` (skinned
creatures, `ecs_tentacles.skin`), `atomic` (temporary file + rename).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import TYPE_CHECKING

from ecs_tentacles.export.kinds import output_kind
from ecs_tentacles.take import Take, TakeError

if TYPE_CHECKING:
    from ecs_tentacles.export.skinned import Skin
    from ecs_tentacles.export.take_chunks import ChunkSource
    from ecs_tentacles.skin.keys import KeyReport

__all__ = [
    "SUFFIXES",
    "Take",
    "TakeError",
    "output_kind",
    "work_units",
    "write",
    "write_usd_stream",
]

SUFFIXES = (".npz", ".usd", ".usda", ".usdc", ".glb")


def write(
    take: Take,
    path: str | os.PathLike[str],
    progress: Callable[[int], object] | None = None,
    skin: Skin | None = None,
    locators: bool | None = None,
) -> KeyReport | None:
    """Write `take` in the format its suffix names (see `SUFFIXES`), atomically.

    `progress(n)` hears of the work done, n of the units `work_units` names at a time.
    With `skin`, USD and glTF get skinned creatures (`ecs_tentacles.export.skinned`) and
    the key report is returned; without, rigid bodies. `locators`: suckers and goals as
    locators (USD Xforms, glTF nodes); None is the form's default: off when skinned, on
    when rigid.
    """
    kind = output_kind(path)
    if kind != "take":  # a take refuses itself (`Take.save`), with its own verb
        take.check_exportable(path)
    if skin is not None and kind in ("usd", "gltf"):
        from ecs_tentacles.export.skinned import write_skinned

        return write_skinned(take, path, skin, bool(locators), progress)
    if kind == "take":
        take.save(path, progress)
    elif kind == "usd":
        from ecs_tentacles.export.usd import write_usd

        write_usd(take, path, progress, locators is not False)
    elif kind == "gltf":
        from ecs_tentacles.export.gltf import write_glb

        write_glb(take, path, locators is not False, progress)
    else:
        raise ValueError(f"{path}: unknown output format (use {', '.join(SUFFIXES)})")
    return None


def write_usd_stream(
    source: ChunkSource,
    path: str | os.PathLike[str],
    progress: Callable[[int], object] | None = None,
    skin: Skin | None = None,
    locators: bool | None = None,
) -> KeyReport | None:
    """Write a take read a chunk of frames at a time (`ecs_tentacles.take.stream.open_take`)
    as USD, atomically: skinned with `skin` (the key report returned), else rigid;
    `progress(n)` as n more frames are written; `locators` as `write`'s."""
    if skin is not None:
        from ecs_tentacles.export.skinned_usd import write_skinned_usd

        return write_skinned_usd(source, path, skin, bool(locators), progress)
    from ecs_tentacles.export.usd import write_usd

    write_usd(source, path, progress, locators is not False)
    return None


def work_units(
    take: Take, path: str | os.PathLike[str], skin: Skin | None = None
) -> tuple[int, str]:
    """(how many, of what) `write(take, path, progress, skin)` tells `progress` of: the
    bytes of a take's arrays, the frames of a USD file (written a chunk of frames at a
    time), the creatures of a skinned glb, the bodies of a rigid one."""
    kind = output_kind(path)
    if kind == "take":
        return take.stored_bytes(), "B"
    if kind == "usd":
        return take.frames, "frame"
    if skin is not None:
        return len(take.header["creatures"]), "creature"
    return len(take.header["bodies"]), "body"
