"""Resources are typed: mypy knows what `world.resource(T)` returns and refuses typos.

A script that writes `world.gaols` (or any name no class defines) fails type checking
instead of reaching a run-time fallback; `world.resource(GoalBook)` is a `GoalBook`.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from tests.conftest import once_a_session

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


def test_mypy_strict_rejects_unknown_world_attributes(mypy_output: str) -> None:
    errors = strict_errors(mypy_output, "script")
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


def test_mypy_strict_checks_spawn_placements(mypy_output: str) -> None:
    errors = strict_errors(mypy_output, "spawn")
    assert '"positon"' in errors[0]
    assert "'push'" in errors[1]


SNIPPETS = {"script": SCRIPT, "spawn": SPAWN}


def _check_snippets(folder: Path) -> Path:
    """Every snippet written to `folder` and checked by one mypy --strict run (one
    analysis of the package for all); its output saved to `mypy.out`."""
    scripts = []
    for name, source in SNIPPETS.items():
        (folder / f"{name}.py").write_text(source)
        scripts.append(str(folder / f"{name}.py"))
    result = subprocess.run(
        [sys.executable, "-m", "mypy", "--strict", "--follow-imports=silent",
         "--cache-dir", str(folder / "cache"), "--no-error-summary", *scripts],
        capture_output=True, text=True, check=False, cwd=Path(__file__).parents[1],
    )  # fmt: skip
    out = folder / "mypy.out"
    out.write_text(result.stdout + result.stderr)
    return out


@pytest.fixture(scope="module")
def mypy_output(tmp_path_factory: pytest.TempPathFactory) -> str:
    """The one mypy --strict run's output over every snippet (made once a session)."""
    return once_a_session(tmp_path_factory, "typing_snippets", _check_snippets).read_text()


def strict_errors(output: str, name: str) -> list[str]:
    """mypy --strict's error lines on the snippet `name` (two expected)."""
    errors = [line for line in output.splitlines()
              if ": error:" in line and Path(line.split(":")[0]).name == f"{name}.py"]  # fmt: skip
    assert len(errors) == 2, output
    return errors
