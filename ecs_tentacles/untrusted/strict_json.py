"""JSON text as users write it, parsed strictly: every key once in its object.

    data = strict_loads(text)      # DuplicateKey: '"creatures" twice (line 9, column 3)'

Python's `json` keeps the last of two equal keys without a word, so a scene with
`"creatures"` written twice silently loses the first list. `strict_loads` refuses it,
naming the key and where its second occurrence starts. The parse itself is the standard
library's (its C scanner, at its speed); only when a key repeats is the text walked
again, in pure Python, to find the line and column (`_second_key_at`).

Numbers: a float too large for a double (`1e400`) and the non-standard `NaN` /
`Infinity` literals are refused (ValueError), as a scene's numbers must be finite.
"""

from __future__ import annotations

import json
from json import JSONDecoder
from typing import NoReturn

_WHITESPACE = " \t\n\r"
_CLOSING = {"{": "}", "[": "]"}  # a container's opening character -> its closing one


class DuplicateKey(ValueError):
    """A key written twice in one JSON object; the message names it and its line."""

    def __init__(self, key: str, line: int | None = None, column: int | None = None) -> None:
        where = f" (line {line}, column {column})" if line is not None else ""
        super().__init__(f"{json.dumps(key, ensure_ascii=False)} twice{where}")
        self.key, self.line, self.column = key, line, column


class _Repeated(Exception):
    """Raised from the object hook (carries the key) to leave the C parser at once."""

    def __init__(self, key: str) -> None:
        self.key = key


def _finite_float(text: str) -> float:
    """A JSON number as a float, refusing ones too large for one (1e400 would be inf)."""
    value = float(text)
    if value in (float("inf"), float("-inf")):
        raise ValueError(f"number {text} is too large")
    return value


def _refuse_constant(name: str) -> NoReturn:
    """Refuse the non-standard ``NaN``/``Infinity`` literals Python's json accepts."""
    raise ValueError(f"{name} is not valid JSON")


def _unique_pairs(pairs: list[tuple[str, object]]) -> dict[str, object]:
    """An object's pairs as a dict; `_Repeated` if a key comes twice."""
    out = dict(pairs)
    if len(out) != len(pairs):
        seen: set[str] = set()
        for key, _ in pairs:
            if key in seen:
                raise _Repeated(key)
            seen.add(key)
    return out


_DECODER = JSONDecoder(
    object_pairs_hook=_unique_pairs, parse_float=_finite_float, parse_constant=_refuse_constant
)
_PLAIN = JSONDecoder()  # reads keys and steps over scalars while a repeated key is looked for


def strict_loads(text: str) -> object:
    """`text` parsed as JSON with every key once per object and finite numbers.

    Raises DuplicateKey (naming the key and the line and column of its second
    occurrence), json.JSONDecodeError for malformed text, ValueError for a number too
    large or a NaN / Infinity literal, RecursionError for nesting too deep to parse."""
    try:
        return _DECODER.decode(text)
    except _Repeated as repeated:
        at = _second_key_at(text)
        if at is None:  # cannot happen for text the parser read; said without a place
            raise DuplicateKey(repeated.key) from None
        key, index = at
        line = text.count("\n", 0, index) + 1
        column = index - text.rfind("\n", 0, index)
        raise DuplicateKey(key, line, column) from None


def _skip(text: str, index: int) -> int:
    while index < len(text) and text[index] in _WHITESPACE:
        index += 1
    return index


def _second_key_at(text: str) -> tuple[str, int] | None:
    """The repeated key whose second occurrence comes first in `text`, and the index of
    that occurrence's opening quote; None if no object holds a key twice."""
    try:
        found, _ = _walk(text, _skip(text, 0))
    except (RecursionError, ValueError, IndexError):
        return None
    return found


def _walk(text: str, index: int) -> tuple[tuple[str, int] | None, int]:
    """Walk the value at `index` (no whitespace before it): the first repeated key
    inside it (key, index) or None, and the index after the value."""
    closing = _CLOSING.get(text[index])
    if closing is None:  # a string, number, true, false or null
        _, end = _PLAIN.raw_decode(text, index)
        return None, end
    seen: set[str] = set()  # an object's keys so far
    index = _skip(text, index + 1)
    if text[index] == closing:
        return None, index + 1
    while True:
        if closing == "}":
            start = index
            key, index = _PLAIN.raw_decode(text, index)
            if key in seen:
                return (key, start), index
            seen.add(key)
            index = _skip(text, _skip(text, index) + 1)  # past the colon
        found, index = _walk(text, index)
        if found is not None:
            return found, index
        index = _skip(text, index)
        if text[index] == closing:
            return None, index + 1
        index = _skip(text, index + 1)  # past the comma
