"""The herding game's best times: one JSON file in the user's data folder.

    record_win("Open field", 41.3)   # -> (best, is_new): the best time of that level now
    best_time("Open field")          # seconds, or None: never won

The file is `best_times.json` in the user's data folder (`platformdirs`: on Linux
`~/.local/share/ecs_tentacles/`; `ECS_TENTACLES_DATA` names another folder), never
inside the package. A win is written under a lock beside the file (`filelock`): the
file is read, the level's time kept if it beats the best, and the whole file written
to a temporary file and renamed (`ecs_tentacles.output.atomic`), so two games that
finish at once both count and the file is always one whole JSON object. Times are
stored as they are (JSON numbers round-trip a float exactly): a 0.0004 s win stays one.

The file is read within bounds, entry by entry (`best_times_read`): a bad entry (a
400-digit number, `true`, NaN) is left out and the good ones kept; a file that does not
read at all (truncated, too deep, too large, not a regular file) gives no times. Reading
never moves a file. The next win, under the lock, sets the old file aside whole as
`best_times.json.bad.N` (the first N free: no set-aside file is ever overwritten),
writes the good times with the win, and says so once (one line naming both files).
`record_win` is the caller's wait for the lock; the sandbox records wins off its frame
(`ecs_tentacles.herding.win_recorder`).
"""

from __future__ import annotations

import itertools
import json
import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

from filelock import FileLock
from platformdirs import user_data_dir

from ecs_tentacles.herding.best_times_read import BestTimesRead, read_best_times
from ecs_tentacles.output.atomic import atomic_file

FILE = "best_times.json"
VERSION = 1
LOCK_WAIT = 30.0  # seconds a win waits for another game's write before giving up


def data_folder() -> Path:
    """Where the user's game data lives (made when first written)."""
    override = os.environ.get("ECS_TENTACLES_DATA")
    return Path(override) if override else Path(user_data_dir("ecs_tentacles", appauthor=False))


def path() -> Path:
    return data_folder() / FILE


def best_times() -> dict[str, float]:
    """Every level's best time, seconds: the file's good entries (reading says nothing and
    moves nothing: only a win, under the lock, sets a bad file aside)."""
    return read_best_times(path()).times


def best_time(level: str) -> float | None:
    return best_times().get(level)


@dataclass(frozen=True)
class Recorded:
    """A win as written: the level's best now, whether it is this win, and a note (None:
    nothing to say) when the old file was set aside."""

    best: float
    new: bool
    note: str | None = None


def set_aside(file: Path) -> Path:
    """Move `file` to the first free `<name>.bad.N` (created exclusively, then the file
    renamed onto it: an earlier set-aside file is never overwritten)."""
    for number in itertools.count(1):
        aside = file.with_name(f"{file.name}.bad.{number}")
        try:
            os.close(os.open(aside, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o600))
        except FileExistsError:
            continue
        os.replace(file, aside)
        return aside
    raise AssertionError("unreachable")


def _note(file: Path, read: BestTimesRead, aside: Path) -> str:
    if read.whole:
        return f"{file}: {read.problems[0]}; kept as {aside.name}, starting a new one"
    more = f" and {len(read.problems) - 1} more" if len(read.problems) > 1 else ""
    return (
        f"{file}: {read.problems[0]}{more}; kept as {aside.name},"
        f" its {len(read.times)} good time(s) kept"
    )


def check_seconds(seconds: float) -> float:
    """`seconds` as a float if it is a time a game can take (finite, above zero, a number
    but not a bool), else ValueError."""
    if isinstance(seconds, bool) or not (math.isfinite(seconds) and seconds > 0):
        raise ValueError(f"seconds: {seconds!r} is not a time a game can take")
    return float(seconds)


def record(
    level: str, seconds: float, *, timeout: float = LOCK_WAIT, file: Path | None = None
) -> Recorded:
    """Count a win of `level` in `seconds` in `file` (None: `path()`), waiting at most
    `timeout` seconds for the lock (`filelock.Timeout`, an OSError, past it)."""
    seconds = check_seconds(seconds)
    file = path() if file is None else file
    file.parent.mkdir(parents=True, exist_ok=True)
    with FileLock(str(file) + ".lock", timeout=timeout):
        read = read_best_times(file)
        note = None
        if read.problems:  # set aside whole, not trusted; its good times carry on
            note = _note(file, read, set_aside(file))
        times = read.times
        old = times.get(level)
        new = old is None or seconds < old
        if new:
            times[level] = seconds
        if new or note is not None:
            text = json.dumps({"version": VERSION, "best_seconds": times}, indent=2, sort_keys=True)
            with atomic_file(file) as handle:
                handle.write((text + "\n").encode())
        return Recorded(times[level], new, note)


def record_win(level: str, seconds: float, *, timeout: float = LOCK_WAIT) -> tuple[float, bool]:
    """Count a win of `level` in `seconds`: (the level's best now, whether this is it); a
    file set aside is said once as a UserWarning."""
    done = record(level, seconds, timeout=timeout)
    if done.note is not None:
        warnings.warn(done.note, stacklevel=2)
    return done.best, done.new
