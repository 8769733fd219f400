"""`WorldOptions`: how a scene's world is built, over what the scene itself says.

One frozen object carries a run's choices from where they are made (the command line:
`ecs_tentacles.cli.world_options`; a script) to the world that uses them:
`World.from_scene(scene, options)`, the sandbox (`Sandbox`, `SandboxSession`), bakes
(`BakePlan.world`) and the shards of a distributed bake (`ecs_tentacles.distributed`).

    options = WorldOptions(seed=7, threads=2, lod=False)
    world = World.from_scene("crowd.json", options)
    shard = World.from_scene("crowd.json", options.but(only={0, 1}))

Reads and writes nothing.
"""

from __future__ import annotations

import os
import pathlib
import warnings
from collections.abc import Collection, Mapping
from dataclasses import dataclass, replace
from typing import Any

__all__ = ["Focus", "WorldOptions"]

Focus = tuple[float, float, float]  # x, y, radius (m): a circle on the ground


@dataclass(frozen=True)
class WorldOptions:
    """A run's choices over its scene; every field's default keeps what the scene says.

    * `seed`: the random seed (None: the scene's `seed`).
    * `allow_systems`: import the code a scene names (plugins from files or modules, its
      `systems`); refused without it.
    * `threads`: threads stepping the physics (None: one per core); results do not
      depend on it.
    * `lod`: level of detail on (True) or off (False: every creature at full physics)
      over the scene's `physics.lod.enabled` (None: the scene's).
    * `focus`: (x, y, radius in m): creatures in this circle always run full physics.
    * `plugins`: plugins turned on, off or configured over the scene's `plugins`
      (`{"locomotion": False}`: scripts drive the motors).
    * `scene_dir`: the folder plugin files are looked up in, for a scene given as a dict
      (a file's own folder otherwise).
    * `only`: build just the creatures at these scene indices (a shard of a distributed
      bake); `world.scene` is still the whole scene.
    """

    seed: int | None = None
    allow_systems: bool = False
    threads: int | None = None
    lod: bool | None = None
    focus: Focus | None = None
    plugins: Mapping[str, object] | None = None
    scene_dir: pathlib.Path | None = None
    only: frozenset[int] | None = None

    def __post_init__(self) -> None:
        # accept what callers naturally hold (a set, a str path, a list) and keep it frozen
        if self.only is not None and not isinstance(self.only, frozenset):
            object.__setattr__(self, "only", frozenset(self.only))
        if self.scene_dir is not None and not isinstance(self.scene_dir, pathlib.Path):
            object.__setattr__(self, "scene_dir", pathlib.Path(os.fspath(self.scene_dir)))
        if self.focus is not None:
            x, y, radius = (float(v) for v in self.focus)
            object.__setattr__(self, "focus", (x, y, radius))
        if self.plugins is not None:  # a copy: the caller's dict may change after
            object.__setattr__(self, "plugins", dict(self.plugins))

    def but(self, **changes: Any) -> WorldOptions:
        """These options with `changes` (`options.but(threads=1, only={3})`)."""
        return replace(self, **changes)

    def with_only(self, only: Collection[int] | None) -> WorldOptions:
        """These options building just the creatures at scene indices `only`."""
        return self.but(only=None if only is None else frozenset(only))

    def given(self, keywords: Mapping[str, object], where: str) -> WorldOptions:
        """These options with old-style keywords over them (`bake(plan, threads=2)`, from
        before the options had an object), with a DeprecationWarning naming `where`;
        TypeError for a keyword no field has."""
        if not keywords:
            return self
        warnings.warn(
            f"{where}: the keywords {', '.join(keywords)} are deprecated; pass them in a"
            " WorldOptions (ecs_tentacles.options)",
            DeprecationWarning,
            stacklevel=3,
        )
        return self.but(**keywords)

    def scene_with_lod(self, scene: Mapping[str, object]) -> dict[str, object]:
        """`scene` with `lod` and `focus` written into its `physics.lod` (a new dict;
        `scene` is left as it was): a bake's take and its shards see them in the scene
        and its hash. The same scene unchanged (a copy of the top level) without them."""
        if self.lod is None and self.focus is None:
            return dict(scene)
        given = scene.get("physics")
        physics = dict(given) if isinstance(given, Mapping) else {}
        given = physics.get("lod")
        lod = dict(given) if isinstance(given, Mapping) else {}
        if self.lod is not None:
            lod["enabled"] = self.lod
        if self.focus is not None:
            x, y, radius = self.focus
            lod["focus"] = {"center": [x, y], "radius": radius}
        physics["lod"] = lod
        return {**scene, "physics": physics}
