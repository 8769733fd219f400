"""Parsing JSON from a file that may lie: bounded size, nesting and number length.

    header = bounded_json.loads(text, "header", max_bytes=64 * 1024**2)

Python's `json` takes any number of any length (a 400-digit integer comes back as an
int no float can hold: `math.isfinite`, `float()` and numpy raise OverflowError later)
and nests as deep as the stack allows (RecursionError, here or in whatever walks the
result). Files the project reads back (take headers, work shards) are parsed here
instead, which refuses with a `JsonLimit` (a ValueError) whose one line names the JSON
path where it can:

- text longer than `max_bytes`: `header: larger than 67108864 bytes`;
- a number written with more than `max_number` characters (no float or seed needs 100):
  `header.fps: a number of 400 characters, at most 100`;
- arrays and objects nested more than `max_depth` deep: `header: nested deeper than
  64 levels`.

Malformed JSON stays a `json.JSONDecodeError`. No files: it parses the text it is given.
"""

from __future__ import annotations

import json
import re
from collections.abc import Callable
from typing import Any

MAX_DEPTH = 64  # take headers nest 5 deep
MAX_NUMBER = 100  # characters of one number: a float's repr needs 24, an int64 20
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


class JsonLimit(ValueError):
    """JSON beyond a limit of `loads`; the message is one line naming where."""


class _Long:
    """Stands in for a number too long to convert, until its path is known."""

    __slots__ = ("length",)

    def __init__(self, length: int) -> None:
        self.length = length


def loads(
    text: str | bytes,
    where: str,
    *,
    max_bytes: int,
    max_depth: int = MAX_DEPTH,
    max_number: int = MAX_NUMBER,
) -> Any:
    """`json.loads(text)` within the limits above; `where` names the document in errors."""
    if len(text) > max_bytes:
        raise JsonLimit(f"{where}: larger than {max_bytes} bytes")
    long = False

    def number(kind: type[int] | type[float]) -> Callable[[str], int | float | _Long]:
        def parse(literal: str) -> int | float | _Long:
            nonlocal long
            if len(literal) > max_number:  # never converted: no float could hold it
                long = True
                return _Long(len(literal))
            return kind(literal)

        return parse

    try:
        value = json.loads(text, parse_int=number(int), parse_float=number(float))
    except RecursionError:  # deeper than the stack: certainly deeper than max_depth
        raise JsonLimit(f"{where}: nested deeper than {max_depth} levels") from None
    problem = _problem(value, where, max_depth, max_number, long)
    if problem:
        raise JsonLimit(problem)
    return value


Entry = tuple[object, int, "tuple[Entry, object] | None"]  # value, depth, (parent, key)


def _problem(value: object, where: str, max_depth: int, max_number: int, long: bool) -> str | None:
    """The first container nested too deep or (when `long`) number too long, or None.
    A loop, not recursion: the value may be nested as deep as the parser allowed."""
    if isinstance(value, _Long):
        return f"{where}: a number of {value.length} characters, at most {max_number}"
    stack: list[Entry] = [(value, 1, None)]
    while stack:
        entry = stack.pop()
        item, depth, _ = entry
        if not isinstance(item, dict | list):
            continue
        if depth > max_depth:
            return f"{where}: nested deeper than {max_depth} levels"
        pairs = item.items() if isinstance(item, dict) else enumerate(item)
        for key, child in pairs:
            if isinstance(child, dict | list):
                stack.append((child, depth + 1, (entry, key)))
            elif long and isinstance(child, _Long):
                path = _path((child, depth + 1, (entry, key)), where)
                return f"{path}: a number of {child.length} characters, at most {max_number}"
    return None


def _path(entry: Entry, where: str) -> str:
    """`where.bodies[3].radius` for the entry at the end of a chain of parents."""
    keys: list[object] = []
    link = entry[2]
    while link is not None:
        parent, key = link
        keys.append(key)
        link = parent[2]
    parts = [where]
    for key in reversed(keys):
        if isinstance(key, int):
            parts.append(f"[{key}]")
        elif isinstance(key, str) and _NAME.fullmatch(key):
            parts.append(f".{key}")
        else:
            parts.append(f"[{json.dumps(key)[:40]}]")
    return "".join(parts)
