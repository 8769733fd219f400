"""Shared pieces of the command-line tests: a small scene file."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ecs_tentacles.cli import main
from tests.export.conftest import SMALL_SCENE


@pytest.fixture
def scene(tmp_path: Path) -> Path:
    """`SMALL_SCENE` (one creature, a goal 1 m ahead) as `small.json` in the test's folder."""
    path = tmp_path / "small.json"
    path.write_text(json.dumps(SMALL_SCENE))
    return path


def refused(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """What `ecs-tentacles ARGV` said on stderr when it refused its arguments: it must
    stop with exit 2 (argparse's way) before doing anything."""
    with pytest.raises(SystemExit) as caught:
        main(argv)
    assert caught.value.code == 2
    return capsys.readouterr().err
