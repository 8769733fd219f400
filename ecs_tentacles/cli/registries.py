"""What `ecs-tentacles run` asks the plugins for its report: the command line's registry
(`ecs_tentacles.registry`), filled in plugins' `build(app)`.

- `RunSummaries`: `entry(world)` -> a `RunSummary` (counts for `--json`, a phrase for
  the line: locomotion's "goals reached 2, left 0") or None.

Importing it loads no command (`ecs_tentacles.cli` loads them on first use).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from ecs_tentacles.registry import Registry

if TYPE_CHECKING:
    from ecs_tentacles.host import Host


@dataclass(frozen=True)
class RunSummary:
    """What a plugin adds to `ecs-tentacles run`'s report: counts for `--json` and a
    phrase for the line (`"goals reached 2, left 0"`)."""

    counts: dict[str, int] = field(default_factory=dict)
    text: str = ""


class RunSummaries(Registry[Callable[["Host"], RunSummary | None]]):
    """What plugins add to `run`'s report."""
