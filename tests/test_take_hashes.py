"""The built-in scenes behave exactly as recorded: same take, byte for byte.

The hashes in `tests/data/take_sha256.json` were last re-recorded for issue 20 (its
"about" says why: the motion arrays did not change, the header's scene defaults did).
MuJoCo and numpy releases may change floating-point results, so the test compares
only under the version sets the hashes were checked with (when upgrading, bake each
scene with `ecs-tentacles bake SCENE --seconds 2 --out t.npz`: if the hashes agree, add
the versions to the list; if not, re-record them on purpose).
"""

from __future__ import annotations

import hashlib
import json
import pathlib

import mujoco
import numpy as np
import pytest

from ecs_tentacles.cli import main

DATA = pathlib.Path(__file__).parent / "data"  # scenes that are not bundled (crowd16)
RECORD = json.loads((DATA / "take_sha256.json").read_text())
VERSIONS = {"mujoco": mujoco.__version__, "numpy": np.__version__}


@pytest.mark.skipif(
    VERSIONS not in RECORD["versions"],
    reason=f"hashes checked with {RECORD['versions']}, running {VERSIONS}",
)
@pytest.mark.parametrize("scene", sorted(RECORD["takes"]))
def test_bundled_scene_take_is_unchanged(scene: str, tmp_path: pathlib.Path) -> None:
    out = tmp_path / f"{scene}.npz"
    source = str(DATA / f"{scene}.json") if (DATA / f"{scene}.json").is_file() else scene
    assert main(["bake", source, "--seconds", "2", "--out", str(out), "--quiet"]) == 0
    assert hashlib.sha256(out.read_bytes()).hexdigest() == RECORD["takes"][scene]
