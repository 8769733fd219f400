"""Shared pieces of the command-line tests: a small scene file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tests.export.conftest import SMALL_SCENE


@pytest.fixture
def scene(tmp_path: Path) -> Path:
    """`SMALL_SCENE` (one creature, a goal 1 m ahead) as `small.json` in the test's folder."""
    path = tmp_path / "small.json"
    path.write_text(json.dumps(SMALL_SCENE))
    return path
