"""Schemas turned into plain Python checks that tell a value surely passes them.

jsonschema descends into every object and array of a scene, and each descent costs some
microseconds: a crowd of 10,000 creatures took about two seconds. `passes_check(schema,
resolver)` makes, once per schema, a function of a value that is True only when
jsonschema would find nothing wrong with it, and False when it might: the validator
(`ecs_tentacles.scene.json_validator`) skips a value that passes and descends into any
other as before, so the problems reported, their paths and messages are jsonschema's.

Only the keywords a scene's schema uses are turned into checks (types, bounds, lengths,
`enum` and `const` of strings, `pattern`, `properties`, `required`,
`additionalProperties`, `items`, local `$ref`s); a schema with any other keyword gets
no check (None), and its parent's check answers False wherever it holds a value
under that schema, so only that value is descended into.
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable, Mapping
from typing import Any

from referencing.exceptions import Unresolvable

Check = Callable[[object], bool]

# A schema's notes, which say nothing of a value (x-... are ours too):
NOTES = frozenset({"description", "default", "title", "examples", "$comment", "$schema", "$defs"})
_BOUNDS = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")
LONG_NUMBERS = 64  # arrays of numbers at least this long: the validator's numpy check


@functools.lru_cache(maxsize=256)
def ecma_pattern(pattern: str) -> re.Pattern[str]:
    """`pattern` as JSON Schema (ECMA 262) reads it: `$` is the end of the text.

    Python's `$` also matches before a trailing newline, which let `"octo\\n"` pass as a
    name; here every `$` outside a character class becomes `\\Z`.
    """
    out, escaped, in_class = [], False, False
    for char in pattern:
        if escaped:
            escaped = False
        elif char == "\\":
            escaped = True
        elif char == "[":
            in_class = True
        elif char == "]":
            in_class = False
        elif char == "$" and not in_class:
            char = r"\Z"
        out.append(char)
    return re.compile("".join(out))


def _is_number(value: object) -> bool:
    if isinstance(value, float):
        return math.isfinite(value)
    return isinstance(value, int) and not isinstance(value, bool)


# JSON Schema's types as the scene validator reads them (an integer is written 8, a
# number is finite; bool is neither):
TYPES: dict[str, Check] = {
    "object": lambda value: isinstance(value, dict),
    "array": lambda value: isinstance(value, list),
    "string": lambda value: isinstance(value, str),
    "boolean": lambda value: isinstance(value, bool),
    "null": lambda value: value is None,
    "integer": lambda value: isinstance(value, int) and not isinstance(value, bool),
    "number": _is_number,
}


# (id(schema), base URI) -> (schema kept alive, its check or None):
_CHECKS: dict[tuple[int, str], tuple[object, Check | None]] = {}
_MOST = 8192


def passes_check(schema: object, resolver: Any) -> Check | None:
    """A function telling a value surely passes `schema` (True) or might not (False);
    None when the schema uses a keyword not turned into a check. `resolver` is the
    validator's (`referencing`'s Resolver where `schema` sits), for local `$ref`s."""
    base = str(getattr(resolver, "_base_uri", ""))
    key = (id(schema), base)
    found = _CHECKS.get(key)
    if found is not None and found[0] is schema:
        return found[1]
    if len(_CHECKS) > _MOST:
        _CHECKS.clear()
    if schema is True:
        check: Check | None = _always
    elif not isinstance(schema, dict):
        check = None
    else:
        later: list[Check | None] = []  # a schema that refers to itself meets its own key
        _CHECKS[key] = (schema, lambda value: later[0] is not None and later[0](value))
        try:
            check = _object_check(schema, resolver, base)
        except Unresolvable:
            check = None
        later.append(check)
    _CHECKS[key] = (schema, check)
    return check


def _always(value: object) -> bool:
    return True


def _object_check(schema: dict[str, Any], resolver: Any, base: str) -> Check | None:
    """`passes_check` of a schema object: every keyword's check, all of which must pass."""
    rules = {k: v for k, v in schema.items() if k not in NOTES and not k.startswith("x-")}
    checks: list[Check] = []
    ref = rules.pop("$ref", None)
    if ref is not None:
        if not base or not isinstance(ref, str) or not ref.startswith("#"):
            return None  # a scene's refs are to its own $defs, under its $id
        resolved = resolver.lookup(ref)
        target = passes_check(resolved.contents, resolved.resolver)
        if target is None:
            return None
        checks.append(target)
    kind = rules.pop("type", None)
    bounds = [rules.pop(k, None) for k in _BOUNDS]
    if kind in ("number", "integer"):  # a number's type and bounds in one test
        checks.append(_number_check(kind, *bounds))
    else:
        if kind is not None:
            kinds = [kind] if isinstance(kind, str) else kind
            if not all(k in TYPES for k in kinds):
                return None  # (jsonschema says the type is unknown)
            tests = [TYPES[k] for k in kinds]
            checks.append(tests[0] if len(tests) == 1 else _any(tests))
        if any(b is not None for b in bounds):
            checks.append(_bounds_check(*bounds))
    for keyword in ("minItems", "maxItems", "minLength", "maxLength", "maxProperties"):
        if keyword in rules:
            checks.append(_length_check(keyword, rules.pop(keyword)))
    for keyword in ("enum", "const"):
        if keyword in rules:
            allowed = rules.pop(keyword)
            allowed = allowed if keyword == "enum" else [allowed]
            if not isinstance(allowed, list) or not all(isinstance(a, str) for a in allowed):
                return None
            checks.append(_one_of(frozenset(allowed)))
    if "pattern" in rules:
        search = ecma_pattern(rules.pop("pattern")).search
        checks.append(lambda value: not isinstance(value, str) or search(value) is not None)
    if "items" in rules:
        if "prefixItems" in rules:
            return None
        items = rules.pop("items")
        each = passes_check(items, resolver)
        checks.append(_items_check(each, long_numbers=_plain_number(items)))
    if {"properties", "required", "additionalProperties"} & rules.keys():
        found = _properties_check(
            rules.pop("properties", {}),
            rules.pop("required", []),
            rules.pop("additionalProperties", True),
            resolver,
        )
        if found is None:
            return None
        checks.append(found)
    if rules:  # a keyword not turned into a check
        return None
    return _all(checks)


def _not_a_check(value: object) -> bool:
    """`_properties_check`'s stand-in for a name with no schema (no schema's check)."""
    return False


def _all(checks: list[Check]) -> Check:
    """True where every one of `checks` is."""
    if not checks:
        return _always
    if len(checks) == 1:
        return checks[0]
    if len(checks) == 2:
        first, second = checks
        return lambda value: first(value) and second(value)

    def passes(value: object) -> bool:
        for check in checks:
            if not check(value):
                return False
        return True

    return passes


def _one_of(allowed: frozenset[str]) -> Check:
    """`enum` or `const` of strings: a string (not a subclass) among them."""
    return lambda value: type(value) is str and value in allowed


def _any(checks: list[Check]) -> Check:
    return lambda value: any(check(value) for check in checks)


def _within(low: Any, high: Any, above: Any, below: Any) -> Callable[[float], bool]:
    """Whether a finite number is within the bounds (each None when absent)."""

    def within(value: float) -> bool:
        return (
            (low is None or not value < low)
            and (high is None or not value > high)
            and (above is None or not value <= above)
            and (below is None or not value >= below)
        )

    return within


def _number_check(kind: str, low: Any, high: Any, above: Any, below: Any) -> Check:
    """`type` number (finite) or integer (written 8, not 8.0), within its bounds."""
    integer = kind == "integer"
    within = _within(low, high, above, below)

    def passes(value: object) -> bool:
        if isinstance(value, float):
            if integer or not math.isfinite(value):
                return False
        elif not isinstance(value, int) or isinstance(value, bool):
            return False
        return within(value)

    return passes


def _bounds_check(low: Any, high: Any, above: Any, below: Any) -> Check:
    """Numeric bounds, which say nothing of a value that is not a number; a number
    that is not finite is left to jsonschema (False)."""
    within = _within(low, high, above, below)

    def passes(value: object) -> bool:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            return True
        if isinstance(value, float) and not math.isfinite(value):
            return False
        return within(value)

    return passes


def _length_check(keyword: str, limit: Any) -> Check:
    """minItems / maxItems (lists), minLength / maxLength (strings, in code points as
    Python counts them), maxProperties (objects)."""
    kind = {"Items": list, "Length": str, "Properties": dict}[keyword[3:]]
    most = keyword.startswith("max")
    if not isinstance(limit, int):
        return lambda value: not isinstance(value, kind)

    def passes(value: object) -> bool:
        if not isinstance(value, kind):
            return True
        size = len(value)
        return size <= limit if most else size >= limit

    return passes


def _plain_number(schema: object) -> bool:
    """Whether `schema` is a number's type and bounds only: a long array of such items is
    left to the validator, which checks it with numpy (`json_validator.FAST_ITEMS`), not
    with a call per number (a million heights)."""
    return (
        isinstance(schema, dict)
        and schema.get("type") == "number"
        and all(k in NOTES or k == "type" or k in _BOUNDS for k in schema)
    )


def _items_check(each: Check | None, long_numbers: bool = False) -> Check:
    if each is None:  # an array's items are left to jsonschema
        return lambda value: not isinstance(value, list) or not value
    if long_numbers:
        return lambda value: (
            not isinstance(value, list) or (len(value) < LONG_NUMBERS and all(map(each, value)))
        )
    return lambda value: not isinstance(value, list) or all(map(each, value))


def _properties_check(
    properties: Mapping[str, object], required: list[str], extra: object, resolver: Any
) -> Check | None:
    """`properties`, `required` and `additionalProperties` (False or a schema)."""
    if not isinstance(properties, Mapping) or not isinstance(required, list):
        return None
    known = {name: passes_check(sub, resolver) for name, sub in properties.items()}
    other = None if extra is False else passes_check(extra, resolver)
    closed = extra is False
    needed = tuple(required)
    missing = _not_a_check

    def passes(value: object) -> bool:
        if not isinstance(value, dict):
            return True
        for name in needed:
            if name not in value:
                return False
        for name, item in value.items():
            check = known.get(name, missing)
            if check is missing:
                check = None if closed else other
            if check is None or not check(item):
                return False
        return True

    return passes
