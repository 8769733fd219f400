"""Validate scene data against the scene JSON Schema and a few semantic rules.

Every problem is one line ``"<json path>: <message>"``; paths look like
``creatures[1].tentacles.end_scale`` and the root itself is called ``scene``.

The schema a scene is checked against is assembled (`ecs_tentacles.scene.schema`): the
core schema plus the fragment of each plugin the scene turns on; each plugin's
`plugins.<name>` config is checked against the plugin's own `config_schema`.
"""

from __future__ import annotations

import copy
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

from ecs_tentacles.plugin import calling
from ecs_tentacles.scene.defaults import copied, fill, nested, resolve, with_defaults
from ecs_tentacles.scene.json_validator import StrictValidator, validator_for
from ecs_tentacles.scene.plain_pass import passes_check
from ecs_tentacles.scene.problem_text import JsonPath as JsonPath
from ecs_tentacles.scene.problem_text import Problem as Problem
from ecs_tentacles.scene.problem_text import count_bounds, describe, path_key, shown
from ecs_tentacles.scene.problem_text import format_path as format_path
from ecs_tentacles.scene.schema import at, builtin_keys, schema_for
from ecs_tentacles.scene.shards import shard_problems
from ecs_tentacles.scene.spec import CreatureSpec, as_spec, creature_specs

if TYPE_CHECKING:
    from jsonschema.validators import _Validator  # what `StrictValidator(...)` makes

    from ecs_tentacles.plugin import Plugin


MAX_DEPTH = 32  # a scene is about 8 levels deep; deeper data is refused before recursing


def _semantic_problems(scene: Mapping[str, object]) -> list[Problem]:
    """Rules the schema cannot express; ``scene`` is schema-valid with defaults applied."""
    problems: list[Problem] = []
    creatures = creature_specs(scene)
    seen_names: dict[str, int] = {}
    for i, creature in enumerate(creatures):
        name = creature["name"]
        if name in seen_names:
            first = format_path(("creatures", seen_names[name]))
            problems.append(
                (("creatures", i, "name"), f"duplicate name {shown(name)} (also {first})")
            )
        else:
            seen_names[name] = i
        problems += _creature_rules(("creatures", i), creature)
    return problems + shard_problems(scene)


def _creature_rules(where: JsonPath, creature: CreatureSpec) -> list[Problem]:
    """The rules of one creature entry the schema cannot express (its overrides' indices)."""
    problems: list[Problem] = []
    tentacles = creature["tentacles"]
    count = tentacles["count"]
    seen_indices: dict[int, int] = {}
    for j, override in enumerate(tentacles["overrides"]):
        path: JsonPath = (*where, "tentacles", "overrides", j, "index")
        index = override["index"]
        if index >= count:
            problems.append((path, f"must be < count ({count}), got {index}"))
        if index in seen_indices:
            first = format_path((*where, "tentacles", "overrides", seen_indices[index]))
            problems.append((path, f"duplicate index {index} (also {first})"))
        else:
            seen_indices[index] = j
    return problems


def _schema_problems(data: object, validator: _Validator, prefix: JsonPath = ()) -> list[Problem]:
    errors = list(validator.iter_errors(data))
    # A value of the wrong type (0.5 for an integer) may fail its range too: report the type.
    mistyped = {tuple(e.absolute_path) for e in errors if e.validator == "type"}
    return [
        ((*prefix, *path), message)
        for error in errors
        if error.validator == "type" or tuple(error.absolute_path) not in mistyped
        for path, message in describe(error)
    ]


def schema_problems(
    data: object, schema: Mapping[str, object], prefix: JsonPath = ()
) -> list[Problem]:
    """`data` checked against the JSON Schema `schema` (the scene's validator), each
    problem's path under `prefix` (a plugin's keys: `("game",)`)."""
    return _schema_problems(data, StrictValidator(schema), prefix)


def _plugin_configs(data: Mapping[str, object], plugins: Sequence[Plugin]) -> list[Problem]:
    """Each plugin's `plugins.<name>` config against the plugin's own `config_schema`."""
    chosen = data.get("plugins", {})
    problems: list[Problem] = []
    for plugin in plugins:
        config = chosen.get(plugin.key, {}) if isinstance(chosen, Mapping) else {}
        if isinstance(config, Mapping):
            config = {k: v for k, v in config.items() if k != "from"}
            validator = StrictValidator(plugin.config_schema)
            problems += _schema_problems(config, validator, ("plugins", plugin.key))
    return problems


def registered_problems(scene: Mapping[str, object], plugins: Sequence[Plugin]) -> list[Problem]:
    """What the `SceneChecks` entries of `plugins` find in a defaults-filled `scene` (the
    rules that depend on what the plugins registered: a game's mode)."""
    from ecs_tentacles.scene.registries import SceneChecks, plugin_entries

    registries = plugin_entries(plugins)
    checks = registries.get(SceneChecks)
    return [problem for check in checks for problem in check(scene, registries)]


def validate_scene(data: object, plugins: Sequence[Plugin] | None = None) -> list[str]:
    """Return every problem of ``data`` as a scene, sorted by JSON path; ``[]`` if it is valid.

    Each problem is one line ``"<json path>: <message>"``. ``plugins`` are the plugins
    the scene turns on (`ecs_tentacles.scene.plugins.resolve`; default: the default ones): their
    keys are part of the schema, and their own rules run. Semantic rules (override
    indices, unique names) are checked only once the schema passes; overlapping bodies
    are a physical problem (`ecs_tentacles.scene.physical`), checked when loading.
    """
    return validated(data, plugins)[0]


def validated(
    data: object, plugins: Sequence[Plugin] | None = None
) -> tuple[list[str], dict[str, object] | None]:
    """`validate_scene`'s problems, and `with_defaults(data)` when there are none.

    The loader uses the scene completed here instead of completing it a second time
    (a crowd of 10,000 creatures took 1.4 s each time).
    """
    if plugins is None:
        from ecs_tentacles.scene.plugins import resolve

        plugins = resolve(None)
    schema = schema_for(plugins)
    too_long = _limit_problems(data, schema, schema)  # iterative, stops at long arrays
    if too_long:  # checked first: validating a million goals would take minutes
        return [f"{format_path(path)}: {message}" for path, message in too_long], None
    deep = _too_deep(data)
    if deep is not None:  # before anything recursive (jsonschema, deepcopy, json.dumps)
        return [f"{format_path(deep)}: nested deeper than {MAX_DEPTH} levels"], None
    problems = _schema_problems(data, validator_for(schema))
    if isinstance(data, dict):
        problems += _plugin_configs(data, plugins)
    full = None
    if not problems and isinstance(data, dict):
        full = with_defaults(data, plugins)
        problems = _semantic_problems(full)
        for plugin in plugins:
            with calling(plugin, "problems"):
                problems += plugin.problems(full)
        problems += registered_problems(full, plugins)
    problems = _name_plugins_that_are_off(problems, {p.name for p in plugins})
    unique = sorted(set(problems), key=path_key)
    lines = [f"{format_path(path)}: {message}" for path, message in unique]
    return lines, None if lines else full


def validated_creature(
    entry: object, scene: Mapping[str, object], plugins: Sequence[Plugin]
) -> tuple[list[str], dict[str, object] | None]:
    """`entry` checked as one more creature of `scene` (validated, defaults in: a running
    world's, with the creatures it has now), and the entry with its defaults filled in
    when there are no problems (a spawn's: `ecs_tentacles.creatures.spawning`).

    The entry alone is checked against the scene schema's creature, completed and held
    to the creature rules; the plugins' checks (`Plugin.problems`, `SceneChecks`) see it
    among the scene's creatures, in the scene's game and settings, and only what they
    find in it is reported. Each problem is one line whose path starts at `creature`.
    """
    schema = schema_for(plugins)
    entries = at(schema, "properties", "creatures", "items")
    items = resolve(entries, schema)
    creatures = creature_specs(scene)
    where: JsonPath = ("creatures", len(creatures))
    lines = _entry_lines
    too_long = _limit_problems(entry, items, schema)
    if too_long:
        return lines([((*where, *path), message) for path, message in too_long]), None
    deep = _too_deep(entry, where)
    if deep is not None:
        return lines([(deep, f"nested deeper than {MAX_DEPTH} levels")]), None
    problems = _schema_problems(entry, validator_for(_entry_schema(schema, entries)), where)
    if problems or not isinstance(entry, dict):
        return lines(_name_plugins_that_are_off(problems, {p.name for p in plugins})), None
    completed = {key: copied(value) for key, value in entry.items()}  # (`copied`)
    fill(completed, items, schema)
    problems = _creature_rules(where, as_spec(completed))
    if not problems:
        among = {**scene, "creatures": [*creatures, completed]}
        found: list[Problem] = []
        for plugin in plugins:
            with calling(plugin, "problems"):
                found += plugin.problems(among)
        found += registered_problems(among, plugins)
        problems = [problem for problem in found if problem[0][: len(where)] == where]
    return lines(problems), None if problems else completed


def _entry_lines(problems: list[Problem]) -> list[str]:
    """A spawned entry's problems, sorted, their paths starting at `creature`."""
    unique = sorted(set(problems), key=path_key)
    return [format_path(("creature", *path[2:])) + f": {message}" for path, message in unique]


def _entry_schema(schema: dict[str, object], entries: Mapping[str, object]) -> dict[str, object]:
    """The schema of one creature entry (`entries`, its `creatures.items`) of the
    assembled `schema`, its `$defs` along; made once per assembled schema, so its
    validator is made once too."""
    found = _ENTRY_SCHEMAS.get(id(schema))
    if found is None or found[0] is not schema:
        if len(_ENTRY_SCHEMAS) > 64:
            _ENTRY_SCHEMAS.clear()
        entry = {**entries, "$defs": schema.get("$defs", {})}
        found = _ENTRY_SCHEMAS[id(schema)] = (schema, entry)
    return found[1]


_ENTRY_SCHEMAS: dict[int, tuple[dict[str, object], dict[str, object]]] = {}


def repaired(data: object, plugins: Sequence[Plugin]) -> dict[str, object] | None:
    """`data` with every value the schema refuses taken out (so its default applies) and
    unknown keys dropped: a scene the later stages (semantic and physical checks) can
    look at while the schema's problems are reported, so one run reports them all.

    None when that cannot be done without guessing: a required key missing, a list item
    or the whole scene of the wrong kind, or problems that remain after the repair.
    """
    schema = schema_for(plugins)
    if not isinstance(data, dict) or _limit_problems(data, schema, schema):
        return None  # too long to look at twice
    if _too_deep(data) is not None:
        return None  # copying it would recurse too deep
    fixed = copy.deepcopy(data)
    validator = validator_for(schema)
    errors = list(validator.iter_errors(fixed))
    for error in sorted(errors, key=lambda e: -len(e.absolute_path)):  # deepest first
        path = tuple(error.absolute_path)
        try:
            node: object = fixed
            for part in path[:-1] if path else ():
                node = json_child(node, part)
            if error.validator == "additionalProperties":
                container = json_child(node, path[-1]) if path else node
                if not isinstance(container, dict):
                    raise TypeError("additionalProperties: not an object")
                allowed = (
                    error.schema.get("properties", {}) if isinstance(error.schema, dict) else {}
                )
                for key in [k for k in container if k not in allowed]:
                    del container[key]
            elif error.validator == "required" or not path or not isinstance(node, dict):
                return None  # a missing key, the scene itself, or a list item (renumbering)
            else:
                node.pop(path[-1], None)
        except (KeyError, IndexError, TypeError):
            return None
    if _schema_problems(fixed, validator) or _plugin_configs(fixed, plugins):
        return None
    return fixed


def json_child(node: object, part: str | int) -> object:
    """`node[part]` of JSON data: a KeyError, IndexError or TypeError as indexing
    raises them."""
    if isinstance(node, dict):
        return node[part]
    if isinstance(node, list) and isinstance(part, int):
        return node[part]
    raise TypeError(f"{type(node).__name__} has no item {part!r}")


def _place(path: JsonPath) -> str | None:
    """Where a key at `path` sits: a creature's key, a tentacle key, a scene key."""
    if len(path) == 1:
        return "scene"
    if len(path) == 3 and path[0] == "creatures":
        return "creature"
    tentacles = len(path) == 4 or (len(path) == 6 and path[3] == "overrides")
    if tentacles and path[0] == "creatures" and path[2] == "tentacles":
        return "tentacles"
    return None


def _name_plugins_that_are_off(problems: list[Problem], on: set[str]) -> list[Problem]:
    """An unknown key that a built-in plugin which is off would know says so."""
    from ecs_tentacles.scene.plugins import shipped

    if not any(message.startswith("unknown key") for _, message in problems):
        return problems
    off = {name: builtin_keys(name) for name in shipped() if name not in on}
    named: list[Problem] = []
    for path, message in problems:
        place = _place(path) if message.startswith("unknown key") else None
        owner = next((n for n, keys in off.items() if path[-1] in keys.get(place or "", ())), None)
        if owner is not None:
            message = (
                f"unknown key: the {owner} plugin's, which is off (turn it on, or remove"
                " the key: `ecs-tentacles migrate` does)"
            )
        named.append((path, message))
    return named


def _too_deep(data: object, start: JsonPath = ()) -> JsonPath | None:
    """The path of the first value nested deeper than `MAX_DEPTH`, or None (no recursion);
    `data` sits at `start` in the scene."""
    stack: list[tuple[JsonPath, object]] = [(start, data)]
    while stack:
        path, value = stack.pop()
        if len(path) > MAX_DEPTH:
            return path
        if isinstance(value, dict):
            stack.extend(((*path, str(k)), v) for k, v in value.items())
        elif isinstance(value, list):  # numbers and strings go no deeper: not stacked
            stack.extend(((*path, i), v) for i, v in nested(value))
    return None


def _limit_problems(
    data: object, schema: Mapping[str, object], root: Mapping[str, object]
) -> list[Problem]:
    """Arrays longer than their schema's `maxItems`, found without descending into them
    (nor into values that surely pass their schema: `passes_check`, which looks at an
    array's length before its items)."""
    problems: list[Problem] = []
    stack: list[tuple[JsonPath, object, Mapping[str, object]]] = [((), data, schema)]
    resolver = getattr(validator_for(root), "_resolver", None) if isinstance(root, dict) else None
    while stack:
        path, value, node = stack.pop()
        check = passes_check(node, resolver)
        if check is not None and check(value):
            continue
        node = resolve(node, root)
        if isinstance(value, list):
            most, items = node.get("maxItems"), node.get("items")
            if isinstance(most, int) and len(value) > most:
                problems.append(
                    (path, f"must have {count_bounds(node, 'Items')}, got {len(value)}")
                )
            elif isinstance(items, Mapping):
                stack.extend(((*path, i), v, items) for i, v in nested(value))
        elif isinstance(value, dict):
            properties = node.get("properties", {})
            if isinstance(properties, Mapping):
                stack.extend(
                    ((*path, k), v, properties[k])
                    for k, v in value.items()
                    if isinstance(properties.get(k), Mapping)
                )
    return sorted(problems, key=path_key)
