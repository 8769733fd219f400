"""The import contracts (pyproject's [tool.importlinter]) hold, read by plain
`lint-imports`: every module's import path is its file path, so import-linter sees every
import, a feature's systems included (a forbidden one is caught)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
LINT = "from importlinter.cli import lint_imports_command; raise SystemExit(lint_imports_command())"

pytestmark = pytest.mark.skipif(
    not (ROOT / "pyproject.toml").is_file(), reason="needs the source tree"
)


def _lint(root: Path) -> subprocess.CompletedProcess[str]:
    """`lint-imports --no-cache` run in `root` (import-linter puts it first on the path)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    return subprocess.run(
        [sys.executable, "-c", LINT, "--no-cache"],
        cwd=root,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )


def test_the_repository_keeps_every_contract() -> None:
    result = _lint(ROOT)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 broken" in result.stdout


def test_core_importing_a_features_systems_is_caught(tmp_path: Path) -> None:
    skip = shutil.ignore_patterns("__pycache__", "*.nbi", "*.nbc")
    for name in ("ecs_tentacles", "systems"):
        shutil.copytree(ROOT / name, tmp_path / name, ignore=skip, symlinks=True)
    shutil.copy2(ROOT / "pyproject.toml", tmp_path / "pyproject.toml")
    backend = tmp_path / "ecs_tentacles" / "physics" / "backend.py"
    backend.write_text(backend.read_text() + "\nimport ecs_tentacles.locomotion.systems.goals\n")
    result = _lint(tmp_path)
    assert result.returncode == 1, result.stdout + result.stderr
    text = " ".join(result.stdout.split())
    assert "Core depends on no feature and no generic layer above it BROKEN" in text
    assert "ecs_tentacles.physics.backend -> ecs_tentacles.locomotion.systems.goals" in text
