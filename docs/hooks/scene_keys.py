"""The scene reference's markdown (`scenes/reference.md`, written by scene_reference.py when
the site is built), from the schema the validator uses: the core schema
(`assets/schema/core.schema.json`), the fragment of every installed built-in plugin (their
`<name>.schema.json`, read through the plugins themselves) and the `game` keys of every
game mode they register. Every key gets a row; nothing is written by hand, so the page
cannot go stale (tests/docs/test_scene_reference.py)."""

from __future__ import annotations

import importlib
import importlib.metadata
from collections.abc import Iterator, Mapping
from typing import Any

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.scene.schema import core_schema

GROUP = "ecs_tentacles.plugins"
NUMBERS = (
    ("minimum", ">= {}"),
    ("exclusiveMinimum", "> {}"),
    ("maximum", "<= {}"),
    ("exclusiveMaximum", "< {}"),
    ("minItems", "at least {} items"),
    ("maxItems", "at most {} items"),
    ("maxLength", "at most {} characters"),
)


def builtin_plugins() -> dict[str, type[Plugin]]:
    """Every plugin the package itself provides, by name: its entry points in the
    `ecs_tentacles.plugins` group and the names `ecs_tentacles.scene.plugins` knows."""
    targets: dict[str, str] = {}
    for entry in importlib.metadata.entry_points(group=GROUP):
        if entry.dist is not None and entry.dist.name.replace("_", "-") == "ecs-tentacles":
            targets[entry.name] = entry.value
    found = importlib.import_module("ecs_tentacles.scene.plugins")
    for table in ("BUILTIN", "BUNDLED"):
        for name, target in getattr(found, table, {}).items():
            targets.setdefault(name, target)
    classes: dict[str, type[Plugin]] = {}
    for name, target in sorted(targets.items()):
        module, _, attribute = target.partition(":")
        classes[name] = getattr(importlib.import_module(module), attribute)
    return classes


def cell(text: object) -> str:
    """`text` safe inside a markdown table cell."""
    return str(text).replace("|", "\\|").replace("\n", " ")


def kind(node: Mapping[str, Any]) -> str:
    """The key's type as a reader says it (a `$ref` links to its section)."""
    if "$ref" in node:
        name = str(node["$ref"]).rsplit("/", 1)[-1]
        return f"[{name}](#def-{name.replace('_', '-')})"
    if "const" in node:
        return f"`{node['const']!r}`"
    if "enum" in node:
        return " or ".join(f"`{value}`" for value in node["enum"])
    for combined in ("oneOf", "anyOf"):
        if combined in node:
            return " or ".join(kind(option) for option in node[combined])
    found = node.get("type", "")
    text = " or ".join(found) if isinstance(found, list) else str(found)
    items = node.get("items")
    if text == "array" and isinstance(items, Mapping):
        text = f"array of {kind(items)}"
    return text or "any"


def limits(node: Mapping[str, Any]) -> str:
    """Ranges, lengths and the default, in one phrase."""
    said = [form.format(node[key]) for key, form in NUMBERS if key in node]
    if "default" in node and node["default"] not in ({}, []):
        said.append(f"default `{node['default']!r}`")
    return "; ".join(said)


def rows(node: Mapping[str, Any], path: str) -> Iterator[str]:
    """One table row per key under `node` (an object schema), nested keys as `a.b`."""
    properties = node.get("properties", {})
    required = set(node.get("required", ()))
    for name, child in properties.items():
        here = f"{path}.{name}" if path else name
        need = " (required)" if name in required else ""
        description = child.get("description", "")
        yield (
            f"| `{here}`{need} | {cell(kind(child))} | {cell(limits(child))} |"
            f" {cell(description)} |"
        )
        yield from rows(child, here)
        items = child.get("items")
        if isinstance(items, Mapping) and "properties" in items:
            yield from rows(items, f"{here}[]")
        extra = child.get("additionalProperties")
        if isinstance(extra, Mapping) and "properties" in extra:
            yield from rows(extra, f"{here}.<name>")


def table(node: Mapping[str, Any], path: str = "") -> str:
    """The keys under `node` as a markdown table (or a line saying there are none)."""
    lines = list(rows(node, path))
    if not lines:
        return "No keys of its own.\n"
    head = "| key | type | range and default | what it is |\n| --- | --- | --- | --- |\n"
    return head + "\n".join(lines) + "\n"


def section_of_defs(defs: Mapping[str, Any], level: str) -> Iterator[str]:
    """A section for each shared definition, with an anchor `$ref`s link to."""
    for name, node in defs.items():
        anchor = name.replace("_", "-")
        yield f"{level} `{name}` {{#def-{anchor}}}\n\n"
        if node.get("description"):
            yield f"{node['description']}\n\n"
        if "properties" in node:
            yield table(node)
        else:
            yield f"{cell(kind(node))}; {cell(limits(node)) or 'no limits'}.\n"
        yield "\n"


def page() -> str:
    """The whole reference page."""
    core = core_schema()
    out = [
        "# Scene reference\n\n",
        "Every key a scene may hold, generated when the site is built from the schema the"
        " validator checks scenes against: the core schema (`assets/schema/core.schema.json`),"
        " then each built-in plugin's keys (on in a scene only while that plugin is on), then"
        " the `game` keys of each game mode. `ecs-tentacles schema` writes the assembled"
        " schema for an editor. How scenes work: [Scenes](index.md).\n\n",
        "## Core: the scene\n\n",
        f"{core.get('description', '')}\n\n",
        table(core),
        "\n## Core: shared definitions\n\n",
        *section_of_defs(core.get("$defs", {}), "###"),
    ]
    from ecs_tentacles.game.modes import GameModes
    from ecs_tentacles.game.rules import mode_schema
    from ecs_tentacles.scene.registries import plugin_entries

    plugins = builtin_plugins()
    modes = []
    for name, cls in plugins.items():
        out.append(f"## Plugin `{name}`\n\n")
        if cls.description:
            out.append(f"{cls.description}.\n\n".replace("..", "."))
        places = (
            ("Scene keys", cls.scene_schema, ""),
            ("Creature keys (`creatures[]`)", cls.creature_schema, "creatures[]"),
            ("Tentacle keys (`creatures[].tentacles`)", cls.tentacle_schema, "tentacles"),
            (f"Its config (`plugins.{name}`)", cls.config_schema, f"plugins.{name}"),
        )
        shown = False
        for title, keys, path in places:
            node = keys if path.startswith("plugins.") else {"properties": keys}
            if node.get("properties"):
                out += [f"### {title}\n\n", table(node, path), "\n"]
                shown = True
        if not shown:
            out.append("No scene keys of its own.\n\n")
        if cls.defs:
            out += ["### Its shared definitions\n\n", *section_of_defs(cls.defs, "####")]
        try:
            instance = cls()
        except (TypeError, ValueError):  # made only by its layer (the sandbox's renderer)
            continue
        modes += [(name, mode) for mode in plugin_entries([instance]).get(GameModes)]
    for owner, mode in modes:
        out.append(f"## Game mode `{mode.name}` (plugin `{owner}`)\n\n")
        if mode.description:
            out.append(f"{mode.description}\n\n")
        out.append(table(mode_schema(mode), "game"))
        out.append("\n")
    return "".join(out)
