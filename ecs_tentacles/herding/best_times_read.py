"""Reading the best-times file within bounds, entry by entry.

    read = read_best_times(Path("best_times.json"))
    read.times      # {"Open field": 41.3}: every entry that is a time
    read.problems   # ["'Maze': true is not a time in seconds"]: one line each

Reads one file and writes nothing. The file is trusted no more than any other input:
only a regular file is opened (a FIFO or a device in its place is refused without
waiting on it), at most `MAX_BYTES` of it are read, it must be UTF-8 JSON nested no
deeper than the parser's recursion allows, and every entry of `best_seconds` is
checked on its own: a time is a JSON number (not `true`), finite, above zero, written
with at most `MAX_DIGITS` digits before any fraction. A bad entry is left out and
named; the good ones are kept. A file that does not read at all gives no times and
one problem (`whole`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from ecs_tentacles.untrusted.files import TooLarge, Unfit, read_regular

MAX_BYTES = 1 << 20  # 1 MiB: about 20,000 levels' best times
MAX_DIGITS = 20  # an integer of more digits is no game's time (and no float holds it)
SHOWN = 40  # characters of a level's name a message quotes


@dataclass
class BestTimesRead:
    """What a best-times file holds: its times and what is wrong with it."""

    times: dict[str, float] = field(default_factory=dict)
    problems: list[str] = field(default_factory=list)  # one line each
    whole: bool = False  # the file did not read at all (no times kept from it)


@dataclass(frozen=True)
class _Refused:
    """A number the parser would not make (too many digits, NaN, Infinity)."""

    said: str


def _int(text: str) -> int | _Refused:
    digits = len(text.lstrip("-"))
    return int(text) if digits <= MAX_DIGITS else _Refused(f"a {digits}-digit number")


def _constant(text: str) -> _Refused:
    return _Refused(text)  # NaN, Infinity, -Infinity: JSON has no such numbers


def _describe(value: object) -> str:
    """A short name for a JSON value (never the whole of a large one)."""
    if isinstance(value, _Refused):
        return value.said
    if value is None or isinstance(value, bool):
        return json.dumps(value)
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return "a string"
    return "a list" if isinstance(value, list) else "an object"


def _level(name: str) -> str:
    return repr(name if len(name) <= SHOWN else name[:SHOWN] + "...")


def _problem(value: object) -> str | None:
    """Why `value` is not a time in seconds (None: it is one)."""
    number = value if type(value) in (int, float) else None  # a bool is no time
    if not isinstance(number, (int, float)) or not (math.isfinite(number) and number > 0):
        return f"{_describe(value)} is not a time in seconds"
    return None


def _text(file: Path) -> str | None:
    """The file's text (None: there is none), read within `MAX_BYTES`; ValueError says
    why it cannot be read as a best-times file."""
    try:  # non-blocking: a FIFO opens at once (and is then refused), never waits
        data = read_regular(file, MAX_BYTES)
    except FileNotFoundError:
        return None  # an unreadable folder (another OSError) is the caller's to say
    except TooLarge:
        raise ValueError(f"larger than {MAX_BYTES >> 20} MiB") from None
    except Unfit:
        raise ValueError("not a regular file") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ValueError(f"not UTF-8 ({error.reason} at byte {error.start})") from None


def _unread(problem: str) -> BestTimesRead:
    return BestTimesRead(problems=[problem], whole=True)


def read_best_times(file: Path) -> BestTimesRead:
    """Level -> best seconds from `file` (none if it does not exist), and its problems."""
    try:
        text = _text(file)
    except ValueError as error:
        return _unread(str(error))
    if text is None:
        return BestTimesRead()
    try:
        raw: object = json.loads(text, parse_int=_int, parse_constant=_constant)
    except RecursionError:
        return _unread("not JSON (nested too deeply)")
    except ValueError as error:
        return _unread(f"not JSON ({error})")
    times = raw.get("best_seconds") if isinstance(raw, dict) else None
    if not isinstance(times, dict):
        return _unread("not a best-times file (best_seconds: level -> seconds)")
    read = BestTimesRead()
    for level, value in times.items():
        problem = _problem(value)
        if problem is None:
            read.times[level] = float(value)
        else:
            read.problems.append(f"{_level(level)}: {problem}")
    return read
