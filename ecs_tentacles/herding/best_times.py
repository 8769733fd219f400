"""The herding game's best times: one JSON file in the user's data folder.

    record_win("Open field", 41.3)   # -> (best, is_new): the best time of that level now
    best_time("Open field")          # seconds, or None: never won

The file is `best_times.json` in the user's data folder (`platformdirs`: on Linux
`~/.local/share/ecs_tentacles/`; `ECS_TENTACLES_DATA` names another folder), never
inside the package. A win is written under a lock beside the file (`filelock`): the
file is read, the level's time kept if it beats the best, and the whole file written
to a temporary file and renamed (`ecs_tentacles.output.atomic`), so two games that
finish at once both count and the file is always one whole JSON object. A file that
is not one (hand-edited, truncated by another program) reads as no best times; the
next win, under the lock, sets it aside as `best_times.json.bad` and starts a fresh
one, with a one-line warning (reading never moves a file).
"""

from __future__ import annotations

import json
import math
import os
import warnings
from pathlib import Path
from typing import Any

from filelock import FileLock
from platformdirs import user_data_dir

from ecs_tentacles.output.atomic import atomic_file

FILE = "best_times.json"
VERSION = 1


def data_folder() -> Path:
    """Where the user's game data lives (made when first written)."""
    override = os.environ.get("ECS_TENTACLES_DATA")
    return Path(override) if override else Path(user_data_dir("ecs_tentacles", appauthor=False))


def path() -> Path:
    return data_folder() / FILE


def _read(file: Path) -> tuple[dict[str, float], str | None]:
    """Level -> best seconds, and what is wrong with the file (None: nothing)."""
    try:
        raw: Any = json.loads(file.read_text())
    except FileNotFoundError:
        return {}, None
    except ValueError as error:  # an unreadable folder (OSError) is the caller's to say
        return {}, f"not JSON ({error})"
    times = raw.get("best_seconds") if isinstance(raw, dict) else None
    if not isinstance(times, dict) or not all(
        isinstance(k, str) and isinstance(v, (int, float)) and math.isfinite(v) and v > 0
        for k, v in times.items()
    ):
        return {}, "not a best-times file (best_seconds: level -> seconds)"
    return {k: float(v) for k, v in times.items()}, None


def best_times() -> dict[str, float]:
    """Every level's best time, seconds (none from a file that is not one: only a win,
    under the lock, sets such a file aside)."""
    return _read(path())[0]


def best_time(level: str) -> float | None:
    return best_times().get(level)


def record_win(level: str, seconds: float) -> tuple[float, bool]:
    """Count a win of `level` in `seconds`: (the level's best now, whether this is it)."""
    if not (math.isfinite(seconds) and seconds > 0):
        raise ValueError(f"seconds: {seconds} is not a time a game can take")
    file = path()
    file.parent.mkdir(parents=True, exist_ok=True)
    with FileLock(str(file) + ".lock", timeout=30):
        times, wrong = _read(file)
        if wrong is not None:  # set aside, not trusted
            aside = file.with_name(file.name + ".bad")
            os.replace(file, aside)
            warnings.warn(
                f"{file}: {wrong}; kept as {aside.name}, starting a new one", stacklevel=2
            )
        old = times.get(level)
        if old is not None and old <= seconds:
            return old, False
        times[level] = round(float(seconds), 3)
        text = json.dumps({"version": VERSION, "best_seconds": times}, indent=2, sort_keys=True)
        with atomic_file(file) as handle:
            handle.write((text + "\n").encode())
        return times[level], True
