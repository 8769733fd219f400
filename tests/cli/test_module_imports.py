"""Every command-line module imports on its own, first thing in a fresh interpreter (tools
import `ecs_tentacles.cli.crowd` directly: a circle through the package's lazy names
once broke that while every test, importing `ecs_tentacles.cli.main` first, passed)."""

from __future__ import annotations

import pkgutil
import subprocess
import sys

import pytest

import ecs_tentacles.cli

MODULES = sorted(
    m.name for m in pkgutil.iter_modules(ecs_tentacles.cli.__path__) if m.name != "__main__"
)


def test_the_list_is_the_package() -> None:
    assert {"bake", "bake_ray", "bench", "command", "crowd", "play"} <= set(MODULES)


@pytest.mark.parametrize("module", MODULES)
def test_a_cli_module_imports_alone(module: str) -> None:
    done = subprocess.run(
        [sys.executable, "-c", f"import ecs_tentacles.cli.{module}"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr.strip().splitlines()[-1:]
