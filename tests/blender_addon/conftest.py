"""Blender for the add-on's tests: bpy as a module (a Python given by
ECS_TENTACLES_BLENDER_PYTHON, as tests/tools/test_blender_import.py uses it), a fresh
Blender user folder with the add-on installed by `ecs-tentacles blender-addon --install`,
and scripts run in it that print JSON."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path
from typing import Any

import pytest

from ecs_tentacles.cli import main

BLENDER = os.environ.get("ECS_TENTACLES_BLENDER_PYTHON", "")
needs_blender = pytest.mark.skipif(
    not Path(BLENDER).is_file(),
    reason="set ECS_TENTACLES_BLENDER_PYTHON to a Python with bpy (CI installs bpy==5.0.1)",
)
# a script's start: the user's preferences (the add-on enabled), an empty scene
START = """
import json, sys, bpy
bpy.ops.wm.read_userpref()
bpy.ops.wm.read_homefile(use_empty=True)
"""


def install(folder: Path) -> dict[str, str]:
    """Install the add-on into the Blender user folder `folder` with the command line;
    the environment that makes Blender use that folder."""
    env = {**os.environ, "BLENDER_USER_RESOURCES": str(folder)}
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("BLENDER_USER_RESOURCES", str(folder))
        assert main(["blender-addon", "--install", "--blender", BLENDER]) == 0
    return env


def run(env: dict[str, str], script: str, *args: str, timeout: float = 300) -> Any:
    """Run `START + script` in Blender with `args`; what its last line prints, as JSON."""
    done = subprocess.run(
        [BLENDER, "-c", START + script, *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.splitlines()[-1])


@pytest.fixture(scope="session")
def blender_env(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """A fresh Blender user folder with the add-on installed and enabled."""
    if not Path(BLENDER).is_file():
        pytest.skip("no Blender (ECS_TENTACLES_BLENDER_PYTHON)")
    return install(tmp_path_factory.mktemp("blender_user"))
