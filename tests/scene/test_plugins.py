"""Plugins are found through entry points, the engine's own as any installed package's.

A plugin package built from a pyproject and installed with pip into a fresh venv runs in
a scene there without any edit to the engine (and, not being the engine's, only with
consent). The engine's own plugins are entry points too: listing them, and which are on
by default or in the sandbox, imports no plugin's code; those roles are the engine's
alone (another package's plugin is on only when a scene names it), and another package
cannot take a built-in plugin's name.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import sysconfig
import textwrap
from pathlib import Path

import pytest

from ecs_tentacles.scene.errors import SceneError
from ecs_tentacles.scene.plugins import default_on, sandbox_on, shipped
from ecs_tentacles.world import World

PYPROJECT = """
[build-system]
requires = ["flit_core>=3.4,<5"]
build-backend = "flit_core.buildapi"

[project]
name = "tentacle-glow"
version = "1.0"
description = "A glow for tentacled creatures"

[project.entry-points."ecs_tentacles.plugins"]
glow = "tentacle_glow:GlowPlugin"
"""
MODULE = '''
"""A plugin installed as a package: its system says on stderr when it runs."""

import sys

from ecs_tentacles.plugin import Plugin
from ecs_tentacles.system import System


class Glow(System):
    """Reads nothing; writes nothing (says that it ran)."""

    name = "glow"
    stage = "animate"

    def process(self, world, dt):
        print(f"glow at frame {world.frame}", file=sys.stderr)


class GlowPlugin(Plugin):
    name = "glow"

    def systems(self):
        return [Glow()]
'''
SCENE = {
    "version": 1,
    "creatures": [{"name": "octo", "tentacles": {"count": 3, "links": 2}}],
    "plugins": {"glow": {}},
}


def _package(folder: Path) -> Path:
    """A plugin package's source: a pyproject and one module."""
    folder.mkdir()
    (folder / "pyproject.toml").write_text(PYPROJECT)
    (folder / "tentacle_glow.py").write_text(MODULE)
    return folder


def _fresh_venv(folder: Path) -> Path:
    """A new venv (no pip of its own) that sees this environment's packages, the engine
    and flit_core included, as an installed site (its `.pth` files run: editable installs
    resolve); its python."""
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(folder)], check=True)
    python = folder / "bin" / "python"
    site = subprocess.run(
        [python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    ours = sysconfig.get_paths()["purelib"]
    Path(site, "outer_site.pth").write_text(f"import site; site.addsitedir({ours!r})\n")
    return python


def _run(*args: str | Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    return subprocess.run(
        [str(a) for a in args], cwd=cwd, env=env, capture_output=True, text=True, check=False
    )


@pytest.mark.skipif(sys.platform == "win32", reason="the venv's layout is POSIX's")
def test_a_plugin_package_installed_with_pip_runs_in_a_scene(tmp_path: Path) -> None:
    source = _package(tmp_path / "tentacle-glow")
    python = _fresh_venv(tmp_path / "venv")
    pip = (sys.executable, "-m", "pip", "--python", python, "install", "--quiet")
    installed = _run(*pip, "--no-deps", "--no-build-isolation", "--no-index", source, cwd=tmp_path)
    assert installed.returncode == 0, installed.stderr
    scene = tmp_path / "glow.json"
    scene.write_text(json.dumps(SCENE))
    command = (python, "-P", "-m", "ecs_tentacles", "run", scene, "--frames", "2", "--quiet")

    refused = _run(*command, cwd=tmp_path)  # another package's code: only with consent
    assert (refused.returncode, refused.stderr.strip().splitlines()[-1]) == (
        2,
        f"error: {scene}: plugins.glow: runs code from 'tentacle_glow:GlowPlugin'; allow it"
        " with --allow-systems (API: allow_systems=True)",
    )
    ran = _run(*command, "--allow-systems", "--json", cwd=tmp_path)
    assert ran.returncode == 0, ran.stderr
    assert json.loads(ran.stdout)["frames"] == 2
    assert ran.stderr == "glow at frame 0\nglow at frame 1\n"
    # and this environment, where the package is not installed, does not know it
    with pytest.raises(SceneError, match=r"plugins\.glow: no plugin of that name"):
        World.from_scene(SCENE, allow_systems=True)


def test_listing_the_plugins_and_their_roles_imports_none() -> None:
    code = textwrap.dedent(
        """
        import sys
        from ecs_tentacles.scene.plugins import default_on, sandbox_on, shipped
        from ecs_tentacles.scene.schema import builtin_keys, load_schema
        listed = (default_on(), sandbox_on(), sorted(shipped()), len(load_schema()))
        keys = {name: builtin_keys(name) for name in shipped()}  # their schema fragments
        modules = {target.partition(":")[0] for target in shipped().values()}
        imported = sorted(
            m for m in sys.modules
            if m in modules or ".systems" in m or m.startswith("ecs_tentacles_examples")
        )
        print(listed, imported)
        """
    )
    result = _run(sys.executable, "-P", "-c", code, cwd=Path.cwd())
    assert result.returncode == 0, result.stderr
    assert result.stdout.rstrip().endswith(" []"), result.stdout


def test_the_engines_plugins_and_roles_are_its_entry_points() -> None:
    assert default_on() == ("clips", "fur", "locomotion", "suckers", "terrain", "threats")
    assert sandbox_on() == ("director",)
    assert set(shipped()) == {
        *default_on(),
        *sandbox_on(),
        *("record", "render", "herding", "game", "race"),
        *("wander", "flee", "follow_leader", "flock"),
    }
    # defaults are built by their `build_order`, whatever the order they are listed in
    world = World.from_scene({"version": 1})
    with world:
        assert [p.key for p in world.plugins] == [
            "locomotion", "suckers", "threats", "fur", "clips", "terrain"
        ]  # fmt: skip


def _installed(folder: Path, monkeypatch: pytest.MonkeyPatch, entry_points: str) -> None:
    """A package `lamp` (module `lamp.py` and its metadata) on the import path."""
    (folder / "lamp.py").write_text(MODULE.replace("glow", "lamp").replace("Glow", "Lamp"))
    info = folder / "lamp-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: lamp\nVersion: 1.0\n")
    (info / "entry_points.txt").write_text(entry_points)
    monkeypatch.syspath_prepend(str(folder))


def test_another_packages_plugin_is_never_on_by_default(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    _installed(
        tmp_path,
        monkeypatch,
        "[ecs_tentacles.plugins.default]\nlamp = lamp:LampPlugin\n"
        "[ecs_tentacles.plugins.sandbox]\nlamp2 = lamp:LampPlugin\n",
    )
    assert (default_on(), sandbox_on()) == (
        ("clips", "fur", "locomotion", "suckers", "terrain", "threats"),
        ("director",),
    )
    with World.from_scene({"version": 1}, allow_systems=True) as world:
        assert "lamp" not in world.schedule
    with pytest.raises(SceneError, match="runs code from 'lamp:LampPlugin'; allow it"):
        World.from_scene({"version": 1, "plugins": {"lamp": {}}})
    with World.from_scene({"version": 1, "plugins": {"lamp": {}}}, allow_systems=True) as world:
        assert "lamp" in world.schedule and world.plugin("lamp").source == "lamp:LampPlugin"


def test_another_package_cannot_take_a_built_in_plugins_name(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    _installed(tmp_path, monkeypatch, "[ecs_tentacles.plugins]\nfur = lamp:LampPlugin\n")
    with World.from_scene({"version": 1}) as world:
        assert type(world.plugin("fur")).__module__ == "ecs_tentacles.fur.plugin"
        assert world.plugin("fur").source is None and "lamp" not in world.schedule


OLD_KEY_SCENE = Path(__file__).parents[1] / "data" / "old_lod_plugin_key.json"


def test_a_scene_with_the_clips_plugins_former_key_loads_with_one_warning() -> None:
    with pytest.warns(FutureWarning) as caught:
        world = World.from_scene(OLD_KEY_SCENE)
    with world:
        keys = [p.key for p in world.plugins]
    assert "clips" not in keys and "lod" not in keys  # plugins.lod: false turned it off
    assert "physics_health" in world.schedule.names
    [warning] = caught  # one, at the file's line that names the old key
    assert (warning.filename, warning.lineno) == (str(OLD_KEY_SCENE), 5)
    assert str(warning.message) == (
        "plugins.lod is deprecated: the plugin is now plugins.clips (read as such)"
    )
    assert world.scene is not None and world.scene["plugins"]["clips"] is False


def test_the_former_key_configures_the_plugin_and_the_new_key_wins_over_it() -> None:
    scene = json.loads(OLD_KEY_SCENE.read_text())
    scene["plugins"] = {"lod": {}}
    with pytest.warns(FutureWarning, match=r"^plugins\.lod is deprecated"):
        world = World.from_scene(scene)
    with world:
        assert "clips" in [p.key for p in world.plugins]
    assert scene["plugins"] == {"lod": {}}  # the caller's dict is left as it was
    scene["plugins"] = {"lod": {}, "clips": False}
    with pytest.warns(FutureWarning, match=r"\(ignored: plugins\.clips is set too\)$"):
        world = World.from_scene(scene)
    with world:
        assert "clips" not in [p.key for p in world.plugins]
