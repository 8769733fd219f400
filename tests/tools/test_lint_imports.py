"""tools/lint_imports.py: the import contracts see `ecs_tentacles.systems` imports (they
did not: a forbidden import into the systems folder came back kept), and the repository
keeps every contract."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from tests.tools.loader import TOOLS, load_tool

TOOL = TOOLS / "lint_imports.py"
ROOT = TOOLS.parent


def _copy(into: Path) -> Path:
    """The package, the systems folder and pyproject.toml (its contracts) under `into`."""
    skip = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc")
    for name in ("ecs_tentacles", "systems"):
        shutil.copytree(ROOT / name, into / name, ignore=skip)
    shutil.copy2(ROOT / "pyproject.toml", into / "pyproject.toml")
    return into


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_the_repository_keeps_every_contract() -> None:
    result = load_tool("lint_imports").lint(ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


@pytest.mark.skipif(not TOOL.is_file(), reason="needs the source tree")
def test_a_forbidden_import_into_the_systems_folder_is_caught(tmp_path: Path) -> None:
    root = _copy(tmp_path)
    backend = root / "ecs_tentacles" / "physics" / "backend.py"
    text = backend.read_text()
    # core (the physics) reaching a feature's systems, written as the code writes them
    backend.write_text(text + "\nimport ecs_tentacles.systems.locomotion.goals  # noqa\n")
    result = load_tool("lint_imports").lint(root)
    assert result.returncode == 1
    assert "Core depends on no feature and no generic layer above it BROKEN" in " ".join(
        result.stdout.split()
    )
    assert "ecs_tentacles.physics.backend -> ecs_tentacles.systems.locomotion.goals" in (
        result.stdout
    )
