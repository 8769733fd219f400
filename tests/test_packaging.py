"""Packaging: every package found (none listed by hand), a feature's systems inside its
package, the example plugins of `systems/` as `ecs_tentacles_examples` (never a top-level
`systems`: users have their own), the bundled scenes and schemas as `ecs_tentacles.assets`,
and every plugin registered as an entry point."""

from __future__ import annotations

import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

USER_CHECK = """
import systems, ecs_tentacles, ecs_tentacles_examples
from ecs_tentacles.world import World
assert systems.MINE is True, "the user's own systems package"
assert ecs_tentacles.__file__.startswith({where!r}), ecs_tentacles.__file__
assert ecs_tentacles_examples.__file__.startswith({where!r}), ecs_tentacles_examples.__file__
world = World.from_scene("octopus")
world.step(2)
print(world.schedule.names)
"""


def _user_project(tmp_path: Path) -> Path:
    """A folder with the user's own `systems` package, as a working directory."""
    project = tmp_path / "user_project"
    (project / "systems").mkdir(parents=True)
    (project / "systems" / "__init__.py").write_text("MINE = True\n")
    return project


def _run(code: str, cwd: Path, pythonpath: str | None = None) -> subprocess.CompletedProcess[str]:
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    return subprocess.run(
        [sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True, check=False
    )


def test_installed_package_beside_a_user_systems_package(tmp_path: Path) -> None:
    import ecs_tentacles

    where = str(Path(ecs_tentacles.__file__).parents[1])
    result = _run(USER_CHECK.format(where=where), _user_project(tmp_path))
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().endswith(
        "'physics', 'lod_replay', 'physics_sync', 'physics_health', 'threats', 'emotion', 'rig']"
    )


@pytest.mark.skipif(not (ROOT / "pyproject.toml").exists(), reason="needs the source tree")
def test_wheel_holds_every_module_and_asset_and_runs(tmp_path: Path) -> None:
    built = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", str(ROOT), "-w", str(tmp_path)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert built.returncode == 0, built.stderr
    wheel = next(tmp_path.glob("ecs_tentacles-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    expected = {
        f"ecs_tentacles/{p.relative_to(ROOT / 'ecs_tentacles')}"
        for p in ROOT.glob("ecs_tentacles/**/*.py")
    }
    expected |= {
        f"ecs_tentacles_examples/{p.name}" for p in ROOT.glob("systems/ecs_tentacles_examples/*.py")
    }
    expected |= {
        f"ecs_tentacles/assets/{p.relative_to(ROOT / 'assets')}"
        for p in ROOT.glob("assets/**/*.json")
    }
    expected |= {  # each feature's schema fragment, by pattern
        f"ecs_tentacles/{p.relative_to(ROOT / 'ecs_tentacles')}"
        for p in ROOT.glob("ecs_tentacles/*/*.schema.json")
    }
    expected.add("ecs_tentacles/take/version1.json")
    expected.add("ecs_tentacles/blender_addon/blender_manifest.toml")  # the add-on's zip
    assert expected <= names, sorted(expected - names)
    assert not any(n.startswith(("systems/", "assets/", "tests/", "tools/")) for n in names)
    unpacked = tmp_path / "site"
    zipfile.ZipFile(wheel).extractall(unpacked)
    result = _run(USER_CHECK.format(where=str(unpacked)), _user_project(tmp_path), str(unpacked))
    assert result.returncode == 0, result.stderr
