"""The core keys of a validated scene as TypedDicts: `SceneSpec`, `PhysicsSpec`, `LodSpec`.

What `assets/schema/core.schema.json` says of a scene's top level, its `physics`
(with `lod` and its `focus`) and `render`, as types mypy checks every read of core
against; the creature entry is `scene.spec.CreatureSpec`. A plugin's scene keys
(`terrain`, `game`, ...) are the plugin's own: it declares a TypedDict of its own
and narrows the `Mapping[str, object]` its hooks receive (docs "Architecture",
"Types"). `tests/scene/test_scene_spec.py` holds these keys equal to the schema's.
Reads nothing, writes nothing.
"""

from __future__ import annotations

from typing import Literal, Required, TypedDict

from ecs_tentacles.scene.json_types import JsonObject
from ecs_tentacles.scene.spec import CreatureSpec


class FocusSpec(TypedDict):
    """A region whose creatures always run the full physics."""

    center: list[float]  # x, y (m)
    radius: float  # m


class LodSpec(TypedDict, total=False):
    """`physics.lod`: level-of-detail budgets (`ecs_tentacles.settings.LodSettings`)."""

    enabled: bool
    full: int
    reduced: int
    hold_seconds: float
    contact_margin: float  # m
    focus: FocusSpec


class PhysicsSpec(TypedDict):
    """A scene's `physics`, defaults filled in (`ecs_tentacles.settings.Settings`)."""

    fps: float
    substeps: int
    gravity: list[float]  # m/s^2, x, y, z
    ground_friction: float
    sucker_timeconst: float  # s
    max_speed: float  # m/s
    max_penetration: float  # m
    sleep: bool
    lod: LodSpec
    separate_overlaps: bool  # read while building only (`settings.BUILD_ONLY`)


class RenderSpec(TypedDict, total=False):
    """How the sandbox draws the scene."""

    palette: Literal["natural", "debug"]


# "$schema" is no identifier: the functional form names it
_SceneKeys = TypedDict(
    "_SceneKeys",
    {
        "$schema": str,
        "version": Required[int],
        "name": str,
        "description": str,
        "seed": int,
        "physics": PhysicsSpec,
        "systems": list[str],  # "package.module:ClassName"
        "plugins": dict[str, bool | JsonObject],  # name -> on/off or its config
        "creatures": list[CreatureSpec],
        "shards": list[list[str]],  # creature names
        "render": RenderSpec,
    },
    total=False,
)


class SceneSpec(_SceneKeys):
    """The core keys of a validated scene (plugins' keys ride along untyped here)."""
