"""The creature creator's model: everything its window edits, builds and exports.

The thesis's creator (III.B, IV.A.2) works in two steps, and so does this class:

1. uniform settings: mantle radius and height, tentacle count, and for every
   tentacle the first link's length and radius, the number of links and the end
   scale; `build(...)` ("Build creature") makes every tentacle the same;
2. customising: `select(k)` a tentacle, then `set_tentacle(link_length=...,
   link_radius=..., end_scale=...)`, `add_link()`, `remove_link()` (thesis table 1);
   `set_mantle(...)` still resizes the mantle.

`preview_world()` builds the World the window draws, `scene()` / `export(path)`
give the scene JSON ("Export to simulation"). The creature is built from exactly
that scene, so loading the exported file builds the creature that was shown.
Bad values raise `DesignError` naming the field, and leave the design unchanged.

    design = CreatureDesign(name="squid")
    design.build(count=6, links=10, end_scale=0.4)
    design.select(2)
    design.add_link()
    design.export("squid.json")
"""

from __future__ import annotations

import copy
import json
import os
import pathlib
import re
from dataclasses import asdict, dataclass, replace
from typing import TYPE_CHECKING, Any, TypedDict

from ecs_tentacles.creator.limits import DesignError, checked, default
from ecs_tentacles.output.atomic import atomic_file
from ecs_tentacles.scene.construction import TentacleShape, tentacle_shape
from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.load import load_scene, read_scene_json, resolve_scene_path
from ecs_tentacles.scene.schema import load_schema

if TYPE_CHECKING:
    from typing_extensions import Unpack  # (typing's own from Python 3.12)

    from ecs_tentacles.world import World

SHAPE_KEYS = ("links", "link_length", "link_radius", "end_scale")


class UniformSettings(TypedDict, total=False):
    """The creature's uniform settings (`CreatureDesign(...)`, `build`); None: as it is."""

    mantle_radius: float | None
    mantle_height: float | None
    count: int | None
    links: int | None
    link_length: float | None
    link_radius: float | None
    end_scale: float | None


@dataclass(frozen=True)
class TentacleDesign:
    """One tentacle: the first link's length and radius, link count, end scale (tip / base)."""

    links: int
    link_length: float
    link_radius: float
    end_scale: float

    def checked(self, prefix: str = "") -> TentacleDesign:
        """A copy with every value checked against the scene schema."""
        values = {k: checked(prefix + k, "tentacles", k, getattr(self, k)) for k in SHAPE_KEYS}
        return TentacleDesign(**values)


class CreatureDesign:
    """A creature being designed; see the module docstring for the two steps."""

    def __init__(self, name: str = "creature", **settings: Unpack[UniformSettings]):
        self.name = name  # checked by the property
        self.mantle_radius: float = default("mantle", "radius")
        self.mantle_height: float = default("mantle", "height")
        self.uniform = TentacleDesign(*(default("tentacles", k) for k in SHAPE_KEYS))
        self.tentacles: list[TentacleDesign] = []
        self.selected: int | None = None
        # the rest of a loaded scene and creature entry (physics, locomotion, strength...)
        self._scene: dict[str, Any] = {"version": 1}
        self._creatures: list[dict[str, Any]] = [{}]
        self._index = 0
        self.build(**settings)

    @property
    def name(self) -> str:
        """The creature's name: letters, digits and _, not starting with a digit."""
        return self._name

    @name.setter
    def name(self, value: str) -> None:
        pattern = load_schema()["$defs"]["name"]["pattern"]
        if not isinstance(value, str) or not re.fullmatch(pattern, value):
            raise DesignError(
                "name", f"must be letters, digits and _, not starting with a digit, got {value!r}"
            )
        self._name = value

    # -- step 1: uniform settings ------------------------------------------------------
    def build(self, **settings: Unpack[UniformSettings]) -> None:
        """The "Build creature" button: take these uniform settings, make every tentacle so.

        Settings left out or None keep their current value. Per-tentacle changes are lost.
        """
        changes: dict[str, Any] = {k: settings.get(k) for k in SHAPE_KEYS}
        uniform = replace(self.uniform, **{k: v for k, v in changes.items() if v is not None})
        uniform = uniform.checked()
        count = settings.get("count")
        if count is None:
            count = len(self.tentacles) or default("tentacles", "count")
        number = checked("count", "tentacles", "count", count)
        self.set_mantle(radius=settings.get("mantle_radius"), height=settings.get("mantle_height"))
        self.uniform = uniform
        self.tentacles = [uniform] * number
        self.selected = None

    def set_mantle(self, *, radius: float | None = None, height: float | None = None) -> None:
        """Resize the mantle (None keeps a value)."""
        new_radius = self.mantle_radius if radius is None else radius
        new_height = self.mantle_height if height is None else height
        self.mantle_radius = checked("mantle_radius", "mantle", "radius", new_radius)
        self.mantle_height = checked("mantle_height", "mantle", "height", new_height)

    # -- step 2: one tentacle at a time ------------------------------------------------
    def select(self, index: int | None) -> None:
        """Select tentacle `index` (0 lies along +x, counter-clockwise), or nothing."""
        if index is not None and not 0 <= index < len(self.tentacles):
            last = len(self.tentacles) - 1
            raise DesignError("tentacle", f"must be in [0, {last}], got {index}")
        self.selected = index

    def _target(self, index: int | None) -> int:
        if index is None:
            if self.selected is None:
                raise DesignError("tentacle", "no tentacle selected")
            return self.selected
        self.select(index)
        return index

    def set_tentacle(
        self,
        index: int | None = None,
        *,
        links: int | None = None,
        link_length: float | None = None,
        link_radius: float | None = None,
        end_scale: float | None = None,
    ) -> None:
        """Change tentacle `index` (default: the selected one); None keeps a value."""
        k = self._target(index)
        changes: dict[str, Any] = {"links": links, "link_length": link_length}
        changes |= {"link_radius": link_radius, "end_scale": end_scale}
        new = replace(self.tentacles[k], **{f: v for f, v in changes.items() if v is not None})
        self.tentacles[k] = new.checked()

    def add_link(self, index: int | None = None) -> None:
        """Add a link at the end of tentacle `index` (default: the selected one)."""
        k = self._target(index)
        self.set_tentacle(k, links=self.tentacles[k].links + 1)

    def remove_link(self, index: int | None = None) -> None:
        """Remove the last link of tentacle `index` (default: the selected one)."""
        k = self._target(index)
        self.set_tentacle(k, links=self.tentacles[k].links - 1)

    def reset_tentacle(self, index: int | None = None) -> None:
        """Make tentacle `index` (default: the selected one) uniform again."""
        self.tentacles[self._target(index)] = self.uniform

    # -- outputs -----------------------------------------------------------------------
    def shapes(self) -> list[TentacleShape]:
        """Each tentacle's link lengths, radii and centre distances, for quick drawing."""
        return [
            tentacle_shape(self.mantle_radius, t.link_length, t.link_radius, t.links, t.end_scale)
            for t in self.tentacles
        ]

    def creature_entry(self) -> dict[str, Any]:
        """The creature as a scene entry: uniform settings plus per-tentacle overrides."""
        entry = copy.deepcopy(self._creatures[self._index])
        entry["name"] = self.name
        entry.setdefault("position", [0, 0])
        entry["mantle"] = {**entry.get("mantle", {}), "radius": self.mantle_radius}
        entry["mantle"]["height"] = self.mantle_height
        tentacles = {**entry.get("tentacles", {}), "count": len(self.tentacles)}
        tentacles.update(asdict(self.uniform))
        overrides = {o["index"]: o for o in tentacles.get("overrides", [])}
        result = []
        for k, tentacle in enumerate(self.tentacles):
            kept = {f: v for f, v in overrides.get(k, {}).items() if f not in SHAPE_KEYS}
            shape = {f: v for f, v in asdict(tentacle).items() if v != getattr(self.uniform, f)}
            if len(kept) > 1 or shape:  # more than the index alone
                result.append({**kept, "index": k, **shape})
        tentacles["overrides"] = result
        if not result:
            del tentacles["overrides"]
        entry["tentacles"] = tentacles
        return entry

    def scene(self) -> dict[str, Any]:
        """The scene JSON (as a dict) holding this creature, ready to export."""
        scene = copy.deepcopy(self._scene)
        scene.setdefault("name", self.name)
        scene.setdefault("description", "A creature made with the creature creator.")
        creatures = copy.deepcopy(self._creatures)
        creatures[self._index] = self.creature_entry()
        scene["creatures"] = creatures
        return scene

    def export(self, path: str | os.PathLike[str]) -> None:
        """Validate the scene and write it as JSON to `path`, atomically."""
        scene = self.scene()
        load_scene(scene)  # raises SceneError if the schema disagrees with the design
        with atomic_file(path) as handle:
            handle.write((json.dumps(scene, indent=2) + "\n").encode())

    def preview_world(self) -> World:
        """The World of this design as exported (physics compiled, nothing stepped)."""
        from ecs_tentacles.world import World

        return World.from_scene(self.scene())

    @classmethod
    def from_scene(
        cls, source: str | os.PathLike[str] | dict[str, Any], creature: int | str = 0
    ) -> CreatureDesign:
        """Edit creature `creature` (index or name) of a scene; the rest is kept on export."""
        if not isinstance(source, dict):
            source = resolve_scene_path(os.fspath(source))  # a path or a bundled scene's name
        resolved = load_scene(source)  # validates (SceneError) and fills defaults
        raw = source if isinstance(source, dict) else _read(source)
        names = [c["name"] for c in resolved["creatures"]]
        index = names.index(creature) if creature in names else creature
        if not isinstance(index, int) or not 0 <= index < len(names):
            known = ", ".join(names) or "none"
            raise DesignError(
                "creature", f"the scene has no creature {creature!r} (it has {known})"
            )
        entry = resolved["creatures"][index]
        design = cls(entry["name"])
        design._scene = {k: v for k, v in copy.deepcopy(raw).items() if k != "creatures"}
        design._creatures = copy.deepcopy(raw.get("creatures", []))
        design._index = index
        tentacles = entry["tentacles"]
        design.mantle_radius = entry["mantle"]["radius"]
        design.mantle_height = entry["mantle"]["height"]
        design.uniform = TentacleDesign(*(tentacles[k] for k in SHAPE_KEYS))
        design.tentacles = [design.uniform] * tentacles["count"]
        for override in tentacles["overrides"]:
            shape = {k: v for k, v in override.items() if k in SHAPE_KEYS}
            k = override["index"]
            design.tentacles[k] = replace(design.tentacles[k], **shape)
        return design


def _read(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The scene file as written (defaults not filled in), read as every scene is."""
    data = read_scene_json(pathlib.Path(path))
    if not isinstance(data, dict):
        raise SceneError([f"{path}: the scene is not an object"])
    return data
