"""Schema defaults filled into scene data (`with_defaults`, `plugin_config`).

Every `default` of the assembled schema (`ecs_tentacles.scene.schema`) goes into a deep
copy of the scene: objects, array items, local `$ref`s, `x-presets`, and each plugin's
config under `plugins`. Lists of plain numbers and strings (a million heights) are
passed over and copied at C speed (`nested`, `copied`).
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any

from ecs_tentacles.scene.schema import schema_for

if TYPE_CHECKING:
    from ecs_tentacles.plugin import Plugin

ATOMS = {int, float, str, bool, type(None)}  # JSON values that hold no others


def nested(values: list[object]) -> list[tuple[int, object]]:
    """The (index, item) of the objects and lists in `values` (a list of a million numbers
    is passed over at C speed)."""
    if set(map(type, values)) <= ATOMS:
        return []
    return [(i, v) for i, v in enumerate(values) if isinstance(v, (dict, list))]


# (id(schema), id(root)) -> (schema, root, resolved): both kept alive, so the ids stay theirs
_Schema = Mapping[str, object]
_RESOLVED: dict[tuple[int, int], tuple[_Schema, _Schema, _Schema]] = {}


def resolve(schema: Mapping[str, object], root: Mapping[str, object]) -> Mapping[str, object]:
    """Follow local ``$ref``s; keywords beside a ``$ref`` (like ``default``) win.

    Worked out once per schema object and root (a crowd's creatures resolve the same
    `$ref`s some hundred thousand times); the answer is read, never written."""
    if "$ref" not in schema:
        return schema
    found = _RESOLVED.get((id(schema), id(root)))
    if found is not None and found[0] is schema and found[1] is root:
        return found[2]
    resolved = _resolve(schema, root)
    if len(_RESOLVED) > 4096:
        _RESOLVED.clear()
    _RESOLVED[id(schema), id(root)] = (schema, root, resolved)
    return resolved


def _resolve(schema: Mapping[str, object], root: Mapping[str, object]) -> Mapping[str, object]:
    """`resolve`, worked out."""
    seen: set[str] = set()
    ref = schema.get("$ref")
    while isinstance(ref, str) and ref not in seen:
        seen.add(ref)
        target: object = root
        for part in ref.removeprefix("#").strip("/").split("/"):
            if part:
                if not isinstance(target, Mapping):
                    raise TypeError(f"$ref {ref!r} goes through a value that is no object")
                target = target[part.replace("~1", "/").replace("~0", "~")]
        if not isinstance(target, Mapping):
            raise TypeError(f"$ref {ref!r} names a value that is no schema object")
        schema = {**target, **{k: v for k, v in schema.items() if k != "$ref"}}
        ref = schema.get("$ref")
    return schema


def _fill(value: object, schema: Mapping[str, object], root: Mapping[str, object]) -> None:
    """Fill schema defaults into ``value`` in place, recursing into objects and arrays."""
    schema = resolve(schema, root)
    if isinstance(value, dict):
        presets = schema.get("x-presets", {})
        preset = value.get("preset")
        if isinstance(presets, Mapping) and preset in presets:  # fills what the scene lacks
            _merge_under(value, presets[preset])
        properties = schema.get("properties", {})
        for key, sub in properties.items() if isinstance(properties, Mapping) else ():
            if not isinstance(sub, Mapping):
                continue  # (`true`: no defaults)
            sub = resolve(sub, root)
            if key not in value and "default" in sub:
                value[key] = copy.deepcopy(sub["default"])
            if key in value:
                _fill(value[key], sub, root)
    elif isinstance(value, list):
        items = schema.get("items")
        if isinstance(items, Mapping):
            for _, item in nested(value):  # defaults go into objects only
                _fill(item, items, root)


def fill(value: object, schema: Mapping[str, object], root: Mapping[str, object]) -> None:
    """Fill the defaults of `schema` (a part of the schema `root`, whose `$ref`s it may
    use) into `value` in place (a spawned creature's entry: `validate.validated_creature`)."""
    _fill(value, schema, root)


def _merge_under(value: dict[str, object], base: object) -> None:
    """Copy into ``value`` every key of ``base`` (an object) it lacks, merging nested objects."""
    for key, item in base.items() if isinstance(base, Mapping) else ():
        if key not in value:
            value[key] = copy.deepcopy(item)
            continue
        mine = value[key]
        if isinstance(mine, dict) and isinstance(item, Mapping):
            _merge_under(mine, item)


def copied(data: object) -> object:
    """A deep copy of scene data (JSON-like; anything else through `copy.deepcopy`); a
    list of numbers is copied at once (a million heights took a second one by one)."""
    if type(data) is dict:
        return {key: copied(value) for key, value in data.items()}
    if type(data) is list:
        if set(map(type, data)) <= ATOMS:
            return list(data)  # immutable items: nothing to copy further
        return [copied(value) for value in data]
    return data if type(data) in ATOMS else copy.deepcopy(data)


def plugin_config(plugin: Plugin, given: object) -> dict[str, Any]:
    """A plugin's config as a scene gives it (`true`, absent or an object), defaults filled."""
    return filled(given if isinstance(given, Mapping) else {}, plugin.config_schema)


def filled(data: Mapping[str, object], schema: Mapping[str, object]) -> dict[str, object]:
    """A deep copy of `data` with the defaults of its own JSON Schema `schema` filled in
    (a plugin's config, a game mode's keys)."""
    out = copy.deepcopy(dict(data))
    _fill(out, schema, schema)
    return out


def with_defaults(
    data: dict[str, object], plugins: Sequence[Plugin] | None = None
) -> dict[str, Any]:
    """Return a deep copy of ``data`` with every schema ``default`` filled in.

    Works recursively through nested objects (objects defaulting to ``{}`` get their own
    defaults too), array items and ``$ref``s. An object whose schema has ``x-presets``
    and whose ``preset`` names one first takes the preset's values it lacks. Creatures
    without a name are called ``creature_<index>``. Optional fields without a default
    stay absent; ``data`` is not modified. ``plugins`` (default: the default ones) add
    their keys' defaults, and each plugin's config gets its defaults under `plugins`.
    """
    result = {key: copied(value) for key, value in data.items()}  # (`copied`)
    if plugins is None:
        from ecs_tentacles.scene.plugins import resolve

        plugins = resolve(None)
    schema = schema_for(plugins)
    _fill(result, schema, schema)
    chosen = result.get("plugins")
    if isinstance(chosen, dict):  # absent (most scenes): the defaults are the plugins' own
        for plugin in plugins:
            chosen[plugin.key] = plugin_config(plugin, chosen.get(plugin.key))
    creatures = result.get("creatures")
    if isinstance(creatures, list):
        for i, creature in enumerate(creatures):
            if isinstance(creature, dict):
                creature.setdefault("name", f"creature_{i}")
    filled: dict[str, object] = result
    return filled
