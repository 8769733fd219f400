"""How a scene problem reads: its JSON path (`creatures[1].tentacles.end_scale`, the root
called `scene`) and, from a JSON Schema error, a message a person can act on (the value
shown short, the range or count the schema allows, the type it wants).

Read by `ecs_tentacles.scene.validate`, which finds the problems."""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterable, Mapping

from jsonschema import ValidationError

JsonPath = tuple[str | int, ...]
Problem = tuple[JsonPath, str]

_IDENT = re.compile(r"^[A-Za-z_$][A-Za-z0-9_$]*$")
_TYPE_NAMES = {
    "number": "a number",
    "integer": "an integer",
    "string": "a string",
    "boolean": "a boolean",
    "object": "an object",
    "array": "an array",
    "null": "null",
}
_MAX_SHOWN = 60


def format_path(path: Iterable[str | int]) -> str:
    """Format a path such as ``("creatures", 1, "name")`` as ``creatures[1].name``."""
    out = ""
    for part in path:
        if isinstance(part, int):
            out += f"[{part}]"
        elif _IDENT.fullmatch(part):
            out += f".{part}" if out else part
        else:
            out += f"[{json.dumps(part)}]"
    return out or "scene"


def shown(value: object) -> str:
    """JSON text of a value, shortened so a problem stays one readable line."""
    try:
        text = json.dumps(value)
    except (TypeError, ValueError):
        shape = getattr(value, "shape", None)
        if isinstance(shape, tuple) and hasattr(value, "tolist"):  # a script's numpy array
            return f"a numpy array of shape {shape} (give a list: .tolist())"
        text = " ".join(repr(value).split())  # one line, whatever the object prints
    return text if len(text) <= _MAX_SHOWN else text[: _MAX_SHOWN - 3] + "..."


def _range(schema: Mapping[str, object]) -> str:
    """Describe every numeric bound of ``schema``: ``in (0, 1]``, ``>= 1`` or ``< 5``."""
    low: tuple[str, object] | None = None
    high: tuple[str, object] | None = None
    if "exclusiveMinimum" in schema:
        low = ("(", schema["exclusiveMinimum"])
    elif "minimum" in schema:
        low = ("[", schema["minimum"])
    if "exclusiveMaximum" in schema:
        high = (")", schema["exclusiveMaximum"])
    elif "maximum" in schema:
        high = ("]", schema["maximum"])
    if low and high:
        return f"in {low[0]}{shown(low[1])}, {shown(high[1])}{high[0]}"
    if low:
        return f"{'>' if low[0] == '(' else '>='} {shown(low[1])}"
    assert high is not None
    return f"{'<' if high[0] == ')' else '<='} {shown(high[1])}"


def count_bounds(schema: Mapping[str, object], unit: str) -> str:
    """Describe minItems/maxItems-style bounds: ``2 to 3 items``, ``at least 1 item``."""
    low, high = schema.get(f"min{unit}"), schema.get(f"max{unit}")
    noun = "items" if unit == "Items" else "characters"
    if low is not None and high is not None:
        return f"exactly {low} {noun}" if low == high else f"{low} to {high} {noun}"
    return f"at least {low} {noun}" if low is not None else f"at most {high} {noun}"


def describe(error: ValidationError) -> list[Problem]:
    """Turn one jsonschema error into human one-line problems (with their paths)."""
    path: JsonPath = tuple(error.absolute_path)
    schema: Mapping[str, object] = error.schema if isinstance(error.schema, Mapping) else {}
    value: object = error.instance
    expected: object = error.validator_value
    listed = expected if isinstance(expected, list) else [expected]  # types, keys, options
    kind = error.validator
    got = f"got {shown(value)}"
    if kind == "type" and isinstance(value, float) and not math.isfinite(value):
        return [(path, f"must be a finite number, {got}")]
    if kind == "type":
        names = [str(t) for t in listed]
        return [(path, f"must be {' or '.join(_TYPE_NAMES.get(t, t) for t in names)}, {got}")]
    if kind in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum"):
        return [(path, f"must be {_range(schema)}, {got}")]
    if kind == "additionalProperties" and isinstance(value, Mapping):
        properties = schema.get("properties", {})
        allowed = sorted(properties) if isinstance(properties, Mapping) else []
        extra = [key for key in value if key not in allowed]
        hint = f"unknown key (allowed: {', '.join(allowed)})"
        return [((*path, key), hint) for key in extra]
    if kind == "required" and isinstance(value, Mapping):
        return [((*path, str(key)), "is required") for key in listed if key not in value]
    if kind == "enum":
        options = ", ".join(shown(option) for option in listed)
        return [(path, f"must be one of {options}, {got}")]
    if kind == "const":
        return [(path, f"must be {shown(expected)}, {got}")]
    if kind in ("minItems", "maxItems") and isinstance(value, list):
        return [(path, f"must have {count_bounds(schema, 'Items')}, got {len(value)}")]
    if kind in ("minLength", "maxLength") and isinstance(value, str):
        return [(path, f"must have {count_bounds(schema, 'Length')}, got {len(value)}")]
    if kind == "uniqueItems":
        return [(path, f"must not repeat an item, got {shown(value)}")]
    if kind == "pattern":
        given = schema.get("x-hint")
        hint = given if isinstance(given, str) and given else f"text matching {expected}"
        return [(path, f"must be {hint}, {got}")]
    return [(path, " ".join(error.message.split()))]


def path_key(problem: Problem) -> tuple[tuple[tuple[int, int | str], ...], str]:
    """Sort key: paths compared part by part (indices numerically), then the message."""
    parts = tuple((0, p) if isinstance(p, int) else (1, p) for p in problem[0])
    return parts, problem[1]
