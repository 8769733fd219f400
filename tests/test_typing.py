"""Resources are typed: mypy knows what `world.resource(T)` returns and refuses typos.

A script that writes `world.gaols` (or any name no class defines) fails type checking
instead of reaching a run-time fallback; `world.resource(GoalBook)` is a `GoalBook`.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

SCRIPT = textwrap.dedent(
    """
    from ecs_tentacles.locomotion.goals import GoalBook
    from ecs_tentacles.world import World


    def crawl(world: World) -> None:
        book: GoalBook = world.resource(GoalBook)
        book.set(world.creature("octo"), [1.0, 0.0])
        maybe: GoalBook | None = world.get_resource(GoalBook)
        print(book, maybe)
        world.no_such_thing.set(0, [1.0, 0.0])
        world.resource(GoalBook).no_such_method()
    """
)


def strict_errors(tmp_path: Path, source: str) -> list[str]:
    """mypy --strict's error lines on `source` (two expected), written to a script."""
    script = tmp_path / "script.py"
    script.write_text(source)
    result = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--follow-imports=silent",
         "--cache-dir", str(tmp_path / "cache"), "--no-error-summary", str(script)],
        capture_output=True, text=True, check=False, cwd=Path(__file__).parents[1],
    )  # fmt: skip
    errors = [line for line in result.stdout.splitlines() if ": error:" in line]
    assert len(errors) == 2, result.stdout + result.stderr
    return errors


def test_mypy_strict_rejects_unknown_world_attributes(tmp_path: Path) -> None:
    errors = strict_errors(tmp_path, SCRIPT)
    assert '"World" has no attribute "no_such_thing"' in errors[0]
    assert '"GoalBook" has no attribute "no_such_method"' in errors[1]


SPAWN = textwrap.dedent(
    """
    from ecs_tentacles.host import Host
    from ecs_tentacles.world import World


    def add(world: World, host: Host) -> None:
        world.spawn({"name": "a"}, position=(1.0, 2.0), on_overlap="move")
        host.spawn({"name": "b"}, heading_deg=90.0)
        world.spawn({"name": "c"}, positon=(1.0, 2.0))
        host.spawn({"name": "d"}, on_overlap="push")
    """
)


def test_mypy_strict_checks_spawn_placements(tmp_path: Path) -> None:
    errors = strict_errors(tmp_path, SPAWN)
    assert '"positon"' in errors[0]
    assert "'push'" in errors[1]
