"""The scene schema: the core schema plus each plugin's fragment, assembled.

`assets/schema/core.schema.json` holds physics and the creatures' bodies. Each plugin
adds creature keys, scene keys, tentacle keys (which its tentacles' `overrides` get too,
without default) and `$defs`; a built-in plugin's fragment is `<name>.schema.json` in
its feature package, read without importing the plugin. `load_schema()` is the schema
of a scene that says nothing about plugins (the default plugins on); `schema_for` that
of a scene turning on the given plugins.
"""

from __future__ import annotations

import copy
import functools
import importlib.resources
import importlib.util
import json
import pathlib
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ecs_tentacles.plugin import Plugin

PLACES = ("$defs", "creature", "scene", "tentacles")  # where a fragment adds keys
NOT_IN_OVERRIDES = ("default", "x-parameter")  # an override's key only changes one tentacle
Part = tuple[str, tuple[Mapping[str, object], ...]]  # plugin key, its keys by place (PLACES)


@functools.cache
def core_schema() -> dict[str, Any]:
    """The core scene schema bundled with the package, without any plugin's keys."""
    resource = importlib.resources.files("ecs_tentacles.assets") / "schema" / "core.schema.json"
    schema: dict[str, object] = json.loads(resource.read_text(encoding="utf-8"))
    return schema


@functools.cache
def fragment(package: str, name: str) -> dict[str, Any]:
    """A built-in plugin's schema fragment: `<name>.schema.json` in its feature package."""
    found: dict[str, object] = json.loads(_fragment_file(package, name).read_text(encoding="utf-8"))
    return found


def plugin_schemas(package: str, name: str) -> tuple[dict[str, Any], ...]:
    """A feature plugin's `creature_schema`, `tentacle_schema`, `scene_schema` and `defs`
    from its fragment (`fragment(package, name)`; {} for a place it has no keys in). In
    the plugin's class body, its own package and name:

        creature_schema, tentacle_schema, scene_schema, defs = plugin_schemas(__package__, name)
    """
    found = fragment(package, name)
    return tuple(found.get(place, {}) for place in ("creature", "tentacles", "scene", "$defs"))


def _fragment_file(package: str, name: str) -> importlib.resources.abc.Traversable:
    """`<name>.schema.json` in a feature package, found without importing the package
    (nor its top: `importlib.resources.files` would run an examples package's
    `__init__`)."""
    top, *rest = package.split(".")
    spec = importlib.util.find_spec(top)
    folders = list(spec.submodule_search_locations or []) if spec is not None else []
    if not folders:
        return importlib.resources.files(top).joinpath(*rest, f"{name}.schema.json")
    return pathlib.Path(folders[0]).joinpath(*rest, f"{name}.schema.json")


def builtin_fragment(name: str) -> dict[str, object]:
    """The fragment of the engine's plugin `name` ({} when it has none), its code not
    imported (where it is: its entry point)."""
    from ecs_tentacles.scene.plugins import shipped

    package = shipped()[name].partition(":")[0].rpartition(".")[0]  # the feature package
    return fragment(package, name) if _fragment_file(package, name).is_file() else {}


def builtin_keys(name: str) -> dict[str, set[str]]:
    """A built-in plugin's keys by place (`creature`, `tentacles`, `scene`)."""
    by_place = dict(zip(PLACES, by_places(builtin_fragment(name)), strict=True))
    return {place: set(by_place[place]) for place in ("creature", "tentacles", "scene")}


def by_places(part: Mapping[str, object]) -> tuple[Mapping[str, object], ...]:
    """A fragment's keys at each of `PLACES` ({} where it adds none)."""
    found = (part.get(place, {}) for place in PLACES)
    return tuple(keys if isinstance(keys, Mapping) else {} for keys in found)


def at(schema: Mapping[str, object], *path: str) -> Mapping[str, object]:
    """The schema object at `path` in `schema` (`at(schema, "properties", "physics")`);
    a KeyError naming the path where there is none."""
    node = schema
    for i, key in enumerate(path):
        child = node.get(key)
        if not isinstance(child, Mapping):
            raise KeyError(f"schema: no object at {'.'.join(path[: i + 1])}")
        node = child
    return node


def schema_for(plugins: Sequence[Plugin]) -> dict[str, object]:
    """The core schema with each plugin's keys added."""
    parts = [
        (p.key, (p.defs, p.creature_schema, p.scene_schema, p.tentacle_schema)) for p in plugins
    ]
    if any(p.source is not None for p in plugins):  # users' plugins: assembled each time
        return _assemble(parts)
    key = tuple((p.key, type(p)) for p in plugins)  # built-in fragments never change
    if key not in _SCHEMAS:
        _SCHEMAS[key] = _assemble(parts)
    return _SCHEMAS[key]


_SCHEMAS: dict[tuple[tuple[str, type], ...], dict[str, object]] = {}


@functools.cache
def load_schema() -> dict[str, Any]:
    """The schema of a scene that turns no plugin on or off (the default plugins' keys).

    Assembled from the fragment files of the default plugins (their code is not imported).
    """
    from ecs_tentacles.scene.plugins import default_on

    parts = [(name, builtin_fragment(name)) for name in default_on()]
    return _assemble([(name, by_places(part)) for name, part in parts])


def _assemble(parts: Sequence[Part]) -> dict[str, object]:
    """Core schema + each plugin's keys. Tentacle keys join the creature's `tentacles`
    and, without their default and parameter annotation, each entry of its `overrides`."""
    schema = copy.deepcopy(core_schema())
    schema["$id"] = schema["$id"].replace("core.schema.json", "scene.schema.json")
    owner: dict[tuple[str, str], str] = {}
    creature = schema["$defs"]["creature"]["properties"]
    places = dict(
        zip(
            PLACES,
            (schema["$defs"], creature, schema["properties"], creature["tentacles"]["properties"]),
            strict=True,
        )
    )
    overrides = schema["$defs"]["tentacle_override"]["properties"]
    for key, entries_by_place in parts:
        for place, entries in zip(PLACES, entries_by_place, strict=True):
            for name, entry in entries.items():
                if name in places[place] or (place, name) in owner:
                    first = owner.get((place, name), "core")
                    raise ValueError(
                        f"plugins.{key}: its {place} key {name!r} is already {first}'s"
                    )
                owner[(place, name)] = key
                places[place][name] = copy.deepcopy(entry)
                if place == "tentacles" and isinstance(entry, Mapping):
                    overrides[name] = {
                        k: copy.deepcopy(v) for k, v in entry.items() if k not in NOT_IN_OVERRIDES
                    }
    return schema
