"""Shared pieces of the herding tests: a data folder of the test's own."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture
def data_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """Best times and wins kept in the test's folder (`ECS_TENTACLES_DATA`), not the user's."""
    folder = tmp_path / "data"
    monkeypatch.setenv("ECS_TENTACLES_DATA", str(folder))
    return folder
